"""Isotropic linear elasticity in plane stress and plane strain (eq. 24-25 of the C-NEM paper).

The constitutive facts that C-NEM, the P1 anchor, fracture and peridynamics share: the
planes, the Lamé parameters, the matrix ``C``, Kolosov's constant and the effective modulus.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from .errors import MaterialError, check_choice

__all__ = ["PLANES", "parse_materials", "check_stiffness", "lame", "stiffness_matrix", "kappa", "effective_modulus"]

#: The 2-D idealisations: plane stress or plane strain.
PLANES = ("stress", "strain")


def parse_materials(materials: ArrayLike, nregions: int,
                    plane: Literal["stress", "strain"] | None = None) -> np.ndarray:
    """``(r, 2)`` array of ``(E, nu)`` per region from one pair or a list of pairs; with
    ``plane``, also their elasticity matrices must be finite (E near the float64 limit
    overflows them)."""
    try:
        arr = np.asarray(materials, dtype=float)
    except (TypeError, ValueError):
        raise MaterialError(f"materials: expected an (E, nu) pair or a list of {nregions} pairs, "
                            f"received {materials!r}") from None
    if arr.shape == (2,):
        arr = np.tile(arr, (nregions, 1))
    if arr.shape != (nregions, 2):
        raise MaterialError(f"materials: expected an (E, nu) pair or one pair per region "
                            f"({nregions} regions), received shape {arr.shape}")
    E, nu = arr[:, 0], arr[:, 1]
    if not (np.isfinite(arr).all() and (E > 0).all()):
        raise MaterialError(f"materials: Young's moduli must be positive and finite, received "
                            f"{E.tolist()}")
    if not ((nu > -1.0) & (nu < 0.5)).all():
        raise MaterialError(f"materials: Poisson ratios must lie in (-1, 0.5), received "
                            f"{nu.tolist()}")
    if plane is not None:
        check_stiffness(stiffness_matrix(E, nu, plane), arr, "the elasticity matrix")
    return arr


def check_stiffness(values: np.ndarray, materials: np.ndarray, what: str) -> None:
    """Raise `MaterialError` naming the materials when ``values`` (a stiffness built from
    ``materials``, ``(r, 2)`` pairs (E, nu)) are not all finite."""
    if not np.isfinite(values).all():
        top = int(np.argmax(materials[:, 0]))
        raise MaterialError(
            f"materials: {what} is not finite (float64 overflow) for E up to "
            f"{materials[top, 0]:g} (material {top}, nu = {materials[top, 1]:g}): expected "
            f"moduli whose stiffness and stresses are representable; express E in other "
            f"units (e.g. MPa or GPa instead of Pa)")


def lame(E: ArrayLike, nu: ArrayLike,
         plane: Literal["stress", "strain"]) -> tuple[np.ndarray, np.ndarray]:
    """Lamé parameters of the 2-D law: ``sigma = 2 mu eps + lam tr(eps) I``.

    In plane stress ``lam`` is ``lambda* = 2 lambda mu / (lambda + 2 mu)``.

    Returns
    -------
    lam, mu : ndarray
    """
    check_choice("plane", plane, PLANES)
    E, nu = np.asarray(E, dtype=float), np.asarray(nu, dtype=float)
    mu = E / (2.0 * (1.0 + nu))
    if plane == "stress":        # 2 lambda mu / (lambda + 2 mu), without the product
        lam = E * nu / ((1.0 + nu) * (1.0 - nu))
    else:
        lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
    return lam, mu


def stiffness_matrix(E: ArrayLike, nu: ArrayLike, plane: Literal["stress", "strain"]) -> np.ndarray:
    """The matrix ``C`` of eq. 24 (strain) or 25 (stress), Voigt ``[xx, yy, xy]``
    with engineering shear strain.

    Returns
    -------
    (..., 3, 3) ndarray
    """
    lam, mu = lame(E, nu, plane)
    C = np.zeros(np.shape(lam) + (3, 3))
    C[..., 0, 0] = C[..., 1, 1] = lam + 2.0 * mu
    C[..., 0, 1] = C[..., 1, 0] = lam
    C[..., 2, 2] = mu
    return C


def kappa(nu: float | np.ndarray, plane: Literal["stress", "strain"]) -> float | np.ndarray:
    """Kolosov's constant: ``3 - 4 nu`` (plane strain) or ``(3 - nu) / (1 + nu)`` (plane stress)."""
    check_choice("plane", plane, PLANES)
    return 3.0 - 4.0 * nu if plane == "strain" else (3.0 - nu) / (1.0 + nu)


def effective_modulus(E: float | np.ndarray, nu: float | np.ndarray,
                      plane: Literal["stress", "strain"]) -> float | np.ndarray:
    """``E' = E`` (plane stress) or ``E / (1 - nu^2)`` (plane strain): ``G = K^2 / E'``."""
    kappa(nu, plane)
    return E if plane == "stress" else E / (1.0 - nu * nu)
