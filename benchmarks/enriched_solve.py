"""Benchmark: the linear solve of a branch-enriched centre-cracked plate.

Workload
--------
The square ``[-0.5, 0.5]^2`` with a centre crack from (-0.1, 0) to (0.1, 0), a regular
cloud of spacing ``h`` (``--nodes`` sets it: about ``1 / h^2`` nodes), the four branch
functions on the nodes within ``--radius`` (0.1) of the tips, E = 1, nu = 0.3, clamped at
y = -0.5 and pulled to v = 1e-3 at y = 0.5.

What is measured
----------------
Wall times of the model and stiffness, then of each solve of the condensed system
``A x = b``: ``solve_spd`` with ``method="amg"`` and the nodal mask (smoothed aggregation
on the nodal block + LU of the enriched block), optionally (``--direct``) the direct
solve, with the relative residual ``|A x - b| / |b|`` and the CG iterations (logged), and
the estimated direct factor (`cnem.solvers.linsolve.direct_factor_bytes`).

Run: ``python benchmarks/enriched_solve.py --nodes 16000 100000 [--direct]``.
"""

import argparse
import logging
import pathlib
import sys
import time

import numpy as np
import scipy.sparse.linalg as spla

from cnem.solvers import linsolve

from _harness import MachineLoad, load_text, peak_rss_bytes


def build(nodes, radius):
    """The condensed system, its nodal mask and rigid modes (the tests' plate,
    `tests/test_robust_solve.py`)."""
    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "tests"))
    from test_robust_solve import _centre_cracked
    return _centre_cracked(1.0 / np.sqrt(nodes), radius)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--nodes", type=int, nargs="+", default=[16_000])
    parser.add_argument("--radius", type=float, default=0.1)
    parser.add_argument("--direct", action="store_true", help="time the direct solve too")
    args = parser.parse_args()
    logging.basicConfig(level=logging.INFO, format="  %(message)s")
    machine = MachineLoad()
    print(f"benchmarks/enriched_solve.py: load average {load_text(machine.before.load)}")
    for nodes in args.nodes:
        start = time.perf_counter()
        A, b, nodal, modes = build(nodes, args.radius)
        print(f"{A.shape[0]} unknowns ({(~nodal).sum()} enriched), {A.nnz} "
              f"non-zeros, estimated direct factor {linsolve.direct_factor_bytes(A) / 1e9:.2f} "
              f"GB; model + K {time.perf_counter() - start:.1f} s", flush=True)
        start = time.perf_counter()
        x = linsolve.solve_spd(A, b, modes=modes, method="amg", nodal=nodal)
        print(f"  block-preconditioned CG {time.perf_counter() - start:.1f} s, residual "
              f"{np.linalg.norm(A @ x - b) / np.linalg.norm(b):.1e}", flush=True)
        if args.direct:
            start = time.perf_counter()
            x = spla.spsolve(A.tocsc(), b)
            print(f"  direct {time.perf_counter() - start:.1f} s, residual "
                  f"{np.linalg.norm(A @ x - b) / np.linalg.norm(b):.1e}", flush=True)
        print(f"  peak RSS {peak_rss_bytes() / 1e9:.2f} GB", flush=True)
    print("\n" + machine.stop().report())


if __name__ == "__main__":
    main()
