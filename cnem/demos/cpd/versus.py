"""Runs of `cnem.demos.cnem_vs_cpd`: one finite-strain problem solved by C-NEM
(`cnem.Hyperelasticity` with `cnem.demos.cpd.bond_law.BondContinuum`) and by CPD
(`cnem.pd.CPD`, one-neighbour, the same Seth-Hill energy) on the same nodes, each load
step recorded."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

import numpy as np

import cnem
import cnem.pd as pd
from cnem.pd.cpd_moduli import moduli_per_constant
from cnem.solvers.newton import newton

from .bond_law import BondContinuum

if TYPE_CHECKING:
    from typing import Callable

__all__ = ["bulk_factor", "cpd_material", "run_cnem", "run_cpd", "Run"]

#: Relative residual of every Newton solve.
TOL = 1e-9
#: Newton corrections allowed per load step of CPD (its bent one-neighbour beams at the
#: largest horizon wander for 10-60 iterations in a step before the quadratic phase; a
#: line search makes that worse: it stalls on tiny steps).
MAX_ITERATIONS = 60


class Run(dict):
    """One method's result: ``u`` (s, n, 2) after each load step, ``factor`` (s,),
    ``force`` (s, n, 2) internal forces, ``history`` (Newton residuals per step),
    ``iterations`` (Newton corrections in all), ``seconds`` (Newton), ``evaluate_seconds``
    (one residual plus tangent) and, for CPD, ``setup_seconds`` (body and interactions),
    ``C1``, ``bulk``, ``horizon``."""

    __getattr__ = dict.__getitem__


def bulk_factor(body: pd.Body, inside: np.ndarray) -> float:
    """The one-neighbour lattice sum of ``body``'s interior points against its continuum
    value: the median over the points ``inside`` of ``sum_i |Xi| beta_i V_i / (2 pi
    delta^3 t / 3)`` (``t`` the thickness), the trace of the bond tensor
    ``sum |Xi| V^i M M M M`` whose continuum limit gives ``lam = mu = C1 pi delta^3 / 24``.

    Returns
    -------
    float
        1 on the continuum; the discrete body's small-strain stiffness per C1 is this
        factor times `cnem.pd.cpd_moduli.moduli_per_constant`'s.
    """
    weights = body.length * body.beta * body.volumes[body.bond_j]
    trace = np.bincount(body.bond_i, weights=weights, minlength=len(body))
    continuum = 2.0 * np.pi * body.horizon ** 3 * body.thickness / 3.0
    return float(np.median(trace[inside]) / continuum)


def cpd_material(body: pd.Body, law: BondContinuum, inside: np.ndarray) -> tuple[pd.CPD, float]:
    """`cnem.pd.CPD` with C1 giving ``body``'s interior points the shear modulus of ``law``
    (C2 = 0, the law's Seth-Hill exponent), and the `bulk_factor` used."""
    factor = bulk_factor(body, inside)
    mu_per_c1 = moduli_per_constant(2, body.horizon, body.thickness)[0, 1]
    return pd.CPD(law.mu / (factor * mu_per_c1), exponent=law.exponent), factor


def _timed_evaluate(evaluate: Callable, size: int) -> float:
    """Seconds of one residual plus tangent at zero displacement."""
    start = time.perf_counter()
    evaluate(np.zeros(size), True)
    return time.perf_counter() - start


def run_cnem(model: cnem.Model, law: BondContinuum, dirichlet: list[tuple],
             traction: tuple | None, steps: int) -> Run:
    """`cnem.Hyperelasticity` of ``model`` with ``dirichlet`` [(where, component, value)]
    and an optional dead ``traction`` (where, t), in ``steps`` load steps."""
    prob = cnem.Hyperelasticity(model, law)
    for where, component, value in dirichlet:
        prob.add_dirichlet(where, component, value)
    if traction is not None:
        prob.add_traction(*traction)
    evaluate_seconds = _timed_evaluate(prob.system.evaluate, model.nodes.size)
    sol = prob.solve(steps=steps, tol=TOL)
    n = len(model.nodes)
    u = np.array([dofs.reshape(n, 2) for _, dofs in sol.steps])
    force = np.array([prob.system.evaluate(dofs, False)[0].reshape(n, 2) for _, dofs in sol.steps])
    return Run(u=u, factor=np.array([f for f, _ in sol.steps]), force=force,
               history=sol.residual_history, seconds=sol.timings["newton"],
               iterations=sum(len(h) - 1 for h in sol.residual_history),
               evaluate_seconds=evaluate_seconds)


def run_cpd(cloud: cnem.NodeCloud, horizon_factor: float, law: BondContinuum,
            inside: Callable[[pd.Body], np.ndarray], dirichlet: list[tuple],
            point_forces: np.ndarray | None, steps: int) -> Run:
    """CPD on the nodes of ``cloud`` (`cnem.pd.Body.from_cloud`, horizon
    ``horizon_factor`` spacings), calibrated by `cpd_material` on the points
    ``inside(body)`` selects, with ``dirichlet`` and optional nodal forces
    ``point_forces (n, 2)`` (the whole load), in ``steps`` load steps."""
    start = time.perf_counter()
    body = pd.Body.from_cloud(cloud, horizon_factor)
    material, bulk = cpd_material(body, law, inside(body))
    prob = pd.Problem(body, material)
    for where, component, value in dirichlet:
        prob.add_dirichlet(where, component, value)
    if point_forces is not None:
        prob.add_body_force(point_forces / body.volumes[:, None])
    evaluate, pattern = prob.behaviour.static_system()
    setup_seconds = time.perf_counter() - start
    evaluate_seconds = _timed_evaluate(evaluate, body.points.size)
    D, values = prob.prescribed()
    states = []
    start = time.perf_counter()
    _, history = newton(evaluate, prob.load(), D, values, points=body.points, pattern=pattern,
                        tol=TOL, steps=steps, max_iterations=MAX_ITERATIONS,
                        on_step=lambda k, u: states.append((k / steps, u)))
    seconds = time.perf_counter() - start
    n = len(body)
    return Run(u=np.array([u.reshape(n, 2) for _, u in states]),
               factor=np.array([f for f, _ in states]),
               force=np.array([evaluate(u, False)[0].reshape(n, 2) for _, u in states]),
               history=history, seconds=seconds, iterations=sum(len(h) - 1 for h in history),
               evaluate_seconds=evaluate_seconds, setup_seconds=setup_seconds, C1=material.C1, bulk=bulk,
               horizon=body.horizon)
