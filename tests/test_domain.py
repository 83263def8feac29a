"""`cnem.Domain` and the builders of `cnem.geometry`: areas, bounds, tips, queries, PSLG."""

from __future__ import annotations

import re

import numpy as np
import pytest
import shapely

import cnem
import cases
from cnem import geometry, nodes

BOUNDARY, INTERFACE, CRACK = 0, 1, 2
UNIT = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]


def _ngon_area(r, n):
    """Area of a regular n-gon inscribed in a circle of radius r."""
    return 0.5 * n * r**2 * np.sin(2 * np.pi / n)


def _edge_length(pslg, kind):
    v, e = pslg.vertices, pslg.edges[pslg.kind == kind]
    return float(np.linalg.norm(v[e[:, 0]] - v[e[:, 1]], axis=1).sum())


# ------------------------------------------------------------ area, bounds
def test_rectangle_area_bounds_and_orientation():
    dom = geometry.rectangle(2.0, 0.5, origin=(-1.0, 3.0))
    assert dom.area == pytest.approx(1.0, rel=1e-15)
    assert dom.bounds == (-1.0, 3.0, 1.0, 3.5)
    assert dom.diameter == pytest.approx(np.hypot(2.0, 0.5), rel=1e-15)
    assert len(dom.regions) == 1 and dom.regions[0].exterior.is_ccw
    assert len(dom.tips) == 0 and dom.tips.shape == (0, 2)


def test_clockwise_input_is_reoriented():
    dom = cnem.Domain(UNIT[::-1])
    assert dom.regions[0].exterior.is_ccw
    assert dom.area == 1.0


def test_l_shape_area():
    dom = geometry.l_shape(2.0, 0.5)
    assert dom.area == pytest.approx(4.0 - 0.25, rel=1e-15)
    assert dom.bounds == (0.0, 0.0, 2.0, 2.0)
    assert not dom.contains([[1.75, 1.75]])[0] and dom.contains([[1.25, 1.25]])[0]


def test_plate_with_hole_area_is_the_inscribed_polygon():
    r = 0.2
    dom = geometry.plate_with_hole(1.0, 1.0, r)
    (hole,) = dom.regions[0].interiors
    ring = np.asarray(hole.coords)[:-1]
    np.testing.assert_allclose(np.linalg.norm(ring - 0.5, axis=1), r, rtol=1e-14)
    expected = 1.0 - _ngon_area(r, len(ring))
    assert dom.area == pytest.approx(expected, rel=1e-12)
    assert 1 - np.pi * r**2 < dom.area < 1 - np.pi * r**2 + np.pi * r**2 * (2 * np.pi / len(ring))**2
    assert dom.region_of([[0.5, 0.5]])[0] == -1 and not dom.contains([[0.5, 0.5]])[0]


@pytest.mark.parametrize("spacing", [0.05, 0.2])
def test_annulus_regions_and_areas(spacing):
    radii = [1.0, 1.5, 2.0]
    dom = geometry.annulus(radii, spacing=spacing)
    assert len(dom.regions) == 2
    for k, poly in enumerate(dom.regions):
        r_in, r_out = radii[k], radii[k + 1]
        outer = np.asarray(poly.exterior.coords)[:-1]
        (inner,) = [np.asarray(h.coords)[:-1] for h in poly.interiors]
        np.testing.assert_allclose(np.linalg.norm(outer, axis=1), r_out, rtol=1e-14)
        np.testing.assert_allclose(np.linalg.norm(inner, axis=1), r_in, rtol=1e-14)
        # chords no longer than the spacing; the area is that of the two polygons
        for ring in (outer, inner):
            chords = np.linalg.norm(np.roll(ring, -1, axis=0) - ring, axis=1)
            assert chords.max() <= spacing * (1 + 1e-12)
        exact = np.pi * (r_out**2 - r_in**2)
        deficit = lambda r: np.pi * r**2 * (2 * np.arcsin(spacing / (2 * r)))**2 / 6  # noqa: E731
        assert exact - deficit(r_out) <= poly.area <= exact + deficit(r_in)
    assert dom.area == pytest.approx(sum(p.area for p in dom.regions), rel=1e-15)
    # the circle of radius 1.5 is an interface: same vertices on both sides
    inter = dom.pslg.edges[dom.pslg.kind == INTERFACE]
    assert len(inter) > 0
    v = dom.pslg.vertices
    np.testing.assert_allclose(np.linalg.norm(v[inter.ravel()], axis=1), 1.5, rtol=1e-14)
    bnd = dom.pslg.edges[dom.pslg.kind == BOUNDARY]
    radius = np.linalg.norm(v[bnd.ravel()], axis=1)
    assert np.all(np.isclose(radius, 1.0) | np.isclose(radius, 2.0))


