"""Velocity conditions of the explicit PD dynamics (`cnem.pd.velocity`): exact motion of
the prescribed points, a rigid translation that stores no energy, precedence over
Dirichlet conditions, refusal by the static solvers, and the distributed run on one
rank equal to the serial one."""

from __future__ import annotations

import importlib.util

import numpy as np
import pytest

import cnem.pd as pd
from cnem.errors import ConditionError

H = 1e-3
V = np.array([32.0, -5.0])


def grid(nx=12, ny=6):
    x, y = np.meshgrid((np.arange(nx) + 0.5) * H, (np.arange(ny) + 0.5) * H, indexing="ij")
    return np.column_stack([x.ravel(), y.ravel()])


def problem(module=pd, **body):
    b = module.Body(grid(), H * H, 3.015 * H, **body)
    return module.Problem(b, module.BondBased(191e9, fracture_energy=2.2e4, density=8000.0))


def test_all_points_at_one_velocity_translate_rigidly():
    prob = problem()
    prob.add_velocity(lambda p: np.ones(len(p), bool), None, lambda p: np.tile(V, (len(p), 1)))
    dt = prob.stable_time_step()
    run = prob.run_dynamic(dt, 40, every=10, progress=False)
    mass = 8000.0 * prob.body.volumes.sum()
    for t, (u, damage) in zip(run.times, run.frames):
        np.testing.assert_allclose(u, np.tile(V * t, (len(u), 1)), rtol=1e-13,
                                   atol=1e-13 * np.abs(V).max() * run.times[-1])
        assert damage.max() == 0.0
    np.testing.assert_allclose(run.velocity, np.tile(V, (len(run.u), 1)), rtol=0, atol=0)
    np.testing.assert_allclose(run.energy, 0.5 * mass * (V @ V), rtol=1e-12)


def test_the_struck_edge_moves_at_its_velocity_and_pushes_the_rest():
    """After k steps the motion has reached the points within k - 1 horizons of the
    struck ones and no further (each step's forces reach one horizon further)."""
    prob = problem()
    edge = lambda p: p[:, 0] < H                                    # noqa: E731
    prob.add_dirichlet(edge, 0, 1.0)              # overridden by the velocity below
    prob.add_velocity(edge, 0, V[0])
    dt, steps = prob.stable_time_step(), 3
    run = prob.run_dynamic(dt, steps, progress=False)
    pts = prob.body.points
    at = edge(pts)
    np.testing.assert_allclose(run.u[at, 0], V[0] * steps * dt, rtol=1e-14)
    assert np.all(run.velocity[at, 0] == V[0])             # y stays free
    reach = np.linalg.norm(pts[:, None] - pts[at][None], axis=2).min(axis=1)
    near = ~at & (reach <= (steps - 1) * prob.body.horizon)
    far = reach > (steps - 1) * prob.body.horizon        # still at rest, up to the round-off
    assert far.sum() > 10                                # of the bond lengths at rest
    assert np.abs(run.u[far]).max() <= 1e-12 * V[0] * steps * dt
    assert near.sum() > 10 and np.all(run.u[near, 0] > 0)     # pushed forward


def test_the_static_solvers_refuse_velocity_conditions():
    prob = problem()
    prob.add_velocity([0, 1], 0, 1.0)
    for solve in (prob.solve, prob.relax):
        with pytest.raises(ConditionError, match="add_velocity"):
            solve()


def test_a_velocity_condition_that_selects_nothing_is_named():
    with pytest.raises(ConditionError, match="add_velocity: `where` selects no node"):
        problem().add_velocity(lambda p: p[:, 0] < 0, 0, 1.0)


def test_velocities_that_disagree_on_a_point_are_refused_and_agreeing_ones_merge():
    prob = problem()
    left = lambda p: p[:, 0] < 1.5 * H
    prob.add_velocity(left, None, V)
    prob.add_velocity(lambda p: left(p) & (p[:, 1] < 1.5 * H), 0, V[0])     # agrees
    dofs, values = prob.prescribed_velocity()
    assert dofs.size == 2 * 6 and np.all(values.reshape(-1, 2) == V)
    prob.add_velocity(lambda p: left(p) & (p[:, 1] < 1.5 * H), 1, 0.0)     # disagrees
    with pytest.raises(ConditionError, match=r"add_velocity: .*conflicting values on 1 dof"):
        prob.prescribed_velocity()


@pytest.mark.skipif(importlib.util.find_spec("mpi4py") is None, reason="needs cnem[mpi]")
def test_one_rank_gives_the_serial_run_with_a_velocity_condition():
    import cnem.pd.distributed as dpd
    runs = []
    for module in (pd, dpd):
        prob = problem(module)
        prob.add_velocity(lambda p: (p[:, 0] < H) & (p[:, 1] < 3 * H), 0, 200.0)
        runs.append(prob.run_dynamic(2e-8, 200, progress=False))
    serial, one = runs
    assert serial.broken > 0                              # the run breaks bonds
    np.testing.assert_allclose(one.u, serial.u, rtol=0, atol=1e-12 * np.abs(serial.u).max())
    assert one.broken == serial.broken
