"""SCNI smoothed gradients (C-NEM paper §4.2, eq. 26-32).

For integration cell ``k`` (area ``A_k``, boundary ``Γ_k``) and node ``j``::

    b~_kj = (1 / A_k) ∮_{Γ_k} φ_j n dΓ                       (eq. 31-32)

Every cell edge is cut where it crosses a circumcircle of the triangulation:
between two crossings the natural neighbours of a point do not change and φ
is a smooth rational function of the position along the edge, which Gauss
quadrature integrates with fast (geometric) convergence. The linear patch test
holds to round-off for any number of points, because φ reproduces linear
fields exactly and Gauss quadrature integrates linear functions exactly.
"""

from __future__ import annotations

import logging

import numpy as np
import scipy.sparse as sp
import shapely

from .. import config
from .._memory import release_free_memory
from ..geometry.topology import constraint_edges
from ..shape.natural import PointRows, path_order, point_rows
from .._parallel import work_chunks
from ..spatial.rtree import RTree
from . import _fan_kernels as FK
from . import _kernels as K
from . import _sparse_kernels as SK

__all__ = ["SmoothedGradient", "smoothed_gradient", "fan_gradient", "fan_quadratures",
           "BoundaryQuadrature", "boundary_quadrature", "boundary_quadratures", "cell_edges"]

log = logging.getLogger(__name__)

#: Cells whose boundary quadrature is built and evaluated in one pass of `smoothed_gradient`.
CELLS_PER_PASS = 10_000


class SmoothedGradient:
    """The operator ``B~`` of eq. 30: smoothed derivatives of every shape function.

    Attributes
    ----------
    x, y : scipy.sparse.csr_matrix, shape (m, n)
        ``x[k, j] = b~_xj(cell k)`` and ``y[k, j] = b~_yj(cell k)``.
    points : int
        Number of quadrature points evaluated for it on the cell boundaries (with
        the other sets of cells computed in the same passes, `fan_gradient`: their
        shared count).
    """

    def __init__(self, x, y, points):
        self.x, self.y, self.points = x, y, points

    def __iter__(self):
        return iter((self.x, self.y))

    def __repr__(self):
        m, n = self.x.shape
        return f"<SmoothedGradient {m} cells x {n} nodes, {self.x.nnz} non-zeros, {self.points} points>"


def cell_edges(cells):
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


def _pieces(model, a, b, whole=None, group=None):
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
    centre, radius2, tree = model.circumcircles()
    ne = len(a)
    cut = np.arange(ne) if whole is None else np.flatnonzero(~np.asarray(whole, dtype=bool))
    ca, cb = a[cut], b[cut]
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


def _crack_faces(model):
    """Crack-face edges, each oriented with its own face's triangle on the left.

    Returns
    -------
    p, q : (f, 2) ndarray
        Ends.
    owner : (f,) int64 ndarray
        The triangle of that face.
    """
    crack = model.segments[model.segment_kind == 2]
    n = len(model.nodes)
    edges, owner = constraint_edges(model.triangles, model.neighbors())
    is_face = np.isin(np.sort(edges, axis=1) @ [n, 1], np.sort(crack, axis=1) @ [n, 1])
    edges, owner = edges[is_face], owner[is_face]
    return model.nodes[edges[:, 0]], model.nodes[edges[:, 1]], owner


def _slit_edges(model, faces, cells):
    """Crack faces running inside cells (near crack tips a cell can wrap around the
    end of a crack; its polygon then does not show the slit, but the slit's two
    faces are part of the cell's boundary, with different shape functions).

    Returns
    -------
    cell : (s,) int64 ndarray
    a, b : (s, 2) ndarray
        Slit edges, oriented like their face (the face's material on the left).
    hint : (s,) int64 ndarray
        The triangle of the face.
    """
    p, q, owner = faces
    if len(p) == 0:
        return np.zeros(0, np.int64), np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0, np.int64)
    first = np.repeat(np.arange(len(cells.area)), np.diff(cells.offsets))
    lo = np.full((len(cells.area), 2), np.inf)
    hi = np.full((len(cells.area), 2), -np.inf)
    np.minimum.at(lo, first, cells.vertices)
    np.maximum.at(hi, first, cells.vertices)
    off, idx = RTree(lo, hi).query(np.minimum(p, q), np.maximum(p, q))
    out = []
    for f in range(len(p)):
        face = shapely.LineString([p[f], q[f]])
        for c in idx[off[f]:off[f + 1]]:
            polygon = shapely.Polygon(cells.polygon(c))
            eps = 1e-6 * np.sqrt(cells.area[c])
            for piece in _line_parts(face.intersection(polygon)):
                xy = np.asarray(piece.coords)
                d = xy[-1] - xy[0]
                length = np.hypot(*d)
                if length <= eps:
                    continue
                mid = 0.5 * (xy[0] + xy[-1])
                side = eps * np.array([-d[1], d[0]]) / length
                if polygon.contains(shapely.Point(mid + side)) and \
                        polygon.contains(shapely.Point(mid - side)):
                    out.append((c, xy[0], xy[-1], owner[f]))
    if not out:
        return np.zeros(0, np.int64), np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0, np.int64)
    cell, a, b, hint = zip(*out)
    return np.array(cell, np.int64), np.array(a), np.array(b), np.array(hint, np.int64)


