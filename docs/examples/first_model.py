"""Your first model: an L-shaped steel plate with a hole, clamped on the left edge and
pulled down on its right end (units: mm, N, MPa; plane stress, unit thickness)."""

import pathlib

import numpy as np
import shapely

import cnem

# geometry: an L (2 x 2 mm without its top-right 1 x 1 mm corner) minus a hole of radius 0.25
L = shapely.Polygon([(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)])
hole = shapely.Point(0.5, 0.5).buffer(0.25, quad_segs=16)       # a 64-gon
dom = cnem.Domain(L.difference(hole))
print(f"area {dom.area:.6f} mm^2 = 3 - {3 - dom.area:.6f} (the 64-gon; pi r^2 = {np.pi * 0.25**2:.6f})")

# nodes about every 0.05 mm, then the C-NEM model
cloud = cnem.nodes.irregular(dom, h=0.05, seed=0)
model = cnem.discretize(cloud)
print(model)

# steel, plane stress; clamped at x = 0, a downward traction of 10 MPa on the end x = 2
prob = cnem.Elasticity(model, (210000.0, 0.3), plane="stress")
tol = 1e-9 * 2.0                                                # relative to the model's size
clamped = np.abs(model.nodes[:, 0]) < tol
prob.add_dirichlet(clamped, None)                                # u_x = u_y = 0
prob.add_traction(lambda x, n: np.abs(x[:, 0] - 2.0) < tol,      # edges on x = 2
                  lambda x, n: np.tile([0.0, -10.0], (len(x), 1)))  # t (q, 2) in MPa
sol = prob.solve()

# stresses: one [sxx, syy, sxy] per integration cell (MPa)
vm = cnem.elasticity.von_mises(sol.stress)
print(f"max von Mises {vm.max():.1f} MPa; largest deflection {-sol.u[:, 1].min() * 1e3:.3f} um down")

# the force the clamp exerts: K u - f summed over its nodes (N per mm of thickness)
reaction = sol.reaction(clamped)
print(f"reaction ({reaction[0]:+.4f}, {reaction[1]:+.4f}) N/mm balances the load (0, -10) N/mm")

# a file for ParaView and a picture
pathlib.Path("results/first_model").mkdir(parents=True, exist_ok=True)
sol.write("results/first_model/l_plate.vtu")
sol.plot("results/first_model/l_plate_von_mises.png", field="von_mises",
         title=r"$\sigma_\mathrm{vM}$ (MPa)", length_unit="mm").close()
