"""A symmetric matrix stored by its upper triangle: half the bytes of CSR, its product
and its symmetric Gauss-Seidel sweep each reading half the data
(`cnem.solvers._symmetric_kernels`).

The stiffness of 3-D SCNI has about 530 entries per row (175 neighbour nodes): 159M
at 100k nodes, 1.9 GB as CSR (float64 values, int32 columns). 3-D elasticity assembles
it in this form (`cnem.Elasticity.stiffness` with ``upper``), and the iterative solve
runs its products and the smoothing of the finest level on a view of it on the free dofs
(`UpperTriangle.principal`): one half-size copy of the stiffness in all.

>>> import numpy as np, scipy.sparse as sp
>>> from cnem.solvers.symmetric import UpperTriangle
>>> A = sp.csr_matrix(np.array([[4.0, 1.0, 0.0], [1.0, 4.0, 2.0], [0.0, 2.0, 4.0]]))
>>> U = UpperTriangle.from_matrix(A)
>>> (U @ np.ones(3)).tolist(), U.nnz
([5.0, 7.0, 6.0], 5)
"""

from __future__ import annotations

import copy

import numba
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..errors import InputError
from . import _symmetric_kernels as kernels

__all__ = ["UpperTriangle"]


class UpperTriangle(spla.LinearOperator):
    """A symmetric ``(n, n)`` matrix from the diagonal and the entries right of it, CSR.

    Parameters
    ----------
    indptr : (n + 1,) int64 ndarray
    indices : (nnz,) uint32 ndarray
        Columns, sorted in each row, each row's first its diagonal.
    data : (nnz,) float64 ndarray

    Attributes
    ----------
    nnz : int
        Stored entries.
    nbytes : int
        Bytes of the three arrays.
    keep : (k,) int64 ndarray or None
        For a principal view (`principal`): the rows and columns it keeps (its
        ``shape`` is then ``(k, k)``, ``nnz`` and ``nbytes`` still the whole triangle's).
    """

    def __init__(self, indptr: np.ndarray, indices: np.ndarray, data: np.ndarray) -> None:
        n = len(indptr) - 1
        self.indptr = np.asarray(indptr, dtype=np.int64)
        self.indices = np.asarray(indices, dtype=np.uint32)
        self.data = np.asarray(data, dtype=float)
        if n and not (np.all(np.diff(self.indptr) > 0) and
                      np.all(self.indices[self.indptr[:-1]] == np.arange(n))):
            raise InputError("expected every row to start with its diagonal entry, received "
                             "a row without it; build it with UpperTriangle.from_matrix")
        self.nnz = len(self.data)
        self.nbytes = self.indptr.nbytes + self.indices.nbytes + self.data.nbytes
        self._work = None
        self.keep = None
        super().__init__(dtype=float, shape=(n, n))

    def principal(self, keep: np.ndarray) -> UpperTriangle:
        """The principal submatrix on ``keep`` as a view sharing this triangle's arrays (no
        copy): its product and sweep run on the whole triangle, the other rows and
        columns held at zero (the system on the free dofs of a stiffness, say).

        Parameters
        ----------
        keep : (k,) int ndarray
            Strictly increasing rows in ``[0, n)``.

        Returns
        -------
        UpperTriangle
            Of shape ``(k, k)``.
        """
        keep = np.asarray(keep, dtype=np.int64).reshape(-1)
        n = len(self.indptr) - 1
        if self.keep is not None or (keep.size and (keep[0] < 0 or keep[-1] >= n or
                                                    np.any(np.diff(keep) <= 0))):
            raise InputError(f"keep: expected strictly increasing rows in [0, {n}) of a whole "
                             f"triangle; pass np.unique(keep) to the triangle itself")
        out = copy.copy(self)
        out.keep, out.shape, out._work = keep, (len(keep), len(keep)), None
        out._kept = np.zeros(n, dtype=bool)
        out._kept[keep] = True
        return out

    def _whole(self, v):
        """``v`` on the kept rows as a vector of the whole triangle, zero elsewhere."""
        whole = np.zeros(len(self.indptr) - 1)
        whole[self.keep] = v
        return whole

    @classmethod
    def from_matrix(cls, A: sp.spmatrix) -> UpperTriangle:
        """The upper triangle of a symmetric sparse matrix with a stored diagonal.

        Parameters
        ----------
        A : sparse (n, n)
            Symmetric (only its upper triangle is read).

        Returns
        -------
        UpperTriangle
        """
        U = sp.triu(sp.csr_matrix(A), format="csr")
        U.sum_duplicates()
        U.sort_indices()
        return cls(U.indptr, U.indices, U.data)

    def _matvec(self, x):
        x = np.ascontiguousarray(x, dtype=float).reshape(-1)
        if self.keep is not None:
            x = self._whole(x)
        out = np.empty(len(x))
        chunks = numba.get_num_threads()
        if self._work is None or self._work.shape[0] != chunks:
            self._work = np.empty((chunks, len(x)))
        kernels.multiply(self.indptr, self.indices, self.data, x, out, self._work)
        return out if self.keep is None else out[self.keep]

    def _rmatvec(self, x):                  # symmetric
        return self._matvec(x)

    def sweep(self, b: np.ndarray, x: np.ndarray, *, from_zero: bool = False,
              residual: bool = True) -> np.ndarray | None:
        """A symmetric Gauss-Seidel sweep on ``A x = b`` (forward, then backward), in
        place on ``x``.

        Parameters
        ----------
        b, x : (n,) float64 ndarray, contiguous
        from_zero : bool
            ``x`` is zero on entry (a quarter of the sweep's work saved).
        residual : bool
            Return the residual after the sweep (made by the sweep itself; without it,
            another quarter saved).

        Returns
        -------
        (n,) ndarray or None
            ``b - A x`` after the sweep, if ``residual``.
        """
        if self.keep is None:
            out = np.empty(self.shape[0] if residual else 0)
            kernels.symmetric_sweep(self.indptr, self.indices, self.data, b, x,
                                    np.empty(self.shape[0]), out, from_zero, np.empty(0, bool))
            return out if residual else None
        whole_x, n = self._whole(x), len(self.indptr) - 1
        out = np.empty(n if residual else 0)
        kernels.symmetric_sweep(self.indptr, self.indices, self.data, self._whole(b), whole_x,
                                np.empty(n), out, from_zero, self._kept)
        x[:] = whole_x[self.keep]
        return out[self.keep] if residual else None

    def tocsr(self) -> sp.csr_matrix:
        """The whole matrix, CSR ``(n, n)`` (for a direct solve or a check); of a
        principal view, its submatrix ``(k, k)``."""
        n = len(self.indptr) - 1
        U = sp.csr_matrix((self.data, self.indices.astype(np.int64), self.indptr),
                          shape=(n, n))
        if self.keep is not None:
            U = U[self.keep][:, self.keep]
        return (U + sp.triu(U, k=1).T).tocsr()
