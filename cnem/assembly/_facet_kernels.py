"""Numba kernels of the 3-D smoothed gradients (`cnem.assembly.facet_gradients`,
`cnem.assembly.pyramid_cells`): the cells' boundary integrals as ``d`` matrices on one
pattern, and the twin of every directed facet edge by a hash table on exact coordinates.
"""

import numba
import numpy as np

from .. import _compile  # noqa: F401  (says once when the kernels compile)
from .._parallel import parallel_kernel
from . import _sparse_kernels as SK


@parallel_kernel("ptr")
def weighted_rows(ptr, item, weight, v_ptr, v_idx, v_val, ncol, nch):
    """``X_c[i] = sum_p weight[p, c] V[item[p]]`` over ``p`` in ``ptr[i]:ptr[i + 1]``: the
    ``d`` matrices ``X_c`` on one pattern (the union of the rows summed).

    Parameters
    ----------
    ptr, item : CSR pattern (m, q)
        The rows of ``V`` (points) each output row (cell) sums.
    weight : (nnz, d) float64
        Their weights (area-normal component over the cell's volume).
    v_ptr, v_idx, v_val : CSR (q, ncol)
        ``V``: the shape functions at the points.
    ncol, nch : int
        Columns of ``V``; work chunks shared between threads.

    Returns
    -------
    indptr : (m + 1,) int64
    indices : (nnz,) int32
        Sorted in every row.
    data : (d, nnz) float64
    """
    m, d = len(ptr) - 1, weight.shape[1]
    indptr = SK._offsets(SK._block_counts(ptr, item, v_ptr, v_idx, ncol, nch, False))
    indices = np.empty(indptr[m], dtype=np.int32)
    data = np.zeros((d, indptr[m]))
    for ch in numba.prange(nch):
        slot = np.full(ncol, -1, dtype=np.int64)
        lo, hi = SK._chunk(ch, nch, m)
        for i in range(lo, hi):                             # the row's columns, sorted ...
            SK._block_row_columns(i, ptr, item, v_ptr, v_idx, indptr[i], slot, indices, False)
            for p in range(ptr[i], ptr[i + 1]):             # ... then their values
                r = item[p]
                for k in range(v_ptr[r], v_ptr[r + 1]):
                    at = slot[v_idx[k]]
                    for c in range(d):
                        data[c, at] += weight[p, c] * v_val[k]
    return indptr, indices, data


@numba.njit(cache=True, inline="always")
def _mix(h, bits):
    """One step of a 64-bit hash: ``bits`` folded in, then splitmix64's finaliser."""
    h = (h ^ bits) + np.uint64(0x9E3779B97F4A7C15)
    h = (h ^ (h >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    h = (h ^ (h >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return h ^ (h >> np.uint64(31))


@numba.njit(cache=True, inline="always")
def _key_hash(owner, a, b, i):
    """Hash of the key ``(owner[i], a[i], b[i])`` (coordinates by their bits)."""
    h = _mix(np.uint64(0x84222325CBF29CE4), np.uint64(owner[i]))
    for c in range(a.shape[1]):
        h = _mix(h, a[i, c])
    for c in range(b.shape[1]):
        h = _mix(h, b[i, c])
    return h


@numba.njit(cache=True, inline="always")
def _same(owner, p, q, i, j):
    """Whether edge ``j`` is edge ``i`` reversed: same owner, ``p[j] = q[i]`` and
    ``q[j] = p[i]`` bit for bit."""
    if owner[i] != owner[j]:
        return False
    for c in range(p.shape[1]):
        if p[j, c] != q[i, c] or q[j, c] != p[i, c]:
            return False
    return True


@numba.njit(cache=True)
def reverse_edges(owner, p, q):
    """The edge ``q -> p`` of the same owner for each directed edge ``p -> q``.

    Coordinates are compared exactly (as their bits: ``-0.0`` and ``0.0`` differ, as
    in a byte comparison), through an open-addressing hash table at most half full.

    Parameters
    ----------
    owner : (e,) int64
    p, q : (e, 3) uint64
        The ends' coordinates viewed as their bits.

    Returns
    -------
    (e,) int64
        The twin's index (the first such edge when there are several), -1 if none.
    """
    e = owner.shape[0]
    size = 1
    while size < 2 * e + 2:
        size *= 2
    mask = np.uint64(size - 1)
    table = np.full(size, -1, dtype=np.int64)
    for i in range(e):                          # edges by (owner, p, q)
        h = _key_hash(owner, p, q, i) & mask
        while table[h] >= 0:                    # at most half full: a free slot is met
            h = (h + np.uint64(1)) & mask
        table[h] = i
    out = np.full(e, -1, dtype=np.int64)
    for i in range(e):                          # look up (owner, q, p)
        h = _key_hash(owner, q, p, i) & mask
        while table[h] >= 0:
            j = table[h]
            if _same(owner, p, q, i, j) and (out[i] < 0 or j < out[i]):
                out[i] = j
            h = (h + np.uint64(1)) & mask
    return out
