"""Crack-path stability of a double cantilever beam: a slightly kinked crack curves away from the centre line.

The problem
-----------
A double cantilever beam (DCB) of length L = 6 and height 2H = 2 (arms of
height H = 1, so L = 3 x height and the initial crack as long as the height:
the proportions of the meshless and XFEM crack-path studies of the DCB) with
a crack from the middle of the left edge along the centre line to x = a0 = 2,
ending in a short kinked segment of length 0.2 H at an angle theta0 = 1.43,
2.86 or 5.71 degrees (atan 0.025, atan 0.05, atan 0.1) above the centre
line. The arms are pulled apart by equal and opposite end forces P = 1 per
unit thickness (a uniform shear traction P / H on the left end of each arm),
the right end is clamped; E = 1, nu = 0.3, plane strain, K_Ic = 1. Maximum
hoop stress growth (`cnem.fracture.grow`) with increments ``increment`` on a
regular cloud of spacing ``h`` (symmetric about the centre line, so that the
kink is the only asymmetry: with theta0 = 0 the path stays on the line).

What the literature shows
-------------------------
Cotterell & Rice (1980, Int. J. Fract. 16) showed that the path of a crack
slightly off its symmetry line is unstable when the T-stress is positive: the
deviation grows instead of dying out. The bending arms of a DCB give a large
positive T, and the meshless (element-free Galerkin) and XFEM crack-growth
studies of this DCB with the initial angles 1.43, 2.86 and 5.71 degrees show
every path curving away from the centre line towards the face of one arm,
the more and the sooner the larger the initial angle (qualitative: the
set-ups and the loading differ between the papers, so no path is compared
point by point here).

Load and compliance
-------------------
At every increment the critical load (``load_factor = K_Ic / K_eq``: the end
force at which the crack grows, brittle growth) is compared with slender
beam theory, G = 12 P^2 a^2 / (E' B^2 h^3) with B = 1, h = H, a the distance
from the load line to the tip, i.e. K = 2 sqrt(3) P a / h^(3/2) and
P_c = K_Ic h^(3/2) / (2 sqrt(3) a). Beam theory clamps the arms at the tip;
the root rotation of the real arms (Kanninen's beam on an elastic foundation)
makes them behave as if a crack longer by about 0.64 h: P_c is lower by the
factor a / (a + 0.64 h), 24 % at a = 2 h. The table gives both.

Expected result
---------------
* Every kinked path curves away from the centre line (tip y-offset growing
  with crack length) and the offset at a given crack length grows with the
  initial angle; the paths end on the top face of the upper arm, which they
  cut off (`cnem.GeometryError`, the path so far in its ``history``).
  Measured with the defaults (h = 0.05, about 5040 nodes, increment 0.1,
  rings after the kink, ``grow``'s ``refine="auto"``): tip y at crack length
  2.6 / 2.8 / 3.0 / 3.2 is 0.029 / 0.065 / 0.142 / 0.279 (1.43 deg), 0.055 /
  0.118 / 0.239 / 0.411 (2.86 deg), 0.106 / 0.216 / 0.380 / 0.570 (5.71 deg);
  the top face is cut off after 17, 15 and 14 increments.
* The critical end force 0.5 % below the root-rotation-corrected beam theory
  at the first increment (5.71 deg), 23 % below the uncorrected one; the
  compliance 3 % above the corrected bending-only beam (shear adds to it).
  Both part from beam theory as the crack turns into the arm.
* Convergence (2.86 deg, tip y at crack length 2.8): 0.1732 (h = 0.05) and
  0.1746 (h = 0.025) at increment 0.05 -- converged in the spacing; 0.118 /
  0.173 / 0.217 at increments 0.1 / 0.05 / 0.025 -- converging slowly with
  the increment (steps of 0.055 then 0.044: the instability amplifies the lag
  of every straight step). The qualitative result, curving away growing with
  the angle, is the same in every run.
* ``dcb_paths.png``: the three paths over the beam; ``dcb_load.png``: load
  against crack length and load-displacement (opening of the arm ends) for
  the largest angle.
"""

from __future__ import annotations

import pathlib
import warnings
from typing import TYPE_CHECKING

import numpy as np

import cnem
from cnem.cli import demo_parser, positive_float, positive_int

if TYPE_CHECKING:
    from typing import Sequence

