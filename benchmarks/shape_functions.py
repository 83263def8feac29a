"""Benchmark: ``Model.shape_functions`` (Sibson values) against scipy's barycentric weights.

Workload
--------
For each domain and each size n (default 10k, 100k and 1M nodes)::

    dom = cnem.geometry.rectangle()                                      # "square"
    dom = cnem.geometry.rectangle(cracks=[[[0.0, 0.5], [0.5, 0.5]]])     # "cracked" plate
    cloud = cnem.nodes.irregular(dom, h=1 / sqrt(n), seed=0)
    model = cnem.discretize(cloud, progress=False)

and ``--queries`` (default 1M) query points drawn uniformly at random in the unit square
(``numpy.random.default_rng(12345).random((q, 2))``, the same points in every process; for the
cracked plate they are all inside too: the crack has measure zero).  The points are passed in
random order, unsorted: whatever sorting ``shape_functions`` does internally is counted.

What is measured
----------------
Every measurement runs in its own fresh child process (``multiprocessing`` with the ``spawn``
start method).

**cnem** -- two children per domain and size, one with ``numba.set_num_threads(1)`` and one
with two threads.  Each child

1. warms numba up: discretizes a tiny cloud of the same domain and evaluates its shape
   functions at a few points, twice (the serial and the parallel copies of the kernels,
   ``_harness.warm_both``), so JIT compile time (or loading from numba's cache) is
   excluded; the warm-up time is printed;
2. builds the model (``discretize`` runs with numba's default thread count and is timed on
   its own; it is *not* part of the rate);
3. sets the thread count and calls ``model.shape_functions(points[:10])`` once: the first
   call on a model builds the cached R-tree over the circumcircles (point location; the
   triangle-neighbour table comes with the model from ``discretize``); this once-per-model
   ``setup`` time is reported on its own and excluded from the rate;
4. times ``model.shape_functions(points)`` (``kind="sibson"``, values only, a
   ``scipy.sparse.csr_matrix``) ``--repeat`` times; rate = query points / median time.

**scipy** (the floor) -- one child per domain and size, which does not import cnem (no
numba): on the same nodes ``model.nodes`` (saved by the cnem child; for the cracked plate
they include the duplicated crack-face nodes) ``tri = scipy.spatial.Delaunay(nodes)`` is
timed on its own (``Delaunay s``), then the standard recipe for barycentric weights::

    simplex = tri.find_simplex(points)
    T = tri.transform[simplex]
    b = np.einsum("ijk,ik->ij", T[:, :2], points - T[:, 2])
    weights = np.c_[b, 1 - b.sum(axis=1)]

is timed as a whole; rate = query points / median time.  Before that, a first query on
10 points, which computes and caches ``tri.transform`` (scipy's own once-per-triangulation
setup), is timed apart (``sc setup``) and excluded, like cnem's setup.  This is a floor,
not a rival: it neither respects the crack nor computes natural-neighbour coordinates
(three weights from one triangle, no cavity), and ``find_simplex`` is single-threaded.
scipy's walk from the previous point's simplex is slow for random query order on large
triangulations (tens of seconds per 1M points at 100k nodes), so the baseline's
repetitions (of the Delaunay build and of the query, each) stop early once their
cumulative time passes ``--baseline-budget`` seconds (default 60; at least one run); the
table's ``rep`` column gives the runs done.

**CGAL** (the compiled anchor, square domain only) -- when g++ and CGAL's headers are found
(Debian: ``apt-get install libcgal-dev``; a benchmark-time tool, not a cnem dependency), the
driver ``tests/cgal_sibson.cpp`` is compiled once into a cache folder
(``~/.cache/cnem-benchmarks``, see ``tests/cgal_coordinates.py``) and run as its own process on the
cnem model's nodes and the same query points (raw float64 files).  It builds a
``Delaunay_triangulation_2`` (timed apart, not counted), then ``--repeat`` times, single
threaded: ``CGAL::hilbert_sort`` of the query indices (counted), ``locate`` from the
previous query's face and ``natural_neighbor_coordinates_2`` there (Sibson coordinates,
normalised), and the CSR matrix in the input order of the queries (counted: cnem returns
one); rate = query points / median time.  The last run's matrix is read back and compared
with cnem's one-thread values: max ``|cnem - CGAL|`` is printed and checked against 1e-12.
Otherwise the column says why it was skipped.  The cracked plate has no CGAL column: CGAL's
unconstrained Delaunay triangulation ignores the crack, so its values are not cnem's there.
``1T/CGAL`` is cnem's one-thread rate over CGAL's (target, issue 22: >= 1 at 100k and 1M
nodes); the same ratio by CPU time per run (``time.process_time`` / ``std::clock``, less
sensitive to other processes on a shared machine) is printed under the target.

Peak memory is the child's high-water resident set size, ``VmHWM`` from
``/proc/self/status`` (``ru_maxrss`` is not used: across ``exec`` the kernel carries the
parent's peak over into a spawned child).  In the cnem children the high-water mark is reset
(``echo 5 > /proc/self/clear_refs``) after ``discretize``, so ``peak MB`` is that of the
shape-function phase: interpreter, imports, the model, the query points and the timed calls
(``discretize``'s own peak is printed in the details).  Where the reset is not available
the figure is the whole child's and is marked ``*``.  The scipy figure is the whole child:
interpreter, imports, nodes, Delaunay, points and the timed runs.

Checks (printed): on the smallest model of each domain, the rows of Phi sum to 1 and
``Phi @ model.nodes`` reproduces the query points, both to 1e-12, on all the query points;
no negative value; the one- and two-thread results are identical (fingerprint); every
query point lies in a scipy simplex and the barycentric weights reproduce the points.

The machine's load (``_harness.MachineLoad``: load average, other processes' CPU time, CPU
steal) is printed before and after the run and over each size: the machine is shared, so
compare the rates measured within one run. Without a CGAL column the CGAL rates recorded in
an earlier issue are printed instead; the plain numba Watson kernel's recorded rates are
printed next to our square-domain rates. Target (issue): >= 2 M points/s with two threads
on 100k nodes for 1M random (unsorted) query points, sorting included, Sibson values only.
Timings are printed, never asserted.

How to run
----------
::

    python benchmarks/shape_functions.py                      # 10k, 100k, 1M nodes, 1M queries
    python benchmarks/shape_functions.py --quick              # 5k nodes, 20k queries, cracked
    python benchmarks/shape_functions.py --sizes 10000 100000 --queries 200000
    python benchmarks/shape_functions.py --domains square --repeat 5
    python benchmarks/shape_functions.py --no-cgal                # without the CGAL column
"""
import argparse
import gc
import os
import sys
import tempfile
import time