def test_annulus_sector():
    dom = geometry.annulus([1.0, 2.0, 3.0], angles=(0.0, np.pi / 2), spacing=0.1)
    assert len(dom.regions) == 2
    exact = np.pi / 4 * (9.0 - 1.0)
    assert dom.area == pytest.approx(exact, rel=1e-3)
    assert dom.area < exact     # inscribed arcs
    assert dom.region_of([[1.5, 0.1], [0.1, 2.5], [-0.1, 1.5], [0.5, 0.5]]).tolist() == [0, 1, -1, -1]


# ------------------------------------------------------------------ tips
@pytest.mark.parametrize("cracks, tips", [
    ([cases.EDGE_CRACK], [[0.5, 0.5]]),
    ([[[0.3, 0.5], [0.7, 0.5]]], [[0.3, 0.5], [0.7, 0.5]]),
    ([cases.KINKED_CRACK], [cases.KINKED_CRACK[0], cases.KINKED_CRACK[-1]]),
    ([[[0.0, 0.2], [1.0, 0.3]]], np.empty((0, 2))),                      # through crack
    ([[[0.3, 0.5], [0.7, 0.5]], [[1.0, 0.1], [0.8, 0.2]]], [[0.3, 0.5], [0.7, 0.5], [0.8, 0.2]]),
])
def test_tips(cracks, tips):
    dom = geometry.rectangle(1.0, 1.0, cracks=cracks)
    got = sorted(map(tuple, dom.tips.tolist()))
    assert got == sorted(map(tuple, np.asarray(tips, float).tolist()))
    assert dom.area == 1.0     # cracks remove no area


def test_crack_from_a_hole_is_an_edge_crack():
    dom = geometry.plate_with_hole(1.0, 1.0, 0.2, cracks=[[[0.7, 0.5], [0.85, 0.5]]])
    np.testing.assert_array_equal(dom.tips, [[0.85, 0.5]])
    # the crack mouth on the hole is a vertex, and the hole edge is split there
    v = dom.pslg.vertices
    assert (np.linalg.norm(v - [0.7, 0.5], axis=1) == 0).sum() == 1


# --------------------------------------------------------- contains, region_of
def test_contains_and_region_of():
    dom = cnem.Domain([UNIT, [[1, 0], [2, 0], [2, 1], [1, 1]]])
    pts = [[0.5, 0.5], [1.5, 0.5], [1.0, 0.5], [3.0, 0.5], [-1e-3, 0.5], [0.0, 0.5], [2.0, 1.0],
           [1.0, 1.0]]
    np.testing.assert_array_equal(dom.region_of(pts), [0, 1, 0, -1, -1, 0, 1, 0])
    np.testing.assert_array_equal(dom.contains(pts), [1, 1, 1, 0, 0, 1, 1, 1])
    assert dom.region_of(np.empty((0, 2))).shape == (0,)
    assert dom.region_of([1.5, 0.5]).tolist() == [1]       # a single point
    # lowest index wins on an interface, whatever the order of the regions
    dom2 = cnem.Domain([[[1, 0], [2, 0], [2, 1], [1, 1]], UNIT])
    assert dom2.region_of([[1.0, 0.5]]).tolist() == [0]
    assert dom2.region_of([[0.5, 0.5]]).tolist() == [1]


