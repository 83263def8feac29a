"""Constrained natural-neighbour shape functions (C-NEM paper §2.2, §3)."""

from __future__ import annotations

from typing import Any, Literal, NamedTuple

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike

from .. import config
from ..errors import (CNEMError, GeometryError, UnsupportedError, check_array, check_choice,
                      check_real)
from .._parallel import work_chunks
from . import _kernels as K

__all__ = ["shape_functions", "point_rows", "PointRows", "ShapeGradients", "KINDS"]

KINDS = ("sibson", "laplace")


class ShapeGradients(tuple):
    """Shape functions at points with their derivatives: ``(Phi, dPhi_dx, dPhi_dy)``
    in 2-D (``dPhi_dz`` too in 3-D), CSR ``(p, n)`` of one pattern, and unpacked like
    that tuple.

    Attributes
    ----------
    value : scipy.sparse.csr_matrix, shape (p, n)
        ``Phi``.
    gradient : tuple of scipy.sparse.csr_matrix, shape (p, n)
        The derivatives along each axis, ``dim`` of them.
    dim : int
    """

    __slots__ = ()

    def __new__(cls, value: sp.csr_matrix, *gradient: sp.csr_matrix) -> ShapeGradients:
        return super().__new__(cls, (value,) + gradient)

    @property
    def value(self) -> sp.csr_matrix:
        """``Phi``, ``(p, n)``."""
        return self[0]

    @property
    def gradient(self) -> tuple[sp.csr_matrix, ...]:
        """``(dPhi_dx, dPhi_dy[, dPhi_dz])``, ``(p, n)`` each."""
        return tuple(self[1:])

    @property
    def dim(self) -> int:
        """The dimension: the number of derivatives."""
        return len(self) - 1

def path_order(pts, bounds, per_tile=4):
    """Order of points along a serpentine path through a square grid of tiles.

    Parameters
    ----------
    pts : (p, 2) float64 ndarray
    bounds : (4,) array_like
        ``xmin, ymin, xmax, ymax`` of the grid.
    per_tile : float
        About how many points a tile holds (4: locality for walks; more: runs
        of consecutive points that fill compact blocks).

    Returns
    -------
    (p,) int64 ndarray
        Tile by tile, the tiles row by row in alternating directions, the points
        of a tile in their given order.
    """
    k = max(1, int(np.ceil(np.sqrt(len(pts) / per_tile))))
    lo, hi = np.asarray(bounds[:2], dtype=float), np.asarray(bounds[2:], dtype=float)
    scale = k / np.maximum(hi - lo, 1e-300)
    return K.path_order(pts, lo[0], lo[1], scale[0], scale[1], k)


def _locate_sorted(model, nodes, spts, tol):
    """A triangle holding each of the path-ordered points ``spts`` (-1 outside), all
    in the model's local frame (``nodes``, ``tol`` too): a walk from each point to the
    next, started from a few points found with the R-tree of the circumcircles (each
    holds its triangle); for the points the walk cannot reach (across holes and
    cracks) the same tree, or one of the triangles when they are many (the trees are
    in the local frame too)."""
    nb_all = model.neighbors(across_regions=True)
    nch = work_chunks()
    starts = (np.arange(nch) * len(spts)) // nch
    seeds = K.locate(nodes, model.triangles, spts[starts],
                     *_candidates(model.circumcircles()[2], spts[starts], tol), tol)
    tri_of = K.locate_walk(nodes, model.triangles, nb_all, spts, seeds, nch)
    lost = np.flatnonzero(tri_of < 0)
    if lost.size:
        many = lost.size > config.TRIANGLE_TREE_AFTER * len(model.triangles)
        tree = model.triangle_tree() if many else model.circumcircles()[2]
        tri_of[lost] = K.locate(nodes, model.triangles, spts[lost],
                                *_candidates(tree, spts[lost], tol), tol)
    return tri_of


def _candidates(tree, local_points, tol):
    """The entries of a local R-tree whose boxes meet the boxes ``tol`` about local points."""
    return tree.query(local_points - tol, local_points + tol)


