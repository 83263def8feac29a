"""The deviatoric sub-cell stabilisation (`cnem.elasticity.stabilization`): its linear
law is ``2 mu dev(e3) : dev(e3)`` of the body's 3-D strain in every idealisation; the
stabilised free stiffness has exactly the rigid motions as its nullspace on irregular
2-D and 3-D clouds, also as ``nu -> 1/2`` (the deviator alone leaves no spurious
zero-energy mode); the isochoric neo-Hookean energy ignores volume changes and
linearises to the deviatoric law (its stress and tangent against hyper-dual derivatives
and its plane strain: `tests/test_materials_hyper.py`);
the finite-strain tangent at rest is the linear stabilised stiffness in 3-D."""

from __future__ import annotations

import numpy as np
import pytest

import cases
import cases3d
import cnem
from cnem.elasticity.stabilization import IsochoricNeoHookean, deviatoric_lame, stabilization_lame
from cnem.material import SaintVenantKirchhoff

RNG = np.random.default_rng(61)


def _deviatoric_energy(e3, mu):
    """``2 mu dev(e3) : dev(e3)`` of 3-D strains ``(q, 3, 3)``."""
    dev = e3 - np.trace(e3, axis1=1, axis2=2)[:, None, None] / 3.0 * np.eye(3)
    return 2.0 * mu * np.einsum("qij,qij->q", dev, dev)


@pytest.mark.parametrize("plane", ["strain", "stress", None])
@pytest.mark.parametrize("nu", [0.0, 0.3, 0.4999])
def test_the_linear_law_is_the_deviatoric_energy_of_the_3d_strain(plane, nu):
    mu, q = 1.7, 20
    d = 3 if plane is None else 2
    e = RNG.normal(size=(q, d, d))
    e = 0.5 * (e + np.swapaxes(e, 1, 2))
    trace = np.trace(e, axis1=1, axis2=2)
    e3 = np.zeros((q, 3, 3))
    e3[:, :d, :d] = e
    if plane == "stress":                      # sigma_zz = 0 of the body's own law
        e3[:, 2, 2] = -nu / (1.0 - nu) * trace
    lam_s = deviatoric_lame(mu, nu, plane)
    law = 2.0 * mu * np.einsum("qij,qij->q", e, e) + lam_s * trace ** 2
    np.testing.assert_allclose(law, _deviatoric_energy(e3, mu), rtol=1e-12)


@pytest.mark.parametrize("nu", [0.0, 0.3, 0.4999])
def test_plane_stress_keeps_the_shear_only_law_and_the_rest_the_deviatoric_one(nu):
    mu = np.array([1.7, 0.4])
    np.testing.assert_array_equal(stabilization_lame(mu, nu, "stress"), 0.0)
    for plane in ("strain", None):
        np.testing.assert_allclose(stabilization_lame(mu, nu, plane), -2.0 * mu / 3.0,
                                   rtol=1e-15)


def _clouds():
    """Small irregular 2-D and 3-D models (a few seeds), built on first use."""
    square = cnem.geometry.rectangle(1.0, 1.0)
    box = cnem.geometry.box((0.0, 0.0, 0.0), (1.0, 0.8, 0.6))
    return {
        "square-seed1": lambda: cnem.discretize(cnem.nodes.irregular(square, 0.09, seed=1)),
        "square-seed2": lambda: cnem.discretize(cnem.nodes.irregular(square, 0.09, seed=2)),
        "holed": lambda: cases.model("plate_hole_irregular")[2],
        "lshape": lambda: cases.model("lshape_irregular")[2],
        "box-seed1": lambda: cnem.discretize(cnem.nodes.irregular(box, 0.22, seed=1)),
        "box-seed2": lambda: cnem.discretize(cnem.nodes.irregular(box, 0.22, seed=2)),
        "l-block": lambda: cnem.discretize(cnem.nodes.irregular(
            cnem.Domain3D(cases3d.l_block(4)[:2]), 0.3, seed=0)),
        "hollow-sphere": lambda: cnem.discretize(cnem.nodes.irregular(
            cnem.geometry.hollow_sphere(1.0, 2.0, subdivisions=1), 0.55, seed=1)),
    }


