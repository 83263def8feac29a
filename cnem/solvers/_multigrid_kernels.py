"""Numba kernels of the multigrid cycle: sparse products and Gauss-Seidel sweeps over
blocks of rows, both parallel over rows (scipy's and pyamg's are single-threaded).

The sweeps are *hybrid*: Gauss-Seidel inside each block of consecutive rows, Jacobi
between blocks (the other blocks' values are read from a snapshot taken before the
sweep), with each row's diagonal raised by the absolute sum of its entries outside its
block (the l1 smoother of Baker, Falgout, Kolev and Yang, SIAM J. Sci. Comput. 33, 2011,
which converges for any symmetric positive definite matrix). The blocks are fixed by
the matrix alone, so results do not depend on the number of threads.
"""

import numba

from .. import _compile  # noqa: F401  (says once when the kernels compile)
from .._parallel import parallel_kernel


@numba.njit(cache=True, inline="always")
def _row_product(indptr, indices, data, x, i):
    """Row ``i`` of ``A x``, two partial sums (a shorter dependency chain)."""
    s0, s1 = 0.0, 0.0
    p, end = indptr[i], indptr[i + 1]
    while p + 1 < end:
        s0 += data[p] * x[indices[p]]
        s1 += data[p + 1] * x[indices[p + 1]]
        p += 2
    if p < end:
        s0 += data[p] * x[indices[p]]
    return s0 + s1


@parallel_kernel("out")
def multiply(indptr, indices, data, x, out, accumulate):
    """``out = A x``, or ``out += A x`` with ``accumulate``; ``A`` CSR ``(m, n)``
    (``indices`` unsigned: no negative-index wrap-around per entry), ``x`` ``(n,)``,
    ``out`` ``(m,)``."""
    for i in numba.prange(out.shape[0]):
        s = _row_product(indptr, indices, data, x, i)
        out[i] = out[i] + s if accumulate else s


@parallel_kernel("out")
def residual(indptr, indices, data, x, b, out):
    """``out = b - A x``; ``A`` CSR ``(n, n)`` as in `multiply`, the vectors ``(n,)``."""
    for i in numba.prange(out.shape[0]):
        out[i] = b[i] - _row_product(indptr, indices, data, x, i)


@parallel_kernel("diagonal")
def l1_diagonal(indptr, indices, data, starts, diagonal):
    """Each row's diagonal entry plus the absolute sum of its entries outside its block.

    Parameters
    ----------
    indptr, indices, data : CSR (n, n)
    starts : (nb + 1,) int ndarray
        First row of each block, then ``n``.
    diagonal : (n,) ndarray
        Filled.
    """
    for k in numba.prange(starts.shape[0] - 1):
        lo, hi = starts[k], starts[k + 1]
        for i in range(lo, hi):
            d = 0.0
            for p in range(indptr[i], indptr[i + 1]):
                j = indices[p]
                if j == i:
                    d += data[p]
                elif j < lo or j >= hi:
                    d += abs(data[p])
            diagonal[i] = d


@parallel_kernel("diagonal")
def sweep(indptr, indices, data, diagonal, starts, b, x, before, backward):
    """One hybrid Gauss-Seidel sweep on ``A x = b``, in place on ``x``.

    Parameters
    ----------
    indptr, indices, data : CSR (n, n), sorted indices (a row whose first and last
        columns are in its block is swept without testing each entry)
    diagonal : (n,) ndarray
        From `l1_diagonal` with the same ``starts``.
    starts : (nb + 1,) int ndarray
        The blocks (consecutive rows), swept in parallel.
    b : (n,) ndarray
    x : (n,) ndarray
        The iterate, updated.
    before : (n,) ndarray
        A copy of ``x`` taken before the sweep (the values read across blocks).
    backward : bool
        Rows in decreasing order inside each block (the transposed sweep).
    """
    for k in numba.prange(starts.shape[0] - 1):
        lo, hi = starts[k], starts[k + 1]
        for t in range(hi - lo):
            i = hi - 1 - t if backward else lo + t
            first, end = indptr[i], indptr[i + 1]
            if end == first or (indices[first] >= lo and indices[end - 1] < hi):
                s = b[i] - _row_product(indptr, indices, data, x, i)     # all in the block
            else:
                s = b[i]
                for p in range(first, end):
                    j = indices[p]
                    s -= data[p] * (x[j] if lo <= j < hi else before[j])
            x[i] += s / diagonal[i]
