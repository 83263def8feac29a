"""Slow, obviously-correct reference implementations used by the tests."""

from __future__ import annotations

import numpy as np
import shapely


def _orient(a, b, c):
    return (b[..., 0] - a[..., 0]) * (c[..., 1] - a[..., 1]) - (b[..., 1] - a[..., 1]) * (c[..., 0] - a[..., 0])


def blocked(x, y, seg_a, seg_b, eps=1e-12):
    """Whether segment x-y touches any segment (seg_a, seg_b) anywhere but at ``y``.

    Parameters
    ----------
    x, y : (2,) ndarray
    seg_a, seg_b : (s, 2) ndarray

    Returns
    -------
    bool
    """
    at_y = (np.linalg.norm(seg_a - y, axis=1) <= eps) | (np.linalg.norm(seg_b - y, axis=1) <= eps)
    a, b = seg_a[~at_y], seg_b[~at_y]
    if len(a) == 0:
        return False
    d1 = _orient(a, b, x[None])
    d2 = _orient(a, b, y[None])
    d3 = _orient(x[None], y[None], a)
    d4 = _orient(x[None], y[None], b)
    proper = (d1 * d2 < 0) & (d3 * d4 < 0)
    return bool(proper.any())


def _enters_triangle_of(model, j, x):
    """Whether the segment from node ``j`` towards ``x`` starts inside a triangle of ``j``.

    This is the side rule at crack faces and at reflex corners: a node on a
    crack face sees only its own side.
    """
    p = model.nodes[j]
    y = p + 1e-7 * (x - p)
    tris = model.triangles[(model.triangles == j).any(axis=1)]
    a, b, c = (model.nodes[tris[:, k]] for k in range(3))
    tol = -1e-18
    inside = (_orient(a, b, y[None]) >= tol) & (_orient(b, c, y[None]) >= tol) & (_orient(c, a, y[None]) >= tol)
    return bool(inside.any())


def nearest_visible_nodes(model, x, region, rel_tie=1e-9):
    """All nodes of ``region`` visible from ``x`` at the smallest distance.

    Brute force over every node; visibility tested against every constraint
    segment of the model (boundaries, interfaces, both crack faces).

    Returns
    -------
    list of int
        Node indices tied at the smallest distance (within ``rel_tie``).
    """
    members = np.unique(model.triangles[model.triangle_region == region])
    dist = np.linalg.norm(model.nodes[members] - x, axis=1)
    seg_a = model.nodes[model.segments[:, 0]]
    seg_b = model.nodes[model.segments[:, 1]]
    best, found = np.inf, []
    for k in np.argsort(dist):
        if dist[k] > best * (1 + rel_tie):
            break
        j = members[k]
        if blocked(x, model.nodes[j], seg_a, seg_b):
            continue
        if dist[k] > 0 and not _enters_triangle_of(model, j, x):
            continue
        best = min(best, dist[k])
        found.append(int(j))
    return found


def cell_owner(model, x, region):
    """Owner nodes of the cells of ``region`` whose closed polygon contains ``x``."""
    cells = model.cells
    owners = []
    for c in np.flatnonzero(cells.region == region):
        poly = shapely.Polygon(cells.polygon(c))
        if poly.distance(shapely.Point(x)) <= 1e-12:
            owners.append(int(cells.node[c]))
    return owners
