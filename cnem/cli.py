"""The ``cnem`` command: run the demos, compile the kernels ahead, show what is installed.

    cnem demo list                                   # the demos
    cnem demo bimaterial-cylinder --nodes 687 --irregular   # results/bimaterial_cylinder/
    cnem demo cracked-plate-geometry --gamma 45 --out my/folder/
    cnem pd list                                     # the peridynamics demos
    cnem pd pd-vs-cnem-crack --n 16 32               # PD and C-NEM on one cloud
    cnem pd pd-crack-branching --help                # dynamic crack branching
    cnem pd cpd-examples --example tension2d         # CPD examples (Javili et al. §6)
    cnem warmup                                      # compile every kernel now (first run only)
    cnem warmup --parallel                           # and their parallel copies (large models)
    cnem info                                        # versions, threads

Each demo keeps its own options (``cnem demo bimaterial-cylinder --help``, defaults
shown); the demos are the modules of `cnem.demos` (``python -m cnem.demos.bimaterial_cylinder``),
installed with the package, each called by its module's name with dashes. Every demo
writes its files to ``--out``, by default ``results/<module>/`` (`output_folder`).
"""

from __future__ import annotations

import argparse
import math
import importlib
import logging
import pathlib
import sys
from typing import TYPE_CHECKING

from ._aliases import RENAMED_DEMOS
from .errors import CNEMError

if TYPE_CHECKING:
    from typing import Callable, Sequence

__all__ = ["main", "positive_int", "positive_float", "DEMOS", "PD_DEMOS", "current_name",
           "HelpFormatter", "demo_parser", "dynamic_run_options", "output_folder",
           "show_compile_notice", "warmup", "build_parser"]

def _named(*modules: str) -> dict[str, str]:
    """Command-line name -> module of `cnem.demos`: each demo is called by its module's
    name with dashes (``bimaterial_cylinder`` -> ``bimaterial-cylinder``)."""
    return {module.replace("_", "-"): module for module in modules}


#: ``cnem demo <name>`` -> module of `cnem.demos`.
DEMOS = _named("bimaterial_cylinder", "inclined_crack", "mode1_crack", "pd_vs_cnem_crack",
               "cracked_plate_geometry", "growth_sent", "growth_kink", "growth_two_holes",
               "growth_pd_vs_cnem", "growth_dcb", "kalthoff_winkler", "bracket_stl")

#: ``cnem pd <name>`` -> module of `cnem.demos` (add a PD demo here).
PD_DEMOS = _named("pd_vs_cnem_crack", "pd_crack_branching", "pd_vs_cnem_3d", "cpd_examples",
                  "kalthoff_winkler", "cnem_vs_cpd")

#: Subcommand -> its table of demos.
_TABLES = {"demo": DEMOS, "pd": PD_DEMOS}

#: The package of the demo modules.
PACKAGE = "cnem.demos"


class HelpFormatter(argparse.RawDescriptionHelpFormatter, argparse.ArgumentDefaultsHelpFormatter):
    """Help text as written, each option followed by its default (none for flags and for
    options without one)."""

    def _get_help_string(self, action: argparse.Action) -> str:
        if any(action.default is nothing for nothing in (None, False, argparse.SUPPRESS)):
            return action.help or ""
        return super()._get_help_string(action)


def output_folder(module_file: str) -> str:
    """The default output folder of a demo: ``results/<module>`` (pass the demo's ``__file__``).

    >>> output_folder("/any/where/cnem/demos/bimaterial_cylinder.py")
    'results/bimaterial_cylinder'
    """
    return f"results/{pathlib.PurePath(module_file).stem}"


def demo_command(module_file: str) -> str | None:
    """The ``cnem`` command that runs a demo module (``cnem demo <name>`` first, then
    ``cnem pd <name>``), None for a module in no table.

    >>> demo_command("/any/where/cnem/demos/cracked_plate_geometry.py")
    'cnem demo cracked-plate-geometry'
    """
    stem = pathlib.PurePath(module_file).stem
    for sub, table in _TABLES.items():
        for name, module in table.items():
            if module == stem:
                return f"cnem {sub} {name}"
    return None


def _positive(kind: type) -> Callable[[str], int | float]:
    """An argparse ``type`` that takes only positive, finite numbers of ``kind``: a bad value
    is one line naming the option (``error: argument --h: ...``), exit status 2."""
    noun = "whole number" if kind is int else "number"

    def parse(text: str) -> int | float:
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a positive {noun}, received {text!r}") \
                from None
        if not (math.isfinite(value) and value > 0):
            raise argparse.ArgumentTypeError(f"expected a positive {noun}, received {text}")
        return value

    parse.__name__ = f"positive {noun}"
    return parse


#: argparse types of the demos' sizes, spacings, counts and times.
positive_int, positive_float = _positive(int), _positive(float)


