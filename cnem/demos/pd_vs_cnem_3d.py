"""A 3-D bar in tension, solved on one node cloud by C-NEM and by state-based PD.

The problem
-----------
A bar ``[0, L] x [0, 1] x [0, 1]`` with L = 2, E = 1, nu = 0.25, under a uniform
traction sigma = 1 on its end x = L, held by the three symmetry planes x = 0
(u_x = 0), y = 0 (u_y = 0) and z = 0 (u_z = 0). The exact solution is uniaxial
stress: u = sigma / E (x, -nu y, -nu z). The same irregular cloud
(`cnem.nodes.irregular` on `cnem.geometry.box`) is used twice:

* C-NEM + SCNI (`cnem.Elasticity` on `cnem.discretize`): constrained Voronoi
  cells, Laplace shape functions, the sub-cell stabilisation;
* ordinary state-based peridynamics (LPS, `cnem.pd.StateBased`) on the very nodes
  of the C-NEM model (`cnem.pd.Body.from_cloud`: the cells' volumes are the points'
  volumes), horizon delta = 3 h, surface correction on; the end traction is applied
  as body forces on the end points (the nodal forces of the C-NEM load vector
  divided by the point volumes), as in the 2-D demo ``pd_vs_cnem_crack``.

Expected result
---------------
* C-NEM reproduces the linear field to round-off (it passes the patch test).
* PD does not, and the difference is at the two ends. In the bulk its strain is
  sigma / E within a few per cent (the table's mid-bar strain: the slope of u_x over
  the middle half). But the conditions act on the surface points alone, whose
  horizons are cut: the held face's points stay at u_x = 0 while the layer behind
  them slides (u_x jumps by about 0.1-0.25 sigma L / E within one spacing), and the
  loaded face's points, which carry the whole traction as body forces on their small
  volumes, spread out. PD practice applies both over a layer of thickness delta; this
  demo applies what C-NEM applies, on the same nodes, and shows the consequence.
* Pictures in ``outdir``: ``pd_cnem_3d_axial.png`` (u_x of every node against x,
  both methods and the exact line).
"""

from __future__ import annotations

import pathlib
import sys
from typing import TYPE_CHECKING

import numpy as np
from tqdm.auto import tqdm

import cnem
import cnem.pd as pd
from cnem.cli import demo_parser

if TYPE_CHECKING:
    from typing import Sequence

__all__ = ["main", "cli", "study"]

L, E, NU, SIGMA = 2.0, 1.0, 0.25, 1.0
SPACINGS = (0.25, 0.125)


#: How long the demo runs at its defaults (its --help says it; see cnem.cli.demo_parser).
RUN_TIME = "about 40 s"


def exact(x):
    """The uniaxial-stress displacement ``(p, 3)`` at points ``x (p, 3)``."""
    return SIGMA / E * x * [1.0, -NU, -NU]


def symmetry_planes(prob, tol):
    """u_x = 0 on x = 0, u_y = 0 on y = 0, u_z = 0 on z = 0."""
    for k in range(3):
        prob.add_dirichlet(lambda p, k=k: np.abs(p[:, k]) < tol, k)


def solve_cnem(cloud, tol):
    model = cnem.discretize(cloud, progress=False)
    prob = cnem.Elasticity(model, (E, NU))
    prob.add_traction(lambda x, n: x[:, 0] > L - tol, [SIGMA, 0.0, 0.0])
    symmetry_planes(prob, tol)
    return prob, prob.solve(progress=False)


def solve_pd(cloud, cnem_problem, tol, horizon_factor=3.0):
    body = pd.Body.from_cloud(cloud, horizon_factor)
    forces = cnem_problem.load().reshape(-1, 3)
    prob = pd.Problem(body, pd.StateBased(E, NU))
    prob.add_body_force(lambda p: forces / body.volumes[:, None])
    symmetry_planes(prob, tol)
    return body, prob.solve()


