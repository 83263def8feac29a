"""Family search with one horizon for all points: its numba kernels and their driver.

With a common horizon the relation is symmetric, so every pair is tested once.
Points are binned into columns along the first two axes and sorted by the
third inside each column. The points of a column are visited in that order;
for every neighbouring column that follows it in the sorted order (and for
the column itself, points after the visited one), a window of heights
``(z - reach, z + reach)`` slides up the neighbour as ``z`` grows, with
``reach`` set by the gap between the extents of the two columns' points (on
a lattice, whose columns are lines, the window holds the members only: half
the candidates of a gap between the columns' cells). Each candidate in the
window is tested once; a member ``q`` of ``s`` goes to the row of ``s`` and
``s`` to the row of ``q``.

On a periodic third axis the neighbour column is seen as three copies
(shifted by ``-L``, ``0``, ``+L``) laid end to end, so the window still
slides monotonically; when the horizon reaches half the period, whole
columns are tested with wrapped distances instead.

Rows written by different work chunks are kept apart: each chunk counts, and
later writes, the entries it adds to each row in a window of rows of its own
(``lo[c] <= row < hi[c]``: partners follow a point in the sorted order by at
most the columns its horizon reaches), and a row takes the chunks'
contributions one after the other.

Membership uses the same arithmetic as the other methods (squared
minimum-image distance ``0 < s < h ** 2``; ``x_q - x_s`` is exactly the
negative of ``x_s - x_q``, also after a periodic shift), so the sets are
identical to theirs.
"""

import numba
import numpy as np

from .. import _compile  # noqa: F401  (says once when the kernels compile)
from ._family_kernels import _dist2, _shifted_dist2, bin_points


@numba.njit(cache=True, parallel=True)
def _sort_columns(pts, perm, start):
    """Sort every column of ``perm`` by the third coordinate, in place (stable; a
    column already in order, as a structured grid's often is, is left as it is),
    and gather the sorted points and the extents of each column.

    Returns
    -------
    spts : (n, 3) float64, ``pts[perm]``
    box : (ncol, 4) float64, extents ``xmin, xmax, ymin, ymax`` of the points of
        each column (``inf, -inf`` for an empty column)
    """
    ncol = start.shape[0] - 1
    spts = np.empty_like(pts)
    box = np.empty((ncol, 4))
    for c in numba.prange(ncol):
        a, b = start[c], start[c + 1]
        ordered = True
        for s in range(a + 1, b):
            if pts[perm[s], 2] < pts[perm[s - 1], 2]:
                ordered = False
                break
        if not ordered:
            seg = perm[a:b]
            seg[:] = seg[np.argsort(pts[seg, 2], kind="mergesort")]
        x0, x1, y0, y1 = np.inf, -np.inf, np.inf, -np.inf
        for s in range(a, b):
            i = perm[s]
            x, y = pts[i, 0], pts[i, 1]
            spts[s, 0], spts[s, 1], spts[s, 2] = x, y, pts[i, 2]
            x0, x1, y0, y1 = min(x0, x), max(x1, x), min(y0, y), max(y1, y)
        box[c, 0], box[c, 1], box[c, 2], box[c, 3] = x0, x1, y0, y1
    return spts, box


@numba.njit(cache=True)
def _axis_columns(c, r, nc, size, period, tol, col, shift, gap):
    """Columns within ``r`` of column ``c`` along one axis.

    Writes each column, the periodic shift of its points (0, +L, -L; NaN when
    ``r`` spans the period: distances are then wrapped one by one) and the gap
    between the two columns along the axis, less ``tol``. Returns their number.
    """
    if np.isfinite(period) and 2 * r + 1 >= nc:
        for k in range(nc):
            col[k], shift[k], gap[k] = k, np.nan, 0.0
        return nc
    m = 0
    for o in range(-r, r + 1):
        k = c + o
        s = 0.0
        if np.isfinite(period):
            if k < 0:
                s = -period
            elif k >= nc:
                s = period
            k %= nc
        elif k < 0 or k >= nc:
            continue
        col[m], shift[m], gap[m] = k, s, max((abs(o) - 1) * size - tol, 0.0)
        m += 1
    return m


@numba.njit(cache=True, inline="always")
def _box_gap(lo_c, hi_c, lo_k, hi_k, shift, tol):
    """Gap along one axis between the extents ``[lo_c, hi_c]`` of a column and
    ``[lo_k, hi_k]`` of another shifted by ``shift`` (0 when NaN: the period is
    spanned), less ``tol``, at least 0."""
    if np.isnan(shift):
        return 0.0
    return max(lo_k + shift - hi_c - tol, lo_c - (hi_k + shift) - tol, 0.0)


