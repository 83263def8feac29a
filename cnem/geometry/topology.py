"""Triangle adjacency, vertex stars and circumcentres of a triangulation."""

from __future__ import annotations

import numpy as np

__all__ = ["triangle_neighbors", "cut_between_regions", "vertex_triangles", "circumcenters",
           "constraint_edges"]


def triangle_neighbors(triangles: np.ndarray, region: np.ndarray | None = None) -> np.ndarray:
    """Neighbour across each edge; edges between regions count as boundaries.

    Parameters
    ----------
    triangles : (t, 3) int ndarray
    region : (t,) int ndarray, optional
        When given, neighbours in another region are reported as -1.

    Returns
    -------
    (t, 3) int64 ndarray
        ``nb[t, k]`` is the triangle across the edge opposite vertex ``k``, -1 if none.
    """
    t = len(triangles)
    a = triangles[:, [1, 2, 0]].ravel().astype(np.int64)
    b = triangles[:, [2, 0, 1]].ravel().astype(np.int64)
    n = int(triangles.max()) + 1 if t else 0
    key = np.minimum(a, b) * n + np.maximum(a, b)
    order = np.argsort(key, kind="stable")
    pair = np.flatnonzero(key[order][1:] == key[order][:-1])
    nb = np.full(3 * t, -1, dtype=np.int64)
    nb[order[pair]] = order[pair + 1] // 3
    nb[order[pair + 1]] = order[pair] // 3
    nb = nb.reshape(t, 3)
    return nb if region is None else cut_between_regions(nb, region)


def cut_between_regions(nb: np.ndarray, region: np.ndarray) -> np.ndarray:
    """Neighbours ``(t, 3)`` with -1 where the neighbour lies in another region (a copy)."""
    nb = nb.copy()
    other = nb >= 0
    cross = np.zeros_like(other)
    cross[other] = region[nb[other]] != np.repeat(region[:, None], 3, axis=1)[other]
    nb[cross] = -1
    return nb


def vertex_triangles(triangles: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """CSR of the triangles around each vertex.

    Returns
    -------
    offsets : (n + 1,) int64 ndarray
    indices : (3 t,) int64 ndarray
        Triangle indices, grouped by vertex.
    """
    flat = triangles.ravel()
    order = np.argsort(flat, kind="stable")
    offsets = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(np.bincount(flat, minlength=n), out=offsets[1:])
    return offsets, (order // 3).astype(np.int64)


def circumcenters(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Circumcentres of triangles, computed relative to the first vertex.

    Returns
    -------
    (t, 2) ndarray
    """
    a = points[triangles[:, 0]]
    b = points[triangles[:, 1]] - a
    c = points[triangles[:, 2]] - a
    d = 2.0 * (b[:, 0] * c[:, 1] - b[:, 1] * c[:, 0])
    b2, c2 = (b * b).sum(1), (c * c).sum(1)
    ux = (c[:, 1] * b2 - b[:, 1] * c2) / d
    uy = (b[:, 0] * c2 - c[:, 0] * b2) / d
    return a + np.column_stack([ux, uy])


def constraint_edges(triangles: np.ndarray, nb: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Edges with no neighbour (boundary, crack face, or interface side).

    Returns
    -------
    edges : (e, 2) int64 ndarray
        Vertex pairs, oriented counter-clockwise with respect to their triangle.
    owner : (e,) int64 ndarray
        The triangle each edge belongs to.
    """
    t, k = np.nonzero(nb < 0)
    a = triangles[t, (k + 1) % 3]
    b = triangles[t, (k + 2) % 3]
    return np.column_stack([a, b]).astype(np.int64), t.astype(np.int64)