#: What a demo's ``--help`` calls its run time at the defaults (`demo_parser`).
RUN_TIME_LABEL = "Expected run time at the defaults"


def demo_parser(module_file: str, doc: str, prog: str | None = None, *,
                run_time: str) -> argparse.ArgumentParser:
    """The command line every demo starts from (the one place of the demos' output rule).

    Parameters
    ----------
    module_file : str
        The demo's ``__file__``: names its default output folder (`output_folder`).
    doc : str
        The demo's module docstring; its first line is the description.
    prog : str, optional
        The command shown in the usage line (`main` passes the one it was called as), by
        default the demo's ``cnem`` command (`demo_command`).
    run_time : str
        How long the demo runs at its defaults on a 2-core machine with the numba
        kernels compiled (the demo's ``RUN_TIME``, measured, e.g. ``"about 10 s"``);
        the description says it after the docstring's first line.

    Returns
    -------
    argparse.ArgumentParser
        With defaults shown (`HelpFormatter`), ``--out`` (default ``results/<module>``) and
        ``--no-plot``; the demo adds its own options. Compiling kernels is announced on the
        terminal (`show_compile_notice`).
    """
    first_line = doc.strip().split("\n")[0]
    description = (f"{first_line}\n\n{RUN_TIME_LABEL}: {run_time}\n(a shared 2-core "
                   "machine, kernels compiled; a first run compiles them first)")
    parser = argparse.ArgumentParser(prog=prog or demo_command(module_file),
                                     description=description, formatter_class=HelpFormatter)
    parser.add_argument("--out", default=output_folder(module_file),
                        help="folder for the files and pictures")
    parser.add_argument("--no-plot", action="store_true", help="skip the pictures")
    show_compile_notice()
    return parser


def dynamic_run_options(parser: argparse.ArgumentParser, frames: float, quick_h: float,
                        quick_m: float, quick_t_end: float) -> None:
    """Add the options of a dynamic (time-stepped) demo: ``--frames``, ``--quick`` and
    ``--no-progress``.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The demo's parser (`demo_parser`), which holds ``--h``, ``--m`` and ``--time``.
    frames : float
        Default time between damage frames in µs.
    quick_h, quick_m, quick_t_end : float
        The small run of ``--quick``: grid spacing in m, horizon / spacing and simulated time
        in s (shown in the help in mm and µs).
    """
    parser.add_argument("--frames", type=positive_float, default=frames, help="µs between damage frames")
    parser.add_argument("--quick", action="store_true",
                        help=f"a small run: h = {quick_h * 1e3:g} mm, m = {quick_m:g}, "
                             f"{quick_t_end * 1e6:g} µs (overrides --h, --m, --time)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")


def show_compile_notice() -> None:
    """Show the line `cnem._compile` logs when numba compiles the kernels on stderr (once
    per process, ``cnem: compiling numba kernels, first run only ...``)."""
    logger = logging.getLogger("cnem._compile")
    if not any(getattr(h, "_cnem_notice", False) for h in logger.handlers):
        handler = logging.StreamHandler(sys.stderr)
        handler.setFormatter(logging.Formatter("cnem: %(message)s"))
        handler.setLevel(logging.INFO)
        handler._cnem_notice = True
        logger.addHandler(handler)
    if logger.getEffectiveLevel() > logging.INFO:
        logger.setLevel(logging.INFO)


def current_name(name: str, command: str = "demo") -> str:
    """The name of a demo of ``cnem <command>``; an old name of `cnem._aliases.RENAMED_DEMOS`
    gives the new one, with a one-line notice on stderr."""
    new = RENAMED_DEMOS[command].get(name)
    if new is None:
        return name
    print(f"cnem: '{command} {name}' is now '{command} {new}' ({name} goes in the next release)",
          file=sys.stderr)
    return new


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
    width = max(map(len, _TABLES[command]))
    for name in _TABLES[command]:
        module = _module_name(name, command)
        doc = _summary(module)
        print(f"{name:{width}s} {module}  {'(not installed)' if doc is None else doc}")


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
    print(f"  numba cache: {numba.config.CACHE_DIR or 'next to the sources (__pycache__)'}")


#: What `warmup` runs: (demo module, positional arguments, keyword arguments), the
#: smallest sizes that call every kernel the demos use.
WARMUP = (
    ("bimaterial_cylinder", (((7, 21),),), dict(irregular=(False, True))),
    ("mode1_crack", ((1 / 8,),), {}),
    ("inclined_crack", ((30.0,),), dict(sif_cloud=(0.2, 0.4, 0.05, 0.3),
                                        paper_cloud=(0.2, 0.4, 0.05, 0.3))),
    ("pd_vs_cnem_crack", ((1 / 16,),), {}),
    ("growth_sent", (0.1,), dict(a1=0.3, increment=0.1, progress=False)),
    ("pd_crack_branching", (), dict(h=0.5e-3, m=4.0, t_end=30e-6, progress=False)),
    ("cpd_examples", (("tension2d",),), dict(quick=True)),
)


