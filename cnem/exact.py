"""Exact solutions used by the demos and tests.

>>> import numpy as np
>>> cyl = LayeredCylinder([0.5, 0.7, 0.9], [(210000.0, 0.3), (105000.0, 0.2)], pressure=1.0)
>>> bool(np.isclose(cyl.radial_stress(np.array([0.5]))[0], -1.0))
True
"""

from __future__ import annotations

import numpy as np

from .material import lame

__all__ = ["LayeredCylinder"]


class LayeredCylinder:
    """Hollow cylinder of concentric layers under internal pressure (paper §4.3, eq. 35-41).

    In layer ``i`` (``R_i <= r <= R_{i+1}``) ``u_r = a_i r + b_i / r``,
    ``σ_rr = 2 (λ_i + μ_i) a_i - 2 μ_i b_i / r²``, ``σ_θθ = 2 (λ_i + μ_i) a_i
    + 2 μ_i b_i / r²`` with the 2-D Lamé parameters of the plane law (in plane
    stress ``λ* = 2 λ μ / (λ + 2 μ)``). The ``a_i, b_i`` follow from
    ``σ_rr(R_0) = -P``, ``σ_rr(R_last) = 0`` and continuity of ``u_r`` and
    ``σ_rr`` at every interface (eq. 41).

    Parameters
    ----------
    radii : (k + 1,) array_like
        Increasing radii: inner, interfaces, outer.
    materials : list of k ``(E, nu)`` pairs, inner layer first
    pressure : float
    plane : {"stress", "strain"}
    center : (2,) array_like
    """

    def __init__(self, radii, materials, *, pressure=1.0, plane="stress", center=(0.0, 0.0)):
        self.radii = np.asarray(radii, dtype=float)
        mats = np.asarray(materials, dtype=float).reshape(-1, 2)
        if len(mats) != len(self.radii) - 1 or not (np.diff(self.radii) > 0).all():
            raise ValueError(f"expected increasing radii and one material per layer, received "
                             f"{len(self.radii)} radii and {len(mats)} materials")
        self.lam, self.mu = lame(mats[:, 0], mats[:, 1], plane)
        self.center = np.asarray(center, dtype=float)
        k = len(mats)
        A = np.zeros((2 * k, 2 * k))
        rhs = np.zeros(2 * k)

        def srr(i, r):      # coefficients of (a_i, b_i) in sigma_rr
            return 2.0 * (self.lam[i] + self.mu[i]), -2.0 * self.mu[i] / r ** 2

        A[0, 0:2] = srr(0, self.radii[0])
        rhs[0] = -pressure
        A[1, 2 * k - 2:] = srr(k - 1, self.radii[-1])
        for i in range(k - 1):
            r = self.radii[i + 1]
            A[2 + 2 * i, 2 * i:2 * i + 2] = [r, 1.0 / r]
            A[2 + 2 * i, 2 * i + 2:2 * i + 4] = [-r, -1.0 / r]
            A[3 + 2 * i, 2 * i:2 * i + 2] = srr(i, r)
            A[3 + 2 * i, 2 * i + 2:2 * i + 4] = np.negative(srr(i + 1, r))
        coef = np.linalg.solve(A, rhs).reshape(k, 2)
        self.a, self.b = coef[:, 0], coef[:, 1]

    def layer(self, r):
        """Layer index of radii (the inner layer at an interface)."""
        return np.clip(np.searchsorted(self.radii, r, side="left") - 1, 0, len(self.a) - 1)

    def radial_displacement(self, r):
        i = self.layer(r)
        return self.a[i] * r + self.b[i] / r

    def radial_stress(self, r):
        i = self.layer(r)
        return 2.0 * (self.lam[i] + self.mu[i]) * self.a[i] - 2.0 * self.mu[i] * self.b[i] / r ** 2

    def hoop_stress(self, r):
        i = self.layer(r)
        return 2.0 * (self.lam[i] + self.mu[i]) * self.a[i] + 2.0 * self.mu[i] * self.b[i] / r ** 2

    def _polar(self, points):
        rel = np.asarray(points, dtype=float) - self.center
        r = np.hypot(rel[:, 0], rel[:, 1])
        return r, rel[:, 0] / r, rel[:, 1] / r

    def displacement(self, points):
        """``(p, 2)`` Cartesian displacements."""
        r, c, s = self._polar(points)
        ur = self.radial_displacement(r)
        return np.column_stack([ur * c, ur * s])

    def stress(self, points, *, layer=None):
        """``(p, 3)`` ``[sxx, syy, sxy]``; ``layer`` forces the layer (for cells on an interface)."""
        r, c, s = self._polar(points)
        i = self.layer(r) if layer is None else np.asarray(layer)
        lm = 2.0 * (self.lam[i] + self.mu[i]) * self.a[i]
        dev = 2.0 * self.mu[i] * self.b[i] / r ** 2
        srr, stt = lm - dev, lm + dev
        return np.column_stack([srr * c * c + stt * s * s, srr * s * s + stt * c * c,
                                (srr - stt) * s * c])
