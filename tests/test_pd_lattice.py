"""Lattices of PD bodies (`cnem.pd.lattice`), the small-strain moduli of CPD materials
(`cnem.pd.cpd_moduli`) and the nonlocal deformation gradient (`cnem.pd.strain`)."""

import numpy as np
import pytest
from scipy import integrate

import cnem.pd as pd
from cnem.pd.cpd_moduli import constant_for_ratio, lame_constants, moduli_per_constant
from cnem.pd.lattice import lattice, lattice_measure


@pytest.mark.parametrize("dim", [2, 3])
def test_lattice_is_the_grid_in_c_order(dim):
    counts = (4, 3, 5)[:dim]
    x = lattice(counts, 0.5)
    grid = x.reshape(*counts, dim)
    for axis in range(dim):
        steps = np.diff(grid, axis=axis)
        expected = np.zeros(dim)
        expected[axis] = 0.5
        np.testing.assert_allclose(steps.reshape(-1, dim),
                                   np.tile(expected, (steps.size // dim, 1)))
    np.testing.assert_array_equal(x[0], np.zeros(dim))


@pytest.mark.parametrize("dim", [2, 3])
def test_lattice_measure_of_an_affine_map(dim):
    rng = np.random.default_rng(dim)
    counts = (4, 3, 5)[:dim]
    x = lattice(counts, 0.5)
    F = np.eye(dim) + 0.3 * rng.standard_normal((dim, dim))
    cells = lattice_measure(x @ F.T + 1.0, counts)
    assert cells.shape == tuple(c - 1 for c in counts)
    np.testing.assert_allclose(cells, np.linalg.det(F) * 0.5 ** dim, rtol=1e-12)


def test_lattice_measure_of_a_folded_cell_is_negative():
    x = lattice((2, 2), 1.0)
    mirrored = x * [-1.0, 1.0]
    assert lattice_measure(mirrored, (2, 2))[0, 0] == pytest.approx(-1.0)


@pytest.mark.parametrize("dim", [2, 3])
def test_one_neighbour_limit_is_the_bond_energy_integral(dim):
    """One-neighbour CPD is a Cauchy solid (lambda = mu) whose shear modulus follows from
    the energy density 1/4 C1 int_H |xi| (xi.eps.xi / |xi|^2)^2 dV of a pure shear
    eps_12 = g: 2 mu g^2 (a quadrature over the horizon)."""
    horizon, thickness, g = 0.3, 0.7, 1e-3
    if dim == 2:
        density = integrate.dblquad(lambda t, r: r * r * (g * np.sin(2 * t)) ** 2,
                                    0, horizon, 0, 2 * np.pi)[0] * thickness
    else:
        density = integrate.tplquad(
            lambda p, t, r: r ** 3 * np.sin(t) * (g * np.sin(t) ** 2 * np.sin(2 * p)) ** 2,
            0, horizon, 0, np.pi, 0, 2 * np.pi)[0]
    lam, mu = moduli_per_constant(dim, horizon, thickness)[0]
    assert lam == mu
    assert 2 * mu * g * g == pytest.approx(0.25 * density, rel=1e-8)


@pytest.mark.parametrize("dim, order", [(2, 2), (3, 2), (3, 3)])
def test_constant_for_ratio_adds_that_much_lambda(dim, order):
    horizon, C1, ratio = 0.2, 3.0, 7.0
    C = constant_for_ratio(order, ratio, dim, horizon, C1)
    lam1, mu1 = lame_constants(pd.CPD(C1), dim, horizon)
    lam, mu = lame_constants(pd.CPD(C1, *((C, 0.0) if order == 2 else (0.0, C))), dim, horizon)
    assert lam - lam1 == pytest.approx(ratio * mu1, rel=1e-12)
    assert mu >= mu1


@pytest.mark.parametrize("dim", [2, 3])
def test_deformation_gradient_of_an_affine_map_is_exact_everywhere(dim):
    """Inside and at the boundary (truncated families), a scattered cloud included."""
    from cnem.pd.strain import deformation_gradient
    rng = np.random.default_rng(dim)
    counts = (7, 6, 5)[:dim]
    x = lattice(counts, 0.25) + rng.uniform(-0.05, 0.05, (np.prod(counts), dim))
    body = pd.Body(x, 0.25 ** dim, 0.6)
    F = np.eye(dim) + 0.2 * rng.standard_normal((dim, dim))
    u = x @ (F - np.eye(dim)).T + rng.standard_normal(dim)          # plus a translation
    expected = np.broadcast_to(F, (len(x), dim, dim))
    np.testing.assert_allclose(deformation_gradient(body, u), expected, atol=1e-12)
