"""The edges of integration cells, and their pieces between circumcircle crossings.

Along a piece the natural neighbours of a point do not change, so the shape
functions are smooth rational functions of the position on it (C-NEM §4.2):
Gauss points on the pieces integrate them with geometric convergence.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from . import _kernels as K

if TYPE_CHECKING:
    from ..geometry.model import Cells, Model

__all__ = ["cell_edges", "circle_pieces", "distinct_edges"]


def cell_edges(cells: Cells) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Directed edges of every cell polygon (counter-clockwise).

    Returns
    -------
    cell : (e,) int64 ndarray
        Cell of each edge.
    a, b : (e, 2) ndarray
        Start and end; the cell lies on the left, the outward normal is
        ``(b - a)`` turned clockwise.
    """
    counts = np.diff(cells.offsets)
    cell = np.repeat(np.arange(len(counts), dtype=np.int64), counts)
    nxt = np.arange(len(cells.vertices)) + 1
    nxt[cells.offsets[1:] - 1] = cells.offsets[:-1]
    return cell, cells.vertices, cells.vertices[nxt]


def circle_pieces(model: Model, a: np.ndarray, b: np.ndarray, whole: np.ndarray | None = None,
                  group: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pieces of the edges between circumcircle crossings (``whole``: (e,) bool,
    edges left in one piece).

    ``group``: (e,) keys; consecutive edges with the same key (the edges of one
    cell) look their candidate circles up in one query of the circumcircles'
    R-tree, with the box of them all.

    Returns
    -------
    edge : (q,) int64 ndarray
    t0, t1 : (q,) ndarray
        Piece ``i`` is ``t0[i] <= t <= t1[i]`` along edge ``edge[i]``.
    """
    centre, radius2, tree = model.circumcircles()          # in the model's local frame
    ne = len(a)
    cut = np.arange(ne) if whole is None else np.flatnonzero(~np.asarray(whole, dtype=bool))
    ca, cb = model.frame.to_local(a[cut]), model.frame.to_local(b[cut])
    lo, hi = np.minimum(ca, cb), np.maximum(ca, cb)
    gid = np.arange(len(cut))
    if group is not None and len(cut):
        key = np.asarray(group)[cut]
        start = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
        gid = np.repeat(np.arange(len(start)), np.diff(np.r_[start, len(cut)]))
        lo, hi = np.minimum.reduceat(lo, start, axis=0), np.maximum.reduceat(hi, start, axis=0)
    off, idx = tree.query(lo, hi)
    counts = np.zeros(len(cut) + 1, dtype=np.int64)
    K.circle_crossings(ca, cb, centre, radius2, off, idx, gid, counts, np.zeros(0), False)
    offsets = np.zeros(ne + 1, dtype=np.int64)
    offsets[cut + 1] = counts[1:]
    np.cumsum(offsets, out=offsets)
    t = np.empty(offsets[-1])
    K.circle_crossings(ca, cb, centre, radius2, off, idx, gid, offsets[cut], t, True)
    return K.edge_pieces(offsets, t)


def distinct_edges(a: np.ndarray, b: np.ndarray, hint: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The distinct edges among directed edges ``(e, 2)`` (the same ends bit for bit
    and the same ``hint``, either way round).

    Each edge is integrated once, from its lexicographically smaller end: the two
    cells sharing it get the same integral with opposite signs (they cancel exactly).

    Returns
    -------
    rows : (u, 5) float64
        ``[x0, y0, x1, y1, hint]`` of every distinct edge.
    sign : (e,) float64
        -1 where an edge runs against its distinct edge.
    first : (u,) int64
        An edge of each distinct edge.
    occurrence : (e,) int64
        The distinct edge of every edge.
    """
    rows, sign = K.canonical_rows(a, b, hint)
    first, occurrence = K.unique_rows(rows.view(np.uint64))
    return rows[first], sign, first, occurrence
