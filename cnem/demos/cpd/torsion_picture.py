"""The picture of the torsion example of `cnem.demos.cnem_vs_cpd`: the twisted C-NEM and
CPD columns and their difference (pyvista, off-screen), and the torque and axial force
of every run against the twist (matplotlib)."""

from __future__ import annotations

import numpy as np

from .pictures import horizon_curves

__all__ = ["torsion_picture"]


def _columns(points, runs, cpd):
    """Three pyvista views side by side at the last twist: C-NEM and run ``cpd``
    coloured by ``|u|``, and ``|u_CPD - u_C-NEM|`` on C-NEM's deformed column, as an
    RGB image ``(h, w, 3)``."""
    import pyvista as pv
    grid = pv.PolyData(points).delaunay_3d()
    outline = grid.extract_feature_edges(boundary_edges=False, feature_angle=60)
    u_cnem, u_cpd = runs["C-NEM"].u[-1], runs[cpd].u[-1]
    top = max(np.linalg.norm(u_cnem, axis=1).max(), np.linalg.norm(u_cpd, axis=1).max())
    diff = np.linalg.norm(u_cpd - u_cnem, axis=1)
    size = "displacement magnitude"
    views = (("C-NEM", u_cnem, np.linalg.norm(u_cnem, axis=1), size, "viridis", top),
             (cpd.replace("h", " spacings") + " (same scale)", u_cpd,
              np.linalg.norm(u_cpd, axis=1), size + " ", "viridis", top),
             (f"difference, CPD {cpd[4:-1]} sp. - C-NEM", u_cnem, diff,
              "difference magnitude", "magma", diff.max()))
    pl = pv.Plotter(off_screen=True, shape=(1, 3), window_size=(1500, 640), border=False)
    pl.set_background("white")
    for k, (title, u, values, name, cmap, vmax) in enumerate(views):
        pl.subplot(0, k)
        body = grid.copy()
        body.points = points + u
        body.point_data[name] = values
        pl.add_mesh(body.extract_surface(algorithm="dataset_surface"), scalars=name,
                    cmap=cmap, clim=(0.0, vmax), show_edges=True, edge_color="grey", line_width=0.3,
                    scalar_bar_args=dict(title=f"{name.strip()} (length unit)", color="black",
                                         vertical=False, position_x=0.15, width=0.7))
        pl.add_mesh(outline, color="grey", line_width=1.0, opacity=0.6)
        pl.add_text(title, font_size=11, color="black")
        pl.camera_position = "iso"
        pl.camera.zoom(1.1)
    image = pl.screenshot(return_img=True)
    pl.close()
    return image


def torsion_picture(path: str, res: dict, cpd: str) -> str:
    """Write ``path``: the columns (`_columns`) over the torque and the axial force of
    every run against the twist, with Saint-Venant's linear torque.

    Parameters
    ----------
    path : str
    res : dict
        The torsion example of `cnem.demos.cnem_vs_cpd` (``points``, ``runs``,
        ``degrees``, ``torque``, ``axial``, ``saint_venant``).
    cpd : str
        The key of the CPD run drawn.

    Returns
    -------
    str
    """
    from cnem.plot.charts import offscreen_pyplot
    plt = offscreen_pyplot()
    image = _columns(res["points"], res["runs"], cpd)
    fig = plt.figure(figsize=(13, 10))
    grid = fig.add_gridspec(2, 2, height_ratios=[1.1, 1])
    ax = fig.add_subplot(grid[0, :])
    ax.imshow(image)
    ax.set_axis_off()
    ax.set_title(f"torsion of a 1 x 1 x 4 column at {res['degrees'][-1]:g} deg (grey: "
                 f"undeformed edges); left C-NEM, middle CPD, right their difference",
                 fontsize=10)
    for k, (key, label) in enumerate((("torque", "torque $T$ ($\\mu a^3$)"),
                                      ("axial", "axial force $N$ held by the grip ($\\mu a^2$)"))):
        ax = fig.add_subplot(grid[1, k])
        if key == "torque":
            ends = np.array([0.0, res["degrees"][-1]])
            ax.plot(ends, res["saint_venant"] * np.radians(ends), color="k", lw=1.0,
                    label="Saint-Venant, linear")
        horizon_curves(ax, res["degrees"], res[key], "twist $\\theta$ (degrees)", label)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path
