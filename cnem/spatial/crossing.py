"""Remove bonds that cross a set of segments (pre-cracks, interfaces)."""

from __future__ import annotations

import numpy as np

from . import _family_kernels as K
from .family import Family
from .rtree import RTree

__all__ = ["remove_crossing"]


def remove_crossing(family, points, segments):
    """Drop every bond ``(i, j)`` whose straight segment properly crosses a segment.

    A bond that only touches a segment (an end on it, or passing through a
    segment's end point) is kept: a point on a crack line, or a crack tip, does
    not cut bonds.

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
    pts = np.ascontiguousarray(points, dtype=np.float64)
    seg = np.ascontiguousarray(np.asarray(segments, dtype=np.float64).reshape(-1, 4))
    if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) != len(family):
        raise ValueError(f"points: expected ({len(family)}, 2) 2-D points of the family, "
                         f"received shape {pts.shape}")
    if np.isfinite(family.period).any():
        raise ValueError("remove_crossing does not support periodic families: a bond's "
                         "segment is ambiguous across the cell boundary")
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
    keep = K.crossing_mask(pts, family.offsets, idx, seg, cand_off, cand_idx)
    counts = np.bincount(rows[keep], minlength=len(pts))
    offsets = np.zeros(len(pts) + 1, dtype=np.int64)
    np.cumsum(counts, out=offsets[1:])
    return Family(offsets, family.indices[keep], family.horizon, family.period)
