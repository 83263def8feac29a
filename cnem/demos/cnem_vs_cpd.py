"""Finite-strain C-NEM against CPD on the same nodes: tension, cantilever, L-shape, torsion.

Uniaxial tension to 100 % stretch, a bent cantilever, the L-shape and the torsion of a
square column (issue 38 item 4; the seed paper's §6.1-6.4 examples).

The problems
------------
One node cloud (`cnem.nodes.regular`, or ``irregular``) is solved twice:

* by C-NEM, `cnem.Hyperelasticity` (total Lagrangian SCNI, sub-cell stabilisation 1), and
* by CPD, `cnem.pd.CPD` on `cnem.pd.Body.from_cloud` of the same cloud (the nodes with
  their cell areas as volumes), at horizons of 2, 3 and 4 node spacings,

with the same energy: CPD's one-neighbour Seth-Hill energy ``C1 |Xi| S_n(lam)^2 / 2``
(C2 = 0) integrated over a full horizon is the continuum law
`cnem.demos.cpd.bond_law.BondContinuum` ``W(F) = 4 mu / pi int p_n(|F M|) dtheta``
(a Cauchy solid, lam = mu; for n = 2 exactly Saint Venant-Kirchhoff with nu = 1/4), which
C-NEM solves. C1 is calibrated per horizon so that CPD's *interior* points have that
``mu``: C1 = mu / (f pi delta^3 / 24), ``f`` the lattice sum of the interior bonds against
its continuum value (`cnem.demos.cpd.versus.bulk_factor`, printed; 0.67-0.94 here).
Everything is in units of ``mu = 1`` and the length of the model; thickness 1.

1. **Tension** (n = 1, the paper's Figure 5 law): a 2 x 1 strip between rollers (left
   edge ``u_x = 0``, its lower corner ``u_y = 0``, right edge ``u_x = L (lambda - 1)``),
   lateral edges free, to ``lambda = 2`` in 8 load steps. Force-stretch: the reaction of
   the right grip against the closed form of the homogeneous state
   (``P22(lambda, b) = 0`` for the lateral stretch b, force ``P11 H``).
2. **Cantilever** (n = 2, the paper's Figure 7 law): a 5 x 1 beam clamped on its left
   edge, a downward load P on its right edge (C-NEM: a dead traction P/H; CPD: P shared
   by the edge's points), to P = 0.008 in 8 load steps (tip deflection about 0.3 of the
   length). Tip deflection (mean over the right edge) against load, with the small-load
   linear limit: `cnem.Elasticity` on the same model with the linearised law.
3. **L-shape** (n = 1, the paper's Figure 10 law; `cnem.demos.cpd.lshape`): the unit
   square less its top-right quarter at spacing ``h / 2``, bottom clamped, the top of
   the left arm pulled up by 1e-3 (``u_x = 0`` there), one step. Profiles of ``u_y``
   along the column ``x = 1/2`` and the row ``y = 1/2`` through the re-entrant corner.
4. **Torsion** (3-D, n = 2; `cnem.demos.cpd.torsion`): a 1 x 1 x 4 column at spacing
   ``2 h``, bottom clamped, top turned rigidly to 90 degrees with ``u_z`` held, in
   ``steps // 2`` increments after a 0.5 degree twist. CPD's one-neighbour n = 2 energy
   over a horizon ball is exactly Saint Venant-Kirchhoff with lambda = mu (C-NEM solves
   that); C1 from the lattice sum of the regular lattice. Torque and axial force (the
   Poynting effect) against the twist, with Saint-Venant's ``0.1406 mu a^4 theta / L``.

Horizons are in `cnem.pd.Body.from_cloud`'s spacings ``sqrt(area / n)`` (0.093 and
0.094 here: the regular cloud's boundary nodes count).

Expected result (``h = 0.1``, regular cloud; 231, 561, 341 and 756 nodes)
-------------------------------------------------------------------------------
* Tension: C-NEM is the closed form to round-off at every stretch (SCNI passes the
  finite-strain patch test): 0.71548, 1.50749, 3.23888 at stretch 1.25, 1.5, 2. CPD is
  softer, by -20 %/-15 % (2 spacings, at 1.25/2), -25 % (3) and -41 % (4): a fraction
  that grows with the horizon and hardly with the stretch. With the same energy the
  finite-strain kinematics agree; the difference is CPD's *surface effect*: points
  within a horizon of the free lateral edges miss bonds, so a skin a horizon thick on
  each side of the strip is softer, and the strip contracts less (lateral stretch 0.70-
  0.74 against 0.683). The difference field peaks next to the grips, where the
  prescribed columns meet points with few bonds.
* Cantilever: C-NEM starts on the linear answer (0.9986 of it at the first load) and
  stiffens as the beam turns (1.427 against 1.546 at P = 0.008). CPD bends more: +39 %,
  +57 %, +79 % at the smallest load, as bending loads the soft skin; at 4 spacings its
  curve jumps between P = 0.006 and 0.007 when the bonds next to the clamp's lower corner
  collapse (smallest bond stretch 0.07; the SVK bond energy does not resist it). The
  difference field grows from the clamp to the tip. The CPD curves approach C-NEM's as
  the horizon shrinks. (The tables and the reasons: ``docs/finite_strain.md``.)
* L-shape (341 nodes): the profiles agree to 6-9 % of the largest displacement on the
  row and 9-26 % on the column (2 to 4 spacings); CPD's corner is softer (u_y 0.32 pull
  against C-NEM's 0.35) and its column, whose points near the clamp miss bonds, rises
  faster from the clamped edge.
* Torsion (``--example torsion``; 756 nodes, ~14 min on the loaded shared machine, C-NEM's
  3-D Newton most of it): C-NEM starts on Saint-Venant's torque (1.009 of it at 0.5
  degree) and stiffens slightly (1.017 at 90 degrees); the grip has to pull (N > 0:
  this compressible SVK column would shorten, a negative Poynting effect), N growing as
  theta^2. CPD's torque is 0.64, 0.48, 0.36 of C-NEM's at 2, 3, 4 spacings and its N
  about half: on a section 5 spacings wide every point is within a horizon of a free
  face (``docs/finite_strain.md``).
* Pictures ``tension.png``, ``cantilever.png``, ``lshape.png`` (displacements drawn
  x 100): the deformed C-NEM and CPD (3 spacings) bodies over the undeformed outline, the
  difference ``|u_CPD - u_C-NEM|`` on the deformed C-NEM body, and the curves (the
  profiles) of every horizon; ``torsion.png``: the twisted columns and their difference
  (pyvista) over the torque and axial-force curves.

Run ``python demos/cnem_vs_cpd.py --help`` or ``cnem pd cnem-vs-cpd --help``.
"""

