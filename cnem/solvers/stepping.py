"""Explicit time stepping: velocity Verlet with hooks, for every explicit dynamics.

`velocity_verlet` advances displacements ``u`` and velocities ``v`` (updated in
place) by the kick-drift-kick form of the central difference::

    v += dt/2 a(u)          (half kick)
    u += dt v               (drift), then the prescribed displacements at t = step dt
    a  = f(u) / m           (forces hook)
    v += dt/2 a             (half kick), then the prescribed velocities
    after_step(step, u, v)  (breaking, damage, checks, checkpoints, ...)
    frame(step, u, v)       (at the first step, every ``every`` steps and the last)

The method is second-order accurate in ``dt`` and symplectic: for a linear system
below the stable step ``2 / omega_max`` the energy oscillates about its initial value
and does not drift. What the method integrates — peridynamic bonds, a C-NEM stiffness —
lives in the ``forces`` hook; `Prescribed` holds Dirichlet and prescribed-velocity
dofs (any object with its ``displace`` and ``hold`` methods may take its place).

>>> import numpy as np
>>> u, v = np.array([1.0]), np.array([0.0])            # x'' = -x, x(0) = 1
>>> velocity_verlet(u, v, 1e-3, 1000, forces=lambda u: -u, mass=1.0, progress=False)
>>> bool(abs(u[0] - np.cos(1.0)) < 1e-6)
True
"""

from __future__ import annotations

import sys
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from tqdm.auto import tqdm

from ..errors import InputError, check_count

if TYPE_CHECKING:
    from typing import Callable

__all__ = ["Prescribed", "velocity_verlet"]


def _dofs(a) -> np.ndarray:
    return np.asarray(a, dtype=np.int64).reshape(-1)


def _values(a) -> np.ndarray:
    return np.asarray(a, dtype=float).reshape(-1)


@dataclass(frozen=True, repr=False)
class Prescribed:
    """Prescribed dofs of an explicit run, as indices into the flattened ``u`` and ``v``.

    Parameters
    ----------
    fixed : (k,) int array_like
        Dofs held at ``values`` (Dirichlet conditions), at rest.
    values : (k,) array_like
    moving : (m,) int array_like
        Dofs moved at constant ``speeds``: ``u = speed t``, ``v = speed``. A dof in both
        lists moves (the velocity condition is applied last).
    speeds : (m,) array_like
    """

    fixed: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    values: np.ndarray = field(default_factory=lambda: np.zeros(0))
    moving: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    speeds: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def __post_init__(self):
        for dofs, values in (("fixed", "values"), ("moving", "speeds")):
            object.__setattr__(self, dofs, _dofs(getattr(self, dofs)))
            object.__setattr__(self, values, _values(getattr(self, values)))
            if len(getattr(self, dofs)) != len(getattr(self, values)):
                raise InputError(f"expected as many {values} as {dofs} dofs, received "
                                 f"{len(getattr(self, values))} {values} for "
                                 f"{len(getattr(self, dofs))} dofs; give one value per dof")

    def __repr__(self):
        return f"<Prescribed {len(self.fixed)} fixed dofs, {len(self.moving)} moving dofs>"

    def start(self, u: np.ndarray, v: np.ndarray) -> None:
        """The state at ``t = 0``: the fixed dofs at their values and at rest, the moving
        ones at zero and at their speeds (``u``, ``v`` C-contiguous, updated in place)."""
        u.reshape(-1)[self.fixed] = self.values
        u.reshape(-1)[self.moving] = 0.0
        v.reshape(-1)[self.fixed] = 0.0
        v.reshape(-1)[self.moving] = self.speeds

    def displace(self, u: np.ndarray, time: float) -> None:
        """The prescribed displacements at ``time`` (in place)."""
        u.reshape(-1)[self.fixed] = self.values
        u.reshape(-1)[self.moving] = self.speeds * time

    def hold(self, v: np.ndarray, time: float) -> None:
        """The prescribed velocities at ``time`` (in place)."""
        v.reshape(-1)[self.fixed] = 0.0
        v.reshape(-1)[self.moving] = self.speeds


