"""A scalar field at the nodes of a model (a temperature), off-screen with pyvista."""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from ..errors import PlotInputError, check_array
from ..geometry.model import check_model
from .fields import (BAR, _legend, _lift, _lines, _plotter, _pyvista, _save, _scale_bar,
                     _top_view, colour_bar_font, view_bounds, window_pixels)

if TYPE_CHECKING:
    import pyvista

    from ..geometry.model import Model

__all__ = ["scalar_field"]


def scalar_field(model: Model, values: ArrayLike, path: str | os.PathLike | None = None, *,
                 title: str = "value", cmap: str = "coolwarm",
                 bounds: tuple[float, float, float, float] | None = None,
                 window_size: tuple[int, int] = (1200, 1000),
                 length_unit: str | None = None) -> pyvista.Plotter:
    r"""The model's triangles coloured by nodal values (interpolated across them), its
    boundary, interfaces and cracks as black lines, a colour bar and a scale bar.

    Parameters
    ----------
    model : Model
        ``n`` nodes.
    values : (n,) array_like
        One value per node (a temperature, say).
    path : str or os.PathLike, optional
        Write a PNG there.
    title : str
        Colour-bar title with its unit, e.g. ``"T (°C)"`` (matplotlib mathtext allowed).
    cmap : str
        Matplotlib colour map name.
    bounds : (4,) float, optional
        ``(xmin, ymin, xmax, ymax)`` to show (a zoom); default the whole domain.
    window_size : (2,) int
    length_unit : str, optional
        The unit of the coordinates, written on the scale bar.

    Returns
    -------
    pyvista.Plotter
        Off-screen; call ``.close()`` when done with it.
    """
    pv = _pyvista()
    mdl = check_model(model, "cnem.plot.scalar_field")
    n = len(mdl.nodes)
    vals = check_array("values", values, finite=False, error=PlotInputError,
                       fix="pass one real value per node")
    if vals.shape != (n,):
        raise PlotInputError(f"values: expected one value per node ({n},), received shape "
                             f"{vals.shape}; pass nodal values (e.g. sol.T)")
    view = view_bounds(mdl.domain.bounds if bounds is None else bounds)
    width, height = window_pixels(window_size)
    diameter = mdl.domain.diameter
    pl = _plotter(pv, width, height)
    triangles = np.asarray(mdl.triangles)
    faces = np.column_stack([np.full(len(triangles), 3), triangles]).ravel()
    mesh = pv.PolyData(_lift(np.asarray(mdl.nodes), 0.0), faces=faces)
    mesh.point_data[title] = vals
    pl.add_mesh(mesh, scalars=title, cmap=cmap, lighting=False,
                scalar_bar_args=dict(BAR, title=title))
    colour_bar_font(pl.scalar_bar)
    lift = 1e-3 * diameter
    pl.add_mesh(_lines(pv, mdl.nodes, np.asarray(mdl.segments), lift), color="black",
                line_width=max(1.0, width / 1200), lighting=False)
    _legend(pl, [("boundary, interfaces and cracks", "black")])
    pad = 0.06 * (view[3] - view[1])
    shown = (view[0], view[1] - 2.5 * pad, view[2], view[3] + 2.5 * pad)
    _top_view(pl, shown, width, height, diameter, right=0.2)
    _scale_bar(pl, pv, shown, length_unit, 2 * lift)
    return _save(pl, path, "scalar_field")
