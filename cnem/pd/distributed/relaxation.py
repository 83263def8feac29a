"""Adaptive dynamic relaxation over MPI ranks (`cnem.pd.relaxation` with global sums).

The algorithm is that of `cnem.pd.relaxation.relax` (Kilic & Madenci 2010): every
rank updates the free dofs of its own points, and the norms and the two dot
products of the adaptive damping are summed over the ranks (allreduce). The
fictitious density is a quarter of the stiffness rows' absolute sums, exact for
the PMB and bounded from above for the state-based solid
(`LocalOperators.row_bound`), raised where it grows after bonds broke (a state-based
point that lost bonds takes the moment tensor of its live bonds); the settled
equilibrium is the same.
"""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING

import numpy as np

from ..relaxation import force_round_off, load_steps
from ...errors import InputError, check_count
from ..solution import Relaxation

if TYPE_CHECKING:
    from typing import Any

__all__ = ["relax"]


def relax(problem: Any, *, tol: float = 1e-8, max_steps: int = 100_000, steps: int = 1,
          every: int | None = None, progress: bool | None = None) -> Relaxation:
    """Quasi-static equilibrium by ADR on the ranks; parameters as `cnem.pd.relaxation.relax`.

    Returns
    -------
    cnem.pd.relaxation.Relaxation
        ``u (n, d)`` and ``damage (n,)`` on rank 0 (None on the others),
        ``residual_history``, ``iterations``, ``broken`` on every rank.

    Raises
    ------
    ConvergenceError
        A load step that has not settled within ``max_steps`` iterations, or whose
        residual went non-finite (the residual reached is given, the residual
        history is the error's ``history``). Unlike the serial solver, free rigid motions are
        not detected beforehand: they show as a load step that does not settle.
    """
    tol, max_steps = float(tol), check_count("max_steps", max_steps)
    steps = check_count("steps", steps)
    every = 10 if every is None else check_count("every", every)
    if not tol > 0 or max_steps < 1 or steps < 1 or every < 1:
        raise InputError(f"expected tol > 0 and max_steps, steps, every >= 1, received tol={tol}, "
                         f"max_steps={max_steps}, steps={steps}, every={every}")
    body, d, o = problem.body, problem.dim, problem.body.n_owned
    fixed, values = problem.owned_prescribed()
    free = np.setdiff1d(np.arange(d * o), fixed)
    density = 0.25 * problem.ops.row_bound().reshape(-1)[free]
    limit = problem.material.stretch_limit(d, problem.plane, body.horizon)
    volumes = np.repeat(body.volumes[:o], d)[free]
    load = problem.load().reshape(-1)
    u = np.zeros((len(body.points), d))
    flat = u[:o].reshape(-1)
    x, external = np.zeros(len(free)), np.zeros(len(free))

    def forces(breaking=np.inf):
        flat[free] = x
        force, count = problem.internal_force(u, breaking)
        count = problem.comm.allreduce(count)
        if count and problem.ops.grows_when_breaking:        # the rows may grow (as serial)
            np.maximum(density, 0.25 * problem.ops.row_bound().reshape(-1)[free], out=density)
        return external + volumes * force.reshape(-1)[free], count

    at_rest = np.repeat(body.volumes[:o], d) * problem.internal_force(u, np.inf)[0].reshape(-1)
    noise = 10.0 * problem.norm(force_round_off(problem, problem.ops.round_off_stiffness,
                                                at_rest, o)[free])

    def prescribe(fraction):
        flat[fixed] = fraction * values

    show = (sys.stderr.isatty() if progress is None else progress) and problem.root
    history, total, broken = load_steps(x, forces, density, external, load[free], prescribe,
                                        tol=tol, noise=noise, limit=limit, steps=steps,
                                        max_steps=max_steps, every=every, show=show,
                                        dot=lambda a, b: problem.allsum(np.dot(a, b)))
    flat[free] = x
    return Relaxation(problem, problem.gather(u[:o]), damage=problem.gather(problem.damage()),
                      residual_history=history, iterations=total, broken=broken)
