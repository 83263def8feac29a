"""Smoothed-aggregation multigrid as a CG preconditioner: pyamg builds the hierarchy,
cnem's parallel kernels run the cycle.

pyamg's set-up (aggregation, prolongation, Galerkin products) is kept; its cycle is
single-threaded. `VCycle` runs the same V-cycle, a symmetric Gauss-Seidel smoothing
(a forward then a backward sweep) before and after the coarse correction, with hybrid
sweeps (`cnem.solvers._multigrid_kernels`): every product and sweep parallel over rows.
(One forward sweep before and one backward after is also symmetric and half the
smoothing, but CG then needs 82 iterations instead of 66 on the stabilised 1M-node
system, and twice as many for plain SCNI, whose oscillating modes only smoothing
with K itself removes.)

>>> import numpy as np, scipy.sparse as sp
>>> from cnem.solvers.multigrid import hierarchy
>>> A = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(500, 500), format="csr")
>>> M = hierarchy(A)
>>> x = M.matvec(np.ones(500))
>>> bool(np.all(np.isfinite(x)))
True
"""

from __future__ import annotations

import copy
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..errors import InputError
from . import _multigrid_kernels as kernels
from .symmetric import UpperTriangle

if TYPE_CHECKING:
    import pyamg

__all__ = ["VCycle", "Rows", "hierarchy", "parallel_operator"]

#: The sweeps cut each level into at most this many blocks of consecutive rows, and
#: into blocks of at least BLOCK_ROWS rows: enough blocks for every thread, few
#: enough that the coupling across blocks (where Gauss-Seidel becomes Jacobi) stays small
#: for rows ordered along space (the model's nodes, the aggregates built from them).
MAX_BLOCKS, BLOCK_ROWS = 16, 4096

#: Prolongation smoothing of the set-up: damped Jacobi with the Gershgorin (row-sum)
#: scaling, which needs no spectral-radius estimate. pyamg's default estimates it
#: by Arnoldi on every level (two thirds of its 1M-node set-up: 17 -> 7 s CPU); this
#: costs CG iterations (stabilised SCNI: 51 -> 53 at 100k nodes, 57 -> 67 at 1M).
PROLONGATION_SMOOTHER = ("jacobi", {"omega": 4.0 / 3.0, "weighting": "local"})


class Rows(NamedTuple):
    """A CSR matrix as the kernels take it."""

    indptr: np.ndarray     #: (m + 1,) int64
    indices: np.ndarray    #: (nnz,) uint32
    data: np.ndarray       #: (nnz,) float64
    shape: tuple


def hierarchy(matrix: sp.spmatrix, modes: np.ndarray | None = None,
              top: sp.spmatrix | UpperTriangle | None = None) -> VCycle:
    """Smoothed aggregation on ``matrix`` (pyamg), as a `VCycle`.

    Parameters
    ----------
    matrix : sparse (N, N)
        Symmetric positive definite; the hierarchy is built on it.
    modes : (N, k) ndarray, optional
        Near-null space (rigid motions); pyamg's constant vector if None.
    top : sparse (N, N) or UpperTriangle, optional
        Smooth the finest level with this matrix instead (the system's own matrix
        when ``matrix`` only approximates it).

    Returns
    -------
    VCycle
    """
    import pyamg
    ml = pyamg.smoothed_aggregation_solver(sp.csr_matrix(matrix), B=modes,
                                           symmetry="symmetric", smooth=PROLONGATION_SMOOTHER)
    return VCycle(ml, top)


