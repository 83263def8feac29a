"""Peridynamics on MPI ranks (`cnem.pd.distributed`) against the serial solvers.

The cases of `pd_mpi_cases` run under ``mpiexec -n 2``, ``-n 3`` and ``-n 4``
(oversubscribed on small machines) in subprocesses, and on one rank in this
process; each is compared with the serial `cnem.pd` run of the same problem:
the dynamic runs (bond- and state-based with bond breaking, a periodic body) give
the serial displacements to 1e-12 relative and the same broken bonds, a state-based
body cut in two by broken bonds the serial forces and dilatations, the
relaxation the serial equilibrium to its tolerance, a resumed run the
uninterrupted one, and the VTU pieces with their ``.pvtu`` index the gathered
displacements.
"""

from __future__ import annotations

import os
import pathlib
import shutil
import subprocess
import sys

import numpy as np
import pytest

import cnem.pd as pd
from cnem.errors import CNEMError, MissingExtraError

HERE = pathlib.Path(__file__).parent
sys.path.insert(0, str(HERE))
import pd_mpi_cases as C  # noqa: E402

MPI_TIMEOUT = 600                       # seconds per mpiexec launch (a busy 2-core machine)
needs_mpi = pytest.mark.skipif(shutil.which("mpiexec") is None or
                               __import__("importlib").util.find_spec("mpi4py") is None,
                               reason="mpiexec / mpi4py not installed (pip install 'cnem[mpi]')")


@pytest.fixture(scope="module", autouse=True)
def one_thread():
    """Numba at one thread in this process (as every rank): small bodies run faster, and
    a loaded machine does not stall the threads."""
    import numba
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    yield
    numba.set_num_threads(threads)


@pytest.fixture(scope="module")
def serial():
    """Serial runs of every case: (problem, result)."""
    out = {}
    for case in C.CASES:
        prob = C.setup(pd, case)
        out[case] = (prob, C.run(prob, case))
    return out


#: what each launch runs (4 ranks, oversubscribed on 2 cores: the bond-based case only)
LAUNCHES = {2: C.CASES + ("restart", "cut"), 3: C.CASES + ("restart", "cut"), 4: ("bond",)}


def _skip_unless_run(ranks, case):
    if case not in LAUNCHES[ranks]:
        pytest.skip(f"{ranks} ranks run {', '.join(LAUNCHES[ranks])} only (time)")


def _launch(ranks, tmp):
    env = dict(os.environ, OMP_NUM_THREADS="1", NUMBA_NUM_THREADS="1",
               PYTHONPATH=os.pathsep.join([str(HERE.parent), os.environ.get("PYTHONPATH", "")]))
    out = tmp / "results.npz"
    cmd = [shutil.which("mpiexec"), "-n", str(ranks), sys.executable, str(HERE / "pd_mpi_cases.py"),
           str(out), *LAUNCHES[ranks]]
    proc = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=MPI_TIMEOUT)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    with np.load(out, allow_pickle=False) as data:
        return dict(data)


@pytest.fixture(scope="module", params=[2, 3, 4])
def distributed(request, tmp_path_factory):
    """Results of `pd_mpi_cases.main` under ``mpiexec -n 2 / 3 / 4``."""
    if shutil.which("mpiexec") is None:
        pytest.skip("mpiexec not installed (pip install 'cnem[mpi]')")
    return request.param, _launch(request.param, tmp_path_factory.mktemp(f"mpi{request.param}"))


def _pairs(prob):
    b = prob.body
    return {(int(i), int(j)) for i, j in zip(b.bond_i[prob.alive == 0], b.bond_j[prob.alive == 0])}


def _assert_same_dynamics(serial, u, broken, case):
    prob, ref = serial[case]
    assert np.abs(u - ref.u).max() <= 1e-12 * np.abs(ref.u).max()
    assert {tuple(p) for p in broken.tolist()} == _pairs(prob)
    assert len(_pairs(prob)) > 100                      # the runs do break bonds


@pytest.mark.slow
@needs_mpi
@pytest.mark.parametrize("case", ["bond", "state", "periodic", "cube"])
def test_one_rank_in_process_equals_serial(serial, case):
    import cnem.pd.distributed as dpd
    res = C.run(C.setup(dpd, case), case)
    _assert_same_dynamics(serial, res.u, res.broken_bonds, case)
    np.testing.assert_allclose(res.energy, serial[case][1].energy, rtol=1e-10)
    assert res.broken == serial[case][1].broken


