"""Benchmark: ``cnem.spatial.family_search`` against scipy's ``cKDTree`` (peridynamic families).

Workload
--------
The family-search paper's workload (section 2, Tables 1-3): a 3-D cubic lattice
``{0, 1, ..., m-1}^3`` with spacing 1 and horizon ``3.0001``.  With the strict
``0 < |x_j - x_i| < horizon`` every interior point has 122 family members (the lattice
vectors with squared length 1..9); the open lattice's total bond count is known in closed
form and is checked.  Sizes N = m^3: 27k (30^3), 125k (50^3), 343k (70^3) and 1M (100^3) by
default, plus 8M (200^3) with ``--big``.

What is measured
----------------
Every measurement runs in its own fresh child process (``multiprocessing`` with the
``spawn`` start method), which builds the cloud itself, so that peak memory is that of the
one measurement.  Peak memory is the child's high-water resident set size: ``VmHWM`` from
``/proc/self/status`` on Linux (``ru_maxrss`` elsewhere).  ``ru_maxrss`` itself is not used
on Linux because the kernel carries the parent's peak over into a spawned child (``exec``
keeps the high-water mark), which would add the driver's own peak to every child.  The
figure is the whole process: interpreter, imports, the cloud and the timed runs.

**ours** -- in a child that first warms numba up with a few calls on tiny clouds, for the
serial and the parallel copies of the kernels (``_harness.warm_both``; compile time
excluded; the warm-up time is printed):

* ``cells``: ``family_search(points, 3.0001, method="cells")`` (what ``method="auto"``
  picks for this uniform workload);
* ``rtree``: ``RTree.from_points(points)`` timed on its own (``rt build``), and
  ``family_search(points, 3.0001, method="rtree")`` (``rt total``: build + query + CSR).

**scipy** -- in children that do not import cnem (no numba):

* ``kd pairs+CSR``: ``cKDTree(points)`` + ``query_pairs(3.0001, output_type="ndarray")``
  + conversion to a CSR of both directions with rows in order: the ``(i, j)`` and ``(j, i)``
  halves copied into int32 ``rows``/``cols`` and handed to scipy.sparse's COO -> CSR, which is
  a counting sort in C++ (O(bonds + N)).  The pairs are unique, so the COO's
  canonical-format flag is set to skip scipy's duplicate summation (which would also sort
  every row); columns within a row are therefore in query order.  This was the fastest of
  the numpy/scipy conversions tried (``np.argsort`` on the rows, ``np.sort`` of
  ``i * N + j`` keys, COO -> CSR with and without duplicate summation).
* ``kd ball``: ``cKDTree(points)`` + ``query_ball_point(points, 3.0001, workers=-1,
  return_sorted=False)``, the list-of-lists result (each list includes the point itself).
  Its Python int objects cost ~40 bytes per bond (the issue's anchor: 6.7 GB at 1M), so it
  is skipped above 1M points unless ``--big`` is given.

Each timing is repeated ``--repeat`` times (default 3, 1 for N >= 1M) and the median is
reported.  ``ratio`` = fastest scipy route / cells (how many times faster cells is).  A
measurement whose estimated memory exceeds 80 % of ``MemAvailable`` (or ``--mem-limit-gb``)
is skipped and says so rather than invite the out-of-memory killer.

Checks (printed): cells, rtree and the kdtree CSR give the same number of bonds at every
size (the ball route too, less the N self entries), equal to the closed-form count, and the
same bond sets -- exactly on the smallest size (the saved CSRs compared as sorted
``i * N + j`` keys, the ball lists included), by an order-independent 64-bit hash of the
bonds on every size.

Extra cases, each printed as its own small table:

(a) **graded cloud** (``--graded-n``, default 300k; 4k with ``--quick``): random points in
    the unit cube with density ``1 / h(x)^3`` where the local spacing
    ``h(x) = h0 * clip(|x - c| / r0, 1, 30)`` grows 30x from the cube's centre ``c`` to its
    corners (a refinement around a crack tip or an impact point: equal numbers of points per
    octave of distance), with the per-point horizon ``3.0001 * h(x_i)`` passed as an (n,)
    array.  ``family_search`` with ``method="cells"`` (cells sized for the largest horizon),
    ``"rtree"`` and ``"kdtree"`` (``query_pairs`` at the largest horizon, then exact
    filtering).  The kdtree method's candidate pairs are first estimated from a sample of
    ``query_ball_point(..., return_length=True)``; when they would not fit in memory the
    measurement is skipped and the estimate printed.
(b) **periodic vs open** on the same lattice (N = 125k and 1M by default; points
    ``0..m-1`` along each axis, ``period = m``, so every point has exactly 122 members) for
    cells and rtree; ``ratio`` = periodic / open (target <= 1.3x).

Targets (from the issues; timings are printed, never asserted): ``family_search`` on 1M
points <= 0.5 s median with peak memory <= 1.5 GB, and >= 10x faster than the fastest scipy
route in the same run (issue 22: per-core parity with compiled peers); ``RTree.from_points`` on 1M points <= 0.3 s; periodic / open <= 1.3x.
The load average is printed before and after the run (other processes on the machine slow
every measurement, the two-thread ones most). The issue's anchor figures at 1M (this machine class, this workload) are printed for
orientation next to ours.

How to run
----------
::

    python benchmarks/family_search.py                 # 27k, 125k, 343k, 1M + extras (~10 min)
    python benchmarks/family_search.py --big           # ... and 8M (rtree needs ~18 GB)
    python benchmarks/family_search.py --quick         # N = 8000 only, CI smoke run (seconds)
    python benchmarks/family_search.py --sizes 27000 125000 --repeat 5
    python benchmarks/family_search.py --no-graded --no-periodic
    python benchmarks/family_search.py --graded-n 100000 --periodic-sizes 125000

With ``--sizes`` the periodic case runs at those of its default sizes not above the largest
requested size (or at the largest requested size if none is).  Non-cubic sizes are rounded
to the nearest cube.
"""
import argparse
import os
import sys
import tempfile
import time