@pytest.mark.parametrize("regions", [
    [UNIT],
    [UNIT, [[1, 0], [2, 0], [2, 1], [1, 1]]],
    [[[1e6, 1e6], [1e6 + 1e-6, 1e6], [1e6 + 1e-6, 1e6 + 3e-6], [1e6, 1e6 + 3e-6]]],
    [[[0, 0], [1, 0], [1, 1], [0.5, 1], [0, 1]]],            # a rectangle with a vertex mid-edge
    [[[0, 0], [1, 0], [1, 1], [0, 0.5]]],                     # not a rectangle
])
def test_region_of_a_rectangle_is_shapely_s_closed_polygon_test(regions):
    """Rectangular regions are tested by coordinate comparisons: the same answers as
    shapely's ``intersects_xy`` of the closed polygons, inside, outside and exactly on
    the sides and corners, the lowest region winning on an interface."""
    dom = cnem.Domain(regions)
    x0, y0, x1, y1 = dom.bounds
    rng = np.random.default_rng(0)
    pts = np.array([x0, y0]) + np.array([x1 - x0, y1 - y0]) * rng.uniform(-0.1, 1.1, (20000, 2))
    corners = np.array([[x, y] for p in dom.regions for x, y in p.exterior.coords])
    pts[:100, 0] = x0
    pts[100:200, 1] = y1
    pts[200:300, 0] = corners[rng.integers(len(corners), size=100), 0]
    pts[300:300 + len(corners)] = corners
    want = np.full(len(pts), -1)
    for i in reversed(range(len(dom.regions))):
        want[shapely.intersects_xy(dom.regions[i], pts[:, 0], pts[:, 1])] = i
    np.testing.assert_array_equal(dom.region_of(pts), want)


def test_region_of_with_holes_and_rings():
    dom = geometry.annulus([1.0, 1.5, 2.0], spacing=0.05)
    theta = 0.3
    pts = [[0.0, 0.0], [1.25 * np.cos(theta), 1.25 * np.sin(theta)],
           [1.75 * np.cos(theta), 1.75 * np.sin(theta)], [2.5, 0.0],
           [1.5, 0.0],      # a vertex of the interface circle
           [2.0, 0.0],      # a vertex of the outer boundary
           [0.5, 0.5]]      # in the hole
    np.testing.assert_array_equal(dom.region_of(pts), [-1, 0, 1, -1, 0, 1, -1])


def test_domain_from_shapely_and_tuple():
    hole = [[0.4, 0.4], [0.6, 0.4], [0.6, 0.6], [0.4, 0.6]]
    a = cnem.Domain(shapely.Polygon(UNIT, [hole]))
    b = cnem.Domain((UNIT, [hole]))
    c = cnem.Domain([(UNIT, [hole])])
    for d in (a, b, c):
        assert d.area == pytest.approx(0.96, rel=1e-14)
        assert len(d.regions) == 1
        assert d.region_of([[0.5, 0.5], [0.2, 0.2]]).tolist() == [-1, 0]


# -------------------------------------------------------------------- PSLG
def test_pslg_of_a_square():
    dom = geometry.rectangle()
    p = dom.pslg
    assert len(p.vertices) == 4 and len(p.edges) == 4
    assert np.all(p.kind == BOUNDARY)
    # every vertex has degree 2 in a single ring
    assert np.array_equal(np.bincount(p.edges.ravel()), [2, 2, 2, 2])


def test_interfaces_with_different_vertices_are_shared():
    """Region 1 and 2 put vertices (1, 0.5) and (1.3, 0.5) inside edges of their neighbours."""
    dom = cnem.Domain(cases.THREE_RECTANGLES)
    p = dom.pslg
    v = p.vertices
    # each vertex once
    d = np.linalg.norm(v[:, None] - v[None], axis=2) + np.eye(len(v))
    assert d.min() > 0
    for q in ([1.0, 0.5], [1.3, 0.5]):
        assert (np.linalg.norm(v - q, axis=1) == 0).sum() == 1
    inter = p.edges[p.kind == INTERFACE]
    seg = {tuple(sorted(map(tuple, v[e].tolist()))) for e in inter}
    assert seg == {((1.0, 0.0), (1.0, 0.5)), ((1.0, 0.5), (1.0, 1.0)),
                   ((1.0, 0.5), (1.3, 0.5)), ((1.3, 0.5), (2.0, 0.5))}
    assert _edge_length(p, INTERFACE) == pytest.approx(2.0, rel=1e-14)
    assert _edge_length(p, BOUNDARY) == pytest.approx(6.0, rel=1e-14)
    # no edge is repeated, and no vertex lies inside an edge
    assert len(np.unique(np.sort(p.edges, axis=1), axis=0)) == len(p.edges)
    lines = shapely.linestrings(v[p.edges])
    for k, q in enumerate(v):
        touching = np.flatnonzero(shapely.distance(lines, shapely.Point(q)) <= 1e-12)
        ends = (p.edges[touching] == k).any(axis=1)
        assert ends.all(), f"vertex {q} lies inside edge {p.edges[touching[~ends]]}"


