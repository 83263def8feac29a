"""Guards of the long PD computations: explicit dynamics refuses or
flags a time step above the stable one and stops, naming the step, when its state goes
non-finite; dynamic relaxation and Newton report non-convergence with their residual
history."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import cnem
import cnem.pd as pd
from cnem import config
from cnem.pd import distributed as dpd

H = 0.05
MATERIALS = {"bond": pd.BondBased(1.0), "state": pd.StateBased(1.0, 0.3)}


def _grid(h=H, lx=1.0, ly=0.5):
    gx, gy = np.arange(0, lx + 1e-9, h), np.arange(0, ly + 1e-9, h)
    return np.array([(x, y) for x in gx for y in gy])


def _wave(p):
    return 1e-3 * np.column_stack([np.sin(np.pi * p[:, 0]), np.cos(np.pi * p[:, 1])])


def _problem(kind, module=pd):
    return module.Problem(module.Body(_grid(), H * H, 3.015 * H), MATERIALS[kind])


def _critical_step(prob):
    """``2 / omega_max`` of the linear stiffness (the real stability limit of Verlet)."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla
    scale = sp.diags(1.0 / np.sqrt(np.repeat(prob.body.volumes * prob.material.density, 2)))
    top = spla.eigsh(scale @ prob.stiffness() @ scale, k=1, which="LA")[0][0]
    return 2.0 / np.sqrt(top)


@pytest.mark.parametrize("kind", MATERIALS)
def test_a_step_100_times_the_stable_one_is_refused_with_the_stable_value(kind):
    prob = _problem(kind)
    stable = prob.stable_time_step(1.0)
    with pytest.raises(cnem.InputError, match=rf"100 times the stable time step "
                                              rf"{stable:.6g}.*Use dt <= {stable:.6g}"):
        prob.run_dynamic(100 * stable, 10, velocity=_wave, progress=False)


@pytest.mark.parametrize("kind", MATERIALS)
def test_the_bound_is_below_the_real_critical_step_and_the_limit_above_it(kind):
    # what makes the refusal safe: below the bound always stable, the limit no lower
    # than the real critical step of a uniform lattice
    prob = _problem(kind)
    critical = _critical_step(prob)
    assert prob.stable_time_step(1.0) < critical <= config.DT_LIMIT * prob.stable_time_step(1.0)


@pytest.mark.parametrize("kind", MATERIALS)
def test_a_step_beyond_the_critical_one_stops_at_the_step_it_blows_up(kind, monkeypatch):
    monkeypatch.setattr(config, "DT_LIMIT", 1e3)       # let 100x the stable step through
    prob = _problem(kind)
    dt = 100 * prob.stable_time_step(1.0)
    with pytest.warns(cnem.StabilityWarning, match="may be unstable"), \
            pytest.raises(cnem.DivergenceError, match=r"not finite at step \d+") as err:
        prob.run_dynamic(dt, 10_000, velocity=_wave, progress=False)
    assert 1 <= err.value.step < 10_000 and 0 <= err.value.point < len(prob.body)
    assert isinstance(err.value, cnem.SolveError)
    # the step named is the first non-finite one: one step fewer runs to the end, finite
    run = prob.run_dynamic(dt, err.value.step - 1, velocity=_wave, progress=False)
    assert np.isfinite(run.u).all() and np.isfinite(run.velocity).all()


def test_a_step_between_the_bound_and_the_critical_one_warns_and_runs():
    prob = _problem("bond")
    dt = 0.5 * (prob.stable_time_step(1.0) + _critical_step(prob))
    with pytest.warns(cnem.StabilityWarning, match=r"times the stable time step"):
        run = prob.run_dynamic(dt, 300, velocity=_wave, progress=False)
    assert np.isfinite(run.u).all()
    assert abs(run.energy[-1] / run.energy[0] - 1) < 0.05         # still conservative


def test_a_stable_step_neither_warns_nor_fails():
    prob = _problem("state")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        run = prob.run_dynamic(prob.stable_time_step(), 20, velocity=_wave, progress=False)
    assert np.isfinite(run.u).all()


def test_velocities_that_overflow_the_forces_stop_at_the_first_step():
    prob = _problem("bond")
    with pytest.raises(cnem.DivergenceError, match=r"not finite at step 1 .*loads, velocities"):
        prob.run_dynamic(prob.stable_time_step(), 50, velocity=lambda p: 1e200 + 0 * p,
                         progress=False)


@pytest.mark.parametrize("kind", MATERIALS)
def test_distributed_dynamics_has_the_same_guards(kind, monkeypatch):
    pytest.importorskip("mpi4py")
    prob = _problem(kind, dpd)
    stable = prob.stable_time_step(1.0)
    with pytest.raises(cnem.InputError, match=rf"times the stable time step {stable:.6g}"):
        prob.run_dynamic(100 * stable, 10, velocity=_wave, progress=False)
    monkeypatch.setattr(config, "DT_LIMIT", 1e3)
    serial = _problem(kind)
    with pytest.warns(cnem.StabilityWarning), pytest.raises(cnem.DivergenceError) as mine:
        prob.run_dynamic(100 * stable, 10_000, velocity=_wave, progress=False)
    with pytest.warns(cnem.StabilityWarning), pytest.raises(cnem.DivergenceError) as ref:
        serial.run_dynamic(100 * stable, 10_000, velocity=_wave, progress=False)
    if kind == "bond":        # the same forces: the same step (state-based: a bounded stable step)
        assert mine.value.step == ref.value.step


def _stretched(material):
    prob = pd.Problem(pd.Body(_grid(0.1), 0.01, 0.3015), material)
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None)
    prob.add_dirichlet(lambda p: p[:, 0] > 1 - 1e-9, 0, 1e-3)
    return prob


def test_relaxation_out_of_iterations_carries_its_residual_history():
    with pytest.raises(cnem.ConvergenceError, match=r"did not converge in load step 1.*history") \
            as err:
        _stretched(pd.StateBased(1.0, 0.3)).relax(tol=1e-10, max_steps=40, every=5)
    history = err.value.history
    assert isinstance(err.value, cnem.SolveError) and len(history) == 1
    assert len(history[0]) == 1 + 40 // 5 + 1 and np.isfinite(history[0]).all()
    assert history[0][-1] < history[0][0] and history[0][-1] > 1e-10 * history[0][0]


def test_relaxation_whose_forces_overflow_is_not_returned_as_settled():
    prob = _stretched(pd.BondBased(1.0))
    prob.add_body_force(lambda p: 1e300 + 0 * p)
    with pytest.raises(cnem.ConvergenceError, match=r"not finite") as err:
        prob.relax(max_steps=1000)
    assert not np.isfinite(err.value.history[-1][-1])


def test_newton_out_of_iterations_carries_its_residual_history():
    prob = _stretched(pd.BondBased(1.0))
    with pytest.raises(cnem.ConvergenceError, match=r"Newton did not converge in load step 1 of "
                                                     r"1.*residuals") as err:
        prob.solve(tol=1e-300, max_iterations=2)
    history = err.value.history
    assert [len(r) for r in history] == [3]        # the first residual and two corrections
    assert history[0][1] < 1e-6 * history[0][0]          # the first correction solves it
