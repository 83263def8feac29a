"""Tolerances and tuning constants used across cnem, kept in one place.

All tolerances are *relative*: multiply by the domain diameter (lengths) or
its square (areas) before comparing. The modules read them as ``config.NAME``
when they run, so a change here (or a monkeypatch in a test) takes effect at
the next call. (``cnem.shape._kernels.MAX_CAVITY`` stays in its kernel module:
numba compiles it into the kernels as a constant.)
"""

__all__ = ["SNAP_TOL", "OVERLAP_TOL", "MERGE_TOL", "GRID_TOL", "SHAPE_TOL", "CELLS_PER_PASS",
           "ROW_SLOTS", "TRIANGLE_TREE_AFTER"]

#: Points closer than ``SNAP_TOL * diameter`` to a boundary, interface or crack
#: are snapped onto it; vertices closer than this are the same vertex.
SNAP_TOL = 1e-9

#: Relative area below which an overlap of two regions is considered round-off.
OVERLAP_TOL = 1e-12

#: Relative length below which two Voronoi vertices are merged into one.
MERGE_TOL = 1e-13

#: Relative grid (times the extent of the nodes) on which the exact cell
#: clipping is snap-rounded, so that neighbouring cells share their vertices.
GRID_TOL = 1e-13

#: Relative distance (times the domain diameter) under which a query point is
#: taken to be at a node or on a constraint edge in the shape functions.
SHAPE_TOL = 1e-12

# -- tuning (speed and memory only: results do not depend on them) ----------------------

#: Cells whose boundary quadrature is built and evaluated in one pass of the SCNI
#: smoothed gradients (`cnem.assembly.passes`): bounds the memory of the points
#: and their shape functions, and keeps a pass in cache.
CELLS_PER_PASS = 10_000

#: Room per point for the shape-function rows written chunk by chunk
#: (`cnem.shape.natural`; doubled when a chunk overflows: points have about 5-6
#: natural neighbours on average).
ROW_SLOTS = 8

#: Points the walks of the point location cannot reach, as a fraction of the
#: triangles, above which they are located with an R-tree of the triangles
#: (`Model.triangle_tree`, built once) rather than of the circumcircles.
TRIANGLE_TREE_AFTER = 0.01