import numpy as np

from _harness import (MachineLoad, fmt_n, in_child, load_text, median, mem_available_bytes,
                      memory_limit, memory_skip, peak_rss_bytes, print_targets, warm_both)

HORIZON = 3.0001
DEFAULT_SIZES = [27_000, 125_000, 343_000, 1_000_000]
BIG_SIZE = 8_000_000
QUICK_SIZE = 8_000
BALL_MAX_N = 1_000_000              # query_ball_point above this only with --big
GRADED_N, GRADED_QUICK_N, GRADED_RATIO, GRADED_SAMPLE = 300_000, 4_000, 30.0, 1000
PERIODIC_SIZES = [125_000, 1_000_000]
SET_CHECK_MAX_BONDS = 20_000_000    # exact set comparison in the driver up to this many bonds

TARGET_N = 1_000_000
TARGET_SECONDS = 0.5
TARGET_MEMORY_GB = 1.5
TARGET_SPEEDUP = 10.0
TARGET_BUILD_SECONDS = 0.3
TARGET_PERIODIC_RATIO = 1.3

# memory model for skipping what cannot fit (bytes; measured at 8k-125k, rounded up)
BASE_BYTES = 400e6                  # interpreter + imports + slack
BYTES_PER_POINT = 120.0             # the cloud and per-point work arrays
BYTES_PER_BOND = {
    "cells": 6.0,                   # int32 indices (4 B/bond)
    "rtree": 19.0,                  # int64 query output + its int32 copy
    "kd pairs": 21.0,               # pairs (8 B/bond) + int32 rows/cols (8) + CSR (5)
    "kd ball": 56.0,                # Python ints (32 B) + list slots (8) + list headers
}
KD_METHOD_BYTES_PER_PAIR = 72.0     # cnem's kdtree method: pairs + int64 both directions + mask


def estimated_bytes(method, n, bonds):
    """Rough peak memory of one lattice measurement."""
    return BASE_BYTES + BYTES_PER_POINT * n + BYTES_PER_BOND[method] * bonds


ANCHORS_1M = [  # (anchor, seconds, GB or None, our result, its times, our label)
    ("Boost packed R-tree build", 0.16, None, "rtree", "builds", "RTree.from_points"),
    ("Boost packed R-tree search", 7.8, None, "rtree", "runs", "family_search rtree"),
    ("C++ cell list", 2.0, None, "cells", "runs", "family_search cells"),
    ("cKDTree query_pairs + CSR", 4.9, None, "kd pairs", "runs", "kd pairs+CSR"),
    ("cKDTree query_ball_point", 27.0, 6.7, "kd ball", "runs", "kd ball"),
]


# --------------------------------------------------------------------------- clouds


def lattice_side(n):
    """Side ``m`` of the cubic lattice closest to ``n`` points."""
    return max(2, int(round(n ** (1.0 / 3.0))))


def lattice(m):
    """The ``m^3`` points ``{0, ..., m-1}^3`` as a C-contiguous ``(m^3, 3)`` array."""
    pts = np.empty((m ** 3, 3))
    axis = np.arange(m, dtype=np.float64)
    pts[:, 0] = np.repeat(axis, m * m)
    pts[:, 1] = np.tile(np.repeat(axis, m), m)
    pts[:, 2] = np.tile(axis, m * m)
    return pts


def lattice_offsets():
    """Integer lattice vectors ``v`` with ``0 < |v| < HORIZON`` (the 122 of an interior point)."""
    r = int(np.ceil(HORIZON))
    v = np.arange(-r, r + 1)
    off = np.stack(np.meshgrid(v, v, v, indexing="ij"), axis=-1).reshape(-1, 3)
    d2 = (off ** 2).sum(axis=1)
    return off[(d2 > 0) & (d2 < HORIZON ** 2)]


def lattice_bonds(m, periodic=False):
    """Closed-form number of bonds (ordered pairs) of the ``m^3`` lattice."""
    off = lattice_offsets()
    if periodic:
        if m <= 2 * int(np.ceil(HORIZON)):
            raise ValueError(f"periodic lattice side {m} too small for horizon {HORIZON}")
        return len(off) * m ** 3
    return int(np.prod(np.clip(m - np.abs(off), 0, None), axis=1).sum())


