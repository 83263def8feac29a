"""Quasi-static crack growth by linear elastic fracture mechanics: `grow`.

Each increment solves the user's problem on the current model, takes K_I and
K_II at every growing tip by the interaction integral (`sif`), turns them into
a kink angle and an equivalent SIF by a criterion (`cnem.fracture.criteria`),
and appends a straight segment at every tip (``scheme="corrector"``: turned by
half the kink found at the end of a trial segment, `cnem.fracture.corrector`).
The node cloud stays: the new crack vertices become nodes, the nodes too close
to a new segment are dropped (`cnem.fracture.advance`), and the grown domain is
discretized again. A body
that the cracks cut apart stops the run, or, with ``continue_with``, loses its
loose pieces and goes on growing.

>>> import numpy as np, cnem
>>> dom = cnem.geometry.rectangle(1.0, 2.0, cracks=[[[0.0, 1.0], [0.3, 1.0]]])
>>> def setup(model):                       # tension on both ends, symmetric about y = 1
...     prob = cnem.Elasticity(model, (1.0, 0.3), plane="strain")
...     ends = lambda x, n: np.abs(np.abs(x[:, 1] - 1.0) - 1.0) < 1e-9
...     prob.add_traction(ends, lambda x, n: n * [0.0, 1.0])
...     prob.add_dirichlet(lambda p: np.hypot(p[:, 0] - 1.0, p[:, 1]) < 1e-9, None)
...     prob.add_dirichlet(lambda p: np.hypot(p[:, 0] - 1.0, p[:, 1] - 2.0) < 1e-9, 0)
...     return prob
>>> hist = cnem.fracture.grow(dom, cnem.nodes.regular(dom, 0.1), setup, increment=0.1, steps=1,
...                           progress=False)
>>> hist.cracks[0][-1].round(6).tolist()        # straight on, mode I
[0.4, 1.0]
"""

from __future__ import annotations

import logging
import warnings
from typing import TYPE_CHECKING

import numpy as np
from tqdm.auto import tqdm

from ..errors import CNEMError, GeometryError, GrowthError, GrowthWarning, check_real
from ..geometry.cloud import NodeCloud
from ..geometry.model import discretize
from ..geometry.model_update import update
from ..material import kappa as kolosov
from ..geometry.nodes import irregular
from . import advance
from .corrector import SCHEMES, corrections
from .refine import Refinement, as_refinement, auto_refinement, refined_cloud
from .criteria import CRITERIA, kink
from .history import GrowthHistory, GrowthEvent, Step
from .interaction import sif

if TYPE_CHECKING:
    from typing import Any, Callable, Literal
    from ..geometry.domain import Domain

__all__ = ["grow"]

log = logging.getLogger(__name__)

#: Events that also raise a `GrowthWarning` (the others are expected ends of growth).
_WARN = {"crack", "closed", "sharp_kink", "left_domain"}


def _positive(value, name, allow_none=False):
    if value is None and allow_none:
        return None
    check_real(name, value, error=GrowthError, fix="pass a positive number")
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = np.nan
    if not np.isfinite(v) or v <= 0:
        raise GrowthError(f"{name}: expected a positive number, received {value!r}")
    return v


def _tip_rows(domain):
    """``[[crack, end, active], ...]`` for every tip of the domain."""
    rows = []
    for tip in domain.tips:
        for j, c in enumerate(domain.cracks):
            for end in (0, -1):
                if np.array_equal(c[end], tip):
                    rows.append([j, end, True])
    return rows


def _crack_length(crack):
    return float(np.hypot(*np.diff(crack, axis=0).T).sum())



def _checked_setup(setup: Callable[[Any], Any]) -> Callable[[Any], Any]:
    """``setup`` with its result checked: the problem to solve (what has ``solve``), named
    when it is missing (a ``setup`` without ``return prob`` gave None to the solve)."""
    if not callable(setup):
        raise GrowthError(f"setup: expected a function setup(model) -> problem, received "
                          f"{type(setup).__name__}")

    def checked(model):
        prob = setup(model)
        if not callable(getattr(prob, "solve", None)):
            raise GrowthError(f"setup(model) must return the problem it builds (e.g. the "
                              f"cnem.Elasticity with its supports and loads), received "
                              f"{type(prob).__name__}; end setup with `return prob`")
        return prob

    return checked

