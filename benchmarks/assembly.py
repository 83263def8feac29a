"""Benchmark: C-NEM elasticity (smoothed gradients B~, stiffness K, solve) against scikit-fem P1.

Workload
--------
For each size n (default 10k, 100k and 1M nodes), with ``k = round(sqrt(n))`` nodes per
side, the same plane-strain problem on the unit square (E = 1, nu = 0.3), clamped on
x = 0 (both components), traction (1, 0) on x = 1:

* **C-NEM**: ``cloud = cnem.nodes.irregular(cnem.geometry.rectangle(1.0, 1.0), h=1 / (k - 1),
  seed=0)`` (about k^2 nodes; ``--cloud regular``: exactly the k x k lattice),
  ``cnem.Elasticity(model, (E, nu), plane="strain")``;
* **scikit-fem** (the anchor): ``MeshTri.init_tensor`` on the same k x k lattice (the same
  nodes), ``Basis(mesh, ElementVector(ElementTriP1()))``, ``linear_elasticity(
  *lame_parameters(E, nu))`` (these Lamé parameters are the plane-strain ones, hence
  ``plane="strain"`` on the C-NEM side: both solve the same problem).

What is measured
----------------
Wall times of each stage, median over ``--repeat`` runs (default 1), in this one process,
one side after the other; every run redoes every stage from the node cloud (resp. from
nothing), so nothing cached by one run serves the next:

* C-NEM ``model``: ``cnem.discretize(cloud)``;
* C-NEM ``B~``: the smoothed gradients on the fresh model (which holds only the
  triangle-neighbour table ``discretize`` built), so it includes the once-per-model setup it
  triggers (the circumcircles and their R-tree): ``gradients.fan()`` of a
  ``cnem.assembly.GradientCache(model)`` (B~ of the cells and of their fan sub-cells,
  for the default stabilisation), ``gradients.cells()`` with ``--stabilization 0``;
* C-NEM ``K``: ``Elasticity(..., gradients=gradients).stiffness()`` with the gradients
  already kept by ``gradients``: the cell bases, their operators and the assembly of K;
* skfem ``mesh``, ``basis``, ``K``: ``MeshTri.init_tensor``, ``Basis(...)`` and
  ``asm(linear_elasticity(...), basis)``;
* ``solve`` (both sides, the very same function): ``cnem.solvers.condensation.free_system``
  of the clamped dofs (skfem.condense's system, its matrix multiplied on K itself), the
  rigid-body modes of the free dofs, and ``cnem.solvers.linsolve.solve_spd`` (direct up to
  2.5M non-zeros, smoothed aggregation + CG above: pyamg's set-up, cnem's parallel V-cycle,
  ``cnem.solvers.multigrid``; tol 1e-10; on the C-NEM side the
  hierarchy is built on the P1 stiffness of the same nodes on the model's triangles,
  ``Elasticity.solver_options``, whose assembly is timed in the stage).  This is what
  ``Elasticity.solve`` does after K and the load, minus its rigid-motion check
  (``free_rigid_motions``), which is timed apart and printed in the details;
* ``total``: the sum of a run's stages (load vectors and dof selection are not timed).

Both sides first run once on a tiny problem, C-NEM twice (serial and parallel copies of
its kernels, ``_harness.warm_both``), with the iterative solver forced
(``cnem.config.DIRECT_NNZ = 0``) so that its kernels compile too: numba JIT compile and
first-call costs are excluded from the timings.  Peak memory is the process's high-water resident set size
(``VmHWM``), reset (``echo 5 > /proc/self/clear_refs``) before every stage: the peak of a
side is the largest of its stages', i.e. the whole process (interpreter, imports, the node
cloud or mesh, whatever is live) while that side runs; the details give every stage's.
Where the reset is not available the figures are cumulative and marked so.

The sides run in this process, so running out of memory would end the benchmark (and
strain a shared machine): before each side and size a guard compares ``MemAvailable`` with
the estimated need (see ``memory_need``: extrapolated from the largest size already run on
that side, or a default per node, times a safety margin) and skips it with a message when
it does not fit (``--no-memory-check`` disables it).

Checks (printed): no rigid motion left free, K symmetric, and the mean x-displacement of the
nodes on x = 1 on both sides (they should agree to about the discretisation error).

Targets: C-NEM (B~ + K) within 3x of scikit-fem (basis + K) at 100k nodes (issue 2); the
1M C-NEM total at most 60 s with peak memory at most 6 GB (issue 22).  Printed, never
asserted.

How to run
----------
::

    python benchmarks/assembly.py                  # 10k, 100k, 1M (minutes, several GB)
    python benchmarks/assembly.py --quick          # 2k and 10k, smoke run (seconds)
    python benchmarks/assembly.py --sizes 100000 --repeat 3
    python benchmarks/assembly.py --skip-fem-above 100000
"""
import argparse
import gc
import sys
import time