def graded_cloud(n, ratio=GRADED_RATIO, seed=0):
    """Random points in the unit cube whose local spacing grows ``ratio``-fold from the centre.

    The density is ``1 / h(x)^3`` with ``h(x) = h0 * clip(|x - c| / r0, 1, ratio)``,
    ``c`` the cube's centre and ``r0 = (sqrt(3) / 2) / ratio`` (so ``h`` reaches
    ``ratio * h0`` at the corners), and ``h0`` set so that the density integrates to ``n``.
    Sampled exactly: radius by inverse CDF of ``r^2 / g(r)^3`` in the circumscribed
    ball, direction uniform, points outside the cube rejected.

    Returns
    -------
    points : (n, 3) ndarray
    spacing : (n,) ndarray
        Local spacing ``h(x_i)``.
    """
    rng = np.random.default_rng(seed)
    centre = np.full(3, 0.5)
    rmax = np.sqrt(3.0) / 2.0
    r0 = rmax / ratio
    inner, outer = r0 ** 3 / 3.0, r0 ** 3 * np.log(rmax / r0)    # int r^2 g^-3 dr
    chunks, got, drawn, kept = [], 0, 0, 0
    while got < n:
        m = int(1.3 * (n - got)) + 1000
        s = rng.random(m) * (inner + outer)
        r = np.where(s < inner, np.cbrt(3.0 * np.minimum(s, inner)),
                     r0 * np.exp((np.maximum(s, inner) - inner) / r0 ** 3))
        d = rng.standard_normal((m, 3))
        d /= np.linalg.norm(d, axis=1)[:, None]
        x = centre + r[:, None] * d
        ok = ((x >= 0.0) & (x < 1.0)).all(axis=1)
        drawn, kept, got = drawn + m, kept + int(ok.sum()), got + int(ok.sum())
        chunks.append(x[ok])
    pts = np.ascontiguousarray(np.concatenate(chunks)[:n])
    integral = 4.0 * np.pi * (inner + outer) * kept / drawn     # int_cube g^-3 dV
    h0 = np.cbrt(integral / n)
    g = np.clip(np.linalg.norm(pts - centre, axis=1) / r0, 1.0, ratio)
    return pts, h0 * g


def make_cloud(spec):
    """``(points, horizon, period)`` of a cloud spec: ``("lattice", m, periodic)`` or
    ``("graded", n)``."""
    if spec[0] == "lattice":
        _, m, periodic = spec
        return lattice(m), HORIZON, (np.full(3, float(m)) if periodic else None)
    _, n = spec
    pts, spacing = graded_cloud(n)
    return pts, HORIZON * spacing, None


# --------------------------------------------------------------------------- helpers


def bond_hash(offsets, indices):
    """Order-independent 64-bit hash of the bonds ``(i, j)`` of a CSR (chunked, O(chunk) memory)."""
    n = len(offsets) - 1
    nb = int(offsets[-1])
    step = max(1, int(4_000_000 * n / max(nb, 1)))
    total = 0
    m1, m2 = np.uint64(0x9E3779B97F4A7C15), np.uint64(0xBF58476D1CE4E5B9)
    for a in range(0, n, step):
        b = min(n, a + step)
        lo, hi = int(offsets[a]), int(offsets[b])
        rows = np.repeat(np.arange(a, b, dtype=np.uint64), np.diff(offsets[a:b + 1]))
        h = rows * m1 + indices[lo:hi].astype(np.uint64)
        h ^= h >> np.uint64(29)
        h *= m2
        h ^= h >> np.uint64(32)
        total = (total + int(h.sum(dtype=np.uint64))) % 2 ** 64
    return total


def csr_summary(offsets, indices, save=None):
    """Bond count, hash, family-size range; optionally save the CSR for the set check."""
    counts = np.diff(offsets)
    if save:
        np.savez(save, offsets=offsets, indices=indices)
    return dict(bonds=int(offsets[-1]), hash=bond_hash(offsets, indices),
                count_min=int(counts.min()), count_max=int(counts.max()))


def _timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - t0


# --------------------------------------------------------------------------- children


