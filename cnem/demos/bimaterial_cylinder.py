"""Two-layer cylinder under internal pressure: C-NEM with SCNI against the exact solution and FEM.

The problem
-----------
The first example of the C-NEM paper (Yvonnet et al., IJNME 2004, §4.3, Figure
10, Table I): a hollow cylinder of two materials, R_int = 0.5, R_1 = 0.7 (the
interface), R_ext = 0.9 mm; inner layer E1 = 210000 MPa, nu1 = 0.3, outer layer
E2 = 105000 MPa, nu2 = 0.2; internal pressure P = 1 MPa; plane stress. One
quarter is modelled with symmetry conditions (u_x = 0 on x = 0, u_y = 0 on
y = 0). The exact solution (eq. 35-41) is `cnem.exact.LayeredCylinder`.

Node clouds are polar lattices (147, 315, 690 and 1863 nodes: 7x21, 9x35,
15x46, 23x81 radii x angles, see `grid_for`; the paper's third cloud has 687),
with a ring of nodes on the interface circle; the irregular clouds move every node off the boundaries
and the interface randomly by up to 30 % of the spacings. The polygonal
boundaries have their vertices at the boundary nodes.

For the fairness anchor the same cylinder is solved with scikit-fem P1
triangles on a quality mesh from `triangle` with (about) the same node count
(`cnem.fem`, "FEM"), and with P1 on each C-NEM model's own nodes and constrained
Delaunay triangles (`cnem.fem.P1Elasticity.from_model`, "P1 same nodes").

Expected result
---------------
* The error in the energy norm falls like h (fitted rate >= 0.95), about the
  rate of linear FEM, as in the paper's Figure 13.
* Our `ElasticSolution.energy_error` is sqrt(∫ (σh-σ)ᵀ C⁻¹ (σh-σ)). The
  paper's Table I values are matched by sqrt(½ ∫ ...), i.e. ours / sqrt(2):
  the table prints that column beside Table I; it lies at or below the paper's
  values for every cloud.
* P1 on the C-NEM nodes ("P1 same e"): its error is 1.15-1.40 times C-NEM's on every
  cloud, regular and irregular (5.34e-5 against 4.08e-5 on 1863 regular nodes).
* Pictures in ``outdir``: the convergence plot with the paper's values and the
  fitted slopes (``cylinder_convergence.png``), the radial profiles of u_r,
  sigma_rr and sigma_tt across the interface (``cylinder_profiles.png``,
  Figures 11-12: sigma_tt jumps at r = 0.7, u_r and sigma_rr are continuous),
  and sigma_tt on the deformed cylinder (``cylinder_hoop_stress.png``); the
  finest regular solution as ``cylinder.vtu`` for ParaView.

Run ``python demos/bimaterial_cylinder.py --help`` for the options.
"""

from __future__ import annotations

import pathlib
import sys
import time
from typing import TYPE_CHECKING

import numpy as np
from tqdm.auto import tqdm

import cnem
from cnem.cli import demo_parser, positive_int
from cnem.errors import InputError
from cnem.exact import LayeredCylinder

if TYPE_CHECKING:
    from typing import Sequence
    from ..geometry.cloud import NodeCloud
    from ..geometry.domain import Domain

__all__ = ["main", "cli", "run", "rate", "build", "exact_solution", "GRIDS", "TABLE_I"]

RADII = (0.5, 0.7, 0.9)
MATERIALS = ((210000.0, 0.3), (105000.0, 0.2))
PRESSURE = 1.0
#: The paper's Table I: nodes -> (regular, irregular) error in the energy norm.
TABLE_I = {147: (1.13e-4, 1.21e-4), 315: (7.41e-5, 8.10e-5), 687: (4.95e-5, 5.48e-5),
           1863: (3.06e-5, 3.46e-5)}
#: Angular over radial node spacing (at the interface) of the lattices.
ASPECT = 0.75
TOL = 1e-9


#: How long the demo runs at its defaults (its --help says it; see cnem.cli.demo_parser).
RUN_TIME = "about 10 s"


