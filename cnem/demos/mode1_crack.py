"""Mode-I edge crack with exact near-tip tractions: convergence of C-NEM, enriched C-NEM and FEM.

The problem
-----------
The second example of the C-NEM paper (Yvonnet et al., IJNME 2004, §4.4,
Figures 14-15): a square L = 1 with an edge crack of length a = L/2 along
y = L/2, its tip at the centre. On the whole outer boundary the tractions of
the exact mode-I near-tip field (Williams, eq. 42-44, K_I = 1) are imposed; the
crack faces are free; no symmetry is used; the rigid motions are fixed by
holding the exact displacement at the corner (L, L) and the exact horizontal
displacement at the corner (L, 0). Plane strain, E = 1, nu = 0.3.

The error in the energy norm against the exact field is measured on regular
clouds for: plain C-NEM (the paper measured a rate of 0.42; the singularity
limits any uniform refinement to 0.5), enriched C-NEM (`cnem.Elasticity(
enrich=...)`: the four branch functions on the nodes within 0.25 L of the tip,
partition of unity with the C-NEM shape functions; the sqrt(r) function of
eq. 47 alone cannot follow the angular variation of the near-tip field), and
scikit-fem P1 triangles on quality meshes with the same node counts
(`cnem.fem`, "fem") and on the C-NEM model's own nodes and constrained Delaunay
triangles (`cnem.fem.P1Elasticity.from_model`, "fem_same"). For C-NEM two errors are given: with the constant SCNI stress of
each (sub-)cell ("smoothed", the stress the method outputs) and with the
stress of the displacement field's own gradient at the quadrature points
("pointwise": the energy norm of u - u_h, which is what FEM P1 reports too).

Expected result
---------------
* Plain C-NEM and FEM: rates about 0.5 (measured 0.48 and 0.43 on h = 1/8 ... 1/64).
* P1 on the C-NEM nodes ("fem_same"): above plain C-NEM on every cloud (0.140 against
  0.111 at h = 1/32), close to P1 on a quality mesh.
* Enriched C-NEM: pointwise errors 13 times lower than plain C-NEM at h = 1/64
  (5.7e-3 vs 7.7e-2) and a pointwise rate of about 1 (1.07 over h = 1/8 ... 1/64),
  thanks to quadratures graded at the tip (collapsed rule on the triangles at the
  tip, t = s^2 on the cell edges ending there; see docs/fracture.md). The smoothed
  SCNI stress is constant per sub-cell and cannot follow the r^-1/2 field in the
  cells at the tip: its error stays at rate 0.5.
* K_I by the interaction integral (`cnem.fracture.sif`) close to 1.
* Pictures in ``outdir``: ``mode1_convergence.png`` (Figure 15 with the three
  methods) and ``mode1_crack_open.png`` (opened crack, von Mises).

Run ``python demos/mode1_crack.py --help`` for the options.
"""

from __future__ import annotations

import pathlib
import sys
from typing import TYPE_CHECKING

import numpy as np
from tqdm.auto import tqdm

import cnem
from cnem.cli import demo_parser, positive_int
from cnem.fracture import polar, sif, williams

if TYPE_CHECKING:
    from typing import Sequence

__all__ = ["main", "cli", "study"]

L, E, NU, PLANE, KI = 1.0, 1.0, 0.3, "strain", 1.0
TIP = np.array([0.5, 0.5])
DIRECTION = np.array([1.0, 0.0])
SPACINGS = (1 / 8, 1 / 16, 1 / 32, 1 / 64)
ENRICH = dict(radius=0.25, functions="branch")
TOL = 1e-9


#: How long the demo runs at its defaults (its --help says it; see cnem.cli.demo_parser).
RUN_TIME = "about 45 s"


def domain():
    return cnem.geometry.rectangle(L, L, cracks=[[[0.0, 0.5 * L], TIP]])


