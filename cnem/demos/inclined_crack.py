"""A plate with an inclined central crack under remote tension: SIFs and near-tip stresses.

The problem
-----------
The third example of the C-NEM paper (Yvonnet et al., IJNME 2004, §4.5, Figures
16-19): a square plate of side 2W with a straight central crack of length 2a =
0.2 inclined at gamma to the x axis, remote stress sigma_22 = 1 on the top and
bottom edges, E = 1, nu = 0.3, plane stress; rigid motions fixed by pinning the
bottom-left corner and holding the bottom-right one vertically. Nodes are
graded towards both tips (`cnem.nodes.graded`).

* Figure 18 (gamma = 0, the paper's plate 2W = 2 and cloud of ~760 nodes):
  sigma_22 of the cells ahead of the tip against Muskhelishvili's infinite-plate
  solution sigma_22 = sigma (a + r) / sqrt(r (2a + r)) (eq. 45).
* Figure 19: K_I and K_II at both tips for gamma = 0 ... 75 degrees by the
  interaction integral (`cnem.fracture.sif`, integration disc of radius 0.4 a)
  against K_I = sigma sqrt(pi a) cos^2 gamma, K_II = sigma sqrt(pi a) sin gamma
  cos gamma (eq. 46). The finite width is made negligible by a wider plate,
  2W / 2a = 40 (Feddersen's strip correction sqrt(sec(pi a / 2W)) = 1.0004),
  with the same tip refinement, at most 2000 nodes.

Expected result
---------------
* sigma_22 follows eq. 45 ahead of the tip, rising towards it.
* K_I / sigma sqrt(pi a) and K_II / sigma sqrt(pi a) within 0.02 of the exact
  values for every angle (measured: 0.011), equal at both tips (symmetry);
  within 0.01 with the sqrt(r) enrichment of the nodes within 0.02 of the tips
  (measured: 0.001).
* Pictures in ``outdir``: ``inclined_sigma22.png`` (Figure 18),
  ``inclined_sif.png`` (Figure 19) and ``inclined_crack_open.png`` (the opened
  crack, von Mises, gamma = 30 degrees).

Run ``python demos/inclined_crack.py --help`` for the options.
"""

from __future__ import annotations

import pathlib
import sys
from typing import TYPE_CHECKING

import numpy as np
from tqdm.auto import tqdm

import cnem
from cnem.cli import demo_parser, positive_float
from cnem.exact import CentralCrack
from cnem.fracture import sif

if TYPE_CHECKING:
    from typing import Sequence

__all__ = ["main", "cli", "sif_study", "muskhelishvili"]

HALF_CRACK = 0.1
E, NU, SIGMA = 1.0, 0.3, 1.0
#: (half width W, spacing away from the crack, spacing at the tips, grading rate)
PAPER_CLOUD = (1.0, 0.1, 0.01, 0.1)
SIF_CLOUD = (4.0, 0.4, 0.0025, 0.15)
ANGLES = (0.0, 15.0, 30.0, 45.0, 60.0, 75.0)


#: How long the demo runs at its defaults (its --help says it; see cnem.cli.demo_parser).
RUN_TIME = "about 35 s"


def build(gamma_deg, cloud=SIF_CLOUD, seed=0):
    """The plate, its graded cloud and the model. Returns ``(model, tip_right)``."""
    W, h, h_min, growth = cloud
    g = np.deg2rad(gamma_deg)
    d = HALF_CRACK * np.array([np.cos(g), np.sin(g)])
    dom = cnem.geometry.rectangle(2 * W, 2 * W, origin=(-W, -W), cracks=[[-d, d]])
    nodes = cnem.nodes.graded(dom, h, near=dom.tips, h_min=h_min, growth=growth, seed=seed)
    return cnem.discretize(nodes, progress=False), d


#: Enrichment of the nodes within this distance of both tips (8 tip spacings).
ENRICH_RADIUS = 0.02


def solve(model, W, enrich=None):
    """Remote tension on the top and bottom edges (not on the crack faces)."""
    prob = cnem.Elasticity(model, (E, NU), plane="stress", enrich=enrich)
    prob.add_traction(lambda x, n: np.abs(np.abs(x[:, 1]) - W) < 1e-9 * W,
                      lambda x, n: SIGMA * n * [0.0, 1.0])
    prob.add_dirichlet(lambda p: np.hypot(*(p - [-W, -W]).T) < 1e-9 * W, None)
    prob.add_dirichlet(lambda p: np.hypot(*(p - [W, -W]).T) < 1e-9 * W, 1)
    return prob.solve(progress=False)


