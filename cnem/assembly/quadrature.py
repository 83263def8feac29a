"""Quadrature over the integration-cell polygons (for errors and post-processing)."""

from __future__ import annotations

import numpy as np
import shapely
from skfem.quadrature import get_quadrature
from skfem.refdom import RefTri

__all__ = ["cell_triangles", "cell_quadrature"]


def cell_triangles(cells):
    """Triangles covering every cell polygon exactly.

    A fan from the centroid where the polygon is star-shaped from it (the
    usual case), a constrained Delaunay triangulation of the polygon (shapely)
    elsewhere.

    Returns
    -------
    cell : (t,) int64 ndarray
    corners : (t, 3, 2) ndarray
        Counter-clockwise.
    """
    offsets, verts = cells.offsets, cells.vertices
    counts = np.diff(offsets)
    cell = np.repeat(np.arange(len(counts), dtype=np.int64), counts)
    nxt = np.arange(len(verts)) + 1
    nxt[offsets[1:] - 1] = offsets[:-1]
    centre = cells.centroid()[cell]
    a, b = verts - centre, verts[nxt] - centre
    signed = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    bad = np.zeros(len(counts), dtype=bool)
    bad[cell[signed <= 0.0]] = True
    keep = ~bad[cell]
    corners = [np.stack([centre[keep], verts[keep], verts[nxt][keep]], axis=1)]
    owner = [cell[keep]]
    for c in np.flatnonzero(bad):
        polygon = shapely.Polygon(cells.polygon(c))
        for tri in shapely.constrained_delaunay_triangles(polygon).geoms:
            xy = np.asarray(tri.exterior.coords)[:3]
            if np.cross(xy[1] - xy[0], xy[2] - xy[0]) < 0:
                xy = xy[::-1]
            corners.append(xy[None])
            owner.append(np.array([c]))
    return np.concatenate(owner), np.concatenate(corners)


def cell_quadrature(cells, order=4):
    """Quadrature points and weights on every cell polygon.

    Parameters
    ----------
    cells : Cells
        ``m`` cells.
    order : int
        Polynomial degree integrated exactly on each triangle of the cells.

    Returns
    -------
    cell : (q,) int64 ndarray
        The cell of each point.
    points : (q, 2) ndarray
    weights : (q,) ndarray
        ``sum(weights[cell == k]) == cells.area[k]``.
    """
    owner, corners = cell_triangles(cells)
    ref, w = get_quadrature(RefTri, order)          # reference triangle, area 1/2
    e1 = corners[:, 1] - corners[:, 0]
    e2 = corners[:, 2] - corners[:, 0]
    jac = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    points = (corners[:, None, 0] + ref[0][None, :, None] * e1[:, None]
              + ref[1][None, :, None] * e2[:, None])
    weights = jac[:, None] * w[None, :]
    return np.repeat(owner, len(w)), points.reshape(-1, 2), weights.reshape(-1)
