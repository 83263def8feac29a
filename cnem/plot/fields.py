"""Scenes with pyvista, off-screen: a `Model` (cells, triangles, nodes, cracks) and
a solution (deformed shape coloured by a field).

pyvista is imported only here, and only when a picture is drawn (`_pyvista`); the
package's docstring (`cnem.plot`) shows the use.
"""

from __future__ import annotations

import logging
import os
import pathlib
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from .. import config
from ..errors import PlotDependencyError, PlotError, PlotInputError, check_array
from ..geometry.model import check_model
from ..geometry.pslg import SegmentKind
from ..io import cell_topology

if TYPE_CHECKING:
    import pyvista

    from ..geometry.model import Model

__all__ = ["model", "solution", "cells_polydata", "region_color", "PlotError", "REGION_COLORS",
           "SOLUTION_FIELDS", "FIELD_LABELS"]

log = logging.getLogger(__name__)

#: Categorical colours of the regions (RGB, 0-255), light so that the black
#: cell edges, grey triangles and red cracks stand out; region ``r`` gets
#: ``REGION_COLORS[r % len(REGION_COLORS)]``.
REGION_COLORS = np.array([
    [166, 206, 227],   # light blue
    [253, 191, 111],   # light orange
    [178, 223, 138],   # light green
    [251, 154, 153],   # light red
    [202, 178, 214],   # light purple
    [255, 255, 153],   # light yellow
    [141, 211, 199],   # teal
    [217, 217, 217],   # light grey
    [252, 205, 229],   # pink
    [204, 235, 197],   # mint
], dtype=np.uint8)

INSTALL_HINT = 'install the plotting extra: pip install "cnem[plot]"'


def _pyvista():
    """pyvista, set to render off-screen, or a `PlotError` saying how to get it."""
    try:
        import pyvista
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise PlotDependencyError(f"cnem.plot needs pyvista, which cannot be imported ({exc}); "
                        f"{INSTALL_HINT}") from exc
    pyvista.OFF_SCREEN = True
    return pyvista


def region_color(region: ArrayLike) -> np.ndarray:
    """RGB colour (0-255) of each region, ``(r, 3)`` uint8 for ``(r,)`` region indices."""
    index = check_array("region", region, shape=(None,), error=PlotInputError,
                        fix="pass the region index of each cell (model.cells.region)")
    if (index != np.round(index)).any():
        raise PlotInputError(f"region: expected whole region indices, received "
                             f"{index[index != np.round(index)][0]!r}")
    return REGION_COLORS[index.astype(np.int64) % len(REGION_COLORS)]


def _lift(points2d, z):
    out = np.zeros((len(points2d), 3))
    out[:, :2] = points2d
    out[:, 2] = z
    return out


def _lines(pv, points2d, pairs, z):
    """PolyData of the segments ``pairs (s, 2)`` between ``points2d`` at height ``z``."""
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    lines = np.column_stack([np.full(len(pairs), 2), pairs]).ravel()
    return pv.PolyData(_lift(points2d, z), lines=lines)


def cells_polydata(model: Model) -> pyvista.PolyData:
    """The integration cells as a pyvista ``PolyData`` (one polygon per cell).

    Parameters
    ----------
    model : Model
        ``m`` integration cells.

    Returns
    -------
    pyvista.PolyData
        ``m`` polygons in the order of ``model.cells``, points at ``z = 0``,
        cell data ``region``, ``node``, ``area`` and ``cell`` (0..m-1) and
        ``color`` (``(m, 3)`` uint8, the region's colour).
    """
    pv = _pyvista()
    points, offsets, connectivity = cell_topology(model.cells)
    sizes = np.diff(offsets)
    faces = np.insert(connectivity, offsets[:-1], sizes)
    poly = pv.PolyData(_lift(points, 0.0), faces=faces)
    cells = model.cells
    poly.cell_data["region"] = np.asarray(cells.region, np.int64)
    poly.cell_data["node"] = np.asarray(cells.node, np.int64)
    poly.cell_data["area"] = np.asarray(cells.area, np.float64)
    poly.cell_data["cell"] = np.arange(len(cells), dtype=np.int64)
    poly.cell_data["color"] = region_color(cells.region)
    return poly


def _triangle_edges(triangles):
    t = np.asarray(triangles, dtype=np.int64)
    e = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    return np.unique(np.sort(e, axis=1), axis=0)


