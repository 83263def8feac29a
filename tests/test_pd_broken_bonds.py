"""Broken bonds in the state-based (LPS) peridynamic solid: a bond that broke carries
neither dilatation nor force, so a body cut in two by breaking every bond across a line
is two bodies.

The dilatation sums the live bonds with the moment tensors of the live bonds; the weighted
volume ``m`` of the deviatoric part stays that of the reference family (the usual
convention, Silling et al. 2007, as Peridigm), so a half's deviatoric forces are those of a
separate body with the reference ``m``. Checked: the stiffness couples no dof of one half to
the other; a half's dilatations, forces, energies and stresses do not depend on the other
half's displacement; a rigid motion of a half (translation and rotation) strains nothing in
it whatever the other half does; a half's dilatation is that of the same points taken as a
separate body, for any displacement; an undamaged body's dilatation is still the trace of
its nonlocal gradient; the operators follow the bonds as they break and heal.
"""

from __future__ import annotations

import numpy as np
import pytest

import cnem.pd as pd

H = 0.05
CUT = 0.5 - 0.5 * H                    # between two columns of points


def _points():
    x, y = np.arange(0.0, 1.0 + 1e-9, H), np.arange(0.0, 0.5 + 1e-9, H)
    X, Y = np.meshgrid(x, y, indexing="ij")
    return np.column_stack([X.ravel(), Y.ravel()])


def _crossing(body):
    """Bonds from one side of ``x = CUT`` to the other."""
    p = body.points
    return (p[body.bond_i, 0] < CUT) != (p[body.bond_j, 0] < CUT)


@pytest.fixture(scope="module", params=[False, True], ids=["plain", "corrected"])
def cut(request):
    """A state-based plate with every bond across ``x = CUT`` broken, and its left half."""
    body = pd.Body(_points(), H * H, 3.015 * H)
    prob = pd.Problem(body, pd.StateBased(2.0, 0.3), plane="strain",
                      surface_correction=request.param)
    prob.alive[_crossing(body)] = 0
    assert (prob.alive == 0).sum() > 50
    return prob, body.points[:, 0] < CUT


def _field(p, a, b):
    """A smooth non-linear displacement field ``(n, 2)`` (small)."""
    x, y = p[:, 0], p[:, 1]
    return 1e-3 * np.column_stack([np.sin(a * x + y) + x * y, np.cos(b * y - x) + a * x * x])


def _dofs(mask):
    return np.repeat(mask, 2)


def test_the_stiffness_couples_no_dof_across_the_cut(cut):
    prob, left = cut
    K = prob.stiffness().tocsr()
    L, R = _dofs(left), _dofs(~left)
    assert abs(K[L][:, R]).max() == 0.0 and abs(K[R][:, L]).max() == 0.0
    assert abs(K[L][:, L]).max() > 0.0


def test_a_half_does_not_feel_the_other_halfs_displacement(cut):
    prob, left = cut
    p = prob.body.points
    u1 = np.where(left[:, None], _field(p, 2.0, 3.0), _field(p, 5.0, -1.0))
    u2 = np.where(left[:, None], _field(p, 2.0, 3.0), _field(p, -4.0, 7.0))
    K = prob.stiffness()
    for half in (left, ~left):
        v1 = np.where(half[:, None], u1, _field(p, 1.0, 1.0))     # the other half differs
        v2 = np.where(half[:, None], u2, _field(p, -2.0, 6.0))
        for a, b in ((v1, np.where(half[:, None], u1, 0.0)), (v2, np.where(half[:, None], u2, 0.0))):
            fa, fb = (K @ a.reshape(-1)).reshape(-1, 2), (K @ b.reshape(-1)).reshape(-1, 2)
            scale = np.abs(fa[half]).max()
            assert scale > 0
            assert np.abs(fa[half] - fb[half]).max() <= 1e-12 * scale
            ta, tb = prob.T @ a.reshape(-1), prob.T @ b.reshape(-1)
            assert np.abs(ta[half] - tb[half]).max() <= 1e-12 * np.abs(ta[half]).max()
            wa, wb = prob.energy_density(a), prob.energy_density(b)
            assert np.abs(wa[half] - wb[half]).max() <= 1e-12 * np.abs(wa[half]).max()
            sa, sb = prob.stress_tensor(a), prob.stress_tensor(b)
            assert np.abs(sa[half] - sb[half]).max() <= 1e-12 * np.abs(sa[half]).max()


def test_a_rigid_motion_of_a_half_strains_nothing_in_it(cut):
    prob, left = cut
    p = prob.body.points
    rigid = np.array([1e-3, -2e-3]) + 1e-3 * np.column_stack([-p[:, 1], p[:, 0]])
    u = np.where(left[:, None], rigid, _field(p, 3.0, 2.0)).reshape(-1)
    scale = np.abs(prob.stiffness() @ u).max()
    f = (prob.stiffness() @ u).reshape(-1, 2)
    assert np.abs(f[left]).max() <= 1e-12 * scale
    theta = prob.T @ u
    assert np.abs(theta[left]).max() <= 1e-12 * np.abs(theta).max()
    assert prob.energy_density(u)[left].max() <= 1e-12 * prob.energy_density(u).max()


def test_a_halfs_dilatation_is_that_of_the_half_as_a_separate_body(cut):
    prob, left = cut
    p = prob.body.points
    u = np.where(left[:, None], _field(p, 2.0, 3.0), _field(p, 5.0, -1.0))
    eps = np.array([[1e-3, 4e-4], [4e-4, -6e-4]])
    theta, uniform = prob.T @ u.reshape(-1), prob.T @ (p @ eps.T).reshape(-1)
    for half in (left, ~left):
        separate = pd.Problem(pd.Body(p[half], H * H, 3.015 * H), pd.StateBased(2.0, 0.3),
                              plane="strain")
        expected = separate.T @ u[half].reshape(-1)
        np.testing.assert_allclose(theta[half], expected, rtol=0,
                                   atol=1e-12 * np.abs(expected).max())
        np.testing.assert_allclose(uniform[half], np.trace(eps), rtol=1e-12)


def test_an_undamaged_body_keeps_the_trace_of_its_gradient():
    body = pd.Body(_points(), H * H, 3.015 * H)
    prob = pd.Problem(body, pd.StateBased(2.0, 0.3))
    u = _field(body.points, 2.0, 3.0)
    grad = prob.displacement_gradient(u)
    np.testing.assert_allclose(prob.T @ u.reshape(-1), np.trace(grad, axis1=1, axis2=2),
                               rtol=1e-12, atol=1e-12 * np.abs(grad).max())


def test_the_operators_follow_the_bonds_that_break():
    body = pd.Body(_points(), H * H, 3.015 * H)
    prob = pd.Problem(body, pd.StateBased(2.0, 0.3))
    u = _field(body.points, 2.0, 3.0).reshape(-1)
    before = prob.T @ u
    prob.alive[_crossing(body)] = 0
    after = prob.T @ u
    touched = np.bincount(body.bond_i[_crossing(body)], minlength=len(body)) > 0
    assert (after[~touched] == before[~touched]).all()
    assert (after[touched] != before[touched]).all()
    prob.alive[:] = 1
    np.testing.assert_array_equal(prob.T @ u, before)