def _line_parts(geom):
    """The line pieces of a shapely intersection result."""
    if isinstance(geom, shapely.LineString):
        return [geom] if not geom.is_empty else []
    if hasattr(geom, "geoms"):
        return [g for g in geom.geoms if isinstance(g, shapely.LineString)]
    return []


def _face_triangles(model, a, b, faces):
    """For cell edges lying on a crack face, the triangle of that face on the
    cell's side (the shape functions there depend on the side); -1 elsewhere.

    Returns
    -------
    (e,) int64 ndarray
    """
    hint = np.full(len(a), -1, dtype=np.int64)
    p, q, owner = faces
    tol = config.SNAP_TOL * model.domain.diameter
    mid = 0.5 * (a + b)
    off, idx = RTree(np.minimum(p, q) - tol, np.maximum(p, q) + tol).query(mid, mid)
    row = np.repeat(np.arange(len(a)), np.diff(off))
    pq, d = q[idx] - p[idx], (b - a)[row]
    length = np.linalg.norm(pq, axis=1)
    rel = mid[row] - p[idx]
    on_line = np.abs(pq[:, 0] * rel[:, 1] - pq[:, 1] * rel[:, 0]) <= tol * length
    along = (rel * pq).sum(axis=1) / length
    inside = (along > -tol) & (along < length + tol)
    same_way = (d * pq).sum(axis=1) > 0.0          # the face's triangle lies on the left too
    hit = on_line & inside & same_way
    hint[row[hit]] = owner[idx[hit]]
    return hint


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

    def __init__(self, points, hint, wx, wy, to_cells):
        self.points, self.hint, self.wx, self.wy, self.to_cells = points, hint, wx, wy, to_cells

    def cell_integrals(self, values, rows=None):
        """``(1 / A_k) ∮_{Γ_k} f n dΓ`` for ``values = f(points)``, ``(q, ...)`` array or
        sparse ``(q, c)`` (then CSR results); returns the x and y parts, ``(m, ...)``.
        ``rows``: the point of each row of ``values`` when they come in another order."""
        if not sp.issparse(values):
            values = np.asarray(values)[self._value_rows(rows)]
            return self.to_cells @ (self.wx @ values), self.to_cells @ (self.wy @ values)
        return self.from_edges(self.edge_integrals(values, rows))

    def from_edges(self, edges):
        """`cell_integrals` from the `edge_integrals` ``(ex, ey)`` of the same points
        (quadratures with the same points share them): two CSR ``(m, c)``."""
        ex, ey = edges
        c = self.to_cells
        return _csr_pair(*SK.weighted_row_sums(
            c.indptr, c.indices, c.data, c.data, np.arange(c.shape[1], dtype=np.int64),
            *_row_bounds(ex.indptr), ex.indices, ex.data, ey.data, ex.shape[1],
            work_chunks()), (c.shape[0], ex.shape[1]))

    def edge_integrals(self, values, rows=None):
        """``∫_e f n dΓ`` of every distinct edge for sparse ``values = f(points)``
        ``(q, c)`` (``rows`` as in `cell_integrals`), or for the shape functions
        as `point_rows` gives them: x and y parts, CSR ``(e, c)`` with one pattern."""
        if isinstance(values, PointRows):
            start, end, cols, vals = values.start, values.end, values.cols, values.vals
            where, ncol = self._value_rows(values.order), values.nodes
        else:
            phi = values.tocsr()
            (start, end), cols, vals = _row_bounds(phi.indptr), phi.indices, phi.data
            where, ncol = self._value_rows(rows), phi.shape[1]
        w = self.wx
        return _csr_pair(*SK.weighted_row_sums(
            w.indptr, w.indices, w.data, self.wy.data, where, start, end, cols, vals, vals,
            ncol, work_chunks()), (w.shape[0], ncol))

    def point_rows(self, model):
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

    def shape_functions(self, model, select=None):
        """The shape functions at the points (or at ``points[select]``), sides
        respected, rows in any order: returns ``(Phi, order)``, row ``r`` of ``Phi``
        at ``points[order[r]]`` (indices into the selection)."""
        hint = self._hint()
        if select is None:
            return model.shape_functions(self.points, triangles=hint, in_order=False)
        return model.shape_functions(self.points[select], in_order=False,
                                     triangles=None if hint is None else hint[select])


