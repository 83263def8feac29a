"""The one Newton solver: load steps, line search, inexact linear solves, residual history.

Every nonlinear static problem (peridynamics with CPD, finite-strain C-NEM next) gives
its internal forces and tangent as ``evaluate(u, tangent) -> (f_int, K or None)``; `newton`
finds ``f_int(u) = f_ext`` on the free dofs with the prescribed values held, ramping the
Dirichlet values and the loads in equal load steps. Each correction is one constrained
linear solve (`cnem.solvers.constrained.solve_constrained`).

>>> import numpy as np, scipy.sparse as sp
>>> def evaluate(u, tangent):          # a spring whose force is u + u^3, pulled by 2
...     return u + u ** 3, sp.csr_matrix(1.0 + 3.0 * u[None, :] ** 2) if tangent else None
>>> u, history = newton(evaluate, np.array([2.0]), [], [], points=None)
>>> float(u[0]), len(history)
(1.0, 1)
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .. import config
from ..errors import ConvergenceError, InputError, SolveError, check_count
from .condensation import free_dofs
from .constrained import check_supports, solve_constrained

if TYPE_CHECKING:
    from typing import Callable

    import scipy.sparse as sp
    from numpy.typing import ArrayLike

__all__ = ["newton", "LINE_SEARCH_HALVINGS"]

#: Most step halvings of the backtracking line search of `newton`.
LINE_SEARCH_HALVINGS = 10


def newton(evaluate: Callable[[np.ndarray, bool], tuple[np.ndarray, sp.spmatrix | None]],
           load: np.ndarray, fixed: ArrayLike, values: ArrayLike, *,
           points: np.ndarray | None, pattern: sp.spmatrix | None = None,
           initial: ArrayLike | None = None, tol: float = 1e-10, steps: int = 1,
           max_iterations: int = 20, line_search: bool = False, linear: bool = False,
           halvings: int = LINE_SEARCH_HALVINGS,
           values_at: Callable[[float], np.ndarray] | None = None,
           on_step: Callable[[int, np.ndarray], None] | None = None,
           options: Callable[[np.ndarray], dict] | None = None
           ) -> tuple[np.ndarray, list[list[float]]]:
    """Newton-Raphson with the exact tangent, Dirichlet values and loads ramped in
    ``steps`` equal increments (the Dirichlet values along ``values_at`` when given).

    The residual is ``R(u) = f_int(u) - f_ext`` on the free dofs. Each load step starts
    with a tangent predictor: the increments of the Dirichlet values and loads, spread
    over the free dofs by a solve with the last tangent; its linearised residual is the
    step's first entry. A step has converged when ``|R| <= tol`` times the largest of the
    norms of its load, of the reactions at the prescribed dofs and of that first entry.
    Nonlinear problems solve each correction to a relative tolerance
    ``min(NEWTON_FORCING, |R| / reference)`` (`cnem.config`; inexact Newton, still
    quadratic), linear ones to ``min(tol, NEWTON_INNER_FLOOR)``.

    Parameters
    ----------
    evaluate : callable ``(u (N,), tangent: bool) -> (f_int (N,), K (N, N) sparse or None)``
        Internal forces at ``u`` and, when ``tangent`` is True, their derivative
        (symmetric, positive definite on the free dofs near the solution).
    load : (N,) ndarray
        External forces of the whole load.
    fixed : (k,) int array_like
        Prescribed dofs, distinct.
    values : (k,) array_like
        Their values under the whole load.
    points : (n, d) ndarray or None
        The nodes, whose ``d n`` dofs come first (node-major): the supports are checked
        once for free rigid motions and the rigid motions are the solver's near-null
        space. None for a system without nodes.
    pattern : sparse (N, N), optional
        A matrix with the tangent's pattern for the support check (default: the tangent
        at ``initial``).
    initial : (N,) array_like, optional
        Starting values (the prescribed values replace theirs); zero by default.
    tol : float
    steps : int
        Load steps.
    max_iterations : int
        Corrections allowed per load step.
    line_search : bool
        Backtrack along each correction (halving the step up to ``halvings`` times)
        until the residual norm decreases.
    linear : bool
        ``f_int = K u`` with a constant ``K``: every correction is solved to round-off.
    halvings : int
        Most halvings of the line search.
    values_at : callable ``(factor: float) -> (k,) ndarray``, optional
        The prescribed values at the load factor ``factor = step / steps`` (a rigid
        rotation of a face by ``factor`` times an angle, say), in place of the linear
        ramp ``factor * values``; ``values`` are then its values at 1.
    on_step : callable ``(step, u (N,)) -> None``, optional
        Called after each converged load step ``1..steps`` with a copy of ``u``.
    options : callable, optional
        ``options(free) -> dict``: the linear solver's keywords for the corrections
        (a preconditioner, ...), as in `cnem.solvers.constrained.solve_constrained`.

    Returns
    -------
    u : (N,) ndarray
    history : list of list of float
        The residual norms of the free dofs at each Newton iterate, one list per load step.

    Raises
    ------
    InputError
        ``steps`` or ``max_iterations`` below 1, or ``values_at`` returning other than
        one finite value per prescribed dof.
    SolveError
        Rigid motions not fixed (named), or a linear solve that fails.
    ConvergenceError
        A load step that does not converge, or whose residual goes non-finite (named,
        with its residuals; the error's ``history`` holds those of every load step so far).
    """
    steps = check_count("steps", steps)
    max_iterations = check_count("max_iterations", max_iterations)
    tol = float(tol)
    if not (np.isfinite(tol) and tol > 0):
        raise InputError(f"tol: expected a positive relative residual, received {tol}; "
                         f"pass e.g. 1e-10")
    load = np.asarray(load, dtype=float).reshape(-1)
    fixed = np.asarray(fixed, dtype=np.int64).reshape(-1)
    values = np.asarray(values, dtype=float).reshape(-1)
    size = len(load)
    u = np.zeros(size) if initial is None else np.asarray(initial, float).reshape(-1).copy()
    free = free_dofs(size, fixed)
    start = evaluate(u, True) if pattern is None else None
    if points is not None:
        check_supports(start[1] if pattern is None else pattern, points, fixed)
    f, Kt = evaluate(u, True) if start is None else start

    def correction(rhs, rtol):
        """``K_ff x_f = rhs_f`` with ``x`` zero at the prescribed dofs, ``(N,)``."""
        return solve_constrained(Kt, rhs, fixed, np.zeros(len(fixed)), points=points,
                                 tol=rtol, options=options, check=False)

    history = []
    for step in range(1, steps + 1):
        step_load = step / steps * load
        target = step / steps * values if values_at is None else \
            _path_values(values_at, step / steps, len(fixed))
        jump = np.zeros(size)
        jump[fixed] = target - u[fixed]
        residual = f - step_load + Kt @ jump                 # linearised, on the free dofs
        u[fixed] = target
        res = [float(np.linalg.norm(residual[free]))]
        while not (res[-1] <= tol * (ref := _reference(step_load[free], f[fixed], res))
                   or res[-1] == 0.0):
            if not np.isfinite(res[-1]):
                raise ConvergenceError(
                    f"load step {step} of {steps}, Newton iteration {len(res) - 1}: the "
                    f"internal forces are not finite (an interaction inverted or collapsed "
                    f"where its energy is undefined); try more load steps or "
                    f"line_search=True", history + [res])
            if len(res) > max_iterations:
                raise ConvergenceError(
                    f"Newton did not converge in load step {step} of {steps}: residual "
                    f"{res[-1]:.3e} (wanted {tol * ref:.3e}) after {len(res) - 1} "
                    f"iteration(s), residuals {', '.join(f'{r:.2e}' for r in res)}; try "
                    f"more load steps, line_search=True or a larger max_iterations",
                    history + [res])
            floor = config.NEWTON_INNER_FLOOR
            rtol = min(tol, floor) if linear else min(config.NEWTON_FORCING,
                                                      max(res[-1] / ref, floor))
            rhs = np.zeros(size)
            rhs[free] = residual[free]
            try:
                du = correction(rhs, rtol)
            except SolveError as exc:
                raise SolveError(f"load step {step} of {steps}, Newton iteration "
                                 f"{len(res)}: {exc}") from exc
            u = _update(u, du, free, step_load, evaluate, res[-1],
                        halvings if line_search else 0)
            f, Kt = evaluate(u, True)
            residual = f - step_load
            res.append(float(np.linalg.norm(residual[free])))
        history.append(res)
        if on_step is not None:
            on_step(step, u.copy())
    return u, history


def _path_values(values_at, factor, count):
    """``values_at(factor)``, checked to be ``count`` finite values."""
    target = np.asarray(values_at(factor), dtype=float)
    if target.shape != (count,) or not np.isfinite(target).all():
        raise InputError(f"values_at({factor:g}): expected {count} finite values, one per "
                         f"prescribed dof, received shape {target.shape}"
                         f"{'' if target.shape != (count,) else ' with NaN or inf'}; return "
                         f"the prescribed values at that load factor")
    return target


def _reference(load, reactions, res):
    """What a load step's residual is measured against: the largest of its load, the
    reactions at the prescribed dofs (round-off in the residual scales with the
    internal forces) and its first residual."""
    return max(float(np.linalg.norm(load)), float(np.linalg.norm(reactions)), res[0])


def _update(u, du, free, load, evaluate, current, halvings):
    """``u - du`` on the free dofs or, with ``halvings > 0``, the first of
    ``u - du / 2^k`` (k <= halvings) whose residual norm is below ``current`` (the
    last one tried if none is)."""
    for k in range(halvings + 1):
        trial = u.copy()
        trial[free] -= du[free] / 2 ** k
        if not halvings or np.linalg.norm(
                (evaluate(trial, False)[0] - load)[free]) < current:
            break
    return trial
