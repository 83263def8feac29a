"""CPD examples of §6.2-6.4 (Figures 7-10): cantilever bending, torsion of a block and the
nonlocality of the stress at the re-entrant corner of an L-shape."""

from __future__ import annotations

import math
import pathlib
import time

import numpy as np

import cnem.pd as pd

from cnem.demos.cpd.common import EPS, TOL, convergence_table, finish, solve
from cnem.pd.cpd_moduli import (constant_for_ratio, lame_constants,
                                 moduli_per_constant)
from cnem.pd.lattice import lattice
from cnem.pd.strain import deformation_gradient

__all__ = ["cantilever", "torsion", "lshape"]

#: The paper's constants as ratios (see `cnem.pd.cpd_moduli`): cantilever C2 = 1e4,
#: torsion C3 = 1e8.
CANTILEVER_RATIO, TORSION_RATIO = 15.0, 0.5


def cantilever(spacing: float = 0.04, *, C1s: tuple = (1.0, 2.0, 4.0), height: float = 0.2,
               aspect: int = 25, m: float = 3.0, steps: int = 20, load: float = 5.0,
               outdir: str = "results/cpd_examples", plot: bool = True) -> dict:
    """§6.2, Figure 7 (2-D row): a beam ``aspect * height`` long, clamped over the first
    horizon, bent by a downward force spread over the last horizon, for each C1 with
    C2 fixed (`CANTILEVER_RATIO` for C1 = 1), n = 2. The force is ``load * 3 E I / L^2``
    (the force that would deflect a linear Euler beam of the C1 = 1 material by ``load``
    L); nonlocal bending stiffness (delta comparable to the height) and large rotations
    make the real deflection smaller. The paper prescribes a 90 degree rotation and a
    compression of the end instead; a force lets the deflection depend on C1.
    Paper: D = 0.02 (default 0.04 here).

    Returns
    -------
    dict
        ``force``, ``runs``, per C1: ``tip`` (mean displacement of the end column, (2,)),
        ``u``, ``history``, ``seconds``; ``files``.
    """
    length = aspect * height
    counts = (int(round(length / spacing)) + 1, int(round(height / spacing)) + 1)
    h = height / (counts[1] - 1)
    x = lattice(counts, h)
    body = pd.Body(x, h * h, m * h * (1 + EPS))
    C2 = constant_for_ratio(2, CANTILEVER_RATIO, 2, body.horizon)
    lam, mu = lame_constants(pd.CPD(1.0, C2), 2, body.horizon)
    E = 4 * mu * (lam + mu) / (lam + 2 * mu)
    force = load * 3 * E * height ** 3 / 12 / length ** 2
    clamp, end = x[:, 0] < body.horizon, x[:, 0] > length - body.horizon
    b = np.zeros((len(x), 2))
    b[end, 1] = -force / body.volumes[end].sum()
    tip = x[:, 0] > length - EPS
    labels = [f"load {s / steps:.2f}" for s in range(1, steps + 1)]
    runs, tables = {}, []
    print(f"cantilever: {counts[0]}x{counts[1]} points, D = {h:.4g}, delta = {m:g}D, "
          f"C2 = {C2:.4g}, tip force {force:.4g}, {steps} load steps")
    for C1 in C1s:
        r = solve(body, pd.CPD(C1, C2, exponent=2.0), [(clamp, None, 0.0)], steps=steps,
                  force=b)
        runs[C1] = dict(r, tip=r["u"][tip].mean(axis=0))
        tables.append(convergence_table(f"C1 = {C1:g}, C2 = {C2:.4g}: residual norms",
                                        r["history"], labels))
    print(f"{'C1':>6} {'tip u_x / L':>12} {'tip u_y / L':>12} {'time':>6}")
    for C1, r in runs.items():
        print(f"{C1:>6g} {r['tip'][0] / length:>12.4f} {r['tip'][1] / length:>12.4f} "
              f"{r['seconds']:>5.1f}s")
    def panels():
        return [dict(points=x + r["u"], counts=counts, values=r["u"][:, 1], reference=x,
                     field=r"$u_y$", title=f"$C_1 = {C1:g}$, $\\delta = {m:g}h$")
                for C1, r in runs.items()]
    return finish("cantilever", dict(force=force, runs=runs, tables=tables), outdir, plot,
                  panels, 2, window=(1500, 450))


