"""Quadrature over the integration-cell polygons (for errors and post-processing)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from skfem.quadrature import get_quadrature
from skfem.refdom import RefTet, RefTri

from .._aliases import renamed_attributes
from ..errors import InputError, check_count
from .subdivision import cell_triangles

if TYPE_CHECKING:
    from ..geometry.model import Cells

__all__ = ["triangle_quadrature", "tetrahedron_quadrature", "cell_quadrature"]

#: Old names (one release): see `cnem._aliases`.
__getattr__ = renamed_attributes(__name__, {
    "subdivide": ("cnem.assembly.subdivision", "subdivide"),
    "tip_cells": ("cnem.assembly.subdivision", "tip_cells")})


#: The highest polynomial degree of scikit-fem's triangle rules.
MAX_TRIANGLE_ORDER = 19


def _triangle_rule(corners, order):
    """Gauss points and signed weights of a triangle rule of degree ``order``."""
    ref, w = get_quadrature(RefTri, order)          # reference triangle, area 1/2
    e1 = corners[:, 1] - corners[:, 0]
    e2 = corners[:, 2] - corners[:, 0]
    jac = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    points = (corners[:, None, 0] + ref[0][None, :, None] * e1[:, None]
              + ref[1][None, :, None] * e2[:, None])
    return points, jac[:, None] * w[None, :]        # signed: negative fan triangles subtract


def _collapsed_rule(apex, b, c, order):
    """A rule for integrands like ``1/r`` about ``apex`` on triangles ``(apex, b, c)``.

    The unit square is mapped onto the triangle with its side ``u = 0`` collapsed
    onto the apex (Duffy): ``x = apex + u ((1 - v) (b - apex) + v (c - apex))``,
    Jacobian ``u * 2 * area``. The factor ``u`` cancels a ``1/r`` singularity, so a
    tensor Gauss rule converges fast; it is exact for polynomials of degree ``order``.

    Returns
    -------
    points : (t, g, 2) ndarray
    weights : (t, g) ndarray
        Signed like the triangle.
    """
    g, w = np.polynomial.legendre.leggauss(order // 2 + 2)
    g, w = 0.5 * (g + 1.0), 0.5 * w
    u, v = (a.reshape(-1) for a in np.meshgrid(g, g, indexing="ij"))
    wu = np.outer(w, w).reshape(-1) * u
    pb, pc = b - apex, c - apex
    jac = pb[:, 0] * pc[:, 1] - pb[:, 1] * pc[:, 0]
    ray = (1.0 - v)[None, :, None] * pb[:, None] + v[None, :, None] * pc[:, None]
    return apex[:, None] + u[None, :, None] * ray, jac[:, None] * wu[None, :]


def _split_at_singular(corners, singular, rel_tol=1e-9):
    """Triangles holding a singular point (closed: a point closer than ``rel_tol``
    times an edge's length to its line counts as on it), split at the point into
    triangles with it as apex; their signed areas add up to the triangle's.

    Returns
    -------
    hit : (t,) bool ndarray
        Triangles that hold a singular point.
    source : (s,) int64 ndarray
        The triangle each piece comes from.
    apex, b, c : (s, 2) ndarray
        The pieces ``(apex, b, c)`` (pieces of zero area left out).
    """
    hit = np.zeros(len(corners), dtype=bool)
    edge2 = ((corners[:, [1, 2, 0]] - corners) ** 2).sum(axis=2)          # (t, 3)
    pieces = []
    for p in singular:
        rel = corners - p                                                # (t, 3, 2)
        nxt = rel[:, [1, 2, 0]]
        cross = rel[:, :, 0] * nxt[:, :, 1] - rel[:, :, 1] * nxt[:, :, 0]   # 2 x piece areas
        sign = np.sign(cross.sum(axis=1))[:, None]                       # the triangle's
        on_line = np.abs(cross) <= rel_tol * edge2
        inside = ~hit & (sign[:, 0] != 0) & ((sign * cross > 0) | on_line).all(axis=1)
        hit |= inside
        for k in range(3):
            idx = np.flatnonzero(inside & ~on_line[:, k])
            pieces.append((idx, np.broadcast_to(p, (len(idx), 2)), corners[idx, k],
                           corners[idx, (k + 1) % 3]))
    if not pieces:
        empty = np.zeros((0, 2))
        return hit, np.zeros(0, np.int64), empty, empty, empty
    source, apex, b, c = (np.concatenate(x) for x in zip(*pieces))
    return hit, source, apex, b, c


def triangle_quadrature(corners: np.ndarray, order: int = 4, *,
                        singular: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Quadrature points and weights on triangles, collapsed at singular points.

    Parameters
    ----------
    corners : (t, 3, 2) ndarray
        Triangles (clockwise ones get negative weights).
    order : int
        Polynomial degree integrated exactly on each triangle.
    singular : (s, 2) array_like, optional
        Points where the integrand may grow like ``1/r`` (crack tips: squared
        ``r^-1/2`` stresses). The triangles holding one are split at it and
        integrated by a collapsed (Duffy) rule, which removes the singularity;
        a plain Gauss rule there has an error that does not shrink with the
        triangle's size.

    Returns
    -------
    triangle : (q,) int64 ndarray
        The triangle of each point.
    points : (q, 2) ndarray
    weights : (q,) ndarray
        Summing to each triangle's signed area.
    """
    order = check_count("order", order)
    if order > MAX_TRIANGLE_ORDER:
        raise InputError(f"order: expected a polynomial degree from 1 to {MAX_TRIANGLE_ORDER} "
                         f"(the triangle rules scikit-fem has), received {order}")
    singular = np.zeros((0, 2)) if singular is None else np.asarray(singular, float).reshape(-1, 2)
    hit, source, apex, b, c = _split_at_singular(corners, singular)
    regular = np.flatnonzero(~hit)
    points, weights = _triangle_rule(corners[regular], order)
    owners = [np.repeat(regular, weights.shape[1])]
    points, weights = [points.reshape(-1, 2)], [weights.reshape(-1)]
    if len(source):
        p, w = _collapsed_rule(apex, b, c, order)
        owners.append(np.repeat(source, w.shape[1]))
        points.append(p.reshape(-1, 2))
        weights.append(w.reshape(-1))
    return np.concatenate(owners), np.concatenate(points), np.concatenate(weights)


def tetrahedron_quadrature(corners: np.ndarray, order: int = 4
                           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """scikit-fem's rule of degree ``order`` on tetrahedra.

    Parameters
    ----------
    corners : (t, 4, 3) ndarray
        Tetrahedra (negatively oriented ones get negative weights).
    order : int
        Polynomial degree integrated exactly on each tetrahedron.

    Returns
    -------
    tet : (q,) int64 ndarray
        The tetrahedron of each point.
    points : (q, 3) ndarray
    weights : (q,) ndarray
        Summing to each tetrahedron's signed volume.
    """
    ref, ref_weights = get_quadrature(RefTet, order)             # (3, r), (r,): volume 1/6
    jac = np.moveaxis(corners[:, 1:] - corners[:, :1], 1, 2)     # (t, 3, 3): columns edges
    points = corners[:, :1] + np.einsum("tij,jr->tri", jac, ref)
    weights = np.linalg.det(jac)[:, None] * ref_weights[None, :]
    owner = np.repeat(np.arange(len(corners)), len(ref_weights))
    return owner, points.reshape(-1, 3), weights.reshape(-1)


def cell_quadrature(cells: Cells, nodes: np.ndarray, order: int = 4, *,
                    singular: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Quadrature points and weights on every cell polygon (3-D: polyhedron).

    Parameters
    ----------
    cells : Cells or Cells3D
        ``m`` cells.
    nodes : (n, 2) or (n, 3) ndarray
        The model's nodes.
    order : int
        Polynomial degree integrated exactly on each triangle of the cells.
    singular : (s, 2) array_like, optional
        Crack tips: collapsed rules about them (see `triangle_quadrature`).

    Returns
    -------
    cell : (q,) int64 ndarray
        The cell of each point.
    points : (q, 2) ndarray
    weights : (q,) ndarray
        ``sum(weights[cell == k]) == cells.measure[k]``.
    """
    if nodes.shape[1] == 3:
        # the cones from each cell's apex (else its node) over its facet triangles, signed:
        # they make the cell however its facets are shaped
        tri = cells.facet_triangles
        apex = (cells.apex if cells.apex is not None else nodes[cells.node])[cells.facet_cell]
        corners = np.concatenate([apex[:, None], tri], axis=1)
        tet, points, weights = tetrahedron_quadrature(corners, order)
        return cells.facet_cell[tet], points, weights
    owner, corners = cell_triangles(cells, nodes)
    triangle, points, weights = triangle_quadrature(corners, order, singular=singular)
    return owner[triangle], points, weights
