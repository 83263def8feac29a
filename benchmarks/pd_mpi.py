"""Benchmark: distributed peridynamics (``cnem.pd.distributed``) on 1 and 2 MPI ranks
against the threaded serial code, with a projection to cluster sizes.

Workload
--------
Lattices of spacing ``h`` on the unit square / cube (``k`` points per side), volumes
``h^d``, horizon ``3.015 h``, ``BondBased(1.0)`` (surface correction on, no bond
breaking), a random initial velocity (seed 0). Cases: 2-D 1M points (1000^2, ~28M bonds)
and 3-D 1M points (100^3, ~122M bonds); ``--quick``: 2-D 40k (200^2).

What is measured (each configuration in a fresh process, one after the other)
-------------------------------------------------------------------------------
* ``serial 2T``: ``cnem.pd.Body`` + ``cnem.pd.Problem`` with numba at 2 threads;
* ``1 rank`` / ``2 ranks``: ``mpiexec -n 1 / 2`` of ``cnem.pd.distributed`` with
  ``NUMBA_NUM_THREADS=OMP_NUM_THREADS=1`` per rank.

``s/step``: the median wall time of one step of ``run_dynamic(dt, S, every=S)``, after an
untimed one-step run (which loads the compiled kernels), the largest over the ranks. The
steps are timed one by one, between the iterations of the run's step loop (its progress
iterator is wrapped by `StepClock`): the run's set-up and its two stored frames stay out.
(The difference ``(T(2 + S) - T(2)) / S`` of two runs' wall times, used before, took the
noise of the runs' set-ups into a few steps: 4.33x for 2 ranks on 2 cores in 3-D.) ``halo``: ghosts over owned points, summed over the ranks.
``bytes/step``: bytes sent by all ranks per step (displacements of the ghosts).
``exch s/step``: wall time inside the halo exchanges per step (rank mean): posting them
and waiting for them after the interior bonds (the part the overlap does not hide). ``peak GB``:
each process's high-water RSS (``VmHWM``, set-up included), the largest rank.

Memory-bandwidth bound: each round also times a read kernel over synthetic bond arrays of
the case's size (``benchmarks/_bandwidth.py``: what the force loop must read each step) in
one single-threaded process, then split between two processes running at once; the ratio of
the rates bounds the 2-rank / 1-rank speed-up of a bandwidth-bound step, printed beside it
with the share of the read rate that one rank's step reaches (measured 2-D 1M with the former
point-by-point kernel, 37 bytes per bond: about 19 %, compute-bound, so two ranks beat that
bound).

Targets (issue; printed MET / MISSED, never asserted): 2 ranks >= 1.8x one rank;
2 ranks >= 0.9x the 2-thread serial code; peak memory per rank <= 0.6x the serial peak.

Projection model (printed table)
--------------------------------
A rank of ``m = N / P`` points computes its bonds in ``t_c = m t_p`` (``t_p``: the
measured 1-rank time per point and step) and exchanges ``g(m) = f m`` ghost values with
``2 d`` neighbours, the ghost fraction of a compact part falling like its surface over
its volume: ``f(m) = f_2 (m_2 / m)^(1/d)`` from the measured 2-rank fraction ``f_2`` at
``m_2 = N_2 / 2``. The exchange costs ``t_x = 2 d alpha + 8 d g(m) / beta`` with a
network latency ``alpha = 5 us`` and the bandwidth ``beta`` measured here (bytes over
exchange time; shared memory, so a cluster network of ~10 GB/s gives a similar order).
Parallel efficiency ``E = t_c / (t_c + t_x)`` (as if no exchange were hidden behind the
interior bonds: a lower bound, the code overlaps them). Beside it: Peridynamics.jl's published thread scaling, 39 % efficiency at 16
threads on 337,500 points.

How to run
----------
::

    python benchmarks/pd_mpi.py              # 2-D 1M and 3-D 1M, 3 interleaved rounds (minutes, ~15 GB)
    python benchmarks/pd_mpi.py --quick      # 2-D 40k, seconds
"""

import argparse
import json
import os
import shutil
import subprocess
import sys
import time

import numpy as np

import _bandwidth as stream
from _harness import (MachineLoad, load_text, median, memory_skip, peak_rss_bytes,
                      print_targets)