import numpy as np

from _harness import (MachineLoad, fmt_n, in_child, load_text, median, peak_rss_bytes,
                      reset_peak_rss, verdict, warm_both)

# the CGAL driver lives with the test that checks cnem's Sibson values against it
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "tests"))
import cgal_coordinates  # noqa: E402

DOMAINS = {
    "square": dict(),
    "cracked": dict(cracks=[[[0.0, 0.5], [0.5, 0.5]]]),
}
DEFAULT_SIZES = [10_000, 100_000, 1_000_000]
DEFAULT_QUERIES = 1_000_000
QUICK_SIZE, QUICK_QUERIES, QUICK_DOMAIN = 5_000, 20_000, "cracked"
QUERY_SEED = 12345
SETUP_POINTS = 10
WARMUP_H, WARMUP_POINTS = 0.05, 50
CHECK_TOL = 1e-12

TARGET_N = 100_000
TARGET_QUERIES = 1_000_000
TARGET_RATE = 2.0            # M points/s, two threads
TARGET_THREADS = 2
CGAL_TARGET_SIZES = (100_000, 1_000_000)   # cnem 1 thread >= CGAL 1 thread (issue 22)

# (nodes, CGAL random order, CGAL Hilbert-sorted) in M points/s, 1M random queries (issue)
CGAL_ANCHORS = [
    (10_000, 0.6, 2.1),
    (100_000, 0.07, 1.6),
    (1_000_000, None, 1.0),
]
CGAL_SORT_SECONDS = 0.2      # Hilbert sorting of the 1M queries, extra (100k row)
WATSON_ANCHOR = (100_000, 1.4, 5.4)   # plain numba Watson kernel, two threads (issue)


# --------------------------------------------------------------------------- helpers


def query_points(q):
    """The benchmark's query points: uniform random in the unit square, fixed seed."""
    return np.random.default_rng(QUERY_SEED).random((q, 2))


