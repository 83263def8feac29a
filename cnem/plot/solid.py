"""3-D scenes with pyvista, off-screen: a 3-D C-NEM solution on its integration cells,
clipped by a plane so that the inside shows.

The cells are drawn as their facet triangles (`cnem.io.polyhedron_topology`), each
coloured by its cell's value (stresses are constant per cell) or by the displacement
interpolated at its vertices, on the deformed or undeformed body. The cells whose
centroids lie on the far side of the clipping plane are left out whole (a "crinkle"
clip), so the cut shows the cells as they are, not a plane through them.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import PlotInputError, check_array
from ..io import polyhedron_topology
from .fields import (BAR, _legend, _plotter, _pyvista, _save, colour_bar_font, use_font,
                     window_pixels)

if TYPE_CHECKING:
    import pyvista

__all__ = ["solution3d", "SOLID_FIELDS", "SOLID_LABELS"]

#: Fields `solution3d` can colour by: per cell (stress, strain) or at the vertices (u).
SOLID_FIELDS = ("von_mises", "sxx", "syy", "szz", "syz", "sxz", "sxy", "exx", "eyy", "ezz",
                "ux", "uy", "uz", "|u|")

#: The colour bar's symbol of each field (matplotlib mathtext, as in `cnem.plot.FIELD_LABELS`).
SOLID_LABELS = {"von_mises": r"$\sigma_\mathrm{vM}$", "sxx": r"$\sigma_{xx}$",
                "syy": r"$\sigma_{yy}$", "szz": r"$\sigma_{zz}$", "syz": r"$\sigma_{yz}$",
                "sxz": r"$\sigma_{xz}$", "sxy": r"$\sigma_{xy}$", "exx": r"$\varepsilon_{xx}$",
                "eyy": r"$\varepsilon_{yy}$", "ezz": r"$\varepsilon_{zz}$", "ux": "$u_x$",
                "uy": "$u_y$", "uz": "$u_z$", "|u|": "$|u|$"}

#: Clipping planes by name: the normal (the side kept is behind it).
_NORMALS = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0),
            "-x": (-1.0, 0.0, 0.0), "-y": (0.0, -1.0, 0.0), "-z": (0.0, 0.0, -1.0)}


def _values(sol, field):
    """``(values, on_cells)``: the field per cell (``(m,)``) or per vertex (``(q,)``)."""
    if field not in SOLID_FIELDS:
        raise PlotInputError(f"field must be one of {SOLID_FIELDS}, received {field!r}; "
                             f"pick one of those names")
    if field in ("ux", "uy", "uz", "|u|"):
        u = sol.vertex_displacement()
        return ({"ux": u[:, 0], "uy": u[:, 1], "uz": u[:, 2]}.get(field)
                if field != "|u|" else np.linalg.norm(u, axis=1)), False
    if field == "von_mises":
        return sol.von_mises, True
    names = ("xx", "yy", "zz", "yz", "xz", "xy")
    source = sol.stress if field[0] == "s" else sol.strain
    return source[:, names.index(field[1:])], True


def _plane(clip, origin, model):
    """The clipping plane's unit normal and origin (default the body's centre), or None."""
    if clip is None:
        return None
    fix = f"pass None, one of {tuple(_NORMALS)} or a normal (3,), e.g. clip='-y'"
    if isinstance(clip, str):
        if clip not in _NORMALS:
            raise PlotInputError(f"clip: expected None, one of {tuple(_NORMALS)} or a normal "
                                 f"(3,), received {clip!r}; e.g. clip='-y'")
        normal = np.array(_NORMALS[clip])
    else:
        normal = check_array("clip", clip, shape=(3,), error=PlotInputError, fix=fix)
        if not np.linalg.norm(normal):
            raise PlotInputError(f"clip: expected a normal (3,) of nonzero length, received "
                                 f"{clip!r}; {fix}")
    nodes = model.nodes
    centre = 0.5 * (nodes.min(axis=0) + nodes.max(axis=0)) if origin is None else \
        check_array("origin", origin, shape=(3,), error=PlotInputError,
                    fix="pass a point (x, y, z) of the clipping plane, or None for the centre")
    return normal / np.linalg.norm(normal), centre


#: The camera's direction without a clipping plane (x to the right, z up), added to the
#: plane's normal with one: the cut face is seen at an angle.
_OBLIQUE = np.array([1.0, -1.0, 0.8]) / np.linalg.norm([1.0, -1.0, 0.8])


def _camera(pl, plane, width, height):
    """Look at the body from the clipping plane's side, z up, zoomed out so that it
    stands left of the colour bar (which takes the right 20 % of the window)."""
    toward = _OBLIQUE if plane is None else 0.5 * plane[0] + _OBLIQUE
    up = (0.0, 0.0, 1.0) if abs(toward[2]) < 0.95 * np.linalg.norm(toward) else (0.0, 1.0, 0.0)
    pl.view_vector(toward, viewup=up)
    pl.reset_camera()
    cam = pl.camera
    cam.zoom(0.85)
    focal, position = np.array(cam.focal_point), np.array(cam.position)
    distance = np.linalg.norm(position - focal)
    right = np.cross(focal - position, np.array(cam.up))
    right /= np.linalg.norm(right)
    view_width = 2.0 * distance * np.tan(np.radians(cam.view_angle) / 2.0) * width / height
    shift = 0.1 * view_width / 0.85 * right              # the body's centre at 40 % of the width
    cam.focal_point, cam.position = focal + shift, position + shift
    pl.reset_camera_clipping_range()


def _cut_text(clip, plane):
    """How the legend names the clipping plane."""
    if plane is None:
        return ""
    if isinstance(clip, str):
        axis = clip[-1]
        return f", clipped at {axis} = {plane[1]['xyz'.index(axis)]:.4g}"
    return ", clipped by a plane"


def solution3d(sol: Any, path: str | os.PathLike | None = None, *,
               field: str = "von_mises", clip: str | tuple | None = "-y",
               origin: tuple | None = None, scale: float | None = None,
               window_size: tuple[int, int] = (1200, 900), cmap: str = "viridis",
               title: str | None = None, length_unit: str | None = None,
               show_edges: bool = True) -> pyvista.Plotter:
    r"""A 3-D C-NEM solution on its cells, clipped by a plane, off-screen.

    The kept cells are drawn on the body deformed by ``scale * u`` (the displacement
    interpolated at the cell vertices), coloured by ``field``; the undeformed body's
    boundary edges are drawn as thin black lines, the colour bar stands on the right
    and the axes at the lower left.

    Parameters
    ----------
    sol : ElasticSolution or HyperelasticSolution
        Of a 3-D model.
    path : str or os.PathLike, optional
        Write a PNG there.
    field : str
        One of `SOLID_FIELDS`.
    clip : str or (3,) array_like or None
        The cells whose centroid lies in front of the plane through ``origin`` with
        this normal are left out: ``"x"``, ``"y"``, ``"z"``, ``"-x"``, ``"-y"``,
        ``"-z"`` or a normal; None draws every cell. The camera looks at the cut
        from the normal's side (``"-y"``, the default: x to the right, z up).
    origin : (3,) array_like, optional
        A point of the plane; default the centre of the nodes' bounding box.
    scale : float, optional
        Displacement magnification; default so that the largest displacement is 5 %
        of the body's diameter; 0 draws the undeformed body.
    window_size : (2,) int
    cmap : str
    title : str, optional
        Colour-bar title with its unit, e.g. ``r"$\sigma_\mathrm{vM}$ (MPa)"``
        (default the field's symbol, `SOLID_LABELS`).
    length_unit : str, optional
        The unit of the coordinates, written on the axes' titles.
    show_edges : bool
        Draw the facet triangles' edges.

    Returns
    -------
    pyvista.Plotter
    """
    pv = _pyvista()
    model = sol.model
    if np.shape(model.nodes)[1] != 3 or not hasattr(model.cells, "facet_triangles"):
        raise PlotInputError(f"sol: expected the solution of a 3-D model, received one of "
                             f"{np.shape(model.nodes)[1]}-D nodes; use cnem.plot.solution")
    width, height = window_pixels(window_size)
    values, on_cells = _values(sol, field)
    plane = _plane(clip, origin, model)
    cells = model.cells
    points, triangles = polyhedron_topology(cells)
    diameter = float(np.linalg.norm(np.ptp(model.nodes, axis=0)))
    u = sol.vertex_displacement()
    umax = float(np.abs(u).max()) if len(u) else 0.0
    if scale is None:
        scale = 0.05 * diameter / umax if umax > 0 else 0.0
    elif not (np.ndim(scale) == 0 and np.isfinite(scale)):
        raise PlotInputError(f"scale: expected a finite number (the displacement magnification), "
                             f"received {scale!r}; give e.g. 10.0, or None for 5 % of the body")
    keep = np.ones(len(cells), dtype=bool)
    if plane is not None:
        keep = (cells.centroid() - plane[1]) @ plane[0] <= 0.0
    shown = keep[cells.facet_cell]
    faces = np.column_stack([np.full(shown.sum(), 3), triangles[shown]]).ravel()
    mesh = pv.PolyData(points + scale * u, faces=faces)
    name = "field"
    if on_cells:
        mesh.cell_data[name] = np.asarray(values)[cells.facet_cell[shown]]
    else:
        mesh.point_data[name] = values
    pl = _plotter(pv, width, height)
    pl.add_mesh(mesh, scalars=name, cmap=cmap, show_edges=show_edges, edge_color=(0.3, 0.3, 0.3),
                line_width=0.5, scalar_bar_args=dict(BAR, title=title or SOLID_LABELS[field]))
    colour_bar_font(pl.scalar_bar)
    outline = pv.PolyData(model.nodes, faces=np.column_stack(
        [np.full(len(model.boundary_faces), 3), model.boundary_faces]).ravel())
    pl.add_mesh(outline.extract_feature_edges(boundary_edges=True, feature_edges=True,
                                              manifold_edges=False, non_manifold_edges=False),
                color="black", line_width=max(1.5, 1.5 * width / 1200), lighting=False)
    _legend(pl, [(f"undeformed edges; cells deformed ×{scale:.3g}{_cut_text(clip, plane)}",
                  "black")])
    unit = f" ({length_unit})" if length_unit else ""
    axes = pl.add_axes(color="black", xlabel=f"x{unit}", ylabel=f"y{unit}", zlabel=f"z{unit}",
                       line_width=3, viewport=(0.0, 0.0, 0.22, 0.3))
    use_font(*(getattr(axes, f"Get{a}AxisCaptionActor2D")().GetCaptionTextProperty()
               for a in "XYZ"))
    _camera(pl, plane, width, height)
    return _save(pl, path, "solution3d")