def study(spacings: tuple = SPACINGS, seed: int = 2) -> list[dict]:
    rows = []
    dom = cnem.geometry.box((0.0, 0.0, 0.0), (L, 1.0, 1.0))
    tol = 1e-9 * L
    for h in tqdm(spacings, desc="clouds", disable=not sys.stderr.isatty(), leave=False):
        cloud = cnem.nodes.irregular(dom, h, seed=seed)
        cprob, csol = solve_cnem(cloud, tol)
        body, psol = solve_pd(cloud, cprob, tol)
        x = csol.model.nodes
        ref = exact(x)
        scale = np.abs(ref).max()
        end = x[:, 0] > L - tol
        middle = np.abs(x[:, 0] - 0.5 * L) < 0.25 * L
        rows.append(dict(h=h, nodes=len(x), bonds=len(body.bond_i),
                         cnem_error=float(np.abs(csol.u - ref).max() / scale),
                         pd_error=float(np.abs(psol.u - ref).max() / scale),
                         pd_end=float(psol.u[end, 0].mean() / (SIGMA * L / E)),
                         pd_strain=float(np.polyfit(x[middle, 0], psol.u[middle, 0], 1)[0]
                                         / (SIGMA / E)),
                         x=x, u_cnem=csol.u, u_pd=psol.u))
    return rows


def table(rows):
    lines = [f"{'h':>7} {'nodes':>6} {'PD bonds':>9} | {'max|u-exact|/max|u| C-NEM':>26} "
             f"{'PD':>8} | {'PD end u_x / (sigma L/E)':>24} {'PD mid-bar strain / (sigma/E)':>30}"]
    for r in rows:
        lines.append(f"{r['h']:>7.4f} {r['nodes']:>6d} {r['bonds']:>9d} | {r['cnem_error']:>26.2e} "
                     f"{r['pd_error']:>8.4f} | {r['pd_end']:>24.4f} {r['pd_strain']:>30.4f}")
    lines.append("exact: uniaxial stress, u = sigma/E (x, -nu y, -nu z); C-NEM passes the patch "
                 "test; PD's bulk strain is right, its error comes from the two end faces")
    return "\n".join(lines)


def _plot(rows, out):
    from cnem.plot.charts import offscreen_pyplot
    plt = offscreen_pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.5))
    xx = np.linspace(0.0, L, 50)
    ax.plot(xx, SIGMA * xx / E, "k-", label=r"exact $\sigma x / E$")
    r = rows[-1]
    ax.plot(r["x"][:, 0], r["u_cnem"][:, 0], "o", ms=3, mfc="none", label="C-NEM (every node)")
    ax.plot(r["x"][:, 0], r["u_pd"][:, 0], ".", ms=3, label="state-based PD (every node)")
    ax.set_xlabel(r"$x$ (length unit; the bar is $L$ = " + f"{L:g} long)")
    ax.set_ylabel(r"$u_x$ (length unit, $\sigma$ = " + f"{SIGMA:g}, $E$ = {E:g})")
    ax.set_title(f"Bar in tension, same {r['nodes']} nodes, $h$ = {r['h']:g}, "
                 r"$\delta$ = 3$h$")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    path = out / "pd_cnem_3d_axial.png"
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def main(spacings: tuple = SPACINGS, *, outdir: str = "results/pd_vs_cnem_3d",
         plot: bool = True) -> dict:
    """Run the comparison, print the table, write the figure.

    Returns
    -------
    dict
        ``rows`` (per h: ``nodes, bonds, cnem_error, pd_error, pd_end, pd_strain``),
        ``files``.
    """
    out = pathlib.Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    rows = study(spacings)
    print(table(rows))
    files = []
    if plot:
        files = [_plot(rows, out)]
        for f in files:
            print(f"wrote {f}")
    keep = ("h", "nodes", "bonds", "cnem_error", "pd_error", "pd_end", "pd_strain")
    return dict(rows=[{k: r[k] for k in keep} for r in rows], files=[str(f) for f in files])


def cli(argv: Sequence[str] | None = None, prog: str | None = None) -> None:
    """Command line: ``python demos/pd_vs_cnem_3d.py --help`` or ``cnem pd pd-vs-cnem-3d``."""
    parser = demo_parser(__file__, __doc__, prog, run_time=RUN_TIME)
    parser.add_argument("--h", type=float, nargs="+", default=list(SPACINGS),
                        help="node spacings")
    args = parser.parse_args(argv)
    return main(tuple(args.h), outdir=args.out, plot=not args.no_plot)


if __name__ == "__main__":
    cli()
