"""Constrained Delaunay triangulation of a node cloud with `triangle`, no Steiner points."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import triangle

from ..errors import GeometryError
from ._mesh_kernels import canonical_order, orient_and_centroids
from .pslg import segment_projection

if TYPE_CHECKING:
    from .cloud import NodeCloud

__all__ = ["constrained_delaunay"]


def _steiner_error(points, segments, extra, tol):
    """Name the constraint segments that meet at inserted (Steiner) points."""
    a, b = points[segments[:, 0]], points[segments[:, 1]]
    msgs = []
    for p in extra[:3]:
        t, dist = segment_projection(p, a, b)
        hit = np.flatnonzero((dist <= max(tol, 1e-12)) & (t > -1e-12) & (t < 1 + 1e-12))
        msgs.append(f"at ({p[0]:.6g}, {p[1]:.6g}) segments "
                    + ", ".join(f"{s} {points[segments[s]].tolist()}" for s in hit[:4]))
    return GeometryError(
        f"the constraint segments intersect away from nodes ({len(extra)} crossing points): "
        + "; ".join(msgs) + "; boundaries, interfaces and cracks may only meet at shared vertices")


def constrained_delaunay(cloud: NodeCloud) -> tuple[np.ndarray, np.ndarray]:
    """Triangulate a `NodeCloud` respecting all its segments.

    Parameters
    ----------
    cloud : NodeCloud

    Returns
    -------
    triangles : (t, 3) int64 ndarray
        Counter-clockwise triangles inside the domain.
    region : (t,) int64 ndarray
        Region index of each triangle.

    Raises
    ------
    GeometryError
        If `triangle` had to insert a Steiner point (segments cross), a node is
        not a vertex of any triangle (duplicated or outside the domain), or the
        nodes make no triangle at all (collinear).
    """
    points = np.ascontiguousarray(cloud.points, dtype=float)
    segments = np.ascontiguousarray(cloud.segments, dtype=np.int32)
    out = triangle.triangulate({"vertices": points, "segments": segments}, "pQ")
    verts = out["vertices"]
    if len(verts) != len(points) or not np.array_equal(verts, points):
        extra = verts[len(points):]
        raise _steiner_error(points, cloud.segments, extra, cloud.domain.tolerance)
    if len(out.get("triangles", ())) == 0:
        raise GeometryError(
            f"the {len(points)} nodes make no triangle: they are (to round-off) collinear; a "
            f"body this thin ({cloud.domain.area:.3g} in area over a diameter of "
            f"{cloud.domain.diameter:.3g}) needs a spacing below its thickness, or model it "
            f"as a line")
    tri = np.ascontiguousarray(out["triangles"])           # int32 from triangle, ours
    region = cloud.domain.region_of(orient_and_centroids(points, tri))
    inside = region >= 0
    # an order that depends on the triangles alone: `triangle` numbers them as its flips
    # went, and those change with the triangles it removes afterwards (in holes: the same
    # body moved elsewhere may triangulate a cocircular hole otherwise), and so would the
    # crack faces' node copies and every cell's first vertex
    tri, order = canonical_order(tri[inside], len(points))
    region = region[inside][order]
    used = np.zeros(len(points), dtype=bool)
    used[tri.ravel()] = True
    if not used.all():
        lost = np.flatnonzero(~used)
        raise GeometryError(
            f"{lost.size} nodes are not vertices of the triangulation (duplicated or outside "
            f"the domain), first (index: point) "
            + ", ".join(f"{i}: {points[i].tolist()}" for i in lost[:5])
            + "; remove duplicated nodes and nodes outside the domain")
    return tri, region