def exact(points):
    """Exact displacement ``(p, 2)`` and stress ``(p, 3)`` in global axes (the crack
    lies along x, so the crack-tip frame is the global one)."""
    r, theta = polar(points, TIP, DIRECTION)
    with np.errstate(divide="ignore", invalid="ignore"):
        u, s, _ = williams(r, theta, KI, 0.0, E, NU, PLANE)
    return u, s


def exact_stress(points):
    return exact(points)[1]


def outer(x, n):
    """Outer boundary edges (not the crack faces)."""
    return (np.abs(x[:, 0]) < TOL) | (np.abs(x[:, 0] - L) < TOL) | \
        (np.abs(x[:, 1]) < TOL) | (np.abs(x[:, 1] - L) < TOL)


def traction(x, n):
    s = exact_stress(x)
    return np.column_stack([s[:, 0] * n[:, 0] + s[:, 2] * n[:, 1],
                            s[:, 2] * n[:, 0] + s[:, 1] * n[:, 1]])


def pose(prob):
    """Exact tractions on the outer boundary; rigid motions fixed at two corners."""
    prob.add_traction(outer, traction)
    a = lambda p: np.hypot(*(p - [L, L]).T) < TOL
    b = lambda p: np.hypot(*(p - [L, 0.0]).T) < TOL
    prob.add_dirichlet(a, None, lambda p: exact(p)[0])
    prob.add_dirichlet(b, 0, lambda p: exact(p)[0][:, 0])
    return prob


def solve_cnem(h, enrich=False):
    model = cnem.discretize(cnem.nodes.regular(domain(), h), progress=False)
    kwargs = dict(enrich=dict(tips=[TIP], **ENRICH)) if enrich else {}
    return pose(cnem.Elasticity(model, (E, NU), plane=PLANE, **kwargs)).solve(progress=False)


def solve_fem(nodes):
    from cnem import fem
    return pose(fem.P1Elasticity(domain(), (E, NU), plane=PLANE, nodes=nodes)).solve()


def solve_fem_same(h):
    """P1 on the nodes and triangles of the C-NEM model of spacing ``h``."""
    from cnem import fem
    model = cnem.discretize(cnem.nodes.regular(domain(), h), progress=False)
    return pose(fem.P1Elasticity.from_model(model, (E, NU), plane=PLANE)).solve()


def rate(h, errors):
    """Fitted slope of log(error) against log(h)."""
    return float(np.polyfit(np.log(h), np.log(errors), 1)[0])


def study(spacings: tuple = SPACINGS,
          methods: tuple = ("cnem", "enriched", "fem", "fem_same")) -> list[dict]:
    """Energy errors per method and spacing. Returns a list of dict rows."""
    rows = []
    jobs = [(m, h) for m in methods for h in spacings]
    for method, h in tqdm(jobs, desc="solves", disable=not sys.stderr.isatty(), leave=False):
        if method == "fem":
            nodes = len(cnem.discretize(cnem.nodes.regular(domain(), h), progress=False).nodes)
            sol = solve_fem(nodes)
            n = len(sol.u)
            K = float("nan")
        elif method == "fem_same":
            sol = solve_fem_same(h)
            n = len(sol.u)
            K = float("nan")
        else:
            sol = solve_cnem(h, enrich=method == "enriched")
            n = len(sol.u)
            K = sif(sol, TIP, radius=0.3 * L)[0]
        smoothed = sol.energy_error(exact_stress)
        pointwise = smoothed if method.startswith("fem") else \
            sol.energy_error(exact_stress, strain="pointwise")
        rows.append(dict(method=method, h=h, nodes=n, smoothed=smoothed, error=pointwise, KI=K))
    return rows


