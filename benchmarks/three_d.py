"""Benchmark: 3-D C-NEM against P1 tetrahedra on the same nodes, the same load (issue 37).

Workload
--------
The cantilever of issue 37: the box ``[0, 5] x [0, 1] x [0, 1]`` (E = 1000, nu = 0.3),
clamped (u = 0) on x = 0, the shear traction ``(0, 0, -1)`` on x = 5. For each size n
(default 10k nodes; ``--sizes 10000 100000 1000000``) one irregular cloud
``cnem.nodes.irregular(box, h, seed=0)``, ``h`` chosen for about n nodes (one
correction from a first cloud), one model ``cnem.discretize(cloud)``, and on it:

* **C-NEM**: ``cnem.Elasticity(model, (E, nu))`` (default stabilisation);
* **P1** (the anchor): ``cnem.fem.P1Elasticity.from_model(model, (E, nu))``, scikit-fem
  ``ElementVector(ElementTetP1())`` on the model's own tetrahedra.

What is measured
----------------
Wall times of each stage, in one fresh child process per size (numba warmed up first on a
tiny cantilever, twice: ``_harness.warm_both``), C-NEM first, then P1 on the same model:

* ``tetrahedra``, ``cells``: ``model.timings`` (``discretize``); P1 needs the tetrahedra
  (the same ones: its column repeats the number) but no cells;
* ``shape functions``: every call of ``Model3D.shape_functions`` (the first builds the
  located tetrahedrisation, ``Model3D.tet_mesh``), timed by wrapping the method: they
  are made inside the smoothed gradients and the traction loads, whose times below
  exclude them;
* ``smoothed gradients``: B~ of the cells and of their sub-cells (building
  ``prob.basis``); P1: ``from_model`` (the scikit-fem mesh and basis);
* ``K``: ``prob.stiffness()``, C-NEM's as its upper triangle as ``prob.solve()`` makes it
  (``stiffness(upper=True)``);
* ``loads``: the traction loads (``prob.load()``);
* ``solve``: ``solve_constrained`` as ``prob.solve()`` runs it (support check,
  condensation, direct solve up to 2.5M non-zeros, smoothed aggregation + CG above);
* ``total``: the sum.

Peak memory: the process's high-water RSS (``VmHWM``) reset before each side's stages
(P1's after the model is built: the model is alive, its tetrahedrisation counted on the
C-NEM side).

Error per node: ``rms_i |u_h(x_i) - u_ref(x_i)| / max_i |u_ref(x_i)|`` against the P2
reference (``tests/reference.py: cantilever_p2``, ``--reference-cells`` cubes across the
section, default 6: 31k dofs, within 0.05 % of 8 on the tip deflection), and the tip
deflection (mean ``u_z`` over the end face) of each side against it.

``--cantilever`` prints instead the convergence table of the tip deflection: C-NEM and
P1 at several spacings (``--spacings``), the P2 reference refined (``--reference-cells``
list) until it changes by less than 0.1 %, and Timoshenko's beam value.

How to run
----------
::

    python benchmarks/three_d.py                        # 10k nodes (~4 min, busy 2 cores)
    python benchmarks/three_d.py --sizes 10000 100000 1000000
    python benchmarks/three_d.py --cantilever           # the tip-deflection table (~3 min)
"""
import argparse
import os
import sys
import time

import numpy as np

from _harness import (MachineLoad, fmt_n, in_child, load_text, peak_rss_bytes, reset_peak_rss,
                      warm_both)

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "tests"))
from reference import beam_tip, cantilever_p2, end_face_mean  # noqa: E402

LENGTH, WIDTH, LOAD, MATERIAL = 5.0, 1.0, 1.0, (1000.0, 0.3)
DEFAULT_SIZES = [10_000]
STAGES = ["tetrahedra", "cells", "shape functions", "smoothed gradients", "K", "loads",
          "solve"]


# --------------------------------------------------------------------------- the problem
def _cloud(n):
    """An irregular cloud of about ``n`` nodes in the cantilever box."""
    import cnem
    box = cnem.geometry.box((0.0, 0.0, 0.0), (LENGTH, WIDTH, WIDTH))
    h = (LENGTH * WIDTH ** 2 / n) ** (1.0 / 3.0)
    cloud = cnem.nodes.irregular(box, h, seed=0)
    h *= (len(cloud.points) / n) ** (1.0 / 3.0)
    return cnem.nodes.irregular(box, h, seed=0), h


def _conditions(prob):
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9 * LENGTH, None)
    prob.add_traction(lambda x, n: n[:, 0] > 0.5, [0.0, 0.0, -LOAD])


