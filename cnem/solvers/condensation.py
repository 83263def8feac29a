"""The linear system on the free dofs: the free dofs, the principal submatrix of the
stiffness on them and the right-hand side lifted by the prescribed values.

`condensed_system` gives what ``skfem.condense(K, f, x=x, D=D)`` gives for a vector right-hand
side, with the submatrix and the lifting computed by parallel kernels
(`cnem.solvers._condense_kernels`, `cnem.solvers._multigrid_kernels.multiply`) and the
free dofs by a mask (skfem's single-threaded fancy indexing and ``setdiff1d`` took 6 s of
a 2M-dof solve). ``cnem.assembly.condense`` stays scikit-fem's, with its wider interface
(``I``, matrix right-hand sides).

`free_system` gives the same system with the submatrix as a `FreeBlock`: products on
the stiffness itself (scatter, parallel product, gather), the submatrix formed only
when a solver needs its entries (a direct solve, a smoother on it), so that an
iterative solve holds one copy of the stiffness, not two (1.3 GB at 1M nodes). The
stiffness may be given as its upper triangle (`cnem.solvers.symmetric.UpperTriangle`,
as 3-D elasticity assembles it): the block and the lifting are then taken from it, the
whole matrix never formed unless a solver needs its entries.

>>> import numpy as np, scipy.sparse as sp
>>> K = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(5, 5), format="csr")
>>> A, b, x, I = condensed_system(K, np.zeros(5), x=np.array([1.0, 0, 0, 0, 0]), D=[0, 4])
>>> I.tolist(), b.tolist()
([1, 2, 3], [1.0, 0.0, 0.0])
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .._aliases import renamed_attributes
from ..errors import InputError
from . import _condense_kernels as kernels
from .multigrid import parallel_operator
from .symmetric import UpperTriangle
from .._sets import distinct

__all__ = ["free_dofs", "principal_submatrix", "FreeBlock", "free_system", "condensed_system"]

#: Old names (one release): see `cnem._aliases`.
__getattr__ = renamed_attributes(__name__, {"condense": (__name__, "condensed_system")})

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
    k = len(rows)
    out = type(A)(_kept_arrays(A, rows, upper=False), shape=(k, k))
    out.has_canonical_format = True          # kept columns of canonical rows, in order
    return out


def _kept_arrays(A, rows, upper):
    """``(data, indices, indptr)`` of the principal submatrix of ``A`` (compressed,
    canonical) on ``rows`` (strictly increasing), its upper triangle only if ``upper``;
    int32 indices when they fit."""
    k = len(rows)
    counts, new_index = _kept_counts(A, rows, upper)
    total = int(counts.sum())
    index = np.int32 if max(total, k) <= _INT32_MAX else np.int64
    out_ptr = np.zeros(k + 1, dtype=index)
    np.cumsum(counts, out=out_ptr[1:])
    out_indices = np.empty(total, dtype=index)
    out_data = np.empty(total, dtype=A.data.dtype)
    kernels.fill_kept(A.indptr, A.indices, A.data, rows, new_index.astype(index, copy=False),
                      out_ptr, out_indices, out_data, upper)
    return out_data, out_indices, out_ptr


class FreeBlock(spla.LinearOperator):
    """The principal submatrix ``K[free][:, free]`` of a symmetric matrix, as a
    `scipy.sparse.linalg.LinearOperator` whose products run on ``K`` itself.

    Parameters
    ----------
    K : sparse (n, n) or UpperTriangle
        Symmetric. CSR, or CSC (its transpose, CSR, is multiplied: the same matrix,
        no copy), or its upper triangle; other formats are converted to CSR.
    free : (k,) int ndarray, strictly increasing, or (n,) bool ndarray, optional
        The kept dofs; all of them if None (the operator is then ``K``).

    Attributes
    ----------
    free : (k,) int64 ndarray
    shape : (k, k)
    """

    def __init__(self, K: sp.spmatrix, free: np.ndarray | None = None) -> None:
        self._K = _compressed(K)
        n = self._K.shape[0]
        self.free = np.arange(n) if free is None else _kept(free, n)
        self._all = len(self.free) == n
        self._triangle = isinstance(self._K, UpperTriangle)
        self._product = (self._K if self._triangle else
                         parallel_operator(self._K.T if self._K.format == "csc" else self._K))
        self._matrix = None
        self._upper = None
        self._nnz = None
        super().__init__(dtype=float, shape=(len(self.free), len(self.free)))

    @property
    def nnz(self) -> int:
        """Stored entries of the submatrix (counted without forming it)."""
        if self._nnz is None:
            self._nnz = (self._K.nnz if self._all
                         else int(_kept_counts(self._K, self.free, self._triangle)[0].sum()))
            if self._triangle:                 # the diagonal once, the rest twice
                self._nnz = 2 * self._nnz - self.shape[0]
        return self._nnz

    def matrix(self) -> sp.spmatrix:
        """The submatrix's entries (`principal_submatrix`; ``K`` itself when every dof is
        kept), formed at the first call and kept."""
        if self._matrix is None:
            if self._triangle:
                self._matrix = self.submatrix(np.arange(self.shape[0]))
            else:
                self._matrix = self._K if self._all else principal_submatrix(self._K, self.free)
        return self._matrix

    def upper(self) -> UpperTriangle:
        """The submatrix's upper triangle (half its bytes), formed at the first call and
        kept (of an `UpperTriangle` ``K``, a view of it on the free dofs, no copy); the
        block's products then run on it (reading half the data of ``K``'s)."""
        if self._upper is None:
            if self._triangle:                 # a view of K's triangle: no copy
                self._upper = self._K if self._all else self._K.principal(self.free)
            else:
                data, indices, indptr = _kept_arrays(self._K, self.free, upper=True)
                self._upper = UpperTriangle(indptr, indices, data)
        return self._upper

    def submatrix(self, keep: np.ndarray) -> sp.spmatrix:
        """The principal submatrix of this block on ``keep`` (its own numbering), taken
        from ``K`` directly.

        Parameters
        ----------
        keep : (m,) int ndarray, strictly increasing, or (k,) bool ndarray

        Returns
        -------
        sparse (m, m)
        """
        rows = self.free[_kept(keep, self.shape[0])]
        if self._triangle:
            data, indices, indptr = _kept_arrays(self._K, rows, upper=True)
            return UpperTriangle(indptr, indices, data).tocsr()
        return principal_submatrix(self._K, rows)

    def _matvec(self, x):
        x = np.asarray(x, dtype=float).reshape(-1)
        if self._upper is not None:
            return self._upper @ x
        if self._all:
            return self._product @ x
        whole = np.zeros(self._K.shape[0])
        whole[self.free] = x
        return (self._product @ whole)[self.free]

    def _rmatvec(self, x):                  # symmetric
        return self._matvec(x)


def free_system(K: sp.spmatrix, f: np.ndarray, *, x: np.ndarray, D: np.ndarray
                ) -> tuple[FreeBlock, np.ndarray, np.ndarray]:
    """The system on the free dofs ``I``, ``K[I][:, I] u_I = f[I] - K[I][:, D] x[D]``, its
    matrix as a `FreeBlock` of ``K``.

    Parameters
    ----------
    K : sparse (n, n) or UpperTriangle
        CSR or CSC (kept), or the upper triangle of a symmetric matrix (kept), other
        formats as CSR; symmetric for the block's products.
    f : (n,) ndarray
    x : (n,) ndarray
        The prescribed values on ``D`` (the rest is not read).
    D : (d,) int array_like
        The fixed dofs (repeats allowed).

    Returns
    -------
    A : FreeBlock (k, k)
    b : (k,) float64 ndarray
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
    if not isinstance(K, UpperTriangle) and K.format == "csc":  # the fixed columns (once each)
        D = distinct(np.asarray(D, dtype=np.int64))
        lifted = K[:, D] @ x[D]
    else:
        xd = x.astype(float)
        xd[I] = 0.0
        lifted = (K if isinstance(K, UpperTriangle) else parallel_operator(K)) @ xd
    return FreeBlock(K, I), f[I] - lifted[I], I


