"""The Kalthoff-Winkler demo (`cnem.demos.kalthoff_winkler`): its geometry against the
specification, the crack-angle measurement on synthetic damage fields of known angle,
and the same run serially and on two MPI ranks (``mpiexec -n 2``, the demo's own
command line)."""

from __future__ import annotations

import importlib.util
import os
import pathlib
import shutil
import subprocess
import sys

import numpy as np
import pytest

from cnem.demos import kalthoff_winkler as kw

ROOT = pathlib.Path(__file__).parent.parent


def test_the_plate_has_the_notch_slots_of_the_specification():
    """At h = 0.25 mm the 1.5 mm slots are six rows of cells, 50 mm (200 cells) long, centred
    on y = +-25 mm."""
    h = 0.25e-3
    pts = kw.plate(h)
    assert len(pts) == 400 * 800 - 2 * 200 * 6
    x, y = np.meshgrid((np.arange(400) + 0.5) * h, (np.arange(800) + 0.5) * h - 0.1,
                       indexing="ij")
    full = np.column_stack([x.ravel(), y.ravel()])
    kept = {tuple(p) for p in np.round(pts / h * 2).astype(int)}
    gone = np.array([p for p in full if tuple(np.round(p / h * 2).astype(int)) not in kept])
    assert gone[:, 0].max() < 0.05 < gone[:, 0].max() + h
    for s in (1, -1):
        rows = np.unique(gone[np.sign(gone[:, 1]) == s, 1])
        assert len(rows) == 6 and abs(rows.mean() - s * 0.025) < 1e-12
        assert abs(rows.max() - rows.min() + h - 1.5e-3) < 1e-12


def synthetic(angle, h=0.5e-3, width=1.2e-3, length=0.045):
    """Grid points of the plate with damage 1 within ``width / 2`` of a ray from each notch
    tip at ``angle`` degrees to +x, outwards (mirrored for the lower notch), a decoy band
    from each tip towards the struck middle, and damage 0.3 (below the threshold) elsewhere."""
    pts = kw.plate(h)
    damage = np.full(len(pts), 0.3)
    for s in (1, -1):
        rel = (pts - [0.05, s * 0.025]) * [1.0, s]
        for a in (np.radians(angle), np.radians(-60.0)):          # the crack, the decoy
            along = rel @ [np.cos(a), np.sin(a)]
            across = rel @ [-np.sin(a), np.cos(a)]
            damage[(along > 0) & (along < length) & (np.abs(across) < 0.5 * width)] = 1.0
    return pts, damage


@pytest.mark.parametrize("angle", [45.0, 65.0, 70.0, 88.0])
def test_crack_angle_of_a_synthetic_damage_field(angle):
    pts, damage = synthetic(angle)
    res = kw.measure(pts, damage, horizon=2e-3)
    tol = 1.0             # a band a few cells wide on a 0.5 mm grid, fitted over 20 mm
    assert abs(res["upper"] - angle) < tol and abs(res["lower"] - angle) < tol
    assert abs(res["mean"] - angle) < tol
    assert res["crack_points"] > 100


def test_no_crack_gives_no_angle():
    pts = kw.plate(1e-3)
    res = kw.measure(pts, np.zeros(len(pts)), horizon=4e-3)
    assert np.isnan(res["upper"]) and np.isnan(res["mean"]) and res["crack_points"] == 0
    text = kw.table([dict(h=1e-3, horizon=4e-3, stretch=0.006, nodes=len(pts), ranks=1,
                          steps=1, seconds=1.0, **res)], 50e-6)
    assert "nan" not in text and "run longer" in text


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("mpiexec") is None or importlib.util.find_spec("mpi4py") is None,
                    reason="mpiexec / mpi4py not installed (pip install 'cnem[mpi]')")
def test_two_ranks_give_the_serial_run(tmp_path):
    """``mpiexec -n 2 python -m cnem.demos.kalthoff_winkler --quick``: the serial
    displacements to 1e-12, the same broken bonds and damage, ``.pvtu`` frames."""
    import numba
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        serial = kw.main(**kw.QUICK, outdir=tmp_path / "serial", plot=False, progress=False)
    finally:
        numba.set_num_threads(threads)
    env = dict(os.environ, OMP_NUM_THREADS="1", NUMBA_NUM_THREADS="1",
               PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    cmd = [shutil.which("mpiexec"), "-n", "2", sys.executable, "-m", "cnem.demos.kalthoff_winkler",
           "--quick", "--no-plot", "--no-progress", "--out", str(tmp_path / "mpi")]
    done = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    assert "    2 " in done.stdout.splitlines()[2]                       # the ranks column
    name = "kalthoff_winkler_h2.5mm.npz"
    with np.load(tmp_path / "serial" / name) as a, np.load(tmp_path / "mpi" / name) as b:
        scale = np.abs(a["u"]).max()
        assert np.abs(a["u"] - b["u"]).max() <= 1e-12 * scale
        assert len(a["broken_bonds"]) > 1000                         # the run breaks bonds
        np.testing.assert_array_equal(a["broken_bonds"], b["broken_bonds"])
        np.testing.assert_allclose(a["damage"], b["damage"], rtol=0, atol=1e-12)
    frames = sorted((tmp_path / "mpi" / "frames_h2.5mm").glob("*.pvtu"))
    assert len(frames) == len(serial["rows"][0]["files"]) - 1 > 2    # the .npz is listed too
    assert len(list((tmp_path / "mpi" / "frames_h2.5mm").glob("kw_r0001_*.vtu"))) == len(frames)


def test_bad_times_and_spacings_are_refused(tmp_path):
    from cnem.errors import InputError
    with pytest.raises(InputError, match="t_end: expected a positive time"):
        kw.main(h=(2.5e-3,), t_end=-1e-6, outdir=tmp_path)
    with pytest.raises(InputError, match="frame_every: expected a time in"):
        kw.main(h=(2.5e-3,), t_end=1e-6, frame_every=2e-6, outdir=tmp_path)
    with pytest.raises(InputError, match="divides 25 mm"):
        kw.plate(0.3e-3)
    with pytest.raises(InputError, match="at most a quarter"):
        kw.build(2.5e-3, 6.0)                             # delta = 15 mm
    with pytest.raises(SystemExit) as done:
        kw.cli(["--h", "0.3", "--out", str(tmp_path)])
    assert done.value.code == 2
