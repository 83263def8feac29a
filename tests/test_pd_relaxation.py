"""Adaptive dynamic relaxation, VTU frames of dynamic runs and 3-D rigid motions (`cnem.pd`).

ADR is checked against the static solution of the same problem: both solve
the same equilibrium, so they agree up to the ADR tolerance and, for the
bond-based material, the geometric nonlinearity of the PMB forces (relative
size about the strain: the bond-based cases use strains of 1e-7 to 1e-6).
"""

from __future__ import annotations

import re

import meshio
import numpy as np
import pytest
from test_pd import _grid

import cnem
import cnem.pd as pd
from cnem.solvers.linsolve import free_rigid_motions, rigid_modes, solve_spd

H = 0.05


def _plate(material, load):
    """A unit plate clamped at x = 0, pulled at x = 1 or loaded by a body force."""
    prob = pd.Problem(pd.Body(_grid(H), H * H, 3.015 * H), material)
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None)
    if load == "dirichlet":
        prob.add_dirichlet(lambda p: p[:, 0] > 1 - 1e-9, 0, 1e-6)
    else:
        prob.add_body_force([2e-7, 0.0])
    return prob


@pytest.mark.parametrize("material", [pd.BondBased(1.0), pd.StateBased(1.0, 0.3)],
                         ids=["bond", "state"])
@pytest.mark.parametrize("load", ["dirichlet", "body force"])
def test_relaxation_matches_the_static_solution(material, load):
    prob = _plate(material, load)
    static = prob.solve_static().u
    relaxed = prob.relax(tol=1e-9, progress=False)
    assert np.abs(relaxed.u - static).max() <= 1e-6 * np.abs(static).max()
    assert relaxed.iterations > 0 and relaxed.broken == 0
    np.testing.assert_array_equal(relaxed.damage, 0.0)
    np.testing.assert_allclose(relaxed.stress_tensor(), prob.stress_tensor(relaxed.u))


def test_load_steps_reach_the_same_equilibrium():
    prob = _plate(pd.StateBased(1.0, 0.25), "dirichlet")
    static = prob.solve_static().u
    sol = prob.relax(tol=1e-10, steps=3, progress=False)
    assert len(sol.residual_history) == 3
    assert np.abs(sol.u - static).max() <= 1e-8 * np.abs(static).max()


def test_residual_falls_to_the_tolerance():
    """The residual, stored at every iteration, falls from quarter to quarter of
    the run (ADR oscillates little with the adaptive damping) down to tol."""
    prob = _plate(pd.StateBased(1.0, 0.3), "dirichlet")
    sol = prob.relax(tol=1e-10, every=1, progress=False)
    res = np.array(sol.residual_history[0])
    assert len(res) == sol.iterations + 1                     # iteration 0 and every one after
    assert res[-1] <= 1e-10 * res[0] < res[-2]               # no reference load: the first residual
    quarters = [q.max() for q in np.array_split(res, 4)]
    assert all(b < a for a, b in zip(quarters, quarters[1:])), quarters


def test_too_few_iterations_raise_with_the_residual():
    prob = _plate(pd.BondBased(1.0), "dirichlet")
    with pytest.raises(cnem.SolveError, match=r"load step 1: residual \d\.\d{3}e-\d+ .* after 5 "
                                              r"iterations; raise max_steps"):
        prob.relax(max_steps=5, progress=False)
    free = pd.Problem(pd.Body(_grid(0.1), 0.01, 0.3015), pd.BondBased(1.0))
    free.add_body_force([1.0, 0.0])
    with pytest.raises(cnem.SolveError, match="translation in x; translation in y; rotation"):
        free.relax(progress=False)
    with pytest.raises(ValueError, match="tol > 0"):
        prob.relax(tol=0.0)


