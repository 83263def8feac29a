"""Constrained natural-neighbour shape functions (`cnem.shape`, `Model.shape_functions`).

Checked against the slow definitions in `reference.py` (`sibson_reference`,
`laplace_reference`: Voronoi cells as half-plane intersections of the nodes
visible from the point, C-NEM eq. 3-4 and 13) and against the properties the
API promises (partition of unity, linear reproduction, non-negativity,
Kronecker delta, visibility, linearity on constraint segments, continuity,
outside points rejected) -- never against numbers the code printed.
"""

from __future__ import annotations

import functools
import re

import numpy as np
import pytest
import scipy.sparse as sp

import cnem
import cases
import reference

NAMES = cases.NAMES


def _phi(model, points, kind="sibson"):
    """Dense Phi through the public entry, checking the container on the way."""
    points = np.asarray(points, dtype=float)
    out = model.shape_functions(points, kind=kind)
    assert sp.issparse(out) and out.format == "csr", f"expected a CSR matrix, got {type(out)}"
    assert out.shape == (len(points), len(model.nodes)), out.shape
    return out.toarray()


def _seg_dist(points, a, b):
    """Distance ``(p,)`` from each point to the nearest of the segments ``a-b``."""
    ab = b - a
    ll = np.maximum((ab * ab).sum(axis=1), 1e-300)
    best = np.full(len(points), np.inf)
    for lo in range(0, len(points), 256):
        p = points[lo:lo + 256, None, :]
        t = np.clip(((p - a) * ab).sum(axis=2) / ll, 0.0, 1.0)
        d = np.linalg.norm(p - (a + t[..., None] * ab), axis=2)
        best[lo:lo + 256] = d.min(axis=1)
    return best


def _constraint_dist(model, points):
    seg = model.segments
    return _seg_dist(np.asarray(points, float), model.nodes[seg[:, 0]], model.nodes[seg[:, 1]])


def interior_points(name, count, seed, margin=1e-6):
    """Seeded random points inside the domain, farther than ``margin`` from every
    constraint segment and every node."""
    dom, _, model = cases.model(name)
    rng = np.random.default_rng([seed, len(name)])
    lo, hi = np.asarray(dom.bounds[:2]), np.asarray(dom.bounds[2:])
    got = []
    while sum(len(g) for g in got) < count:
        cand = lo + rng.random((4 * count, 2)) * (hi - lo)
        cand = cand[dom.contains(cand)]
        cand = cand[_constraint_dist(model, cand) > margin]
        dn = np.min(np.linalg.norm(cand[:, None, :] - model.nodes[None], axis=2), axis=1)
        got.append(cand[dn > margin])
    return np.concatenate(got)[:count]


@functools.lru_cache(maxsize=None)
def _property_sample(name):
    """300 random points of a case (no margin: some fall near constraints) and their Phi."""
    dom, _, model = cases.model(name)
    rng = np.random.default_rng([99, len(name)])
    lo, hi = np.asarray(dom.bounds[:2]), np.asarray(dom.bounds[2:])
    pts = lo + rng.random((2000, 2)) * (hi - lo)
    pts = pts[dom.contains(pts)][:300]
    assert len(pts) == 300
    return pts, _phi(model, pts)


def _scale(model):
    return max(1.0, float(np.abs(model.nodes).max()))


def _copies(model):
    """For each node, the nodes at exactly the same coordinates (crack-face copies), itself included."""
    groups = {}
    for j, p in enumerate(map(tuple, model.nodes)):
        groups.setdefault(p, []).append(j)
    return [groups[tuple(p)] for p in model.nodes]


def _dict_row(ref, n):
    row = np.zeros(n)
    row[list(ref)] = list(ref.values())
    return row


def _compare_rows(model, points, got, ref_fn, tol):
    dom = model.domain
    regions = dom.region_of(points)
    worst = (0.0, None)
    for x, r, row in zip(points, regions, got):
        ref = ref_fn(model, x, int(r))
        vals = np.array(list(ref.values()))
        idx = np.array(list(ref), dtype=int)
        # the reference must itself be a valid coordinate system, or the comparison means nothing
        assert abs(vals.sum() - 1.0) <= 1e-11, f"reference broken at {x.tolist()}: sum {vals.sum()}"
        assert np.abs(vals @ model.nodes[idx] - x).max() <= 1e-11 * _scale(model), \
            f"reference broken at {x.tolist()}: no linear reproduction"
        err = np.abs(row - _dict_row(ref, len(model.nodes)))
        if err.max() > worst[0]:
            k = int(np.argmax(err))
            worst = (float(err.max()), (x.tolist(), k, float(row[k]), ref.get(k, 0.0)))
    assert worst[0] <= tol, ("largest difference from the reference %.3g at x=%s, node %d: "
                             "got %.17g, reference %.17g" % (worst[0], *worst[1]))


