"""The nodes' shares of a traction on boundary facets (edges in 2-D, triangles in 3-D).

A traction ``t`` (force per unit boundary area) on a facet is shared among its corners by
the facet's linear hat functions, ``f_a = int_facet t phi_a dA``: the forces sum to the
integral of ``t`` over the facets (``t`` times their area for a constant traction) and
their moment is that of the traction. The peridynamic problems turn tractions into point
forces with it; C-NEM uses it on its boundary edges.

>>> import numpy as np
>>> from cnem.solvers.facet_loads import facet_loads
>>> points = np.array([[0.0, 0.0], [1.0, 0.0], [3.0, 0.0]])
>>> edges, normal = np.array([[0, 1], [1, 2]]), np.array([[0.0, -1.0], [0.0, -1.0]])
>>> facet_loads(points, edges, normal, [0.0, -2.0])[:, 1]       # 2 x length 3 = 6 in all
array([-1., -3., -2.])
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Callable

import numpy as np

from .conditions import traction_at

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

__all__ = ["facet_loads"]

_GAUSS, _GAUSS_WEIGHTS = np.polynomial.legendre.leggauss(3)
#: 3-point Gauss rule on an edge, parameter in [0, 1] and weights summing to 1: exact for
#: the hat times a traction quadratic along the edge.
EDGE_POINTS, EDGE_WEIGHTS = 0.5 * (_GAUSS + 1.0), 0.5 * _GAUSS_WEIGHTS
#: The edge-midpoint rule on a triangle (barycentric coordinates, weights summing to 1):
#: exact for the hat times a traction linear over the triangle.
TRIANGLE_POINTS = np.array([[0.5, 0.5, 0.0], [0.0, 0.5, 0.5], [0.5, 0.0, 0.5]])
TRIANGLE_WEIGHTS = np.full(3, 1.0 / 3.0)


def facet_loads(points: np.ndarray, facets: np.ndarray, normal: np.ndarray,
                t: ArrayLike | Callable[..., np.ndarray]) -> np.ndarray:
    """``f_a = sum over the facets of int t phi_a dA``, with ``phi_a`` the linear hat of
    corner ``a`` on each facet.

    Parameters
    ----------
    points : (n, d) ndarray
        The nodes, d = 2 or 3.
    facets : (e, d) int ndarray
        Boundary edges (2-D) or triangles (3-D), as node indices.
    normal : (e, d) ndarray
        Their outward unit normals (passed to a callable ``t``).
    t : (d,) array_like, or callable ``(x, nrm) -> (q, d)``
        The traction (see `cnem.solvers.conditions.traction_at`).

    Returns
    -------
    (n, d) ndarray
        Per unit thickness in 2-D.
    """
    d = points.shape[1]
    corners = points[facets]                                       # (e, d, d)
    if d == 2:
        bary = np.column_stack([1.0 - EDGE_POINTS, EDGE_POINTS])
        weights = EDGE_WEIGHTS
        size = np.linalg.norm(corners[:, 1] - corners[:, 0], axis=1)
    else:
        bary, weights = TRIANGLE_POINTS, TRIANGLE_WEIGHTS
        size = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0],
                                             corners[:, 2] - corners[:, 0]), axis=1)
    f = np.zeros((len(points), d))
    for phi, w in zip(bary, weights):
        tr = traction_at(t, np.einsum("c,ecd->ed", phi, corners), normal)
        for corner in range(d):
            if phi[corner]:
                np.add.at(f, facets[:, corner], (w * phi[corner] * size)[:, None] * tr)
    return f