def model(model: Model, path: str | os.PathLike | None = None, *, show_triangles: bool = True,
          show_nodes: bool = True, show_cracks: bool = True,
          window_size: tuple[int, int] = (1200, 1200),
          bounds: tuple[float, float, float, float] | None = None,
          node_size: float | None = None, length_unit: str | None = None) -> pyvista.Plotter:
    """Top view of a model: constrained Voronoi cells, Delaunay triangles, nodes, cracks,
    a legend and a scale bar.

    Cells are filled with their region's colour (`REGION_COLORS`, unlit so the
    colours in the picture are exact) with black edges; triangle edges are
    thin grey lines, nodes black dots and crack faces thick red lines.

    Parameters
    ----------
    model : Model
        From `cnem.discretize`.
    path : str or os.PathLike, optional
        Write a PNG there (parent folders are created).
    show_triangles, show_nodes, show_cracks : bool
        Draw the constrained Delaunay triangles, the nodes, the crack faces
        (segments with ``segment_kind == SegmentKind.CRACK``).
    window_size : (2,) int
        Picture size in pixels, ``(width, height)``.
    bounds : (4,) float, optional
        ``(xmin, ymin, xmax, ymax)`` to show (a zoom; the order of
        ``Domain.bounds``); default the whole domain.
    node_size : float, optional
        Node dot size in pixels; default from the smallest node spacing in view.
    length_unit : str, optional
        The unit of the coordinates, written on the scale bar (e.g. ``"mm"``).

    Returns
    -------
    pyvista.Plotter
        Off-screen; call ``.close()`` when done with it.

    Raises
    ------
    PlotDependencyError
        pyvista missing, or the picture cannot be rendered (an `ImportError`).
    PlotInputError
        empty ``bounds`` (a `ValueError`).
    """
    pv = _pyvista()
    mdl = check_model(model, "cnem.plot.model")
    dom = mdl.domain
    bx0, by0, bx1, by1 = view_bounds(dom.bounds if bounds is None else bounds)
    width, height = window_pixels(window_size)
    lift = 1e-4 * dom.diameter        # draw lines above the cells (parallel view: no shift)
    pl = _plotter(pv, width, height)
    # pixels per unit length in the final view
    scale = min(width / (bx1 - bx0), height / (by1 - by0)) / 1.04
    pl.add_mesh(cells_polydata(mdl), scalars="color", rgb=True, lighting=False,
                show_edges=True, edge_color="black", line_width=max(1.0, width / 1200),
                show_scalar_bar=False)
    if show_triangles and len(mdl.triangles):
        pl.add_mesh(_lines(pv, mdl.nodes, _triangle_edges(mdl.triangles), lift),
                    color=(0.55, 0.55, 0.55), line_width=max(0.5, 0.5 * width / 1200),
                    lighting=False)
    crack = np.asarray(mdl.segments)[np.asarray(mdl.segment_kind) == SegmentKind.CRACK]
    if show_cracks:
        if len(crack):
            pl.add_mesh(_lines(pv, mdl.nodes, crack, 2 * lift), color="red",
                        line_width=max(3.0, 4.0 * width / 1200), lighting=False)
    if show_nodes:
        nodes = np.asarray(mdl.nodes)
        if node_size is None:
            spacing = np.asarray(mdl.cloud.spacing)
            seen = ((mdl.cloud.points[:, 0] >= bx0) & (mdl.cloud.points[:, 0] <= bx1)
                    & (mdl.cloud.points[:, 1] >= by0) & (mdl.cloud.points[:, 1] <= by1))
            h = spacing[seen].min() if seen.any() else spacing.min()
            node_size = float(np.clip(0.25 * h * scale, 2.0, 10.0))
        pl.add_mesh(pv.PolyData(_lift(nodes, 3 * lift)), color="black",
                    point_size=node_size, render_points_as_spheres=True, lighting=False)
    view = (bx0, by0 - 0.1 * (by1 - by0), bx1, by1)          # room below for the scale bar
    entries = [("constrained Voronoi cells, a colour per region", "black")]
    entries += [("constrained Delaunay triangles", (0.55, 0.55, 0.55))] * show_triangles
    entries += [("crack faces", "red")] * (show_cracks and bool(len(crack)))
    entries += [("nodes", "black")] * show_nodes
    _legend(pl, entries)
    _top_view(pl, view, width, height, dom.diameter)
    _scale_bar(pl, pv, view, length_unit, 4 * lift)
    return _save(pl, path, "model")


