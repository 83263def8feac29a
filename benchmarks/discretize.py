"""Benchmark: ``cnem.discretize`` against bare ``triangle`` and against scipy Voronoi + shapely.

What is measured
----------------
Two geometries, each at every size n (default 100k and 1M nodes)::

    square:  dom = cnem.geometry.rectangle(1.0, 1.0)
    cracked: dom = cnem.geometry.rectangle(1.0, 1.0, cracks=[[[0.0, 0.5], [0.5, 0.5]]])
    cloud = cnem.nodes.irregular(dom, h=1 / sqrt(n), seed=0)

**cnem** — wall time of ``cnem.discretize(cloud, progress=False)``: constrained Delaunay
triangulation, crack opening by node duplication and the constrained Voronoi integration
cells.  The stage times are those the model reports in ``model.timings``
(``triangulation``, ``splitting``, ``cells``); ``total`` is the wall time around the call,
``cpu`` its CPU time (``time.process_time``: every thread of the process).

**triangle** (anchor 1, issue 22 item 2) — ``triangle.triangulate`` on the same points and
the same constraint segments (``cloud.points``, ``cloud.segments``: the square's boundary,
or the cracked plate's boundary and crack) with the switches ``discretize`` uses
(``"pQ"``), timed in the same child process, each repetition just before the
``discretize`` one.  ``ratio`` = discretize / triangle (wall; ``cpu ratio`` of the CPU
times).  Target: at most 3x at 1M nodes.

**voronoi** (anchor 2, cracked plate only) — on the same points ``cloud.points``:

* ``voronoi``: ``scipy.spatial.Voronoi(points)`` with four far-away dummy points appended so
  that every real region is bounded (the standard trick);
* ``clip``: the regions' polygons built in one vectorised call
  (``shapely.linearrings`` with a ring index, then ``shapely.polygons``) and clipped to the
  unit square with ``shapely.clip_by_rect`` (vectorised). The flattening of scipy's
  list-of-lists ``regions`` into a CSR index array is counted here too.

This baseline is *less* work than cnem: it neither respects the crack (its cells straddle
the crack faces) nor produces a triangulation, so the ratio cnem/baseline is conservative.
Both sides are checked to tile the square (sum of cell areas = 1).

Each size runs in fresh child processes (``multiprocessing`` with the ``spawn`` start
method): one for cnem and triangle, one for the Voronoi baseline, so that peak memory (the
child's own high-water RSS, i.e. the whole process: interpreter, imports, node cloud and
the timed runs) of one size does not pollute another.  In the cnem child numba is warmed
up by one tiny ``discretize`` (twice: the serial and the parallel copies of the kernels,
``_harness.warm_both``) and ``triangle`` by one tiny call before anything is timed, so JIT
compile time is excluded.  Each timing is repeated ``--repeat`` times (default 3) and the
median is reported.  The load average is printed before and after each size and at the
end: the machine may be shared, and wall times move with it (the ratios are from one run).

Targets: ``discretize`` within 3x of bare ``triangle`` at 1M nodes (both geometries) and
within 3x of the Voronoi baseline at 100k nodes; 1M nodes in under 60 s with peak memory
under 4 GB.  Timings are printed, never asserted.

How to run
----------
::

    python benchmarks/discretize.py              # 100k and 1M, both geometries (~5 minutes)
    python benchmarks/discretize.py --quick      # ~5k nodes, CI smoke run (seconds)
    python benchmarks/discretize.py --sizes 20000 200000 --repeat 5 --geometries cracked
"""
import argparse
import os
import statistics
import sys
import tempfile
import time

import numpy as np

from _harness import (MachineLoad, fmt_n, in_child, load_text, peak_rss_bytes,
                      print_targets, warm_both)

CRACK = [[[0.0, 0.5], [0.5, 0.5]]]
GEOMETRIES = {"square": None, "cracked": CRACK}
SWITCHES = "pQ"          # those of cnem.geometry.triangulation.constrained_delaunay
TARGET_TRIANGLE_AT = 1_000_000
TARGET_RATIO_AT = 100_000
TARGET_RATIO = 3.0
TARGET_1M_SECONDS = 60.0
TARGET_1M_MEMORY_GB = 4.0


# --------------------------------------------------------------------------- children


def _domain(geometry):
    import cnem
    cracks = GEOMETRIES[geometry]
    return cnem.geometry.rectangle(1.0, 1.0, cracks=cracks) if cracks else cnem.geometry.rectangle(1.0, 1.0)


