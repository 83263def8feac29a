"""Benchmark: ``cnem.discretize`` against scipy Voronoi + shapely clipping.

What is measured
----------------
For each size n (default 10k, 100k and 1M nodes) the domain is a cracked unit square::

    dom = cnem.geometry.rectangle(1.0, 1.0, cracks=[[[0.0, 0.5], [0.5, 0.5]]])
    cloud = cnem.nodes.irregular(dom, h=1 / sqrt(n), seed=0)

**cnem** — wall time of ``cnem.discretize(cloud, progress=False)``: constrained Delaunay
triangulation, crack opening by node duplication and the constrained Voronoi integration
cells.  The stage times are those the model reports in ``model.timings``
(``triangulation``, ``splitting``, ``cells``); ``total`` is the wall time around the call.

**baseline** (the anchor) — on the same points ``cloud.points``:

* ``voronoi``: ``scipy.spatial.Voronoi(points)`` with four far-away dummy points appended so
  that every real region is bounded (the standard trick);
* ``clip``: the regions' polygons built in one vectorised call
  (``shapely.linearrings`` with a ring index, then ``shapely.polygons``) and clipped to the
  unit square with ``shapely.clip_by_rect`` (vectorised). The flattening of scipy's
  list-of-lists ``regions`` into a CSR index array is counted here too.

The baseline is *less* work than cnem: it neither respects the crack (its cells straddle the
crack faces) nor produces a triangulation, so the ratio cnem/baseline is conservative.
Both sides are checked to tile the square (sum of cell areas = 1).

Each size runs in two fresh child processes (``multiprocessing`` with the ``spawn`` start
method): one for cnem, one for the baseline, so that peak memory (the child's own
``ru_maxrss``, i.e. the whole process: interpreter, imports, node cloud and the timed runs)
of one size does not pollute another.  In the cnem child numba is warmed up by one tiny
``discretize`` (twice: the serial and the parallel copies of the kernels,
``_harness.warm_both``) before anything is timed, so JIT compile time is excluded.  Each timing is
repeated ``--repeat`` times (default 3 for n <= 100k, 1 above) and the median is reported.

Targets: ``discretize`` within 3x of the baseline at 100k nodes; 1M nodes in under 60 s
with peak memory under 4 GB.  Timings are printed, never asserted.

How to run
----------
::

    python benchmarks/discretize.py              # 10k, 100k, 1M  (about 5 minutes)
    python benchmarks/discretize.py --quick      # ~5k nodes, CI smoke run (seconds)
    python benchmarks/discretize.py --sizes 20000 200000 --repeat 5
"""
import argparse
import multiprocessing as mp
import os
import statistics
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from _harness import fmt_n, peak_rss_bytes, warm_both

CRACK = [[[0.0, 0.5], [0.5, 0.5]]]
TARGET_RATIO_AT = 100_000
TARGET_RATIO = 3.0
TARGET_1M_SECONDS = 60.0
TARGET_1M_MEMORY_GB = 4.0


# --------------------------------------------------------------------------- children


