"""`RTree`: a packed R-tree over boxes or points, bulk-loaded by Sort-Tile-Recursive.

>>> import numpy as np
>>> from cnem.spatial import RTree
>>> tree = RTree.from_points(np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 3.0]]))
>>> offsets, indices = tree.query_ball(np.array([[0.0, 0.0]]), 1.5)
>>> sorted(indices.tolist())
[0, 1]
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from .. import config
from .._parallel import work_chunks
from ..errors import SpatialError, check_array, check_points, check_real
from . import _rtree_kernels as K

__all__ = ["RTree", "check_period", "as_points"]


def as_points(points: ArrayLike, name: str = "points") -> np.ndarray:
    """Validate a ``(n, d)`` float64 C-contiguous array with d = 2 or 3, finite and
    below `cnem.config.COORDINATE_LIMIT` (`cnem.errors.check_points`)."""
    return check_points(name, points, error=SpatialError)


def check_period(period: ArrayLike | None, dim: int, *points: np.ndarray) -> np.ndarray:
    """Period as a ``(d,)`` array (``inf`` where not periodic); points must lie in ``[0, L)``."""
    if period is None:
        return np.full(dim, np.inf)
    per = np.asarray(check_real("period", period, error=SpatialError), dtype=np.float64)
    if per.ndim > 1 or per.size not in (1, dim):
        raise SpatialError(f"period: expected None, a number or {dim} lengths, received "
                           f"{period!r}")
    per = np.broadcast_to(per, (dim,)).copy()
    if not (np.isfinite(per) & (per > 0)).all():
        raise SpatialError(f"period: expected {dim} positive finite lengths, received {period!r}")
    for arr in points:
        bad = ((arr < 0) | (arr >= per)).any(axis=1)
        if bad.any():
            first = np.flatnonzero(bad)[:3]
            raise SpatialError(
                f"{bad.sum()} points lie outside the periodic cell [0, L) with L = {per.tolist()}, "
                f"first {arr[first].tolist()}; wrap them with np.mod(points, L) first")
    return per


def unit_scale(lengths: np.ndarray) -> float:
    """Power of two that brings the largest of ``lengths`` (horizons, radii) to about 1.

    Scaling coordinates, horizons and periods by a power of two is exact, so the
    families are unchanged wherever the squared distances were representable; it
    keeps them representable (neither subnormal nor overflowing) for bodies of
    any size, e.g. coordinates of order 1e-300, whose squared distances would
    underflow to zero.
    """
    return float(np.ldexp(1.0, -int(np.frexp(lengths.max())[1])))


def _str_order(centres, fanout):
    """Sort-Tile-Recursive order of box centres ``(b, d)``."""
    b, d = centres.shape
    leaves = -(-b // fanout)
    slabs = int(np.ceil(leaves ** (1.0 / d)))
    perm = np.argsort(centres[:, 0], kind="stable").astype(np.int64)
    run = b
    for k in range(1, d):
        run = -(-run // slabs)
        run = -(-run // fanout) * fanout
        K.sort_within(np.ascontiguousarray(centres[:, k]), perm, max(run, 1))
    return perm


class RTree:
    """Packed R-tree (STR bulk loading) over axis-aligned boxes, optionally periodic.

    Parameters
    ----------
    lo, hi : (b, d) array_like
        Lower and upper corners, ``d`` = 2 or 3. Under periodic boundaries a
        box may straddle the cell boundary: its centre must lie in ``[0, L)``.
    period : None or (d,) array_like
        Lengths of the periodic cell ``[0, L_1) x ... x [0, L_d)``.

    Notes
    -----
    Boxes and nodes are kept in centre / half-width form; node boxes grow by
    the minimum image of their children (Niina, Algorithms 1-2) and queries
    compare wrapped centre distances (Algorithms 3-5). All queries are exact.
    """

    def __init__(self, lo: ArrayLike, hi: ArrayLike, *, period: ArrayLike | None = None) -> None:
        self._corners = None
        lo, hi = as_points(lo, "lo"), as_points(hi, "hi")
        if lo.shape != hi.shape:
            raise SpatialError(f"lo and hi must have the same shape, received {lo.shape} and "
                               f"{hi.shape}; pass one lower and one upper corner per box")
        if (hi < lo).any():
            raise SpatialError(f"{int((hi < lo).any(axis=1).sum())} boxes have hi < lo; "
                             "pass lower corners as lo and upper corners as hi")
        self._corners = (lo, hi)
        self._build(0.5 * (lo + hi), 0.5 * (hi - lo), period)

    @classmethod
    def from_points(cls, points: ArrayLike, *, period: ArrayLike | None = None) -> RTree:
        """A tree over points (zero-size boxes).

        Parameters
        ----------
        points : (n, d) array_like
        period : None or (d,) array_like
        """
        pts = as_points(points)
        tree = cls.__new__(cls)
        tree._corners = (pts, pts)
        tree._build(pts, np.zeros_like(pts), period)
        return tree

    @classmethod
    def from_points_in(cls, points: ArrayLike, lo: ArrayLike, hi: ArrayLike,
                       extent: tuple[np.ndarray, np.ndarray]) -> tuple[RTree, np.ndarray]:
        """A tree over the 2-D points that may lie in the closed boxes ``[lo, hi]``:
        those in the cells of a coarse grid (about 4 points per cell) that the boxes
        meet. A query by a box that holds one of ``[lo, hi]`` finds every point of
        ``points`` in that one (the points left out lie in no box), at the cost of
        the points near the boxes, not of all of them.

        Parameters
        ----------
        points : (n, 2) array_like
        lo, hi : (b, 2) array_like
        extent : two (2,) ndarray
            The points' bounding box (`cnem._predicates.bounding_box`).

        Returns
        -------
        tree : RTree
            Over ``points[subset]``: its entry ``k`` is point ``subset[k]``.
        subset : (m,) int64 ndarray
            Increasing.
        """
        pts = np.ascontiguousarray(points, dtype=np.float64)  # those in the tree are checked
        if pts.ndim != 2 or pts.shape[1] != 2:
            raise SpatialError(f"from_points_in: expected (n, 2) points, received shape "
                               f"{pts.shape}; use RTree.from_points in 3-D")
        g = max(1, int(np.sqrt(len(pts)) / 2))
        width = extent[1] - extent[0]
        inv = np.divide(g, width, out=np.zeros(2), where=width > 0)
        subset = np.flatnonzero(K.grid_cover(pts, as_points(lo, "lo"), as_points(hi, "hi"),
                                             np.asarray(extent[0], dtype=np.float64), inv, g))
        return cls.from_points(pts[subset]), subset

    def _build(self, centre, half, period):
        b, d = centre.shape
        self.dim, self.fanout = d, config.FANOUT          # children per node, fixed per tree
        self.period = check_period(period, d, centre)
        if self.periodic:
            too_big = (half > 0.5 * self.period).any(axis=1)
            if too_big.any():
                raise SpatialError(f"expected boxes no wider than the periodic cell "
                                   f"{self.period.tolist()}, received {too_big.sum()} boxes wider than the periodic "
                                   f"cell; enlarge the period or split the boxes")
        self.size = b
        if b == 0:
            self.order = np.zeros(0, dtype=np.int64)
            return
        order = _str_order(centre, self.fanout)
        sizes = [b]
        while sizes[-1] > 1:
            sizes.append(-(-sizes[-1] // self.fanout))
        level_start = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
        total = int(level_start[-1])
        cen, hw = np.empty((total, d)), np.empty((total, d))
        first, cnt = np.zeros(total, dtype=np.int64), np.zeros(total, dtype=np.int64)
        cen[:b], hw[:b] = centre[order], half[order]
        for lev in range(1, len(sizes)):
            K.build_level(cen, hw, first, cnt, level_start[lev - 1], sizes[lev - 1], self.fanout,
                          level_start[lev], self.period)
            if sizes[lev] > self.fanout:     # STR again on this level's nodes before grouping them
                perm = _str_order(cen[level_start[lev]:level_start[lev + 1]], self.fanout)
                for arr in (cen, hw, first, cnt):
                    arr[level_start[lev]:level_start[lev + 1]] = \
                        arr[level_start[lev]:level_start[lev + 1]][perm]
        self.order, self.level_start = order, level_start
        self.lo = np.ascontiguousarray(self._corners[0][order])
        self.hi = np.ascontiguousarray(self._corners[1][order])
        self.centre, self.half, self.first, self.count = cen, hw, first, cnt

    # ----------------------------------------------------------------- queries
    def _query(self, qcen, qhalf, radius, kind, exclude_zero=False, qlo=None, qhi=None,
               scale=1.0):
        """The kernel's bulk query; with ``scale`` (a power of two) on copies of the tree
        and the queries scaled by it (exact), for radii whose squares would leave the
        float range."""
        if self.size == 0 or len(qcen) == 0:
            return np.zeros(len(qcen) + 1, dtype=np.int64), np.zeros(0, dtype=np.int64)
        qlo = qcen if qlo is None else qlo
        qhi = qcen if qhi is None else qhi
        tree = (self.centre, self.half, self.period, self.lo, self.hi)
        query = (qcen, qhalf, radius, qlo, qhi)
        if scale != 1.0:
            tree, query = ([a * scale for a in arrays] for arrays in (tree, query))
        cen, half, period, lo, hi = tree
        qcen, qhalf, radius, qlo, qhi = query
        return K.query(cen, half, self.first, self.count, self.size, self.depth, self.fanout,
                       self.order, qcen, qhalf, radius, kind, period, exclude_zero,
                       work_chunks(), lo, hi, qlo, qhi)

    def _points(self, points, name, *, in_cell=True):
        arr = np.asarray(check_real(name, points, error=SpatialError), dtype=np.float64)
        if arr.size == 0:
            return np.zeros((0, self.dim))
        pts = as_points(arr, name)
        if pts.shape[1] != self.dim:
            raise SpatialError(f"{name}: expected dimension {self.dim}, received {pts.shape[1]}; "
                               f"query with points of the tree's dimension")
        if in_cell and self.periodic:
            check_period(self.period, self.dim, pts)
        return pts

    @property
    def periodic(self) -> bool:
        """bool: whether the tree has periodic boundaries."""
        return bool(np.isfinite(self.period).all())

    def query(self, qlo: ArrayLike, qhi: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """Boxes intersecting each query box (closed boxes).

        Parameters
        ----------
        qlo, qhi : (q, d) array_like

        Returns
        -------
        offsets : (q + 1,) int64 ndarray
        indices : (k,) int64 ndarray
            Box indices hitting query ``i``: ``indices[offsets[i]:offsets[i + 1]]``.
        """
        qlo = self._points(qlo, "qlo", in_cell=False)
        qhi = self._points(qhi, "qhi", in_cell=False)
        if qlo.shape != qhi.shape or (qhi < qlo).any():
            raise SpatialError(f"qlo and qhi must have the same shape with qlo <= qhi, received "
                               f"shapes {qlo.shape} and {qhi.shape}; swap the corners")
        qcen = 0.5 * (qlo + qhi)
        if self.periodic:                # translate each query box into the cell
            shift = self.period * np.floor(qcen / self.period)
            qlo, qhi = qlo - shift, qhi - shift
            qcen = 0.5 * (qlo + qhi)
        return self._query(qcen, 0.5 * (qhi - qlo), np.zeros(len(qlo)), K.INTERSECT,
                           qlo=qlo, qhi=qhi)

    def query_ball(self, points: ArrayLike, r: float | ArrayLike, *, strict: bool = False,
                   exclude_self: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """Boxes within distance ``r`` of each point.

        Parameters
        ----------
        points : (q, d) array_like
        r : float or (q,) array_like
        strict : bool
            ``distance < r`` instead of ``distance <= r``.
        exclude_self : bool
            Leave out boxes at distance exactly zero whose centre is the point
            (the point itself in a tree of points).

        Returns
        -------
        offsets : (q + 1,) int64 ndarray
        indices : (k,) int64 ndarray
        """
        pts = self._points(points, "points")
        radius = check_array("r", r, shape=(len(pts),), broadcast=True, nonnegative=True,
                             error=SpatialError, fix="pass one distance >= 0, or one per point")
        kind = K.BALL_OPEN if strict else K.BALL_CLOSED
        # the ball test squares distances: at radii near the ends of the float range
        # (1e-300, 1e300) they would underflow or overflow, so the test then runs on
        # copies scaled by the power of two that brings the largest radius to about 1
        scale = unit_scale(radius) if len(radius) and radius.max() > 0.0 else 1.0
        if 2.0 ** -400 <= scale <= 2.0 ** 400:
            scale = 1.0
        return self._query(pts, np.zeros_like(pts), radius, kind, exclude_self, scale=scale)

    def nearest(self, points: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """Nearest box to each point.

        Returns
        -------
        index : (q,) int64 ndarray
            Smallest box index among ties; -1 for an empty tree.
        distance : (q,) ndarray
        """
        pts = self._points(points, "points")
        if self.size == 0:
            return np.full(len(pts), -1, dtype=np.int64), np.full(len(pts), np.inf)
        return K.nearest(self.centre, self.half, self.first, self.count, self.size, self.depth,
                         self.fanout, self.order, pts, self.period, work_chunks())

    def node_boxes(self, level: int) -> tuple[np.ndarray, np.ndarray]:
        """Centre and half-width of the nodes at ``level`` (0: the boxes, sorted)."""
        a, b = self.level_start[level], self.level_start[level + 1]
        return self.centre[a:b], self.half[a:b]

    @property
    def depth(self) -> int:
        """int: number of levels above the boxes."""
        return 0 if self.size == 0 else len(self.level_start) - 2

    def __len__(self):
        return self.size

    def __repr__(self):
        per = f"period {self.period.tolist()}" if self.periodic else "open"
        return f"<RTree {self.size} boxes, {self.dim}-D, depth {self.depth}, {per}>"