def test_bonds_break_at_equilibrium():
    """A strip clamped at both ends and pulled near the critical stretch: bonds
    break where the clamps concentrate the strain, the final state stretches no
    live bond beyond the critical stretch and it is the static equilibrium of
    the damaged body."""
    sc = 1e-7
    pts = _grid(H, 1.0, 0.5)
    prob = pd.Problem(pd.Body(pts, H * H, 3.015 * H), pd.BondBased(1.0, critical_stretch=sc))
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None)
    prob.add_dirichlet(lambda p: p[:, 0] > 1 - 1e-9, None, [1.05 * sc, 0.0])
    sol = prob.relax(tol=1e-8, progress=False)
    b = prob.body
    assert sol.broken > 0 and sol.broken == (prob.alive == 0).sum()
    y = b.xi + sol.u[b.bond_j] - sol.u[b.bond_i]
    stretch = np.linalg.norm(y, axis=1) / b.length - 1
    assert stretch[prob.alive == 1].max() <= sc
    np.testing.assert_allclose(sol.damage, prob.damage())
    static = prob.solve_static().u                           # the damaged body's stiffness
    assert np.abs(sol.u - static).max() <= 1e-6 * np.abs(static).max()


@pytest.mark.parametrize("output, pattern", [("run", "run_*.vtu"), ("run.vtu", "run_*.vtu"),
                                             ("frames/", "frames/pd_*.vtu"), (".", "pd_*.vtu")])
def test_dynamic_run_writes_vtu_frames(tmp_path, output, pattern):
    pts = _grid(0.1, 1.0, 0.5)
    prob = pd.Problem(pd.Body(pts, 0.01, 0.3015), pd.BondBased(1.0))
    v0 = lambda p: 1e-3 * np.column_stack([np.sin(np.pi * p[:, 0]), 0 * p[:, 1]])
    run = prob.run_dynamic(0.5 * prob.stable_time_step(), 20, velocity=v0, every=5,
                           output=f"{tmp_path}/{output}", progress=False)
    files = sorted(tmp_path.glob(pattern))
    assert len(files) == len(run.frames) == 5 and files == sorted(run.files)
    assert [f.stem[-2:] for f in files] == ["00", "05", "10", "15", "20"]
    for path, (u, damage) in zip(files, run.frames):
        mesh = meshio.read(path)
        np.testing.assert_array_equal(mesh.points, np.column_stack([pts, np.zeros(len(pts))]))
        np.testing.assert_array_equal(mesh.cells_dict["vertex"].ravel(), np.arange(len(pts)))
        # ParaView's form (issue 39): 3-component vectors, z = 0 in 2-D
        shape = (len(pts), 3)
        assert mesh.point_data["displacement"].shape == mesh.point_data["velocity"].shape == shape
        np.testing.assert_array_equal(mesh.point_data["displacement"][:, :2], u)
        assert (mesh.point_data["displacement"][:, 2] == 0).all()
        np.testing.assert_array_equal(mesh.point_data["damage"], damage)
    np.testing.assert_array_equal(meshio.read(files[-1]).point_data["velocity"][:, :2],
                                  run.velocity)
    # the .pvd beside the frames lists them with the run's times
    pvd = files[0].with_name(files[0].name.rsplit("_", 1)[0] + ".pvd")
    listed = re.findall(r'timestep="([^"]+)" group="" part="0" file="([^"]+)"', pvd.read_text())
    np.testing.assert_array_equal([float(t) for t, _ in listed], run.times)
    assert [name for _, name in listed] == [f.name for f in files]
    assert prob.run_dynamic(0.1, 2, progress=False).files == []


def _cube(material):
    h = 0.25
    pts = _grid(h, dim=3)
    return pd.Problem(pd.Body(pts, h ** 3, 3.015 * h), material)


def test_3d_rigid_motions_are_named():
    prob = _cube(pd.BondBased(1.0))
    prob.add_body_force([0.0, 0.0, -1.0])
    with pytest.raises(cnem.SolveError, match="translation in x; translation in y; translation "
                                              "in z; rotation about x through .*; rotation about "
                                              "y through .*; rotation about z through"):
        prob.solve_static()
    # the corner (0, 0, 0) fixed: the rotations about the three axes through it are free,
    # each named by its point nearest the centroid (0.5, 0.5, 0.5)
    pts = prob.body.points
    K = prob.stiffness()
    assert free_rigid_motions(K, pts, [0, 1, 2]) == [
        "rotation about x through (0.5, 0, 0)", "rotation about y through (0, 0.5, 0)",
        "rotation about z through (0, 0, 0.5)"]
    # z fixed on the face z = 0: translations in x, y and the rotation about z are free
    bottom = 3 * np.flatnonzero(pts[:, 2] < 1e-9) + 2
    assert free_rigid_motions(K, pts, bottom) == [
        "translation in x", "translation in y", "rotation about z through (0.5, 0.5, 0.5)"]
    # two points fixed: the rotation about the line through them
    assert free_rigid_motions(K, pts, [0, 1, 2, 3 * 124, 3 * 124 + 1, 3 * 124 + 2]) == [
        "rotation about (1, 1, 1) through (0.5, 0.5, 0.5)"]


