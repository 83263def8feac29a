"""Adaptive dynamic relaxation (ADR) for quasi-static peridynamics.

Kilic & Madenci (2010), "An adaptive dynamic relaxation method for
quasi-static simulations using the peridynamic theory", Theor. Appl. Fract.
Mech. 53, 194-204. The static equilibrium ``F(u) = f_ext - f_int(u) = 0`` is
reached as the steady state of the damped fictitious dynamics
``Lambda u'' + c Lambda u' = F(u)`` with

* the time step ``dt = 1`` and the diagonal fictitious density
  ``lambda_ii = dt^2 / 4 sum_j |K_ij|`` (eq. 21; Gershgorin: every frequency
  of ``Lambda^-1 K`` is at most 2, so the central difference is stable),
* the damping ``c^n = 2 sqrt(u^T K^n_loc u / u^T u)`` from the diagonal
  local stiffness ``K^n_loc,ii = -(F^n_i - F^(n-1)_i) / (lambda_ii dt v^(n-1/2)_i)``
  (eqs. 17-18; ``c = 0`` when the quotient is not positive),
* the central-difference update (eqs. 15-16)
  ``v^(n+1/2) = ((2 - c^n dt) v^(n-1/2) + 2 dt Lambda^-1 F^n) / (2 + c^n dt)``,
  ``u^(n+1) = u^n + dt v^(n+1/2)``, started by ``v^(1/2) = dt Lambda^-1 F^0 / 2``.

The forces are those of explicit dynamics (`Problem.run_dynamic`), so bonds
stretched beyond the material's critical stretch break during the
iterations; the body then settles into its damaged equilibrium.

>>> import numpy as np, cnem.pd as pd
>>> h = 0.1
>>> g = np.arange(0, 1 + 1e-9, h)
>>> pts = np.array([(x, y) for x in g for y in g])
>>> prob = pd.Problem(pd.Body(pts, h * h, 3.015 * h), pd.StateBased(1.0, 0.3))
>>> prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None)
>>> prob.add_dirichlet(lambda p: p[:, 0] > 1 - 1e-9, 0, 1e-3)
>>> sol = prob.relax(tol=1e-10)
>>> bool(np.abs(sol.u - prob.solve().u).max() < 1e-9)
True
"""

from __future__ import annotations

import logging
import sys
from typing import TYPE_CHECKING

import numpy as np
from tqdm.auto import tqdm

from ..assembly.linsolve import free_rigid_motions
from ..errors import ConvergenceError, InputError, SolveError
from .solution import Relaxation

if TYPE_CHECKING:
    from typing import Any, Callable

__all__ = ["relax", "Relaxation", "load_steps", "unsettled"]

log = logging.getLogger(__name__)


def _damping(u, force, previous, velocity, density, dot=np.dot):
    """Kilic & Madenci's ``c = 2 sqrt(u^T K_loc u / u^T u)`` with the diagonal local
    stiffness from the last force change (0 where the velocity vanishes); ``dot`` is the
    inner product."""
    moving = velocity != 0.0
    k = np.zeros_like(u)
    k[moving] = -(force[moving] - previous[moving]) / (density[moving] * velocity[moving])
    num, den = float(dot(u, k * u)), float(dot(u, u))
    return 2.0 * np.sqrt(num / den) if num > 0.0 and den > 0.0 else 0.0


def _settle(x, forces, density, target, budget, record, dot=np.dot):
    """ADR iterations from rest (``dt = 1``) until the out-of-balance force is at
    most ``target``.

    Parameters
    ----------
    x : (f,) ndarray
        Free dofs, updated in place.
    forces : callable () -> (f,) ndarray
        Out-of-balance force at the current ``x``.
    density : (f,) ndarray
        Fictitious density.
    target : float
    budget : int
        Iterations allowed.
    record : callable (float) -> None
        Called with the force norm after every iteration.
    dot : callable (a, b) -> float
        Inner product of two dof vectors (a sum over the ranks when they are split).

    Returns
    -------
    float
        Force norm reached (above ``target`` when the budget ran out).
    """
    force = forces()
    norm = float(np.sqrt(dot(force, force)))
    velocity = 0.5 * force / density
    iterations = 0
    while norm > target and norm > 0.0 and iterations < budget:      # False on NaN
        iterations += 1
        x += velocity
        previous, force = force, forces()
        c = _damping(x, force, previous, velocity, density, dot)
        velocity = ((2.0 - c) * velocity + 2.0 * force / density) / (2.0 + c)
        norm = float(np.sqrt(dot(force, force)))
        record(norm)
    return norm


