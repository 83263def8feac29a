"""Node generators of `cnem.nodes`: regular, irregular, graded, from_points."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from scipy.spatial import cKDTree

import cnem
import cases
from cnem import geometry, nodes

H = 0.1


def _domains():
    return {
        "square": geometry.rectangle(1.0, 1.0),
        "lshape": geometry.l_shape(1.0, 0.5),
        "hole": geometry.plate_with_hole(1.0, 1.0, 0.25, spacing=0.1),
        "sector": geometry.annulus([1.0, 1.5, 2.0], angles=(0.0, np.pi / 2), spacing=0.1),
        "three": cnem.Domain(cases.THREE_RECTANGLES),
        "edge_crack": geometry.rectangle(1.0, 1.0, cracks=[cases.EDGE_CRACK]),
        "kinked": geometry.rectangle(1.0, 1.0, cracks=[cases.KINKED_CRACK]),
    }


DOMAINS = _domains()


def _generate(kind, dom, h=H, seed=0):
    if kind == "regular":
        return nodes.regular(dom, h)
    if kind == "irregular":
        return nodes.irregular(dom, h, seed=seed)
    if kind == "graded":
        near = dom.tips if len(dom.tips) else np.asarray(dom.polygon.centroid.coords)
        return nodes.graded(dom, h, near=near, h_min=h / 4, growth=0.3, seed=seed)
    raise ValueError(kind)


generators = pytest.mark.parametrize("kind", ["regular", "irregular", "graded"])
domains = pytest.mark.parametrize("dname", list(DOMAINS))


def _seg_lengths(cloud, kind=None):
    s = cloud.segments if kind is None else cloud.segments[cloud.segment_kind == kind]
    return np.linalg.norm(cloud.points[s[:, 0]] - cloud.points[s[:, 1]], axis=1)


def _check_cloud(dom, cloud):
    """Properties every node cloud has."""
    pts = cloud.points
    assert pts.ndim == 2 and pts.shape[1] == 2 and pts.dtype == np.float64
    assert len(cloud) == len(pts) == len(cloud.spacing)
    assert cloud.segments.dtype == np.int64 and cloud.segments.shape[1] == 2
    assert len(cloud.segment_kind) == len(cloud.segments)
    # every node inside the closed domain, no duplicates
    assert dom.contains(pts).all() or _on_constraints(dom, pts[~dom.contains(pts)]).all()
    assert cKDTree(pts).query(pts, k=2)[0][:, 1].min() > 1e3 * dom.tolerance
    # every PSLG vertex is a node (exactly)
    d, _ = cKDTree(pts).query(dom.pslg.vertices)
    assert d.max() == 0.0, "a corner, interface or crack vertex is not a node"
    # the segments chain along the PSLG edges: same total length per kind,
    # every segment on an edge of that kind, no node inside a segment
    v, e = dom.pslg.vertices, dom.pslg.edges
    edge_lines = shapely.linestrings(v[e])
    for k in (0, 1, 2):
        want = np.linalg.norm(v[e[dom.pslg.kind == k, 0]] - v[e[dom.pslg.kind == k, 1]], axis=1).sum()
        assert _seg_lengths(cloud, k).sum() == pytest.approx(want, rel=1e-12, abs=1e-14)
    mids = 0.5 * (pts[cloud.segments[:, 0]] + pts[cloud.segments[:, 1]])
    dist = shapely.distance(edge_lines[None, :], shapely.points(mids)[:, None])
    nearest = dist.argmin(axis=1)
    assert dist.min(axis=1).max() <= 1e-12 * dom.diameter
    np.testing.assert_array_equal(dom.pslg.kind[nearest], cloud.segment_kind)
    seg_lines = shapely.linestrings(pts[cloud.segments])
    tree = shapely.STRtree(seg_lines)
    pi, si = tree.query(shapely.points(pts), predicate="dwithin", distance=dom.tolerance)
    end = (cloud.segments[si] == pi[:, None]).any(axis=1)
    assert end.all(), f"node {pi[~end][:3]} lies inside segment {si[~end][:3]}"


def _on_constraints(dom, pts):
    lines = shapely.linestrings(dom.pslg.vertices[dom.pslg.edges])
    d = shapely.distance(shapely.MultiLineString(list(lines)), shapely.points(pts))
    return d <= dom.tolerance


@generators
@domains
def test_generated_clouds_are_well_formed(kind, dname):
    dom = DOMAINS[dname]
    _check_cloud(dom, _generate(kind, dom))


@domains
def test_regular_boundary_spacing_is_about_h(dname):
    dom = DOMAINS[dname]
    cloud = nodes.regular(dom, H)
    lengths = _seg_lengths(cloud)
    # (no PSLG edge of these domains is shorter than h/2, which would force a short segment)
    edge_len = np.linalg.norm(np.diff(dom.pslg.vertices[dom.pslg.edges], axis=1)[:, 0], axis=1)
    assert edge_len.min() >= 0.5 * H
    assert lengths.min() >= 0.5 * H and lengths.max() <= 1.5 * H, (lengths.min(), lengths.max())
    np.testing.assert_allclose(cloud.spacing, H)


@domains
def test_regular_density_and_clearance(dname):
    dom = DOMAINS[dname]
    cloud = nodes.regular(dom, H)
    # about one node per h^2
    assert 0.8 * dom.area / H**2 < len(cloud) < 1.6 * dom.area / H**2 + 4 / H
    # nodes are at least ~h/2 apart (lattice vs boundary nodes)
    nn = cKDTree(cloud.points).query(cloud.points, k=2)[0][:, 1]
    assert nn.min() >= 0.25 * H and np.median(nn) == pytest.approx(H, rel=0.05)
    # interior nodes keep h/2 from every constraint (the boundary nodes stand there)
    on = np.zeros(len(cloud), dtype=bool)
    on[cloud.segments.ravel()] = True
    lines = shapely.MultiLineString(list(shapely.linestrings(dom.pslg.vertices[dom.pslg.edges])))
    d = shapely.distance(lines, shapely.points(cloud.points[~on]))
    assert d.min() >= 0.5 * H * (1 - 1e-6)


def test_regular_square_lattice():
    cloud = nodes.regular(geometry.rectangle(1.0, 1.0), 0.25)
    xs = np.linspace(0, 1, 5)
    expected = {(x, y) for x in xs for y in xs}
    got = {tuple(p) for p in np.round(cloud.points, 14).tolist()}
    assert got == expected


@domains
def test_irregular_is_reproducible_and_seeded(dname):
    dom = DOMAINS[dname]
    a = nodes.irregular(dom, H, seed=3)
    b = nodes.irregular(dom, H, seed=3)
    c = nodes.irregular(dom, H, seed=4)
    np.testing.assert_array_equal(a.points, b.points)
    np.testing.assert_array_equal(a.segments, b.segments)
    assert a.points.shape != c.points.shape or not np.array_equal(a.points, c.points)
    # same density as the lattice, boundary nodes roughly h apart
    assert 0.7 * dom.area / H**2 < len(a) < 1.6 * dom.area / H**2 + 4 / H
    lengths = _seg_lengths(a)
    assert lengths.min() >= 0.3 * H and lengths.max() <= 1.7 * H
    # the interior differs from a lattice: not all x coordinates on a grid
    frac = np.mod(a.points[:, 0] / H, 1.0)
    assert np.unique(np.round(frac, 6)).size > len(a) / 4


def test_irregular_boundary_nodes_are_jittered():
    dom = geometry.rectangle(1.0, 1.0)
    a, r = nodes.irregular(dom, H, seed=1), nodes.regular(dom, H)
    la, lr = _seg_lengths(a, 0), _seg_lengths(r, 0)
    assert np.ptp(lr) < 1e-12 and np.ptp(la) > 0.05 * H


def test_graded_spacing_near_tips():
    dom = geometry.rectangle(1.0, 1.0, cracks=[cases.INCLINED_CRACK])
    h, h_min, growth = 0.1, 0.01, 0.3
    cloud = nodes.graded(dom, h, near=dom.tips, h_min=h_min, growth=growth, seed=0)
    _check_cloud(dom, cloud)
    tree = cKDTree(cloud.points)
    nn = tree.query(cloud.points, k=2)[0][:, 1]
    for tip in dom.tips:
        k = tree.query_ball_point(tip, 3 * h_min)
        assert len(k) >= 5, "too few nodes near the tip"
        # the nominal spacing there is h_min .. 1.9 h_min
        assert 0.5 * h_min <= np.median(nn[k]) <= 2 * h_min
        assert 0.6 <= np.median(nn[k] / cloud.spacing[k]) <= 1.5
        d_tip, _ = tree.query(tip, k=2)
        assert d_tip[0] == 0.0
        assert 0.5 * h_min <= d_tip[1] <= 1.5 * h_min
    # far from the tips the spacing is back to h
    d = np.linalg.norm(cloud.points[:, None] - dom.tips[None], axis=2).min(axis=1)
    far = d > (h - h_min) / growth + h
    assert far.sum() > 10
    assert np.median(nn[far]) == pytest.approx(h, rel=0.3)
    # the nominal spacing follows min(h, h_min + growth d)
    np.testing.assert_allclose(cloud.spacing, np.minimum(h, h_min + growth * d), rtol=1e-12)
    # graded clouds without seed are deterministic lattices
    a = nodes.graded(dom, h, near=dom.tips, h_min=h_min)
    b = nodes.graded(dom, h, near=dom.tips, h_min=h_min)
    np.testing.assert_array_equal(a.points, b.points)


def test_graded_crack_spacing_near_tips():
    dom = geometry.rectangle(1.0, 1.0, cracks=[cases.INCLINED_CRACK])
    h, h_min = 0.1, 0.02
    cloud = nodes.graded(dom, h, near=dom.tips, h_min=h_min, growth=0.3)
    crack = _seg_lengths(cloud, 2)
    pts = cloud.points[cloud.segments[cloud.segment_kind == 2]]
    mid = pts.mean(axis=1)
    d = np.linalg.norm(mid[:, None] - dom.tips[None], axis=2).min(axis=1)
    assert crack[d < 2 * h_min].max() <= 2.5 * h_min
    assert crack.max() <= 1.5 * h


# ------------------------------------------------------------- from_points
def test_from_points_keeps_points_in_order():
    dom = geometry.rectangle(1.0, 1.0)
    rng = np.random.default_rng(0)
    pts = rng.uniform(0.05, 0.95, (40, 2))
    cloud = nodes.from_points(dom, pts)
    np.testing.assert_array_equal(cloud.points[:40], pts)
    # the missing corners are appended, and nodes filled in along the bare outline
    # (fill=True: it had no point over ~12 spacings), nothing else
    extra = cloud.points[40:]
    corners = [(0.0, 0.0), (0.0, 1.0), (1.0, 0.0), (1.0, 1.0)]
    assert set(corners) <= set(map(tuple, extra.tolist()))
    assert (np.min(np.abs(np.concatenate([extra, 1 - extra], axis=1)), axis=1) == 0).all()
    _check_cloud(dom, cloud)


def test_from_points_given_corners_are_not_duplicated():
    dom = geometry.rectangle(1.0, 1.0)
    pts = np.array([[0.5, 0.5], [1.0, 1.0], [0.0, 0.0], [0.25, 0.0], [1.0, 0.6]])
    cloud = nodes.from_points(dom, pts)
    np.testing.assert_array_equal(cloud.points[:5], pts)
    assert len(cloud) == 7
    _check_cloud(dom, cloud)
    # the points on the boundary split its segments
    assert {3, 4} <= set(np.unique(cloud.segments[cloud.segment_kind == 0]).tolist())


def test_from_points_snaps_onto_boundary_crack_and_corners():
    dom = geometry.rectangle(1.0, 1.0, cracks=[cases.EDGE_CRACK])
    eps = 1e-10            # well inside 1e-9 x diameter
    pts = np.array([
        [0.4, eps],              # 0 -> bottom edge
        [1.0 - eps, 0.3],        # 1 -> right edge
        [eps, -eps],             # 2 -> corner (0, 0)
        [0.3, 0.5 + eps],        # 3 -> crack
        [0.5 - eps, 0.5 + eps],  # 4 -> crack tip
        [0.2, 0.3],              # 5 interior, untouched
        [0.6, 1e-6],             # 6 far from the tolerance: untouched
        [0.0, 0.5 + 0.5 * eps],  # 7 -> crack mouth (vertex on the boundary)
    ])
    cloud = nodes.from_points(dom, pts)
    expected = [[0.4, 0.0], [1.0, 0.3], [0.0, 0.0], [0.3, 0.5], [0.5, 0.5], [0.2, 0.3],
                [0.6, 1e-6], [0.0, 0.5]]
    np.testing.assert_array_equal(cloud.points[:8], expected)
    assert len(cloud) == 8 + 3       # corners (1, 0), (1, 1), (0, 1)
    _check_cloud(dom, cloud)
    segs = cloud.segments
    on_boundary = set(np.unique(segs[cloud.segment_kind == 0]).tolist())
    on_crack = set(np.unique(segs[cloud.segment_kind == 2]).tolist())
    assert {0, 1, 2, 7} <= on_boundary and 6 not in on_boundary and 5 not in on_boundary
    assert on_crack == {3, 4, 7}
    model = cnem.discretize(cloud, progress=False)
    # the snapped crack point is split into two nodes, the tip is not
    count = np.bincount(model.node_of_point, minlength=len(cloud))
    assert count[3] == 2 and count[7] == 2 and count[4] == 1


def test_from_points_nominal_spacing_is_nearest_neighbour_distance():
    dom = geometry.rectangle(1.0, 1.0)
    pts = np.random.default_rng(5).uniform(0.1, 0.9, (30, 2))
    cloud = nodes.from_points(dom, pts)
    nn = cKDTree(cloud.points).query(cloud.points, k=2)[0][:, 1]
    np.testing.assert_allclose(cloud.spacing, nn, rtol=1e-12)


def test_random_points_case():
    dom, cloud = cases.case("random_points")
    n = 250 + len(cases.RANDOM_ON_BOUNDARY)
    np.testing.assert_array_equal(cloud.points[n - len(cases.RANDOM_ON_BOUNDARY):n],
                                  cases.RANDOM_ON_BOUNDARY)
    on_boundary = set(np.unique(cloud.segments[cloud.segment_kind == 0]).tolist())
    assert set(range(250, n)) <= on_boundary
    _check_cloud(dom, cloud)


def test_cloud_repr_counts_segments():
    cloud = nodes.regular(geometry.rectangle(1.0, 1.0, cracks=[cases.EDGE_CRACK]), 0.25)
    text = repr(cloud)
    assert f"{len(cloud)} nodes" in text
    assert f"{np.count_nonzero(cloud.segment_kind == 2)} crack" in text