def view_bounds(bounds: Any) -> tuple[float, float, float, float]:
    """``bounds = (xmin, ymin, xmax, ymax)`` of a view (the order of ``Domain.bounds``),
    checked.

    Raises
    ------
    PlotInputError
        Not four finite numbers, or an empty view.
    """
    bx0, by0, bx1, by1 = check_array("bounds", bounds, shape=(4,), error=PlotInputError,
                                     fix="pass (xmin, ymin, xmax, ymax)")
    if not (bx1 > bx0 and by1 > by0):
        raise PlotInputError(f"bounds must be (xmin, ymin, xmax, ymax) with xmin < xmax and "
                             f"ymin < ymax, received {tuple(bounds)}; give a non-empty view")
    return float(bx0), float(by0), float(bx1), float(by1)


def window_pixels(window_size: Any) -> tuple[int, int]:
    """``(width, height)`` of a picture, checked before VTK sees them.

    Parameters
    ----------
    window_size : (2,) int array_like

    Returns
    -------
    (int, int)

    Raises
    ------
    PlotInputError
        Not two whole numbers from 1 to `cnem.config.PLOT_MAX_PIXELS` (VTK aborts the
        interpreter on a negative or huge window, and divides by zero on an empty one).
    """
    size = np.asarray(window_size, dtype=object).reshape(-1) if np.ndim(window_size) else None
    limit = config.PLOT_MAX_PIXELS
    ok = size is not None and len(size) == 2 and all(
        isinstance(v, (int, np.integer)) and not isinstance(v, bool) and 1 <= v <= limit
        for v in size)
    if not ok:
        raise PlotInputError(f"window_size: expected (width, height) in whole pixels from 1 to "
                             f"{limit}, received {window_size!r}; give e.g. (1200, 1000)")
    return int(size[0]), int(size[1])


def _plotter(pv, width, height):
    """An off-screen plotter with a white background."""
    try:
        pl = pv.Plotter(off_screen=True, window_size=(width, height))
    except Exception as exc:  # pragma: no cover - depends on the environment
        raise PlotDependencyError(f"pyvista cannot open an off-screen window ({exc}); "
                                  f"{INSTALL_HINT} and make sure VTK has an off-screen backend "
                                  f"(OSMesa/EGL) or a display") from exc
    pl.set_background("white")
    return pl


def _top_view(pl, bounds, width, height, diameter, right=0.0):
    """Parallel top view of ``bounds = (xmin, ymin, xmax, ymax)`` with a 4 % margin,
    and ``right`` (a fraction of the window's width) free on the right (a colour bar)."""
    bx0, by0, bx1, by1 = bounds
    bx1 = bx0 + (bx1 - bx0) / (1.0 - right)
    pl.view_xy()
    pl.enable_parallel_projection()
    cx, cy = 0.5 * (bx0 + bx1), 0.5 * (by0 + by1)
    cam = pl.camera
    cam.focal_point = (cx, cy, 0.0)
    cam.position = (cx, cy, 10.0 * diameter)
    cam.up = (0.0, 1.0, 0.0)
    cam.parallel_scale = 0.5 * 1.04 * max(by1 - by0, (bx1 - bx0) * height / width)
    pl.reset_camera_clipping_range()


def font_file() -> str | None:
    """A TrueType font with Greek letters and subscripts (matplotlib's DejaVu Sans), or
    None without matplotlib (VTK's own fonts then, which lack them)."""
    try:
        import matplotlib
    except ImportError:  # pragma: no cover - depends on the environment
        return None
    path = pathlib.Path(matplotlib.get_data_path()) / "fonts" / "ttf" / "DejaVuSans.ttf"
    return str(path) if path.exists() else None


def use_font(*properties) -> None:
    """Draw the VTK text properties ``properties`` in `font_file` (so σ, θ, δ show)."""
    font = font_file()
    if font is None:  # pragma: no cover - depends on the environment
        return
    for prop in properties:
        prop.SetFontFamily(4)                     # VTK_FONT_FILE
        prop.SetFontFile(font)


def nice_length(span: float) -> float:
    """A round length (1, 2 or 5 times a power of ten) near a fifth of ``span > 0``."""
    target = 0.2 * span
    power = 10.0 ** np.floor(np.log10(target))
    return float(max(m * power for m in (1.0, 2.0, 5.0) if m * power <= target))


