"""3-D SCNI across material interfaces (`cnem.assembly.interface_facets`).

The cells on the two sides of an interface cut it into different polygons; their
facets are integrated on the common refinement, so the integration constraint holds
across it: a linear field on a two-region body of one material, and the piecewise
linear field of a bimaterial (displacement and traction continuous across the
interface plane), are reproduced to round-off, with and without the stabilisation.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely

import cnem
from cnem.assembly.facet_gradients import model_interface_pieces
from cnem.assembly.interface_facets import _triangle_overlaps
from cnem.geometry.shapes3d import box_surface
from cnem.material import LinearElastic

A = np.array([[0.3, -0.2, 0.1], [0.05, -0.4, 0.25], [0.15, 0.2, 0.35]]) * 1e-2
LOWER, UPPER = (3.0, 0.3), (12.0, 0.2)
Z_INTERFACE = 0.5


@pytest.fixture(scope="module", params=[1, 2])
def two_boxes(request):
    """Two boxes stacked on z = 0.5 (seed 2 puts interface triangles of the two sides
    edge to edge)."""
    dom = cnem.Domain3D([box_surface((0, 0, 0), (1, 1, Z_INTERFACE)),
                         box_surface((0, 0, Z_INTERFACE), (1, 1, 1))])
    return cnem.discretize(cnem.nodes.irregular(dom, 0.25, seed=request.param))


def _on_boundary(prob, n):
    faces, _ = prob.boundary_edges()
    on = np.zeros(n, dtype=bool)
    on[faces.ravel()] = True
    return on


def _stress(grad, material):
    eps = 0.5 * (grad + grad.T)
    lam_mu = LinearElastic(*material).elasticity_matrix(3)
    voigt = np.array([eps[0, 0], eps[1, 1], eps[2, 2], 2 * eps[1, 2], 2 * eps[0, 2], 2 * eps[0, 1]])
    s = lam_mu @ voigt
    return np.array([[s[0], s[5], s[4]], [s[5], s[1], s[3]], [s[4], s[3], s[2]]])


def _upper_gradient():
    """``A + a e_z^T``: the gradient above the interface whose field is continuous
    with ``A x`` below and whose traction ``sigma e_z`` matches (3 equations in a)."""
    ez = np.array([0.0, 0.0, 1.0])
    target = _stress(A, LOWER) @ ez
    jac = np.column_stack([_stress(np.outer(e, ez), UPPER) @ ez for e in np.eye(3)])
    a = np.linalg.solve(jac, target - _stress(A, UPPER) @ ez)
    return A + np.outer(a, ez)


def _bimaterial_field(p):
    upper = np.maximum(p[:, 2] - Z_INTERFACE, 0.0)
    return p @ A.T + upper[:, None] * (_upper_gradient() - A)[:, 2][None, :]


def test_the_exact_field_is_continuous_in_displacement_and_traction():
    g = _upper_gradient()
    ez = np.array([0.0, 0.0, 1.0])
    np.testing.assert_allclose(g[:, :2], A[:, :2], rtol=0, atol=0)
    np.testing.assert_allclose(_stress(g, UPPER) @ ez, _stress(A, LOWER) @ ez, atol=1e-15)
    assert np.abs(g - A).max() > 1e-3        # a real kink


def test_triangle_overlaps_against_shapely():
    rng = np.random.default_rng(0)
    a, b = rng.uniform(-1, 1, (2, 400, 3, 2))
    area, centre = _triangle_overlaps(a, b)
    ref = shapely.intersection(shapely.polygons(a), shapely.polygons(b))
    np.testing.assert_allclose(area, shapely.area(ref), atol=1e-14)
    hit = area > 1e-6
    assert 50 < hit.sum() < 400
    c = shapely.centroid(ref[hit])
    np.testing.assert_allclose(centre[hit], np.column_stack([shapely.get_x(c), shapely.get_y(c)]),
                               atol=1e-10)


def test_triangles_on_two_sides_of_an_edge_do_not_overlap():
    """Two triangles sharing an edge (from the interface of seed 2) meet in no area;
    a triangle meets itself (either orientation) in its area, centred on its centroid."""
    p, q = np.array([0.5269537805043139, 0.5263531149759143]), np.array([0.1758912375388952,
                                                                          0.6058797085300986])
    a = np.array([[p, [0.3001476882008815, 0.756515200592028], q]])
    b = np.array([[q, p, [0.50966209778223, 0.5082821533665767]]])
    (ux, uy), (vx, vy) = a[0, 1] - a[0, 0], a[0, 2] - a[0, 0]
    own = 0.5 * abs(ux * vy - uy * vx)
    for x, y, expected in ((a, b, 0.0), (b, a, 0.0), (a, a[:, ::-1], own)):
        area, centre = _triangle_overlaps(x, y)
        assert abs(area[0] - expected) <= 1e-15
    np.testing.assert_allclose(centre[0], a[0].mean(axis=0), atol=1e-15)


def test_pieces_cover_both_sides(two_boxes):
    m = two_boxes
    pieces = model_interface_pieces(m, m.cells)
    cells = m.cells
    tri = cells.facet_triangles[pieces.on_interface]
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    # every interface facet is cut, each side's pieces tile the interface square once
    assert np.isclose(area.sum(), 2.0, rtol=1e-12)
    np.testing.assert_allclose(np.abs(pieces.area_normal_a[:, 2]).sum(), 1.0, rtol=1e-12)
    np.testing.assert_allclose(pieces.area_normal_a, -pieces.area_normal_b, atol=1e-15)
    np.testing.assert_allclose(pieces.point[:, 2], Z_INTERFACE, atol=1e-15)
    region = cells.region[cells.facet_cell]
    assert np.all(region[pieces.tri_a] != region[pieces.tri_b])


@pytest.mark.parametrize("stabilization", [0.0, 1.0])
def test_linear_field_across_an_interface_of_one_material(two_boxes, stabilization):
    m = two_boxes
    prob = cnem.Elasticity(m, [LOWER, LOWER], stabilization=stabilization)
    prob.add_dirichlet(_on_boundary(prob, len(m.nodes)), None, lambda p: p @ A.T)
    sol = prob.solve(progress=False)
    exact = m.nodes @ A.T
    assert np.abs(sol.u - exact).max() <= 1e-12 * np.abs(exact).max()


@pytest.mark.parametrize("stabilization", [0.0, 1.0])
def test_bimaterial_patch_test(two_boxes, stabilization):
    m = two_boxes
    assert np.all((m.nodes[m.cells.node, 2] <= Z_INTERFACE) | (m.cells.region == 1))
    prob = cnem.Elasticity(m, [LOWER, UPPER], stabilization=stabilization)
    prob.add_dirichlet(_on_boundary(prob, len(m.nodes)), None, _bimaterial_field)
    sol = prob.solve(progress=False)
    exact = _bimaterial_field(m.nodes)
    assert np.abs(sol.u - exact).max() <= 1e-10 * np.abs(exact).max()


@pytest.mark.parametrize("stabilization", [0.0, 1.0])
def test_tractions_on_a_two_region_body(two_boxes, stabilization):
    """The traction points are the outer facets only (not the interface's): clamped
    on x = 0 and loaded by the field's tractions elsewhere, the field is exact."""
    m = two_boxes
    sv = _stress(A, LOWER)
    prob = cnem.Elasticity(m, [LOWER, LOWER], stabilization=stabilization)
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None, lambda p: p @ A.T)
    prob.add_traction(lambda x, n: x[:, 0] > 1e-9, lambda x, n: n @ sv)
    sol = prob.solve(progress=False)
    exact = m.nodes @ A.T
    assert np.abs(sol.u - exact).max() <= 1e-12 * np.abs(exact).max()


