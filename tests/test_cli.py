"""The ``cnem`` command line (`cnem.cli`)."""

from __future__ import annotations

import subprocess
import sys

import pytest

from cnem import cli


def test_demo_list(capsys):
    assert cli.main(["demo", "list"]) == 0
    out = capsys.readouterr().out
    for name in cli.DEMOS:
        assert name in out


def test_demo_cylinder_writes_its_files(tmp_path, capsys):
    cli.main(["demo", "cylinder", "--nodes", "147", "--irregular", "--no-plot",
              "--out", str(tmp_path)])
    out = capsys.readouterr().out
    assert f"wrote {tmp_path / 'cylinder.vtu'}" in out
    assert (tmp_path / "cylinder.vtu").stat().st_size > 0
    assert "irregular    147" in out


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


def test_pd_crack_help_exits_cleanly(capsys):
    with pytest.raises(SystemExit) as done:
        cli.main(["pd", "crack", "--help"])
    assert done.value.code == 0
    assert "--n N [N ...]" in capsys.readouterr().out


def test_unknown_or_missing_pd_demo_is_named(monkeypatch):
    with pytest.raises(SystemExit, match=r"unknown pd demo 'brnaching'; choose one of crack, "
                                         r"branching.*cnem pd list"):
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
        cli.main(["pd", "cpd", "--example", "bending"])
    assert done.value.code == 2


def test_cnem_pd_cpd_runs_the_demo(tmp_path, capsys):
    cli.main(["pd", "cpd", "--example", "lshape", "--quick", "--no-plot", "--out",
              str(tmp_path)])
    assert "delta/D" in capsys.readouterr().out


def test_python_dash_m_runs():
    done = subprocess.run([sys.executable, "-m", "cnem", "info"], capture_output=True, text=True,
                          check=True)
    assert done.stdout.startswith("cnem ")
