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


def test_python_dash_m_runs():
    done = subprocess.run([sys.executable, "-m", "cnem", "info"], capture_output=True, text=True,
                          check=True)
    assert done.stdout.startswith("cnem ")
