"""Kalthoff-Winkler impact: the shear-loaded double-notched steel plate, serial or on MPI ranks.

The problem
-----------
The experiment of Kalthoff & Winkler (1988; Kalthoff 2000, "Modes of dynamic
shear failure in solids", Int. J. Fract. 101:1-31): a maraging steel plate with
two parallel edge notches is struck on that edge, between the notches, by a
projectile at 32 m/s. The struck middle part is pushed into the plate while the
outer parts stay behind, loading each notch tip in shear (mode II), and a brittle
crack runs from each tip at about 70 degrees to the notch, away from the struck
part. It is the standard dynamic-fracture check of peridynamics (Silling 2003,
"Dynamic fracture modeling with a meshfree peridynamic code"; the PD studies
find 65-70 degrees).

The geometry is that of the PD studies (e.g. the Kalthoff-Winkler tutorial of
Peridynamics.jl): a plate 100 mm deep (x, the notch direction; struck at x = 0)
and 200 mm wide (y in [-100, 100] mm), two notches 50 mm long, 1.5 mm wide and
50 mm apart (centre lines y = +-25 mm, tips at x = 50 mm); 2-D plane stress,
thickness 1. Maraging steel: E = 191 GPa, rho = 8000 kg/m^3, G_c = 2.2e4 J/m^2.
Bond-based PMB (`cnem.pd.BondBased`, nu = 1/3), critical stretch from G_c
(`cnem.pd.critical_stretch.bond_based`, plane stress:
``s_c = sqrt(4 pi G_c / (9 E delta))``), surface correction on, velocity Verlet
at 0.8 times the stable step. The impactor is not modelled, as usual in PD
papers: the points of the first two rows at the struck edge between the notches
(``|y| < 25 mm - 2 delta``) move at 32 m/s in x from t = 0 (a velocity condition,
`cnem.pd.Problem.add_velocity`); y stays free.

Discretisation: one point at the centre of each h x h cell; the notch is the
cells whose centre lies inside the 1.5 mm slot (1.5 mm rounded to whole cells:
2, 1 and 1.5 mm at h = 1, 0.5, 0.25 mm) and, as the horizon spans the slot, the
bonds that cross its centre line, cut (`cnem.pd.Body(cracks=...)`). Horizon
delta = m h (m = 4 by default): refining h at fixed m shrinks the horizon with
the grid (the "delta convergence" of the angle).

Serial or distributed, one script
---------------------------------
``python -m cnem.demos.kalthoff_winkler`` runs on one process (`cnem.pd`);
``mpiexec -n 2 python -m cnem.demos.kalthoff_winkler`` runs the same problem on
two ranks (`cnem.pd.distributed`, chosen when the script is started on more
than one rank), which give the serial displacements to round-off and the same
broken bonds. Damage frames go to ``outdir/frames_h<h>mm/`` as ``.vtu`` (one
rank) or ``.pvtu`` indexing one piece per rank (ParaView opens either series);
rank 0 measures, prints, saves the final fields (``kalthoff_winkler_h<h>mm.npz``)
and draws the damage (``kalthoff_winkler_h<h>mm.png``).

The crack angle (`crack_angle`)
-------------------------------
For each notch: the points with damage at least 0.35 (`THRESHOLD`) at a distance
from the notch tip between ``2 delta`` (past the tip's own damaged zone) and
``2 delta + 20 mm`` (`WINDOW`), on the outer side of the tip (``y`` beyond the
notch centre line); a straight line is fitted to them by total least squares
(the principal axis of their scatter), and the angle is that of the line to the
notch direction, +x, opening away from the struck middle (upper notch: towards
+y; lower notch measured on the mirrored plate). The table gives both notches'
angles and their mean.

Measured here (50 us of impact)
-------------------------------
``mpiexec -n 2 python -m cnem.demos.kalthoff_winkler --h 1 0.5 0.25`` (2 shared cores
at a load average of 5-8 from other jobs, so the wall times are only an order):

=======  =========  =======  ========  =====  ========  ==============
h (mm)   delta      s_c      points    steps  wall (s)  angle (deg)
=======  =========  =======  ========  =====  ========  ==============
1        4 mm       0.0063   19 800    256    8.3       56.9 / 53.8
0.5      2 mm       0.0090   79 400    511    44.2      64.5 / 65.3
0.25     1 mm       0.0127   317 600   1021   314.8     69.0 / 68.8
=======  =========  =======  ========  =====  ========  ==============

(upper / lower notch): the angle approaches the experiment's 70 degrees as the horizon
shrinks. One rank gives the 2-rank displacements to 1e-14 and the same broken bonds.
Not in the experiment: at delta = 4 and 2 mm a crack from the back face along the
centre line (the reflected impact wave: its strain 32 m/s / c of about 0.006 reaches s_c
at coarse horizons), at 4 mm cracks from the ends of the struck zone, and at every
resolution the cracks branch 20-30 mm from the tips.

Run ``python -m cnem.demos.kalthoff_winkler --help`` for the options.
"""

