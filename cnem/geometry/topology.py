"""Triangle adjacency, vertex stars and circumcentres of a triangulation."""

from __future__ import annotations

import numpy as np

from ._mesh_kernels import circumcentres, cut_regions, edge_neighbors, vertex_star

__all__ = ["triangle_neighbors", "cut_between_regions", "vertex_triangles", "circumcenters",
           "constraint_edges"]


def triangle_neighbors(triangles: np.ndarray, region: np.ndarray | None = None, *,
                       star: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
    """Neighbour across each edge; edges between regions count as boundaries.

    Parameters
    ----------
    triangles : (t, 3) int ndarray
        A triangulation: each edge in at most two triangles.
    region : (t,) int ndarray, optional
        When given, neighbours in another region are reported as -1.
    star : (offsets, indices), optional
        `vertex_triangles` of ``triangles``, if already known.

    Returns
    -------
    (t, 3) int64 ndarray
        ``nb[t, k]`` is the triangle across the edge opposite vertex ``k``, -1 if none.
    """
    triangles = np.ascontiguousarray(triangles, dtype=np.int64)
    n = int(triangles.max()) + 1 if len(triangles) else 0
    nb = edge_neighbors(triangles, *(vertex_star(triangles, n) if star is None else star))
    return nb if region is None else cut_between_regions(nb, region)


def cut_between_regions(nb: np.ndarray, region: np.ndarray) -> np.ndarray:
    """Neighbours ``(t, 3)`` with -1 where the neighbour lies in another region (a copy)."""
    return cut_regions(np.ascontiguousarray(nb, dtype=np.int64),
                       np.ascontiguousarray(region, dtype=np.int64))


def vertex_triangles(triangles: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """CSR of the triangles around each vertex.

    Returns
    -------
    offsets : (n + 1,) int64 ndarray
    indices : (3 t,) int64 ndarray
        Triangle indices, grouped by vertex, in increasing order within each group.
    """
    return vertex_star(np.ascontiguousarray(triangles, dtype=np.int64), n)


def circumcenters(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Circumcentres of triangles, computed relative to the vertex opposite the longest
    edge (`._mesh_kernels.circumcentres`).

    Returns
    -------
    (t, 2) ndarray
    """
    return circumcentres(np.ascontiguousarray(points, dtype=np.float64),
                         np.ascontiguousarray(triangles, dtype=np.int64))


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
