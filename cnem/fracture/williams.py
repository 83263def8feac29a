"""The Williams near-tip fields (leading terms, modes I and II) in crack-tip coordinates.

Coordinates: ``x1`` along the crack's extension, ``x2`` normal to it, ``r``
and ``theta`` polar about the tip (``theta = ±pi`` on the two crack faces).
``kappa = 3 - 4 nu`` (plane strain) or ``(3 - nu) / (1 + nu)`` (plane stress).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..errors import FractureError, check_array
from ..material import kappa

if TYPE_CHECKING:
    from typing import Literal
    from ..geometry.model import Model

__all__ = ["williams", "polar", "sided_polar", "nodal_williams"]


def williams(r: np.ndarray, theta: np.ndarray, KI: float, KII: float, E: float, nu: float,
             plane: Literal["stress", "strain"]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Displacements, stresses and x1-derivatives of the displacements of the
    leading Williams terms.

    Parameters
    ----------
    r, theta : (p,) ndarray
        Polar coordinates about the tip, ``theta`` in ``[-pi, pi]``.
    KI, KII : float
        Stress intensity factors.
    E, nu : float
    plane : {"stress", "strain"}

    Returns
    -------
    u : (p, 2) ndarray
        ``[u1, u2]``.
    stress : (p, 3) ndarray
        ``[s11, s22, s12]``.
    du_dx1 : (p, 2) ndarray
        ``[du1/dx1, du2/dx1]``.
    """
    r = check_array("r", r, error=FractureError, fix="pass real distances from the tip")
    theta = check_array("theta", theta, error=FractureError, fix="pass real angles in radians")
    k = kappa(nu, plane)
    mu = E / (2.0 * (1.0 + nu))
    s, c = np.sin(theta / 2), np.cos(theta / 2)
    s3, c3 = np.sin(1.5 * theta), np.cos(1.5 * theta)
    amp = np.sqrt(r / (2 * np.pi)) / (2 * mu)
    # angular parts f(theta) of u = amp * f and their derivatives f'(theta)
    f1 = KI * c * (k - 1 + 2 * s * s) + KII * s * (k + 1 + 2 * c * c)
    f2 = KI * s * (k + 1 - 2 * c * c) - KII * c * (k - 1 - 2 * s * s)
    d1 = (KI * (-0.5 * s * (k - 1 + 2 * s * s) + 2 * s * c * c)
          + KII * (0.5 * c * (k + 1 + 2 * c * c) - 2 * s * s * c))
    d2 = (KI * (0.5 * c * (k + 1 - 2 * c * c) + 2 * s * s * c)
          + KII * (0.5 * s * (k - 1 - 2 * s * s) + 2 * s * c * c))
    u = np.stack([amp * f1, amp * f2], axis=-1)
    # d/dx1 = cos(theta) d/dr - sin(theta) / r d/dtheta, with du/dr = u / (2 r)
    ct, st = np.cos(theta), np.sin(theta)
    du = np.stack([amp * (ct * f1 / (2 * r) - st * d1 / r),
                   amp * (ct * f2 / (2 * r) - st * d2 / r)], axis=-1)
    scale = 1.0 / np.sqrt(2 * np.pi * r)
    s11 = scale * (KI * c * (1 - s * s3) - KII * s * (2 + c * c3))
    s22 = scale * (KI * c * (1 + s * s3) + KII * s * c * c3)
    s12 = scale * (KI * s * c * c3 + KII * c * (1 - s * s3))
    return u, np.stack([s11, s22, s12], axis=-1), du


def polar(points: np.ndarray, tip: np.ndarray, direction: np.ndarray) -> tuple:
    """Crack-tip polar coordinates ``(r, theta)`` of global points.

    Parameters
    ----------
    points : (p, 2) ndarray
    tip, direction : (2,) ndarray
        The tip and the unit crack direction (out of the crack).
    """
    points = check_array("points", points, shape=(None, 2), error=FractureError,
                         fix="pass one row (x, y) per point")
    tip = check_array("tip", tip, shape=(2,), error=FractureError, fix="pass one point (x, y)")
    direction = check_array("direction", direction, shape=(2,), error=FractureError,
                            fix="pass the crack's unit direction (dx, dy)")
    rel = points - tip
    x1 = rel @ direction
    x2 = rel @ np.array([-direction[1], direction[0]])
    return np.hypot(x1, x2), np.arctan2(x2, x1)


def sided_polar(points: np.ndarray, tip: np.ndarray, direction: np.ndarray,
                sides: np.ndarray, tol: float) -> tuple:
    """`polar`, with ``theta = ±pi`` on the crack line behind the tip (points within
    the distance ``tol`` of it, the domain's tolerance: far from the origin a point
    on a face stands off the line by the coordinates' round-off) chosen by the side
    of a reference point per point (``sides``, ``(p, 2)``)."""
    r, theta = polar(points, tip, direction)
    _, side = polar(sides, tip, direction)
    behind = (np.abs(theta) > 0.5 * np.pi) & (r * np.abs(np.sin(theta)) <= tol)
    theta[behind] = np.pi * np.where(side[behind] < 0, -1.0, 1.0)
    return r, theta


def nodal_williams(model: Model, tip: np.ndarray, KI: float, KII: float, E: float, nu: float,
                   plane: Literal["stress", "strain"]) -> np.ndarray:
    """The Williams displacement at every node of a model, in global axes.

    A node on a crack face takes the value of its own face (``theta = ±pi``
    decided by the side its integration cell lies on), so that the crack
    opens.

    Parameters
    ----------
    model : Model
    tip : (2,) array_like
        A point; the crack tip nearest to it is used (see `Domain.tip_frame`).
    KI, KII, E, nu : float
    plane : {"stress", "strain"}

    Returns
    -------
    (n, 2) ndarray
    """
    at, d = model.domain.tip_frame(tip)
    r, theta = sided_polar(model.nodes, at, d, model.node_sides(), model.domain.tolerance)
    with np.errstate(divide="ignore", invalid="ignore"):
        u = williams(r, theta, KI, KII, E, nu, plane)[0]
    u[r == 0.0] = 0.0
    back = np.array([[d[0], -d[1]], [d[1], d[0]]])          # crack-tip frame -> global
    return u @ back.T