def _row_bounds(indptr):
    """Starts and ends of the rows of a CSR matrix, as int64 (one kernel signature)."""
    indptr = np.asarray(indptr, dtype=np.int64)
    return indptr[:-1], indptr[1:]


def _csr_pair(indptr, indices, x, y, shape):
    """Two CSR matrices on one pattern, each with its own index arrays (scipy may
    sort one matrix's indices in place)."""
    return sp.csr_matrix((x, indices, indptr), shape=shape), \
        sp.csr_matrix((y, indices.copy(), indptr.copy()), shape=shape)


def _graded_rule(s, w, start, end):
    """Gauss points ``s`` and weights ``w`` on ``[0, 1]`` per piece, graded towards
    the ends flagged in ``start`` / ``end`` by ``t = s^2`` (``1 - (1 - s)^2``): a
    ``sqrt(t)`` behaviour at that end becomes smooth. Returns ``(q, g)`` arrays."""
    S = np.broadcast_to(s, (len(start), len(s))).copy()
    W = np.broadcast_to(w, (len(start), len(s))).copy()
    S[start], W[start] = s ** 2, 2.0 * s * w
    S[end], W[end] = 1.0 - (1.0 - s) ** 2, 2.0 * (1.0 - s) * w
    return S, W


def boundary_quadrature(model, *, gauss=2, cells=None, singular=None):
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
        hint = _face_triangles(model, a, b, faces)
        slit = _slit_edges(model, faces, cells)
        cell, a, b, hint = (np.concatenate([x, y]) for x, y in zip((cell, a, b, hint), slit))
        spoke = np.concatenate([spoke, np.zeros(len(slit[0]), dtype=bool)])
    return cell, a, b, hint, spoke


def boundary_quadratures(model, cell_sets, *, gauss=2, singular=None):
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
    gauss = _check_gauss(gauss)
    faces = _crack_faces(model) if (model.segment_kind == 2).any() else None
    edges = [_set_edges(model, cells, faces) for cells in cell_sets]
    cell, a, b, hint, spoke = (np.concatenate(x) for x in zip(*edges))
    # one key per cell of every set: the edges first seen in one cell share a query
    shift = np.repeat(np.cumsum([0] + [len(c.area) for c in cell_sets[:-1]]),
                      [len(e[0]) for e in edges])
    rows, sign, first, occurrence = _distinct_edges(a, b, hint)
    whole = _all_spokes(spoke, occurrence, len(first))
    points = _edge_points(model, rows, hint[first], whole, (cell + shift)[first], gauss, singular)
    out, lo = [], 0
    for cells, (set_cell, *_) in zip(cell_sets, edges):
        hi = lo + len(set_cell)
        to_cells = _to_cells(cells, set_cell, sign[lo:hi], occurrence[lo:hi], len(rows))
        out.append(BoundaryQuadrature(*points, to_cells))
        lo = hi
    log.info("SCNI quadrature: %s cells, %d edges, %d points",
             "+".join(str(len(c.area)) for c in cell_sets), len(rows), len(points[0]))
    return out


def fan_quadratures(model, cells, sub, parent, *, gauss=2):
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
    if (model.segment_kind == 2).any() or sub.edge_source is None:
        return tuple(boundary_quadratures(model, [cells, sub], gauss=gauss))
    gauss = _check_gauss(gauss)
    cell, a, b = cell_edges(cells)
    rows, sign, first, occurrence = _distinct_edges(a, b, np.full(len(a), -1, dtype=np.int64))
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
    points = _edge_points(model, rows, np.full(len(rows), -1, dtype=np.int64), whole, group,
                          gauss, None)
    sub_cell = np.repeat(np.arange(len(sub.area), dtype=np.int64), counts)
    log.info("SCNI quadrature: %d cells + %d sub-cells, %d edges, %d points",
             len(cells.area), len(sub.area), len(rows), len(points[0]))
    return (BoundaryQuadrature(*points, _to_cells(cells, cell, sign, occurrence, len(rows))),
            BoundaryQuadrature(*points, _to_cells(sub, sub_cell, sub_sign, sub_edge, len(rows))))


def _check_gauss(gauss):
    gauss = int(gauss)
    if gauss < 1:
        raise ValueError(f"gauss: expected a positive number of Gauss points, received {gauss}")
    return gauss


