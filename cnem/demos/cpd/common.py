"""Helpers of the CPD examples (`cnem.demos.cpd_examples`): the solve, the convergence
tables and the pictures (lattices: `cnem.pd.lattice`; moduli: `cnem.pd.cpd_moduli`)."""

from __future__ import annotations

import pathlib
import time
from typing import TYPE_CHECKING

import numpy as np

import cnem.pd as pd

if TYPE_CHECKING:
    from typing import Sequence
    from ...pd.body import Body
    from ...pd.cpd import CPD

__all__ = ["solve", "convergence_table", "picture", "finish", "RATIO", "TOL", "EPS"]

#: Stiffness ratio of the ">> C1" cases: lambda added per shear modulus of the bonds.
RATIO = 100.0
TOL = 1e-10
EPS = 1e-9
#: Scalar-bar placement: below the 2-D bodies, right of the 3-D ones.
BAR = {2: dict(position_x=0.15, position_y=0.04, width=0.7, height=0.09),
       3: dict(position_x=0.8, position_y=0.15, height=0.65)}


def solve(body: Body, material: CPD, conditions: list[tuple], *, steps: int = 1,
          force: np.ndarray | None = None, tol: float = TOL) -> dict:
    """`cnem.pd.Problem.solve` of ``body`` with the Dirichlet ``conditions``
    [(where, component, value), ...] and an optional body force, in ``steps`` load steps.

    Returns
    -------
    dict
        ``u`` (n, d), ``history`` (residual norms per Newton iteration, one list per
        load step), ``seconds``.
    """
    prob = pd.Problem(body, material)
    for where, component, value in conditions:
        prob.add_dirichlet(where, component, value)
    if force is not None:
        prob.add_body_force(force)
    start = time.perf_counter()
    sol = prob.solve(tol=tol, steps=steps)
    return dict(u=sol.u, history=sol.residual_history, seconds=time.perf_counter() - start)


def convergence_table(title: str, history: Sequence[float], labels: Sequence[str],
                      columns: int = 5) -> str:
    """The residual norms per Newton iteration (rows) of up to ``columns`` load steps
    (evenly chosen, always the last), like the paper's Tables 4-8."""
    pick = np.unique(np.linspace(0, len(history) - 1, min(columns, len(history))).round()
                     .astype(int))
    rows = max(len(history[k]) for k in pick)
    lines = [title, "iteration" + "".join(f"{labels[k]:>14}" for k in pick)]
    for it in range(rows):
        lines.append(f"{it:>9}" + "".join(f"{history[k][it]:>14.3e}" if it < len(history[k])
                                           else " " * 14 for k in pick))
    total = sum(len(h) for h in history)
    lines.append(f"{len(history)} load steps, {total} residual evaluations in all")
    return "\n".join(lines)


def picture(path: str, panels: list[dict], *, dim: int,
            window: tuple = (1200, 600)) -> str | np.ndarray:
    """The deformed bodies of ``panels`` side by side, at one scale (pyvista, off-screen).

    Each panel is a dict with ``points`` (deformed, (n, d), in `cnem.pd.lattice.lattice` order),
    ``counts`` (the lattice shape), ``values`` (n,) of the field named ``field``,
    ``title`` and optionally ``hidden`` (n,) bool (lattice points not in the body) and
    ``reference`` (the undeformed points, drawn light grey behind)."""
    from cnem.plot import _pyvista
    pv = _pyvista()

    def grid_of(points, counts, z=0.0):
        grid = pv.StructuredGrid()
        grid.points = np.column_stack([points, np.full((len(points), 3 - dim), z)])
        grid.dimensions = (tuple(counts[::-1]) + (1,))[:3]      # C order: last axis fastest
        return grid
    pl = pv.Plotter(off_screen=True, window_size=window, shape=(1, len(panels)),
                    border=False)
    for k, panel in enumerate(panels):
        pl.subplot(0, k)
        pl.set_background("white")
        grid = grid_of(panel["points"], panel["counts"])
        name = panel["field"] + " " * k          # pyvista shares the bars of equal titles
        grid.point_data[name] = panel["values"]
        if "hidden" in panel:
            grid.hide_points(np.flatnonzero(panel["hidden"]))
        if "reference" in panel:                  # below the deformed body in a 2-D view
            pl.add_mesh(grid_of(panel["reference"], panel["counts"], z=-1.0),
                        color=(0.88, 0.88, 0.88), lighting=False)
        top = np.abs(panel["values"]).max()
        signed = panel["values"].min() < 0 < panel["values"].max()
        pl.add_mesh(grid, scalars=name, cmap="viridis", show_edges=max(panel["counts"]) <= 40,
                    clim=(-top, top) if signed else None,
                    edge_color=(0.3, 0.3, 0.3), lighting=dim == 3,
                    scalar_bar_args=dict(title=name + "\n" * (dim == 3),   # room above
                                         color="black", vertical=dim == 3,
                                         title_font_size=14, label_font_size=12, fmt="%.3g",
                                         **BAR[dim]))
        if dim == 2:                                      # the labels under the bar
            pl.scalar_bars[name].SetTextPositionToPrecedeScalarBar()
        pl.add_text(panel["title"], position="upper_edge", font_size=11, color="black")
    pl.link_views()                                       # one camera: one scale
    if dim == 2:
        pl.view_xy()
        pl.enable_parallel_projection()
    else:
        pl.view_isometric()
    pl.reset_camera()
    pl.screenshot(str(path))
    pl.close()
    return str(path)


def finish(name: str, result: dict, outdir: str, plot: bool, panels: list[dict], dim: int,
           window: tuple = (1200, 600)) -> dict:
    """Print the example's tables, write its picture, return its numbers."""
    for text in result.pop("tables"):
        print(text + "\n")
    result.setdefault("files", [])
    if plot:
        out = pathlib.Path(outdir)
        out.mkdir(parents=True, exist_ok=True)
        result["files"].append(picture(out / f"cpd_{name}.png", panels(), dim=dim,
                                       window=window))
        print(f"wrote {result['files'][-1]}")
    return result
