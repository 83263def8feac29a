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
from cnem.geometry import cells
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
    accepted = refused = 0
    for i in range(len(local)):
        for r in np.unique(region[star[off[i]:off[i + 1]]]):
            fan = exact.fan(i, r)
            start = float(np.linalg.norm(local[tri[fan].ravel()] - local[i], axis=1).max())
            poly = half.cell(i, r, start)
            if poly is None:
                refused += 1
                continue
            accepted += 1
            a, b = shapely.Polygon(poly), shapely.Polygon(exact.cell(i, r))
            assert a.is_valid and a.exterior.is_ccw
            assert a.symmetric_difference(b).area < 1e-10 * b.area, (i, r)
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