import numpy as np

from _harness import (MachineLoad, fmt_n, load_text, mem_available_bytes, median, memory_skip,
                      peak_rss_bytes, print_targets, reset_peak_rss, warm_both)

E, NU, PLANE = 1.0, 0.3, "strain"
TRACTION = (1.0, 0.0)
EDGE_TOL = 1e-9
WARMUP_SIDE = 11
DEFAULT_SIZES = [10_000, 100_000, 1_000_000]
QUICK_SIZES = [2_000, 10_000]

TARGET_RATIO_AT, TARGET_RATIO = 100_000, 3.0
TARGET_1M, TARGET_1M_SECONDS, TARGET_1M_GB = 1_000_000, 60.0, 6.0

# memory guard (see memory_need): bytes per node and base RSS when no size has been run yet
# on a side; safety margin; growth exponent of the sparse direct solver's memory; memory of
# the free system + pyamg's hierarchy per byte of K (CSR, 12 bytes a non-zero)
DEFAULT_BYTES_PER_NODE = {"cnem": 12_000, "skfem": 6_000}
DEFAULT_BASE_BYTES = 0.3 * 2**30
MEMORY_MARGIN = 1.3
DIRECT_MEMORY_EXPONENT = 1.5
AMG_BYTES_PER_K_BYTE = 4.0
STAGES = {"cnem": ("model", "B~", "K", "solve"), "skfem": ("mesh", "basis", "K", "solve")}
LABELS = {"cnem": "C-NEM", "skfem": "skfem"}


# --------------------------------------------------------------------------- shared


def side_count(n):
    """Nodes per side of the k x k lattice standing for n nodes."""
    return max(3, int(round(np.sqrt(n))))


def clamped_dofs(points):
    """Both dofs (interleaved numbering) of every node on x = 0."""
    nodes = np.flatnonzero(points[:, 0] <= EDGE_TOL)
    return np.column_stack([2 * nodes, 2 * nodes + 1]).reshape(-1)


def condensed_solve(K, f, points, D, solver_options=None):
    """What both sides time as ``solve``: the free system, rigid modes of the free dofs, solve_spd
    (C-NEM: with ``solver_options(free dofs)``, ``Elasticity.solver_options``: the P1
    matrix its smoothed aggregation is built on, as in ``Elasticity.solve``)."""
    from cnem.solvers.condensation import free_system
    from cnem.solvers.linsolve import rigid_modes, solve_spd

    x = np.zeros(K.shape[0])
    A, b, interior = free_system(K, f, x=x, D=D)
    options = {} if solver_options is None else solver_options(interior)
    x[interior] = solve_spd(A, b, modes=rigid_modes(points)[interior], **options)
    return x


def tip_displacement(points, x):
    """Mean x-displacement of the nodes on x = 1."""
    return float(x[0::2][points[:, 0] >= 1.0 - EDGE_TOL].mean())


def staged(run, stage, fn):
    """Call ``fn()`` as stage ``stage`` of ``run``: wall time and the process peak during it."""
    reset_peak_rss()
    t0 = time.perf_counter()
    out = fn()
    run["time"][stage] = time.perf_counter() - t0
    run["peak"][stage] = peak_rss_bytes()
    return out



def symmetry_error(K):
    return float(abs(K - K.T).max() / abs(K).max())


# --------------------------------------------------------------------------- the two sides


#: C-NEM node cloud: "irregular" (default) or "regular" (set by --cloud), and the
#: weight of the sub-cell stabilisation (--stabilization; 0 = the paper's plain SCNI).
CLOUD = {"kind": "irregular", "stabilization": 1.0}


def lattice_cloud(k):
    """The C-NEM node cloud: the k x k lattice of the unit square (``--cloud regular``),
    or an irregular cloud of the same spacing (``cnem.nodes.irregular``, seed 0; about
    k^2 nodes). On the exact lattice every Delaunay circle holds four nodes (a degenerate
    case for natural neighbours, with sparser SCNI rows), so the irregular cloud is the
    representative case."""
    import cnem

    dom = cnem.geometry.rectangle(1.0, 1.0)
    if CLOUD["kind"] == "regular":
        return cnem.nodes.regular(dom, 1.0 / (k - 1))
    return cnem.nodes.irregular(dom, 1.0 / (k - 1), seed=0)


