"""Numba kernels for the sparse products of SCNI assembly (row by row, Gustavson).

scipy's general sparse-times-sparse products are single-threaded and build
every intermediate product; these kernels compute each output row at once
with a dense accumulator per thread (two passes: count, then fill); `weighted_row_sums`,
called on small pieces of large models, with a small hash table per chunk instead.
"""

import numba
import numpy as np

from .. import _compile  # noqa: F401  (says once when the kernels compile)
from .._parallel import parallel_kernel


@numba.njit(cache=True, inline="always")
def _chunk(ch, nch, n):
    return ch * n // nch, (ch + 1) * n // nch


@numba.njit(cache=True)
def _offsets(counts):
    """CSR row pointers ``(n + 1,)`` from row counts ``(n,)``."""
    indptr = np.zeros(counts.shape[0] + 1, dtype=np.int64)
    for i in range(counts.shape[0]):     # a loop: a slice assignment compiles numba's
        indptr[i + 1] = indptr[i] + counts[i]    # shape-mismatch message (seconds)
    return indptr


@numba.njit(cache=True, inline="always")
def _add_column(j, start, end, slot, indices):
    """Append column ``j`` to the row being built at ``indices[start:end]`` unless
    it is there (``slot[j] >= start``); returns the new ``end``."""
    if slot[j] < start:
        slot[j] = start
        indices[end] = j
        end += 1
    return end


@numba.njit(cache=True, inline="always")
def _sort_slots(indices, start, end, slot):
    """Sort the row's columns and point ``slot`` at their positions."""
    indices[start:end].sort()
    for p in range(start, end):
        slot[indices[p]] = p


#: First size of the per-chunk column tables of `weighted_row_sums` (a power of two;
#: doubled for a row with more entries than a quarter of it).
_TABLE_START = 256


@numba.njit(cache=True, inline="always")
def _row_entries(ptr, item, row_of, v_start, v_end, i):
    """Entries summed into output row ``i`` of `weighted_row_sums` (duplicates counted)."""
    total = 0
    for p in range(ptr[i], ptr[i + 1]):
        r = row_of[item[p]]
        total += v_end[r] - v_start[r]
    return total


@numba.njit(cache=True)
def _table_for(table, entries):
    """``table`` (all -1), or an empty one large enough to hold ``entries`` columns at
    most a quarter full (open addressing stays short)."""
    size = table.shape[0]
    if 4 * entries <= size:
        return table
    while 4 * entries > size:
        size *= 2
    return np.full(size, -1, dtype=np.int64)


@numba.njit(cache=True, inline="always")
def _probe(table, mask, j):
    """The slot of column ``j`` in an open-addressing table (``-1``: empty; never full,
    so the probe ends)."""
    h = (j * 2654435761) & mask
    while table[h] >= 0 and table[h] != j:
        h = (h + 1) & mask
    return h


