"""Numba kernels of a symmetric matrix stored by its upper triangle (CSR rows holding the
diagonal and the entries right of it): the product and the Gauss-Seidel sweeps.

Each stored entry ``a_ij`` (``j > i``) serves twice: in row ``i`` (gathered) and in row
``j`` (scattered), so a pass reads half the data of the whole matrix's. The forward sweep
scatters the new values into the rows below as it goes (``lower``); a backward sweep
right after it finds there the products with the rows' left parts that it needs (the
values it reads left of the diagonal are those the forward sweep left), so the pair, a
symmetric Gauss-Seidel sweep, costs two passes over the upper triangle: one of the whole
matrix.
"""

import numba

from .. import _compile  # noqa: F401  (says once when the kernels compile)
from .._parallel import parallel_kernel


@parallel_kernel("out")
def multiply(indptr, indices, data, x, out, partial):
    """``out = A x`` for ``A`` symmetric stored by its upper triangle.

    Parameters
    ----------
    indptr : (n + 1,) int64 ndarray
    indices : (nnz,) uint32 ndarray
        Sorted in each row, the diagonal first.
    data : (nnz,) float64 ndarray
    x : (n,) ndarray
    out : (n,) ndarray
        Filled.
    partial : (chunks, n) ndarray
        Work space (overwritten): ``chunks`` blocks of consecutive rows are done in
        parallel, each into its own row of ``partial`` (the scattered entries of one
        block land in rows of others), added at the end.
    """
    chunks, n = partial.shape
    for k in numba.prange(chunks):
        own = partial[k]
        own[:] = 0.0
        for i in range(k * n // chunks, (k + 1) * n // chunks):
            xi = x[i]
            s = 0.0
            for p in range(indptr[i], indptr[i + 1]):
                j = indices[p]
                a = data[p]
                s += a * x[j]
                if j != i:
                    own[j] += a * xi
            own[i] += s
    for i in numba.prange(n):
        s = 0.0
        for k in range(chunks):
            s += partial[k, i]
        out[i] = s


@numba.njit(cache=True)
def symmetric_sweep(indptr, indices, data, b, x, lower, residual, from_zero, kept):
    """A forward then a backward Gauss-Seidel sweep on ``A x = b``, in place on ``x``,
    and the residual ``b - A x`` after it.

    Parameters
    ----------
    indptr, indices, data : the upper triangle, as in `multiply` (the diagonal first in
        each row, positive)
    b : (n,) ndarray
    x : (n,) ndarray
        The iterate, updated.
    lower : (n,) ndarray
        Work space (overwritten): ``sum_{j < i} a_ij x_j`` of the new values.
    residual : (n,) or (0,) ndarray
        Unless empty, filled with ``b - A x`` of the final ``x``: row ``i`` of the backward sweep
        leaves a zero residual but for the changes of the ``x_j`` left of it, which it
        then makes, ``sum_{j < i} a_ij (x_j^forward - x_j^final)``, scattered from the
        rows as they change (no further pass over the matrix).
    from_zero : bool
        ``x`` is zero on entry: the forward sweep reads nothing right of the diagonal.
    kept : (n,) bool or (0,) ndarray
        Unless empty, sweep only the rows it marks, the others' ``x`` zero and left so:
        the sweep of the principal submatrix on the kept rows (their residual only).
    """
    n = x.shape[0]
    every = kept.shape[0] == 0
    lower[:] = 0.0
    for i in range(n):                      # forward: new values left, old right
        if not (every or kept[i]):
            continue
        first, end = indptr[i], indptr[i + 1]
        s = b[i] - lower[i]
        if not from_zero:
            for p in range(first + 1, end):
                s -= data[p] * x[indices[p]]
        xi = s / data[first]
        x[i] = xi
        for p in range(first + 1, end):
            lower[indices[p]] += data[p] * xi
    track = residual.shape[0] == n
    residual[:] = 0.0
    for i in range(n - 1, -1, -1):          # backward: new values right, forward's left
        if not (every or kept[i]):
            continue
        first, end = indptr[i], indptr[i + 1]
        s = b[i] - lower[i]
        for p in range(first + 1, end):
            s -= data[p] * x[indices[p]]
        xi = s / data[first]
        change = x[i] - xi
        x[i] = xi
        if track:
            for p in range(first + 1, end):
                residual[indices[p]] += data[p] * change
