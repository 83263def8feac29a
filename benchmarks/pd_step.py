"""Benchmark: peridynamic setup (``cnem.pd.Body`` + ``Problem``) and the explicit bond-based step.

Workload
--------
Square and cubic lattices of spacing ``h`` filling the unit square / cube (``k`` points per
side, ``h = 1 / (k - 1)``), volumes ``h^2`` (2-D, thickness 1) or ``h^3`` (3-D), horizon
``3.015 h`` (delta = 3h: 28 members per interior point in 2-D, 122 in 3-D), material
``cnem.pd.BondBased(1.0)``.  Cases (default): 2-D 100k (316^2) and 1M (1000^2) points, 3-D 1M
(100^3); ``--quick``: 2-D 20k (141^2) only.

What is measured
----------------
Everything runs in this one process, one case after the other (each case's arrays are freed
before the next).  Before the first case a warm-up runs every stage once on tiny 2-D and 3-D
lattices (numba compile or cache load excluded; its time is printed).  The load average at
the start and numba's threading layer are printed too: on a busy machine the "omp" layer's
spinning workers (GNU OpenMP's default wait policy) can make two threads slower than one
(``OMP_WAIT_POLICY=PASSIVE`` or ``NUMBA_THREADING_LAYER=workqueue`` avoid that penalty).

* ``fam s``: ``cnem.spatial.family_search(points, horizon)`` alone (``method="auto"``).
* ``setup s``: ``cnem.pd.Body(points, volumes, horizon)`` (family search, bond geometry,
  partial-volume factors) + ``cnem.pd.Problem(body, BondBased(1.0))`` (surface correction on:
  extension operator A, then the energy-method correction).  The Problem is built through a
  subclass whose only change is to time its ``_correction`` call, so the details split the
  Problem into operators and correction at no extra cost.  Setup timings are medians over
  ``--setup-repeat`` runs (default 3 below 1M points, 1 at 1M), each from scratch.
* ``kernel s/step``: ``cnem.pd._pmb_kernels.pmb_forces`` -- the force loop of
  ``Problem.run_dynamic`` -- called with the arrays of the Body, the per-bond stiffness
  ``bond_stiffness * factor * beta`` that ``run_dynamic`` passes, every bond alive
  (uint8 ones), ``limit = inf`` (no breaks) and a random displacement field
  ``u = 1e-4 h * U(-1, 1)`` (seed 0), under ``numba.set_num_threads(1)`` and ``(2)``: one
  warm-up call, then the median over ``--repeat`` (default 5) calls.
  ``Mbond/s`` = bonds / (s/step) / 1e6 (bond updates per second).
* ``numpy s/step``: the same force loop vectorised in NumPy (``numpy_forces``: bond vectors
  ``y = xi + u[j] - u[i]``, stretch, force per bond, ``np.bincount`` per component into the
  points), one warm-up call then the median over ``--repeat``; its forces are compared with
  the kernel's (``max |F_np - F_kernel| / max |F_kernel|``, printed).
  ``speed-up`` = NumPy s/step / kernel (2 threads) s/step.

* ``stream``: the memory-bandwidth bound (``benchmarks/_bandwidth.py``): a read kernel
  over the step's own bond arrays (lengths, partner indices, stiffness, alive flags:
  what the force loop must read every step; the reference bond vectors come from the
  points, read from the caches) and STREAM's triad, at 1 and 2
  threads, medians over ``--repeat`` calls; printed beside the kernel as the bond updates
  per second the read rate allows (read GB/s over bytes per bond) and the 2-thread /
  1-thread speed-up it allows (ratio of the read rates).

Peak memory: the process's high-water RSS (``VmHWM``) is reset before each stage (where
``/proc/self/clear_refs`` allows) and the stage's growth over the RSS at its start is reported
in bytes per bond (``peak GB`` in the table is the whole process during the setup).  On small
cases the growth under-reads: arrays below glibc's mmap threshold (up to 32 MB) reuse heap
memory that earlier stages freed but the process still holds.  Stages
whose estimated need (bytes per bond below, or what an earlier case of the same dimension
measured if larger, times ``MEMORY_MARGIN``) exceeds 80 % of ``MemAvailable`` at that moment
(or ``--mem-limit-gb`` if lower) are skipped with a message: without a Problem the kernel runs with the
uncorrected stiffness ``bond_stiffness * beta`` (same cost), without a Body the case is skipped.

Targets (issues; printed as MET / MISSED, never asserted): >= 500 M bond updates per second
with two threads (bond-based), per case (issue 22; the earlier speed issue asked 150 M); family search + volume / surface corrections
(``setup s``) for 1M points (2-D) under 3 s.

How to run
----------
::

    python benchmarks/pd_step.py                  # 2-D 100k, 2-D 1M, 3-D 1M (minutes, ~20 GB)
    python benchmarks/pd_step.py --quick          # 2-D 20k only, CI smoke run (seconds)
    python benchmarks/pd_step.py --cases 2d-100k 2d-1M --repeat 9
    python benchmarks/pd_step.py --cases 3d-1M --no-numpy
"""
import argparse
import gc
import sys
import time

