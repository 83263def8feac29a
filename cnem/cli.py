"""The ``cnem`` command: run the demos and show what is installed.

    cnem demo list                                   # the demos
    cnem demo cylinder --nodes 687 --irregular --out results/
    cnem demo cracked-plate --gamma 45 --out results/
    cnem pd list                                     # the peridynamics demos
    cnem pd crack --n 16 32 --out results/           # PD and C-NEM on one cloud
    cnem pd branching --help                         # dynamic crack branching
    cnem pd cpd --example tension2d --out results/   # CPD examples (Javili et al. §6)
    cnem info                                        # versions, threads

Each demo keeps its own options (``cnem demo cylinder --help``); the demos
are the scripts in the ``demos/`` folder of the source tree.
"""

from __future__ import annotations

import argparse
import importlib.util
import pathlib
import sys

__all__ = ["main", "DEMOS", "PD_DEMOS"]

#: Command-line name -> script in ``demos/``.
DEMOS = {
    "cylinder": "bimaterial_cylinder",
    "inclined-crack": "inclined_crack",
    "mode1-crack": "mode1_crack",
    "pd-crack": "pd_vs_cnem_crack",
    "cracked-plate": "cracked_plate_geometry",
}

#: ``cnem pd <name>`` -> script in ``demos/`` (add a CPD demo here).
PD_DEMOS = {
    "crack": "pd_vs_cnem_crack",
    "branching": "pd_crack_branching",
    "cpd": "cpd_examples",
}

#: Subcommand -> its table of demos.
_TABLES = {"demo": DEMOS, "pd": PD_DEMOS}


def demos_folder():
    """The ``demos/`` folder of the source tree this package was installed from."""
    folder = pathlib.Path(__file__).resolve().parents[1] / "demos"
    if not folder.is_dir():
        raise SystemExit(f"cnem: the demos ship with the source repository and {folder} does "
                         "not exist; install from a clone with pip install -e .")
    return folder


def load_demo(name, command="demo"):
    """The demo module for a command-line name of ``cnem demo`` (see `DEMOS`) or of
    ``cnem pd`` (``command="pd"``, see `PD_DEMOS`)."""
    table = _TABLES[command]
    kind = "demo" if command == "demo" else f"{command} demo"
    if name not in table:
        raise SystemExit(f"cnem: unknown {kind} {name!r}; choose one of {', '.join(table)} "
                         f"(cnem {command} list)")
    path = demos_folder() / f"{table[name]}.py"
    if not path.is_file():
        raise SystemExit(f"cnem: the {kind} {name!r} runs demos/{path.name}, which is not in "
                         f"{path.parent}; update the source tree (git pull)")
    spec = importlib.util.spec_from_file_location(table[name], path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _list(command):
    """Print each demo of ``cnem <command>`` with its script and its first docstring line."""
    table = _TABLES[command]
    for name, script in table.items():
        if (demos_folder() / f"{script}.py").is_file():
            doc = (load_demo(name, command).__doc__ or "").strip().split("\n")[0]
        else:
            doc = "(not in this source tree yet)"
        print(f"{name:15s} demos/{script}.py  {doc}")


def _info():
    import numba
    import numpy
    import scipy
    import skfem

    import cnem
    print(f"cnem {cnem.__version__} ({pathlib.Path(cnem.__file__).parent})")
    for mod in (numpy, scipy, numba, skfem):
        print(f"  {mod.__name__:8s} {mod.__version__}")
    print(f"  numba threads: {numba.get_num_threads()}")


def main(argv=None):
    """Entry point of the ``cnem`` command (and ``python -m cnem``)."""
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = argparse.ArgumentParser(prog="cnem", description=__doc__.split("\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter,
                                     epilog=__doc__.split("\n\n", 1)[1])
    sub = parser.add_subparsers(dest="command", required=True)
    demo = sub.add_parser("demo", help="run a demo (cnem demo list)", add_help=False)
    demo.add_argument("name", help="demo name, or 'list'")
    pd = sub.add_parser("pd", help="run a peridynamics demo (cnem pd list)", add_help=False)
    pd.add_argument("name", help="pd demo name, or 'list'")
    sub.add_parser("info", help="versions and threads")
    args, rest = parser.parse_known_args(argv)
    if args.command == "info":
        if rest:
            parser.error(f"unrecognised arguments: {' '.join(rest)}")
        _info()
        return 0
    if args.name == "list":
        _list(args.command)
        return 0
    load_demo(args.name, args.command).cli(rest)
    return 0


if __name__ == "__main__":
    sys.exit(main())
