"""Continuum-kinematics-inspired peridynamics (`cnem.pd.CPD`) and the Newton solver.

Checked against hand-derived derivatives of the Seth-Hill energies, finite differences
of the energy and of the residual, the energy of eq. 8 summed by hand, exact counts of
pairs and triplets on lattices, frame indifference, and Newton's quadratic convergence.
"""

from __future__ import annotations

import numpy as np
import pytest

import cnem
import cnem.pd as pd
from cnem import hyperdual as hd


def _grid(k, dim, h=1.0):
    g = np.arange(k) * h
    mesh = np.meshgrid(*([g] * dim), indexing="ij")
    return np.column_stack([m.ravel() for m in mesh])


def _rotation(angle, dim):
    c, s = np.cos(angle), np.sin(angle)
    Q = np.array([[c, -s], [s, c]])
    if dim == 3:                                  # about the axis (1, 2, 2) / 3
        n = np.array([1.0, 2.0, 2.0]) / 3
        N = np.array([[0, -n[2], n[1]], [n[2], 0, -n[0]], [-n[1], n[0], 0]])
        Q = np.eye(3) + s * N + (1 - c) * N @ N
    return Q


# bodies: 2-D 5 x 5 with delta = 2.2 h, 3-D 3 x 3 x 3 with delta = 1.5 h (triplets)
BODIES = {2: (5, 2.2), 3: (3, 1.5)}


def _body(dim, h=0.5):
    k, factor = BODIES[dim]
    return pd.Body(_grid(k, dim, h), h ** dim, factor * h)


def _displacement(body, scale=0.05, seed=0):
    h = body.volumes[0] ** (1 / body.dim)
    return scale * h * np.random.default_rng(seed).standard_normal(body.points.shape)


def _fd_jacobian(f, x, step):
    cols = []
    for k in range(x.size):
        e = np.zeros(x.size)
        e[k] = step
        cols.append((f(x + e) - f(x - e)) / (2 * step))
    return np.array(cols).T


MATERIALS = [(2, (1.0, 0.0, 0.0)), (2, (1.0, 0.7, 0.0)), (3, (1.0, 0.0, 0.0)),
             (3, (1.0, 0.5, 0.0)), (3, (1.0, 0.5, 0.3))]


@pytest.mark.parametrize("dim, C", MATERIALS)
@pytest.mark.parametrize("exponent", [2.0, 1.0, 0.0, -1.0, 0.5])
def test_hyperdual_equals_the_hand_derived_derivatives(dim, C, exponent):
    body = _body(dim)
    u = _displacement(body)
    inter = pd.CPD(*C, exponent=exponent).interactions(body)
    e_h, f_h, K_h = inter.evaluate(u)
    analytic = pd.CPD(*C, exponent=exponent, derivatives="analytic")
    e_a, f_a, K_a = inter.with_material(analytic).evaluate(u)
    assert abs(e_h - e_a) <= 1e-12 * e_a
    np.testing.assert_allclose(f_h, f_a, rtol=0, atol=1e-10 * np.abs(f_a).max())
    assert abs(K_h - K_a).max() <= 1e-10 * abs(K_a).max()
    assert abs(K_h - K_h.T).max() <= 1e-13 * abs(K_h).max()


@pytest.mark.parametrize("dim, C", MATERIALS)
def test_force_and_tangent_are_the_derivatives_of_the_energy(dim, C):
    body = _body(dim)
    inter = pd.CPD(*C, exponent=1.0).interactions(body)
    x = _displacement(body).reshape(-1)
    energy, force, K = inter.evaluate(x)
    step = 1e-6 * body.volumes[0] ** (1 / dim)
    grad = _fd_jacobian(lambda v: np.atleast_1d(inter.evaluate(v, tangent=False)[0]), x, step)
    np.testing.assert_allclose(grad[0], force, rtol=0, atol=1e-7 * np.abs(force).max())
    J = _fd_jacobian(inter.internal_force, x, step)
    np.testing.assert_allclose(J, K.toarray(), rtol=0, atol=1e-6 * abs(K).max())


