"""Peridynamics (`cnem.pd`): bodies, bond- and state-based materials, statics, dynamics.

Checked against classical elasticity (uniform strains, a bar in tension, the
lateral contraction at free edges), exact energy conservation of velocity
Verlet, the crack filter, and periodic against open bodies.
"""

from __future__ import annotations

import numpy as np
import pytest

import cnem
import cnem.pd as pd
from cnem.material import stiffness_matrix


def _grid(h, width=1.0, height=1.0, dim=2):
    axes = [np.arange(0.0, width + 1e-9, h), np.arange(0.0, height + 1e-9, h)]
    if dim == 3:
        axes.append(np.arange(0.0, height + 1e-9, h))
    mesh = np.meshgrid(*axes, indexing="ij")
    return np.column_stack([m.ravel() for m in mesh])


def _voigt(s):
    return np.stack([s[:, 0, 0], s[:, 1, 1], s[:, 0, 1]], axis=1)


@pytest.mark.parametrize("material, nu, plane", [
    (pd.BondBased(2.0), 1 / 3, "stress"), (pd.BondBased(2.0), 0.25, "strain"),
    (pd.StateBased(2.0, 0.3), 0.3, "stress"), (pd.StateBased(2.0, 0.1), 0.1, "strain"),
])
def test_uniform_strain_gives_the_classical_stress_in_the_bulk(material, nu, plane):
    h = 0.025
    pts = _grid(h)
    prob = pd.Problem(pd.Body(pts, h * h, 3.015 * h), material, plane=plane)
    C = stiffness_matrix(2.0, nu, plane)
    bulk = (np.abs(pts - 0.5) < 0.5 - 10 * h).all(axis=1)     # beyond three horizons
    for eps in ([[1e-3, 0], [0, 0]], [[0, 1e-3], [1e-3, 0]], [[1e-3, -5e-4], [-5e-4, 2e-3]]):
        eps = np.array(eps)
        stress = _voigt(prob.stress_tensor(pts @ eps.T))[bulk]
        exact = C @ [eps[0, 0], eps[1, 1], 2 * eps[0, 1]]
        np.testing.assert_allclose(stress, np.broadcast_to(exact, stress.shape),
                                   atol=0.01 * np.abs(exact).max())
        # and no force on the bulk points
        force = (prob.stiffness() @ (pts @ eps.T).reshape(-1)).reshape(-1, 2)[bulk]
        assert np.abs(force).max() < 1e-9 * np.abs(exact).max() * h


@pytest.mark.slow
def test_uniform_strain_in_3d():
    h = 0.1
    pts = _grid(h, dim=3)
    prob = pd.Problem(pd.Body(pts, h ** 3, 3.015 * h), pd.StateBased(1.0, 0.3))
    eps = np.array([[1e-3, 2e-4, 0], [2e-4, -5e-4, 1e-4], [0, 1e-4, 3e-4]])
    stress = prob.stress_tensor(pts @ eps.T)
    bulk = (np.abs(pts - 0.5) < 0.5 - 3.5 * h).all(axis=1)
    E, nu = 1.0, 0.3
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    exact = lam * np.trace(eps) * np.eye(3) + 2 * mu * eps
    np.testing.assert_allclose(stress[bulk], np.broadcast_to(exact, stress[bulk].shape),
                               atol=0.01 * np.abs(exact).max())


@pytest.mark.parametrize("material, nu_eff", [
    (pd.BondBased(1.0), 1 / 3), (pd.StateBased(1.0, 0.3), 0.3),
])
def test_free_edges_with_surface_correction(material, nu_eff):
    """A strip stretched between its ends: the lateral contraction across the free
    edges is the classical one within 2 % with the surface correction."""
    h = 0.02
    pts = _grid(h, 1.0, 0.5)
    found = {}
    for corr in (False, True):
        prob = pd.Problem(pd.Body(pts, h * h, 3.015 * h), material, surface_correction=corr)
        prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, 0, 0.0)
        prob.add_dirichlet(lambda p: p[:, 0] > 1 - 1e-9, 0, 1e-3)
        prob.add_dirichlet(lambda p: (p[:, 0] < 1e-9) & (np.abs(p[:, 1] - 0.26) < 1e-9), 1)
        u = prob.solve_static().u
        mid = np.abs(pts[:, 0] - 0.5) < 1e-9
        found[corr] = -np.polyfit(pts[mid, 1], u[mid, 1], 1)[0] / 1e-3
        np.testing.assert_allclose(u[mid, 0], 5e-4, rtol=1e-6)
    assert abs(found[True] - nu_eff) < 0.02 * nu_eff, found


