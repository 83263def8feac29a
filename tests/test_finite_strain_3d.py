"""3-D finite strain against closed forms: the incompressible neo-Hookean thick sphere
inflated by an imposed cavity radius, and Rivlin's torsion (`cnem.exact`). The closed
forms are checked first against the radial equilibrium they come from, integrated
numerically."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

import cnem
from cnem.exact import inflated_sphere_pressure, rivlin_torsion


@pytest.mark.parametrize("la", [1.1, 1.5, 2.0, 3.0])
def test_sphere_pressure_is_the_integral_of_radial_equilibrium(la):
    """``p = int_a^b 2 mu (lambda^2 - lambda^-4) / r dr``, ``lambda = r / R``,
    ``R^3 = r^3 - (a^3 - A^3)``; and the cavitation limit ``5 mu / 2`` of a large body."""
    mu, A, B = 1.7, 0.8, 1.9
    c = (la ** 3 - 1) * A ** 3
    stretch = lambda r: r / np.cbrt(r ** 3 - c)                     # noqa: E731
    b = np.cbrt(B ** 3 + c)
    p, _ = quad(lambda r: 2 * mu * (stretch(r) ** 2 - stretch(r) ** -4) / r, la * A, b,
                epsabs=0, epsrel=1e-12)
    assert np.isclose(inflated_sphere_pressure(la, A, B, mu), p, rtol=1e-10)
    assert np.isclose(inflated_sphere_pressure(1e3, A, 1e6 * A, mu), 2.5 * mu, rtol=1e-3)


def test_rivlin_torque_and_axial_force_are_the_integrals_of_the_stresses():
    """``M = int 2 pi r^2 sigma_thetaz dr``, ``N = int 2 pi r sigma_zz dr`` with
    ``sigma_thetaz = mu tau r`` and ``sigma_zz = int_a^r mu tau^2 s ds``."""
    mu, a = 0.6, 1.3
    tau = np.array([0.2, 0.7])
    M, N = rivlin_torsion(tau, a, mu)
    for t, m, n in zip(tau, M, N):
        szz = lambda r: -quad(lambda s: mu * t * t * s, r, a)[0]   # noqa: E731
        assert np.isclose(m, quad(lambda r: 2 * np.pi * r * r * mu * t * r, 0, a)[0])
        assert np.isclose(n, quad(lambda r: 2 * np.pi * r * szz(r), 0, a)[0])
        assert n < 0


def test_closed_forms_refuse_bad_input():
    with pytest.raises(cnem.errors.InputError, match="inner < outer"):
        inflated_sphere_pressure(1.5, 2.0, 1.0, 1.0)
    with pytest.raises(cnem.errors.InputError, match="mu"):
        rivlin_torsion(0.5, 1.0, -1.0)
