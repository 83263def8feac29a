"""`cnem.discretize`: constrained Delaunay triangulation, crack opening, bookkeeping."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from scipy.spatial import cKDTree

import cnem
import cases
import reference

all_cases = pytest.mark.parametrize("name", cases.NAMES)
cracked = pytest.mark.parametrize("name", cases.CRACKED)


@pytest.fixture
def built(name):
    return cases.model(name)


def _edges(tri):
    return np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])


# ------------------------------------------------------------ triangulation
@all_cases
def test_no_steiner_points_ccw_nondegenerate(built):
    dom, cloud, model = built
    n = len(model.nodes)
    tri = model.triangles
    assert tri.ndim == 2 and tri.shape[1] == 3 and tri.min() >= 0 and tri.max() < n
    assert np.array_equal(np.unique(tri), np.arange(n)), "some nodes are not triangle vertices"
    assert np.array_equal(model.nodes, cloud.points[model.node_of_point])
    twice = reference.orient2d(*(model.nodes[tri[:, k]] for k in range(3)))
    assert twice.min() > 1e-10 * dom.diameter**2, "flat or clockwise triangle"
    # the triangles tile the (polygonal) domain and carry the region they lie in
    assert abs(0.5 * twice.sum() - dom.area) <= 1e-12 * dom.area
    centroid = model.nodes[tri].mean(axis=1)
    assert np.array_equal(model.triangle_region, dom.region_of(centroid))


@all_cases
def test_triangulation_is_edge_conforming(built):
    """Each interior edge is shared by exactly two triangles, a constraint edge by one."""
    _, _, model = built
    edges = np.sort(_edges(model.triangles), axis=1)
    uniq, count = np.unique(edges, axis=0, return_counts=True)
    assert count.max() <= 2
    once = set(map(tuple, uniq[count == 1].tolist()))
    segs = set(map(tuple, np.sort(model.segments, axis=1).tolist()))
    # every edge on the rim of the triangulation is a boundary or crack-face segment
    rim = {s for s, k in zip(map(tuple, np.sort(model.segments, axis=1).tolist()),
                             model.segment_kind) if k != 1}
    assert once == rim
    assert rim <= segs


@all_cases
def test_triangulation_respects_every_constraint(built):
    """Every cloud segment is a triangle edge; every model segment maps onto a cloud segment."""
    _, cloud, model = built
    nop = model.node_of_point
    edges = _edges(model.triangles)
    as_points = set(map(tuple, np.sort(nop[edges], axis=1).tolist()))
    for s in np.sort(cloud.segments, axis=1).tolist():
        assert tuple(s) in as_points, f"constraint segment {s} is not a triangle edge"
    tri_edges = set(map(tuple, np.sort(edges, axis=1).tolist()))
    cloud_segs = {(tuple(s), int(k)) for s, k in zip(np.sort(cloud.segments, axis=1).tolist(),
                                                     cloud.segment_kind)}
    for s, k in zip(model.segments.tolist(), model.segment_kind):
        assert tuple(sorted(s)) in tri_edges
        assert (tuple(sorted(nop[s].tolist())), int(k)) in cloud_segs


@all_cases
def test_constrained_delaunay_property(built):
    """No node visible from inside a triangle lies strictly inside its circumcircle."""
    dom, _, model = built
    nodes, tri = model.nodes, model.triangles
    a, b, c = (nodes[tri[:, k]] for k in range(3))
    d = 2 * reference.orient2d(a, b, c)
    b_, c_ = b - a, c - a
    cc = a + np.column_stack([c_[:, 1] * (b_**2).sum(1) - b_[:, 1] * (c_**2).sum(1),
                              b_[:, 0] * (c_**2).sum(1) - c_[:, 0] * (b_**2).sum(1)]) / d[:, None]
    r = np.linalg.norm(cc - a, axis=1)
    centroid = (a + b + c) / 3
    tree = cKDTree(nodes)
    for t in range(len(tri)):
        for j in tree.query_ball_point(cc[t], r[t] * (1 - 1e-9)):
            if j in tri[t]:
                continue
            # j strictly inside the circumcircle: it must be hidden from the triangle
            assert not reference.visible(model, j, centroid[t]), (
                f"triangle {t} is not constrained Delaunay: node {j} inside its circumcircle")


# ------------------------------------------------------------- bookkeeping
@all_cases
def test_every_node_owns_one_cell_per_adjacent_region(built):
    dom, _, model = built
    cells = model.cells
    n = len(model.nodes)
    assert np.array_equal(np.unique(cells.node), np.arange(n)), "a node owns no cell"
    expected = sorted(set(zip(model.triangles.ravel().tolist(),
                              np.repeat(model.triangle_region, 3).tolist())))
    got = sorted(zip(cells.node.tolist(), cells.region.tolist()))
    assert got == expected
    interface = np.unique(model.segments[model.segment_kind == 1])
    assert (len(interface) > 0) == bool((dom.pslg.kind == 1).any())
    for i in interface:
        owned = cells.region[cells.node == i].tolist()
        assert len(owned) >= 2 and len(set(owned)) == len(owned), (i, owned)


@all_cases
def test_node_lies_in_its_own_cells(built):
    _, _, model = built
    cells = model.cells
    polys = reference.cell_polygons(model)
    d = shapely.distance(polys, shapely.points(model.nodes[cells.node]))
    assert d.max() <= 1e-12


@pytest.mark.parametrize("name", cases.INTERFACES)
def test_interface_nodes_own_exactly_one_cell_per_region(built):
    dom, _, model = built
    cells = model.cells
    interface = np.unique(model.segments[model.segment_kind == 1])
    assert len(interface) > 0
    tri_regions = {}
    for t, r in zip(model.triangles.tolist(), model.triangle_region.tolist()):
        for v in t:
            tri_regions.setdefault(v, set()).add(r)
    for i in interface:
        owned = sorted(cells.region[cells.node == i].tolist())
        assert owned == sorted(tri_regions[i])
        assert len(owned) >= 2
        # the cell in region r has its area in region r, on that side of the interface
        for c in np.flatnonzero(cells.node == i):
            poly = shapely.Polygon(cells.polygon(c))
            assert poly.intersection(dom.regions[cells.region[c]]).area >= (1 - 1e-9) * poly.area


# ------------------------------------------------------------ crack opening
def _crack_points(dom, cloud):
    """Cloud points on crack segments, split into (tips, others)."""
    on_crack = np.unique(cloud.segments[cloud.segment_kind == 2])
    tip = np.zeros(len(on_crack), dtype=bool)
    for t in dom.tips:
        tip |= np.linalg.norm(cloud.points[on_crack] - t, axis=1) == 0
    return on_crack[tip], on_crack[~tip]


@cracked
def test_crack_nodes_split_once(built):
    dom, cloud, model = built
    tips, split = _crack_points(dom, cloud)
    assert len(tips) == len(dom.tips), "every crack tip must be a node"
    assert len(split) > 0
    assert len(model.nodes) - len(cloud.points) == len(split)
    count = np.bincount(model.node_of_point, minlength=len(cloud.points))
    expected = np.ones(len(cloud.points), dtype=int)
    expected[split] = 2
    np.testing.assert_array_equal(count, expected)
    np.testing.assert_array_equal(model.nodes, cloud.points[model.node_of_point])


@cracked
def test_no_triangle_joins_both_faces(built):
    dom, cloud, model = built
    _, split = _crack_points(dom, cloud)
    nop = model.node_of_point
    for p in split:
        copies = np.flatnonzero(nop == p)
        assert len(copies) == 2
        both = np.isin(model.triangles, copies).sum(axis=1)
        assert both.max() <= 1, f"a triangle uses both copies of crack point {p}"
        # each copy is a vertex of some triangle (on its own side)
        for c in copies:
            assert (model.triangles == c).any()
    # no triangle reaches across the crack: the crack polylines miss every
    # (slightly shrunk) triangle interior
    shrink = 1e-9 * dom.diameter
    tris = shapely.polygons(model.nodes[model.triangles]).tolist()
    inner = shapely.buffer(np.array(tris, dtype=object), -shrink)
    for k, crack in enumerate(dom.cracks):
        hit = shapely.intersects(inner, shapely.LineString(crack))
        assert not hit.any(), f"triangles {np.flatnonzero(hit)[:5]} cross crack {k}"


@cracked
def test_triangles_around_a_crack_node_use_their_side_copy(built):
    """Triangles touching a crack point from opposite sides use different copies."""
    dom, cloud, model = built
    _, split = _crack_points(dom, cloud)
    nop = model.node_of_point
    crack_segs = cloud.segments[cloud.segment_kind == 2]
    for p in split:
        copies = np.flatnonzero(nop == p)
        # the crack direction(s) at p: the other ends of its crack segments
        ends = crack_segs[(crack_segs == p).any(axis=1)].ravel()
        ends = ends[ends != p]
        side_of_copy = []
        for c in copies:
            ts = model.triangles[(model.triangles == c).any(axis=1)]
            cen = model.nodes[ts].mean(axis=1)
            side_of_copy.append(_side(cloud.points[p], cloud.points[ends], cen))
        a, b = side_of_copy
        assert len(set(a)) == 1 and len(set(b)) == 1 and a[0] != b[0], (
            f"crack point {p}: triangles of one copy lie on both faces")


def _side(p, ends, pts):
    """Which side of the crack through ``p`` each point of ``pts`` lies on (by angle)."""
    ang_e = np.sort(np.arctan2(ends[:, 1] - p[1], ends[:, 0] - p[0]))
    ang = np.arctan2(pts[:, 1] - p[1], pts[:, 0] - p[0])
    if len(ang_e) == 1:
        # crack end on the boundary: the crack splits the fan in two
        return (np.sign(np.sin(ang - ang_e[0]))).astype(int).tolist()
    lo, hi = ang_e
    return ((ang > lo) & (ang < hi)).astype(int).tolist()


@cracked
def test_crack_segments_appear_once_per_face(built):
    dom, cloud, model = built
    nop = model.node_of_point
    face = model.segments[model.segment_kind == 2]
    crack = cloud.segments[cloud.segment_kind == 2]
    assert len(face) == 2 * len(crack)
    assert len(np.unique(np.sort(face, axis=1), axis=0)) == len(face), "duplicated face segment"
    by_point = {}
    for s in face.tolist():
        by_point.setdefault(tuple(sorted(nop[s].tolist())), []).append(s)
    assert set(by_point) == set(map(tuple, np.sort(crack, axis=1).tolist()))
    for key, pair in by_point.items():
        assert len(pair) == 2, key
        # the two copies of a segment bound triangles on opposite sides
        sides = []
        for a, b in pair:
            t = np.flatnonzero((model.triangles == a).any(axis=1) & (model.triangles == b).any(axis=1))
            assert len(t) == 1, f"face segment {a, b} is an edge of {len(t)} triangles"
            third = [v for v in model.triangles[t[0]] if v not in (a, b)][0]
            sides.append(np.sign(reference.orient2d(model.nodes[a], model.nodes[b],
                                                    model.nodes[third])))
        # orientation relative to the same (cloud) direction
        a0, b0 = pair[0]
        a1, b1 = pair[1]
        if nop[a0] != nop[a1]:
            sides[1] = -sides[1]
        assert sides[0] == -sides[1], f"both copies of crack segment {key} face the same side"


def test_discretize_rejects_a_domain():
    with pytest.raises(cnem.GeometryError, match="NodeCloud"):
        cnem.discretize(cnem.geometry.rectangle())


# ------------------------------------------------------------ tiny clouds
TINY = {
    # every node takes the fast (numba) path
    "lattice_5x5": lambda d: cnem.nodes.regular(d, 0.25),
    "centre_point": lambda d: cnem.nodes.from_points(d, [[0.5, 0.5]]),
    # one node close to a long boundary edge: its circumcentre lies outside
    "point_near_edge": lambda d: cnem.nodes.from_points(d, [[0.5, 0.9]]),
    "two_points": lambda d: cnem.nodes.from_points(d, [[0.3, 0.4], [0.8, 0.7]]),
}


@pytest.mark.parametrize("tiny", list(TINY))
def test_tiny_clouds_partition_the_square(tiny):
    dom = cnem.geometry.rectangle(1.0, 1.0)
    model = cnem.discretize(TINY[tiny](dom), progress=False)
    cells = model.cells
    assert abs(cells.area.sum() - 1.0) <= 1e-12
    assert np.array_equal(np.unique(cells.node), np.arange(len(model.nodes)))
    polys = reference.cell_polygons(model)
    assert all(p.is_valid and p.area > 0 for p in polys)
    union = shapely.union_all(polys)
    assert dom.polygon.symmetric_difference(union).area < 1e-12
    rng = np.random.default_rng(0)
    for x in rng.uniform(0, 1, (40, 2)):
        owners = reference.cell_owner(model, x, 0)
        assert owners and set(owners) <= set(reference.nearest_visible_nodes(model, x, 0))


def test_short_internal_crack_is_opened():
    """A crack between two tips shorter than the spacing still gets a node to split."""
    dom = cnem.geometry.rectangle(cracks=[[[0.4, 0.5], [0.6, 0.5]]])
    for cloud in (cnem.nodes.regular(dom, 0.25),
                  cnem.nodes.from_points(dom, np.random.default_rng(1).random((200, 2)) * 0.98 + 0.01)):
        model = cnem.discretize(cloud, progress=False)
        # every crack node but the two tips is split (from_points also fills the crack
        # at the local spacing of its random points: 0.2 long, ~3 spacings)
        inside = len(np.unique(cloud.segments[cloud.segment_kind == 2])) - 2
        assert inside >= 1
        assert len(model.nodes) == len(cloud.points) + inside
        assert np.count_nonzero(model.segment_kind == 2) == 2 * np.count_nonzero(cloud.segment_kind == 2)
        assert abs(model.cells.area.sum() - dom.area) <= 1e-12 * dom.area


def test_far_from_the_origin():
    """Coordinates of 3e4 with spacing 0.05: the cells still partition the domain."""
    dom = cnem.geometry.rectangle(origin=(3e4, 3e4))
    model = cnem.discretize(cnem.nodes.irregular(dom, 0.05, seed=1), progress=False)
    assert abs(model.cells.area.sum() - dom.area) <= 1e-10 * dom.area
    assert (model.cells.area > 0).all()
    centroid = model.cells.centroid()
    assert (np.linalg.norm(centroid - model.nodes[model.cells.node], axis=1) < 0.1).all()


@all_cases
def test_neighbors_are_the_triangulation_adjacency(name):
    """`Model.neighbors` (filled by `discretize`, or computed on a cold cache) is the
    adjacency of the triangles: neighbours share the edge facing the vertex, in
    the same region unless asked across regions."""
    from cnem.geometry.topology import triangle_neighbors
    _, _, model = cases.model(name)
    tri, region = model.triangles, model.triangle_region
    cold = cnem.geometry.model.Model(model.cloud, model.nodes, model.node_of_point, tri, region,
                                     model.segments, model.segment_kind, model.cells, {})
    for m in (model, cold):
        for across in (False, True):
            nb = m.neighbors(across_regions=across)
            np.testing.assert_array_equal(nb, triangle_neighbors(tri, None if across else region))
            t, k = np.nonzero(nb >= 0)
            edge = np.sort(np.stack([tri[t, (k + 1) % 3], tri[t, (k + 2) % 3]], axis=1), axis=1)
            other = np.sort(tri[nb[t, k]], axis=1)
            assert all(set(e) <= set(o) for e, o in zip(edge, other))
            assert across or (region[nb[t, k]] == region[t]).all()
    if len(np.unique(region)) > 1:
        assert (model.neighbors() < 0).sum() > (model.neighbors(across_regions=True) < 0).sum()


@all_cases
def test_circumcircles_and_their_tree(name):
    """`Model.circumcircles` (in the model's local frame): every vertex of a
    triangle at the radius from its centre, and the R-tree of their boxes finds
    each triangle from its centroid (it serves point location)."""
    _, _, model = cases.model(name)
    centre, radius2, tree = model.circumcircles()
    assert model.circumcircles()[2] is tree
    corners = model.frame.to_local(model.nodes)[model.triangles]
    dist2 = ((corners - centre[:, None, :]) ** 2).sum(axis=2)
    np.testing.assert_allclose(dist2, np.repeat(radius2[:, None], 3, axis=1), rtol=1e-9)
    centroid = corners.mean(axis=1)
    off, idx = tree.query(centroid, centroid)
    assert all(t in idx[off[t]:off[t + 1]] for t in range(len(centroid)))