def cnem_pipeline(cloud, run):
    """C-NEM from the cloud: model, B~, K, rigid-motion check, solve (timed into ``run``)."""
    import cnem
    from cnem.assembly import GradientCache
    from cnem.solvers.linsolve import free_rigid_motions

    model = staged(run, "model", lambda: cnem.discretize(cloud, progress=False))
    # the smoothed gradients Elasticity needs: with the stabilisation those of the fan
    # sub-cells too, computed with the cells' (one set of shape-function values)
    gradients = GradientCache(model)
    staged(run, "B~", lambda: gradients.fan() if CLOUD["stabilization"] > 0
           else gradients.cells())
    grad = gradients.cells()
    points = gradients.fan()[1].points if CLOUD["stabilization"] > 0 else grad.points
    prob = cnem.Elasticity(model, (E, NU), plane=PLANE, stabilization=CLOUD["stabilization"],
                           gradients=gradients)
    K = staged(run, "K", prob.stiffness)
    prob.add_traction(lambda x, nrm: nrm[:, 0] > 0.5, list(TRACTION))
    f, D = prob.load(), clamped_dofs(model.nodes)
    t0 = time.perf_counter()
    free = free_rigid_motions(K, model.nodes, D)
    run["check"] = time.perf_counter() - t0
    x = staged(run, "solve", lambda: condensed_solve(K, f, model.nodes, D,
                                                     prob.solver_options))
    return dict(nodes=len(model.nodes), cells=len(model.cells), quad=points,
                grad_nnz=int(grad.x.nnz), K_nnz=int(K.nnz), dofs=K.shape[0], free=free,
                sym=symmetry_error(K), tip=tip_displacement(model.nodes, x))


def skfem_pipeline(k, run):
    """scikit-fem P1 on the k x k lattice: mesh, basis, K, solve (timed into ``run``)."""
    from skfem import (Basis, ElementTriP1, ElementVector, FacetBasis, LinearForm, MeshTri,
                       asm)
    from skfem.models.elasticity import lame_parameters, linear_elasticity

    @LinearForm
    def traction(v, w):
        return TRACTION[0] * v[0] + TRACTION[1] * v[1]

    line = np.linspace(0.0, 1.0, k)
    mesh = staged(run, "mesh", lambda: MeshTri.init_tensor(line, line))
    basis = staged(run, "basis", lambda: Basis(mesh, ElementVector(ElementTriP1())))
    K = staged(run, "K", lambda: asm(linear_elasticity(*lame_parameters(E, NU)), basis))
    right = mesh.facets_satisfying(lambda p: p[0] >= 1.0 - EDGE_TOL)
    f = asm(traction, FacetBasis(mesh, basis.elem, facets=right))
    points = mesh.p.T
    x = staged(run, "solve", lambda: condensed_solve(K, f, points, clamped_dofs(points)))
    return dict(nodes=mesh.p.shape[1], cells=mesh.t.shape[1], K_nnz=int(K.nnz),
                dofs=K.shape[0], sym=symmetry_error(K), tip=tip_displacement(points, x))


def measure(side, n, repeat):
    """``repeat`` runs of a side at n nodes in this process, each from scratch.

    The C-NEM cloud is built once, untimed; every run rebuilds everything else. The side's
    peak is the largest of its stages' (VmHWM is reset before each).
    """
    k = side_count(n)
    arg = lattice_cloud(k) if side == "cnem" else k
    gc.collect()
    reset = reset_peak_rss()
    rss_before = peak_rss_bytes()
    runs, facts = [], None
    for _ in range(repeat):
        facts = None
        gc.collect()
        run = dict(time={}, peak={})
        facts = PIPELINES[side](arg, run)
        runs.append(run)
    rss = max(p for run in runs for p in run["peak"].values())
    return dict(facts, runs=runs, rss_before=rss_before, rss=rss, reset=reset)


PIPELINES = {"cnem": cnem_pipeline, "skfem": skfem_pipeline}