# ------------------------------------------------------------------ against the definition
@pytest.mark.slow
@pytest.mark.parametrize("name", NAMES)
def test_sibson_matches_reference(name):
    _, _, model = cases.model(name)
    pts = interior_points(name, 50, seed=1)
    _compare_rows(model, pts, _phi(model, pts), reference.sibson_reference, 1e-10)


@pytest.mark.parametrize("name", ["square_irregular", "lshape_regular", "plate_hole_irregular",
                                  "three_rectangles_irregular", "edge_crack_regular",
                                  "kinked_crack_irregular"])
def test_laplace_matches_reference(name):
    _, _, model = cases.model(name)
    pts = interior_points(name, 20, seed=2)
    try:
        got = _phi(model, pts, kind="laplace")
    except NotImplementedError as exc:
        pytest.skip(f"kind='laplace' not implemented: {exc}")
    _compare_rows(model, pts, got, reference.laplace_reference, 1e-10)
    np.testing.assert_allclose(got.sum(axis=1), 1.0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(got @ model.nodes, pts, rtol=0, atol=1e-12 * _scale(model))


def test_module_entry_and_model_method_agree():
    _, _, model = cases.model("lshape_irregular")
    pts = interior_points("lshape_irregular", 20, seed=3)
    a = cnem.shape.shape_functions(model, pts)
    b = model.shape_functions(pts)
    assert (a != b).nnz == 0


def test_unknown_kind_rejected():
    _, _, model = cases.model("square_irregular")
    with pytest.raises(ValueError):
        model.shape_functions(np.array([[0.5, 0.5]]), kind="linear")


# ------------------------------------------------------------------ properties
@pytest.mark.parametrize("name", NAMES)
def test_partition_of_unity_linear_reproduction_nonnegative(name):
    _, _, model = cases.model(name)
    pts, phi = _property_sample(name)
    sums = phi.sum(axis=1)
    k = int(np.argmax(np.abs(sums - 1)))
    assert abs(sums[k] - 1) <= 1e-12, f"row sum {sums[k]!r} at {pts[k].tolist()}"
    rep = np.abs(phi @ model.nodes - pts).max(axis=1)
    k = int(np.argmax(rep))
    assert rep[k] <= 1e-12 * _scale(model), f"Phi @ nodes off by {rep[k]:.3g} at {pts[k].tolist()}"
    k, j = np.unravel_index(np.argmin(phi), phi.shape)
    assert phi[k, j] >= -1e-14, f"phi_{j} = {phi[k, j]!r} at {pts[k].tolist()}"
    assert np.isfinite(phi).all()


@pytest.mark.parametrize("name", NAMES)
def test_no_weight_from_invisible_nodes(name):
    dom, _, model = cases.model(name)
    pts, phi = _property_sample(name)
    regions = dom.region_of(pts)
    members = {r: set(np.unique(model.triangles[model.triangle_region == r]).tolist())
               for r in np.unique(regions)}
    bad = []
    for x, r, row in zip(pts, regions, phi):
        for j in np.flatnonzero(np.abs(row) > 1e-14):
            if not reference.visible(model, j, x) or int(j) not in members[r]:
                bad.append((x.tolist(), int(j), model.nodes[j].tolist(), float(row[j])))
    assert not bad, f"{len(bad)} weights from nodes the point cannot see, first " \
                    f"(x, node, node xy, phi): {bad[:3]}"


@pytest.mark.parametrize("name", NAMES)
def test_kronecker_delta_at_nodes(name):
    _, _, model = cases.model(name)
    phi = _phi(model, model.nodes)
    copies = _copies(model)
    bad = []
    for j, row in enumerate(phi):
        ok = False
        for k in copies[j]:
            unit = np.zeros(len(row))
            unit[k] = 1.0
            ok |= bool(np.abs(row - unit).max() <= 1e-12)
        if not ok:
            nz = np.flatnonzero(np.abs(row) > 1e-14)
            bad.append((j, model.nodes[j].tolist(), dict(zip(nz.tolist(), row[nz].round(15).tolist()))))
    assert not bad, f"{len(bad)} nodes without a unit row, first (node, xy, row): {bad[:3]}"


def _check_on_segments(model, kinds, ts):
    """Points t a + (1 - t) b on every segment of the given kinds: weight t at a,
    1 - t at b (either crack-face copy), nothing elsewhere."""
    seg = model.segments[np.isin(model.segment_kind, kinds)]
    assert len(seg)
    a, b = model.nodes[seg[:, 0]], model.nodes[seg[:, 1]]
    pts = (ts[:, None, None] * a[None] + (1 - ts)[:, None, None] * b[None]).reshape(-1, 2)
    tt = np.repeat(ts, len(seg))
    sa, sb = np.tile(seg[:, 0], len(ts)), np.tile(seg[:, 1], len(ts))
    phi = _phi(model, pts)
    copies = _copies(model)
    bad = []
    for x, t, i, j, row in zip(pts, tt, sa, sb, phi):
        expected_ok = False
        for ci in copies[i]:
            for cj in copies[j]:
                want = np.zeros(len(row))
                want[ci], want[cj] = t, 1 - t
                err = np.abs(row - want)
                err[[ci, cj]] /= 1e2        # end weights to 1e-12, every other weight to 1e-14
                expected_ok |= bool(err.max() <= 1e-14)
        if not expected_ok:
            nz = np.flatnonzero(np.abs(row) > 1e-14)
            bad.append((x.tolist(), float(t), int(i), int(j),
                        dict(zip(nz.tolist(), row[nz].round(15).tolist()))))
    return bad


@pytest.mark.parametrize("name", NAMES)
def test_linear_on_boundary_segments(name):
    _, _, model = cases.model(name)
    ts = np.array([0.5, 0.1, 0.37, 0.83, 1e-7])
    bad = _check_on_segments(model, [0], ts)
    assert not bad, (f"{len(bad)} boundary points not interpolated linearly between the segment "
                     f"ends, first (x, t, a, b, row): {bad[:3]}")


@pytest.mark.parametrize("name", cases.CRACKED + cases.INTERFACES)
def test_linear_on_crack_faces_and_interfaces(name):
    _, _, model = cases.model(name)
    ts = np.array([0.5, 0.23, 0.71])
    bad = _check_on_segments(model, [1, 2], ts)
    assert not bad, (f"{len(bad)} crack/interface points not interpolated linearly between the "
                     f"segment ends, first (x, t, a, b, row): {bad[:3]}")


# ------------------------------------------------------------------ continuity
def _circumcircles(model):
    p = model.nodes[model.triangles]
    a, b, c = p[:, 0], p[:, 1], p[:, 2]
    d = 2 * (a[:, 0] * (b[:, 1] - c[:, 1]) + b[:, 0] * (c[:, 1] - a[:, 1]) + c[:, 0] * (a[:, 1] - b[:, 1]))
    sa, sb, sc = (a * a).sum(1), (b * b).sum(1), (c * c).sum(1)
    ux = (sa * (b[:, 1] - c[:, 1]) + sb * (c[:, 1] - a[:, 1]) + sc * (a[:, 1] - b[:, 1])) / d
    uy = (sa * (c[:, 0] - b[:, 0]) + sb * (a[:, 0] - c[:, 0]) + sc * (b[:, 0] - a[:, 0])) / d
    centre = np.stack([ux, uy], axis=1)
    return centre, np.linalg.norm(a - centre, axis=1)


def _continuity_points(name, count=120):
    """Points on interior triangle edges and on circumcircles (where the set of
    natural neighbours changes), plus random ones, with a random unit direction each."""
    dom, _, model = cases.model(name)
    rng = np.random.default_rng([7, len(name)])
    tri = model.triangles
    e = tri[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)
    t = rng.uniform(0.05, 0.95, len(e))
    on_edges = t[:, None] * model.nodes[e[:, 0]] + (1 - t[:, None]) * model.nodes[e[:, 1]]
    centre, rad = _circumcircles(model)
    ang = rng.uniform(0, 2 * np.pi, len(centre))
    on_circles = centre + rad[:, None] * np.stack([np.cos(ang), np.sin(ang)], axis=1)
    pts = np.concatenate([rng.permutation(on_edges)[:count // 3],
                          rng.permutation(on_circles)[:3 * count],
                          interior_points(name, count // 3, seed=7)])
    pts = pts[dom.contains(pts)]
    pts = pts[_constraint_dist(model, pts) > 1e-6]
    ang = rng.uniform(0, 2 * np.pi, len(pts))
    return pts[:count], np.stack([np.cos(ang), np.sin(ang)], axis=1)[:count]


@pytest.mark.parametrize("name", NAMES)
def test_continuity_across_edges_and_circumcircles(name):
    _, _, model = cases.model(name)
    pts, d = _continuity_points(name)
    assert len(pts) >= 60
    p0, p1, pm = _phi(model, pts), _phi(model, pts + 1e-9 * d), _phi(model, pts - 1e-9 * d)
    for other, label in ((p1, "x + 1e-9 d"), (pm, "x - 1e-9 d")):
        diff = np.abs(other - p0).max(axis=1)
        k = int(np.argmax(diff))
        assert diff[k] <= 1e-6, f"Phi(x) and Phi({label}) differ by {diff[k]:.3g} at x={pts[k].tolist()}"
    # the points exactly on edges / circles are still valid coordinates
    np.testing.assert_allclose(p0.sum(axis=1), 1.0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(p0 @ model.nodes, pts, rtol=0, atol=1e-12 * _scale(model))
    assert p0.min() >= -1e-14


# ------------------------------------------------------------------ cocircular lattice
@functools.lru_cache(maxsize=None)
def _lattice_model():
    """Square with nodes on the exact binary lattice k / 8: every grid square cocircular."""
    dom = cnem.geometry.rectangle(1.0, 1.0)
    g = np.arange(9) / 8.0
    pts = np.stack(np.meshgrid(g, g, indexing="ij"), axis=-1).reshape(-1, 2)
    return cnem.discretize(cnem.nodes.from_points(dom, pts), progress=False)


def test_lattice_square_centres_quarter_each():
    model = _lattice_model()
    assert len(model.nodes) == 81
    h = 1.0 / 8.0
    centres = np.array([[h * (i + 0.5), h * (j + 0.5)] for i in range(8) for j in range(8)])
    phi = _phi(model, centres)
    for x, row in zip(centres, phi):
        corners = [k for k in range(81) if np.abs(np.abs(model.nodes[k] - x) - h / 2).max() < 1e-15]
        assert len(corners) == 4
        want = np.zeros(81)
        want[corners] = 0.25        # by symmetry; also what the reference gives
        assert np.abs(row - want).max() <= 1e-12, (x.tolist(), row[np.abs(row) > 1e-14])
    ref = reference.sibson_reference(model, centres[27], 0)
    assert sorted(ref.values()) == pytest.approx([0.25] * 4, abs=1e-13)


def test_lattice_degenerate_points_match_reference():
    """Random points, points on grid lines and on circles through four lattice nodes."""
    model = _lattice_model()
    rng = np.random.default_rng(5)
    h = 1.0 / 8.0
    rand = rng.uniform(0.01, 0.99, (30, 2))
    on_lines = np.stack([rng.integers(1, 8, 15) * h, rng.uniform(0.01, 0.99, 15)], axis=1)
    on_lines = np.concatenate([on_lines, on_lines[:, ::-1]])
    c = (rng.integers(1, 7, (20, 2)) + 0.5) * h
    ang = rng.uniform(0, 2 * np.pi, 20)
    on_circles = c + (h / np.sqrt(2)) * np.stack([np.cos(ang), np.sin(ang)], axis=1)
    pts = np.concatenate([rand, on_lines, on_circles])
    pts = pts[np.min(np.linalg.norm(pts[:, None] - model.nodes[None], axis=2), axis=1) > 1e-6]
    phi = _phi(model, pts)
    _compare_rows(model, pts, phi, reference.sibson_reference, 1e-10)
    np.testing.assert_allclose(phi.sum(axis=1), 1.0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(phi @ model.nodes, pts, rtol=0, atol=1e-12)
    assert phi.min() >= -1e-14
    # continuity through the cocircular configurations
    d = rng.normal(size=pts.shape)
    d /= np.linalg.norm(d, axis=1)[:, None]
    assert np.abs(_phi(model, pts + 1e-9 * d) - phi).max() <= 1e-6


def test_lattice_kronecker_and_boundary():
    model = _lattice_model()
    phi = _phi(model, model.nodes)
    assert np.abs(phi - np.eye(81)).max() <= 1e-12
    ts = np.array([0.5, 0.25, 0.9])
    assert not _check_on_segments(model, [0], ts)


# ------------------------------------------------------------------ outside points
def _outside_points(name, count, seed):
    dom, _, model = cases.model(name)
    rng = np.random.default_rng([seed, len(name)])
    lo, hi = np.asarray(dom.bounds[:2]), np.asarray(dom.bounds[2:])
    span = hi - lo
    cand = lo - 0.2 * span + rng.random((5000, 2)) * 1.4 * span
    cand = cand[~dom.contains(cand)]
    cand = cand[_constraint_dist(model, cand) > 1e-3 * dom.diameter]
    # prefer points in holes / notches (inside the bounding box) when there are some
    inbox = ((cand >= lo) & (cand <= hi)).all(axis=1)
    cand = np.concatenate([cand[inbox], cand[~inbox]])
    assert len(cand) >= count
    return cand[:count]


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("count", [1, 3])
def test_points_outside_raise(name, count):
    _, _, model = cases.model(name)
    inside = interior_points(name, 10, seed=4)
    out = _outside_points(name, count, seed=count)
    pts = np.concatenate([inside[:4], out, inside[4:]])
    with pytest.raises(cnem.GeometryError) as info:
        model.shape_functions(pts)
    msg = str(info.value)
    assert re.search(rf"(?<![\d.]){count}(?![\d.])", msg), f"message does not say {count}: {msg!r}"
    # the first offender is named, by its index (4) or its coordinates
    first = out[0]
    assert re.search(r"(?<![\d.])4(?![\d.])", msg) or f"{first[0]:.6g}"[:6] in msg, \
        f"message does not name the first point outside (index 4, {first.tolist()}): {msg!r}"


def test_points_far_outside_and_in_a_hole_raise():
    _, _, model = cases.model("plate_hole_irregular")
    dom = model.domain
    lo, hi = np.asarray(dom.bounds[:2]), np.asarray(dom.bounds[2:])
    pts = np.array([(lo + hi) / 2 + 1e-3, hi + 10.0, lo - [0.0, 1e-3]])
    assert not dom.contains(pts).any()
    with pytest.raises(cnem.GeometryError, match=r"(?<![\d.])3(?![\d.])"):
        model.shape_functions(pts)


def test_triangle_hint_chooses_the_crack_face():
    """A point exactly on a crack face takes the face of the triangle it is given."""
    dom = cnem.geometry.rectangle(cracks=[[[0.0, 0.5], [0.5, 0.5]]])
    model = cnem.discretize(cnem.nodes.regular(dom, 0.1), progress=False)
    x = np.array([[0.25, 0.5]])
    centroid = model.nodes[model.triangles].mean(axis=1)
    near = np.linalg.norm(centroid - x[0], axis=1) < 0.06
    checked = 0
    for side in (1, -1):
        for t in np.flatnonzero(near & (np.sign(centroid[:, 1] - 0.5) == side)):
            if np.abs(model.nodes[model.triangles[t], 1] - 0.5).min() > 1e-12:
                continue                 # t does not touch the crack line
            try:
                phi = model.shape_functions(x, triangles=[t])
            except cnem.GeometryError:
                continue                 # x is on the crack but not on this triangle
            assert np.isclose(phi.data.sum(), 1.0) and len(phi.indices) == 2
            for j in phi.indices:        # the weights sit on the copies of that face
                around = model.triangles[(model.triangles == j).any(axis=1)]
                assert (np.sign(model.nodes[around].mean(axis=1)[:, 1] - 0.5) == side).all()
            checked += 1
    assert checked >= 2
    with pytest.raises(cnem.GeometryError, match="given triangles"):
        model.shape_functions(x, triangles=[int(np.argmax(centroid[:, 0]))])


# ------------------------------------------------------------------------ gradients
@pytest.mark.parametrize("name", NAMES)
def test_gradients_match_central_differences(name):
    """Analytic Sibson gradients against central differences of Phi, at points
    away from circumcircles (where Phi is only C1) and constraints."""
    _, _, model = cases.model(name)
    pts = interior_points(name, 80, seed=3, margin=1e-4)
    cc, radius = _circumcircles(model)
    gap = np.abs(np.linalg.norm(pts[:, None, :] - cc[None], axis=2) - radius[None]).min(axis=1)
    pts = pts[gap > 1e-4]
    phi, dx, dy = model.shape_functions(pts, gradient=True)
    # same pattern as Phi (checked first: sparse arithmetic may sort indices in place)
    assert (dx.indices == phi.indices).all() and (dy.indptr == phi.indptr).all()
    h = 1e-6 * _scale(model)
    for d, got in (([h, 0.0], dx), ([0.0, h], dy)):
        fd = (model.shape_functions(pts + d) - model.shape_functions(pts - d)) / (2 * h)
        assert abs(fd - got).max() < 1e-5 * max(1.0, abs(got).max())
    # gradients reproduce the gradient of linear fields and sum to zero
    np.testing.assert_allclose(dx @ model.nodes, np.tile([1.0, 0.0], (len(pts), 1)), atol=1e-10)
    np.testing.assert_allclose(dy @ model.nodes, np.tile([0.0, 1.0], (len(pts), 1)), atol=1e-10)
    assert abs(dx.sum(axis=1)).max() < 1e-10 and abs(dy.sum(axis=1)).max() < 1e-10


def test_gradients_refused_at_nodes_and_on_constraints():
    _, _, model = cases.model(NAMES[0])
    with pytest.raises(cnem.GeometryError, match="not defined"):
        model.shape_functions(model.nodes[:3], gradient=True)
    with pytest.raises(NotImplementedError, match="sibson"):
        model.shape_functions(model.nodes[:1], kind="laplace", gradient=True)


@pytest.mark.parametrize("name", NAMES)
def test_point_rows_hold_the_shape_functions(name):
    """`point_rows` (the kernel's layout, rows in visit order) holds the rows of
    `shape_functions` for the same points."""
    from cnem.shape.natural import point_rows
    _, _, model = cases.model(name)
    pts = interior_points(name, 60, seed=11)
    phi = model.shape_functions(pts).toarray()
    rows = point_rows(model, pts)
    assert rows.nodes == len(model.nodes) and sorted(rows.order) == list(range(len(pts)))
    got = np.zeros_like(phi)
    for s, p in enumerate(rows.order):
        got[p, rows.cols[rows.start[s]:rows.end[s]]] = rows.vals[rows.start[s]:rows.end[s]]
    np.testing.assert_array_equal(got, phi)


def test_point_rows_and_unordered_rows_of_no_points_and_bad_kinds():
    """No points: empty rows (and the unordered matrix comes with its empty order);
    an unknown kind is refused like `shape_functions` does."""
    from cnem.shape.natural import point_rows
    _, _, model = cases.model("square_irregular")
    rows = point_rows(model, np.zeros((0, 2)))
    assert len(rows.order) == len(rows.start) == len(rows.end) == 0
    assert rows.nodes == len(model.nodes)
    phi, order = model.shape_functions(np.zeros((0, 2)), in_order=False)
    assert phi.shape == (0, len(model.nodes)) and len(order) == 0
    with pytest.raises(ValueError, match="kind must be one of"):
        point_rows(model, np.array([[0.5, 0.5]]), kind="linear")
    with pytest.raises(cnem.GeometryError, match=r"\(p, 2\)"):
        point_rows(model, np.array([0.5, 0.5]))


@pytest.mark.parametrize("name", ["kinked_crack_irregular", "graded_inclined_crack",
                                  "plate_hole_irregular"])
def test_points_the_walks_miss_are_found_by_either_tree(name, monkeypatch):
    """Unsorted points across cracks and holes, where walks stop: located with the
    circumcircles' R-tree or with one of the triangles, the same shape functions."""
    from cnem import config
    _, _, model = cases.model(name)
    pts = interior_points(name, 400, seed=5)
    results, built = [], []
    asked, triangle_tree = [], type(model).triangle_tree
    monkeypatch.setattr(type(model), "triangle_tree",
                        lambda self: asked.append(1) or triangle_tree(self))
    for fraction in (np.inf, 0.0):
        monkeypatch.setattr(config, "TRIANGLE_TREE_AFTER", fraction)
        asked.clear()
        results.append(model.shape_functions(pts).toarray())
        built.append(bool(asked))
    np.testing.assert_array_equal(*results)
    assert built == [False, True]            # some walks did stop, and each tree served