from __future__ import annotations

import pathlib
from typing import TYPE_CHECKING

import numpy as np
from scipy.optimize import brentq

import cnem
from cnem.cli import demo_parser, positive_float, positive_int
from cnem.errors import OptionError
from cnem.demos.cpd.bond_law import BondContinuum
from cnem.demos.cpd.lshape import lshape_runs
from cnem.demos.cpd.pictures import compare_picture
from cnem.demos.cpd.torsion import SAINT_VENANT_SQUARE, grip_loads, twist_cnem, twist_cpd
from cnem.demos.cpd.torsion_picture import torsion_picture
from cnem.demos.cpd.versus import run_cnem, run_cpd
from .._sets import distinct

if TYPE_CHECKING:
    from typing import Sequence

__all__ = ["main", "cli", "tension_closed_form", "CLOUDS"]

#: Node clouds the demo can use.
CLOUDS = ("regular", "irregular")
#: Stretches of the force table.
TABLE_STRETCHES = (1.25, 1.5, 2.0)
#: How long the demo runs at its defaults (its --help says it; see cnem.cli.demo_parser).
RUN_TIME = "about 30 s (the 2-D examples; --example all adds the 3-D torsion: ~15 min)"


def tension_closed_form(law: BondContinuum, stretch: float) -> tuple[float, float]:
    """Lateral stretch ``b`` and nominal stress ``P11`` of the homogeneous uniaxial state
    ``F = diag(stretch, b)`` of ``law`` with ``P22 = 0`` (one root in ``(0.05, 1]``)."""
    def lateral(b):
        return law.evaluate(np.diag([stretch, b])[None], tangent=False)[1][0, 1, 1]
    b = brentq(lateral, 0.05, 1.0, xtol=1e-14) if stretch != 1 else 1.0
    return b, float(law.evaluate(np.diag([stretch, b])[None], tangent=False)[1][0, 0, 0])