def warmup(progress: bool = True, parallel: bool = False) -> list[str]:
    """Compile (or load from numba's cache) every kernel the demos use, by running each
    demo of `WARMUP` once at its smallest size, without pictures, into a temporary folder;
    with ``parallel``, once more with every kernel on its parallel copy (the one models
    above `cnem.config.PARALLEL_MIN` work items use, `cnem._parallel.parallel_kernel`).

    Returns
    -------
    list of str
        ``module.function`` of each kernel compiled (empty when the cache was warm).
    """
    import contextlib
    import io
    import tempfile

    from tqdm.auto import tqdm

    from . import _compile
    from ._parallel import always_parallel
    before = len(_compile.compiled)
    passes = ((False, True) if parallel else (False,))
    jobs = [(copy, job) for copy in passes for job in WARMUP]
    with tempfile.TemporaryDirectory() as tmp:
        for copy, (module, args, kwargs) in tqdm(jobs, desc="warmup", disable=not progress,
                                                 unit="demo"):
            demo = importlib.import_module(f"{PACKAGE}.{module}")
            with (always_parallel() if copy else contextlib.nullcontext()), \
                    contextlib.redirect_stdout(io.StringIO()):
                demo.main(*args, **kwargs, outdir=pathlib.Path(tmp) / module, plot=False)
    return _compile.compiled[before:]


def _warmup(parallel: bool):
    import time
    t0 = time.perf_counter()
    names = warmup(progress=sys.stderr.isatty(), parallel=parallel)
    print(f"cnem warmup: {len(names)} kernels compiled in {time.perf_counter() - t0:.0f} s"
          if names else f"cnem warmup: every kernel was cached already "
                        f"({time.perf_counter() - t0:.0f} s)")


def build_parser() -> tuple[argparse.ArgumentParser, dict[str, argparse.ArgumentParser]]:
    """The ``cnem`` parser and its subcommands' parsers (``{"demo": ..., "pd": ..., ...}``)."""
    parser = argparse.ArgumentParser(prog="cnem", description=__doc__.split("\n")[0],
                                     formatter_class=HelpFormatter,
                                     epilog=__doc__.split("\n\n", 1)[1])
    from . import __version__
    parser.add_argument("--version", action="version", version=f"cnem {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    commands = {}
    for command, what in (("demo", "a demo"), ("pd", "a peridynamics demo")):
        commands[command] = sub.add_parser(
            command, help=f"run {what} (cnem {command} list)", add_help=False,
            formatter_class=HelpFormatter,
            usage=f"cnem {command} NAME [options] | cnem {command} NAME --help | "
                  f"cnem {command} list",
            description=f"Run {what}; its own options follow its name "
                        f"(cnem {command} NAME --help).")
        commands[command].add_argument("name", nargs="?", help=f"{what[2:]} name, or 'list'")
    commands["warmup"] = sub.add_parser(
        "warmup", help="compile every numba kernel now (first run only)",
        formatter_class=HelpFormatter,
        description="Compile every numba kernel the demos use, once, into numba's cache "
                    "(about 2 min of CPU in a fresh environment; a warm cache only loads them).")
    commands["warmup"].add_argument(
        "--parallel", action="store_true",
        help="also the kernels' parallel copies, which models above cnem.config.PARALLEL_MIN "
             "work items (points, cells, rows) use")
    commands["info"] = sub.add_parser("info", help="versions, threads and the numba cache",
                                      formatter_class=HelpFormatter,
                                      description="Versions, threads and the numba cache.")
    return parser, commands


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``cnem`` command (and ``python -m cnem``)."""
    argv = sys.argv[1:] if argv is None else list(argv)
    parser, commands = build_parser()
    args, rest = parser.parse_known_args(argv)
    show_compile_notice()
    if args.command in ("info", "warmup"):
        if rest:
            commands[args.command].error(f"unrecognised arguments: {' '.join(rest)}")
        _info() if args.command == "info" else _warmup(args.parallel)
        return 0
    if args.name is None:
        if not {"-h", "--help"} & set(rest):
            commands[args.command].error("expected a demo name, or 'list'")
        commands[args.command].print_help()
        print("\ndemos:" if args.command == "demo" else f"\n{args.command} demos:")
        _list(args.command)
        return 0
    if args.name == "list":
        _list(args.command)
        return 0
    name = current_name(args.name, args.command)
    prog = f"cnem {args.command} {name}"
    try:
        load_demo(name, args.command).cli(rest, prog=prog)
    except (CNEMError, OSError) as err:
        # a value the options' types cannot judge (a window the picture refuses, an output
        # folder that cannot be written): one line, as argparse reports its own errors
        sys.stderr.write(f"{prog}: error: {err}\n")
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
