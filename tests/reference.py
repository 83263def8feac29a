"""Slow, obviously-correct reference implementations used by the tests."""

from __future__ import annotations

import numpy as np
import shapely


def _orient(a, b, c):
    return (b[..., 0] - a[..., 0]) * (c[..., 1] - a[..., 1]) - (b[..., 1] - a[..., 1]) * (c[..., 0] - a[..., 0])


def blocked(x, y, seg_a, seg_b, eps=1e-12):
    """Whether segment x-y touches any segment (seg_a, seg_b) anywhere but at ``y``.

    Parameters
    ----------
    x, y : (2,) ndarray
    seg_a, seg_b : (s, 2) ndarray

    Returns
    -------
    bool
    """
    at_y = (np.linalg.norm(seg_a - y, axis=1) <= eps) | (np.linalg.norm(seg_b - y, axis=1) <= eps)
    a, b = seg_a[~at_y], seg_b[~at_y]
    if len(a) == 0:
        return False
    d1 = _orient(a, b, x[None])
    d2 = _orient(a, b, y[None])
    d3 = _orient(x[None], y[None], a)
    d4 = _orient(x[None], y[None], b)
    proper = (d1 * d2 < 0) & (d3 * d4 < 0)
    return bool(proper.any())


def _enters_triangle_of(model, j, x):
    """Whether the segment from node ``j`` towards ``x`` starts inside a triangle of ``j``.

    This is the side rule at crack faces and at reflex corners: a node on a
    crack face sees only its own side.
    """
    p = model.nodes[j]
    y = p + 1e-7 * (x - p)
    tris = model.triangles[(model.triangles == j).any(axis=1)]
    a, b, c = (model.nodes[tris[:, k]] for k in range(3))
    tol = -1e-18
    inside = (_orient(a, b, y[None]) >= tol) & (_orient(b, c, y[None]) >= tol) & (_orient(c, a, y[None]) >= tol)
    return bool(inside.any())


def nearest_visible_nodes(model, x, region, rel_tie=1e-9):
    """All nodes of ``region`` visible from ``x`` at the smallest distance.

    Brute force over every node; visibility tested against every constraint
    segment of the model (boundaries, interfaces, both crack faces).

    Returns
    -------
    list of int
        Node indices tied at the smallest distance (within ``rel_tie``).
    """
    members = np.unique(model.triangles[model.triangle_region == region])
    dist = np.linalg.norm(model.nodes[members] - x, axis=1)
    seg_a = model.nodes[model.segments[:, 0]]
    seg_b = model.nodes[model.segments[:, 1]]
    best, found = np.inf, []
    for k in np.argsort(dist):
        if dist[k] > best * (1 + rel_tie):
            break
        j = members[k]
        if blocked(x, model.nodes[j], seg_a, seg_b):
            continue
        if dist[k] > 0 and not _enters_triangle_of(model, j, x):
            continue
        best = min(best, dist[k])
        found.append(int(j))
    return found


def cell_owner(model, x, region):
    """Owner nodes of the cells of ``region`` whose closed polygon contains ``x``."""
    cells = model.cells
    owners = []
    for c in np.flatnonzero(cells.region == region):
        poly = shapely.Polygon(cells.polygon(c))
        if poly.distance(shapely.Point(x)) <= 1e-12:
            owners.append(int(cells.node[c]))
    return owners


def visible(model, j, x):
    """Whether node ``j`` is visible from point ``x`` (C-NEM eq. 13).

    The segment ``x``-node crosses no constraint segment of the model
    (boundaries, interfaces, both crack faces) and, unless ``x`` is the node
    itself, leaves the node into one of its own triangles (a node on a crack
    face sees only its own side).
    """
    x = np.asarray(x, dtype=float)
    p = model.nodes[j]
    seg_a = model.nodes[model.segments[:, 0]]
    seg_b = model.nodes[model.segments[:, 1]]
    if blocked(x, p, seg_a, seg_b):
        return False
    return bool(np.linalg.norm(x - p) == 0 or _enters_triangle_of(model, j, x))


def cell_polygons(model):
    """The cells of ``model`` as shapely polygons, ``(m,)`` object array."""
    cells = model.cells
    return np.array([shapely.Polygon(cells.polygon(c)) for c in range(len(cells))], dtype=object)