def torsion(n: int = 7, *, slenderness: int = 2, m: float = 1.5, angle: float = 180.0,
            steps: int = 18, outdir: str = "results/cpd_examples", plot: bool = True) -> dict:
    """§6.3, Figures 8-9: a block ``1 x 1 x slenderness``, bottom layer clamped, top
    layer turned by ``angle`` degrees about the axis in ``steps`` increments, C1 = 1, C3
    from `TORSION_RATIO`, n = 0. Each increment is one `solve` from the last
    state with the top's values of the new angle (a linear ramp of the displacements
    would not be a rotation). Paper: D = 0.02, delta = 3D; here ``n`` points across,
    delta = ``m`` D.

    Returns
    -------
    dict
        ``C3``, ``z`` (section heights), ``rotation`` (degrees, per section, unwrapped),
        ``u``, ``history`` (one list per increment), ``seconds``, ``files``.
    """
    h = 1.0 / (n - 1)
    counts = (n, n, int(round(slenderness / h)) + 1)
    x = lattice(counts, h)
    body = pd.Body(x, h ** 3, m * h * (1 + EPS))
    C3 = constant_for_ratio(3, TORSION_RATIO, 3, body.horizon)
    top = x[:, 2] > x[:, 2].max() - EPS
    material = pd.CPD(1.0, 0.0, C3, exponent=0.0)

    def turn(p, theta):
        r = p[:, :2] - 0.5
        c, s = math.cos(theta), math.sin(theta)
        return np.column_stack([c * r[:, 0] - s * r[:, 1] - r[:, 0],
                                s * r[:, 0] + c * r[:, 1] - r[:, 1], np.zeros(len(p))])
    print(f"torsion: {counts[0]}x{counts[1]}x{counts[2]} points, D = {h:.4g}, delta = {m:g}D, "
          f"C3 = {C3:.4g}, {steps} steps of {angle / steps:g} degrees")
    levels = np.linspace(0.0, angle, steps + 1)[1:]
    u, history, start = None, [], time.perf_counter()
    for theta in np.radians(levels):             # one problem per angle, started from the last
        prob = pd.Problem(body, material)
        prob.add_dirichlet(x[:, 2] < EPS, None, 0.0)
        prob.add_dirichlet(top, None, lambda p, t=theta: turn(p, t))
        sol = prob.solve(tol=TOL, initial=u)
        u, history = sol.u, history + sol.residual_history
    seconds = time.perf_counter() - start
    grid, ref = (x + u).reshape(*counts, 3), x.reshape(*counts, 3)
    r, y = ref[..., :2] - 0.5, grid[..., :2] - 0.5
    cross = (r[..., 0] * y[..., 1] - r[..., 1] * y[..., 0]).sum(axis=(0, 1))
    dot = (r * y).sum(axis=(0, 1, 3))
    rotation = np.degrees(np.unwrap(np.arctan2(cross, dot)))
    table = convergence_table(f"cf. paper Figures 8-9: C3 = {C3:.4g}, residual norms",
                              history, [f"{a:g} deg" for a in levels])
    print("section z / L:   " + " ".join(f"{z:6.2f}" for z in ref[0, 0, :, 2] / slenderness))
    print("rotation (deg):  " + " ".join(f"{a:6.1f}" for a in rotation) + f"   ({seconds:.1f}s)")

    def panels():
        return [dict(points=x + u, counts=counts, values=u[:, 1], field="$u_y$",
                     title=f"top turned {angle:g}°, δ = {m:g}h")]
    result = dict(C3=C3, z=ref[0, 0, :, 2], rotation=rotation, u=u, history=history,
                  seconds=seconds, tables=[table])
    return finish("torsion", result, outdir, plot, panels, 3, window=(700, 700))


def _von_mises(body, u, lam, mu):
    """von Mises stress per point from the nonlocal deformation gradient
    (`cnem.pd.strain.deformation_gradient`) and linear elasticity with the material's
    ``lam, mu`` (2-D, no out-of-plane stress)."""
    G = deformation_gradient(body, u) - np.eye(2)
    eps = 0.5 * (G + G.transpose(0, 2, 1))
    tr = eps[:, 0, 0] + eps[:, 1, 1]
    sxx, syy, sxy = lam * tr + 2 * mu * eps[:, 0, 0], lam * tr + 2 * mu * eps[:, 1, 1], \
        2 * mu * eps[:, 0, 1]
    return np.sqrt(sxx ** 2 - sxx * syy + syy ** 2 + 3 * sxy ** 2)


