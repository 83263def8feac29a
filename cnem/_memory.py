"""Giving freed memory back to the operating system.

Work done in passes (the smoothed gradients of large models) allocates and
frees many arrays of a few megabytes each. glibc serves those from its heaps
(below its mmap threshold) and keeps the freed space resident: after such a
computation the process can hold gigabytes it no longer uses (2.3 GB after the
smoothed gradients of a 1M-node model). `release_free_memory` asks glibc to
return it; elsewhere it does nothing.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import functools

__all__ = ["release_free_memory"]


@functools.lru_cache(maxsize=None)
def _malloc_trim():
    """glibc's ``malloc_trim``, or None on other C libraries."""
    name = ctypes.util.find_library("c")
    try:
        return ctypes.CDLL(name).malloc_trim if name else None
    except (OSError, AttributeError):
        return None


def release_free_memory() -> bool:
    """Return the free space of the C heaps to the operating system (glibc only).

    Returns
    -------
    bool
        Whether anything was returned (False where it is not available).
    """
    trim = _malloc_trim()
    return bool(trim(0)) if trim is not None else False