from __future__ import annotations

import pathlib
import time
from typing import TYPE_CHECKING

import numpy as np

import cnem.pd as pd
from cnem.cli import demo_parser, dynamic_run_options, positive_float
from cnem.errors import InputError, MissingExtraError
from cnem.pd.critical_stretch import bond_based
from cnem.pd.guards import checked_schedule

if TYPE_CHECKING:
    from typing import Any, Sequence

__all__ = ["main", "cli", "plate", "build", "crack_points", "crack_angle", "measure", "table", "engine",
           "QUICK"]

DEPTH, WIDTH = 0.1, 0.2               # x (notch direction) and y extents of the plate, m
NOTCH, GAP, SLOT = 0.05, 0.05, 1.5e-3  # notch length, distance between notches, width, m
E, DENSITY, G_C = 191e9, 8000.0, 2.2e4
SPEED = 32.0                          # impact velocity, m/s
STRUCK_ROWS = 2                       # rows of points moving with the impactor
EXPERIMENT = 70.0                     # crack angle of the experiment, degrees
LITERATURE = (65.0, 70.0)             # crack angles of the PD studies, degrees
THRESHOLD = 0.35                      # damage of the points taken as crack points
WINDOW = 20e-3                        # length of the crack fitted, beyond 2 delta, m
QUICK = dict(h=(2.5e-3,), m=3.0, t_end=50e-6)


#: How long the demo runs at its defaults (its --help says it; see cnem.cli.demo_parser).
RUN_TIME = "about 70 s"


def plate(h: float) -> np.ndarray:
    """Cell-centred grid points of the plate without the notch slots.

    Parameters
    ----------
    h : float
        Grid spacing (m); it must divide 25 mm.

    Returns
    -------
    (n, 2) ndarray
    """
    h = float(h)
    cells = 0.5 * GAP / h if np.isfinite(h) and h > 0 else np.nan
    if not abs(cells - round(cells)) < 1e-6 or round(cells) < 1:
        raise InputError(f"h = {h * 1e3:g} mm: expected a spacing that divides 25 mm (the plate "
                         f"and notch dimensions), e.g. 2.5, 1, 0.5 or 0.25 mm")
    nx, ny = round(DEPTH / h), round(WIDTH / h)
    x = (np.arange(nx) + 0.5) * h
    y = (np.arange(ny) + 0.5) * h - 0.5 * WIDTH
    X, Y = np.meshgrid(x, y, indexing="ij")
    pts = np.column_stack([X.ravel(), Y.ravel()])
    in_slot = (pts[:, 0] < NOTCH) & (np.abs(np.abs(pts[:, 1]) - 0.5 * GAP) < 0.5 * SLOT)
    return pts[~in_slot]


def engine() -> Any:
    """`cnem.pd.distributed` when the script runs on more than one MPI rank, else `cnem.pd`
    (also when mpi4py is not installed)."""
    from cnem.pd.distributed.comm import world
    try:
        ranks = world().size
    except MissingExtraError:
        ranks = 1
    if ranks > 1:
        import cnem.pd.distributed as dpd
        return dpd
    return pd


