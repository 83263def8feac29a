"""Two edge cracks growing past two holes (a standard XFEM crack-growth benchmark).

The problem
-----------
A 20 x 10 mm plate with two holes of radius 2 mm centred at (3, 7) and (17, 3),
and two 1 mm horizontal edge cracks: from the left edge at y = 2.85 and from
the right edge at y = 7.15. E = 2e5 MPa, nu = 0.3, plane strain; the bottom
edge held vertically (u_y = 0, and u_x = 0 at its left corner), the top edge
pulled up by u_y = 0.1 mm. Maximum hoop stress, increments of 1 mm, 12 steps,
an irregular cloud (`cnem.nodes.irregular`, spacing ``h``), the default
`cnem.fracture.sif` radius.

Each crack is drawn towards the hole ahead of it. A published XFEM solution
ends the left crack near (11.64, 3.70) and the right crack near (8.35, 6.27)
(the published points are given only to compare with; a tip that reaches a
hole stops there and is recorded as an event).

Expected result
---------------
* Both paths curve towards the hole ahead of them; the table gives the tip
  positions at every step and the distance of the last ones to the published
  points.
* ``two_holes_paths.png``: the paths over the von Mises field;
  ``two_holes_sif.png``: K_I, K_II against crack length.
"""

from __future__ import annotations

import pathlib
from typing import TYPE_CHECKING

import numpy as np

import cnem
from cnem.cli import demo_parser
from cnem.geometry import arc

if TYPE_CHECKING:
    from typing import Sequence

__all__ = ["main", "cli"]

L, B, R = 20.0, 10.0, 2.0
HOLES = ((3.0, 7.0), (17.0, 3.0))
E, NU, PULL = 2e5, 0.3, 0.1
#: published end points (left crack, right crack)
PUBLISHED = np.array([[11.64, 3.70], [8.35, 6.27]])


def domain(h):
    shell = [[0.0, 0.0], [L, 0.0], [L, B], [0.0, B]]
    holes = [arc(c, R, 0.0, 2 * np.pi, h)[:-1][::-1] for c in HOLES]
    cracks = [[[0.0, 2.85], [1.0, 2.85]], [[L, 7.15], [L - 1.0, 7.15]]]
    return cnem.Domain([(shell, holes)], cracks=cracks)


def setup(model):
    tol = 1e-9 * L
    prob = cnem.Elasticity(model, (E, NU), plane="strain")
    prob.add_dirichlet(lambda p: np.abs(p[:, 1]) < tol, 1)
    prob.add_dirichlet(lambda p: np.hypot(*p.T) < tol, 0)
    prob.add_dirichlet(lambda p: np.abs(p[:, 1] - B) < tol, 1, PULL)
    return prob


def run(h=0.25, increment=1.0, steps=12, progress=True):
    dom = domain(h)
    return cnem.fracture.grow(dom, h, setup, increment=increment, steps=steps, progress=progress)


def main(h: float = 0.25, *, increment: float = 1.0, steps: int = 12,
         outdir: str = "results/growth_two_holes", plot: bool = True,
         progress: bool = True) -> dict:
    """Grow both cracks; print the tips at every step.

    Returns
    -------
    dict
        ``tips (steps + 1, 2, 2)`` (tip 0 the left crack), ``final (2, 2)``,
        ``distance (2,)`` to the published end points, ``events``, ``files``.
    """
    out = pathlib.Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    hist = run(h, increment, steps, progress)
    tips = hist.paths()
    left = int(np.argmin(tips[0, :, 0]))
    order = [left, 1 - left]
    tips = tips[:, order]
    angles = np.degrees(hist.array("angle"))[:, order]
    print(f"{'step':>4} | {'left x':>7} {'left y':>7} {'kink':>7} | {'right x':>7} {'right y':>7} "
          f"{'kink':>7}")
    for k in range(len(tips)):
        print(f"{k:>4d} | {tips[k, 0, 0]:>7.3f} {tips[k, 0, 1]:>7.3f} {angles[k, 0]:>7.2f} | "
              f"{tips[k, 1, 0]:>7.3f} {tips[k, 1, 1]:>7.3f} {angles[k, 1]:>7.2f}")
    distance = np.hypot(*(tips[-1] - PUBLISHED).T)
    print(f"published ends: left {PUBLISHED[0].tolist()}, right {PUBLISHED[1].tolist()}; distance of "
          f"ours: left {distance[0]:.3f} mm, right {distance[1]:.3f} mm")
    for e in hist.events:
        print(e)
    files = []
    if plot:
        fig = hist.plot(None, kind="paths", length_unit="mm", stress_unit="MPa",
                        title=f"Two holes, two edge cracks: {len(hist.steps)} increments of "
                              f"{increment:g} mm, h = {h:g} mm")
        fig.axes[0].plot(*PUBLISHED.T, "X", ms=10, color="tab:orange", mec="black",
                         label="published XFEM end points")
        fig.axes[0].legend(loc="upper center", fontsize=8, framealpha=0.9)
        fig.savefig(out / "two_holes_paths.png", dpi=130)
        hist.plot(out / "two_holes_sif.png", kind="sif", length_unit="mm", sif_unit="MPa sqrt(mm)")
        files = [out / "two_holes_paths.png", out / "two_holes_sif.png"]
    return dict(tips=tips, final=tips[-1], distance=distance, events=[str(e) for e in hist.events],
                files=[str(f) for f in files], history=hist)


def cli(argv: Sequence[str] | None = None, prog: str | None = None) -> None:
    """Command line: ``python -m cnem.demos.growth_two_holes --help`` or ``cnem demo growth-two-holes``."""
    parser = demo_parser(__file__, __doc__, prog)
    parser.add_argument("--h", type=float, default=0.25, help="node spacing (mm)")
    parser.add_argument("--increment", type=float, default=1.0, help="crack increment (mm)")
    parser.add_argument("--steps", type=int, default=12, help="growth increments")
    args = parser.parse_args(argv)
    return main(args.h, increment=args.increment, steps=args.steps, outdir=args.out, plot=not args.no_plot)


if __name__ == "__main__":
    cli()