def test_bar_converges_as_the_horizon_shrinks():
    """A bar under a uniform axial body force, clamped at x = 0: u(L) -> b L^2 / (2 E)."""
    errors = []
    for h in (0.05, 0.025, 0.0125):
        pts = _grid(h, 1.0, 0.2)
        prob = pd.Problem(pd.Body(pts, h * h, 3.015 * h), pd.StateBased(1.0, 0.0))
        prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None)
        prob.add_body_force([1.0, 0.0])
        u = prob.solve_static().u
        end = pts[:, 0] > 1 - 1e-9
        errors.append(abs(u[end, 0].mean() - 0.5) / 0.5)
    assert errors[2] < errors[1] < errors[0] and errors[2] < 0.05, errors


def test_newton_history_and_load_steps():
    h = 0.05
    pts = _grid(h)
    prob = pd.Problem(pd.Body(pts, h * h, 3.015 * h), pd.BondBased(1.0))
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None)
    prob.add_dirichlet(lambda p: p[:, 0] > 1 - 1e-9, 0, 0.01)
    one = prob.solve_static()
    three = prob.solve_static(steps=3)
    np.testing.assert_allclose(one.u, three.u, atol=1e-13)
    assert len(three.residual_history) == 3
    assert all(r[-1] <= 1e-10 * max(r[0], 1e-300) or r[-1] < 1e-14 for r in three.residual_history)


@pytest.mark.slow
def test_verlet_conserves_energy_without_breaking():
    h = 0.05
    pts = _grid(h, 1.0, 0.5)
    for material in (pd.BondBased(1.0), pd.StateBased(1.0, 0.3)):
        prob = pd.Problem(pd.Body(pts, h * h, 3.015 * h), material)
        dt = 0.2 * prob.stable_time_step()
        v0 = lambda p: 1e-3 * np.column_stack([np.sin(np.pi * p[:, 0]), np.cos(np.pi * p[:, 1])])
        run = prob.run_dynamic(dt, 1000, velocity=v0, every=1, progress=False)
        e, t = run.energy / run.energy[0], run.times
        drift = np.polyfit(t, e, 1)[0] * t[-1]            # the trend over the 1000 steps
        assert abs(drift) < 1e-6, drift
        # velocity Verlet's energy error is a bounded O(dt^2) oscillation
        assert np.abs(e - 1).max() < 2e-4
        assert run.broken == 0 and run.damage.max() == 0


def test_bonds_break_and_damage():
    h = 0.05
    pts = _grid(h, 1.0, 0.5)
    prob = pd.Problem(pd.Body(pts, h * h, 3.015 * h), pd.BondBased(1.0, critical_stretch=0.01))
    v = lambda p: np.column_stack([np.where(p[:, 0] > 0.5, 0.2, -0.2), 0 * p[:, 1]])
    run = prob.run_dynamic(0.5 * prob.stable_time_step(), 300, velocity=v, progress=False)
    assert run.broken > 0
    cut = np.abs(pts[:, 0] - 0.5) < 2 * h
    assert run.damage[cut].mean() > run.damage[~cut].mean()
    assert 0.0 <= run.damage.min() and run.damage.max() <= 1.0


