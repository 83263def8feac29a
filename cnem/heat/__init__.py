"""Scalar physics on C-NEM models: steady heat conduction.

>>> import numpy as np, cnem
>>> model = cnem.discretize(cnem.nodes.regular(cnem.geometry.rectangle(), 0.2))
>>> prob = cnem.HeatConduction(model, 1.0)
>>> prob.add_temperature("left", 0.0)
>>> prob.add_flux("right", 2.0)                       # into the body: T = 2 x / k
>>> sol = prob.solve()
>>> bool(np.allclose(sol.T, 2.0 * model.nodes[:, 0]))
True
"""

from .problem import HeatConduction, conduction_form
from .solution import HeatSolution

__all__ = ["HeatConduction", "HeatSolution", "conduction_form"]
