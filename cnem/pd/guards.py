"""Guards of explicit peridynamic dynamics, shared by `cnem.pd.Problem` and
`cnem.pd.distributed.Problem`: the time step against the stable one, and the state
checked for non-finite values at every step.

The stable step is Silling & Askari's bound ``sqrt(2 rho / sum_j C_ij V_j)``
(`stable_time_step` with ``safety=1``). Above it the central difference may still be
stable (the bound is a sufficient condition), so a step up to `cnem.config.DT_LIMIT`
times the bound runs with a `cnem.errors.StabilityWarning`; a larger one is refused.

>>> check_time_step(0.5, 1.0)
>>> try:
...     check_time_step(100.0, 1.0)
... except InputError as exc:
...     print(str(exc)[:44])
dt = 100 is 100 times the stable time step 1
"""

from __future__ import annotations

import warnings

import numpy as np

from .. import config
from ..errors import DivergenceError, InputError, StabilityWarning, check_count

__all__ = ["check_time_step", "checked_run", "checked_schedule", "first_non_finite",
           "diverged"]


def check_time_step(dt: float, stable: float, *, stacklevel: int = 3) -> None:
    """Refuse ``dt`` above `cnem.config.DT_LIMIT` times the stable step, warn above it.

    Parameters
    ----------
    dt : float
        The time step asked for.
    stable : float
        Silling & Askari's bound (``stable_time_step(safety=1)``).

    Raises
    ------
    InputError
        ``dt > DT_LIMIT * stable`` (the message gives both).
    """
    if dt <= stable:
        return
    ratio = dt / stable
    if ratio > config.DT_LIMIT:
        raise InputError(
            f"dt = {dt:.6g} is {ratio:.3g} times the stable time step {stable:.6g} "
            f"(Silling & Askari's bound; expected at most {config.DT_LIMIT:g} times it): the "
            f"explicit integration would blow up. Use dt <= {stable:.6g}, e.g. "
            f"problem.stable_time_step() (0.8 times it), or raise cnem.config.DT_LIMIT")
    warnings.warn(f"dt = {dt:.6g} is {ratio:.3g} times the stable time step {stable:.6g} "
                  f"(Silling & Askari's bound): the run may be unstable; the state is checked "
                  f"at every step. Use dt <= {stable:.6g} to be safe",
                  StabilityWarning, stacklevel=stacklevel)


def checked_run(dt: float, steps: int, stable: float) -> tuple[float, int]:
    """``(dt, steps)`` of an explicit run as numbers, after `check_time_step`.

    Raises
    ------
    InputError
        ``dt <= 0``, ``steps < 1``, or ``dt`` above `cnem.config.DT_LIMIT` times ``stable``.
    """
    dt, steps = float(dt), check_count("steps", steps)
    if not dt > 0 or steps < 1:
        raise InputError(f"expected dt > 0 and steps >= 1, received dt={dt}, steps={steps}")
    check_time_step(dt, stable, stacklevel=4)
    return dt, steps


def checked_schedule(t_end: float, frame_every: float) -> tuple[float, float]:
    """The simulated time of a run and the time between its stored frames, checked.

    Returns
    -------
    t_end, frame_every : float

    Raises
    ------
    InputError
        ``t_end`` not positive, or ``frame_every`` outside ``(0, t_end]``.
    """
    t_end, frame_every = float(t_end), float(frame_every)
    if not np.isfinite(t_end) or t_end <= 0:
        raise InputError(f"t_end: expected a positive time in seconds, received {t_end}")
    if not 0 < frame_every <= t_end:
        raise InputError(f"frame_every: expected a time in (0, t_end = {t_end:g}] s, received "
                         f"{frame_every}")
    return t_end, frame_every


def first_non_finite(*arrays: np.ndarray) -> int:
    """The first row holding a non-finite value in any of ``arrays`` (each ``(n, d)``),
    or -1."""
    bad = np.zeros(len(arrays[0]), dtype=bool)
    for a in arrays:
        bad |= ~np.isfinite(a).all(axis=1)
    return int(np.argmax(bad)) if bad.any() else -1


def diverged(step: int, dt: float, point: int, where: np.ndarray, stable: float) -> DivergenceError:
    """The `DivergenceError` of a run whose displacement or velocity went non-finite at
    ``step`` at ``point`` (global number) located at ``where``."""
    at = "(" + ", ".join(f"{c:.6g}" for c in where) + ")"
    return DivergenceError(
        f"explicit dynamics diverged: the displacement or velocity of point {point} at {at} "
        f"is not finite at step {step} (t = {step * dt:.6g}); dt = {dt:.6g}, stable time "
        f"step {stable:.6g}. Use a smaller dt (problem.stable_time_step()), or check the "
        f"loads, velocities and material constants (they must keep the forces finite)",
        step=step, point=point)