def test_no_bond_crosses_a_crack():
    dom = cnem.geometry.rectangle(1.0, 1.0, cracks=[[[0.0, 0.5], [0.5, 0.5]]])
    cloud = cnem.nodes.regular(dom, 0.05)
    body = pd.Body.from_cloud(cloud, 3.0)
    x = body.points
    a, b = x[body.bond_i], x[body.bond_j]
    # a bond crosses the crack line y = 0.5 at some x < 0.5 (strictly between its ends)
    t = (0.5 - a[:, 1]) / np.where(b[:, 1] != a[:, 1], b[:, 1] - a[:, 1], np.nan)
    xc = a[:, 0] + t * (b[:, 0] - a[:, 0])
    crossing = (t > 1e-9) & (t < 1 - 1e-9) & (xc < 0.5 - 1e-9)
    assert not crossing.any()
    # the two copies of a face point are on opposite faces: each bonds to its own side only
    model = body.model
    copies = np.flatnonzero(np.bincount(model.node_of_point)[model.node_of_point] == 2)
    assert len(copies) > 0
    np.testing.assert_allclose(body.volumes.sum(), dom.area, rtol=1e-12)
    for i in copies[:6]:
        others = body.family.row(i)
        side = np.sign(x[others, 1] - 0.5)
        assert len(np.unique(side[side != 0])) == 1


@pytest.mark.slow
def test_periodic_body_matches_the_interior_of_an_open_one():
    h, L = 0.05, 1.0
    pts = _grid(h, L - h, L - h)
    field = lambda p: 1e-3 * np.column_stack([np.sin(2 * np.pi * p[:, 0] / L), np.cos(2 * np.pi * p[:, 1] / L)])
    per = pd.Problem(pd.Body(pts, h * h, 3.015 * h, period=[L, L]), pd.StateBased(1.0, 0.25),
                     surface_correction=False)
    f_per = (per.stiffness() @ field(pts).reshape(-1)).reshape(-1, 2)
    big = _grid(h, 3 * L - h, 3 * L - h)
    opn = pd.Problem(pd.Body(big, h * h, 3.015 * h), pd.StateBased(1.0, 0.25), surface_correction=False)
    f_open = (opn.stiffness() @ field(big).reshape(-1)).reshape(-1, 2)
    centre = (big >= L - 1e-9).all(axis=1) & (big < 2 * L - 1e-9).all(axis=1)
    order = np.lexsort((big[centre, 1], big[centre, 0]))
    np.testing.assert_allclose(f_open[centre][order], f_per, atol=1e-12)


def test_errors():
    with pytest.raises(ValueError, match="volumes"):
        pd.Body(np.zeros((3, 2)) + np.arange(3)[:, None], -1.0, 1.0)
    with pytest.raises(ValueError, match="horizon"):
        pd.Body(np.random.default_rng(0).random((5, 2)), 1.0, 0.0)
    with pytest.raises(ValueError, match="Poisson"):
        pd.StateBased(1.0, 0.5)
    with pytest.raises(ValueError, match="material"):
        pd.Problem(pd.Body(_grid(0.1), 0.01, 0.3), object())
    h = 0.1
    prob = pd.Problem(pd.Body(_grid(h), h * h, 3.015 * h), pd.BondBased(1.0))
    with pytest.raises(cnem.SolveError, match="translation in x.*translation in y.*rotation"):
        prob.solve_static()
    with pytest.raises(ValueError, match="dt"):
        prob.run_dynamic(-1.0, 10)


def test_body_from_a_3d_cloud():
    """The nodes of the 3-D model, each with its cells' volume (an interface node sums its
    cells): the volumes tile the body, and the horizon is 3 cbrt(V / n)."""
    lo, mid, hi = np.zeros(3), np.array([0.5, 1.0, 1.0]), np.array([1.0, 1.0, 1.0])
    from cnem.geometry.shapes3d import box_surface
    dom = cnem.Domain3D([box_surface(lo, mid), box_surface([0.5, 0.0, 0.0], hi)])
    cloud = cnem.nodes.irregular(dom, 0.25, seed=1)
    body = pd.Body.from_cloud(cloud, 3.0)
    model = body.model
    assert body.dim == 3 and len(body.points) == len(model.nodes)
    np.testing.assert_allclose(body.volumes.sum(), 1.0, rtol=1e-12)
    on_interface = np.bincount(model.cells.node, minlength=len(model.nodes)) == 2
    assert on_interface.any()
    i = int(np.flatnonzero(on_interface)[0])
    np.testing.assert_allclose(body.volumes[i], model.cells.volume[model.cells.node == i].sum())
    np.testing.assert_allclose(body.horizon, 3.0 * (1.0 / len(model.nodes)) ** (1 / 3))
    with pytest.raises(cnem.InputError, match="thickness"):
        pd.Body.from_cloud(cloud, 3.0, thickness=2.0)
