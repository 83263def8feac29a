"""The two-hole plate grown by C-NEM (LEFM, maximum hoop stress) and broken by quasi-static PD on the same nodes.

The problem
-----------
The plate, holes, edge cracks, material and supports of
`cnem.demos.growth_two_holes` (imported, not copied), on the cloud of that demo
(`cnem.nodes.irregular`, spacing ``h``, seed 0):

* C-NEM: `cnem.fracture.grow` with the demo's ``setup``, increments of 1 mm,
  ``K_Ic`` given, so each step also has its critical load factor.
* PD: `cnem.pd.Body.from_cloud` on the very nodes of the initial C-NEM model
  (horizon ``m h``, m = 3), the same E and G_c = K_Ic^2 / E' (plane strain),
  bond-based PMB by default (``model="state"``: the linear peridynamic solid
  with the same nu); the critical stretch from G_c by
  `cnem.pd.critical_stretch`. The top-edge displacement of ``setup`` is ramped
  by `cnem.pd.quasistatic` (ADR to equilibrium, bonds breaking at equilibrium
  until none breaks, each step bounded); it starts at the factor at which the
  first bond of the elastic solution reaches the critical stretch. PD's
  displacement conditions hold the layers of points within one horizon of the
  bottom and top edges (a single prescribed row over-stretches the bonds next
  to it: 1.8x the mean strain, measured on a strip), u_x = 0 at the origin.
* The PD crack paths are the ridges of damage >= 0.5 from each initial tip
  (`cnem.demos.damage.ridge.ridge_path`).

Compared: the Hausdorff distance between the paths (shapely; the longer path
cut to the length of the shorter one), the first kink angle (the chord over the
first increment from the initial tip, against the crack direction), the crack
length at which each path first comes within ``h`` of a hole, the outer
boundary or the other crack, and the load factor at which growth starts.

Expected result
---------------
C-NEM sends the two cracks between the holes (its growth is LEFM, independent of
K_Ic except for the load factor). PD has a material length, the horizon, and so an
intrinsic strength ``~ E s_c`` with ``s_c ~ delta^-1/2``: where it breaks first is
a race between the holes (a stress concentration: first break at a load
``~ delta^-1/2``) and the notches (a crack: a load that does not scale with delta
once delta is below the notch length). ``--scaling`` measures it from the elastic
PD solution (PMB, m = 3, seed 0; load factors of the 0.1 mm pull; C-NEM's critical
factor 0.51 - 0.56):

======  =====  ======  ==========  ============  ==========
h (mm)  delta  nodes   hole/notch  hole/C-NEM    notch/C-NEM
======  =====  ======  ==========  ============  ==========
0.5     1.41   795     0.44        0.38          0.86
0.25    0.73   2995    0.74        0.57          0.77
0.125   0.37   11573   0.83        0.76          0.91
0.0625  0.19   45487   1.22        1.19          0.98
======  =====  ======  ==========  ============  ==========

(the notch column takes the weaker tip; the hole factors are 0.211, 0.301, 0.389,
0.610). The hole's factor grows as delta^-0.54 over the three finer clouds (0.5
expected); the notch's scatters by up to 40 % between the two tips of one cloud
(0.665 / 0.467 at h = 0.125), with no trend in delta: it is set by the shortest
bond at the tip node (0.21 against 0.07 mm long there), the K field being
singular. No bond crosses either notch. The largest notch-tip stretch is 0.12 -
0.30 of the one the LEFM (Williams) field with C-NEM's K gives on the same bonds:
within a horizon of the tip PD is not the K field.
Above h = 0.1 the holes break first and no PD crack runs from a notch (the table
says so, NaN rows); at h = 0.0625 (45k nodes) both cracks start at the notches.
ADR load steps are then too slow (1300 - 2200 iterations per settle at 11k nodes
already, 70 - 100 s each at a load average of 6.5); the event-by-event linear
solves of ``--solver sequential`` (`cnem.pd.sequential`, 0.7 - 2 s a solve at 45k
nodes) run the whole loading, with the ridge threshold 0.35 (``--threshold``: a
clean PD crack's face points lose about 40 % of their bonds, so no point reaches
0.5 near the tips)::

    cnem demo growth-pd-vs-cnem --h 0.0625 --solver sequential --threshold 0.35

(C-NEM 73 - 162 s, PD 1066 - 1951 s, by the machine's load; 40 load factors, 16834
bonds broken, ended by the load drop). Measured: both PD cracks start at the
notches (first bond at factor 0.49, growth from 0.50; C-NEM's critical factor
0.513) and kink more than C-NEM's, first kink PD 28.3 / 25.0 degrees against
C-NEM 16.8 / 16.8 (left / right); over the first 2.1 / 2.4 mm the paths are 0.35
/ 0.16 mm apart (Hausdorff). The PD notch cracks grow stably against a rising
load (about 2 mm long at factor 0.67) and then stop; at factor 0.76 two cracks start
at the holes' edges facing the plate's centre and run at that load: 10.2 mm
from the hole at (17, 3) to (5.0, 4.3) and 2.3 mm from the hole at (3, 7); the
load drops and the run ends. Neither PD notch crack reaches a hole or the
boundary; the C-NEM cracks (1 mm increments, LEFM: no strength, no nucleation)
pass between the holes and meet each other after 11.4 mm. So at this horizon
the two methods agree on where the notch cracks start and roughly on their
first direction, not on the failure: PD's strength (the hole breaks at a stress
~ E s_c that grows like delta^-1/2) still lets the holes nucleate before a
notch crack gets there. The picture (``pd_cnem_paths.png``) draws the paths
over the geometry on the PD damage field, one panel per spacing, with the PD
cracks that did not grow from a notch (`cnem.demos.damage.ridge.ridge_bands`).
"""

