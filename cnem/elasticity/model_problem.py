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

from ..assembly.facet_gradients import boundary_points_3d
from ..assembly.gradients import GradientCache
from ..errors import GeometryError
from ..geometry.model import check_model
from ..solvers.conditions import Conditions, traction_at
from ..solvers.facet_loads import facet_loads
from .._sets import isin

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
        self._boundary_points = None
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
        return self.model.boundary_with_normals()

    def nodal_load(self) -> np.ndarray:
        """The nodes' share of the tractions (3-point Gauss rule on each edge, exact up
        to quadratic tractions; in 3-D the cells' boundary facet points, see
        `_facet_loads`) and of the body forces (one value per cell, at its node), on
        the reference configuration.

        Returns
        -------
        (n, dim) ndarray
        """
        n, d = self.model.nodes.shape
        f = np.zeros((n, d))
        x = self.model.nodes
        for traction in self.tractions:
            if d == 3:
                f += self._facet_loads(traction.index, traction.value)
            else:
                f += facet_loads(x, traction.edges, traction.normal, traction.value)
        cells = self.cells
        for b in self.body_forces_at(x[cells.node]):
            np.add.at(f, cells.node, cells.measure[:, None] * b)
        return f

    def _facet_loads(self, faces: np.ndarray, t) -> np.ndarray:
        """``sum_q phi_I(x_q) t(x_q) A_q`` over the 3-D cells' boundary facet points on
        the boundary triangles ``faces`` (`boundary_points_3d`): the points of the
        cells' own boundary integrals, so that a constant stress gives loads that
        balance ``K u`` exactly (the shape functions on a boundary face are not the
        linear hats of its triangles).

        Returns
        -------
        (n, 3) ndarray
        """
        if self._boundary_points is None:
            self._boundary_points = boundary_points_3d(self.model, self.gradients.interface())
        points, area_normal, face = self._boundary_points
        take = isin(face, faces)
        area = np.linalg.norm(area_normal[take], axis=1)
        tr = traction_at(t, points[take], area_normal[take] / area[:, None])
        return np.asarray(self.model.shape_functions(points[take]).T @ (area[:, None] * tr))