def unsettled(step: int, norm: float, scale: float, target: float, max_steps: int,
              history: list | None = None) -> ConvergenceError:
    """The `ConvergenceError` of a load step that has not settled within ``max_steps``
    (or whose residual went non-finite); ``history``: the residuals so far, one list per
    load step."""
    if not np.isfinite(norm):
        return ConvergenceError(
            f"dynamic relaxation diverged in load step {step}: the out-of-balance force is "
            f"not finite (residual {norm}); check the loads and material constants (the "
            f"forces must stay finite), or use more load steps", history)
    return ConvergenceError(
        f"dynamic relaxation did not converge in load step {step}: residual "
        f"{norm:.3e} ({norm / scale:.1e} of the reference {scale:.3e}, wanted "
        f"{target / scale:.1e}) after {max_steps} iterations; raise max_steps or tol "
        f"(the residual history is the error's .history)", history)


def load_steps(x: np.ndarray, forces: Callable[..., np.ndarray], density: np.ndarray,
               external: np.ndarray, load: np.ndarray, prescribe: Callable[..., np.ndarray], *,
               tol: float, noise: float, limit: float, steps: int, max_steps: int, every: int,
               show: bool, dot: Callable[..., np.ndarray] = np.dot) -> tuple[list, int, int]:
    """The load steps of `relax`: each settles from the last equilibrium, then breaks the
    over-stretched bonds and settles again until no bond breaks.

    Parameters
    ----------
    x : (f,) ndarray
        Free dofs, updated in place.
    forces : callable (breaking=inf) -> ((f,) ndarray, int)
        Out-of-balance force at ``x`` and the bonds broken beyond ``breaking``.
    density : (f,) ndarray
    external, load : (f,) ndarray
        The applied force of the step (filled here) and the full load.
    prescribe : callable (float) -> None
        Sets the Dirichlet values to that fraction of theirs.
    tol, noise, limit : float
        Relative tolerance, smallest reachable residual, critical stretch.
    steps, max_steps, every : int
    show : bool
        Progress bars.
    dot : callable (a, b) -> float
        Inner product of dof vectors (a sum over the ranks when they are split).

    Returns
    -------
    history : list of list of float
    iterations : int
    broken : int
    """
    def norm_of(v):
        return float(np.sqrt(dot(v, v)))

    broken = 0
    history, total = [], 0
    for step in range(1, steps + 1):
        frac = step / steps
        prescribe(frac)
        external[:] = frac * load
        start = norm_of(forces()[0])
        scale = norm_of(external) or start
        target = max(tol * scale, noise)
        res, used = [start], 0
        bar = tqdm(total=max_steps, desc=f"ADR load step {step}/{steps}", disable=not show,
                   leave=False)

        def record(norm):
            nonlocal used
            used += 1
            if used % every == 0:
                res.append(norm)
                bar.update(every)
                bar.set_postfix(residual=f"{norm / max(scale, 1e-300):.1e}", refresh=False)

        while True:
            norm = _settle(x, lambda: forces()[0], density, target, max_steps - used, record,
                           dot)
            if not (norm <= target and np.isfinite(norm)):          # not settled, or not finite
                bar.close()
                raise unsettled(step, norm, scale, target, max_steps, history + [res + [norm]])
            count = forces(limit)[1]                # break the over-stretched bonds
            if not count:
                break
            broken += count
        bar.close()
        if used % every:
            res.append(norm)
        log.info("ADR load step %d: %d iterations, residual %.3e", step, used, norm)
        history.append(res)
        total += used
    return history, total, broken