@pytest.mark.slow
@needs_mpi
@pytest.mark.parametrize("case", ["bond", "state", "periodic", "cube"])
def test_ranks_give_the_serial_dynamics(serial, distributed, case):
    ranks, res = distributed
    _skip_unless_run(ranks, case)
    _assert_same_dynamics(serial, res[f"{case}_u"], res[f"{case}_broken"], case)
    np.testing.assert_allclose(res[f"{case}_energy"], serial[case][1].energy, rtol=1e-10)


@pytest.mark.slow
@needs_mpi
def test_relaxation_reaches_the_serial_equilibrium(serial, distributed):
    ranks, res = distributed
    _skip_unless_run(ranks, "relax")
    _, ref = serial["relax"]
    static = serial["relax"][0].solve_static().u
    scale = np.abs(static).max()
    assert np.abs(ref.u - static).max() <= 1e-6 * scale          # the serial ADR itself
    assert np.abs(res["relax_u"] - static).max() <= 1e-6 * scale


def _serial_cut():
    """Force per unit volume and dilatation of the serial ``cut`` case at `C.cut_field`."""
    prob = C.setup(pd, "relax")
    b = prob.body
    assert C.cut(prob, b.points[b.bond_i], b.points[b.bond_j]) > 50
    u = C.cut_field(b.points).reshape(-1)
    return -(prob.stiffness() @ u).reshape(-1, 2) / b.volumes[:, None], prob.T @ u


def _assert_same_cut(force, theta):
    ref_force, ref_theta = _serial_cut()
    assert np.abs(force - ref_force).max() <= 1e-12 * np.abs(ref_force).max()
    assert np.abs(theta - ref_theta).max() <= 1e-12 * np.abs(ref_theta).max()


@pytest.mark.slow
@needs_mpi
def test_one_rank_gives_the_serial_forces_of_a_cut_body():
    import cnem.pd.distributed as dpd
    res = C.cut_forces(dpd)
    _assert_same_cut(res["cut_force"], res["cut_theta"])


@pytest.mark.slow
@needs_mpi
def test_ranks_give_the_serial_forces_of_a_cut_body(distributed):
    ranks, res = distributed
    _skip_unless_run(ranks, "cut")
    _assert_same_cut(res["cut_force"], res["cut_theta"])


@pytest.mark.slow
@needs_mpi
def test_resumed_run_equals_the_uninterrupted_one(serial, distributed):
    ranks, res = distributed
    _skip_unless_run(ranks, "restart")
    assert round(float(res["resumed_first"])) == C.CHECKPOINT
    np.testing.assert_array_equal(res["resumed_u"], res["bond_u"])
    np.testing.assert_array_equal(res["resumed_broken"], res["bond_broken"])


@pytest.mark.slow
@needs_mpi
def test_pvtu_frames_hold_the_gathered_displacements(distributed):
    vtk = pytest.importorskip("vtk")
    from vtk.util.numpy_support import vtk_to_numpy
    ranks, res = distributed
    _skip_unless_run(ranks, "restart")
    frames = [pathlib.Path(f) for f in res["frames"]]
    assert frames[-1].name.endswith(f"_{C.STEPS['bond']}.pvtu") and len(frames) == 3
    reader = vtk.vtkXMLPUnstructuredGridReader()
    reader.SetFileName(str(frames[-1]))
    reader.Update()
    grid = reader.GetOutput()
    assert reader.GetNumberOfPieces() == ranks
    points = vtk_to_numpy(grid.GetPoints().GetData())[:, :2]
    u = vtk_to_numpy(grid.GetPointData().GetArray("u"))
    order = np.lexsort(points.T[::-1])
    ref_points = C.plate()
    ref = np.lexsort(ref_points.T[::-1])
    np.testing.assert_allclose(points[order], ref_points[ref], atol=1e-15)
    np.testing.assert_array_equal(u[order], res["resumed_u"][ref])


def test_without_mpi4py_the_error_names_the_extra(monkeypatch):
    import cnem.pd.distributed as dpd
    monkeypatch.setitem(sys.modules, "mpi4py", None)
    with pytest.raises(MissingExtraError, match=r"cnem\[mpi\]") as err:
        dpd.Body(C.plate(), C.H ** 2, 3 * C.H)
    assert isinstance(err.value, CNEMError)
    prob = C.setup(pd, "bond")                  # serial use is untouched
    assert prob.run_dynamic(C.DT, 2, progress=False).broken >= 0