def lshape(spacing: float = 1 / 40, *, ratios: tuple = (2.0, 3.0, 4.0, 5.0), pull: float = 1e-3,
           outdir: str = "results/cpd_examples", plot: bool = True) -> dict:
    """§6.4, Figure 10: the unit square without its top-right quarter, bottom clamped,
    top of the left arm pulled up by ``pull`` (u_x = 0 there), C2 = 0, n = 1, at one
    grid for horizons ``delta = m D`` (m >= 2: at m = 1.5 the 8-neighbour lattice is
    anisotropic, a lattice effect on top); C1 is scaled with delta so that the shear modulus
    of the continuum limit stays 1 (nu = 1/3). The von Mises stress (`_von_mises`) is
    read along the row (y = 1/2, leftwards) and the column (x = 1/2, downwards) through
    the re-entrant corner (1/2, 1/2). Paper: D = 0.005 (default 1/40 here).

    Returns
    -------
    dict
        ``results``, per m: ``C1``, ``corner`` (von Mises at the corner point), ``row``
        and ``column`` (profiles from the corner), ``von_mises`` (n,), ``u``,
        ``history``, ``seconds``; ``distance`` (of the profile points from the corner),
        ``files``.
    """
    n = int(round(1 / spacing)) + 1
    h = 1.0 / (n - 1)
    full = lattice((n, n), h)
    inside = ~((full[:, 0] > 0.5 + EPS) & (full[:, 1] > 0.5 + EPS))
    x = full[inside]
    row = np.flatnonzero((np.abs(x[:, 1] - 0.5) < EPS) & (x[:, 0] < 0.5 + EPS))[::-1]
    column = np.flatnonzero((np.abs(x[:, 0] - 0.5) < EPS) & (x[:, 1] < 0.5 + EPS))[::-1]
    grip = (x[:, 1] > 1 - EPS)
    bottom = x[:, 1] < EPS
    results, tables = {}, []
    print(f"lshape: {len(x)} points, D = {h:.4g}, u_y = {pull:g} at the top of the left arm")
    for m in ratios:
        body = pd.Body(x, h * h, m * h * (1 + EPS))
        C1 = 1.0 / moduli_per_constant(2, body.horizon, 1.0)[0, 1]
        r = solve(body, pd.CPD(C1, exponent=1.0),
                  [(bottom, None, 0.0), (grip, 0, 0.0), (grip, 1, pull)])
        vm = _von_mises(body, r["u"], 1.0, 1.0)
        results[m] = dict(r, C1=C1, corner=float(vm[row[0]]), row=vm[row], column=vm[column],
                          von_mises=vm)
        tables.append(convergence_table(f"delta = {m:g}D, C1 = {C1:.4g}: residual norms",
                                        r["history"], [f"u_y = {pull:g}"]))
    distance = x[row[0], 0] - x[row, 0]
    print(f"{'delta/D':>8} {'corner vM':>10} {'max row':>9} {'max column':>11}")
    for m, r in results.items():
        print(f"{m:>8g} {r['corner']:>10.4g} {r['row'].max():>9.4g} {r['column'].max():>11.4g}")
    out = dict(results=results, distance=distance, tables=tables, files=[])
    if plot:
        out["files"].append(_profiles(pathlib.Path(outdir), distance, results, h))

    def panel(m):
        values = np.zeros(len(full))
        values[inside] = results[m]["von_mises"]
        return dict(points=full, counts=(n, n), values=values, hidden=~inside,
                    field=r"von Mises stress $\sigma_\mathrm{vM}$ ($\mu = 1$)",
                    title=f"$\\delta = {m:g}h$ ($h$ = {h:.4g})")
    return finish("lshape", out, outdir, plot, lambda: [panel(ratios[0]), panel(ratios[-1])],
                  2, window=(1200, 560))


def _profiles(out, distance, results, h):
    """von Mises along the row and the column through the corner (Figure 10); returns
    the file written."""
    from cnem.plot.charts import offscreen_pyplot
    plt = offscreen_pyplot()
    out.mkdir(parents=True, exist_ok=True)
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.6), sharey=True)
    for m, r in results.items():
        axes[0].plot(distance, r["row"], "o-", ms=3, label=f"$\\delta = {m:g}h$")
        axes[1].plot(distance[:len(r["column"])], r["column"], "o-", ms=3,
                     label=f"$\\delta = {m:g}h$")
    for ax, what in zip(axes, (r"leftwards from the corner ($y = 1/2$)",
                               r"downwards from the corner ($x = 1/2$)")):
        ax.set_xlabel(f"distance {what}")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    axes[0].set_ylabel(r"von Mises stress $\sigma_\mathrm{vM}$ ($\mu = 1$)")
    fig.suptitle(f"L-shape, lattice spacing $h$ = {h:.4g} (plate side 1): larger horizons "
                 f"smooth the corner's concentration")
    fig.tight_layout()
    fig.savefig(out / "cpd_lshape_profiles.png", dpi=100)
    plt.close(fig)
    print(f"wrote {out / 'cpd_lshape_profiles.png'}")
    return str(out / "cpd_lshape_profiles.png")
