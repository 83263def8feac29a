"""Numba kernels of the packed R-tree (arrays and scalars only).

Boxes and tree nodes are stored in centre / half-width form (Niina). Under
periodic boundaries every centre lies in ``[0, L)`` and every difference of
centres is reduced to its minimum image, so boxes that straddle the cell
boundary are handled without images or copied queries (Periortree,
Algorithms 1-5). ``period[k] = inf`` means "not periodic along k".
"""

import numba
import numpy as np

from .. import _compile  # noqa: F401  (says once when the kernels compile)
from .._parallel import parallel_kernel

#: Query kinds.
INTERSECT, BALL_CLOSED, BALL_OPEN = 0, 1, 2


@numba.njit(cache=True, inline="always")
def _wrap(d, period):
    """Minimum image of a coordinate difference (RestrictVector).

    Every coordinate lies in ``[0, L)``, so ``|d| < L`` and one shift at most
    is needed; with ``L = inf`` both comparisons fail and ``d`` is returned.
    """
    if d > 0.5 * period:
        return d - period
    if d < -0.5 * period:
        return d + period
    return d


@numba.njit(cache=True, inline="always")
def _wrap_any(d, period):
    """Minimum image of any coordinate difference (several periods allowed)."""
    if np.isfinite(period):
        return d - period * np.floor(d / period + 0.5)
    return d


@parallel_kernel("perm")
def sort_within(keys, perm, size):
    """Sort ``perm`` by ``keys[perm]`` inside consecutive runs of ``size`` items."""
    n = perm.shape[0]
    runs = (n + size - 1) // size
    for s in numba.prange(runs):
        a = s * size
        b = min(n, a + size)
        idx = perm[a:b].copy()
        order = np.argsort(keys[idx], kind="mergesort")
        for k in range(b - a):
            perm[a + k] = idx[order[k]]


@parallel_kernel("count")
def build_level(cen, half, first, cnt, start, count, fanout, out_start, period):
    """Parent boxes of ``count`` consecutive entries starting at ``start``.

    Writes ``ceil(count / fanout)`` parents at ``out_start`` with their child
    ranges (Algorithm 1 under periodic boundaries: expand by the minimum image
    of each child centre).
    """
    d = cen.shape[1]
    parents = (count + fanout - 1) // fanout
    for p in numba.prange(parents):
        a = start + p * fanout
        b = start + min(count, (p + 1) * fanout)
        first[out_start + p] = a
        cnt[out_start + p] = b - a
        lo = np.empty(d)
        hi = np.empty(d)
        for k in range(d):
            lo[k] = cen[a, k] - half[a, k]
            hi[k] = cen[a, k] + half[a, k]
        for c in range(a + 1, b):
            for k in range(d):
                ref = 0.5 * (lo[k] + hi[k])
                cc = ref + _wrap_any(cen[c, k] - ref, period[k])
                lo[k] = min(lo[k], cc - half[c, k])
                hi[k] = max(hi[k], cc + half[c, k])
        for k in range(d):
            c = 0.5 * (lo[k] + hi[k])
            h = 0.5 * (hi[k] - lo[k])
            # round outwards, in the arithmetic of the tests (|p - c| - h <= 0 for
            # every p in [lo, hi]; rounding is monotone so the ends suffice): the
            # smallest such h >= the half width is the larger rounded end distance
            # (one step, whatever the distance from the origin)
            h = max(h, hi[k] - c, c - lo[k])
            if np.isfinite(period[k]):
                h += 4.0 * np.finfo(np.float64).eps * period[k]   # wrapping rounds too
                if h >= 0.5 * period[k]:
                    h = 0.5 * period[k]
                c = c - period[k] * np.floor(c / period[k])
                if c >= period[k]:
                    c = 0.0
            cen[out_start + p, k] = c
            half[out_start + p, k] = h


@numba.njit(cache=True, inline="always")
def _box_test(cen, half, e, qc, qh, i, r2, kind, period):
    """Whether entry ``e`` passes query ``i`` (Algorithms 3 and 5, or a ball)."""
    d = cen.shape[1]
    if kind == INTERSECT:
        for k in range(d):
            # slack of a few ulps: the query's centre and half-width are rounded
            reach = qh[i, k] + half[e, k]
            slack = 4e-16 * (reach + abs(qc[i, k]) + abs(cen[e, k]))
            if abs(_wrap(qc[i, k] - cen[e, k], period[k])) > reach + slack:
                return False
        return True
    s = 0.0
    for k in range(d):
        g = abs(_wrap(qc[i, k] - cen[e, k], period[k])) - half[e, k]
        if g > 0.0:
            s += g * g
    if kind == BALL_OPEN:
        return s < r2
    return s <= r2


