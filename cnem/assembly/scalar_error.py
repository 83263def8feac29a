"""The H1 error of a scalar field on the SCNI cells against an exact gradient.

``|T - T_h|_1 = sqrt(sum_k int_{cell k} |grad~ T_h - grad T|^2 dx)``, the smoothed
gradient of each cell (constant on it) against the exact gradient at the points of a
triangle rule on the cell's polygon: the scalar counterpart of
`cnem.ElasticSolution.energy_error`.

>>> import numpy as np, cnem
>>> from cnem.assembly import CellBasis, h1_error
>>> model = cnem.discretize(cnem.nodes.irregular(cnem.geometry.rectangle(), 0.2, seed=0))
>>> T = 3.0 * model.nodes[:, 0] - model.nodes[:, 1]                 # linear: exact gradient
>>> h1_error(CellBasis(model), T, lambda x: np.tile([3.0, -1.0], (len(x), 1))) < 1e-12
True
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..errors import InputError, check_array
from .quadrature import cell_quadrature

if TYPE_CHECKING:
    from typing import Callable
    from .basis import CellBasis

__all__ = ["h1_error"]


def h1_error(basis: CellBasis, values: np.ndarray,
             exact_gradient: Callable[[np.ndarray], np.ndarray], *, order: int = 4) -> float:
    """H1 seminorm of the error of a scalar field (see the module docstring).

    Parameters
    ----------
    basis : CellBasis
        A scalar basis on cells (2-D).
    values : (n,) array_like
        The field's nodal values (a dof vector of ``basis``).
    exact_gradient : callable ``(q, 2) -> (q, 2)``
        The exact gradient at points.
    order : int
        Degree of the triangle rule on the triangles of each cell.

    Returns
    -------
    float
    """
    if basis.vector or basis.cells is None:
        raise InputError("h1_error: expected a scalar CellBasis on cells, received "
                         f"{basis!r}; build it as CellBasis(model)")
    values = check_array("values", values, fix="pass one value per node (e.g. sol.T)")
    if values.shape != (basis.N,):
        raise InputError(f"values: expected one value per dof ({basis.N},), received shape "
                         f"{values.shape}; pass the field's nodal values")
    field = basis.interpolate(values)
    cell, points, weights = cell_quadrature(basis.cells, basis.model.nodes, order,
                                            singular=basis.model.domain.tips)
    exact = check_array("exact_gradient", exact_gradient(points),
                        fix="return one finite gradient row per point")
    if exact.shape != points.shape:
        raise InputError(f"exact_gradient must return ({len(points)}, {points.shape[1]}) "
                         f"values, received shape {exact.shape}; return one row per point")
    diff = field.grad.T[cell] - exact
    return float(np.sqrt(weights @ (diff * diff).sum(axis=1)))
