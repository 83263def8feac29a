"""CPD examples of §6.1 (Figures 5-6, Tables 4-8): 2-D and 3-D uniaxial stretch to twice
the length with one-, two- and three-neighbour interactions."""

from __future__ import annotations

import numpy as np

import cnem.pd as pd

from cnem.demos.cpd.common import EPS, RATIO, convergence_table, finish, solve
from cnem.pd.cpd_moduli import constant_for_ratio
from cnem.pd.lattice import lattice, lattice_measure

__all__ = ["tension2d", "cube"]


#: The cases of `tension2d` in symbols (picture titles).
SYMBOLS = {"C2=0": r"$C_2 = 0$", "C2>>C1": r"$C_2 \gg C_1$"}


def tension2d(spacing: float = 0.02, *, m: float = 3.0, steps: int = 10, ratio: float = RATIO,
              outdir: str = "results/cpd_examples", plot: bool = True) -> dict:
    """§6.1, Figure 5: a unit square stretched to twice its length (n = 1), C2 = 0 and
    C2 >> C1 (`RATIO`). Left column u_x = 0, right column u_x = 1, u_y = 0 at the middle
    of both (lateral contraction free). Paper: D = 0.01 (default 0.02 here).

    Returns
    -------
    dict
        ``cases``, per case (``"C2=0"``, ``"C2>>C1"``): ``C2``, ``area_ratio`` (deformed /
        reference lattice area), ``central_area_ratio`` (middle third in x),
        ``lateral_stretch`` (mid-length width / 1), ``history``, ``seconds``, ``u``;
        ``files``.
    """
    n = int(round(1 / spacing)) + 1
    counts, h = (n, n), 1.0 / (n - 1)
    x = lattice(counts, h)
    body = pd.Body(x, h * h, m * h * (1 + EPS))
    left, right = x[:, 0] < EPS, x[:, 0] > 1 - EPS
    held = (left | right) & (np.abs(x[:, 1] - 0.5) < EPS)
    mid = np.abs(x[:, 0] - x[np.argmin(np.abs(x[:, 0] - 0.5)), 0]) < EPS
    centre = np.abs(lattice(np.array(counts) - 1, h)[:, 0] + h / 2 - 0.5) < 1 / 6
    levels = np.arange(1, steps + 1) / steps
    cases, tables = {}, []
    print(f"tension2d: {n}x{n} points, D = {h:.4g}, delta = {m:g}D, {steps} load steps")
    stiff = constant_for_ratio(2, ratio, 2, body.horizon)
    for name, table, C2 in (("C2=0", 5, 0.0), ("C2>>C1", 4, stiff)):
        r = solve(body, pd.CPD(1.0, C2, exponent=1.0),
                  [(left, 0, 0.0), (right, 0, 1.0), (held, 1, 0.0)], steps=steps)
        cells = lattice_measure(x + r["u"], counts).reshape(-1)
        cases[name] = dict(r, C2=C2, area_ratio=float(cells.sum()),
                           central_area_ratio=float(cells[centre].sum() / (h * h * centre.sum())),
                           lateral_stretch=float(np.ptp((x + r["u"])[mid, 1])))
        tables.append(convergence_table(f"cf. paper Table {table}: {name} (C2 = {C2:.4g}), "
                                        f"residual norms", r["history"],
                                        [f"stretch {1 + t:.2f}" for t in levels]))
    print(f"{'case':>8} {'C2':>10} {'area ratio':>11} {'central':>8} {'width':>7} {'time':>6}")
    for name, c in cases.items():
        print(f"{name:>8} {c['C2']:>10.4g} {c['area_ratio']:>11.4f} "
              f"{c['central_area_ratio']:>8.4f} {c['lateral_stretch']:>7.4f} {c['seconds']:>5.1f}s")
    return finish("tension2d", dict(cases=cases, tables=tables), outdir, plot, lambda: [
        dict(points=x + c["u"], counts=counts, values=c["u"][:, 1], reference=x,
             field=r"$u_y$", title=f"{SYMBOLS[k]}, stretch 2, $\\delta = {m:g}h$")
        for k, c in cases.items()], 2)