HORIZON_FACTOR = 3.015
CASES = {"2d-40k": (2, 200), "2d-1M": (2, 1000), "3d-1M": (3, 100)}
DEFAULT_CASES, QUICK_CASES = ["2d-1M", "3d-1M"], ["2d-40k"]
STEPS = {"2d-40k": 20, "2d-1M": 50, "3d-1M": 10}
#: peak bytes per bond (all processes) of the serial code (Body + Problem + a run: its
#: energy evaluation's temporaries) and of the distributed one, for the memory guard
BYTES_PER_BOND = {"serial": 190.0, "dist": 110.0}
MEMBERS = {2: 28, 3: 122}
ALPHA = 5e-6                            # s, network latency of the projection
JL_EFFICIENCY = (16, 337_500, 0.39)     # Peridynamics.jl: threads, points, efficiency
TARGET_SPEEDUP, TARGET_VS_THREADS, TARGET_MEMORY = 1.8, 0.9, 0.6


def lattice(k, d):
    h = 1.0 / (k - 1)
    grid = np.indices((k,) * d, dtype=np.float64).reshape(d, -1).T
    return np.ascontiguousarray(grid * h), h


class StepClock:
    """Wall times of the steps of a run: the step loop's progress iterator (``tqdm`` of the
    module that runs the loop) replaced, while in the ``with`` block, by one that notes the
    time at each iteration; ``steps`` holds the intervals between them (one per step but the
    last, whose end is the run's final output)."""

    def __init__(self, module):
        self.module, self.steps = module, []

    def __enter__(self):
        self.saved = self.module.tqdm

        def ticking(iterable, **_):
            marks = []
            for item in iterable:
                marks.append(time.perf_counter())
                yield item
            self.steps = list(np.diff(marks))
        self.module.tqdm = ticking
        return self

    def __exit__(self, *exc):
        self.module.tqdm = self.saved


def worker(case, mode):
    """Build and time one configuration; the JSON result line is printed by rank 0."""
    d, k = CASES[case]
    steps = STEPS[case]
    points, h = lattice(k, d)
    velocity = 1e-4 * np.random.default_rng(0).uniform(-1.0, 1.0, points.shape)
    t0 = time.perf_counter()
    if mode == "serial":
        import cnem.pd as pd
        prob = pd.Problem(pd.Body(points, h ** d, HORIZON_FACTOR * h), pd.BondBased(1.0))
        rank, comm = 0, None
        vel = velocity
    else:
        import cnem.pd.distributed as pd
        prob = pd.Problem(pd.Body(points, h ** d, HORIZON_FACTOR * h), pd.BondBased(1.0))
        comm = prob.comm
        rank = comm.rank
        vel = lambda p: velocity[prob.body.owned]           # noqa: E731
        halo = prob.body.halo
        spent = [0.0]

        def timed(call):
            def run(*args):
                s = time.perf_counter()
                out = call(*args)
                spent[0] += time.perf_counter() - s
                return out
            return run
        halo.start, halo.finish = timed(halo.start), timed(halo.finish)
    setup = time.perf_counter() - t0
    dt = 0.5 * h
    prob.run_dynamic(dt, 1, velocity=vel, every=1, progress=False)   # kernels loaded, not timed
    if comm is not None:
        comm.Barrier()
        before, spent[0] = halo.bytes, 0.0
    import cnem.solvers.stepping as stepping           # the one time stepper's loop
    with StepClock(stepping) as clock:
        prob.run_dynamic(dt, steps, velocity=vel, every=steps, progress=False)
    step = median(clock.steps)
    out = dict(case=case, mode=mode, setup=setup, step=step, peak=peak_rss_bytes(),
               bonds=len(prob.body.bond_j))
    if comm is not None:
        out["exchange"] = spent[0] / steps
        out["bytes"] = (halo.bytes - before) / steps
        out["ghosts"], out["owned"] = len(prob.body.ghosts), prob.body.n_owned
        every = comm.gather(out, root=0)
        if rank:
            return
        out = dict(case=case, mode=mode, ranks=comm.size,
                   setup=max(r["setup"] for r in every), step=max(r["step"] for r in every),
                   peak=max(r["peak"] for r in every), bonds=sum(r["bonds"] for r in every),
                   exchange=float(np.mean([r["exchange"] for r in every])),
                   bytes=sum(r["bytes"] for r in every),
                   halo=sum(r["ghosts"] for r in every) / sum(r["owned"] for r in every))
    print("RESULT " + json.dumps(out), flush=True)