def cell(x, fmt="{:8.3f}", width=8):
    return fmt.format(x) if x is not None else f"{'-':>{width}}"


# --------------------------------------------------------------------------- children


def _cnem_child(task):
    """Warm up, discretize (timed apart), setup call, timed shape_functions at a thread count."""
    import numba

    import cnem

    threads, repeat, q = task["threads"], task["repeat"], task["queries"]
    dom = cnem.geometry.rectangle(**DOMAINS[task["domain"]])

    t0 = time.perf_counter()       # warm-up: compile (or load from cache) every kernel used
    def tiny():
        wmodel = cnem.discretize(cnem.nodes.irregular(dom, h=WARMUP_H, seed=0), progress=False)
        wmodel.shape_functions(query_points(WARMUP_POINTS), kind="sibson")
    warm_both(tiny)
    warmup = time.perf_counter() - t0

    cloud = cnem.nodes.irregular(dom, h=1.0 / np.sqrt(task["n"]), seed=0)
    t0 = time.perf_counter()
    model = cnem.discretize(cloud, progress=False)
    t_disc = time.perf_counter() - t0
    del cloud
    if task.get("save"):
        np.save(task["save"], model.nodes)
    pts = query_points(q)
    gc.collect()
    rss_disc = peak_rss_bytes()
    reset = reset_peak_rss()

    numba.set_num_threads(threads)
    t0 = time.perf_counter()
    model.shape_functions(pts[:SETUP_POINTS], kind="sibson")
    setup = time.perf_counter() - t0

    runs, cpu_runs, phi = [], [], None
    for _ in range(repeat):
        phi = None
        t0, c0 = time.perf_counter(), time.process_time()
        phi = model.shape_functions(pts, kind="sibson")
        runs.append(time.perf_counter() - t0)
        cpu_runs.append(time.process_time() - c0)
    rss = peak_rss_bytes()
    if task.get("save_phi"):                 # for the comparison with CGAL's values
        import scipy.sparse
        scipy.sparse.save_npz(task["save_phi"], phi, compressed=False)
    grad_runs = []
    if task.get("gradient"):                 # the same points with gradients (cavity points)
        for _ in range(repeat):
            out = None
            t0 = time.perf_counter()
            out = model.shape_functions(pts, kind="sibson", gradient=True)
            grad_runs.append(time.perf_counter() - t0)
        del out

    data = phi.data
    cols = phi.indices.astype(np.float64)
    out = dict(n_nodes=len(model.nodes), n_tri=len(model.triangles), threads=threads,
               numba_threads=numba.get_num_threads(), warmup=warmup, discretize=t_disc,
               setup=setup, runs=runs, cpu_runs=cpu_runs, grad_runs=grad_runs, rss=rss,
               rss_disc=rss_disc,
               reset=reset,
               nnz=int(phi.nnz), vmin=float(data.min()),
               fingerprint=(int(phi.nnz), float(data.sum()), float((data * cols).sum()),
                            int(phi.indptr[-1])))
    if task.get("check"):
        rows = np.asarray(phi.sum(axis=1)).ravel()
        out["check"] = dict(sum_err=float(np.abs(rows - 1.0).max()),
                            rep_err=float(np.abs(phi @ model.nodes - pts).max()),
                            points=q)
    return out


def _scipy_child(task):
    """scipy Delaunay (timed apart) + find_simplex + transform barycentric weights."""
    from scipy.spatial import Delaunay

    nodes = np.load(task["nodes"])
    pts = query_points(task["queries"])
    repeat, budget = task["repeat"], task["budget"]

    builds, tri = [], None
    while len(builds) < repeat and (not builds or sum(builds) < budget):
        tri = None
        t0 = time.perf_counter()
        tri = Delaunay(nodes)
        builds.append(time.perf_counter() - t0)

    def barycentric(x):
        simplex = tri.find_simplex(x)
        T = tri.transform[simplex]
        b = np.einsum("ijk,ik->ij", T[:, :2], x - T[:, 2])
        return simplex, np.c_[b, 1.0 - b.sum(axis=1)]

    t0 = time.perf_counter()       # first query: computes and caches tri.transform
    barycentric(pts[:SETUP_POINTS])
    setup = time.perf_counter() - t0

    runs, simplex, weights = [], None, None
    while len(runs) < repeat and (not runs or sum(runs) < budget):
        simplex = weights = None
        t0 = time.perf_counter()
        simplex, weights = barycentric(pts)
        runs.append(time.perf_counter() - t0)
    rss = peak_rss_bytes()

    outside = int((simplex < 0).sum())
    inside = simplex >= 0
    corners = nodes[tri.simplices[simplex[inside]]]                 # (p, 3, 2)
    rep = np.einsum("ij,ijk->ik", weights[inside], corners)
    return dict(n_nodes=len(nodes), n_tri=len(tri.simplices), builds=builds, setup=setup,
                runs=runs,
                rss=rss, outside=outside,
                rep_err=float(np.abs(rep - pts[inside]).max()) if inside.any() else None)


