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
    domain : Domain or Domain3D
    points : (n0, 2) or (n0, 3) ndarray
        Node coordinates; every corner, interface and crack vertex of the
        domain (every surface vertex in 3-D) is one of them.
    segments : (s, 2) int64 ndarray
        Constraint segments as index pairs into ``points``; no node lies
        inside a segment. In 3-D the feature edges (the borders of the planar
        surface patches) split at their nodes.
    segment_kind : (s,) int8 ndarray
        `SegmentKind` of each segment: 0 boundary, 1 interface, 2 crack.
    spacing : (n0,) ndarray
        Nominal local node spacing at each node.
    boundary_faces : (b, 3) int64 ndarray or None
        3-D only: triangles between the surface nodes that tile every face of the
        domain (each lies in one input face's plane), oriented like the domain's
        faces (normal out of ``boundary_face_regions[:, 0]``).
    boundary_face_regions : (b, 2) int64 ndarray or None
        3-D only: as `Domain3D.face_regions`, the region each triangle points out of
        and the region on its other side (-1 outside the body).
    """

    domain: object
    points: np.ndarray
    segments: np.ndarray
    segment_kind: np.ndarray
    spacing: np.ndarray
    boundary_faces: np.ndarray | None = None
    boundary_face_regions: np.ndarray | None = None

    @property
    def dim(self) -> int:
        """int: 2 or 3, the points' dimension."""
        return self.points.shape[1]

    def __len__(self):
        return len(self.points)

    def __repr__(self):
        if self.boundary_faces is not None:
            return (f"<NodeCloud {len(self.points)} nodes (3-D), {len(self.boundary_faces)} "
                    f"boundary faces>")
        counts = ", ".join(f"{np.count_nonzero(self.segment_kind == k)} {k.name.lower()}"
                           for k in SegmentKind)
        return f"<NodeCloud {len(self.points)} nodes, segments: {counts}>"
