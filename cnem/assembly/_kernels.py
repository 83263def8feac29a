"""Numba kernels of the SCNI boundary quadrature (arrays and scalars only)."""

import numba
import numpy as np

from .. import _compile  # noqa: F401  (says once when the kernels compile)
from .._parallel import parallel_kernel


@parallel_kernel("a")
def circle_crossings(a, b, centre, radius2, cand_off, cand_idx, group, out_off, out_t, fill):
    """Parameters ``t`` in (0, 1) where segments ``a + t (b - a)`` cross circles.

    Two passes: with ``fill=False`` writes the count of crossings of segment
    ``k`` to ``out_off[k + 1]``; with ``fill=True`` writes them to
    ``out_t[out_off[k]:out_off[k + 1]]`` (unsorted). Candidates of segment ``k``
    are the circles ``cand_idx[cand_off[g]:cand_off[g + 1]]`` of its group
    ``g = group[k]``. Crossings closer than 1e-12 (relative) to an end are left
    out: they would make empty pieces.
    """
    for k in numba.prange(len(a)):
        dx = b[k, 0] - a[k, 0]
        dy = b[k, 1] - a[k, 1]
        length2 = dx * dx + dy * dy
        count = 0
        g = group[k]
        for p in range(cand_off[g], cand_off[g + 1]):
            c = cand_idx[p]
            fx = a[k, 0] - centre[c, 0]
            fy = a[k, 1] - centre[c, 1]
            half_b = fx * dx + fy * dy
            disc = half_b * half_b - length2 * (fx * fx + fy * fy - radius2[c])
            if disc <= 0.0:
                continue
            root = np.sqrt(disc)
            for t in ((-half_b - root) / length2, (-half_b + root) / length2):
                if 1e-12 < t < 1.0 - 1e-12:
                    if fill:
                        out_t[out_off[k] + count] = t
                    count += 1
        if not fill:
            out_off[k + 1] = count


@parallel_kernel("offsets")
def edge_pieces(offsets, t):
    """Pieces of every edge between its crossings, in order along the edge.

    Edge ``k`` is crossed at ``t[offsets[k]:offsets[k + 1]]`` (any order; sorted
    in place); its pieces are ``[0, t_1], [t_1, t_2], ..., [t_c, 1]``.

    Returns
    -------
    edge : (offsets[-1] + e,) int64, sorted
    t0, t1 : (offsets[-1] + e,) float64
        Piece ``i`` is ``t0[i] <= t <= t1[i]`` along edge ``edge[i]``.
    """
    ne = offsets.shape[0] - 1
    total = offsets[ne] + ne
    edge = np.empty(total, dtype=np.int64)
    t0 = np.empty(total)
    t1 = np.empty(total)
    for k in numba.prange(ne):
        lo, hi = offsets[k], offsets[k + 1]
        for i in range(lo + 1, hi):          # insertion sort: a few crossings per edge
            v = t[i]
            j = i - 1
            while j >= lo and t[j] > v:
                t[j + 1] = t[j]
                j -= 1
            t[j + 1] = v
        p = lo + k
        prev = 0.0
        for i in range(lo, hi):
            edge[p], t0[p], t1[p] = k, prev, t[i]
            prev = t[i]
            p += 1
        edge[p], t0[p], t1[p] = k, prev, 1.0
    return edge, t0, t1


@numba.njit(cache=True)
def unique_rows(bits):
    """Distinct rows of a ``(e, w)`` uint64 array (rows equal bit for bit), by hashing.

    Returns
    -------
    first : (u,) int64
        The first row of each distinct row, in order of first appearance.
    occurrence : (e,) int64
        ``bits[i]`` equals ``bits[first[occurrence[i]]]``.
    """
    e, w = bits.shape
    size = 1
    while size < 2 * e + 2:
        size *= 2
    table = np.full(size, -1, dtype=np.int64)       # index into first
    first = np.empty(e, dtype=np.int64)
    occurrence = np.empty(e, dtype=np.int64)
    u = 0
    for i in range(e):
        h = np.uint64(14695981039346656037)
        for c in range(w):
            h = (h ^ bits[i, c]) * np.uint64(1099511628211)
            h ^= h >> np.uint64(29)
        slot = np.int64(h & np.uint64(size - 1))
        while True:
            f = table[slot]
            if f < 0:
                table[slot] = u
                first[u] = i
                occurrence[i] = u
                u += 1
                break
            r = first[f]
            same = True
            for c in range(w):
                if bits[r, c] != bits[i, c]:
                    same = False
                    break
            if same:
                occurrence[i] = f
                break
            slot = (slot + 1) & (size - 1)
    return first[:u].copy(), occurrence


@numba.njit(cache=True)
def piece_points(a, b, edge, t0, t1, S, W, single):
    """Quadrature points on edge pieces, with their weights times the edge normal.

    Piece ``i`` (``t0[i] <= t <= t1[i]`` along edge ``edge[i]``, from ``a`` to
    ``b``) gets the points ``S[i]`` and weights ``W[i]`` of a rule on [0, 1]
    (``S[0]``, ``W[0]`` for every piece when they have one row), or its midpoint
    alone where ``single[edge[i]]``.

    Returns
    -------
    points : (q, 2) float64
    wx, wy : (q,) float64
        Weight times ``(dy, -dx)`` of the edge's direction ``d = b - a`` (its
        outward normal times length, for a cell on the left).
    indptr : (e + 1,) int64
        The points of edge ``k`` are ``indptr[k]:indptr[k + 1]`` (pieces come
        edge by edge).
    """
    npiece, g = edge.shape[0], S.shape[1]
    ne = a.shape[0]
    indptr = np.zeros(ne + 1, dtype=np.int64)
    for i in range(npiece):
        indptr[edge[i] + 1] += 1 if single[edge[i]] else g
    for k in range(ne):
        indptr[k + 1] += indptr[k]
    q = indptr[ne]
    points = np.empty((q, 2))
    wx = np.empty(q)
    wy = np.empty(q)
    p = 0
    for i in range(npiece):
        e = edge[i]
        r = i if S.shape[0] > 1 else 0
        dx, dy = b[e, 0] - a[e, 0], b[e, 1] - a[e, 1]
        span = t1[i] - t0[i]
        for j in range(1 if single[e] else g):
            s, w = (0.5, 1.0) if single[e] else (S[r, j], W[r, j])
            t = t0[i] + span * s
            points[p, 0] = a[e, 0] + t * dx
            points[p, 1] = a[e, 1] + t * dy
            wx[p] = span * w * dy
            wy[p] = -span * w * dx
            p += 1
    return points, wx, wy, indptr


@parallel_kernel("a")
def canonical_rows(a, b, hint):
    """Every edge from its lexicographically smaller end, as one row of numbers.

    Returns
    -------
    rows : (e, 5) float64
        ``[x0, y0, x1, y1, hint]``: equal rows (bit for bit, as uint64) are the
        same edge seen from the same side.
    sign : (e,) float64
        -1 where the edge was turned round, else 1.
    """
    e = a.shape[0]
    rows = np.empty((e, 5))
    sign = np.empty(e)
    for i in numba.prange(e):
        flip = a[i, 0] > b[i, 0] or (a[i, 0] == b[i, 0] and a[i, 1] > b[i, 1])
        p, q = (b, a) if flip else (a, b)
        rows[i, 0], rows[i, 1] = p[i, 0], p[i, 1]
        rows[i, 2], rows[i, 3] = q[i, 0], q[i, 1]
        rows[i, 4] = float(hint[i])
        sign[i] = -1.0 if flip else 1.0
    return rows, sign
