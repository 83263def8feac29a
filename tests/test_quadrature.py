"""Quadrature on triangles and cell polygons (`cnem.assembly.quadrature`), and the
graded rule of the cell-boundary quadrature (`cnem.assembly.edge_quadrature`).

Checked against exact integrals: polynomials up to the rule's degree, the signed
areas, and ``∫ 1/r`` over a triangle with a corner at the singular point
(closed form), which a plain Gauss rule gets wrong by an amount that does not
shrink with the triangle.
"""

from __future__ import annotations

import numpy as np
import pytest

import cases
import cnem
from cnem.assembly.quadrature import cell_quadrature, triangle_quadrature
from cnem.assembly.edge_quadrature import graded_rule


def _monomial_integral(corners, a, b):
    """∫ x^a y^b over triangles, exactly: the degree-19 rule is exact for these."""
    tri, pts, w = triangle_quadrature(corners, 19)
    return np.bincount(tri, weights=w * pts[:, 0] ** a * pts[:, 1] ** b, minlength=len(corners))


def _inverse_r_integral(p, b, c):
    """∫ 1/|x - p| over the triangle (p, b, c): ``d (asinh tan β_c - asinh tan β_b)``,
    ``d`` the distance from p to the line bc and β the angles from its normal."""
    t = (c - b) / np.linalg.norm(c - b)
    foot = b + ((p - b) @ t) * t
    d = np.linalg.norm(foot - p)
    return d * (np.arcsinh(((c - foot) @ t) / d) - np.arcsinh(((b - foot) @ t) / d))


def _random_triangles(rng, count):
    corners = rng.uniform(-1, 1, (count, 3, 2))
    e1, e2 = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    ccw = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0] > 0
    corners[~ccw] = corners[~ccw][:, ::-1]
    return corners


@pytest.mark.parametrize("order", [2, 4, 6])
@pytest.mark.parametrize("where", ["none", "vertex", "edge", "inside"])
def test_polynomials_up_to_the_degree_are_exact(order, where):
    rng = np.random.default_rng(order)
    corners = _random_triangles(rng, 20)
    singular = {"none": np.zeros((0, 2)),
                "vertex": corners[:, 1],
                "edge": 0.3 * corners[:, 0] + 0.7 * corners[:, 2],
                "inside": corners.mean(axis=1)}[where]
    tri, pts, w = triangle_quadrature(corners, order, singular=singular)
    for a in range(order + 1):
        for b in range(order + 1 - a):
            got = np.bincount(tri, weights=w * pts[:, 0] ** a * pts[:, 1] ** b,
                              minlength=len(corners))
            assert np.allclose(got, _monomial_integral(corners, a, b), rtol=1e-12, atol=1e-13)


def test_weights_add_up_to_signed_areas():
    rng = np.random.default_rng(1)
    corners = _random_triangles(rng, 10)
    corners[::2] = corners[::2][:, ::-1]                       # clockwise: negative areas
    e1, e2 = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    area = 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    tri, _, w = triangle_quadrature(corners, 4, singular=corners[:, 0] + 0.25 * (e1 + e2))
    assert np.allclose(np.bincount(tri, weights=w, minlength=10), area, rtol=1e-13)


@pytest.mark.parametrize("scale", [1.0, 1e-3])
def test_collapsed_rule_integrates_inverse_r(scale):
    """∫ 1/r about a corner: the collapsed rule converges to the closed form, a plain
    Gauss rule has a relative error that is the same at every scale."""
    p = np.array([0.2, -0.1])
    b, c = p + scale * np.array([1.0, 0.2]), p + scale * np.array([0.3, 0.9])
    exact = _inverse_r_integral(p, b, c)
    corners = np.array([[p, b, c]])
    errors = {}
    for order in (2, 4, 8, 12):
        _, pts, w = triangle_quadrature(corners, order, singular=[p])
        errors[order] = abs(w @ (1 / np.hypot(*(pts - p).T)) / exact - 1)
    _, pts, w = triangle_quadrature(corners, 8)
    plain = abs(w @ (1 / np.hypot(*(pts - p).T)) / exact - 1)
    assert errors[12] < 1e-7 and errors[12] < errors[8] < errors[4] < errors[2]
    assert plain > 1e-3 and errors[4] < 1e-2 * plain


def test_singular_point_shared_by_triangles_and_far_away():
    """A point at a vertex shared by several triangles splits each of them; a point
    outside every triangle changes nothing."""
    fan = np.array([[[0, 0], [1, 0], [0.5, 1]], [[0, 0], [0.5, 1], [-1, 0.5]],
                    [[0, 0], [-1, 0.5], [-0.5, -1]]], float)
    tri, pts, w = triangle_quadrature(fan, 14, singular=[[0.0, 0.0]])
    exact = sum(_inverse_r_integral(np.zeros(2), t[1], t[2]) for t in fan)
    assert abs(w @ (1 / np.hypot(*pts.T)) / exact - 1) < 1e-7
    far = triangle_quadrature(fan, 4, singular=[[5.0, 5.0]])
    plain = triangle_quadrature(fan, 4)
    for x, y in zip(far, plain):
        assert np.array_equal(x, y)


@pytest.mark.parametrize("name", cases.CRACKED)
def test_cell_quadrature_at_crack_tips_keeps_cell_areas(name):
    _, _, model = cases.model(name)
    tips = model.domain.tips
    cell, _, w = cell_quadrature(model.cells, model.nodes, 4, singular=tips)
    assert np.allclose(np.bincount(cell, weights=w, minlength=len(model.cells.area)),
                       model.cells.area, rtol=1e-12)
    plain, _, _ = cell_quadrature(model.cells, model.nodes, 4)
    assert len(cell) > len(plain)                       # the tips' triangles were split


@pytest.mark.parametrize("gauss", [2, 3, 4])
def test_graded_rule_integrates_sqrt_ends(gauss):
    """``∫_0^1 sqrt(t) t^k`` and ``∫_0^1 sqrt(1 - t) t^k`` exactly with the ends graded."""
    s, w = np.polynomial.legendre.leggauss(gauss)
    s, w = 0.5 * (s + 1.0), 0.5 * w
    S, W = graded_rule(s, w, np.array([True, False, False]), np.array([False, True, False]))
    for k in range(gauss - 1):
        exact = 1.0 / (k + 1.5)
        assert abs(W[0] @ (np.sqrt(S[0]) * S[0] ** k) - exact) < 1e-14
        assert abs(W[1] @ (np.sqrt(1 - S[1]) * (1 - S[1]) ** k) - exact) < 1e-14
    assert np.array_equal(S[2], s) and np.array_equal(W[2], w)
    plain = abs(w @ np.sqrt(s) - 2 / 3)
    assert plain > 1e-4


@pytest.mark.parametrize("name", ["whole", "node_apex"])
def test_subdivide_checks_its_per_cell_flags(name):
    from cnem.assembly.subdivision import subdivide
    model = cnem.discretize(cnem.nodes.regular(cnem.geometry.rectangle(), 0.25))
    m = len(model.cells.area)
    with pytest.raises(ValueError, match=rf"{name}: expected one flag per cell, shape \({m},\), "
                                         rf"received shape \({m - 1},\)"):
        subdivide(model.cells, model.nodes, **{name: np.zeros(m - 1, dtype=bool)})