def _ours_child(task):
    """cells / rtree / kdtree through cnem.spatial.family_search (numba warmed up first)."""
    import numba
    from cnem.spatial import RTree, family_search
    from cnem.spatial.family import choose_method

    method, repeat = task["method"], task["repeat"]
    t0 = time.perf_counter()           # warm-up: compile (or load from cache) every kernel used
    def tiny():
        for spec in (("lattice", 6, False), ("lattice", 8, True), ("graded", 500)):
            wp, wh, wper = make_cloud(spec)
            family_search(wp, wh, period=wper, method=method)
            if method == "rtree":
                RTree.from_points(wp, period=wper)
    warm_both(tiny)
    warmup = time.perf_counter() - t0

    pts, horizon, period = make_cloud(task["cloud"])
    n = len(pts)
    h = np.broadcast_to(np.asarray(horizon, dtype=np.float64), (n,))
    out = dict(n=n, warmup=warmup, threads=numba.get_num_threads(),
               auto=choose_method(np.ascontiguousarray(h)), hmax=float(h.max()))
    if method == "kdtree":             # would query_pairs at the largest horizon fit?
        from scipy.spatial import cKDTree
        tree = cKDTree(pts)
        sample = np.random.default_rng(1).choice(n, size=min(n, GRADED_SAMPLE), replace=False)
        within = tree.query_ball_point(pts[sample], float(h.max()), return_length=True)
        pairs = 0.5 * n * (float(np.mean(within)) - 1.0)
        del tree
        need = BASE_BYTES + BYTES_PER_POINT * n + KD_METHOD_BYTES_PER_PAIR * pairs
        out.update(candidate_pairs=pairs, need=need)
        skip = memory_skip(need, task["mem_limit"])
        if skip:
            out["skipped"] = (f"query_pairs at the largest horizon {h.max():.4g} would return "
                              f"~{pairs:.2g} candidate pairs: {skip}")
            return out

    out["rss_before"] = peak_rss_bytes()
    builds, runs, fam = [], [], None
    if method == "rtree":
        for _ in range(repeat):
            tree = None
            tree, dt = _timed(lambda: RTree.from_points(pts, period=period))
            builds.append(dt)
        del tree
    for _ in range(repeat):
        fam = None
        fam, dt = _timed(lambda: family_search(pts, horizon, period=period, method=method))
        runs.append(dt)
    out.update(rss=peak_rss_bytes(), runs=runs, builds=builds)
    out.update(csr_summary(fam.offsets, fam.indices, task.get("save")))
    return out


def _kd_pairs_child(task):
    """cKDTree build + query_pairs + both-direction CSR (scipy only)."""
    import scipy.sparse
    from scipy.spatial import cKDTree

    pts, horizon, _ = make_cloud(task["cloud"])
    n = len(pts)
    itype = np.int32 if n < 2 ** 31 - 1 else np.int64
    rss_before = peak_rss_bytes()
    runs, csr = [], None
    for _ in range(task["repeat"]):
        csr = None
        t0 = time.perf_counter()
        tree = cKDTree(pts)
        t1 = time.perf_counter()
        pairs = tree.query_pairs(horizon, output_type="ndarray")
        t2 = time.perf_counter()
        k = len(pairs)
        rows, cols = np.empty(2 * k, dtype=itype), np.empty(2 * k, dtype=itype)
        rows[:k], rows[k:] = pairs[:, 0], pairs[:, 1]
        cols[:k], cols[k:] = pairs[:, 1], pairs[:, 0]
        del pairs
        coo = scipy.sparse.coo_array((np.ones(2 * k, dtype=np.int8), (rows, cols)), shape=(n, n))
        del rows, cols
        coo.has_canonical_format = True      # unique pairs: skip duplicate summation / row sorts
        csr = coo.tocsr()
        del coo
        t3 = time.perf_counter()
        del tree
        runs.append(dict(build=t1 - t0, pairs=t2 - t1, csr=t3 - t2, total=t3 - t0))
    out = dict(n=n, rss_before=rss_before, rss=peak_rss_bytes(), runs=runs)
    out.update(csr_summary(csr.indptr.astype(np.int64), csr.indices, task.get("save")))
    return out


def _kd_ball_child(task):
    """cKDTree build + query_ball_point(workers=-1, return_sorted=False) (scipy only)."""
    from itertools import chain

    from scipy.spatial import cKDTree

    pts, horizon, _ = make_cloud(task["cloud"])
    n = len(pts)
    rss_before = peak_rss_bytes()
    runs, lists = [], None
    for _ in range(task["repeat"]):
        lists = None
        t0 = time.perf_counter()
        tree = cKDTree(pts)
        lists = tree.query_ball_point(pts, horizon, workers=-1, return_sorted=False)
        runs.append(time.perf_counter() - t0)
        del tree
    rss = peak_rss_bytes()
    lengths = np.fromiter(map(len, lists), dtype=np.int64, count=n)
    out = dict(n=n, rss_before=rss_before, rss=rss, runs=runs,
               bonds=int(lengths.sum()) - n)        # each list holds the point itself
    if task.get("save"):
        flat = np.fromiter(chain.from_iterable(lists), dtype=np.int64, count=int(lengths.sum()))
        rows = np.repeat(np.arange(n), lengths)
        keep = flat != rows
        offsets = np.zeros(n + 1, dtype=np.int64)
        np.cumsum(np.bincount(rows[keep], minlength=n), out=offsets[1:])
        out.update(csr_summary(offsets, flat[keep], task["save"]))
    return out


CHILDREN = {"cells": _ours_child, "rtree": _ours_child, "kdtree": _ours_child,
            "kd pairs": _kd_pairs_child, "kd ball": _kd_ball_child}


# --------------------------------------------------------------------------- driver


def default_repeat(n, repeat):
    return repeat if repeat is not None else (3 if n < 1_000_000 else 1)


def ok(r):
    return r is not None and "error" not in r and "skipped" not in r


def run_one(label, task):
    print(f" {label}", end="", flush=True)
    if task.get("skip"):
        print(" (skipped)", end="", flush=True)
        return dict(skipped=task["skip"])
    res = in_child(CHILDREN[task["method"]], task)
    if "error" in res:
        print(" (FAILED)", end="", flush=True)
    elif "skipped" in res:
        print(" (skipped)", end="", flush=True)
    return res