def grid_for(nodes):
    """The polar lattice ``(radii, angles)`` for about ``nodes`` nodes: an odd number
    of radii (so that a ring of nodes lies on the interface, midway), the angles
    making the angular spacing at the interface closest to `ASPECT` times the
    radial one. This rule gives the paper's lattices 7x21 = 147, 9x35 = 315 and
    23x81 = 1863 (and 15x46 = 690 for its 687-node cloud)."""
    if nodes < 9:
        raise InputError(f"nodes: need at least 9 nodes (3 x 3), received {nodes}")
    best = None
    for nr in range(3, int(np.sqrt(nodes)) + 2, 2):
        na = max(3, int(round(nodes / nr)))
        aspect = (RADII[1] * np.pi / 2 / (na - 1)) / ((RADII[-1] - RADII[0]) / (nr - 1))
        if best is None or abs(aspect - ASPECT) < best[0]:
            best = (abs(aspect - ASPECT), nr, na)
    return best[1], best[2]


#: (radii, angles) of the lattices for the paper's node counts.
GRIDS = tuple(grid_for(n) for n in TABLE_I)


def build(n_radial: int, n_angular: int, *, irregular: bool = False,
          seed: int = 0) -> tuple[Domain, NodeCloud]:
    """The quarter cylinder and a polar node lattice on it.

    Returns
    -------
    domain : cnem.Domain
        Region 0 the inner layer, region 1 the outer layer.
    cloud : cnem.NodeCloud
    """
    if n_radial < 3 or n_angular < 3:
        raise InputError(f"need at least 3 radii and 3 angles, received {n_radial} x {n_angular}")
    dom = cnem.geometry.annulus(RADII, angles=(0.0, np.pi / 2), segments=n_angular - 1)
    r = np.linspace(RADII[0], RADII[-1], n_radial)
    r[np.argmin(np.abs(r - RADII[1]))] = RADII[1]          # a ring of nodes on the interface
    t = np.linspace(0.0, np.pi / 2, n_angular)
    rr, tt = np.meshgrid(r, t, indexing="ij")
    if irregular:
        rng = np.random.default_rng(seed)
        free = (np.abs(rr - RADII[0]) > TOL) & (np.abs(rr - RADII[1]) > TOL) \
            & (np.abs(rr - RADII[2]) > TOL) & (tt > TOL) & (tt < np.pi / 2 - TOL)
        dr, dt = np.diff(r).min(), t[1] - t[0]
        rr = rr + free * rng.uniform(-0.3, 0.3, rr.shape) * dr
        tt = tt + free * rng.uniform(-0.3, 0.3, tt.shape) * dt
    pts = np.column_stack([(rr * np.cos(tt)).ravel(), (rr * np.sin(tt)).ravel()])
    return dom, cnem.nodes.from_points(dom, pts)


def exact_solution(plane: str = "stress") -> LayeredCylinder:
    return LayeredCylinder(RADII, MATERIALS, pressure=PRESSURE, plane=plane)


def exact_stress(exact):
    """``exact_stress(points, region)`` for `energy_error` (the layer of each point is
    its cell's region: the polygonal interface is not the circle)."""
    return lambda points, region=None: exact.stress(points, layer=region)


def pose(problem):
    """Symmetry conditions and the internal pressure on a C-NEM or FEM problem."""
    problem.add_dirichlet(lambda p: np.abs(p[:, 0]) < TOL, 0)
    problem.add_dirichlet(lambda p: np.abs(p[:, 1]) < TOL, 1)
    inner = lambda x, n: np.hypot(x[:, 0], x[:, 1]) < RADII[0] + 1e-6 * (RADII[1] - RADII[0])
    problem.add_traction(inner, lambda x, n: -PRESSURE * n)
    return problem


def solve_cnem(cloud):
    """C-NEM + SCNI solution and the seconds it took (discretisation included)."""
    t0 = time.perf_counter()
    model = cnem.discretize(cloud, progress=False)
    sol = pose(cnem.Elasticity(model, MATERIALS, plane="stress")).solve(progress=False)
    return sol, time.perf_counter() - t0


