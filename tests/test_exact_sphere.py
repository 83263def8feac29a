"""`cnem.exact.ThickSphere`: Lamé's hollow sphere, checked by its own equations."""

import numpy as np
import pytest

import cnem


@pytest.fixture
def sphere():
    return cnem.exact.ThickSphere(0.5, 1.25, 3.0, 0.3, pressure=2.0, center=(1.0, -2.0, 0.5))


def _points(sphere, k, seed=0):
    rng = np.random.default_rng(seed)
    n = rng.normal(size=(k, 3))
    n /= np.linalg.norm(n, axis=1)[:, None]
    r = rng.uniform(sphere.inner, sphere.outer, k)
    return sphere.center + r[:, None] * n, n


def test_boundary_tractions(sphere):
    for radius, want in ((sphere.inner, -2.0), (sphere.outer, 0.0)):
        _, n = _points(sphere, 20)
        s = sphere.stress(sphere.center + radius * n)
        sig = np.array([[s[:, 0], s[:, 5], s[:, 4]], [s[:, 5], s[:, 1], s[:, 3]],
                        [s[:, 4], s[:, 3], s[:, 2]]]).transpose(2, 0, 1)
        traction = np.einsum("kij,kj->ki", sig, n)
        np.testing.assert_allclose(traction, want * n, atol=1e-12)


def test_hooke_and_equilibrium(sphere):
    """The stress is Hooke's law of the displacement's strain (finite differences), and its
    divergence vanishes."""
    x, _ = _points(sphere, 15, seed=1)
    eps = 1e-5
    grad = np.stack([(sphere.displacement(x + eps * e) - sphere.displacement(x - eps * e))
                     / (2 * eps) for e in np.eye(3)], axis=2)           # [k, i, j] = du_i/dx_j
    strain = np.column_stack([grad[:, 0, 0], grad[:, 1, 1], grad[:, 2, 2],
                              grad[:, 1, 2] + grad[:, 2, 1], grad[:, 0, 2] + grad[:, 2, 0],
                              grad[:, 0, 1] + grad[:, 1, 0]])
    C = cnem.material.LinearElastic(3.0, 0.3).elasticity_matrix(3)
    np.testing.assert_allclose(strain @ C.T, sphere.stress(x), atol=1e-8)
    voigt = ((0, 5, 4), (5, 1, 3), (4, 3, 2))
    div = np.zeros((len(x), 3))
    for j, e in enumerate(np.eye(3)):
        ds = (sphere.stress(x + eps * e) - sphere.stress(x - eps * e)) / (2 * eps)
        for i in range(3):
            div[:, i] += ds[:, voigt[i][j]]
    np.testing.assert_allclose(div, 0.0, atol=1e-7)


def test_bad_radii_are_refused():
    with pytest.raises(cnem.InputError, match="inner"):
        cnem.exact.ThickSphere(1.0, 0.5, 1.0, 0.3)
