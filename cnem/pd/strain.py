"""The nonlocal deformation gradient of a PD body: a strain at every point from its bonds.

>>> import numpy as np, cnem.pd as pd
>>> from cnem.pd.lattice import lattice
>>> x = lattice((6, 6), 0.2)
>>> body = pd.Body(x, 0.04, 0.45)
>>> F = deformation_gradient(body, x @ np.array([[0.1, 0.0], [0.02, -0.03]]).T)
>>> bool(np.allclose(F, [[1.1, 0.0], [0.02, 0.97]]))
True
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from .body import Body

__all__ = ["deformation_gradient"]


def deformation_gradient(body: Body, u: np.ndarray) -> np.ndarray:
    """``F_i = (sum_j w y xi^T) (sum_j w xi xi^T)^-1`` over the bonds of every point.

    ``xi`` is a bond in the reference configuration, ``y = xi + u_j - u_i`` the
    deformed bond and ``w`` the bond's partial volume (``beta V_j``). ``F`` is the
    exact gradient of any affine displacement, also near the boundary.

    Parameters
    ----------
    body : cnem.pd.Body
    u : (n, d) array_like
        Displacement of the points.

    Returns
    -------
    (n, d, d) ndarray
    """
    u = np.asarray(u, dtype=float).reshape(len(body), -1)
    d = u.shape[1]
    w = body.beta * body.volumes[body.bond_j]
    y = body.xi + u[body.bond_j] - u[body.bond_i]
    K, N = np.zeros((len(body), d, d)), np.zeros((len(body), d, d))
    np.add.at(K, body.bond_i, w[:, None, None] * body.xi[:, :, None] * body.xi[:, None, :])
    np.add.at(N, body.bond_i, w[:, None, None] * y[:, :, None] * body.xi[:, None, :])
    return N @ np.linalg.inv(K)
