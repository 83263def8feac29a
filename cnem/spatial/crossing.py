"""Remove bonds that cross a set of segments (pre-cracks, interfaces)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from .. import config
from ..errors import SpatialError, check_array
from . import _family_kernels as K
from .family import Family
from .rtree import RTree

__all__ = ["remove_crossing"]


def _far_ends(seg):
    """(s, 2, 2): for each segment end, the far end of another segment sharing it (NaN if none)."""
    ends = seg.reshape(-1, 2)                       # end e of segment s is row 2 s + e
    far = np.full_like(ends, np.nan)
    _, group, size = np.unique(ends, axis=0, return_inverse=True, return_counts=True)
    group = group.reshape(-1)
    for g in np.flatnonzero(size == 2):
        a, b = np.flatnonzero(group == g)
        far[a] = ends[b ^ 1]                        # the other end of b's segment
        far[b] = ends[a ^ 1]
    return far.reshape(-1, 2, 2)


def remove_crossing(family: Family, points: ArrayLike, segments: ArrayLike) -> Family:
    """Drop every bond ``(i, j)`` whose straight segment crosses a segment.

    A bond crosses when the interiors cross, or when it passes through an
    inner vertex of a polyline (two segments sharing an end) whose segments
    leave on opposite sides of it. A bond that only touches (an end on a
    segment, passing through a crack tip, running along a segment) is kept: a
    point on a crack line, or a crack tip, does not cut bonds. A point within
    `cnem.config.ROUNDOFF_ULPS` round-offs of the coordinates (``eps`` times their
    largest magnitude) from a line counts as on it, so points put on a crack stay
    on it in other units or far from the origin.

    Parameters
    ----------
    family : Family
        Open (non-periodic) 2-D families.
    points : (n, 2) array_like
        The points the family was built on.
    segments : (s, 2, 2) array_like
        Segment end points.

    Returns
    -------
    Family
        Same points and horizon, fewer bonds.
    """
    pts = check_array("points", points, error=SpatialError,
                      fix="pass the points the family was searched on")
    seg = check_array("segments", segments, error=SpatialError,
                      fix="pass one pair of end points per segment")
    if seg.ndim == 2 and seg.shape[1] == 4:
        seg = seg.reshape(-1, 2, 2)
    if seg.ndim != 3 or seg.shape[1:] != (2, 2):
        raise SpatialError(f"segments: expected an (s, 2, 2) array of end points, received "
                           f"shape {seg.shape}; pass one pair of points per segment")
    far = _far_ends(seg)
    seg = np.ascontiguousarray(seg.reshape(-1, 4))
    if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) != len(family):
        raise SpatialError(f"points: expected ({len(family)}, 2) 2-D points of the family, "
                           f"received shape {pts.shape}; pass the points it was searched on")
    if np.isfinite(family.period).any():
        raise SpatialError("remove_crossing: expected a family without period, received a "
                           "periodic one (a bond's segment is ambiguous across the cell "
                           "boundary); search the family without period= to cut bonds")
    if len(seg) == 0 or len(family.indices) == 0:
        return family
    lo = np.minimum(seg[:, :2], seg[:, 2:])
    hi = np.maximum(seg[:, :2], seg[:, 2:])
    tree = RTree(lo, hi)
    reach = np.zeros(len(pts))
    idx = family.indices.astype(np.int64)
    rows = np.repeat(np.arange(len(pts)), family.counts)
    np.maximum.at(reach, rows, np.linalg.norm(pts[idx] - pts[rows], axis=1))
    cand_off, cand_idx = tree.query_ball(pts, reach)
    # within the coordinates' round-off of a line is on it (any units, any origin)
    tol = config.ROUNDOFF_ULPS * np.finfo(float).eps * max(np.abs(pts).max(), np.abs(seg).max())
    keep = K.crossing_mask(pts, family.offsets, idx, seg, far, cand_off, cand_idx, tol)
    counts = np.bincount(rows[keep], minlength=len(pts))
    offsets = np.zeros(len(pts) + 1, dtype=np.int64)
    np.cumsum(counts, out=offsets[1:])
    return Family(offsets, family.indices[keep], family.horizon, family.period)
