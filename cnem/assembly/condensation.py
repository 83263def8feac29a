"""The linear system on the free dofs: the free dofs, the principal submatrix of the
stiffness on them and the right-hand side lifted by the prescribed values.

`condense` gives what ``skfem.condense(K, f, x=x, D=D)`` gives for a vector right-hand
side, with the submatrix and the lifting computed by parallel kernels
(`cnem.assembly._condense_kernels`, `cnem.assembly._multigrid_kernels.multiply`) and the
free dofs by a mask (skfem's single-threaded fancy indexing and ``setdiff1d`` took 6 s of
a 2M-dof solve). ``cnem.assembly.condense`` stays scikit-fem's, with its wider interface
(``I``, matrix right-hand sides).

>>> import numpy as np, scipy.sparse as sp
>>> K = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(5, 5), format="csr")
>>> A, b, x, I = condense(K, np.zeros(5), x=np.array([1.0, 0, 0, 0, 0]), D=[0, 4])
>>> I.tolist(), b.tolist()
([1, 2, 3], [1.0, 0.0, 0.0])
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..errors import InputError
from . import _condense_kernels as kernels
from .multigrid import parallel_operator

__all__ = ["free_dofs", "principal_submatrix", "condense"]

_INT32_MAX = np.iinfo(np.int32).max


def free_dofs(size: int, fixed: np.ndarray) -> np.ndarray:
    """The dofs of ``range(size)`` not in ``fixed``.

    Parameters
    ----------
    size : int
    fixed : (d,) int array_like
        Dof numbers in ``[0, size)``; repeats are allowed.

    Returns
    -------
    (size - unique d,) int64 ndarray
        Sorted.
    """
    fixed = np.asarray(fixed).reshape(-1)
    if fixed.size and fixed.dtype.kind not in "iu":
        raise InputError(f"fixed dofs: expected integer dof numbers, received dtype "
                         f"{fixed.dtype}; pass np.flatnonzero(mask) for a boolean mask")
    if fixed.size and (fixed.min() < 0 or fixed.max() >= size):
        raise InputError(f"fixed dofs: expected numbers in [0, {size}), received "
                         f"[{fixed.min()}, {fixed.max()}]; number the dofs of this system")
    free = np.ones(size, dtype=bool)
    free[fixed.astype(np.int64, copy=False)] = False
    return np.flatnonzero(free)


def principal_submatrix(A: sp.spmatrix, keep: np.ndarray) -> sp.spmatrix:
    """``A[keep][:, keep]``, by two parallel passes over the kept rows.

    Parameters
    ----------
    A : sparse (n, n)
        CSC stays CSC (the kept columns of its arrays: exact for any matrix, no
        conversion); any other format is taken as CSR.
    keep : (k,) int ndarray, strictly increasing, or (n,) bool ndarray

    Returns
    -------
    sparse (k, k)
        CSR (CSC for CSC ``A``), sorted indices, no duplicates; int32 indices when
        they fit.
    """
    A = _compressed(A)
    rows = _kept(keep, A.shape[0])
    n, k = A.shape[0], len(rows)
    counts = np.empty(k, dtype=np.int64)
    new_index = np.full(n, -1, dtype=np.int32 if n <= _INT32_MAX else np.int64)
    new_index[rows] = np.arange(k)
    kernels.kept_counts(A.indptr, A.indices, rows, new_index, counts)
    total = int(counts.sum())
    index = np.int32 if max(total, k) <= _INT32_MAX else np.int64
    out_ptr = np.zeros(k + 1, dtype=index)
    np.cumsum(counts, out=out_ptr[1:])
    out_indices = np.empty(total, dtype=index)
    out_data = np.empty(total, dtype=A.data.dtype)
    kernels.fill_kept(A.indptr, A.indices, A.data, rows, new_index.astype(index, copy=False),
                      out_ptr, out_indices, out_data)
    out = type(A)((out_data, out_indices, out_ptr), shape=(k, k))
    out.has_canonical_format = True          # kept columns of canonical rows, in order
    return out


def condense(K: sp.spmatrix, f: np.ndarray, *, x: np.ndarray, D: np.ndarray
             ) -> tuple[sp.spmatrix, np.ndarray, np.ndarray, np.ndarray]:
    """The system on the free dofs ``I``: ``K[I][:, I] u_I = f[I] - K[I][:, D] x[D]``.

    Parameters
    ----------
    K : sparse (n, n)
        CSR or CSC (kept), other formats as CSR.
    f : (n,) ndarray
    x : (n,) ndarray
        The prescribed values on ``D`` (the rest is not read).
    D : (d,) int array_like
        The fixed dofs (repeats allowed).

    Returns
    -------
    A : sparse (k, k)
        `principal_submatrix` of ``K`` on ``I``.
    b : (k,) float64 ndarray
    x : (n,) ndarray
        The ``x`` given (skfem's return).
    I : (k,) int64 ndarray
        The free dofs, sorted.
    """
    K = _compressed(K)
    n = K.shape[0]
    f, x = np.asarray(f), np.asarray(x)
    for name, vector in (("f", f), ("x", x)):
        if vector.shape != (n,):
            raise InputError(f"{name}: expected shape ({n},) like K's rows, received "
                             f"{vector.shape}; pass one value per dof")
    I = free_dofs(n, D)
    if K.format == "csc":                      # the fixed columns, a few (once each)
        D = np.unique(np.asarray(D, dtype=np.int64))
        lifted = K[:, D] @ x[D]
    else:
        xd = x.astype(float)
        xd[I] = 0.0
        lifted = parallel_operator(K) @ xd
    return principal_submatrix(K, I), f[I] - lifted[I], x, I


def _compressed(A):
    """``A`` square, CSC or else CSR, canonical (a copy if it was not)."""
    if not sp.issparse(A):
        raise InputError(f"expected a scipy sparse matrix, received {type(A).__name__}; "
                         "pass scipy.sparse.csr_matrix(A)")
    if A.shape[0] != A.shape[1]:
        raise InputError(f"expected a square matrix, received shape {A.shape}")
    if A.format not in ("csr", "csc"):
        A = A.tocsr()
    if not A.has_canonical_format:
        A = A.copy()
        A.sum_duplicates()
    return A


def _kept(keep, n):
    """The kept rows of a principal submatrix of order ``n``: ``(k,)`` int64."""
    keep = np.asarray(keep).reshape(-1)
    if keep.dtype == bool:
        if keep.shape != (n,):
            raise InputError(f"keep: expected a boolean mask of shape ({n},), received "
                             f"{keep.shape}")
        return np.flatnonzero(keep)
    if keep.size and keep.dtype.kind not in "iu":
        raise InputError(f"keep: expected integer dofs or a boolean mask, received dtype "
                         f"{keep.dtype}")
    keep = keep.astype(np.int64, copy=False)
    if keep.size and (keep[0] < 0 or keep[-1] >= n or np.any(np.diff(keep) <= 0)):
        raise InputError(f"keep: expected strictly increasing dofs in [0, {n}); "
                         "pass np.unique(keep)")
    return keep
