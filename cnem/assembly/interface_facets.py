"""The facets of 3-D cells on material interfaces, cut into their common refinement.

A node on an interface owns one cell per region, and the cells on the two sides cut
the interface into *different* polygons: a facet of region ``r`` overlaps several
facets of region ``s``. Integrated facet by facet (one point each), the two sides'
integrals would not cancel and the integration constraint would fail. So each
interface facet is cut by the facets of the other side it overlaps (the
intersections of their triangles, in the 2-D coordinates of its plane): every piece
is one point (its centroid) and one area, taken by both cells with opposite
normals, and the pieces of a facet cover it exactly (their area-normals sum to the
facet's, their first moments to its, so the rule stays exact for linear fields).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import shapely
from scipy.spatial import cKDTree

from ..errors import GeometryError

__all__ = ["InterfacePieces", "interface_pieces"]

#: A facet lies in an interface face's plane when its normal is parallel to the
#: face's to this (``1 - |cos|``) ...
PARALLEL_TOL = 1e-6
#: ... and its distance from the plane is below this fraction of the model's size.
PLANE_RTOL = 1e-9
#: The pieces of an interface facet must cover it to this fraction of its area.
COVER_RTOL = 1e-9


class InterfacePieces(NamedTuple):
    """The pieces of the interface facets.

    Piece ``j`` lies on the facet of triangle ``tri_a[j]`` (its area-normal points out
    of that triangle's cell) and on the facet of ``tri_b[j]`` (out of which it points
    the other way).

    Attributes
    ----------
    point : (p, 3) ndarray
        The pieces' centroids.
    area_normal_a, area_normal_b : (p, 3) ndarray
        Out of ``tri_a``'s cell and out of ``tri_b``'s, of length the piece's area
        (each side's pieces scaled to sum to its facet's area-normal to round-off).
    tri_a, tri_b : (p,) int64 ndarray
        A facet triangle of each side.
    on_interface : (f,) bool ndarray
        The facet triangles whose facets the pieces replace.
    """

    point: np.ndarray
    area_normal_a: np.ndarray
    area_normal_b: np.ndarray
    tri_a: np.ndarray
    tri_b: np.ndarray
    on_interface: np.ndarray


def interface_pieces(facet_triangles: np.ndarray, facet_cell: np.ndarray,
                     facet_normal: np.ndarray, facet_group: np.ndarray,
                     face_corners: np.ndarray, size: float) -> InterfacePieces:
    """The common refinement of the cells' facets on interface faces.

    Parameters
    ----------
    facet_triangles : (f, 3, 3) ndarray
        The cells' boundary triangles.
    facet_cell : (f,) int64 ndarray
    facet_normal : (f, 3) ndarray
        Outward unit normals.
    facet_group : (f,) int64 ndarray
        The facet (cell, plane) of each triangle.
    face_corners : (b, 3, 3) ndarray
        The interface faces (between two regions).
    size : float
        The model's size (tolerances are relative to it).

    Returns
    -------
    InterfacePieces

    Raises
    ------
    GeometryError
        An interface facet the other side's facets do not cover.
    """
    f = len(facet_triangles)
    on = _on_faces(facet_triangles, facet_normal, face_corners, size)
    empty = InterfacePieces(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3)),
                            np.zeros(0, np.int64),
                            np.zeros(0, np.int64), np.zeros(f, dtype=bool))
    if not on.any():
        return empty
    # the whole facet of any triangle on an interface
    on = np.isin(facet_group, facet_group[on])
    tri_idx = np.flatnonzero(on)
    ta, tb = _overlapping(facet_triangles, facet_normal, tri_idx, size)
    # the pair's triangles in the 2-D frame of ta's plane, about ta's centre
    origin = facet_triangles[ta].mean(axis=1)
    e1, e2 = _plane_basis(facet_normal[ta])
    poly_a = _polygons(facet_triangles[ta] - origin[:, None], e1, e2)
    poly_b = _polygons(facet_triangles[tb] - origin[:, None], e1, e2)
    piece = shapely.intersection(poly_a, poly_b)
    area = shapely.area(piece)
    keep = area > 0
    ta, tb, area, piece = ta[keep], tb[keep], area[keep], piece[keep]
    origin, e1, e2 = origin[keep], e1[keep], e2[keep]
    c = shapely.centroid(piece)
    point = origin + shapely.get_x(c)[:, None] * e1 + shapely.get_y(c)[:, None] * e2
    # one piece per pair of facets
    pair = np.column_stack([facet_group[ta], facet_group[tb]])
    _, first, which = np.unique(pair, axis=0, return_index=True, return_inverse=True)
    which = which.reshape(-1)
    total = np.bincount(which, weights=area)
    moment = np.column_stack([np.bincount(which, weights=area * point[:, i]) for i in range(3)])
    ta, tb = ta[first], tb[first]
    # each side's pieces sum to its facet's area-normal (the two areas agree to round-off)
    area_normal = _facet_area_normals(facet_triangles, facet_normal, facet_group)
    ga, gb = facet_group[ta], facet_group[tb]
    covered = np.bincount(np.concatenate([ga, gb]), weights=np.concatenate([total, total]),
                          minlength=len(area_normal))
    facets = np.unique(facet_group[on])
    _check_cover(np.linalg.norm(area_normal[facets], axis=1), covered[facets])
    flux_a, flux_b = (area_normal[g] * (total / covered[g])[:, None] for g in (ga, gb))
    return InterfacePieces(moment / total[:, None], flux_a, flux_b, ta, tb, on)


def _on_faces(tri, normal, corners, size):
    """Whether each triangle's centroid lies on a face (in its plane, parallel normals)."""
    f = len(tri)
    out = np.zeros(f, dtype=bool)
    if len(corners) == 0 or f == 0:
        return out
    centre = corners.mean(axis=1)
    reach = float(np.linalg.norm(corners - centre[:, None], axis=2).max())
    face_tree = cKDTree(centre)
    point = tri.mean(axis=1)
    dist, _ = face_tree.query(point, distance_upper_bound=reach * (1.0 + 1e-9))
    near = np.flatnonzero(np.isfinite(dist))
    hits = face_tree.query_ball_point(point[near], r=reach * (1.0 + 1e-9))
    count = np.array([len(h) for h in hits], dtype=np.int64)
    t = np.repeat(near, count)
    face = np.concatenate([np.asarray(h, dtype=np.int64) for h in hits] + [t[:0]])
    a, b, c = corners[face, 0], corners[face, 1], corners[face, 2]
    e1, e2, d = b - a, c - a, point[t] - a
    nf = np.cross(e1, e2)
    nn = np.einsum("ij,ij->i", nf, nf)
    s = np.einsum("ij,ij->i", np.cross(d, e2), nf) / nn
    u = np.einsum("ij,ij->i", np.cross(e1, d), nf) / nn
    off = np.abs(np.einsum("ij,ij->i", d, nf)) / np.sqrt(nn)
    cos = np.abs(np.einsum("ij,ij->i", normal[t], nf)) / np.sqrt(nn)
    tol = 1e-9
    inside = ((s >= -tol) & (u >= -tol) & (s + u <= 1.0 + tol) & (off <= PLANE_RTOL * size)
              & (cos >= 1.0 - PARALLEL_TOL))
    out[t[inside]] = True
    return out


