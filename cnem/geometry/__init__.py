"""Geometry layer: domains, node clouds, constrained Delaunay and Voronoi cells.

>>> import cnem
>>> from cnem.geometry import rectangle
>>> dom = rectangle(1.0, 1.0, cracks=[[[0.0, 0.5], [0.5, 0.5]]])
>>> model = cnem.discretize(cnem.nodes.regular(dom, 0.1))
>>> bool(abs(model.cells.area.sum() - dom.area) < 1e-12)
True
"""

from .._aliases import renamed_attributes
from .cloud import NodeCloud
from .domain import Domain
from .domain3d import Domain3D
from .model import Cells, Model, discretize
from .pslg import PSLG, SegmentKind
from .shapes import annulus, arc, l_shape, plate_with_hole, rectangle
from .shapes3d import box, cylinder, hollow_sphere, sphere

__all__ = ["Domain", "Domain3D", "NodeCloud", "Model", "Cells", "PSLG", "SegmentKind",
           "discretize", "rectangle", "plate_with_hole", "annulus", "l_shape", "arc",
           "box", "sphere", "hollow_sphere", "cylinder"]

#: Old names (one release): see `cnem._aliases`.
__getattr__ = renamed_attributes(__name__, {})
