"""Numba kernels of family search: cell list, brute force, bond-crossing filter.

Every method decides membership with the same arithmetic: the squared
(minimum-image) distance ``s = sum(d_k ** 2)`` must satisfy ``0 < s < h_i ** 2``,
so that all methods return identical sets even at ties.
"""

import numba
import numpy as np

from .. import _compile  # noqa: F401  (says once when the kernels compile)
from .._predicates import orient2d as _orient

from ._rtree_kernels import _wrap


@numba.njit(cache=True, inline="always")
def _dist2(a, i, b, j, period):
    """Squared minimum-image distance between ``a[i]`` and ``b[j]`` (no row views:
    views inside parallel loops cost atomic reference counting)."""
    s = 0.0
    for k in range(a.shape[1]):
        d = _wrap(b[j, k] - a[i, k], period[k])
        s += d * d
    return s


@numba.njit(cache=True, inline="always")
def _shifted_dist2(pts, q, x0, x1, x2, s0, s1, s2):
    """Squared distance from ``(x0, x1, x2)`` to ``pts[q]`` shifted by ``(s0, s1, s2)``.

    ``(x_q - x_i) + shift`` is exactly the minimum-image difference that
    ``_wrap`` computes when the shift is the right periodic image, so all
    methods agree to the last bit.
    """
    r = np.uint64(q)                # no index is negative: no wrap-around code
    d = (pts[r, 0] - x0) + s0
    d2 = d * d
    d = (pts[r, 1] - x1) + s1
    d2 += d * d
    d = (pts[r, 2] - x2) + s2
    return d2 + d * d


@numba.njit(cache=True)
def _cell_axis(x, origin, size, nc):
    """Cell of a coordinate (clamped: periodic coordinates already lie in [0, L))."""
    c = int(np.floor((x - origin) / size))
    return min(max(c, 0), nc - 1)


@numba.njit(cache=True)
def bin_points(pts, origin, size, nc, period):
    """Counting sort of points into a 3-D grid of cells.

    Returns
    -------
    perm : (n,) int64, points sorted by cell
    start : (ncells + 1,) int64, CSR of the cells over ``perm``
    """
    n = pts.shape[0]
    ncell = nc[0] * nc[1] * nc[2]
    cell = np.empty(n, dtype=np.int64)
    count = np.zeros(ncell + 1, dtype=np.int64)
    for i in range(n):
        c0 = _cell_axis(pts[i, 0], origin[0], size[0], nc[0])
        c1 = _cell_axis(pts[i, 1], origin[1], size[1], nc[1])
        c2 = _cell_axis(pts[i, 2], origin[2], size[2], nc[2])
        cell[i] = (c0 * nc[1] + c1) * nc[2] + c2
        count[cell[i] + 1] += 1
    for c in range(ncell):
        count[c + 1] += count[c]
    fill = count[:-1].copy()
    perm = np.empty(n, dtype=np.int64)
    for i in range(n):
        perm[fill[cell[i]]] = i
        fill[cell[i]] += 1
    return perm, count


@numba.njit(cache=True, inline="always")
def _axis_cells(x, origin, size, nc, reach, period, out, row, shift):
    """Cells along one axis that may hold points within ``reach`` of ``x``.

    Writes the cells to ``out[row]`` and, to ``shift[row]``, the periodic
    shift (0, +L or -L) that brings each cell's points to their minimum image
    as seen from ``x``; NaN when the reach spans the whole period (then no
    single shift is right and distances are wrapped one by one).
    """
    periodic = np.isfinite(period)
    c = _cell_axis(x, origin, size, nc)
    r = int(np.ceil(reach / size))
    m = 0
    if periodic and 2 * r + 1 >= nc:
        for k in range(nc):
            out[row, m] = k
            shift[row, m] = np.nan
            m += 1
        return m
    for o in range(-r, r + 1):
        k = c + o
        s = 0.0
        if periodic:
            if k < 0:
                s = -period
            elif k >= nc:
                s = period
            k = k % nc
        elif k < 0 or k >= nc:
            continue
        out[row, m] = k
        shift[row, m] = s
        m += 1
    return m


@numba.njit(cache=True, inline="always")
def _gap(x, k, origin, size, period):
    """Distance from coordinate ``x`` to the slab of cell ``k`` along one axis,
    rounded down by a hair (a cell is never skipped because of rounding)."""
    if np.isfinite(period):
        centre = origin + (k + 0.5) * size
        g = abs(_wrap(x - centre, period)) - 0.5 * size
    else:
        lo = origin + k * size
        g = max(lo - x, x - lo - size)
    return max(g - 1e-12 * size, 0.0)


