"""Hyperelastic laws as energies: the hand-written first Piola-Kirchhoff stress and its
tangent against hyper-dual derivatives of the energy, the plane-strain law as the 3-D
law with ``F33 = 1``, objectivity, the small-strain limit (Hooke), and bad inputs."""

from __future__ import annotations

import numpy as np
import pytest

import cnem
from cnem import hyperdual as hd
from cnem.elasticity.stabilization import IsochoricNeoHookean
from cnem.material import Hyperelastic, LinearElastic, NeoHookean, SaintVenantKirchhoff

RNG = np.random.default_rng(38)
MATERIALS = [NeoHookean(1.3, 2.1), NeoHookean(0.7, -0.3), SaintVenantKirchhoff(3.0, 0.3)]
#: With the energy of the deviatoric sub-cell stabilisation (no bulk modulus, no Hooke pair).
LAWS = MATERIALS + [IsochoricNeoHookean(1.1)]


def _gradients(d, q=12, spread=0.3):
    """Deformation gradients ``(q, d, d)`` around I with det F > 0."""
    F = np.eye(d) + spread * RNG.normal(size=(q, d, d))
    F[np.linalg.det(F) < 0, 0] *= -1.0
    return F


def _stretch_shear():
    """The homogeneous stretch plus shear of the patch tests, det F = 1.25."""
    return np.array([[[1.6, 0.3], [0.1, 0.8]]])


@pytest.mark.parametrize("mat", LAWS, ids=repr)
@pytest.mark.parametrize("d", [2, 3])
def test_stress_and_tangent_are_the_energy_derivatives(mat, d):
    F = _gradients(d)
    if d == 2:
        F = np.concatenate([F, _stretch_shear()])
    W, P, A = mat.evaluate(F)
    q = len(F)
    value, grad, hess = hd.derivatives(lambda y: mat.energy(y.reshape(y.shape[:-1] + (d, d))),
                                       F.reshape(q, -1))
    scale = max(1.0, np.abs(P).max())
    np.testing.assert_allclose(W, value, rtol=1e-13, atol=1e-13 * scale)
    np.testing.assert_allclose(P.reshape(q, -1), grad, rtol=1e-12, atol=1e-12 * scale)
    np.testing.assert_allclose(A.reshape(q, d * d, d * d), hess, rtol=1e-11,
                               atol=1e-11 * np.abs(hess).max())
    np.testing.assert_allclose(A, np.transpose(A, (0, 3, 4, 1, 2)), atol=1e-12 * np.abs(A).max())
    np.testing.assert_allclose(mat.energy(F), W, rtol=1e-13, atol=1e-14)
    W2, P2, none = mat.evaluate(F, tangent=False)
    assert none is None and np.array_equal(W2, W) and np.array_equal(P2, P)


