"""A square plate with an inclined internal crack: nodes, opened crack, constrained Voronoi cells.

The problem
-----------
The third example of the C-NEM paper (Yvonnet et al., IJNME 2004, §4.5, Figures
16-17): a square plate of side 2W = 2 mm centred at the origin, with a straight
internal crack of length 2a = 0.2 mm through the centre, inclined at an angle
gamma to the x axis (the paper loads it with sigma_22 = 1 MPa at infinity,
E = 1 MPa, nu = 0.3, plane stress — loads come with the elasticity layer).
The paper's cloud has 760 nodes: 400 uniform, 20 on each crack side and 320
concentrated around the two tips. Here: a uniform lattice of spacing ``h``
(400 nodes for h = 0.1, as in the paper), refined towards both tips down to
``h_min`` with `cnem.nodes.graded`, then `cnem.discretize`: constrained
Delaunay triangulation, crack opened by duplicating each crack node except the
tips, and the constrained Voronoi integration cells (paper eq. 13).

Expected result
---------------
* The cells partition the plate: their areas sum to 4 mm^2 to round-off
  (relative error ~1e-15).
* Every crack node but the two tips is split into one node per crack face,
  so ``n_nodes - n_points == n_crack_points - 2``; there is one cell per node.
* ``results/cracked_plate_geometry/cracked_plate_cells.png`` shows the cells (paper Figure 16b), the crack
  in red; ``results/cracked_plate_geometry/cracked_plate_tip.png`` zooms on a tip (paper Figure 17): the
  cells shrink towards the tip, and no cell reaches across the crack — the
  cells of the two copies of a crack node lie on opposite faces.
* ``results/cracked_plate_geometry/cracked_plate.vtu`` holds the cells and nodes for ParaView.

Run ``python demos/cracked_plate_geometry.py --help`` for the sizes.
"""

from __future__ import annotations

import pathlib
import time
from typing import TYPE_CHECKING

import numpy as np

import cnem
import cnem.io
import cnem.plot
from cnem.cli import demo_parser, positive_float, positive_int
from cnem.geometry import SegmentKind, rectangle
from .._sets import distinct

if TYPE_CHECKING:
    from typing import Sequence
    from ..geometry.cloud import NodeCloud
    from ..geometry.domain import Domain

__all__ = ["main", "cli", "build"]

#: Half side W and half crack length a of the paper (mm).
HALF_WIDTH, HALF_CRACK = 1.0, 0.1


#: How long the demo runs at its defaults (its --help says it; see cnem.cli.demo_parser).
RUN_TIME = "about 5 s"


def build(h: float = 0.1, h_min: float = 0.01, gamma_deg: float = 30.0,
          growth: float = 0.1) -> tuple[Domain, NodeCloud]:
    """The cracked plate and its graded node cloud.

    Returns
    -------
    domain : cnem.Domain
    cloud : cnem.NodeCloud
    """
    g = np.deg2rad(gamma_deg)
    d = HALF_CRACK * np.array([np.cos(g), np.sin(g)])
    dom = rectangle(2 * HALF_WIDTH, 2 * HALF_WIDTH, origin=(-HALF_WIDTH, -HALF_WIDTH),
                    cracks=[[-d, d]])
    cloud = cnem.nodes.graded(dom, h, near=dom.tips, h_min=h_min, growth=growth)
    return dom, cloud


def main(h: float = 0.1, h_min: float = 0.01, gamma_deg: float = 30.0, growth: float = 0.1,
         outdir: str = "results/cracked_plate_geometry", plot: bool = True,
         window_size: tuple[int, int] = (1200, 1200)) -> dict:
    """Build, discretise, write and draw the cracked plate.

    Parameters
    ----------
    h : float
        Node spacing away from the crack (mm).
    h_min : float
        Node spacing at the crack tips (mm).
    gamma_deg : float
        Crack angle to the x axis, in degrees.
    growth : float
        Grading rate of the spacing away from the tips.
    outdir : str or os.PathLike
        Folder for the VTU file and the pictures.
    plot : bool
        Draw the two pictures (needs pyvista).
    window_size : (2,) int
        Picture size in pixels.

    Returns
    -------
    dict
        ``n_points`` (cloud), ``n_nodes`` (after splitting), ``n_cells``,
        ``n_crack_points`` (cloud nodes on the crack, tips included),
        ``n_split`` (``n_nodes - n_points``), ``tips`` ``(2, 2)``,
        ``cell_area``, ``domain_area``, ``exact_area`` (4.0),
        ``area_error`` (relative), ``seconds`` and ``files``.
    """
    out = pathlib.Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    dom, cloud = build(h, h_min, gamma_deg, growth)
    model = cnem.discretize(cloud, progress=False)
    seconds = time.perf_counter() - t0

    crack_points = distinct(cloud.segments[cloud.segment_kind == SegmentKind.CRACK])
    exact_area = (2 * HALF_WIDTH) ** 2
    cell_area = float(model.cells.area.sum())
    files = {"vtu": cnem.io.write(model, out / "cracked_plate.vtu")}
    if plot:
        files["cells"] = out / "cracked_plate_cells.png"
        cnem.plot.model(model, files["cells"], window_size=window_size).close()
        tip = dom.tips[np.argmax(dom.tips[:, 0])]
        half = max(HALF_CRACK, 6 * h_min)      # a square of one crack length around the tip
        files["tip"] = out / "cracked_plate_tip.png"
        cnem.plot.model(model, files["tip"], window_size=window_size,
                        bounds=(tip[0] - half, tip[1] - half, tip[0] + half, tip[1] + half)
                        ).close()
    for path in files.values():
        print(f"wrote {path}")
    return {
        "n_points": len(cloud.points),
        "n_nodes": len(model.nodes),
        "n_cells": len(model.cells),
        "n_crack_points": len(crack_points),
        "n_split": len(model.nodes) - len(cloud.points),
        "tips": dom.tips.copy(),
        "cell_area": cell_area,
        "domain_area": float(dom.area),
        "exact_area": exact_area,
        "area_error": abs(cell_area - exact_area) / exact_area,
        "seconds": seconds,
        "files": files,
    }


def cli(argv: Sequence[str] | None = None, prog: str | None = None) -> None:
    """Command line: ``python demos/cracked_plate_geometry.py --help`` or
    ``cnem demo cracked-plate-geometry``."""
    parser = demo_parser(__file__, __doc__, prog, run_time=RUN_TIME)
    parser.add_argument("--h", type=positive_float, default=0.1, help="spacing away from the crack")
    parser.add_argument("--h-min", type=positive_float, default=0.01, help="spacing at the tips")
    parser.add_argument("--gamma", type=float, default=30.0, help="crack angle in degrees")
    parser.add_argument("--growth", type=positive_float, default=0.1, help="spacing grading rate")
    parser.add_argument("--size", type=positive_int, default=1200, help="picture size in pixels")
    args = parser.parse_args(argv)
    res = main(h=args.h, h_min=args.h_min, gamma_deg=args.gamma, growth=args.growth,
               outdir=args.out, plot=not args.no_plot, window_size=(args.size, args.size))
    print(f"cracked plate, gamma = {args.gamma:g} deg: {res['n_points']} cloud nodes -> "
          f"{res['n_nodes']} nodes ({res['n_split']} crack nodes split, "
          f"{res['n_crack_points']} on the crack incl. 2 tips), {res['n_cells']} cells "
          f"in {res['seconds']:.2f} s")
    print(f"sum of cell areas {res['cell_area']:.15g} vs plate area {res['exact_area']:g} "
          f"(relative error {res['area_error']:.1e})")
    return res


if __name__ == "__main__":
    cli()