def solve_fem(domain, nodes):
    """scikit-fem P1 on a quality mesh with about ``nodes`` nodes."""
    from cnem import fem
    t0 = time.perf_counter()
    sol = pose(fem.P1Elasticity(domain, MATERIALS, plane="stress", nodes=nodes)).solve()
    return sol, time.perf_counter() - t0


def solve_fem_same(model):
    """scikit-fem P1 on the nodes and constrained Delaunay triangles of a C-NEM model."""
    from cnem import fem
    return pose(fem.P1Elasticity.from_model(model, MATERIALS, plane="stress")).solve()


def rate(nodes: np.ndarray, errors: np.ndarray) -> float:
    """Fitted convergence rate of ``errors`` against h ~ nodes^(-1/2)."""
    return np.polyfit(-0.5 * np.log(nodes), np.log(errors), 1)[0]


def run(grids: tuple = GRIDS, irregular: tuple = (False, True), fem: bool = True,
        seed: int = 0) -> list:
    """Solve every cloud; one row per (cloud kind, size).

    Returns
    -------
    list of dict
        ``kind, nodes, h, error, paper, fem_nodes, fem_error, time, fem_time``, and
        ``fem_same_error`` (P1 on the C-NEM nodes) when ``fem``.
    """
    exact = exact_solution()
    stress = exact_stress(exact)
    rows = []
    jobs = [(irr, grid) for irr in irregular for grid in grids]
    for irr, (nr, na) in tqdm(jobs, desc="clouds", disable=not sys.stderr.isatty(), leave=False):
        dom, cloud = build(nr, na, irregular=irr, seed=seed)
        sol, seconds = solve_cnem(cloud)
        n = len(sol.model.nodes)
        row = dict(kind="irregular" if irr else "regular", nodes=n,
                   h=(RADII[-1] - RADII[0]) / (nr - 1), error=sol.energy_error(stress),
                   paper=_paper(n, irr), time=seconds, solution=sol)
        out = solve_fem(dom, n) if fem and irr == irregular[0] else None
        if out is not None:
            fsol, fsec = out
            row.update(fem_nodes=len(fsol.u), fem_error=fsol.energy_error(stress), fem_time=fsec)
        if fem:
            row.update(fem_same_error=solve_fem_same(sol.model).energy_error(stress))
        rows.append(row)
    return rows


def _paper(n, irregular):
    """Table I value for a node count within 1 % of the paper's, else NaN."""
    for count, values in TABLE_I.items():
        if abs(n - count) <= 0.01 * count:
            return values[int(irregular)]
    return float("nan")


def table(rows):
    """The error table as text (ours, ours / sqrt 2 beside Table I, FEM, P1 on our nodes)."""
    lines = [f"{'cloud':>9} {'nodes':>6} {'h':>7} {'C-NEM e':>10} {'e/sqrt2':>10} "
             f"{'Table I':>10} {'ratio':>6} {'time s':>7} | {'FEM nodes':>9} {'FEM e':>10} {'time s':>7}"
             f" | {'P1 same e':>10}"]
    for r in rows:
        half = r["error"] / np.sqrt(2.0)
        fem = (f"{r['fem_nodes']:>9d} {r['fem_error']:>10.3e} {r['fem_time']:>7.2f}"
               if "fem_error" in r else f"{'-':>9} {'-':>10} {'-':>7}")
        same = f"{r['fem_same_error']:>10.3e}" if "fem_same_error" in r else f"{'-':>10}"
        lines.append(f"{r['kind']:>9} {r['nodes']:>6d} {r['h']:>7.4f} {r['error']:>10.3e} "
                     f"{half:>10.3e} {r['paper']:>10.3e} {half / r['paper']:>6.2f} "
                     f"{r['time']:>7.2f} | {fem} | {same}")
    for kind in ("regular", "irregular"):
        sel = [r for r in rows if r["kind"] == kind]
        if len(sel) > 1:
            n = np.array([r["nodes"] for r in sel])
            line = f"rate ({kind}): C-NEM {rate(n, [r['error'] for r in sel]):.3f}"
            paper = np.array([r["paper"] for r in sel])
            if np.isfinite(paper).all():
                line += f", paper {rate(n, paper):.3f}"
            if all("fem_error" in r for r in sel):
                line += f", FEM {rate([r['fem_nodes'] for r in sel], [r['fem_error'] for r in sel]):.3f}"
            if all("fem_same_error" in r for r in sel):
                line += f", P1 same nodes {rate(n, [r['fem_same_error'] for r in sel]):.3f}"
            lines.append(line)
    return "\n".join(lines)


