"""Benchmark: finite-strain C-NEM (`cnem.Hyperelasticity`): a Newton iteration against the
linear `cnem.Elasticity` solve on the same model and against felupe P1/P2 (issue 38);
``--cpd``: against CPD (`cnem.pd.CPD`) on the same nodes.

Workload (default)
------------------
A cantilever ``[0, 5] x [0, 1]`` (2-D, plane strain) or ``[0, 5] x [0, 1]^2`` (3-D, the
box of `benchmarks/three_d.py`), clamped (u = 0) on x = 0, a dead downward traction
0.012 mu on the end face x = 5 (tip deflection about 0.3 of the length, rotations of
about 30 degrees), compressible neo-Hookean ``mu = 1``, ``lam = 1.5`` (nu = 0.3),
4 load steps, relative tolerance 1e-8. For each dimension (``--dims``) and size
(``--sizes``, default 10k nodes) one cloud ``cnem.nodes.irregular(domain, h, seed=0)``,
``h`` chosen for about n nodes, one model ``cnem.discretize``, and on it, in one fresh
child process per case (numba warmed up first on a tiny case, `_harness.warm_both`):

* **C-NEM**: ``cnem.Hyperelasticity(model, NeoHookean(1, 1.5))`` (stabilisation 1).
  Per Newton iteration, medians over the iterations: ``residual + tangent`` (one
  ``system.evaluate(u, True)``, what Newton calls), the ``solve`` (the constrained linear
  solve of the correction), and ``residual`` alone (``evaluate(u, False)`` at the end
  state, median of 3), ``tangent`` the difference.
* **linear**: ``cnem.Elasticity(model, (E, nu), plane="strain")`` with the linearised
  moduli, the same conditions, the same smoothed gradients: ``K + load`` and ``solve``
  of ``prob.solve()``.
* **felupe P1** (only when felupe is importable: ``pip install -e .[compare]``; it is
  GPL, an optional extra for the benchmarks only): `felupe.NeoHookeCompressible` (the
  same W up to a constant) on the model's own triangles / tetrahedra and nodes, the
  consistent nodal loads of the same traction, felupe's own Newton and sparse direct
  solve; per iteration tangent, solve and residual (felupe's plugin hooks).
* **equal accuracy**: the tip deflection (load-weighted mean of the end face's
  displacement along the load, ``f . u / |sum f|``) against a converged reference, felupe
  P2 on a structured mesh (`REFERENCE_CELLS`: 32 squares across the section in 2-D, 4
  cubes in 3-D, whose sparse direct solves are what a busy 2-core machine affords; the
  table shows the change from half as many); felupe P2 on structured meshes with 1, 2,
  3, ... cells across (`P2_CELLS`), the coarsest whose error is at most C-NEM's, and the
  time of each whole run (setup + Newton; C-NEM's with `cnem.discretize`).

Both sides run on one thread where they can (felupe's assembly and scipy's direct solve
are single-threaded; run with ``NUMBA_NUM_THREADS=1`` for the same on C-NEM's side).

How to run
----------
::

    python benchmarks/finite_strain.py                           # 10k nodes, 2-D and 3-D
    python benchmarks/finite_strain.py --dims 2 --sizes 10000 100000
    python benchmarks/finite_strain.py --cpd small large         # the CPD comparison
"""
import argparse
import sys
import time

import numpy as np

import _cpd_versus
import _felupe_side as felupe_side
from _harness import (MachineLoad, fmt_n, in_child, load_text, print_targets, warm_both,
                      warm_median)

LENGTH, WIDTH, TRACTION, MU, LAM, STEPS, TOL = 5.0, 1.0, 0.012, 1.0, 1.5, 4, 1e-8
REFERENCE_CELLS = {2: 32, 3: 4}
P2_CELLS = {2: (1, 2, 3, 4, 6, 8, 12, 16), 3: (1, 2, 3)}


