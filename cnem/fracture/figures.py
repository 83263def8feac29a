"""Pictures of a crack-growth run (`GrowthHistory.plot`): matplotlib charts, off-screen
(`cnem.plot.charts`), PNG.

* `paths`: the geometry, the final von Mises field (at load factor 1) and the
  crack paths with a dot at every increment's tip;
* `sif_curves`: K_I, K_II and K_eq of every tip against its crack length;

Labels are matplotlib mathtext (``$K_\\mathrm{I}$``); units given by the caller may be too.
* `load_curves`: the critical load factor against crack length and, with a
  ``measure``, the load-displacement curve of brittle growth.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..io import cell_topology
from ..plot.charts import offscreen_pyplot

if TYPE_CHECKING:
    from typing import Any
    from matplotlib.figure import Figure

__all__ = ["paths", "sif_curves", "load_curves"]


def _unit(u):
    return f" ({u})" if u else ""


def _finish(fig, path):
    fig.tight_layout()
    if path is not None:
        fig.savefig(path, dpi=130)
    return fig


def _outline(ax, domain):
    for poly in domain.regions:
        for ring in [poly.exterior, *poly.interiors]:
            xy = np.asarray(ring.coords)
            ax.plot(xy[:, 0], xy[:, 1], "k-", lw=1.0)


def paths(hist: Any, path: str | None = None, *, length_unit: str = "", stress_unit: str = "",
          title: str | None = None, field: bool = True) -> Figure:
    """Crack paths over the geometry and the final von Mises field.

    Parameters
    ----------
    hist : GrowthHistory
    path : str or os.PathLike, optional
        PNG to write.
    length_unit, stress_unit : str
        Units for the axes and the colour bar.
    title : str, optional
    field : bool
        Draw the von Mises field of the last solution.

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = offscreen_pyplot()
    xmin, ymin, xmax, ymax = hist.domain.bounds
    aspect = (xmax - xmin) / (ymax - ymin)
    fig, ax = plt.subplots(figsize=(min(12.0, max(5.0, 5.0 * aspect + 2.2)), 5.5))
    sol = hist.solution
    if field and sol is not None:
        from matplotlib.collections import PolyCollection
        points, offsets, connectivity = cell_topology(sol.model.cells)
        polygons = [points[connectivity[a:b]] for a, b in zip(offsets[:-1], offsets[1:])]
        vm = np.asarray(sol.von_mises)                 # one value per cell: no smoothing
        top = np.percentile(vm, 99)                    # the tip singularity would wash out the rest
        art = PolyCollection(polygons, array=vm, cmap="viridis", edgecolors="face",
                             linewidths=0.2)
        art.set_clim(0.0, top)
        ax.add_collection(art)
        bar = fig.colorbar(art, ax=ax, shrink=0.8, extend="max")
        bar.set_label(r"von Mises stress $\sigma_\mathrm{vM}$ on the cells, at load factor 1"
                      f"{_unit(stress_unit)}")
    _outline(ax, hist.domain)
    first = True
    for crack in hist.cracks:
        ax.plot(crack[:, 0], crack[:, 1], "-", color="tab:red", lw=1.8,
                label="crack paths" if first else None)
        first = False
    tips = hist.paths()
    ax.plot(tips[..., 0].ravel(), tips[..., 1].ravel(), "o", ms=3, color="white", mec="black",
            mew=0.6, label="tip at each increment")
    ax.set_aspect("equal")
    ax.set_xlabel(f"$x${_unit(length_unit)}")
    ax.set_ylabel(f"$y${_unit(length_unit)}")
    ax.set_title(title or f"Crack paths, {len(hist.steps)} increments ({hist.criterion})")
    ax.legend(loc="upper right", fontsize=8, framealpha=0.9)
    return _finish(fig, path)


def sif_curves(hist: Any, path: str | None = None, *, length_unit: str = "", sif_unit: str = "",
               title: str | None = None, reference: np.ndarray | None = None) -> Figure:
    """K_I, K_II and K_eq of every tip against its crack length.

    Parameters
    ----------
    reference : (a, K) tuple of arrays, optional
        A reference K_I curve to draw (a handbook solution, say).

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = offscreen_pyplot()
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    length, K, K_eq = hist.array("crack_length"), hist.array("K"), hist.array("K_eq")
    if reference is not None:
        ax.plot(reference[0], reference[1], "k-", lw=1.0, label=r"reference $K_\mathrm{I}$")
    for i in range(K.shape[1]):
        tag = f" tip {i}" if K.shape[1] > 1 else ""
        # larger hollow markers and thinner lines for later tips: tips that coincide show
        style = dict(ms=3 + 3 * i, mfc="none" if i else None, lw=1.5 / (1 + i))
        ax.plot(length[:, i], K[:, i, 0], "o-", label=rf"$K_\mathrm{{I}}${tag}", **style)
        ax.plot(length[:, i], K[:, i, 1], "s--", label=rf"$K_\mathrm{{II}}${tag}", **style)
        ax.plot(length[:, i], K_eq[:, i], ":", lw=1.2 / (1 + i),
                label=rf"$K_\mathrm{{eq}}${tag}")
    ax.set_xlabel(f"crack length{_unit(length_unit)}")
    ax.set_ylabel(f"$K$ at load factor 1{_unit(sif_unit)}")
    ax.set_title(title or f"Stress intensity factors during growth "
                          f"({hist.criterion.replace('_', ' ')})")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return _finish(fig, path)


def load_curves(hist: Any, path: str | None = None, *, length_unit: str = "", load_unit: str = "",
                displacement_unit: str = "", title: str | None = None) -> Figure:
    """Critical load factor against crack length and, when ``measure`` was given,
    the load-displacement curve (``load_factor * measure`` against ``load_factor``).

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = offscreen_pyplot()
    measure = hist.array("measure")
    panels = 2 if np.isfinite(measure).any() else 1
    fig, axes = plt.subplots(1, panels, figsize=(6.0 * panels, 4.5), squeeze=False)
    length, load = hist.array("crack_length"), hist.array("load_factor")
    critical = np.nanmin(np.where(np.isfinite(load), load, np.inf), axis=1)
    critical[~np.isfinite(critical)] = np.nan
    ax = axes[0, 0]
    for i in range(load.shape[1]):
        ax.plot(length[:, i], load[:, i], "o-", ms=3,
                label=f"tip {i}" if load.shape[1] > 1
                else r"load factor $K_\mathrm{Ic} / K_\mathrm{eq}$")
    ax.set_xlabel(f"crack length{_unit(length_unit)}")
    ax.set_ylabel(f"critical load factor{_unit(load_unit)}")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title or "Load for growth against crack length")
    if panels == 2:
        ax = axes[0, 1]
        ax.plot(critical * measure, critical, "o-", ms=3,
                label=r"brittle growth ($K_\mathrm{eq} = K_\mathrm{Ic}$)")
        ax.plot([0, critical[0] * measure[0]], [0, critical[0]], "k:", lw=1.0,
                label="elastic loading, initial crack")
        ax.set_xlabel(f"displacement (measure × load factor){_unit(displacement_unit)}")
        ax.set_ylabel(f"load factor{_unit(load_unit)}")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        ax.set_title("Load-displacement")
    return _finish(fig, path)