def shape_functions(model: Any, points: ArrayLike, *, kind: Literal["sibson", "laplace"] = "sibson",
                    triangles: ArrayLike | None = None, gradient: bool = False,
                    in_order: bool = True
                    ) -> sp.csr_matrix | tuple[sp.csr_matrix, np.ndarray] | ShapeGradients:
    """Constrained natural-neighbour coordinates of points.

    Parameters
    ----------
    model : Model
        Or any triangulation like it: ``nodes``, ``triangles``, ``domain``
        (``diameter``, ``bounds``) and the methods ``neighbors``,
        ``circumcircles`` and ``triangle_tree`` of `cnem.geometry.Model`, and its
        local frame (``frame``, ``local_nodes``) in which the coordinates are
        computed.
    points : (p, 2) array_like
        Points of the closed domain.
    kind : {"sibson", "laplace"}
    triangles : (p,) array_like of int, optional
        A triangle of ``model.triangles`` holding each point, or -1 to let the
        point be located. A point exactly on a crack face lies in triangles of
        both faces; give the triangle on the side wanted. By default (and for
        -1) the triangle the point is deepest inside.
    gradient : bool
        Also return the derivatives of the Sibson coordinates (analytic, Piper
        / Braun-Sambridge), for points inside cells: not at nodes nor on
        constraint segments, where they are not defined.

    Returns
    -------
    Phi : scipy.sparse.csr_matrix, shape (p, n)
        With ``gradient=True`` a `ShapeGradients`, the tuple ``(Phi, dPhi_dx,
        dPhi_dy)`` of three CSR matrices with the same pattern (``value``,
        ``gradient``, ``dim``).
        Row ``k`` holds the coordinates of ``points[k]`` with respect to the
        nodes: rows sum to 1, ``Phi @ model.nodes`` gives back the points, a
        point at a node gets its unit row, a point on a boundary, interface or
        crack-face segment interpolates linearly between the segment's ends,
        and no node has weight at a point it cannot see.

    Raises
    ------
    GeometryError
        Points outside the domain (how many, and the first few).
    """
    check_choice("kind", kind, KINDS)
    if gradient and kind != "sibson":
        raise UnsupportedError("gradient=True: gradients are available for kind='sibson' "
                               "only; pass kind='sibson' or gradient=False")
    pts = np.ascontiguousarray(check_real("points", points, error=GeometryError),
                               dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise GeometryError(f"points: expected a (p, 2) array, received shape {pts.shape}")
    if not np.isfinite(pts).all():
        raise GeometryError("points: coordinates must be finite, received NaN or inf")
    n = len(model.nodes)
    if len(pts) == 0:
        empty = sp.csr_matrix((0, n))
        if gradient:
            return ShapeGradients(empty, empty.copy(), empty.copy())
        return empty if in_order else (empty, np.zeros(0, dtype=np.int64))
    order, start, size, cols, vals, gx, gy, kinds = _coordinates(model, pts, kind, triangles,
                                                                 gradient)
    rows = np.arange(len(pts), dtype=np.int64) if not in_order and not gradient else order
    offsets, cols, vals, gx, gy = K.permute_rows(start, size, cols, vals, gx, gy, rows)
    if not in_order and not gradient:
        return sp.csr_matrix((vals, cols, offsets), shape=(len(pts), n)), order
    phi = sp.csr_matrix((vals, cols, offsets), shape=(len(pts), n))
    if not gradient:
        return phi
    singular = np.sort(order[kinds != K.CAVITY])
    if singular.size:
        raise GeometryError(
            f"{singular.size} points lie at a node or on a boundary, interface or crack "
            f"segment, where the gradients are not defined, first {pts[singular[:3]].tolist()}; "
            "evaluate gradients inside the cells")
    # own index arrays: scipy may sort one matrix's indices in place
    return ShapeGradients(phi, sp.csr_matrix((gx, cols.copy(), offsets.copy()), shape=phi.shape),
                          sp.csr_matrix((gy, cols.copy(), offsets.copy()), shape=phi.shape))


class PointRows(NamedTuple):
    """Coordinates of points as computed, row by row in the order the points were
    visited (no CSR matrix built): point ``order[s]`` has the values
    ``vals[start[s]:end[s]]`` at the nodes ``cols[start[s]:end[s]]``, of
    ``nodes`` nodes."""

    start: np.ndarray
    end: np.ndarray
    cols: np.ndarray
    vals: np.ndarray
    order: np.ndarray
    nodes: int


def point_rows(model: Any, points: ArrayLike, *, kind: Literal["sibson", "laplace"] = "sibson",
               triangles: ArrayLike | None = None) -> PointRows:
    """`shape_functions` of many points left in the layout the kernel writes them,
    for consumers that read the rows one by one (points and keywords as in
    `shape_functions`).

    Returns
    -------
    PointRows
    """
    check_choice("kind", kind, KINDS)
    pts = np.ascontiguousarray(points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 2 or not np.isfinite(pts).all():
        raise GeometryError(f"points: expected a (p, 2) array of finite coordinates, received "
                            f"shape {pts.shape}")
    if len(pts) == 0:
        empty = np.zeros(0, dtype=np.int64)
        return PointRows(empty, empty, np.zeros(0, dtype=np.int32), np.zeros(0), empty,
                         len(model.nodes))
    order, start, size, cols, vals, _, _, _ = _coordinates(model, pts, kind, triangles, False)
    return PointRows(start, start + size, cols, vals, order, len(model.nodes))


def _coordinates(model, pts, kind, triangles, gradient):
    """The kernel's rows for ``(p, 2)`` points (``p > 0``), in visit order ``order``:
    ``(order, start, size, cols, vals, gx, gy, kinds)`` (see `K.natural`)."""
    nb = model.neighbors()
    frame, nodes = model.frame, model.local_nodes()
    local = frame.to_local(pts)
    tol = max(config.SHAPE_TOL * model.domain.diameter / frame.scale,
              config.ROUNDOFF_ULPS * frame.resolution)
    order = path_order(local, frame.to_local(np.reshape(model.domain.bounds, (2, 2))).ravel())
    spts = K.gather_rows(local, order)
    if triangles is None:
        tri_of = _locate_sorted(model, nodes, spts, tol)
    else:
        values = check_array("triangles", triangles, shape=(len(pts),), error=GeometryError,
                             fix="pass one triangle index per point, or -1 to locate it")
        hint = values.astype(np.int64)
        if (hint != values).any() or (hint < -1).any() or (hint >= len(model.triangles)).any():
            raise GeometryError(f"triangles: expected {len(pts)} indices into the "
                                f"{len(model.triangles)} triangles (or -1), received "
                                f"shape {hint.shape}, range [{hint.min()}, {hint.max()}]")
        hint = hint[order]
        given = hint >= 0
        tri_of = np.full(len(pts), -1, dtype=np.int64)
        tri_of[given] = K.locate(nodes, model.triangles, spts[given],
                                 np.arange(given.sum() + 1, dtype=np.int64), hint[given], tol)
        if not given.all():
            tri_of[~given] = _locate_sorted(model, nodes, spts[~given], tol)
    outside = np.sort(order[tri_of < 0])
    if outside.size:
        where = "the domain" if triangles is None else "the domain (or their given triangles)"
        raise GeometryError(
            f"{outside.size} of {len(pts)} points lie outside {where}, first (index: point) "
            + ", ".join(f"{i}: {pts[i].tolist()}" for i in outside[:5]))
    slots = config.ROW_SLOTS
    while True:                                # rows in path order, chunk by chunk
        start, size, cols, vals, gx, gy, kinds, full = K.natural(
            nodes, model.triangles, nb, spts, tri_of, tol, tol, work_chunks(),
            kind == "laplace", gradient, slots)
        if not full:
            break
        slots *= 2
    if gradient:                                          # d/dx = d/dx_local / scale
        gx /= frame.scale
        gy /= frame.scale
    failed = np.sort(order[kinds == K.FAILED])            # kinds are in path order
    if failed.size:
        raise CNEMError(
            f"the natural-neighbour cavity of {failed.size} points was inconsistent (round-off "
            f"on a circumcircle), first {pts[failed[:3]].tolist()}; please report this case")
    return order, start, size, cols, vals, gx, gy, kinds