from __future__ import annotations

import pathlib
import time
from typing import TYPE_CHECKING

import numpy as np
import shapely

import cnem
import cnem.pd as pd
from cnem._parallel import one_thread
from cnem.cli import demo_parser, positive_float, positive_int
from cnem.errors import GeometryError
from cnem.demos import growth_two_holes as plate
from cnem.demos.damage.ridge import ridge_bands, ridge_path
from cnem.pd.critical_stretch import fracture_energy
from cnem.pd.quasistatic import load_drop, quasistatic
from cnem.pd.sequential import sequential

if TYPE_CHECKING:
    from typing import Sequence

__all__ = ["main", "cli", "compare"]

#: Fracture toughness, MPa sqrt(mm) (50 MPa sqrt(m): a steel-like value).
K_IC = 50.0 * np.sqrt(1000.0)
#: Initial tips (left crack, right crack) and crack directions.
TIPS = np.array([[1.0, 2.85], [plate.L - 1.0, 7.15]])
DIRECTIONS = np.array([[1.0, 0.0], [-1.0, 0.0]])


#: How long the demo runs at its defaults (its --help says it; see cnem.cli.demo_parser).
RUN_TIME = "about 2 min"


def _cnem(dom, cloud, increment, steps):
    try:
        hist = cnem.fracture.grow(dom, cloud, plate.setup, increment=increment, steps=steps,
                                  K_Ic=K_IC, progress=False)
    except GeometryError as exc:            # the cracks joined and cut the plate: the run so far
        print(f"C-NEM: {exc}")
        hist = exc.history
    tips = hist.paths()                                     # (steps + 1, tips, 2)
    order = [int(np.argmin(np.hypot(*(tips[0] - t).T))) for t in TIPS]
    paths = [_dedupe(tips[:, i]) for i in order]
    return paths, float(hist.steps[0].critical_load_factor), hist


def _dedupe(path):
    """A polyline without repeated vertices (a tip that stopped repeats its position)."""
    keep = np.r_[True, np.hypot(*np.diff(path, axis=0).T) > 1e-12]
    return path[keep]


