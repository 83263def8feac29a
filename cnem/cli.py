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
are the modules of `cnem.demos` (``python -m cnem.demos.bimaterial_cylinder``),
installed with the package.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from typing import Sequence

__all__ = ["main", "DEMOS", "PD_DEMOS"]

#: Command-line name -> module of `cnem.demos`.
DEMOS = {
    "cylinder": "bimaterial_cylinder",
    "inclined-crack": "inclined_crack",
    "mode1-crack": "mode1_crack",
    "pd-crack": "pd_vs_cnem_crack",
    "cracked-plate": "cracked_plate_geometry",
    "growth-sent": "growth_sent",
    "growth-kink": "growth_kink",
    "growth-two-holes": "growth_two_holes",
    "growth-dcb": "growth_dcb",
}

#: ``cnem pd <name>`` -> module of `cnem.demos` (add a PD demo here).
PD_DEMOS = {
    "crack": "pd_vs_cnem_crack",
    "branching": "pd_crack_branching",
    "cpd": "cpd_examples",
}

#: Subcommand -> its table of demos.
_TABLES = {"demo": DEMOS, "pd": PD_DEMOS}


#: The package of the demo modules.
PACKAGE = "cnem.demos"


def _module_name(name, command):
    """The full module name of a demo (``SystemExit`` naming the choices if unknown)."""
    table = _TABLES[command]
    if name not in table:
        kind = "demo" if command == "demo" else f"{command} demo"
        raise SystemExit(f"cnem: unknown {kind} {name!r}; choose one of {', '.join(table)} "
                         f"(cnem {command} list)")
    return f"{PACKAGE}.{table[name]}"


def load_demo(name, command="demo"):
    """The demo module for a command-line name of ``cnem demo`` (see `DEMOS`) or of
    ``cnem pd`` (``command="pd"``, see `PD_DEMOS`)."""
    module = _module_name(name, command)
    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as exc:
        if exc.name != module:
            raise
        kind = "demo" if command == "demo" else f"{command} demo"
        raise SystemExit(f"cnem: the {kind} {name!r} runs {module}, which is not installed; "
                         f"update cnem (pip install --upgrade cnem, or git pull in a "
                         f"source tree)") from None


def _summary(module):
    """First docstring line of a demo module, read without importing it (``None`` if the
    module is not installed)."""
    import ast
    import importlib.util
    spec = importlib.util.find_spec(module)
    if spec is None:
        return None
    doc = ast.get_docstring(ast.parse(spec.loader.get_source(module))) or ""
    return doc.strip().split("\n")[0]


def _list(command):
    """Print each demo of ``cnem <command>`` with its module and its first docstring line."""
    for name in _TABLES[command]:
        module = _module_name(name, command)
        doc = _summary(module)
        print(f"{name:15s} {module}  {'(not installed)' if doc is None else doc}")


def _info():
    import os

    import numba
    import numpy
    import scipy
    import skfem

    import cnem
    print(f"cnem {cnem.__version__} ({os.path.dirname(cnem.__file__)})")
    for mod in (numpy, scipy, numba, skfem):
        print(f"  {mod.__name__:8s} {mod.__version__}")
    print(f"  numba threads: {numba.get_num_threads()}")


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``cnem`` command (and ``python -m cnem``)."""
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = argparse.ArgumentParser(prog="cnem", description=__doc__.split("\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter,
                                     epilog=__doc__.split("\n\n", 1)[1])
    sub = parser.add_subparsers(dest="command", required=True)
    runners = {}
    for command, what in (("demo", "a demo"), ("pd", "a peridynamics demo")):
        runners[command] = sub.add_parser(
            command, help=f"run {what} (cnem {command} list)", add_help=False,
            usage=f"cnem {command} NAME [options] | cnem {command} NAME --help | "
                  f"cnem {command} list",
            description=f"Run {what}; its own options follow its name.")
        runners[command].add_argument("name", nargs="?", help=f"{what[2:]} name, or 'list'")
    sub.add_parser("info", help="versions and threads")
    args, rest = parser.parse_known_args(argv)
    if args.command == "info":
        if rest:
            parser.error(f"unrecognised arguments: {' '.join(rest)}")
        _info()
        return 0
    if args.name is None:
        if not {"-h", "--help"} & set(rest):
            runners[args.command].error("expected a demo name, or 'list'")
        runners[args.command].print_help()
        print("\ndemos:" if args.command == "demo" else f"\n{args.command} demos:")
        _list(args.command)
        return 0
    if args.name == "list":
        _list(args.command)
        return 0
    load_demo(args.name, args.command).cli(rest)
    return 0


if __name__ == "__main__":
    sys.exit(main())
