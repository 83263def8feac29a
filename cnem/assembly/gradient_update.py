"""Smoothed gradients after a local model update: only the changed cells' rows recomputed.

A cell that `cnem.geometry.model_update.update` copied from the old model lies outside
every changed circumcircle, so the natural neighbours of the points on its
boundary, their shape functions and its row of ``B~`` are those of the old
model: the row is copied with its columns renumbered to the new nodes. The
rows of the recomputed cells come from `smoothed_gradient` on those cells alone.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp

from .._parallel import one_thread
from ..errors import CNEMError
from . import _renumber_kernels as RK
from .gradients import SmoothedGradient, smoothed_gradient

if TYPE_CHECKING:
    from ..geometry.model_update import ModelUpdate

__all__ = ["updated_gradient", "renumber_rows"]


def renumber_rows(matrix: sp.spmatrix, rows: np.ndarray, columns: np.ndarray, shape: tuple, *,
                  drop: bool = False) -> sp.spmatrix:
    """Rows ``rows`` of ``matrix`` with their columns renumbered by ``columns``.

    Parameters
    ----------
    matrix : sparse (r, c)
    rows : (k,) int array
        Row of ``matrix`` that becomes each row of the result; -1 for an empty row.
    columns : (c,) int64 ndarray
        New index of every column; -1 for a column that must not appear.
    shape : tuple
        ``(k, c_new)``.
    drop : bool
        Leave out the entries on columns mapped to -1 (else they raise).

    Returns
    -------
    scipy.sparse.csr_matrix, shape ``shape``

    Raises
    ------
    CNEMError
        A taken row has a non-zero in a column mapped to -1 (and not ``drop``).
    """
    matrix = sp.csr_matrix(matrix)
    rows = np.ascontiguousarray(rows, dtype=np.int64)
    columns = np.ascontiguousarray(columns, dtype=np.int64)
    indptr = matrix.indptr.astype(np.int64, copy=False)
    indices = matrix.indices.astype(np.int64, copy=False)
    counts, dropped = RK.renumbered_counts(indptr, indices, rows, columns)
    if dropped and not drop:
        raise CNEMError(f"{dropped} non-zeros of the copied rows fall on columns that have "
                        "no new index; the rows must be recomputed instead")
    out_ptr = np.zeros(len(rows) + 1, dtype=np.int64)
    np.cumsum(counts, out=out_ptr[1:])
    out_idx = np.empty(out_ptr[-1], dtype=np.int64)
    out_data = np.empty(out_ptr[-1], dtype=matrix.data.dtype)
    RK.renumbered_fill(indptr, indices, matrix.data, rows, columns, out_ptr, out_idx, out_data)
    out = sp.csr_matrix((out_data, out_idx, out_ptr), shape=shape)
    out.has_sorted_indices = True
    return out


def updated_gradient(old: SmoothedGradient, change: ModelUpdate, *,
                     gauss: int = 2) -> SmoothedGradient:
    """``B~`` of the updated model: copied rows for the copied cells, the others computed.

    Parameters
    ----------
    old : SmoothedGradient
        ``B~`` of ``change.old`` (its cells), ``x, y`` ``(m_old, n_old)``.
    change : cnem.geometry.model_update.ModelUpdate
    gauss : int
        As in `smoothed_gradient` (the one ``old`` was computed with).

    Returns
    -------
    SmoothedGradient
        ``x, y`` ``(m, n)`` of ``change.model``; ``points`` counts the quadrature
        points of the recomputed cells only.
    """
    model = change.model
    m, n = len(model.cells), len(model.nodes)
    if old.x.shape != (len(change.old.cells), len(change.old.nodes)):
        raise CNEMError(f"old: expected the smoothed gradient of the old model, "
                        f"{len(change.old.cells)} cells x {len(change.old.nodes)} nodes, "
                        f"received {old.x.shape[0]} x {old.x.shape[1]}")
    redo = change.changed_cells
    model.circumcircles()               # the whole model's: in parallel
    with one_thread():                  # a few cells
        fresh = smoothed_gradient(model, gauss=gauss, cells=model.cells.subset(redo))
    columns = change.new_node()
    place = np.full(m, -1, dtype=np.int64)
    place[redo] = np.arange(len(redo))

    def merged(old_part, new_part):
        copied = renumber_rows(old_part, change.old_cell, columns, (m, n))
        return copied + renumber_rows(new_part, place, np.arange(n), (m, n))

    return SmoothedGradient(*map(merged, old, fresh), points=fresh.points)
