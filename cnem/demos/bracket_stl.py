"""A steel bracket read from an STL file: bolted at its hole, loaded at the end of its arm.

The problem
-----------
An L-shaped plate 60 x 40 mm, 10 mm thick (a foot ``[0, 60] x [0, 20]`` and an arm
``[0, 20] x [20, 40]`` in the x-y plane, extruded along z), with a bolt hole of
diameter 12 mm centred at (42, 10) in the foot. The surface is made with trimesh
(``extrude_polygon`` of a shapely polygon, the hole a 32-gon), written to
``bracket.stl`` in the output folder and read back with `cnem.Domain3D.from_file`,
as a user's CAD file would be. Steel, E = 210 GPa, nu = 0.3, in mm and N (stresses
in MPa). The hole's face is clamped (the bolt), and the arm's end face y = 40 carries
a shear traction of 5 MPa along +x (1000 N in all): the arm bends about the
re-entrant edge at (20, 20), the foot twists about the bolt.

The same irregular cloud (`cnem.nodes.irregular`, spacing ``h``) is solved by

* C-NEM + SCNI (`cnem.Elasticity` on `cnem.discretize`: constrained Voronoi cells,
  Laplace shape functions, the sub-cell stabilisation);
* P1 tetrahedra on the model's own tetrahedrisation (`cnem.fem.P1Elasticity.from_model`);
* a reference: scikit-fem P2 tetrahedra on that tetrahedrisation (``--refine k``: refined
  k times; the same faceted body, so the three differ by their discretisation only).

Expected result
---------------
* The tip displacement (the x-displacement at the centre of the arm's end face, about
  24 um) of C-NEM is closer to the P2 reference than P1's on the same nodes (P1
  tetrahedra are too stiff in bending; at h = 4 mm C-NEM is 6.6 % above P2 on the same
  tetrahedra, 5.6 % above P2 on them refined once, P1 11-12 % below).
* The von Mises stress is raised along the re-entrant edge and round the bolt hole; it
  peaks on the hole's rim, where the clamped face meets the free faces (a singular
  corner of the boundary conditions: its maximum grows as h shrinks).
* Files in ``outdir``: ``bracket.stl``, ``bracket.vtu`` (displacements and stresses
  for ParaView) and ``bracket_von_mises.png`` (the body cut at mid-thickness, von
  Mises stress in MPa on the deformed cells).
"""

from __future__ import annotations

import pathlib
import time
from typing import TYPE_CHECKING

import numpy as np

import cnem
from cnem.cli import demo_parser

if TYPE_CHECKING:
    from typing import Sequence

    from cnem.geometry.model3d import Model3D

__all__ = ["main", "cli", "bracket_stl", "p2_reference"]

E, NU = 210e3, 0.3                       # MPa
THICKNESS, HOLE_CENTRE, HOLE_RADIUS = 10.0, (42.0, 10.0), 6.0
TRACTION = (5.0, 0.0, 0.0)               # MPa on the arm's end face y = 40
TIP = (10.0, 40.0, 5.0)                  # the centre of the arm's end face

#: How long the demo runs at its defaults (its --help says it; see cnem.cli.demo_parser).
RUN_TIME = "about 15 s"


def bracket_stl(path: pathlib.Path) -> pathlib.Path:
    """Write the bracket's surface to an STL file with trimesh; returns its path."""
    import shapely
    import trimesh

    foot_and_arm = shapely.Polygon([(0, 0), (60, 0), (60, 20), (20, 20), (20, 40), (0, 40)])
    hole = shapely.Point(*HOLE_CENTRE).buffer(HOLE_RADIUS, quad_segs=8)
    trimesh.creation.extrude_polygon(foot_and_arm.difference(hole), THICKNESS).export(path)
    return path


def _on_hole(x, size):
    return np.hypot(x[:, 0] - HOLE_CENTRE[0], x[:, 1] - HOLE_CENTRE[1]) <= HOLE_RADIUS + 1e-9 * size


def _conditions(prob, size):
    """The bolt's face clamped, the traction on the arm's end face."""
    prob.add_dirichlet(lambda x: _on_hole(x, size), None, 0.0)
    prob.add_traction(lambda x, n: (x[:, 1] > 40.0 - 1e-9 * size) & (n[:, 1] > 0.5), TRACTION)


def p2_reference(model: Model3D, refine: int = 0) -> float:
    """The tip x-displacement of scikit-fem P2 tetrahedra on the model's tetrahedra
    (refined ``refine`` times: the same faceted body)."""
    from skfem import Basis, ElementTetP2, ElementVector, FacetBasis, LinearForm, MeshTet, \
        asm, condense, solve
    from skfem.models.elasticity import lame_parameters, linear_elasticity

    size = float(np.linalg.norm(np.ptp(model.nodes, axis=0)))
    mesh = MeshTet(model.nodes.T.copy(), model.tetrahedra.T.copy()).refined(refine)
    element = ElementVector(ElementTetP2())
    basis = Basis(mesh, element)
    stiffness = asm(linear_elasticity(*lame_parameters(E, NU)), basis)
    end = mesh.facets_satisfying(lambda x: x[1] > 40.0 - 1e-9 * size, boundaries_only=True)

    @LinearForm
    def traction(v, w):
        return sum(TRACTION[i] * v.value[i] for i in range(3))

    load = asm(traction, FacetBasis(mesh, element, facets=end))
    clamped = basis.get_dofs(lambda x: _on_hole(x.T, size)).all()
    u = solve(*condense(stiffness, load, D=clamped))
    return float((basis.probes(np.array(TIP)[:, None]) @ u)[0])