def _cloud(domain, h, kind):
    return cnem.nodes.regular(domain, h) if kind == "regular" else \
        cnem.nodes.irregular(domain, h, seed=1)


def _interior(length, height):
    """``inside(body)``: the points whose bonds, partial ones included (they reach half a
    spacing past the horizon), all end at interior points (on a body too thin for any,
    the points farthest from the edges)."""
    def inside(body):
        p = body.points
        depth = np.minimum.reduce([p[:, 0], length - p[:, 0], p[:, 1], height - p[:, 1]])
        reach = body.horizon + 0.5 * np.sqrt(np.median(body.volumes) / body.thickness)
        return depth > min(reach, depth.max() * (1 - 1e-9))
    return inside


def tension(h: float, factors: Sequence[float], steps: int, cloud: str) -> dict:
    """Example 1: the runs, the force table and the closed form."""
    length, height, law = 2.0, 1.0, BondContinuum(1.0, exponent=1.0)
    tol = 1e-9 * length
    nodes = _cloud(cnem.geometry.rectangle(length, height), h, cloud)
    model = cnem.discretize(nodes, progress=False)
    left = lambda p: p[:, 0] < tol                                       # noqa: E731
    right = lambda p: p[:, 0] > length - tol                             # noqa: E731
    dirichlet = [(left, 0, 0.0), (lambda p: left(p) & (p[:, 1] < tol), 1, 0.0),
                 (right, 0, length)]                                     # to stretch 2
    runs = {"C-NEM": run_cnem(model, law, dirichlet, None, steps)}
    for m in factors:
        runs[f"CPD {m:g}h"] = run_cpd(nodes, m, law, _interior(length, height), dirichlet,
                                      None, steps)
    grip = right(model.nodes)
    stretch = 1.0 + runs["C-NEM"].factor
    curves = {name: run.force[:, grip, 0].sum(axis=1) for name, run in runs.items()}
    exact = np.array([tension_closed_form(law, s)[1] * height for s in stretch])
    fine = np.linspace(1.0, 2.0, 41)
    closed = np.array([tension_closed_form(law, s)[1] * height for s in fine])
    b_exact = tension_closed_form(law, 2.0)[0]
    middle = np.abs(model.nodes[:, 0] - length / 2) < 0.5 * h
    top, bottom = middle & (model.nodes[:, 1] > height - tol), middle & (model.nodes[:, 1] < tol)
    width = {name: (height + run.u[-1][top, 1].mean() - run.u[-1][bottom, 1].mean()) / height
             for name, run in runs.items()}
    lines = [f"Tension of a {length:g} x {height:g} strip, {len(model.nodes)} nodes ({cloud}, "
             f"h = {h:g}), BondContinuum n = 1, mu = 1: grip force",
             f"{'stretch':>8}{'closed form':>13}" + "".join(f"{k:>12}" for k in runs)]
    for s in TABLE_STRETCHES:
        k = int(np.argmin(np.abs(stretch - s)))
        lines.append(f"{stretch[k]:>8.3f}{exact[k]:>13.5f}"
                     + "".join(f"{c[k]:>12.5f}" for c in curves.values()))
    lines.append(f"{'rel. diff':>8}{'at 2':>13}" + "".join(
        f"{c[-1] / exact[-1] - 1:>+12.2%}" for c in curves.values()))
    lines.append(f"lateral stretch at mid-length, stretch 2: closed form {b_exact:.4f}; "
                 + ", ".join(f"{k} {v:.4f}" for k, v in width.items()))
    lines.append("CPD C1 (bulk factor f): " + ", ".join(
        f"{k} {r.C1:.4g} ({r.bulk:.3f})" for k, r in runs.items() if k != "C-NEM"))
    return dict(model=model, runs=runs, stretch=stretch, force=curves, exact=exact,
                closed=(fine, closed), width=width, lateral=b_exact, lines=lines,
                x=stretch, xlabel="stretch $\\lambda$", ylabel="grip force $F$ ($\\mu H$)")