def warm_up():
    """Both sides once on a tiny problem, the iterative solver forced (numba compile, first
    calls); seconds per side."""
    from cnem import config

    times, direct_nnz = {}, config.DIRECT_NNZ
    config.DIRECT_NNZ = 0
    try:
        for side in PIPELINES:
            t0 = time.perf_counter()
            warm_both(lambda: measure(side, WARMUP_SIDE ** 2, 1))
            times[side] = time.perf_counter() - t0
    finally:
        config.DIRECT_NNZ = direct_nnz
    return times


def ok(r):
    return r is not None and "error" not in r and "skipped" not in r


# --------------------------------------------------------------------------- driver


def solver(nnz):
    """The method `solve_spd` picks for a matrix with ``nnz`` non-zeros."""
    from cnem import config
    return "direct" if nnz <= config.DIRECT_NNZ else "amg"


def memory_need(side, n, done):
    """Estimated peak bytes of a side at n nodes, and where the estimate comes from.

    From the largest size already run on that side: its RSS before the runs plus its stages'
    growth over it scaled to n nodes, linearly for discretisation and assembly, with
    ``DIRECT_MEMORY_EXPONENT`` for a direct solve (fill-in); where the solver switches from
    direct to pyamg, the K stage's growth plus ``AMG_BYTES_PER_K_BYTE`` times K's bytes.
    """
    nodes = side_count(n) ** 2
    measured = [r for r in done if ok(r[side])]
    if not measured:
        per_node = DEFAULT_BYTES_PER_NODE[side]
        return (DEFAULT_BASE_BYTES + MEMORY_MARGIN * per_node * nodes,
                f"default {per_node / 1e3:.0f} kB/node")
    last = max(measured, key=lambda r: r["n"])[side]
    scale = nodes / last["nodes"]
    grow = {s: max(run["peak"][s] for run in last["runs"]) - last["rss_before"]
            for s in STAGES[side]}
    assembly = scale * max(grow[s] for s in STAGES[side][:3])
    method, was = solver(scale * last["K_nnz"]), solver(last["K_nnz"])
    if method == was:
        solve = grow["solve"] * scale ** (DIRECT_MEMORY_EXPONENT if method == "direct" else 1.0)
    else:
        solve = scale * (grow["K"] + AMG_BYTES_PER_K_BYTE * 12 * last["K_nnz"])
    return (last["rss_before"] + MEMORY_MARGIN * max(assembly, solve),
            f"extrapolated from {last['nodes']} nodes, {method} solve")


def run(sizes, repeat, skip_fem_above, memory_check):
    results = []
    for n in sizes:
        r = dict(n=n, repeat=repeat)
        print(f"  n = {fmt_n(n)} x{repeat}:", end="", flush=True)
        for side in ("cnem", "skfem"):
            if side == "skfem" and skip_fem_above is not None and n > skip_fem_above:
                r[side] = dict(skipped=f"--skip-fem-above {fmt_n(skip_fem_above)}")
                print(f" {side} skipped", end="", flush=True)
                continue
            need, source = memory_need(side, n, results)
            avail = mem_available_bytes()
            short = memory_skip(need, avail if avail is not None else float("inf"),
                                detail=f" ({source}, x{MEMORY_MARGIN:g} margin)")
            if memory_check and short:
                r[side] = dict(skipped=f"not enough memory: {short} (MemAvailable)")
                print(f" {side} SKIPPED (memory)", end="", flush=True)
                continue
            print(f" {side} (est. {need / 2**30:.1f} GB)", end="", flush=True)
            try:
                r[side] = measure(side, n, repeat)
            except Exception as exc:          # noqa: BLE001 - keep the sizes already run
                r[side] = dict(error=f"{type(exc).__name__}: {exc}")
                print(" (FAILED)", end="", flush=True)
            gc.collect()
        print(" done", flush=True)
        results.append(r)
    return results


# --------------------------------------------------------------------------- report


def stage_time(res, stage):
    return median(run["time"][stage] for run in res["runs"]) if ok(res) else None


def total_time(res):
    return median(sum(run["time"].values()) for run in res["runs"]) if ok(res) else None


def assembly_ratio(r):
    cn, fe = r["cnem"], r["skfem"]
    if not (ok(cn) and ok(fe)):
        return None
    return ((stage_time(cn, "B~") + stage_time(cn, "K"))
            / (stage_time(fe, "basis") + stage_time(fe, "K")))


def cell(x, fmt="{:7.3f}", width=7):
    return fmt.format(x) if x is not None else f"{'-':>{width}}"


def gb(res):
    return res["rss"] / 2**30 if ok(res) else None


