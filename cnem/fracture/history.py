"""The record of a crack-growth run: one `Step` per increment, events, and the `GrowthHistory`.

Every tip of the initial domain keeps its row ``i`` in every step's arrays
(``tips (t, 2)``, ``K (t, 2)``, ...); a tip that stopped growing is inactive
(``active[i]`` False) and its K's are NaN from then on.
"""

from __future__ import annotations

import csv
import json
import pathlib
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from .._aliases import renamed_attributes
from ..solvers.series import write_pvd

if TYPE_CHECKING:
    import os
    from typing import Any, Literal
    from matplotlib.figure import Figure

__all__ = ["GrowthEvent", "Step", "GrowthHistory", "EVENT_KINDS"]

#: Old names (one release): see `cnem._aliases`.
__getattr__ = renamed_attributes(__name__, {"CrackPath": (__name__, "GrowthHistory")})

#: What can happen to a tip, by name.
EVENT_KINDS = {
    "boundary": "the tip reached the outer boundary and stopped (the crack is an edge crack)",
    "hole": "the tip reached a hole and stopped (the crack is an edge crack)",
    "joined": "the tip met the tip of another crack and the two cracks became one",
    "crack": "the tip met another crack away from its tips and stopped short of it "
             "(a T-junction of cracks is not a Domain cnem can represent)",
    "closed": "K_I <= 0: the crack is closed at the tip, which does not grow in this step",
    "sharp_kink": "the kink is sharper than max_kink, or the criterion found no opening "
                  "direction inside its range",
    "left_domain": "the increment would leave the domain: it was cut where it meets the boundary",
    "split": "the cracks cut the body apart and, with continue_with, the loose pieces were "
             "dropped (tip -1: the whole body)",
    "predictor": "scheme=\"corrector\": the tip's trial segment met the boundary, a hole or a "
                 "crack, or its trial tip found no direction; the step took the predictor's "
                 "(explicit) direction",
}


@dataclass(frozen=True)
class GrowthEvent:
    """Something that happened to a tip in a step.

    Attributes
    ----------
    kind : str
        A key of `EVENT_KINDS`.
    step : int
    tip : int
        Row of the tip (-1 for the whole body).
    point : (2,) ndarray
    message : str
    """

    kind: str
    step: int
    tip: int
    point: np.ndarray
    message: str

    def __str__(self):
        return f"step {self.step}, tip {self.tip}: {self.kind}: {self.message}"


@dataclass(frozen=True, repr=False)
class Step:
    """One increment: the state before growing and how each tip grew.

    Attributes
    ----------
    tips : (t, 2) ndarray
        Tip positions before growing.
    active : (t,) bool ndarray
        Tips that were still growing.
    K : (t, 2) ndarray
        ``[K_I, K_II]`` at the tips (at the load of ``setup``, load factor 1).
    K_eq : (t,) ndarray
        Equivalent SIF of the criterion.
    angle : (t,) ndarray
        Kink angle, radians, positive counter-clockwise from the crack direction.
    increment : (t,) ndarray
        Length of the segment added at each tip (0 for a tip that stopped).
    crack_length : (t,) ndarray
        Length of each tip's crack polyline before growing.
    load_factor : (t,) ndarray
        ``K_Ic / K_eq`` (the load multiplier at which the tip grows), NaN without ``K_Ic``.
    cycles : float
        Load cycles spent on this step's growth (Paris law), NaN without ``paris``.
    measure : float
        ``measure(solution)`` of the run at load factor 1 (NaN without ``measure``).
    events : tuple of GrowthEvent
    solution : ElasticSolution or None
        The solution of this step (kept with ``keep=True``).
    correction : (t,) ndarray
        Turn of each new segment from ``angle`` (radians): half the kink at the
        trial tip with ``scheme="corrector"``, 0 otherwise; the segment leaves the
        tip at ``angle + correction`` from the crack direction.
    """

    tips: np.ndarray
    active: np.ndarray
    K: np.ndarray
    K_eq: np.ndarray
    angle: np.ndarray
    increment: np.ndarray
    crack_length: np.ndarray
    load_factor: np.ndarray
    cycles: float = np.nan
    measure: float = np.nan
    events: tuple = ()
    solution: object = None
    correction: np.ndarray = None

    @property
    def critical_load_factor(self) -> float:
        """float: the smallest load factor over the active tips (NaN if none)."""
        lf = self.load_factor[self.active]
        return float(np.nanmin(lf)) if lf.size and np.isfinite(lf).any() else np.nan

    def __repr__(self):
        return (f"<Step {int(self.active.sum())} of {len(self.active)} tips growing, "
                f"K_eq max {np.nanmax(self.K_eq) if np.isfinite(self.K_eq).any() else np.nan:.4g}, "
                f"{len(self.events)} events>")