def ok(r):
    return r is not None and "error" not in r and "skipped" not in r


def cgal_vs_cnem(exe, nodes_file, phi_file, queries, repeat, tmp):
    """CGAL's Sibson coordinates on the cnem model's nodes and the same queries, timed by
    the driver in its own process, and their max abs difference from cnem's values."""
    import scipy.sparse

    pts = query_points(queries)
    out = cgal_coordinates.run(exe, np.load(nodes_file), pts, repeat, tmp)
    if "error" in out:
        return out
    phi = out.pop("phi")
    ours = scipy.sparse.load_npz(phi_file)
    out["diff"] = float(abs(phi - ours).max())
    out["sum_err"] = float(np.abs(np.asarray(phi.sum(axis=1)).ravel() - 1.0).max())
    out["nnz"] = int(phi.nnz)
    return out


# --------------------------------------------------------------------------- driver


def run(domains, sizes, queries, repeat, budget, tmp, cgal):
    results = []
    two = os.cpu_count() is not None and os.cpu_count() >= TARGET_THREADS
    for domain in domains:
        for i, n in enumerate(sizes):
            nodes_file = os.path.join(tmp, f"nodes_{domain}_{n}.npy")
            print(f"  {domain} n = {fmt_n(n)}, {fmt_n(queries)} queries x{repeat}:",
                  end="", flush=True)
            phi_file = os.path.join(tmp, f"phi_{domain}_{n}.npz")
            with_cgal = "exe" in cgal and domain == "square"
            during = MachineLoad()
            r = dict(domain=domain, n=n, queries=queries, repeat=repeat, smallest=i == 0)
            base = dict(domain=domain, n=n, queries=queries, repeat=repeat)
            print(" cnem 1T", end="", flush=True)
            r["1T"] = in_child(_cnem_child, dict(base, threads=1, save=nodes_file, check=i == 0,
                                            save_phi=phi_file if with_cgal else None))
            if two:
                print(f" cnem {TARGET_THREADS}T", end="", flush=True)
                r["2T"] = in_child(_cnem_child, dict(base, threads=TARGET_THREADS, gradient=True))
            else:
                r["2T"] = dict(skipped=f"{os.cpu_count()} CPU(s)")
            if os.path.exists(nodes_file):
                print(" scipy", end="", flush=True)
                r["scipy"] = in_child(_scipy_child, dict(nodes=nodes_file, queries=queries,
                                                    repeat=repeat, budget=budget))
            else:
                r["scipy"] = dict(error="no nodes (the cnem 1T child failed)")
            if not with_cgal:
                r["cgal"] = dict(skipped=cgal.get("skipped") or
                                 "cracked plate: CGAL's unconstrained Delaunay triangulation "
                                 "ignores the crack (its values are not cnem's there)")
            elif os.path.exists(phi_file):
                print(" CGAL", end="", flush=True)
                r["cgal"] = cgal_vs_cnem(cgal["exe"], nodes_file, phi_file, queries, repeat, tmp)
            else:
                r["cgal"] = dict(error="no cnem values (the cnem 1T child failed)")
            for path in (nodes_file, phi_file):
                if os.path.exists(path):
                    os.remove(path)
            for key in ("1T", "2T", "scipy", "cgal"):
                if "error" in r[key]:
                    print(f" ({key} FAILED)", end="", flush=True)
            print(" done", flush=True)
            r["load"] = during.stop().short()
            results.append(r)
    return results


# --------------------------------------------------------------------------- report


def rate(r, queries):
    """Median rate in M points/s, or None."""
    if not ok(r):
        return None
    return queries / median(r["runs"]) / 1e6