__all__ = ["main", "cli"]

L, H, A0, KINK = 6.0, 1.0, 2.0, 0.2
E, NU, P, K_IC = 1.0, 0.3, 1.0, 1.0
#: initial kink angles (degrees): atan(0.025), atan(0.05), atan(0.1)
ANGLES = tuple(float(np.degrees(np.arctan(s))) for s in (0.025, 0.05, 0.1))
#: Kanninen's root-rotation correction of beam theory: a -> a + ROOT h
ROOT = 0.64


#: How long the demo runs at its defaults (its --help says it; see cnem.cli.demo_parser).
RUN_TIME = "about 100 s"


def domain(theta_deg):
    """The beam with a crack along y = 0 ending in a kink of ``theta_deg`` degrees."""
    t = np.radians(theta_deg)
    crack = [[0.0, 0.0], [A0, 0.0], [A0 + KINK * H * np.cos(t), KINK * H * np.sin(t)]]
    return cnem.geometry.rectangle(L, 2 * H, origin=(0.0, -H), cracks=[crack])


def setup(model):
    """End forces +-P on the arms (shear traction P / H on x = 0); right end clamped."""
    tol = 1e-9 * L
    prob = cnem.Elasticity(model, (E, NU), plane="strain")
    prob.add_traction(lambda x, n: np.abs(x[:, 0]) < tol,
                      lambda x, n: np.c_[np.zeros(len(x)), np.sign(x[:, 1]) * P / H])
    prob.add_dirichlet(lambda p: np.abs(p[:, 0] - L) < tol, None)
    return prob


def opening(sol):
    """Opening of the arm ends: u_y(0, H/2) - u_y(0, -H/2) at P = 1."""
    u = sol.displacement(np.array([[0.0, 0.5 * H], [0.0, -0.5 * H]]))
    return float(u[0, 1] - u[1, 1])


def beam_load(a, root=0.0):
    """Critical end force of slender beam theory (``root``: a -> a + root h)."""
    return K_IC * H ** 1.5 / (2 * np.sqrt(3.0) * (np.asarray(a) + root * H))


def beam_compliance(a, root=ROOT):
    """Opening of the arm ends per unit end force of beam theory, 8 (a + root h)^3 / (E' h^3)
    (both arms; bending only)."""
    return 8.0 * (np.asarray(a) + root * H) ** 3 / (cnem.fracture.effective_modulus(E, NU, "strain")
                                                     * H ** 3)


def run(theta_deg, h, increment, steps, progress=False, scheme="explicit"):
    """Grow one kinked crack until ``steps`` increments or until it cuts an arm off
    (``scheme``: the increment of `cnem.fracture.grow`).

    Returns
    -------
    (GrowthHistory, str or None)
        The history and, when an arm came off, the error's message.
    """
    dom = domain(theta_deg)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", cnem.errors.GrowthWarning)   # events printed below
        try:
            hist = cnem.fracture.grow(dom, cnem.nodes.regular(dom, h), setup, increment=increment,
                                      steps=steps, K_Ic=K_IC, measure=opening, keep=False,
                                      scheme=scheme, progress=progress)
            return hist, None
        except cnem.GeometryError as err:
            return err.history, str(err)


def _offsets_table(runs):
    """Tip offset y against crack length, one column per angle (step by step)."""
    n = max(len(r["length"]) for r in runs)
    head = "  ".join(f"{'a':>6} {'y(' + format(r['theta'], '.2f') + ')':>9}" for r in runs)
    print(f"{'step':>4}  {head}")
    for k in range(n):
        cols = []
        for r in runs:
            if k < len(r["length"]):
                cols.append(f"{r['length'][k]:>6.3f} {r['tips'][k, 1]:>9.5f}")
            else:
                cols.append(" " * 16)
        print(f"{k:>4d}  " + "  ".join(cols))


