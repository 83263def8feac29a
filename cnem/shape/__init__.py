"""Shape functions: constrained natural-neighbour (Sibson) coordinates.

>>> import numpy as np, cnem
>>> model = cnem.discretize(cnem.nodes.regular(cnem.geometry.rectangle(), 0.25))
>>> phi = model.shape_functions(np.array([[0.3, 0.6]]))
>>> bool(np.allclose(phi @ model.nodes, [[0.3, 0.6]]))
True
"""

from .natural import KINDS, shape_functions

__all__ = ["shape_functions", "KINDS"]