def _triangle(cloud):
    """Bare ``triangle`` on the cloud's points and segments; (wall, cpu, triangle count)."""
    import triangle

    t0, c0 = time.perf_counter(), time.process_time()
    out = triangle.triangulate({"vertices": np.ascontiguousarray(cloud.points, dtype=float),
                                "segments": np.ascontiguousarray(cloud.segments, dtype=np.int32)},
                               SWITCHES)
    return time.perf_counter() - t0, time.process_time() - c0, len(out["triangles"])


def _cnem_child(geometry, n, repeat, points_file):
    """Build the cloud, warm numba and triangle up, time ``triangle`` then ``discretize``
    ``repeat`` times; save the points for the Voronoi baseline."""
    import cnem

    dom = _domain(geometry)
    # warm-up: compile (or load from cache) every numba kernel on a tiny problem
    t0 = time.perf_counter()
    tiny = cnem.nodes.irregular(dom, h=0.05, seed=0)
    warm_both(lambda: cnem.discretize(tiny, progress=False))
    _triangle(tiny)
    warmup = time.perf_counter() - t0

    cloud = cnem.nodes.irregular(dom, h=1.0 / np.sqrt(n), seed=0)
    np.save(points_file, cloud.points)
    rss_before = peak_rss_bytes()

    runs = []
    for _ in range(repeat):
        tri_wall, tri_cpu, n_tri = _triangle(cloud)
        t0, c0 = time.perf_counter(), time.process_time()
        model = cnem.discretize(cloud, progress=False)
        total, cpu = time.perf_counter() - t0, time.process_time() - c0
        runs.append(dict(model.timings, total=total, cpu=cpu, triangle=tri_wall,
                         triangle_cpu=tri_cpu))
        area = float(model.cells.area.sum())
        n_nodes, n_cells, n_model_tri = len(model.nodes), len(model.cells), len(model.triangles)
        del model
    return dict(points=len(cloud.points), segments=len(cloud.segments), nodes=n_nodes,
                cells=n_cells, triangles=n_model_tri, triangle_triangles=n_tri, area=area,
                warmup=warmup, runs=runs, rss_before=rss_before, rss=peak_rss_bytes())


def _voronoi_clip(points):
    """scipy Voronoi + shapely clip of every region to the unit square; returns (polys, t_vor, t_clip)."""
    import shapely
    from scipy.spatial import Voronoi

    t0 = time.perf_counter()
    lo, hi = points.min(axis=0), points.max(axis=0)
    c, r = 0.5 * (lo + hi), 10.0 * float(np.max(hi - lo))
    far = c + r * np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
    vor = Voronoi(np.concatenate([points, far]))
    t1 = time.perf_counter()

    regions = vor.regions
    region_of = vor.point_region[: len(points)]
    lengths = np.fromiter((len(regions[k]) for k in region_of), dtype=np.int64,
                          count=len(region_of))
    flat = np.fromiter((v for k in region_of for v in regions[k]), dtype=np.int64,
                       count=int(lengths.sum()))
    if np.any(flat < 0):
        raise RuntimeError("an unbounded Voronoi region survived the far dummy points")
    rings = shapely.linearrings(vor.vertices[flat],
                                indices=np.repeat(np.arange(len(lengths)), lengths))
    polys = shapely.clip_by_rect(shapely.polygons(rings), 0.0, 0.0, 1.0, 1.0)
    t2 = time.perf_counter()
    return polys, t1 - t0, t2 - t1


def _baseline_child(points_file, repeat):
    """Time scipy Voronoi + shapely clipping on the saved points."""
    import shapely

    points = np.load(points_file)
    rss_before = peak_rss_bytes()
    runs = []
    for _ in range(repeat):
        polys, t_vor, t_clip = _voronoi_clip(points)
        runs.append(dict(voronoi=t_vor, clip=t_clip, total=t_vor + t_clip))
        area = float(shapely.area(polys).sum())
        del polys
    return dict(area=area, runs=runs, rss_before=rss_before, rss=peak_rss_bytes())


def _measured(fn, *args):
    """``fn(*args)`` in a fresh child process (`_harness.in_child`); its error stops the run."""
    out = in_child(fn, *args)
    if "error" in out:
        raise RuntimeError(out["error"])
    return out


# --------------------------------------------------------------------------- driver


def _median(runs, key):
    return statistics.median(r[key] for r in runs)