class _ShapeFunctionClock:
    """Wraps ``Model3D.shape_functions`` and adds up the seconds spent in it."""

    def __init__(self):
        from cnem.geometry.model3d import Model3D
        self.seconds = 0.0
        original = Model3D.shape_functions

        def timed(model, *args, **kwargs):
            t0 = time.perf_counter()
            try:
                return original(model, *args, **kwargs)
            finally:
                self.seconds += time.perf_counter() - t0

        Model3D.shape_functions = timed

    def since(self, start):
        return self.seconds - start


def _stage(times, peaks, name, fn, clock=None):
    """Run ``fn``, record its wall time (less the shape functions inside) and peak RSS."""
    reset_peak_rss()
    start = clock.seconds if clock else 0.0
    t0 = time.perf_counter()
    out = fn()
    times[name] = time.perf_counter() - t0 - (clock.since(start) if clock else 0.0)
    peaks[name] = peak_rss_bytes()
    return out


def _sides(model, clock):
    """C-NEM then P1 on ``model``: stage times, peaks and the displacements."""
    import cnem
    from cnem._memory import release_free_memory
    from cnem.solvers.constrained import solve_constrained
    out = {}
    for side in ("C-NEM", "P1"):
        times, peaks = {}, {}
        sf0 = clock.seconds
        if side == "C-NEM":
            times.update(model.timings)
            prob = cnem.Elasticity(model, MATERIAL)
            _stage(times, peaks, "smoothed gradients", lambda: prob.basis, clock)
        else:
            times["tetrahedra"] = model.timings["tetrahedra"]
            prob = _stage(times, peaks, "smoothed gradients",
                          lambda: cnem.fem.P1Elasticity.from_model(model, MATERIAL))
        _conditions(prob)
        K = _stage(times, peaks, "K", lambda: prob.stiffness(upper=True) if side == "C-NEM"
                   else prob.stiffness())
        f = _stage(times, peaks, "loads", prob.load, clock)
        options = prob.solver_options if side == "C-NEM" else None
        dofs, values = prob.prescribed()
        x = _stage(times, peaks, "solve", lambda: solve_constrained(
            K, f, dofs, values, points=model.nodes, options=options))
        times["shape functions"] = clock.since(sf0)
        out[side] = dict(times=times, peak=max(peaks.values()), u=x.reshape(-1, 3),
                         dofs=len(x))
        del prob, K, f, x
        release_free_memory()
    return out


def _size_child(n, reference_cells):
    """One size: warm-up, cloud, model, both sides, the P2 reference at the nodes."""
    import cnem
    t0 = time.perf_counter()
    warm_model = cnem.discretize(_cloud(300)[0])
    warm_both(lambda: [cnem.Elasticity(warm_model, MATERIAL).stiffness(),
                       cnem.fem.P1Elasticity.from_model(warm_model, MATERIAL).stiffness()])
    warmup = time.perf_counter() - t0
    cloud, h = _cloud(n)
    clock = _ShapeFunctionClock()
    reset_peak_rss()
    model = cnem.discretize(cloud)
    discretize_peak = peak_rss_bytes()
    out = _sides(model, clock)
    out["C-NEM"]["peak"] = max(out["C-NEM"]["peak"], discretize_peak)
    result = dict(n=n, nodes=len(model.nodes), tets=len(model.tetrahedra),
                  cells=len(model.cells.node), h=h, warmup=warmup)
    for side in ("C-NEM", "P1"):
        u = out[side].pop("u")
        out[side]["tip"] = end_face_mean(model, u[:, 2])
        out[side]["u"] = u
    result["sides"] = out
    if reference_cells:
        tip, displacement, dofs = cantilever_p2(LENGTH, WIDTH, MATERIAL, LOAD, reference_cells)
        u_ref = displacement(model.nodes)
        scale = np.linalg.norm(u_ref, axis=1).max()
        result["reference"] = dict(tip=tip, dofs=dofs)
        for side in ("C-NEM", "P1"):
            diff = np.linalg.norm(out[side]["u"] - u_ref, axis=1)
            out[side]["node_error"] = float(np.sqrt((diff ** 2).mean()) / scale)
    for side in ("C-NEM", "P1"):
        out[side].pop("u")
    return result