@pytest.mark.parametrize("material", [pd.BondBased(1.0), pd.StateBased(1.0, 0.3)],
                         ids=["bond", "state"])
def test_3d_clamped_cube_solves(material):
    prob = _cube(material)
    prob.add_dirichlet(lambda p: p[:, 2] < 1e-9, None)
    prob.add_body_force([0.0, 0.0, -1e-3])
    u = prob.solve_static().u
    assert (u[:, 2] <= 1e-15).all() and u[:, 2].min() < 0
    # the stiffness annihilates the six rigid motions, which the AMG solver is given
    K = prob.stiffness()
    modes = rigid_modes(prob.body.points)
    assert modes.shape == (3 * len(u), 6)
    assert np.abs(K @ modes).max() <= 1e-12 * abs(K).max()
    fixed = np.flatnonzero(np.repeat(prob.body.points[:, 2] < 1e-9, 3))
    interior = np.setdiff1d(np.arange(K.shape[0]), fixed)
    A, f = K[interior][:, interior], prob.load()[interior]
    np.testing.assert_allclose(solve_spd(A, f, modes=modes[interior], method="amg", tol=1e-12),
                               u.reshape(-1)[interior], atol=1e-8 * np.abs(u).max())


def test_2d_names_are_unchanged():
    pts = _grid(0.1)
    prob = pd.Problem(pd.Body(pts, 0.01, 0.3015), pd.BondBased(1.0))
    K = prob.stiffness()
    assert free_rigid_motions(K, pts, []) == ["translation in x", "translation in y",
                                              "rotation about (0.5, 0.5)"]
    assert free_rigid_motions(K, pts, [0, 1]) == ["rotation about (0, 0)"]
    left = 2 * np.flatnonzero(pts[:, 0] < 1e-9)
    assert free_rigid_motions(K, pts, left) == ["translation in y"]
    np.testing.assert_array_equal(rigid_modes(pts)[0::2, 2], 0.5 - pts[:, 1])


def test_round_off_floor_covers_the_pmb_force_error():
    """`force_round_off` of a PMB plate at a small random displacement (strains ~1e-7): the
    kernel's nodal forces against the same sums in extended precision differ by less than
    the floor (norms), and the floor is not orders of magnitude above that difference."""
    from cnem.pd.relaxation import force_round_off
    prob = _plate(pd.BondBased(1.0), "body force")
    b, d, n = prob.body, prob.dim, len(prob.body)
    state = prob._force_state()
    u = np.random.default_rng(6).uniform(-1.0, 1.0, (n, d)) * 1e-7 * H
    found = np.repeat(b.volumes, d) * prob._internal_force(u, np.inf, state)[0].reshape(-1)
    q = np.longdouble
    xi = b.points[b.bond_j].astype(q) - b.points[b.bond_i].astype(q)
    y = xi + u[b.bond_j].astype(q) - u[b.bond_i].astype(q)
    ly, L = np.sqrt((y * y).sum(axis=1)), np.sqrt((xi * xi).sum(axis=1))
    g = state["stiffness"].astype(q) * b.volumes[b.bond_j].astype(q) * (ly - L) / (L * ly)
    exact = np.zeros((n, d), dtype=q)
    for c in range(d):
        np.add.at(exact[:, c], b.bond_i, g * y[:, c])
    exact = (b.volumes[:, None].astype(q) * exact).reshape(-1)
    error = float(np.linalg.norm((found - exact).astype(float)))
    floor = float(np.linalg.norm(force_round_off(prob, state["stiffness"], np.zeros(d * n), n)))
    assert 0.0 < error <= floor <= 1e3 * error