import numpy as np

import _bandwidth as stream
from _harness import (MachineLoad, load_text, median, mem_available_bytes, memory_limit,
                      memory_skip, peak_rss_bytes, print_targets, reset_peak_rss, warm_median)

HORIZON_FACTOR = 3.015                  # horizon / h (delta = 3h)
DISPLACEMENT = 1e-4                     # |u| ~ DISPLACEMENT * h
CASES = {"2d-20k": (2, 141), "2d-100k": (2, 316), "2d-1M": (2, 1000), "3d-1M": (3, 100)}
DEFAULT_CASES = ["2d-100k", "2d-1M", "3d-1M"]
QUICK_CASES = ["2d-20k"]
WARMUP_SIDE = {2: 12, 3: 8}
THREADS = (1, 2)

TARGET_RATE = 500e6                     # bond updates / s with two threads
TARGET_THREADS = 2
TARGET_SETUP_CASE, TARGET_SETUP_SECONDS = "2d-1M", 3.0

# memory guard: growth of the process's peak RSS per bond during a stage (measured in fresh
# processes on 300^2 and 30^3 lattices, 2.5M / 2.9M bonds: Body 90 / 93, Problem 288 / 453,
# NumPy step 49 / 64; rounded up), MEMORY_MARGIN on top
BYTES_PER_BOND = {
    "body": {2: 100.0, 3: 100.0},       # family CSR, bond_i/j, xi, length, beta + temporaries
    "problem": {2: 300.0, 3: 480.0},    # A (int64 COO -> CSR), unit vectors, correction
    "numpy": {2: 64.0, 3: 80.0},        # gathers u[j], u[i], y, stretch, per-bond forces
}
MEMORY_MARGIN = 1.2


# --------------------------------------------------------------------------- workload


def square_lattice(k, d):
    """The ``k^d`` points of the lattice of spacing ``1 / (k - 1)`` on the unit square / cube."""
    h = 1.0 / (k - 1)
    grid = np.indices((k,) * d, dtype=np.float64).reshape(d, -1).T
    return np.ascontiguousarray(grid * h), h


def members(d):
    """Lattice vectors ``v`` with ``0 < |v| < HORIZON_FACTOR`` (in units of h): interior family size."""
    r = np.arange(-int(HORIZON_FACTOR), int(HORIZON_FACTOR) + 1)
    v = np.stack(np.meshgrid(*[r] * d), axis=-1).reshape(-1, d)
    d2 = (v * v).sum(axis=1)
    return int(((d2 > 0) & (d2 < HORIZON_FACTOR ** 2)).sum())


def numpy_forces(u, body, stiffness):
    """``pmb_forces`` (all bonds alive, none breaking) in vectorised NumPy."""
    n, d = u.shape
    y = body.xi + u[body.bond_j] - u[body.bond_i]
    ly = np.sqrt(np.einsum("bc,bc->b", y, y))
    g = stiffness * (ly / body.length - 1.0) * body.volumes[body.bond_j] / ly
    out = np.empty_like(u)
    for c in range(d):
        out[:, c] = np.bincount(body.bond_i, weights=g * y[:, c], minlength=n)
    return out


def kernel_forces(u, body, stiffness, alive, out):
    from cnem.pd._pmb_kernels import pmb_forces
    pmb_forces(u, body.points, body.image, body.length, body.family.offsets, body.bond_j,
               stiffness, body.volumes, alive, np.inf, out)
    return out


