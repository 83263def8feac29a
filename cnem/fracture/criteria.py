"""Crack-growth direction criteria: the kink angle and the equivalent SIF from K_I, K_II.

Angles ``theta`` are measured in the crack-tip frame, positive
counter-clockwise from the crack's direction (a positive K_II kinks the crack
clockwise, ``theta < 0``). Each criterion returns the kink angle and the
equivalent stress intensity factor ``K_eq`` (the K_I of a straight mode-I
crack with the same driving force: the crack grows when ``K_eq = K_Ic``).

* ``"max_hoop"`` — maximum hoop stress (Erdogan & Sih 1963), closed form
  ``theta = 2 atan((K_I - sqrt(K_I^2 + 8 K_II^2)) / (4 K_II))``,
  ``K_eq = cos(theta/2) (K_I cos^2(theta/2) - 3/2 K_II sin(theta))``.
* ``"max_energy_release"`` — maximum energy release rate of the kinked crack,
  ``G(theta) = (k_I^2 + k_II^2) / E'`` with the kinked-crack factors of Hussain,
  Pu & Underwood (1974), ``K_eq = sqrt(E' G_max)``.
* ``"min_sed"`` — minimum strain-energy density factor (Sih 1974),
  ``16 mu S = a11 K_I^2 + 2 a12 K_I K_II + a22 K_II^2``, ``K_eq = sqrt(8 mu S_min / (kappa - 1))``.

The two numerical criteria take the best interior local optimum over
``|theta| < pi`` (a fine grid, then a bounded Brent search) among the angles
where the kink opens (``k_I(theta) > 0``, tensile hoop stress); the crack
faces ``theta = ±pi`` are never a growth direction.

>>> import numpy as np
>>> from cnem.fracture.criteria import kink
>>> theta, K_eq, _ = kink("max_hoop", 0.0, 1.0)
>>> round(float(np.degrees(theta)), 2)
-70.53
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import minimize_scalar

from ..errors import GrowthError

__all__ = ["CRITERIA", "kink", "hoop_angle", "kinked_sif", "sed_factor"]

#: Grid of trial angles of the numerical criteria (interior of (-pi, pi)).
_GRID = np.linspace(-np.pi, np.pi, 721)[1:-1]


def hoop_angle(KI, KII):
    """Kink angle of the maximum hoop stress criterion (closed form).

    Parameters
    ----------
    KI, KII : float or (t,) array_like

    Returns
    -------
    theta : float or (t,) ndarray
        Radians, ``|theta| <= 2 atan(1 / sqrt(2)) = 70.53°``; 0 where ``K_II = 0``.
    """
    KI, KII = np.asarray(KI, dtype=float), np.asarray(KII, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        theta = 2.0 * np.arctan((KI - np.sqrt(KI * KI + 8.0 * KII * KII)) / (4.0 * KII))
    theta = np.where(KII == 0.0, 0.0, theta)
    return float(theta) if theta.ndim == 0 else theta


def _hoop_keq(KI, KII, theta):
    c = np.cos(0.5 * theta)
    return c * (KI * c * c - 1.5 * KII * np.sin(theta))


def kinked_sif(KI, KII, theta):
    """SIFs at the tip of an infinitesimal kink at ``theta`` (Hussain, Pu & Underwood 1974).

    Parameters
    ----------
    KI, KII : float
    theta : float or (p,) ndarray
        Kink angles, ``|theta| < pi``.

    Returns
    -------
    kI, kII : float or (p,) ndarray
    """
    theta = np.asarray(theta, dtype=float)
    x = theta / np.pi
    g = 4.0 / (3.0 + np.cos(theta) ** 2) * ((1.0 - x) / (1.0 + x)) ** (0.5 * x)
    return (g * (KI * np.cos(theta) - 1.5 * KII * np.sin(theta)),
            g * (KII * np.cos(theta) + 0.5 * KI * np.sin(theta)))


def sed_factor(KI, KII, theta, kappa):
    """Sih's strain-energy density factor times ``16 mu``.

    Returns
    -------
    float or (p,) ndarray
        ``a11 K_I^2 + 2 a12 K_I K_II + a22 K_II^2`` (each ``a`` times ``16 mu``).
    """
    c, s = np.cos(theta), np.sin(theta)
    a11 = (1.0 + c) * (kappa - c)
    a12 = s * (2.0 * c - kappa + 1.0)
    a22 = (kappa + 1.0) * (1.0 - c) + (1.0 + c) * (3.0 * c - 1.0)
    return a11 * KI * KI + 2.0 * a12 * KI * KII + a22 * KII * KII


def _interior_minimum(f, opening):
    """The lowest interior local minimum of ``f`` on ``(-pi, pi)`` among the angles
    where ``opening(theta) > 0`` (the kink opens: tensile hoop stress).

    Returns ``(theta, value, at_bound)``; ``at_bound`` when ``f`` has no such
    interior minimum and the best grid angle was taken.
    """
    values = f(_GRID)
    inner = np.flatnonzero((values[1:-1] <= values[:-2]) & (values[1:-1] <= values[2:])) + 1
    best = None
    for k in inner:
        res = minimize_scalar(f, bounds=(_GRID[k - 1], _GRID[k + 1]), method="bounded",
                              options=dict(xatol=1e-12))
        if opening(res.x) > 0 and (best is None or res.fun < best[1]):
            best = (float(res.x), float(res.fun))
    if best is None:
        ok = opening(_GRID) > 0
        k = int(np.argmin(np.where(ok, values, np.inf))) if ok.any() else len(_GRID) // 2
        return float(_GRID[k]), float(values[k]), True
    return best[0], best[1], False


def kink(criterion, KI, KII, *, kappa=None):
    """Kink angle and equivalent SIF at one tip.

    Parameters
    ----------
    criterion : {"max_hoop", "max_energy_release", "min_sed"}
    KI, KII : float
    kappa : float, optional
        Kolosov's constant (``"min_sed"`` only).

    Returns
    -------
    theta : float
        Kink angle (radians, counter-clockwise from the crack direction).
    K_eq : float
        Equivalent mode-I SIF.
    at_bound : bool
        The numerical criterion found no interior optimum (the angle is the
        end of its search range): the criterion does not pick a direction.

    Raises
    ------
    GrowthError
        Unknown criterion; ``"min_sed"`` without ``kappa``.
    """
    if criterion not in CRITERIA:
        raise GrowthError(f"criterion: expected one of {sorted(CRITERIA)}, received {criterion!r}")
    KI, KII = float(KI), float(KII)
    if criterion == "max_hoop":
        theta = hoop_angle(KI, KII)
        return theta, float(_hoop_keq(KI, KII, theta)), False
    if criterion == "max_energy_release":
        theta, value, at_bound = _interior_minimum(
            lambda t: -np.hypot(*kinked_sif(KI, KII, t)), lambda t: kinked_sif(KI, KII, t)[0])
        return theta, -value, at_bound
    if kappa is None or not kappa > 1.0:
        raise GrowthError(f"min_sed needs Kolosov's constant kappa > 1, received {kappa!r}")
    theta, value, at_bound = _interior_minimum(lambda t: sed_factor(KI, KII, t, kappa),
                                               lambda t: _hoop_keq(KI, KII, t))
    return theta, float(np.sqrt(max(value, 0.0) / (2.0 * (kappa - 1.0)))), at_bound


#: The growth criteria by name, each with a one-line description.
CRITERIA = {
    "max_hoop": "maximum hoop stress (Erdogan-Sih), closed form",
    "max_energy_release": "maximum energy release rate of the kinked crack (Hussain-Pu-Underwood)",
    "min_sed": "minimum strain-energy density factor (Sih)",
}
