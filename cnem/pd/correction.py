"""The surface correction of peridynamic bonds by the energy method (Le & Bobaru 2018).

Every point's bonds are scaled so that uniform test strains store the classical
energy density of the material at that point; a bond takes the mean of its two
points' factors. The pieces every model shares live here: the classical density, the
unit test strains of the PMB and the per-point fits; the serial behaviours
(`cnem.pd.behaviour`) and the distributed operators put them together.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from . import _kernels as K

if TYPE_CHECKING:
    from .body import Body

__all__ = ["classical_density", "unit_strain_targets", "fit", "pmb_factors",
           "state_test_fields"]


def classical_density(strain: np.ndarray, bulk: float, shear: float) -> float:
    """``1/2 eps : C : eps`` of the isotropic d-dimensional law of moduli ``bulk``, ``shear``.

    Parameters
    ----------
    strain : (d, d) ndarray
    """
    d = len(strain)
    tr = np.trace(strain)
    dev = strain - tr / d * np.eye(d)
    return 0.5 * bulk * tr * tr + shear * (dev * dev).sum()


def unit_strain_targets(dim: int, bulk: float, shear: float) -> tuple[np.ndarray, np.ndarray]:
    """The unit strains ``eps_ac = eps_ca = 1`` (``a <= c``) and their classical densities.

    Returns
    -------
    pairs : (k, 2) int64 ndarray
        ``(a, c)`` of every unit strain, ``k = d (d + 1) / 2``.
    target : (k,) ndarray
    """
    pairs = np.array([(a, c) for a in range(dim) for c in range(a, dim)], dtype=np.int64)
    target = []
    for a, c in pairs:
        eps = np.zeros((dim, dim))
        eps[a, c] = eps[c, a] = 1.0
        target.append(classical_density(eps, bulk, shear))
    return pairs, np.array(target)


def fit(Q: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Per-point coefficients solving ``Q_i c_i = target`` (least squares where singular).

    Parameters
    ----------
    Q : (n, t, k) ndarray
    target : (t,) ndarray

    Returns
    -------
    (n, k) ndarray
    """
    rhs = np.broadcast_to(target, Q.shape[:2])[..., None]
    try:
        return np.linalg.solve(Q, rhs)[..., 0]
    except np.linalg.LinAlgError:                           # a point with too few bonds
        return np.array([np.linalg.lstsq(q, target, rcond=None)[0] for q in Q])


def pmb_factors(body: Body, weight: np.ndarray, bond_stiffness: float, bulk: float,
                shear: float) -> np.ndarray:
    """The energy-method factors ``(b,)`` of the PMB bonds of a serial body, from per-bond
    sums (numba): every unit strain stores the classical density of the moduli
    ``bulk``, ``shear`` (the law the PMB matches) at every point, with a function of the
    bond direction even in each component.

    Parameters
    ----------
    body : cnem.pd.Body
    weight : (b,) ndarray
        ``beta V_j`` of every bond.
    bond_stiffness : float
        The micromodulus.
    """
    pairs, target = unit_strain_targets(body.dim, bulk, shear)
    Q = np.zeros((len(body), len(pairs), len(pairs)))
    K.pmb_correction_moments(body.xi, body.length, weight, body.family.offsets, pairs, Q)
    Q *= 0.25 * bond_stiffness
    coef = np.ascontiguousarray(fit(Q, target))
    factor = np.empty(len(body.bond_i))
    K.pmb_bond_factors(body.xi, body.length, body.family.offsets, body.bond_j, pairs, coef,
                       factor)
    return factor


def state_test_fields(unit: np.ndarray, dim: int) -> tuple[list, list]:
    """The deviatoric test strains of the state-based correction and its direction
    functions ``{1, sum_{a<c} n_a^2 n_c^2}`` of the bond direction.

    Parameters
    ----------
    unit : (b, d) ndarray
        Unit bond directions.

    Returns
    -------
    tests : list of (d, d) ndarray
    basis : list of (b,) ndarray
    """
    d = dim
    pairs = [(a, c) for a in range(d) for c in range(a, d)]
    n = unit
    tests = []
    for a, c in pairs:
        if a != c:
            eps = np.zeros((d, d))
            eps[a, c] = eps[c, a] = 1e-3
            tests.append(eps)
    eps = np.zeros((d, d))
    eps[0, 0], eps[1, 1] = 1e-3, -1e-3
    tests.append(eps)
    quartic = sum(n[:, a] ** 2 * n[:, c] ** 2 for a, c in pairs if a != c)
    return tests, [np.ones(len(n)), quartic]
