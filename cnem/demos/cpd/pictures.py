"""The picture of one example of `cnem.demos.cnem_vs_cpd`: both deformed bodies over the
undeformed outline, their difference, and the curves of every run."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["compare_picture", "horizon_curves"]


def _deformed(ax, tri, points, u, values, label, cmap, vmax):
    """``values`` on the body deformed by ``u``, over the undeformed outline (matplotlib
    triangulation ``tri`` of the reference points)."""
    import matplotlib.tri as mtri
    ref = tri.triangles
    edges = tri.edges
    boundary = _outline(ref)
    for a, b in boundary:
        ax.plot(points[[a, b], 0], points[[a, b], 1], color="0.55", lw=0.8, ls="--", zorder=0)
    ax.plot([], [], color="0.55", lw=0.8, ls="--", label="undeformed")
    x = points + u
    shaded = ax.tripcolor(mtri.Triangulation(x[:, 0], x[:, 1], ref), values, shading="gouraud",
                          cmap=cmap, vmin=0.0, vmax=vmax, zorder=1)
    if len(edges) < 2500:
        ax.triplot(mtri.Triangulation(x[:, 0], x[:, 1], ref), color="0.3", lw=0.25, zorder=2)
    ax.set_title(label, fontsize=10)
    ax.set_aspect("equal")
    ax.set_xlabel("$x$ (length unit)")
    ax.set_ylabel("$y$ (length unit)")
    ax.legend(loc="best", fontsize=7, framealpha=0.8)
    return shaded


def _outline(triangles):
    """The edges used by one triangle only: the outline of the triangulated body."""
    e = np.sort(np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]],
                                triangles[:, [2, 0]]]), axis=1)
    unique, count = np.unique(e, axis=0, return_counts=True)
    return unique[count == 1]


def compare_picture(path: str, res: dict, cpd: str, name: str) -> str:
    """Write ``path``: C-NEM's and CPD run ``cpd``'s deformed shapes (colour: |u|), the
    difference ``|u_CPD - u_C-NEM|`` on C-NEM's deformed body, all at the last load step,
    and ``res["force"]`` of every run against ``res["x"]`` with ``res["closed"]``.

    Parameters
    ----------
    path : str
    res : dict
        An example's result of `cnem.demos.cnem_vs_cpd` (``model``, ``runs``, ``force``,
        ``x``, ``closed``, ``xlabel``, ``ylabel``; optional ``triangles`` of the nodes
        for a non-convex body, ``origin``: the abscissa of the curves' zero point, None
        for none, ``closed`` None for no reference curve, ``magnify`` the displacements
        drawn).
    cpd : str
        The key of the CPD run drawn.
    name : str
        The example's name (titles).

    Returns
    -------
    str
    """
    from matplotlib.tri import Triangulation

    from cnem.plot.charts import offscreen_pyplot
    plt = offscreen_pyplot()
    points = res["model"].nodes
    tri = Triangulation(points[:, 0], points[:, 1], res.get("triangles"))
    u_cnem, u_cpd = res["runs"]["C-NEM"].u[-1], res["runs"][cpd].u[-1]
    size = [np.hypot(*u_cnem.T), np.hypot(*u_cpd.T)]
    top = max(s.max() for s in size)
    magnify = res.get("magnify", 1.0)
    shown = f" (x {magnify:g})" if magnify != 1.0 else ""
    wide = np.ptp(points[:, 0]) > 3 * np.ptp(points[:, 1])
    fig, axes = plt.subplots(2, 2, figsize=(13, 8.5 if wide else 9.5))
    for ax, u, s, label in ((axes[0, 0], u_cnem, size[0], "C-NEM (Hyperelasticity)"),
                            (axes[0, 1], u_cpd, size[1], f"{cpd.replace('h', ' h')}")):
        shaded = _deformed(ax, tri, points, magnify * u, s, f"{name}: {label}, deformed{shown}",
                           "viridis", top)
        fig.colorbar(shaded, ax=ax, shrink=0.8, label="$|u|$ (length unit)")
    diff = np.hypot(*(u_cpd - u_cnem).T)
    shaded = _deformed(axes[1, 0], tri, points, magnify * u_cnem, diff,
                       f"$|u_{{CPD}} - u_{{C-NEM}}|$ ({cpd}) on C-NEM's deformed body",
                       "magma", diff.max())
    fig.colorbar(shaded, ax=axes[1, 0], shrink=0.8, label="difference (length unit)")
    ax = axes[1, 1]
    if res.get("closed") is not None:
        fine, closed = res["closed"]
        ax.plot(fine, closed, color="k", lw=1.2,
                label="closed form" if name == "tension" else "linear limit (C-NEM)")
    horizon_curves(ax, res["x"], res["force"], res["xlabel"], res["ylabel"],
                   res.get("origin", 0.0 if name != "tension" else 1.0))
    ax.set_title(res.get("curve_title", f"{name}: C-NEM and CPD as the horizon shrinks"),
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def horizon_curves(ax: Axes, x: np.ndarray, curves: dict, xlabel: str, ylabel: str,
                   origin: float | None = 0.0) -> None:
    """Draw ``curves`` (run name -> values ``(s,)``: "C-NEM" and "CPD <m>h") against
    ``x (s,)`` on the matplotlib axes ``ax``, each from ``(origin, 0)`` unless ``origin``
    is None, C-NEM solid, CPD dashed."""
    x = x if origin is None else np.concatenate([[origin], x])
    for key, curve in curves.items():
        style = dict(marker="o", lw=1.8, color="tab:red") if key == "C-NEM" else \
            dict(marker="s", lw=1.0, ms=4, ls="--")
        ax.plot(x, curve if origin is None else np.concatenate([[0.0], curve]),
                label=f"CPD, horizon {key[4:-1]} spacings" if key != "C-NEM" else "C-NEM",
                **style)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
