"""Recursive coordinate bisection of a point cloud and the ghost candidates of each part.

>>> import numpy as np
>>> from cnem.pd.distributed.partition import bisect
>>> pts = np.column_stack([np.arange(8.0), np.zeros(8)])
>>> bisect(pts, np.ones(8), 2).tolist()
[0, 0, 0, 0, 1, 1, 1, 1]
"""

from __future__ import annotations

import numpy as np

from ...spatial import RTree
from ..._sets import distinct

__all__ = ["bisect", "ghost_candidates"]


def bisect(points: np.ndarray, weights: np.ndarray, parts: int) -> np.ndarray:
    """Recursive coordinate bisection: each cut halves the weight across the longest
    extent of the current set (the parts of a cut in proportion to their ranks).

    Parameters
    ----------
    points : (n, d) ndarray
    weights : (n,) ndarray
        Work per point (its family size).
    parts : int

    Returns
    -------
    (n,) int64 ndarray
        Part of each point, ``0..parts-1``; deterministic (every rank computes the same).
    """
    part = np.zeros(len(points), dtype=np.int64)
    stack = [(np.arange(len(points)), 0, int(parts))]
    while stack:
        ids, first, count = stack.pop()
        if count == 1 or len(ids) == 0:
            part[ids] = first
            continue
        sub = points[ids]
        axis = int(np.argmax(sub.max(axis=0) - sub.min(axis=0)))
        order = ids[np.argsort(sub[:, axis], kind="stable")]
        left = count // 2
        cumulative = np.cumsum(weights[order])
        cut = int(np.searchsorted(cumulative, cumulative[-1] * left / count)) + 1
        cut = min(max(cut, 1), len(ids) - 1) if len(ids) > 1 else cut
        stack.append((order[:cut], first, left))
        stack.append((order[cut:], first + left, count - left))
    return part


def ghost_candidates(points: np.ndarray, part: np.ndarray, rank: int, reach: float,
                     period: np.ndarray | None = None) -> np.ndarray:
    """Points within the bounding box of part ``rank`` grown by ``reach``, not in it.

    Parameters
    ----------
    points : (n, d) ndarray
    part : (n,) int ndarray
    rank : int
    reach : float
        The horizon (every point within it of an owned point is inside the grown box).
    period : None or (d,) array_like
        Periodic cell: the grown box wraps around it (Niina's periodic R-tree).

    Returns
    -------
    (k,) int64 ndarray
        Increasing global ids.
    """
    mine = part == rank
    if not mine.any():
        return np.zeros(0, dtype=np.int64)
    own = points[mine]
    lo, hi = own.min(axis=0) - reach, own.max(axis=0) + reach
    tree = RTree.from_points(points, period=period)
    _, hits = tree.query(lo[None, :], hi[None, :])
    hits = distinct(hits)
    return hits[~mine[hits]]
