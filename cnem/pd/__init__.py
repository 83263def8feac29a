"""Peridynamics on the shared spatial index: bodies, bond- and state-based materials,
continuum-kinematics-inspired PD (`CPD`, nonlinear, hyper-dual derivatives), static
(Newton, sparse tangent) and explicit dynamic solvers.

>>> import numpy as np, cnem.pd as pd
>>> h = 0.05
>>> g = np.arange(0, 1 + 1e-9, h)
>>> pts = np.array([(x, y) for x in g for y in g])
>>> body = pd.Body(pts, h * h, 3 * h)
>>> prob = pd.Problem(body, pd.StateBased(1.0, 0.3))
>>> prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None)
>>> prob.add_body_force([1.0, 0.0])
>>> sol = prob.solve()                 # (solve_static: the former name)
>>> bool(sol.u[:, 0].max() > 0)
True
"""

from .body import Body
from .cpd import CPD
from .materials import BondBased, StateBased
from .problem import Problem
from .solution import DynamicRun, Relaxation, StaticSolution

__all__ = ["Body", "BondBased", "StateBased", "CPD", "Problem", "StaticSolution", "DynamicRun",
           "Relaxation"]