def build(h: float, m: float, module: Any = pd) -> Any:
    """The struck plate.

    Parameters
    ----------
    h, m : float
        Grid spacing (m) and horizon over spacing.
    module : module
        `cnem.pd` or `cnem.pd.distributed`.

    Returns
    -------
    cnem.pd.Problem or cnem.pd.distributed.Problem
    """
    m = float(m)
    if not 2.0 <= m <= 10.0:
        raise InputError(f"m: expected a horizon of 2 to 10 grid spacings, received {m}")
    points = plate(h)
    horizon = m * h
    if horizon > 0.25 * GAP:
        raise InputError(f"delta = m h = {horizon * 1e3:g} mm: expected a horizon of at most "
                         f"a quarter of the distance between the notch and the struck middle "
                         f"({0.25 * GAP * 1e3:g} mm); refine h or lower m")
    notches = [[[-horizon, s * 0.5 * GAP], [NOTCH, s * 0.5 * GAP]] for s in (1, -1)]
    body = module.Body(points, h * h, horizon, cracks=notches)
    problem = module.Problem(body, module.BondBased(E, fracture_energy=G_C, density=DENSITY),
                             plane="stress")
    problem.add_velocity(lambda p: (p[:, 0] < STRUCK_ROWS * h) &
                         (np.abs(p[:, 1]) < 0.5 * GAP - 2 * horizon), 0, SPEED)
    return problem


def crack_points(points: np.ndarray, damage: np.ndarray, tip: Sequence[float], r_min: float,
                 r_max: float, threshold: float = THRESHOLD) -> np.ndarray:
    """The points taken as the crack from a notch tip (`crack_angle`).

    Parameters
    ----------
    points : (n, 2) ndarray
    damage : (n,) ndarray
    tip : (2,) array_like
        The notch tip; the crack is looked for on its ``y > tip_y`` side.
    r_min, r_max : float
        The distances from the tip between which the damaged points are taken.
    threshold : float
        Least damage of a crack point.

    Returns
    -------
    (n,) bool ndarray
        ``damage >= threshold``, ``r_min <= |x - tip| <= r_max`` and ``y > tip_y``.
    """
    rel = np.asarray(points, dtype=float) - np.asarray(tip, dtype=float)
    r = np.hypot(rel[:, 0], rel[:, 1])
    return (np.asarray(damage) >= threshold) & (r >= r_min) & (r <= r_max) & (rel[:, 1] > 0)


def crack_angle(points: np.ndarray, damage: np.ndarray, tip: Sequence[float], r_min: float,
                r_max: float, threshold: float = THRESHOLD) -> float:
    """Angle of a crack from a notch tip to the notch direction (+x), in degrees.

    Parameters
    ----------
    points, damage, tip, r_min, r_max, threshold
        As in `crack_points`.

    Returns
    -------
    float
        The angle in [0, 180) to +x of the total-least-squares line through the
        `crack_points` (the principal axis of their scatter); NaN with fewer than
        three of them.
    """
    pick = crack_points(points, damage, tip, r_min, r_max, threshold)
    if pick.sum() < 3:
        return float("nan")
    sel = points[pick] - points[pick].mean(axis=0)
    direction = np.linalg.eigh(sel.T @ sel)[1][:, -1]
    return float(np.degrees(np.arctan2(direction[1], direction[0])) % 180.0)


def measure(points: np.ndarray, damage: np.ndarray, horizon: float) -> dict:
    """The crack angles of both notches (`crack_angle`, the lower one on the mirrored plate).

    Returns
    -------
    dict
        ``upper, lower, mean`` (degrees; NaN where no crack was found) and
        ``crack_points`` (the points fitted, both notches).
    """
    window = (2 * horizon, 2 * horizon + WINDOW)
    tip = (NOTCH, 0.5 * GAP)
    out, count = {}, 0
    for key, pts in (("upper", points), ("lower", points * [1.0, -1.0])):
        out[key] = crack_angle(pts, damage, tip, *window)
        count += int(crack_points(pts, damage, tip, *window).sum())
    both = [out["upper"], out["lower"]]
    out["mean"] = float(np.nanmean(both)) if np.isfinite(both).any() else float("nan")
    return dict(out, crack_points=count)


