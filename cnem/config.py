"""Tolerances used across cnem, kept in one place.

All tolerances are *relative*: multiply by the domain diameter (lengths) or
its square (areas) before comparing.
"""

__all__ = ["SNAP_TOL", "OVERLAP_TOL", "MERGE_TOL", "GRID_TOL", "SHAPE_TOL"]

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
