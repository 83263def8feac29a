"""Gauss points on the boundaries of integration cells (C-NEM paper eq. 31-32).

Every distinct cell edge is cut where it crosses a circumcircle (`circle_pieces`)
and gets ``gauss`` points per piece, once for the cells on both of its sides;
crack faces are seen from the cell's side, slits in crack-tip cells added
(`cnem.assembly.crack_faces`).
"""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp

from ..errors import InputError
from ..geometry.pslg import CRACK
from ..shape.natural import PointRows, point_rows
from .._parallel import work_chunks
from . import _kernels as K
from . import _sparse_kernels as SK
from .crack_faces import crack_faces, face_triangles, slit_edges
from .csr import csr_pair, row_bounds
from .edges import cell_edges, circle_pieces, distinct_edges

if TYPE_CHECKING:
    from typing import Sequence
    from numpy.typing import ArrayLike
    from ..geometry.model import Cells, Model

__all__ = ["BoundaryQuadrature", "boundary_quadrature", "boundary_quadratures", "edge_points",
           "edges_to_cells", "graded_rule", "check_gauss"]

log = logging.getLogger(__name__)


class BoundaryQuadrature:
    """Gauss points on the boundaries of all integration cells (each distinct edge once).

    ``∮_{Γ_k} f n dΓ = (to_cells @ (Wx @ f(points)), ...)`` times ``A_k``: for a
    function sampled at the points, ``cell_integrals(f)`` gives the ``(1/A_k) ∮ f n``
    of every cell (the smoothed gradient of ``f``).

    Attributes
    ----------
    points : (q, 2) ndarray
    hint : (q,) int64 ndarray
        Triangle on the cell's side for points on crack faces, -1 elsewhere.
    wx, wy : scipy.sparse.csr_matrix, shape (e, q)
        Weights times the outward normal components of every distinct edge.
    to_cells : scipy.sparse.csr_matrix, shape (m, e)
        ``±1 / A_k`` for the edges of cell ``k``.
    """

    def __init__(self, points: np.ndarray, hint: np.ndarray, wx: sp.csr_matrix, wy: sp.csr_matrix,
                 to_cells: sp.csr_matrix):
        self.points, self.hint, self.wx, self.wy, self.to_cells = points, hint, wx, wy, to_cells

    def cell_integrals(self, values: ArrayLike | sp.spmatrix, rows: np.ndarray | None = None
                       ) -> tuple[np.ndarray | sp.csr_matrix, np.ndarray | sp.csr_matrix]:
        """``(1 / A_k) ∮_{Γ_k} f n dΓ`` for ``values = f(points)``, ``(q, ...)`` array or
        sparse ``(q, c)`` (then CSR results); returns the x and y parts, ``(m, ...)``.
        ``rows``: the point of each row of ``values`` when they come in another order."""
        if not sp.issparse(values):
            values = np.asarray(values)[self._value_rows(rows)]
            return self.to_cells @ (self.wx @ values), self.to_cells @ (self.wy @ values)
        return self.from_edges(self.edge_integrals(values, rows))

    def from_edges(self, edges: tuple[sp.csr_matrix, sp.csr_matrix]
                   ) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """`cell_integrals` from the `edge_integrals` ``(ex, ey)`` of the same points
        (quadratures with the same points share them): two CSR ``(m, c)``."""
        ex, ey = edges
        c = self.to_cells
        return csr_pair(*SK.weighted_row_sums(
            c.indptr, c.indices, c.data, c.data, np.arange(c.shape[1], dtype=np.int64),
            *row_bounds(ex.indptr), ex.indices, ex.data, ey.data, work_chunks()),
            (c.shape[0], ex.shape[1]))

    def edge_integrals(self, values: sp.spmatrix | PointRows, rows: np.ndarray | None = None
                       ) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """``∫_e f n dΓ`` of every distinct edge for sparse ``values = f(points)``
        ``(q, c)`` (``rows`` as in `cell_integrals`), or for the shape functions
        as `point_rows` gives them: x and y parts, CSR ``(e, c)`` with one pattern."""
        if isinstance(values, PointRows):
            start, end, cols, vals = values.start, values.end, values.cols, values.vals
            where, ncol = self._value_rows(values.order), values.nodes
        else:
            phi = values.tocsr()
            (start, end), cols, vals = row_bounds(phi.indptr), phi.indices, phi.data
            where, ncol = self._value_rows(rows), phi.shape[1]
        w = self.wx
        return csr_pair(*SK.weighted_row_sums(
            w.indptr, w.indices, w.data, self.wy.data, where, start, end, cols, vals, vals,
            work_chunks()), (w.shape[0], ncol))

    def point_rows(self, model: Model) -> PointRows:
        """The shape functions at the points, sides respected, as `point_rows` leaves
        them (for `edge_integrals`)."""
        return point_rows(model, self.points, triangles=self._hint())

    def _hint(self):
        """The points' triangles where they matter (crack faces), else None."""
        return self.hint if (self.hint >= 0).any() else None

    def _value_rows(self, rows):
        """The row of the values of every point (``rows[r]``: the point of row ``r``)."""
        where = np.arange(len(self.points))
        if rows is not None:
            where[rows] = np.arange(len(rows))
        return where

    def shape_functions(self, model: Model, select: ArrayLike | None = None
                        ) -> tuple[sp.csr_matrix, np.ndarray]:
        """The shape functions at the points (or at ``points[select]``), sides
        respected, rows in any order: returns ``(Phi, order)``, row ``r`` of ``Phi``
        at ``points[order[r]]`` (indices into the selection)."""
        hint = self._hint()
        if select is None:
            return model.shape_functions(self.points, triangles=hint, in_order=False)
        return model.shape_functions(self.points[select], in_order=False,
                                     triangles=None if hint is None else hint[select])


