"""Physical models on C-NEM: linear elasticity, and finite-strain hyperelasticity
(`Hyperelasticity`).

>>> import cnem
>>> model = cnem.discretize(cnem.nodes.regular(cnem.geometry.rectangle(), 0.2))
>>> prob = cnem.Elasticity(model, (1.0, 0.3), plane="strain")
>>> prob.add_dirichlet(lambda p: p[:, 1] < 1e-12, None)
>>> prob.add_body_force([0.0, -1.0])
>>> sol = prob.solve(progress=False)
>>> bool(sol.u[:, 1].min() < 0)
True
"""

from .._aliases import renamed_attributes
from .linear import Elasticity, elasticity_form
from .hyperelasticity import Hyperelasticity
from .hyperelastic_solution import HyperelasticSolution
from ..material import lame, stiffness_matrix
from .solution import ElasticSolution, von_mises

__all__ = ["Elasticity", "ElasticSolution", "Hyperelasticity", "HyperelasticSolution",
           "elasticity_form", "lame", "stiffness_matrix",
           "von_mises"]

#: Old names (one release): the modules of ``cnem.elasticity`` as attributes
#: (``cnem.elasticity.linear``); see `cnem._aliases`.
__getattr__ = renamed_attributes(__name__, {"elasticity": ("cnem.elasticity", "linear"),
                                            "local_update": ("cnem.elasticity", "operator_update")})