def exact_sif(gamma_deg):
    """K_I, K_II of the crack in an infinite plate (eq. 46)."""
    return CentralCrack(HALF_CRACK, SIGMA, np.deg2rad(gamma_deg)).sif()


def sif_study(angles: tuple = ANGLES, cloud: tuple = SIF_CLOUD,
              radius: float = 0.4 * HALF_CRACK) -> list[dict]:
    """K_I, K_II at both tips for every angle. Returns a list of dict rows."""
    rows = []
    for gamma in tqdm(angles, desc="angles", disable=not sys.stderr.isatty(), leave=False):
        model, d = build(gamma, cloud)
        sol = solve(model, cloud[0])
        right, left = sif(sol, d, radius=radius), sif(sol, -d, radius=radius)
        enriched = solve(model, cloud[0], enrich=dict(radius=ENRICH_RADIUS))
        e_right, e_left = sif(enriched, d, radius=radius), sif(enriched, -d, radius=radius)
        rows.append(dict(gamma=gamma, nodes=len(model.nodes), exact=exact_sif(gamma),
                         right=tuple(right), left=tuple(left),
                         enriched_right=tuple(e_right), enriched_left=tuple(e_left)))
    return rows


def muskhelishvili(r: float) -> np.ndarray:
    """sigma_22 ahead of the tip of a crack in an infinite plate (eq. 45)."""
    return CentralCrack(HALF_CRACK, SIGMA).normal_stress_ahead(r)


def stress_ahead(sol, tip):
    """Cells cut by the line ahead of the tip (theta = 0): distance of their centroid
    from the tip and their sigma_22."""
    c = sol.model.cells.centroid()
    rel = c - tip
    near = (np.abs(rel[:, 1]) < 0.5 * np.sqrt(sol.model.cells.area)) & (rel[:, 0] > 0)
    order = np.argsort(rel[near, 0])
    return rel[near, 0][order], sol.stress[near, 1][order]


def table(rows):
    k0 = SIGMA * np.sqrt(np.pi * HALF_CRACK)
    lines = [f"{'gamma':>6} {'nodes':>6} | {'KI/K0':>7} {'exact':>7} {'KII/K0':>7} {'exact':>7} | "
             f"{'left KI':>7} {'left KII':>8} | {'max err':>7} | {'enriched KI':>11} {'KII':>7} "
             f"{'max err':>7}"]

    def worst(r, right, left):
        return max(abs(r[right][0] - r["exact"][0]), abs(r[right][1] - r["exact"][1]),
                   abs(r[left][0] - r["exact"][0]), abs(r[left][1] - r["exact"][1])) / k0
    for r in rows:
        r["error"] = worst(r, "right", "left")
        r["enriched_error"] = worst(r, "enriched_right", "enriched_left")
        lines.append(f"{r['gamma']:>6.0f} {r['nodes']:>6d} | {r['right'][0] / k0:>7.4f} "
                     f"{r['exact'][0] / k0:>7.4f} {r['right'][1] / k0:>7.4f} {r['exact'][1] / k0:>7.4f} | "
                     f"{r['left'][0] / k0:>7.4f} {r['left'][1] / k0:>8.4f} | {r['error']:>7.4f} | "
                     f"{r['enriched_right'][0] / k0:>11.4f} {r['enriched_right'][1] / k0:>7.4f} "
                     f"{r['enriched_error']:>7.4f}")
    lines.append("errors: largest |K - K_exact| / sigma sqrt(pi a) over both tips and both modes; "
                 f"enriched: sqrt(r) enrichment within {ENRICH_RADIUS} of the tips")
    return "\n".join(lines)


