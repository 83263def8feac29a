"""The smoothed gradients of 3-D cells from quadratures on their boundary facets.

A 3-D cell's boundary is given as triangles with outward unit normals (the
cells' facets, cut into triangles); the smoothed derivative of shape function
``phi_I`` on cell ``k`` (the C-NEM paper's eq. 30 in 3-D) is

    b~_Ii(k) = 1 / V_k  sum_f  int_f phi_I n_i dA

integrated by a triangle rule on every facet triangle. Any rule exact for
linear functions keeps the integration constraint (the patch test): the shape
functions reproduce ``x`` and ``int_dV x (x) n dA = V I`` over a closed surface.

The stabilisation's sub-cells are the pyramids from each cell's node to its
facet triangles (tetrahedra: a constrained Voronoi cell is star-shaped from its
node, since every point of it sees the node). A sub-cell's boundary is its facet
triangle plus three *spokes* (node, facet edge), shared with the neighbouring
sub-cells of the same cell, where they cancel; the spokes are integrated by
their centroid alone, exact for the linear fields the shape functions reproduce.
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np
import scipy.sparse as sp
from skfem.quadrature import get_quadrature
from skfem.refdom import RefTri

from ..errors import GeometryError
from .smoothed_gradient import SmoothedGradient

__all__ = ["facet_rule", "facet_gradient", "pyramid_sub_cells", "cell_gradient_3d", "sub_cell_gradient_3d"]

#: Shape functions at points: ``evaluate(points (q, 3)) -> csr (q, n)``.
Evaluate = Callable[[np.ndarray], sp.csr_matrix]


def facet_rule(triangles: np.ndarray, order: int = 2) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points and weights of a triangle rule of degree ``order`` on 3-D triangles.

    Parameters
    ----------
    triangles : (t, 3, 3) ndarray
        Corners of each triangle.
    order : int
        Polynomial degree integrated exactly (scikit-fem's rules).

    Returns
    -------
    triangle : (q,) int64 ndarray
        The triangle of each point.
    points : (q, 3) ndarray
    weights : (q,) ndarray
        Positive, summing to each triangle's area.
    """
    ref, w = get_quadrature(RefTri, order)              # reference triangle, area 1/2
    e1 = triangles[:, 1] - triangles[:, 0]
    e2 = triangles[:, 2] - triangles[:, 0]
    jac = np.linalg.norm(np.cross(e1, e2), axis=1)      # twice the area
    points = (triangles[:, None, 0] + ref[0][None, :, None] * e1[:, None]
              + ref[1][None, :, None] * e2[:, None])
    owner = np.repeat(np.arange(len(triangles), dtype=np.int64), len(w))
    return owner, points.reshape(-1, 3), (jac[:, None] * w[None, :]).reshape(-1)


def facet_gradient(facet_triangles: np.ndarray, facet_cell: np.ndarray, facet_normal: np.ndarray,
                   volume: np.ndarray, evaluate: Evaluate, *, order: int = 2,
                   spokes: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None = None
                   ) -> SmoothedGradient:
    """``B~`` of 3-D cells from their boundary triangles.

    Parameters
    ----------
    facet_triangles : (f, 3, 3) ndarray
        The cells' boundary triangles, in the model's local frame (coordinates of the
        size of the body, not of its distance from the origin: the normals and the
        rule's points keep their digits).
    facet_cell : (f,) int64 ndarray
        The cell each bounds.
    facet_normal : (f, 3) ndarray
        Outward unit normals (out of ``facet_cell``).
    volume : (m,) ndarray
        The cells' volumes.
    evaluate : callable ``(q, 3) -> csr (q, n)``
        The shape functions at points.
    order : int
        Degree of the triangle rule on the facets.
    spokes : (centroid (s, 3), area-normal (s, 3), cell_a (s,), cell_b (s,)), optional
        Faces integrated by one point (the sub-cells' spokes, `pyramid_sub_cells`),
        with the normal out of ``cell_a`` and, where ``cell_b >= 0``, the opposite
        one out of ``cell_b``.

    Returns
    -------
    SmoothedGradient
        ``x, y, z`` sparse ``(m, n)``.
    """
    m = len(volume)
    if np.any(~(volume > 0)):
        bad = np.flatnonzero(~(volume > 0))[:5]
        raise GeometryError(f"expected cells of positive volume, received volumes "
                            f"{volume[bad].tolist()} at cells {bad.tolist()}")
    owner, points, weights = facet_rule(facet_triangles, order)
    column = np.arange(len(points), dtype=np.int64)
    cell = facet_cell[owner]
    flux = weights[:, None] * facet_normal[owner]                       # (q, 3)
    if spokes is not None:
        centre, area_normal, a, b = spokes
        shared = np.flatnonzero(b >= 0)
        at = len(points) + np.arange(len(centre), dtype=np.int64)
        points = np.concatenate([points, centre])
        column = np.concatenate([column, at, at[shared]])
        cell = np.concatenate([cell, a, b[shared]])
        flux = np.concatenate([flux, area_normal, -area_normal[shared]])
    phi = evaluate(points)
    q = len(points)
    parts = []
    for i in range(3):
        to_cell = sp.csr_matrix((flux[:, i] / volume[cell], (cell, column)), shape=(m, q))
        parts.append((to_cell @ phi).tocsr())
    return SmoothedGradient(*parts, points=q)


