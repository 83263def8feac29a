"""Materials as objects, and the isotropic linear law in 2-D (plane stress or strain,
eq. 24-25 of the C-NEM paper) and 3-D.

A material is an object that knows its constitutive law in any dimension
(`Material`); `LinearElastic` is the isotropic Hooke law. The vectorised functions
below (`lame`, `stiffness_matrix`, `kappa`, `effective_modulus`) are the constitutive
facts that C-NEM, the P1 anchor, fracture and peridynamics share, over arrays of
``(E, nu)``. Voigt order: ``[xx, yy, xy]`` in 2-D, ``[xx, yy, zz, yz, xz, xy]`` in
3-D, engineering shear strains.

>>> from cnem.material import LinearElastic
>>> steel = LinearElastic(210e3, 0.3)
>>> steel.elasticity_matrix(2, "strain").shape, steel.elasticity_matrix(3).shape
((3, 3), (6, 6))
>>> E, nu = steel                     # unpacks like the (E, nu) pair it replaces
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from .errors import MaterialError, OptionError, check_array, check_choice, check_real

__all__ = ["PLANES", "Material", "LinearElastic", "parse_materials", "moduli", "check_plane", "check_stiffness",
           "lame", "stiffness_matrix", "kappa", "effective_modulus"]

#: The 2-D idealisations: plane stress or plane strain.
PLANES = ("stress", "strain")


def check_plane(dim: int, plane: str | None) -> None:
    """Raise unless ``plane`` suits dimension ``dim``: one of `PLANES` in 2-D, None in 3-D."""
    if dim == 2:
        check_choice("plane", plane, PLANES)
    elif dim == 3:
        if plane is not None:
            raise OptionError(f"plane: a 3-D body has no plane idealisation, received "
                              f"{plane!r}; pass plane=None")
    else:
        raise OptionError(f"dim: expected 2 or 3, received {dim!r}")


class Material:
    """A material: its constitutive law in 2-D (with a plane idealisation) or 3-D.

    Subclasses give `tangent`, the Voigt matrix ``d sigma / d eps`` at an
    integration point; a linear law's tangent is its elasticity matrix whatever
    the strain, a hyperelastic law's (energy, stress and tangent per point) depends
    on it.
    """

    def tangent(self, dim: int = 2, plane: Literal["stress", "strain"] | None = None) -> np.ndarray:
        """The tangent ``(3, 3)`` (2-D) or ``(6, 6)`` (3-D) in Voigt order."""
        raise NotImplementedError


@dataclass(frozen=True)
class LinearElastic(Material):
    """Isotropic linear elasticity (Hooke's law).

    Parameters
    ----------
    E : float
        Young's modulus, positive and finite.
    nu : float
        Poisson's ratio, in (-1, 0.5).

    Examples
    --------
    >>> LinearElastic(1.0, 0.25).lame(3)
    (0.4, 0.4)
    """

    E: float
    nu: float

    def __post_init__(self):
        try:
            E, nu = float(self.E), float(self.nu)
        except (TypeError, ValueError):
            raise MaterialError(f"LinearElastic: expected numbers E and nu, received "
                                f"E={self.E!r}, nu={self.nu!r}") from None
        _check_moduli(np.array([E]), np.array([nu]))
        object.__setattr__(self, "E", E)
        object.__setattr__(self, "nu", nu)

    def __iter__(self):
        """``E, nu = material``, as with the pair it replaces."""
        return iter((self.E, self.nu))

    def lame(self, dim: int = 2, plane: Literal["stress", "strain"] | None = None
             ) -> tuple[float, float]:
        """Lamé parameters ``(lam, mu)`` of the law in ``dim`` dimensions (see `lame`)."""
        check_plane(dim, plane)
        lam, mu = lame(self.E, self.nu, plane)
        return float(lam), float(mu)

    def elasticity_matrix(self, dim: int = 2,
                          plane: Literal["stress", "strain"] | None = None) -> np.ndarray:
        """``C`` in Voigt order: ``(3, 3)`` in 2-D (``plane`` "stress" or "strain"),
        ``(6, 6)`` in 3-D (``plane`` None); see `stiffness_matrix`."""
        check_plane(dim, plane)
        return stiffness_matrix(self.E, self.nu, plane)

    def tangent(self, dim: int = 2, plane: Literal["stress", "strain"] | None = None) -> np.ndarray:
        """The elasticity matrix (`elasticity_matrix`): the tangent of a linear law."""
        return self.elasticity_matrix(dim, plane)


def _check_moduli(E: np.ndarray, nu: np.ndarray) -> None:
    """Raise `MaterialError` unless every E is positive and finite and every nu in (-1, 0.5)."""
    if not (np.isfinite(E).all() and (E > 0).all()):
        raise MaterialError(f"materials: Young's moduli must be positive and finite, received "
                            f"{E.tolist()}")
    if not ((nu > -1.0) & (nu < 0.5)).all():          # NaN fails too
        raise MaterialError(f"materials: Poisson ratios must lie in (-1, 0.5), received "
                            f"{nu.tolist()}")


def parse_materials(materials: Material | ArrayLike | list, nregions: int,
                    plane: Literal["stress", "strain"] | None = None, *,
                    dim: int | None = None) -> tuple[LinearElastic, ...]:
    """One material object per region.

    Parameters
    ----------
    materials : Material, (E, nu) pair, or a list of either, one per region
        Pairs become `LinearElastic` materials.
    nregions : int
    plane : {"stress", "strain"}, optional
        With ``plane`` (2-D) or ``dim=3``, the elasticity matrices must also be
        finite (E near the float64 limit overflows them).
    dim : int, optional
        2 or 3 (default 2 when ``plane`` is given).

    Returns
    -------
    tuple of Material, length ``nregions``

    Raises
    ------
    MaterialError
        Not one material (pair) per region, or moduli out of range.
    """
    if isinstance(materials, Material):
        found = (materials,) * nregions
    elif isinstance(materials, (list, tuple)) and materials and \
            all(isinstance(m, Material) for m in materials):
        if len(materials) != nregions:
            raise MaterialError(f"materials: expected one material per region ({nregions} "
                                f"regions), received {len(materials)}")
        found = tuple(materials)
    else:
        found = tuple(LinearElastic(E, nu) for E, nu in _pairs(materials, nregions))
    if plane is not None or dim == 3:
        linear = [m for m in found if isinstance(m, LinearElastic)]
        if linear:
            table = moduli(linear)
            check_stiffness(stiffness_matrix(table[:, 0], table[:, 1], plane), table,
                            "the elasticity matrix")
    return found


def _pairs(materials, nregions):
    """``(r, 2)`` array of ``(E, nu)`` from one pair or a list of pairs, checked."""
    try:
        arr = np.asarray(check_real("materials", materials, error=MaterialError), dtype=float)
    except (TypeError, ValueError):
        raise MaterialError(f"materials: expected an (E, nu) pair, a Material or a list of "
                            f"{nregions} of either, received {materials!r}") from None
    if arr.shape == (2,):
        arr = np.tile(arr, (nregions, 1))
    if arr.shape != (nregions, 2):
        raise MaterialError(f"materials: expected an (E, nu) pair or one pair per region "
                            f"({nregions} regions), received shape {arr.shape}")
    _check_moduli(arr[:, 0], arr[:, 1])
    return arr


def moduli(materials: tuple[LinearElastic, ...] | list) -> np.ndarray:
    """``(r, 2)`` array of ``(E, nu)`` of linear isotropic materials.

    Raises
    ------
    MaterialError
        A material that is not `LinearElastic`.
    """
    other = [type(m).__name__ for m in materials if not isinstance(m, LinearElastic)]
    if other:
        raise MaterialError(f"materials: expected linear isotropic materials (LinearElastic or "
                            f"(E, nu) pairs), received {', '.join(other)}")
    return np.array([[m.E, m.nu] for m in materials], dtype=float).reshape(-1, 2)


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


def _real_moduli(name: str, value: ArrayLike) -> float | np.ndarray:
    """``value`` (a modulus or an array of them) as a float or a float64 array, refused
    with a `MaterialError` when it is complex, boolean, not numbers or not finite."""
    arr = check_array(name, value, error=MaterialError,
                      fix="pass real, finite elastic constants")
    return float(arr) if arr.ndim == 0 else arr


def lame(E: ArrayLike, nu: ArrayLike,
         plane: Literal["stress", "strain"] | None) -> tuple[np.ndarray, np.ndarray]:
    """Lamé parameters of the law: ``sigma = 2 mu eps + lam tr(eps) I``.

    In plane stress ``lam`` is ``lambda* = 2 lambda mu / (lambda + 2 mu)``; plane
    strain and 3-D (``plane=None``) have the same ``lambda``.

    Returns
    -------
    lam, mu : ndarray
    """
    if plane is not None:
        check_choice("plane", plane, PLANES)
    E, nu = np.asarray(_real_moduli("E", E)), np.asarray(_real_moduli("nu", nu))
    mu = E / (2.0 * (1.0 + nu))
    if plane == "stress":        # 2 lambda mu / (lambda + 2 mu), without the product
        lam = E * nu / ((1.0 + nu) * (1.0 - nu))
    else:
        lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
    return lam, mu


def stiffness_matrix(E: ArrayLike, nu: ArrayLike,
                     plane: Literal["stress", "strain"] | None) -> np.ndarray:
    """The matrix ``C`` with engineering shear strains: eq. 24 (strain) or 25 (stress)
    in 2-D, Voigt ``[xx, yy, xy]``; with ``plane=None`` the 3-D law, Voigt
    ``[xx, yy, zz, yz, xz, xy]``.

    Returns
    -------
    (..., 3, 3) or (..., 6, 6) ndarray
    """
    lam, mu = lame(E, nu, plane)
    dim = 2 if plane is not None else 3
    size = dim * (dim + 1) // 2
    C = np.zeros(np.shape(lam) + (size, size))
    for i in range(dim):
        for j in range(dim):
            C[..., i, j] = lam + 2.0 * mu if i == j else lam
    for i in range(dim, size):
        C[..., i, i] = mu
    return C


def kappa(nu: float | np.ndarray, plane: Literal["stress", "strain"]) -> float | np.ndarray:
    """Kolosov's constant: ``3 - 4 nu`` (plane strain) or ``(3 - nu) / (1 + nu)`` (plane stress)."""
    check_choice("plane", plane, PLANES)
    nu = _real_moduli("nu", nu)
    return 3.0 - 4.0 * nu if plane == "strain" else (3.0 - nu) / (1.0 + nu)


def effective_modulus(E: float | np.ndarray, nu: float | np.ndarray,
                      plane: Literal["stress", "strain"]) -> float | np.ndarray:
    """``E' = E`` (plane stress) or ``E / (1 - nu^2)`` (plane strain): ``G = K^2 / E'``."""
    kappa(nu, plane)
    E, nu = _real_moduli("E", E), _real_moduli("nu", nu)
    return E if plane == "stress" else E / (1.0 - nu * nu)
