"""Triangulation, crack opening and constrained Voronoi cells over the case catalogue.

Every check is against the definition of the cells (C-NEM eq. 13), the brute
force reference in `reference.py`, scipy's unconstrained Voronoi diagram or a
geometric property (partition, CCW, conformity) -- never against numbers the
code printed.
"""

from __future__ import annotations

import zlib

import numpy as np
import pytest
import shapely
from scipy.spatial import Voronoi

import cases
import reference

pytestmark = pytest.mark.parametrize("name", cases.NAMES)


@pytest.fixture
def built(name):
    return cases.model(name)


def _polys(model):
    return reference.cell_polygons(model)


# --------------------------------------------------------------- partition
def test_cell_areas_sum_to_domain_area(built):
    dom, _, model = built
    cells = model.cells
    assert len(cells.area) == len(cells.node) == len(cells.region) == len(cells.offsets) - 1
    assert abs(cells.area.sum() - dom.area) <= 1e-12 * dom.area


def test_cell_polygons_valid_ccw_positive(built):
    dom, _, model = built
    cells = model.cells
    assert cells.offsets[0] == 0 and cells.offsets[-1] == len(cells.vertices)
    assert np.all(np.diff(cells.offsets) >= 3)
    for c, poly in enumerate(_polys(model)):
        assert poly.is_valid, (c, shapely.is_valid_reason(poly))
        xy = cells.polygon(c)
        x, y = xy[:, 0], xy[:, 1]
        signed = 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)
        assert signed > 0, f"cell {c} of node {cells.node[c]} is not counter-clockwise"
        assert poly.area > 0
        assert abs(cells.area[c] - poly.area) <= 1e-12 * dom.area
        assert abs(signed - cells.area[c]) <= 1e-12 * dom.area
    centroid = cells.centroid()
    expected = np.array([np.asarray(p.centroid.coords[0]) for p in _polys(model)])
    np.testing.assert_allclose(centroid, expected, rtol=0, atol=1e-9 * dom.diameter)


def test_cells_do_not_overlap(built):
    dom, _, model = built
    polys = _polys(model)
    left, right = shapely.STRtree(polys).query(polys, predicate="intersects")
    keep = left < right
    left, right = left[keep], right[keep]
    overlap = shapely.area(shapely.intersection(polys[left], polys[right]))
    worst = int(np.argmax(overlap)) if len(overlap) else None
    assert len(overlap) == 0 or overlap[worst] < 1e-12 * dom.area, (
        f"cells {left[worst]} and {right[worst]} overlap by {overlap[worst]:.3g}")


def test_cells_cover_domain(built):
    dom, _, model = built
    union = shapely.union_all(_polys(model))
    assert dom.polygon.difference(union).area < 1e-11 * dom.area
    assert union.difference(dom.polygon).area < 1e-11 * dom.area


def test_each_cell_lies_in_its_region(built):
    dom, _, model = built
    cells = model.cells
    for c, poly in enumerate(_polys(model)):
        r = int(cells.region[c])
        assert 0 <= r < len(dom.regions)
        outside = poly.difference(dom.regions[r]).area
        assert outside < 1e-12 * dom.area, f"cell {c} pokes {outside:.3g} out of region {r}"


# -------------------------------------------------------------- visibility
def test_each_cell_is_visible_from_its_node(built):
    dom, _, model = built
    cells = model.cells
    checked = 0
    for c, poly in enumerate(_polys(model)):
        j = int(cells.node[c])
        xj = model.nodes[j]
        verts = cells.polygon(c)
        centre = np.asarray(poly.centroid.coords[0])
        samples = np.concatenate([verts + 0.01 * (xj - verts), verts + 0.01 * (centre - verts),
                                  centre[None]])
        # strictly inside (points pulled along a boundary edge of the cell are
        # on the domain boundary, where visibility is decided by round-off)
        inside = shapely.contains_xy(poly, samples[:, 0], samples[:, 1]) & (
            shapely.distance(poly.exterior, shapely.points(samples)) > 1e-9 * dom.diameter)
        assert inside.sum() >= (len(verts) + 1) // 2, f"cell {c}: too few interior sample points"
        for x in samples[inside]:
            assert reference.visible(model, j, x), (
                f"node {j} at {xj.tolist()} does not see {x.tolist()} in its cell {c}")
            checked += 1
    assert checked >= len(cells)