@parallel_kernel("ptr")
def weighted_row_sums(ptr, item, wx, wy, row_of, v_start, v_end, v_idx, vx, vy, nch):
    """``X[i] = sum_p wx[p] Vx[row_of[item[p]]]`` over ``p`` in ``ptr[i]:ptr[i + 1]``,
    and ``Y`` alike with ``wy``, ``Vy``: two CSR matrices with one pattern.

    The boundary integrals of SCNI in two steps: the integral of every edge
    from its points (weights times the normal, ``V`` the shape functions), then
    that of every cell from its edges (``±1 / A_k``, ``V`` the edge integrals).

    Parameters
    ----------
    ptr, item, wx, wy : CSR (m, r)
        What each output row sums and with what weights.
    row_of : (r,) int64
        The row of ``V`` holding item ``r``.
    v_start, v_end, v_idx : (rows,) int64, (rows,) int64, (k,) int32
        The pattern of ``Vx`` and ``Vy``: row ``s`` at ``v_idx[v_start[s]:v_end[s]]``
        (CSR: ``indptr[:-1]``, ``indptr[1:]`` as int64), values ``vx``, ``vy`` (the
        same array for both is fine).
    nch : int
        Work chunks shared between threads.

    Returns
    -------
    indptr : (m + 1,) int64
    indices : (nnz,) int32
        Sorted in every row.
    x, y : (nnz,) float64
    """
    m = len(ptr) - 1
    counts = np.zeros(m, dtype=np.int64)
    for ch in numba.prange(nch):
        table = np.full(_TABLE_START, -1, dtype=np.int64)
        used = np.empty(_TABLE_START, dtype=np.int64)
        lo, hi = _chunk(ch, nch, m)
        for i in range(lo, hi):
            table = _table_for(table, _row_entries(ptr, item, row_of, v_start, v_end, i))
            if used.shape[0] < table.shape[0]:
                used = np.empty(table.shape[0], dtype=np.int64)
            mask = table.shape[0] - 1
            count = 0
            for p in range(ptr[i], ptr[i + 1]):
                r = row_of[item[p]]
                for k in range(v_start[r], v_end[r]):
                    h = _probe(table, mask, v_idx[k])
                    if table[h] < 0:
                        table[h] = v_idx[k]
                        used[count] = h
                        count += 1
            counts[i] = count
            for e in range(count):                # empty the row's slots for the next
                table[used[e]] = -1
    indptr = _offsets(counts)
    indices = np.empty(indptr[m], dtype=np.int32)
    x = np.empty(indptr[m])
    y = np.empty(indptr[m])
    for ch in numba.prange(nch):
        table = np.full(_TABLE_START, -1, dtype=np.int64)
        slot = np.empty(_TABLE_START, dtype=np.int64)
        used = np.empty(_TABLE_START, dtype=np.int64)
        lo, hi = _chunk(ch, nch, m)
        for i in range(lo, hi):
            table = _table_for(table, _row_entries(ptr, item, row_of, v_start, v_end, i))
            if slot.shape[0] < table.shape[0]:
                slot = np.empty(table.shape[0], dtype=np.int64)
                used = np.empty(table.shape[0], dtype=np.int64)
            mask = table.shape[0] - 1
            start = indptr[i]
            end = start
            for p in range(ptr[i], ptr[i + 1]):
                r = row_of[item[p]]
                sx, sy = wx[p], wy[p]
                for k in range(v_start[r], v_end[r]):
                    j = v_idx[k]
                    h = _probe(table, mask, j)
                    if table[h] < 0:                # first time in this row
                        table[h] = j
                        slot[h] = end
                        used[end - start] = h
                        indices[end] = j
                        x[end] = 0.0
                        y[end] = 0.0
                        end += 1
                    at = slot[h]
                    x[at] += sx * vx[k]
                    y[at] += sy * vy[k]
            for e in range(end - start):          # empty the row's slots for the next
                table[used[e]] = -1
            _sort_row(indices, x, y, start, end)
    return indptr, indices, x, y


@numba.njit(cache=True)
def _sort_row(indices, x, y, start, end):
    """Sort one CSR row by column (insertion sort: rows are short)."""
    for i in range(start + 1, end):
        j, a, b = indices[i], x[i], y[i]
        k = i - 1
        while k >= start and indices[k] > j:
            indices[k + 1], x[k + 1], y[k + 1] = indices[k], x[k], y[k]
            k -= 1
        indices[k + 1], x[k + 1], y[k + 1] = j, a, b


