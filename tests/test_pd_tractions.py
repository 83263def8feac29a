"""PD tractions (`cnem.pd.Problem.add_traction`): the point forces sum to the traction times
the loaded boundary area, in 2-D and 3-D, on bodies from clouds and on lattices; the same
traction in C-NEM and PD pulls a bar by the same amount (to PD's discretisation error)."""

from __future__ import annotations

import numpy as np
import pytest

import cnem
import cnem.pd as pd

E, NU = 1000.0, 0.3


def _plate_with_hole(h=0.2):
    """A 3 x 2 plate (origin (1, -1)) with a hole of radius 0.4 at (2.5, 0), a body from
    its cloud of thickness 0.5."""
    hole = cnem.geometry.arc((2.5, 0.0), 0.4, 0.0, 2 * np.pi, h / 2)[:-1][::-1]
    shell = [[1.0, -1.0], [4.0, -1.0], [4.0, 1.0], [1.0, 1.0]]
    dom = cnem.Domain([(shell, [hole])])
    return pd.Body.from_cloud(cnem.nodes.irregular(dom, h), thickness=0.5), hole


def test_the_resultant_is_the_traction_times_the_area_2d():
    body, hole = _plate_with_hole()
    prob = pd.Problem(body, pd.StateBased(E, NU))
    prob.add_traction(lambda x, n: x[:, 0] > 4.0 - 1e-9, [3.0, -1.0])     # edge x = 4, length 2
    force = prob.load().reshape(-1, 2)
    np.testing.assert_allclose(force.sum(axis=0), np.array([3.0, -1.0]) * 2.0 * 0.5, rtol=1e-13)
    assert np.flatnonzero(np.abs(force).sum(axis=1)).size == \
        np.count_nonzero(body.points[:, 0] > 4.0 - 1e-9)          # on that edge's nodes only
    # a traction linear along the edge: its integral (int_-1^1 (y + 2) dy = 4) and its
    # moment about the origin (int_-1^1 -y (y + 2) dy = -2/3), times the thickness
    prob = pd.Problem(body, pd.StateBased(E, NU))
    prob.add_traction(lambda x, n: x[:, 0] > 4.0 - 1e-9, lambda x, n: np.column_stack(
        [x[:, 1] + 2.0, np.zeros(len(x))]))
    force = prob.load().reshape(-1, 2)
    assert force[:, 0].sum() == pytest.approx(4.0 * 0.5, rel=1e-13)
    moment = (body.points[:, 0] * force[:, 1] - body.points[:, 1] * force[:, 0]).sum()
    assert moment == pytest.approx(-2.0 / 3.0 * 0.5, rel=1e-12)
    # a pressure on the hole: no resultant, and its push away from the centre: on each chord
    # of the hole's polygon the pressure times the chord's length and its distance from
    # the centre over the radius (sum f . r / R over the nodes, r from the centre)
    prob = pd.Problem(body, pd.StateBased(E, NU))
    prob.add_traction(lambda x, n: np.hypot(x[:, 0] - 2.5, x[:, 1]) < 0.41,
                      lambda x, n: -5.0 * n)
    force = prob.load().reshape(-1, 2)
    assert np.abs(force.sum(axis=0)).max() < 1e-12
    radial = (force * (body.points - [2.5, 0.0])).sum() / 0.4
    a, b = hole - [2.5, 0.0], np.roll(hole, -1, axis=0) - [2.5, 0.0]
    chords = np.abs(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]) / 0.4    # length x distance / R
    assert radial == pytest.approx(5.0 * chords.sum() * 0.5, rel=1e-12)


def test_a_boundary_name_loads_that_boundary():
    dom = cnem.Domain([[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]],
                      boundaries={"top": [[0.0, 1.0], [2.0, 1.0]]})
    body = pd.Body.from_cloud(cnem.nodes.regular(dom, 0.25))
    prob = pd.Problem(body, pd.StateBased(E, NU))
    prob.add_traction("top", [0.0, -2.0])
    assert prob.load().reshape(-1, 2).sum(axis=0) == pytest.approx([0.0, -4.0], rel=1e-13)


def test_the_resultant_is_the_traction_times_the_area_3d():
    box = cnem.geometry.box((0.0, 0.0, 0.0), (2.0, 1.0, 0.5))
    body = pd.Body.from_cloud(cnem.nodes.regular(box, 0.25))
    prob = pd.Problem(body, pd.StateBased(E, NU))
    prob.add_traction(lambda x, n: n[:, 0] > 0.5, [1.0, 2.0, -3.0])      # face x = 2: 1 x 0.5
    force = prob.load().reshape(-1, 3)
    np.testing.assert_allclose(force.sum(axis=0), [0.5, 1.0, -1.5], rtol=1e-13)
    assert np.all(body.points[np.abs(force).sum(axis=1) > 0, 0] > 2.0 - 1e-9)