@pytest.mark.slow
def test_user_energy_written_with_hyperdual_functions():
    """A neo-Hookean-like stretch energy and an exponential area energy: the residual and
    tangent by hyper-dual numbers are the derivatives of the energy (finite
    differences), and ``derivatives="fd"`` agrees to its truncation error."""
    neo = lambda lam: 0.5 * (lam * lam - 1.0) - hd.log(lam)                # noqa: E731
    expo = lambda lam: hd.exp(lam - 1.0) - lam                              # noqa: E731
    for dim in (2, 3):
        body = _body(dim)
        extra = {"psi3": expo, "C3": 0.4} if dim == 3 else {}
        mat = pd.CPD(1.0, 0.6, psi1=neo, psi2=expo, **extra)
        inter = mat.interactions(body)
        x = _displacement(body, 0.1).reshape(-1)
        energy, force, K = inter.evaluate(x)
        step = 1e-6 * body.volumes[0] ** (1 / dim)
        grad = _fd_jacobian(lambda v: np.atleast_1d(inter.evaluate(v, tangent=False)[0]),
                            x, step)
        np.testing.assert_allclose(grad[0], force, rtol=0, atol=1e-7 * np.abs(force).max())
        J = _fd_jacobian(inter.internal_force, x, step)
        np.testing.assert_allclose(J, K.toarray(), rtol=0, atol=1e-6 * abs(K).max())
        seth_hill = pd.CPD(1.0, 0.6, **extra).interactions(body).evaluate(x)[1]
        assert np.abs(seth_hill - force).max() > 1e-3 * np.abs(force).max()
        fd = pd.CPD(1.0, 0.6, psi1=neo, psi2=expo, derivatives="fd", **extra)
        _, f_fd, K_fd = fd.interactions(body).evaluate(x)
        np.testing.assert_allclose(f_fd, force, rtol=0, atol=1e-6 * np.abs(force).max())
        assert abs(K_fd - K).max() <= 1e-5 * abs(K).max()


def test_energy_of_eq_8_by_hand():
    """Three points (0, 0), (h, 0), (0, h) with horizon 1.01 h: four bonds and one pair
    at the corner; a homogeneous stretch diag(lx, ly)."""
    h, lx, ly, n = 0.5, 1.3, 0.8, 1.0
    body = pd.Body(np.array([[0, 0], [h, 0], [0, h]]), 0.2, 1.01 * h)
    beta = body.beta[0]
    C1, C2 = 2.0, 3.0
    u = body.points * [lx - 1, ly - 1]
    energy = pd.CPD(C1, C2, exponent=n).interactions(body).evaluate(u, tangent=False)[0]
    S2 = lambda lam: 0.5 * ((lam ** n - 1) / n) ** 2                          # noqa: E731
    bonds = 2 * 0.5 * 0.2 * 0.2 * beta * C1 * h * (S2(lx) + S2(ly))
    pair = 2 / 3 * 0.2 * (0.2 * beta) ** 2 * C2 * h * h * S2(lx * ly)
    assert np.isclose(energy, bonds + pair, rtol=1e-14)


def test_pairs_and_triplets_on_lattices():
    """Nearest neighbours only: collinear pairs and coplanar triplets are left out."""
    h = 0.5
    inter = pd.CPD(1.0, 1.0).interactions(pd.Body(_grid(3, 2, h), h * h, 1.01 * h))
    # centre: 4 of 6 pairs, edge midpoints: 2 of 3, corners: 1 of 1
    assert len(inter.pairs) == 4 + 4 * 2 + 4 * 1
    np.testing.assert_allclose(inter.pair_ref, h * h, rtol=1e-14)
    body = pd.Body(_grid(3, 3, h), h ** 3, 1.01 * h)
    inter = pd.CPD(1.0, 0.0, 1.0).interactions(body)
    centre = 13
    mine = body.bond_i[inter.triplets[:, 0]] == centre
    assert mine.sum() == 8                       # one per octant: 20 minus 12 coplanar
    np.testing.assert_allclose(np.abs(inter.triplet_ref), h ** 3, rtol=1e-14)
    assert (body.bond_i[inter.triplets] == body.bond_i[inter.triplets[:, :1]]).all()