def cantilever(h: float, factors: Sequence[float], steps: int, cloud: str,
               load: float = 0.008) -> dict:
    """Example 2: the runs, the tip-deflection table and the linear limit."""
    length, height, law = 5.0, 1.0, BondContinuum(1.0, exponent=2.0)
    tol = 1e-9 * length
    nodes = _cloud(cnem.geometry.rectangle(length, height), h, cloud)
    model = cnem.discretize(nodes, progress=False)
    clamp = lambda p: p[:, 0] < tol                                      # noqa: E731
    tip = model.nodes[:, 0] > length - tol
    dirichlet = [(clamp, None, 0.0)]
    traction = (lambda x, n: x[:, 0] > length - tol, np.array([0.0, -load / height]))
    forces = np.zeros((len(model.nodes), 2))
    forces[tip, 1] = -load / tip.sum()
    runs = {"C-NEM": run_cnem(model, law, dirichlet, traction, steps)}
    for m in factors:
        runs[f"CPD {m:g}h"] = run_cpd(nodes, m, law, _interior(length, height), dirichlet,
                                      forces, steps)
    linear = cnem.Elasticity(model, law.linearized(), plane="strain")
    linear.add_dirichlet(clamp, None, 0.0)
    linear.add_traction(*traction)
    per_load = -linear.solve(progress=False).u[tip, 1].mean() / load
    loads = load * runs["C-NEM"].factor
    deflection = {name: -run.u[:, tip, 1].mean(axis=1) for name, run in runs.items()}
    lines = [f"Cantilever {length:g} x {height:g}, {len(model.nodes)} nodes ({cloud}, h = {h:g}),"
             f" BondContinuum n = 2 (SVK, nu = 1/4), mu = 1: tip deflection",
             f"{'load':>8}{'linear':>10}" + "".join(f"{k:>12}" for k in runs)]
    for k in sorted({0, len(loads) // 2 - 1, len(loads) - 1}):
        lines.append(f"{loads[k]:>8.4f}{per_load * loads[k]:>10.4f}"
                     + "".join(f"{d[k]:>12.4f}" for d in deflection.values()))
    lines.append(f"{'rel. diff':>8}{'last':>10}" + "".join(
        f"{d[-1] / deflection['C-NEM'][-1] - 1:>+12.2%}" for d in deflection.values()))
    lines.append(f"C-NEM at the first load / linear: "
                 f"{deflection['C-NEM'][0] / (per_load * loads[0]):.4f}; CPD C1 (bulk factor "
                 f"f): " + ", ".join(f"{k} {r.C1:.4g} ({r.bulk:.3f})" for k, r in runs.items()
                                     if k != "C-NEM"))
    return dict(model=model, runs=runs, loads=loads, deflection=deflection,
                linear_per_load=per_load, lines=lines, force=deflection, x=loads,
                closed=(np.array([0.0, loads[-1]]), per_load * np.array([0.0, loads[-1]])),
                xlabel="load $P$ ($\\mu H$)", ylabel="tip deflection ($H$)")


def lshape(h: float, factors: Sequence[float], steps: int, cloud: str) -> dict:
    """Example 3 (2-D, spacing ``h / 2``; ``steps`` unused: one small step): the
    displacement profiles along the row and the column through the re-entrant corner."""
    res = lshape_runs(h / 2, factors, cloud)
    pull, row, column = res["pull"], res["row"], res["column"]
    path = np.concatenate([column[::-1], row[1:]])            # bottom -> corner -> left
    s = np.concatenate([-res["distance"][1][::-1], res["distance"][0][1:]])
    profile = {k: run.u[-1][path, 1] / pull for k, run in res["runs"].items()}
    ref = res["runs"]["C-NEM"].u[-1]
    lines = [f"L-shape (unit square less its top-right quarter), {len(res['model'].nodes)} nodes "
             f"({cloud}, h = {h / 2:g}), BondContinuum n = 1, mu = 1, u_y = {pull:g} at the top "
             f"of the left arm: u_y / pull along column (s < 0) and row (s > 0)",
             f"{'s':>8}" + "".join(f"{k:>12}" for k in profile)]
    for k in distinct(np.linspace(0, len(s) - 1, 7).round().astype(int)):
        lines.append(f"{s[k]:>8.3f}" + "".join(f"{p[k]:>12.4f}" for p in profile.values()))
    for name, line in (("row", row), ("column", column)):
        scale = np.linalg.norm(ref[line], axis=1).max()
        lines.append(f"max |u_CPD - u_C-NEM| / max |u_C-NEM| on the {name}: " + ", ".join(
            f"{k} {np.linalg.norm(r.u[-1][line] - ref[line], axis=1).max() / scale:.1%}"
            for k, r in res["runs"].items() if k != "C-NEM"))
    return dict(res, lines=lines, force=profile, x=s, closed=None, origin=None,
                magnify=0.1 / pull, xlabel="$s$: column $x = 1/2$ ($s < 0$, from the "
                "bottom), row $y = 1/2$ ($s > 0$, leftwards)", ylabel="$u_y$ / pull",
                curve_title="L-shape: $u_y$ through the re-entrant corner ($s = 0$)")


def torsion(h: float, factors: Sequence[float], steps: int, cloud: str) -> dict:
    """Example 4 (3-D, spacing ``2 h``): torque and axial force of the square column
    against the twist, to 90 degrees in ``max(2, steps // 2)`` increments after a small
    first twist (the linear range)."""
    length, spacing = 4.0, 2 * h
    nodes = _cloud(cnem.geometry.box((0.0, 0.0, 0.0), (1.0, 1.0, length)), spacing, cloud)
    model = cnem.discretize(nodes, progress=False)
    increments = max(2, steps // 2)
    degrees = np.concatenate([[0.5], 90.0 * np.arange(1, increments + 1) / increments])
    angles = np.radians(degrees)
    runs = {"C-NEM": twist_cnem(model, 1.0, length, angles)}
    for m in factors:
        runs[f"CPD {m:g}h"] = twist_cpd(nodes, m, 1.0, spacing, length, angles)
    loads = {k: grip_loads(model.nodes, r) for k, r in runs.items()}
    torque = {k: v[0] for k, v in loads.items()}
    axial = {k: v[1] for k, v in loads.items()}
    saint_venant = SAINT_VENANT_SQUARE / length                     # torque per radian
    lines = [f"Torsion of a 1 x 1 x {length:g} column, {len(model.nodes)} nodes ({cloud}, "
             f"h = {spacing:g}), SVK lambda = mu = 1 (CPD n = 2, C1 only), top turned by "
             f"theta, u_z held: torque T and axial force N",
             f"{'theta':>6}{'SV T':>9}" + "".join(f"{'T ' + k:>13}" for k in runs)
             + "".join(f"{'N ' + k:>13}" for k in runs)]
    for k in range(len(degrees)):
        lines.append(f"{degrees[k]:>6.1f}{saint_venant * angles[k]:>9.5f}"
                     + "".join(f"{t[k]:>13.6f}" for t in torque.values())
                     + "".join(f"{n[k]:>13.3e}" for n in axial.values()))
    lines.append("T / T_C-NEM at 90 deg: " + ", ".join(
        f"{k} {t[-1] / torque['C-NEM'][-1]:.3f}" for k, t in torque.items() if k != "C-NEM")
        + f"; C-NEM T at {degrees[0]:g} deg / Saint-Venant "
        f"{torque['C-NEM'][0] / (saint_venant * angles[0]):.4f}")
    lines.append("CPD C1 (lattice factor f; pairs, triplets that C2, C3 > 0 would add): "
                 + ", ".join(f"{k} {r.C1:.4g} ({r.bulk:.3f}; {r.pairs:.3g}, {r.triplets:.3g})"
                             for k, r in runs.items() if k != "C-NEM"))
    return dict(model=model, points=model.nodes, runs=runs, degrees=degrees, torque=torque,
                axial=axial, saint_venant=saint_venant, lines=lines)


EXAMPLES = {"tension": tension, "cantilever": cantilever, "lshape": lshape, "torsion": torsion}
#: What runs by default: the 2-D examples (the 3-D torsion takes minutes: ``--example
#: torsion`` or ``all``).
DEFAULT_EXAMPLES = ("tension", "cantilever", "lshape")


def main(h: float = 0.1, factors: Sequence[float] = (2.0, 3.0, 4.0), *, steps: int = 8,
         cloud: str = "regular", examples: Sequence[str] = DEFAULT_EXAMPLES,
         outdir: str = "results/cnem_vs_cpd", plot: bool = True) -> dict:
    """Run the examples, print their tables and Newton counts, write their pictures.

    Parameters
    ----------
    h : float
        Node spacing (the strip is 2 x 1, the beam 5 x 1); the L-shape (1 x 1) uses
        ``h / 2``, the column (1 x 1 x 4) ``2 h``.
    factors : sequence of float
        CPD horizons in node spacings.
    steps : int
        Load steps of every run.
    cloud : {"regular", "irregular"}
    examples : sequence of {"tension", "cantilever", "lshape", "torsion"}

    Returns
    -------
    dict
        Example name -> its numbers (``runs``: C-NEM and each CPD, see
        `cnem.demos.cpd.versus.Run`; ``force`` per run per load step, ...) and
        ``files``.
    """
    if cloud not in CLOUDS:
        raise OptionError(f"cloud: expected one of {CLOUDS}, received {cloud!r}")
    unknown = [e for e in examples if e not in EXAMPLES]
    if unknown:
        raise OptionError(f"examples: expected names from {tuple(EXAMPLES)}, received {unknown}")
    out, files = {}, []
    for name in examples:
        res = EXAMPLES[name](h, factors, steps, cloud)
        print("\n".join(res["lines"]))
        print("Newton iterations (seconds): " + ", ".join(
            f"{k} {r.iterations} ({r.seconds:.2f} s)" for k, r in res["runs"].items()) + "\n")
        if plot:
            path = pathlib.Path(outdir) / f"{name}.png"
            path.parent.mkdir(parents=True, exist_ok=True)
            middle = [k for k in res["runs"] if k != "C-NEM"][len(factors) // 2]
            draw = torsion_picture if name == "torsion" else \
                lambda p, r, c: compare_picture(p, r, c, name)
            files.append(draw(str(path), res, middle))
            print(f"wrote {files[-1]}")
        out[name] = res
    out["files"] = files
    return out


def cli(argv: Sequence[str] | None = None, prog: str | None = None) -> dict:
    """Command line: ``python demos/cnem_vs_cpd.py --help`` or ``cnem pd cnem-vs-cpd``."""
    parser = demo_parser(__file__, __doc__, prog, run_time=RUN_TIME)
    parser.add_argument("--h", type=positive_float, default=0.1, help="node spacing")
    parser.add_argument("--factors", type=positive_float, nargs="+", default=[2.0, 3.0, 4.0],
                        help="CPD horizons in node spacings")
    parser.add_argument("--steps", type=positive_int, default=8, help="load steps")
    parser.add_argument("--cloud", choices=CLOUDS, default="regular", help="node cloud")
    parser.add_argument("--example", choices=tuple(EXAMPLES) + ("2d", "all"), default="2d",
                        help="the example to run (2d: tension, cantilever and lshape; all: "
                             "with the 3-D torsion, about 15 min at the defaults on a loaded "
                             "2-core machine)")
    args = parser.parse_args(argv)
    examples = {"all": tuple(EXAMPLES), "2d": DEFAULT_EXAMPLES}.get(args.example,
                                                                     (args.example,))
    return main(args.h, tuple(args.factors), steps=args.steps, cloud=args.cloud,
                examples=examples, outdir=args.out, plot=not args.no_plot)


if __name__ == "__main__":
    cli()