def _plots(rows, ahead, out):
    from cnem.plot.charts import offscreen_pyplot
    plt = offscreen_pyplot()
    r, s22 = ahead
    fig, ax = plt.subplots(figsize=(6, 4.5))
    rr = np.linspace(max(r.min(), 1e-4), r.max(), 300)
    ax.plot(rr, muskhelishvili(rr), "k-", label="Muskhelishvili (eq. 45)")
    ax.plot(r, s22, "o", ms=4, label="C-NEM cells")
    ax.set_xlabel(r"distance ahead of the tip $r$ (mm)")
    ax.set_ylabel(r"$\sigma_{22}$ (MPa)")
    ax.set_xscale("log")
    ax.set_title(r"Stress ahead of the tip, $\gamma = 0$ (paper Figure 18)")
    ax.grid(alpha=0.3, which="both")
    ax.legend()
    fig.tight_layout()
    fig.savefig(out / "inclined_sigma22.png", dpi=120)
    plt.close(fig)
    k0 = SIGMA * np.sqrt(np.pi * HALF_CRACK)
    g = np.array([row["gamma"] for row in rows])
    gg = np.linspace(0, 90, 200)
    fig, ax = plt.subplots(figsize=(6, 4.5))
    ax.plot(gg, np.cos(np.deg2rad(gg)) ** 2, "k-", label=r"$K_\mathrm{I}$ exact (eq. 46)")
    ax.plot(gg, np.sin(np.deg2rad(gg)) * np.cos(np.deg2rad(gg)), "k--",
            label=r"$K_\mathrm{II}$ exact")
    ax.plot(g, [row["right"][0] / k0 for row in rows], "o", label=r"$K_\mathrm{I}$ C-NEM")
    ax.plot(g, [row["right"][1] / k0 for row in rows], "s", label=r"$K_\mathrm{II}$ C-NEM")
    ax.set_xlabel(r"crack angle $\gamma$ (degrees)")
    ax.set_ylabel(r"$K / \sigma\sqrt{\pi a}$")
    ax.set_title("SIFs of the inclined crack (paper Figure 19)")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(out / "inclined_sif.png", dpi=120)
    plt.close(fig)


def main(angles: tuple = ANGLES, *, sif_cloud: tuple = SIF_CLOUD, paper_cloud: tuple = PAPER_CLOUD,
         outdir: str = "results/inclined_crack", plot: bool = True) -> dict:
    """Run both studies, print the table, write the figures.

    Returns
    -------
    dict
        ``rows`` (one per angle: ``gamma, nodes, exact, right, left, error``),
        ``max_error`` (over angles and both tips, divided by sigma sqrt(pi a)),
        ``ahead`` (``r, sigma_22, exact`` arrays for gamma = 0), ``files``.
    """
    out = pathlib.Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    rows = sif_study(angles, sif_cloud)
    print(table(rows))
    model, d = build(0.0, paper_cloud)
    sol0 = solve(model, paper_cloud[0])
    ahead = stress_ahead(sol0, d)
    print(f"gamma = 0, {len(model.nodes)} nodes: sigma_22 ahead of the tip vs eq. 45, median "
          f"relative difference {np.median(np.abs(ahead[1] / muskhelishvili(ahead[0]) - 1)):.3f}")
    files = []
    if plot:
        _plots(rows, ahead, out)
        model, d = build(30.0, paper_cloud)
        sol = solve(model, paper_cloud[0])
        sol.plot(out / "inclined_crack_open.png", field="von_mises",
                 title=r"$\sigma_\mathrm{vM}$ (MPa)", length_unit="mm").close()
        files = [out / "inclined_sigma22.png", out / "inclined_sif.png", out / "inclined_crack_open.png"]
        for f in files:
            print(f"wrote {f}")
    return dict(rows=rows, max_error=max(r["error"] for r in rows),
                max_enriched_error=max(r["enriched_error"] for r in rows),
                ahead=dict(r=ahead[0], sigma_22=ahead[1], exact=muskhelishvili(ahead[0])),
                files=[str(f) for f in files])


def cli(argv: Sequence[str] | None = None, prog: str | None = None) -> None:
    """Command line: ``python demos/inclined_crack.py --help`` or ``cnem demo inclined-crack``."""
    parser = demo_parser(__file__, __doc__, prog, run_time=RUN_TIME)
    parser.add_argument("--angles", type=float, nargs="+", default=list(ANGLES),
                        help="crack angles in degrees")
    parser.add_argument("--h-min", type=positive_float, default=SIF_CLOUD[2], help="spacing at the tips")
    args = parser.parse_args(argv)
    cloud = (SIF_CLOUD[0], SIF_CLOUD[1], args.h_min, SIF_CLOUD[3])
    return main(tuple(args.angles), sif_cloud=cloud, outdir=args.out, plot=not args.no_plot)


if __name__ == "__main__":
    cli()
