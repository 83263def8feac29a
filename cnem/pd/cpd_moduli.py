"""Small-strain continuum limit of the CPD sums: the Lame constants of a `cnem.pd.CPD`
material, and the constants C2, C3 that stiffen it by a given ratio.

The horizon integrals of the CPD energies (Javili et al., eq. 41) with ``S ~ strain``:
one-neighbour interactions give the Cauchy solid lambda = mu; in 2-D the area strain
of every pair of bonds is tr(eps); in 3-D a pair's is ``tr(eps) - m.eps.m`` (m its
normal) and a triplet's tr(eps). The lattice sums of a discrete body are within about
10-40 % of these limits (lower for delta >= 2 spacings).

>>> import cnem.pd as pd
>>> lam, mu = lame_constants(pd.CPD(1.0), 2, 0.1)
>>> bool(abs(lam - mu) < 1e-15)
True
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from .cpd import CPD

__all__ = ["moduli_per_constant", "lame_constants", "constant_for_ratio"]


def moduli_per_constant(dim: int, horizon: float, thickness: float = 1.0) -> np.ndarray:
    """``(lambda, mu)`` per unit C1, C2 and C3.

    Parameters
    ----------
    dim : {2, 3}
    horizon : float
    thickness : float
        Of a 2-D body.

    Returns
    -------
    (3, 2) ndarray
        Row ``k``: ``(lambda, mu)`` of ``C_{k+1} = 1``.
    """
    d = horizon
    if dim == 2:
        mu1 = thickness * math.pi * d ** 3 / 24
        return np.array([[mu1, mu1], [8 * math.pi * thickness ** 2 * d ** 6 / 27, 0.0],
                         [0.0, 0.0]])
    mu1 = math.pi * d ** 4 / 30
    return np.array([[mu1, mu1], [math.pi ** 3 * d ** 8 / 30, math.pi ** 3 * d ** 8 / 180],
                     [math.pi ** 4 * d ** 12 / 32, 0.0]])


def lame_constants(material: CPD, dim: int, horizon: float, thickness: float = 1.0) -> np.ndarray:
    """Lame constants ``(lambda, mu)`` of a `cnem.pd.CPD` material in the small-strain
    continuum limit.

    Parameters
    ----------
    material : cnem.pd.CPD
    dim : {2, 3}
    horizon, thickness : float

    Returns
    -------
    (float, float)
    """
    return tuple(np.array([material.C1, material.C2, material.C3]) @
                 moduli_per_constant(dim, horizon, thickness))


def constant_for_ratio(order: int, ratio: float, dim: int, horizon: float, C1: float = 1.0,
                       thickness: float = 1.0) -> float:
    """C2 (``order=2``) or C3 (``order=3``) adding ``ratio`` times the bonds' shear
    modulus (that of ``C1``) to lambda.

    Returns
    -------
    float
    """
    table = moduli_per_constant(dim, horizon, thickness)
    return ratio * C1 * table[0, 1] / table[order - 1, 0]