def run_lattice(sizes, args, mem_limit, tmp):
    results = []
    for i, n_req in enumerate(sizes):
        m = lattice_side(n_req)
        n = m ** 3
        rep = default_repeat(n, args.repeat)
        smallest = i == 0 and lattice_bonds(m) <= SET_CHECK_MAX_BONDS
        spec = ("lattice", m, False)

        def task(method, **kw):
            save = os.path.join(tmp, f"{method.replace(' ', '_')}_{n}.npz") if smallest else None
            return dict(method=method, cloud=spec, repeat=rep, save=save, mem_limit=mem_limit, **kw)

        bonds = lattice_bonds(m)
        skip = {}
        for method in BYTES_PER_BOND:
            too_big = memory_skip(estimated_bytes(method, n, bonds), mem_limit)
            if too_big:
                skip[method] = too_big + " (--mem-limit-gb)"
        if n > BALL_MAX_N and not args.big:
            skip["kd ball"] = f"N > {fmt_n(BALL_MAX_N)} (use --big)"
        print(f"  N = {fmt_n(n)} ({m}^3) x{rep}:", end="", flush=True)
        r = dict(n=n, m=m, repeat=rep, bonds_expected=bonds, smallest=smallest)
        for method in ("cells", "rtree", "kd pairs", "kd ball"):
            r[method] = run_one(method, task(method, skip=skip.get(method)))
        print(" done", flush=True)
        if smallest:
            r["sets"] = compare_sets(tmp, n, ["cells", "rtree", "kd pairs", "kd ball"], r)
        results.append(r)
    return results


def compare_sets(tmp, n, methods, r):
    """Exact comparison of the saved CSRs as sorted ``i * n + j`` keys."""
    keys = {}
    for method in methods:
        path = os.path.join(tmp, f"{method.replace(' ', '_')}_{n}.npz")
        if not ok(r[method]) or not os.path.exists(path):
            continue
        with np.load(path) as z:
            offsets, indices = z["offsets"], z["indices"]
        rows = np.repeat(np.arange(n, dtype=np.int64), np.diff(offsets))
        keys[method] = np.sort(rows * n + indices.astype(np.int64))
        os.remove(path)
    ref = keys.get("cells")
    return {m: (ref is not None and len(k) == len(ref) and bool(np.array_equal(k, ref)))
            for m, k in keys.items() if m != "cells"}


def run_graded(n, args, mem_limit):
    rep = default_repeat(n, args.repeat)
    print(f"  graded N = {fmt_n(n)} x{rep}:", end="", flush=True)
    r = dict(n=n, repeat=rep)
    for method in ("cells", "rtree", "kdtree"):
        need = estimated_bytes(method, n, 130 * n) if method in BYTES_PER_BOND else 0
        skip = memory_skip(need, mem_limit)
        r[method] = run_one(method, dict(method=method, cloud=("graded", n), repeat=rep,
                                         mem_limit=mem_limit, skip=skip))
    print(" done", flush=True)
    return r


def run_periodic(sizes, args, mem_limit):
    results = []
    for n_req in sizes:
        m = lattice_side(n_req)
        n = m ** 3
        rep = default_repeat(n, args.repeat)
        print(f"  periodic N = {fmt_n(n)} ({m}^3) x{rep}:", end="", flush=True)
        r = dict(n=n, m=m, repeat=rep, bonds_open=lattice_bonds(m),
                 bonds_periodic=lattice_bonds(m, periodic=True))
        for method in ("cells", "rtree"):
            for periodic in (False, True):
                key = (method, "periodic" if periodic else "open")
                need = estimated_bytes(method, n, r["bonds_periodic"])
                skip = memory_skip(need, mem_limit)
                r[key] = run_one(f"{method}/{key[1]}",
                                 dict(method=method, cloud=("lattice", m, periodic), repeat=rep,
                                      mem_limit=mem_limit, skip=skip))
        print(" done", flush=True)
        results.append(r)
    return results


# --------------------------------------------------------------------------- report


def t_of(r, key="runs"):
    """Median time of a result, or None."""
    if not ok(r):
        return None
    runs = r[key]
    if runs and isinstance(runs[0], dict):
        return median([x["total"] for x in runs])
    return median(runs)


def cell(x, fmt="{:8.4f}", width=8):
    return fmt.format(x) if x is not None else f"{'-':>{width}}"


def mb(r):
    return r["rss"] / 2 ** 20 if ok(r) else None


def best_scipy(r):
    opts = [(t_of(r[k]), k) for k in ("kd pairs", "kd ball") if t_of(r[k]) is not None]
    return min(opts) if opts else (None, None)