@numba.njit(cache=True, inline="always")
def _box_far(lo_c, hi_c, lo_k, hi_k, shift, tol):
    """Largest distance along one axis between a point of ``[lo_c, hi_c]`` and one
    of ``[lo_k, hi_k]`` shifted by ``shift``, plus ``tol``."""
    return max(hi_k + shift - lo_c, hi_c - (lo_k + shift)) + tol


@numba.njit(cache=True)
def _neighbours(c, start, box, nc, size, period, h2, tol, cols, sx, sy, reach, sure):
    """Columns that may hold partners of column ``c`` and follow it in sorted order.

    Fills ``cols``, their shifts ``sx``, ``sy``, height ``reach`` and ``sure``;
    the own column comes first. The reach is set by the gap between the
    extents of the two columns' points (``box``), so that on a lattice, whose
    columns are lines, only the members' heights are scanned. Within the
    height ``sure`` (-1: none) of a point every candidate is a member whatever
    its place in the column's extent: the largest distance across the two
    extents and the coordinates' rounding (``tol``) leave the squared distance
    below ``h2`` by a relative 1e-9, and the columns' gap keeps it above 0.
    Returns their number.
    """
    h = np.sqrt(h2)
    r0 = int(np.ceil(h / size[0]))
    r1 = int(np.ceil(h / size[1]))
    w = max(nc[0], nc[1], 2 * max(r0, r1) + 1)
    ca, sa, ga = np.empty(w, np.int64), np.empty(w), np.empty(w)
    cb, sb, gb = np.empty(w, np.int64), np.empty(w), np.empty(w)
    na = _axis_columns(c // nc[1], r0, nc[0], size[0], period[0], tol, ca, sa, ga)
    nb = _axis_columns(c % nc[1], r1, nc[1], size[1], period[1], tol, cb, sb, gb)
    cols[0], sx[0], sy[0], reach[0], sure[0] = c, 0.0, 0.0, np.sqrt(h2), -1.0
    m = 1
    for a in range(na):
        for b in range(nb):
            k = ca[a] * nc[1] + cb[b]
            if k == c:
                sx[0], sy[0] = sa[a], sb[b]     # NaN when the period is spanned
            elif k > c and ga[a] * ga[a] + gb[b] * gb[b] < h2 and start[k + 1] > start[k]:
                g0 = _box_gap(box[c, 0], box[c, 1], box[k, 0], box[k, 1], sa[a], tol)
                g1 = _box_gap(box[c, 2], box[c, 3], box[k, 2], box[k, 3], sb[b], tol)
                g = g0 * g0 + g1 * g1
                if g < h2:
                    cols[m], sx[m], sy[m], reach[m] = k, sa[a], sb[b], np.sqrt(h2 - g)
                    sure[m] = -1.0
                    if g > 0.0 and not (np.isnan(sa[a]) or np.isnan(sb[b])):
                        f0 = _box_far(box[c, 0], box[c, 1], box[k, 0], box[k, 1], sa[a], tol)
                        f1 = _box_far(box[c, 2], box[c, 3], box[k, 2], box[k, 3], sb[b], tol)
                        r2 = h2 * (1.0 - 1e-9) - (f0 * f0 + f1 * f1)
                        if r2 > 0.0:
                            sure[m] = np.sqrt(r2) - 2.0 * tol
                    m += 1
    return m


@numba.njit(cache=True, inline="always")
def _height(spts, base, m, v, period):
    """Height of point ``v`` of the three copies of a column (``m`` points each)
    shifted by ``-period``, 0 and ``+period``."""
    if v < m:
        return spts[np.uint64(base + v), 2] - period
    if v < 2 * m:
        return spts[np.uint64(base + v - m), 2]
    return spts[np.uint64(base + v - 2 * m), 2] + period


@numba.njit(cache=True, inline="always")
def _at(spts, base, m, v, period, periodic):
    """Height of point ``v`` of a column of ``m`` points (of its three shifted
    copies on a periodic third axis, see `_height`)."""
    return _height(spts, base, m, v, period) if periodic else spts[np.uint64(base + v), 2]


@numba.njit(cache=True)
def _column_pass(col, spts, h2, tol, start, box, perm, nc, size, period, wrap_z, write, rows, lo,
                 dif, out, cols, sx, sy, reach, sure):
    """Count (``write`` False) or write the pairs of the points of column ``col``.

    Counting adds 1 to ``rows[x - lo]`` for both points of every pair (for a
    run of sure members ``a <= x < b`` of a point: 1 to ``dif[a - lo]``, -1 to
    ``dif[b - lo]``, summed later); writing uses ``rows`` as cursors into
    ``out``. ``tol`` bounds the rounding of coordinates (gaps are shrunk and
    windows widened by it).

    The neighbour columns are the outer loop and the points of ``col`` the
    inner one: a window slides up one neighbour column at a time, so its
    length repeats (on a lattice it is the same for every point) and the rows
    written stay few. Each neighbour column appears once, so every row
    receives its entries in the same order as with the points outermost.
    """
    m = _neighbours(col, start, box, nc, size, period, h2, tol, cols, sx, sy, reach, sure)
    periodic_z = np.isfinite(period[2]) and not wrap_z
    first, stop = start[col], start[col + 1]
    pz = period[2]
    for k in range(m):
        base = start[cols[k]]
        size_k = start[cols[k] + 1] - base
        exact = wrap_z or np.isnan(sx[k]) or np.isnan(sy[k])
        sa, sb, rz = sx[k], sy[k], sure[k]
        if wrap_z:
            for s in range(first, stop):
                # in the own column (k = 0) only the points after s: each pair
                # is found from its first point
                qa = s + 1 if k == 0 else base
                rows[s - lo] = _run(qa, base + size_k, 0.0, True, s, spts, h2, sa, sb, period,
                                    write, rows, lo, out, perm, rows[s - lo])
            continue
        offset, end = (size_k, 3 * size_k) if periodic_z else (0, size_k)
        va, vb, ua, ub = 0, 0, 0, 0
        for s in range(first, stop):
            x0, x1, x2 = spts[s, 0], spts[s, 1], spts[s, 2]
            zlo, zhi = x2 - reach[k] - tol, x2 + reach[k] + tol
            after = s + 1 if k == 0 else base
            # the window slides over the column (periodic: over its three copies
            # shifted by -L, 0, +L laid end to end; offset: where the unshifted starts)
            while va < end and _at(spts, base, size_k, va, pz, periodic_z) <= zlo:
                va += 1
            vb = max(vb, va)
            while vb < end and _at(spts, base, size_k, vb, pz, periodic_z) < zhi:
                vb += 1
            mine = rows[s - lo]
            if va < offset or vb > offset + size_k:
                for copy in range(3):      # the window wraps around the period
                    qa = base + max(va - copy * size_k, 0)
                    qb = base + min(vb - copy * size_k, size_k)
                    mine = _run(max(qa, after), qb, (copy - 1) * pz, exact, s, spts,
                                h2, sa, sb, period, write, rows, lo, out, perm, mine)
                rows[s - lo] = mine
                continue
            qa, qb = max(base + va - offset, after), base + vb - offset
            if exact:
                rows[s - lo] = _run(qa, qb, 0.0, True, s, spts, h2, sa, sb, period, write, rows,
                                    lo, out, perm, mine)
                continue
            qu, qv = qb, qb                # the sure members [qu, qv), not tested
            if rz > 0.0:
                while ua < end and _at(spts, base, size_k, ua, pz, periodic_z) <= x2 - rz:
                    ua += 1
                ub = max(ub, ua)
                while ub < end and _at(spts, base, size_k, ub, pz, periodic_z) < x2 + rz:
                    ub += 1
                qu = min(max(base + ua - offset, qa), qb)
                qv = min(max(base + ub - offset, qu), qb)
            own = perm[s]
            # the straight runs written out here: through _run (inlined by
            # numba) this loop measured 1.4x slower
            for q in range(qa, qu):
                d2 = _shifted_dist2(spts, q, x0, x1, x2, sa, sb, 0.0)
                mine = _record(d2, h2, write, rows, lo, out, q, own, perm, mine)
            if write:
                for q in range(qu, qv):
                    mine = _member(rows, lo, out, q, own, perm, mine)
            elif qv > qu:
                mine += qv - qu
                dif[qu - lo] += 1
                dif[qv - lo] -= 1
            for q in range(qv, qb):
                d2 = _shifted_dist2(spts, q, x0, x1, x2, sa, sb, 0.0)
                mine = _record(d2, h2, write, rows, lo, out, q, own, perm, mine)
            rows[s - lo] = mine


@numba.njit(cache=True, inline="always")
def _run(qa, qb, sz, exact, s, spts, h2, sx, sy, period, write, rows, lo, out, perm, mine):
    """Test the candidates ``qa <= q < qb`` of point ``s``, shifted by
    ``(sx, sy, sz)`` (or wrapped one by one when ``exact``). Returns the new ``mine``."""
    own = perm[s]
    x0, x1, x2 = spts[s, 0], spts[s, 1], spts[s, 2]
    for q in range(qa, qb):
        if exact:
            d2 = _dist2(spts, s, spts, q, period)
        else:
            d2 = _shifted_dist2(spts, q, x0, x1, x2, sx, sy, sz)
        mine = _record(d2, h2, write, rows, lo, out, q, own, perm, mine)
    return mine


@numba.njit(cache=True, inline="always")
def _record(d2, h2, write, rows, lo, out, q, own, perm, mine):
    """Candidate ``q`` at squared distance ``d2`` from the point ``own``: when a
    member, count it in the row of ``q`` and in ``mine`` (the count, or the
    write cursor, of the row of ``own``), or write both entries.
    Returns the new ``mine``."""
    if not write:                    # branch-free: about half the candidates are members
        hit = (d2 < h2) & (d2 > 0.0)
        rows[np.uint64(q - lo)] += hit
        return mine + hit
    if d2 < h2 and d2 > 0.0:
        return _member(rows, lo, out, q, own, perm, mine)
    return mine


@numba.njit(cache=True, inline="always")
def _member(rows, lo, out, q, own, perm, mine):
    """Write the pair of member ``q`` and the point ``own``: ``own`` at the cursor of
    the row of ``q``, ``q`` at ``mine``. Returns the new ``mine``."""
    x = np.uint64(q - lo)           # unsigned: no index is negative, no wrap-around code
    i = rows[x]
    out[np.uint64(i)] = own
    rows[x] = i + 1
    out[np.uint64(mine)] = perm[np.uint64(q)]
    return mine + 1


@numba.njit(cache=True, parallel=True)
def _scan_all(spts, h2, tol, start, box, perm, nc, size, period, wrap_z, chunk_cols, lo, woff,
              write, rows, dif, out):
    """One counting (``write`` False) or filling pass, a chunk of columns per thread.

    ``dif`` holds ``woff[c + 1] - woff[c] + 1`` run ends per chunk ``c`` (from
    ``woff[c] + c``), added to ``rows`` at the end of a counting pass."""
    nch = lo.shape[0]
    h = np.sqrt(h2)
    most = (2 * int(np.ceil(h / size[0])) + 1) * (2 * int(np.ceil(h / size[1])) + 1)
    most = min(most, nc[0] * nc[1]) + 1
    for c in numba.prange(nch):
        cols = np.empty(most, dtype=np.int64)
        sx, sy, reach, sure = np.empty(most), np.empty(most), np.empty(most), np.empty(most)
        window = rows[woff[c]:woff[c + 1]]
        runs = dif[woff[c] + c:woff[c + 1] + c + 1]
        for col in range(chunk_cols[c], chunk_cols[c + 1]):
            _column_pass(col, spts, h2, tol, start, box, perm, nc, size, period, wrap_z, write,
                         window, lo[c], runs, out, cols, sx, sy, reach, sure)
        if not write:
            t = 0
            for x in range(window.shape[0]):
                t += runs[x]
                window[x] += t


@numba.njit(cache=True)
def _chunks(start, nc, size, h, period, nch):
    """Columns of each chunk (balanced by points) and the rows it may write.

    Returns
    -------
    chunk_cols : (nch + 1,) int64, chunk ``c`` visits columns
        ``chunk_cols[c] <= col < chunk_cols[c + 1]``
    lo, hi : (nch,) int64, it writes rows ``lo[c] <= row < hi[c]`` (sorted order)
    """
    ncol = start.shape[0] - 1
    n = start[ncol]
    chunk_cols = np.empty(nch + 1, dtype=np.int64)
    chunk_cols[0] = 0
    chunk_cols[nch] = ncol
    col = 0
    for c in range(1, nch):
        while col < ncol and start[col] < c * n // nch:
            col += 1
        chunk_cols[c] = col
    ahead = (int(np.ceil(h / size[0])) * nc[1] + int(np.ceil(h / size[1]))) + 1
    periodic = np.isfinite(period[0]) or np.isfinite(period[1])
    lo = np.empty(nch, dtype=np.int64)
    hi = np.empty(nch, dtype=np.int64)
    for c in range(nch):
        lo[c] = start[chunk_cols[c]]
        hi[c] = n if periodic else start[min(chunk_cols[c + 1] - 1 + ahead, ncol)]
        hi[c] = max(hi[c], start[chunk_cols[c + 1]])
    return chunk_cols, lo, hi


def uniform_family(pts, h, origin, size, nc, period, index_dtype_sample, nch):
    """Family of every point for one horizon ``h``, each pair tested once.

    A counting pass, the row offsets, then a filling pass. The output is
    allocated here by NumPy, not inside a kernel, so that it gets NumPy's huge
    pages like every other large array: on a 1M-point lattice (0.5 GB of
    families, 2 threads) the filling pass took 0.24-0.29 s instead of
    0.52-0.63 s with memory the process had used before (0.21-0.23 s since the
    hot loops index with unsigned integers). Memory the machine has
    not handed out for a while costs more to touch on some virtual machines
    (freed memory returned to the host), in huge pages more than in small ones:
    a first call in a fresh process there took 0.96-1.23 s, against 0.51-0.64 s
    with small pages.

    Parameters
    ----------
    pts : (n, 3) float64
        Points (2-D points padded with a zero coordinate; the third axis is the
        one swept, so it should be a real one).
    h : float
    origin, size : (3,) float64
        Origin and widths of the columns.
    nc : (3,) int64
        Columns along the first two axes; ``nc[2]`` must be 1.
    period : (3,) float64
        ``inf`` on open axes.
    index_dtype_sample : (0,) array
        Its dtype (int32 or int64) is the dtype of the returned indices.
    nch : int
        Work chunks (about one per thread: each holds a window of row counters).

    Returns
    -------
    offsets : (n + 1,) int64
    indices : (offsets[-1],) index_dtype_sample.dtype
    """
    perm, start = bin_points(pts, origin, size, nc, period)     # nc[2] = 1: columns
    spts, box = _sort_columns(pts, perm, start)
    tol = _tolerance(pts, h)
    wrap_z = bool(np.isfinite(period[2]) and 2.0 * h * (1.0 + 1e-9) >= period[2])
    nch = max(1, min(nch, int(nc[0] * nc[1])))
    chunk_cols, lo, hi = _chunks(start, nc, size, h, period, nch)
    woff = np.zeros(nch + 1, dtype=np.int64)
    np.cumsum(hi - lo, out=woff[1:])
    rows = np.zeros(woff[nch], dtype=np.int64)
    dif = np.zeros(woff[nch] + nch, dtype=np.int64)
    scan = (spts, h * h, tol, start, box, perm, nc, size, period, wrap_z, chunk_cols, lo, woff)
    _scan_all(*scan, False, rows, dif, np.empty(0, dtype=index_dtype_sample.dtype))
    offsets = _cursors(rows, woff, lo, hi, perm)
    out = np.empty(offsets[-1], dtype=index_dtype_sample.dtype)
    _scan_all(*scan, True, rows, dif, out)
    return offsets, out


@numba.njit(cache=True)
def _tolerance(pts, h):
    """Bound on the rounding of coordinates and of their differences: relative to
    the horizon and to the largest ``|x|`` (found without an (n, 3) temporary)."""
    return 1e-9 * h + 1e-12 * (max(-pts.min(), pts.max()) + h)


@numba.njit(cache=True)
def _chunk_range(x, lo, hi):
    """Chunks whose row windows hold sorted row ``x``: ``first <= c < stop``."""
    stop = np.searchsorted(lo, x, side="right")
    first = stop - 1
    while first > 0 and hi[first - 1] > x:
        first -= 1
    return first, stop


@numba.njit(cache=True, parallel=True)
def _cursors(rows, woff, lo, hi, perm):
    """Row offsets; the per-chunk row counts turned into write cursors, in place."""
    n = perm.shape[0]
    counts = np.empty(n, dtype=np.int64)
    for x in numba.prange(n):
        first, stop = _chunk_range(x, lo, hi)
        t = 0
        for c in range(first, stop):
            t += rows[woff[c] + x - lo[c]]
        counts[perm[x]] = t
    offsets = np.empty(n + 1, dtype=np.int64)
    offsets[0] = 0
    for i in range(n):
        offsets[i + 1] = offsets[i] + counts[i]
    for x in numba.prange(n):
        first, stop = _chunk_range(x, lo, hi)
        t = offsets[perm[x]]
        for c in range(first, stop):
            k = woff[c] + x - lo[c]
            v = rows[k]
            rows[k] = t
            t += v
    return offsets