def velocity_verlet(u: np.ndarray, v: np.ndarray, dt: float, steps: int, *,
                    forces: Callable[[np.ndarray], np.ndarray],
                    mass: float | np.ndarray | None = None,
                    prescribed: Prescribed | None = None,
                    after_step: Callable[[int, np.ndarray, np.ndarray], None] | None = None,
                    frame: Callable[[int, np.ndarray, np.ndarray], None] | None = None,
                    every: int | None = None, start: int = 0, progress: bool | None = None,
                    desc: str = "steps") -> None:
    """Advance ``u`` and ``v`` in place from step ``start`` to step ``steps`` by
    velocity Verlet.

    Parameters
    ----------
    u : (n, d) or (n,) ndarray
        Displacements at step ``start`` (C-contiguous float64), updated in place.
    v : ndarray, shape of ``u``
        Velocities at step ``start``, updated in place.
    dt : float
        Time step; step ``k`` is at time ``k dt``.
    steps : int
        The last step (the number of steps when ``start`` is 0).
    forces : callable ``(u) -> f``
        The force on every dof at ``u`` (the same shape), called once before the
        first step and once per step. It may change state (break bonds); a force
        that needs more than ``u`` (ghost rows around owned ones) closes over the
        larger array of which ``u`` is a view.
    mass : float or ndarray broadcastable to ``u``, optional
        Mass (or density, with forces per unit volume) per dof or per point:
        the acceleration is ``forces(u) / mass``. Without it ``forces`` returns
        the accelerations.
    prescribed : Prescribed, optional
        Applied after every drift (``displace(u, time)``) and every second half
        kick (``hold(v, time)``); any object with these two methods will do. The
        initial state is the caller's (`Prescribed.start`).
    after_step : callable ``(step, u, v) -> None``, optional
        Called after every step, before its frame: checks (raise to stop),
        damage updates, checkpoints.
    frame : callable ``(step, u, v) -> None``, optional
        Called at ``start`` (after the first force evaluation), at the steps that
        are multiples of ``every`` and at the last step.
    every : int, optional
        Default: a tenth of ``steps`` (at least 1).
    start : int
        The step ``u`` and ``v`` are at (a restarted run continues from it).
    progress : bool, optional
        tqdm bar (default: when stderr is a terminal).
    desc : str
        The bar's label.

    Raises
    ------
    InputError
        ``dt <= 0``, ``steps < start`` or ``every < 1``, or ``u`` and ``v`` not
        C-contiguous arrays of one shape.
    """
    dt, start = float(dt), check_count("start", start, minimum=0)
    steps = check_count("steps", steps, minimum=0)
    every = max(1, steps // 10) if every is None else check_count("every", every)
    if not dt > 0 or steps < start or every < 1:
        raise InputError(f"expected dt > 0, steps >= start and every >= 1, received "
                         f"dt={dt}, steps={steps}, start={start}, every={every}")
    if u.shape != v.shape or not (u.flags.c_contiguous and v.flags.c_contiguous):
        raise InputError(f"expected u and v as C-contiguous arrays of one shape (they are "
                         f"updated in place), received shapes {u.shape} and {v.shape}; "
                         f"pass np.ascontiguousarray copies and read them back")

    def acceleration():
        return forces(u) if mass is None else forces(u) / mass

    acc = acceleration()
    if frame is not None:
        frame(start, u, v)
    show = sys.stderr.isatty() if progress is None else progress
    for step in tqdm(range(start + 1, steps + 1), desc=desc, disable=not show, leave=False):
        v += 0.5 * dt * acc
        u += dt * v
        if prescribed is not None:
            prescribed.displace(u, step * dt)
        acc = acceleration()
        v += 0.5 * dt * acc
        if prescribed is not None:
            prescribed.hold(v, step * dt)
        if after_step is not None:
            after_step(step, u, v)
        if frame is not None and (step % every == 0 or step == steps):
            frame(step, u, v)
