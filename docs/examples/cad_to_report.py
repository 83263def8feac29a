"""From a CAD file to a report: an aluminium lug drawn in a DXF file (docs/examples/bracket.dxf,
layers ``clamp``, ``edge``, ``pin``), clamped on its left edge and pulled down by a pin in its
hole; the model reads the drawing, takes its boundary conditions by layer name, and writes
a VTU file for ParaView and a CSV of the forces on each named boundary (units: mm, N, MPa;
plane stress, 10 mm thick)."""

import csv
import pathlib

import numpy as np

import cnem

THICKNESS = 10.0                                   # mm
PIN_LOAD = 2000.0                                  # N, downwards
PIN_CENTRE, PIN_RADIUS = np.array([60.0, 20.0]), 8.0

# the drawing: each layer of the outline is a named boundary
dom = cnem.Domain.from_file(pathlib.Path(__file__).with_name("bracket.dxf"))
print(dom)
print(f"named boundaries: {', '.join(dom.boundaries)}")

model = cnem.discretize(cnem.nodes.irregular(dom, h=1.5, seed=0))
print(model)

# aluminium; the clamp layer fixed; the pin bears on the lower half of the hole (where the
# body's outward normal points up, into the hole) with a uniform downward traction whose
# resultant is the pin's load: divided by the length of those edges of the hole
prob = cnem.Elasticity(model, (70000.0, 0.33), plane="stress")
prob.add_dirichlet("clamp", None)
_, edges, normal = prob.select_facets("pin", "the bearing")    # node pairs, outward normals
lower = model.nodes[edges[normal[:, 1] > 0]]                    # (e, 2, 2)
bearing = PIN_LOAD / THICKNESS / np.linalg.norm(lower[:, 1] - lower[:, 0], axis=1).sum()
prob.add_traction("pin", lambda x, n: np.where(n[:, 1:] > 0, [0.0, -bearing], 0.0))
print(f"bearing traction {bearing:.3f} MPa on the lower half of the hole")
sol = prob.solve()

vm = sol.von_mises
peak = model.cells.centroid()[np.argmax(vm)]
bottom_of_hole = PIN_CENTRE - [0.0, PIN_RADIUS]
sag = -sol.displacement(bottom_of_hole[None])[0, 1]
print(f"max von Mises {vm.max():.1f} MPa near ({peak[0]:.1f}, {peak[1]:.1f}) mm; "
      f"the bottom of the pin hole moves {sag * 1e3:.2f} um down")
# a hand check: beam theory's bending stress 6 M / (t H^2) at 20 mm from the clamp, where
# the moment is M = F (60 - 20) mm: tension on top, compression below
top_bottom = np.array([[20.0, 40.0], [20.0, 0.0]])
beam = 6 * PIN_LOAD * (PIN_CENTRE[0] - 20.0) / (THICKNESS * 40.0**2)
sxx = sol.stress_at(top_bottom)[:, 0]
print(f"sxx at x = 20 mm, top and bottom: {sxx[0]:+.2f}, {sxx[1]:+.2f} MPa; "
      f"beam theory +/-{beam:.2f} MPa")

# forces on the named boundaries, times the thickness: the load the pin puts on the body
# (the loads f on the pin's nodes) and the force the clamp exerts (K u - f on its nodes)
load = prob.load().reshape(-1, 2)[prob.named_nodes("pin")].sum(axis=0) * THICKNESS
reaction = sol.reaction("clamp") * THICKNESS
rows = [("pin", "load", *load), ("clamp", "reaction", *reaction),
        ("total", "sum", *(load + reaction))]
out = pathlib.Path("results/cad_to_report")
out.mkdir(parents=True, exist_ok=True)
with open(out / "forces.csv", "w", newline="") as f:
    writer = csv.writer(f)
    writer.writerow(["boundary", "kind", "force_x_N", "force_y_N"])
    for name, kind, *force in rows:             # to 1 mN (+ 0.0: no "-0.000")
        writer.writerow([name, kind, *(f"{round(value, 3) + 0.0:.3f}" for value in force)])
print(f"wrote {out / 'forces.csv'}:")
print((out / "forces.csv").read_text().strip())

# displacement (3 components), stress and strain tensors, von Mises: ParaView reads it as is
sol.write(out / "bracket.vtu")
print(f"wrote {out / 'bracket.vtu'}")
