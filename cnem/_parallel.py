"""How parallel kernels cut their work: shared by the spatial index, the shape
functions and the assembly."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

import numba

__all__ = ["work_chunks", "one_thread"]


def work_chunks() -> int:
    """Number of chunks a parallel loop is cut into (a few per thread)."""
    return 8 * numba.get_num_threads()


@contextmanager
def one_thread() -> Iterator[None]:
    """Run the parallel kernels called inside on the calling thread alone.

    For small work (a local update's few cells): a parallel region then waits
    for no other thread, which on a busy machine can cost more than the work.
    """
    before = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        yield
    finally:
        numba.set_num_threads(before)