def make_material_class():
    """``cnem.pd.BondBased`` whose behaviour records the wall time of the surface correction
    on its problem (``problem.correction_seconds``; nothing else changes)."""
    from cnem.pd import BondBased
    from cnem.pd.behaviour import BondBehaviour

    class TimedBehaviour(BondBehaviour):
        def correction(self):
            t0 = time.perf_counter()
            out = super().correction()
            self.problem.correction_seconds = time.perf_counter() - t0
            return out

    class TimedBondBased(BondBased):
        def behaviour(self, problem):
            return TimedBehaviour(problem)

    return TimedBondBased


# --------------------------------------------------------------------------- measuring


class Stage:
    """Context: wall time and peak-RSS growth (bytes over the RSS at entry) of one stage."""

    def __enter__(self):
        gc.collect()
        self.reset = reset_peak_rss()
        self.rss0 = peak_rss_bytes()
        self.t0 = time.perf_counter()
        return self

    def __exit__(self, *exc):
        self.seconds = time.perf_counter() - self.t0
        self.peak = peak_rss_bytes()
        self.growth = self.peak - self.rss0
        return False


def timed_calls(fn, repeat):
    """One warm-up call, then ``repeat`` timed calls: (median seconds, last result, growth)."""
    with Stage() as st:
        seconds, out = warm_median(fn, repeat)
    return seconds, out, st.growth


def setup(points, volumes, horizon, material_class, with_problem):
    """Body (+ Problem) once: times, peak growths and the objects."""
    import cnem.pd as pd
    with Stage() as sb:
        body = pd.Body(points, volumes, horizon)
    run = dict(body=sb.seconds, body_growth=sb.growth, peak=sb.peak, reset=sb.reset)
    prob = None
    if with_problem:
        with Stage() as sp_:
            prob = pd.Problem(body, material_class(1.0))
        run.update(problem=sp_.seconds, problem_growth=sp_.growth,
                   correction=prob.correction_seconds, peak=max(sb.peak, sp_.peak))
    return run, body, prob


def warm_up(material_class):
    """Every stage once on tiny 2-D and 3-D lattices; seconds."""
    import numba

    from cnem.spatial import family_search
    t0 = time.perf_counter()
    for d, k in WARMUP_SIDE.items():
        pts, h = square_lattice(k, d)
        family_search(pts, HORIZON_FACTOR * h)
        _, body, prob = setup(pts, h ** d, HORIZON_FACTOR * h, material_class, True)
        stiffness = np.ascontiguousarray(prob.bond_stiffness * prob.factor * body.beta)
        u = np.zeros_like(pts)
        alive = np.ones(len(body.bond_j), dtype=np.uint8)
        for t in available_threads():
            numba.set_num_threads(t)
            kernel_forces(u, body, stiffness, alive, np.empty_like(u))
        numpy_forces(u, body, stiffness)
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    return time.perf_counter() - t0


def available_threads():
    import numba
    return [t for t in THREADS if t <= numba.config.NUMBA_NUM_THREADS]


class Guard:
    """Estimated stage needs against the memory limit; learns bytes/bond from measured stages."""

    def __init__(self, limit_bytes):
        self.limit = limit_bytes
        self.per_bond = {k: dict(v) for k, v in BYTES_PER_BOND.items()}

    def current_limit(self):
        """The user's limit or 80 % of the MemAvailable of the moment, whichever is lower."""
        return min(self.limit, memory_limit())

    def describe(self):
        avail = mem_available_bytes()
        user = "" if self.limit == float("inf") else f"--mem-limit-gb {self.limit / 2**30:g}, "
        return (f"{user}80% of MemAvailable (now "
                f"{avail / 2**30 if avail else float('nan'):.1f} GB) at each stage")

    def check(self, stage, d, bonds):
        """None if the stage fits, else the reason to skip it."""
        need = MEMORY_MARGIN * self.per_bond[stage][d] * bonds
        return memory_skip(need, self.current_limit(), digits=".3g",
                           detail=f" ({self.per_bond[stage][d]:.0f} B/bond x "
                                  f"{bonds / 1e6:.3g}M bonds x{MEMORY_MARGIN:g})")

    def learn(self, stage, d, growth, bonds):
        if bonds:
            self.per_bond[stage][d] = max(self.per_bond[stage][d], growth / bonds)