@numba.njit(cache=True)
def _scan(s0, spts, hs2, start, perm, origin, size, nc, period, dest, pos, cap, buf,
          shift):
    """Family of sorted point ``s0``: its size, members written to ``dest[pos:cap]``.

    Every candidate is written at the next free slot while room is left and
    the slot is kept only if the candidate is a member (a branch-free test:
    about half of the candidates are members, so a branch would be
    mispredicted). With ``cap <= pos`` nothing is written (counting only);
    a return value larger than ``cap - pos`` means the members did not fit.
    """
    h2 = hs2[s0]
    h = np.sqrt(h2)
    x0, x1, x2 = spts[s0, 0], spts[s0, 1], spts[s0, 2]
    n0 = _axis_cells(x0, origin[0], size[0], nc[0], h, period[0], buf, 0, shift)
    n1 = _axis_cells(x1, origin[1], size[1], nc[1], h, period[1], buf, 1, shift)
    n2 = _axis_cells(x2, origin[2], size[2], nc[2], h, period[2], buf, 2, shift)
    room = cap - pos
    hits = 0
    for a in range(n0):
        g0 = _gap(x0, buf[0, a], origin[0], size[0], period[0])
        g0 *= g0
        if g0 >= h2:
            continue
        for b in range(n1):
            g1 = _gap(x1, buf[1, b], origin[1], size[1], period[1])
            g1 = g0 + g1 * g1
            if g1 >= h2:
                continue
            base = (buf[0, a] * nc[1] + buf[1, b]) * nc[2]
            for c in range(n2):
                g2 = _gap(x2, buf[2, c], origin[2], size[2], period[2])
                if g1 + g2 * g2 >= h2:
                    continue
                cell = base + buf[2, c]
                s0_, s1_, s2_ = shift[0, a], shift[1, b], shift[2, c]
                if np.isnan(s0_) or np.isnan(s1_) or np.isnan(s2_):
                    for q in range(start[cell], start[cell + 1]):
                        d2 = _dist2(spts, s0, spts, q, period)
                        if hits < room:
                            dest[pos + hits] = perm[q]
                        hits += (d2 < h2) & (d2 > 0.0)
                else:
                    for q in range(start[cell], start[cell + 1]):
                        d2 = _shifted_dist2(spts, q, x0, x1, x2, s0_, s1_, s2_)
                        if hits < room:
                            dest[pos + hits] = perm[q]
                        hits += (d2 < h2) & (d2 > 0.0)
                if 0 < room <= hits:
                    return hits          # the row is full: no member is left
    return hits