def _overlapping(tri, normal, index, size):
    """Candidate pairs ``ta < tb`` of the triangles ``index``: opposite normals, one
    plane, bounding spheres that meet (each pair once, whichever side is which)."""
    centre = tri.mean(axis=1)
    reach = np.linalg.norm(tri - centre[:, None], axis=2).max(axis=1)
    radius = float(reach[index].max()) * 2.0 * (1.0 + 1e-9)
    hits = cKDTree(centre[index]).query_ball_point(centre[index], r=radius)
    count = np.array([len(h) for h in hits], dtype=np.int64)
    ta = np.repeat(index, count)
    tb = index[np.concatenate([np.asarray(h, dtype=np.int64) for h in hits] + [ta[:0]])]
    opposite = np.einsum("ij,ij->i", normal[ta], normal[tb]) <= -(1.0 - PARALLEL_TOL)
    coplanar = (np.abs(np.einsum("ij,ij->i", normal[ta], centre[tb] - centre[ta]))
                <= PLANE_RTOL * size)
    close = (np.linalg.norm(centre[tb] - centre[ta], axis=1)
             <= (reach[ta] + reach[tb]) * (1.0 + 1e-9))
    keep = (ta < tb) & opposite & coplanar & close
    return ta[keep], tb[keep]


def _plane_basis(normal):
    """Two unit vectors ``(k, 3)`` spanning the planes of unit ``normal``."""
    helper = np.eye(3)[np.argmin(np.abs(normal), axis=1)]
    e1 = np.cross(normal, helper)
    e1 /= np.linalg.norm(e1, axis=1)[:, None]
    return e1, np.cross(normal, e1)


def _polygons(tri, e1, e2):
    """Shapely triangles from ``(k, 3, 3)`` corners in the frames ``e1, e2``."""
    xy = np.stack([np.einsum("kij,kj->ki", tri, e1), np.einsum("kij,kj->ki", tri, e2)], axis=2)
    return shapely.polygons(xy)


def _facet_area_normals(tri, normal, group):
    """The area-normal of every facet: its triangles' areas times their normals, summed."""
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    n_groups = int(group.max()) + 1
    return np.column_stack([np.bincount(group, weights=area * normal[:, i], minlength=n_groups)
                            for i in range(3)])


def _check_cover(facet_area, covered):
    """Raise unless the pieces of every interface facet sum to its area."""
    gap = np.abs(covered - facet_area) > COVER_RTOL * facet_area
    if gap.any():
        raise GeometryError(
            f"expected the interface facets of the two sides to cover each other, received "
            f"facets of area {facet_area[gap][:5].tolist()} covered by "
            f"{covered[gap][:5].tolist()}; the interface faces must be shared by the cells "
            f"of both regions")
