"""How parallel kernels cut their work: shared by the spatial index, the shape
functions and the assembly."""

from __future__ import annotations

import numba

__all__ = ["work_chunks"]


def work_chunks() -> int:
    """Number of chunks a parallel loop is cut into (a few per thread)."""
    return 8 * numba.get_num_threads()