def _pd_problem(cloud, model, horizon_factor):
    body = pd.Body.from_cloud(cloud, horizon_factor)
    G_c = fracture_energy(K_IC, plate.E, plate.NU, "strain")
    material = (pd.BondBased(plate.E, fracture_energy=G_c) if model == "bond" else
                pd.StateBased(plate.E, plate.NU, fracture_energy=G_c))
    prob = pd.Problem(body, material, plane="strain")
    layer = body.horizon
    prob.add_dirichlet(lambda p: p[:, 1] < layer, 1)
    prob.add_dirichlet(lambda p: np.hypot(*p.T) < 1e-9 * plate.L, 0)
    prob.add_dirichlet(lambda p: p[:, 1] > plate.B - layer, 1, plate.PULL)
    return body, prob


def _first_breaking_factor(prob):
    """The load factor at which the most stretched bond of the (linear) elastic solution
    at factor 1 reaches the critical stretch."""
    b = prob.body
    u = prob.solve().u
    stretch = np.hypot(*(b.xi + u[b.bond_j] - u[b.bond_i]).T) / b.length - 1.0
    return prob.material.stretch_limit(2, prob.plane, b.horizon) / float(stretch.max())


class _Report:
    """After every load factor of a PD run, the factor at which each point's damage first
    reached ``threshold`` (``reached``, (n,), NaN where it has not); every `REPORT_EVERY`
    factors, one line on the terminal (factor, bonds broken, time) and the damage so far
    in ``snapshot`` (an ``.npz`` of ``points``, ``damage``, ``factor``; None: not saved),
    so a long run shows its progress and leaves its crack behind if it is stopped."""

    def __init__(self, prob, snapshot, threshold):
        self.prob, self.snapshot, self.threshold = prob, snapshot, threshold
        self.count, self.broken, self.t0 = 0, 0, time.perf_counter()
        self.reached = np.full(len(prob.body), np.nan)

    def __call__(self, step, u):
        self.count += 1
        self.broken += step.broken
        damage = self.prob.damage() if step.damage is None else step.damage
        self.reached[np.isnan(self.reached) & (damage >= self.threshold)] = step.factor
        if self.count % REPORT_EVERY:
            return
        print(f"PD: load factor {step.factor:.4f}, {self.broken} bonds broken after "
              f"{self.count} factors, {time.perf_counter() - self.t0:.0f} s", flush=True)
        if self.snapshot is not None:
            np.savez(self.snapshot, points=self.prob.body.points, damage=damage,
                     factor=step.factor)


#: Load factors between two progress lines (and damage snapshots) of a sequential run.
REPORT_EVERY = 25


def _pd(cloud, model, horizon_factor, factor_step, factor_max, max_rounds, load_steps,
        solver="adr", max_solves=100_000, threshold=0.5, snapshot=None):
    body, prob = _pd_problem(cloud, model, horizon_factor)
    start = _first_breaking_factor(prob)
    report = _Report(prob, snapshot, threshold)
    if solver == "sequential":
        run = sequential(prob, factor_max, stop=load_drop(0.2), max_solves=max_solves,
                         tol=1e-8, progress=False, callback=report)
    else:
        factors = start * np.arange(1.0, factor_max / start + 1e-9, factor_step)[:load_steps]
        # the PMB kernel on one thread: on a shared, busy machine two threads stall each
        # other (measured 20x slower per force evaluation at a load average of 18)
        with one_thread():
            run = quasistatic(prob, factors, stop=load_drop(0.2), max_rounds=max_rounds,
                              progress=False, callback=report)
    started = next((s.factor for s in run.steps if s.broken), np.nan)
    paths = []
    for tip in TIPS:
        near = np.hypot(*(body.points - tip).T) < body.horizon
        paths.append(ridge_path(body.points, run.damage, tip, threshold=threshold)
                     if (run.damage[near] >= threshold).any() else tip[None].copy())
    return body, run, paths, start, started, report.reached


