"""Quasi-static PD fracture: the critical stretch from G_c, and load steps with breaking."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree

import cnem.pd as pd
from cnem.errors import InputError, MaterialError, UnsupportedError
from cnem.demos.damage.ridge import ridge_path
from cnem.pd import critical_stretch as cs
from cnem.pd.quasistatic import load_drop, quasistatic


def periodic_lattice(m):
    """A doubly periodic square lattice (h = 1) of 6m x 6m points, horizon m h: every
    point has a full horizon, and the line y = 3m crosses bonds of the bulk only."""
    n = 6 * m
    g = np.arange(n) + 0.5
    pts = np.array([(x, y) for x in g for y in g])
    return pd.Body(pts, 1.0, m + 0.015, period=[float(n), float(n)]), float(n)


def crossing(body, line):
    """Bonds from one side of the line y = line to the other (within the horizon)."""
    y = body.points[body.bond_i, 1]
    return (y - line) * (y + body.xi[:, 1] - line) < 0


@pytest.fixture(scope="module")
def lattice():
    return periodic_lattice(6)


@pytest.mark.parametrize("plane", ["stress", "strain"])
def test_bond_based_critical_stretch_stores_G_c_in_the_crossing_bonds(lattice, plane):
    """At the critical stretch of G_c = 1, the PMB energy of the bonds crossing a line,
    summed bond by bond, is G_c per unit length (the surface correction makes the lattice's
    bulk stiffness the continuum one; without it the lattice sums are ~10 % low)."""
    body, length = lattice
    prob = pd.Problem(body, pd.BondBased(1.0), plane=plane)
    s_c = cs.bond_based(1.0, 1.0, body.horizon, plane)
    assert pd.BondBased(1.0, fracture_energy=1.0).stretch_limit(2, plane, body.horizon) == s_c
    # each ordered bond carries half of its pair's energy c s^2 L V_i V_j / 2
    per_bond = 0.25 * prob.factor * prob.bond_stiffness * s_c ** 2 * body.length * \
        prob.weight * body.volumes[body.bond_i]
    energy = per_bond[crossing(body, length / 2)].sum() / length
    assert energy == pytest.approx(1.0, rel=0.04)


@pytest.mark.parametrize("plane", ["stress", "strain"])
def test_state_based_critical_stretch_stores_G_c_at_the_crossing_bonds(lattice, plane):
    """The same for the linear peridynamic solid: with only the crossing bonds at the
    critical stretch, sum_i V_i W_i (the state-based energy, written out here from the
    definition, dilatation included) is G_c per unit length (uncorrected: the model's own
    moment m normalises the lattice sums)."""
    body, length = lattice
    nu = 0.3
    prob = pd.Problem(body, pd.StateBased(1.0, nu), plane=plane, surface_correction=False)
    s_c = pd.StateBased(1.0, nu, fracture_energy=1.0).stretch_limit(2, plane, body.horizon)
    e = np.where(crossing(body, length / 2), s_c * body.length, 0.0)
    w = prob.weight
    theta = 2.0 * np.bincount(body.bond_i, weights=w * body.length * e, minlength=len(body)) / prob.m
    e_dev = e - theta[body.bond_i] * body.length / 2.0
    W = 0.5 * prob.bulk * theta ** 2 + np.bincount(
        body.bond_i, weights=0.5 * prob.alpha[body.bond_i] * w * e_dev ** 2, minlength=len(body))
    assert (body.volumes * W).sum() / length == pytest.approx(1.0, rel=0.04)


def test_critical_stretch_formulas():
    # Ha & Bobaru's plane-stress PMB value; Irwin's G = K^2 / E'
    assert cs.bond_based(2.0, 3.0, 0.5, "stress") == pytest.approx(np.sqrt(8 * np.pi / 13.5))
    assert cs.fracture_energy(2.0, 4.0, 0.3, "strain") == pytest.approx(0.91)
    assert cs.fracture_energy(2.0, 4.0, 0.3, "stress") == pytest.approx(1.0)
    # s_c ~ 1 / sqrt(delta) and ~ sqrt(G_c)
    assert cs.state_based(4.0, 1.0, 0.3, 1.0, "strain") == pytest.approx(
        4 * cs.state_based(1.0, 1.0, 0.3, 4.0, "strain"), rel=1e-12)
    with pytest.raises(UnsupportedError):
        cs.state_based(1.0, 1.0, 0.3, 1.0, "strain", dim=3)
    with pytest.raises(MaterialError):
        pd.StateBased(1.0, 0.3, fracture_energy=-1.0)


def strip_problem(material, *, notch=True, h=0.05, width=1.0, height=0.5):
    """A strip on a lattice symmetric about y = height / 2 (rows between), pulled in y
    over layers one horizon deep, with an edge notch along the symmetry line."""
    xs = np.arange(0.0, width + 1e-9, h)
    ys = np.arange(h / 2, height, h)
    pts = np.array([(x, y) for x in xs for y in ys])
    mid = height / 2
    delta = 3.015 * h
    cracks = [[[-h, mid], [0.2 * width, mid]]] if notch else []
    prob = pd.Problem(pd.Body(pts, h * h, delta, cracks=cracks), material, plane="strain")
    prob.add_dirichlet(lambda p: p[:, 1] < ys[0] + delta, 1)
    prob.add_dirichlet(lambda p: p[:, 1] > ys[-1] - delta, 1, 0.01)
    prob.add_dirichlet(lambda p: (p[:, 1] < ys[0] + 1e-9) & (np.abs(p[:, 0] - width / 2) < 1e-9),
                       0)
    return prob, mid


def first_breaking_factor(prob):
    """The load factor at which the most stretched bond of the linear solution at factor 1
    reaches the critical stretch (exact for a linear model)."""
    b = prob.body
    u = prob.solve().u
    stretch = np.hypot(*(b.xi + u[b.bond_j] - u[b.bond_i]).T) / b.length - 1.0
    return prob.material.stretch_limit(2, prob.plane, b.horizon) / stretch.max()


def test_bonds_break_once_the_load_passes_the_critical_stretch():
    """The state-based solid is linear: no bond breaks below the factor at which the
    elastic solution's largest stretch is the critical one, some break just above."""
    prob, _ = strip_problem(pd.StateBased(1.0, 0.3, critical_stretch=0.02))
    f = first_breaking_factor(prob)
    run = quasistatic(prob, [0.5 * f, 0.99 * f, 1.01 * f], max_rounds=1)
    assert [s.broken for s in run.steps[:2]] == [0, 0] and run.steps[2].broken > 0
    # before breaking the reaction is proportional to the load
    r = run.array("reaction")[:, 1]
    assert r[1] / r[0] == pytest.approx(0.99 / 0.5, rel=1e-4)
    assert not run.steps[2].complete or run.steps[2].rounds <= 1


