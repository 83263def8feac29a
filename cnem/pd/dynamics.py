"""Explicit peridynamic dynamics: the stable time step, velocity Verlet with bond
breaking and damage, and adaptive dynamic relaxation.

`Dynamics` is a part of `cnem.pd.Problem`: it reads the problem's body, material,
conditions and the forces of its behaviour (`cnem.pd.behaviour`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..solvers.conditions import per_point, vector_constant
from ..solvers.solution import vector3
from ..solvers.stepping import Prescribed, velocity_verlet
from ..errors import InputError
from .frames import FrameWriter
from .guards import checked_run, diverged, first_non_finite
from .relaxation import relax
from .solution import DynamicRun

if TYPE_CHECKING:
    import os
    from typing import Callable

    from .solution import Relaxation

__all__ = ["Dynamics"]


class Dynamics:
    """Explicit dynamics and dynamic relaxation of a peridynamic problem (a mixin of
    `Problem`)."""

    def stable_time_step(self, safety: float = 0.8) -> float:
        """Silling & Askari's bound ``sqrt(2 rho / sum_j C_ij V_j)`` (the smallest
        over points) times ``safety``."""
        self._linear_only("stable_time_step")
        diag = self.behaviour.stable_diagonal()
        return safety * float(np.sqrt(2.0 * self.material.density / diag.max()))

    def damage(self) -> np.ndarray:
        """``1 - (live bond volume) / (all bond volume)`` per point, ``(n,)``."""
        b = self.body
        total = np.bincount(b.bond_i, weights=self.weight, minlength=len(b))
        live = np.bincount(b.bond_i, weights=self.weight * self.alive, minlength=len(b))
        return 1.0 - live / np.maximum(total, 1e-300)

    def _force_state(self):
        """What `_internal_force` keeps between calls (the behaviour's ``force_state``)."""
        return self.behaviour.force_state()

    def _internal_force(self, u, limit, state):
        """Force per unit volume ``(n, d)``, breaking bonds (returns count broken)."""
        return self.behaviour.internal_force(u, limit, state)

    def run_dynamic(self, dt: float, steps: int, *,
                    velocity: np.ndarray | Callable[..., np.ndarray] | None = None,
                    every: int | None = None, output: str | os.PathLike | None = None,
                    progress: bool | None = None) -> DynamicRun:
        """Explicit velocity Verlet with bond breaking.

        Parameters
        ----------
        dt : float
            Time step (see `stable_time_step`). Above Silling & Askari's bound
            (``stable_time_step(safety=1)``) a `cnem.errors.StabilityWarning`; above
            `cnem.config.DT_LIMIT` times it, refused (`cnem.pd.guards`).
        steps : int
        velocity : (n, d) array_like or callable ``(n, d) -> (n, d)``, optional
            Initial velocity (zero at Dirichlet components; the velocity conditions,
            `cnem.pd.velocity`, hold theirs through the run).
        every : int, optional
            Store a frame (u, damage, energy) every so many steps (default: 10 frames),
            and at the first and last steps.
        output : str or os.PathLike, optional
            A folder or a path stem: every frame is also written to a VTU file
            (``<stem>_<step>.vtu``, see `cnem.pd.frames.FrameWriter`) with the point
            data ``displacement (n, 3)``, ``damage (n,)`` and ``velocity (n, 3)``
            (``z = 0`` in 2-D), and listed with its time in ``<stem>.pvd``.
        progress : bool, optional

        Returns
        -------
        DynamicRun

        Raises
        ------
        InputError
            ``dt`` above `cnem.config.DT_LIMIT` times the stable step.
        DivergenceError
            The displacement or velocity went non-finite (the step and a point are named).
        """
        self._linear_only("run_dynamic")
        b, d, n = self.body, self.dim, len(self.body)
        stable = self.stable_time_step(1.0)
        dt, steps = checked_run(dt, steps, stable)
        limit = self.material.stretch_limit(d, self.plane, b.horizon)
        state = self._force_state()
        prescribed = Prescribed(*self.prescribed(), *self.prescribed_velocity())
        u = np.zeros((n, d))
        v = np.zeros((n, d))
        if velocity is not None:
            velocity = vector_constant(velocity, d, "velocity", "give one velocity vector for "
                                       "every point, (n, d), a constant (d,), or a callable",
                                       points=len(b.points))
            v[:] = per_point(velocity, b.points, d, "velocity")
        prescribed.start(u, v)
        fext = self.load().reshape(n, d) / b.volumes[:, None]
        total_broken = 0

        def forces(u):
            nonlocal total_broken
            force, broken = self._internal_force(u, limit, state)
            total_broken += broken
            return force + fext

        def check(step, u, v):
            if (bad := first_non_finite(u, v)) >= 0:
                raise diverged(step, dt, bad, b.points[bad], stable)

        writer = None if output is None else FrameWriter(output, b.points, steps)
        times, frames, energy, files = [], [], [], []

        def store(step, u, v):
            times.append(step * dt)
            frames.append((u.copy(), self.damage()))
            energy.append(self._energy(u, v))
            if writer is not None:
                files.append(writer.write(step, step * dt, displacement=vector3(u),
                                          damage=frames[-1][1], velocity=vector3(v)))

        velocity_verlet(u, v, dt, steps, forces=forces, mass=self.material.density,
                        prescribed=prescribed, after_step=check, frame=store, every=every,
                        progress=progress, desc="PD steps")
        return DynamicRun(self, u, velocity=v, damage=self.damage(), times=np.array(times),
                          frames=frames, energy=np.array(energy), broken=total_broken,
                          files=files)

    def relax(self, *, tol: float = 1e-8, max_steps: int = 100_000, steps: int = 1,
              every: int | None = None, progress: bool | None = None) -> Relaxation:
        """Quasi-static equilibrium by adaptive dynamic relaxation (Kilic & Madenci 2010),
        with bond breaking: see `cnem.pd.relaxation.relax` for the parameters.

        Returns
        -------
        cnem.pd.relaxation.Relaxation
            ``u (n, d)``, ``damage (n,)``, ``residual_history``, ``iterations``.
        """
        self._linear_only("relax")
        self.static_only("relax")
        return relax(self, tol=tol, max_steps=max_steps, steps=steps, every=every,
                     progress=progress)

    def _energy(self, u, v):
        """Kinetic plus elastic energy (the behaviour's, linearised for the state-based solid)."""
        b = self.body
        kinetic = 0.5 * self.material.density * float(b.volumes @ (v * v).sum(axis=1))
        return kinetic + self.behaviour.elastic_energy(u)
