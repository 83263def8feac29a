"""The pieces of the C-NEM vs CPD demo (`cnem.demos.cnem_vs_cpd`): the continuum law of
CPD's bonds (`BondContinuum`), the closed form of uniaxial tension, and the calibration
of C1 on the interior points (`bulk_factor`)."""

from __future__ import annotations

import numpy as np
import pytest

import cnem
import cnem.hyperdual as hd
import cnem.pd as pd
from cnem.demos.cnem_vs_cpd import tension_closed_form
from cnem.demos.cpd.bond_law import BondContinuum
from cnem.demos.cpd.versus import bulk_factor, cpd_material
from cnem.material import SaintVenantKirchhoff

RNG = np.random.default_rng(3)
F = np.eye(2) + 0.35 * RNG.standard_normal((6, 2, 2))


@pytest.mark.parametrize("exponent", [2.0, 1.0, 0.0, -1.0])
def test_stress_and_tangent_are_the_derivatives_of_the_energy(exponent):
    law = BondContinuum(1.7, exponent)
    W, P, A = law.evaluate(F)
    value, grad, hess = hd.derivatives(lambda y: law.energy(y.reshape(y.shape[:-1] + (2, 2))),
                                       F.reshape(len(F), 4))
    scale = np.abs(A).max()
    np.testing.assert_allclose(W, value, rtol=1e-13)
    np.testing.assert_allclose(P.reshape(len(F), 4), grad, atol=1e-13 * scale)
    np.testing.assert_allclose(A.reshape(len(F), 4, 4), hess, atol=1e-12 * scale)


@pytest.mark.parametrize("angles", [3, 7, 48])
def test_green_lagrange_bonds_are_saint_venant_kirchhoff_with_lam_equal_mu(angles):
    """n = 2: ``(|F M|^2 - 1)^2 / 8`` is a trigonometric polynomial of degree 4 in the
    direction, integrated exactly from three directions of a half turn: the law is SVK
    with lam = mu (E = 5 mu / 2, nu = 1/4 in plane strain) for any deformation."""
    mu = 0.8
    ours = BondContinuum(mu, 2.0, angles=angles).evaluate(F)
    svk = SaintVenantKirchhoff(2.5 * mu, 0.25).evaluate(F)
    for a, b in zip(ours, svk):
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-13 * np.abs(b).max())


def test_linearisation_is_the_cauchy_solid():
    """At F = I the tangent is Hooke's ``lam d_iJ d_kL + mu (d_ik d_JL + d_iL d_Jk)`` with
    lam = mu, for every exponent (p''(1) = 1), as `lame` and `linearized` say."""
    eye = np.eye(2)
    hooke = np.einsum("iJ,kL->iJkL", eye, eye) + np.einsum("ik,JL->iJkL", eye, eye) \
        + np.einsum("iL,Jk->iJkL", eye, eye)
    for n in (2.0, 1.0, 0.0):
        law = BondContinuum(1.3, n)
        np.testing.assert_allclose(law.evaluate(eye[None])[2][0], 1.3 * hooke, atol=1e-13)
        assert law.lame(2) == (1.3, 1.3)
    lam, mu = BondContinuum(1.3).linearized().elasticity_matrix(2, "strain")[0, 1], 1.3
    assert abs(lam - mu) < 1e-12


def test_bad_laws_and_three_dimensional_gradients_are_refused():
    with pytest.raises(cnem.MaterialError, match="mu > 0"):
        BondContinuum(-1.0)
    with pytest.raises(cnem.MaterialError, match="2-D law"):
        BondContinuum(1.0).evaluate(np.eye(3)[None])
    with pytest.raises(cnem.MaterialError, match="2-D law"):
        BondContinuum(1.0).lame(3)


def test_tension_closed_form_of_saint_venant_kirchhoff():
    """n = 2 is SVK with lam = mu: uniaxial plane strain has ``E22 = -E11 / 3`` and
    ``P11 = stretch 8 mu E11 / 3``."""
    mu, stretch = 1.0, 1.5
    b, P11 = tension_closed_form(BondContinuum(mu, 2.0), stretch)
    E11 = (stretch ** 2 - 1) / 2
    assert abs(b - np.sqrt(1 - 2 * E11 / 3)) < 1e-12
    assert abs(P11 - stretch * 8 * mu * E11 / 3) < 1e-12


def test_bulk_factor_tends_to_one_and_calibrates_the_interior():
    """The interior lattice sum approaches its continuum value as the horizon spans more
    points, and the calibrated C1 gives the interior points of a body under a small
    homogeneous strain the energy density of the continuum law."""
    g = np.arange(41.0) / 40
    points = np.array([(x, y) for x in g for y in g])
    factors = []
    for m in (3.0, 6.0):
        body = pd.Body(points, (1 / 40) ** 2, m / 40)
        factors.append(bulk_factor(body, np.linalg.norm(points - 0.5, axis=1) < 0.05))
    assert abs(factors[1] - 1) < abs(factors[0] - 1) < 0.15
    assert abs(factors[1] - 1) < 0.1
    # the energy density of the middle point under a homogeneous strain eps = 1e-4 e1 e1
    law = BondContinuum(1.0, 1.0)
    middle = np.linalg.norm(points - 0.5, axis=1) < 1e-9
    material, _ = cpd_material(body, law, middle)
    strain = 1e-4
    stretch = np.abs(1 + strain * body.xi[:, 0] ** 2 / body.length ** 2)   # |F M| to O(eps^2)
    bond_energy = 0.5 * material.C1 * body.length * (stretch - 1) ** 2 \
        * body.beta * body.volumes[body.bond_j]
    density = 0.5 * bond_energy[middle[body.bond_i]].sum()
    continuum = 0.5 * (law.mu + 2 * law.mu) * strain ** 2      # (lam / 2 + mu) eps^2
    # isotropic part calibrated; the square lattice's anisotropy remains (a few %)
    assert abs(density / continuum - 1) < 0.05
