"""The fast peridynamic forces (numba PMB kernel, sparse LPS stiffness) against the
plain double loops of `tests.reference` (formulas of `cnem.pd.materials`)."""

from __future__ import annotations

import numpy as np
import pytest

import cnem.pd as pd
from reference import lps_force, pmb_force


def _irregular_2d(seed=0, shape=(11, 8)):
    """A perturbed lattice of 11 x 8 points (or ``shape``) with unequal volumes."""
    rng = np.random.default_rng(seed)
    h = 0.1
    g = np.stack(np.meshgrid(*[np.arange(k) * h for k in shape], indexing="ij"), -1)
    pts = g.reshape(-1, 2) + rng.uniform(-0.2 * h, 0.2 * h, (int(np.prod(shape)), 2))
    return pts, h * h * rng.uniform(0.8, 1.2, len(pts)), 3.015 * h


def _lattice_3d():
    h = 0.1
    g = np.stack(np.meshgrid(*[np.arange(5) * h] * 3, indexing="ij"), -1)
    return g.reshape(-1, 3), np.full(125, h ** 3), 2.015 * h


CASES = {"irregular 2-D": _irregular_2d, "3-D lattice": _lattice_3d}


def _moduli(E, nu, d, plane):
    """Bulk (d-dimensional) and shear modulus of the classical law."""
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    if d == 3:
        return lam + 2 * mu / 3, mu
    if plane == "stress":
        lam = 2 * lam * mu / (lam + 2 * mu)
    return lam + mu, mu


def _displacement(points, seed=1):
    """A linear field plus a random one, small against the spacing."""
    rng = np.random.default_rng(seed)
    d = points.shape[1]
    grad = rng.normal(0.0, 1e-3, (d, d))
    return points @ grad.T + rng.normal(0.0, 1e-3 * 0.1, points.shape)


def _factor(prob):
    b = prob.body
    table = {(int(i), int(j)): float(f) for i, j, f in zip(b.bond_i, b.bond_j, prob.factor)}
    return lambda i, j: table[(i, j)]


def _fast_force(prob, u):
    return prob._internal_force(u, np.inf, prob._force_state())[0]


@pytest.mark.parametrize("case", CASES)
@pytest.mark.parametrize("correction", [False, True], ids=["plain", "corrected"])
def test_pmb_force_matches_the_double_loop(case, correction):
    points, volumes, horizon = CASES[case]()
    d, E = points.shape[1], 2.0
    prob = pd.Problem(pd.Body(points, volumes, horizon), pd.BondBased(E),
                      surface_correction=correction)
    u = _displacement(points)
    # the micromodulus of the BondBased docstring
    c = 12 * E / (np.pi * horizon ** 4) if d == 3 else 9 * E / (np.pi * horizon ** 3)
    expected = pmb_force(points, volumes, horizon, u, c, _factor(prob))
    found = _fast_force(prob, u)
    assert np.abs(found - expected).max() <= 1e-12 * np.abs(expected).max()


@pytest.mark.parametrize("case", CASES)
@pytest.mark.parametrize("plane", ["stress", "strain"])
@pytest.mark.parametrize("correction", [False, True], ids=["plain", "corrected"])
def test_lps_force_matches_the_double_loop(case, plane, correction):
    points, volumes, horizon = CASES[case]()
    d, E, nu = points.shape[1], 2.0, 0.3
    prob = pd.Problem(pd.Body(points, volumes, horizon), pd.StateBased(E, nu), plane=plane,
                      surface_correction=correction)
    u = _displacement(points)
    bulk, shear = _moduli(E, nu, d, plane)
    expected = lps_force(points, volumes, horizon, u, bulk, shear, _factor(prob))
    found = _fast_force(prob, u)
    assert np.abs(found - expected).max() <= 1e-12 * np.abs(expected).max()


def _kernel_step(body, u, stiffness, alive, limit):
    """`cnem.pd._pmb_kernels.pmb_forces` on the arrays of ``body``: (forces, broken count)."""
    from cnem.pd._pmb_kernels import pmb_forces
    out = np.empty_like(u)
    broken = pmb_forces(u, body.points, body.image, body.length, body.family.offsets, body.bond_j,
                        stiffness, body.volumes, alive, limit, out)
    return out, int(broken)


def _bond_loop(body, u, stiffness, alive):
    """Plain loop over the bonds: stretches ``|y| / L - 1`` and the PMB forces of the bonds
    flagged in ``alive``."""
    f = np.zeros_like(u)
    stretch = np.empty(len(body.bond_j))
    for b, (i, j) in enumerate(zip(body.bond_i, body.bond_j)):
        y = body.xi[b] + u[j] - u[i]
        stretch[b] = np.linalg.norm(y) / body.length[b] - 1.0
        if alive[b]:
            f[i] += stiffness[b] * stretch[b] * y / np.linalg.norm(y) * body.volumes[j]
    return f, stretch


def _median_gap_limit(stretch):
    """A stretch limit in the widest gap between the stretches near their median."""
    ranked = np.sort(stretch)
    mid = len(ranked) // 2 - 20 + int(np.argmax(np.diff(ranked[len(ranked) // 2 - 20:][:41])))
    limit = 0.5 * float(ranked[mid] + ranked[mid + 1])
    assert np.abs(stretch - limit).min() > 1e-9 * np.abs(stretch).max()   # no tie at round-off
    return limit


