"""Start-up cost: ``import cnem``, ``cnem --help`` and the first use of each subpackage,
each in fresh processes (median of ``--repeat``), against the bare interpreter and
``import numpy`` measured in the same run.

    python benchmarks/import_time.py            # this checkout
    python benchmarks/import_time.py --source /path/to/other/checkout   # e.g. an older commit

Target (architecture issue): ``import cnem`` under 0.5 s.
"""

from __future__ import annotations

import argparse
import os
import pathlib
import subprocess
import sys
import time

from _harness import MachineLoad, load_text, median

STATEMENTS = {
    "python (nothing)": "pass",
    "import numpy": "import numpy",
    "import cnem": "import cnem",
    "cnem --help": "import sys; sys.argv = ['cnem', '--help']\n"
                   "from cnem.cli import main\ntry:\n    main()\nexcept SystemExit:\n    pass",
    "cnem.Domain": "import cnem; cnem.Domain",
    "cnem.pd.Body": "import cnem; cnem.pd.Body",
    "cnem.fracture.sif": "import cnem; cnem.fracture.sif",
}


def _time(statement, source, repeat):
    env = dict(os.environ, PYTHONPATH=str(source))
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        done = subprocess.run([sys.executable, "-c", statement], env=env, cwd=source,
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        if done.returncode:
            return None
        times.append(time.perf_counter() - t0)
    return median(times)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="fresh processes per row (default 5)")
    parser.add_argument("--source", type=pathlib.Path,
                        default=pathlib.Path(__file__).resolve().parents[1],
                        help="checkout whose cnem is imported (default: this one)")
    parser.add_argument("--quick", action="store_true", help="one process per row")
    args = parser.parse_args(argv)
    repeat = 1 if args.quick else args.repeat
    check = "import cnem, pathlib; print(pathlib.Path(cnem.__file__).parents[1])"
    found = subprocess.run([sys.executable, "-c", check], cwd=args.source.resolve(), text=True,
                           capture_output=True, check=True).stdout.strip()
    machine = MachineLoad()
    print(f"load average before {load_text(machine.before.load)}; cnem from {found}")
    base = None
    print(f"{'statement':<22} {'median s':>9} {'minus python':>13}")
    for label, statement in STATEMENTS.items():
        t = _time(statement, args.source.resolve(), repeat)
        if t is None:
            print(f"{label:<22} {'fails':>9}")
            continue
        base = t if base is None else base
        print(f"{label:<22} {t:9.3f} {t - base:13.3f}")
    print("\n" + machine.stop().report())


if __name__ == "__main__":
    main()
