"""A regular (non-editable) install runs the demos: the wheel built from this tree, installed
into a fresh virtual environment, gives a ``cnem`` command that finds `cnem.demos` far from
the source tree."""

from __future__ import annotations

import importlib.util
import os
import pathlib
import re
import shutil
import site
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]


def _run(args, cwd, **kw):
    """Run a command, failing the test with its output if it fails."""
    done = subprocess.run(args, cwd=cwd, capture_output=True, text=True, **kw)
    assert done.returncode == 0, f"{args} exited {done.returncode}\n{done.stdout}\n{done.stderr}"
    return done


def _build_wheel(tmp_path):
    """The wheel of a copy of the package's files (the source tree stays clean). Without
    build isolation when setuptools and wheel are at hand (no index needed), else with
    pip's isolated build (setuptools and wheel from the configured index)."""
    src = tmp_path / "src"
    src.mkdir()
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(ROOT / name, src / name)
    shutil.copytree(ROOT / "cnem", src / "cnem",
                    ignore=shutil.ignore_patterns("__pycache__", "*.pyc", "*.nbi", "*.nbc"))
    isolation = []
    if importlib.util.find_spec("wheel") is not None:
        import setuptools
        if int(setuptools.__version__.split(".")[0]) >= 68:
            isolation = ["--no-build-isolation"]
    dist = tmp_path / "dist"
    _run([sys.executable, "-m", "pip", "wheel", "--no-deps", *isolation, "-w", str(dist),
          str(src)], cwd=tmp_path)
    wheels = list(dist.glob("cnem-*.whl"))
    assert len(wheels) == 1, wheels
    return wheels[0]


def _fresh_venv(path):
    """A virtual environment that sees the packages of this interpreter (numpy, numba, ...)
    but not this source tree: ``--system-site-packages``, plus this environment's
    site-packages when the tests run in a virtual environment themselves."""
    _run([sys.executable, "-m", "venv", "--system-site-packages", str(path)], cwd=path.parent)
    python = path / ("Scripts" if os.name == "nt" else "bin") / "python"
    if sys.prefix != sys.base_prefix:
        own = _run([str(python), "-c", "import sysconfig; print(sysconfig.get_path('purelib'))"],
                   cwd=path).stdout.strip()
        pathlib.Path(own, "_parent_environment.pth").write_text(
            "\n".join(site.getsitepackages()) + "\n")
    return python


@pytest.mark.slow
def test_cnem_demo_runs_from_an_installed_wheel(tmp_path):
    wheel = _build_wheel(tmp_path)
    python = _fresh_venv(tmp_path / "venv")
    _run([str(python), "-m", "pip", "install", "--no-deps", "--no-index", "--force-reinstall",
          str(wheel)], cwd=tmp_path)
    scripts = python.parent
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["PYVISTA_OFF_SCREEN"] = "true"

    where = _run([str(python), "-c", "import cnem.demos, cnem.cli; print(cnem.demos.__file__)"],
                 cwd=elsewhere, env=env).stdout.strip()
    assert pathlib.Path(where).is_relative_to(tmp_path / "venv"), where

    cnem = str(scripts / "cnem")
    help_text = _run([cnem, "demo", "--help"], cwd=elsewhere, env=env).stdout
    assert "cylinder" in help_text and "cnem.demos.bimaterial_cylinder" in help_text

    out = _run([cnem, "demo", "cracked-plate-geometry", "--h", "0.4", "--h-min", "0.1", "--no-plot",
                "--out", str(elsewhere / "out")], cwd=elsewhere, env=env).stdout
    counts = re.search(r"(\d+) cloud nodes -> (\d+) nodes \((\d+) crack nodes split", out)
    assert counts, out
    points, nodes, split = map(int, counts.groups())
    assert nodes == points + split > points
    error = re.search(r"vs plate area 4 \(relative error ([0-9.e+-]+)\)", out)
    assert error and float(error.group(1)) <= 1e-12, out
    assert (elsewhere / "out" / "cracked_plate.vtu").stat().st_size > 0

    module = _run([str(python), "-m", "cnem.demos.cracked_plate_geometry", "--help"],
                  cwd=elsewhere, env=env).stdout
    assert "usage: cnem demo cracked-plate-geometry" in module
