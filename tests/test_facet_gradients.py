"""3-D smoothed gradients from facet quadratures (`cnem.assembly.facet_gradients`) and
the pyramid sub-cells (`cnem.assembly.pyramid_cells`).

On synthetic cells — the Delaunay tetrahedra of a jittered cube lattice — with the
P1 interpolant as the shape functions, the smoothed gradient of every cell must be
the P1 gradient of its tetrahedron (the field is linear there, and the facet rule
integrates linear functions exactly), and so must the gradient of every pyramid
sub-cell from an apex inside (or on a face of) the cell.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.spatial import Delaunay

from cnem.assembly.facet_gradients import (facet_gradient, facet_points, facet_rule,
                                           gradients_of_rules)
from cnem.assembly.pyramid_cells import merged_across_holes, pyramid_sub_cells
from cnem.errors import GeometryError


def _lattice(k=4, seed=0, scale=1.0):
    rng = np.random.default_rng(seed)
    axis = np.linspace(0.0, 1.0, k)
    nodes = np.array(list(itertools.product(axis, axis, axis)))
    free = (nodes > 0.0) & (nodes < 1.0)        # jitter along the faces too: no cocircular
    nodes += free * rng.uniform(-0.15, 0.15, nodes.shape) / (k - 1)    # squares, no flat tets
    nodes = nodes * scale
    dt = Delaunay(nodes)
    tets = dt.simplices
    six_v = np.linalg.det(nodes[tets[:, 1:]] - nodes[tets[:, :1]])
    keep = np.abs(six_v) > 1e-9 * scale ** 3
    return nodes, dt, tets[keep]


def _p1(nodes, dt):
    """The P1 interpolant's values at points, ``csr (q, n)``."""
    def evaluate(points):
        simplex = dt.find_simplex(points, tol=1e-9)
        assert np.all(simplex >= 0)
        T = dt.transform[simplex]
        bary = np.einsum("qij,qj->qi", T[:, :3], points - T[:, 3])
        bary = np.column_stack([bary, 1.0 - bary.sum(axis=1)])
        q = len(points)
        return sp.csr_matrix((bary.ravel(), (np.repeat(np.arange(q), 4),
                                             dt.simplices[simplex].ravel())),
                             shape=(q, len(nodes)))
    return evaluate


def _facets(nodes, tets):
    """The four faces of every tetrahedron, oriented outward, their cells and normals."""
    corners = nodes[tets]
    six_v = np.linalg.det(corners[:, 1:] - corners[:, :1])
    tets = np.where((six_v > 0)[:, None], tets, tets[:, [1, 0, 2, 3]])
    faces = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]])
    tri = nodes[tets[:, faces]].reshape(-1, 3, 3)
    cell = np.repeat(np.arange(len(tets)), 4)
    nrm = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    nrm /= np.linalg.norm(nrm, axis=1)[:, None]
    return tets, tri, cell, nrm, np.abs(six_v) / 6.0


def _p1_gradients(nodes, tets):
    corners = nodes[tets]
    inv = np.linalg.inv(corners[:, 1:] - corners[:, :1])
    return np.concatenate([-inv.sum(axis=2)[:, None, :], np.transpose(inv, (0, 2, 1))], axis=1)


@pytest.mark.parametrize("scale", [1.0, 1e-3, 1e3])
def test_cell_gradients_are_the_p1_gradients(scale):
    nodes, dt, tets = _lattice(scale=scale)
    tets, tri, cell, nrm, vol = _facets(nodes, tets)
    grad = facet_gradient(tri, cell, nrm, vol, _p1(nodes, dt))
    exact = _p1_gradients(nodes, tets)                     # (t, 4, 3)
    for i in range(3):
        dense = grad.components[i].toarray()
        expected = np.zeros_like(dense)
        np.put_along_axis(expected, tets, exact[:, :, i], axis=1)
        np.testing.assert_allclose(dense, expected, atol=1e-10 / scale)


