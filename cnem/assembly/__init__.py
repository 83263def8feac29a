"""Variational layer: SCNI smoothed gradients, a cell basis and scikit-fem style forms.

>>> import numpy as np, cnem
>>> from cnem.assembly import BilinearForm, LinearForm, CellBasis, solve, condense
>>> from skfem.helpers import dot, grad
>>> model = cnem.discretize(cnem.nodes.irregular(cnem.geometry.rectangle(), 0.1, seed=0))
>>> basis = CellBasis(model)
>>> A = BilinearForm(lambda u, v, w: dot(grad(u), grad(v))).assemble(basis)
>>> b = LinearForm(lambda v, w: 0.0 * v).assemble(basis)
>>> x = model.nodes[:, 0] + 2 * model.nodes[:, 1]          # linear: reproduced exactly
>>> boundary = basis.get_dofs(lambda p: (np.abs(p - 0.5) > 0.5 - 1e-12).any(axis=1))
>>> u = solve(*condense(A, b, x=x, D=boundary))
>>> bool(np.allclose(u, x))
True
"""

from skfem import condense, solve

from .._aliases import renamed_attributes

from .basis import CellBasis
from ..solvers.conditions import select_nodes
from .forms import BilinearForm, Functional, LinearForm, asm
from .edges import cell_edges
from .gradients import SmoothedGradient, GradientCache, fan_gradient, smoothed_gradient
from .scalar_error import h1_error

__all__ = ["CellBasis", "BilinearForm", "LinearForm", "Functional", "asm", "condense", "solve",
           "SmoothedGradient", "GradientCache", "smoothed_gradient", "fan_gradient",
           "cell_edges", "select_nodes", "h1_error"]

#: Old names (one release): see `cnem._aliases`.
__getattr__ = renamed_attributes(
    __name__, {"SmoothedGradients": ("cnem.assembly.gradients", "GradientCache")})
