"""A central crack under remote tension, solved on one node cloud by C-NEM and by state-based PD.

The problem
-----------
A square plate of side 2W = 2 with a central crack of length 2a = 0.5 along
the x axis, remote tension sigma = 1 on the top and bottom edges, E = 1,
nu = 0.3, plane stress; the bottom-left corner pinned and the bottom-right
corner held vertically. The same regular cloud (`cnem.nodes.regular`) is used
twice:

* C-NEM + SCNI (`cnem.Elasticity`), K_I by the interaction integral;
* ordinary state-based peridynamics (LPS, `cnem.pd.StateBased`) on the very
  nodes of the C-NEM model (`cnem.pd.Body.from_cloud`: the crack-face nodes
  are doubled, the cell areas are the volumes, no bond crosses the crack),
  horizon delta = 3h, surface correction on; the edge tractions are applied
  as body forces on the edge points (the nodal forces of the C-NEM load
  vector divided by the point volumes); K_I estimated from the crack opening
  near the tip, delta_y(r) = (8 K_I / E) sqrt(r / 2 pi).

Both are compared with Griffith's opening of a crack in an infinite plate,
delta_y(x) = 4 sigma / E sqrt(a^2 - x^2), and K_I = sigma sqrt(pi a) (the
finite plate, a / W = 0.25, raises K_I by about 3-4 %).

Expected result
---------------
* Both openings follow Griffith's ellipse within a few % (the finite plate
  opens about 4 % more), C-NEM (with its default sub-cell stabilisation: plain
  SCNI lets the face nodes oscillate) and PD alike.
* The PD opening and its K_I converge as h (and delta = 3h) shrink.
* Pictures in ``outdir``: ``pd_cnem_opening.png`` (opening profiles),
  ``pd_cnem_difference.png`` (|u_PD - u_C-NEM| on the nodes).
"""

from __future__ import annotations

import pathlib
import sys
from typing import TYPE_CHECKING

import numpy as np
from tqdm.auto import tqdm

import cnem
import cnem.pd as pd
from cnem.cli import demo_parser, positive_int
from cnem.exact import CentralCrack
from cnem.fracture import sif
from cnem.fracture.opening import crack_opening, k_from_opening

if TYPE_CHECKING:
    from typing import Sequence

__all__ = ["main", "cli", "study"]

W, A, SIGMA, E, NU = 1.0, 0.25, 1.0, 1.0, 0.3
SPACINGS = (1 / 16, 1 / 32, 1 / 64)
TOL = 1e-9


#: How long the demo runs at its defaults (its --help says it; see cnem.cli.demo_parser).
RUN_TIME = "about 1 min"


def domain():
    return cnem.geometry.rectangle(2 * W, 2 * W, origin=(-W, -W), cracks=[[[-A, 0.0], [A, 0.0]]])


def supports(prob):
    prob.add_dirichlet(lambda p: np.hypot(*(p - [-W, -W]).T) < TOL, None)
    prob.add_dirichlet(lambda p: np.hypot(*(p - [W, -W]).T) < TOL, 1)


def solve_cnem(cloud):
    model = cnem.discretize(cloud, progress=False)
    prob = cnem.Elasticity(model, (E, NU), plane="stress")
    prob.add_traction(lambda x, n: np.abs(np.abs(x[:, 1]) - W) < TOL, lambda x, n: SIGMA * n * [0.0, 1.0])
    supports(prob)
    return prob, prob.solve(progress=False)


def solve_pd(cloud, cnem_problem, horizon_factor=3.0):
    body = pd.Body.from_cloud(cloud, horizon_factor)
    forces = cnem_problem.load().reshape(-1, 2)            # exact edge integrals of the tractions
    prob = pd.Problem(body, pd.StateBased(E, NU), plane="stress")
    prob.add_body_force(lambda p: forces / body.volumes[:, None])
    supports(prob)
    return body, prob.solve()


def opening(model, u):
    """Crack opening ``u_y(upper) - u_y(lower)`` at the crack-face point pairs, by x."""
    points, delta, _ = crack_opening(model, u, [(-A, 0.0), (A, 0.0)])
    return points[:, 0], delta


def griffith(x):
    """Griffith's opening of the crack in an infinite plate."""
    return CentralCrack(A, SIGMA).opening(x, E)


def k_from_tips(x, delta, h):
    """K_I fitted to the opening at 2h < r < a/2 from both tips (`k_from_opening`); ``nan``
    when the cloud is too coarse to put a node there (h >= a/6: `table` says so)."""
    r = A - np.abs(x)
    return k_from_opening(r, delta, E, NU, "stress", where=(r > 2 * h) & (r < 0.5 * A))


def study(spacings: tuple = SPACINGS) -> list[dict]:
    rows = []
    for h in tqdm(spacings, desc="clouds", disable=not sys.stderr.isatty(), leave=False):
        cloud = cnem.nodes.regular(domain(), h)
        cprob, csol = solve_cnem(cloud)
        body, psol = solve_pd(cloud, cprob)
        model = csol.model
        x, dc = opening(model, csol.u)
        _, dp = opening(model, psol.u)
        g = griffith(x)
        rows.append(dict(h=h, nodes=len(model.nodes), bonds=len(body.bond_i), x=x, cnem=dc, pd=dp,
                         griffith=g,
                         cnem_error=float(np.abs(dc - g).max() / g.max()),
                         pd_error=float(np.abs(dp - g).max() / g.max()),
                         K_cnem=float(sif(csol, (A, 0.0), radius=0.4 * A)[0]),
                         K_pd=k_from_tips(x, dp, h),
                         u_difference=float(np.abs(psol.u - csol.u).max() / np.abs(csol.u).max()),
                         model=model, u_cnem=csol.u, u_pd=psol.u))
    return rows