def _other_cracks(body, run, notch_paths, threshold, reached):
    """The PD cracks that did not grow from a notch: the bands of damage >= ``threshold``
    (`ridge_bands`) with no point within a horizon of a notch path and a ridge longer than
    a horizon, each from its end nearest a hole or the outer boundary along its ridge
    (`ridge_path`). One dict each, largest first: ``path`` (k, 2), ``length``,
    ``start`` (what it starts at) and ``factor``, the first load factor at which a
    point of the band reached the threshold (``reached``: that factor per point, see
    `_Report`)."""
    if not (run.damage >= threshold).any():
        return []
    labels = ridge_bands(body.points, run.damage, threshold=threshold)
    notches = shapely.MultiLineString([p if len(p) > 1 else np.vstack([p, p])
                                       for p in notch_paths])
    edges = _plate_edges()
    cracks = []
    for k in range(labels.max() + 1):
        band = labels == k
        where = shapely.points(body.points[band])
        if shapely.distance(notches, where).min() < body.horizon:
            continue
        gaps = {name: shapely.distance(edge, where) for name, edge in edges.items()}
        name = min(gaps, key=lambda e: gaps[e].min())
        start = body.points[band][int(np.argmin(gaps[name]))]
        field = np.where(band, run.damage, 0.0)
        first = np.nanmin(reached[band]) if np.isfinite(reached[band]).any() else np.nan
        path = ridge_path(body.points, field, start, threshold=threshold)
        if _length(path) < body.horizon:                # a speck of damage, not a crack
            continue
        cracks.append(dict(path=path, length=_length(path), start=name, factor=float(first)))
    return cracks


def _length(path):
    return float(np.hypot(*np.diff(path, axis=0).T).sum()) if len(path) > 1 else 0.0


def _cut(path, length):
    """The polyline from its start to arc length ``length``."""
    if len(path) < 2:
        return path
    line = shapely.LineString(path)
    length = min(length, line.length)
    s = np.r_[0.0, np.cumsum(np.hypot(*np.diff(path, axis=0).T))]
    inner = path[s < length]
    end = np.array(line.interpolate(length).coords[0])
    return np.vstack([inner, end])


def _kink_deg(path, direction, chord):
    """Angle (degrees, counter-clockwise) of the chord from the path's start over arc
    length ``chord``, against ``direction``."""
    if _length(path) == 0.0:
        return np.nan
    end = _cut(path, chord)[-1] - path[0]
    return float(np.degrees(np.arctan2(direction[0] * end[1] - direction[1] * end[0],
                                       direction @ end)))


def _plate_edges():
    """The holes' edges (named by their centres) and the outer boundary, as lines."""
    edges = {f"hole ({c[0]:g}, {c[1]:g})": shapely.Point(c).buffer(plate.R, 256).exterior
             for c in plate.HOLES}
    edges["boundary"] = shapely.box(0.0, 0.0, plate.L, plate.B).exterior
    return edges


def _arrival(path, other, reach):
    """Crack growth (arc length from the initial tip) at which ``path`` first comes
    within ``reach`` of a hole, the outer boundary or ``other``, and what it meets."""
    edges = _plate_edges()
    targets = {"hole": shapely.union_all([e for n, e in edges.items() if n != "boundary"]),
               "boundary": edges["boundary"]}
    if _length(other) > 0:
        targets["other crack"] = shapely.LineString(other)
    s = np.r_[0.0, np.cumsum(np.hypot(*np.diff(path, axis=0).T))]
    for k, p in enumerate(path[1:], start=1):
        for name, target in targets.items():
            if shapely.distance(shapely.Point(p), target) < reach:
                return float(s[k]), name
    return np.nan, "none"


