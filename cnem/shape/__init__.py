"""Shape functions: constrained natural-neighbour (Sibson, Laplace) coordinates in 2-D and 3-D.

>>> import numpy as np, cnem
>>> model = cnem.discretize(cnem.nodes.regular(cnem.geometry.rectangle(), 0.25))
>>> phi = model.shape_functions(np.array([[0.3, 0.6]]))
>>> bool(np.allclose(phi @ model.nodes, [[0.3, 0.6]]))
True
"""

from .natural import KINDS, shape_functions
from .natural3d import TetMesh, shape_functions_3d, tet_mesh

__all__ = ["shape_functions", "KINDS", "tet_mesh", "TetMesh", "shape_functions_3d"]
