"""`cnem.spatial.RTree` against brute force: ball and box queries, nearest, tree invariants.

Every query must return exactly the brute-force sets of `reference` (compared
row by row as sets) on uniform, clustered, graded and lattice clouds, in 2-D
and 3-D, open and periodic. The periodic references try all 3**d images
explicitly, so they check the tree's minimum-image arithmetic (Niina,
Algorithms 1-5) independently.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest

import reference as R
from cnem.spatial import RTree

CASES = R.SPATIAL_CASES
case_id = R.spatial_case_id
SIZES = {2: 1200, 3: 800}


@functools.lru_cache(maxsize=None)
def cloud(kind, dim, periodic):
    """Points, period (None if open) and query radius (per point on graded clouds)."""
    pts, ext, spacing = R.spatial_cloud(kind, dim, SIZES[dim], periodic=periodic, seed=1)
    if kind == "lattice":
        radius = 2.0                    # integer: lattice points at exactly r
    elif kind == "graded":
        radius = 3.0 * spacing
    else:
        radius = 2.5 * spacing[0]
    return pts, (ext if periodic else None), radius


def assert_csr(result, n_rows):
    offsets, indices = result
    assert offsets.dtype == np.int64 and indices.dtype == np.int64
    assert offsets.shape == (n_rows + 1,) and offsets[0] == 0
    assert (np.diff(offsets) >= 0).all() and offsets[-1] == len(indices)


def assert_same_rows(result, ref, what):
    assert_csr(result, len(ref[0]) - 1)
    diff = R.csr_row_differences(*result, *ref)
    assert not diff, f"{what}: rows differ from brute force, (row, missing, extra): {diff}"


def in_cell(rng, m, ext):
    """``m`` random points in ``[0, ext)``."""
    return rng.random((m, len(ext))) * ext


def random_boxes(rng, m, ext, periodic):
    """Boxes of mixed sizes (10 % points, a few large); under periodic boundaries
    about 10 % straddle the cell boundary (centre within 5 % of a face, half-width 10 %)."""
    dim = len(ext)
    centre = (0.001 + 0.998 * rng.random((m, dim))) * ext
    half = ext * 0.03 * rng.random((m, dim)) ** 2
    half[: m // 10] = 0.0
    half[m // 10: m // 10 + m // 50] = ext * (0.1 + 0.2 * rng.random((m // 50, dim)))
    if periodic:
        k = slice(m - m // 10, m)
        near = rng.random((m // 10, dim)) * 0.05
        centre[k] = np.where(rng.random((m // 10, dim)) < 0.5, 0.001 + near, 0.999 - near) * ext
        half[k] = 0.1 * ext
    return centre - half, centre + half


# ---------------------------------------------------------------- ball queries
@pytest.mark.parametrize("case", CASES, ids=case_id)
def test_query_ball_on_points_matches_brute(case):
    pts, period, radius = cloud(*case)
    tree = RTree.from_points(pts, period=period)
    assert len(tree) == len(pts) and tree.dim == pts.shape[1]
    closed = tree.query_ball(pts, radius)
    assert_same_rows(closed, R.brute_ball(pts, pts, pts, radius, period), "closed ball")
    fam = tree.query_ball(pts, radius, strict=True, exclude_self=True)
    ref = R.brute_ball(pts, pts, pts, radius, period, strict=True, exclude_self=True)
    assert_same_rows(fam, ref, "strict ball without self")
    if case[0] == "lattice":     # the ties at exactly r make the two differ
        assert len(closed[1]) > len(fam[1]) + len(pts)


@pytest.mark.parametrize("case", [c for c in CASES if c[0] != "lattice"], ids=case_id)
def test_query_ball_from_other_points_matches_brute(case):
    pts, period, radius = cloud(*case)
    dim = pts.shape[1]
    ext = period if period is not None else np.ptp(pts, axis=0)
    rng = np.random.default_rng(5)
    q = in_cell(rng, 300, ext) + (0 if period is not None else pts.min(axis=0))
    r = np.median(radius) * rng.uniform(0.2, 3.0, len(q))
    r[:10] = 0.0
    tree = RTree.from_points(pts, period=period)
    for strict in (False, True):
        assert_same_rows(tree.query_ball(q, r, strict=strict),
                         R.brute_ball(q, pts, pts, r, period, strict=strict), f"strict={strict}")
    # a scalar radius is the same as the radius repeated
    res = tree.query_ball(q, 0.1 * ext.min())
    assert_same_rows(res, R.brute_ball(q, pts, pts, np.full(len(q), 0.1 * ext.min()), period),
                     f"scalar radius, {dim}-D")


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("periodic", [False, True], ids=["open", "periodic"])
def test_query_ball_on_boxes_matches_brute(dim, periodic):
    ext = np.array([1.0, 0.75, 0.5][:dim])
    rng = np.random.default_rng(dim)
    lo, hi = random_boxes(rng, 1500, ext, periodic)
    period = ext if periodic else None
    tree = RTree(lo, hi, period=period)
    q = in_cell(rng, 400, ext)
    r = 0.08 * ext.min() * rng.random(len(q))
    for strict in (False, True):
        assert_same_rows(tree.query_ball(q, r, strict=strict),
                         R.brute_ball(q, lo, hi, r, period, strict=strict), f"strict={strict}")
    # distance 0 inside a box: a zero radius finds exactly the boxes containing the point
    assert_same_rows(tree.query_ball(q, 0.0), R.brute_ball(q, lo, hi, 0.0, period), "r = 0")


# ----------------------------------------------------------------- box queries
def dyadic_boxes(rng, m, ext, periodic):
    """Boxes with corners on a 1/64 grid (exact arithmetic: many boxes exactly touch)."""
    dim = len(ext)
    lo = np.floor(rng.random((m, dim)) * ext * 64) / 64 - 2 / 64
    hi = lo + rng.integers(0, 9, (m, dim)) / 64
    if periodic:
        c = 0.5 * (lo + hi)
        keep = ((c >= 0) & (c < ext)).all(axis=1)
        lo, hi = lo[keep], hi[keep]
    return lo, hi


def query_boxes(rng, m, ext):
    """Query boxes: random, zero-size, one covering the cell, and ones across the cell faces."""
    dim = len(ext)
    c = in_cell(rng, m, ext)
    h = ext * 0.1 * rng.random((m, dim))
    h[:20] = 0.0
    h[20] = 0.5 * ext
    c[21:30] = ext                     # centred on the far faces: straddle the boundary
    c[30:40] = 0.0
    h[21:40] = 0.05 * ext
    return c - h, c + h


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("periodic", [False, True], ids=["open", "periodic"])
@pytest.mark.parametrize("boxes", ["random", "dyadic", "points"])
def test_query_matches_brute(dim, periodic, boxes):
    ext = np.array([1.0, 0.75, 0.5][:dim])
    rng = np.random.default_rng([dim, int(periodic)])
    period = ext if periodic else None
    if boxes == "random":
        lo, hi = random_boxes(rng, 2000, ext, periodic)
        tree = RTree(lo, hi, period=period)
        qlo, qhi = query_boxes(rng, 500, ext)
    elif boxes == "dyadic":
        lo, hi = dyadic_boxes(rng, 2000, ext, periodic)
        tree = RTree(lo, hi, period=period)
        qlo, qhi = dyadic_boxes(rng, 500, ext, periodic)
        # the exact touchings this case is about do occur
        touch = ((qlo[:, None, :] == hi[None]) | (qhi[:, None, :] == lo[None])).any(axis=2)
        assert touch.sum() > 100
    else:
        lo = hi = R.spatial_cloud("clustered", dim, 1500, periodic=periodic)[0]
        tree = RTree.from_points(lo, period=period)
        qlo, qhi = query_boxes(rng, 500, ext)
    res = tree.query(qlo, qhi)
    assert_same_rows(res, R.brute_box_query(qlo, qhi, lo, hi, period), f"{boxes} boxes")
    assert len(res[1]) > len(qlo)


def test_query_straddling_box_from_the_other_side():
    """A box centred near 0 with half-width 0.1 L covers [0.9 L, L) through the boundary."""
    for dim in (2, 3):
        L = np.array([1.0, 0.75, 0.5][:dim])
        rng = np.random.default_rng(dim)
        lo, hi = random_boxes(rng, 300, L, periodic=True)
        lo[0], hi[0] = -0.08 * L, 0.12 * L          # centre 0.02 L, half-width 0.1 L
        tree = RTree(lo, hi, period=L)
        far = tree.query([0.9 * L, 0.5 * L], [0.95 * L, 0.6 * L])
        assert 0 in far[1][far[0][0]:far[0][1]]         # across every face
        assert 0 not in far[1][far[0][1]:far[0][2]]
        beyond = tree.query([1.05 * L], [1.06 * L])    # a query box outside the cell, same image
        assert 0 in beyond[1]
        off, idx = tree.query_ball([0.95 * L, 0.85 * L], [0.0, 0.05 * L.min()])
        assert 0 in idx[off[0]:off[1]]                 # inside the image: distance 0
        assert 0 not in idx[off[1]:off[2]]             # 0.05 L from the image's corner, r too small
        index, dist = tree.nearest([0.95 * L])
        assert index[0] == 0 and dist[0] == 0.0


@pytest.mark.parametrize("dim", [2, 3])
def test_query_boxes_translated_by_whole_periods(dim):
    """Under periodic boundaries a query box and its translate by any whole number
    of periods hit the same boxes (query boxes need not lie in the cell)."""
    L = np.array([1.0, 0.75, 0.5][:dim])
    rng = np.random.default_rng(20 + dim)
    lo, hi = random_boxes(rng, 1000, L, periodic=True)
    tree = RTree(lo, hi, period=L)
    qlo, qhi = query_boxes(rng, 300, L)
    ref = R.brute_box_query(qlo, qhi, lo, hi, L)
    shifts = np.zeros((len(qlo), dim))
    shifts[:, 0] = rng.integers(-3, 4, len(qlo))
    shifts[:, -1] = rng.integers(-3, 4, len(qlo))
    assert (shifts != 0).sum() > len(qlo)
    for k in (1, -1, 3, -2):
        assert_same_rows(tree.query(qlo + k * L, qhi + k * L), ref, f"shifted by {k} L")
    assert_same_rows(tree.query(qlo + shifts * L, qhi + shifts * L), ref, "shifted by n L")


@pytest.mark.parametrize("dim", [2, 3])
def test_points_on_the_cell_faces(dim):
    """Points at 0 and at np.nextafter(L, 0) are neighbours across the boundary."""
    L = np.array([1.0, 0.75, 0.5][:dim])
    top = np.nextafter(L, 0)
    corners = np.array(np.meshgrid(*[[0.0, 1.0]] * dim, indexing="ij")).reshape(dim, -1).T
    pts = np.vstack([np.where(corners > 0, top, 0.0), 0.5 * L])
    tree = RTree.from_points(pts, period=L)
    off, idx = tree.query_ball(pts, 1e-9, exclude_self=True)
    for i in range(2 ** dim):      # every corner sees the other corners, not the centre
        assert sorted(idx[off[i]:off[i + 1]].tolist()) == [j for j in range(2 ** dim) if j != i]
    assert_same_rows((off, idx), R.brute_ball(pts, pts, pts, 1e-9, L, exclude_self=True), "faces")
    qlo, qhi = np.full((1, dim), -1e-12), np.full((1, dim), 1e-12)
    assert sorted(tree.query(qlo, qhi)[1].tolist()) == list(range(2 ** dim))
    index, dist = tree.nearest([0.999999 * L])
    assert dist[0] < 2e-6 * L.max() and index[0] < 2 ** dim


# --------------------------------------------------------------------- nearest
def check_nearest(tree, q, lo, hi, period):
    index, dist = tree.nearest(q)
    assert index.dtype == np.int64 and index.shape == dist.shape == (len(q),)
    d2 = R.box_dist2(q, lo, hi, period) if not np.array_equal(lo, hi) \
        else R.point_dist2(q, lo, period)
    ref_index, ref_dist = R.brute_nearest(q, lo, hi, period)
    np.testing.assert_allclose(dist, ref_dist, rtol=1e-12, atol=1e-15)
    # the returned box is at the returned distance
    np.testing.assert_allclose(np.sqrt(d2[np.arange(len(q)), index]), ref_dist, rtol=1e-12,
                               atol=1e-15)
    part = np.sort(d2, axis=1)[:, :2]
    clear = (part[:, 1] > part[:, 0] * (1 + 1e-9)) | (part[:, 0] == 0.0)
    bad = np.flatnonzero(clear & (index != ref_index))
    assert not len(bad), (f"nearest index differs at {bad[:5]}: {index[bad[:5]]} "
                          f"instead of {ref_index[bad[:5]]}")
    return index, dist


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("periodic", [False, True], ids=["open", "periodic"])
@pytest.mark.parametrize("kind", ["clustered", "graded"])
def test_nearest_point_tree_matches_brute(dim, periodic, kind):
    pts, ext, _ = R.spatial_cloud(kind, dim, 1200, periodic=periodic, seed=2)
    period = ext if periodic else None
    tree = RTree.from_points(pts, period=period)
    rng = np.random.default_rng(dim)
    q = np.vstack([in_cell(rng, 400, ext), pts[::10]])
    index, dist = check_nearest(tree, q, pts, pts, period)
    assert (dist[400:] == 0).all() and (index[400:] == np.arange(0, len(pts), 10)).all()


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("periodic", [False, True], ids=["open", "periodic"])
def test_nearest_box_tree_matches_brute(dim, periodic):
    ext = np.array([1.0, 0.75, 0.5][:dim])
    rng = np.random.default_rng(10 + dim)
    lo, hi = random_boxes(rng, 1500, ext, periodic)
    period = ext if periodic else None
    tree = RTree(lo, hi, period=period)
    q = in_cell(rng, 500, ext)
    index, dist = check_nearest(tree, q, lo, hi, period)
    assert (dist == 0).sum() > 50          # many points inside (several) boxes: smallest index


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("periodic", [False, True], ids=["open", "periodic"])
def test_nearest_ties_on_a_lattice_take_the_smallest_index(dim, periodic):
    pts, ext, _ = R.spatial_cloud("lattice", dim, 800, periodic=periodic)
    period = ext if periodic else None
    tree = RTree.from_points(pts, period=period)
    rng = np.random.default_rng(dim)
    # centres of lattice cells: 2**d points at distance sqrt(d) / 2 exactly
    q = np.floor(rng.random((300, dim)) * (ext - 1)) + 0.5
    if periodic:   # cells across the boundary: the lattice point 0 is one of the tied ones
        q[:20] = ext - 0.5
        q[20:40, 0] = ext[0] - 0.5
    index, dist = tree.nearest(q)
    assert (dist == np.sqrt(dim) / 2).all()
    ref_index, _ = R.brute_nearest(q, pts, pts, period)
    assert (index == ref_index).all(), np.flatnonzero(index != ref_index)[:5]
    if periodic:
        assert (index[:20] == 0).all()


# ------------------------------------------------------------- tree invariants
def check_tree(tree, lo, hi, period):
    """Node boxes contain their children (Algorithm 4 under periodic boundaries), the
    child ranges of each level partition the level below, the leaves are the boxes."""
    centre, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    b, dim = centre.shape
    assert len(tree) == b
    levels = [tree.node_boxes(k) for k in range(tree.depth + 1)]
    sizes = [len(c) for c, _ in levels]
    start = np.concatenate([[0], np.cumsum(sizes)])
    # level 0 holds every box exactly once
    c0, h0 = levels[0]
    got = np.column_stack([c0, h0])
    want = np.column_stack([centre, half])
    assert np.array_equal(got[np.lexsort(got.T[::-1])], want[np.lexsort(want.T[::-1])])
    if b > 1:
        assert sizes[-1] == 1, "one root"
    tol = 1e-12 * (np.max(period) if period is not None else np.abs(want).max() + 1.0)
    for k in range(1, tree.depth + 1):
        cp, hp = levels[k]
        nodes = np.arange(start[k], start[k + 1])
        first, count = tree.first[nodes], tree.count[nodes]
        assert (count >= 1).all()
        children = np.concatenate([np.arange(f, f + c) for f, c in zip(first, count)])
        assert np.array_equal(np.sort(children), np.arange(start[k - 1], start[k])), \
            f"level {k}: the child ranges do not partition level {k - 1}"
        parent = np.repeat(np.arange(len(nodes)), count)
        cc, hc = levels[k - 1][0][children - start[k - 1]], levels[k - 1][1][children - start[k - 1]]
        assert (hp >= 0).all()
        dc = cp[parent] - cc
        if period is not None:
            assert ((cp >= 0) & (cp < period)).all(), "node centres restricted to the cell"
            assert (hp <= 0.5 * period).all()
            dc = dc - period * np.round(dc / period)
            ok = (np.abs(dc) + hc <= hp[parent] + tol) | (hp[parent] == 0.5 * period)
        else:
            ok = np.abs(dc) + hc <= hp[parent] + tol
        bad = np.flatnonzero(~ok.all(axis=1))
        assert not len(bad), (f"level {k}: node {parent[bad[0]]} (centre {cp[parent[bad[0]]]}, "
                              f"half {hp[parent[bad[0]]]}) does not contain child centre "
                              f"{cc[bad[0]]}, half {hc[bad[0]]}")


TREES = ["points-uniform", "points-clustered", "points-graded", "boxes", "dyadic", "full-width"]


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("periodic", [False, True], ids=["open", "periodic"])
@pytest.mark.parametrize("what", TREES)
def test_node_boxes_contain_their_children(dim, periodic, what):
    ext = np.array([1.0, 0.75, 0.5][:dim])
    rng = np.random.default_rng(dim)
    period = ext if periodic else None
    if what.startswith("points"):
        lo = hi = R.spatial_cloud(what.split("-")[1], dim, 3000, periodic=periodic, seed=3)[0]
        tree = RTree.from_points(lo, period=period)
    else:
        if what == "dyadic":
            lo, hi = dyadic_boxes(rng, 3000, ext, periodic)
        else:
            lo, hi = random_boxes(rng, 3000, ext, periodic)
        if what == "full-width":     # boxes as wide as the cell along x (exactly, dyadic)
            lo[::97, 0], hi[::97, 0] = -0.25 * ext[0], 0.75 * ext[0]
            if not periodic:
                lo[::89], hi[::89] = lo[::89] - 0.5 * ext, lo[::89] + 0.5 * ext
        tree = RTree(lo, hi, period=period)
    assert tree.depth >= 2
    check_tree(tree, lo, hi, period)


def test_periodic_nodes_stay_small_across_the_boundary():
    """Algorithm 1: a cluster around the corner of the cell gets a small node box
    through the boundary, not one spanning the whole cell."""
    for dim in (2, 3):
        L = np.array([1.0, 0.75, 0.5][:dim])
        rng = np.random.default_rng(dim)
        pts = np.mod(rng.uniform(-0.05, 0.05, (3000, dim)) * L, L)
        pts = np.where(pts >= L, 0.0, pts)
        tree = RTree.from_points(pts, period=L)
        check_tree(tree, pts, pts, L)
        centre, half = tree.node_boxes(tree.depth)
        assert (half[0] <= 0.05 * L * (1 + 1e-9)).all(), half


def test_empty_and_single():
    for dim in (2, 3):
        for period in (None, np.ones(dim)):
            empty = RTree.from_points(np.zeros((0, dim)), period=period)
            assert len(empty) == 0 and empty.depth == 0
            q = np.full((2, dim), 0.5)
            off, idx = empty.query_ball(q, 0.3)
            assert off.tolist() == [0, 0, 0] and len(idx) == 0
            off, idx = empty.query(q - 0.1, q + 0.1)
            assert off.tolist() == [0, 0, 0] and len(idx) == 0
            index, dist = empty.nearest(q)
            assert index.tolist() == [-1, -1] and np.isinf(dist).all()
            empty_boxes = RTree(np.zeros((0, dim)), np.zeros((0, dim)), period=period)
            assert len(empty_boxes.query(q, q)[1]) == 0

            one = RTree.from_points(np.full((1, dim), 0.25), period=period)
            assert one.depth == 0
            q[:, 1:] = 0.25                     # at distance 0.25 exactly, along x
            off, idx = one.query_ball(q, [0.25, 0.1])
            assert off.tolist() == [0, 1, 1] and idx.tolist() == [0]
            off, idx = one.query_ball(q, 0.25, strict=True)
            assert off.tolist() == [0, 0, 0]
            off, idx = one.query(q - 0.25, q)
            assert off.tolist() == [0, 1, 2] and idx.tolist() == [0, 0]
            index, dist = one.nearest(q)
            assert index.tolist() == [0, 0] and (dist == 0.25).all()
            off, idx = one.query_ball(np.full((1, dim), 0.25), 0.0, exclude_self=True)
            assert off.tolist() == [0, 0]

            tree = RTree.from_points(np.random.default_rng(0).random((100, dim)), period=period)
            for res in (tree.query_ball(np.zeros((0, dim)), 0.1),
                        tree.query(np.zeros((0, dim)), np.zeros((0, dim)))):
                assert res[0].tolist() == [0] and len(res[1]) == 0
            index, dist = tree.nearest(np.zeros((0, dim)))
            assert len(index) == len(dist) == 0


def test_duplicate_points():
    rng = np.random.default_rng(4)
    base = rng.random((300, 2))
    pts = np.vstack([base, base[:100], base[:50]])
    for period in (None, [1.0, 1.0]):
        tree = RTree.from_points(pts, period=period)
        for kw in ({}, {"strict": True, "exclude_self": True}):
            assert_same_rows(tree.query_ball(pts, 0.05, **kw),
                             R.brute_ball(pts, pts, pts, 0.05, period, **kw), str(kw))


def test_nearest_duplicates_take_the_smallest_index():
    rng = np.random.default_rng(4)
    base = rng.random((300, 2))
    pts = np.vstack([base, base[:100], base[:50]])
    first = np.concatenate([np.arange(300), np.arange(100), np.arange(50)])
    for period in (None, [1.0, 1.0]):
        index, dist = RTree.from_points(pts, period=period).nearest(pts)
        assert (dist == 0).all()
        bad = np.flatnonzero(index != first)
        assert not len(bad), f"period {period}: nearest of {bad} is {index[bad]}, not {first[bad]}"


# ---------------------------------------------------- exactness at (near-)ties
@pytest.mark.parametrize("periodic", [False, True], ids=["open", "periodic"])
def test_ball_at_exactly_r(periodic):
    """Query points moved off a data point along x only: the data point is at
    distance r = |dx| exactly (r * r equals the squared distance), so the closed
    ball must contain it, the strict ball with r + 1 ulp too, and neither the
    closed ball with r - 1 ulp nor the strict ball with r. The cloud sits away
    from the origin, where node boxes in centre / half-width form round."""
    rng = np.random.default_rng(7)
    pts = 10.0 + rng.random((3000, 2))
    period = np.array([16.0, 16.0]) if periodic else None
    tree = RTree.from_points(pts, period=period)
    q = pts.copy()
    q[:, 0] += rng.uniform(-0.05, 0.05, len(q))
    r = np.abs(q[:, 0] - pts[:, 0])
    assert ((q - pts)[:, 0] ** 2 == r * r).all()
    for radius, strict in ((r, False), (np.nextafter(r, np.inf), True),
                           (np.nextafter(r, 0), False), (r, True)):
        ref = R.brute_ball(q, pts, pts, radius, period, strict=strict)
        assert_same_rows(tree.query_ball(q, radius, strict=strict), ref,
                         f"strict={strict}, r = |dx| {'' if radius is r else '-+ 1 ulp'}")


@pytest.mark.parametrize("periodic", [False, True], ids=["open", "periodic"])
def test_query_box_touching_or_one_ulp_apart(periodic):
    """Closed boxes with random (non-dyadic) corners: a query whose lower x equals
    a box's upper x intersects it; one whose lower x is 1 ulp above does not."""
    rng = np.random.default_rng(8)
    lo = 0.2 + 0.6 * rng.random((2000, 2))
    hi = lo + 0.02 * rng.random((2000, 2))
    period = np.ones(2) if periodic else None
    tree = RTree(lo, hi, period=period)
    pick = rng.integers(0, len(lo), 500)
    for gap in (False, True):
        x = np.nextafter(hi[pick, 0], np.inf) if gap else hi[pick, 0]
        qlo = np.column_stack([x, lo[pick, 1] - 0.01])
        qhi = qlo + 0.02 * rng.random((500, 2)) + [0.0, 0.01]
        ref = R.brute_box_query(qlo, qhi, lo, hi, period)
        hit = [p in ref[1][ref[0][i]:ref[0][i + 1]] for i, p in enumerate(pick)]
        assert not any(hit) if gap else all(hit)
        assert_same_rows(tree.query(qlo, qhi), ref, "1 ulp apart" if gap else "touching")


