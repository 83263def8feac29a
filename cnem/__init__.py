"""cnem: the constrained natural element method (C-NEM) on 2-D node clouds.

>>> import cnem
>>> dom = cnem.geometry.rectangle(1.0, 1.0, cracks=[[[0.0, 0.5], [0.5, 0.5]]])
>>> model = cnem.discretize(cnem.nodes.regular(dom, 0.1))
>>> float(round(model.cells.area.sum(), 12))
1.0
"""

from . import (assembly, exact, fracture, geometry, hyperdual, io, models, nodes, plot, shape,
               spatial)
from .errors import (CNEMError, ConditionError, FormatError, FormError, FractureError, GeometryError, HyperDualError, InputError, LimitError, MaterialError, OptionError, PlotDependencyError, PlotError, PlotInputError, SolveError, SpatialError, UnsupportedError)  # noqa: E501
from .geometry import Domain, Model, NodeCloud, discretize
from .models import ElasticSolution, Elasticity

__version__ = "0.1.0"

__all__ = ["Domain", "NodeCloud", "Model", "discretize", "Elasticity", "ElasticSolution",
           "nodes", "geometry", "assembly", "models", "exact", "fracture", "io", "plot", "shape",
           "spatial", "hyperdual",
           "CNEMError", "InputError", "OptionError", "GeometryError", "MaterialError", "FormError",
           "ConditionError", "SpatialError", "FractureError", "FormatError", "HyperDualError",
           "LimitError", "UnsupportedError", "SolveError", "PlotError", "PlotDependencyError",
           "PlotInputError", "__version__"]