def plot_convergence(rows, path):
    from cnem.plot.charts import offscreen_pyplot
    plt = offscreen_pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    for kind, marker in (("regular", "o"), ("irregular", "s")):
        sel = [r for r in rows if r["kind"] == kind]
        if not sel:
            continue
        n = np.array([r["nodes"] for r in sel])
        e = np.array([r["error"] for r in sel]) / np.sqrt(2.0)
        ax.loglog(1 / np.sqrt(n), e, marker + "-", label=f"C-NEM {kind} (rate {rate(n, e):.2f})")
        paper = np.array([r["paper"] for r in sel])
        if np.isfinite(paper).all():
            ax.loglog(1 / np.sqrt(n), paper, marker + "--", mfc="none",
                      label=f"paper Table I {kind} (rate {rate(n, paper):.2f})")
        if all("fem_error" in r for r in sel):
            nf = np.array([r["fem_nodes"] for r in sel])
            ef = np.array([r["fem_error"] for r in sel]) / np.sqrt(2.0)
            ax.loglog(1 / np.sqrt(nf), ef, "^:", label=f"FEM P1 (rate {rate(nf, ef):.2f})")
        if all("fem_same_error" in r for r in sel):
            es = np.array([r["fem_same_error"] for r in sel]) / np.sqrt(2.0)
            ax.loglog(1 / np.sqrt(n), es, marker + ":", mfc="none",
                      label=f"P1 on the C-NEM {kind} nodes (rate {rate(n, es):.2f})")
    ax.set_xlabel(r"$1/\sqrt{\mathrm{nodes}}$  ($\propto h$)")
    ax.set_ylabel(r"$\sqrt{\frac{1}{2}\int \mathbf{e}\cdot\mathbf{C}^{-1}\mathbf{e}\;"
                  r"\mathrm{d}A}$  (energy-norm error)")
    ax.set_title("Bimaterial cylinder: convergence (paper Figure 13)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def polar_stress(sol):
    """Radius of each cell centroid and its (sigma_rr, sigma_tt)."""
    c = sol.model.cells.centroid()
    r = np.hypot(c[:, 0], c[:, 1])
    cs, sn = c[:, 0] / r, c[:, 1] / r
    sxx, syy, sxy = sol.stress.T
    srr = sxx * cs * cs + syy * sn * sn + 2 * sxy * cs * sn
    stt = sxx * sn * sn + syy * cs * cs - 2 * sxy * cs * sn
    return r, srr, stt


def plot_profiles(sol, path):
    from cnem.plot.charts import offscreen_pyplot
    plt = offscreen_pyplot()
    exact = exact_solution()
    x = sol.model.nodes
    rn = np.hypot(x[:, 0], x[:, 1])
    ur = (sol.u * x).sum(axis=1) / rn
    rc, srr, stt = polar_stress(sol)
    fig, axes = plt.subplots(1, 3, figsize=(13, 4))
    for i in range(2):
        r = np.linspace(RADII[i], RADII[i + 1], 100)
        axes[0].plot(r, exact.radial_displacement(r) * 1e6, "k-")
        axes[1].plot(r, exact.radial_stress(r), "k-")
        axes[2].plot(r, exact.hoop_stress(r), "k-")
    axes[0].plot(rn, ur * 1e6, ".", ms=3, label="C-NEM nodes")
    axes[1].plot(rc, srr, ".", ms=3, label="C-NEM cells (centroids)")
    axes[2].plot(rc, stt, ".", ms=3, label="C-NEM cells (centroids)")
    names = (r"$u_r$ ($10^{-6}$ mm)", r"$\sigma_{rr}$ (MPa)", r"$\sigma_{\theta\theta}$ (MPa)")
    for ax, name in zip(axes, names):
        ax.lines[0].set_label("exact")
        ax.axvline(RADII[1], color="grey", lw=0.8, ls=":", label=f"interface, r = {RADII[1]:g} mm")
        ax.set_xlabel("r (mm)")
        ax.set_ylabel(name)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(f"Across the interface, {len(x)} nodes (paper Figures 11-12)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(grids: tuple = GRIDS, *, irregular: tuple = (False, True), fem: bool = True,
         outdir: str = "results/bimaterial_cylinder", plot: bool = True, seed: int = 0) -> dict:
    """Run the study, print the table, write the figures.

    Returns
    -------
    dict
        ``rows`` (see `run`, without the solutions), ``rates`` per cloud kind,
        ``fem_rate``, ``finest`` (the C-NEM solution on the finest regular cloud, or on
        the finest cloud if none is regular), ``files``.
    """
    out = pathlib.Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    rows = run(grids, irregular, fem, seed)
    print(table(rows))
    files = []
    regular = [r for r in rows if r["kind"] == "regular"] or rows
    finest = regular[-1]["solution"]
    files.append(finest.write(out / "cylinder.vtu"))
    if plot:
        plot_convergence(rows, out / "cylinder_convergence.png")
        plot_profiles(regular[min(1, len(regular) - 1)]["solution"], out / "cylinder_profiles.png")
        _, _, stt = polar_stress(finest)
        finest.plot(out / "cylinder_hoop_stress.png", field=stt,
                    title=r"$\sigma_{\theta\theta}$ (MPa)", length_unit="mm").close()
        files += [out / "cylinder_convergence.png", out / "cylinder_profiles.png",
                  out / "cylinder_hoop_stress.png"]
    rates = {}
    for kind in ("regular", "irregular"):
        sel = [r for r in rows if r["kind"] == kind]
        if len(sel) > 1:
            rates[kind] = rate([r["nodes"] for r in sel], [r["error"] for r in sel])
    fem_rows = [r for r in rows if "fem_error" in r]
    fem_rate = (rate([r["fem_nodes"] for r in fem_rows], [r["fem_error"] for r in fem_rows])
                if len(fem_rows) > 1 else None)
    for f in files:
        print(f"wrote {f}")
    return dict(rows=[{k: v for k, v in r.items() if k != "solution"} for r in rows],
                rates=rates, fem_rate=fem_rate, finest=finest, files=[str(f) for f in files])


def cli(argv: Sequence[str] | None = None, prog: str | None = None) -> None:
    """Command line: ``python demos/bimaterial_cylinder.py --help`` or
    ``cnem demo bimaterial-cylinder``."""
    parser = demo_parser(__file__, __doc__, prog, run_time=RUN_TIME)
    parser.add_argument("--nodes", type=positive_int, nargs="+",
                        help="node counts (default the paper's 147 315 687 1863)")
    kind = parser.add_mutually_exclusive_group()
    kind.add_argument("--irregular", action="store_true", help="irregular clouds only")
    kind.add_argument("--regular", action="store_true", help="regular clouds only")
    parser.add_argument("--no-fem", action="store_true",
                        help="skip the scikit-fem P1 anchors (quality mesh and C-NEM nodes)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the irregular clouds")
    args = parser.parse_args(argv)
    grids = GRIDS if not args.nodes else tuple(grid_for(n) for n in args.nodes)
    irregular = (True,) if args.irregular else (False,) if args.regular else (False, True)
    return main(grids, irregular=irregular, fem=not args.no_fem, outdir=args.out,
                plot=not args.no_plot, seed=args.seed)


if __name__ == "__main__":
    cli()
