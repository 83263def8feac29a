"""Two small CSR helpers shared by the boundary quadrature and the passes."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["row_bounds", "csr_pair"]


def row_bounds(indptr: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Starts and ends of the rows of a CSR matrix, as int64 (one kernel signature)."""
    indptr = np.asarray(indptr, dtype=np.int64)
    return indptr[:-1], indptr[1:]


def csr_pair(indptr: np.ndarray, indices: np.ndarray, x: np.ndarray, y: np.ndarray,
             shape: tuple[int, int]) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """Two CSR matrices on one pattern, each with its own index arrays (scipy may
    sort one matrix's indices in place)."""
    return sp.csr_matrix((x, indices, indptr), shape=shape), \
        sp.csr_matrix((y, indices.copy(), indptr.copy()), shape=shape)