@pytest.mark.parametrize("apex", ["centroid", "face"])
def test_sub_cell_gradients_are_the_p1_gradients_and_fill_the_cell(apex):
    nodes, dt, tets = _lattice(k=3)
    tets, tri, cell, nrm, vol = _facets(nodes, tets)
    corners = nodes[tets]
    node_xyz = corners.mean(axis=1) if apex == "centroid" else corners[:, 1:].mean(axis=1)
    parent, triangle_sub, sub_vol, spokes = pyramid_sub_cells(node_xyz, tri, cell, nrm)
    np.testing.assert_allclose(np.bincount(parent, weights=sub_vol, minlength=len(tets)), vol,
                               rtol=1e-12)
    assert len(sub_vol) == (4 if apex == "centroid" else 3) * len(tets)
    grad = facet_gradient(tri, triangle_sub, nrm, sub_vol, _p1(nodes, dt), spokes=spokes)
    exact = _p1_gradients(nodes, tets)[parent]
    for i in range(3):
        dense = grad.components[i].toarray()
        expected = np.zeros_like(dense)
        np.put_along_axis(expected, tets[parent], exact[:, :, i], axis=1)
        np.testing.assert_allclose(dense, expected, atol=1e-10)


def test_rules_evaluated_together_equal_each_alone_and_evaluate_each_point_once():
    nodes, dt, tets = _lattice(k=3)
    tets, tri, cell, nrm, vol = _facets(nodes, tets)
    parent, triangle_sub, sub_vol, spokes = pyramid_sub_cells(nodes[tets].mean(axis=1), tri,
                                                              cell, nrm)
    evaluated = []

    def one_by_one(points):
        """The P1 values point by point (`find_simplex` starts where the last point's
        walk ended: a point on a face would take either tetrahedron)."""
        return sp.vstack([_p1(nodes, dt)(x[None]) for x in points], format="csr")

    def recorded(points):
        evaluated.append(np.array(points))
        return one_by_one(points)

    rules = [facet_rule(tri, triangle_sub, nrm, sub_vol, spokes=spokes),
             facet_rule(tri, cell, nrm, vol)]
    together = gradients_of_rules(rules, recorded)
    (points,) = evaluated                                   # one call
    assert len(np.unique(points, axis=0)) == len(points)    # no point twice
    # the sub-cells' facet points are the cells': fewer points than the two rules hold
    assert len(points) <= sum(len(rule.points) for rule in rules) - len(rules[1].points)
    alone = [facet_gradient(tri, triangle_sub, nrm, sub_vol, one_by_one, spokes=spokes),
             facet_gradient(tri, cell, nrm, vol, one_by_one)]
    for got, want in zip(together, alone):
        for a, b in zip(got.components, want.components):
            assert np.array_equal(a.indptr, b.indptr) and np.array_equal(a.indices, b.indices)
            np.testing.assert_array_equal(a.data, b.data)


def test_cells_without_volume_are_refused():
    nodes, dt, tets = _lattice(k=3)
    tets, tri, cell, nrm, vol = _facets(nodes, tets)
    vol[2] = 0.0
    with pytest.raises(GeometryError, match="positive volume"):
        facet_gradient(tri, cell, nrm, vol, _p1(nodes, dt))


def test_a_facet_gets_one_point_whatever_its_triangles():
    """A square facet cut along either diagonal, or into four, gives the same point
    and area-normal: the two cells sharing it evaluate it alike."""
    sq = np.array([[0.0, 0.0, 0.5], [1.0, 0.0, 0.5], [1.0, 1.0, 0.5], [0.0, 1.0, 0.5]]) * 0.3
    cuts = [sq[[[0, 1, 2], [0, 2, 3]]], sq[[[0, 1, 3], [1, 2, 3]]],
            np.array([[sq[i], sq[(i + 1) % 4], sq.mean(axis=0)] for i in range(4)])]
    for tri in cuts:
        cell, point, area_normal = facet_points(tri, np.zeros(len(tri), dtype=np.int64),
                                                np.tile([0.0, 0.0, 1.0], (len(tri), 1)))
        assert cell.tolist() == [0]
        np.testing.assert_allclose(point, [sq.mean(axis=0)], rtol=1e-15, atol=1e-16)
        np.testing.assert_allclose(area_normal, [[0.0, 0.0, 0.09]], rtol=1e-14)