def mb(r):
    return r["rss"] / 2 ** 20 if ok(r) else None


def report(results, args):
    queries = results[0]["queries"] if results else args.queries
    print()
    print(f"Model.shape_functions(points, kind='sibson') vs scipy Delaunay.find_simplex + "
          f"transform; {fmt_n(queries)} uniformly random query points (unsorted); "
          "rates in M points/s from median times")
    first = next((r[k] for r in results for k in ("1T", "2T") if ok(r[k])), None)
    if first:
        print(f"numba warmed up in each cnem child (tiny model of the same domain, shape functions "
              f"at {WARMUP_POINTS} points) before timing: compile time excluded "
              f"(warm-up {first['warmup']:.2f} s)")
    print(f"setup = first call on a model ({SETUP_POINTS} points: builds the cached R-tree of the "
          f"circumcircles), excluded from the rates; discretize timed apart, not counted")
    marks = any(ok(r[k]) and not r[k]["reset"] for r in results for k in ("1T", "2T"))
    print("peak MB = VmHWM of the measurement's own fresh child; cnem: reset after discretize "
          "(model + points + shape-function calls)" + ("; * = not reset, whole child" if marks
                                                       else "") +
          "; scipy: whole child")
    print()
    head = (f"{'domain':<8} {'n':>5} {'nodes':>8} {'rep':>5} | {'discr s':>7} {'setup s':>7} | "
            f"{'1T':>7} {f'{TARGET_THREADS}T':>7} {'2T/1T':>6} | {'Delny s':>7} {'sc setup':>8} "
            f"{'scipy':>7} | {'CGAL':>7} {'1T/CGAL':>7} | "
            f"{'2T/scipy':>8} | {'1T MB':>6} {'2T MB':>6} {'sc MB':>6}")
    print(head)
    print("-" * len(head))
    for r in results:
        c1, c2, sc = r["1T"], r["2T"], r["scipy"]
        ref = c1 if ok(c1) else c2 if ok(c2) else None
        r1, r2, rs = rate(c1, queries), rate(c2, queries), rate(sc, queries)
        rc = rate(r["cgal"], queries)
        n_nodes = ref["n_nodes"] if ref else (sc["n_nodes"] if ok(sc) else None)
        disc = median([c["discretize"] for c in (c1, c2) if ok(c)]) if ref else None
        setup = median([c["setup"] for c in (c1, c2) if ok(c)]) if ref else None
        rep = f"{r['repeat']}/{len(sc['runs'])}" if ok(sc) else f"{r['repeat']}"

        def mbc(c):
            if not ok(c):
                return f"{'-':>6}"
            return f"{mb(c):5.0f}" + (" " if c["reset"] else "*")
        print(f"{r['domain']:<8} {fmt_n(r['n']):>5} {cell(n_nodes, '{:8d}')} {rep:>5} | "
              f"{cell(disc, '{:7.2f}', 7)} {cell(setup, '{:7.3f}', 7)} | "
              f"{cell(r1, '{:7.3f}', 7)} {cell(r2, '{:7.3f}', 7)} "
              f"{cell(r2 / r1 if r1 and r2 else None, '{:5.2f}x', 6)} | "
              f"{cell(median(sc['builds']) if ok(sc) else None, '{:7.2f}', 7)} "
              f"{cell(sc['setup'] if ok(sc) else None, '{:8.3f}', 8)} "
              f"{cell(rs, '{:7.3f}', 7)} | {cell(rc, '{:7.3f}', 7)} "
              f"{cell(r1 / rc if r1 and rc else None, '{:6.2f}x', 7)} | "
              f"{cell(r2 / rs if r2 and rs else None, '{:7.2f}x', 8)} | "
              f"{mbc(c1)} {mbc(c2)} {cell(mb(sc), '{:6.0f}', 6)}")
    print()
    print("columns: n = requested nodes (h = 1/sqrt(n)); nodes = model nodes (crack faces "
          "duplicated); rep = cnem repeats / scipy query runs done;")
    print("         discr s = discretize wall time (median over the cnem children, default "
          "threads); setup s = first call on 10 points (median over the cnem children);")
    print(f"         1T, {TARGET_THREADS}T = shape_functions rate with numba.set_num_threads(1), "
          f"({TARGET_THREADS}); Delny s = scipy.spatial.Delaunay(model.nodes), timed apart;")
    print("         sc setup = scipy's first query on 10 points (computes tri.transform), "
          "excluded from its rate;")
    print("         scipy = find_simplex + transform barycentric weights rate (single-threaded); "
          f"2T/scipy = our {TARGET_THREADS}-thread rate / scipy's ('-' = not run)")
    print("         CGAL = natural_neighbor_coordinates_2 (Sibson) on a Delaunay_triangulation_2 "
          "of the same nodes, C++, 1 thread, queries")
    print("                Hilbert-sorted (sort counted), previous face as the hint, CSR in "
          "input order; Delaunay build apart; square only;")
    print("         1T/CGAL = our 1-thread rate / CGAL's (measured in this run)")

    print()
    print("details:")
    for r in results:
        parts = []
        for key in ("1T", "2T"):
            c = r[key]
            if ok(c):
                parts.append(f"{key}: median {median(c['runs']):.3f} s (runs "
                             + ", ".join(f"{t:.3f}" for t in c["runs"]) + "; CPU "
                             + ", ".join(f"{t:.3f}" for t in c["cpu_runs"]) +
                             f"), numba threads {c['numba_threads']}, {c['n_tri']} triangles, "
                             f"{c['nnz'] / r['queries']:.2f} natural neighbours per point, "
                             f"discretize {c['discretize']:.2f} s / peak "
                             f"{c['rss_disc'] / 2**20:.0f} MB, warm-up {c['warmup']:.2f} s")
            elif c is not None:
                parts.append(f"{key}: {c.get('skipped') or c.get('error')}")
        sc = r["scipy"]
        if ok(sc):
            parts.append(f"scipy: Delaunay {sc['n_tri']} triangles, builds "
                         + ", ".join(f"{t:.2f}" for t in sc["builds"]) + " s; setup (first "
                         f"query on {SETUP_POINTS} points: computes tri.transform) "
                         f"{sc['setup']:.3f} s; query runs "
                         + ", ".join(f"{t:.3f}" for t in sc["runs"]) + " s")
        else:
            parts.append(f"scipy: {sc.get('error')}")
        cg = r["cgal"]
        if ok(cg):
            parts.append(f"CGAL: Delaunay {cg['n_vertices']} vertices built in "
                         f"{cg['build']:.2f} s; "
                         "runs " + ", ".join(f"{t:.3f}" for t in cg["runs"]) + " s (CPU "
                         + ", ".join(f"{t:.3f}" for t in cg["cpu_runs"]) + "); "
                         f"{cg['nnz'] / r['queries']:.2f} natural neighbours per point; peak "
                         f"{cg['rss'] / 2**20:.0f} MB (whole driver)")
        else:
            parts.append(f"CGAL: {cg.get('skipped') or cg.get('error')}")
        parts.append("machine during the size: " + r["load"])
        print(f"  {r['domain']} {fmt_n(r['n'])}: " + ";\n    ".join(parts))

    print()
    print("checks:")
    for r in results:
        c1, c2, sc = r["1T"], r["2T"], r["scipy"]
        line, good = [], True
        ch = c1.get("check") if ok(c1) else None
        if ch:
            g = ch["sum_err"] <= CHECK_TOL and ch["rep_err"] <= CHECK_TOL
            good &= g
            line.append(f"on all {ch['points']} query points max |row sum - 1| = "
                        f"{ch['sum_err']:.1e}, max |Phi @ nodes - points| = {ch['rep_err']:.1e} "
                        f"(<= {CHECK_TOL:g}: {'yes' if g else 'NO'})")
        for key in ("1T", "2T"):
            if ok(r[key]):
                nonneg = r[key]["vmin"] >= 0.0
                good &= nonneg
                line.append(f"{key} min value {r[key]['vmin']:.1e}"
                            f"{'' if nonneg else ' (NEGATIVE)'}")
        if ok(c1) and ok(c2):
            same = c1["fingerprint"] == c2["fingerprint"]
            good &= same
            line.append(f"1T and 2T results {'identical' if same else 'DIFFERENT'} (fingerprint)")
        if ok(sc):
            g = sc["outside"] == 0 and sc["rep_err"] is not None and sc["rep_err"] <= 1e-12
            good &= g
            line.append(f"scipy: {sc['outside']} points outside, barycentric reproduction "
                        f"{sc['rep_err']:.1e}")
        cg = r["cgal"]
        if ok(cg):
            g = cg["outside"] == 0 and cg["diff"] <= CHECK_TOL
            good &= g
            line.append(f"CGAL: {cg['outside']} points outside, max |cnem - CGAL| = "
                        f"{cg['diff']:.1e} (<= {CHECK_TOL:g}: {'yes' if g else 'NO'}), "
                        f"CGAL max |row sum - 1| = {cg['sum_err']:.1e}")
        if not line:
            continue
        print(f"  {r['domain']} {fmt_n(r['n'])}: {'OK' if good else 'FAILED'}: "
              + ";\n    ".join(line))

    measured = [r for r in results if ok(r["cgal"])]
    if measured:
        print()
        print("target (issue): cnem at 1 thread >= CGAL at 1 thread (same run, same nodes and "
              "queries) at 100k and 1M nodes:")
        for r in measured:
            r1, rc = rate(r["1T"], queries), rate(r["cgal"], queries)
            judged = (f"-> {verdict(r1 >= rc)}" if r["n"] in CGAL_TARGET_SIZES
                      else "(not a target size)") if r1 else ""
            print(f"  {r['domain']:<8} {fmt_n(r['n']):>5}: " +
                  (f"{r1:.3f} vs {rc:.3f} M points/s, {r1 / rc:.2f}x {judged}"
                   if r1 else "cnem 1T not run"))
            if r1:
                c1, cc = median(r["1T"]["cpu_runs"]), median(r["cgal"]["cpu_runs"])
                print(f"  {'':<8} {'':>5}  by CPU time per run (less sensitive to a busy "
                      f"machine): cnem 1T {c1:.3f} s, CGAL {cc:.3f} s, {cc / c1:.2f}x")
    else:
        anchors(results, queries)
    watson(results, queries)
    targets(results, queries)