def _distinct_edges(a, b, hint):
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


def _edge_points(model, rows, hint, whole, group, gauss, singular):
    """Gauss points on the distinct edges ``rows`` (see `_distinct_edges`), cut at
    circumcircle crossings unless ``whole`` (then their midpoint alone); ``group``
    as in `_pieces`. Returns ``points, hint, wx, wy`` of `BoundaryQuadrature`."""
    a, b = np.ascontiguousarray(rows[:, :2]), np.ascontiguousarray(rows[:, 2:4])
    edge, t0, t1 = _pieces(model, a, b, whole, group=group)
    s, w = np.polynomial.legendre.leggauss(gauss)
    s, w = 0.5 * (s + 1.0), 0.5 * w
    S, W = s[None], w[None]                   # one rule for every piece
    if singular is not None:                  # pieces that begin or end at a singular point
        tol = config.SNAP_TOL * model.domain.diameter
        d = b - a
        first, last = a[edge] + t0[:, None] * d[edge], a[edge] + t1[:, None] * d[edge]
        start, end = np.zeros(len(edge), dtype=bool), np.zeros(len(edge), dtype=bool)
        for p in np.asarray(singular, float).reshape(-1, 2):
            start |= np.hypot(*(first - p).T) <= tol
            end |= np.hypot(*(last - p).T) <= tol
        S, W = _graded_rule(s, w, start, end)
    points, wx, wy, indptr = K.piece_points(a, b, edge, t0, t1, S, W, whole)
    cols = np.arange(len(points), dtype=np.int32)
    shape = (len(a), len(points))
    # one pattern for both (explicit zeros kept): cell_integrals relies on it
    wx = sp.csr_matrix((wx, cols, indptr), shape=shape)
    wy = sp.csr_matrix((wy, cols.copy(), indptr.copy()), shape=shape)
    return points, np.repeat(hint, np.diff(indptr)), wx, wy


def _to_cells(cells, edge_cell, sign, occurrence, count):
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


def smoothed_gradient(model, *, gauss=2, cells=None):
    """The smoothed gradient operator ``B~`` of a model (cached on the model).

    Parameters
    ----------
    model : Model
        ``n`` nodes, ``m`` integration cells.
    gauss : int
        Gauss points on each piece of a cell edge between circumcircle
        crossings. The patch test holds for any value; more points make
        ``b~`` converge to the exact boundary integrals (see docs/elasticity.md).
    cells : Cells, optional
        Integration cells other than ``model.cells`` (not cached).

    Returns
    -------
    SmoothedGradient
        ``x, y`` sparse ``(m, n)``.
    """
    key = ("scni", int(gauss))
    if cells is None and key in model._cache:
        return model._cache[key]
    every = model.cells if cells is None else cells
    runs = _cell_runs(model, every)
    grad, = _gradients(model, [every], lambda sets, _: boundary_quadratures(model, sets, gauss=gauss),
                       None if runs is None else [[run] for run in runs])
    if cells is None:
        model._cache[key] = grad
    return grad


def fan_gradient(model, *, gauss=2, release=False):
    """Smoothed gradients on the fan sub-cells of the model's cells (cached).

    The sub-cells (`cnem.assembly.subdivide`, spokes marked; crack-tip cells
    fanned from their node) share every edge but their spokes with their
    cells, so ``B~`` of the cells (`smoothed_gradient`, cached too when not yet
    there) comes from the same shape-function values: only the spokes add
    points.

    Parameters
    ----------
    model : Model
    gauss : int
        As in `smoothed_gradient`.
    release : bool
        Drop the result from the model's cache (its last user: about as large
        as ``B~`` six times over, so a large model does not keep it).

    Returns
    -------
    sub : Cells
        ``s`` fan sub-cells.
    grad : SmoothedGradient
        ``x, y`` sparse ``(s, n)``.
    """
    from .quadrature import subdivide, tip_cells
    key = ("scni-fan", int(gauss))
    if key in model._cache:
        return model._cache.pop(key) if release else model._cache[key]
    cells = model.cells
    sub, parent = subdivide(cells, model.nodes, node_apex=tip_cells(model), mark_spokes=True)
    runs = _cell_runs(model, cells)
    passes = None
    if runs is not None:        # the sub-cells go with their cells' runs
        run_of = np.empty(len(cells), dtype=np.int64)
        place = np.empty(len(cells), dtype=np.int64)       # of a cell in its run
        for r, run in enumerate(runs):
            run_of[run], place[run] = r, np.arange(len(run))
        key_of = run_of[parent]
        sub_order = np.argsort(key_of, kind="stable")
        cuts = np.searchsorted(key_of[sub_order], np.arange(len(runs) + 1))
        passes = [[run, sub_order[cuts[r]:cuts[r + 1]]] for r, run in enumerate(runs)]

    def quadratures(sets, index):
        local = parent if index is None else place[parent[index[1]]]
        return fan_quadratures(model, *sets, local, gauss=gauss)

    have_cells = ("scni", int(gauss)) in model._cache
    grads = _gradients(model, [cells, sub], quadratures, passes, wanted=[not have_cells, True])
    if not have_cells:
        model._cache[("scni", int(gauss))] = grads[0]
    if not release:
        model._cache[key] = sub, grads[1]
    return sub, grads[1]