def graded_rule(s: np.ndarray, w: np.ndarray, start: np.ndarray, end: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray]:
    """Gauss points ``s`` and weights ``w`` on ``[0, 1]`` per piece, graded towards
    the ends flagged in ``start`` / ``end`` by ``t = s^2`` (``1 - (1 - s)^2``): a
    ``sqrt(t)`` behaviour at that end becomes smooth. Returns ``(q, g)`` arrays."""
    S = np.broadcast_to(s, (len(start), len(s))).copy()
    W = np.broadcast_to(w, (len(start), len(s))).copy()
    S[start], W[start] = s ** 2, 2.0 * s * w
    S[end], W[end] = 1.0 - (1.0 - s) ** 2, 2.0 * (1.0 - s) * w
    return S, W


def boundary_quadrature(model: Model, *, gauss: int = 2, cells: Cells | None = None,
                        singular: ArrayLike | None = None
                        ) -> BoundaryQuadrature:
    """Gauss points on every cell boundary: each edge cut at circumcircle crossings,
    ``gauss`` points per piece, crack faces seen from their side, slits in tip cells.

    ``cells``: integration cells other than ``model.cells`` (sub-cells, say);
    their spokes (``cells.spokes``), if marked, get their midpoint alone: exact
    for the linear fields the shape functions reproduce, so the patch test still
    holds, and their integrals cancel between neighbouring sub-cells (only the
    stabilisation sees them).
    ``singular``: ``(s, 2)`` points (crack tips) where the integrand behaves like
    ``sqrt(r)`` (enrichment functions); the pieces ending at one are graded.

    Returns
    -------
    BoundaryQuadrature
    """
    cells = model.cells if cells is None else cells
    return boundary_quadratures(model, [cells], gauss=gauss, singular=singular)[0]


def _set_edges(model, cells, faces):
    """The directed edges of one set of cells, with slits and crack-face hints.

    Returns
    -------
    cell : (e,) int64 ndarray
    a, b : (e, 2) ndarray
    hint : (e,) int64 ndarray
        Triangle of the crack face the edge lies on (its side), -1 elsewhere.
    spoke : (e,) bool ndarray
        Spokes of fan sub-cells (one midpoint each).
    """
    cell, a, b = cell_edges(cells)
    hint = np.full(len(a), -1, dtype=np.int64)
    spoke = np.zeros(len(a), dtype=bool) if cells.spokes is None else np.asarray(cells.spokes)
    if faces is not None:
        hint = face_triangles(model, a, b, faces)
        slit = slit_edges(model, faces, cells)
        cell, a, b, hint = (np.concatenate([x, y]) for x, y in zip((cell, a, b, hint), slit))
        spoke = np.concatenate([spoke, np.zeros(len(slit[0]), dtype=bool)])
    return cell, a, b, hint, spoke