@numba.njit(cache=True, inline="always")
def _leaf_test(blo, bhi, e, qlo, qhi, i, period):
    """Exact box-box intersection in corner form (no centre/half rounding).

    Under periodic boundaries the box is also tried shifted by -L and +L
    along each axis (centres lie in ``[0, L)`` and boxes are at most ``L``
    wide, so these images suffice).
    """
    for k in range(blo.shape[1]):
        if np.isfinite(period[k]):
            ok = False
            for m in range(-1, 2):
                v = m * period[k]
                if qlo[i, k] <= bhi[e, k] + v and blo[e, k] + v <= qhi[i, k]:
                    ok = True
            if not ok:
                return False
        elif qlo[i, k] > bhi[e, k] or blo[e, k] > qhi[i, k]:
            return False
    return True


@numba.njit(cache=True)
def _traverse(cen, half, first, cnt, nbox, qc, qh, i, r2, kind, period, out, write_at,
              exclude_zero, stack, blo, bhi, qlo, qhi):
    """Depth-first search for query ``i``; count hits, writing them if ``write_at >= 0``.

    Arrays are passed whole with an index (no row views): views inside
    parallel loops cost atomic reference counting. Box-box intersections of
    leaves are tested exactly in corner form (``blo, bhi`` against ``qlo,
    qhi``); ball tests against points are exact in centre form.
    """
    corners = kind == INTERSECT
    root = cen.shape[0] - 1
    node_kind = BALL_CLOSED if kind != INTERSECT else INTERSECT
    hits = 0
    if nbox == 1:
        stack[0] = 0
    elif not _box_test(cen, half, root, qc, qh, i, r2, node_kind, period):
        return 0
    else:
        stack[0] = root
    top = 1
    while top > 0:
        top -= 1
        e = stack[top]
        if e < nbox:
            if corners:
                hit = _leaf_test(blo, bhi, e, qlo, qhi, i, period)
            else:
                hit = _box_test(cen, half, e, qc, qh, i, r2, kind, period)
            if hit:
                if exclude_zero:
                    s = 0.0
                    for q in range(cen.shape[1]):
                        g = _wrap(qc[i, q] - cen[e, q], period[q])
                        s += g * g
                    if s == 0.0:
                        continue
                if write_at >= 0:
                    out[write_at + hits] = e
                hits += 1
            continue
        for c in range(first[e], first[e] + cnt[e]):
            if c < nbox or _box_test(cen, half, c, qc, qh, i, r2, node_kind, period):
                stack[top] = c
                top += 1
    return hits