# ------------------------------------------------------------------------------ reports
def _table(results):
    print("\nstage times (s), peak memory, errors against the P2 reference:")
    header = f"  {'n':>5} {'nodes':>7} {'stage':<20} {'C-NEM':>9} {'P1':>9} {'ratio':>7}"
    print(header)
    for r in results:
        if "error" in r:
            print(f"  {fmt_n(r['n']):>5}: {r['error']}")
            continue
        c, p = r["sides"]["C-NEM"], r["sides"]["P1"]
        rows = [(s, c["times"].get(s, 0.0), p["times"].get(s, 0.0)) for s in STAGES]
        rows.append(("total", sum(v for _, v, _ in rows), sum(v for _, _, v in rows)))
        for k, (stage, a, b) in enumerate(rows):
            lead = f"  {fmt_n(r['n']):>5} {r['nodes']:>7}" if k == 0 else " " * 15
            ratio = f"{a / b:7.1f}" if b > 0 else "      -"
            print(f"{lead} {stage:<20} {a:9.3f} {b:9.3f} {ratio}")
        print(f"{'':15} {'peak memory (GB)':<20} {c['peak'] / 2**30:9.2f} {p['peak'] / 2**30:9.2f} "
              f"{c['peak'] / p['peak']:7.1f}")
        if "reference" in r:
            ref = r["reference"]
            print(f"{'':15} {'error per node':<20} {c['node_error']:9.2e} {p['node_error']:9.2e} "
                  f"{c['node_error'] / p['node_error']:7.2f}")
            print(f"{'':15} {'tip deflection':<20} {c['tip']:9.5f} {p['tip']:9.5f}   "
                  f"(P2 {ref['tip']:.5f}, {ref['dofs']} dofs: errors "
                  f"{c['tip'] / ref['tip'] - 1:+.2%} and {p['tip'] / ref['tip'] - 1:+.2%})")
        print(f"{'':15} h = {r['h']:.4f}, {r['tets']} tetrahedra, {r['cells']} cells, "
              f"warm-up {r['warmup']:.1f} s")


def _cantilever_table(spacings, reference_cells):
    """Tip deflection of C-NEM and P1 at several spacings against the P2 reference."""
    import cnem
    refs = []
    print("P2 reference (cubes across the section, dofs, tip deflection, change):")
    for cells in reference_cells:
        t0 = time.perf_counter()
        tip, _, dofs = cantilever_p2(LENGTH, WIDTH, MATERIAL, LOAD, cells)
        change = f"{tip / refs[-1] - 1:+.3%}" if refs else ""
        refs.append(tip)
        print(f"  {cells:3d} {dofs:8d} {tip:.6f} {change}  ({time.perf_counter() - t0:.0f} s)",
              flush=True)
    reference = refs[-1]
    beam = -beam_tip(LENGTH, WIDTH, MATERIAL, LOAD * WIDTH ** 2)
    print(f"Timoshenko beam: {beam:.5f} ({beam / reference - 1:+.2%} from P2)")
    print(f"\n  {'h':>6} {'nodes':>6} {'C-NEM tip':>10} {'P1 tip':>10} {'P2 ref':>10} "
          f"{'C-NEM err':>10} {'P1 err':>10}")
    box = cnem.geometry.box((0.0, 0.0, 0.0), (LENGTH, WIDTH, WIDTH))
    for h in spacings:
        model = cnem.discretize(cnem.nodes.irregular(box, h, seed=0))
        tips = []
        for prob in (cnem.Elasticity(model, MATERIAL),
                     cnem.fem.P1Elasticity.from_model(model, MATERIAL)):
            _conditions(prob)
            tips.append(end_face_mean(model, prob.solve().u[:, 2]))
        print(f"  {h:6.3f} {len(model.nodes):6d} {tips[0]:10.5f} {tips[1]:10.5f} "
              f"{reference:10.5f} {tips[0] / reference - 1:+10.2%} {tips[1] / reference - 1:+10.2%}",
              flush=True)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", type=int, nargs="+", metavar="N", default=DEFAULT_SIZES,
                        help="node counts (default 10000)")
    parser.add_argument("--reference-cells", type=int, nargs="+", metavar="K", default=None,
                        help="P2 reference: cubes across the section (default 6; "
                             "--cantilever: 4 6 8); 0: no reference")
    parser.add_argument("--cantilever", action="store_true",
                        help="the tip-deflection table at several spacings instead")
    parser.add_argument("--spacings", type=float, nargs="+", default=[0.5, 1 / 3, 0.25, 0.2])
    args = parser.parse_args(argv)
    machine = MachineLoad()
    print(f"benchmarks/three_d.py: load average {load_text(machine.before.load)}")
    if args.cantilever:
        _cantilever_table(args.spacings, args.reference_cells or [4, 6, 8])
    else:
        cells = (args.reference_cells or [6])[-1]
        results = []
        for n in args.sizes:
            print(f"  n = {fmt_n(n)} ...", flush=True)
            results.append({"n": n, **in_child(_size_child, n, cells)})
        _table(results)
    print("\n" + machine.stop().report())


if __name__ == "__main__":
    main()
