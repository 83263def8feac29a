"""Adaptive dynamic relaxation over MPI ranks (`cnem.pd.relaxation` with global sums).

The algorithm is that of `cnem.pd.relaxation.relax` (Kilic & Madenci 2010): every
rank updates the free dofs of its own points, and the norms and the two dot
products of the adaptive damping are summed over the ranks (allreduce). The
fictitious density is a quarter of the stiffness rows' absolute sums, exact for
the PMB and bounded from above for the state-based solid
(`LocalOperators.row_bound`); the settled equilibrium is the same.
"""

from __future__ import annotations

import logging
import sys

import numpy as np
from tqdm.auto import tqdm

from ..relaxation import _settle, unsettled
from ..solution import Relaxation

__all__ = ["relax"]

log = logging.getLogger(__name__)


def relax(problem, *, tol=1e-8, max_steps=100_000, steps=1, every=None, progress=None):
    """Quasi-static equilibrium by ADR on the ranks; parameters as `cnem.pd.relaxation.relax`.

    Returns
    -------
    cnem.pd.relaxation.Relaxation
        ``u (n, d)`` and ``damage (n,)`` on rank 0 (None on the others),
        ``residual_history``, ``iterations``, ``broken`` on every rank.

    Raises
    ------
    SolveError
        A load step that has not settled within ``max_steps`` iterations (the
        residual reached is given). Unlike the serial solver, free rigid motions are
        not detected beforehand: they show as a load step that does not settle.
    """
    tol, max_steps, steps = float(tol), int(max_steps), int(steps)
    every = 10 if every is None else int(every)
    if not tol > 0 or max_steps < 1 or steps < 1 or every < 1:
        raise ValueError(f"expected tol > 0 and max_steps, steps, every >= 1, received tol={tol}, "
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
    broken = 0

    def forces(breaking=np.inf):
        flat[free] = x
        body.halo.exchange(u)
        force, count = problem.internal_force(u, breaking)
        return external + volumes * force.reshape(-1)[free], problem.comm.allreduce(count)

    body.halo.exchange(u)
    noise = 10.0 * problem.norm(volumes * problem.internal_force(u, np.inf)[0].reshape(-1)[free])
    show = (sys.stderr.isatty() if progress is None else progress) and problem.root
    history, total = [], 0
    for step in range(1, steps + 1):
        frac = step / steps
        flat[fixed] = frac * values
        external[:] = frac * load[free]
        start = problem.norm(forces()[0])
        scale = problem.norm(external) or start
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

        while True:
            norm = _settle(x, lambda: forces()[0], density, target, max_steps - used, record,
                           dot=lambda a, b: problem.allsum(np.dot(a, b)))
            if norm > target:
                bar.close()
                raise unsettled(step, norm, scale, target, max_steps)
            count = forces(limit)[1]
            if not count:
                break
            broken += count
        bar.close()
        if used % every:
            res.append(norm)
        log.info("ADR load step %d: %d iterations, residual %.3e", step, used, norm)
        history.append(res)
        total += used
    flat[free] = x
    return Relaxation(problem, problem.gather(u[:o]), damage=problem.gather(problem.damage()),
                      residual_history=history, iterations=total, broken=broken)