def anchors(results, queries):
    """The CGAL rates recorded in the earlier issue, printed when CGAL was not run here."""
    print()
    here = "" if queries == TARGET_QUERIES else f", measured here with {fmt_n(queries)} queries"
    print(f"anchors from the issue (this machine, 1M random queries; C++/numba, unconstrained: "
          f"compared with our square-domain rates{here}):")
    sq = {r["n"]: r for r in results if r["domain"] == "square"}
    head = (f"  {'nodes':>5} | {'CGAL rnd':>8} {'CGAL srt':>8} | {'ours 1T':>7} "
            f"{f'ours {TARGET_THREADS}T':>7} | {'2T/CGAL rnd':>11} {'2T/CGAL srt':>11}")
    print(head)
    print("  " + "-" * (len(head) - 2))
    for n, a_rnd, a_srt in CGAL_ANCHORS:
        r = sq.get(n)
        r1 = rate(r["1T"], queries) if r else None
        r2 = rate(r["2T"], queries) if r else None
        note = "" if r else "  (not run)"
        if n == 100_000:
            note += f"  (CGAL sorted: + {CGAL_SORT_SECONDS:g} s Hilbert sort of the queries)"
        print(f"  {fmt_n(n):>5} | {cell(a_rnd, '{:8.2f}')} {cell(a_srt, '{:8.2f}')} | "
              f"{cell(r1, '{:7.3f}', 7)} {cell(r2, '{:7.3f}', 7)} | "
              f"{cell(r2 / a_rnd if r2 and a_rnd else None, '{:10.2f}x', 11)} "
              f"{cell(r2 / a_srt if r2 and a_srt else None, '{:10.2f}x', 11)}{note}")
    print("  CGAL columns: rnd = random query order, srt = Hilbert-sorted queries each starting "
          "from the previous face; M points/s")


