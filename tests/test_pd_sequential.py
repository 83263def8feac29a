"""Quasi-static PD fracture by linear solves, event by event (`cnem.pd.sequential`),
against the elastic solution and the ADR load steps of `cnem.pd.quasistatic`."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree

import cnem.pd as pd
from cnem.errors import InputError, SolveError
from cnem.demos.damage.ridge import ridge_path
from cnem.pd.quasistatic import load_drop, quasistatic
from cnem.pd.sequential import sequential

from test_pd_quasistatic import strip_problem


def linear_first_factor(prob):
    """``s_c / max n.(u_j - u_i) / L`` of the elastic solution at factor 1."""
    b = prob.body
    u = prob.solve().u
    s = (prob.unit * (u[b.bond_j] - u[b.bond_i])).sum(axis=1) / b.length
    return prob.material.stretch_limit(2, prob.plane, b.horizon) / s.max()


@pytest.mark.parametrize("material", [pd.BondBased(1.0, critical_stretch=0.02),
                                      pd.StateBased(1.0, 0.3, critical_stretch=0.02)],
                         ids=["bond", "state"])
def test_the_first_break_is_at_the_elastic_critical_factor(material):
    prob, _ = strip_problem(material)
    f = linear_first_factor(prob)
    run = sequential(prob, 0.9 * f)
    assert run.steps == [] and (prob.alive == 1).all() and run.stopped == "end"
    prob.alive[:] = 1
    run = sequential(prob, 1.5 * f, stop=lambda steps: True)        # the first event only
    assert run.steps[0].factor == pytest.approx(f, rel=1e-6)
    assert run.steps[0].broken >= 2                              # a bond and its reverse
    assert run.stopped == "<lambda>"


def test_each_step_is_an_equilibrium_that_breaks_nothing_more():
    """After every step the body at that factor is in equilibrium (the residual of the live
    stiffness on the free dofs, against the sums of the bond forces' sizes ``|K| |u|``; the
    reactions vanish as the strip comes apart) with every live stretch at most critical."""
    prob, _ = strip_problem(pd.BondBased(1.0, critical_stretch=0.02))
    b, limit = prob.body, 0.02
    fixed, values = prob.prescribed()
    free = np.setdiff1d(np.arange(2 * len(b)), fixed)
    seen = []

    def check(step, u):
        if not step.complete:                       # cut by max_solves: its breaks unsolved
            return
        K = prob.stiffness()
        f, size = K @ u.reshape(-1), abs(K) @ np.abs(u.reshape(-1))
        seen.append(np.abs(f[free]).max() / size.max())
        np.testing.assert_allclose(u.reshape(-1)[fixed], step.factor * values, rtol=1e-15)
        s = (prob.unit * (u[b.bond_j] - u[b.bond_i])).sum(axis=1) / b.length
        assert s[prob.alive == 1].max() <= limit * (1 + 1e-6)

    run = sequential(prob, 1.0, tol=1e-10, max_solves=40, callback=check)
    assert len(seen) >= 3 and max(seen) < 1e-8
    assert np.all(np.diff(run.array("factor")) > 0)


def test_a_notched_strip_breaks_straight_across_as_with_ADR():
    """The strip of the ADR test: the crack runs along the symmetry line to the far edge,
    most bonds across it break (the run stops at 5 % of the peak load), and the reaction peaks at the factor the ADR load steps
    find (within their step). (The ADR steps of 0.1 of the first factor overshoot and
    break about a fifth more bonds off the line.)"""
    material = pd.BondBased(1.0, critical_stretch=0.02)
    prob, mid = strip_problem(material)
    f = linear_first_factor(prob)
    run = sequential(prob, 6.0 * f, stop=load_drop(0.05))
    assert run.stopped == "load_drop"
    path = ridge_path(prob.body.points, run.damage, (0.2, mid), threshold=0.3)
    inner = path[(path[:, 0] > 0.2 + 0.15) & (path[:, 0] < 1.0 - 0.15)]
    # the damage is symmetric about the notch line (the bonds through the notch's tip are
    # all kept), so the ridge runs in the band's middle, up to its tie-breaking between
    # the two rows (as in the ADR test)
    p = prob.body.points
    dist, mirror = cKDTree(p).query(np.column_stack([p[:, 0], 2 * mid - p[:, 1]]))
    assert dist.max() < 1e-12 and np.abs(run.damage - run.damage[mirror]).max() < 1e-12
    assert len(inner) >= 2 and np.abs(inner[:, 1] - mid).max() < 0.01 * 0.05
    assert path[-1, 0] > 1.0 - 0.1
    adr_prob, _ = strip_problem(material)
    step = 0.1
    adr = quasistatic(adr_prob, f * np.arange(1.0, 3.0, step), stop=load_drop(0.05))
    peak_adr = adr.steps[int(np.argmax(np.linalg.norm(adr.array("reaction"), axis=1)))].factor
    peak = run.steps[int(np.argmax(np.linalg.norm(run.array("reaction"), axis=1)))].factor
    assert abs(peak - peak_adr) <= step * f + 1e-3 * f
    b = prob.body
    y = b.points[b.bond_i, 1]
    across = (y - mid) * (y + b.xi[:, 1] - mid) < 0
    assert across.sum() > 100                                 # beyond the notch
    assert (prob.alive[across] == 0).mean() > 0.75 and (adr_prob.alive[across] == 0).mean() > 0.75


def test_sequential_refuses_bad_input():
    prob, _ = strip_problem(pd.BondBased(1.0), h=0.1)
    with pytest.raises(InputError):
        sequential(prob, 1.0)                               # no critical stretch
    prob, _ = strip_problem(pd.BondBased(1.0, critical_stretch=0.02), h=0.1)
    for bad in (dict(factor_max=-1.0), dict(factor_max=1.0, tol=2.0),
                dict(factor_max=1.0, max_solves=0)):
        with pytest.raises(InputError):
            sequential(prob, **bad)
    loose = pd.Problem(prob.body, pd.BondBased(1.0, critical_stretch=0.02))
    loose.add_dirichlet(lambda p: p[:, 1] > 0.4, 1, 0.01)
    with pytest.raises(SolveError, match="free"):
        sequential(loose, 1.0)