def relax(problem: Any, *, tol: float = 1e-8, max_steps: int = 100_000, steps: int = 1,
          every: int | None = None, progress: bool | None = None) -> Relaxation:
    """Quasi-static equilibrium of a peridynamic problem by adaptive dynamic relaxation.

    Bonds break at equilibrium only (the fictitious transient must not break
    them): once a load step has settled, the bonds stretched beyond the
    critical stretch break and the body settles again, until an equilibrium
    breaks no more bonds. Each load step starts from the previous equilibrium.

    Parameters
    ----------
    problem : cnem.pd.Problem
        Its Dirichlet values and loads are ramped in ``steps`` equal increments.
    tol : float
        A load step has settled when the out-of-balance force on the free dofs
        is at most ``tol`` times the load's norm there (or, with no load there,
        times the out-of-balance force at the start of the step, from the
        prescribed displacements), or at most ten times the round-off of the
        forces (their norm at zero displacement), whichever is larger.
    max_steps : int
        Iterations allowed per load step.
    steps : int
        Load steps.
    every : int, optional
        Store the residual every so many iterations (default 10).
    progress : bool, optional
        tqdm bar per load step (default: when stderr is a terminal).

    Returns
    -------
    Relaxation
        ``u (n, d)``, ``damage (n,)``, ``residual_history``, ``iterations``.

    Raises
    ------
    SolveError
        Rigid motions left free by the Dirichlet conditions (named).
    ConvergenceError
        A load step that has not settled within ``max_steps`` iterations, or whose
        residual went non-finite (the residual reached is given, the residual
        history is the error's ``history``).
    """
    tol, max_steps, steps = float(tol), int(max_steps), int(steps)
    every = 10 if every is None else int(every)
    if not tol > 0 or max_steps < 1 or steps < 1 or every < 1:
        raise InputError(f"expected tol > 0 and max_steps, steps, every >= 1, received tol={tol}, "
                         f"max_steps={max_steps}, steps={steps}, every={every}")
    body, d, n = problem.body, problem.dim, len(problem.body)
    stiffness = problem.stiffness()
    fixed, values = problem.prescribed()
    free_motions = free_rigid_motions(stiffness, body.points, fixed)
    if free_motions:
        raise SolveError("dynamic relaxation cannot settle: the Dirichlet conditions leave free "
                         "the " + "; ".join(free_motions) + ". Fix them with add_dirichlet")
    free = np.setdiff1d(np.arange(d * n), fixed)
    density = 0.25 * np.asarray(abs(stiffness).sum(axis=1)).reshape(-1)[free]   # dt = 1
    limit = problem.material.stretch_limit(d, problem.plane, body.horizon)
    state = problem._force_state()
    volumes = np.repeat(body.volumes, d)[free]
    load = problem.load()
    u = np.zeros((n, d))
    flat, x = u.reshape(-1), np.zeros(len(free))              # x: the free dofs
    external = np.zeros(len(free))
    # the force at zero displacement is the round-off of the bond stretches (it should
    # vanish): a residual below a few times it cannot be reached
    noise = 10.0 * float(np.linalg.norm(volumes * problem._internal_force(
        u, np.inf, state)[0].reshape(-1)[free]))

    def forces(breaking=np.inf):
        """Out-of-balance force on the free dofs at ``x`` (``(f,)``), and the number of
        bonds stretched beyond ``breaking`` (broken by this call)."""
        flat[free] = x
        force, count = problem._internal_force(u, breaking, state)
        return external + volumes * force.reshape(-1)[free], count

    def prescribe(fraction):
        flat[fixed] = fraction * values

    show = sys.stderr.isatty() if progress is None else progress
    history, total, broken = load_steps(x, forces, density, external, load[free], prescribe,
                                        tol=tol, noise=noise, limit=limit, steps=steps,
                                        max_steps=max_steps, every=every, show=show)
    flat[free] = x
    return Relaxation(problem, u, damage=problem.damage(), residual_history=history,
                      iterations=total, broken=broken)