def pyramid_sub_cells(node_xyz: np.ndarray, facet_triangles: np.ndarray, facet_cell: np.ndarray,
                      rtol: float = 1e-12) -> tuple[np.ndarray, np.ndarray, np.ndarray, tuple]:
    """The tetrahedra from each cell's node to its facet triangles, as sub-cells.

    Parameters
    ----------
    node_xyz : (m, 3) ndarray
        The node of every cell.
    facet_triangles : (f, 3, 3) ndarray
        The cells' boundary triangles, oriented with outward normals (right-hand rule).
    facet_cell : (f,) int64 ndarray
    rtol : float
        Sub-cells thinner than this fraction of their facet's size (the facets
        through the node: the cell's boundary faces on which the node lies) are
        dropped; they have no volume.

    Returns
    -------
    sub_parent : (s,) int64 ndarray
        The cell each sub-cell belongs to; its facet triangle is ``kept[i]``.
    kept : (s,) int64 ndarray
        Index of each sub-cell's facet triangle.
    volume : (s,) ndarray
    spokes : (centroid (k, 3), area-normal (k, 3), sub_a (k,), sub_b (k,))
        The spoke faces shared by two sub-cells, oriented out of ``sub_a``.
    """
    apex = node_xyz[facet_cell]
    a, b, c = (facet_triangles[:, i] - apex for i in range(3))
    six_v = np.einsum("ij,ij->i", a, np.cross(b, c))            # > 0: apex behind the facet
    size = np.max(np.linalg.norm(facet_triangles - facet_triangles[:, [1, 2, 0]], axis=2), axis=1)
    kept = np.flatnonzero(six_v > rtol * size ** 3)
    # each spoke (apex, p, q) of a kept facet triangle, keyed by its cell and edge
    tri = facet_triangles[kept]
    parent = facet_cell[kept]
    spoke_p = np.concatenate([tri[:, i] for i in range(3)])
    spoke_q = np.concatenate([tri[:, (i + 1) % 3] for i in range(3)])
    owner = np.tile(np.arange(len(kept), dtype=np.int64), 3)
    centre_apex = node_xyz[parent[owner]]
    # the spoke face (apex, q, p) seen from sub-cell `owner` has the outward normal
    # (q - apex) x (p - apex) (the facet triangle (p, q, .) turns the other way)
    area_normal = 0.5 * np.cross(spoke_q - centre_apex, spoke_p - centre_apex)
    centroid = (centre_apex + spoke_p + spoke_q) / 3.0
    # match each spoke with its twin (the same edge traversed q -> p in the same cell)
    key_pq = _edge_keys(parent[owner], spoke_p, spoke_q)
    key_qp = _edge_keys(parent[owner], spoke_q, spoke_p)
    order = np.argsort(key_pq, kind="stable")
    pos = np.searchsorted(key_pq[order], key_qp)
    pos = np.minimum(pos, len(order) - 1)
    twin = order[pos]
    matched = key_pq[twin] == key_qp
    first = matched & (np.arange(len(owner)) < twin)
    unmatched = ~matched
    # an unmatched spoke lies on a dropped (flat) sub-cell's side: its face is then part
    # of the cell boundary through the node and carries no flux difference; keep it
    # one-sided so that each sub-cell stays closed
    sub_a = np.concatenate([owner[first], owner[unmatched]])
    sub_b = np.concatenate([owner[twin[first]], np.full(unmatched.sum(), -1, dtype=np.int64)])
    centre = np.concatenate([centroid[first], centroid[unmatched]])
    an = np.concatenate([area_normal[first], area_normal[unmatched]])
    return parent, kept, six_v[kept] / 6.0, (centre, an, sub_a, sub_b)


def _edge_keys(cell, p, q):
    """One hashable key per (cell, directed edge) from exact coordinates (rows of bytes)."""
    rows = np.column_stack([cell.astype(np.float64), p, q])
    return np.ascontiguousarray(rows).view(np.dtype((np.void, rows.dtype.itemsize * 7))).ravel()


def cell_gradient_3d(model: Any, cells: Any, order: int = 2) -> SmoothedGradient:
    """``B~`` of a 3-D model's cells (`facet_gradient` on their facet triangles, the
    model's shape functions).

    Parameters
    ----------
    model : Model3D
    cells : Cells3D
        ``model.cells`` or other cells of the model with facets.
    order : int
        Degree of the triangle rule on the facets.

    Returns
    -------
    SmoothedGradient
    """
    return facet_gradient(cells.facet_triangles, cells.facet_cell, cells.facet_normal,
                          cells.volume, model.shape_functions, order=order)


def sub_cell_gradient_3d(model: Any, order: int = 2) -> tuple[Any, SmoothedGradient]:
    """The pyramid sub-cells of a 3-D model's cells and their ``B~``, from the cells'
    facet points and one point on each spoke.

    Parameters
    ----------
    model : Model3D
    order : int
        Degree of the triangle rule on the facets.

    Returns
    -------
    sub : Cells3D
        One cell per kept pyramid, with its parent's node and region.
    grad : SmoothedGradient
    """
    cells = model.cells
    parent, kept, volume, spokes = pyramid_sub_cells(model.nodes[cells.node],
                                                     cells.facet_triangles, cells.facet_cell)
    sub = type(cells)(cells.node[parent], cells.region[parent], volume,
                      cells.facet_triangles[kept], np.arange(len(kept), dtype=np.int64),
                      cells.facet_normal[kept])
    grad = facet_gradient(sub.facet_triangles, sub.facet_cell, sub.facet_normal, volume,
                          model.shape_functions, order=order, spokes=spokes)
    return sub, grad