@pytest.mark.parametrize("case", CASES)
def test_pmb_kernel_breaks_the_bonds_beyond_the_limit(case):
    points, volumes, horizon = CASES[case]()
    body = pd.Body(points, volumes, horizon)
    rng = np.random.default_rng(2)
    u = rng.normal(0.0, 0.02 * horizon, points.shape)
    stiffness = rng.uniform(0.5, 1.5, len(body.bond_j))
    dead = rng.uniform(size=len(body.bond_j)) < 0.1            # broken before this step
    _, stretch = _bond_loop(body, u, stiffness, ~dead)
    limit = _median_gap_limit(stretch)
    survive = ~dead & (stretch <= limit)
    expected, _ = _bond_loop(body, u, stiffness, survive)
    alive = (~dead).astype(np.uint8)
    found, broken = _kernel_step(body, u, stiffness, alive, limit)
    assert np.array_equal(alive == 1, survive)
    assert broken == int((~dead & (stretch > limit)).sum())
    assert np.abs(found - expected).max() <= 1e-12 * np.abs(expected).max()


@pytest.mark.parametrize("limit, survivors", [(np.inf, "all"), (-1.5, "none")])
def test_pmb_kernel_at_the_extreme_limits(limit, survivors):
    """No bond breaks at an infinite limit; every live one below -1 (a stretch is >= -1)."""
    points, volumes, horizon = _irregular_2d()
    body = pd.Body(points, volumes, horizon)
    u = np.random.default_rng(3).normal(0.0, 0.02 * horizon, points.shape)
    alive = np.ones(len(body.bond_j), dtype=np.uint8)
    alive[::7] = 0
    live = int(alive.sum())
    found, broken = _kernel_step(body, u, np.ones(len(alive)), alive, limit)
    if survivors == "all":
        assert broken == 0 and int(alive.sum()) == live
    else:
        assert broken == live and not alive.any() and not found.any()


def test_pmb_kernel_takes_the_minimum_image_in_a_periodic_cell():
    """Bonds across the sides of a periodic cell: the kernel's forces and breaks against a
    NumPy loop over the bonds with the minimum image taken independently, on more points
    than one block of the kernel."""
    from cnem.pd._pmb_kernels import BLOCK_BONDS
    rng = np.random.default_rng(4)
    period, n = np.array([0.8, 0.5]), 3 * BLOCK_BONDS // 20 + 17     # ~28 bonds a point
    points = rng.uniform(0.0, 1.0, (n, 2)) * period
    horizon = 3.0 * np.sqrt(period.prod() / n)
    body = pd.Body(points, period.prod() / n, horizon, period=period)
    i, j = body.bond_i, body.bond_j
    xi = points[j] - points[i]
    assert (np.abs(xi) > 0.5 * period).any()                  # some bonds wrap around
    assert len(j) > 2 * BLOCK_BONDS                           # several blocks
    xi -= period * np.round(xi / period)
    u = rng.normal(0.0, 0.02 * horizon, points.shape)
    stiffness = rng.uniform(0.5, 1.5, len(j))
    y = xi + u[j] - u[i]
    ly = np.linalg.norm(y, axis=1)
    stretch = ly / np.linalg.norm(xi, axis=1) - 1.0
    limit = _median_gap_limit(stretch)
    keep = stretch <= limit
    g = np.where(keep, stiffness * stretch / ly * body.volumes[j], 0.0)
    expected = np.stack([np.bincount(i, weights=g * y[:, c], minlength=n) for c in range(2)], 1)
    alive = np.ones(len(j), dtype=np.uint8)
    found, broken = _kernel_step(body, u, stiffness, alive, limit)
    assert np.array_equal(alive == 1, keep) and broken == int((~keep).sum())
    assert np.abs(found - expected).max() <= 1e-12 * np.abs(expected).max()


@pytest.mark.parametrize("shape", [(11, 8), (37, 29)], ids=["one block", "blocks"])
def test_pmb_kernel_on_some_points_gives_their_bits(shape):
    """`pmb_forces_rows` on a sorted subset of the points (runs and isolated points): the
    same forces, to the bit, and the same breaks at those points as `pmb_forces` on all,
    and no other bond touched."""
    from cnem.pd._pmb_kernels import BLOCK_BONDS, pmb_forces_rows
    points, volumes, horizon = _irregular_2d(shape=shape)
    body = pd.Body(points, volumes, horizon)
    assert (len(body.bond_j) > 2 * BLOCK_BONDS) == (shape != (11, 8))
    rng = np.random.default_rng(5)
    u = rng.normal(0.0, 0.02 * horizon, points.shape)
    stiffness = rng.uniform(0.5, 1.5, len(body.bond_j))
    _, stretch = _bond_loop(body, u, stiffness, np.ones(len(body.bond_j), dtype=bool))
    limit = _median_gap_limit(stretch)
    every = np.ones(len(body.bond_j), dtype=np.uint8)
    full, broken_all = _kernel_step(body, u, stiffness, every, limit)
    rows = np.flatnonzero(rng.uniform(size=len(points)) < 0.6)
    mine = np.isin(body.bond_i, rows)
    alive = np.ones(len(body.bond_j), dtype=np.uint8)
    out = np.full_like(u, np.nan)
    broken = pmb_forces_rows(rows, u, body.points, body.image, body.length, body.family.offsets,
                             body.bond_j, stiffness, body.volumes, alive, limit, out)
    assert np.array_equal(out[rows], full[rows])
    assert np.isnan(np.delete(out, rows, axis=0)).all()
    assert np.array_equal(alive[mine], every[mine]) and alive[~mine].all()
    assert broken == int((every[mine] == 0).sum()) and 0 < broken < broken_all
