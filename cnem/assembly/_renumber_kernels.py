"""Numba kernels of `cnem.assembly.gradient_update.renumber_rows`: rows of a CSR matrix taken
in a new order with their columns renumbered, in two passes (count, then fill and
sort each row), instead of NumPy's gathers over every non-zero."""

import numba
import numpy as np

from .. import _compile  # noqa: F401  (says once when the kernels compile)


@numba.njit(cache=True)
def renumbered_counts(indptr, indices, rows, columns):
    """Non-zeros of every new row on a column with a new index, and how many fall on
    columns without one (``columns[j] < 0``): ``(counts (k,), dropped)``."""
    k = rows.shape[0]
    counts = np.zeros(k, dtype=np.int64)
    dropped = 0
    for r in range(k):
        i = rows[r]
        if i < 0:
            continue
        c = 0
        for p in range(indptr[i], indptr[i + 1]):
            if columns[indices[p]] >= 0:
                c += 1
            else:
                dropped += 1
        counts[r] = c
    return counts, dropped


@numba.njit(cache=True, parallel=True)
def renumbered_fill(indptr, indices, data, rows, columns, out_ptr, out_idx, out_data):
    """Fill the new rows (``out_ptr`` from `renumbered_counts`), each sorted by column."""
    for r in numba.prange(rows.shape[0]):
        i = rows[r]
        if i < 0:
            continue
        q = out_ptr[r]
        for p in range(indptr[i], indptr[i + 1]):
            j = columns[indices[p]]
            if j >= 0:
                # insertion into the sorted part of the row (rows hold a few dozen entries)
                s = q
                while s > out_ptr[r] and out_idx[s - 1] > j:
                    out_idx[s] = out_idx[s - 1]
                    out_data[s] = out_data[s - 1]
                    s -= 1
                out_idx[s] = j
                out_data[s] = data[p]
                q += 1
