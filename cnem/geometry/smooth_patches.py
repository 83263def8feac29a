"""Smooth patches of a 3-D body's boundary, and which of them hide points (block visibility).

A body bounded by a faceted curved surface (a sphere cavity, a cylindrical hole, a
fillet) is, strictly, full of re-entrant edges: two neighbouring facets of a spherical
cavity meet at a few degrees past 180 seen from the material. Were each such facet to
cut visibility, every cell near the cavity would be cut by the shadows of dozens of
facets that approximate a surface that hides nothing locally. So the faces of each
region are grouped into *smooth patches*: flood-filled across the edges whose dihedral
angle, measured inside the region, differs from 180 degrees by less than
`cnem.config.SMOOTH_ANGLE` (convex and re-entrant shallow edges alike). A patch
*blocks* when one of its edges is a sharp re-entrant edge (angle in the region above
``180 + SMOOTH_ANGLE``, including faces meeting back to back at a slot's or crack's
front, and edges shared by more than two faces of the region). Only the faces of
blocking patches cut visibility in `cnem.geometry.cells3d`.

>>> import numpy as np
>>> from cnem.geometry.shapes3d import box_surface
>>> from cnem.geometry.smooth_patches import blocking_sides
>>> v, f = box_surface((0, 0, 0), (1, 1, 1))
>>> blocking, reentrant = blocking_sides(v, f, np.tile([0, -1], (len(f), 1)))
>>> blocking.any(), reentrant.any()           # a box hides nothing, all its edges are convex
(np.False_, np.False_)
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from .. import config
from .._sets import isin

__all__ = ["blocking_sides"]

#: A vertex within this fraction of the edge-to-vertex distance of the other face's
#: plane counts as in that plane (faces back to back, or coplanar).
_COPLANAR = 1e-9


def blocking_sides(points: ArrayLike, faces: ArrayLike,
                   face_regions: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Whether each face, seen from the region on each of its sides, belongs to a
    blocking patch, and whether it has a re-entrant edge.

    Parameters
    ----------
    points : (n, 3) array_like
    faces : (b, 3) array_like of int
        Boundary and interface triangles, their normals pointing out of
        ``face_regions[:, 0]``.
    face_regions : (b, 2) array_like of int
        The region on each side (-1 outside the body).

    Returns
    -------
    blocking : (b, 2) bool ndarray
        ``blocking[f, s]``: face ``f`` hides points from the nodes of region
        ``face_regions[f, s]`` (False where that is -1).
    reentrant : (b, 2) bool ndarray
        ``reentrant[f, s]``: an edge of face ``f`` is re-entrant (at any angle) in region
        ``face_regions[f, s]``: the region is not convex there.
    """
    points = np.asarray(points, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64)
    face_regions = np.asarray(face_regions, dtype=np.int64)
    # one entry per (face, side with a region), its triangle turned to face out of that region
    face, side = np.nonzero(face_regions >= 0)
    region = face_regions[face, side]
    tri = np.where((side == 0)[:, None], faces[face], faces[face][:, ::-1])
    x = points[tri]
    normal = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    # the entries' edges, keyed by region and vertex pair
    start, end = tri, np.roll(tri, -1, axis=1)
    lo, hi = np.minimum(start, end).ravel(), np.maximum(start, end).ravel()
    opposite = np.roll(tri, 1, axis=1).ravel()          # the vertex off each edge
    key = np.column_stack([np.repeat(region, 3), lo, hi])
    _, edge, uses = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    edge = edge.ravel()
    entry = np.repeat(np.arange(len(face)), 3)
    order = np.argsort(edge, kind="stable")
    first = np.searchsorted(edge[order], np.arange(len(uses)))
    manifold = np.flatnonzero(uses == 2)
    a, b = order[first[manifold]], order[first[manifold] + 1]       # the two edge rows
    ea, eb = entry[a], entry[b]
    cos = np.clip(np.einsum("ij,ij->i", normal[ea], normal[eb]), -1.0, 1.0)
    turn = np.degrees(np.arccos(cos))
    reach = points[opposite[b]] - points[lo[b]]
    lean = np.einsum("ij,ij->i", normal[ea], reach) / np.linalg.norm(reach, axis=1)
    coplanar = np.abs(lean) <= _COPLANAR
    reentrant = (lean > _COPLANAR) | (coplanar & (cos < 0))
    smooth = turn < config.SMOOTH_ANGLE
    graph = coo_matrix((np.ones(int(smooth.sum())), (ea[smooth], eb[smooth])),
                       shape=(len(face), len(face)))
    _, patch = connected_components(graph, directed=False)
    sharp = np.zeros(len(face), dtype=bool)
    sharp[ea[reentrant & ~smooth]] = True
    sharp[eb[reentrant & ~smooth]] = True
    sharp[entry[isin(edge, np.flatnonzero(uses != 2))]] = True   # non-manifold edges
    blocking = np.zeros(patch.max(initial=-1) + 1, dtype=bool)
    blocking[patch[sharp]] = True
    bent = np.zeros(len(face), dtype=bool)
    bent[ea[reentrant]] = True
    bent[eb[reentrant]] = True
    out = np.zeros((2,) + face_regions.shape, dtype=bool)
    out[0, face, side] = blocking[patch]
    out[1, face, side] = bent | sharp
    return out[0], out[1]
