"""`BondContinuum`: the hyperelastic law of CPD's one-neighbour interactions in the
continuum limit, for C-NEM (`cnem.Hyperelasticity`) to solve with the same energy as
`cnem.pd.CPD` (2-D, ``C2 = 0``).

A homogeneous deformation ``F`` stretches a bond of direction ``M`` by
``lam(M) = |F M|``. CPD's one-neighbour energy per unit volume (Javili et al., eq. 8
and 41-42, ``psi1 = C1 |Xi| p(lam)``, ``p = S_n(lam)^2 / 2``), integrated over a full
horizon disc of radius ``delta``, is

    W(F) = 1/2 int_disc C1 r p(lam(M)) dA = C1 delta^3 / 6 int_0^2pi p(|F M(theta)|) dtheta,

and linearises to Hooke's law with ``lam = mu = C1 pi delta^3 / 24`` (the Cauchy solid
of `cnem.pd.cpd_moduli`). In terms of that shear modulus ``W = 4 mu / pi int p dtheta``.
The integrand is pi-periodic and smooth, so the trapezoidal rule over ``angles`` equally
spaced directions of a half turn converges exponentially; for ``n = 2`` the integrand is a
trigonometric polynomial of degree 4 and any ``angles >= 3`` gives it exactly: the law is
then Saint Venant-Kirchhoff with ``lam = mu`` (``E = 5 mu / 2``, ``nu = 1/4`` in plane
strain), which the tests check.

>>> import numpy as np
>>> W, P, A = BondContinuum(1.0, 1.0).evaluate(np.eye(2)[None])
>>> bool(abs(W[0]) < 1e-15 and abs(P).max() < 1e-15), float(A[0, 0, 0, 0, 0].round(12))
(True, 3.0)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

import cnem.hyperdual as hd
from cnem.errors import MaterialError
from cnem.material import Hyperelastic, LinearElastic
from cnem.pd.cpd import seth_hill

if TYPE_CHECKING:
    from typing import Literal

__all__ = ["BondContinuum"]


@dataclass(frozen=True)
class BondContinuum(Hyperelastic):
    """CPD's one-neighbour Seth-Hill energy integrated over the directions of a horizon
    (2-D): ``W(F) = 4 mu / pi int_0^2pi p_n(|F M(theta)|) dtheta``.

    Parameters
    ----------
    mu : float
        Shear modulus (= Lamé's lambda) of the linearised law, positive.
    exponent : float
        Seth-Hill ``n`` of `cnem.pd.CPD` (2 Green-Lagrange-like, 1 Biot-like, 0 logarithmic).
    angles : int
        Directions of the trapezoidal rule over a half turn.
    """

    mu: float
    exponent: float = 2.0
    angles: int = 48

    def __post_init__(self):
        if not (np.isfinite(self.mu) and self.mu > 0 and np.isfinite(self.exponent)
                and int(self.angles) >= 3):
            raise MaterialError(f"BondContinuum: expected mu > 0, a finite exponent and "
                                f"angles >= 3, received mu={self.mu}, exponent={self.exponent}, "
                                f"angles={self.angles}")

    def _directions(self) -> tuple[np.ndarray, float]:
        """``M (a, 2)`` and the weight of each direction in ``W = weight sum p``."""
        theta = np.pi * np.arange(self.angles) / self.angles
        return np.column_stack([np.cos(theta), np.sin(theta)]), 8.0 * self.mu / self.angles

    @staticmethod
    def _check_2d(F):
        if F.shape[-1] != 2:
            raise MaterialError(f"BondContinuum is a 2-D law (CPD's planar bonds): expected "
                                f"F of shape (..., 2, 2), received {F.shape}")

    def lame(self, dim: int = 2, plane: Literal["strain"] | None = None
             ) -> tuple[float, float]:
        """``(mu, mu)``: the Cauchy solid (2-D only)."""
        if dim != 2 or plane not in (None, "strain"):
            raise MaterialError(f"BondContinuum is a 2-D law: expected dim=2 (plane strain), "
                                f"received dim={dim}, plane={plane!r}")
        return float(self.mu), float(self.mu)

    def linearized(self) -> LinearElastic:
        """``E = 5 mu / 2``, ``nu = 1/4``: plane strain of it has ``lam = mu``."""
        return LinearElastic(2.5 * self.mu, 0.25)

    def energy(self, F: np.ndarray | hd.HyperDual) -> np.ndarray | hd.HyperDual:
        """``W (...)`` at ``F (..., 2, 2)`` (ndarray or `cnem.hyperdual.HyperDual`)."""
        self._check_2d(F)
        M, weight = self._directions()
        stretched = hd.matmul(F[..., None, :, :], M[:, :, None])[..., 0]   # (..., a, 2)
        return weight * seth_hill(self.exponent)(hd.norm(stretched)).sum(axis=-1)

    def evaluate(self, F: np.ndarray, *, tangent: bool = True
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """``W (q,)``, ``P (q, 2, 2)``, ``A (q, 2, 2, 2, 2)`` at ``F (q, 2, 2)``."""
        F = np.asarray(F, dtype=float)
        self._check_2d(F)
        M, weight = self._directions()
        FM = np.einsum("qiJ,aJ->qai", F, M)
        lam = np.sqrt(np.einsum("qai,qai->qa", FM, FM))
        p, p1, p2 = (v.reshape(lam.shape) for v in
                     hd.derivative(seth_hill(self.exponent), lam.ravel()))
        a = FM / lam[..., None]                                     # unit deformed bonds
        W = weight * p.sum(axis=1)
        P = weight * np.einsum("qa,qai,aJ->qiJ", p1, a, M)
        if not tangent:
            return W, P, None
        # A_iJkL = sum p'' a_i a_k M_J M_L + p' / lam (d_ik - a_i a_k) M_J M_L
        soft = (p1 / lam)[..., None, None] * (np.eye(2) - a[..., :, None] * a[..., None, :])
        along = p2[..., None, None] * a[..., :, None] * a[..., None, :]
        A = weight * np.einsum("qaik,aJ,aL->qiJkL", along + soft, M, M)
        return W, P, A