def orient2d(a, b, c):
    """Twice the signed area of triangles ``(a, b, c)``, positive counter-clockwise."""
    return _orient(np.asarray(a, float), np.asarray(b, float), np.asarray(c, float))


# ---------------------------------------------------------------- cnem.spatial
# Brute-force references for the spatial index (tests/test_spatial_*.py). Every
# pair is tested; periodic cells are handled by trying all 3**d images
# explicitly (no minimum-image formula), so they check Niina's wrapped
# centre differences independently. Squared distances are summed axis by axis
# in order (dx*dx + dy*dy [+ dz*dz]) and compared with ``r * r``, so points
# exactly at distance ``r`` (integer lattices) are decided as in exact arithmetic.


def image_shifts(period, dim):
    """Translations of the periodic images: ``(3**d, d)``, or one zero shift if open.

    All 3**d images suffice when centres lie in ``[0, L]`` and half-widths are at most ``L / 2``.
    """
    if period is None:
        return np.zeros((1, dim))
    per = np.broadcast_to(np.asarray(period, dtype=float), (dim,))
    combos = np.stack(np.meshgrid(*[[-1.0, 0.0, 1.0]] * dim, indexing="ij"), axis=-1)
    return combos.reshape(-1, dim) * per


def _rows_to_csr(rows):
    offsets = np.zeros(len(rows) + 1, dtype=np.int64)
    offsets[1:] = np.cumsum([len(r) for r in rows])
    indices = np.concatenate(rows).astype(np.int64) if rows else np.zeros(0, dtype=np.int64)
    return offsets, indices


def _chunks(n, size=256):
    for a in range(0, n, size):
        yield slice(a, min(n, a + size))


def _min_over_images(axis_terms, shifts, shape):
    """Minimum over the image shifts of the axis-ordered sum of per-axis squared terms.

    ``axis_terms(k, v)`` is the squared term along axis ``k`` for the image shifted by ``v``.
    """
    out = np.full(shape, np.inf)
    dim = shifts.shape[1]
    sq = {(k, v): axis_terms(k, v) for k in range(dim) for v in np.unique(shifts[:, k])}
    for s in shifts:                 # every one of the 3**d images
        acc = sq[0, s[0]].copy()
        for k in range(1, dim):
            acc += sq[k, s[k]]
        np.minimum(out, acc, out=out)
    return out


def box_dist2(points, lo, hi, period=None):
    """Squared distance ``(q, b)`` from each point to each closed box (0 inside),
    minimised over all periodic images of the box."""
    points, lo, hi = (np.asarray(a, dtype=float) for a in (points, lo, hi))
    shifts = image_shifts(period, points.shape[1])
    out = np.empty((len(points), len(lo)))
    for rows in _chunks(len(points)):
        x = points[rows, None, :]

        def term(k, v):
            below = (lo[None, :, k] + v) - x[..., k]
            above = x[..., k] - (hi[None, :, k] + v)
            g = np.maximum(np.maximum(below, above), 0.0)
            return g * g

        out[rows] = _min_over_images(term, shifts, (len(x), len(lo)))
    return out


def point_dist2(points, others, period=None):
    """Squared distance ``(q, n)`` between points, minimised over all 3**d images
    (``((x_j - x_i) + shift) ** 2`` summed axis by axis)."""
    points, others = np.asarray(points, dtype=float), np.asarray(others, dtype=float)
    shifts = image_shifts(period, points.shape[1])
    out = np.empty((len(points), len(others)))
    for rows in _chunks(len(points)):
        diff = others[None, :, :] - points[rows, None, :]

        def term(k, v):
            t = diff[..., k] + v
            return t * t

        out[rows] = _min_over_images(term, shifts, diff.shape[:2])
    return out