def run(geometries, sizes, repeat=3):
    """Benchmark every geometry and size; returns a list of per-case result dicts."""
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        for geometry in geometries:
            for n in sizes:
                points_file = os.path.join(tmp, f"points_{geometry}_{n}.npy")
                load_before = load_text()
                print(f"  {geometry} n = {fmt_n(n)}: triangle + cnem x{repeat} ...", end="",
                      flush=True)
                cn = _measured(_cnem_child, geometry, n, repeat, points_file)
                bl = None
                if GEOMETRIES[geometry] is not None:
                    print(f" voronoi baseline x{repeat} ...", end="", flush=True)
                    bl = _measured(_baseline_child, points_file, repeat)
                print(" done", flush=True)
                results.append(dict(geometry=geometry, n=n, repeat=repeat, cnem=cn, baseline=bl,
                                    load_before=load_before, load_after=load_text()))
    return results


def _ratios(r):
    """discretize / triangle of the medians: (wall, cpu)."""
    runs = r["cnem"]["runs"]
    return (_median(runs, "total") / _median(runs, "triangle"),
            _median(runs, "cpu") / _median(runs, "triangle_cpu"))


def _table_head(head, *title):
    """Print a blank line, the title lines, a blank line, the column heads and a rule."""
    print()
    print("\n".join(title))
    print()
    print(head)
    print("-" * len(head))


def _report_triangle(results):
    head = (f"{'geometry':>8} {'n':>5} {'points':>8} {'rep':>3} | {'triangle':>8} {'cpu':>6} | "
            f"{'triang':>6} {'split':>6} {'cells':>6} {'total':>6} {'cpu':>6} | "
            f"{'ratio':>5} {'cpu ratio':>9} | {'MB':>5}")
    _table_head(head, "cnem.discretize vs bare triangle.triangulate(points, segments, 'pQ') in "
                      "the same process (median times in s)")
    for r in results:
        cn = r["cnem"]
        runs = cn["runs"]
        wall, cpu = _ratios(r)
        print(f"{r['geometry']:>8} {fmt_n(r['n']):>5} {cn['points']:>8d} {r['repeat']:>3d} | "
              f"{_median(runs, 'triangle'):8.3f} {_median(runs, 'triangle_cpu'):6.3f} | "
              f"{_median(runs, 'triangulation'):6.3f} {_median(runs, 'splitting'):6.3f} "
              f"{_median(runs, 'cells'):6.3f} {_median(runs, 'total'):6.3f} "
              f"{_median(runs, 'cpu'):6.3f} | {wall:5.2f} {cpu:9.2f} | {cn['rss'] / 2**20:5.0f}")
    print()
    print("columns: triangle = bare triangle wall time, cpu = its CPU time; triang/split/cells =")
    print("         model.timings stages (triang includes the triangle call); total = wall time")
    print("         of discretize, cpu = its CPU time (all threads); ratio = total / triangle,")
    print("         cpu ratio = cpu / triangle cpu; MB = peak RSS of the child")


def _report_voronoi(results):
    rows = [r for r in results if r["baseline"] is not None]
    if not rows:
        return
    head = (f"{'n':>6} {'points':>9} {'rep':>3} | {'triang':>7} {'split':>7} {'cells':>7} "
            f"{'cnem':>7} | {'voronoi':>7} {'clip':>7} {'base':>7} | {'ratio':>5} | "
            f"{'cnem MB':>8} {'base MB':>8}")
    _table_head(head, "cnem.discretize vs scipy.spatial.Voronoi + shapely.clip_by_rect "
                      "(cracked unit square, median wall times in s)",
                "numba warmed up by one tiny discretize in each cnem child before timing "
                "(compile time excluded)",
                "peak memory = high-water RSS of a fresh child per size and side "
                "(interpreter + imports + cloud + timed runs)")
    for r in rows:
        cn, bl = r["cnem"], r["baseline"]
        c_tot, b_tot = _median(cn["runs"], "total"), _median(bl["runs"], "total")
        print(f"{fmt_n(r['n']):>6} {cn['points']:>9d} {r['repeat']:>3d} | "
              f"{_median(cn['runs'], 'triangulation'):7.3f} "
              f"{_median(cn['runs'], 'splitting'):7.3f} {_median(cn['runs'], 'cells'):7.3f} "
              f"{c_tot:7.3f} | {_median(bl['runs'], 'voronoi'):7.3f} "
              f"{_median(bl['runs'], 'clip'):7.3f} {b_tot:7.3f} | {c_tot / b_tot:5.2f} | "
              f"{cn['rss'] / 2**20:8.0f} {bl['rss'] / 2**20:8.0f}")
    print()
    print("columns: triang/split/cells = model.timings stages; cnem = wall time of discretize;")
    print("         voronoi = scipy Voronoi (+4 far dummy points); clip = polygons + clip_by_rect;")
    print("         base = voronoi + clip; ratio = cnem / base")


