"""Linear triangles (P1) on a model's constrained Delaunay triangulation.

The SCNI stiffness couples every node with the nodes of its neighbours'
cells (about 28 nodes, 56 non-zeros per row in 2-D elasticity); the P1
stiffness of the same nodes on their triangulation couples only the
triangles' corners (about 12 non-zeros per row) and is spectrally close to
it. Smoothed aggregation built on the P1 matrix is a cheaper and leaner
preconditioner for CG on the SCNI system than smoothed aggregation built on
the SCNI matrix itself (see `cnem.solvers.linsolve.solve_spd`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
import scipy.sparse as sp

from .. import config
from ..errors import GeometryError
from .basis import CellBasis

if TYPE_CHECKING:
    from ..geometry.model import Model

__all__ = ["triangle_basis", "tetrahedron_basis", "simplex_basis"]


def triangle_basis(model: Model, *, vector: bool = False) -> CellBasis:
    """The P1 hat functions of the model's nodes on its triangles, one-point rule.

    Parameters
    ----------
    model : Model
        ``n`` nodes, ``t`` triangles (cracks opened: the faces are apart).
    vector : bool

    Returns
    -------
    CellBasis
        Over ``t`` integration points (the triangles' centroids, weights their
        areas): values 1/3 at the corners and the constant gradients, exact for
        forms of the gradients with coefficients constant per triangle.
    """
    tri = model.triangles
    corners = model.nodes[tri]                                   # (t, 3, 2)
    # grad phi_i = the opposite edge turned clockwise over twice the area
    opposite = corners[:, [2, 0, 1]] - corners[:, [1, 2, 0]]       # edge (j -> k) opposite i
    e1, e2 = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    twice = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    if not (twice > 0).all():
        raise GeometryError(f"triangle_basis: {int((twice <= 0).sum())} of {len(tri)} triangles "
                            "are degenerate or clockwise; expected counter-clockwise triangles of "
                            "positive area: move the collinear nodes")
    dx = -opposite[:, :, 1] / twice[:, None]
    dy = opposite[:, :, 0] / twice[:, None]
    t, n = len(tri), len(model.nodes)
    indptr = np.arange(0, 3 * t + 1, 3)
    cols = tri.reshape(-1)

    def op(values):
        return sp.csr_matrix((values.reshape(-1), cols, indptr), shape=(t, n))

    return CellBasis.from_operators(model, op(np.full((t, 3), 1.0 / 3.0)), (op(dx), op(dy)),
                                    0.5 * twice, corners.mean(axis=1), vector=vector)


def tetrahedron_basis(model: Any, *, vector: bool = False) -> tuple[CellBasis, np.ndarray]:
    """The P1 hat functions of a 3-D model's nodes on its tetrahedra, one-point rule.

    Parameters
    ----------
    model : Model3D
        ``n`` nodes, ``t`` positively oriented tetrahedra.
    vector : bool

    Returns
    -------
    basis : CellBasis
        Over the tetrahedra of positive volume (flat slivers of cospherical nodes
        carry no volume and are left out): values 1/4 at the corners and the
        constant gradients.
    keep : (t,) bool ndarray
        Which of ``model.tetrahedra`` it holds.
    """
    corners = model.nodes[model.tetrahedra]                        # (t, 4, 3)
    edges = corners[:, 1:] - corners[:, :1]
    six_v = np.linalg.det(edges)
    size = np.linalg.norm(edges, axis=2).max(axis=1)
    keep = six_v > config.SHAPE_TOL * size ** 3
    tets, edges, six_v = model.tetrahedra[keep], edges[keep], six_v[keep]
    inv = np.linalg.inv(edges)                                    # rows: d lambda_1..3 / dx
    grad = np.concatenate([-inv.sum(axis=2)[:, None, :], np.transpose(inv, (0, 2, 1))], axis=1)
    t, n = len(tets), len(model.nodes)
    indptr = np.arange(0, 4 * t + 1, 4)
    cols = tets.reshape(-1)

    def op(values):
        return sp.csr_matrix((values.reshape(-1), cols, indptr), shape=(t, n))

    return CellBasis.from_operators(model, op(np.full((t, 4), 0.25)),
                                    tuple(op(grad[:, :, i]) for i in range(3)), six_v / 6.0,
                                    corners[keep].mean(axis=1), vector=vector), keep


def simplex_basis(model: Any, *, vector: bool = False) -> tuple[CellBasis, np.ndarray]:
    """P1 on the model's own simplices: `triangle_basis` in 2-D, `tetrahedron_basis` in 3-D.

    Returns
    -------
    basis : CellBasis
    region : (s,) int64 ndarray
        The region of each of the basis' simplices.
    """
    if model.nodes.shape[1] == 3:
        basis, keep = tetrahedron_basis(model, vector=vector)
        return basis, model.tet_region[keep]
    return triangle_basis(model, vector=vector), model.triangle_region