def test_a_split_facet_keeps_its_points_on_it():
    """A thin L-shaped facet (a bisector wrapping a re-entrant edge) has its centroid off
    itself, in the notch. Cut with ``split``, each piece of the two sides' (differently
    triangulated) triangles keeps its own point, on the facet, and the pieces still
    cover each side's area."""
    from cnem.assembly.interface_facets import interface_pieces

    outline = shapely.Polygon([(0, 0), (1, 0), (1, 0.2), (0.2, 0.2), (0.2, 1), (0, 1)])
    sides = []
    for sign, flip in ((1.0, False), (-1.0, True)):
        rects = [shapely.box(0, 0, 1, 0.2), shapely.box(0, 0.2, 0.2, 1)] if not flip else \
            [shapely.box(0, 0, 0.2, 1), shapely.box(0.2, 0, 1, 0.2)]
        for rect in rects:
            for tri in shapely.get_parts(shapely.delaunay_triangles(rect)):
                xy = np.asarray(tri.exterior.coords)[:3]
                xyz = np.column_stack([xy, np.zeros(3)])
                if np.cross(xyz[1] - xyz[0], xyz[2] - xyz[0])[2] * sign < 0:
                    xyz = xyz[::-1]
                sides.append((xyz, sign, int(flip)))
    tri = np.array([t for t, _, _ in sides])
    normal = np.array([[0.0, 0.0, s] for _, s, _ in sides])
    group = np.array([g for _, _, g in sides])
    every = np.ones(len(tri), dtype=bool)
    merged = interface_pieces(tri, normal, group, np.zeros((0, 3, 3)), 1.0, also=every)
    assert not outline.buffer(1e-12).contains(shapely.points(merged.point[:, :2])).any()
    pieces = interface_pieces(tri, normal, group, np.zeros((0, 3, 3)), 1.0, also=every,
                              split=every)
    assert len(pieces.point) > 2
    assert outline.buffer(1e-12).contains(shapely.points(pieces.point[:, :2])).all()
    np.testing.assert_allclose(pieces.area_normal_a.sum(axis=0), [0, 0, 0.36], atol=1e-14)
    np.testing.assert_allclose(pieces.area_normal_b.sum(axis=0), [0, 0, -0.36], atol=1e-14)
