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

``docs/elasticity.md`` quotes its 16k-node run (``--nodes 16000 --direct``): the
hierarchy, the LU of the enriched block and the CG iterations against the direct solve.

Run: ``python benchmarks/enriched_solve.py --nodes 16000 100000 [--direct]``;
``--quick``: 2.5k nodes, with the direct solve (a smoke run).
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

# the plate is the tests' case (tests/cases.py, used by tests/test_errors_solve.py)
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "tests"))
import cases  # noqa: E402

QUICK_NODES = 2_500


def build(nodes, radius):
    """The condensed system, its nodal mask and rigid modes
    (`cases.enriched_centre_crack_system`)."""
    return cases.enriched_centre_crack_system(1.0 / np.sqrt(nodes), radius)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--nodes", type=int, nargs="+", default=[16_000])
    parser.add_argument("--radius", type=float, default=0.1)
    parser.add_argument("--direct", action="store_true", help="time the direct solve too")
    parser.add_argument("--quick", action="store_true",
                        help=f"a smoke run: {QUICK_NODES} nodes, with the direct solve")
    args = parser.parse_args()
    if args.quick:
        args.nodes, args.direct = [QUICK_NODES], True
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