def launch(case, mode, ranks):
    """Run one configuration in a fresh process; its result dict (None if it failed)."""
    env = dict(os.environ)
    here = os.path.dirname(os.path.abspath(__file__))
    script = [sys.executable, os.path.join(here, "pd_mpi.py"), "--worker", case, mode]
    if mode == "serial":
        env.update(NUMBA_NUM_THREADS="2", OMP_NUM_THREADS="2")
        cmd = script
    else:
        env.update(NUMBA_NUM_THREADS="1", OMP_NUM_THREADS="1")
        cmd = [shutil.which("mpiexec"), "-n", str(ranks)] + script
    proc = subprocess.run(cmd, env=env, capture_output=True, text=True)
    for line in proc.stdout.splitlines():
        if line.startswith("RESULT "):
            return json.loads(line[7:])
    print(f"    {case} {mode} {ranks}: failed\n{proc.stdout[-2000:]}{proc.stderr[-2000:]}")
    return None


def projection(r1, r2, d, n2):
    """Projected efficiency table rows: (points, ranks, efficiency)."""
    t_point = r1["step"] / n2
    beta = r2["bytes"] / max(r2["exchange"], 1e-12) / 2          # per rank
    m2 = n2 / 2
    rows = []
    for total in (1e7, 1e8):
        for ranks in (8, 16, 32, 64, 128, 256):
            m = total / ranks
            ghosts = r2["halo"] * (m2 / m) ** (1.0 / d) * m
            tc = m * t_point
            tx = 2 * d * ALPHA + 8 * d * ghosts / beta
            rows.append((total, ranks, tc / (tc + tx)))
    return rows, beta


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="2-D 40k only (seconds)")
    parser.add_argument("--cases", nargs="+", choices=list(CASES))
    parser.add_argument("--repeat", type=int, default=3,
                        help="interleaved rounds of the three configurations; medians reported")
    parser.add_argument("--worker", nargs=2, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        return worker(*args.worker)
    if shutil.which("mpiexec") is None:
        print("benchmarks/pd_mpi.py: mpiexec not found; pip install 'cnem[mpi]'")
        return None
    cases = args.cases or (QUICK_CASES if args.quick else DEFAULT_CASES)
    machine = MachineLoad()
    print(f"benchmarks/pd_mpi.py: cases {cases}; load average {load_text(machine.before.load)} "
          "(other processes slow every configuration)")
    results, streams, failures = {}, {}, 0
    for case in cases:
        d, k = CASES[case]
        rounds = {}
        streams[case] = {1: [], 2: []}
        for round_ in range(max(1, args.repeat)):
            for mode, ranks in (("serial", 1), ("dist", 1), ("dist", 2)):
                skip = memory_skip(BYTES_PER_BOND[mode] * MEMBERS[d] * k ** d)
                if skip:
                    print(f"  {case} {mode} {ranks} rank(s) skipped: {skip}")
                    continue
                during = MachineLoad()
                r = launch(case, mode, ranks)
                print(f"  round {round_ + 1}: {case} {mode} {ranks} rank(s): "
                      + ("failed" if r is None else f"{r['step']:.4f} s/step") +
                      f" ({during.stop().short()})", flush=True)
                if r is None:
                    failures += 1
                else:
                    rounds.setdefault((mode, ranks), []).append(r)
            during = MachineLoad()
            for procs in streams[case]:
                streams[case][procs].append(stream.concurrent_read(MEMBERS[d] * k ** d, procs))
            print(f"  round {round_ + 1}: {case} read bandwidth, 1 process "
                  f"{streams[case][1][-1]:.1f} GB/s, 2 at once {streams[case][2][-1]:.1f} GB/s "
                  f"({during.stop().short()})", flush=True)
        # the run of median step time of each configuration
        results[case] = {key: sorted(rs, key=lambda r: r["step"])[(len(rs) - 1) // 2]
                         for key, rs in rounds.items()}
    report(results)
    report_bandwidth(results, streams)
    print("\n" + machine.stop().report())
    if failures:
        raise SystemExit(f"pd_mpi: {failures} run(s) failed (see above)")
    return results


def report_bandwidth(results, streams):
    """The memory-bandwidth bound on the ranks' speed-up beside the measured one."""
    print()
    print("memory-bandwidth bound (benchmarks/_bandwidth.py: single-threaded processes reading "
          "synthetic bond arrays of the case's size, split between them, all at once; "
          "medians over the rounds):")
    for case, bw in streams.items():
        per_bond = stream.nbytes(stream.bond_arrays(1))
        b1, b2 = median(bw[1]), median(bw[2])
        r1, r2 = results[case].get(("dist", 1)), results[case].get(("dist", 2))
        line = (f"  {case}: {per_bond} bytes per bond; 1 process {b1:.1f} GB/s, 2 at once "
                f"{b2:.1f} GB/s: a bandwidth-bound step would gain at most {b2 / b1:.2f}x "
                "on 2 ranks")
        if r1 and r2:
            floor = r1["bonds"] * per_bond / (b1 * 1e9)
            line += (f"; measured {r1['step'] / r2['step']:.2f}x, and 1 rank's step "
                     f"{r1['step']:.4f} s against {floor:.4f} s to read its bonds once "
                     f"({floor / r1['step']:.0%} of the read rate): "
                     + ("bandwidth-bound" if floor > 0.7 * r1["step"] else
                        "not bandwidth-bound, the bound does not apply"))
        print(line)


def report(results):
    print()
    head = (f"{'case':<7} {'config':<10} {'bonds':>10} {'setup s':>8} {'s/step':>8} "
            f"{'peak GB':>8} {'halo':>7} {'MB/step':>8} {'exch s/step':>11}")
    print(head)
    print("-" * len(head))
    for case, runs in results.items():
        for (mode, ranks), r in runs.items():
            if r is None:
                continue
            name = "serial 2T" if mode == "serial" else f"{ranks} rank(s)"
            extra = "" if mode == "serial" else \
                f" {r['halo']:7.4f} {r['bytes'] / 1e6:8.3f} {r['exchange']:11.5f}"
            print(f"{case:<7} {name:<10} {r['bonds']:>10d} {r['setup']:8.2f} {r['step']:8.4f} "
                  f"{r['peak'] / 2**30:8.2f}{extra}")
    print()
    rows = []
    for case, runs in results.items():
        s, r1, r2 = runs.get(("serial", 1)), runs.get(("dist", 1)), runs.get(("dist", 2))
        if r1 and r2:
            x = r1["step"] / r2["step"]
            rows.append((case, f"2 ranks vs 1 rank {x:.2f}x (>= {TARGET_SPEEDUP})",
                         x >= TARGET_SPEEDUP))
        if s and r2:
            x = s["step"] / r2["step"]
            rows.append((case, f"2 ranks vs serial at 2 threads {x:.2f}x (>= {TARGET_VS_THREADS})",
                         x >= TARGET_VS_THREADS))
            x = r2["peak"] / s["peak"]
            rows.append((case, f"peak memory per rank / serial peak {x:.2f} (<= {TARGET_MEMORY})",
                         x <= TARGET_MEMORY))
    print_targets(rows)
    for case, runs in results.items():
        r1, r2 = runs.get(("dist", 1)), runs.get(("dist", 2))
        if not (r1 and r2):
            continue
        d, k = CASES[case]
        rows, beta = projection(r1, r2, d, k ** d)
        print()
        print(f"projected efficiency from {case} (halo {r2['halo']:.4f} at 2 ranks, measured "
              f"exchange bandwidth {beta / 1e9:.2f} GB/s per rank, latency {ALPHA * 1e6:g} us; "
              f"model in the docstring):")
        print("  points  " + " ".join(f"{p:>6d}" for p in (8, 16, 32, 64, 128, 256)))
        for total in (1e7, 1e8):
            print(f"  {total:.0e}   " + " ".join(f"{e * 100:5.1f}%" for t, p, e in rows
                                                if t == total))
        t, n, e = JL_EFFICIENCY
        print(f"  Peridynamics.jl (published, threads): {e * 100:.0f} % efficiency at {t} "
              f"threads on {n:,} points")


if __name__ == "__main__":
    main()