def _scale_bar(pl, pv, view, unit, z):
    """A black bar of a round length at the lower left of ``view`` (``(xmin, ymin,
    xmax, ymax)``, the area shown), labelled with its length and ``unit``."""
    bx0, by0, bx1, by1 = view
    length = nice_length(bx1 - bx0)
    x0, y0 = bx0 + 0.02 * (bx1 - bx0), by0 + 0.025 * (by1 - by0)
    ends = np.array([[x0, y0], [x0 + length, y0]])
    pl.add_mesh(_lines(pv, ends, [[0, 1]], z), color="black", line_width=6, lighting=False)
    label = f"{length:g} {unit}" if unit else f"{length:g} (length unit)"
    pl.add_point_labels(_lift(ends[:1] + [[0.0, 0.03 * (by1 - by0)]], z),
                        [label], font_size=22, text_color="black", shape=None,
                        show_points=False, always_visible=True)


#: Pixels between an upright colour bar's title and the top of the bar: more than half a
#: label's height (labels of ``label_font_size`` 18 stand centred on their values), so the
#: title clears the top label (a plain or a ``$...$`` mathtext title alike).
BAR_TITLE_GAP = 24


def colour_bar_font(bar) -> None:
    """Write a VTK scalar bar's title and labels in `font_file` and lift its title
    `BAR_TITLE_GAP` pixels off the bar (upright bars: the title above, the labels beside it,
    so they cannot overlap)."""
    use_font(bar.GetTitleTextProperty(), bar.GetLabelTextProperty())
    bar.SetVerticalTitleSeparation(BAR_TITLE_GAP)


#: Where the upright colour bars of `solution` sit (fractions of the window).
BAR = {"vertical": True, "position_x": 0.84, "position_y": 0.2, "width": 0.05, "height": 0.6,
       "title_font_size": 22, "label_font_size": 18, "fmt": "%.3g", "color": "black"}


def _legend(pl, entries):
    """A legend of ``entries`` ((label, colour) pairs, drawn as lines) at the upper left."""
    legend = pl.add_legend(labels=[[text, colour] for text, colour in entries],
                           bcolor="white", face="line", size=(0.7 / len(entries) ** 0.5,
                                                              0.035 * len(entries) ** 0.5),
                           loc="upper left")
    use_font(legend.GetEntryTextProperty())


#: The picture formats VTK writes.
PICTURE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff")


def _save(pl, path, what):
    """Write a PNG if ``path`` is given; return the plotter."""
    if path is not None:
        path = pathlib.Path(path)
        if path.suffix.lower() not in PICTURE_SUFFIXES:
            pl.close()
            raise PlotInputError(f"path: expected a picture file ending in one of "
                                 f"{', '.join(PICTURE_SUFFIXES)}, received {str(path)!r}; "
                                 f"e.g. {path.with_suffix('.png').name!r}")
        path.parent.mkdir(parents=True, exist_ok=True)
        try:
            pl.screenshot(str(path))
        except Exception as exc:  # pragma: no cover - depends on the environment
            pl.close()
            raise PlotDependencyError(f"pyvista could not render {str(path)!r} off-screen "
                                      f"({exc}); {INSTALL_HINT}, with a VTK that renders "
                                      f"off-screen") from exc
        log.info("cnem.plot.%s: wrote %s", what, path)
    return pl


#: Fields `solution` can colour by.
SOLUTION_FIELDS = ("von_mises", "sxx", "syy", "sxy", "exx", "eyy", "gxy", "ux", "uy", "|u|")


def _per_place(sol, name):
    """The field ``name`` (a stress or strain name of `SOLUTION_FIELDS`) at the places
    of ``sol.stress``."""
    shear = sol.stress.shape[1] - 1                     # the xy entry of the Voigt order
    return {"von_mises": sol.von_mises, "sxx": sol.stress[:, 0], "syy": sol.stress[:, 1],
            "sxy": sol.stress[:, shear], "exx": sol.strain[:, 0], "eyy": sol.strain[:, 1],
            "gxy": sol.strain[:, shear]}[name]


#: How `solution` names its fields on the colour bar (stresses in the unit of E): the symbols
#: in matplotlib's mathtext, as the matplotlib pictures write them (VTK draws ``$...$``
#: through matplotlib, so the pyvista pictures show the same symbols).
FIELD_LABELS = {"von_mises": r"$\sigma_\mathrm{vM}$", "sxx": r"$\sigma_{xx}$",
                "syy": r"$\sigma_{yy}$", "sxy": r"$\sigma_{xy}$", "exx": r"$\varepsilon_{xx}$",
                "eyy": r"$\varepsilon_{yy}$", "gxy": r"$\gamma_{xy}$", "ux": "$u_x$",
                "uy": "$u_y$", "|u|": "$|u|$"}