@pytest.mark.parametrize("dim, C", MATERIALS[1::2] + [MATERIALS[-1]])
def test_frame_indifference(dim, C):
    body = _body(dim)
    inter = pd.CPD(*C, exponent=1.0).interactions(body)
    x = body.points
    typical = np.abs(inter.internal_force(0.1 * x * (np.arange(dim) == 0))).max()
    # at rest, after a rigid translation and after a rigid rotation of 30 degrees
    assert np.abs(inter.internal_force(np.zeros_like(x))).max() <= 1e-14 * typical
    assert np.abs(inter.internal_force(np.full_like(x, 0.3))).max() <= 1e-14 * typical
    Q = _rotation(np.pi / 6, dim)
    assert np.abs(inter.internal_force(x @ Q.T - x)).max() <= 1e-12 * typical
    # a rotated reference configuration: the same energy, the rotated forces
    u = _displacement(body, 0.1)
    energy, force, _ = inter.evaluate(u, tangent=False)
    turned = pd.Body(x @ Q.T, body.volumes, body.horizon)
    energy_r, force_r, _ = pd.CPD(*C, exponent=1.0).interactions(turned).evaluate(
        u @ Q.T, tangent=False)
    assert np.isclose(energy_r, energy, rtol=1e-12)
    np.testing.assert_allclose(force_r.reshape(-1, dim), force.reshape(-1, dim) @ Q.T,
                               atol=1e-12 * typical)


def _stretched_strip(material, stretch):
    h = 0.1
    pts = _grid(11, 2, h)
    prob = pd.Problem(pd.Body(pts, h * h, 3.015 * h), material)
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, 0, 0.0)
    prob.add_dirichlet(lambda p: p[:, 0] > 1 - 1e-9, 0, stretch)
    prob.add_dirichlet(lambda p: (p[:, 0] < 1e-9) & (np.abs(p[:, 1] - 0.5) < 1e-9), 1)
    return prob, pts


def test_uniaxial_stretch_converges_quadratically():
    """30 % stretch with free lateral edges; C2 >> C1 preserves the area of the pairs'
    triangles (paper §6.1: nearly incompressible), so the width tends to 1 / 1.3."""
    prob, pts = _stretched_strip(pd.CPD(1.0, 1e4), 0.3)
    sol = prob.solve_static()
    (res,) = sol.residual_history
    rel = np.array(res) / res[0]
    assert rel[-1] <= 1e-10 and len(res) <= 8
    # quadratic in the last iterations: r_{k+1} <= C r_k^2
    tail = [(a, b) for a, b in zip(rel[:-1], rel[1:]) if a < 1e-2]
    assert len(tail) >= 2 and all(b <= 10 * a * a for a, b in tail), rel
    # the hand-derived tangent converges alike (round-off apart, amplified by the solves)
    analytic, _ = _stretched_strip(pd.CPD(1.0, 1e4, derivatives="analytic"), 0.3)
    np.testing.assert_allclose(analytic.solve_static().residual_history[0][:4], res[:4],
                               rtol=1e-4)
    # equilibrium: the reactions balance; free edges contract symmetrically
    f = prob.interactions.internal_force(sol.u).reshape(-1, 2)
    left, right = pts[:, 0] < 1e-9, pts[:, 0] > 1 - 1e-9
    assert abs(f[left, 0].sum() + f[right, 0].sum()) < 1e-8 * abs(f[left, 0].sum())
    mid = np.abs(pts[:, 0] - 0.5) < 1e-9
    y = pts[mid, 1] + sol.u[mid, 1]
    np.testing.assert_allclose(y + y[::-1], 1.0, atol=1e-9)
    assert abs(np.ptp(y) * 1.3 - 1.0) < 5e-3
    # without two-neighbour interactions the strip contracts much less
    alone, _ = _stretched_strip(pd.CPD(1.0), 0.3)
    y1 = pts[mid, 1] + alone.solve_static().u[mid, 1]
    assert 0.85 < np.ptp(y1) < 1.0