class _Run:
    """The mutable state of one `grow` call."""

    def __init__(self, domain, cloud, setup, criterion, K_Ic, max_kink, measure, radius, keep,
                 local, continue_with=None, refine=None):
        self.domain, self.cloud, self.local = domain, cloud, local
        self.setup = _checked_setup(setup)
        self.refine = refine          # the cloud that is discretized: `nodes()`
        self.continue_with = continue_with
        self.retired = {}                     # row -> (tip, crack length) of a crack gone
        self.split = None                     # the split event until the next solve
        self.criterion, self.K_Ic, self.max_kink = criterion, K_Ic, max_kink
        self.measure, self.radius, self.keep = measure, radius, keep
        self.cracks = [np.array(c, dtype=float) for c in domain.cracks]
        self.rows = _tip_rows(domain)
        self.model = self.problem = None
        self.steps, self.events = [], []
        self.trial_events = None              # a list while a trial step runs (`corrector`)

    def event(self, kind, step, tip, point, message):
        e = GrowthEvent(kind, step, tip, np.asarray(point, dtype=float).copy(), message)
        if self.trial_events is not None:     # a trial segment's: neither recorded nor warned
            self.trial_events.append(e)
            return e
        self.events.append(e)
        log.info("%s", e)
        if kind in _WARN:
            warnings.warn(str(e), GrowthWarning, stacklevel=4)
        return e

    def snapshot(self):
        """The geometry, cloud, model and problem of the accepted configuration, for
        `restore` after a trial step (the arrays are replaced by `advance`, never changed)."""
        return dict(domain=self.domain, cloud=self.cloud, cracks=list(self.cracks),
                    rows=[list(r) for r in self.rows], retired=dict(self.retired),
                    split=self.split, model=self.model, problem=self.problem)

    def restore(self, saved):
        """Back to a `snapshot`."""
        for name, value in saved.items():
            setattr(self, name, value)

    def tip_kink(self, sol, tip):
        """``(K (2,) SIFResult, kink angle, K_eq, at_bound)`` of the criterion at a tip."""
        res = sif(sol, tip, radius=self.radius)
        E, nu = sol.problem.materials[res.region]
        theta, K_eq, at_bound = kink(self.criterion, res[0], res[1], kappa=kolosov(nu, sol.plane))
        return res, theta, K_eq, at_bound

    def solve(self):
        """Re-discretise the grown cloud, set the problem up and solve it."""
        if self.split is None:
            self.problem = self._problem()
            self.model = self.problem.model
            return self.problem.solve(progress=False)
        split, self.split, self.problem = self.split, None, None   # a new body: built afresh
        try:
            self.problem = self._problem()
            self.model = self.problem.model
            return self.problem.solve(progress=False)
        except CNEMError as err:
            raise GeometryError(
                f"{split.message}; setup(model) on the remaining body fails: {err} (its supports "
                "or loads may lie on the pieces dropped: continue with another piece, or give "
                "supports the remaining body keeps)") from err

    def nodes(self):
        """The cloud of this increment: the background ``cloud``, refined about the
        active tips as ``refine`` says (`cnem.fracture.refine`)."""
        if self.refine is None:
            return self.cloud
        tips = np.reshape([self.cracks[c][e] for c, e, active in self.rows if active], (-1, 2))
        refinement = self.refine
        if refinement == "auto":
            tips, refinement = auto_refinement(self.cloud, tips)
        if refinement is None:
            return self.cloud
        return refined_cloud(self.cloud, tips, refinement)

    def _problem(self):
        """``setup`` on the model of the current cloud: by a local update of the previous
        model and problem (`cnem.geometry.model_update.update`, the problem's ``update_from``)
        while ``local``, else (and when the problem refuses the update) from scratch."""
        cloud = self.nodes()
        if not self.local or self.problem is None:
            return self.setup(discretize(cloud, progress=False))
        change = update(self.model, cloud, progress=False)
        prob = self.setup(change.model)
        update_from = getattr(prob, "update_from", None)
        if update_from is None:
            reason = f"{type(prob).__name__} has no update_from"
        else:
            try:
                return update_from(self.problem, change)
            except CNEMError as err:
                reason = str(err)
        # the same model as discretize(cloud); only B~ and K are built from scratch
        log.info("grow: the problem refuses the local update (%s); every further increment "
                 "builds the model and the operators from scratch", reason)
        self.local = False
        return self.setup(change.model)

    def state(self, sol, step):
        """K, K_eq, angle, load factor at every active tip (NaN elsewhere)."""
        t = len(self.rows)
        tips = np.array([self.retired[i][0] if i in self.retired else self.cracks[c][e]
                         for i, (c, e, _) in enumerate(self.rows)]).reshape(t, 2)
        active = np.array([a for *_, a in self.rows], dtype=bool)
        K, K_eq, angle = np.full((t, 2), np.nan), np.full(t, np.nan), np.full(t, np.nan)
        for i in np.flatnonzero(active):
            res, theta, K_eq[i], at_bound = self.tip_kink(sol, tips[i])
            K[i] = res
            angle[i] = theta
            if at_bound:
                self.event("sharp_kink", step, i, tips[i],
                           f"{self.criterion} finds no opening direction for K = {res[0]:.4g}, "
                           f"{res[1]:.4g}; the crack kinks by {np.degrees(theta):.2f} degrees")
            elif self.max_kink is not None and abs(theta) > self.max_kink:
                self.event("sharp_kink", step, i, tips[i],
                           f"kink {np.degrees(theta):.2f} degrees is sharper than max_kink = "
                           f"{np.degrees(self.max_kink):.2f} degrees")
        with np.errstate(divide="ignore", invalid="ignore"):
            load = np.where(K_eq > 0, self.K_Ic / K_eq, np.nan) if self.K_Ic else np.full(t, np.nan)
        lengths = np.array([self.retired[i][1] if i in self.retired else
                            _crack_length(self.cracks[c])
                            for i, (c, *_) in enumerate(self.rows)]).reshape(t)
        return dict(tips=tips, active=active, K=K, K_eq=K_eq, angle=angle, load_factor=load,
                    crack_length=lengths,
                    measure=float(self.measure(sol)) if self.measure else np.nan)

    def advance(self, state, increments, step, clearance, correction=None):
        """Append the new segments, turned by ``correction`` (radians, per tip) from
        the kink angles of ``state``; update the domain and the cloud."""
        segments, spacings = [], []
        for i in np.flatnonzero(increments > 0):
            c, end, active = self.rows[i]
            if not active:                  # joined by another tip earlier in this step
                continue
            crack = self.cracks[c]
            start = crack[end].copy()
            d = advance.tip_direction(crack, end)
            th = state["angle"][i] + (0.0 if correction is None else correction[i])
            e = np.array([np.cos(th) * d[0] - np.sin(th) * d[1], np.sin(th) * d[0] + np.cos(th) * d[1]])
            h = advance.local_spacing(self.cloud, start)
            reach = clearance * h
            da = increments[i]
            hit = advance.first_hit(self.domain, self.cracks, c, end, start, start + da * e, reach)
            stop = start + da * e
            if hit.kind in ("boundary", "hole"):
                stop = hit.point
                self.rows[i][2] = False
                if hit.distance < da * (1 - 1e-9):
                    self.event("left_domain", step, i, start,
                               f"the increment {da:.4g} would leave the domain: cut at "
                               f"{hit.distance:.4g} where it meets the {hit.kind}")
                self.event(hit.kind, step, i, stop, f"tip reached the {hit.kind} at "
                           f"({stop[0]:.6g}, {stop[1]:.6g}); crack {c} is an edge crack")
            elif hit.kind == "crack":
                length = hit.distance - reach
                self.rows[i][2] = False
                self.event("crack", step, i, hit.point,
                           f"tip meets crack {hit.crack} at ({hit.point[0]:.6g}, {hit.point[1]:.6g}) "
                           f"away from its tips; it stops {reach:.3g} short of it")
                if length <= reach:
                    continue
                stop = start + length * e
            elif hit.kind == "joined":
                stop = hit.point
                self.event("joined", step, i, stop, f"tip joins the tip of crack {hit.crack} at "
                           f"({stop[0]:.6g}, {stop[1]:.6g})")
                segments.append((start, stop))
                spacings.append(h)
                self._join(i, hit)
                continue
            self.cracks[c] = np.vstack([crack, stop]) if end == -1 else np.vstack([stop, crack])
            segments.append((start, stop))
            spacings.append(h)
        if not segments:
            return False
        self.domain = advance.rebuilt_domain(self.domain, self.cracks)
        self.cloud = advance.grown_cloud(self.cloud, self.domain, segments, spacings, clearance)
        if self.continue_with is None:
            advance.check_connected(self.domain, step)
        else:
            self._keep_one_piece(step)
        return True

    def _keep_one_piece(self, step):
        """With ``continue_with``: drop the loose pieces (their nodes and cracks) and go on
        with the piece chosen, recorded as event ``"split"``."""
        parts = advance.pieces(self.domain)
        if len(parts) < 2:
            return
        choice = self.continue_with
        k = 0 if choice == "largest" else choice(parts) if callable(choice) else choice
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 0 <= k < len(parts):
            raise GeometryError(
                f"after step {step} the cracks cut the body into {len(parts)} pieces: "
                f"{advance.describe(parts)}; continue_with: expected the index of one of them "
                f"(0 the largest), received {k!r}")
        dropped = [j for j in range(len(parts)) if j != k]
        domain, index = advance.remaining_body(self.domain, parts[k])
        gone = [j for j, i in enumerate(index) if i < 0]
        for r, row in enumerate(self.rows):
            if r in self.retired:
                continue
            if index[row[0]] < 0:                # its crack is boundary now, or dropped
                self.retired[r] = (self.cracks[row[0]][row[1]].copy(),
                                   _crack_length(self.cracks[row[0]]))
                row[0], row[2] = -1, False
            else:
                row[0] = index[row[0]]
        self.cracks = [c for c, i in zip(self.cracks, index) if i >= 0]
        self.domain, self.cloud = domain, advance.cloud_in(self.cloud, domain)
        point = parts[dropped[0]].representative_point()
        self.split = self.event(
            "split", step, -1, [point.x, point.y],
            f"after step {step} the cracks cut the body into {len(parts)} pieces; continuing with "
            f"{advance.describe(parts, [k])}, dropped {advance.describe(parts, dropped)} and "
            f"crack{'s' if len(gone) != 1 else ''} {gone} (now boundary or in a dropped piece)")

    def _join(self, i, hit):
        """Crack of tip ``i`` joined to ``hit.crack`` at its end ``hit.end``: one polyline."""
        c, end, _ = self.rows[i]
        j = hit.crack
        a = self.cracks[c] if end == -1 else self.cracks[c][::-1]
        b = self.cracks[j] if hit.end == 0 else self.cracks[j][::-1]
        merged = np.vstack([a, b])
        for row in self.rows:
            if row[0] == c:
                if row[1] == end:
                    row[2] = False
                row[1] = 0 if row[1] != end else -1
            elif row[0] == j:
                if row[1] == hit.end:
                    row[2] = False
                row[0], row[1] = c, (-1 if row[1] != hit.end else 0)
        self.rows[i][2] = False
        self.cracks[c] = merged
        del self.cracks[j]
        for row in self.rows:
            if row[0] > j:
                row[0] -= 1