def nodal_field(sol, field):
    """A solution field at the nodes: displacements as they are, the fields at the
    places of ``sol.stress`` (cells, triangles or points) through
    ``sol.nodal_average`` (a C-NEM node takes its cell's value, area-weighted over
    the cells of a node on an interface).

    Parameters
    ----------
    sol : cnem.solvers.solution.Solution
    field : str or ndarray
        One of `SOLUTION_FIELDS`, or values ``(n,)`` at the nodes or ``(k,)`` at the
        places of ``sol.stress``.

    Returns
    -------
    (n,) ndarray
    """
    n, k = len(sol.u), len(sol.stress)
    if not isinstance(field, str):
        values = _field_values(field)
        if values.shape == (n,):
            return values
        if values.shape != (k,):
            raise PlotInputError(f"field: expected a name in {SOLUTION_FIELDS}, or values at "
                                 f"the {n} nodes or the {k} {sol.stress_places}, received shape "
                                 f"{values.shape}; pass {n} or {k} values")
        per_place = values
    elif field not in SOLUTION_FIELDS:
        raise PlotInputError(f"field must be one of {SOLUTION_FIELDS} or an array of values, "
                             f"received {field!r}; pick one of those names")
    elif field in ("ux", "uy", "|u|"):
        return {"ux": sol.u[:, 0], "uy": sol.u[:, 1], "|u|": np.linalg.norm(sol.u, axis=1)}[field]
    else:
        per_place = _per_place(sol, field)
    return sol.nodal_average(per_place)