@numba.njit(cache=True, parallel=True)
def cell_family(pts, horizon, origin, size, nc, period, index_dtype_sample, nch):
    """Family of every point with a cell list: a counting pass, then a filling pass.

    Parameters
    ----------
    pts : (n, 3) float64
        Points (2-D points padded with a zero third coordinate).
    horizon : (n,) float64
    origin, size : (3,) float64
        Grid origin and cell sizes.
    nc : (3,) int64
        Cells per axis.
    period : (3,) float64
        ``inf`` on open axes.
    index_dtype_sample : (0,) array
        Its dtype (int32 or int64) is the dtype of the returned indices.
    nch : int
        Work chunks shared between threads.
    """
    n = pts.shape[0]
    perm, start = bin_points(pts, origin, size, nc, period)
    spts = np.empty_like(pts)
    hs2 = np.empty(n)
    for s in numba.prange(n):
        for k in range(3):
            spts[s, k] = pts[perm[s], k]
        hs2[s] = horizon[perm[s]] * horizon[perm[s]]
    width = 1
    for k in range(3):
        width = max(width, nc[k])
    nch = max(1, min(n, nch))
    dummy = np.empty(0, dtype=index_dtype_sample.dtype)
    counts = np.zeros(n, dtype=np.int64)
    for ch in numba.prange(nch):
        buf = np.empty((3, width + 1), dtype=np.int64)
        shift = np.empty((3, width + 1))
        for s in range(ch * n // nch, (ch + 1) * n // nch):
            counts[perm[s]] = _scan(s, spts, hs2, start, perm, origin, size, nc, period,
                                    dummy, 0, 0, buf, shift)
    offsets = np.zeros(n + 1, dtype=np.int64)
    for i in range(n):
        offsets[i + 1] = offsets[i] + counts[i]
    out = np.empty(offsets[n], dtype=index_dtype_sample.dtype)
    for ch in numba.prange(nch):
        buf = np.empty((3, width + 1), dtype=np.int64)
        shift = np.empty((3, width + 1))
        for s in range(ch * n // nch, (ch + 1) * n // nch):
            i = perm[s]
            _scan(s, spts, hs2, start, perm, origin, size, nc, period, out, offsets[i],
                  offsets[i + 1], buf, shift)
    return offsets, out


@numba.njit(cache=True, parallel=True)
def brute_family(pts, horizon, period):
    """Reference: every pair tested, O(n^2)."""
    n = pts.shape[0]
    counts = np.zeros(n, dtype=np.int64)
    for i in numba.prange(n):
        h2 = horizon[i] * horizon[i]
        c = 0
        for j in range(n):
            d2 = _dist2(pts, i, pts, j, period)
            if d2 < h2 and d2 > 0.0:
                c += 1
        counts[i] = c
    offsets = np.zeros(n + 1, dtype=np.int64)
    for i in range(n):
        offsets[i + 1] = offsets[i] + counts[i]
    out = np.empty(offsets[n], dtype=np.int64)
    for i in numba.prange(n):
        h2 = horizon[i] * horizon[i]
        w = offsets[i]
        for j in range(n):
            d2 = _dist2(pts, i, pts, j, period)
            if d2 < h2 and d2 > 0.0:
                out[w] = j
                w += 1
    return offsets, out


@numba.njit(cache=True, parallel=True)
def exact_filter(pts, rows, cols, horizon, period):
    """Mask of candidate pairs ``(rows, cols)`` that satisfy ``0 < d^2 < h_row^2``."""
    keep = np.empty(rows.shape[0], dtype=np.bool_)
    for k in numba.prange(rows.shape[0]):
        i = rows[k]
        d2 = _dist2(pts, i, pts, cols[k], period)
        keep[k] = d2 < horizon[i] * horizon[i] and d2 > 0.0
    return keep


@numba.njit(cache=True)
def _side(ax, ay, bx, by, px, py, tol):
    """`_orient` of ``p`` against the line ``a -> b``, 0 when ``p`` lies within ``tol``
    of it (the coordinates' round-off: a point put on a crack stays on it in any units)."""
    o = _orient(ax, ay, bx, by, px, py)
    return 0.0 if abs(o) <= tol * np.hypot(bx - ax, by - ay) else o


@numba.njit(cache=True, parallel=True)
def crossing_mask(pts, offsets, indices, seg, far, cand_off, cand_idx, tol):
    """Mask of bonds that cross none of their point's candidate segments.

    ``seg`` is ``(s, 4)``: ``ax, ay, bx, by``; ``far`` is ``(s, 2, 2)``: for
    each end of each segment, the far end of the other segment that shares
    that end (a polyline's inner vertex), NaN when none does. A bond crosses
    a segment when their interiors cross, or when it passes through an inner
    vertex of a polyline whose two segments leave on opposite sides of the
    bond; a bond through a crack tip or along a segment only touches it.
    Candidates of point ``i`` are ``cand_idx[cand_off[i]:cand_off[i + 1]]``. A point
    within ``tol`` of a line is on it.
    """
    n = offsets.shape[0] - 1
    keep = np.ones(indices.shape[0], dtype=np.bool_)
    for i in numba.prange(n):
        xi, yi = pts[i, 0], pts[i, 1]
        for k in range(offsets[i], offsets[i + 1]):
            j = indices[k]
            xj, yj = pts[j, 0], pts[j, 1]
            for c in range(cand_off[i], cand_off[i + 1]):
                s = cand_idx[c]
                ax, ay, bx, by = seg[s, 0], seg[s, 1], seg[s, 2], seg[s, 3]
                o1 = _side(ax, ay, bx, by, xi, yi, tol)
                o2 = _side(ax, ay, bx, by, xj, yj, tol)
                if o1 * o2 >= 0.0:
                    continue
                o3 = _side(xi, yi, xj, yj, ax, ay, tol)
                o4 = _side(xi, yi, xj, yj, bx, by, tol)
                if o3 * o4 < 0.0:
                    keep[k] = False
                    break
                # the bond passes through an end of the segment: through an
                # inner vertex of a polyline it crosses when the neighbouring
                # segment leaves on the other side of the bond
                for end in range(2):
                    o_end, o_other = (o3, o4) if end == 0 else (o4, o3)
                    fx, fy = far[s, end, 0], far[s, end, 1]
                    if o_end == 0.0 and o_other != 0.0 and not np.isnan(fx):
                        if o_other * _side(xi, yi, xj, yj, fx, fy, tol) < 0.0:
                            keep[k] = False
                if not keep[k]:
                    break
    return keep
