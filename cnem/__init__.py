"""cnem: the constrained natural element method (C-NEM) on 2-D node clouds.

>>> import cnem
>>> dom = cnem.geometry.rectangle(1.0, 1.0, cracks=[[[0.0, 0.5], [0.5, 0.5]]])
>>> model = cnem.discretize(cnem.nodes.regular(dom, 0.1))
>>> float(round(model.cells.area.sum(), 12))
1.0

``import cnem`` loads nothing but this file and the error classes: each subpackage
(``cnem.pd``, ``cnem.fracture``, ...) and each workflow name (``cnem.Domain``, ...) is
imported on first use (PEP 562), so the command line starts at once and a script
pays only for what it uses.

The layers, lowest first (a module imports only from its own layer or lower ones;
``tests/test_architecture.py`` checks it, ``docs/architecture.md`` draws it):

========== ==============================================================================
core       ``errors``, ``config``, ``_compile``, ``_parallel``, ``_memory``, ``_predicates``,
           ``hyperdual``, ``material``, ``exact``, ``_aliases``
spatial    ``spatial``: packed R-tree (periodic), family search, bond crossing
shape      ``shape``: constrained natural-neighbour coordinates on a triangulation
geometry   ``geometry`` (``nodes`` is ``geometry.nodes``): domains, node clouds, ``discretize``
output     ``io``, ``plot``: VTU files and off-screen pictures
solvers    ``solvers``: conditions, solution base, the constrained linear solve, sparse solvers
assembly   ``assembly``: SCNI smoothed gradients, bases, forms
fracture   ``fracture``: Williams fields, SIFs, enrichment, crack growth
problems   ``elasticity`` (C-NEM), ``heat`` (heat conduction), ``fem`` (P1 anchor),
           ``pd`` (peridynamics)
front      ``cli``, ``__main__``, the demos
========== ==============================================================================
"""

from __future__ import annotations

import importlib

from .errors import (CNEMError, ConditionError, ConvergenceError, DivergenceError,
                     FormatError, FormError, FractureError, GeometryError, GrowthError,
                     GrowthWarning, HyperDualError, InputError,
                     LimitError, MaterialError, MissingExtraError, OptionError,
                     PlotDependencyError, PlotError, PlotInputError, SIFWarning, SolveError,
                     SpatialError, StabilityWarning, UnsupportedError)

from . import _aliases

_aliases.install()

__version__ = "0.1.0"

#: Submodules and subpackages reachable as attributes of ``cnem`` (loaded on first use).
_MODULES = frozenset({"assembly", "cli", "config", "elasticity", "errors", "exact", "fem",
                      "fracture", "geometry", "heat", "hyperdual", "io", "material", "nodes", "pd",
                      "plot", "shape", "solvers", "spatial"})

#: The core workflow names -> the module that defines them.
_NAMES = {"Domain": "geometry", "Domain3D": "geometry", "NodeCloud": "geometry",
          "Model": "geometry", "discretize": "geometry", "Elasticity": "elasticity",
          "ElasticSolution": "elasticity", "Hyperelasticity": "elasticity",
          "HeatConduction": "heat"}

__all__ = ["Domain", "Domain3D", "NodeCloud", "Model", "discretize", "Elasticity", "ElasticSolution",
           "Hyperelasticity", "HeatConduction",
           "nodes", "geometry", "assembly", "elasticity", "exact", "fracture", "io", "plot", "shape",
           "spatial", "hyperdual", "pd", "fem", "heat", "material",
           "CNEMError", "InputError", "OptionError", "GeometryError", "MaterialError", "FormError",
           "ConditionError", "SpatialError", "FractureError", "GrowthError", "FormatError",
           "HyperDualError", "GrowthWarning", "SIFWarning", "MissingExtraError",
           "LimitError", "UnsupportedError", "SolveError", "PlotError", "PlotDependencyError",
           "PlotInputError", "ConvergenceError", "DivergenceError", "StabilityWarning",
           "__version__"]


def __getattr__(name: str):
    if name in _MODULES:
        return importlib.import_module(f".{name}", __name__)
    if name in _NAMES:
        value = getattr(importlib.import_module(f".{_NAMES[name]}", __name__), name)
        globals()[name] = value
        return value
    moved = _aliases.moved_submodule(__name__, name)
    if moved is not None:
        return moved
    raise AttributeError(f"module 'cnem' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(__all__) | _MODULES)