# ---------------------------------------------------------------------- errors
def test_period_of_the_wrong_length_is_named():
    pts = np.random.default_rng(0).random((50, 2))
    with pytest.raises(ValueError, match="period"):
        RTree.from_points(pts, period=[1.0, 1.0, 1.0])


def test_errors():
    L = np.array([1.0, 0.75])
    pts = np.random.default_rng(0).random((50, 2)) * L
    with pytest.raises(ValueError, match=r"1 points lie outside the periodic cell.*1\.0, 0\.75"
                                         r".*\[\[1\.0, 0\.5\]\].*np\.mod"):
        RTree.from_points(np.vstack([pts, [[1.0, 0.5]]]), period=L)
    with pytest.raises(ValueError, match=r"2 points lie outside the periodic cell.*-1e-300"):
        RTree.from_points(np.vstack([pts, [[0.5, -1e-300]], [[0.2, 0.75]]]), period=L)
    tree = RTree.from_points(pts, period=L)
    for bad in ([[0.5, 0.75]], [[-0.1, 0.1]], [[1.5, 0.1]]):
        with pytest.raises(ValueError, match="outside the periodic cell"):
            tree.query_ball(bad, 0.1)
        with pytest.raises(ValueError, match="outside the periodic cell"):
            tree.nearest(bad)
    with pytest.raises(ValueError, match="outside the periodic cell"):
        RTree([[0.9, 0.7]], [[1.1, 0.8]], period=L)     # centre (1.0, 0.75) outside
    with pytest.raises(ValueError, match="wider than the periodic cell"):
        RTree([[0.0, 0.0]], [[1.2, 0.1]], period=L)
    with pytest.raises(ValueError, match="period"):
        RTree.from_points(pts, period=[1.0, -1.0])
    # shapes and values
    with pytest.raises(ValueError, match=r"\(n, 2\) or \(n, 3\).*\(5, 4\)"):
        RTree.from_points(np.zeros((5, 4)))
    with pytest.raises(ValueError, match=r"\(n, 2\) or \(n, 3\)"):
        RTree.from_points(np.zeros(6))
    with pytest.raises(ValueError, match="finite"):
        RTree.from_points([[0.0, 0.0], [np.nan, 1.0]])
    with pytest.raises(ValueError, match="finite"):
        RTree.from_points([[0.0, 0.0], [np.inf, 1.0]])
    with pytest.raises(ValueError, match="hi < lo"):
        RTree([[0.0, 0.0], [1.0, 1.0]], [[1.0, 1.0], [2.0, 0.5]])
    with pytest.raises(ValueError, match="same shape"):
        RTree([[0.0, 0.0]], [[1.0, 1.0], [2.0, 2.0]])
    tree = RTree.from_points(pts)
    with pytest.raises(ValueError, match="dimension 2, received 3"):
        tree.query_ball([[0.1, 0.2, 0.3]], 0.1)
    with pytest.raises(ValueError, match="dimension 2, received 3"):
        tree.nearest([[0.1, 0.2, 0.3]])
    with pytest.raises(ValueError, match="dimension"):
        tree.query([[0.1, 0.2, 0.3]], [[0.2, 0.3, 0.4]])
    with pytest.raises(ValueError, match="finite"):
        tree.query_ball([[np.nan, 0.2]], 0.1)
    with pytest.raises(ValueError, match="finite"):
        tree.nearest([[0.1, np.nan]])
    with pytest.raises(ValueError, match="non-negative"):
        tree.query_ball(pts[:2], -0.1)
    with pytest.raises(ValueError, match="non-negative"):
        tree.query_ball(pts[:2], [0.1, -1e-300])
    with pytest.raises(ValueError, match="finite"):
        tree.query_ball(pts[:2], np.nan)
    with pytest.raises(ValueError, match="qlo <= qhi"):
        tree.query([[0.5, 0.5]], [[0.4, 0.6]])
    with pytest.raises(ValueError, match="same shape"):
        tree.query([[0.5, 0.5]], [[0.6, 0.6], [0.7, 0.7]])


