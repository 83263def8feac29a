"""Numba kernels of the principal submatrix ``A[keep][:, keep]`` of a compressed sparse
matrix: two passes parallel over the kept rows (count, then fill); scipy's fancy
indexing is single-threaded."""

import numba

from .. import _compile  # noqa: F401  (says once when the kernels compile)
from .._parallel import parallel_kernel


@parallel_kernel("rows")
def kept_counts(indptr, indices, rows, new_index, counts, upper):
    """``counts[r]``: the entries of row ``rows[r]`` whose column is kept (and, with
    ``upper``, whose new number is at least ``r``: the upper triangle).

    Parameters
    ----------
    indptr, indices : compressed pattern (n, n)
    rows : (k,) int ndarray
        The kept rows.
    new_index : (n,) int ndarray
        The new number of every kept column, -1 for the others.
    counts : (k,) int64 ndarray
        Filled.
    upper : bool
    """
    for r in numba.prange(rows.shape[0]):
        lowest = r if upper else 0
        count = 0
        for p in range(indptr[rows[r]], indptr[rows[r] + 1]):
            if new_index[indices[p]] >= lowest:
                count += 1
        counts[r] = count


@parallel_kernel("rows")
def fill_kept(indptr, indices, data, rows, new_index, out_ptr, out_indices, out_data, upper):
    """Copy the kept entries of the kept rows, columns renumbered by ``new_index`` (in
    the order of the input: sorted input rows give sorted output rows).

    Parameters
    ----------
    indptr, indices, data : compressed (n, n)
    rows, new_index : as in `kept_counts`
    out_ptr : (k + 1,) int ndarray
        Offsets from `kept_counts`'s counts.
    out_indices, out_data : (out_ptr[k],) ndarray
        Filled.
    upper : bool
        The upper triangle only (as in `kept_counts`).
    """
    for r in numba.prange(rows.shape[0]):
        lowest = r if upper else 0
        at = out_ptr[r]
        for p in range(indptr[rows[r]], indptr[rows[r] + 1]):
            j = new_index[indices[p]]
            if j >= lowest:
                out_indices[at] = j
                out_data[at] = data[p]
                at += 1