def watson(results, queries):
    """The plain numba Watson kernel's recorded rates beside ours."""
    sq = {r["n"]: r for r in results if r["domain"] == "square"}
    wn, w_rnd, w_srt = WATSON_ANCHOR
    r = sq.get(wn)
    r2 = rate(r["2T"], queries) if r else None
    print(f"  plain numba Watson kernel ({TARGET_THREADS} threads, cavity-boundary sum): "
          f"{w_rnd:g} random, {w_srt:g} sorted; ours {TARGET_THREADS}T at {fmt_n(wn)}: "
          + (f"{r2:.3f} ({r2 / w_rnd:.2f}x random, {r2 / w_srt:.2f}x sorted)" if r2
             else "(not run)"))


def targets(results, queries):
    """The earlier issue's two-thread and gradient targets."""
    print()
    print("target (issue): >= 2 M points/s with two threads on 100k nodes for 1M random "
          "(unsorted) query points, sorting included, Sibson values only:")
    any_target = False
    for r in results:
        if r["n"] != TARGET_N:
            continue
        any_target = True
        r2 = rate(r["2T"], queries)
        caveat = "" if queries == TARGET_QUERIES else \
            f"  (measured with {fmt_n(queries)} queries, not {fmt_n(TARGET_QUERIES)}: indicative)"
        print(f"  {r['domain']:<8} {TARGET_THREADS}T at {fmt_n(TARGET_N)}: "
              + (f"{r2:.3f} M points/s -> {verdict(r2 >= TARGET_RATE)}" if r2 else "not run")
              + caveat)
    if not any_target:
        print(f"  ({fmt_n(TARGET_N)} nodes not run: target not evaluated)")
    print(f"companion target (issue): values and gradients no more than 2x slower than values "
          f"only ({TARGET_THREADS}T, same points):")
    for r in results:
        c2 = r["2T"]
        if ok(c2) and c2.get("grad_runs"):
            ratio = median(c2["grad_runs"]) / median(c2["runs"])
            print(f"  {r['domain']:<8} {fmt_n(r['n']):>5}: {median(c2['grad_runs']):.3f} s vs "
                  f"{median(c2['runs']):.3f} s, {ratio:.2f}x -> {verdict(ratio <= 2.0)}")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true",
                        help=f"CI smoke run: {fmt_n(QUICK_SIZE)} nodes, {fmt_n(QUICK_QUERIES)} "
                             f"queries, the {QUICK_DOMAIN} domain only")
    parser.add_argument("--sizes", type=int, nargs="+", metavar="N",
                        help="node counts (default 10000 100000 1000000)")
    parser.add_argument("--queries", type=int, default=None,
                        help=f"query points (default {DEFAULT_QUERIES})")
    parser.add_argument("--repeat", type=int, default=3,
                        help="timed repetitions per measurement (default 3)")
    parser.add_argument("--domains", nargs="+", choices=list(DOMAINS), default=None,
                        help="domains (default: square cracked)")
    parser.add_argument("--baseline-budget", type=float, default=60.0, metavar="S",
                        help="stop repeating a scipy timing once its runs total S seconds "
                             "(default 60; at least one run)")
    parser.add_argument("--no-cgal", action="store_true",
                        help="skip the CGAL column even when g++ and CGAL's headers are found")
    args = parser.parse_args(argv)

    if args.sizes:
        sizes = sorted(set(args.sizes))
    elif args.quick:
        sizes = [QUICK_SIZE]
    else:
        sizes = list(DEFAULT_SIZES)
    queries = args.queries or (QUICK_QUERIES if args.quick else DEFAULT_QUERIES)
    args.queries = queries
    domains = args.domains or ([QUICK_DOMAIN] if args.quick else list(DOMAINS))
    repeat = max(1, args.repeat)

    import scipy
    print(f"benchmarks/shape_functions.py: domains {domains}, sizes "
          f"{[fmt_n(n) for n in sizes]}, {fmt_n(queries)} queries, repeat {repeat}; "
          f"python {sys.version.split()[0]}, numpy {np.__version__}, scipy {scipy.__version__}, "
          f"{os.cpu_count()} CPUs")
    cgal = cgal_coordinates.build() if "square" in domains and not args.no_cgal else \
        dict(skipped="CGAL column not requested (--no-cgal or no square domain)")
    if "exe" in cgal:
        print(f"CGAL {cgal['cgal']} driver: {cgal['exe']} ("
              + (f"compiled in {cgal['compile_s']:.1f} s" if cgal["compile_s"] else "cached")
              + ")")
    else:
        print(cgal["skipped"])
    machine = MachineLoad()
    print(f"load average before {load_text(machine.before.load)} (a shared machine: compare "
          "rates within one run)")
    with tempfile.TemporaryDirectory() as tmp:
        results = run(domains, sizes, queries, repeat, args.baseline_budget, tmp, cgal)
    report(results, args)
    print("\n" + machine.stop().report())
    return results


if __name__ == "__main__":
    main()
