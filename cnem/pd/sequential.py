"""Quasi-static peridynamic fracture by linear solves, event by event.

Between two bond breaks the linearised bond- or state-based body is linear elastic,
so its equilibrium under the proportional load ``lambda (u_D, f)`` is ``lambda u_1``
with ``u_1`` the solution at factor 1, and the bond stretches are ``lambda s_1``.
`sequential` raises the load factor straight to the first break,
``lambda = s_c / max s_1`` over the live bonds, breaks that bond, solves again at the
same factor and breaks whatever is then over-stretched, round after round, until an
equilibrium breaks no more bonds; then the next event sets the next factor. This is
the equilibrium sequence of `cnem.pd.quasistatic.quasistatic` (ADR, bonds breaking
at equilibrium) in the limit of fine load steps, each equilibrium solved exactly,
without fictitious dynamics (sequentially linear analysis, Rots et al. 2008,
Eng. Fract. Mech. 75:4306, with peridynamic bonds as the elements). The stretches
are the linearised ``n . (u_j - u_i) / L``.

Every solve is CG preconditioned by smoothed aggregation (pyamg) on an earlier
stiffness of the same body (rebuilt when CG needs more than
`REBUILD_ITERATIONS`), started from the last solution: a round changes a few bonds
only. Points left without a live bond are held where they are (their displacement
is undefined).

>>> import numpy as np, cnem.pd as pd
>>> h = 0.1
>>> g = np.arange(0, 1 + 1e-9, h)
>>> pts = np.array([(x, y) for x in g for y in g])
>>> prob = pd.Problem(pd.Body(pts, h * h, 3.015 * h), pd.BondBased(1.0,
...                   critical_stretch=0.01))
>>> prob.add_dirichlet(lambda p: p[:, 0] < 0.3, 0)
>>> prob.add_dirichlet(lambda p: (p[:, 0] < 1e-9) & (p[:, 1] < 1e-9), 1)
>>> prob.add_dirichlet(lambda p: p[:, 0] > 0.7, 0, 0.02)     # free part 0.4 long: strain 0.05
>>> b, u = prob.body, prob.solve().u                        # the elastic solution at factor 1
>>> first = 0.01 / ((prob.unit * (u[b.bond_j] - u[b.bond_i])).sum(axis=1) / b.length).max()
>>> run = sequential(prob, 1.0)
>>> bool(abs(run.steps[0].factor / first - 1) < 1e-9), run.stopped
(True, 'end')
"""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse.linalg as spla
from tqdm.auto import tqdm

from ..solvers.linsolve import free_rigid_motions, rigid_modes
from ..errors import ConvergenceError, InputError, SolveError
from .quasistatic import LoadStep, QuasiStaticRun

if TYPE_CHECKING:
    from typing import Any, Callable

__all__ = ["sequential", "REBUILD_ITERATIONS"]

#: CG iterations of one solve above which the preconditioner is rebuilt on the
#: current stiffness.
REBUILD_ITERATIONS = 60

#: A bond breaks at ``lambda s_1 >= s_c (1 - BREAK_TOL)``: the bond that sets the
#: factor, and any other as stretched to round-off.
BREAK_TOL = 1e-12


class _Solver:
    """CG on the free dofs of the live stiffness, with an AMG preconditioner kept across
    rounds."""

    def __init__(self, problem, free, tol):
        self.problem, self.free, self.tol = problem, free, tol
        self.modes = rigid_modes(problem.body.points)[free]
        self.M = None
        self.iterations = 0

    def _precondition(self, A):
        import pyamg
        ml = pyamg.smoothed_aggregation_solver(A, B=self.modes, max_coarse=500)
        self.M = ml.aspreconditioner(cycle="V")

    def solve(self, A, b, x0):
        if self.M is None:
            self._precondition(A)
        for attempt in range(2):
            its = [0]

            def count(_):
                its[0] += 1

            x, info = spla.cg(A, b, x0=x0, rtol=self.tol, maxiter=20 * REBUILD_ITERATIONS,
                              M=self.M, callback=count)
            self.iterations += its[0]
            if info == 0 and its[0] <= REBUILD_ITERATIONS:
                return x
            self._precondition(A)                       # the old hierarchy has aged
            if info == 0:
                return x
        raise ConvergenceError(f"sequential: CG did not reach the relative residual {self.tol:g} "
                               f"in {20 * REBUILD_ITERATIONS} iterations with a fresh "
                               f"preconditioner; a part of the body may have come loose",
                               [])


def _stretches(problem, u):
    """Linearised stretches ``n . (u_j - u_i) / L`` of the live bonds, ``-inf`` for the
    broken ones, ``(b,)``."""
    b = problem.body
    s = (problem.unit * (u[b.bond_j] - u[b.bond_i])).sum(axis=1) / b.length
    s[problem.alive == 0] = -np.inf
    return s


def _without(problem, K, over):
    """Break the bonds ``over`` of ``problem`` and return its new stiffness: the PMB's by
    subtracting theirs, the state-based one assembled again (a point's dilatation changes
    with its live bonds)."""
    problem.alive[over] = 0
    return problem.behaviour.stiffness_without(K, over)