def _picture(points, damage, h, horizon, angles, t_end, path):
    """Damage of the plate, axes in mm, colour bar, the fitted crack directions."""
    import matplotlib

    from cnem.plot.charts import offscreen_pyplot
    plt = offscreen_pyplot()
    fig, ax = plt.subplots(figsize=(5.2, 8.4), layout="constrained")
    image = np.full((round(DEPTH / h), round(WIDTH / h)), np.nan)     # the slots stay empty
    cell = np.floor((points + [0.0, 0.5 * WIDTH]) / h).astype(int)
    image[cell[:, 0], cell[:, 1]] = damage
    cmap = matplotlib.colormaps["inferno"].with_extremes(bad="0.75")
    art = ax.imshow(image.T, origin="lower", extent=(0, DEPTH * 1e3, -0.5 * WIDTH * 1e3,
                                                     0.5 * WIDTH * 1e3),
                    cmap=cmap, vmin=0.0, vmax=0.6, interpolation="nearest")
    for s, key in ((1, "upper"), (-1, "lower")):
        ax.plot([0, NOTCH * 1e3], [s * 25.0] * 2, color="cyan", lw=1.0)
        if np.isfinite(angles[key]):
            a = np.radians(angles[key])
            ax.plot(NOTCH * 1e3 + np.array([0, 40]) * np.cos(a),
                    s * (25.0 + np.array([0, 40]) * np.sin(a)), "--", color="lime", lw=1.0)
    ax.annotate("", xy=(-0.5, 0), xytext=(-7.5, 0), annotation_clip=False,
                arrowprops=dict(arrowstyle="->", color="k"))
    ax.set_xlim(-8, DEPTH * 1e3)
    ax.set_ylim(-0.5 * WIDTH * 1e3, 0.5 * WIDTH * 1e3)
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_title(f"Kalthoff-Winkler, PD damage at {t_end * 1e6:.0f} µs\nh = {h * 1e3:g} mm, "
                 f"δ = {horizon * 1e3:g} mm; fitted angles {angles['upper']:.1f}° / "
                 f"{angles['lower']:.1f}°\n(notches cyan, fits dashed, impact at 32 m/s →)",
                 fontsize=9)
    fig.colorbar(art, ax=ax, shrink=0.6, label="damage")
    fig.savefig(path, dpi=130)
    plt.close(fig)
    return path


def _one(module, h, m, t_end, frame_every, outdir, plot, progress):
    """Run one resolution; the row of the table (measured on rank 0)."""
    start = time.perf_counter()
    problem = build(h, m, module)
    body = problem.body
    dt = problem.stable_time_step()
    steps = int(np.ceil(t_end / dt))
    tag = f"h{h * 1e3:g}mm"
    frames = pathlib.Path(outdir) / f"frames_{tag}"
    run = problem.run_dynamic(dt, steps, every=max(1, round(frame_every / dt)),
                              output=frames / "kw", progress=progress)
    seconds = time.perf_counter() - start
    comm = getattr(body, "comm", None)
    seconds = comm.allreduce(seconds, op=_max()) if comm is not None else seconds
    row = dict(h=h, horizon=body.horizon, nodes=len(body), ranks=comm.size if comm else 1,
               steps=steps, dt=dt, seconds=seconds, broken=int(run.broken),
               stretch=bond_based(G_C, E, body.horizon, "stress"), files=list(map(str, run.files)))
    if run.u is None:                      # not rank 0 of a distributed run
        return row
    points = body.global_points if comm is not None else body.points
    row.update(measure(points, run.damage, body.horizon))
    out = pathlib.Path(outdir)
    np.savez(out / f"kalthoff_winkler_{tag}.npz", points=points, u=run.u, damage=run.damage,
             broken_bonds=_pairs(problem, run))
    row["files"].append(str(out / f"kalthoff_winkler_{tag}.npz"))
    if plot:
        row["files"].append(str(_picture(points, run.damage, h, body.horizon, row, steps * dt,
                                          out / f"kalthoff_winkler_{tag}.png")))
    return row


def _pairs(problem, run):
    """Broken bonds as sorted ``(k, 2)`` global point pairs (both directions)."""
    pairs = run.broken_bonds if getattr(run, "broken_bonds", None) is not None else \
        np.column_stack([problem.body.bond_i, problem.body.bond_j])[problem.alive == 0]
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    return pairs[np.lexsort(pairs.T[::-1])]


def _max():
    from cnem.pd.distributed.comm import mpi
    return mpi().MAX