def run_case(name, args, guard, material_class):
    import numba

    import cnem.pd as pd
    from cnem.spatial import family_search
    d, k = CASES[name]
    n = k ** d
    setup_repeat = args.setup_repeat or (3 if n < 1_000_000 else 1)
    r = dict(name=name, d=d, n=n, setup_repeat=setup_repeat, members=members(d))
    est_bonds = r["members"] * n
    print(f"  {name} ({k}^{d} = {n} points):", end="", flush=True)
    points, h = square_lattice(k, d)
    horizon = HORIZON_FACTOR * h
    skip = guard.check("body", d, est_bonds)
    if skip:
        print(" skipped", flush=True)
        r["skipped"] = f"Body {skip}"
        return r

    print(" family search", end="", flush=True)
    fam_times = []
    for _ in range(setup_repeat):
        with Stage() as st:
            fam = family_search(points, horizon)
        fam_times.append(st.seconds)
        r["bonds"] = int(fam.offsets[-1])
        del fam
    r["fam"] = median(fam_times)

    problem_skip = guard.check("problem", d, r["bonds"])
    r["problem_skipped"] = problem_skip
    print(" setup", end="", flush=True)
    runs, body, prob = [], None, None
    for _ in range(setup_repeat):
        body = prob = None
        run, body, prob = setup(points, h ** d, horizon, material_class, not problem_skip)
        runs.append(run)
    bonds = len(body.bond_j)
    r["bonds"] = bonds
    r["family_max"] = int(np.diff(body.family.offsets).max())
    r["reset"] = all(x["reset"] for x in runs)
    r["peak"] = max(x["peak"] for x in runs)
    for key in ("body", "problem", "correction"):
        if key in runs[0]:
            r[key] = median(x[key] for x in runs)
    r["setup"] = r["body"] + r["problem"] if "problem" in r else None
    r["body_growth"] = max(x["body_growth"] for x in runs)
    guard.learn("body", d, r["body_growth"], bonds)
    if prob is not None:
        r["problem_growth"] = max(x["problem_growth"] for x in runs)
        guard.learn("problem", d, r["problem_growth"], bonds)
        stiffness = np.ascontiguousarray(prob.bond_stiffness * prob.factor * body.beta)
    else:
        c = pd.BondBased(1.0).micromodulus(d, "stress", horizon, body.thickness)
        stiffness = np.ascontiguousarray(c * body.beta)
    prob = None
    gc.collect()

    u = DISPLACEMENT * h * np.random.default_rng(0).uniform(-1.0, 1.0, (n, d))
    alive = np.ones(bonds, dtype=np.uint8)
    out = np.empty_like(u)
    r["kernel"] = {}
    for t in available_threads():
        print(f" kernel {t}T", end="", flush=True)
        numba.set_num_threads(t)
        r["kernel"][t], _, _ = timed_calls(
            lambda: kernel_forces(u, body, stiffness, alive, out), args.repeat)
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    r["alive"] = bool(alive.all())
    print(" stream", end="", flush=True)
    r["stream"] = stream.measure((body.length, body.bond_j, stiffness, alive),
                                 available_threads(), args.repeat)

    if args.no_numpy:
        r["numpy_skipped"] = "--no-numpy"
    else:
        r["numpy_skipped"] = guard.check("numpy", d, bonds)
    if not r["numpy_skipped"]:
        print(" numpy", end="", flush=True)
        r["numpy"], f_np, r["numpy_growth"] = timed_calls(
            lambda: numpy_forces(u, body, stiffness), args.repeat)
        guard.learn("numpy", d, r["numpy_growth"], bonds)
        r["rel_diff"] = float(np.abs(f_np - out).max() / np.abs(out).max())
        del f_np
    print(" done", flush=True)
    return r


# --------------------------------------------------------------------------- report


def cell(x, fmt="{:8.4f}", width=8):
    return fmt.format(x) if x is not None else f"{'-':>{width}}"


def rate(r, t):
    s = r.get("kernel", {}).get(t)
    return r["bonds"] / s if s else None


