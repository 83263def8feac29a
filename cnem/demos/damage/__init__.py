"""Reading a peridynamic damage field for the demos: the crack path through it (`ridge`),
used by `cnem.demos.growth_pd_vs_cnem`."""

from . import ridge

__all__ = ["ridge"]