def _cube_cell():
    """One cubic cell around its node, each square facet cut into two triangles."""
    corner = np.array(list(itertools.product([0.0, 1.0], repeat=3)))
    squares = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4],
               [1, 5, 7, 3]]                                   # outward, counter-clockwise
    tri = np.array([corner[[s[0], s[k], s[k + 1]]] for s in squares for k in (1, 2)])
    nrm = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    return tri, np.zeros(len(tri), dtype=np.int64), nrm / np.linalg.norm(nrm, axis=1)[:, None]


def _smooth_functions(points):
    """Three non-polynomial functions of the points, as a ``(q, 3)`` CSR matrix."""
    x, y, z = points.T
    return sp.csr_matrix(np.column_stack([np.exp(x * y), np.sin(3 * z + x), 1 / (2 + y * z)]))


@pytest.mark.parametrize("node", [[0.5, 0.5, 0.5], [0.2, 0.7, 0.4], [0.0, 0.5, 0.5]])
def test_sub_cells_integrals_add_up_to_their_cells(node):
    """The pyramids take the cell's facet points and their spokes cancel: sum_s V_s b_s
    equals V b of the cell for any functions, also when a facet through the node
    (a node on the cell's boundary) has no pyramid."""
    tri, cell, nrm = _cube_cell()
    whole = facet_gradient(tri, cell, nrm, np.array([1.0]), _smooth_functions)
    parent, triangle_sub, vol, spokes = pyramid_sub_cells(np.array([node]), tri, cell, nrm)
    assert np.isclose(vol.sum(), 1.0, rtol=1e-14)
    assert len(vol) == (5 if node[0] == 0.0 else 6)
    subs = facet_gradient(tri, triangle_sub, nrm, vol, _smooth_functions, spokes=spokes)
    for w, s in zip(whole.components, subs.components):
        np.testing.assert_allclose(vol @ s.toarray(), w.toarray()[0], rtol=1e-13, atol=1e-14)


def test_parallel_facets_of_one_cell_are_two_facets():
    """A non-convex cell (at a re-entrant edge) can have two facets with the same outward
    normal in different planes (a boundary face and a bisector beyond it): each keeps
    its own point, in its own plane."""
    square = np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 1.0, 1.0], [0.0, 0.0, 1.0]])
    tri = np.concatenate([square[[[0, 1, 2], [0, 2, 3]]], square[[[0, 1, 2], [0, 2, 3]]]
                          + [1.0, 2.0, 0.0]])
    cell, point, area_normal = facet_points(tri, np.zeros(4, dtype=np.int64),
                                            np.tile([1.0, 0.0, 0.0], (4, 1)))
    assert cell.tolist() == [0, 0]
    np.testing.assert_allclose(np.sort(point[:, 0]), [0.0, 1.0], atol=1e-15)
    np.testing.assert_allclose(area_normal, [[1.0, 0.0, 0.0]] * 2, rtol=1e-15)


def test_pyramids_merge_across_a_spoke_outside_the_body():
    """A spoke whose point lies outside the body joins its two pyramids into one
    sub-cell: the volumes add up, the spoke is gone, and the sub-cells' integrals
    still add up to their cell's."""
    tri, cell, nrm = _cube_cell()
    whole = facet_gradient(tri, cell, nrm, np.array([1.0]), _smooth_functions)
    parent, triangle_sub, vol, spokes = pyramid_sub_cells(np.array([[0.5, 0.5, 0.5]]), tri,
                                                          cell, nrm)
    outside = np.zeros(len(spokes[0]), dtype=bool)
    outside[0] = True
    a, b = spokes[2][0], spokes[3][0]
    assert len(spokes[0]) == 12
    parent, triangle_sub, merged, spokes = merged_across_holes(parent, triangle_sub, vol, spokes,
                                                               ~outside)
    assert len(merged) == 5
    assert np.isclose(merged.max(), vol[a] + vol[b], rtol=1e-14)
    assert len(spokes[0]) == 11 and np.all(spokes[2] != spokes[3])      # 12 cube edges
    subs = facet_gradient(tri, triangle_sub, nrm, merged, _smooth_functions, spokes=spokes)
    for w, s in zip(whole.components, subs.components):
        np.testing.assert_allclose(merged @ s.toarray(), w.toarray()[0], rtol=1e-13, atol=1e-14)