def _load_table(r):
    print(f"theta0 = {r['theta']:.2f} deg: critical end force P_c = K_Ic / K_eq against beam theory "
          f"(a = tip x), and the compliance C (opening of the arm ends per unit end force) against "
          f"beam theory with a + {ROOT} h")
    print(f"{'a':>6} {'y':>8} {'K_I':>8} {'K_II':>8} {'kink':>7} {'P_c':>8} {'beam':>8} "
          f"{'err %':>7} {'+0.64h':>8} {'err %':>7} {'C':>8} {'C beam':>8}")
    for k in range(len(r["length"])):
        a = r["tips"][k, 0]
        pb, pc = beam_load(a), beam_load(a, ROOT)
        print(f"{a:>6.3f} {r['tips'][k, 1]:>8.4f} {r['K'][k, 0]:>8.4f} {r['K'][k, 1]:>8.4f} "
              f"{r['kink_deg'][k]:>7.2f} {r['load'][k]:>8.5f} {pb:>8.5f} "
              f"{100 * (r['load'][k] / pb - 1):>7.2f} {pc:>8.5f} {100 * (r['load'][k] / pc - 1):>7.2f} "
              f"{r['measure'][k]:>8.2f} {beam_compliance(a):>8.2f}")


def _record(theta, hist, message):
    return dict(theta=theta, tips=hist.paths()[:, 0], length=hist.array("crack_length")[:, 0],
                K=hist.array("K")[:, 0], kink_deg=np.degrees(hist.array("angle")[:, 0]),
                load=hist.array("load_factor")[:, 0], measure=hist.array("measure"),
                cut=message is not None, message=message, cracks=hist.cracks,
                events=[str(e) for e in hist.events], history=hist)


def _paths_figure(runs, path):
    from cnem.plot.charts import offscreen_pyplot
    plt = offscreen_pyplot()
    fig, ax = plt.subplots(figsize=(10.0, 4.2))
    ax.plot([0, L, L, 0, 0], [-H, -H, H, H, -H], "k-", lw=1.0)
    ax.plot([0, A0], [0, 0], "k-", lw=2.0, label="initial crack")
    ax.plot([0, L], [0, 0], "k:", lw=0.8)
    for r in runs:
        xy = np.vstack([[A0, 0.0], r["tips"]])          # from the end of the straight crack
        ax.plot(xy[:, 0], xy[:, 1], "o-", ms=2.5, lw=1.5,
                label=rf"$\theta_0$ = {r['theta']:.2f}°"
                + (" (ends on the top face)" if xy[-1, 1] > 0.9 * H else ""))
    ax.annotate("", xy=(0.0, 0.9 * H), xytext=(0.0, 0.45 * H),
                arrowprops=dict(arrowstyle="->", color="tab:red"))
    ax.annotate("", xy=(0.0, -0.9 * H), xytext=(0.0, -0.45 * H),
                arrowprops=dict(arrowstyle="->", color="tab:red"))
    ax.plot([], [], color="tab:red", lw=1.0, label="end forces (opening the arms)")
    ax.set_aspect("equal")
    ax.set_xlabel(r"$x$ ($H$)")
    ax.set_ylabel(r"$y$ ($H$)")
    ax.set_title("DCB: paths of slightly kinked cracks (max hoop stress)")
    ax.legend(loc="lower right", fontsize=8, framealpha=0.9)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def _load_figure(r, path):
    """`GrowthHistory.plot` ``kind="load"`` with the straight crack of beam theory beside it."""
    from cnem.plot.charts import offscreen_pyplot
    plt = offscreen_pyplot()
    fig = r["history"].plot(None, kind="load", length_unit="$H$",
                            load_unit=r"$K_\mathrm{Ic}\sqrt{H}$",
                            displacement_unit=r"$K_\mathrm{Ic} / E\sqrt{H}$",
                            title=rf"DCB, $\theta_0$ = {r['theta']:.2f}°: end force for growth")
    a = np.linspace(r["length"][0], r["length"][-1], 100)
    load, opening = fig.axes[0], fig.axes[1]
    load.plot(a, beam_load(a), "k--", lw=1.0, label="beam theory, straight crack")
    load.plot(a, beam_load(a, ROOT), "k-", lw=1.0, label=f"beam theory, $a$ + {ROOT} $h$")
    load.legend(fontsize=8)
    opening.plot(beam_load(a, ROOT) * beam_compliance(a), beam_load(a, ROOT), "k-", lw=1.0,
                 label=f"beam theory, $a$ + {ROOT} $h$, straight crack")
    opening.legend(fontsize=8)
    fig.savefig(path, dpi=130)
    plt.close(fig)


