"""Materials as objects, and the isotropic linear law in 2-D (plane stress or strain,
eq. 24-25 of the C-NEM paper) and 3-D.

A material is an object that knows its constitutive law in any dimension
(`Material`); `LinearElastic` is the isotropic Hooke law. The hyperelastic laws of
finite strain (`Hyperelastic`: `NeoHookean`, `SaintVenantKirchhoff`) are energies of
the deformation gradient ``F`` with their first Piola-Kirchhoff stress and its
tangent, vectorised over integration points ``(q, d, d)``. The vectorised functions
below (`lame`, `stiffness_matrix`, `kappa`, `effective_modulus`) are the constitutive
facts that C-NEM, the P1 anchor, fracture and peridynamics share, over arrays of
``(E, nu)``. Voigt order: ``[xx, yy, xy]`` in 2-D, ``[xx, yy, zz, yz, xz, xy]`` in
3-D, engineering shear strains.

>>> from cnem.material import LinearElastic
>>> steel = LinearElastic(210e3, 0.3)
>>> steel.elasticity_matrix(2, "strain").shape, steel.elasticity_matrix(3).shape
((3, 3), (6, 6))
>>> E, nu = steel                     # unpacks like the (E, nu) pair it replaces
>>> import numpy as np
>>> W, P, A = NeoHookean(1.0, 2.0).evaluate(np.eye(3)[None])   # stress-free reference
>>> float(W[0]), float(abs(P).max()), A.shape
(0.0, 0.0, (1, 3, 3, 3, 3))
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from . import hyperdual as hd
from .errors import MaterialError, OptionError, check_array, check_choice, check_real

__all__ = ["PLANES", "Material", "LinearElastic", "Hyperelastic", "NeoHookean",
           "SaintVenantKirchhoff", "parse_materials", "moduli", "check_plane", "check_stiffness",
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


class Hyperelastic(Material):
    """A hyperelastic law: a strain energy per unit reference volume ``W(F)`` of the
    deformation gradient, its first Piola-Kirchhoff stress ``P = dW/dF`` and the
    tangent ``A = dP/dF``, for any dimension ``d`` of ``F``.

    In 2-D, ``F`` is the in-plane ``2 x 2`` block of a plane-strain deformation
    (``F33 = 1``, no out-of-plane shear): the laws below are written so that the
    2-D energy is exactly the 3-D one of that deformation. Subclasses give
    `evaluate` and `lame`; ``energy`` is written with `cnem.hyperdual` functions, so
    that it also takes hyper-dual numbers (the tests differentiate it that way).
    """

    def evaluate(self, F: np.ndarray, *, tangent: bool = True
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """Energy, stress and tangent at deformation gradients ``F``.

        Parameters
        ----------
        F : (q, d, d) ndarray
            ``F[k, i, J] = dx_i / dX_J``, d = 2 (plane strain) or 3. A point with
            NaN entries gets NaN values.
        tangent : bool
            Also the tangent (else None).

        Returns
        -------
        W : (q,) ndarray
        P : (q, d, d) ndarray
            ``P[k, i, J] = dW / dF_iJ``.
        A : (q, d, d, d, d) ndarray or None
            ``A[k, i, J, k, L] = d P_iJ / d F_kL`` (major symmetry ``A_iJkL = A_kLiJ``).
        """
        raise NotImplementedError

    def energy(self, F: np.ndarray | hd.HyperDual) -> np.ndarray | hd.HyperDual:
        """``W (...)`` at ``F (..., d, d)`` (an ndarray or `cnem.hyperdual.HyperDual`;
        ``(q, d, d)`` for q points, any leading axes allowed), d = 2 or 3."""
        raise NotImplementedError

    def lame(self, dim: int = 2, plane: Literal["strain"] | None = None
             ) -> tuple[float, float]:
        """Lamé parameters ``(lam, mu)`` of the law linearised at ``F = I`` (in 2-D
        plane strain, the only idealisation: ``plane`` None or "strain")."""
        raise NotImplementedError

    def linearized(self) -> LinearElastic:
        """The small-strain law of this material (`LinearElastic` of its `lame`)."""
        lam, mu = self.lame(3, None)
        return LinearElastic(mu * (3.0 * lam + 2.0 * mu) / (lam + mu), lam / (2.0 * (lam + mu)))

    def tangent(self, dim: int = 2, plane: Literal["strain"] | None = None) -> np.ndarray:
        """The Voigt tangent of the law linearised at ``F = I`` (plane strain in 2-D)."""
        self.lame(dim, plane)
        return self.linearized().elasticity_matrix(dim, "strain" if dim == 2 else None)


def _positive_lame(name, lam, mu):
    """``(lam, mu)`` as floats, or a MaterialError unless finite with mu > 0 and a
    positive bulk modulus ``lam + 2 mu / 3``."""
    try:
        lam, mu = float(lam), float(mu)
    except (TypeError, ValueError):
        raise MaterialError(f"{name}: expected numbers, received lam={lam!r}, mu={mu!r}") from None
    if not (np.isfinite(mu) and np.isfinite(lam) and mu > 0 and lam + 2.0 * mu / 3.0 > 0):
        raise MaterialError(f"{name}: expected a finite shear modulus mu > 0 and bulk modulus "
                            f"lam + 2 mu / 3 > 0, received mu={mu}, lam={lam}")
    return lam, mu


def _hyper_lame(dim, plane, lam, mu):
    """``(lam, mu)`` after checking the idealisation: plane strain in 2-D, none in 3-D
    (a hyperelastic plane-stress law needs the out-of-plane stretch solved for); None
    in 2-D is plane strain."""
    if dim == 2 and plane is None:
        plane = "strain"
    check_plane(dim, plane)
    if plane == "stress":
        raise OptionError("plane: the hyperelastic laws are written for plane strain (F33 = 1) "
                          "in 2-D, received 'stress'; pass plane='strain' or use a 3-D model")
    return lam, mu


def _deformation_gradients(F, *, leading=False):
    """``F`` as a float ``(q, d, d)`` array, d = 2 or 3, or a MaterialError naming ``F``
    (complex, boolean, not numbers, another shape). With ``leading``, any leading axes
    ``(..., d, d)`` and a `cnem.hyperdual.HyperDual` (kept as it is) are accepted.
    NaN entries pass: they give NaN energies and stresses at their points, as inverted
    gradients do, which Newton reports as a named `ConvergenceError`."""
    if not (leading and isinstance(F, hd.HyperDual)):
        F = check_array("F", F, finite=False, error=MaterialError)
    if (F.ndim < 2 if leading else F.ndim != 3) or F.shape[-1] != F.shape[-2] \
            or F.shape[-1] not in (2, 3):
        expected = "(..., d, d)" if leading else "(q, d, d) (F[None] for one gradient)"
        raise MaterialError(f"F: expected deformation gradients of shape {expected}, d = 2 or "
                            f"3, received shape {F.shape}")
    return F


@dataclass(frozen=True)
class NeoHookean(Hyperelastic):
    """Compressible neo-Hookean law
    ``W = mu/2 (tr C - 3) - mu ln J + lam/2 (ln J)^2``, ``C = F^T F``, ``J = det F``.

    In plane strain ``tr C = C11 + C22 + 1`` (``F33 = 1``), so the 2-D law is
    ``mu/2 (|F|^2 - 2) - mu ln J + lam/2 (ln J)^2`` with the 2 x 2 ``F``. Its
    stress is ``P = mu (F - F^-T) + lam ln J F^-T`` and its linearisation at
    ``F = I`` Hooke's law with Lamé parameters ``lam``, ``mu``.

    Parameters
    ----------
    mu : float
        Shear modulus, positive and finite.
    lam : float
        Lamé's first parameter; the bulk modulus ``lam + 2 mu / 3`` must be positive.
    """

    mu: float
    lam: float

    def __post_init__(self):
        lam, mu = _positive_lame("NeoHookean", self.lam, self.mu)
        object.__setattr__(self, "mu", mu)
        object.__setattr__(self, "lam", lam)

    def lame(self, dim: int = 2, plane: Literal["strain"] | None = None
             ) -> tuple[float, float]:
        """``(lam, mu)`` as given (see `Hyperelastic.lame`)."""
        return _hyper_lame(dim, plane, self.lam, self.mu)

    def energy(self, F: np.ndarray | hd.HyperDual) -> np.ndarray | hd.HyperDual:
        """``W (...)`` at ``F (..., d, d)`` (see `Hyperelastic.energy`)."""
        F = _deformation_gradients(F, leading=True)
        d = F.shape[-1]
        log_j = hd.log(hd.det(F))
        return 0.5 * self.mu * ((F * F).sum(axis=(-2, -1)) - d) - self.mu * log_j \
            + 0.5 * self.lam * log_j * log_j

    def evaluate(self, F: np.ndarray, *, tangent: bool = True
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """``W``, ``P`` and ``A`` at ``F (q, d, d)`` (see `Hyperelastic.evaluate`)."""
        F = _deformation_gradients(F)
        mu, lam = self.mu, self.lam
        d = F.shape[1]
        # J <= 0 gives NaN (J = 0: inf and NaN), not an error or a warning: Newton reports it
        with np.errstate(invalid="ignore", divide="ignore"):
            log_j = np.log(np.linalg.det(F))
            inv = hd.inv(F)                                     # inv[k, J, i] = F^-1_Ji
            inv_t = np.swapaxes(inv, 1, 2)                      # F^-T_iJ
            W = 0.5 * mu * (np.einsum("kij,kij->k", F, F) - d) - mu * log_j \
                + 0.5 * lam * log_j ** 2
            P = mu * F + (lam * log_j - mu)[:, None, None] * inv_t
            if not tangent:
                return W, P, None
            # A_iJkL = mu d_ik d_JL + (mu - lam ln J) F^-1_Jk F^-1_Li + lam F^-1_Ji F^-1_Lk
            A = mu * np.einsum("ik,JL->iJkL", np.eye(d), np.eye(d))[None] \
                + (mu - lam * log_j)[:, None, None, None, None] \
                * np.einsum("qJk,qLi->qiJkL", inv, inv) \
                + lam * np.einsum("qJi,qLk->qiJkL", inv, inv)
        return W, P, A


@dataclass(frozen=True)
class SaintVenantKirchhoff(Hyperelastic):
    """Saint Venant-Kirchhoff law ``W = lam/2 (tr E)^2 + mu E : E``, ``E = (F^T F - I)/2``.

    In plane strain ``E33 = E13 = E23 = 0``: the 2-D law is the same formula with
    the 2 x 2 ``F``. ``S = lam tr E I + 2 mu E``, ``P = F S``. It does not resist
    strong compression (the energy has a maximum along uniaxial compression near
    a stretch of ``1/sqrt(3)``); use `NeoHookean` there.

    Parameters
    ----------
    E : float
        Young's modulus of the linearised law, positive and finite.
    nu : float
        Its Poisson ratio, in (-1, 0.5).
    """

    E: float
    nu: float

    def __post_init__(self):
        LinearElastic(self.E, self.nu)                          # the same checks
        object.__setattr__(self, "E", float(self.E))
        object.__setattr__(self, "nu", float(self.nu))

    def lame(self, dim: int = 2, plane: Literal["strain"] | None = None
             ) -> tuple[float, float]:
        """``(lam, mu)`` of ``E``, ``nu`` (the 3-D law's, also plane strain's)."""
        lam, mu = lame(self.E, self.nu, None)
        return _hyper_lame(dim, plane, float(lam), float(mu))

    def energy(self, F: np.ndarray | hd.HyperDual) -> np.ndarray | hd.HyperDual:
        """``W (...)`` at ``F (..., d, d)`` (see `Hyperelastic.energy`)."""
        F = _deformation_gradients(F, leading=True)
        lam, mu = self.lame(3, None)
        strain = 0.5 * (hd.matmul(hd.transpose(F), F) - np.eye(F.shape[-1]))
        tr = hd.trace(strain)
        return 0.5 * lam * tr * tr + mu * (strain * strain).sum(axis=(-2, -1))

    def evaluate(self, F: np.ndarray, *, tangent: bool = True
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """``W``, ``P`` and ``A`` at ``F (q, d, d)`` (see `Hyperelastic.evaluate`)."""
        F = _deformation_gradients(F)
        lam, mu = self.lame(3, None)
        d = F.shape[1]
        eye = np.eye(d)
        strain = 0.5 * (np.einsum("kiJ,kiL->kJL", F, F) - eye)
        tr = np.trace(strain, axis1=1, axis2=2)
        S = lam * tr[:, None, None] * eye + 2.0 * mu * strain
        W = 0.5 * lam * tr ** 2 + mu * np.einsum("kij,kij->k", strain, strain)
        P = F @ S
        if not tangent:
            return W, P, None
        # A_iJkL = d_ik S_LJ + lam F_iJ F_kL + mu F_iL F_kJ + mu (F F^T)_ik d_JL
        A = np.einsum("ik,qLJ->qiJkL", eye, S) + lam * np.einsum("qiJ,qkL->qiJkL", F, F) \
            + mu * np.einsum("qiL,qkJ->qiJkL", F, F) \
            + mu * np.einsum("qik,JL->qiJkL", F @ np.swapaxes(F, 1, 2), eye)
        return W, P, A


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
