"""The deviatoric sub-cell stabilisation of SCNI, at small and finite strain.

Plain SCNI (one smoothed strain per integration cell) leaves oscillating modes with
little energy. `cnem.Elasticity` and `cnem.Hyperelasticity` penalise, with a weight
``a``, the difference between every fan sub-cell's smoothed strain and its cell's, with
the deviatoric energy of the shear modulus alone:

    a sum_s A_s 2 mu dev(e_s - e_k) : dev(e_s - e_k),

the deviator taken of the 3-D strain of the idealisation (``e_zz = 0`` in plane strain,
``e_zz = -nu / (1 - nu) (e_xx + e_yy)`` in plane stress). It carries no bulk stiffness
of its own, so it neither locks nor stiffens the volume change as ``nu -> 1/2``.
Written as a linear law ``sigma = 2 mu e + lam_s tr(e) I`` on the strain the
assembly sees (2-D or 3-D), it has ``lam_s = -2 mu / 3`` (3-D and plane strain) and
``lam_s = 2 mu (r^2 - (1 - r)^2 / 3)``, ``r = nu / (1 - nu)``, in plane stress
(`deviatoric_lame`): a constant ``C`` per cell, so the one-pass assembly of
`cnem.Elasticity` holds. In plane stress, where the law's own ``lam* = 2 mu nu / (1 - nu)``
stays below ``2 mu`` and nothing locks, `cnem.Elasticity` keeps the shear-only law
``2 mu (e_s - e_k) : (e_s - e_k)`` (``lam_s = 0``, `stabilization_lame`): the deviator of
the 3-D strain would stiffen it (``lam_s > 0`` for ``nu > 0.22``; Cook's membrane -2.09 %
against -1.98 % at 117 nodes). At finite strain the matching energy is the isochoric
neo-Hookean law (`IsochoricNeoHookean`), whose linearisation at ``F = I`` is that law.

>>> import numpy as np
>>> float(deviatoric_lame(3.0, 0.3, None))
-2.0
>>> W, P, A = IsochoricNeoHookean(1.0).evaluate(np.eye(3)[None] * 1.1)   # pure dilatation
>>> bool(abs(W[0]) < 1e-15 and abs(P).max() < 1e-15)
True
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .. import hyperdual as hd
from ..errors import MaterialError
from ..material import Hyperelastic, LinearElastic, _deformation_gradients, check_plane

if TYPE_CHECKING:
    from typing import Literal

    from numpy.typing import ArrayLike

__all__ = ["deviatoric_lame", "stabilization_lame", "IsochoricNeoHookean"]


def deviatoric_lame(mu: ArrayLike, nu: ArrayLike,
                    plane: Literal["stress", "strain"] | None) -> np.ndarray:
    """``lam_s`` such that ``2 mu e : e + lam_s (tr e)^2`` of the assembly's strain ``e``
    (2-D or 3-D) is ``2 mu dev(e3) : dev(e3)`` of the body's 3-D strain ``e3``.

    Parameters
    ----------
    mu : float or (r,) array_like
        Shear moduli.
    nu : float or (r,) array_like
        Poisson ratios (used in plane stress only, where ``e_zz`` depends on them).
    plane : {"stress", "strain"} or None
        The 2-D idealisation, None in 3-D.

    Returns
    -------
    ndarray, shape of ``mu``
        ``-2 mu / 3`` in 3-D and plane strain (``e_zz = 0``); in plane stress, where
        ``e_zz = -r tr e`` with ``r = nu / (1 - nu)``, ``2 mu (r^2 - (1 - r)^2 / 3)``
        (``-2 mu / 3`` at ``nu = 0``, the plane-stress law's own ``lam* = 2 mu`` at
        ``nu -> 1/2``, where the whole energy is deviatoric).
    """
    mu, nu = np.asarray(mu, dtype=float), np.asarray(nu, dtype=float)
    if plane != "stress":
        return -2.0 * mu / 3.0
    r = nu / (1.0 - nu)
    return 2.0 * mu * (r * r - (1.0 - r) ** 2 / 3.0)


def stabilization_lame(mu: ArrayLike, nu: ArrayLike,
                       plane: Literal["stress", "strain"] | None) -> np.ndarray:
    """``lam_s`` of the sub-cell stabilisation's law ``2 mu e : e + lam_s (tr e)^2``: the
    deviatoric one (`deviatoric_lame`) in 3-D and plane strain, where the volume change
    may lock; ``0`` in plane stress, where it cannot (the shear-only law).

    Parameters
    ----------
    mu, nu : float or (r,) array_like
    plane : {"stress", "strain"} or None

    Returns
    -------
    ndarray, shape of ``mu``
    """
    if plane == "stress":
        return np.zeros_like(np.asarray(mu, dtype=float))
    return deviatoric_lame(mu, nu, plane)


@dataclass(frozen=True)
class IsochoricNeoHookean(Hyperelastic):
    """The isochoric neo-Hookean energy ``W = mu/2 (J^(-2/3) tr C - 3)``, ``C = F^T F``:
    the deviatoric sub-cell stabilisation at finite strain (it has no bulk stiffness,
    so it is not a material on its own).

    In plane strain ``tr C = C11 + C22 + 1`` and ``J = det F`` of the 2 x 2 ``F``
    (``F33 = 1``): the 3-D law of that deformation. Its stress is
    ``P = mu J^(-2/3) (F - tr C / 3 F^-T)``, zero for every pure dilatation, and its
    linearisation at ``F = I`` is ``2 mu dev(e) : dev(e)`` (Lamé ``lam = -2 mu / 3``).

    Parameters
    ----------
    mu : float
        Shear modulus, positive and finite.
    """

    mu: float

    def __post_init__(self):
        try:
            mu = float(self.mu)
        except (TypeError, ValueError):
            raise MaterialError(f"IsochoricNeoHookean: expected a number mu, received "
                                f"{self.mu!r}") from None
        if not (np.isfinite(mu) and mu > 0):
            raise MaterialError(f"IsochoricNeoHookean: expected a finite shear modulus mu > 0, "
                                f"received {mu}")
        object.__setattr__(self, "mu", mu)

    def lame(self, dim: int = 2, plane: Literal["strain"] | None = None
             ) -> tuple[float, float]:
        """``(-2 mu / 3, mu)``: the deviatoric law at ``F = I`` (zero bulk modulus)."""
        check_plane(dim, "strain" if dim == 2 and plane is None else plane)
        return -2.0 * self.mu / 3.0, self.mu

    def linearized(self) -> LinearElastic:
        """Refused: the law has no bulk stiffness, hence no ``(E, nu)``."""
        raise MaterialError("IsochoricNeoHookean: a deviatoric energy has no Young's modulus "
                            "and Poisson ratio (zero bulk modulus); use its tangent() instead")

    def tangent(self, dim: int = 2, plane: Literal["strain"] | None = None) -> np.ndarray:
        """The Voigt matrix of ``2 mu dev(e) : dev(e)`` (plane strain in 2-D)."""
        lam, mu = self.lame(dim, plane)
        size = 3 * (dim - 1)
        C = np.zeros((size, size))
        C[:dim, :dim] = lam
        C[range(size), range(size)] += mu
        C[range(dim), range(dim)] += mu
        return C

    def energy(self, F: np.ndarray | hd.HyperDual) -> np.ndarray | hd.HyperDual:
        """``W (...)`` at ``F (..., d, d)`` (see `Hyperelastic.energy`)."""
        F = _deformation_gradients(F, leading=True)
        d = F.shape[-1]
        trace_c = (F * F).sum(axis=(-2, -1)) + (3 - d)
        return 0.5 * self.mu * (hd.exp(-2.0 / 3.0 * hd.log(hd.det(F))) * trace_c - 3.0)

    def evaluate(self, F: np.ndarray, *, tangent: bool = True
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """``W``, ``P`` and ``A`` at ``F (q, d, d)`` (see `Hyperelastic.evaluate`)."""
        F = _deformation_gradients(F)
        mu, d = self.mu, F.shape[1]
        with np.errstate(invalid="ignore", divide="ignore"):
            scale = mu * np.linalg.det(F) ** (-2.0 / 3.0)               # mu J^(-2/3)
            trace_c = np.einsum("kij,kij->k", F, F) + (3 - d)
            inv = hd.inv(F)                                     # inv[k, J, i] = F^-1_Ji
            inv_t = np.swapaxes(inv, 1, 2)
            W = 0.5 * (scale * trace_c - 3.0 * mu)
            P = scale[:, None, None] * (F - trace_c[:, None, None] / 3.0 * inv_t)
            if not tangent:
                return W, P, None
            # A_iJkL = mu J^(-2/3) [d_ik d_JL - 2/3 (F_iJ F^-1_Lk + F^-1_Ji F_kL)
            #                       + 2/9 tr C F^-1_Ji F^-1_Lk + 1/3 tr C F^-1_Jk F^-1_Li]
            t = trace_c[:, None, None, None, None]
            A = np.einsum("ik,JL->iJkL", np.eye(d), np.eye(d))[None] \
                - 2.0 / 3.0 * (np.einsum("qiJ,qLk->qiJkL", F, inv)
                               + np.einsum("qJi,qkL->qiJkL", inv, F)) \
                + t * (2.0 / 9.0 * np.einsum("qJi,qLk->qiJkL", inv, inv)
                       + 1.0 / 3.0 * np.einsum("qJk,qLi->qiJkL", inv, inv))
            A *= scale[:, None, None, None, None]
        return W, P, A
