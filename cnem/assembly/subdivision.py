"""Cell polygons split into the triangles of a fan: for quadrature and for sub-cells.

A fan runs from the centroid where the polygon is star-shaped from it, else from
the cell's node (always for crack-tip cells, `tip_cells`), else from the first
vertex with signed areas. `cell_triangles` gives the triangles (for a quadrature
on the cells, `cnem.assembly.quadrature.cell_quadrature`); `subdivide` gives them as
sub-cells of their own (enriched fields, the stabilisation's sub-cells).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..errors import InputError
from . import _fan_kernels as FK

if TYPE_CHECKING:
    from ..geometry.model import Cells, Model

__all__ = ["cell_triangles", "subdivide", "tip_cells"]


def _fan(apex, verts, nxt):
    """Twice the signed areas of the fan triangles (apex, v_i, v_i+1)."""
    a, b = verts - apex, verts[nxt] - apex
    return a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]


def cell_triangles(cells: Cells, nodes: np.ndarray, *,
                   node_apex: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
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
    apex = _apexes(cells, nodes, node_apex)[cell]
    signed = _fan(apex, verts, nxt)
    keep = np.abs(signed) > 0.0
    corners = np.stack([apex, verts, verts[nxt]], axis=1)[keep]
    return cell[keep], corners


def _cell_flags(flags, m, name):
    """A ``(m,)`` bool array from an optional per-cell flag argument (checked)."""
    if flags is None:
        return np.zeros(m, dtype=bool)
    arr = np.asarray(flags, dtype=bool)
    if arr.shape != (m,):
        raise InputError(f"{name}: expected one flag per cell, shape ({m},), "
                         f"received shape {arr.shape}; pass a bool array over the cells")
    return arr


def _apexes(cells, nodes, node_apex):
    """The apex of every cell's fan (see `cell_triangles`), ``(m, 2)``."""
    first = _cell_flags(node_apex, len(cells.area), "node_apex")
    return FK.fan_apexes(np.asarray(cells.offsets, dtype=np.int64),
                         np.ascontiguousarray(cells.vertices, dtype=np.float64),
                         np.ascontiguousarray(cells.centroid()),
                         np.ascontiguousarray(nodes[cells.node], dtype=np.float64), first,
                         cells.area)


def subdivide(cells: Cells, nodes: np.ndarray, *, whole: np.ndarray | None = None,
              node_apex: np.ndarray | None = None,
              mark_spokes: bool = False) -> tuple[Cells, np.ndarray]:
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
    mark_spokes : bool
        Mark the triangles' edges from their apex (``sub.spokes``): the
        boundary quadrature then gives them their midpoint alone, fewer points
        where the sub-cells only serve the stabilisation, whose spoke integrals
        cancel between neighbouring triangles. Also says where every edge
        comes from in its parent (``sub.edge_source``).

    Returns
    -------
    sub : Cells
        Triangles (or whole cells), each with its parent's node and region.
    parent : (s,) int64 ndarray
        The cell each sub-cell comes from.
    """
    from ..geometry.model import Cells
    whole = _cell_flags(whole, len(cells.area), "whole")
    parent, offsets, verts, spokes, source = FK.fan_sub_cells(
        np.asarray(cells.offsets, dtype=np.int64),
        np.ascontiguousarray(cells.vertices, dtype=np.float64),
        _apexes(cells, nodes, node_apex), cells.area, whole)
    sub = Cells(cells.node[parent], cells.region[parent], offsets, verts,
                spokes if mark_spokes else None, source if mark_spokes else None)
    return sub, parent


def tip_cells(model: Model) -> np.ndarray:
    """Cells of the crack-tip nodes, ``(m,)`` bool: a crack ends inside them, so
    their fans run from the node (see `cell_triangles`)."""
    tips = model.domain.tips
    x = model.nodes[model.cells.node]
    if len(tips) == 0:
        return np.zeros(len(x), dtype=bool)
    return (np.hypot(*(x[:, None, :] - tips[None]).transpose(2, 0, 1))
            <= model.domain.tolerance).any(axis=1)