def _cell_runs(model, cells):
    """Runs of at most `CELLS_PER_PASS` cells, one pass of `smoothed_gradient` each,
    as index arrays into ``cells`` (None when one pass takes them all).

    A pass bounds the memory of the quadrature points and their shape functions,
    and a small one works in cache; the edges between runs are integrated in both.
    The cells are taken tile by tile along a serpentine path (by their nodes), a
    run about four tiles, so that every run is a compact block whatever the order
    of the nodes.
    """
    m = len(cells)
    if m <= CELLS_PER_PASS:
        return None
    size = -(-m // -(-m // CELLS_PER_PASS))          # runs of equal size, none tiny
    order = path_order(model.nodes[cells.node], model.domain.bounds, per_tile=size / 4)
    return [order[lo:lo + size] for lo in range(0, m, size)]


def _gradients(model, sets, quadratures, runs=None, wanted=None):
    """Smoothed gradients of several sets of cells, pass by pass.

    Parameters
    ----------
    sets : list of Cells
    quadratures : callable
        ``quadratures(subsets, index)``: one `BoundaryQuadrature` per set, with
        one set of points, for the cells ``subsets`` (``index``: their indices
        into ``sets``, one array per set; None when they are the sets).
    runs : list of lists of (r,) int arrays, optional
        For each pass, the cells of every set it takes (the runs of a set cover
        it once); by default one pass takes them all.
    wanted : list of bool, optional
        The sets whose gradients are computed (default all; the others only
        serve the quadrature of the rest).

    Returns
    -------
    list of SmoothedGradient or None
        One per set (None where not wanted).
    """
    wanted = [True] * len(sets) if wanted is None else wanted
    if runs is None:
        parts, points = _passes(model, quadratures, [(sets, None)], wanted)
        return [SmoothedGradient(*part[0], points) if want else None
                for part, want in zip(parts, wanted)]
    # a generator: one pass's cells alive at a time
    parts, points = _passes(model, quadratures,
                            (([cells.subset(i) for cells, i in zip(sets, run)], run) for run in runs),
                            wanted)
    out = [SmoothedGradient(*_place_runs(parts[i], [run[i] for run in runs]), points)
           if wanted[i] else None for i in range(len(sets))]
    del parts                # the passes' arrays are freed, but the C heap keeps them
    release_free_memory()
    return out


def _passes(model, quadratures, runs, wanted):
    """The cell integrals of every run ``(subsets, index)``: ``parts[set][run] = (x, y)``
    (for the ``wanted`` sets), and the number of quadrature points (the runs' cells
    are dropped pass by pass)."""
    parts, points = None, 0
    for run, index in runs:
        if parts is None:
            parts = [[] for _ in run]
        quads = quadratures(run, index)
        edges = quads[0].edge_integrals(quads[0].point_rows(model))
        for part, quad, want in zip(parts, quads, wanted):
            if want:
                part.append(quad.from_edges(edges))
        points += len(quads[0].points)
    return parts, points


def _place_runs(part, targets):
    """The x and y parts of the runs of one set of cells put together, run ``r``'s
    rows going to rows ``targets[r]``: two CSR with their own index arrays."""
    m, n = sum(len(t) for t in targets), part[0][0].shape[1]
    indptr = np.zeros(m + 1, dtype=np.int64)
    for (x, _), target in zip(part, targets):
        indptr[np.asarray(target) + 1] = np.diff(x.indptr)
    np.cumsum(indptr, out=indptr)
    indices = np.empty(indptr[-1], dtype=np.int32)
    vx, vy = np.empty(indptr[-1]), np.empty(indptr[-1])
    for (x, y), target in zip(part, targets):
        SK.place_rows(x.indptr, x.indices, x.data, y.data, np.asarray(target, dtype=np.int64),
                      indptr, indices, vx, vy)
    return _csr_pair(indptr, indices, vx, vy, (m, n))