def brute_ball(points, lo, hi, r, period=None, strict=False, exclude_self=False):
    """CSR ``(offsets, indices)``: boxes within distance ``r`` (scalar or per point)
    of each point (``<= r``, or ``< r`` if ``strict``); ``exclude_self`` leaves out
    boxes whose centre is the point."""
    points, lo, hi = (np.asarray(a, dtype=float) for a in (points, lo, hi))
    zero_size = np.array_equal(lo, hi)
    d2 = point_dist2(points, lo, period) if zero_size else box_dist2(points, lo, hi, period)
    r = np.broadcast_to(np.asarray(r, dtype=float), (len(points),))
    r2 = (r * r)[:, None]
    hit = d2 < r2 if strict else d2 <= r2
    if exclude_self:
        hit &= (d2 if zero_size else point_dist2(points, 0.5 * (lo + hi), period)) > 0.0
    return _rows_to_csr([np.flatnonzero(row) for row in hit])


def brute_family(points, horizon, period=None):
    """CSR families: every ``j`` with ``0 < |x_j - x_i| < horizon_i`` (minimum over images)."""
    points = np.asarray(points, dtype=float)
    h = np.broadcast_to(np.asarray(horizon, dtype=float), (len(points),))
    rows = []
    for sl in _chunks(len(points)):
        d2 = point_dist2(points[sl], points, period)
        hh = (h[sl] * h[sl])[:, None]
        rows.extend(np.flatnonzero(row) for row in (d2 > 0.0) & (d2 < hh))
    return _rows_to_csr(rows)


def brute_box_query(qlo, qhi, lo, hi, period=None):
    """CSR: boxes ``[lo, hi]`` intersecting each closed query box ``[qlo, qhi]``
    (any of the 3**d images of the box)."""
    qlo, qhi, lo, hi = (np.asarray(a, dtype=float) for a in (qlo, qhi, lo, hi))
    hit = np.zeros((len(qlo), len(lo)), dtype=bool)
    for s in image_shifts(period, lo.shape[1] if lo.ndim == 2 else qlo.shape[1]):
        ok = np.ones_like(hit)
        for k in range(qlo.shape[1]):
            ok &= (qlo[:, None, k] <= hi[None, :, k] + s[k]) & (lo[None, :, k] + s[k] <= qhi[:, None, k])
        hit |= ok
    return _rows_to_csr([np.flatnonzero(row) for row in hit])


def brute_nearest(points, lo, hi, period=None):
    """Nearest box to each point: ``(index, distance)``, smallest index among ties."""
    d2 = box_dist2(points, lo, hi, period) if not np.array_equal(lo, hi) \
        else point_dist2(points, lo, period)
    idx = np.argmin(d2, axis=1)
    return idx, np.sqrt(d2[np.arange(len(idx)), idx])


def csr_row_differences(offsets, indices, ref_offsets, ref_indices, limit=5):
    """Rows whose sets differ: ``[(row, missing, extra), ...]`` (at most ``limit``), plus
    rows with repeated entries. Empty list when every row holds exactly the reference set."""
    offsets, ref_offsets = np.asarray(offsets), np.asarray(ref_offsets)
    if len(offsets) != len(ref_offsets):
        return [("row count", len(offsets) - 1, len(ref_offsets) - 1)]
    n = len(offsets) - 1
    if len(indices) == len(ref_indices):         # fast path: same sorted (row, column) keys
        rows = np.repeat(np.arange(n, dtype=np.int64), np.diff(offsets))
        ref_rows = np.repeat(np.arange(n, dtype=np.int64), np.diff(ref_offsets))
        keys = np.sort(rows * (n + 1) + np.asarray(indices, dtype=np.int64))
        ref_keys = np.sort(ref_rows * (n + 1) + np.asarray(ref_indices, dtype=np.int64))
        if np.array_equal(keys, ref_keys):
            return []
    out = []
    for i in range(len(offsets) - 1):
        got = np.asarray(indices[offsets[i]:offsets[i + 1]]).tolist()
        ref = np.asarray(ref_indices[ref_offsets[i]:ref_offsets[i + 1]]).tolist()
        if sorted(got) != sorted(ref):
            missing, extra = sorted(set(ref) - set(got)), sorted(set(got) - set(ref))
            out.append((i, missing, extra if missing or extra else "repeats"))
            if len(out) >= limit:
                break
    return out


