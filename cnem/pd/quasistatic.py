"""Quasi-static peridynamic fracture: load steps, each relaxed with bond breaking.

The problem's Dirichlet values and loads are multiplied by a rising sequence of
load factors. Each load step starts from the previous equilibrium and is
solved by the adaptive dynamic relaxation of `cnem.pd.relaxation` (Kilic &
Madenci 2010); then the bonds stretched beyond the material's critical stretch
(`cnem.pd.critical_stretch`: from ``G_c`` by model) break and the body settles
again, round after round, until an equilibrium breaks no more bonds or
``max_rounds`` rounds have broken some (the step is then reported as not
complete: its last state is settled, some bonds may still be over-stretched and
break at the start of the next step). Bonds break at equilibrium only, never
in the fictitious transient. Every step records its load factor, the rounds and
bonds broken, the ADR iterations, the reaction at the driven dofs and the
damage, so an unstable crack run (many rounds at one load) shows as such.

>>> import numpy as np, cnem.pd as pd
>>> h = 0.1
>>> g = np.arange(0, 1 + 1e-9, h)
>>> pts = np.array([(x, y) for x in g for y in g])
>>> prob = pd.Problem(pd.Body(pts, h * h, 3.015 * h), pd.BondBased(1.0,
...                   critical_stretch=0.01))
>>> prob.add_dirichlet(lambda p: p[:, 0] < 0.3, 0)                    # layers one horizon deep
>>> prob.add_dirichlet(lambda p: (p[:, 0] < 1e-9) & (p[:, 1] < 1e-9), 1)
>>> prob.add_dirichlet(lambda p: p[:, 0] > 0.7, 0, 0.02)     # free part 0.4 long: strain 0.05
>>> run = quasistatic(prob, [0.1, 0.5])                        # half and 2.5 times critical
>>> [s.broken > 0 for s in run.steps], run.stopped
([False, True], 'end')
"""

from __future__ import annotations

import sys
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from tqdm.auto import tqdm

from ..errors import InputError
from .relaxation import System
from .solution import PointSolution

if TYPE_CHECKING:
    from typing import Any, Callable, Sequence

__all__ = ["quasistatic", "QuasiStaticRun", "LoadStep", "load_drop"]


@dataclass(frozen=True, eq=False)
class LoadStep:
    """One load step of `quasistatic`.

    Attributes
    ----------
    factor : float
        Load factor (the Dirichlet values and loads are multiplied by it).
    rounds : int
        Break-and-settle rounds that broke bonds.
    broken : int
        Bonds broken in the step.
    iterations : int
        ADR iterations of the step.
    residual : float
        Out-of-balance force norm at its end.
    complete : bool
        False when ``max_rounds`` rounds all broke bonds (the step was cut short).
    reaction : (d,) ndarray
        Resultant of the forces holding the driven dofs (those with a non-zero
        prescribed value) at the step's equilibrium.
    damage : (n,) ndarray or None
        Damage of every point (`Problem.damage`) at its end (None unless kept).
    """

    factor: float
    rounds: int
    broken: int
    iterations: int
    residual: float
    complete: bool
    reaction: np.ndarray
    damage: np.ndarray | None = None


@dataclass(eq=False, repr=False)
class QuasiStaticRun(PointSolution):
    """Result of `quasistatic`: the last equilibrium and every load step.

    Attributes
    ----------
    damage : (n,) ndarray
        Damage at the end.
    steps : list of LoadStep
    stopped : str
        ``"end"`` (every factor was applied) or ``stop``'s name (it ended the run).
    """

    damage: np.ndarray = None
    steps: list = field(default_factory=list)
    stopped: str = "end"

    def array(self, name: str) -> np.ndarray:
        """A `LoadStep` attribute over the steps, e.g. ``array("reaction")`` ``(s, d)``."""
        return np.array([getattr(s, name) for s in self.steps])

    def fields(self) -> tuple:
        """`Solution.fields` with ``damage`` at the points."""
        point_data, cell_data = super().fields()
        return {**point_data, "damage": self.damage}, cell_data

    def __repr__(self):
        return (f"<QuasiStaticRun {len(self.u)} points, {len(self.steps)} load step(s) to "
                f"factor {self.steps[-1].factor:g}, {int(self.array('broken').sum())} bonds "
                f"broken, stopped: {self.stopped}>")