# --------------------------------------------------------------------------- the problem
def _cloud(dim, n):
    """An irregular cloud of about ``n`` nodes in the beam."""
    import cnem
    domain = (cnem.geometry.rectangle(LENGTH, WIDTH) if dim == 2 else
              cnem.geometry.box((0.0, 0.0, 0.0), (LENGTH, WIDTH, WIDTH)))
    volume = LENGTH * WIDTH ** (dim - 1)
    h = (volume / n) ** (1.0 / dim)
    h *= (len(cnem.nodes.irregular(domain, h, seed=0).points) / n) ** (1.0 / dim)
    return cnem.nodes.irregular(domain, h, seed=0)


def _conditions(prob, dim):
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9 * LENGTH, None, 0.0)
    traction = np.zeros(dim)
    traction[-1] = -TRACTION
    prob.add_traction(lambda x, n: x[:, 0] > LENGTH * (1 - 1e-9), traction)


def _tip(load, u):
    """Load-weighted mean displacement along the load: ``f . u / |sum f|``."""
    return float(load @ u.reshape(-1) / abs(load.sum()))


class _Clock:
    """Times every call of ``obj.name`` until `restore`: ``calls``, a list of (seconds,
    the call's second positional argument as a tuple, e.g. evaluate's ``(tangent,)``)."""

    def __init__(self, obj, name):
        self.calls, self.obj, self.name = [], obj, name
        self.original = original = getattr(obj, name)

        def timed(*args, **kwargs):
            t0 = time.perf_counter()
            out = original(*args, **kwargs)
            self.calls.append((time.perf_counter() - t0, args[1:2]))
            return out

        setattr(obj, name, timed)

    def restore(self):
        setattr(self.obj, self.name, self.original)


def _cnem_sides(model, dim, discretize=0.0):
    """C-NEM Newton and the linear solve on ``model``: timings and tip deflections."""
    import importlib

    import cnem
    newton_module = importlib.import_module("cnem.solvers.newton")  # the name is a function
    t0 = time.perf_counter()
    prob = cnem.Hyperelasticity(model, cnem.material.NeoHookean(MU, LAM))
    _conditions(prob, dim)
    system = prob.system
    setup = time.perf_counter() - t0
    evaluations = _Clock(system, "evaluate")
    solves = _Clock(newton_module, "solve_constrained")
    try:
        sol = prob.solve(steps=STEPS, tol=TOL, progress=False)
    finally:
        solves.restore()
        evaluations.restore()
    evaluate = float(np.median([t for t, flag in evaluations.calls if flag == (True,)]))
    residual, _ = warm_median(lambda: system.evaluate(sol.u.reshape(-1), False), 3)
    load = prob.load()
    its = sum(len(r) - 1 for r in sol.residual_history)
    cnem_row = dict(setup=setup + discretize, newton=sol.timings["newton"], its=its,
                    evaluate=evaluate, residual=residual,
                    solve=float(np.median([t for t, _ in solves.calls])),
                    tip=_tip(load, sol.u))
    E, nu = MU * (3 * LAM + 2 * MU) / (LAM + MU), LAM / (2 * (LAM + MU))
    linear = cnem.Elasticity(model, (E, nu), plane="strain" if dim == 2 else None,
                             gradients=prob.gradients)
    _conditions(linear, dim)
    lsol = linear.solve(progress=False)
    linear_row = dict(assembly=lsol.timings["assembly"], solve=lsol.timings["solve"],
                      tip=_tip(load, lsol.u))
    return cnem_row, linear_row