def crossing_keep(points, offsets, indices, segments):
    """Mask of bonds ``(i, indices[k])`` whose segment does not properly cross any of
    the ``(s, 2, 2)`` segments: both pairs of orientations strictly of opposite
    signs. Touching (an end on a segment, a segment end on the bond, collinear) keeps."""
    pts = np.asarray(points, dtype=float)
    seg = np.asarray(segments, dtype=float).reshape(-1, 2, 2)
    offsets, indices = np.asarray(offsets), np.asarray(indices, dtype=np.int64)
    rows = np.repeat(np.arange(len(offsets) - 1), np.diff(offsets))
    p, q = pts[rows], pts[indices]
    keep = np.ones(len(indices), dtype=bool)
    for a, b in seg:
        A, B = np.broadcast_to(a, p.shape), np.broadcast_to(b, p.shape)
        s1, s2 = np.sign(_orient(A, B, p)), np.sign(_orient(A, B, q))
        s3, s4 = np.sign(_orient(p, q, A)), np.sign(_orient(p, q, B))
        keep &= ~((s1 * s2 < 0) & (s3 * s4 < 0))
    return keep


#: Kinds of clouds `spatial_cloud` draws.
SPATIAL_KINDS = ("uniform", "clustered", "graded", "lattice")


def spatial_cloud(kind, dim, n, *, periodic=False, seed=0):
    """A test cloud for the spatial references.

    ``"uniform"``; ``"clustered"`` (80 % of the points in four tight Gaussian
    blobs, one centred on the origin so that it straddles the periodic cell,
    plus a sparse background); ``"graded"`` (local spacing growing 30x along
    x); ``"lattice"`` (the integer lattice: many exact ties at integer distances).

    Returns
    -------
    points : (m, dim) ndarray
        m = n except for the lattice (m ~ n). Inside ``[0, extent)`` when periodic.
    extent : (dim,) ndarray
        The box of the cloud (the periodic cell).
    spacing : (m,) ndarray
        Local mean spacing (1 on the lattice).
    """
    rng = np.random.default_rng([seed, dim, SPATIAL_KINDS.index(kind), int(periodic)])
    if kind == "lattice":
        m = max(3, int(round(n ** (1.0 / dim))))
        ext = np.array([m, m + 2, m - 1][:dim], dtype=float)
        axes = [np.arange(e) for e in ext]
        pts = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, dim)
        return np.ascontiguousarray(pts), ext, np.ones(len(pts))
    ext = np.array([1.0, 0.75, 0.5][:dim])
    vol = float(np.prod(ext))
    if kind == "uniform":
        pts = rng.random((n, dim)) * ext
        spacing = np.full(n, (vol / n) ** (1.0 / dim))
    elif kind == "clustered":
        nb = int(0.8 * n)
        centres = rng.random((4, dim)) * ext
        centres[0] = 0.0
        sigma = 0.01 * ext.min()
        blobs = centres[rng.integers(0, 4, nb)] + rng.normal(0.0, sigma, (nb, dim))
        pts = np.vstack([blobs, rng.random((n - nb, dim)) * ext])
        spacing = np.full(n, (vol / n) ** (1.0 / dim))
    elif kind == "graded":
        ratio = 30.0
        chunks, have = [], 0
        while have < n:      # density ~ spacing**-d with spacing ~ ratio**(x / ext_x)
            cand = rng.random((4 * n, dim)) * ext
            keep = rng.random(len(cand)) < ratio ** (-dim * cand[:, 0] / ext[0])
            chunks.append(cand[keep])
            have += int(keep.sum())
        pts = np.vstack(chunks)[:n]
        frac = (1.0 - ratio ** -dim) / (dim * np.log(ratio))
        spacing = (vol * frac / n) ** (1.0 / dim) * ratio ** (pts[:, 0] / ext[0])
    else:
        raise ValueError(f"unknown kind {kind!r}")
    if periodic:
        pts = np.mod(pts, ext)
        pts = np.where(pts >= ext, 0.0, pts)      # np.mod(-tiny, L) == L
    return np.ascontiguousarray(pts), ext, spacing


#: Cases of the spatial tests: (cloud kind, dimension, periodic).
SPATIAL_CASES = [(kind, dim, periodic) for kind in SPATIAL_KINDS for dim in (2, 3)
                 for periodic in (False, True)]


def spatial_case_id(case):
    """Readable pytest id of a spatial case."""
    kind, dim, periodic = case
    return f"{kind}-{dim}d-{'periodic' if periodic else 'open'}"