def compare(cnem_path: np.ndarray, pd_path: np.ndarray, other_cnem: np.ndarray,
            other_pd: np.ndarray, direction: np.ndarray, increment: float, reach: float) -> dict:
    """The comparison of one crack's two paths (see the module)."""
    common = min(_length(cnem_path), _length(pd_path))
    hausdorff = (shapely.hausdorff_distance(shapely.LineString(_cut(cnem_path, common)),
                                            shapely.LineString(_cut(pd_path, common)))
                 if common > 0 else np.nan)
    c_len, c_what = _arrival(cnem_path, other_cnem, reach)
    p_len, p_what = _arrival(pd_path, other_pd, reach)
    return dict(hausdorff=float(hausdorff), compared_length=common,
                kink_cnem=_kink_deg(cnem_path, direction, increment),
                kink_pd=_kink_deg(pd_path, direction, increment),
                reach_cnem=c_len, meets_cnem=c_what, reach_pd=p_len, meets_pd=p_what,
                length_cnem=_length(cnem_path), length_pd=_length(pd_path))


def study(h: float, *, model: str = "bond", horizon_factor: float = 3.0, increment: float = 1.0,
          steps: int = 12, factor_step: float = 0.02, factor_max: float = 1.5,
          max_rounds: int = 100, load_steps: int | None = None, solver: str = "adr",
          max_solves: int = 100_000, threshold: float = 0.5, snapshot=None) -> dict:
    """Both methods on the irregular cloud of spacing ``h``; one dict. ``solver``: the PD
    load stepping, ``"adr"`` (`cnem.pd.quasistatic`, load steps of ``factor_step``) or
    ``"sequential"`` (`cnem.pd.sequential`, event by event, at most ``max_solves``,
    reporting its progress and saving the damage so far to the ``.npz`` path
    ``snapshot`` every `REPORT_EVERY` load factors); ``threshold``: the damage of the PD
    ridge paths."""
    dom = plate.domain(h)
    cloud = cnem.nodes.irregular(dom, h, seed=0)
    t0 = time.perf_counter()
    cpaths, c_factor, hist = _cnem(dom, cloud, increment, steps)
    t1 = time.perf_counter()
    print(f"h = {h:g}: C-NEM grown in {t1 - t0:.0f} s on {len(cloud)} nodes; PD next",
          flush=True)
    body, run, ppaths, start, started, reached = _pd(
        cloud, model, horizon_factor, factor_step, factor_max, max_rounds, load_steps, solver,
        max_solves, threshold, snapshot)
    t2 = time.perf_counter()
    others = _other_cracks(body, run, ppaths, threshold, reached)
    rows = [compare(cpaths[i], ppaths[i], cpaths[1 - i], ppaths[1 - i], DIRECTIONS[i], increment,
                    h) for i in range(2)]
    return dict(h=h, horizon=body.horizon, nodes=len(body), rows=rows, cnem_paths=cpaths,
                threshold=threshold,
                pd_paths=ppaths, pd_other=others, cnem_factor=c_factor, pd_first_bond=start,
                pd_started=started,
                pd_steps=len(run.steps), pd_stopped=run.stopped,
                pd_last_factor=run.steps[-1].factor if run.steps else np.nan,
                pd_incomplete=int(sum(not s.complete for s in run.steps)),
                pd_broken=int(run.array("broken").sum()),
                critical_stretch=run.problem.material.stretch_limit(2, "strain", body.horizon),
                points=body.points, damage=run.damage, seconds=(t1 - t0, t2 - t1))


def first_breaks(h: float, *, model: str = "bond", horizon_factor: float = 3.0) -> dict:
    """Where the PD body breaks first, against C-NEM, on the cloud of spacing ``h``.

    From the elastic PD solution at factor 1 (the linearised stretches ``s_1``): the load
    factor ``s_c / max s_1`` at which the first bond breaks among the bonds whose midpoint
    lies within one horizon of each notch tip, and of a hole's edge; and C-NEM's critical
    load factor of the initial cracks (``K_eq = K_Ic``).

    Returns
    -------
    dict
        ``h``, ``horizon``, ``nodes``, ``critical_stretch``, ``hole``, ``notch`` (the two
        tips), ``cnem``, ``seconds``.
    """
    t0 = time.perf_counter()
    dom = plate.domain(h)
    cloud = cnem.nodes.irregular(dom, h, seed=0)
    _, c_factor, _ = _cnem(dom, cloud, 1.0, 1)
    body, prob = _pd_problem(cloud, model, horizon_factor)
    b, u = body, prob.solve().u
    s1 = (prob.unit * (u[b.bond_j] - u[b.bond_i])).sum(axis=1) / b.length
    limit = prob.material.stretch_limit(2, prob.plane, b.horizon)
    mid = b.points[b.bond_i] + 0.5 * b.xi
    edge = np.min([np.hypot(*(mid - c).T) - plate.R for c in plate.HOLES], axis=0)
    notch = [limit / s1[np.hypot(*(mid - tip).T) < b.horizon].max() for tip in TIPS]
    return dict(h=h, horizon=b.horizon, nodes=len(b), critical_stretch=limit,
                hole=limit / s1[edge < b.horizon].max(), notch=notch, cnem=c_factor,
                seconds=time.perf_counter() - t0)