@parallel_kernel("q_ptr")
def weighted_gram(q_ptr, q_idx, q_val, t_ptr, t_row, t_val, coeff, m, ncol, nch):
    """``K = Q^T W Q`` for stacked descriptor operators ``Q`` (``c m`` rows: row
    ``a m + k`` is descriptor ``a`` at cell ``k``) and per-cell couplings
    ``W[b m + k, a m + k] = coeff[k, a, b]``, row by row.

    Parameters
    ----------
    q_ptr, q_idx, q_val : CSR (c m, ncol)
    t_ptr, t_row, t_val : CSR of ``Q^T`` (ncol, c m)
    coeff : (m, c, c) float64
        ``coeff[k, a, b]``: weight of the pair (trial descriptor ``a``, test ``b``).
    m, ncol, nch : int

    Returns
    -------
    indptr : (ncol + 1,) int64
    indices : (nnz,) int32
    data : (nnz,) float64
        ``K[i, j] = sum_k sum_ab Q[b m + k, i] coeff[k, a, b] Q[a m + k, j]``.
    """
    c = coeff.shape[1]
    counts = np.zeros(ncol, dtype=np.int64)
    for ch in numba.prange(nch):
        mark = np.full(ncol, -1, dtype=np.int64)
        lo, hi = _chunk(ch, nch, ncol)
        for i in range(lo, hi):
            count = 0
            for t in range(t_ptr[i], t_ptr[i + 1]):
                b = t_row[t] // m
                k = t_row[t] % m
                for a in range(c):
                    if coeff[k, a, b] * t_val[t] == 0.0:
                        continue
                    row = a * m + k
                    for p in range(q_ptr[row], q_ptr[row + 1]):
                        j = q_idx[p]
                        if mark[j] != i:
                            mark[j] = i
                            count += 1
            counts[i] = count
    indptr = _offsets(counts)
    indices = np.empty(indptr[ncol], dtype=np.int32)
    data = np.zeros(indptr[ncol])
    for ch in numba.prange(nch):
        slot = np.full(ncol, -1, dtype=np.int64)
        lo, hi = _chunk(ch, nch, ncol)
        for i in range(lo, hi):
            start = indptr[i]
            end = start
            for t in range(t_ptr[i], t_ptr[i + 1]):         # the row's columns ...
                b = t_row[t] // m
                k = t_row[t] % m
                for a in range(c):
                    if coeff[k, a, b] * t_val[t] == 0.0:
                        continue
                    row = a * m + k
                    for p in range(q_ptr[row], q_ptr[row + 1]):
                        end = _add_column(q_idx[p], start, end, slot, indices)
            _sort_slots(indices, start, end, slot)          # ... in order
            for t in range(t_ptr[i], t_ptr[i + 1]):         # then their values
                b = t_row[t] // m
                k = t_row[t] % m
                qi = t_val[t]
                for a in range(c):
                    w = coeff[k, a, b] * qi
                    if w == 0.0:
                        continue
                    row = a * m + k
                    for p in range(q_ptr[row], q_ptr[row + 1]):
                        data[slot[q_idx[p]]] += w * q_val[p]
    return indptr, indices, data


@numba.njit(cache=True)
def _transpose_pattern(ptr, idx, ncol):
    """Columns of a CSR pattern: for column ``j``, the rows holding it and the
    positions of those entries, ``(t_ptr, t_row, t_pos)``."""
    m = ptr.shape[0] - 1
    t_ptr = np.zeros(ncol + 1, dtype=np.int64)
    for p in range(ptr[m]):
        t_ptr[idx[p] + 1] += 1
    for j in range(ncol):
        t_ptr[j + 1] += t_ptr[j]
    fill = t_ptr[:-1].copy()
    t_row = np.empty(ptr[m], dtype=np.int64)
    t_pos = np.empty(ptr[m], dtype=np.int64)
    for k in range(m):
        for p in range(ptr[k], ptr[k + 1]):
            j = idx[p]
            t_row[fill[j]] = k
            t_pos[fill[j]] = p
            fill[j] += 1
    return t_ptr, t_row, t_pos


