"""`ModelProblem`: what every C-NEM problem on a model shares, linear or finite strain.

The model (checked), its dimension, the owner of its smoothed gradients
(`cnem.assembly.GradientCache`, one per model and Gauss order), the conditions on its
nodes (`cnem.solvers.conditions.Conditions` with the model's boundary edges) and the
nodal loads of the tractions and body forces. `cnem.Elasticity` and
`cnem.Hyperelasticity` derive from it.

>>> import cnem
>>> model = cnem.discretize(cnem.nodes.regular(cnem.geometry.rectangle(), 0.5))
>>> prob = ModelProblem(model, gauss=2, gradients=None, caller="example")
>>> prob.add_body_force([0.0, -1.0])
>>> float(prob.nodal_load()[:, 1].sum())               # the body's weight: area 1
-1.0
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from skfem.quadrature import get_quadrature
from skfem.refdom import RefTri

from ..assembly.gradients import GradientCache
from ..errors import GeometryError
from ..geometry.model import check_model
from ..geometry.topology import constraint_edges
from ..solvers.conditions import Conditions, traction_at

if TYPE_CHECKING:
    from ..geometry.domain import Domain
    from ..geometry.model import Model

__all__ = ["ModelProblem"]


class ModelProblem(Conditions):
    """Conditions, loads and smoothed gradients of a problem on a C-NEM model.

    Parameters
    ----------
    model : Model
        ``n`` nodes, ``m`` integration cells.
    gauss : int
        Gauss points per cell-edge piece in the smoothed gradients.
    gradients : GradientCache, optional
        The model's smoothed gradients at ``gauss``, to share with other problems
        on the model; by default the problem keeps its own.
    caller : str
        The problem class, named in the errors.

    Attributes
    ----------
    model : Model
    dim : int
        The model's dimension.
    gauss : int
    gradients : GradientCache
        The owner of the smoothed gradients this problem uses.
    cells : Cells
        The integration cells (``model.cells`` unless a subclass sets others).
    """

    #: Dirichlet predicates see the model's nodes (direct imposition: Kronecker delta).
    points_name = "model.nodes"

    def __init__(self, model: Model, *, gauss: int, gradients: GradientCache | None,
                 caller: str):
        self.model = check_model(model, caller)
        self.dim = model.nodes.shape[1]
        self.gauss = gauss
        if gradients is None:
            gradients = GradientCache(model, gauss=gauss)
        elif gradients.model is not model or gradients.gauss != gauss:
            raise GeometryError(f"gradients: expected the GradientCache of this model with "
                                f"gauss={gauss}, received {gradients!r}; build them with "
                                f"GradientCache(model, gauss={gauss})")
        self.gradients = gradients
        self.cells = model.cells
        super().__init__()

    @property
    def condition_points(self) -> np.ndarray:
        """``(n, dim)`` the nodes that conditions refer to (``model.nodes``)."""
        return self.model.nodes

    @property
    def condition_domain(self) -> Domain:
        """The model's domain: its named boundaries may be given as ``where``."""
        return self.model.domain

    def boundary_edges(self) -> tuple:
        """The model's boundary pieces with the body on one side and their outward unit
        normals (see `Conditions.boundary_edges`): constraint edges ``(e, 2)`` in 2-D,
        boundary triangles ``(e, 3)`` in 3-D."""
        if self.dim == 3:
            return self.model.boundary_with_normals()
        tri = self.model.triangles
        edges, _ = constraint_edges(tri, self.model.neighbors(across_regions=True))
        d = self.model.nodes[edges[:, 1]] - self.model.nodes[edges[:, 0]]
        normal = np.column_stack([d[:, 1], -d[:, 0]]) / np.linalg.norm(d, axis=1)[:, None]
        return edges, normal

    def nodal_load(self) -> np.ndarray:
        """The nodes' share of the tractions (3-point Gauss rule on each edge, a
        degree-4 rule on each 3-D boundary triangle: exact up to quadratic tractions)
        and of the body forces (one value per cell, at its node), on the reference
        configuration.

        Returns
        -------
        (n, dim) ndarray
        """
        n, d = self.model.nodes.shape
        f = np.zeros((n, d))
        g, w = np.polynomial.legendre.leggauss(3)
        s, w = 0.5 * (g + 1.0), 0.5 * w
        x = self.model.nodes
        for traction in self.tractions:
            edges, normal, t = traction.edges, traction.normal, traction.value
            if d == 3:
                f += triangle_loads(x, edges, normal, t)
                continue
            a, b = x[edges[:, 0]], x[edges[:, 1]]
            length = np.linalg.norm(b - a, axis=1)
            for sk, wk in zip(s, w):
                pts = a + sk * (b - a)
                tr = traction_at(t, pts, normal)
                np.add.at(f, edges[:, 0], (wk * (1.0 - sk) * length)[:, None] * tr)
                np.add.at(f, edges[:, 1], (wk * sk * length)[:, None] * tr)
        cells = self.cells
        for b in self.body_forces_at(x[cells.node]):
            np.add.at(f, cells.node, cells.measure[:, None] * b)
        return f


def triangle_loads(x: np.ndarray, faces: np.ndarray, normal: np.ndarray, t) -> np.ndarray:
    """The nodes' share ``int t N_a dA`` of a traction on boundary triangles, where the
    shape functions are linear between the three nodes of each face.

    Parameters
    ----------
    x : (n, 3) ndarray
    faces : (e, 3) int64 ndarray
    normal : (e, 3) ndarray
        Outward unit normals.
    t : (3,) array_like or callable ``(x, nrm) -> (q, 3)``

    Returns
    -------
    (n, 3) ndarray
    """
    ref, w = get_quadrature(RefTri, 4)                   # reference triangle, area 1/2
    corners = x[faces]
    e1, e2 = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    twice_area = np.linalg.norm(np.cross(e1, e2), axis=1)
    f = np.zeros_like(x)
    for r, s, wk in zip(ref[0], ref[1], w):
        tr = traction_at(t, corners[:, 0] + r * e1 + s * e2, normal)
        for a, shape in enumerate((1.0 - r - s, r, s)):
            np.add.at(f, faces[:, a], (wk * shape * twice_area)[:, None] * tr)
    return f
