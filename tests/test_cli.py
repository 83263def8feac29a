"""The ``cnem`` command line (`cnem.cli`)."""

from __future__ import annotations

import argparse
import importlib
import inspect
import os
import pathlib
import re
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import cnem
from cnem import cli


def test_demo_list(capsys):
    assert cli.main(["demo", "list"]) == 0
    out = capsys.readouterr().out
    for name in cli.DEMOS:
        assert name in out


def _calls_of_main(module, monkeypatch):
    """Replace ``cnem.demos.<module>.main`` by a recorder: the list of its calls'
    ``(args, kwargs)`` (the demo's own runs are checked in test_demos.py)."""
    demo = importlib.import_module(f"cnem.demos.{module}")
    calls = []
    monkeypatch.setattr(demo, "main", lambda *args, **kwargs: calls.append((args, kwargs)))
    return calls


def test_demo_cylinder_options_reach_main(tmp_path, monkeypatch):
    """``cnem demo bimaterial-cylinder --nodes 147 --irregular --no-plot --out DIR`` runs the study on
    the paper's 147-node irregular cloud only, without pictures, into DIR (the files and the
    table of the demo's run: test_demos.py, ``check_cylinder_files``)."""
    from cnem.demos import bimaterial_cylinder as demo
    calls = _calls_of_main("bimaterial_cylinder", monkeypatch)
    cli.main(["demo", "bimaterial-cylinder", "--nodes", "147", "--irregular", "--no-plot",
              "--out", str(tmp_path)])
    assert calls == [((demo.GRIDS[:1],), dict(irregular=(True,), fem=True, outdir=str(tmp_path),
                                             plot=False, seed=0))]


def test_unknown_demo_is_named():
    with pytest.raises(SystemExit, match="unknown demo 'cylindre'.*cylinder"):
        cli.main(["demo", "cylindre"])