def load_drop(fraction: float) -> Callable[..., bool]:
    """A ``stop`` for `quasistatic`: the resultant reaction (its norm) has fallen below
    ``fraction`` of its peak, after the peak (the body has come apart).

    Raises
    ------
    InputError
        ``fraction`` not in (0, 1).
    """
    fraction = float(fraction)
    if not 0.0 < fraction < 1.0:
        raise InputError(f"load_drop: expected a fraction in (0, 1), received {fraction}")

    def stop(steps: list) -> bool:
        norms = [float(np.linalg.norm(s.reaction)) for s in steps]
        return bool(steps[-1].broken or steps[-1].rounds) and norms[-1] < fraction * max(norms)

    stop.__name__ = "load_drop"
    return stop


def quasistatic(problem: Any, factors: Sequence[float], *, tol: float = 1e-5,
                max_steps: int = 100_000, max_rounds: int = 200,
                stop: Callable[..., bool] | None = None, keep_damage: bool = True,
                progress: bool | None = None,
                callback: Callable[..., None] | None = None) -> QuasiStaticRun:
    """Quasi-static loading with bond breaking, each step relaxed to equilibrium (ADR).

    Parameters
    ----------
    problem : cnem.pd.Problem
        BondBased or StateBased with a critical stretch (``critical_stretch`` or
        ``fracture_energy``); its Dirichlet values and loads are the full load.
    factors : (s,) array_like
        Load factors of the steps, positive and increasing.
    tol : float
        Relative equilibrium tolerance of every settle (see `cnem.pd.relaxation.relax`).
    max_steps : int
        ADR iterations allowed per load step (all its rounds).
    max_rounds : int
        Most break-and-settle rounds per step.
    stop : callable ``(steps: list of LoadStep) -> bool``, optional
        Called after every step; True ends the run (e.g. `load_drop`).
    keep_damage : bool
        Keep every step's damage field.
    progress : bool, optional
        A bar over the steps (default: when stderr is a terminal).
    callback : callable ``(step: LoadStep, u (n, d)) -> None``, optional
        Called after every step with its equilibrium.

    Returns
    -------
    QuasiStaticRun

    Raises
    ------
    InputError
        Factors not positive and increasing, or bad tolerances.
    SolveError
        Free rigid motions, or a step that has not settled within ``max_steps``.
    """
    factors = np.asarray(factors, dtype=float).reshape(-1)
    if len(factors) == 0 or not (np.isfinite(factors).all() and factors[0] > 0 and
                                 (np.diff(factors) > 0).all()):
        raise InputError(f"factors: expected positive increasing load factors, received "
                         f"{factors.tolist()[:6]}{'...' if len(factors) > 6 else ''}")
    tol, max_steps, max_rounds = float(tol), int(max_steps), int(max_rounds)
    if not tol > 0 or max_steps < 1 or max_rounds < 1:
        raise InputError(f"expected tol > 0 and max_steps, max_rounds >= 1, received tol={tol}, "
                         f"max_steps={max_steps}, max_rounds={max_rounds}")
    system = System(problem)
    d = problem.dim
    driven = system.fixed[system.values != 0.0]
    steps, ended = [], []
    bar = tqdm(total=len(factors), desc="PD load steps",
               disable=not (sys.stderr.isatty() if progress is None else progress))

    def after_step(index, factor, **record):
        reaction = np.bincount(driven % d, weights=system.reactions()[driven], minlength=d)
        steps.append(LoadStep(float(factor), reaction=reaction,
                              damage=problem.damage() if keep_damage else None, **record))
        bar.update(1)
        bar.set_postfix(factor=f"{factor:.4g}", broken=record["broken"], refresh=False)
        if callback is not None:
            callback(steps[-1], system.u)
        if stop is not None and stop(steps):
            ended.append(getattr(stop, "__name__", "stop"))
            return True
        return False

    try:
        system.run(tol=tol, max_steps=max_steps, every=10, show=False, fractions=factors,
                   max_rounds=max_rounds, after_step=after_step)
    finally:
        bar.close()
    return QuasiStaticRun(problem, system.u.copy(), damage=problem.damage(), steps=steps,
                          stopped=ended[0] if ended else "end")