def breaks_table(rows: list) -> str:
    """`first_breaks` of several spacings, one line each."""
    lines = [f"{'h':>6} {'delta':>6} {'nodes':>6} {'s_c':>7} | {'first break: hole':>17} "
             f"{'notch L':>7} {'notch R':>7} {'C-NEM':>6} | {'hole/notch':>10} "
             f"{'hole/C-NEM':>10} {'notch/C-NEM':>11}"]
    for r in rows:
        notch = min(r["notch"])
        lines.append(f"{r['h']:>6.4f} {r['horizon']:>6.3f} {r['nodes']:>6d} "
                     f"{r['critical_stretch']:>7.4f} | {r['hole']:>17.4f} {r['notch'][0]:>7.4f} "
                     f"{r['notch'][1]:>7.4f} {r['cnem']:>6.4f} | {r['hole'] / notch:>10.3f} "
                     f"{r['hole'] / r['cnem']:>10.3f} {notch / r['cnem']:>11.3f}")
    lines.append("load factors (multiples of the 0.1 mm pull) of the first broken bond within one "
                 "horizon of a hole's edge / of each notch tip (elastic PD solution), and C-NEM's "
                 "critical load factor; the notch (and growth from it) comes first where "
                 "hole/notch > 1")
    return "\n".join(lines)


def _cell(value: float, spec: str, width: int) -> str:
    """``value`` formatted, or ``-`` where it could not be computed (NaN)."""
    return f"{value:>{width}{spec}}" if np.isfinite(value) else f"{'-':>{width}}"


def table(results: list) -> str:
    lines = [f"{'h':>5} {'delta':>6} {'nodes':>6} {'crack':>5} | {'Hausdorff':>9} {'over':>5} | "
             f"{'kink C-NEM':>10} {'PD':>7} | {'reaches C-NEM':>18} {'PD':>18} | "
             f"{'start factor C-NEM':>18} {'PD':>6}"]
    missing = []
    for r in results:
        for name, row in zip(("left", "right"), r["rows"]):
            c = f"{_cell(row['reach_cnem'], '.2f', 0)} {row['meets_cnem']}"
            p = f"{_cell(row['reach_pd'], '.2f', 0)} {row['meets_pd']}"
            lines.append(f"{r['h']:>5.3f} {r['horizon']:>6.3f} {r['nodes']:>6d} {name:>5} | "
                         f"{_cell(row['hausdorff'], '.3f', 9)} {row['compared_length']:>5.1f} | "
                         f"{_cell(row['kink_cnem'], '.2f', 10)} {_cell(row['kink_pd'], '.2f', 7)} | "
                         f"{c:>18} {p:>18} | "
                         f"{_cell(r['cnem_factor'], '.4f', 18)} {_cell(r['pd_started'], '.4f', 6)}")
            if not np.isfinite(row["kink_pd"]):
                missing.append(f"{name} at h = {r['h']:g}")
    if missing:
        lines.append("-: no PD crack path grew from the notch (" + ", ".join(missing) + "): the "
                     "damage did not link up into a path at this spacing, so there is no PD kink, "
                     "Hausdorff distance or reach; refine (e.g. --h 0.125 or 0.0625) to compare "
                     "the paths")
    for r in results:
        for c in r.get("pd_other", []):
            lines.append(f"h = {r['h']:g}: a PD crack not from a notch, from the {c['start']} at "
                         f"({c['path'][0, 0]:.2f}, {c['path'][0, 1]:.2f}) to "
                         f"({c['path'][-1, 0]:.2f}, {c['path'][-1, 1]:.2f}), {c['length']:.2f} mm "
                         f"long, started at load factor {c['factor']:.4f}")
    lines.append("lengths in mm; Hausdorff over the first 'over' mm of both paths; kink: chord over "
                 "the first increment, degrees; reaches: crack growth when the path comes within h "
                 "of a hole / the boundary / the other crack; start factor: the multiple of the "
                 "0.1 mm pull at which growth starts (C-NEM: K_eq = K_Ic; PD: first broken bond)")
    return "\n".join(lines)