def condensed_system(K: sp.spmatrix, f: np.ndarray, *, x: np.ndarray, D: np.ndarray
             ) -> tuple[sp.spmatrix, np.ndarray, np.ndarray, np.ndarray]:
    """The system on the free dofs ``I``: ``K[I][:, I] u_I = f[I] - K[I][:, D] x[D]``.

    Parameters
    ----------
    K : sparse (n, n)
        CSR or CSC (kept), other formats as CSR.
    f, x, D
        As in `free_system`.

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
    _, b, I = free_system(K, f, x=x, D=D)
    return principal_submatrix(K, I), b, x, I


def _kept_counts(A, rows, upper=False):
    """The kept entries of each kept row of a principal submatrix of ``A`` (compressed,
    canonical) on ``rows`` (its upper triangle if ``upper``): ``counts (k,)`` int64 and
    ``new_index (n,)``, the new number of every kept dof, -1 for the others."""
    n = A.shape[0]
    counts = np.empty(len(rows), dtype=np.int64)
    new_index = np.full(n, -1, dtype=np.int32 if n <= _INT32_MAX else np.int64)
    new_index[rows] = np.arange(len(rows))
    kernels.kept_counts(A.indptr, A.indices, rows, new_index, counts, upper)
    return counts, new_index


def _compressed(A):
    """``A`` square, CSC or else CSR, canonical (a copy if it was not); an
    `UpperTriangle` as it is."""
    if isinstance(A, UpperTriangle):
        return A
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