@numba.njit(cache=True, inline="always")
def _block_counts(t_ptr, t_row, ptr, idx, ncol, nch, upper):
    """Number of node columns in every block row of ``G^T G`` (``G`` the CSR pattern
    ``ptr, idx``, its columns ``t_ptr, t_row``), ``(ncol,)`` (inlined: its loop over
    chunks runs in parallel in the parallel copy of the caller); for any ``t_ptr, t_row``
    (rows of ``G`` summed per output row), the columns of each of its rows. With
    ``upper``, the columns ``j >= i`` of row ``i`` only, its diagonal always counted."""
    rows = t_ptr.shape[0] - 1
    counts = np.zeros(rows, dtype=np.int64)
    for ch in numba.prange(nch):
        mark = np.full(ncol, -1, dtype=np.int64)
        lo, hi = _chunk(ch, nch, rows)
        for i in range(lo, hi):
            count = 0
            lowest = i if upper else 0
            if upper:
                mark[i] = i
                count = 1
            for t in range(t_ptr[i], t_ptr[i + 1]):
                k = t_row[t]
                for p in range(ptr[k], ptr[k + 1]):
                    if idx[p] >= lowest and mark[idx[p]] != i:
                        mark[idx[p]] = i
                        count += 1
            counts[i] = count
    return counts


@numba.njit(cache=True, inline="always")
def _block_row_columns(i, t_ptr, t_row, ptr, idx, start, slot, indices, upper):
    """Write the node columns of block row ``i`` (see `_block_counts`) sorted into
    ``indices[start:end]``, ``slot`` pointing at them; returns ``end``."""
    end = _add_column(i, start, start, slot, indices) if upper else start
    lowest = i if upper else 0
    for t in range(t_ptr[i], t_ptr[i + 1]):
        k = t_row[t]
        for p in range(ptr[k], ptr[k + 1]):
            if idx[p] >= lowest:
                end = _add_column(idx[p], start, end, slot, indices)
    _sort_slots(indices, start, end, slot)
    return end


@numba.njit(cache=True, inline="always")
def _dof_row_base(out_ptr, indptr, d, i, r, upper):
    """Where block column ``q`` (an index into the node blocks' pattern) of dof row
    ``d i + r`` starts, less ``d q``: the entry of trial component ``s`` is at
    ``base + d q + s`` (in the upper triangle, whose diagonal block keeps ``s >= r``
    only, too)."""
    return out_ptr[d * i + r] - d * indptr[i] - (r if upper else 0)