def test_a_lattice_needs_the_area_or_the_spacing():
    dx, thick = 0.1, 0.3
    g = (np.arange(10) + 0.5) * dx                           # cell-centred: 10 x 10 cells
    points = np.array([(x, y) for x in g for y in g])
    body = pd.Body(points, dx * dx * thick, 3 * dx, thickness=thick)
    top = lambda p: p[:, 1] > 1.0 - dx                                  # the outermost row
    prob = pd.Problem(body, pd.StateBased(E, NU))
    prob.add_traction(top, [0.0, 2.0], spacing=dx)
    assert prob.load().reshape(-1, 2).sum(axis=0) == pytest.approx([0.0, 2.0 * 1.0 * thick])
    prob = pd.Problem(body, pd.StateBased(E, NU))
    prob.add_traction(top, lambda x, n: 2.0 * n, area=dx * thick, normal=[0.0, 1.0])
    assert prob.load().reshape(-1, 2).sum(axis=0) == pytest.approx([0.0, 2.0 * 1.0 * thick])
    with pytest.raises(cnem.ConditionError, match="exactly one of area= .* received neither"):
        prob.add_traction(top, [0.0, 1.0])
    with pytest.raises(cnem.ConditionError, match="received both"):
        prob.add_traction(top, [0.0, 1.0], area=0.1, spacing=0.1)
    with pytest.raises(cnem.ConditionError, match="needs the outward normal"):
        prob.add_traction(top, lambda x, n: n, spacing=dx)
    with pytest.raises(cnem.ConditionError, match="vector of 2 components"):
        prob.add_traction(top, 5.0, spacing=dx)
    with pytest.raises(cnem.ConditionError, match="area: expected positive"):
        prob.add_traction(top, [0.0, 1.0], area=-1.0)


def test_a_body_from_a_cloud_refuses_areas_of_the_user():
    body = pd.Body.from_cloud(cnem.nodes.regular(cnem.geometry.rectangle(), 0.25))
    prob = pd.Problem(body, pd.StateBased(E, NU))
    with pytest.raises(cnem.ConditionError, match="expected no spacing"):
        prob.add_traction(lambda x, n: n[:, 1] > 0.5, [0.0, 1.0], spacing=0.25)
    with pytest.raises(cnem.ConditionError, match="expected a predicate where\\(x, nrm\\)"):
        prob.add_traction(lambda x: x[:, 1] > 1 - 1e-9, [0.0, 1.0])


def _bar(h, L=4.0, H=1.0, sigma=2.0):
    """The mean displacement of the loaded end of a bar pulled by a traction sigma, by C-NEM
    and by PD on the same nodes (rollers on the left end), and PD's strain in the middle."""
    cloud = cnem.nodes.regular(cnem.geometry.rectangle(L, H), h)
    tol = 1e-9 * L
    right = lambda x, n: x[:, 0] > L - tol
    ends = []
    for prob in (cnem.Elasticity(cnem.discretize(cloud), (E, NU), plane="stress"),
                 pd.Problem(pd.Body.from_cloud(cloud), pd.StateBased(E, NU), plane="stress")):
        prob.add_traction(right, [sigma, 0.0])
        prob.add_dirichlet(lambda x: x[:, 0] < tol, 0)
        prob.add_dirichlet(lambda x: np.hypot(*x.T) < tol, 1)
        x, u = prob.condition_points, prob.solve(**({"progress": False} if
                                                    isinstance(prob, cnem.Elasticity) else {})).u
        ends.append(u[x[:, 0] > L - tol, 0].mean())
    middle = np.abs(x[:, 0] - L / 2) < L / 4
    strain = np.polyfit(x[middle, 0], u[middle, 0], 1)[0]
    return np.array(ends) / (sigma * L / E), strain / (sigma / E)


def test_a_bar_pulled_by_the_same_traction_in_cnem_and_pd():
    coarse, _ = _bar(0.25)
    fine, strain = _bar(0.125)
    assert coarse[0] == pytest.approx(1.0, abs=1e-12) and fine[0] == pytest.approx(1.0, abs=1e-12)
    # PD: the right stress in the bulk, and the end displacement off by its boundary layers
    # (about three spacings wide at each end), which halve with the spacing
    assert strain == pytest.approx(1.0, abs=0.02)
    assert abs(fine[1] - 1.0) < 0.1
    assert abs(fine[1] - 1.0) == pytest.approx(abs(coarse[1] - 1.0) / 2, rel=0.25)
