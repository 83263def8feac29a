"""Critical bond stretch from the fracture energy, for each peridynamic model.

Every formula below equates the fracture energy ``G_c`` with the energy, per unit
crack area, of the bonds that cross a straight crack line when each of them is at
the critical stretch ``s_c`` and no other bond is stretched (Silling & Askari
2005, Comput. Struct. 83:1526, eq. 25 and their Fig. 7, the same argument in 2-D
in Ha & Bobaru 2010, Int. J. Fract. 162:229, and for state-based models in
Madenci & Oterkus 2014, "Peridynamic theory and its applications", Springer,
§6.2). A point at depth ``z`` below the crack line bonds to the points beyond it at
distance ``xi`` in ``z < xi < delta`` and within the angle ``|phi| < acos(z / xi)``
of the normal, so that a bond quantity ``P(xi)`` per unit volume squared sums over
a unit length of crack (and unit thickness) to ``int_0^delta 2 xi^2 P(xi) dxi``.

Bond-based (PMB, micromodulus ``c`` of `cnem.pd.BondBased`, pair energy
``c s^2 xi / 2``): ``G_c = c t s_c^2 delta^4 / 4`` (2-D) and
``pi c s_c^2 delta^5 / 10`` (3-D), so

* plane stress, ``c = 9 E / (pi t delta^3)``: ``s_c = sqrt(4 pi G_c / (9 E delta))``
  (Ha & Bobaru 2010, eq. 8);
* plane strain, ``c = 48 E / (5 pi t delta^3)``: ``s_c = sqrt(5 pi G_c / (12 E delta))``;
* 3-D, ``c = 18 K / (pi delta^4)``: ``s_c = sqrt(5 G_c / (9 K delta))`` (Silling &
  Askari 2005, eq. 25).

State-based (the linear peridynamic solid of `cnem.pd.StateBased`, influence
``omega = 1``, ``m = pi t delta^4 / 2``, ``alpha = 8 mu / m``). With
``theta = (2 / m) sum omega xi e V`` its energy density is exactly
``W = (k - 2 mu) theta^2 / 2 + (4 mu / m) sum omega e^2 V``: a pair part and a
dilatation part. The pair part of the crossing bonds (``e = s_c xi``) gives
``32 mu delta s_c^2 / (5 pi)``. The dilatation part is the ``theta^2`` energy of the
points within ``delta`` of the line from their crossing bonds alone,
``theta(z) = (4 s_c / pi) J(z / delta)`` with
``J(zeta) = 2 int_zeta^1 x^3 acos(zeta / x) dx
= acos(zeta) / 2 - zeta sqrt(1 - zeta^2) (1 / 6 + zeta^2 / 3)``, which gives
``16 (k - 2 mu) delta s_c^2 C / pi^2`` with ``C = int_0^1 J^2 = pi / 5 - 832 / 2025``.
Hence (2-D, ``k`` the plane-stress or plane-strain bulk modulus of
`cnem.pd.StateBased.moduli`)

    ``s_c = sqrt(G_c / ((32 mu / (5 pi) + 16 C (k - 2 mu) / pi^2) delta))``,

the counterpart for ``omega = 1`` of Madenci & Oterkus's
``sqrt(G_c / ((6 mu / pi + 16 (k - 2 mu) / (9 pi^2)) delta))`` (their influence
``delta / xi``). `tests/test_pd_quasistatic.py` sums both energies bond by bond
on lattices to check these closed forms.

>>> round(state_based(1.0, 1.0, 0.25, 1.0, "strain") / bond_based(1.0, 1.0, 1.0, "strain"), 3)
0.968
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..errors import MaterialError, UnsupportedError
from ..material import PLANES, effective_modulus, lame

if TYPE_CHECKING:
    from typing import Literal

__all__ = ["fracture_energy", "bond_based", "state_based", "DILATATION_INTEGRAL"]

#: ``int_0^1 J(zeta)^2 dzeta`` of the state-based dilatation term (see the module).
DILATATION_INTEGRAL = np.pi / 5.0 - 832.0 / 2025.0


def _positive(name, value):
    value = float(value)
    if not (np.isfinite(value) and value > 0):
        raise MaterialError(f"{name}: expected a positive number, received {value}")
    return value


def _plane(plane):
    if plane not in PLANES:
        raise MaterialError(f"plane: expected one of {list(PLANES)}, received {plane!r}")
    return plane


def fracture_energy(K_Ic: float, E: float, nu: float, plane: Literal['stress', 'strain']) -> float:
    """Irwin's ``G_c = K_Ic^2 / E'``, ``E' = E`` (plane stress) or ``E / (1 - nu^2)``
    (plane strain)."""
    K_Ic, E = _positive("K_Ic", K_Ic), _positive("E", E)
    return K_Ic ** 2 / float(effective_modulus(E, float(nu), _plane(plane)))


def bond_based(G_c: float, E: float, horizon: float, plane: Literal['stress', 'strain'],
               dim: int = 2) -> float:
    """Critical stretch of the PMB material (`cnem.pd.BondBased`) from ``G_c``.

    Parameters
    ----------
    G_c, E, horizon : float
    plane : {"stress", "strain"}
        2-D only.
    dim : {2, 3}

    Returns
    -------
    float
        ``sqrt(4 pi G_c / (9 E delta))`` (plane stress), ``sqrt(5 pi G_c / (12 E delta))``
        (plane strain), ``sqrt(5 G_c / (9 K delta))`` with ``K = 2 E / 3`` (3-D, nu = 1/4).
    """
    G_c, E, horizon = _positive("G_c", G_c), _positive("E", E), _positive("horizon", horizon)
    if dim == 3:
        return float(np.sqrt(5.0 * G_c / (9.0 * (2.0 * E / 3.0) * horizon)))
    if _plane(plane) == "stress":
        return float(np.sqrt(4.0 * np.pi * G_c / (9.0 * E * horizon)))
    return float(np.sqrt(5.0 * np.pi * G_c / (12.0 * E * horizon)))


def state_based(G_c: float, E: float, nu: float, horizon: float,
                plane: Literal['stress', 'strain'], dim: int = 2) -> float:
    """Critical stretch of the linear peridynamic solid (`cnem.pd.StateBased`,
    ``omega = 1``) from ``G_c``, 2-D.

    Returns
    -------
    float
        ``sqrt(G_c / ((32 mu / (5 pi) + 16 C (k - 2 mu) / pi^2) delta))`` (see the module).

    Raises
    ------
    UnsupportedError
        In 3-D (give ``critical_stretch`` there).
    MaterialError
        A Poisson ratio for which the crossing bonds store no energy.
    """
    if dim != 2:
        raise UnsupportedError("state_based: the critical stretch from G_c is derived for 2-D "
                               "bodies only; give StateBased(..., critical_stretch=s_c) in 3-D")
    G_c, E, horizon = _positive("G_c", G_c), _positive("E", E), _positive("horizon", horizon)
    lam, mu = (float(v) for v in lame(E, float(nu), _plane(plane)))
    k = lam + mu
    per = 32.0 * mu / (5.0 * np.pi) + 16.0 * DILATATION_INTEGRAL * (k - 2.0 * mu) / np.pi ** 2
    if not per > 0:
        raise MaterialError(f"nu: expected a Poisson ratio for which the crossing bonds store "
                            f"energy, received {nu} (energy coefficient {per:.3g})")
    return float(np.sqrt(G_c / (per * horizon)))