class VCycle(spla.LinearOperator):
    """A symmetric V-cycle over a pyamg hierarchy, a `scipy.sparse.linalg.LinearOperator`.

    Parameters
    ----------
    ml : pyamg.MultilevelSolver
        Its level matrices, prolongations and restrictions are copied to CSR (the
        solver may then be dropped); its coarse solver solves the last level.
    top : sparse (N, N) or UpperTriangle, optional
        The finest level's matrix for the sweeps and the residual (default: the
        hierarchy's own), held as an `UpperTriangle` (half the bytes and half the data
        read per sweep; a sparse matrix is converted). It is swept as one block
        (plain, sequential Gauss-Seidel: `UpperTriangle.sweep`): the
        oscillating low-energy modes of plain SCNI's K (and of 3-D SCNI's), for which it
        is given, are
        what the smoothing there must remove, and the Jacobi coupling across blocks
        leaves them (50 CG iterations instead of 41 at 100k nodes with 16 blocks).

    Attributes
    ----------
    levels : int
    """

    def __init__(self, ml: pyamg.MultilevelSolver,
                 top: sp.spmatrix | UpperTriangle | None = None) -> None:
        levels = ml.levels
        if top is not None and top.shape != levels[0].A.shape:
            raise InputError(f"top: expected shape {levels[0].A.shape} like the hierarchy's "
                             f"finest level, received {top.shape}; pass the system's matrix")
        self._A = [_csr(lv.A) for lv in levels[:-1]]
        self._top = None
        if top is not None and self._A:
            self._top = top if isinstance(top, UpperTriangle) else UpperTriangle.from_matrix(top)
            self._A[0] = None                   # level 0 is self._top
        self._P = [_csr(lv.P) for lv in levels[:-1]]
        self._R = [_csr(lv.R) for lv in levels[:-1]]
        self._coarse_A, self._coarse = levels[-1].A, ml.coarse_solver
        self._starts, self._diagonal = [], []
        for A in self._A:
            # the top (None) is swept by its own kernel
            starts, diagonal = (None, None) if A is None else _sweep_blocks(A)
            self._starts.append(starts)
            self._diagonal.append(diagonal)
        self.levels = len(levels)
        super().__init__(dtype=float, shape=levels[0].A.shape)

    def smoothing_with(self, top: sp.spmatrix | UpperTriangle) -> VCycle:
        """The same hierarchy with its finest level smoothed with ``top`` ``(N, N)``
        instead (see ``top`` above): its coarse levels are shared, not copied."""
        if top.shape != self.shape:
            raise InputError(f"top: expected shape {self.shape} like the hierarchy's finest "
                             f"level, received {top.shape}; pass the system's matrix")
        out = copy.copy(self)
        if self._A:
            out._A, out._starts, out._diagonal = list(self._A), list(self._starts), \
                list(self._diagonal)
            out._A[0], out._starts[0], out._diagonal[0] = None, None, None
            out._top = top if isinstance(top, UpperTriangle) else UpperTriangle.from_matrix(top)
        return out

    def _matvec(self, b):
        return self._cycle(0, np.ascontiguousarray(b, dtype=float).reshape(-1))

    def _rmatvec(self, b):                  # symmetric
        return self._matvec(b)

    def _cycle(self, level, b):
        """The V-cycle's approximation of ``A_level^-1 b``: ``(n_level,)`` ndarray."""
        if level == len(self._A):
            return np.asarray(self._coarse(self._coarse_A, b), dtype=float).reshape(-1)
        A, P, R = self._A[level], self._P[level], self._R[level]
        x, before = np.zeros_like(b), np.empty_like(b)
        if A is None:                           # the top's sweep gives the residual
            r = self._top.sweep(b, x, from_zero=True)
        else:
            self._smooth(level, b, x, before)
            r = np.empty_like(b)
            kernels.residual(A.indptr, A.indices, A.data, x, b, r)
        coarse_b = np.empty(R.shape[0])
        kernels.multiply(R.indptr, R.indices, R.data, r, coarse_b, False)
        kernels.multiply(P.indptr, P.indices, P.data, self._cycle(level + 1, coarse_b), x, True)
        self._smooth(level, b, x, before)
        return x

    def _smooth(self, level, b, x, before):
        """A forward then a backward sweep on ``x`` (a symmetric smoother: the same one
        before and after the coarse correction makes the cycle symmetric)."""
        A, starts, diagonal = self._A[level], self._starts[level], self._diagonal[level]
        if A is None:
            self._top.sweep(b, x, residual=False)
            return
        for backward in (False, True):
            np.copyto(before, x)
            kernels.sweep(A.indptr, A.indices, A.data, diagonal, starts, b, x, before, backward)

def _sweep_blocks(A):
    """The blocks of rows a level's sweeps cut ``A`` (`Rows`) into, ``starts``, and the
    l1 diagonal the sweeps divide by."""
    n = A.shape[0]
    blocks = max(1, min(MAX_BLOCKS, n // BLOCK_ROWS))
    starts = np.arange(blocks + 1, dtype=np.int64) * n // blocks
    diagonal = np.empty(n)
    kernels.l1_diagonal(A.indptr, A.indices, A.data, starts, diagonal)
    return starts, diagonal


def parallel_operator(A: sp.spmatrix) -> spla.LinearOperator:
    """``A`` as a `scipy.sparse.linalg.LinearOperator` whose product runs in parallel
    (`cnem.solvers._multigrid_kernels.multiply`); ``A`` CSR ``(m, n)`` (converted if not)."""
    A = _csr(A)

    def product(x):
        out = np.empty(A.shape[0])
        kernels.multiply(A.indptr, A.indices, A.data,
                         np.ascontiguousarray(x, dtype=float).reshape(-1), out, False)
        return out

    return spla.LinearOperator(A.shape, matvec=product, rmatvec=None, dtype=float)


def _csr(A):
    """``A`` as CSR arrays for the kernels: ``(indptr, indices, data)``, int64 row
    offsets, uint32 column indices, sorted and without duplicates."""
    A = sp.csr_matrix(A)
    if not A.has_canonical_format:
        A = A.copy()
        A.sum_duplicates()
    if A.shape[1] >= 2**32:
        raise InputError(f"expected fewer than 2**32 columns, received {A.shape[1]}")
    indices = A.indices.view(np.uint32) if A.indices.dtype == np.int32 else \
        A.indices.astype(np.uint32)                    # non-negative: the view is exact
    return Rows(A.indptr.astype(np.int64), indices, A.data, A.shape)
