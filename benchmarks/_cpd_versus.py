"""The C-NEM vs CPD comparison of `benchmarks/finite_strain.py` (``--cpd``): finite-strain C-NEM (`cnem.Hyperelasticity`) against CPD (`cnem.pd.CPD`) on
the same nodes: time per Newton iteration and in all.

Workload
--------
The bent cantilever of `cnem.demos.cnem_vs_cpd`: a 5 x 1 beam, `cnem.nodes.regular` of
spacing h, clamped on its left edge, a downward load 0.008 mu H on its right edge (tip
deflection about 0.3 of the length), the law
`cnem.demos.cpd.bond_law.BondContinuum` with n = 2 (Saint Venant-Kirchhoff, nu = 1/4)
for C-NEM (sub-cell stabilisation 1) and one-neighbour CPD with the same energy
(horizon 3 spacings, C1 calibrated on the interior points), 4 load steps, relative
tolerance 1e-9. Sizes: ``small`` h = 0.05 (2 121 nodes), ``large`` h = 0.02 (12 801 nodes).

What is measured
----------------
One process, size after size, after a warm-up on h = 0.25 (numba kernels, pyamg).

* ``setup s``: C-NEM: `cnem.discretize` + the smoothed and sub-cell gradients
  (``prob.system``); CPD: `cnem.pd.Body.from_cloud` (it discretizes too) + the
  interactions.
* ``evaluate s``: one residual + tangent at the undeformed state (median of 3 after a
  warm-up).
* ``Newton s``: the whole Newton solve (predictors, corrections with their linear
  solves); ``its``: Newton corrections in all; ``s/it``: their ratio.
* The ratio columns: CPD / C-NEM.

scikit-fem P1/P2 on the same nodes is not run here (see `docs/finite_strain.md`).

How to run
----------
::

    python benchmarks/finite_strain.py --cpd small          # a shared machine
    python benchmarks/finite_strain.py --cpd small large
"""
import sys
import time

import numpy as np

from _harness import MachineLoad, load_text, warm_median

SIZES = {"small": 0.05, "large": 0.02}
LENGTH, HEIGHT, LOAD, STEPS, HORIZON = 5.0, 1.0, 0.008, 4, 3.0


def run(h):
    """The measurements of one spacing: a dict per method."""
    import cnem
    from cnem.demos.cnem_vs_cpd import _interior
    from cnem.demos.cpd.bond_law import BondContinuum
    from cnem.demos.cpd.versus import run_cpd
    law = BondContinuum(1.0, 2.0)
    tol = 1e-9 * LENGTH
    t0 = time.perf_counter()
    nodes = cnem.nodes.regular(cnem.geometry.rectangle(LENGTH, HEIGHT), h)
    model = cnem.discretize(nodes, progress=False)
    prob = cnem.Hyperelasticity(model, law)
    prob.add_dirichlet(lambda p: p[:, 0] < tol, None, 0.0)
    prob.add_traction(lambda x, n: x[:, 0] > LENGTH - tol, np.array([0.0, -LOAD / HEIGHT]))
    prob.system
    setup = time.perf_counter() - t0
    zero = np.zeros(model.nodes.size)
    evaluate, _ = warm_median(lambda: prob.system.evaluate(zero, True), 3)
    sol = prob.solve(steps=STEPS, tol=1e-9, progress=False)
    its = sum(len(r) - 1 for r in sol.residual_history)
    rows = {"C-NEM": dict(n=len(model.nodes), setup=setup, evaluate=evaluate,
                          newton=sol.timings["newton"], its=its)}
    tip = model.nodes[:, 0] > LENGTH - tol
    forces = np.zeros((len(model.nodes), 2))
    forces[tip, 1] = -LOAD / tip.sum()
    cpd = run_cpd(nodes, HORIZON, law, _interior(LENGTH, HEIGHT),
                  [(lambda p: p[:, 0] < tol, None, 0.0)], forces, STEPS)
    rows["CPD"] = dict(n=len(model.nodes), setup=cpd.setup_seconds,
                       evaluate=cpd.evaluate_seconds, newton=cpd.seconds, its=cpd.iterations)
    deflection = (-sol.u[tip, 1].mean(), -cpd.u[-1][tip, 1].mean())
    return rows, deflection


def main(sizes):
    """Run the comparison at ``sizes`` (keys of `SIZES`) and print its table."""
    machine = MachineLoad()
    print(f"benchmarks/finite_strain.py: sizes {sizes}; python {sys.version.split()[0]}, "
          f"numpy {np.__version__}; load average {load_text(machine.before.load)}")
    t0 = time.perf_counter()
    run(0.25)
    print(f"  warm-up {time.perf_counter() - t0:.2f} s", flush=True)
    head = (f"{'size':>6}{'nodes':>7}{'method':>7}{'setup s':>9}{'evaluate s':>11}"
            f"{'Newton s':>10}{'its':>5}{'s/it':>8}{'tip':>8}")
    lines = [head]
    for size in sizes:
        rows, deflection = run(SIZES[size])
        for (name, r), tip in zip(rows.items(), deflection):
            lines.append(f"{size:>6}{r['n']:>7}{name:>7}{r['setup']:>9.3f}{r['evaluate']:>11.4f}"
                         f"{r['newton']:>10.3f}{r['its']:>5}{r['newton'] / r['its']:>8.4f}"
                         f"{tip:>8.4f}")
        a, b = rows["C-NEM"], rows["CPD"]
        lines.append(f"{size:>6}{'':>7}{'CPD/CN':>7}{b['setup'] / a['setup']:>9.2f}"
                     f"{b['evaluate'] / a['evaluate']:>11.2f}{b['newton'] / a['newton']:>10.2f}"
                     f"{'':>5}{(b['newton'] / b['its']) / (a['newton'] / a['its']):>8.2f}")
    print("\n" + "\n".join(lines))
    print("\n" + machine.stop().report())