def test_a_notched_strip_breaks_straight_across_on_its_symmetry_line():
    """Mode I on a lattice symmetric about the notch line: the crack runs along it to the
    far edge, and the strip then carries no load."""
    prob, mid = strip_problem(pd.BondBased(1.0, critical_stretch=0.02))
    f = first_breaking_factor(prob)
    run = quasistatic(prob, f * np.arange(1.0, 3.0, 0.1), stop=load_drop(0.05))
    assert run.stopped == "load_drop"
    assert run.steps[0].broken > 0
    # the crack runs between two rows: their points lose ~40 % of their bonds
    path = ridge_path(prob.body.points, run.damage, (0.2, mid), threshold=0.3)
    inner = path[(path[:, 0] > 0.2 + 0.15) & (path[:, 0] < 1.0 - 0.15)]
    # the damage is symmetric about the notch line (the bonds through the notch's tip,
    # which pass it within round-off, are all kept: remove_crossing's tolerance), so the
    # ridge runs in the band's middle, up to its tie-breaking between the two rows
    p = prob.body.points
    dist, mirror = cKDTree(p).query(np.column_stack([p[:, 0], 2 * mid - p[:, 1]]))
    assert dist.max() < 1e-12 and np.abs(run.damage - run.damage[mirror]).max() < 1e-12
    assert len(inner) >= 2 and np.abs(inner[:, 1] - mid).max() < 0.01 * 0.05
    assert np.abs(path[:, 1] - mid).max() <= 0.5 * 0.05 + 1e-9   # near its ends: within h / 2
    assert path[-1, 0] > 1.0 - 0.1
    reaction = run.array("reaction")[:, 1]
    assert reaction[-1] < 0.05 * reaction.max()


def test_quasistatic_refuses_bad_factors():
    prob, _ = strip_problem(pd.BondBased(1.0, critical_stretch=0.02), h=0.1)
    for bad in ([], [0.5, 0.4], [-1.0, 1.0], [np.nan]):
        with pytest.raises(InputError):
            quasistatic(prob, bad)
    with pytest.raises(InputError):
        load_drop(1.5)