@dataclass(frozen=True, repr=False)
class GrowthHistory:
    """The history of a crack-growth run (`cnem.fracture.grow`).

    Attributes
    ----------
    steps : list of Step
        One per increment (the state before growing).
    final : Step
        The state after the last increment (K's of the final cracks; no growth).
    cracks : list of (k, 2) ndarray
        The crack polylines after the last step.
    domain, model, solution
        The last ones (after the last increment).
    criterion : str
    events : list of GrowthEvent
        Every step's events, in order.
    """

    steps: list
    final: Step
    cracks: list
    domain: object
    model: object
    solution: object
    criterion: str
    events: list = field(default_factory=list)

    def __len__(self):
        return len(self.steps)

    def __repr__(self):
        return (f"<GrowthHistory {len(self.steps)} steps, {len(self.final.tips)} tips "
                f"({int(self.final.active.sum())} growing at the end), criterion {self.criterion}, "
                f"{len(self.events)} events>")

    def _all(self):
        return list(self.steps) + [self.final]

    def paths(self) -> np.ndarray:
        """Tip positions through the run: ``(steps + 1, t, 2)`` (the last row after
        the last increment)."""
        return np.stack([s.tips for s in self._all()])

    def array(self, name: str) -> np.ndarray:
        """A per-tip field of every state stacked: ``(steps + 1, t, ...)`` or,
        for ``cycles`` and ``measure``, ``(steps + 1,)``."""
        return np.stack([np.asarray(getattr(s, name)) for s in self._all()])

    @property
    def cycles(self) -> np.ndarray:
        """(steps + 1,) ndarray: cumulative load cycles at each state (0 at the start;
        NaN throughout without a Paris law)."""
        c = np.array([s.cycles for s in self.steps], dtype=float)
        if not np.isfinite(c).any():
            return np.full(len(c) + 1, np.nan)
        return np.concatenate([[0.0], np.cumsum(c)])

    #: The columns of `records` (and of ``sif.csv``), in order.
    COLUMNS = ("step", "tip", "active", "x", "y", "crack_length", "K_I", "K_II", "K_eq",
               "angle_deg", "increment", "load_factor", "cycles")

    def records(self) -> list[dict]:
        """One dict per state and tip with the `COLUMNS`: step, tip, whether it was
        active, its position, crack length, K_I, K_II, K_eq, kink angle (degrees),
        increment, load factor and cumulative cycles (NaN where a value is absent)."""
        cycles, rows = self.cycles, []
        for k, s in enumerate(self._all()):
            for i in range(len(s.tips)):
                rows.append(dict(zip(self.COLUMNS, (
                    k, i, bool(s.active[i]), float(s.tips[i, 0]), float(s.tips[i, 1]),
                    float(s.crack_length[i]), float(s.K[i, 0]), float(s.K[i, 1]),
                    float(s.K_eq[i]), float(np.degrees(s.angle[i])), float(s.increment[i]),
                    float(s.load_factor[i]), float(cycles[k])))))
        return rows

    def table(self) -> str:
        """Text table: per state and tip, position, K_I, K_II, K_eq, angle (degrees),
        load factor, cumulative cycles."""
        lines = [f"{'step':>4} {'tip':>3} {'x':>10} {'y':>10} {'length':>9} {'K_I':>10} "
                 f"{'K_II':>10} {'K_eq':>10} {'angle':>8} {'load':>9} {'cycles':>10}"]
        for r in self.records():
            lines.append(f"{r['step']:>4d} {r['tip']:>3d} {r['x']:>10.5g} {r['y']:>10.5g} "
                         f"{r['crack_length']:>9.5g} {r['K_I']:>10.4g} {r['K_II']:>10.4g} "
                         f"{r['K_eq']:>10.4g} {r['angle_deg']:>8.3f} "
                         f"{r['load_factor']:>9.4g} {r['cycles']:>10.4g}")
        for e in self.events:
            lines.append(str(e))
        return "\n".join(lines)

    def write(self, folder: str | os.PathLike) -> list:
        """The run's files in ``folder``: the K table, ``sif.csv`` (one row per state and
        tip, the `COLUMNS` of `records`; NaN written ``nan``) and ``sif.json`` (``criterion``,
        ``records`` as in `records`, NaN as ``null``, and ``events`` as text); one VTU per
        state, ``step_000.vtu`` ... (displacement, stress, strain, von Mises; see
        `cnem.solvers.solution.Solution.write`), written from the solutions kept with
        ``keep=True``, and ``steps.pvd``, their collection over the growth step (time
        ``k`` for ``step_k``), which ParaView opens as one series.

        Returns
        -------
        list of pathlib.Path
            The VTU files.
        """
        out = pathlib.Path(folder)
        out.mkdir(parents=True, exist_ok=True)
        self._write_sif(out)
        files, steps = [], []
        for k, s in enumerate(self._all()):
            if s.solution is None:
                continue
            files.append(pathlib.Path(s.solution.write(out / f"step_{k:03d}.vtu")))
            steps.append(k)
        if files:
            write_pvd(out / "steps.pvd", list(zip(steps, files)))
        return files

    def _write_sif(self, out: pathlib.Path) -> None:
        """``sif.csv`` and ``sif.json`` in ``out`` (see `write`)."""
        records = self.records()
        with open(out / "sif.csv", "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=self.COLUMNS)
            writer.writeheader()
            writer.writerows(records)
        nulls = [{k: None if isinstance(v, float) and not np.isfinite(v) else v
                  for k, v in r.items()} for r in records]
        with open(out / "sif.json", "w") as f:
            json.dump({"criterion": self.criterion, "records": nulls,
                       "events": [str(e) for e in self.events]}, f, indent=1, allow_nan=False)

    def plot(self, path: str | None = None, *, kind: Literal["paths", "sif", "load"] = "paths",
             **kwargs: Any) -> Figure:
        """Pictures of the run (matplotlib, off-screen PNG; see `cnem.fracture.figures`).

        Parameters
        ----------
        path : str or os.PathLike, optional
            Write a PNG there.
        kind : {"paths", "sif", "load"}
            Crack paths over the geometry and the final von Mises field; K_I, K_II
            and K_eq against crack length; load factor (and ``measure`` times it:
            load-displacement) against crack length.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from . import figures
        draw = {"paths": figures.paths, "sif": figures.sif_curves, "load": figures.load_curves}
        if kind not in draw:
            from ..errors import GrowthError
            raise GrowthError(f"kind: expected one of {sorted(draw)}, received {kind!r}")
        return draw[kind](self, path, **kwargs)