def test_partly_shared_boundary_is_interface_only_where_shared():
    dom = cnem.Domain([UNIT, [[1.0, 0.0], [2.0, 0.0], [2.0, 0.5], [1.0, 0.5]]])
    p = dom.pslg
    inter = p.edges[p.kind == INTERFACE]
    assert {tuple(sorted(map(tuple, p.vertices[e].tolist()))) for e in inter} == {
        ((1.0, 0.0), (1.0, 0.5))}
    # boundary: square (4) minus the shared half (0.5) + rectangle (3) minus it (0.5)
    assert _edge_length(p, BOUNDARY) == pytest.approx(4.0 - 0.5 + 3.0 - 0.5, rel=1e-14)
    cloud = nodes.regular(dom, 0.1)
    on_line = np.flatnonzero(np.abs(cloud.points[:, 0] - 1.0) <= 1e-12)
    pts = cloud.points[on_line]
    # the nodes on x = 1 are shared by both regions: each point once
    assert len(np.unique(pts, axis=0)) == len(pts)
    # interface segments of the cloud run exactly along x = 1, 0 <= y <= 0.5, and chain
    iseg = cloud.segments[cloud.segment_kind == INTERFACE]
    assert np.all(np.abs(cloud.points[iseg.ravel(), 0] - 1.0) <= 1e-12)
    assert np.linalg.norm(np.diff(cloud.points[iseg], axis=1), axis=2).sum() == pytest.approx(0.5)
    model = cnem.discretize(cloud, progress=False)
    inner = np.unique(iseg)
    for i in inner:
        assert sorted(model.cells.region[model.cells.node == i].tolist()) == [0, 1]
    assert abs(model.cells.area.sum() - dom.area) <= 1e-12 * dom.area


def test_crack_crossing_an_interface_gets_a_vertex_there():
    dom = cnem.Domain([UNIT, [[1, 0], [2, 0], [2, 1], [1, 1]]], cracks=[[[0.5, 0.4], [1.5, 0.6]]])
    v = dom.pslg.vertices
    assert (np.linalg.norm(v - [1.0, 0.5], axis=1) <= 1e-12).sum() == 1
    assert len(dom.tips) == 2
    crack = dom.pslg.edges[dom.pslg.kind == CRACK]
    assert len(crack) == 2
    assert _edge_length(dom.pslg, CRACK) == pytest.approx(np.hypot(1.0, 0.2), rel=1e-14)


def test_repr_states_the_facts():
    dom = geometry.rectangle(cracks=[cases.EDGE_CRACK])
    text = repr(dom)
    assert re.search(r"1 region\b", text) and re.search(r"1 crack\b.*\b1 tip", text), text


@pytest.mark.parametrize("degrees", [30.0, 5.0, 2.0])
def test_crack_end_meeting_the_boundary_at_a_shallow_angle_is_an_edge_crack(degrees):
    """A crack whose end reaches the top edge at a shallow angle (as a curving grown crack
    does) is an edge crack: its approach within the snapping tolerance, tol / sin(angle)
    long, belongs to the end (it was refused as touching the boundary away from its ends);
    the model's cells still tile the plate."""
    t = np.radians(degrees)
    end = np.array([0.6, 1.0])
    start = end - 0.3 * np.array([np.cos(t), np.sin(t)])
    dom = cnem.geometry.rectangle(1.0, 1.0, cracks=[[start, end]])
    np.testing.assert_allclose(dom.tips, [start])
    model = cnem.discretize(cnem.nodes.irregular(dom, 0.05, seed=0), progress=False)
    assert abs(model.cells.area.sum() - 1.0) < 1e-12


def test_crack_lying_along_the_boundary_at_its_end_is_refused():
    """Below about one degree the end runs along the boundary: refused, saying so."""
    t = np.radians(0.2)
    end = np.array([0.6, 1.0])
    with pytest.raises(cnem.GeometryError, match="less than about 1 degree"):
        cnem.geometry.rectangle(1.0, 1.0, cracks=[[end - 0.3 * np.array([np.cos(t), np.sin(t)]),
                                                   end]])
