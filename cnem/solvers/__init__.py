"""Solver layer: what every problem shares, whatever its method (C-NEM, P1, PD), its
dimension or its linearity — boundary conditions, the solution base, the one
constrained linear solve and the sparse solvers under it, the one Newton solver
(`newton`) and the one explicit time stepper (`velocity_verlet`).

>>> import numpy as np, scipy.sparse as sp
>>> from cnem.solvers import solve_constrained
>>> K = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(5, 5)).tocsr()
>>> x = solve_constrained(K, np.zeros(5), [0, 4], [0.0, 4.0], points=None)
>>> x.round(12).tolist()
[0.0, 1.0, 2.0, 3.0, 4.0]
"""

from .conditions import Conditions, per_point, select_nodes, traction_at
from .constrained import check_supports, solve_constrained
from .linsolve import free_rigid_motions, rigid_modes, solve_spd
from .newton import newton
from .solution import Solution
from .stepping import Prescribed, velocity_verlet

__all__ = ["Conditions", "Solution", "select_nodes", "per_point", "traction_at",
           "solve_constrained", "check_supports", "solve_spd", "rigid_modes",
           "free_rigid_motions", "newton", "Prescribed", "velocity_verlet"]
