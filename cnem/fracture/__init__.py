"""Fracture with C-NEM: stress intensity factors by the interaction integral, crack growth.

>>> import numpy as np, cnem
>>> from cnem.fracture import nodal_williams, sif
>>> dom = cnem.geometry.rectangle(2.0, 2.0, origin=(-1.0, -1.0), cracks=[[[-1.0, 0.0], [0.0, 0.0]]])
>>> model = cnem.discretize(cnem.nodes.regular(dom, 0.1))
>>> prob = cnem.Elasticity(model, (1.0, 0.3), plane="strain")
>>> exact = nodal_williams(model, (0.0, 0.0), 1.0, 0.0, 1.0, 0.3, "strain")   # mode I, K_I = 1
>>> from cnem.geometry import SegmentKind
>>> boundary = np.unique(model.segments[model.segment_kind != SegmentKind.INTERFACE])
>>> prob.add_dirichlet(boundary, None, lambda p: exact[boundary])
>>> KI, KII = sif(prob.solve(progress=False), (0.0, 0.0), radius=0.6)
>>> bool(abs(KI - 1.0) < 0.02 and abs(KII) < 0.02)
True
"""

from .._aliases import renamed_attributes
from .criteria import CRITERIA, kink
from .enrichment import Enrichment
from ..geometry.domain import Domain
from .growth import grow
from .refine import Refinement
from .history import GrowthHistory, GrowthEvent, Step
from .interaction import SIFResult, sif
from ..material import effective_modulus, kappa
from .williams import nodal_williams, polar, williams

__all__ = ["sif", "SIFResult", "Enrichment", "tip_frame", "williams", "nodal_williams", "polar", "kappa",
           "effective_modulus", "grow", "Refinement", "GrowthHistory", "Step", "GrowthEvent", "kink", "CRITERIA"]

#: Old names (one release): see `cnem._aliases`.
__getattr__ = renamed_attributes(__name__, {"CrackPath": ("cnem.fracture.history", "GrowthHistory")})

#: `Domain.tip_frame` as a function of ``(domain, tip)``.
tip_frame = Domain.tip_frame