def report_lattice(results):
    print()
    print(f"family search on the cubic lattice {{0..m-1}}^3, spacing 1, horizon {HORIZON} "
          f"(strict <: {len(lattice_offsets())} members per interior point); "
          "median wall times in s")
    first = next((r["cells"] for r in results if ok(r["cells"])), None)
    if first:
        print(f"numba: {first['threads']} threads, warmed up on tiny clouds in each cnem child "
              f"before timing (compile time excluded; warm-up {first['warmup']:.2f} s); "
              f'method="auto" picks "{first["auto"]}" here')
    print("peak MB = high-water RSS (VmHWM) of the measurement's own fresh child: "
          "interpreter + imports + lattice + timed runs")
    print()
    head = (f"{'N':>5} {'rep':>3} | {'cells':>8} | {'rt build':>8} {'rt total':>8} | "
            f"{'kd pairs':>8} {'kd ball':>8} | {'cells':>6} {'rtree':>6} {'kd pr':>6} "
            f"{'kd ball':>7} | {'ratio':>6}")
    print(f"{'':>5} {'':>3} | {'':>8} | {'':>8} {'':>8} | {'+CSR':>8} {'':>8} | "
          f"{'peak MB':^35} | {'':>6}")
    print(head)
    print("-" * len(head))
    for r in results:
        tc = t_of(r["cells"])
        tb, _ = best_scipy(r)
        ratio = tb / tc if (tb is not None and tc) else None
        print(f"{fmt_n(r['n']):>5} {r['repeat']:>3d} | {cell(tc)} | "
              f"{cell(t_of(r['rtree'], 'builds'))} {cell(t_of(r['rtree']))} | "
              f"{cell(t_of(r['kd pairs']))} {cell(t_of(r['kd ball']))} | "
              f"{cell(mb(r['cells']), '{:6.0f}', 6)} {cell(mb(r['rtree']), '{:6.0f}', 6)} "
              f"{cell(mb(r['kd pairs']), '{:6.0f}', 6)} {cell(mb(r['kd ball']), '{:7.0f}', 7)} | "
              f"{cell(ratio, '{:5.1f}x', 6)}")
    print()
    print("columns: cells = family_search(method='cells'); rt build = RTree.from_points alone;")
    print("         rt total = family_search(method='rtree') (build + query + CSR);")
    print("         kd pairs+CSR = cKDTree build + query_pairs(ndarray) + COO->CSR of both "
          "directions;")
    print("         kd ball = cKDTree build + query_ball_point(workers=-1, return_sorted=False), "
          "list of lists;")
    print("         ratio = fastest scipy route / cells; '-' = not run (see notes)")
    print()
    print("details (medians, s):")
    for r in results:
        kp = r["kd pairs"]
        parts = []
        if ok(kp):
            parts.append("kd pairs: build {:.3f} + query_pairs {:.3f} + CSR {:.3f}".format(
                *(median([x[k] for x in kp["runs"]]) for k in ("build", "pairs", "csr"))))
        if ok(r["cells"]):             # the spread: fresh memory is slow on some machines
            parts.append("cells runs " + " ".join(f"{t:.3f}" for t in r["cells"]["runs"]))
        rt = r["rtree"]
        if ok(rt):
            parts.append(f"rtree query+CSR ~ {t_of(rt) - t_of(rt, 'builds'):.3f}")
        for key in ("cells", "rtree", "kd pairs", "kd ball"):
            res = r[key]
            if ok(res):
                parts.append(f"{key} RSS before timing {res['rss_before'] / 2**20:.0f} MB, "
                             f"+{(res['rss'] - res['rss_before']) / max(res['bonds'], 1):.1f} "
                             f"B/bond")
            elif res is not None:
                parts.append(f"{key}: {res.get('skipped') or res.get('error')}")
        print(f"  {fmt_n(r['n']):>5}: " + ";\n         ".join(parts))
    print()
    print("checks:")
    for r in results:
        line = [f"expected {r['bonds_expected']} bonds (closed form)"]
        good = True
        for key in ("cells", "rtree", "kd pairs", "kd ball"):
            res = r[key]
            if ok(res):
                same = res["bonds"] == r["bonds_expected"]
                good &= same
                line.append(f"{key} {res['bonds']}{'' if same else ' (MISMATCH)'}")
        hashes = {k: r[k]["hash"] for k in ("cells", "rtree", "kd pairs")
                  if ok(r[k]) and "hash" in r[k]}
        if len(hashes) > 1:
            same_hash = len(set(hashes.values())) == 1
            good &= same_hash
            line.append(f"bond-set hash {'equal' if same_hash else 'DIFFERENT'} "
                        f"({', '.join(hashes)})")
        if ok(r["cells"]):
            c = r["cells"]
            line.append(f"family sizes {c['count_min']}..{c['count_max']}")
            good &= c["count_max"] == len(lattice_offsets())
        if "sets" in r:
            same = all(r["sets"].values())
            good &= same
            line.append("exact sets vs cells: " + ", ".join(
                f"{k} {'same' if v else 'DIFFERENT'}" for k, v in r["sets"].items()))
        print(f"  {fmt_n(r['n']):>5}: {'OK' if good else 'FAILED'}: " + "; ".join(line))
    if results and not results[0].get("smallest"):
        print("  (exact set comparison skipped: the smallest size has more than "
              f"{SET_CHECK_MAX_BONDS} bonds; the hashes compare the sets)")

    print()
    by_n = {r["n"]: r for r in results}
    r = by_n.get(TARGET_N)
    rows = []
    if r is not None:
        tc, tb_rt = t_of(r["cells"]), t_of(r["rtree"], "builds")
        tb, which = best_scipy(r)
        if tc is not None:
            gb = r["cells"]["rss"] / 2 ** 30
            rows.append((f"family_search 1M <= {TARGET_SECONDS:g} s median", f"{tc:.3f} s",
                         tc <= TARGET_SECONDS))
            rows.append((f"family_search 1M peak memory <= {TARGET_MEMORY_GB:g} GB",
                         f"{gb:.2f} GB", gb <= TARGET_MEMORY_GB))
            if tb is not None:
                rows.append((f"family_search 1M >= {TARGET_SPEEDUP:g}x faster than fastest "
                             f"scipy route ({which} {tb:.3f} s)", f"{tb / tc:.1f}x",
                             tb / tc >= TARGET_SPEEDUP))
        if tb_rt is not None:
            rows.append((f"RTree.from_points 1M <= {TARGET_BUILD_SECONDS:g} s", f"{tb_rt:.3f} s",
                         tb_rt <= TARGET_BUILD_SECONDS))
    print_targets(rows)
    if r is None:
        print(f"  (N = {fmt_n(TARGET_N)} not run: 1M targets not evaluated)")
    others = [r for r in results if r["n"] != TARGET_N and t_of(r["cells"]) and best_scipy(r)[0]]
    if others:
        print("  (speed-up over the fastest scipy route at other sizes: " + ", ".join(
            f"{fmt_n(r['n'])} {best_scipy(r)[0] / t_of(r['cells']):.1f}x" for r in others) + ")")

    print()
    print("anchors at 1M from the issue (this machine class, same workload) vs this run:")
    for label, sec, gb, key, times, ours_label in ANCHORS_1M:
        anchor = f"{sec:g} s" + (f" / {gb:g} GB" if gb else "")
        ours = "(1M not run)"
        if r is not None:
            t = t_of(r[key], times)
            ours = f"{ours_label} " + (
                "not run" if t is None else
                f"{t:.3f} s" + (f" / {r[key]['rss'] / 2**30:.2f} GB" if gb else ""))
        print(f"  {label:<28} {anchor:>14}   ours: {ours}")