def describe(side, res):
    """Detail lines of one side's measurement, or why it is missing."""
    label = LABELS[side]
    if res is None:
        return []
    if not ok(res):
        return [f"{label}: {res.get('skipped') or res.get('error')}"]
    if side == "cnem":
        text = (f"{res['cells']} cells, {res['quad'] / res['cells']:.1f} quadrature "
                f"points and {res['grad_nnz'] / res['cells']:.1f} B~ nodes per cell, ")
    else:
        text = f"{res['cells']} triangles, "
    text += f"K {res['dofs']} dofs, {res['K_nnz'] / res['dofs']:.1f} non-zeros per row"
    if side == "cnem":
        text += (f"; rigid-motion check (in Elasticity.solve, not in the table) "
                 f"{median(run['check'] for run in res['runs']):.3f} s")
    return [f"{label}: {text}", f"{label} stage peaks GB: {stage_peaks(res, side)}"]


def report(results, warm):
    print()
    print(f"C-NEM elasticity vs scikit-fem P1 on the unit square, plane {PLANE}, E = {E:g}, "
          f"nu = {NU:g}, clamped on x = 0, traction {TRACTION} on x = 1; median wall times in s")
    print("solve (both sides) = cnem.solvers.condensation.free_system + rigid modes + "
          "cnem.solvers.linsolve.solve_spd "
          "(direct <= 2.5M non-zeros, pyamg + CG above; C-NEM: hierarchy on the P1 matrix of its "
          "triangles, built in the stage): Elasticity.solve's path without its "
          "rigid-motion check (timed in the details)")
    print("B~ = the smoothed gradients on a fresh model (includes the shape-function "
          "setup): GradientCache.fan (cells and their fan sub-cells, one set of points) with "
          "the stabilisation, .cells() without; K = Elasticity.stiffness() from them; "
          "total = sum of the stages")
    import numba
    print(f"warm-up before timing (numba compile, first calls): both sides once on "
          f"{WARMUP_SIDE}x{WARMUP_SIDE} nodes, C-NEM {warm['cnem']:.2f} s, skfem "
          f"{warm['skfem']:.2f} s; numba threads {numba.get_num_threads()}")
    print("peak GB = process VmHWM, reset before each stage, largest over the side's stages "
          "(interpreter + imports + cloud/mesh + live data)")
    print()
    head = (f"{'n':>5} {'nodes':>8} | {'model':>7} {'B~':>7} {'K':>7} {'solve':>7} "
            f"{'total':>7} {'peak GB':>7} | {'mesh':>7} {'basis':>7} {'K':>7} {'solve':>7} "
            f"{'total':>7} {'peak GB':>7} | {'asm ratio':>9} {'tot ratio':>9}")
    print(f"{'':>14} | {'C-NEM':^55} | {'scikit-fem P1':^55} |")
    print(head)
    print("-" * len(head))
    for r in results:
        cn, fe = r["cnem"], r["skfem"]
        nodes = cn["nodes"] if ok(cn) else fe["nodes"] if ok(fe) else None
        cols = [f"{fmt_n(r['n']):>5} {cell(nodes, '{:8d}', 8)}"]
        for side, res in (("cnem", cn), ("skfem", fe)):
            cols.append(" ".join([cell(stage_time(res, s)) for s in STAGES[side]]
                                 + [cell(total_time(res)), cell(gb(res), "{:7.2f}")]))
        ratio = assembly_ratio(r)
        tot = total_time(cn) / total_time(fe) if ok(cn) and ok(fe) else None
        cols.append(f"{cell(ratio, '{:8.2f}x', 9)} {cell(tot, '{:8.2f}x', 9)}")
        print(" | ".join(cols))
    print()
    print("columns: n = requested nodes, nodes = k^2 with k = round(sqrt(n)) per side (the same "
          "nodes on both sides); asm ratio = C-NEM (B~ + K) / skfem (basis + K);")
    print("         tot ratio = C-NEM total / skfem total; '-' = not run")

    print()
    print("details:")
    for r in results:
        lines = describe("cnem", r["cnem"]) + describe("skfem", r["skfem"])
        print(f"  {fmt_n(r['n'])}: " + ";\n    ".join(lines))

    print()
    print("checks:")
    for r in results:
        cn, fe = r["cnem"], r["skfem"]
        line, good = [], True
        if ok(cn):
            good &= not cn["free"] and cn["sym"] < 1e-12
            line.append(f"C-NEM rigid motions left free: {', '.join(cn['free']) or 'none'}, "
                        f"K asymmetry {cn['sym']:.1e}, mean u_x(x=1) {cn['tip']:.6f}")
        if ok(fe):
            good &= fe["sym"] < 1e-12
            line.append(f"skfem K asymmetry {fe['sym']:.1e}, mean u_x(x=1) {fe['tip']:.6f}")
        if ok(cn) and ok(fe):
            rel = abs(cn["tip"] - fe["tip"]) / abs(fe["tip"])
            good &= rel < 1e-2
            line.append(f"relative difference {rel:.1e}")
        if line:
            print(f"  {fmt_n(r['n'])}: {'OK' if good else 'FAILED'}: " + "; ".join(line))

    print()
    by_n = {r["n"]: r for r in results}
    ratio = assembly_ratio(by_n[TARGET_RATIO_AT]) if TARGET_RATIO_AT in by_n else None
    label = (f"C-NEM (B~ + K) within {TARGET_RATIO:g}x of skfem (basis + K) at "
             f"{fmt_n(TARGET_RATIO_AT)}")
    rows = [(label, f"{ratio:.2f}x", ratio <= TARGET_RATIO) if ratio is not None else
            (label, f"({fmt_n(TARGET_RATIO_AT)} not run on both sides)", None)]
    cn = by_n[TARGET_1M]["cnem"] if TARGET_1M in by_n else None
    if ok(cn):
        t, mem = total_time(cn), gb(cn)
        rows.append((f"{fmt_n(TARGET_1M)} C-NEM total at most {TARGET_1M_SECONDS:g} s",
                     f"{t:.1f} s", t <= TARGET_1M_SECONDS))
        rows.append((f"{fmt_n(TARGET_1M)} C-NEM peak memory at most {TARGET_1M_GB:g} GB",
                     f"{mem:.2f} GB", mem <= TARGET_1M_GB))
    else:
        why = (cn.get("skipped") or cn.get("error")) if cn else "not run"
        rows.append((f"{fmt_n(TARGET_1M)} C-NEM total under {TARGET_1M_SECONDS:g} s and peak "
                     f"memory under {TARGET_1M_GB:g} GB", f"({why})", None))
    print_targets(rows)