def _convergence(theta, h, increment, steps, base, progress):
    """The same angle with half the spacing and half the increment: the tip offsets
    of both runs at the crack lengths of the coarse one."""
    hist, message = run(theta, 0.5 * h, 0.5 * increment, 2 * steps, progress)
    fine = _record(theta, hist, message)
    a = base["length"]
    inside = a <= fine["length"][-1]
    y_fine = np.interp(a[inside], fine["length"], fine["tips"][:, 1])
    diff = np.abs(y_fine - base["tips"][inside, 1])
    print(f"convergence, theta0 = {theta:.2f} deg: h {h:g} -> {0.5 * h:g}, increment {increment:g} "
          f"-> {0.5 * increment:g}")
    print(f"{'a':>6} {'y coarse':>9} {'y fine':>9} {'diff':>8}")
    for k in np.flatnonzero(inside):
        print(f"{a[k]:>6.3f} {base['tips'][k, 1]:>9.5f} {y_fine[k]:>9.5f} {diff[k]:>8.5f}")
    return dict(theta=theta, length=a[inside], coarse=base["tips"][inside, 1], fine=y_fine,
                max_difference=float(diff.max()), fine_run=fine)


def main(h: float = 0.05, *, increment: float = 0.1, steps: int = 30, angles: tuple = ANGLES,
         converge: float | None = None, outdir: str = "results/growth_dcb", plot: bool = True,
         progress: bool = True) -> dict:
    """Grow the kinked DCB crack for every initial angle (``converge``: one angle also with
    half the spacing and half the increment).

    Returns
    -------
    dict
        ``runs`` (per angle: ``theta``, ``tips (s + 1, 2)``, ``length``, ``K (s + 1, 2)``,
        ``kink_deg``, ``load`` (critical end force), ``measure`` (opening at P = 1),
        ``cut`` (the run ended on a `GeometryError`, the crack at the top face),
        ``message`` (its text), ``events``), ``beam`` and ``beam_root``
        (the beam-theory critical loads at the tips of each run), ``convergence``
        (or None), ``files``.
    """
    out = pathlib.Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    runs = []
    for theta in angles:
        hist, message = run(theta, h, increment, steps, progress)
        r = _record(theta, hist, message)
        r["beam"], r["beam_root"] = beam_load(r["tips"][:, 0]), beam_load(r["tips"][:, 0], ROOT)
        runs.append(r)
        print(f"theta0 = {theta:.2f} deg: {len(r['length']) - 1} increments, "
              f"{len(hist.model.nodes)} nodes" + (f"; {message.split(';')[0]}" if message else ""))
    print(f"tip offset y against crack length a (h = {h:g}, increment {increment:g}; units of H):")
    _offsets_table(runs)
    _load_table(runs[-1])
    conv = None
    if converge is not None:                    # the run of the nearest angle
        base = min(runs, key=lambda r: abs(r["theta"] - converge))
        conv = _convergence(base["theta"], h, increment, steps, base, progress)
    files = []
    if plot:
        _paths_figure(runs, out / "dcb_paths.png")
        _load_figure(runs[-1], out / "dcb_load.png")
        files = [out / "dcb_paths.png", out / "dcb_load.png"]
    for f in files:
        print(f"wrote {f}")
    return dict(runs=runs, convergence=conv, files=[str(f) for f in files])


def cli(argv: Sequence[str] | None = None, prog: str | None = None) -> None:
    """Command line: ``python -m cnem.demos.growth_dcb --help`` or ``cnem demo growth-dcb``."""
    parser = demo_parser(__file__, __doc__, prog, run_time=RUN_TIME)
    parser.add_argument("--h", type=positive_float, default=0.05, help="node spacing (units of H)")
    parser.add_argument("--increment", type=positive_float, default=0.1, help="crack increment (units of H)")
    parser.add_argument("--steps", type=positive_int, default=30, help="growth increments")
    parser.add_argument("--angles", type=float, nargs="+", default=list(ANGLES),
                        help="initial kink angles (degrees)")
    parser.add_argument("--converge", type=positive_float, default=None,
                        help="an angle (the nearest one is taken): run it again with h / 2 and increment / 2")
    args = parser.parse_args(argv)
    return main(args.h, increment=args.increment, steps=args.steps, angles=tuple(args.angles),
                converge=args.converge, outdir=args.out, plot=not args.no_plot)


if __name__ == "__main__":
    cli()
