"""The surface correction of peridynamic bonds by the energy method (Le & Bobaru 2018).

Every point's bonds are scaled so that uniform test strains store the classical
energy density of the material at that point; a bond takes the mean of its two
points' factors. `SurfaceCorrection` is a part of `cnem.pd.Problem` (and its
functions serve the distributed operators): it reads the problem's ``body``,
``material``, ``dim``, ``plane``, ``unit``, ``weight``, ``bond_stiffness``, ``bulk``,
``shear``, ``T`` and ``energy_density``.
"""

from __future__ import annotations

import numpy as np

from . import _kernels as K

__all__ = ["SurfaceCorrection"]


class SurfaceCorrection:
    """The energy-method bond factors of a peridynamic problem (a mixin of `Problem`)."""

    def _classical_density(self, strain):
        """``1/2 eps : C : eps`` of the material (d-dimensional law)."""
        d = self.dim
        if self.material.kind == "bond":
            nu = self.material.poisson(d, self.plane)
            E = self.material.E
            mu = E / (2 * (1 + nu))
            lam = E * nu / ((1 + nu) * (1 - 2 * nu))
            if d == 2 and self.plane == "stress":
                lam = 2 * lam * mu / (lam + 2 * mu)
            k = lam + 2 * mu / d
        else:
            k, mu = self.bulk, self.shear
        tr = np.trace(strain)
        dev = strain - tr / d * np.eye(d)
        return 0.5 * k * tr * tr + mu * (dev * dev).sum()

    def _pmb_correction(self):
        """The energy-method factors of the PMB from per-bond sums (numba), without
        the operators."""
        b, d = self.body, self.dim
        pairs = np.array([(a, c) for a in range(d) for c in range(a, d)], dtype=np.int64)
        Q = np.zeros((len(b), len(pairs), len(pairs)))
        K.pmb_correction_moments(b.xi, b.length, self.weight, b.family.offsets, pairs, Q)
        Q *= 0.25 * self.bond_stiffness
        target = []
        for a, c in pairs:
            eps = np.zeros((d, d))
            eps[a, c] = eps[c, a] = 1.0
            target.append(self._classical_density(eps))
        coef = np.ascontiguousarray(self._fit(Q, np.array(target)))
        factor = np.empty(len(b.bond_i))
        K.pmb_bond_factors(b.xi, b.length, b.family.offsets, b.bond_j, pairs, coef, factor)
        return factor

    @staticmethod
    def _fit(Q, target):
        """Per-point coefficients solving ``Q_i c_i = target`` (least squares where singular)."""
        rhs = np.broadcast_to(target, Q.shape[:2])[..., None]
        try:
            return np.linalg.solve(Q, rhs)[..., 0]
        except np.linalg.LinAlgError:                           # a point with too few bonds
            return np.array([np.linalg.lstsq(q, target, rcond=None)[0] for q in Q])

    def _test_fields(self):
        """Uniform test strains and the direction functions of the correction: all unit
        strains with ``n_a^2`` and ``n_a^2 n_c^2`` of the bond direction (bond-based), the
        deviatoric shears with ``{1, sum n_a^2 n_b^2}`` (state-based deviatoric part)."""
        d = self.dim
        pairs = [(a, c) for a in range(d) for c in range(a, d)]
        n = self.unit
        if self.material.kind == "bond":
            tests = []
            for a, c in pairs:
                eps = np.zeros((d, d))
                eps[a, c] = eps[c, a] = 1e-3
                tests.append(eps)
            # even functions of the direction: n_a^2 for the normal tests, n_a^2 n_c^2
            # for the shear tests
            return tests, [n[:, a] ** 2 * (n[:, c] ** 2 if a != c else 1.0) for a, c in pairs]
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

    def _correction(self):
        """Bond factors of the energy method: at every point, a function of the bond
        direction fitted so that the uniform test strains store the classical
        energy density there; a bond takes the mean of its two points' functions."""
        b = self.body
        if self.material.kind == "bond":
            return self._pmb_correction()
        tests, basis = self._test_fields()
        rows = []
        for eps in tests:
            u = b.points @ eps.T
            dil = 0.0
            if self.material.kind == "state":
                dil = 0.5 * self.bulk * (self.T @ u.reshape(-1)) ** 2
            rows.append([self.energy_density(u, P) - dil for P in basis])
        Q = np.array(rows).transpose(2, 0, 1)                       # (n, tests, basis)
        target = np.array([self._classical_density(eps) - (
            0.5 * self.bulk * np.trace(eps) ** 2 if self.material.kind == "state" else 0.0)
            for eps in tests])
        coef = self._fit(Q, target)
        G = np.array(basis)                                          # (basis, bonds)
        gi = (coef[b.bond_i].T * G).sum(axis=0)
        gj = (coef[b.bond_j].T * G).sum(axis=0)
        return 0.5 * (gi + gj)
