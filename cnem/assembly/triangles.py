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

from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp

from ..errors import GeometryError
from .basis import CellBasis

if TYPE_CHECKING:
    from ..geometry.model import Model

__all__ = ["triangle_basis"]


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
