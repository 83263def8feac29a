"""Benchmark: one crack-growth increment by the local update against a full rebuild.

What is measured
----------------
A single edge notch in tension (W = 1, H = 2, a0 = 0.3 at mid-height; bottom edge
u_y = 0, its left corner u_x = 0 too; traction (0, 1) on the top; E = 1, nu = 0.3,
plane strain, the default stabilisation), on ``cnem.nodes.irregular(dom, sqrt(2 / n),
seed=0)``. The crack grows straight by ``1.5 h`` per increment; the new vertex becomes
a node (``cnem.nodes.from_points`` of the previous points in the grown domain).
Every increment is done both ways on the same cloud, in one run:

* **local**: ``cnem.geometry.model_update.update(old_model, cloud)`` (``model``), then
  ``setup(new_model).update_from(old_problem, change)`` (``B~ + K``: copied rows and
  cells, only the changed cells integrated), then ``problem.solve()`` (``solve``);
* **full**: ``cnem.discretize(cloud)`` then ``setup(model).solve()``, which builds
  B~ and K from scratch (``model``, ``B~ + K`` from the solution's own timings, ``solve``).

``solve`` is the solution's ``timings["solve"]`` (condensation + the sparse solver,
direct up to ~20k nodes, AMG-CG above), the same in both paths. The table shows the
medians over the increments, the ratio increment / solve (target of issue 18: at most
1.5 for the local increment) and the speed-up full / local, with the machine's load
before and after (``_harness.MachineLoad``): the machine is shared, so absolute times move
with it; the ratios are from one run. Timings are printed, never asserted.

How to run
----------
::

    python benchmarks/growth.py                  # 10k and 100k nodes, 3 increments each
    python benchmarks/growth.py --quick          # ~3k nodes, 2 increments (CI smoke run)
    python benchmarks/growth.py --sizes 20000 --steps 5
"""
import argparse
import time

import numpy as np

from _harness import MachineLoad, fmt_n, load_text, median

W, H, A0 = 1.0, 2.0, 0.3


def domain(cracks):
    import cnem
    return cnem.Domain([[[0.0, 0.0], [W, 0.0], [W, H], [0.0, H]]], cracks=[cracks])


def setup(model):
    import cnem
    prob = cnem.Elasticity(model, (1.0, 0.3), plane="strain")
    prob.add_dirichlet(lambda p: p[:, 1] < 1e-9, 1)
    prob.add_dirichlet(lambda p: (p[:, 1] < 1e-9) & (p[:, 0] < 1e-9), 0)
    prob.add_traction(lambda x, nrm: nrm[:, 1] > 0.5, [0.0, 1.0])
    return prob


def run_size(n, steps):
    """Time ``steps`` increments both ways; one dict of lists of seconds per path."""
    import cnem
    from cnem.geometry.model_update import update

    h = np.sqrt(W * H / n)
    crack = np.array([[0.0, H / 2], [A0, H / 2]])
    cloud = cnem.nodes.irregular(domain(crack), h, seed=0)
    model = cnem.discretize(cloud, progress=False)
    prob = setup(model)
    prob.solve(progress=False)
    times = {path: {"model": [], "B~ + K": [], "solve": [], "increment": []}
             for path in ("local", "full")}
    for _ in range(steps):
        crack = np.vstack([crack, crack[-1] + [1.5 * h, 0.0]])
        cloud = cnem.nodes.from_points(domain(crack), cloud.points)
        t0 = time.perf_counter()
        change = update(model, cloud)
        t1 = time.perf_counter()
        new = setup(change.model).update_from(prob, change)
        t2 = time.perf_counter()
        sol = new.solve(progress=False)
        t3 = time.perf_counter()
        local = times["local"]
        local["model"].append(t1 - t0)
        local["B~ + K"].append(t2 - t1)
        local["solve"].append(sol.timings["solve"])
        local["increment"].append(t3 - t0)
        u_local = sol.u
        t0 = time.perf_counter()
        fresh = cnem.discretize(cloud, progress=False)
        t1 = time.perf_counter()
        ref = setup(fresh).solve(progress=False)
        t2 = time.perf_counter()
        full = times["full"]
        full["model"].append(t1 - t0)
        full["B~ + K"].append(ref.timings["gradients"] + ref.timings["assembly"])
        full["solve"].append(ref.timings["solve"])
        full["increment"].append(t2 - t0)
        scale = np.abs(ref.u).max()
        times.setdefault("u difference", []).append(float(np.abs(u_local - ref.u).max() / scale))
        times.setdefault("recomputed cells", []).append(len(change.changed_cells))
        model, prob = change.model, new
        del fresh, ref, sol
    times["nodes"] = len(model.nodes)
    times["cells"] = len(model.cells)
    return times


def report(n, t):
    print(f"\n{fmt_n(n)} nodes requested: {t['nodes']} nodes, {t['cells']} cells; "
          f"recomputed cells per increment {t['recomputed cells']}; "
          f"max |u_local - u_full| / max |u| = {max(t['u difference']):.2e}")
    print(f"{'median seconds':<16}{'local':>10}{'full':>10}{'full/local':>12}")
    for stage in ("model", "B~ + K", "solve", "increment"):
        a, b = median(t["local"][stage]), median(t["full"][stage])
        print(f"{stage:<16}{a:>10.3f}{b:>10.3f}{b / a:>12.2f}")
    solve = median(t["local"]["solve"])
    for path in ("local", "full"):
        ratio = median(t[path]["increment"]) / solve
        print(f"{path} increment / solve alone: {ratio:.2f}"
              + ("  (target <= 1.5: met)" if path == "local" and ratio <= 1.5 else
                 "  (target <= 1.5: MISSED)" if path == "local" else ""))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[10_000, 100_000])
    parser.add_argument("--steps", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="~3k nodes, 2 increments")
    args = parser.parse_args()
    sizes, steps = ([3_000], 2) if args.quick else (args.sizes, args.steps)
    import cnem
    cnem.discretize(cnem.nodes.irregular(domain(np.array([[0.0, 1.0], [0.3, 1.0]])), 0.1))
    machine = MachineLoad()
    print(f"load average before {load_text(machine.before.load)}")
    for n in sizes:
        report(n, run_size(n, steps))
    print("\n" + machine.stop().report())


if __name__ == "__main__":
    main()