def test_line_search():
    """100 % stretch of a logarithmic material in one step: plain Newton's residual goes
    up on the way, the backtracking one decreases at every iterate."""
    prob, _ = _stretched_strip(pd.CPD(1.0, 1.0, exponent=0.0), 1.0)
    (res,) = prob.solve_static(max_iterations=40).residual_history
    assert any(b > a for a, b in zip(res[:-1], res[1:]))
    (res,) = prob.solve_static(line_search=True).residual_history
    assert all(b < a for a, b in zip(res[:-1], res[1:])) and res[-1] <= 1e-10 * res[0]


def test_load_steps_reach_the_same_state():
    prob, _ = _stretched_strip(pd.CPD(1.0, 1.0), 0.3)
    one = prob.solve_static()
    three = prob.solve_static(steps=3)
    assert len(three.residual_history) == 3
    assert all(r[-1] <= 1e-10 * r[0] for r in three.residual_history)
    np.testing.assert_allclose(three.u, one.u, atol=1e-9)


def test_a_step_that_cannot_converge_is_named():
    prob, _ = _stretched_strip(pd.CPD(1.0, 1.0), 0.3)
    with pytest.raises(cnem.SolveError, match=r"load step 1 of 2: residual .* after 1 "):
        prob.solve_static(steps=2, max_iterations=1)


def test_errors():
    body2 = _body(2)
    with pytest.raises(ValueError, match="C3.*3-D only"):
        pd.CPD(1.0, 0.0, 1.0).interactions(body2)
    with pytest.raises(ValueError, match="C3.*3-D only"):
        pd.Problem(body2, pd.CPD(1.0, 1.0, 0.5))
    with pytest.raises(ValueError, match="C1 > 0"):
        pd.CPD(0.0)
    with pytest.raises(ValueError, match="analytic"):
        pd.CPD(1.0, psi1=lambda lam: lam, derivatives="analytic")
    with pytest.raises(ValueError, match="psi2 is given but C2 = 0"):
        pd.CPD(1.0, psi2=lambda lam: lam)
    with pytest.raises(ValueError, match="derivatives"):
        pd.CPD(1.0, derivatives="complex")
    with pytest.raises(ValueError, match="surface correction does not apply"):
        pd.Problem(body2, pd.CPD(1.0), surface_correction=True)
    with pytest.raises(ValueError, match="u: expected 50"):
        pd.CPD(1.0).interactions(body2).evaluate(np.zeros(7))
    with pytest.raises(ValueError, match="same kinds of interactions"):
        pd.CPD(1.0).interactions(body2).with_material(pd.CPD(1.0, 1.0))
    prob, _ = _stretched_strip(pd.CPD(1.0), 0.1)
    with pytest.raises(NotImplementedError, match="CPD"):
        prob.solve_static().stress
    free = pd.Problem(body2, pd.CPD(1.0, 1.0))
    with pytest.raises(cnem.SolveError, match="translation in x.*translation in y.*rotation"):
        free.solve_static()


def test_linear_model_methods_refuse_cpd():
    """Methods of the linear models say that they do not apply to CPD."""
    g = np.arange(4.0)
    pts = np.stack(np.meshgrid(g, g, indexing="ij"), -1).reshape(-1, 2)
    prob = cnem.pd.Problem(cnem.pd.Body(pts, 1.0, 1.5), cnem.pd.CPD(1.0))
    u = np.zeros_like(pts)
    for call in (lambda: prob.stiffness(), lambda: prob.stress_tensor(u), lambda: prob.energy_density(u),
                 lambda: prob.stable_time_step(), lambda: prob.run_dynamic(1e-3, 1),
                 lambda: prob.relax()):
        with pytest.raises(NotImplementedError, match="not for CPD"):
            call()
