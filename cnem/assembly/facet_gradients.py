"""The smoothed gradients of 3-D cells from quadratures on their boundary facets.

A 3-D cell's boundary is given as triangles with outward unit normals (the
cells' facets, cut into triangles); the smoothed derivative of shape function
``phi_I`` on cell ``k`` (the C-NEM paper's eq. 30 in 3-D) is

    b~_Ii(k) = 1 / V_k  sum_f  int_f phi_I n_i dA

integrated by one point per facet, its centroid (`facet_points`). The rule is
exact for linear functions, which keeps the divergence consistency (the shape
functions reproduce ``x`` and ``int_dV x (x) n dA = V I`` over a closed
surface), and it depends on the facet polygon alone, so the two cells that share
a facet evaluate it at the same point and the integration constraint holds
whatever triangles each cell's facets were cut into.

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
from ..errors import GeometryError
from .smoothed_gradient import SmoothedGradient

__all__ = ["facet_points", "facet_gradient", "pyramid_sub_cells", "cell_gradient_3d", "sub_cell_gradient_3d"]

#: Facet normals are told apart to ``1 / PLANE_RESOLUTION`` (unit normals of one
#: cell's distinct Voronoi facets differ by far more).
PLANE_RESOLUTION = 2.0 ** 24

#: Shape functions at points: ``evaluate(points (q, 3)) -> csr (q, n)``.
Evaluate = Callable[[np.ndarray], sp.csr_matrix]


def facet_points(facet_triangles: np.ndarray, facet_cell: np.ndarray, facet_normal: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One point per facet of every cell: the centroid of its triangles, with their
    summed area times the facet's normal.

    A facet is the set of a cell's triangles of one outward normal (to
    `PLANE_RESOLUTION`). Its centroid and area depend on the polygon only, not on
    how it was cut into triangles, so the two cells that share a facet evaluate
    the shape functions at the same point and their integrals cancel (the
    integration constraint), whichever triangles each was given.

    Parameters
    ----------
    facet_triangles : (f, 3, 3) ndarray
    facet_cell : (f,) int64 ndarray
    facet_normal : (f, 3) ndarray
        Outward unit normals.

    Returns
    -------
    cell : (k,) int64 ndarray
    point : (k, 3) ndarray
    area_normal : (k, 3) ndarray
    """
    tri = facet_triangles
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    key = np.column_stack([facet_cell, np.round(facet_normal * PLANE_RESOLUTION)]).astype(np.int64)
    _, first, group = np.unique(key, axis=0, return_index=True, return_inverse=True)
    group = group.reshape(-1)
    total = np.bincount(group, weights=area, minlength=len(first))
    centre = tri.mean(axis=1)
    point = np.column_stack([np.bincount(group, weights=area * centre[:, i], minlength=len(first))
                             for i in range(3)]) / total[:, None]
    normal = np.column_stack([np.bincount(group, weights=area * facet_normal[:, i],
                                          minlength=len(first)) for i in range(3)])
    return facet_cell[first], point, normal


def facet_gradient(facet_triangles: np.ndarray, facet_cell: np.ndarray, facet_normal: np.ndarray,
                   volume: np.ndarray, evaluate: Evaluate, *,
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
    cell, points, flux = facet_points(facet_triangles, facet_cell, facet_normal)
    column = np.arange(len(points), dtype=np.int64)
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


def cell_gradient_3d(model: Any, cells: Any) -> SmoothedGradient:
    """``B~`` of a 3-D model's cells (`facet_gradient` on their facet triangles, the
    model's shape functions).

    Parameters
    ----------
    model : Model3D
    cells : Cells3D
        ``model.cells`` or other cells of the model with facets.

    Returns
    -------
    SmoothedGradient
    """
    return facet_gradient(cells.facet_triangles, cells.facet_cell, cells.facet_normal,
                          cells.volume, model.shape_functions)


def sub_cell_gradient_3d(model: Any) -> tuple[Any, SmoothedGradient]:
    """The pyramid sub-cells of a 3-D model's cells and their ``B~``, from the cells'
    facet points and one point on each spoke.

    Parameters
    ----------
    model : Model3D

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
                          model.shape_functions, spokes=spokes)
    return sub, grad