def report_graded(r):
    print()
    print(f"graded cloud: {fmt_n(r['n'])} random points in the unit cube, spacing growing "
          f"{GRADED_RATIO:g}x from the centre to the corners, per-point horizon "
          f"{HORIZON} x local spacing")
    ref = next((r[k] for k in ("rtree", "cells", "kdtree") if ok(r[k])), None)
    if ref:
        print(f"  {ref['bonds']} bonds, mean {ref['bonds'] / r['n']:.1f} per point "
              f"(range {ref['count_min']}..{ref['count_max']}), largest horizon "
              f"{ref['hmax']:.4g}; method='auto' picks '{ref['auto']}'")
    head = f"  {'method':<8} | {'median s':>8} | {'peak MB':>7} | {'vs fastest':>10}"
    print(head)
    print("  " + "-" * (len(head) - 2))
    times = {k: t_of(r[k]) for k in ("cells", "rtree", "kdtree")}
    fastest = min((t for t in times.values() if t is not None), default=None)
    for k in ("cells", "rtree", "kdtree"):
        t = times[k]
        note = ""
        if not ok(r[k]):
            note = "  " + (r[k].get("skipped") or r[k].get("error") or "")
        print(f"  {k:<8} | {cell(t)} | {cell(mb(r[k]), '{:7.0f}', 7)} | "
              f"{cell(t / fastest if t is not None and fastest else None, '{:9.1f}x', 10)}{note}")
    done = [k for k in ("cells", "rtree", "kdtree") if ok(r[k])]
    if len(done) > 1:
        same = len({(r[k]["bonds"], r[k]["hash"]) for k in done}) == 1
        print(f"  check: {'OK' if same else 'FAILED'}: bonds " +
              ", ".join(f"{k} {r[k]['bonds']}" for k in done) +
              f"; bond-set hash {'equal' if same else 'DIFFERENT'}")
    print("  kdtree = family_search(method='kdtree'): cKDTree.query_pairs at the largest horizon, "
          "then exact filtering")
    kd = r["kdtree"]
    if kd and "candidate_pairs" in kd:
        print(f"  kdtree candidate pairs at the largest horizon (sampled estimate): "
              f"~{kd['candidate_pairs']:.3g} "
              f"(~{kd['candidate_pairs'] / max(r['n'], 1):.0f} per point, "
              f"estimated need ~{kd['need'] / 2**30:.1f} GB)")


