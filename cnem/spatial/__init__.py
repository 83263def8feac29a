"""One spatial index for everything: packed STR R-tree (optionally periodic) and family search.

>>> import numpy as np
>>> import cnem.spatial as sp
>>> pts = np.random.default_rng(0).random((1000, 2))
>>> fam = sp.family_search(pts, 0.05)
>>> tree = sp.RTree.from_points(pts)
>>> offsets, indices = tree.query_ball(pts, 0.05, strict=True, exclude_self=True)
>>> bool((np.diff(offsets) == fam.counts).all())
True
"""

from .crossing import remove_crossing
from .family import Family, family_search
from .rtree import RTree

__all__ = ["RTree", "Family", "family_search", "remove_crossing"]