def boundary_quadratures(model: Model, cell_sets: Sequence[Cells], *, gauss: int = 2,
                         singular: ArrayLike | None = None
                         ) -> list[BoundaryQuadrature]:
    """`boundary_quadrature` of several sets of cells with one set of points.

    An edge that several sets share (the same ends bit for bit, the same side of
    a crack face) gets its points once: fan sub-cells (`subdivide`) share every
    edge but their spokes with their parent cells, so the shape functions at
    those points serve both smoothed gradients. Where a shared edge is a spoke
    in one set only, it is cut like the other's.

    Parameters
    ----------
    model : Model
    cell_sets : sequence of Cells
    gauss : int
    singular : (s, 2) array_like, optional

    Returns
    -------
    list of BoundaryQuadrature
        One per set, all with the same ``points``, ``hint``, ``wx`` and ``wy``.
    """
    gauss = check_gauss(gauss)
    faces = crack_faces(model) if (model.segment_kind == CRACK).any() else None
    edges = [_set_edges(model, cells, faces) for cells in cell_sets]
    cell, a, b, hint, spoke = (np.concatenate(x) for x in zip(*edges))
    # one key per cell of every set: the edges first seen in one cell share a query
    shift = np.repeat(np.cumsum([0] + [len(c.area) for c in cell_sets[:-1]]),
                      [len(e[0]) for e in edges])
    rows, sign, first, occurrence = distinct_edges(a, b, hint)
    whole = _all_spokes(spoke, occurrence, len(first))
    points = edge_points(model, rows, hint[first], whole, (cell + shift)[first], gauss, singular)
    out, lo = [], 0
    for cells, (set_cell, *_) in zip(cell_sets, edges):
        hi = lo + len(set_cell)
        to_cells = edges_to_cells(cells, set_cell, sign[lo:hi], occurrence[lo:hi], len(rows))
        out.append(BoundaryQuadrature(*points, to_cells))
        lo = hi
    log.info("SCNI quadrature: %s cells, %d edges, %d points",
             "+".join(str(len(c.area)) for c in cell_sets), len(rows), len(points[0]))
    return out


def check_gauss(gauss: int) -> int:
    """The number of Gauss points per piece of edge, checked (a positive int)."""
    gauss = int(gauss)
    if gauss < 1:
        raise InputError(f"gauss: expected a positive number of Gauss points, received {gauss}; "
                         f"2 (the default) is enough for the patch test")
    return gauss


def edge_points(model: Model, rows: np.ndarray, hint: np.ndarray, whole: np.ndarray,
                group: np.ndarray, gauss: int, singular: ArrayLike | None
                ) -> tuple[np.ndarray, np.ndarray, sp.csr_matrix, sp.csr_matrix]:
    """Gauss points on the distinct edges ``rows`` (see `distinct_edges`), cut at
    circumcircle crossings unless ``whole`` (then their midpoint alone); ``group``
    as in `circle_pieces`. Returns ``points, hint, wx, wy`` of `BoundaryQuadrature`."""
    a, b = np.ascontiguousarray(rows[:, :2]), np.ascontiguousarray(rows[:, 2:4])
    edge, t0, t1 = circle_pieces(model, a, b, whole, group=group)
    s, w = np.polynomial.legendre.leggauss(gauss)
    s, w = 0.5 * (s + 1.0), 0.5 * w
    S, W = s[None], w[None]                   # one rule for every piece
    if singular is not None:                  # pieces that begin or end at a singular point
        tol = model.domain.tolerance
        d = b - a
        first, last = a[edge] + t0[:, None] * d[edge], a[edge] + t1[:, None] * d[edge]
        start, end = np.zeros(len(edge), dtype=bool), np.zeros(len(edge), dtype=bool)
        for p in np.asarray(singular, float).reshape(-1, 2):
            start |= np.hypot(*(first - p).T) <= tol
            end |= np.hypot(*(last - p).T) <= tol
        S, W = graded_rule(s, w, start, end)
    points, wx, wy, indptr = K.piece_points(a, b, edge, t0, t1, S, W, whole)
    cols = np.arange(len(points), dtype=np.int32)
    shape = (len(a), len(points))
    # one pattern for both (explicit zeros kept): cell_integrals relies on it
    wx = sp.csr_matrix((wx, cols, indptr), shape=shape)
    wy = sp.csr_matrix((wy, cols.copy(), indptr.copy()), shape=shape)
    return points, np.repeat(hint, np.diff(indptr)), wx, wy


def edges_to_cells(cells: Cells, edge_cell: np.ndarray, sign: np.ndarray, occurrence: np.ndarray,
                   count: int) -> sp.csr_matrix:
    """``±1 / A_k`` from the cells to the ``count`` distinct edges, ``(m, count)``
    CSR, for the directed edges of the cells (cell ``edge_cell``, distinct edge
    ``occurrence``, ``sign`` against it)."""
    data, cols = sign / cells.area[edge_cell], occurrence.astype(np.int32)
    shape = (len(cells.area), count)
    if len(edge_cell) == len(cells.vertices):          # no slits: rows in cell order
        return sp.csr_matrix((data, cols, np.asarray(cells.offsets, dtype=np.int64)), shape=shape)
    return sp.csr_matrix((data, (edge_cell, cols)), shape=shape)


def _all_spokes(spoke, occurrence, count):
    """Per distinct edge: True if every occurrence of it is a spoke."""
    cut = np.zeros(count, dtype=bool)
    cut[occurrence[~spoke]] = True
    return ~cut