def _cnem_child(n, repeat, points_file):
    """Build the cloud, warm numba up, time ``discretize``; save the points for the baseline."""
    import cnem

    dom = cnem.geometry.rectangle(1.0, 1.0, cracks=CRACK)
    # warm-up: compile (or load from cache) every numba kernel on a tiny problem
    t0 = time.perf_counter()
    warm_both(lambda: cnem.discretize(cnem.nodes.irregular(dom, h=0.05, seed=0), progress=False))
    warmup = time.perf_counter() - t0

    cloud = cnem.nodes.irregular(dom, h=1.0 / np.sqrt(n), seed=0)
    np.save(points_file, cloud.points)
    rss_before = peak_rss_bytes()

    runs = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        model = cnem.discretize(cloud, progress=False)
        total = time.perf_counter() - t0
        runs.append(dict(model.timings, total=total))
        area = float(model.cells.area.sum())
        n_nodes, n_cells = len(model.nodes), len(model.cells)
        del model
    return dict(points=len(cloud.points), nodes=n_nodes, cells=n_cells, area=area,
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


def _in_child(fn, *args):
    """Run ``fn(*args)`` in a fresh spawned interpreter and return its result."""
    with ProcessPoolExecutor(max_workers=1, mp_context=mp.get_context("spawn")) as ex:
        return ex.submit(fn, *args).result()


# --------------------------------------------------------------------------- driver


def _median(runs, key):
    return statistics.median(r[key] for r in runs)


def run(sizes, repeat=None):
    """Benchmark every size; returns a list of per-size result dicts."""
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        for n in sizes:
            rep = repeat if repeat is not None else (3 if n <= 100_000 else 1)
            points_file = os.path.join(tmp, f"points_{n}.npy")
            print(f"  n = {fmt_n(n)}: cnem x{rep} ...", end="", flush=True)
            cn = _in_child(_cnem_child, n, rep, points_file)
            print(f" baseline x{rep} ...", end="", flush=True)
            bl = _in_child(_baseline_child, points_file, rep)
            print(" done", flush=True)
            results.append(dict(n=n, repeat=rep, cnem=cn, baseline=bl))
    return results


def report(results):
    head = (f"{'n':>6} {'points':>9} {'rep':>3} | {'triang':>7} {'split':>7} {'cells':>7} "
            f"{'cnem':>7} | {'voronoi':>7} {'clip':>7} {'base':>7} | {'ratio':>5} | "
            f"{'cnem MB':>8} {'base MB':>8}")
    print()
    print("cnem.discretize vs scipy.spatial.Voronoi + shapely.clip_by_rect "
          "(cracked unit square, median wall times in s)")
    print("numba warmed up by one tiny discretize in each cnem child before timing "
          "(compile time excluded)")
    print("peak memory = ru_maxrss of a fresh child per size and side "
          "(interpreter + imports + cloud + timed runs)")
    print()
    print(head)
    print("-" * len(head))
    for r in results:
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
    print()
    print("checks:")
    for r in results:
        cn, bl = r["cnem"], r["baseline"]
        print(f"  {fmt_n(r['n']):>6}: cnem {cn['nodes']} nodes (crack opened), {cn['cells']} cells, "
              f"area {cn['area']:.12f}; baseline area {bl['area']:.12f}; "
              f"numba warm-up {cn['warmup']:.2f} s; RSS before timed runs "
              f"cnem {cn['rss_before'] / 2**20:.0f} MB, baseline {bl['rss_before'] / 2**20:.0f} MB")
    print()
    print("targets:")
    by_n = {r["n"]: r for r in results}
    if TARGET_RATIO_AT in by_n:
        r = by_n[TARGET_RATIO_AT]
        ratio = _median(r["cnem"]["runs"], "total") / _median(r["baseline"]["runs"], "total")
        print(f"  discretize within {TARGET_RATIO:g}x of baseline at 100k: ratio {ratio:.2f} "
              f"-> {'MET' if ratio <= TARGET_RATIO else 'MISSED'}")
    else:
        print(f"  discretize within {TARGET_RATIO:g}x of baseline at 100k: (100k not run)")
    if 1_000_000 in by_n:
        cn = by_n[1_000_000]["cnem"]
        t, gb = _median(cn["runs"], "total"), cn["rss"] / 2**30
        print(f"  1M nodes under {TARGET_1M_SECONDS:g} s: {t:.1f} s "
              f"-> {'MET' if t < TARGET_1M_SECONDS else 'MISSED'}")
        print(f"  1M nodes peak memory under {TARGET_1M_MEMORY_GB:g} GB: {gb:.2f} GB "
              f"-> {'MET' if gb < TARGET_1M_MEMORY_GB else 'MISSED'}")
    else:
        print(f"  1M nodes under {TARGET_1M_SECONDS:g} s, peak memory under "
              f"{TARGET_1M_MEMORY_GB:g} GB: (1M not run)")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true",
                        help="CI smoke run: only ~5k nodes")
    parser.add_argument("--sizes", type=int, nargs="+", metavar="N",
                        help="node counts to run (default 10000 100000 1000000)")
    parser.add_argument("--repeat", type=int, default=None,
                        help="timed repetitions per size (default 3 for n <= 100k, 1 above)")
    args = parser.parse_args(argv)
    if args.sizes:
        sizes = args.sizes
    elif args.quick:
        sizes = [5_000]
    else:
        sizes = [10_000, 100_000, 1_000_000]
    print(f"benchmarks/discretize.py: sizes {sizes}, python {sys.version.split()[0]}, "
          f"{os.cpu_count()} CPUs")
    results = run(sizes, args.repeat)
    report(results)
    return results


if __name__ == "__main__":
    main()