def solution(sol: Any, path: str | os.PathLike | None = None, *,
             field: str | np.ndarray = "von_mises",
             scale: float | None = None, window_size: tuple[int, int] = (1200, 1000),
             show_edges: bool = False, cmap: str = "viridis",
             title: str | None = None, cellwise: bool = True,
             length_unit: str | None = None,
             bounds: tuple[float, float, float, float] | None = None) -> pyvista.Plotter:
    r"""The body coloured by a field, its deformed and undeformed outlines and a scale
    bar (off-screen).

    The solution's triangles (``sol.plot_mesh()``: C-NEM's constrained Delaunay
    triangles, the P1 mesh) are moved by ``scale * u`` (crack faces have their
    own nodes, so cracks open) and coloured by the field at the nodes
    (`nodal_field`), interpolated across the triangles, with the undeformed
    boundary, interfaces and cracks drawn over them as thin black lines; a solution
    without triangles (peridynamics) is drawn as its moved points. A field with one
    value per integration cell (C-NEM stresses and strains) is drawn instead, with
    ``cellwise``, on the cell polygons of the undeformed body, so that its jumps
    across material interfaces and crack faces stay sharp; the deformed boundary,
    interfaces and cracks are drawn over it as grey lines. A legend says which is
    which and the magnification; the colour bar stands on the right.

    Parameters
    ----------
    sol : cnem.solvers.solution.Solution
        An `ElasticSolution`, `cnem.fem.P1Solution` or a `cnem.pd` solution.
    path : str or os.PathLike, optional
        Write a PNG there.
    field : str or ndarray
        One of `SOLUTION_FIELDS`, or values ``(n,)`` at the nodes or ``(m,)``
        on the cells.
    scale : float, optional
        Displacement magnification; default so the largest displacement is
        5 % of the domain's diameter.
    window_size : (2,) int
    show_edges : bool
        Draw the triangle edges.
    cmap : str
        Matplotlib colour map name.
    title : str, optional
        Colour-bar title, with its unit; symbols in matplotlib's mathtext, e.g.
        ``r"$\sigma_{\theta\theta}$ (MPa)"`` (default the field's symbol, `FIELD_LABELS`).
    cellwise : bool
        Draw a field given per cell on the cells (default); False averages it to
        the nodes (`nodal_field`) and draws it on the deformed triangles.
    length_unit : str, optional
        The unit of the coordinates, written on the scale bar (e.g. ``"mm"``).
    bounds : (4,) float, optional
        ``(xmin, ymin, xmax, ymax)`` to show (a zoom, in the order of
        ``Domain.bounds``, as `model`); default the whole body, deformed and
        undeformed.

    Returns
    -------
    pyvista.Plotter
    """
    pv = _pyvista()
    zoom = None if bounds is None else view_bounds(bounds)
    per_cell = _cell_values(sol, field) if cellwise else None
    name = field if isinstance(field, str) else "field"
    label = title or FIELD_LABELS.get(name, name)
    model = getattr(sol, "model", None)
    if per_cell is not None:
        nodes, triangles, diameter = model.nodes, None, model.domain.diameter
    else:
        nodes, triangles, diameter = sol.plot_mesh()
    width, height = window_pixels(window_size)
    umax = float(np.abs(sol.u).max())
    if scale is None:
        scale = 0.05 * diameter / umax if umax > 0 else 0.0
    elif not (np.ndim(scale) == 0 and np.isfinite(scale)):
        raise PlotInputError(f"scale: expected a finite number (the displacement magnification), "
                             f"received {scale!r}; give e.g. 10.0, or None for 5 % of the body")
    moved = nodes + scale * sol.u
    pl = _plotter(pv, width, height)
    if per_cell is not None:
        mesh = cells_polydata(model)
        mesh.cell_data[name] = per_cell
    elif triangles is None:
        mesh = pv.PolyData(moved if moved.shape[1] == 3 else _lift(moved, 0.0))
        mesh.point_data[name] = nodal_field(sol, field)
    else:
        faces = np.column_stack([np.full(len(triangles), 3), triangles]).ravel()
        mesh = pv.PolyData(_lift(moved[:, :2], 0.0), faces=faces)
        mesh.point_data[name] = nodal_field(sol, field)
    points_only = ({"point_size": 8, "render_points_as_spheres": True}
                   if triangles is None and per_cell is None else {})
    pl.add_mesh(mesh, scalars=name, cmap=cmap, lighting=False, show_edges=show_edges,
                edge_color=(0.4, 0.4, 0.4), scalar_bar_args=dict(BAR, title=label),
                **points_only)
    colour_bar_font(pl.scalar_bar)
    lift = 1e-3 * diameter
    entries = []
    if model is not None and len(model.nodes) == len(nodes):
        segments = np.asarray(model.segments)
        grey = (0.35, 0.35, 0.35)
        if per_cell is not None:
            pl.add_mesh(_lines(pv, moved, segments, lift), color=grey,
                        line_width=max(1.5, 1.5 * width / 1200), lighting=False)
            outline = f"deformed outline ×{scale:.3g}" if scale else "outline (undeformed)"
            entries = [(f"{outline}; colours on the undeformed cells", grey)]
        else:
            pl.add_mesh(_lines(pv, model.nodes, segments, lift), color="black",
                        line_width=max(1.0, width / 1200), lighting=False)
            body = f"the body deformed ×{scale:.3g}" if scale else "the undeformed body"
            entries = [(f"undeformed outline; colours on {body}", "black")]
    else:
        entries = [(f"points moved ×{scale:.3g}" if scale else "points (undeformed)", "black")]
    _legend(pl, entries)
    lo = np.minimum(nodes[:, :2].min(axis=0), moved[:, :2].min(axis=0))
    hi = np.maximum(nodes[:, :2].max(axis=0), moved[:, :2].max(axis=0))
    pad = 0.06 * (hi - lo).max()
    view = (lo[0] - pad, lo[1] - 2.5 * pad, hi[0] + pad, hi[1] + 2.5 * pad)
    if zoom is not None:
        pad = 0.06 * (zoom[3] - zoom[1])
        view = (zoom[0], zoom[1] - 2.5 * pad, zoom[2], zoom[3] + 2.5 * pad)
    _top_view(pl, view, width, height, diameter, right=0.2)
    _scale_bar(pl, pv, view, length_unit, 2 * lift)
    return _save(pl, path, "solution")


def _field_values(field):
    """The values of a field given as numbers (at the nodes or the cells), refused when
    complex or boolean; NaN is drawn in the colour map's NaN colour."""
    return check_array("field", field, finite=False, error=PlotInputError,
                       fix="pass real values, one per node or per cell, or a field name")


def _cell_values(sol, field):
    """``field`` as one value per integration cell of a C-NEM solution, or None (a
    displacement, another kind of solution, or values at the nodes)."""
    cells = getattr(sol, "cells", None)
    model = getattr(sol, "model", None)
    if getattr(sol, "stress_places", None) != "cells" or cells is None or model is None \
            or len(sol.stress) != len(model.cells):
        return None
    if isinstance(field, str):
        if field in ("ux", "uy", "|u|") or field not in SOLUTION_FIELDS:
            return None
        return _per_place(sol, field)
    values = _field_values(field)
    return values if values.shape == (len(model.cells),) and len(sol.u) != len(values) else None