def _plot(results, path):
    from cnem.plot.charts import offscreen_pyplot
    plt = offscreen_pyplot()
    fig, axes = plt.subplots(len(results), 1, figsize=(9.0, 4.6 * len(results)), squeeze=False)
    for ax, r in zip(axes[:, 0], results):
        sc = ax.scatter(*r["points"].T, c=r["damage"], s=4.0 * (0.25 / r["h"]) ** 2, cmap="Greys",
                        vmin=0.0, vmax=1.0, zorder=1)
        ax.plot([0, plate.L, plate.L, 0, 0], [0, 0, plate.B, plate.B, 0], "k-", lw=1)
        for c in plate.HOLES:
            t = np.linspace(0, 2 * np.pi, 200)
            ax.plot(c[0] + plate.R * np.cos(t), c[1] + plate.R * np.sin(t), "k-", lw=1)
        for tip, direction in zip(TIPS, DIRECTIONS):
            ax.plot(*np.array([tip - direction, tip]).T, "k-", lw=2.5)
        for k, (cp, pp) in enumerate(zip(r["cnem_paths"], r["pd_paths"])):
            ax.plot(*cp.T, "o-", color="tab:blue", ms=3, lw=2,
                    label="C-NEM (max hoop, 1 mm steps)" if k == 0 else None, zorder=3)
            ax.plot(*pp.T, "s-", color="tab:red", ms=2.5, lw=1.5,
                    label=f"PD ridge of damage ≥ {r.get('threshold', 0.5):g}" if k == 0 else None,
                    zorder=4)
        for k, c in enumerate(r.get("pd_other", [])):
            ax.plot(*c["path"].T, "^-", color="tab:orange", ms=2.5, lw=1.5, zorder=4,
                    label="PD crack not from a notch" if k == 0 else None)
        ax.set_aspect("equal")
        ax.set_xlim(-0.3, plate.L + 0.3)
        ax.set_ylim(-0.3, plate.B + 0.3)
        ax.set_title(f"$h$ = {r['h']:g} mm, PD horizon $\\delta$ = {r['horizon']:.3g} mm, "
                     f"{r['nodes']} nodes", fontsize=10)
        ax.set_xlabel(r"$x$ (mm)")
        ax.set_ylabel(r"$y$ (mm)")
        ax.plot([], [], "k-", lw=2.5, label="initial notches")
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.15), ncol=3, fontsize=8)
        fig.colorbar(sc, ax=ax, label="PD damage", shrink=0.8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(spacings: Sequence[float] = (0.25,), *, model: str = "bond", steps: int = 12,
         factor_step: float = 0.02, factor_max: float = 1.5, max_rounds: int = 100,
         load_steps: int | None = None, outdir: str = "results/growth_pd_vs_cnem",
         plot: bool = True, solver: str = "adr", max_solves: int = 100_000,
         scaling: bool = False, threshold: float = 0.5) -> dict:
    """Run `study` at every spacing; print the table, draw the paths.

    ``load_steps`` caps the PD load steps (from the first-breaking factor up by
    ``factor_step`` of it to ``factor_max``); ``max_rounds`` bounds each step's
    break-and-settle rounds; ``solver``, ``max_solves``: see `study`. With ``scaling``,
    only `first_breaks` at every spacing (`breaks_table`, ``breaks.txt``).

    Returns
    -------
    dict
        ``results`` (one dict per spacing, see `study` or `first_breaks`), ``table`` (str),
        ``files``.
    """
    out = pathlib.Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    if scaling:
        rows = [first_breaks(h, model=model) for h in spacings]
        text = breaks_table(rows)
        print(text)
        (out / "breaks.txt").write_text(text + "\n")
        print(f"wrote {out / 'breaks.txt'}")
        return dict(results=rows, table=text, files=[])
    results = []
    for h in spacings:
        r = study(h, model=model, steps=steps, factor_step=factor_step, factor_max=factor_max,
                  max_rounds=max_rounds, load_steps=load_steps, solver=solver,
                  max_solves=max_solves, threshold=threshold,
                  snapshot=out / f"pd_damage_h{h:g}.npz")
        np.savez(out / f"pd_damage_h{h:g}.npz", points=r["points"], damage=r["damage"],
                 factor=r["pd_last_factor"])
        print(f"wrote {out / f'pd_damage_h{h:g}.npz'}")
        print(f"h = {h:g}: C-NEM {r['seconds'][0]:.0f} s, PD {r['seconds'][1]:.0f} s "
              f"({r['pd_steps']} load steps, {r['pd_broken']} bonds broken, "
              f"{r['pd_incomplete']} steps cut at max_rounds, stopped: {r['pd_stopped']}; "
              f"critical stretch {r['critical_stretch']:.4g}, first bond at factor "
              f"{r['pd_first_bond']:.4f})", flush=True)
        results.append(r)
    text = table(results)
    print(text)
    files = []
    if plot:
        files.append(out / "pd_cnem_paths.png")
        _plot(results, files[-1])
    (out / "table.txt").write_text(text + "\n")
    for f in [*files, out / "table.txt"]:
        print(f"wrote {f}")
    return dict(results=results, table=text, files=[str(f) for f in files])


def cli(argv: Sequence[str] | None = None, prog: str | None = None) -> dict:
    """Command line: ``python -m cnem.demos.growth_pd_vs_cnem --help`` or
    ``cnem demo growth-pd-vs-cnem``."""
    parser = demo_parser(__file__, __doc__, prog, run_time=RUN_TIME)
    parser.add_argument("--h", type=positive_float, nargs="+", default=[0.25], help="node spacings (mm)")
    parser.add_argument("--model", choices=("bond", "state"), default="bond",
                        help="the PD material model")
    parser.add_argument("--steps", type=positive_int, default=12, help="C-NEM increments")
    parser.add_argument("--factor-step", type=positive_float, default=0.02,
                        help="PD load step, a fraction of the first-breaking factor")
    parser.add_argument("--factor-max", type=positive_float, default=1.5, help="largest PD load factor")
    parser.add_argument("--solver", choices=("adr", "sequential"), default="adr",
                        help="PD load stepping: ADR load steps, or event by event with linear "
                             "solves (cnem.pd.sequential)")
    parser.add_argument("--max-solves", type=positive_int, default=100_000,
                        help="most linear solves of --solver sequential")
    parser.add_argument("--scaling", action="store_true",
                        help="only the first-break load factors at holes and notches against "
                             "C-NEM's, at every --h")
    parser.add_argument("--threshold", type=float, default=0.5,
                        help="damage of the PD ridge paths (a clean PD crack between two rows "
                             "leaves its face points at about 0.4)")
    args = parser.parse_args(argv)
    return main(args.h, model=args.model, steps=args.steps, factor_step=args.factor_step,
                factor_max=args.factor_max, outdir=args.out, plot=not args.no_plot,
                solver=args.solver, max_solves=args.max_solves, scaling=args.scaling,
                threshold=args.threshold)


if __name__ == "__main__":
    cli()
