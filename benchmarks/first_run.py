"""A newcomer's first run: the main demo and ``import cnem`` in fresh processes, with an
empty numba cache (a fresh machine) and with the warm cache the first run left behind.

    python benchmarks/first_run.py            # the README's main demo, cold then warm
    python benchmarks/first_run.py --quick    # import cnem and cnem --help only (seconds)
    python benchmarks/first_run.py --root DIR # another checkout (e.g. a copy of an earlier commit)

Each row is one fresh process (``NUMBA_CACHE_DIR`` pointed at a new empty folder for
the cold rows, at the same folder afterwards for the warm ones); wall time and the CPU
time of the process (user + system) are printed with the load average before and
after, so that a run on a busy machine can be read: on a quiet machine the wall time
of the compiling run is about its CPU time (numba compiles on one thread).
Target (issue 21): the main demo under 90 s with an empty cache on a quiet machine.
"""

from __future__ import annotations

import argparse
import os
import pathlib
import resource
import subprocess
import sys
import tempfile
import time

from _harness import MachineLoad, load_text

ROOT = pathlib.Path(__file__).resolve().parents[1]


def commands(root):
    """label -> command (run from a temporary folder, checkout ``root`` first on the path)."""
    return {"import cnem": [sys.executable, "-c", "import cnem"],
            "cnem --help": [sys.executable, "-m", "cnem", "--help"],
            "main demo": [sys.executable, str(root / "demos" / "bimaterial_cylinder.py")]}


def _run(command, cache, cwd, root):
    """Wall and CPU seconds of one fresh process and how many times it announced compiling
    (``None`` if it failed)."""
    env = dict(os.environ, PYTHONPATH=str(root), NUMBA_CACHE_DIR=str(cache),
               PYVISTA_OFF_SCREEN="true")
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    done = subprocess.run(command, env=env, cwd=cwd, stdout=subprocess.DEVNULL,
                          stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode:
        print(done.stderr[-2000:], file=sys.stderr)
        return None
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu, done.stderr.count("compiling numba kernels")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true",
                        help="import cnem and cnem --help only (no demo)")
    parser.add_argument("--root", type=pathlib.Path, default=ROOT,
                        help="the checkout to measure (default this one)")
    args = parser.parse_args(argv)
    root = args.root.resolve()
    print(f"checkout {root}, numba threads {os.environ.get('NUMBA_NUM_THREADS', 'default')}")
    labels = ["import cnem", "cnem --help"] + ([] if args.quick else ["main demo"])
    machine = MachineLoad()
    print(f"load average before {load_text(machine.before.load)}")
    print(f"{'run':<24} {'wall s':>8} {'CPU s':>8}  {'notice':<28} machine during the run")
    with tempfile.TemporaryDirectory() as tmp:
        cache = pathlib.Path(tmp) / "numba-cache"
        cache.mkdir()
        for state in ("empty cache", "warm cache"):
            for label in labels:
                during = MachineLoad()
                res = _run(commands(root)[label], cache, tmp, root)
                name = f"{label}, {state}"
                if res is None:
                    print(f"{name:<24} {'fails':>8}")
                    continue
                wall, cpu, notice = res
                notice = f"compiling announced x{notice}" if notice else "-"
                print(f"{name:<24} {wall:8.2f} {cpu:8.2f}  {notice:<28} {during.stop().short()}",
                      flush=True)
    print("\n" + machine.stop().report())


if __name__ == "__main__":
    main()
