"""Planar straight-line graph (PSLG) of a domain: vertices and constraint edges.

Regions, holes and cracks are turned into one set of vertices and straight
edges in which two regions that share a boundary share exactly the same edges
(vertices of one side that lie on an edge of the other are inserted into it),
and crack ends that touch a boundary split that boundary edge.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from ..errors import GeometryError

__all__ = ["PSLG", "SegmentKind", "BOUNDARY", "INTERFACE", "CRACK", "build_pslg",
           "segment_projection"]


class SegmentKind(enum.IntEnum):
    """Kind of a constraint edge or segment, stored as int8 in ``PSLG.kind``,
    ``NodeCloud.segment_kind`` and ``Model.segment_kind``; compare arrays with the
    names (``model.segment_kind == SegmentKind.CRACK``)."""

    BOUNDARY = 0        #: one region on one side (outer boundary or a hole)
    INTERFACE = 1       #: a region on each side (a material interface)
    CRACK = 2           #: a crack (in a Model: one segment per crack face)


BOUNDARY, INTERFACE, CRACK = SegmentKind.BOUNDARY, SegmentKind.INTERFACE, SegmentKind.CRACK


@dataclass(frozen=True)
class PSLG:
    """Vertices and constraint edges of a domain.

    Attributes
    ----------
    vertices : (v, 2) ndarray
    edges : (e, 2) int64 ndarray
        Vertex index pairs, each straight edge once.
    kind : (e,) int8 ndarray
        `SegmentKind` values: ``BOUNDARY`` (one region on one side), ``INTERFACE``
        (two regions) or ``CRACK``.
    """

    vertices: np.ndarray
    edges: np.ndarray
    kind: np.ndarray


def ring_coordinates(polygon):
    """Open coordinate arrays ``(k, 2)`` of a polygon's exterior then holes."""
    rings = [polygon.exterior] + list(polygon.interiors)
    return [np.asarray(r.coords, dtype=float)[:-1, :2] for r in rings]


def _merge_vertices(points, tol):
    """Merge points closer than ``tol``; return (unique points, index map)."""
    pairs = cKDTree(points).query_pairs(tol, output_type="ndarray")
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])),
                       shape=(len(points), len(points)))
    _, label = connected_components(graph, directed=False)
    first = np.full(label.max() + 1, len(points))
    np.minimum.at(first, label, np.arange(len(points)))   # keep each group's first point
    order = np.argsort(first)
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    return points[first[order]], rank[label]


def segment_projection(points, a, b):
    """Position along and distance from segments of points.

    Parameters
    ----------
    points, a, b : (p, 2) or (2,) array_like
        Points and segment ends (broadcast together).

    Returns
    -------
    t : (p,) ndarray
        Parameter of the projection on the line, 0 at ``a`` and 1 at ``b``.
    dist : (p,) ndarray
        Distance from the line through ``a`` and ``b``.
    """
    points, a, b = (np.atleast_2d(np.asarray(v, dtype=float)) for v in (points, a, b))
    d, rel = b - a, points - a
    length2 = np.einsum("ij,ij->i", d, d)
    t = np.einsum("ij,ij->i", rel, d) / length2
    dist = np.abs(rel[:, 0] * d[:, 1] - rel[:, 1] * d[:, 0]) / np.sqrt(length2)
    return t, dist


def _split_edge(a, b, vertices, tree, tol):
    """Indices of vertices strictly inside segment ``a-b`` sorted along it."""
    pa, pb = vertices[a], vertices[b]
    mid, half = 0.5 * (pa + pb), 0.5 * np.linalg.norm(pb - pa)
    cand = np.asarray(tree.query_ball_point(mid, half + tol), dtype=np.int64)
    cand = cand[(cand != a) & (cand != b)]
    if cand.size == 0:
        return np.empty(0, dtype=np.int64)
    t, dist = segment_projection(vertices[cand], pa, pb)
    keep = (dist <= tol) & (t > 0) & (t < 1)
    order = np.argsort(t[keep])
    return cand[keep][order]


def build_pslg(polylines, kinds_hint, tol, extra_vertices=None):
    """Build a PSLG from rings and crack polylines.

    Parameters
    ----------
    polylines : list of ((k, 2) ndarray, closed : bool)
        Region rings (closed) and crack polylines (open).
    kinds_hint : list of int
        ``-1`` for a ring, ``CRACK`` for a crack, per polyline.
    tol : float
        Absolute merge / on-segment tolerance.
    extra_vertices : (q, 2) ndarray, optional
        Points to insert into every edge they lie on (crack-interface crossings).

    Returns
    -------
    PSLG
    """
    extra = np.empty((0, 2)) if extra_vertices is None else np.asarray(extra_vertices, float)
    pool = np.concatenate([p for p, _ in polylines] + [extra.reshape(-1, 2)])
    vertices, inverse = _merge_vertices(pool, tol)
    tree = cKDTree(vertices)
    start = 0
    ring_edges, crack_edges = [], []
    for (pts, closed), hint in zip(polylines, kinds_hint):
        ids = inverse[start:start + len(pts)]
        start += len(pts)
        seq = np.append(ids, ids[0]) if closed else ids
        target = crack_edges if hint == CRACK else ring_edges
        for a, b in zip(seq[:-1], seq[1:]):
            chain = np.concatenate([[a], _split_edge(a, b, vertices, tree, tol), [b]])
            target.extend(zip(chain[:-1], chain[1:]))
    ring = np.sort(np.asarray(ring_edges, dtype=np.int64).reshape(-1, 2), axis=1)
    ring_u, counts = np.unique(ring, axis=0, return_counts=True)
    kind = np.where(counts >= 2, INTERFACE, BOUNDARY).astype(np.int8)
    edges, kinds = [ring_u], [kind]
    if crack_edges:
        crack = np.unique(np.sort(np.asarray(crack_edges, dtype=np.int64), axis=1), axis=0)
        on_ring = (crack[:, None, :] == ring_u[None, :, :]).all(-1).any(-1)
        if on_ring.any():
            a, b = vertices[crack[on_ring][0]]
            raise GeometryError(
                f"a crack runs along a region boundary or interface between {a} and {b}; "
                "cracks must lie inside a region (a debonded interface is not supported): "
                "move the crack off the boundary")
        edges.append(crack)
        kinds.append(np.full(len(crack), CRACK, dtype=np.int8))
    return PSLG(vertices, np.concatenate(edges), np.concatenate(kinds))