def report_periodic(results):
    print()
    print(f"periodic vs open on the lattice {{0..m-1}}^3 (period m along each axis), "
          f"horizon {HORIZON}; median s")
    head = (f"  {'N':>5} {'method':<6} | {'open':>8} {'periodic':>8} | {'ratio':>6} | "
            f"{'open MB':>7} {'per MB':>7} | target <= {TARGET_PERIODIC_RATIO:g}x")
    print(head)
    print("  " + "-" * (len(head) - 2))
    checks = []
    for r in results:
        for method in ("cells", "rtree"):
            ro, rp = r[(method, "open")], r[(method, "periodic")]
            to, tp = t_of(ro), t_of(rp)
            ratio = tp / to if (to and tp is not None) else None
            verdict = "-" if ratio is None else \
                ("MET" if ratio <= TARGET_PERIODIC_RATIO else "MISSED")
            print(f"  {fmt_n(r['n']):>5} {method:<6} | {cell(to)} {cell(tp)} | "
                  f"{cell(ratio, '{:5.2f}x', 6)} | {cell(mb(ro), '{:7.0f}', 7)} "
                  f"{cell(mb(rp), '{:7.0f}', 7)} | {verdict}")
            for key, res in ((f"{method}/open", ro), (f"{method}/periodic", rp)):
                if not ok(res):
                    why = res.get("skipped") or res.get("error")
                    checks.append(f"{fmt_n(r['n'])} {key}: {why}")
        good, parts = True, []
        for periodic in (False, True):
            tag = "periodic" if periodic else "open"
            expect = r["bonds_periodic" if periodic else "bonds_open"]
            got = {m: r[(m, tag)] for m in ("cells", "rtree") if ok(r[(m, tag)])}
            same = all(g["bonds"] == expect for g in got.values()) and \
                len({g["hash"] for g in got.values()}) <= 1
            if periodic:
                same &= all(g["count_min"] == g["count_max"] == len(lattice_offsets())
                            for g in got.values())
            good &= same
            parts.append(f"{tag} {expect} bonds expected, " +
                         ", ".join(f"{m} {g['bonds']}" for m, g in got.items()) +
                         (" (hash equal)" if len(got) > 1 and same else ""))
        checks.append(f"{fmt_n(r['n'])}: {'OK' if good else 'FAILED'}: " + "; ".join(parts) +
                      f"; every periodic point has {len(lattice_offsets())} members")
    for c in checks:
        print(f"  check {c}")


# --------------------------------------------------------------------------- main


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true",
                        help=f"CI smoke run: N = {QUICK_SIZE} only (extras small too)")
    parser.add_argument("--big", action="store_true",
                        help=f"add N = {fmt_n(BIG_SIZE)} and allow query_ball_point above "
                             f"{fmt_n(BALL_MAX_N)}")
    parser.add_argument("--sizes", type=int, nargs="+", metavar="N",
                        help="lattice sizes (rounded to cubes; default 27k 125k 343k 1M)")
    parser.add_argument("--repeat", type=int, default=None,
                        help="timed repetitions (default 3, 1 for N >= 1M)")
    parser.add_argument("--graded-n", type=int, default=None,
                        help=f"graded cloud size (default {GRADED_N}, --quick {GRADED_QUICK_N})")
    parser.add_argument("--periodic-sizes", type=int, nargs="+", metavar="N",
                        help="periodic-vs-open lattice sizes (default 125000 1000000)")
    parser.add_argument("--no-graded", action="store_true", help="skip the graded-cloud case")
    parser.add_argument("--no-periodic", action="store_true", help="skip the periodic case")
    parser.add_argument("--mem-limit-gb", type=float, default=None,
                        help="skip measurements estimated above this many GB "
                             "(default: 80%% of MemAvailable)")
    args = parser.parse_args(argv)

    if args.sizes:
        sizes = list(args.sizes)
    elif args.quick:
        sizes = [QUICK_SIZE]
    else:
        sizes = list(DEFAULT_SIZES)
    if args.big and BIG_SIZE not in sizes:
        sizes.append(BIG_SIZE)
    sizes = sorted({lattice_side(n) ** 3 for n in sizes})
    if args.periodic_sizes:
        periodic_sizes = args.periodic_sizes
    elif args.quick:
        periodic_sizes = [QUICK_SIZE]
    elif args.sizes:
        periodic_sizes = [n for n in PERIODIC_SIZES if n <= max(sizes)] or [max(sizes)]
    else:
        periodic_sizes = PERIODIC_SIZES
    periodic_sizes = sorted({lattice_side(n) ** 3 for n in periodic_sizes})
    graded_n = args.graded_n or (GRADED_QUICK_N if args.quick else GRADED_N)
    avail = mem_available_bytes()
    mem_limit = memory_limit(args.mem_limit_gb)

    machine = MachineLoad()
    print(f"benchmarks/family_search.py: lattice sizes {[fmt_n(n) for n in sizes]}, "
          f"graded {fmt_n(graded_n) if not args.no_graded else 'off'}, periodic "
          f"{[fmt_n(n) for n in periodic_sizes] if not args.no_periodic else 'off'}; "
          f"python {sys.version.split()[0]}, numpy {np.__version__}, {os.cpu_count()} CPUs, "
          f"MemAvailable {avail / 2**30 if avail else float('nan'):.1f} GB, "
          f"memory limit {mem_limit / 2**30:.1f} GB, load average {load_text(machine.before.load)}")
    with tempfile.TemporaryDirectory() as tmp:
        lattice_results = run_lattice(sizes, args, mem_limit, tmp)
    graded = None if args.no_graded else run_graded(graded_n, args, mem_limit)
    periodic = None if args.no_periodic else run_periodic(periodic_sizes, args, mem_limit)
    print("\n" + machine.stop().report())

    report_lattice(lattice_results)
    if graded:
        report_graded(graded)
    if periodic:
        report_periodic(periodic)
    return dict(lattice=lattice_results, graded=graded, periodic=periodic)


if __name__ == "__main__":
    main()