@pytest.mark.parametrize("offset, extent, n", [(1e12, 1.0, 300), (5e6, 100.0, 20_000)])
def test_far_from_the_origin_in_bounded_time(offset, extent, n):
    """Boxes are rounded outwards in one step, not one ulp per iteration: a cloud far
    from the origin (UTM-like, or at 1e12) builds at once (it hung before) and its ball
    queries are exact. Run in a subprocess with a time limit, so a regression fails
    instead of hanging the suite."""
    import subprocess
    import sys
    code = (
        "import numpy as np, cnem.spatial as sp\n"
        f"rng = np.random.default_rng(1); pts = {offset!r} + {extent!r} * rng.random(({n}, 2))\n"
        "tree = sp.RTree.from_points(pts)\n"
        f"r = 0.02 * {extent!r}; q = pts[:200]\n"
        "o, i = tree.query_ball(q, r)\n"
        "d = np.hypot(*(q[:, None, :] - pts[None, :, :]).transpose(2, 0, 1))\n"
        "print(all(set(i[o[k]:o[k + 1]]) == set(np.flatnonzero(d[k] <= r)) for k in range(len(q))))\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=240)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "True"


@pytest.mark.parametrize("kind", ["uniform", "clustered", "far", "line"])
def test_a_tree_over_the_points_near_boxes_finds_every_point_in_them(kind):
    """`RTree.from_points_in` keeps only the points in the coarse grid cells the boxes
    meet, but a query by any box holding one of them finds exactly the points inside
    it (brute force), on the boxes' sides too; far from the boxes it holds few points."""
    rng = np.random.default_rng(3)
    n = 20000
    pts = rng.random((n, 2))
    if kind == "clustered":
        pts[: n // 2] = 0.5 + 1e-4 * rng.standard_normal((n // 2, 2))
    elif kind == "far":
        pts = 1e6 + 1e-3 * pts
    elif kind == "line":
        pts[:, 1] = 0.25
    lo0, hi0 = pts.min(axis=0), pts.max(axis=0)
    span = hi0 - lo0
    centre = pts[rng.integers(n, size=40)]
    half = span * rng.uniform(0.0, 0.05, (40, 1))
    lo, hi = centre - half, centre + half
    lo[0], hi[0] = pts[1], pts[1]                        # a box of one point
    lo[1], hi[1] = lo0, lo0 + 0.3 * span                 # a corner of the extent
    tree, subset = RTree.from_points_in(pts, lo, hi, (lo0, hi0))
    assert (np.diff(subset) > 0).all()
    grow = 0.01 * span
    for qlo, qhi in ((lo, hi), (lo - grow, hi + grow)):
        ptr, idx = tree.query(qlo, qhi)
        for b in range(len(lo)):
            want = np.flatnonzero(((pts >= lo[b]) & (pts <= hi[b])).all(axis=1))
            got = subset[idx[ptr[b]:ptr[b + 1]]]
            inside = ((pts[got] >= lo[b]) & (pts[got] <= hi[b])).all(axis=1)
            assert np.array_equal(np.sort(got[inside]), want)
    if kind == "uniform":
        assert len(subset) < n / 2


@pytest.mark.parametrize("scale", [1e-300, 1e-200, 1.0, 1e100])
@pytest.mark.parametrize("strict", [False, True])
def test_query_ball_is_the_same_at_every_scale(scale, strict):
    """A lattice of spacing ``scale`` queried at 1.5 spacings finds each point's
    neighbours within 1.5 spacings — the brute-force answer at unit scale — also where
    the squared distances would underflow (1e-300: they used to give every point)."""
    g = np.arange(10.0)
    pts = np.array([(x, y) for x in g for y in g[:3]])
    gaps = np.linalg.norm(pts[:, None] - pts[None], axis=2)
    expected = (gaps < 1.5) if strict else (gaps <= 1.5)
    offsets, indices = RTree.from_points(pts * scale).query_ball(pts * scale, 1.5 * scale,
                                                                 strict=strict)
    for i in range(len(pts)):
        np.testing.assert_array_equal(np.sort(indices[offsets[i]:offsets[i + 1]]),
                                      np.flatnonzero(expected[i]))
