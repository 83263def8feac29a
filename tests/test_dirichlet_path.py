"""Dirichlet conditions of `cnem.Hyperelasticity` that follow a path over the load steps
(`Hyperelasticity.add_dirichlet(..., path=...)`): a rigid rotation of the whole boundary
turns the whole body rigidly at every load step (zero stress), where the linear ramp of
the same final displacements does not; the values per load factor; bad paths named."""

from __future__ import annotations

import numpy as np
import pytest

import cnem
from cnem.material import NeoHookean

THETA = 2.5                       # radians: beyond a quarter turn, where a ramp is far off
CENTRE = np.array([0.3, -0.2])


def _turned(p, t):
    """Displacements of points ``(p, 2)`` turned by ``t THETA`` about `CENTRE`."""
    c, s = np.cos(t * THETA), np.sin(t * THETA)
    x = p - CENTRE
    return x @ np.array([[c, s], [-s, c]]) - x


@pytest.fixture(scope="module")
def model():
    return cnem.discretize(cnem.nodes.irregular(cnem.geometry.rectangle(2.0, 1.0), 0.2, seed=3))


def _boundary_problem(model, **kw):
    prob = cnem.Hyperelasticity(model, NeoHookean(1.0, 3.0))
    boundary = np.unique(prob.boundary_edges()[0])
    prob.add_dirichlet(boundary, None, **kw)
    return prob


def test_rotation_path_turns_the_whole_body_rigidly_at_every_step(model):
    """Every node at ``(R(t THETA) - I)(X - c)`` after each load step ``t = k / 4``, no
    stress (to 1e-10 of mu), no strain; the linear ramp of the last step's displacements
    ends there too, but halfway shrinks the body to ``cos^2(THETA / 2)`` of its area."""
    prob = _boundary_problem(model, path=_turned)
    sol = prob.solve(steps=4, progress=False)
    assert [t for t, _ in sol.steps] == [0.25, 0.5, 0.75, 1.0]
    for t, dofs in sol.steps:
        np.testing.assert_allclose(dofs.reshape(-1, 2), _turned(model.nodes, t), rtol=0,
                                   atol=1e-10)
    assert np.abs(sol.stress).max() < 1e-10 and np.abs(sol.strain).max() < 1e-10
    ramp = _boundary_problem(model, value=lambda p: _turned(p, 1.0))
    ramped = ramp.solve(steps=2, progress=False)
    np.testing.assert_allclose(ramped.u, sol.u, rtol=0, atol=1e-10)
    _, halfway = ramped.series()[0]              # F = (I + R) / 2 = cos(THETA / 2) R(THETA / 2)
    np.testing.assert_allclose(np.linalg.det(halfway.deformation_gradient),
                               np.cos(THETA / 2) ** 2, rtol=1e-8)


def test_prescribed_at_follows_paths_and_ramps(model):
    prob = cnem.Hyperelasticity(model, NeoHookean(1.0, 3.0))
    left = lambda p: p[:, 0] < 1e-9                                # noqa: E731
    prob.add_dirichlet(left, None, path=_turned)
    prob.add_dirichlet(lambda p: p[:, 0] > 2 - 1e-9, 1, 0.4)
    nodes = np.flatnonzero(left(model.nodes))
    right = np.flatnonzero(model.nodes[:, 0] > 2 - 1e-9)
    for t in (0.3, 1.0):
        dofs, values = prob.prescribed_at(t)
        u = np.full(2 * len(model.nodes), np.nan)
        u[dofs] = values
        np.testing.assert_allclose(u.reshape(-1, 2)[nodes], _turned(model.nodes[nodes], t))
        np.testing.assert_allclose(u.reshape(-1, 2)[right, 1], 0.4 * t)
    np.testing.assert_array_equal(prob.prescribed_at(1.0)[1], prob.prescribed()[1])


def test_bad_paths_are_named(model):
    prob = cnem.Hyperelasticity(model, NeoHookean(1.0, 3.0))
    left = lambda p: p[:, 0] < 1e-9                                # noqa: E731
    with pytest.raises(cnem.InputError, match="path: expected a callable"):
        prob.add_dirichlet(left, None, path=np.zeros(2))
    with pytest.raises(cnem.InputError, match="both a value and a path"):
        prob.add_dirichlet(left, 0, 0.5, path=lambda p, t: t * p[:, 0])
    with pytest.raises(cnem.InputError, match="callable of two arguments"):
        prob.add_dirichlet(left, 0, path=lambda p: p[:, 0])
    with pytest.raises(cnem.errors.ConditionError, match=r"shape \(\d+, 2\)"):
        prob.add_dirichlet(left, None, path=lambda p, t: t * p[:, :1].T)
    assert prob.dirichlet == []
    prob.add_dirichlet(left, 0, path=lambda p, t: np.where(t < 1, np.nan, 0.0) + 0 * p[:, 0])
    prob.add_dirichlet(left, 1)
    with pytest.raises(cnem.errors.ConditionError, match="t = 0.5: expected finite"):
        prob.solve(steps=2, progress=False)


def test_a_path_and_a_ramp_must_agree_at_every_step(model):
    """Both reach 0.1 on the left edge's x at the end, only the ramp is there halfway."""
    prob = cnem.Hyperelasticity(model, NeoHookean(1.0, 3.0))
    left = lambda p: p[:, 0] < 1e-9                                # noqa: E731
    prob.add_dirichlet(left, 0, path=lambda p, t: 0.1 * t ** 2 + 0 * p[:, 0])
    prob.add_dirichlet(left, 0, 0.1)
    prob.add_dirichlet(left, 1)
    with pytest.raises(cnem.errors.ConditionError, match="conflicting"):
        prob.prescribed_at(0.5)
    prob.prescribed_at(1.0)
