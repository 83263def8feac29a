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
from scipy.spatial import cKDTree

from ..errors import GeometryError
from .._sets import distinct

__all__ = ["InterfacePieces", "interface_pieces", "on_triangles"]

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


def interface_pieces(facet_triangles: np.ndarray, facet_normal: np.ndarray,
                     facet_group: np.ndarray, face_corners: np.ndarray, size: float,
                     also: np.ndarray | None = None,
                     split: np.ndarray | None = None) -> InterfacePieces:
    """The common refinement of the cells' facets on interface faces (and of ``also``).

    Parameters
    ----------
    facet_triangles : (f, 3, 3) ndarray
        The cells' boundary triangles.
    facet_normal : (f, 3) ndarray
        Outward unit normals.
    facet_group : (f,) int64 ndarray
        The facet (cell, plane) of each triangle.
    face_corners : (b, 3, 3) ndarray
        The interface faces (between two regions).
    size : float
        The model's size (tolerances are relative to it).
    also : (f,) bool ndarray, optional
        Further triangles to cut into pieces with the other side's (facets that two
        cells cut differently off the interfaces: shadows of a face's plane).
    split : (f,) bool ndarray, optional
        Triangles (of ``also``) whose overlaps stay one piece each instead of one piece
        per pair of facets (a non-convex facet, whose centroid may lie off it).

    Returns
    -------
    InterfacePieces

    Raises
    ------
    GeometryError
        An interface facet the other side's facets do not cover.
    """
    on = _on_faces(facet_triangles, facet_normal, face_corners, size)
    if also is not None:
        on |= also
    if not on.any():
        none = np.zeros(0, dtype=np.int64)
        return InterfacePieces(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3)), none, none,
                               on)
    # a facet's triangles to cut (on an interface, or ``also``) apart from its others in
    # the same plane, which the other side's pieces do not cover
    facet_group = np.unique(np.column_stack([facet_group, on]), axis=0,
                            return_inverse=True)[1].reshape(-1)
    tri_idx = np.flatnonzero(on)
    ta, tb = _overlapping(facet_triangles, facet_normal, tri_idx, size)
    # the pair's triangles in the 2-D frame of ta's plane, about ta's centre
    origin = facet_triangles[ta].mean(axis=1)
    e1, e2 = _plane_basis(facet_normal[ta])
    xy_a = _in_plane(facet_triangles[ta] - origin[:, None], e1, e2)
    xy_b = _in_plane(facet_triangles[tb] - origin[:, None], e1, e2)
    area, centre = _triangle_overlaps(xy_a, xy_b)
    keep = area > 0
    ta, tb, area, centre = ta[keep], tb[keep], area[keep], centre[keep]
    origin, e1, e2 = origin[keep], e1[keep], e2[keep]
    point = origin + centre[:, :1] * e1 + centre[:, 1:] * e2
    # one piece per pair of facets
    pair = np.column_stack([facet_group[ta], facet_group[tb]])
    if split is not None:
        alone = split[ta] | split[tb]
        pair[alone] = np.column_stack([-1 - ta[alone], -1 - tb[alone]])
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
    facets = distinct(facet_group[on])
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
    nf = np.cross(corners[face, 1] - corners[face, 0], corners[face, 2] - corners[face, 0])
    cos = np.abs(np.einsum("ij,ij->i", normal[t], nf)) / np.linalg.norm(nf, axis=1)
    inside = (on_triangles(point[t], corners[face], 1e-9, PLANE_RTOL * size)
              & (cos >= 1.0 - PARALLEL_TOL))
    out[t[inside]] = True
    return out


def on_triangles(points: np.ndarray, corners: np.ndarray, rtol: float, plane_tol: float
                 ) -> np.ndarray:
    """Whether each point lies on its triangle: barycentric coordinates above ``-rtol``
    and distance from the triangle's plane at most ``plane_tol``.

    Parameters
    ----------
    points : (k, 3) ndarray
    corners : (k, 3, 3) ndarray
    rtol, plane_tol : float

    Returns
    -------
    (k,) bool ndarray
    """
    a = corners[:, 0]
    e1, e2, d = corners[:, 1] - a, corners[:, 2] - a, points - a
    n = np.cross(e1, e2)
    nn = np.einsum("ij,ij->i", n, n)
    s = np.einsum("ij,ij->i", np.cross(d, e2), n) / nn
    t = np.einsum("ij,ij->i", np.cross(e1, d), n) / nn
    off = np.abs(np.einsum("ij,ij->i", d, n)) / np.sqrt(nn)
    return (s >= -rtol) & (t >= -rtol) & (s + t <= 1.0 + rtol) & (off <= plane_tol)


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


def _in_plane(tri, e1, e2):
    """``(k, 3, 2)`` coordinates of ``(k, 3, 3)`` triangles in the frames ``e1, e2``."""
    return np.stack([np.einsum("kij,kj->ki", tri, e1), np.einsum("kij,kj->ki", tri, e2)], axis=2)


def _triangle_overlaps(a, b):
    """Area ``(k,)`` and centroid ``(k, 2)`` of the intersections of the 2-D triangles
    ``a`` and ``b`` ``(k, 3, 2)``: ``a`` clipped by the three half-planes of ``b``
    (Sutherland-Hodgman; a convex polygon clipped by a half-plane gains at most one
    vertex, so at most six)."""
    k = len(a)
    ccw = _cross(b[:, 1] - b[:, 0], b[:, 2] - b[:, 0]) > 0
    b = np.where(ccw[:, None, None], b, b[:, ::-1])
    poly = np.zeros((k, 7, 2))
    poly[:, :3] = a
    count = np.full(k, 3, dtype=np.int64)
    rows = np.arange(k)
    for edge in range(3):
        p, q = b[:, edge], b[:, (edge + 1) % 3]
        side = _cross((q - p)[:, None, :], poly - p[:, None, :])       # (k, 7), >= 0 inside
        out = np.zeros_like(poly)
        n_out = np.zeros(k, dtype=np.int64)
        for i in range(6):
            valid = i < count
            j = np.where(i + 1 < count, i + 1, 0)
            si, sj = side[:, i], side[rows, j]
            vi, vj = poly[:, i], poly[rows, j]
            keep = valid & (si >= 0)
            out[rows[keep], n_out[keep]] = vi[keep]
            n_out += keep
            cut = valid & (si * sj < 0)
            t = si[cut] / (si[cut] - sj[cut])
            out[rows[cut], n_out[cut]] = vi[cut] + t[:, None] * (vj[cut] - vi[cut])
            n_out += cut
        poly, count = out, n_out
    # shoelace over the closed polygon (slots past the count repeat the first vertex)
    slot = np.arange(7)[None, :]
    poly = np.where((slot < count[:, None])[..., None], poly, poly[:, :1])
    nxt = np.roll(poly, -1, axis=1)
    cross = _cross(poly, nxt)
    twice = cross.sum(axis=1)
    area = 0.5 * np.abs(twice)
    safe = np.where(twice != 0, twice, 1.0)
    centre = ((poly + nxt) * cross[..., None]).sum(axis=1) / (3.0 * safe[:, None])
    # a sliver's centroid is all round-off: keep it in its box (nearer the true one,
    # and in the body; its tiny area makes the moment's error round-off)
    centre = np.clip(centre, poly.min(axis=1), poly.max(axis=1))
    return np.where(count >= 3, area, 0.0), centre


def _cross(u, v):
    """The 2-D cross product of ``(..., 2)`` vectors."""
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


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