def cube(n: int = 7, *, m: float = 2.0, steps: int = 8, ratio: float = RATIO,
         outdir: str = "results/cpd_examples", plot: bool = True) -> dict:
    """§6.1, Figure 6: a unit cube stretched to twice its height (n = 1) with one-,
    one- and two- (C2 >> C1) and one- and three-neighbour (C3 >> C1) interactions.
    Bottom u_z = 0, top u_z = 1, the axis' end points and one bottom point held
    laterally (symmetric, so the contraction is free). Paper: 21^3 points, delta = 3D
    (~10^8 pairs); here ``n^3`` points, delta = ``m`` D.

    Returns
    -------
    dict
        ``cases``, per case (``"one"``, ``"two"``, ``"three"``): ``C2, C3``,
        ``lateral_stretch`` (mid-height width), ``volume_ratio`` (whole lattice),
        ``central_volume_ratio`` (middle third in z), ``history``, ``seconds``, ``u``;
        ``files``.
    """
    counts, h = (n, n, n), 1.0 / (n - 1)
    x = lattice(counts, h)
    body = pd.Body(x, h ** 3, m * h * (1 + EPS))
    bottom, top = x[:, 2] < EPS, x[:, 2] > 1 - EPS
    axis = np.all(np.abs(x[:, :2] - 0.5) < EPS, axis=1) & (bottom | top)
    side = bottom & (np.abs(x[:, 1] - 0.5) < EPS) & (x[:, 0] > 1 - EPS)

    conditions = [(bottom, 2, 0.0), (top, 2, 1.0), (axis, 0, 0.0), (axis, 1, 0.0),
                  (side, 1, 0.0)]
    levels = np.arange(1, steps + 1) / steps
    mid = np.abs(x[:, 2] - x[np.argmin(np.abs(x[:, 2] - 0.5)), 2]) < EPS
    centre = np.abs(lattice(np.array(counts) - 1, h)[:, 2] + h / 2 - 0.5) < 1 / 6
    cases, tables = {}, []
    print(f"cube: {n}^3 points, D = {h:.4g}, delta = {m:g}D, {steps} load steps")
    C2, C3 = (constant_for_ratio(k, ratio, 3, body.horizon) for k in (2, 3))
    for name, table, (c2, c3) in (("one", 6, (0.0, 0.0)), ("two", 7, (C2, 0.0)),
                                  ("three", 8, (0.0, C3))):
        r = solve(body, pd.CPD(1.0, c2, c3, exponent=1.0), conditions, steps=steps)
        cells = lattice_measure(x + r["u"], counts).reshape(-1)
        cases[name] = dict(r, C2=c2, C3=c3, lateral_stretch=float(np.ptp((x + r["u"])[mid, 0])),
                           volume_ratio=float(cells.sum()),
                           central_volume_ratio=float(cells[centre].sum() /
                                                      (h ** 3 * centre.sum())))
        tables.append(convergence_table(f"cf. paper Table {table}: {name}-neighbour "
                                        f"(C2 = {c2:.4g}, C3 = {c3:.4g}), residual norms",
                                        r["history"], [f"stretch {1 + t:.2f}" for t in levels]))
    print(f"{'case':>6} {'width':>7} {'volume':>7} {'central':>8} {'time':>6}")
    for name, c in cases.items():
        print(f"{name:>6} {c['lateral_stretch']:>7.4f} {c['volume_ratio']:>7.4f} "
              f"{c['central_volume_ratio']:>8.4f} {c['seconds']:>5.1f}s")
    return finish("cube", dict(cases=cases, tables=tables), outdir, plot, lambda: [
        dict(points=x + c["u"], counts=counts, values=c["u"][:, 0], field="$u_x$",
             title=f"{k}-neighbour,\nstretch 2, δ = {m:g}h") for k, c in cases.items()], 3)