@pytest.mark.parametrize("mat", LAWS, ids=repr)
def test_plane_strain_is_the_3d_law_with_f33_one(mat):
    F2 = np.concatenate([_gradients(2), _stretch_shear()])
    F3 = np.zeros((len(F2), 3, 3))
    F3[:, :2, :2], F3[:, 2, 2] = F2, 1.0
    W2, P2, A2 = mat.evaluate(F2)
    W3, P3, A3 = mat.evaluate(F3)
    np.testing.assert_allclose(W2, W3, rtol=1e-13, atol=1e-14)
    np.testing.assert_allclose(P2, P3[:, :2, :2], rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(A2, A3[:, :2, :2, :2, :2], rtol=1e-13, atol=1e-13)


@pytest.mark.parametrize("mat", LAWS, ids=repr)
@pytest.mark.parametrize("d", [2, 3])
def test_reference_state_and_objectivity(mat, d):
    W, P, _ = mat.evaluate(np.eye(d)[None])
    assert W[0] == 0.0 and np.abs(P).max() < 1e-15
    F = _gradients(d)
    angle = RNG.uniform(0, 2 * np.pi, len(F))
    c, s = np.cos(angle), np.sin(angle)
    R = np.zeros((len(F), d, d))
    R[:, 0, 0], R[:, 0, 1], R[:, 1, 0], R[:, 1, 1] = c, -s, s, c
    if d == 3:
        R[:, 2, 2] = 1.0
    W, P, _ = mat.evaluate(F)
    WR, PR, _ = mat.evaluate(R @ F)
    np.testing.assert_allclose(WR, W, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(PR, R @ P, rtol=1e-11, atol=1e-12)


@pytest.mark.parametrize("mat", MATERIALS, ids=repr)
@pytest.mark.parametrize("d", [2, 3])
def test_small_strain_limit_is_hookes_law(mat, d):
    """At F = I the tangent is Hooke's law of `lame` (both symmetric parts); a tiny
    strain gives the linear stress."""
    lam, mu = mat.lame(d)
    _, _, A = mat.evaluate(np.eye(d)[None])
    eye = np.eye(d)
    hooke = lam * np.einsum("ij,kl->ijkl", eye, eye) + mu * (np.einsum("ik,jl->ijkl", eye, eye)
                                                             + np.einsum("il,jk->ijkl", eye, eye))
    np.testing.assert_allclose(A[0], hooke, atol=1e-13 * (lam + mu))
    g = 1e-7 * RNG.normal(size=(d, d))
    _, P, _ = mat.evaluate((eye + g)[None])
    eps = 0.5 * (g + g.T)
    np.testing.assert_allclose(P[0], lam * np.trace(eps) * eye + 2 * mu * eps,
                               rtol=1e-5, atol=1e-12 * (lam + mu))
    E, nu = mat.linearized()
    np.testing.assert_allclose(mat.tangent(d), LinearElastic(E, nu).elasticity_matrix(
        d, "strain" if d == 2 else None), rtol=1e-13)
    assert isinstance(mat, Hyperelastic) and isinstance(mat, cnem.material.Material)


def test_neo_hookean_uniaxial_stretch_in_closed_form():
    """F = diag(a, b, b): P11 = mu (a - 1/a) + lam ln(a b^2) / a, written out."""
    mu, lam = 1.3, 2.1
    a, b = 1.7, 0.9
    _, P, _ = NeoHookean(mu, lam).evaluate(np.diag([a, b, b])[None])
    np.testing.assert_allclose(P[0, 0, 0], mu * (a - 1 / a) + lam * np.log(a * b * b) / a,
                               rtol=1e-14)
    np.testing.assert_allclose(P[0, 1, 1], mu * (b - 1 / b) + lam * np.log(a * b * b) / b,
                               rtol=1e-14)


def test_inverted_gradients_give_nan_not_a_warning():
    F = np.array([[[-1.0, 0.0], [0.0, 1.0]]])
    with np.errstate(all="raise"):
        W, P, A = NeoHookean(1.0, 1.0).evaluate(F)
    assert np.isnan(W).all() and np.isnan(P).all()


def test_collapsed_gradient_gives_infinite_energy_not_an_error():
    F = np.array([[[1.0, 0.0], [0.0, 0.0]]])              # J = 0: no inverse
    with np.errstate(all="raise"):
        W, P, A = NeoHookean(1.0, 1.0).evaluate(F)
    assert W[0] == np.inf and not np.isfinite(P).all() and not np.isfinite(A).all()


def test_bad_inputs_are_named():
    with pytest.raises(cnem.MaterialError, match="shear modulus mu > 0"):
        NeoHookean(0.0, 1.0)
    with pytest.raises(cnem.MaterialError, match="shear modulus mu > 0"):
        NeoHookean(np.nan, 1.0)
    with pytest.raises(cnem.MaterialError, match="bulk modulus"):
        NeoHookean(1.0, -1.0)
    with pytest.raises(cnem.MaterialError, match="expected numbers"):
        NeoHookean("soft", 1.0)
    with pytest.raises(cnem.MaterialError, match="Poisson ratios"):
        SaintVenantKirchhoff(1.0, 0.5)
    with pytest.raises(cnem.MaterialError, match=r"shape \(q, d, d\)"):
        NeoHookean(1.0, 1.0).evaluate(np.eye(2))
    with pytest.raises(cnem.MaterialError, match=r"shape \(q, d, d\)"):
        NeoHookean(1.0, 1.0).evaluate(np.ones((3, 4, 4)))
    with pytest.raises(cnem.OptionError, match="plane strain"):
        NeoHookean(1.0, 1.0).lame(2, "stress")
    with pytest.raises(cnem.OptionError, match="3-D body has no plane"):
        SaintVenantKirchhoff(1.0, 0.3).tangent(3, "strain")