def report_bandwidth(results):
    """The memory-bandwidth bound beside the measured step (see `_bandwidth`)."""
    print("  memory-bandwidth bound (streaming kernels over the step's own bond arrays, "
          "medians of --repeat calls):")
    for r in results:
        if "stream" not in r:
            continue
        st = r["stream"]
        per_bond = st["bytes"] / r["bonds"]
        parts = []
        for t in sorted(k for k in st if k != "bytes"):
            bound = st[t]["read"] * 1e9 / per_bond
            got = rate(r, t)
            parts.append(f"{t}T read {st[t]['read']:.1f} GB/s, triad {st[t]['triad']:.1f} GB/s "
                         f"-> at most {bound / 1e6:.0f} M bond updates/s, measured "
                         f"{got / 1e6:.0f} ({got / bound * 100:.0f} % of the bound)")
        ts = sorted(k for k in st if k != "bytes")
        if len(ts) > 1:
            k1, k2 = r["kernel"][ts[0]], r["kernel"][ts[-1]]
            parts.append(f"{ts[-1]}T/{ts[0]}T speed-up bound (read bandwidth ratio) "
                         f"{st[ts[-1]]['read'] / st[ts[0]]['read']:.2f}x, measured "
                         f"{k1 / k2:.2f}x")
        print(f"    {r['name']}: {per_bond:.0f} bytes per bond streamed; " +
              ";\n      ".join(parts))


def report(results, warm, layer):
    print()
    print(f"peridynamic setup and bond-based explicit step on lattices of spacing h, horizon "
          f"{HORIZON_FACTOR} h, BondBased(1.0), |u| ~ {DISPLACEMENT:g} h, no bond breaks")
    print(f"numba threading layer {layer!r}; warm-up (numba compile / cache load, tiny "
          f"lattices, every stage): {warm:.2f} s; "
          "setup times: medians over the setup repeats (rep); step times: medians over "
          "--repeat calls after one warm-up call")
    print()
    head = (f"{'case':<8} {'points':>8} {'bonds':>10} {'rep':>3} | {'fam s':>7} {'setup s':>8} "
            f"{'peak GB':>7} | {'1T s/step':>9} {'2T s/step':>9} | {'1T Mb/s':>7} "
            f"{'2T Mb/s':>7} | {'np s/step':>9} {'np Mb/s':>7} | {'2T/np':>6}")
    print(head)
    print("-" * len(head))
    for r in results:
        if "skipped" in r:
            print(f"{r['name']:<8} {r['n']:>8d}   skipped: {r['skipped']}")
            continue
        k1, k2 = r["kernel"].get(1), r["kernel"].get(TARGET_THREADS)
        tn = r.get("numpy")
        r1, r2 = rate(r, 1), rate(r, TARGET_THREADS)
        print(f"{r['name']:<8} {r['n']:>8d} {r['bonds']:>10d} {r['setup_repeat']:>3d} | "
              f"{cell(r['fam'], '{:7.3f}', 7)} {cell(r['setup'], '{:8.3f}')} "
              f"{cell(r['peak'] / 2**30, '{:7.2f}', 7)} | "
              f"{cell(k1, '{:9.5f}', 9)} {cell(k2, '{:9.5f}', 9)} | "
              f"{cell(r1 and r1 / 1e6, '{:7.1f}', 7)} {cell(r2 and r2 / 1e6, '{:7.1f}', 7)} | "
              f"{cell(tn, '{:9.5f}', 9)} {cell(tn and r['bonds'] / tn / 1e6, '{:7.1f}', 7)} | "
              f"{cell(tn and k2 and tn / k2, '{:5.1f}x', 6)}")
    print()
    print("columns: fam s = family_search alone; setup s = Body + Problem (surface correction on);")
    print("         peak GB = process VmHWM during the setup; 1T / 2T = numba.set_num_threads(1 / 2);")
    print("         Mb/s = million bond updates per second; np = vectorised NumPy force loop;")
    print("         2T/np = NumPy s/step / kernel 2-thread s/step; '-' = not run (see details)")
    print()
    print("details:")
    for r in results:
        if "skipped" in r:
            continue
        parts = [f"Body {r['body']:.3f} s (family search ~{r['fam']:.3f} + bond geometry and "
                 f"partial volumes ~{r['body'] - r['fam']:.3f})"]
        if r["problem_skipped"]:
            parts.append(f"Problem skipped: {r['problem_skipped']}; kernel run with the "
                         "uncorrected stiffness")
        else:
            parts.append(f"Problem {r['problem']:.3f} s (operators ~"
                         f"{r['problem'] - r['correction']:.3f} + surface correction "
                         f"{r['correction']:.3f})")
        mem = [f"Body +{r['body_growth'] / r['bonds']:.0f}"]
        if "problem_growth" in r:
            mem.append(f"Problem +{r['problem_growth'] / r['bonds']:.0f}")
        if "numpy_growth" in r:
            mem.append(f"NumPy step +{r['numpy_growth'] / r['bonds']:.0f}")
        parts.append("peak RSS growth per bond: " + ", ".join(mem) + " B" +
                     ("" if r["reset"] else " (VmHWM reset unavailable: cumulative)"))
        if r["numpy_skipped"]:
            parts.append(f"NumPy skipped: {r['numpy_skipped']}")
        else:
            parts.append(f"forces NumPy vs kernel: max |F_np - F_k| / max |F_k| = "
                         f"{r['rel_diff']:.2e} ({'OK' if r['rel_diff'] < 1e-10 else 'DIFFERENT'})")
        full = r["family_max"] == r["members"]
        k1, k2 = r["kernel"].get(1), r["kernel"].get(TARGET_THREADS)
        if k1 and k2:
            parts.append(f"kernel {TARGET_THREADS} threads vs 1: {k1 / k2:.2f}x")
        parts.append(f"largest family {r['family_max']} (interior lattice point: "
                     f"{r['members']}{'' if full else ', MISMATCH'}); all bonds alive after the "
                     f"steps: {'yes' if r['alive'] else 'NO'}")
        print(f"  {r['name']}: " + ";\n          ".join(parts))
    report_bandwidth(results)
    missing = [t for t in THREADS if t not in available_threads()]
    if missing:
        print(f"  (numba allows {available_threads()[-1]} thread(s) here: "
              f"{missing} not run)")

    print()
    rows = []
    for r in results:
        r2 = None if "skipped" in r else rate(r, TARGET_THREADS)
        label = (f">= {TARGET_RATE / 1e6:.0f} M bond updates per second with two threads "
                 f"(bond-based), {r['name']}")
        rows.append((label, "not run", None) if r2 is None else
                    (label, f"{r2 / 1e6:.1f} M/s", r2 >= TARGET_RATE))
    by_name = {r["name"]: r for r in results}
    r = by_name.get(TARGET_SETUP_CASE)
    label = f"family search + corrections for 1M points (2-D) under {TARGET_SETUP_SECONDS:g} s"
    if r is None or r.get("setup") is None:
        rows.append((label, f"not evaluated ({TARGET_SETUP_CASE} "
                     + ("not run)" if r is None else "setup incomplete)"), None))
    else:
        rows.append((label, f"{r['setup']:.3f} s", r["setup"] < TARGET_SETUP_SECONDS))
    print_targets(rows)


