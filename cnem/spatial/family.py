"""Peridynamic family search: every ``j`` with ``0 < |x_j - x_i| < horizon_i``.

Four interchangeable methods return the same sets: a cell list (``"cells"``,
the region partitioning of Vazic et al. done as a proper cell list), the packed
R-tree (``"rtree"``), scipy's cKDTree (``"kdtree"``) and a brute-force
reference (``"brute"``, small clouds only).

>>> import numpy as np
>>> from cnem.spatial import family_search
>>> pts = np.array([[0.0, 0.0], [1.0, 0.0], [2.5, 0.0]])
>>> fam = family_search(pts, 1.6)
>>> [sorted(fam.row(i).tolist()) for i in range(3)]
[[1], [0, 2], [1]]
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numba
import numpy as np
from numpy.typing import ArrayLike
from scipy.spatial import cKDTree

from .. import config
from ..errors import LimitError, SpatialError, check_array, check_choice, check_real
from . import _family_kernels as K
from . import _pair_kernels as P
from .._parallel import work_chunks
from .rtree import RTree, as_points, check_period, unit_scale

__all__ = ["Family", "family_search", "METHODS"]

METHODS = ("auto", "rtree", "cells", "kdtree", "brute")



@dataclass(frozen=True, repr=False)
class Family:
    """Families of a point cloud in CSR form.

    Attributes
    ----------
    offsets : (n + 1,) int64 ndarray
    indices : (k,) int32 or int64 ndarray
        Members of the family of ``i``: ``indices[offsets[i]:offsets[i + 1]]``
        (int32 when the cloud has fewer than 2**31 points).
    horizon : (n,) ndarray
    period : (d,) ndarray
        ``inf`` on open axes.
    """

    offsets: np.ndarray
    indices: np.ndarray
    horizon: np.ndarray
    period: np.ndarray

    def __len__(self):
        return len(self.offsets) - 1

    @property
    def counts(self) -> np.ndarray:
        """(n,) int64 ndarray: family sizes."""
        return np.diff(self.offsets)

    def row(self, i: int) -> np.ndarray:
        """Family members of point ``i``."""
        return self.indices[self.offsets[i]:self.offsets[i + 1]]

    def pairs(self) -> np.ndarray:
        """All bonds as ``(k, 2)`` int64 ``(i, j)`` pairs."""
        rows = np.repeat(np.arange(len(self), dtype=np.int64), self.counts)
        return np.column_stack([rows, self.indices.astype(np.int64)])

    def __repr__(self):
        c = self.counts
        mean = c.mean() if len(c) else 0.0
        return f"<Family {len(self)} points, {len(self.indices)} bonds, mean {mean:.1f} per point>"


def _index_dtype(n):
    return np.int32 if n < 2**31 - 1 else np.int64


def _grid(pts3, hmax, period3, dim, per_horizon=None):
    """Grid of cells over the first ``dim`` axes: origin, cell sizes and counts,
    ``per_horizon`` (default `cnem.config.CELLS_PER_HORIZON`) cells per horizon and at
    most ~4 cells per point."""
    per_horizon = config.CELLS_PER_HORIZON if per_horizon is None else per_horizon
    n = len(pts3)
    # column by column: reductions along axis 0 of an (n, 3) array are ~15x slower
    lo = np.array([pts3[:, k].min() if n else 0.0 for k in range(3)])
    hi = np.array([pts3[:, k].max() if n else 0.0 for k in range(3)])
    span = np.where(np.isfinite(period3), period3, hi - lo)
    size = np.full(3, hmax / per_horizon)
    active = span[:dim] > 0
    volume = np.prod(span[:dim][active]) if active.any() else 0.0
    if volume > 0:                       # sparse clouds: larger cells, memory stays O(n)
        size[:dim] = np.maximum(size[:dim], (volume / (4 * n + 64)) ** (1 / active.sum()))
    nc = np.ones(3, dtype=np.int64)
    origin = np.zeros(3)
    for k in range(dim):
        if np.isfinite(period3[k]):
            nc[k] = max(1, int(np.floor(period3[k] / size[k])))
            size[k] = period3[k] / nc[k]
        else:
            origin[k] = lo[k]
            nc[k] = int(np.floor(span[k] / size[k])) + 1
    size[dim:] = 1.0
    return origin, size, nc


def _cells(pts3, horizon, period3, dim):
    sample = np.empty(0, dtype=_index_dtype(len(pts3)))
    if horizon.min() == horizon.max():
        # one horizon: each pair tested once, columns along two axes swept
        # along the third, which must be a real one: 2-D points go (0, x, y)
        pts_c, per_c = pts3, period3
        if dim == 2:
            axes = [2, 0, 1]
            pts_c, per_c = np.ascontiguousarray(pts3[:, axes]), period3[axes]
        columns = config.COLUMNS_PER_HORIZON        # a number, or one per dimension
        columns = columns[dim] if isinstance(columns, dict) else columns
        origin, size, nc = _grid(pts_c, float(horizon[0]), per_c, 2, columns)
        return P.uniform_family(pts_c, float(horizon[0]), origin, size, nc, per_c, sample,
                                numba.get_num_threads())
    origin, size, nc = _grid(pts3, float(horizon.max()), period3, dim)
    return K.cell_family(pts3, horizon, origin, size, nc, period3, sample, 2 * work_chunks())


def _kdtree(pts, horizon, period):
    box = None if not np.isfinite(period).all() else period
    tree = cKDTree(pts, boxsize=box)
    pairs = tree.query_pairs(float(horizon.max()), output_type="ndarray")
    rows = np.concatenate([pairs[:, 0], pairs[:, 1]]).astype(np.int64)
    cols = np.concatenate([pairs[:, 1], pairs[:, 0]]).astype(np.int64)
    keep = K.exact_filter(pts, rows, cols, horizon, period)
    rows, cols = rows[keep], cols[keep]
    order = np.argsort(rows, kind="stable")
    offsets = np.zeros(len(pts) + 1, dtype=np.int64)
    np.cumsum(np.bincount(rows, minlength=len(pts)), out=offsets[1:])
    return offsets, cols[order]


def _rtree(pts, horizon, period):
    tree = RTree.from_points(pts, period=None if not np.isfinite(period).all() else period)
    return tree.query_ball(pts, horizon, strict=True, exclude_self=True)


def _search_horizons(horizon, points, period):
    """The horizons the kernels search with: each capped at a bound above every distance
    in the body.

    ``2 d`` times the largest extent of the points (per axis, the minimum-image extent
    of a periodic one: at most half its period) exceeds twice the body's diameter,
    so every pair within the original horizon is within the capped one and the
    families do not change; but a horizon far larger than the body (1e200 on a
    unit square) no longer sets `unit_scale`, which would push the scaled
    coordinate differences into underflow and lose every pair.
    """
    span = np.ptp(points, axis=0)
    periodic = np.isfinite(period)
    span[periodic] = np.minimum(span[periodic], 0.5 * period[periodic])
    bound = 2.0 * points.shape[1] * span.max()
    return np.minimum(horizon, bound) if bound > 0.0 else horizon


def choose_method(horizon):
    """The fastest method for the data: the R-tree when the horizon varies a lot
    (graded clouds; a cell list would size its cells for the largest horizon),
    the cell list otherwise."""
    if len(horizon) and horizon.max() > 4.0 * horizon.min():
        return "rtree"
    return "cells"


def family_search(points: ArrayLike, horizon: float | ArrayLike, *,
                  period: ArrayLike | None = None,
                  method: Literal["auto", "rtree", "cells", "kdtree", "brute"] = "auto") -> Family:
    """Family of each point: every ``j`` with ``0 < |x_j - x_i| < horizon_i``.

    Parameters
    ----------
    points : (n, d) array_like
        d = 2 or 3.
    horizon : float or (n,) array_like
        Positive horizon (one per point for graded clouds).
    period : None or (d,) array_like
        Periodic cell ``[0, L_1) x ... x [0, L_d)``; distances use the minimum image.
    method : {"auto", "rtree", "cells", "kdtree", "brute"}
        All give the same sets; ``"auto"`` picks the fastest for the data.

    Returns
    -------
    Family

    Raises
    ------
    SpatialError
        Bad shapes, non-positive horizon, points outside the periodic cell.
    OptionError
        Unknown method.
    LimitError
        ``"brute"`` on more than `cnem.config.BRUTE_LIMIT` points.
    """
    check_choice("method", method, METHODS)
    arr = np.asarray(check_real("points", points, error=SpatialError), dtype=np.float64)
    pts = as_points(arr if arr.size else arr.reshape(0, arr.shape[-1] if arr.ndim == 2 else 2))
    n, d = pts.shape
    per = check_period(period, d, pts)
    h = check_array("horizon", horizon, shape=(n,), broadcast=True, finite=False,
                    error=SpatialError, fix="pass a number or one positive distance per point")
    bad = ~(np.isfinite(h) & (h > 0))
    if bad.any():
        first = int(np.argmax(bad))
        raise SpatialError(f"horizon must be positive and finite, received {float(h[first])!r} at point "
                           f"{first}; pass a positive distance")
    if n == 0:
        return Family(np.zeros(1, dtype=np.int64), np.zeros(0, dtype=np.int32), h, per)
    if method == "auto":
        method = choose_method(h)
    searched = _search_horizons(h, pts, per)
    scale = unit_scale(searched)
    xs, hs, ps = pts * scale, searched * scale, per * scale     # exact: a power of two
    if method == "brute":
        if n > config.BRUTE_LIMIT:
            raise LimitError(f"method='brute' tests all n^2 pairs and is limited to "
                             f"{config.BRUTE_LIMIT} points, received {n}; use method='auto' "
                             f"(or raise cnem.config.BRUTE_LIMIT)")
        offsets, indices = K.brute_family(xs, hs, ps)
    elif method == "cells":
        pts3 = xs                          # the scaled copy: the kernels only read it
        if d == 2:
            pts3 = np.zeros((n, 3))
            pts3[:, :d] = xs
        per3 = np.full(3, np.inf)
        per3[:d] = ps
        offsets, indices = _cells(pts3, hs, per3, d)
    elif method == "kdtree":
        offsets, indices = _kdtree(xs, hs, ps)
    else:
        offsets, indices = _rtree(xs, hs, ps)
    return Family(offsets, indices.astype(_index_dtype(n), copy=False), h, per)