def main(h: float = 4.0, *, reference: bool = True, refine: int = 0,
         outdir: str = "results/bracket_stl", plot: bool = True) -> dict:
    """Write the STL, read it back, solve by C-NEM and by P1 on the same nodes (and P2
    on a refined mesh), print the numbers, write the VTU and the picture.

    Parameters
    ----------
    h : float
        Node spacing (mm).
    reference : bool
        Also solve the scikit-fem P2 reference.
    refine : int
        Refinements of the model's tetrahedra for the P2 reference (each one costs about
        ten times more: 0 takes seconds, 1 minutes).

    Returns
    -------
    dict
        ``nodes``, ``times`` (s per stage), ``tip`` (x-displacement at the end face's
        centre, mm: ``cnem``, ``p1``, ``p2``), ``max_von_mises`` (MPa: ``cnem``,
        ``p1``), ``files``.
    """
    out = pathlib.Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    times = {}
    t0 = time.perf_counter()
    stl = bracket_stl(out / "bracket.stl")
    dom = cnem.Domain3D.from_file(stl)
    cloud = cnem.nodes.irregular(dom, h)
    times["cloud"] = time.perf_counter() - t0
    model = cnem.discretize(cloud)
    times.update(model.timings)
    size = float(np.linalg.norm(np.ptp(model.nodes, axis=0)))
    t0 = time.perf_counter()
    prob = cnem.Elasticity(model, (E, NU))
    _conditions(prob, size)
    sol = prob.solve(progress=False)
    times["C-NEM solve"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    p1 = cnem.fem.P1Elasticity.from_model(model, (E, NU))
    _conditions(p1, size)
    p1_sol = p1.solve()
    times["P1 solve"] = time.perf_counter() - t0
    tip = {"cnem": float(sol.displacement(np.array([TIP]))[0, 0]),
           "p1": float(p1_sol.displacement(np.array([TIP]))[0, 0]), "p2": None}
    if reference:
        t0 = time.perf_counter()
        tip["p2"] = p2_reference(model, refine)
        times["P2 reference"] = time.perf_counter() - t0
    von_mises = {"cnem": float(sol.von_mises.max()), "p1": float(p1_sol.von_mises.max())}
    print(f"bracket from {stl.name}: {dom.volume:.6g} mm^3, h = {h:g} mm, {len(model.nodes)} "
          f"nodes, {len(model.tetrahedra)} tetrahedra")
    print("stage times: " + ", ".join(f"{k} {v:.1f} s" for k, v in times.items()))
    print(f"{'':>8} {'tip u_x (um)':>13} {'vs P2':>8} {'max von Mises (MPa)':>20}")
    for key, name in (("cnem", "C-NEM"), ("p1", "P1"), ("p2", "P2 ref")):
        if tip[key] is None:
            print(f"{name:>8} {'-':>13}   (no reference: run with the reference on)")
            continue
        rel = f"{tip[key] / tip['p2'] - 1:+8.2%}" if tip["p2"] else f"{'-':>8}"
        vm = f"{von_mises[key]:>20.1f}" if key in von_mises else f"{'-':>20}"
        print(f"{name:>8} {1e3 * tip[key]:>13.3f} {rel} {vm}")
    files = [str(stl)]
    path = out / "bracket.vtu"
    sol.write(path)
    files.append(str(path))
    if plot:
        path = out / "bracket_von_mises.png"
        cnem.plot.solution3d(sol, path, clip="z", title=r"von Mises stress (MPa)",
                             length_unit="mm")
        files.append(str(path))
    for f in files:
        print(f"wrote {f}")
    return dict(nodes=len(model.nodes), times=times, tip=tip, max_von_mises=von_mises,
                files=files)


def cli(argv: Sequence[str] | None = None, prog: str | None = None) -> None:
    """Command line: ``python demos/bracket_stl.py --help`` or ``cnem demo bracket-stl``."""
    parser = demo_parser(__file__, __doc__, prog, run_time=RUN_TIME)
    parser.add_argument("--h", type=float, default=4.0, help="node spacing (mm)")
    parser.add_argument("--no-reference", action="store_true",
                        help="skip the scikit-fem P2 reference")
    parser.add_argument("--refine", type=int, default=0,
                        help="refinements of the tetrahedra for the P2 reference")
    args = parser.parse_args(argv)
    return main(args.h, reference=not args.no_reference, refine=args.refine, outdir=args.out,
                plot=not args.no_plot)


if __name__ == "__main__":
    cli()