def report(results):
    _report_triangle(results)
    _report_voronoi(results)
    print()
    print("checks:")
    for r in results:
        cn, bl = r["cnem"], r["baseline"]
        base = "" if bl is None else f"; voronoi baseline area {bl['area']:.12f}"
        print(f"  {r['geometry']:>8} {fmt_n(r['n']):>5}: cnem {cn['nodes']} nodes (cracks "
              f"opened), {cn['cells']} cells, {cn['triangles']} triangles (triangle: "
              f"{cn['triangle_triangles']}), area {cn['area']:.12f}{base}; numba warm-up "
              f"{cn['warmup']:.2f} s; RSS before timed runs {cn['rss_before'] / 2**20:.0f} MB")
        print(f"  {'':>14} load average before {r['load_before']}, after {r['load_after']}")
    print()
    rows = []
    for geometry in dict.fromkeys(r["geometry"] for r in results):
        at = [r for r in results if r["geometry"] == geometry and r["n"] == TARGET_TRIANGLE_AT]
        label = (f"{geometry}: discretize within {TARGET_RATIO:g}x of bare triangle at "
                 f"{fmt_n(TARGET_TRIANGLE_AT)}")
        if at:
            wall, cpu = _ratios(at[0])
            rows.append((label, f"ratio {wall:.2f} (CPU {cpu:.2f})", wall <= TARGET_RATIO))
        else:
            rows.append((label, "(not run)", None))
    by_n = {r["n"]: r for r in results if r["baseline"] is not None}
    label = f"discretize within {TARGET_RATIO:g}x of the Voronoi baseline at 100k"
    if TARGET_RATIO_AT in by_n:
        r = by_n[TARGET_RATIO_AT]
        ratio = _median(r["cnem"]["runs"], "total") / _median(r["baseline"]["runs"], "total")
        rows.append((label, f"ratio {ratio:.2f}", ratio <= TARGET_RATIO))
    else:
        rows.append((label, "(cracked 100k not run)", None))
    big = [r for r in results if r["n"] == 1_000_000]
    for r in big:
        cn = r["cnem"]
        t, gb = _median(cn["runs"], "total"), cn["rss"] / 2**30
        rows.append((f"{r['geometry']}: 1M nodes under {TARGET_1M_SECONDS:g} s", f"{t:.1f} s",
                     t < TARGET_1M_SECONDS))
        rows.append((f"{r['geometry']}: 1M nodes peak memory under {TARGET_1M_MEMORY_GB:g} GB",
                     f"{gb:.2f} GB", gb < TARGET_1M_MEMORY_GB))
    if not big:
        rows.append((f"1M nodes under {TARGET_1M_SECONDS:g} s, peak memory under "
                     f"{TARGET_1M_MEMORY_GB:g} GB", "(1M not run)", None))
    print_targets(rows, "targets:")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true",
                        help="CI smoke run: only ~5k nodes")
    parser.add_argument("--sizes", type=int, nargs="+", metavar="N",
                        help="node counts to run (default 100000 1000000)")
    parser.add_argument("--geometries", nargs="+", choices=list(GEOMETRIES),
                        default=list(GEOMETRIES), help="default: square cracked")
    parser.add_argument("--repeat", type=int, default=3,
                        help="timed repetitions per case (default 3)")
    args = parser.parse_args(argv)
    if args.sizes:
        sizes = args.sizes
    elif args.quick:
        sizes = [5_000]
    else:
        sizes = [100_000, 1_000_000]
    machine = MachineLoad()
    print(f"benchmarks/discretize.py: geometries {args.geometries}, sizes {sizes}, python "
          f"{sys.version.split()[0]}, {os.cpu_count()} CPUs; load average "
          f"{load_text(machine.before.load)}")
    results = run(args.geometries, sizes, args.repeat)
    report(results)
    print("\n" + machine.stop().report())
    return results


if __name__ == "__main__":
    main()
