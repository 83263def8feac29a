"""Helpers of the CPD examples (`cnem.demos.cpd_examples`): the solve, the convergence
tables and the pictures (lattices: `cnem.pd.lattice`; moduli: `cnem.pd.cpd_moduli`)."""

from __future__ import annotations

import pathlib
import time
from typing import TYPE_CHECKING

import numpy as np

import cnem.pd as pd
from ..._sets import distinct

if TYPE_CHECKING:
    from typing import Sequence
    from ...pd.body import Body
    from ...pd.cpd import CPD

__all__ = ["solve", "convergence_table", "picture", "picture_3d", "finish", "RATIO", "TOL", "EPS"]

#: Stiffness ratio of the ">> C1" cases: lambda added per shear modulus of the bonds.
RATIO = 100.0
TOL = 1e-10
EPS = 1e-9
#: Scalar-bar placement right of the 3-D bodies (`picture_3d`).
BAR = dict(position_x=0.8, position_y=0.15, height=0.65)


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
    pick = distinct(np.linspace(0, len(history) - 1, min(columns, len(history))).round()
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
            window: tuple = (1200, 600)) -> str:
    """The deformed bodies of ``panels`` side by side, at one scale.

    Each panel is a dict with ``points`` (deformed, (n, d), in `cnem.pd.lattice.lattice` order),
    ``counts`` (the lattice shape), ``values`` (n,) of the field named ``field`` (a label,
    mathtext in 2-D), ``title`` and optionally ``hidden`` (n,) bool (lattice points not in the
    body) and ``reference`` (the undeformed points, drawn light grey behind). 2-D bodies are
    drawn by matplotlib (axes, a colour bar and a legend per panel), 3-D ones by pyvista
    (`picture_3d`). ``window`` is the size in pixels."""
    if dim == 3:
        return picture_3d(path, panels, window=window)
    from cnem.plot.charts import offscreen_pyplot
    plt = offscreen_pyplot()
    from matplotlib.collections import LineCollection
    from matplotlib.ticker import MaxNLocator
    from mpl_toolkits.axes_grid1 import make_axes_locatable
    dpi = 100
    fig, axes = plt.subplots(1, len(panels), figsize=(window[0] / dpi, window[1] / dpi),
                             sharex=True, sharey=True, squeeze=False)
    for ax, panel in zip(axes[0], panels):
        counts = tuple(panel["counts"])
        index = np.arange(int(np.prod(counts))).reshape(counts)
        quads = np.stack([index[:-1, :-1], index[1:, :-1], index[1:, 1:], index[:-1, 1:]],
                         axis=-1).reshape(-1, 4)
        if "hidden" in panel:
            quads = quads[~np.asarray(panel["hidden"])[quads].any(axis=1)]
        triangles = np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
        if "reference" in panel:
            ref = np.asarray(panel["reference"])
            ax.tripcolor(ref[:, 0], ref[:, 1], triangles, np.zeros(len(ref)),
                         cmap="Greys", vmin=-1.0, vmax=4.0, shading="flat", zorder=0)
            ax.fill([], [], color=(0.88, 0.88, 0.88), label="undeformed")
        p, values = np.asarray(panel["points"]), np.asarray(panel["values"])
        top = np.abs(values).max()
        signed = values.min() < 0 < values.max()
        shaded = ax.tripcolor(p[:, 0], p[:, 1], triangles, values, shading="gouraud",
                              cmap="viridis", vmin=-top if signed else None,
                              vmax=top if signed else None, zorder=1)
        deformed = "deformed" if "reference" in panel else "deformed, ×1"
        if max(counts) <= 40:
            edges = np.concatenate([quads[:, [0, 1]], quads[:, [1, 2]], quads[:, [2, 3]],
                                    quads[:, [3, 0]]])
            ax.add_collection(LineCollection(p[edges], colors=[(0.3, 0.3, 0.3)],
                                             linewidths=0.5, zorder=2))
            ax.plot([], [], color=(0.3, 0.3, 0.3), lw=0.8, label=f"lattice ({deformed})")
        else:
            ax.fill([], [], color=plt.get_cmap("viridis")(0.5), label=f"body ({deformed})")
        ax.set_aspect("equal")
        ax.set_title(panel["title"])
        ax.set_xlabel(r"$x$ (length unit)")
        ax.legend(loc="upper right", fontsize=8, framealpha=0.9)
        room = make_axes_locatable(ax).append_axes("bottom", size=0.15, pad=0.55)
        bar = fig.colorbar(shaded, cax=room, orientation="horizontal", label=panel["field"])
        bar.ax.xaxis.set_major_locator(MaxNLocator(5))
    axes[0][0].set_ylabel(r"$y$ (length unit)")
    fig.savefig(str(path), dpi=dpi, bbox_inches="tight")
    plt.close(fig)
    return str(path)


def picture_3d(path: str, panels: list[dict], *, window: tuple = (1200, 600)) -> str:
    """`picture` of 3-D lattices (pyvista, off-screen, one camera): each body shaded, the
    colour bar upright beside it, axes with the body's coordinates (length 1 = the cube's
    side) and the panel's title on top."""
    from cnem.plot.fields import _pyvista, colour_bar_font, use_font
    pv = _pyvista()
    pl = pv.Plotter(off_screen=True, window_size=window, shape=(1, len(panels)),
                    border=False)
    for k, panel in enumerate(panels):
        pl.subplot(0, k)
        pl.set_background("white")
        grid = pv.StructuredGrid()
        grid.points = np.asarray(panel["points"])
        grid.dimensions = tuple(panel["counts"][::-1])      # C order: last axis fastest
        name = panel["field"] + " " * k          # pyvista shares the bars of equal titles
        grid.point_data[name] = panel["values"]
        top = np.abs(panel["values"]).max()
        signed = panel["values"].min() < 0 < panel["values"].max()
        pl.add_mesh(grid, scalars=name, cmap="viridis", show_edges=max(panel["counts"]) <= 40,
                    clim=(-top, top) if signed else None, edge_color=(0.3, 0.3, 0.3),
                    scalar_bar_args=dict(title=name, color="black", vertical=True,
                                         title_font_size=14, label_font_size=12, fmt="%.3g",
                                         **BAR))
        colour_bar_font(pl.scalar_bars[name])
        pl.show_bounds(grid="back", location="outer", color="black", font_size=10,
                       xtitle="x", ytitle="y", ztitle="z", fmt="%.1f")
        title = pl.add_text(panel["title"], position="upper_left", font_size=9,
                            color="black")
        use_font(title.GetTextProperty())
    pl.link_views()                                       # one camera: one scale
    pl.view_isometric()
    pl.reset_camera()
    pl.camera.zoom(0.85)                                   # room for the title on top
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
