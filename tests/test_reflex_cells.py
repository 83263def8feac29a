"""The half-plane path at reflex corners (`cnem.geometry._reflex_kernels.reflex_cell`):
every cell it takes is the exact (shapely) path's cell, whatever hides what around the
corner; a hole outlined much finer than the nodes around it needs no shapely at all."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

import cases
import cnem
from cnem.geometry import cells
from cnem.geometry._kernels import fan_regions
from cnem.geometry.halfplane import HalfPlaneCells
from cnem.geometry.model import triangulate
from cnem.geometry.topology import circumcenters, vertex_triangles

SQUARE = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]


def _circle(n, radius):
    t = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    return radius * np.column_stack([np.cos(t), np.sin(t)])


def _star(points, inner, outer):
    t = np.linspace(0.0, 2.0 * np.pi, 2 * points, endpoint=False)
    r = np.where(np.arange(2 * points) % 2 == 0, outer, inner)
    return np.column_stack([r * np.cos(t), r * np.sin(t)])


def _cloud(name):
    """A domain with reflex corners and a cloud on it."""
    if name == "fine_circular_hole":         # 400 hole vertices 0.005 apart, nodes 0.1 apart
        return cnem.nodes.regular(cnem.Domain((SQUARE, [_circle(400, 0.3)])), 0.1)
    if name == "square_hole":                # four 270-degree corners: long shadows
        hole = [[-0.3, -0.3], [-0.3, 0.3], [0.3, 0.3], [0.3, -0.3]]
        return cnem.nodes.irregular(cnem.Domain((SQUARE, [hole])), 0.1, seed=0)
    if name == "star_hole":                  # reflex and convex corners, coarse and fine
        return cnem.nodes.irregular(cnem.Domain((SQUARE, [_star(7, 0.15, 0.4)])), 0.06, seed=1)
    if name == "coarse_circular_hole":       # hole vertices farther apart than the nodes
        return cnem.nodes.irregular(cnem.Domain((SQUARE, [_circle(12, 0.4)])), 0.05, seed=2)
    return cases.case(name)[1]


def _exact_and_reflex(cloud, scale=1.0, offset=0.0):
    """The exact path's state and the half-plane path's cells of the reflex corners:
    ``(exact, node, region, done, cells)`` (``cells[k]`` of pair ``done[k]``)."""
    nodes, _, tri, region, _, _, neighbors = triangulate(cloud, {})
    local = cloud.domain.frame.to_local(nodes) * scale + offset
    off, star = vertex_triangles(tri, len(local))
    exact = cells._ExactCells(local, tri, region, neighbors[0], off, star,
                              circumcenters(local, tri), None)
    half = HalfPlaneCells(local, tri, region, neighbors[0])
    node, reg, start = fan_regions(local, tri, region, off, star,
                                   np.flatnonzero(half.reflex).astype(np.int64))
    done, counts, verts = half.cells(node, reg, start)
    first = np.concatenate([[0], np.cumsum(counts)])
    return exact, node, reg, done, [verts[first[k]:first[k + 1]] for k in range(len(done))]


@pytest.mark.parametrize("moved", [(1.0, 0.0), (1e-3, 0.0), (1e3, 0.0)],
                         ids=["origin", "scale1e-3", "scale1e3"])
@pytest.mark.parametrize("name", ["fine_circular_hole", "square_hole", "star_hole",
                                  "coarse_circular_hole", "lshape_irregular", "plate_hole_irregular"])
def test_reflex_cells_equal_the_exact_cells(name, moved):
    """Every reflex-corner cell the half-plane path takes is the cell the exact path clips
    (to 1e-10 of its area and its snap grid), at the origin and scaled by 1e-3 and 1e3; the fine hole's are
    all taken."""
    exact, node, reg, done, polys = _exact_and_reflex(_cloud(name), *moved)
    for k, c in enumerate(done):
        a = shapely.Polygon(polys[k])
        b = shapely.Polygon(exact.cell(int(node[c]), int(reg[c])))
        assert a.is_valid and a.exterior.is_ccw
        # to the exact path's snap grid along the perimeter (the hole's cells are slivers)
        tol = 1e-10 * b.area + 4 * exact.grid * b.length
        assert a.symmetric_difference(b).area <= tol, (node[c], reg[c])
    if name == "fine_circular_hole":
        assert len(done) == len(node) == 400


def test_shadows_refuse_a_cell():
    """A cell that is only wedge and bisectors is wrong where a corner hides a nearer
    node (the exact cell reaches into the shadow): some of the star's tips are such,
    and the path leaves them to the exact path."""
    exact, node, reg, done, _ = _exact_and_reflex(_cloud("star_hole"))
    refused = np.setdiff1d(np.arange(len(node)), done)
    wrong = 0
    for c in refused:
        i, r = int(node[c]), int(reg[c])
        box, reach = exact.box(i, r)
        naive = shapely.box(*box).intersection(exact.wedge(i, r, reach))
        x = exact.nodes[i]
        for j in np.flatnonzero(np.linalg.norm(exact.nodes - x, axis=1) > 0):
            half = cells._halfplane_box(box, x, exact.nodes[j])
            naive = naive if half is None else naive.difference(half)
        b = shapely.Polygon(exact.cell(i, r))
        wrong += naive.symmetric_difference(b).area > 1e-6 * b.area
    assert wrong > 0


@pytest.mark.parametrize("moved", [(1.0, 0.0), (1.0, 1e6), (1e-3, 0.0)],
                         ids=["origin", "offset1e6", "scale1e-3"])
def test_a_finely_outlined_hole_needs_no_shapely(moved):
    """A square with a hole of 2000 vertices and nodes 0.05 apart: no cell goes to the
    exact path (it took every hole vertex: 8 ms a cell), the cells tile the domain to
    round-off, moved by 1e6 and in units 1e3 times smaller too, and each cell is the
    exact path's on the same nodes."""
    scale, offset = moved
    dom = cnem.Domain((np.array(SQUARE) * scale + offset, [_circle(2000, 0.3) * scale + offset]))
    cloud = cnem.nodes.regular(dom, 0.05 * scale)
    clipped = []
    with pytest.MonkeyPatch.context() as mp:
        exact_cell = cells._ExactCells.cell
        mp.setattr(cells._ExactCells, "cell",
                   lambda self, i, r: clipped.append(i) or exact_cell(self, i, r))
        model = cnem.discretize(cloud, progress=False)
    assert clipped == []
    c = model.cells
    assert abs(c.area.sum() - dom.area) <= 1e-12 * dom.area
    exact, node, reg, done, polys = _exact_and_reflex(cloud)
    assert len(done) == 2000
    for k in range(0, len(done), 37):        # a sample: the exact path is slow
        b = shapely.Polygon(exact.cell(int(node[done[k]]), int(reg[done[k]])))
        tol = 1e-10 * b.area + 4 * exact.grid * b.length
        assert shapely.Polygon(polys[k]).symmetric_difference(b).area <= tol
