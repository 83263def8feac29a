"""Adaptive dynamic relaxation (ADR) for quasi-static peridynamics.

Kilic & Madenci (2010), "An adaptive dynamic relaxation method for
quasi-static simulations using the peridynamic theory", Theor. Appl. Fract.
Mech. 53, 194-204. The static equilibrium ``F(u) = f_ext - f_int(u) = 0`` is
reached as the steady state of the damped fictitious dynamics
``Lambda u'' + c Lambda u' = F(u)`` with

* the time step ``dt = 1`` and the diagonal fictitious density
  ``lambda_ii = dt^2 / 4 sum_j |K_ij|`` (eq. 21; Gershgorin: every frequency
  of ``Lambda^-1 K`` is at most 2, so the central difference is stable; raised
  where a state-based stiffness row grows after bonds broke),
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

from ..solvers.linsolve import free_rigid_motions
from ..errors import ConvergenceError, InputError, SolveError, check_count
from .solution import Relaxation

if TYPE_CHECKING:
    from typing import Any, Callable, Sequence

__all__ = ["relax", "Relaxation", "System", "load_steps", "unsettled"]

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


def force_round_off(problem: Any, stiffness: np.ndarray | None, at_rest: np.ndarray,
                    rows: int) -> np.ndarray:
    """How far round-off alone puts the nodal forces from balance, per dof ``(rows d,)``.

    The force at zero displacement (``at_rest``, nodal, owned rows) says it when the
    stretches of the reference bonds do not come out exactly zero. A PMB bond's force
    (``stiffness (b,)`` its ``c_b``) also rounds ``|y| - L`` to about ``eps L`` at any
    displacement, so it is off by about ``eps c_b V_j``; the bonds of a point add up at
    random, times its volume. The larger of the two, per dof.
    """
    body = problem.body
    d = problem.dim
    if stiffness is None:
        return np.abs(at_rest)
    per_bond = np.finfo(float).eps * stiffness * body.volumes[body.bond_j]
    per_point = body.volumes[:rows] * np.sqrt(np.bincount(body.bond_i, weights=per_bond ** 2,
                                                          minlength=rows))
    return np.maximum(np.abs(at_rest), np.repeat(per_point, d))


def load_steps(x: np.ndarray, forces: Callable[..., np.ndarray], density: np.ndarray,
               external: np.ndarray, load: np.ndarray, prescribe: Callable[..., np.ndarray], *,
               tol: float, noise: float, limit: float, steps: int, max_steps: int, every: int,
               show: bool, dot: Callable[..., np.ndarray] = np.dot,
               fractions: Sequence[float] | None = None, max_rounds: int | None = None,
               after_step: Callable[..., None] | None = None) -> tuple[list, int, int]:
    """The load steps of `relax`: each settles from the last equilibrium, then breaks the
    over-stretched bonds and settles again until no bond breaks.

    Parameters
    ----------
    x : (f,) ndarray
        Free dofs, updated in place.
    forces : callable (breaking=inf) -> ((f,) ndarray, int)
        Out-of-balance force at ``x`` and the bonds broken beyond ``breaking``.
    density : (f,) ndarray
        Fictitious density (``forces`` may raise it in place).
    external, load : (f,) ndarray
        The applied force of the step (filled here) and the full load.
    prescribe : callable (float) -> None
        Sets the Dirichlet values to that fraction of theirs.
    tol, noise, limit : float
        Relative tolerance, smallest reachable residual, critical stretch.
    steps, max_steps, every : int
        ``steps`` equal load steps to the full load (unless ``fractions`` is given).
    show : bool
        Progress bars.
    dot : callable (a, b) -> float
        Inner product of dof vectors (a sum over the ranks when they are split).
    fractions : sequence of float, optional
        The load factor of each step instead (``steps`` is then its length).
    max_rounds : int, optional
        Most break-and-settle rounds per step (default unbounded): a step that
        still breaks bonds in its last round ends settled but not complete.
    after_step : callable, optional
        Called after each step as ``after_step(step, fraction, rounds=, broken=,
        iterations=, residual=, complete=)`` (``rounds``: the settles that broke bonds);
        a true return value ends the run there.

    Returns
    -------
    history : list of list of float
    iterations : int
    broken : int
    """
    def norm_of(v):
        return float(np.sqrt(dot(v, v)))

    if fractions is None:
        fractions = [step / steps for step in range(1, steps + 1)]
    broken = 0
    history, total = [], 0
    for step, frac in enumerate(fractions, start=1):
        prescribe(frac)
        external[:] = frac * load
        start = norm_of(forces()[0])
        scale = norm_of(external) or start
        target = max(tol * scale, noise)
        res, used = [start], 0
        bar = tqdm(total=max_steps, desc=f"ADR load step {step}/{len(fractions)}",
                   disable=not show, leave=False)

        def record(norm):
            nonlocal used
            used += 1
            if used % every == 0:
                res.append(norm)
                bar.update(every)
                bar.set_postfix(residual=f"{norm / max(scale, 1e-300):.1e}", refresh=False)

        rounds, step_broken = 0, 0
        while True:
            norm = _settle(x, lambda: forces()[0], density, target, max_steps - used, record,
                           dot)
            if not (norm <= target and np.isfinite(norm)):          # not settled, or not finite
                bar.close()
                raise unsettled(step, norm, scale, target, max_steps, history + [res + [norm]])
            exhausted = max_rounds is not None and rounds >= max_rounds
            if exhausted:
                break
            count = forces(limit)[1]                # break the over-stretched bonds
            if not count:
                break
            rounds += 1
            step_broken += count
        bar.close()
        if used % every:
            res.append(norm)
        log.info("ADR load step %d: %d iterations, %d rounds, %d bonds broken, residual %.3e",
                 step, used, rounds, step_broken, norm)
        history.append(res)
        total += used
        broken += step_broken
        if after_step is not None and after_step(step, frac, rounds=rounds, broken=step_broken,
                                                 iterations=used, residual=norm,
                                                 complete=not exhausted):
            break
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
        forces (`force_round_off`: their norm at zero displacement or, for the
        PMB, the modelled rounding of the bond forces), whichever is larger.
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
    tol, max_steps = float(tol), check_count("max_steps", max_steps)
    steps = check_count("steps", steps)
    every = 10 if every is None else check_count("every", every)
    if not tol > 0 or max_steps < 1 or steps < 1 or every < 1:
        raise InputError(f"expected tol > 0 and max_steps, steps, every >= 1, received tol={tol}, "
                         f"max_steps={max_steps}, steps={steps}, every={every}")
    system = System(problem)
    show = sys.stderr.isatty() if progress is None else progress
    history, total, broken = system.run(tol=tol, steps=steps, max_steps=max_steps, every=every,
                                        show=show)
    return Relaxation(problem, system.u, damage=problem.damage(), residual_history=history,
                      iterations=total, broken=broken)


class System:
    """The free dofs, fictitious density and forces of a serial ADR run on a problem.

    Parameters
    ----------
    problem : cnem.pd.Problem
        BondBased or StateBased.

    Attributes
    ----------
    u : (n, d) ndarray
        Displacements (updated by `run`).
    free, fixed : int ndarray
        Free and prescribed dofs; ``values`` the prescribed values (full load).

    Raises
    ------
    SolveError
        Rigid motions left free by the Dirichlet conditions (named).
    """

    def __init__(self, problem: Any):
        self.problem = problem
        body, d, n = problem.body, problem.dim, len(problem.body)
        stiffness = problem.stiffness()
        self.fixed, self.values = problem.prescribed()
        free_motions = free_rigid_motions(stiffness, body.points, self.fixed)
        if free_motions:
            raise SolveError("dynamic relaxation cannot settle: the Dirichlet conditions leave "
                             "free the " + "; ".join(free_motions) + ". Fix them with "
                             "add_dirichlet")
        self.free = free = np.setdiff1d(np.arange(d * n), self.fixed)
        self.density = 0.25 * np.asarray(abs(stiffness).sum(axis=1)).reshape(-1)[free]  # dt = 1
        self.limit = problem.material.stretch_limit(d, problem.plane, body.horizon)
        self.state = problem._force_state()
        self.volumes = np.repeat(body.volumes, d)
        self.load = problem.load()[free]
        self.u = np.zeros((n, d))
        self.flat, self.x = self.u.reshape(-1), np.zeros(len(free))     # x: the free dofs
        self.external = np.zeros(len(free))
        # a residual below a few times the forces' round-off cannot be reached
        floor = force_round_off(problem, self.state.get("stiffness"), self._nodal_force()[0], n)
        self.noise = 10.0 * float(np.linalg.norm(floor[free]))

    def _nodal_force(self, breaking=np.inf):
        """Internal forces times volumes at ``u``, ``(d n,)``, and the bonds broken."""
        force, count = self.problem._internal_force(self.u, breaking, self.state)
        return self.volumes * force.reshape(-1), count

    def forces(self, breaking: float = np.inf) -> tuple[np.ndarray, int]:
        """Out-of-balance force on the free dofs at ``x`` (``(f,)``), and the number of
        bonds stretched beyond ``breaking`` (broken by this call)."""
        self.flat[self.free] = self.x
        force, count = self._nodal_force(breaking)
        if count and "K" in self.state:
            # a state-based point that lost bonds takes the moment tensor of the live ones
            # (`cnem.pd.Problem.live_gradient_weights`): its stiffness rows may grow, and
            # the fictitious density follows them (in place: the settle holds the array)
            rows = 0.25 * np.asarray(abs(self.state["K"]).sum(axis=1)).reshape(-1)
            np.maximum(self.density, rows[self.free], out=self.density)
        return self.external + force[self.free], count

    def prescribe(self, fraction: float) -> None:
        """The Dirichlet values at ``fraction`` of theirs."""
        self.flat[self.fixed] = fraction * self.values

    def reactions(self) -> np.ndarray:
        """``(d n,)`` the forces that hold the prescribed dofs at ``u`` (zero on the free
        dofs): minus the internal forces there."""
        out = np.zeros_like(self.flat)
        out[self.fixed] = -self._nodal_force()[0][self.fixed]
        return out

    def run(self, *, tol: float, max_steps: int, every: int, show: bool, steps: int = 1,
            fractions: Sequence[float] | None = None, max_rounds: int | None = None,
            after_step: Callable[..., None] | None = None) -> tuple[list, int, int]:
        """`load_steps` on this system; ``u`` holds the last equilibrium after it (and
        during ``after_step``)."""
        def after(*args, **kwargs):
            self.flat[self.free] = self.x
            return after_step is not None and after_step(*args, **kwargs)

        out = load_steps(self.x, self.forces, self.density, self.external, self.load,
                         self.prescribe, tol=tol, noise=self.noise, limit=self.limit,
                         steps=steps, max_steps=max_steps, every=every, show=show,
                         fractions=fractions, max_rounds=max_rounds, after_step=after)
        self.flat[self.free] = self.x
        return out