def _case_child(dim, n, with_felupe):
    """One dimension and size: warm-up, cloud, model, C-NEM, linear, felupe P1."""
    import cnem
    t0 = time.perf_counter()
    warm_both(lambda: _cnem_sides(cnem.discretize(_cloud(dim, 300 if dim == 3 else 200),
                                                  progress=False), dim))
    warmup = time.perf_counter() - t0
    cloud = _cloud(dim, n)
    t0 = time.perf_counter()
    model = cnem.discretize(cloud, progress=False)
    discretize = time.perf_counter() - t0
    cnem_row, linear_row = _cnem_sides(model, dim, discretize)
    out = dict(dim=dim, n=n, nodes=len(model.nodes), warmup=warmup, discretize=discretize, cnem=cnem_row, linear=linear_row)
    if with_felupe:
        if dim == 2:
            cells, kind = model.triangles, "triangle"
        else:
            cells, kind = felupe_side.positive_tetrahedra(model.nodes, model.tetrahedra), "tetra"
        traction = np.zeros(dim)
        traction[-1] = -TRACTION
        out["p1"] = felupe_side.solve(np.asarray(model.nodes, float), np.asarray(cells),
                                      kind, (MU, LAM), LENGTH, traction, STEPS, TOL)
    return out


def _p2_child(dim, cells_list, reference_cells):
    """felupe P2 on structured meshes of ``cells_list`` and ``reference_cells // 2`` cells
    across, then the reference: a list of rows by cells across, the reference last."""
    traction = np.zeros(dim)
    traction[-1] = -TRACTION
    rows = []
    for k in sorted(set(cells_list) | {reference_cells // 2}) + [reference_cells]:
        points, cells, kind = felupe_side.quadratic(
            felupe_side.structured(dim, LENGTH, WIDTH, k))
        row = felupe_side.solve(points, cells, kind, (MU, LAM), LENGTH, traction, STEPS, TOL)
        rows.append(dict(row, cells=k))
    return rows


# ------------------------------------------------------------------------------ reports
def _report(cases, p2):
    """The tables and the targets."""
    targets = []
    for case in cases:
        dim, n = case.get("dim"), case.get("n")
        print(f"\n{dim}-D, {fmt_n(n)} nodes requested:")
        if "error" in case:
            print(f"  {case['error']}")
            continue
        c, lin = case["cnem"], case["linear"]
        tangent = c["evaluate"] - c["residual"]
        iteration = c["evaluate"] + c["solve"]
        linear = lin["assembly"] + lin["solve"]
        print(f"  {case['nodes']} nodes, discretize {case['discretize']:.2f} s, "
              f"warm-up {case['warmup']:.1f} s")
        print(f"  {'per Newton iteration (median s)':<34}{'C-NEM':>9}{'felupe P1':>11}{'ratio':>7}")
        p1 = case.get("p1")
        rows = [("residual", c["residual"], p1 and p1["residual"]),
                ("tangent", tangent, p1 and p1["tangent"]),
                ("solve", c["solve"], p1 and p1["solve"]),
                ("iteration", iteration, p1 and p1["residual"] + p1["tangent"] + p1["solve"])]
        for name, a, b in rows:
            tail = f"{b:11.3f}{a / b:7.2f}" if b else f"{'-':>11}"
            print(f"  {name:<34}{a:9.3f}{tail}")
        print(f"  {'Newton iterations, Newton s':<34}{c['its']:>4}{c['newton']:>8.1f}  "
              + (f"{p1['its']:>4}{p1['newton']:>8.1f}" if p1 else ""))
        print(f"  linear Elasticity: K + load {lin['assembly']:.3f} s, solve {lin['solve']:.3f} "
              f"s, together {linear:.3f} s; iteration / linear = {iteration / linear:.2f}")
        targets.append((f"{dim}-D {fmt_n(n)}: Newton iteration <= 2 x linear solve",
                        f"{iteration:.3f} s vs {linear:.3f} s ({iteration / linear:.2f}x)",
                        iteration <= 2 * linear))
        ref = p2.get(dim)
        if not isinstance(ref, list):           # not run, or its child's error
            print(f"  tip deflection: C-NEM {c['tip']:.5f}, linear {lin['tip']:.5f}"
                  + (f", P1 {p1['tip']:.5f}" if p1 else "")
                  + (f" (P2: {ref['error']})" if ref else ""))
            continue
        tip_ref = ref[-1]["tip"]
        err = abs(c["tip"] / tip_ref - 1)
        cnem_time = c["setup"] + c["newton"]
        print(f"  tip deflection (P2 reference {tip_ref:.6f}): C-NEM {c['tip']:.6f} "
              f"({c['tip'] / tip_ref - 1:+.3%}), linear {lin['tip']:.5f}"
              + (f", P1 same nodes {p1['tip']:.6f} ({p1['tip'] / tip_ref - 1:+.3%}, "
                 f"{p1['setup'] + p1['newton']:.1f} s)" if p1 else ""))
        match = next((r for r in ref[:-1] if abs(r["tip"] / tip_ref - 1) <= err), None)
        if match is None:
            print(f"  no P2 mesh of the series reaches C-NEM's error {err:.2e}")
            continue
        p2_time = match["setup"] + match["newton"]
        print(f"  equal accuracy: C-NEM {err:.2e} in {cnem_time:.1f} s (discretize + setup "
              f"+ Newton); P2 {match['cells']} across ({match['dofs']} dofs) "
              f"{abs(match['tip'] / tip_ref - 1):.2e} in {p2_time:.2f} s; ratio "
              f"{cnem_time / p2_time:.1f}")
        if n >= 100_000:
            targets.append((f"{dim}-D {fmt_n(n)}: C-NEM <= 1.5 x felupe at equal accuracy",
                            f"{cnem_time:.1f} s vs {p2_time:.2f} s", cnem_time <= 1.5 * p2_time))
    for dim, rows in p2.items():
        if not isinstance(rows, list):
            continue
        print(f"\nfelupe P2, {dim}-D structured (cells across, dofs, tip, error vs "
              f"{REFERENCE_CELLS[dim]} across, its, setup + Newton s, s/iteration):")
        for r in rows:
            print(f"  {r['cells']:3d} {r['dofs']:8d} {r['tip']:.6f} "
                  f"{r['tip'] / rows[-1]['tip'] - 1:+.2e} {r['its']:3d} "
                  f"{r['setup'] + r['newton']:8.2f} "
                  f"{r['residual'] + r['tangent'] + r['solve']:8.3f}")
    print()
    print_targets(targets)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--dims", nargs="+", type=int, choices=(2, 3), default=[2, 3])
    parser.add_argument("--sizes", nargs="+", type=int, default=[10_000],
                        help="nodes per model (default 10000)")
    parser.add_argument("--p2-dims", nargs="*", type=int, choices=(2, 3), default=None,
                        help="dimensions of the P2 series (default: --dims)")
    parser.add_argument("--cpd", nargs="+", choices=tuple(_cpd_versus.SIZES),
                        help="run the C-NEM vs CPD comparison at these sizes instead")
    args = parser.parse_args(argv)
    if args.cpd:
        return _cpd_versus.main(args.cpd)
    machine = MachineLoad()
    with_felupe = felupe_side.available()
    print(f"benchmarks/finite_strain.py: dims {args.dims}, sizes {args.sizes}; python "
          f"{sys.version.split()[0]}, numpy {np.__version__}; load average "
          f"{load_text(machine.before.load)}")
    if not with_felupe:
        print("felupe is not installed: no felupe columns (pip install -e .[compare]; "
              "felupe is GPL-3.0, an optional extra for the benchmarks only)")
    p2 = {}
    if with_felupe:
        for dim in args.dims if args.p2_dims is None else args.p2_dims:
            t0 = time.perf_counter()
            p2[dim] = in_child(_p2_child, dim, P2_CELLS[dim], REFERENCE_CELLS[dim])
            print(f"  felupe P2 series {dim}-D: {time.perf_counter() - t0:.0f} s", flush=True)
    cases = []
    for dim in args.dims:
        for n in args.sizes:
            t0 = time.perf_counter()
            cases.append(dict(in_child(_case_child, dim, n, with_felupe), dim=dim, n=n))
            print(f"  {dim}-D {fmt_n(n)}: {time.perf_counter() - t0:.0f} s", flush=True)
    _report(cases, p2)
    print("\n" + machine.stop().report())


if __name__ == "__main__":
    main()