def sequential(problem: Any, factor_max: float, *, tol: float = 1e-9, max_solves: int = 100_000,
               stop: Callable[..., bool] | None = None, keep_damage: bool = False,
               progress: bool | None = None,
               callback: Callable[..., None] | None = None) -> QuasiStaticRun:
    """Quasi-static loading with bond breaking, factor by factor at each break (see the module).

    Parameters
    ----------
    problem : cnem.pd.Problem
        BondBased or StateBased with a critical stretch; its Dirichlet values and loads
        are the full load (factor 1).
    factor_max : float
        Largest load factor: the run ends when the next break needs more.
    tol : float
        Relative residual of every CG solve.
    max_solves : int
        Most solves (events and rounds) in all.
    stop : callable ``(steps: list of LoadStep) -> bool``, optional
        Called after every load factor's last round; True ends the run (e.g.
        `cnem.pd.quasistatic.load_drop`).
    keep_damage : bool
        Keep the damage of every step (``n`` floats a step).
    progress : bool, optional
        A bar over the solves (default: when stderr is a terminal).
    callback : callable ``(step: LoadStep, u (n, d)) -> None``, optional
        Called after every step with its equilibrium.

    Returns
    -------
    cnem.pd.quasistatic.QuasiStaticRun
        One `LoadStep` per load factor at which bonds broke (``rounds``: the solves at that
        factor that broke bonds, ``iterations``: CG iterations, ``residual``: the CG
        tolerance reached, ``complete``: False for a last step cut by ``max_solves``,
        whose breaks were not solved again); ``stopped`` is ``"end"`` (the next break
        needs more than ``factor_max``, or nothing is in tension), ``"max_solves"`` or
        ``stop``'s name.

    Raises
    ------
    InputError
        A CPD material, no critical stretch, or bad parameters.
    SolveError
        Free rigid motions.
    """
    if not getattr(getattr(problem, "behaviour", None), "linear", False):
        raise InputError("sequential: expected a BondBased or StateBased problem (a linear "
                         "model between breaks), received "
                         f"{type(problem.material).__name__}; use quasistatic for others")
    factor_max, tol, max_solves = float(factor_max), float(tol), int(max_solves)
    if not (factor_max > 0 and 0 < tol < 1 and max_solves >= 1):
        raise InputError(f"expected factor_max > 0, 0 < tol < 1 and max_solves >= 1, received "
                         f"factor_max={factor_max}, tol={tol}, max_solves={max_solves}")
    b, d, n = problem.body, problem.dim, len(problem.body)
    limit = problem.material.stretch_limit(d, problem.plane, b.horizon)
    if not np.isfinite(limit):
        raise InputError("sequential: the material has no critical stretch; give "
                         "critical_stretch or fracture_energy")
    fixed, values = problem.prescribed()
    K = problem.stiffness()
    loose = free_rigid_motions(K, b.points, fixed)
    if loose:
        raise SolveError("sequential: the Dirichlet conditions leave free the " +
                         "; ".join(loose) + ". Fix them with add_dirichlet")
    driven = fixed[values != 0.0]
    load = problem.load()
    u1 = np.zeros(d * n)
    u1[fixed] = values
    solver, mask = None, None
    steps, rounds, broken, factor, solves = [], 0, 0, 0.0, 0
    stopped = "end"
    bar = tqdm(total=max_solves, desc="PD solves",
               disable=not (sys.stderr.isatty() if progress is None else progress))

    def close_step(complete):
        """Record the state at ``factor`` after its last round."""
        nonlocal rounds, broken
        reaction = np.bincount(driven % d, weights=factor * (K @ u1)[driven], minlength=d)
        steps.append(LoadStep(factor, rounds, broken, solver.iterations, tol, complete,
                              reaction, problem.damage() if keep_damage else None))
        solver.iterations, rounds, broken = 0, 0, 0
        if callback is not None:
            callback(steps[-1], factor * u1.reshape(n, d))
        return stop is not None and stop(steps)

    try:
        while True:
            if solves >= max_solves:
                stopped = "max_solves"
                break
            keep = np.repeat(np.bincount(b.bond_i, weights=problem.alive, minlength=n) > 0, d)
            keep[fixed] = False
            if mask is None or not np.array_equal(keep, mask):     # at the start, or a point
                mask, free = keep, np.flatnonzero(keep)              # came loose: new dofs
                solver = _Solver(problem, free, tol)
            rows = K[free]
            u1[free] = solver.solve(rows[:, free].tocsr(), load[free] - rows[:, fixed] @ values,
                                    u1[free])
            solves += 1
            bar.update(1)
            s1 = _stretches(problem, u1.reshape(n, d))
            over = s1 * factor >= limit * (1.0 - BREAK_TOL)
            if not over.any():                          # an equilibrium: the next event
                if rounds and close_step(True):
                    stopped = getattr(stop, "__name__", "stop")
                    break
                peak = float(s1.max())
                if not peak > 0 or limit / peak > factor_max:
                    break
                factor = limit / peak
                over = s1 * factor >= limit * (1.0 - BREAK_TOL)
            K = _without(problem, K, over)
            rounds += 1
            broken += int(over.sum())
    finally:
        bar.close()
    if rounds:                                          # bonds broken since the last solve
        close_step(False)
    u = factor * u1.reshape(n, d)
    return QuasiStaticRun(problem, u.copy(), damage=problem.damage(), steps=steps,
                          stopped=stopped)
