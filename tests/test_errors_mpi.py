"""Bad input to the distributed peridynamics under ``mpiexec -n 2``: every rank raises the
same named error and the job ends (before, the rank with the bad input raised and the other
waited in its next collective call for ever), and a whole-body initial velocity is taken as
the serial code takes it. Each launch is time-boxed: a hang fails the test."""

from __future__ import annotations

import os
import pathlib
import shutil
import subprocess
import sys
import textwrap

import pytest

pytestmark = [pytest.mark.slow, pytest.mark.skipif(
    shutil.which("mpiexec") is None or __import__("importlib").util.find_spec("mpi4py") is None,
    reason="mpiexec / mpi4py not installed (pip install 'cnem[mpi]')")]

ROOT = pathlib.Path(__file__).resolve().parents[1]
TIME_BOX = 240                          # seconds per launch (a busy 2-core machine)

PRELUDE = """
import sys
import numpy as np
import cnem
import cnem.pd.distributed as pd
from mpi4py import MPI
rank = MPI.COMM_WORLD.rank
h = 0.1
g = np.arange(0.0, 1.0 + 1e-9, h)
pts = np.array([(x, y) for x in g for y in g])
try:
{body}
    sys.stdout.write(f"rank {{rank}}: OK\\n")
except cnem.CNEMError as err:
    sys.stdout.write(f"rank {{rank}}: {{type(err).__name__}}: {{err}}\\n")
    sys.exit(1)
"""


def _launch(body):
    script = PRELUDE.format(body=textwrap.indent(textwrap.dedent(body), "    "))
    env = dict(os.environ, OMP_NUM_THREADS="1", NUMBA_NUM_THREADS="1",
               PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    try:
        proc = subprocess.run([shutil.which("mpiexec"), "-n", "2", sys.executable, "-c", script],
                              env=env, capture_output=True, text=True, timeout=TIME_BOX)
    except subprocess.TimeoutExpired:
        pytest.fail(f"mpiexec -n 2 hung for {TIME_BOX} s (a rank waits for the other)")
    return proc.returncode, proc.stdout + proc.stderr


@pytest.mark.parametrize("body, error, words", [
    ("vol = h * h if rank == 0 else -h * h\npd.Body(pts, vol, 3 * h)",
     "InputError", "on rank 1 of 2"),
    ("pd.Body(pts if rank == 0 else pts[:-1], h * h, 3 * h)",
     "InputError", "every rank must be given the same points"),
    ("pd.Body(pts if rank == 0 else pts + 1e-3, h * h, 3 * h)",
     "InputError", "every rank must be given the same points"),
], ids=["bad volumes on one rank", "point counts differ", "coordinates differ"])
def test_bad_input_on_one_rank_stops_every_rank(body, error, words):
    code, out = _launch(body)
    assert code != 0, out
    # the two ranks write at once: their lines may interleave, so no line structure is used
    for rank in (0, 1):
        assert f"rank {rank}: {error}: " in out, out[-3000:]
    assert out.count(words) >= 2, out[-3000:]


def test_a_whole_body_initial_velocity_is_taken_as_in_serial():
    """``velocity=`` of shape (n, 2) for the whole body, valid in serial, was refused under
    2 ranks ("expected (o, 2), received (n, 2)"); each rank now takes its own rows."""
    code, out = _launch("""
        body = pd.Body(pts, h * h, 3 * h)
        prob = pd.Problem(body, pd.BondBased(1.0, density=1.0))
        v = np.zeros_like(pts)
        v[:, 0] = 1e-3 * pts[:, 1]
        run = prob.run_dynamic(0.01, 3, velocity=v, progress=False)
    """)
    assert code == 0 and out.count(": OK") == 2, out[-3000:]
