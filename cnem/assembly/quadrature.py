"""Quadrature over the integration-cell polygons (for errors and post-processing)."""

from __future__ import annotations

import numpy as np
from skfem.quadrature import get_quadrature
from skfem.refdom import RefTri

__all__ = ["cell_triangles", "cell_quadrature", "subdivide"]


def _fan(apex, verts, nxt):
    """Twice the signed areas of the fan triangles (apex, v_i, v_i+1)."""
    a, b = verts - apex, verts[nxt] - apex
    return a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]


def cell_triangles(cells, nodes, *, node_apex=None):
    """Triangles covering every cell polygon exactly (signed weights allowed).

    A fan from the centroid where the polygon is star-shaped from it (the usual
    case), else a fan from the cell's node where it is star-shaped from that,
    else a fan from the first vertex with signed areas (exact for any simple
    polygon when the integrand is smooth across the polygon's hull).

    Parameters
    ----------
    cells : Cells
    nodes : (n, 2) ndarray
        The model's nodes (``cells.node`` indexes them).
    node_apex : (m,) bool array_like, optional
        Cells fanned from their node first (crack-tip cells: a fan from the
        centroid would run along the crack line through the tip).

    Returns
    -------
    cell : (t,) int64 ndarray
    corners : (t, 3, 2) ndarray
        Counter-clockwise, except the negative triangles of a signed fan.
    """
    offsets, verts = cells.offsets, cells.vertices
    counts = np.diff(offsets)
    cell = np.repeat(np.arange(len(counts), dtype=np.int64), counts)
    nxt = np.arange(len(verts)) + 1
    nxt[offsets[1:] - 1] = offsets[:-1]
    apex = cells.centroid()[cell]
    tol = 1e-12 * cells.area[cell]
    bad = np.zeros(len(counts), dtype=bool) if node_apex is None else \
        np.array(node_apex, dtype=bool).copy()
    bad[cell[_fan(apex, verts, nxt) <= tol]] = True
    node_apex = nodes[cells.node][cell]
    use_node = bad[cell]
    apex[use_node] = node_apex[use_node]
    signed = _fan(apex, verts, nxt)
    still = np.zeros(len(counts), dtype=bool)
    still[cell[use_node & (signed < -tol)]] = True
    first = verts[offsets[:-1]][cell]
    apex[still[cell]] = first[still[cell]]
    signed = _fan(apex, verts, nxt)
    keep = np.abs(signed) > 0.0
    corners = np.stack([apex, verts, verts[nxt]], axis=1)[keep]
    return cell[keep], corners


def cell_quadrature(cells, nodes, order=4):
    """Quadrature points and weights on every cell polygon.

    Parameters
    ----------
    cells : Cells
        ``m`` cells.
    nodes : (n, 2) ndarray
        The model's nodes.
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
    owner, corners = cell_triangles(cells, nodes)
    ref, w = get_quadrature(RefTri, order)          # reference triangle, area 1/2
    e1 = corners[:, 1] - corners[:, 0]
    e2 = corners[:, 2] - corners[:, 0]
    jac = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    points = (corners[:, None, 0] + ref[0][None, :, None] * e1[:, None]
              + ref[1][None, :, None] * e2[:, None])
    weights = jac[:, None] * w[None, :]            # signed: negative fan triangles subtract
    return np.repeat(owner, len(w)), points.reshape(-1, 2), weights.reshape(-1)


def subdivide(cells, nodes, *, whole=None, node_apex=None):
    """Split every integration cell into the triangles of a fan (sub-cells).

    Used where one smoothed strain per cell is too few (enriched fields:
    more unknowns per node than strain samples per cell would leave
    zero-energy modes). Cells that only a signed fan covers stay whole.

    Parameters
    ----------
    cells : Cells
    nodes : (n, 2) ndarray
    whole : (m,) bool array_like, optional
        Cells to keep whole.
    node_apex : (m,) bool array_like, optional
        Cells fanned from their node (see `cell_triangles`).

    Returns
    -------
    sub : Cells
        Triangles (or whole cells), each with its parent's node and region.
    parent : (s,) int64 ndarray
        The cell each sub-cell comes from.
    """
    from ..geometry.model import Cells
    owner, corners = cell_triangles(cells, nodes, node_apex=node_apex)
    e1, e2 = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    twice = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    negative = np.zeros(len(cells.area), dtype=bool) if whole is None else \
        np.array(whole, dtype=bool).copy()
    negative[owner[twice < 0]] = True
    # slivers (collinear polygon vertices) would get an ill-defined smoothed gradient
    keep = ~negative[owner] & (twice > 1e-9 * cells.area[owner])
    whole = np.flatnonzero(negative)
    parent = np.concatenate([owner[keep], whole])
    counts = np.concatenate([np.full(keep.sum(), 3), np.diff(cells.offsets)[whole]])
    verts = np.concatenate([corners[keep].reshape(-1, 2)]
                           + [cells.polygon(c) for c in whole]) if len(whole) else \
        corners[keep].reshape(-1, 2)
    order = np.argsort(parent, kind="stable")
    starts = np.concatenate([[0], np.cumsum(counts)])
    index = np.concatenate([np.arange(starts[i], starts[i + 1]) for i in order]) if len(whole) \
        else np.arange(len(verts)).reshape(-1, 3)[order].reshape(-1)
    offsets = np.concatenate([[0], np.cumsum(counts[order])])
    parent = parent[order]
    sub = Cells(cells.node[parent], cells.region[parent], offsets, np.ascontiguousarray(verts[index]))
    return sub, parent
