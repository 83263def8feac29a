"""Benchmark: ``cnem.discretize`` of a domain with a finely outlined hole against one whose
outer boundary is outlined as finely (issue 36 item 8).

What is measured
----------------
Two domains, each outlined by a circle of ``--vertices`` vertices (default 5000), nodes
``cnem.nodes.regular(dom, h)`` (default h = 0.05)::

    hole:  dom = cnem.Domain((square [-1, 1]^2, [circle of radius 0.3]))
    outer: dom = cnem.Domain(circle of radius 1)

Every vertex of the hole is a reflex corner of the domain; they all went to the exact
(shapely) path of the cells (~8 ms a cell), the outer circle's to the fast path. The
wall and CPU times of ``cnem.discretize(cloud, progress=False)`` and its ``cells`` stage
are the medians of ``--repeat`` runs (default 3) in one fresh child process, after a
warm-up that compiles or loads the numba kernels; the cell areas are checked against
the domain's area. The machine may be shared: the load average is printed, and the CPU
time (``time.process_time``) moves less with it than the wall time.

Target: the hole case within 3x of the outer-boundary case. Timings are printed, never
asserted.

How to run
----------
::

    python benchmarks/holes.py                      # 5000 vertices, h = 0.05
    python benchmarks/holes.py --vertices 1000 --repeat 5
"""
import argparse
import os
import sys
import time

import numpy as np

from _harness import MachineLoad, in_child, load_text, median, print_targets, warm_both

TARGET_RATIO = 3.0


def _domain(case, vertices):
    import cnem
    t = np.linspace(0.0, 2.0 * np.pi, vertices, endpoint=False)
    circle = np.column_stack([np.cos(t), np.sin(t)])
    if case == "hole":
        square = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]
        return cnem.Domain((square, [0.3 * circle]))
    return cnem.Domain(circle)


def _child(case, vertices, h, repeat):
    """Warm up, then time ``discretize`` ``repeat`` times; medians and the area check."""
    import cnem
    dom = _domain(case, vertices)
    tiny = cnem.nodes.regular(_domain(case, 64), 0.2)
    warm_both(lambda: cnem.discretize(tiny, progress=False))
    cloud = cnem.nodes.regular(dom, h)
    wall, cpu, cells = [], [], []
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        model = cnem.discretize(cloud, progress=False)
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
        cells.append(model.timings["cells"])
    return dict(nodes=len(cloud.points), wall=median(wall), cpu=median(cpu), cells=median(cells),
                area=abs(float(model.cells.area.sum()) / dom.area - 1.0))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--vertices", type=int, default=5000, help="vertices of the circle")
    parser.add_argument("--h", type=float, default=0.05, help="node spacing")
    parser.add_argument("--repeat", type=int, default=3, help="timed runs per case")
    args = parser.parse_args(argv)
    machine = MachineLoad()
    print(f"benchmarks/holes.py: {args.vertices} vertices, h = {args.h}, python "
          f"{sys.version.split()[0]}, {os.cpu_count()} CPUs; load average "
          f"{load_text(machine.before.load)}")
    results = {}
    for case in ("hole", "outer"):
        results[case] = in_child(_child, case, args.vertices, args.h, args.repeat)
        if "error" in results[case]:
            raise RuntimeError(results[case]["error"])
    head = f"{'case':>6} {'nodes':>7} | {'wall':>7} {'cpu':>7} {'cells':>7} | {'area error':>10}"
    print(f"\nmedians of {args.repeat} runs (s)\n\n{head}\n{'-' * len(head)}")
    for case, r in results.items():
        print(f"{case:>6} {r['nodes']:>7d} | {r['wall']:7.3f} {r['cpu']:7.3f} {r['cells']:7.3f} | "
              f"{r['area']:10.1e}")
    wall = results["hole"]["wall"] / results["outer"]["wall"]
    cpu = results["hole"]["cpu"] / results["outer"]["cpu"]
    print()
    print_targets([(f"hole within {TARGET_RATIO:g}x of the outer boundary",
                    f"ratio {wall:.1f} (CPU {cpu:.1f})", wall <= TARGET_RATIO)], "targets:")
    print("\n" + machine.stop().report())
    return results


if __name__ == "__main__":
    main()