def main(h: Sequence[float] = (1e-3, 0.5e-3), m: float = 4.0, t_end: float = 50e-6, *,
         frame_every: float = 5e-6, outdir: str = "results/kalthoff_winkler", plot: bool = True,
         progress: bool | None = None) -> dict:
    """Run the impact at each spacing, measure the crack angles, print the table.

    Parameters
    ----------
    h : sequence of float
        Grid spacings (m), each dividing 25 mm.
    m : float
        Horizon over spacing (fixed: the horizon shrinks with ``h``).
    t_end, frame_every : float
        Simulated time and time between damage frames (s).
    outdir : str or path
    plot : bool
    progress : bool, optional
        Progress bar on rank 0 (default: when stderr is a terminal).

    Returns
    -------
    dict
        ``rows``: one dict per spacing, ``h, horizon, nodes, ranks, steps, dt, seconds,
        broken, stretch, files`` on every rank and, on rank 0, ``upper, lower, mean``
        (degrees) and ``crack_points``; ``table`` (the printed text, rank 0; None
        elsewhere).
    """
    t_end, frame_every = checked_schedule(t_end, frame_every)
    module = engine()
    outdir = pathlib.Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    rows = [_one(module, float(s), m, t_end, frame_every, outdir, plot, progress) for s in h]
    root = "mean" in rows[0]
    text = table(rows, t_end) if root else None
    if root:
        print(text)
        for f in (f for r in rows for f in r["files"] if not f.endswith((".vtu", ".pvtu"))):
            print(f"wrote {f}")
        for r in rows:                      # the frames: one .pvd series per run
            frames = [f for f in r["files"] if f.endswith((".vtu", ".pvtu"))]
            if frames:
                print(f"wrote {pathlib.Path(frames[0]).with_name('kw.pvd')} "
                      f"({len(frames)} damage frames beside it)")
    return dict(rows=rows, table=text)


def table(rows: list, t_end: float) -> str:
    """The angle table as text (a ``-`` where no crack was found, with the reason)."""
    lines = [f"Kalthoff-Winkler, maraging steel (E = {E / 1e9:g} GPa, rho = {DENSITY:g} kg/m^3, "
             f"G_c = {G_C:g} J/m^2), impact {SPEED:g} m/s, {t_end * 1e6:g} us, bond-based PMB, "
             f"plane stress",
             f"{'h (mm)':>7} {'delta (mm)':>10} {'s_c':>8} {'nodes':>8} {'ranks':>5} {'steps':>6} "
             f"{'wall (s)':>9} {'upper':>7} {'lower':>7} {'mean':>7}  (crack angle to the notch, deg)"]
    missing = False
    for r in rows:
        angles = []
        for key in ("upper", "lower", "mean"):
            if np.isfinite(r[key]):
                angles.append(f"{r[key]:>7.1f}")
            else:
                angles.append(f"{'-':>7}")
                missing = True
        lines.append(f"{r['h'] * 1e3:>7g} {r['horizon'] * 1e3:>10g} {r['stretch']:>8.4f} "
                     f"{r['nodes']:>8d} {r['ranks']:>5d} {r['steps']:>6d} {r['seconds']:>9.1f} "
                     + " ".join(angles))
    lines.append(f"experiment: about {EXPERIMENT:g} deg (Kalthoff & Winkler); PD studies: "
                 f"{LITERATURE[0]:g}-{LITERATURE[1]:g} deg")
    if missing:
        lines.append("-: no crack point (damage >= 0.35) 2 delta to 2 delta + 20 mm from that "
                     "notch tip yet: run longer (--time) or finer (--h)")
    return "\n".join(lines)


def cli(argv: Sequence[str] | None = None, prog: str | None = None) -> dict:
    """Command line: ``python -m cnem.demos.kalthoff_winkler --help`` or
    ``cnem demo kalthoff-winkler``; under ``mpiexec -n N`` it runs on the N ranks."""
    parser = demo_parser(__file__, __doc__, prog, run_time=RUN_TIME)
    parser.epilog = ("Distributed: mpiexec -n 2 python -m cnem.demos.kalthoff_winkler [options] "
                     "(the same run on 2 MPI ranks; needs cnem[mpi]).")
    parser.add_argument("--h", type=positive_float, nargs="+", default=[1.0, 0.5],
                        help="grid spacings in mm (each dividing 25 mm), one run each")
    parser.add_argument("--m", type=positive_float, default=4.0, help="horizon / spacing")
    parser.add_argument("--time", type=positive_float, default=50.0, help="simulated time in µs")
    dynamic_run_options(parser, frames=5.0, quick_h=QUICK["h"][0], quick_m=QUICK["m"],
                        quick_t_end=QUICK["t_end"])
    args = parser.parse_args(argv)
    size = QUICK if args.quick else dict(h=[s * 1e-3 for s in args.h], m=args.m,
                                         t_end=args.time * 1e-6)
    try:
        return main(**size, frame_every=args.frames * 1e-6, outdir=args.out,
                    plot=not args.no_plot, progress=False if args.no_progress else None)
    except ValueError as exc:
        parser.error(str(exc))


if __name__ == "__main__":
    cli()
