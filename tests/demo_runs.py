"""Each demo's `main` runs once per test session: the runs are kept and shared by the tests
that check a demo's numbers (``test_demos.py``) and those that compare a documentation
page with a fresh run of its command (``test_demo_pages.py``).

`run_main` calls ``cnem.demos.<module>.main`` (or hands back the kept run of the same
call); `run_command` runs a command line (``("demo", "bimaterial-cylinder", ...)``, as after ``cnem``)
in this process, its demo's `main` through `run_main`. A run happens on one numba thread,
as the pages' runs do (``docs/demos/regenerate.py``), into a folder of its own under a
temporary one removed at exit; its standard output is kept (and printed again whenever the
run is handed back inside a command, so that a command prints the same text either way).
"""

from __future__ import annotations

import atexit
import contextlib
import importlib
import inspect
import io
import pathlib
import shutil
import tempfile
from dataclasses import dataclass

#: Arguments of a demo's `main` that do not change what it computes.
NOT_IN_KEY = ("outdir", "progress")

_ROOT = pathlib.Path(tempfile.mkdtemp(prefix="cnem_demo_runs_"))
atexit.register(shutil.rmtree, _ROOT, ignore_errors=True)
_MAINS: dict = {}          # (module, arguments) -> DemoRun
_COMMANDS: dict = {}       # argv -> DemoRun


@dataclass(frozen=True)
class DemoRun:
    """One run of a demo: what `main` returned, what it (or its command) printed, and the
    folder its files are in (the printed text names this folder)."""

    result: dict
    stdout: str
    outdir: pathlib.Path


def _original_main(demo):
    return getattr(demo.main, "_original", demo.main)


def _key(module, main, args, kwargs):
    bound = inspect.signature(main).bind(*args, **kwargs)
    bound.apply_defaults()
    arguments = {k: v for k, v in bound.arguments.items() if k not in NOT_IN_KEY}
    return module, repr(sorted(arguments.items()))


def run_main(module: str, *args, **kwargs) -> DemoRun:
    """``cnem.demos.<module>.main(*args, **kwargs)`` (``outdir`` is the run's own), or the
    kept run of the same call (the same arguments, ``outdir`` and ``progress`` aside)."""
    import numba

    demo = importlib.import_module(f"cnem.demos.{module}")
    main = _original_main(demo)
    kwargs.pop("outdir", None)
    key = _key(module, main, args, kwargs)
    if key not in _MAINS:
        outdir = _ROOT / f"{module}-{len(_MAINS)}"
        printed = io.StringIO()
        threads = numba.get_num_threads()
        numba.set_num_threads(1)
        try:
            with contextlib.redirect_stdout(printed):
                result = main(*args, **kwargs, outdir=outdir)
        finally:
            numba.set_num_threads(threads)
        _MAINS[key] = DemoRun(result, printed.getvalue(), outdir)
    return _MAINS[key]


def run_command(argv) -> DemoRun:
    """``cnem *argv`` in this process: the run of the demo's `main` it makes (through
    `run_main`), with the whole command's standard output."""
    from cnem import cli

    argv = tuple(argv)
    if argv not in _COMMANDS:
        demo = cli.load_demo(argv[1], argv[0])
        module = demo.__name__.rpartition(".")[2]
        original, served = _original_main(demo), []

        def main(*args, **kwargs):
            run = run_main(module, *args, **kwargs)
            served.append(run)
            print(run.stdout, end="")
            return run.result

        main._original = original
        asked = _ROOT / f"command-{len(_COMMANDS)}"
        printed = io.StringIO()
        demo.main = main
        try:
            with contextlib.redirect_stdout(printed):
                cli.main([*argv, "--out", str(asked)])
        finally:
            demo.main = original
        (run,) = served
        _COMMANDS[argv] = DemoRun(run.result, printed.getvalue().replace(str(asked),
                                                                         str(run.outdir)),
                                  run.outdir)
    return _COMMANDS[argv]