def table(rows):
    k0 = SIGMA * np.sqrt(np.pi * A)
    lines = [f"{'h':>8} {'nodes':>6} {'PD bonds':>9} | {'opening err C-NEM':>17} {'PD':>7} | "
             f"{'K_I/K0 C-NEM':>12} {'PD':>7} | {'max|u_PD-u_C|/max|u|':>21}"]
    coarse = [r["h"] for r in rows if not np.isfinite(r["K_pd"])]
    for r in rows:
        k_pd = f"{r['K_pd'] / k0:>7.4f}" if np.isfinite(r["K_pd"]) else f"{'-':>6}*"
        lines.append(f"{r['h']:>8.4f} {r['nodes']:>6d} {r['bonds']:>9d} | {r['cnem_error']:>17.4f} "
                     f"{r['pd_error']:>7.4f} | {r['K_cnem'] / k0:>12.4f} {k_pd} | "
                     f"{r['u_difference']:>21.4f}")
    lines.append("opening errors: max |delta - Griffith| / max Griffith; K0 = sigma sqrt(pi a) "
                 "(infinite plate; this finite plate is a few % above)")
    if coarse:
        lines.append(f"* no PD K_I at h = {', '.join(f'{h:g}' for h in coarse)}: too coarse, the "
                     f"opening fit needs nodes between 2h and a/2 = {0.5 * A:g} behind each tip, "
                     f"i.e. h < a/6 = {A / 6:.4f} (--n {int(np.floor(6 / A)) + 1} or more)")
    return "\n".join(lines)


def _plots(rows, out):
    from cnem.plot.charts import offscreen_pyplot
    plt = offscreen_pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.5))
    xx = np.linspace(-A, A, 300)
    ax.plot(xx, griffith(xx), "k-", label="Griffith (infinite plate)")
    for r, style in zip(rows, ("o", "s", "^", "v")):
        ax.plot(r["x"], r["cnem"], style, mfc="none", label=f"C-NEM, $h$ = {r['h']:.4f}")
        ax.plot(r["x"], r["pd"], style + ":", ms=3, label=f"PD, $h$ = {r['h']:.4f}")
    ax.set_xlabel(r"$x$ along the crack ($W$; half-length $a$ = " + f"{A:g})")
    ax.set_ylabel(r"opening $u_y^+ - u_y^-$ ($\sigma W / E$)")
    ax.set_title("Crack opening: C-NEM and state-based PD on the same nodes")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "pd_cnem_opening.png", dpi=120)
    plt.close(fig)
    r = rows[-1]
    x = r["model"].nodes
    diff = np.hypot(*(r["u_pd"] - r["u_cnem"]).T)
    fig, ax = plt.subplots(figsize=(5.6, 5))
    tri = ax.tripcolor(x[:, 0], x[:, 1], r["model"].triangles, diff, shading="gouraud")
    fig.colorbar(tri, ax=ax, label=r"$|\mathbf{u}_\mathrm{PD} - \mathbf{u}_\mathrm{C{-}NEM}|$"
                                   r" ($\sigma W / E$)")
    ax.plot([-A, A], [0, 0], "r-", lw=2, label="crack")
    ax.set_xlabel(r"$x$ ($W$, the plate's half-width)")
    ax.set_ylabel(r"$y$ ($W$)")
    ax.legend(loc="upper right", fontsize=8)
    ax.set_aspect("equal")
    ax.set_title(f"Displacement difference, $h$ = {r['h']:.4f}")
    fig.tight_layout()
    fig.savefig(out / "pd_cnem_difference.png", dpi=120)
    plt.close(fig)


def main(spacings: tuple = SPACINGS, *, outdir: str = "results/pd_vs_cnem_crack",
         plot: bool = True) -> dict:
    """Run the comparison, print the table, write the figures.

    Returns
    -------
    dict
        ``rows`` (per h: ``nodes, bonds, cnem_error, pd_error, K_cnem, K_pd,
        u_difference``), ``files``.
    """
    out = pathlib.Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    rows = study(spacings)
    print(table(rows))
    files = []
    if plot:
        _plots(rows, out)
        files = [out / "pd_cnem_opening.png", out / "pd_cnem_difference.png"]
        for f in files:
            print(f"wrote {f}")
    keep = ("h", "nodes", "bonds", "cnem_error", "pd_error", "K_cnem", "K_pd", "u_difference")
    return dict(rows=[{k: r[k] for k in keep} for r in rows], files=[str(f) for f in files])


def cli(argv: Sequence[str] | None = None, prog: str | None = None) -> None:
    """Command line: ``python demos/pd_vs_cnem_crack.py --help`` or
    ``cnem demo pd-vs-cnem-crack``."""
    parser = demo_parser(__file__, __doc__, prog, run_time=RUN_TIME)
    parser.add_argument("--n", type=positive_int, nargs="+", default=[16, 32, 64],
                        help="nodes per unit length (h = 1 / n)")
    args = parser.parse_args(argv)
    return main(tuple(1.0 / n for n in args.n), outdir=args.out, plot=not args.no_plot)


if __name__ == "__main__":
    cli()
