"""Boundary quadratures of cells and of their fan sub-cells from one set of points,
the sub-cells' edges taken from the cell edges they lie on (no search)."""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING

import numpy as np

from ..geometry.pslg import CRACK
from . import _fan_kernels as FK
from .edge_quadrature import (BoundaryQuadrature, boundary_quadratures, check_gauss, edge_points,
                              edges_to_cells)
from .edges import cell_edges, distinct_edges

if TYPE_CHECKING:
    from numpy.typing import ArrayLike
    from ..geometry.model import Cells, Model

__all__ = ["fan_quadratures"]

log = logging.getLogger(__name__)


def fan_quadratures(model: Model, cells: Cells, sub: Cells, parent: ArrayLike, *, gauss: int = 2
                    ) -> tuple[BoundaryQuadrature, BoundaryQuadrature]:
    """`boundary_quadratures` of cells and of their fan sub-cells (`subdivide` with
    ``mark_spokes``), the sub-cells' edges taken from where they come from.

    The cells' edges are found shared by their coordinates; a sub-cell's edge
    that lies on its cell's edge (``sub.edge_source``) is that edge, and the
    spoke to a cell's vertex is one edge for the two triangles beside it: no
    search. Cracked models (faces and slits to place) take `boundary_quadratures`.

    Parameters
    ----------
    model : Model
    cells : Cells
        ``m`` cells (of the model, or some of them).
    sub : Cells
        Fan sub-cells of ``cells``, with ``spokes`` and ``edge_source``.
    parent : (s,) int array_like
        The cell of each sub-cell (indices into ``cells``).
    gauss : int

    Returns
    -------
    cells_quadrature, sub_quadrature : BoundaryQuadrature
        With the same points.
    """
    if (model.segment_kind == CRACK).any() or sub.edge_source is None:
        return tuple(boundary_quadratures(model, [cells, sub], gauss=gauss))
    gauss = check_gauss(gauss)
    cell, a, b = cell_edges(cells)
    rows, sign, first, occurrence = distinct_edges(a, b, np.full(len(a), -1, dtype=np.int64))
    # the cell vertex every sub-cell edge comes from
    counts = np.diff(sub.offsets)
    vertex = np.repeat(np.asarray(cells.offsets, dtype=np.int64)[np.asarray(parent)], counts) \
        + sub.edge_source
    spoke = np.asarray(sub.spokes, dtype=bool)
    spoke_rows, spoke_index, spoke_sign = FK.fan_spokes(
        np.asarray(sub.offsets, dtype=np.int64), sub.vertices, spoke, vertex, len(cells.vertices))
    sub_edge = np.where(spoke, len(rows) + spoke_index, occurrence[vertex])
    sub_sign = np.where(spoke, spoke_sign, sign[vertex])
    rows = np.concatenate([rows, spoke_rows])
    whole = np.arange(len(rows)) >= len(first)
    group = np.concatenate([cell[first], np.zeros(len(spoke_rows), dtype=np.int64)])
    points = edge_points(model, rows, np.full(len(rows), -1, dtype=np.int64), whole, group,
                          gauss, None)
    sub_cell = np.repeat(np.arange(len(sub.area), dtype=np.int64), counts)
    log.info("SCNI quadrature: %d cells + %d sub-cells, %d edges, %d points",
             len(cells.area), len(sub.area), len(rows), len(points[0]))
    return (BoundaryQuadrature(*points, edges_to_cells(cells, cell, sign, occurrence, len(rows))),
            BoundaryQuadrature(*points, edges_to_cells(sub, sub_cell, sub_sign, sub_edge, len(rows))))