# --------------------------------------------------------------------------- main


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true",
                        help=f"CI smoke run: {', '.join(QUICK_CASES)} only")
    parser.add_argument("--cases", nargs="+", choices=list(CASES),
                        help=f"cases to run (default {' '.join(DEFAULT_CASES)})")
    parser.add_argument("--repeat", type=int, default=5,
                        help="timed force-loop calls per measurement (default 5)")
    parser.add_argument("--setup-repeat", type=int, default=None,
                        help="setup runs per case (default 3 below 1M points, 1 at 1M)")
    parser.add_argument("--no-numpy", action="store_true", help="skip the NumPy force loop")
    parser.add_argument("--mem-limit-gb", type=float, default=None,
                        help="also skip stages estimated above this many GB "
                             "(always: above 80%% of MemAvailable)")
    args = parser.parse_args(argv)
    cases = args.cases or (QUICK_CASES if args.quick else DEFAULT_CASES)

    import numba
    guard = Guard(float("inf") if args.mem_limit_gb is None else args.mem_limit_gb * 2 ** 30)
    machine = MachineLoad()
    print(f"benchmarks/pd_step.py: cases {cases}; python {sys.version.split()[0]}, numpy "
          f"{np.__version__}, numba {numba.__version__} ({numba.config.NUMBA_NUM_THREADS} "
          f"threads max); memory guard: {guard.describe()}; load "
          f"average {load_text(machine.before.load)} (other processes on the machine slow the "
          "multi-threaded kernel)")
    material_class = make_material_class()
    print("  warm-up", flush=True)
    warm = warm_up(material_class)
    results = []
    for name in cases:
        results.append(run_case(name, args, guard, material_class))
        gc.collect()
    report(results, warm, numba.threading_layer())
    print("\n" + machine.stop().report())
    return results


if __name__ == "__main__":
    main()
