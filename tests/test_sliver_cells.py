"""The cells of a sliver triangle (issue 36 item 5): a triangle of length 1 and height
1e-6 .. 1e-8 with nodes 0.1 apart on its edges. Its long sides, cut into many collinear
edges, sent two nodes to the shapely path (their cells 2.8e-5 of the area short), and
the circumcentres of its thin triangles, computed relative to a vertex whose two edges
are both long, moved by a percent of the height (a gap between cells)."""

from __future__ import annotations

import numpy as np
import pytest

import cnem


def _clipped_voronoi(points, corners, i):
    """The Voronoi cell of ``points[i]`` clipped to the convex polygon ``corners``
    (counter-clockwise): the polygon cut by every bisector, relative to the node."""
    x = points[i]
    poly = corners - x
    for j in range(len(points)):
        d = points[j] - x
        if j == i or not d.any():
            continue
        value = poly @ d - 0.5 * (d @ d)          # > 0: nearer to j
        out = []
        for k in range(len(poly)):
            a, b, va, vb = poly[k], poly[(k + 1) % len(poly)], value[k], value[(k + 1) % len(poly)]
            if va <= 0:
                out.append(a)
            if (va <= 0) != (vb <= 0):
                out.append(a + va / (va - vb) * (b - a))
        poly = np.array(out)
    q = poly - poly[0]
    return 0.5 * np.sum(q[:, 0] * np.roll(q[:, 1], -1) - np.roll(q[:, 0], -1) * q[:, 1])


@pytest.mark.parametrize("moved", [(1.0, 0.0), (1e-3, 0.0), (1e3, 0.0), (1.0, 1e6)],
                         ids=["origin", "scale1e-3", "scale1e3", "offset1e6"])
@pytest.mark.parametrize("height", [1e-6, 1e-7, 1e-8])
def test_the_cells_of_a_sliver_tile_it(height, moved):
    """The cells sum to the sliver's area to round-off and each is its node's Voronoi
    cell clipped to the triangle (the triangle is convex: every node sees every point),
    computed in the model's local frame, to 1e-9 of its area."""
    scale, offset = moved
    if offset and height < 1e-6:
        pytest.skip("at 1e6 a height under 1e-6 is a few hundred ulps: not done yet")
    corners = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, height]]) * scale + offset
    dom = cnem.Domain(corners)
    model = cnem.discretize(cnem.nodes.regular(dom, 0.1 * scale), progress=False)
    cells = model.cells
    assert abs(cells.area.sum() - dom.area) <= 1e-12 * dom.area
    local = dom.frame.to_local(model.nodes)
    box = dom.frame.to_local(corners)
    for k, i in enumerate(cells.node):
        want = _clipped_voronoi(local, box, i) * dom.frame.scale ** 2
        assert cells.area[k] == pytest.approx(want, rel=1e-9), i


def test_a_sliver_thinner_than_round_off_is_named():
    """At a height of 1e-9 the nodes of both long sides fall on one line: `triangle`
    returns no triangle, and discretize says so (it raised a bare KeyError)."""
    dom = cnem.Domain([[0.0, 0.0], [1.0, 0.0], [0.5, 1e-9]])
    with pytest.raises(cnem.GeometryError, match="make no triangle.*collinear"):
        cnem.discretize(cnem.nodes.regular(dom, 0.1))