@parallel_kernel("ncol")
def gradient_block_pattern(ptr, idx, d, ncol, nch, upper=False):
    """The pattern of `gradient_block_gram` (``d x d`` node blocks of ``G^T G``, ``G`` the
    CSR pattern ``ptr, idx``, ``(m, ncol)``), computed once for any number of value
    passes (`gradient_block_values`, `gradient_block_values_nd`).

    Parameters
    ----------
    ptr, idx : CSR pattern (m, ncol)
    d : int
        Components per node.
    ncol, nch : int
    upper : bool
        Only the upper triangle (the diagonal and the entries right of it, every row's
        diagonal stored first): half the entries of the symmetric matrix.

    Returns
    -------
    out_ptr : (d ncol + 1,) int64
    out_idx : (nnz,) int32
        ``K``'s CSR pattern over the interleaved dofs, ``(d ncol, d ncol)``, sorted.
    indptr : (ncol + 1,) int64
    indices : (nnz / d^2,) int32
        The node blocks' CSR pattern, ``(ncol, ncol)``, sorted (with ``upper``, the
        blocks on and right of the diagonal).
    t_ptr, t_row, t_pos : int64 arrays
        ``G``'s columns: the rows holding column ``j`` and the positions of those entries.
    """
    t_ptr, t_row, t_pos = _transpose_pattern(ptr, idx, ncol)
    counts = _block_counts(t_ptr, t_row, ptr, idx, ncol, nch, upper)
    indptr = _offsets(counts)                   # of the node blocks
    cut = d * (d - 1) // 2 if upper else 0      # entries left of the diagonal per block
    out_ptr = np.empty(d * ncol + 1, dtype=np.int64)     # of the dofs: d rows per node
    out_ptr[0] = 0
    for i in range(ncol):
        for r in range(d):
            out_ptr[d * i + r + 1] = (d * d * indptr[i] - i * cut + (r + 1) * d * counts[i]
                                      - (r * (r + 1) // 2 if upper else 0))
    indices = np.empty(indptr[ncol], dtype=np.int32)
    out_idx = np.empty(out_ptr[d * ncol], dtype=np.int32)
    for ch in numba.prange(nch):
        slot = np.full(ncol, -1, dtype=np.int64)
        lo, hi = _chunk(ch, nch, ncol)
        for i in range(lo, hi):
            start = indptr[i]
            end = _block_row_columns(i, t_ptr, t_row, ptr, idx, start, slot, indices, upper)
            for r in range(d):
                row = _dof_row_base(out_ptr, indptr, d, i, r, upper)
                for q in range(start, end):
                    for c in range(r if upper and q == start else 0, d):
                        out_idx[row + d * q + c] = d * indices[q] + c
    return out_ptr, out_idx, indptr, indices, t_ptr, t_row, t_pos


@numba.njit(cache=True, inline="always")
def _point_slots(indptr, indices, i, slot):
    """Point ``slot`` at the positions of block row ``i``'s node columns."""
    for q in range(indptr[i], indptr[i + 1]):
        slot[indices[q]] = q


@parallel_kernel("ncol")
def gradient_block_values(ptr, idx, gx, gy, coeff, group, weight, t_ptr, t_row, t_pos,
                          indptr, indices, out_ptr, ncol, nch):
    """The values of `gradient_block_gram` on its pattern (`gradient_block_pattern`,
    ``d = 2``): ``(nnz,)`` float64, in the order of ``out_idx``."""
    data = np.zeros(out_ptr[2 * ncol])
    for ch in numba.prange(nch):
        slot = np.full(ncol, -1, dtype=np.int64)
        v = np.empty((2, 4))
        lo, hi = _chunk(ch, nch, ncol)
        for i in range(lo, hi):
            _point_slots(indptr, indices, i, slot)
            start = indptr[i]
            row0 = out_ptr[2 * i] - 2 * start               # block q -> row0 + 2 q
            row1 = out_ptr[2 * i + 1] - 2 * start
            for t in range(t_ptr[i], t_ptr[i + 1]):
                k = t_row[t]
                gi0, gi1 = weight[k] * gx[t_pos[t]], weight[k] * gy[t_pos[t]]
                c = group[k]
                for r in range(2):                          # test component r
                    for a in range(4):
                        v[r, a] = gi0 * coeff[c, a, 2 * r] + gi1 * coeff[c, a, 2 * r + 1]
                for p in range(ptr[k], ptr[k + 1]):
                    gj0, gj1 = gx[p], gy[p]
                    q = 2 * slot[idx[p]]
                    data[row0 + q] += v[0, 0] * gj0 + v[0, 1] * gj1
                    data[row0 + q + 1] += v[0, 2] * gj0 + v[0, 3] * gj1
                    data[row1 + q] += v[1, 0] * gj0 + v[1, 1] * gj1
                    data[row1 + q + 1] += v[1, 2] * gj0 + v[1, 3] * gj1
    return data


@parallel_kernel("ncol")
def gradient_block_values_nd(ptr, idx, grads, coeff, group, weight, t_ptr, t_row, t_pos,
                             indptr, indices, out_ptr, ncol, nch, upper=False):
    """The values of `gradient_block_gram_nd` on its pattern (`gradient_block_pattern`,
    with the same ``upper``): ``(nnz,)`` float64, in the order of ``out_idx``."""
    d = grads.shape[0]
    data = np.zeros(out_ptr[d * ncol])
    for ch in numba.prange(nch):
        slot = np.full(ncol, -1, dtype=np.int64)
        v = np.empty((d, d * d))
        gi = np.empty(d)
        row = np.empty(d, dtype=np.int64)
        lo, hi = _chunk(ch, nch, ncol)
        for i in range(lo, hi):
            _point_slots(indptr, indices, i, slot)
            for r in range(d):
                row[r] = _dof_row_base(out_ptr, indptr, d, i, r, upper)   # + d q + s
            lowest = i if upper else 0
            for t in range(t_ptr[i], t_ptr[i + 1]):
                k = t_row[t]
                c = group[k]
                for e in range(d):
                    gi[e] = weight[k] * grads[e, t_pos[t]]
                for r in range(d):                          # test component r
                    for a in range(d * d):
                        total = 0.0
                        for e in range(d):
                            total += gi[e] * coeff[c, a, d * r + e]
                        v[r, a] = total
                for p in range(ptr[k], ptr[k + 1]):
                    if idx[p] < lowest:
                        continue
                    q = d * slot[idx[p]]
                    diagonal = upper and idx[p] == i
                    for r in range(d):
                        for s in range(r if diagonal else 0, d):      # trial component s
                            total = 0.0
                            for e in range(d):
                                total += v[r, d * s + e] * grads[e, p]
                            data[row[r] + q + s] += total
    return data


def gradient_block_gram(ptr, idx, gx, gy, coeff, group, weight, ncol, nch):
    """``K`` of a vector form that sees only gradients, by 2 x 2 node blocks
    (`gradient_block_pattern`, then `gradient_block_values`).

    The gradients of the two components are the scalar operators ``gx``,
    ``gy`` (one CSR pattern ``ptr, idx``, ``(m, ncol)``) on interleaved dofs.

    Parameters
    ----------
    ptr, idx : CSR pattern (m, ncol)
    gx, gy : (nnz,) float64
        Values of the x and y derivatives.
    coeff : (G, 4, 4) float64
        ``coeff[g, a, b]`` for trial descriptor ``a = 2 c + d`` (component ``c``,
        direction ``d``) and test descriptor ``b``, in the cells of group ``g``.
    group : (m,) int64
        The group of every cell (``arange(m)``: one per cell).
    weight : (m,) float64
        Cell ``k`` couples by ``weight[k] * coeff[group[k]]`` (its area).
    ncol, nch : int

    Returns
    -------
    indptr : (2 ncol + 1,) int64
    indices : (nnz,) int32
    data : (nnz,) float64
        ``K`` in CSR over the interleaved dofs, ``(2 ncol, 2 ncol)``.
    """
    out_ptr, out_idx, *pattern = gradient_block_pattern(ptr, idx, 2, ncol, nch)
    t_ptr, t_row, t_pos = pattern[2:]
    data = gradient_block_values(ptr, idx, gx, gy, coeff, group, weight, t_ptr, t_row, t_pos,
                                 pattern[0], pattern[1], out_ptr, ncol, nch)
    return out_ptr, out_idx, data


def gradient_block_gram_nd(ptr, idx, grads, coeff, group, weight, ncol, nch):
    """`gradient_block_gram` in any dimension: ``K`` by ``d x d`` node blocks
    (`gradient_block_pattern`, then `gradient_block_values_nd`), from ``grads (d, nnz)``,
    the derivatives along each axis on the one pattern, and ``coeff (G, d d, d d)``
    (trial descriptor ``a = d c + e``: component ``c``, direction ``e``); the other
    arguments and the result as there, over ``d ncol`` dofs (in 2-D the same numbers)."""
    out_ptr, out_idx, *pattern = gradient_block_pattern(ptr, idx, grads.shape[0], ncol, nch)
    t_ptr, t_row, t_pos = pattern[2:]
    data = gradient_block_values_nd(ptr, idx, grads, coeff, group, weight, t_ptr, t_row,
                                    t_pos, pattern[0], pattern[1], out_ptr, ncol, nch)
    return out_ptr, out_idx, data


@parallel_kernel("target")
def place_rows(indptr, indices, x, y, target, out_ptr, out_idx, out_x, out_y):
    """Copy row ``r`` of a CSR (values ``x`` and ``y`` on one pattern) into row
    ``target[r]`` of another whose row pointers ``out_ptr`` are already set."""
    for r in numba.prange(target.shape[0]):
        a, b = indptr[r], out_ptr[target[r]]
        for e in range(indptr[r + 1] - a):
            out_idx[b + e] = indices[a + e]
            out_x[b + e] = x[a + e]
            out_y[b + e] = y[a + e]
