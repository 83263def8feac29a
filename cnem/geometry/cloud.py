"""`NodeCloud`: the nodes of a domain and the constraint segments between them."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .pslg import SegmentKind

__all__ = ["NodeCloud"]


@dataclass(frozen=True, repr=False)
class NodeCloud:
    """Nodes of a domain, with every boundary, interface and crack split at its nodes.

    Attributes
    ----------
    domain : Domain
    points : (n0, 2) ndarray
        Node coordinates; every corner, interface and crack vertex of the
        domain is one of them.
    segments : (s, 2) int64 ndarray
        Constraint segments as index pairs into ``points``; no node lies
        inside a segment.
    segment_kind : (s,) int8 ndarray
        `SegmentKind` of each segment: 0 boundary, 1 interface, 2 crack.
    spacing : (n0,) ndarray
        Nominal local node spacing at each node.
    """

    domain: object
    points: np.ndarray
    segments: np.ndarray
    segment_kind: np.ndarray
    spacing: np.ndarray

    def __len__(self):
        return len(self.points)

    def __repr__(self):
        counts = ", ".join(f"{np.count_nonzero(self.segment_kind == k)} {k.name.lower()}"
                           for k in SegmentKind)
        return f"<NodeCloud {len(self.points)} nodes, segments: {counts}>"