@parallel_kernel("qcen")
def query(cen, half, first, cnt, nbox, depth, fanout, order, qcen, qhalf, radius, kind,
          period, exclude_zero, nch, blo, bhi, qlo, qhi):
    """Bulk query: CSR ``(offsets, indices)`` of the boxes hit by each query.

    ``radius`` is ``(q,)`` (ignored for ``INTERSECT``); ``order`` maps sorted
    positions back to the caller's box indices; ``nch`` work chunks share the
    queries between threads.
    """
    q = qcen.shape[0]
    counts = np.zeros(q, dtype=np.int64)
    dummy = np.empty(0, dtype=np.int64)
    nch = max(1, min(nch, q))
    for ch in numba.prange(nch):
        stack = np.empty((depth + 2) * fanout + 1, dtype=np.int64)
        for i in range(ch * q // nch, (ch + 1) * q // nch):
            r2 = radius[i] * radius[i]
            counts[i] = _traverse(cen, half, first, cnt, nbox, qcen, qhalf, i, r2, kind,  # an int64
                                  period, dummy, np.int64(-1), exclude_zero, stack,  # -1: one
                                  blo, bhi, qlo, qhi)             # compiled _traverse, not two
    offsets = np.zeros(q + 1, dtype=np.int64)
    for i in range(q):
        offsets[i + 1] = offsets[i] + counts[i]
    local = np.empty(offsets[q], dtype=np.int64)
    for ch in numba.prange(nch):
        stack = np.empty((depth + 2) * fanout + 1, dtype=np.int64)
        for i in range(ch * q // nch, (ch + 1) * q // nch):
            r2 = radius[i] * radius[i]
            _traverse(cen, half, first, cnt, nbox, qcen, qhalf, i, r2, kind, period,
                      local, offsets[i], exclude_zero, stack, blo, bhi, qlo, qhi)
    indices = np.empty(offsets[q], dtype=np.int64)
    for k in numba.prange(offsets[q]):
        indices[k] = order[local[k]]
    return offsets, indices


@numba.njit(cache=True)
def _box_dist2(cen, half, e, pts, i, period):
    s = 0.0
    for k in range(cen.shape[1]):
        g = abs(_wrap(pts[i, k] - cen[e, k], period[k])) - half[e, k]
        if g > 0.0:
            s += g * g
    return s


@numba.njit(cache=True)
def _nearest_one(cen, half, first, cnt, nbox, order, points, i, period, root, stack, stack_d):
    """Nearest box to point ``i``: ``(index, squared distance)``."""
    stack[0] = root
    stack_d[0] = _box_dist2(cen, half, root, points, i, period)
    top = 1
    bd = np.inf
    bi = -1
    while top > 0:
        top -= 1
        if stack_d[top] > bd:
            continue
        e = stack[top]
        if e < nbox:
            if stack_d[top] < bd or order[e] < bi:
                bd = stack_d[top]
                bi = order[e]
            continue
        for c in range(first[e], first[e] + cnt[e]):
            d2 = _box_dist2(cen, half, c, points, i, period)
            if d2 <= bd:
                stack[top] = c
                stack_d[top] = d2
                top += 1
    return bi, bd


@parallel_kernel("points")
def nearest(cen, half, first, cnt, nbox, depth, fanout, order, points, period, nch):
    """Index of the nearest box to each point and its distance (branch and bound)."""
    q = points.shape[0]
    best_idx = np.full(q, -1, dtype=np.int64)
    best_d = np.full(q, np.inf)
    root = cen.shape[0] - 1 if nbox > 1 else 0
    nch = max(1, min(nch, q))
    for ch in numba.prange(nch):
        stack = np.empty((depth + 2) * fanout + 1, dtype=np.int64)
        stack_d = np.empty((depth + 2) * fanout + 1)
        for i in range(ch * q // nch, (ch + 1) * q // nch):
            bi, bd = _nearest_one(cen, half, first, cnt, nbox, order, points, i, period, root,
                                  stack, stack_d)
            best_idx[i] = bi
            best_d[i] = np.sqrt(bd)
    return best_idx, best_d


@numba.njit(cache=True, inline="always")
def _grid_cell(x, origin, inv, g):
    """The coarse grid column of coordinate ``x`` (monotone in ``x``, clamped to
    ``[0, g)``): a point inside a box lies in a column between its corners'."""
    v = (x - origin) * inv
    if not v > 0.0:              # also NaN
        return 0
    if v >= g - 1:
        return g - 1
    return int(v)


@parallel_kernel("points")
def grid_cover(points, lo, hi, origin, inv, g):
    """Whether each point lies in a cell of a ``g x g`` grid that a box meets.

    Parameters
    ----------
    points : (n, 2) float64
    lo, hi : (b, 2) float64
        The closed boxes.
    origin, inv : (2,) float64
        Grid cell ``(i, j)`` holds ``floor((x - origin) * inv)`` = ``(i, j)`` (clamped).
    g : int

    Returns
    -------
    (n,) bool
        True at least for every point inside a box (the boxes are marked in a 2-D
        difference array, one prefix sum per axis: ``O(b + g^2 + n)``).
    """
    count = np.zeros((g + 1, g + 1), dtype=np.int64)
    for b in range(lo.shape[0]):
        i0 = _grid_cell(lo[b, 0], origin[0], inv[0], g)
        i1 = _grid_cell(hi[b, 0], origin[0], inv[0], g)
        j0 = _grid_cell(lo[b, 1], origin[1], inv[1], g)
        j1 = _grid_cell(hi[b, 1], origin[1], inv[1], g)
        count[i0, j0] += 1
        count[i1 + 1, j0] -= 1
        count[i0, j1 + 1] -= 1
        count[i1 + 1, j1 + 1] += 1
    for i in range(1, g + 1):
        for j in range(g + 1):
            count[i, j] += count[i - 1, j]
    for i in range(g + 1):
        for j in range(1, g + 1):
            count[i, j] += count[i, j - 1]
    n = points.shape[0]
    mask = np.empty(n, dtype=np.bool_)
    for p in numba.prange(n):
        mask[p] = count[_grid_cell(points[p, 0], origin[0], inv[0], g),
                        _grid_cell(points[p, 1], origin[1], inv[1], g)] > 0
    return mask