def test_pd_list_names_every_pd_demo(capsys, monkeypatch):
    monkeypatch.setitem(cli.PD_DEMOS, "cpd-later", "no_such_demo")
    assert cli.main(["pd", "list"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [line.split()[:2] for line in lines] == [
        [name, f"cnem.demos.{module}"] for name, module in cli.PD_DEMOS.items()]
    assert lines[0].endswith("A central crack under remote tension, solved on one node cloud "
                             "by C-NEM and by state-based PD.")
    assert lines[-1].endswith("(not installed)")


def test_every_demo_is_called_by_its_module_name():
    for table in cli._TABLES.values():
        assert all(name == module.replace("_", "-") for name, module in table.items())


@pytest.mark.parametrize("command, old, new", [
    (command, old, new) for command, table in cli.RENAMED_DEMOS.items()
    for old, new in table.items()])
def test_old_demo_names_run_the_demo_with_a_notice(command, old, new, capsys):
    """An old name of a demo still runs it for one release, saying the new name on stderr."""
    with pytest.raises(SystemExit) as done:
        cli.main([command, old, "--help"])
    assert done.value.code == 0
    out, err = capsys.readouterr()
    assert out.startswith(f"usage: cnem {command} {new}")
    assert f"cnem: '{command} {old}' is now '{command} {new}'" in err
    assert len(err.strip().splitlines()) == 1
    assert new in cli._TABLES[command] and old not in cli._TABLES[command]


def test_pd_crack_help_exits_cleanly(capsys):
    with pytest.raises(SystemExit) as done:
        cli.main(["pd", "pd-vs-cnem-crack", "--help"])
    assert done.value.code == 0
    assert "--n N [N ...]" in capsys.readouterr().out


def test_unknown_or_missing_pd_demo_is_named(monkeypatch):
    with pytest.raises(SystemExit, match=r"unknown pd demo 'brnaching'; choose one of "
                                         r"pd-vs-cnem-crack, pd-crack-branching.*cnem pd list"):
        cli.main(["pd", "brnaching"])
    monkeypatch.setitem(cli.PD_DEMOS, "cpd-later", "no_such_demo")
    with pytest.raises(SystemExit, match=r"pd demo 'cpd-later' runs cnem.demos.no_such_demo, "
                                         r"which is not installed"):
        cli.main(["pd", "cpd-later"])


def test_demo_help_lists_the_demos(capsys):
    assert cli.main(["demo", "--help"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("usage: cnem demo NAME")
    for name, module in cli.DEMOS.items():
        assert f"cnem.demos.{module}" in out and name in out


def test_missing_demo_name_is_an_error():
    with pytest.raises(SystemExit) as done:
        cli.main(["pd"])
    assert done.value.code == 2


def test_bad_cpd_options_are_named():
    from cnem.demos import cpd_examples
    with pytest.raises(ValueError, match="expected names from .*received \\['bending'\\]"):
        cpd_examples.main(("bending",))
    with pytest.raises(SystemExit) as done:
        cli.main(["pd", "cpd-examples", "--example", "bending"])
    assert done.value.code == 2


def test_cnem_pd_cpd_options_reach_main(tmp_path, monkeypatch):
    """``cnem pd cpd-examples --example lshape --quick`` runs that example at its quick size (what
    the demo prints: test_demos.py, ``check_cpd_output``)."""
    calls = _calls_of_main("cpd_examples", monkeypatch)
    cli.main(["pd", "cpd-examples", "--example", "lshape", "--quick", "--no-plot", "--out",
              str(tmp_path)])
    assert calls == [((("lshape",),), dict(quick=True, outdir=str(tmp_path), plot=False))]


def test_python_dash_m_runs():
    done = subprocess.run([sys.executable, "-m", "cnem", "info"], capture_output=True, text=True,
                          check=True)
    assert done.stdout.startswith("cnem ")


def _run(argv, capsys):
    """``cnem argv``: (exit status, stdout)."""
    try:
        code = cli.main(argv)
    except SystemExit as done:
        code = done.code
    return code, capsys.readouterr().out


def _every_command():
    """``[command]`` for every subcommand of the parser, ``[command, name]`` for every demo."""
    _, commands = cli.build_parser()
    argvs = [[command] for command in commands]
    for command, table in cli._TABLES.items():
        argvs += [[command, name] for name in table]
    return argvs


def test_every_command_answers_help(capsys):
    """``--help`` of ``cnem`` and of every subcommand and demo exits 0 and names the command."""
    assert _run(["--help"], capsys)[0] == 0
    argvs = _every_command()
    assert len(argvs) == 4 + len(cli.DEMOS) + len(cli.PD_DEMOS)
    for argv in argvs:
        code, out = _run(argv + ["--help"], capsys)
        assert code == 0, argv
        assert out.startswith(f"usage: cnem {' '.join(argv)}"), (argv, out[:80])


def _demo_parser(command, name, monkeypatch, capsys):
    """The parser a demo builds for ``cnem <command> <name> --help``."""
    seen = []
    print_help = argparse.ArgumentParser.print_help
    monkeypatch.setattr(argparse.ArgumentParser, "print_help",
                        lambda self, *a: (seen.append(self), print_help(self, *a)))
    assert _run([command, name, "--help"], capsys)[0] == 0
    monkeypatch.undo()
    return seen[-1]


@pytest.mark.parametrize("command, name", [(c, n) for c, t in cli._TABLES.items() for n in t])
def test_every_demo_shows_its_defaults_and_follows_the_output_rule(command, name, monkeypatch,
                                                                   capsys):
    parser = _demo_parser(command, name, monkeypatch, capsys)
    assert parser.formatter_class is cli.HelpFormatter
    formatter = parser._get_formatter()
    for action in parser._actions:
        if action.option_strings and not any(action.default is nothing for nothing in
                                             (None, False, argparse.SUPPRESS)):
            assert "(default:" in formatter._expand_help(action), (name, action.option_strings)
    module = cli._TABLES[command][name]
    out = next(a for a in parser._actions if "--out" in a.option_strings)
    assert out.default == f"results/{module}"
    main = importlib.import_module(f"cnem.demos.{module}").main
    assert inspect.signature(main).parameters["outdir"].default == out.default


@pytest.mark.parametrize("command, name", [(c, n) for c, t in cli._TABLES.items() for n in t])
def test_every_demo_states_its_run_time(command, name, capsys):
    """``--help`` of every demo says how long it runs at its defaults (its ``RUN_TIME``: a
    duration in s, min or h)."""
    run_time = importlib.import_module(f"cnem.demos.{cli._TABLES[command][name]}").RUN_TIME
    assert re.search(r"\d+(\.\d+)?(-\d+(\.\d+)?)? (s|min|h)\b", run_time), run_time
    code, out = _run([command, name, "--help"], capsys)
    assert code == 0
    assert f"{cli.RUN_TIME_LABEL}: {run_time}" in " ".join(out.split())


def test_undefined_pd_k_is_explained_with_the_right_threshold():
    """The PD K_I fit needs crack-face nodes 2h < r < a/2 behind the tips: the table's note
    says h < a/6 (--n 25 or more); on the demo's own clouds no fit exists up to n = 24 and
    one does from n = 25."""
    from cnem.demos import pd_vs_cnem_crack as demo

    def k(n):
        points = cnem.nodes.regular(demo.domain(), 1.0 / n).points
        x = points[(np.abs(points[:, 1]) < 1e-12) & (np.abs(points[:, 0]) <= demo.A + 1e-12), 0]
        return demo.k_from_tips(x, demo.griffith(x), 1.0 / n)

    assert all(np.isnan(k(n)) for n in (16, 20, 24)) and np.isfinite(k(25))
    row = dict(h=1 / 16, nodes=1, bonds=1, cnem_error=0.0, pd_error=0.0, K_cnem=1.0,
               K_pd=k(16), u_difference=0.0)
    text = demo.table([row])
    assert "nan" not in text and "too coarse" in text and "--n 25" in text


def test_compiling_is_announced_once_and_logged(tmp_path):
    """A fresh process: the first compilation of a cnem function logs the notice once; a
    function of another package is not announced."""
    script = textwrap.dedent("""
        import logging, numba
        logging.basicConfig(level=logging.INFO, format="%(name)s|%(message)s")
        from cnem import _compile
        def other(x): return x + 1
        def f(x): return x + 1
        def g(x): return x + 2
        numba.njit(other)(1)
        f.__module__ = g.__module__ = "cnem.fake"
        numba.njit(f)(1); numba.njit(g)(1.0)
        print(_compile.compiled)
    """)
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          check=True, env=dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path)))
    notices = [line for line in done.stderr.splitlines() if line.startswith("cnem._compile|")]
    assert notices == [f"cnem._compile|{cnem._compile.NOTICE}"]
    assert done.stdout.split() == ["['cnem.fake.f',", "'cnem.fake.g']"]


def test_every_kernel_module_announces_compiling():
    root = pathlib.Path(cnem.__file__).parent
    for path in root.rglob("*.py"):
        source = path.read_text()
        if "numba.njit" in source and path.name != "_compile.py":
            assert "import _compile" in source, path


def test_warmup_parallel_runs_the_list_again_on_the_parallel_copies(monkeypatch):
    """`cnem warmup --parallel`: each demo once as the first run would (serial copies of
    small kernels), then once more with every kernel on its parallel copy."""
    from cnem import config
    seen = []
    for module, _, _ in cli.WARMUP:
        demo = importlib.import_module(f"cnem.demos.{module}")
        monkeypatch.setattr(demo, "main", lambda *a, _m=module, **k:
                            seen.append((_m, config.PARALLEL_MIN)))
    monkeypatch.setattr(config, "PARALLEL_MIN", 123)
    assert cli.main(["warmup", "--parallel"]) == 0
    modules = [module for module, _, _ in cli.WARMUP]
    assert seen == [(m, 123) for m in modules] + [(m, 0) for m in modules]
    assert config.PARALLEL_MIN == 123


@pytest.mark.slow
def test_warmup_runs_every_listed_demo(monkeypatch):
    """`cnem warmup` runs each demo of its list once, quietly, and reports what compiled
    (the smallest of them, the mode-I crack on one 8 x 8 cloud, is run for real; the others
    only recorded: their runs are test_demos.py's)."""
    ran = []
    for module, _, _ in cli.WARMUP:
        demo = importlib.import_module(f"cnem.demos.{module}")
        real = module == "mode1_crack"
        monkeypatch.setattr(demo, "main", lambda *a, _m=module, _f=demo.main, _real=real, **k:
                            (ran.append(_m), _f(*a, **k) if _real else None)[1])
    compiled = cli.warmup(progress=False)
    assert ran == [module for module, _, _ in cli.WARMUP]
    assert all(name.startswith("cnem.") for name in compiled)


@pytest.mark.parametrize("command, name", [("pd", "pd-crack-branching"),
                                           ("pd", "kalthoff-winkler")])
def test_dynamic_demos_describe_their_quick_run(command, name, monkeypatch, capsys):
    """The time-stepped demos share ``--frames``, ``--quick`` and ``--no-progress``
    (`cli.dynamic_run_options`); ``--quick``'s help states the demo's own small run."""
    parser = _demo_parser(command, name, monkeypatch, capsys)
    options = {o: a for a in parser._actions for o in a.option_strings}
    assert {"--frames", "--quick", "--no-progress"} <= set(options)
    quick = importlib.import_module(f"cnem.demos.{cli.PD_DEMOS[name]}").QUICK
    h = np.atleast_1d(quick["h"])[0]
    assert options["--quick"].help.startswith(
        f"a small run: h = {h * 1e3:g} mm, m = {quick['m']:g}, {quick['t_end'] * 1e6:g} µs")


@pytest.mark.parametrize("argv, option", [
    (["demo", "bimaterial-cylinder", "--nodes", "-5"], "--nodes"),
    (["demo", "mode1-crack", "--n", "0"], "--n"),
    (["demo", "growth-sent", "--h", "-0.1"], "--h"),
    (["demo", "cracked-plate-geometry", "--size", "-5"], "--size"),
    (["demo", "cracked-plate-geometry", "--h", "nan"], "--h"),
    (["pd", "pd-crack-branching", "--time", "inf"], "--time"),
])
def test_a_bad_value_is_one_line_naming_the_option(argv, option, capsys):
    """A negative, zero or non-finite size is refused before the demo runs: argparse's one
    line naming the option and exit status 2 (it was a traceback, or a ZeroDivisionError)."""
    with pytest.raises(SystemExit) as done:
        cli.main(argv)
    assert done.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert f"error: argument {option}: expected a positive" in err


def test_an_unwritable_output_folder_is_one_line(tmp_path, capsys):
    """A library error inside a demo (here the output folder is a file) is one line with
    the command's name and exit status 2, not a traceback."""
    blocked = tmp_path / "file"
    blocked.write_text("")
    code = cli.main(["demo", "cracked-plate-geometry", "--h", "0.5", "--h-min", "0.1",
                     "--no-plot", "--out", str(blocked / "sub")])
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("cnem demo cracked-plate-geometry: error:")


def test_version(capsys):
    with pytest.raises(SystemExit) as done:
        cli.main(["--version"])
    assert done.value.code == 0
    assert capsys.readouterr().out.strip() == f"cnem {cnem.__version__}"