def stage_peaks(res, side):
    mark = "" if res["reset"] else " (VmHWM reset unavailable: cumulative)"
    return ", ".join(f"{s} {max(run['peak'][s] for run in res['runs']) / 2**30:.2f}"
                     for s in STAGES[side]) + \
        f"; before the runs {res['rss_before'] / 2**30:.2f}" + mark


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true",
                        help=f"smoke run: {', '.join(fmt_n(n) for n in QUICK_SIZES)} nodes")
    parser.add_argument("--sizes", type=int, nargs="+", metavar="N",
                        help="node counts (default 10000 100000 1000000)")
    parser.add_argument("--repeat", type=int, default=1,
                        help="timed runs per size and side (default 1)")
    parser.add_argument("--skip-fem-above", type=int, default=None, metavar="N",
                        help="run the scikit-fem anchor only for sizes up to N")
    parser.add_argument("--no-memory-check", action="store_true",
                        help="run every size even when MemAvailable looks too small")
    parser.add_argument("--cloud", choices=("irregular", "regular"), default="irregular",
                        help="C-NEM node cloud (default irregular)")
    parser.add_argument("--stabilization", type=float, default=1.0,
                        help="sub-cell stabilisation weight of cnem.Elasticity (0: plain SCNI)")
    args = parser.parse_args(argv)
    CLOUD["kind"] = args.cloud
    CLOUD["stabilization"] = args.stabilization

    if args.sizes:
        sizes = sorted(set(args.sizes))
    elif args.quick:
        sizes = list(QUICK_SIZES)
    else:
        sizes = list(DEFAULT_SIZES)
    repeat = max(1, args.repeat)

    import scipy
    import skfem
    machine = MachineLoad()
    print(f"benchmarks/assembly.py: sizes {[fmt_n(n) for n in sizes]}, repeat {repeat}, "
          f"C-NEM cloud {args.cloud}, stabilization {args.stabilization:g}; "
          f"python {sys.version.split()[0]}, numpy {np.__version__}, scipy {scipy.__version__}, "
          f"scikit-fem {skfem.__version__}; load average {load_text(machine.before.load)}")
    warm = warm_up()
    results = run(sizes, repeat, args.skip_fem_above, not args.no_memory_check)
    report(results, warm)
    print("\n" + machine.stop().report())
    return results


if __name__ == "__main__":
    main()