def _cycles(paris, prev, now, increments):
    """Paris-law cycles of one step: da / (C dK^m), trapezoidal between the K_eq at the
    start and at the end of the step of the tip that grew most (forward Euler if it stopped)."""
    C, m = paris
    i = int(np.nanargmax(np.where(increments > 0, increments, np.nan)))
    rate = lambda k: 1.0 / (C * k ** m)  # noqa: E731
    k0, k1 = prev["K_eq"][i], now["K_eq"][i]
    if np.isfinite(k1) and k1 > 0:
        return 0.5 * increments[i] * (rate(k0) + rate(k1))
    return increments[i] * rate(k0)


def grow(domain: Domain, cloud: NodeCloud | float, setup: Callable[..., np.ndarray], *,
         increment: float, steps: int,
         criterion: Literal["max_hoop", "max_energy_release", "min_sed"] = "max_hoop",
         K_Ic: float | None = None, paris: np.ndarray | None = None, exponent: float | None = None,
         max_kink: float | None = None, measure: Callable[..., np.ndarray] | None = None,
         radius: float | None = None, clearance: float = 0.5, keep: bool = True, local: bool = True,
         continue_with: Literal["largest"] | int | Callable[[list], int] | None = None,
         refine: Refinement | float | Literal["auto"] | None = "auto",
         scheme: Literal["explicit", "corrector"] = "explicit",
         progress: bool = True) -> GrowthHistory:
    """Grow the cracks of a domain step by step (quasi-static LEFM).

    Parameters
    ----------
    domain : Domain
        With at least one crack tip.
    cloud : NodeCloud or float
        Nodes of ``domain``, or a spacing ``h`` (then ``cnem.nodes.irregular(domain, h, seed=0)``).
    setup : callable
        ``setup(model) -> Elasticity``: materials, supports and loads on each new model.
    increment : float
        Crack extension per step at the fastest tip.
    steps : int
        Number of increments.
    criterion : {"max_hoop", "max_energy_release", "min_sed"}
        Direction criterion (`cnem.fracture.criteria`).
    K_Ic : float, optional
        Fracture toughness: each step's ``load_factor = K_Ic / K_eq`` (proportional loading).
    paris : (C, m), optional
        Paris law ``da/dN = C dK_eq^m`` with ``dK`` the K of ``setup``'s load: cycles per step.
    exponent : float, optional
        Tip-dependent increments ``da_i = increment (K_eq,i / K_eq,max)^exponent``;
        default ``m`` of ``paris`` when given, else 0 (every tip grows ``increment``).
    max_kink : float, optional
        Kink angle (radians) above which a step is reported (event ``"sharp_kink"``).
    measure : callable, optional
        ``measure(solution) -> float`` recorded per step (a load-point displacement,
        say: times ``load_factor`` it gives the load-displacement curve).
    radius : float, optional
        Interaction-integral radius (`sif`; default nested discs up to the largest that fits).
    clearance : float
        Nodes closer than ``clearance`` local spacings to a new segment are dropped,
        and a tip that ends this close to the boundary is carried on to it.
    keep : bool
        Keep every step's solution (`GrowthHistory.write` needs them).
    local : bool
        Re-discretise each increment by a local update (`cnem.geometry.model_update.update`
        and the problem's ``update_from``: only the cells the new segments reach are
        recomputed, the result equals a fresh build); False rebuilds the model and the
        operators from scratch. A problem that refuses the update (enrichment, other
        settings than the previous one) falls back to the full build, said once through
        `logging`.
    refine : "auto", Refinement, float or None
        Nodes graded towards the growing tips (`cnem.fracture.refine`): a disc
        about a tip whose spacing falls to ``refine.spacing`` (a float: that
        spacing) at the tip; the disc moves with the tip and the background nodes
        come back behind it, so the cloud keeps its size. ``cloud`` is then the
        background cloud. ``"auto"`` (default): rings only about a tip whose crack
        kinks too close behind it for the discs of `sif` to stay on the straight
        last segment, graded to a twentieth of that segment
        (`cnem.fracture.refine.auto_refinement`); a straight crack gets none.
        None: never.
    continue_with : "largest", int or callable, optional
        What to do when the cracks cut the body apart. None (default): stop with a
        `GeometryError` naming the pieces. Else go on with one piece: ``"largest"``,
        the index of a piece in the list of pieces sorted largest first, or a callable
        ``continue_with(pieces) -> index`` given that list (shapely Polygons). The
        other pieces are dropped with their nodes; the cracks along the cut become
        boundary, the cracks in a dropped piece go with it (their tips stop), and the
        event ``"split"`` names what was dropped. The remaining body is discretized
        afresh and ``setup`` must still find its supports and loads on it.
    scheme : {"explicit", "corrector"}
        The increment (`cnem.fracture.corrector`). ``"explicit"`` (default): a
        straight segment in the criterion's direction at the tip; the path
        converges to first order in ``increment``. ``"corrector"``: that segment
        is a trial (all tips at once); the trial model is solved and the accepted
        segment is turned by half the kink the criterion finds at the trial tip
        (Heun's predictor-corrector: second order on a smooth path, two solves
        per increment). Each step's turn is ``Step.correction``; the increments,
        load factors and cycles are those of the accepted tips; a tip whose trial
        segment meets the boundary, a hole or a crack takes the predictor's
        direction in that step (event ``"predictor"``).
    progress : bool
        A progress bar over the steps.

    Returns
    -------
    GrowthHistory

    Raises
    ------
    GrowthError
        Bad arguments.
    GeometryError
        The domain has no tip, or the cracks cut the body apart without
        ``continue_with``, or ``setup`` fails on the piece kept (with the run so far
        as the error's ``history``).
    """
    if not isinstance(scheme, str) or scheme not in SCHEMES:
        raise GrowthError(f"scheme: expected one of {sorted(SCHEMES)}, received {scheme!r}")
    if criterion not in CRITERIA:
        raise GrowthError(f"criterion: expected one of {sorted(CRITERIA)}, received {criterion!r}")
    if len(domain.tips) == 0:
        raise GeometryError("grow needs a domain with at least one crack tip (a crack end inside "
                            f"the body), received {domain!r}")
    increment = _positive(increment, "increment")
    if isinstance(steps, bool) or not isinstance(steps, (int, np.integer)) or steps < 0:
        raise GrowthError(f"steps: expected a non-negative integer, received {steps!r}")
    K_Ic = _positive(K_Ic, "K_Ic", allow_none=True)
    if paris is not None:
        if np.shape(check_real("paris", paris, error=GrowthError)) != (2,):
            raise GrowthError(f"paris: expected (C, m), received {paris!r}")
        paris = (_positive(paris[0], "paris C"), _positive(paris[1], "paris m"))
    if exponent is None:
        exponent = paris[1] if paris is not None else 0.0
    elif not np.isfinite(exponent) or exponent < 0:
        raise GrowthError(f"exponent: expected a number >= 0, received {exponent!r}")
    max_kink = _positive(max_kink, "max_kink", allow_none=True)
    clearance = _positive(clearance, "clearance")
    if not (continue_with is None or continue_with == "largest" or callable(continue_with)
            or (isinstance(continue_with, (int, np.integer)) and not isinstance(continue_with, bool)
                and continue_with >= 0)):
        raise GrowthError(f"continue_with: expected None, \"largest\", a piece index >= 0 or "
                          f"a callable(pieces) -> index, received {continue_with!r}")
    if not isinstance(cloud, NodeCloud):
        cloud = irregular(domain, _positive(cloud, "cloud (a spacing)"), seed=0)
    elif cloud.domain is not domain:
        raise GrowthError("cloud: expected a NodeCloud of `domain` (cloud.domain is domain), "
                          "received one of another domain; build it with cnem.nodes from `domain`")
    run = _Run(domain, cloud, setup, criterion, K_Ic, max_kink, measure, radius, keep, bool(local),
               continue_with, as_refinement(refine))
    bar = tqdm(total=steps, desc="crack growth", unit="step", disable=not progress, leave=False)
    sol = run.solve()
    mark = 0                                  # first event of the current step
    now = run.state(sol, 0)
    step = 0
    try:
        while step < steps:
            increments = np.zeros(len(run.rows))
            growing = now["active"] & (now["K"][:, 0] > 0) & (now["K_eq"] > 0)
            for i in np.flatnonzero(now["active"] & ~growing):
                run.event("closed", step, i, now["tips"][i], f"K_I = {now['K'][i, 0]:.4g} <= 0: "
                          "the crack is closed at this tip, which does not grow in this step")
            if not growing.any():
                break
            k_max = now["K_eq"][growing].max()
            increments[growing] = increment * (now["K_eq"][growing] / k_max) ** exponent
            turn = (corrections(run, now, increments, step, clearance) if scheme == "corrector"
                    else np.zeros(len(run.rows)))
            grew = run.advance(now, increments, step, clearance, turn)
            prev, sol_prev, events = now, sol, tuple(run.events[mark:])
            mark = len(run.events)
            if grew:
                sol = run.solve()
                now = run.state(sol, step + 1)
            cycles = _cycles(paris, prev, now, increments) if paris else np.nan
            run.steps.append(Step(**prev, increment=increments, cycles=cycles, events=events,
                                  solution=sol_prev if keep else None, correction=turn))
            bar.update()
            bar.set_postfix(K_eq=f"{k_max:.4g}")
            step += 1
            if not grew:
                break
    except GeometryError as err:
        err.history = _history(run, now, sol, mark)
        raise
    finally:
        bar.close()
    return _history(run, now, sol, mark)


def _history(run, now, sol, mark):
    final = Step(**now, increment=np.zeros(len(run.rows)), events=tuple(run.events[mark:]),
                 solution=sol if run.keep else None, correction=np.zeros(len(run.rows)))
    return GrowthHistory(steps=run.steps, final=final, cracks=[c.copy() for c in run.cracks],
                     domain=run.domain, model=run.model, solution=sol, criterion=run.criterion,
                     events=list(run.events))