def table(rows):
    lines = [f"{'method':>9} {'h':>8} {'nodes':>6} {'pointwise':>11} {'smoothed':>11} {'K_I':>7}"]
    for r in rows:
        k = f"{r['KI']:>7.4f}" if np.isfinite(r["KI"]) else f"{'-':>7}"
        lines.append(f"{r['method']:>9} {r['h']:>8.4f} {r['nodes']:>6d} {r['error']:>11.4e} "
                     f"{r['smoothed']:>11.4e} {k}")
    if any(not np.isfinite(r["KI"]) for r in rows):
        lines.append("K_I -: not computed for fem and fem_same (the interaction integral runs "
                     "on the C-NEM solutions here); fem_same: P1 on the C-NEM nodes and triangles")
    rates, smoothed = {}, {}
    for m in dict.fromkeys(r["method"] for r in rows):
        sel = [r for r in rows if r["method"] == m]
        if len(sel) > 1:
            rates[m] = rate([r["h"] for r in sel], [r["error"] for r in sel])
            smoothed[m] = rate([r["h"] for r in sel], [r["smoothed"] for r in sel])
    lines.append("rates (energy norm of u - u_h): "
                 + ", ".join(f"{m} {v:.3f}" for m, v in rates.items()))
    lines.append("rates (smoothed cell stress):   "
                 + ", ".join(f"{m} {v:.3f}" for m, v in smoothed.items()) + "  (paper: C-NEM 0.42)")
    return "\n".join(lines), rates


def _plot(rows, rates, path):
    from cnem.plot.charts import offscreen_pyplot
    plt = offscreen_pyplot()
    fig, ax = plt.subplots(figsize=(6, 4.5))
    names = {"cnem": "C-NEM", "enriched": "C-NEM + branch enrichment", "fem": "FEM P1",
             "fem_same": "FEM P1 on the C-NEM nodes"}
    for m, marker in (("cnem", "o-"), ("enriched", "s-"), ("fem", "^:"), ("fem_same", "v--")):
        sel = [r for r in rows if r["method"] == m]
        if sel:
            ax.loglog([r["h"] for r in sel], [r["error"] for r in sel], marker,
                      label=f"{names[m]} (rate {rates.get(m, float('nan')):.2f})")
    ax.set_xlabel(r"node spacing $h$ (plate side 1)")
    ax.set_ylabel(r"error in the energy norm of $u - u_h$")
    ax.set_title("Mode-I crack: convergence\n(paper Figure 15: C-NEM rate 0.42)")
    ax.grid(alpha=0.3, which="both")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(spacings: tuple = SPACINGS, *, methods: tuple = ("cnem", "enriched", "fem", "fem_same"),
         outdir: str = "results/mode1_crack", plot: bool = True) -> dict:
    """Run the convergence study, print the table, write the figures.

    Returns
    -------
    dict
        ``rows`` (``method, h, nodes, error`` (pointwise), ``smoothed``, ``KI``), ``rates``
        per method (of the pointwise errors), ``files``.
    """
    out = pathlib.Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    rows = study(spacings, methods)
    text, rates = table(rows)
    print(text)
    files = []
    if plot:
        _plot(rows, rates, out / "mode1_convergence.png")
        sol = solve_cnem(spacings[min(1, len(spacings) - 1)])
        sol.plot(out / "mode1_crack_open.png", field="von_mises").close()   # plate side 1
        files = [out / "mode1_convergence.png", out / "mode1_crack_open.png"]
        for f in files:
            print(f"wrote {f}")
    return dict(rows=rows, rates=rates, files=[str(f) for f in files])


def cli(argv: Sequence[str] | None = None, prog: str | None = None) -> None:
    """Command line: ``python demos/mode1_crack.py --help`` or ``cnem demo mode1-crack``."""
    parser = demo_parser(__file__, __doc__, prog, run_time=RUN_TIME)
    parser.add_argument("--n", type=positive_int, nargs="+", default=[8, 16, 32, 64],
                        help="nodes per side of the regular clouds (h = 1 / n)")
    parser.add_argument("--no-fem", action="store_true",
                        help="skip the scikit-fem P1 anchors (quality mesh and C-NEM nodes)")
    args = parser.parse_args(argv)
    methods = ("cnem", "enriched") + (() if args.no_fem else ("fem", "fem_same"))
    return main(tuple(1.0 / n for n in args.n), methods=methods, outdir=args.out,
                plot=not args.no_plot)


if __name__ == "__main__":
    cli()
