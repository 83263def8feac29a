"""`P1Elasticity`: a linear finite element (scikit-fem P1 triangles) anchor for C-NEM.

The same problem definition as `cnem.Elasticity` (Dirichlet conditions on
nodes, tractions on boundary edges, body forces), solved on a quality mesh
of the domain made by `triangle`: every triangle lies in one region, material
interfaces are mesh edges and cracks are opened (their nodes duplicated, tips
excepted), so that crack faces are traction-free boundaries.

>>> import numpy as np, cnem, cnem.fem
>>> dom = cnem.geometry.rectangle(2.0, 1.0)
>>> prob = cnem.fem.P1Elasticity(dom, (1000.0, 0.3), nodes=200)
>>> prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, 0)
>>> prob.add_dirichlet(lambda p: (p[:, 0] < 1e-9) & (p[:, 1] < 1e-9), 1)
>>> prob.add_traction(lambda x, n: n[:, 0] > 0.5, [10.0, 0.0])
>>> sol = prob.solve()
>>> bool(np.allclose(sol.stress, [10.0, 0.0, 0.0]))           # uniform tension
True
>>> sol.energy_error(lambda x: np.tile([10.0, 0.0, 0.0], (len(x), 1))) < 1e-9
True
"""


from .mesh import mesh_domain
from .problem import P1Elasticity
from .solution import P1Solution

__all__ = ["P1Elasticity", "P1Solution", "mesh_domain"]