def test_definition_at_sample_points(built, name):
    """A sample point's cell owner is among the nearest visible nodes of its region."""
    dom, _, model = built
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    xmin, ymin, xmax, ymax = dom.bounds
    pts = rng.uniform([xmin, ymin], [xmax, ymax], (600, 2))
    pts = pts[dom.region_of(pts) >= 0][:150]
    assert len(pts) >= 100
    regions = dom.region_of(pts)
    for x, r in zip(pts, regions):
        nearest = reference.nearest_visible_nodes(model, x, int(r))
        owners = reference.cell_owner(model, x, int(r))
        assert nearest, f"no node visible from {x.tolist()} in region {r}"
        assert owners, f"{x.tolist()} (region {r}) lies in no cell of its region"
        assert set(owners) <= set(nearest), (
            f"{x.tolist()} (region {r}) lies in the cells of {owners}, but the nearest "
            f"visible nodes are {nearest}")


def test_cells_far_from_constraints_are_voronoi_cells(built):
    """Away from constraints the constrained cell is the ordinary Voronoi cell.

    A node qualifies when the disk of radius ``2 R`` around it (``R`` the
    largest circumradius of its triangles) meets no constraint segment and
    none of its neighbours is on one: the circumdisks of its triangles are
    then free of constraints, so its triangles are true Delaunay triangles.
    """
    dom, cloud, model = built
    nodes, tri = model.nodes, model.triangles
    seg_lines = shapely.linestrings(nodes[model.segments])
    on_constraint = np.zeros(len(nodes), dtype=bool)
    on_constraint[model.segments.ravel()] = True
    a, b, c = nodes[tri[:, 0]], nodes[tri[:, 1]], nodes[tri[:, 2]]
    la, lb, lc = (np.linalg.norm(b - c, axis=1), np.linalg.norm(c - a, axis=1),
                  np.linalg.norm(a - b, axis=1))
    circ_r = la * lb * lc / (2 * np.abs(reference.orient2d(a, b, c)))
    radius = np.zeros(len(nodes))
    np.maximum.at(radius, tri.ravel(), np.repeat(circ_r, 3))
    dist = shapely.STRtree(seg_lines).query_nearest(shapely.points(nodes), return_distance=True,
                                                    all_matches=False)[1]
    neighbour_on = np.zeros(len(nodes), dtype=bool)
    for k in range(3):
        np.logical_or.at(neighbour_on, tri[:, k], on_constraint[tri].any(axis=1))
    far = np.flatnonzero((dist > 2 * radius) & ~neighbour_on)
    assert len(far) >= 3, "the case has no node far from constraints; make it finer"

    unique = cloud.points
    vor = Voronoi(unique)
    cells = model.cells
    polys = _polys(model)
    for i in far:
        mine = np.flatnonzero(cells.node == i)
        assert len(mine) == 1
        region = vor.regions[vor.point_region[model.node_of_point[i]]]
        assert region and -1 not in region
        expected = shapely.convex_hull(shapely.multipoints(vor.vertices[region]))
        got = polys[mine[0]]
        scale = radius[i]
        assert got.symmetric_difference(expected).area <= 1e-12 * scale**2, f"node {i}"
        assert shapely.hausdorff_distance(got, expected) <= 1e-12 * scale, f"node {i}"


# --------------------------------------------------------------- exact path's search
def test_the_exact_path_finds_the_k_d_tree_s_nodes_in_its_order(name):
    """The exact path looks its cells' neighbours up in a tree over the nodes near them
    (`_ExactCells.expect`), or in a k-d tree of all nodes when that one's order could
    matter: the same nodes as that k-d tree, and sorted by distance the same order
    beyond the merge tolerance (among those nearer the cell skips them all)."""
    from scipy.spatial import cKDTree

    from cnem.geometry import cells
    from cnem.geometry._kernels import fan_regions
    from cnem.geometry.model import triangulate
    from cnem.geometry.topology import circumcenters

    dom, cloud = cases.case(name)
    nodes, _, tri, region, _, _, neighbors = triangulate(cloud, {})
    local = dom.frame.to_local(nodes)
    off, star = neighbors[2]
    exact = cells._ExactCells(local, tri, region, neighbors[0], off, star,
                              circumcenters(local, tri), dom.frame)
    node, reg, _ = fan_regions(local, tri, region, off, star, np.arange(0, len(local), 7))
    exact.expect(node, reg)
    full = cKDTree(local)
    for i, r in zip(node.tolist(), reg.tolist()):
        _, reach = exact.box(i, r)
        tiny = cells.config.MERGE_TOL * reach
        got, dist = exact.near(i, r, 2 * reach, tiny)
        want = np.asarray(full.query_ball_point(local[i], 2 * reach), dtype=np.int64)
        assert np.array_equal(np.sort(got), np.sort(want))
        np.testing.assert_array_equal(dist, np.linalg.norm(local[got] - local[i], axis=1))
        w_dist = np.linalg.norm(local[want] - local[i], axis=1)
        a, b = got[np.argsort(dist)], want[np.argsort(w_dist)]
        beyond = np.sort(dist) > tiny
        assert np.array_equal(a[beyond], b[beyond])