CLOUDS = _clouds()


@pytest.mark.parametrize("name", list(CLOUDS))
def test_free_stiffness_has_only_the_rigid_motions_as_nullspace(name):
    """Eigenvalues of the whole stabilised K below 1e-8 of the largest: exactly 3 (2-D)
    or 6 (3-D), in plane strain and stress, at nu = 0.3 and 0.4999, and K annihilates
    the rigid motions."""
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = CLOUDS[name]()
    dim = model.nodes.shape[1]
    rigid = 3 * (dim - 1)
    modes = cnem.solvers.linsolve.rigid_modes(model.nodes)
    for nu in (0.3, 0.4999):
        for plane in (("strain", "stress") if dim == 2 else (None,)):
            K = cnem.Elasticity(model, (1.0, nu), plane=plane).stiffness().toarray()
            eig = np.linalg.eigvalsh(K)
            zero = np.abs(eig) < 1e-8 * eig[-1]
            assert zero.sum() == rigid, (nu, plane, eig[:rigid + 2] / eig[-1])
            np.testing.assert_allclose(K @ modes, 0.0, atol=1e-10 * eig[-1])


def _gradients(d, q=12, spread=0.3):
    F = np.eye(d) + spread * RNG.normal(size=(q, d, d))
    F[np.linalg.det(F) < 0, 0] *= -1.0
    return F


def test_isochoric_energy_ignores_volume_and_linearises_to_the_deviatoric_law():
    """W(s Q F) = W(F) for any scale s > 0 and rotation Q (3-D); at F = I the tangent
    is the deviatoric law, and the second variation is 2 mu dev(e) : dev(e)."""
    mu = 1.9
    law = IsochoricNeoHookean(mu)
    F = _gradients(3)
    Q, _ = np.linalg.qr(RNG.normal(size=(3, 3)))
    Q *= np.sign(np.linalg.det(Q))
    scaled = 1.7 * np.einsum("ij,qjk->qik", Q, F)
    np.testing.assert_allclose(law.evaluate(scaled)[0], law.evaluate(F)[0], rtol=1e-12)
    _, P, A = law.evaluate(np.eye(3)[None] * 1.3)
    assert np.abs(P).max() < 1e-14
    _, _, A = law.evaluate(np.eye(3)[None])
    grad = RNG.normal(size=(10, 3, 3))
    e = 0.5 * (grad + np.swapaxes(grad, 1, 2))
    np.testing.assert_allclose(np.einsum("qij,ijkl,qkl->q", grad, A[0], grad),
                               _deviatoric_energy(e, mu), rtol=1e-12)
    lam, shear = law.lame(3)
    assert (lam, shear) == (-2.0 * mu / 3.0, mu)
    np.testing.assert_allclose(law.tangent(3)[:3, :3], mu * (2 * np.eye(3) - 2 / 3))


def test_isochoric_law_refuses_bad_moduli_and_has_no_young_modulus():
    for bad in (0.0, -1.0, np.nan, "a"):
        with pytest.raises(cnem.MaterialError, match="IsochoricNeoHookean"):
            IsochoricNeoHookean(bad)
    with pytest.raises(cnem.MaterialError, match="bulk"):
        IsochoricNeoHookean(1.0).linearized()


def test_finite_strain_tangent_at_rest_is_the_linear_stabilised_stiffness_3d():
    model = CLOUDS["box-seed1"]()
    mat = SaintVenantKirchhoff(3.0, 0.45)
    prob = cnem.Hyperelasticity(model, mat, stabilization=0.8)
    f, K = prob.system.evaluate(np.zeros(model.nodes.size))
    linear = cnem.Elasticity(model, mat.linearized(), stabilization=0.8).stiffness()
    assert np.abs(f).max() == 0.0
    assert abs(K - linear).max() <= 1e-10 * abs(linear).max()
