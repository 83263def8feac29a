"""The half-plane path of the constrained Voronoi cells (`cnem.geometry.halfplane`):
the same cells as the exact shapely path wherever it accepts a node, and the cells
of thin strips whose circumcentres all lie outside them."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from scipy.spatial import cKDTree

import cases
import cnem
from cnem._parallel import always_parallel
from cnem.geometry import cells
from cnem.geometry._clip_kernels import CLIPPED, GROW, clip_cell, collinear_reach
from cnem.geometry._kernels import fan_regions
from cnem.geometry._reflex_kernels import reflex_cell
from cnem.geometry import halfplane
from cnem.geometry.halfplane import HalfPlaneCells
from cnem.geometry.model import triangulate
from cnem.geometry.topology import circumcenters, vertex_triangles


@pytest.mark.parametrize("name", ["square_irregular", "lshape_irregular", "plate_hole_irregular",
                                  "kinked_crack_irregular", "three_rectangles_irregular",
                                  "random_points"])
def test_half_plane_cells_equal_the_exact_cells(name):
    """Every (node, region) the half-plane path accepts -- interior nodes, straight
    boundaries, convex corners, next to holes, cracks and interfaces -- gets the cell
    the exact path clips (to the exact path's snap grid, 1e-13 of the extent). The
    reflex corners, tips and interface nodes it refuses are left to the exact path."""
    dom, cloud = cases.case(name)
    nodes, _, tri, region, _, _, neighbors = triangulate(cloud, {})
    local = dom.frame.to_local(nodes)
    off, star = vertex_triangles(tri, len(local))
    exact = cells._ExactCells(local, tri, region, neighbors[0], off, star,
                              circumcenters(local, tri), dom.frame)
    half = HalfPlaneCells(local, tri, region, neighbors[0])
    node, reg, start = fan_regions(local, tri, region, off, star, np.arange(len(local)))
    done, counts, verts = half.cells(node, reg, start)
    first = np.concatenate([[0], np.cumsum(counts)])
    for k, c in enumerate(done):
        a = shapely.Polygon(verts[first[k]:first[k + 1]])
        b = shapely.Polygon(exact.cell(int(node[c]), int(reg[c])))
        assert a.is_valid and a.exterior.is_ccw
        assert a.symmetric_difference(b).area < 1e-10 * b.area, (node[c], reg[c])
    accepted, refused = len(done), len(node) - len(done)
    assert accepted > len(local) / 2
    if name != "square_irregular" and name != "random_points":
        assert refused > 0               # corners or tips nearby: some are refused


@pytest.mark.parametrize("h", [1e-3, 3e-4])
def test_cells_of_an_irregular_thin_strip_need_no_shapely(h):
    """A 1 x 1e-6 strip with an irregular cloud: its nodes lie on the two long edges
    at unrelated abscissae, so every circumcentre lies ~h^2 / 1e-6 outside the strip
    and the fast path takes no cell. They all went to shapely (h = 1e-3: 174 s,
    areas summing to the strip's to 2.2e-8); the half-plane path takes every one,
    valid polygons partitioning the strip to round-off."""
    dom = cnem.geometry.rectangle(1.0, 1e-6)
    cloud = cnem.nodes.irregular(dom, h, seed=0)
    clipped = []
    with pytest.MonkeyPatch.context() as mp:
        exact = cells._ExactCells.cell
        mp.setattr(cells._ExactCells, "cell", lambda self, i, r: clipped.append(i) or exact(self, i, r))
        model = cnem.discretize(cloud, progress=False)
    c = model.cells
    assert clipped == []
    polys = [shapely.Polygon(c.vertices[c.offsets[k]:c.offsets[k + 1]]) for k in range(len(c.node))]
    assert all(p.is_valid for p in polys)
    assert (c.area > 0).all()
    assert c.area.sum() == pytest.approx(dom.area, rel=1e-14)
    assert shapely.union_all(polys).area == pytest.approx(dom.area, rel=1e-14)   # no overlaps
    # the strip is convex, so every node sees every point: a point belongs to the cell
    # of its nearest node (points within 1e-9 h of a tie left out)
    rng = np.random.default_rng(1)
    sample = rng.uniform([0.0, 0.0], [1.0, 1e-6], (2000, 2))
    dist, near = cKDTree(model.nodes).query(sample, k=2)
    clear = dist[:, 1] - dist[:, 0] > 1e-9 * h
    assert (np.diff(c.node) > 0).all()                   # one cell per node, sorted
    inside = shapely.contains_xy(np.array(polys, dtype=object)[near[clear, 0]],
                                 sample[clear, 0], sample[clear, 1])
    assert inside.all() and clear.sum() > 1900


def _per_cell(half, i, r, start):
    """The half-plane cell of node ``i`` in region ``r`` one at a time, as before the
    batching (issue 19): three k-d trees (nodes, constraint-edge midpoints, constraint
    ends) queried per cell, candidates in index order, the box doubled on `GROW`; at a
    reflex corner, `reflex_cell` instead of `clip_cell`; a chord's `collinear_reach`
    found per chord."""
    nodes, edges = half.nodes, half.edges
    edge_tree = cKDTree(0.5 * (nodes[edges[:, 0]] + nodes[edges[:, 1]]))
    node_tree = cKDTree(nodes)
    ends = np.flatnonzero(~half.safe)
    x = nodes[i]
    wedge = np.zeros((0, 4))
    if half.next[i] >= 0:
        wedge = np.concatenate([nodes[half.prev[i]], x, x, nodes[half.next[i]]]).reshape(2, 4)
    size = start * (halfplane._REFLEX_START if half.reflex[i] else 1.0)   # as `HalfPlaneCells.cells`
    for _ in range(64):
        box = np.concatenate([np.maximum(x - size, half.extent[:2]), np.minimum(x + size, half.extent[2:])])
        reach = size * np.sqrt(2.0)
        e = np.asarray(edge_tree.query_ball_point(x, reach + half.edge_half, return_sorted=True),
                       dtype=np.int64)
        e = e[(half.edge_region[e] == r) & (edges[e] != i).all(axis=1)]
        j = np.asarray(node_tree.query_ball_point(x, reach, return_sorted=True), dtype=np.int64)
        j = j[half.member[j, r] & (j != i)]
        j = j[np.argsort(np.hypot(*(nodes[j] - x).T), kind="stable")]
        near_ends = nodes[ends[np.hypot(*(nodes[ends] - x).T) <= reach]].reshape(-1, 2)
        scratch = [np.empty((2 * (4 + len(wedge) + len(e) + len(j)) + 8, c)) for c in (2, 2, 3)]
        if half.reflex[i]:
            if half.twin[i]:
                return None
            status, k = reflex_cell(nodes, i, box, half.extent, half.prev, half.next, half.kind,
                                    half.twin, j, len(j), nodes[edges[e]].reshape(-1, 4), len(e),
                                    half.tol, *scratch[:2])
        else:
            reach_on = [collinear_reach(nodes, u, v, half.prev, half.next, half.kind, i, box,
                                        half.line_tol) for u, v in edges[e]]
            chords = np.column_stack([nodes[edges[e]].reshape(-1, 4), np.reshape(reach_on, (-1, 2))])
            status, k = clip_cell(x, box, half.extent, wedge, chords,
                                  np.ascontiguousarray(nodes[j]), half.wedge[j],
                                  np.ascontiguousarray(near_ends), half.tol, *scratch)
        if status == CLIPPED:
            return scratch[0][:k]
        if status != GROW or ((box[:2] <= half.extent[:2]).all() and (box[2:] >= half.extent[2:]).all()):
            return None
        size *= 2.0
    return None


def _strip(h):
    dom = cnem.geometry.rectangle(1.0, 1e-6)
    return dom, cnem.nodes.irregular(dom, h, seed=0)


@pytest.mark.parametrize("moved", [(1.0, 0.0), (1.0, 1e6), (1e-6, 0.0)],
                         ids=["origin", "offset1e6", "scale1e-6"])
@pytest.mark.parametrize("name", ["square_irregular", "plate_hole_irregular", "kinked_crack_irregular",
                                  "three_rectangles_irregular", "graded_inclined_crack", "strip"])
def test_batched_cells_equal_the_per_cell_path(name, moved):
    """All half-plane cells at once (one tree query per leaf, one kernel, the growing boxes
    retried together) are the cells of the per-cell path: the same (node, region)
    pairs taken, the same vertices to 1e-15 of the extent (in practice bit for bit),
    at the origin, moved by 1e6 and in units 1e-6 times smaller."""
    dom, cloud = _strip(1e-3) if name == "strip" else cases.case(name)
    nodes, _, tri, region, _, _, neighbors = triangulate(cloud, {})
    scale, offset = moved
    local = dom.frame.to_local(nodes) * scale + offset
    off, star = vertex_triangles(tri, len(local))
    half = HalfPlaneCells(local, tri, region, neighbors[0])
    node, reg, start = fan_regions(local, tri, region, off, star, np.arange(len(local)))
    done, counts, verts = half.cells(node, reg, start)
    first = np.concatenate([[0], np.cumsum(counts)])
    got = {int(c): verts[first[k]:first[k + 1]] for k, c in enumerate(done)}
    size = float(np.hypot(*np.ptp(local, axis=0)))
    taken = 0
    for c in range(len(node)):
        want = _per_cell(half, node[c], reg[c], start[c])
        assert (want is None) == (c not in got), (node[c], reg[c])
        if want is not None:
            taken += 1
            assert got[c].shape == want.shape
            np.testing.assert_allclose(got[c], want, rtol=0.0, atol=1e-15 * size)
    assert taken > len(node) / 5           # most cells of every case, a third of the graded one


def test_the_parallel_copy_clips_the_same_cells():
    """The batch kernel's parallel copy (`cnem._parallel`, chosen above
    `cnem.config.PARALLEL_MIN` cells) gives the serial copy's cells bit for bit."""
    dom, cloud = _strip(1e-3)
    nodes, _, tri, region, _, _, neighbors = triangulate(cloud, {})
    local = dom.frame.to_local(nodes)
    off, star = vertex_triangles(tri, len(local))
    half = HalfPlaneCells(local, tri, region, neighbors[0])
    pairs = fan_regions(local, tri, region, off, star, np.arange(len(local)))
    serial = half.cells(*pairs)
    with always_parallel():
        parallel = half.cells(*pairs)
    assert len(serial[0]) == len(local)
    for a, b in zip(serial, parallel):
        np.testing.assert_array_equal(a, b)
