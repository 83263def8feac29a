"""Queries on a closed triangle surface: distances, winding numbers, which region.

All functions take coordinates already moved to a local frame (the caller subtracts
the model's centre and divides by its size), so that the tests do not depend on
where the model sits or on its units.

>>> import numpy as np
>>> from cnem.geometry.surface_queries import solid_angle_winding
>>> v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
>>> f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
>>> solid_angle_winding(np.array([[0.1, 0.1, 0.1], [2.0, 2.0, 2.0]]), v, f).round(12).tolist()
[1.0, 0.0]
"""

from __future__ import annotations

import numpy as np

from ..spatial import RTree
from .._sets import distinct

__all__ = ["triangle_distance", "faces_within", "face_tree", "solid_angle_winding",
           "region_winding", "region_weights"]

#: Relative error bound of a 2x2 orientation determinant computed in float64
#: (Shewchuk's ``ccwerrboundA``): a sign whose value is below it times the sum of the
#: magnitudes of its two products is not certain.
_ORIENT_BOUND = (3.0 + 16.0 * np.finfo(float).eps) * np.finfo(float).eps

#: Point-face pairs evaluated at once by the solid-angle sum (memory bound).
_CHUNK_PAIRS = 2_000_000


def _segment_distance(p, a, b):
    """(m,) distance from each ``p`` to the segment ``a-b`` (rows aligned)."""
    ab = b - a
    denom = np.einsum("ij,ij->i", ab, ab)
    t = np.einsum("ij,ij->i", p - a, ab) / np.where(denom > 0, denom, 1.0)
    t = np.clip(t, 0.0, 1.0)
    return np.linalg.norm(p - a - t[:, None] * ab, axis=1)


def triangle_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Distance from points to triangles, pairwise.

    Parameters
    ----------
    p, a, b, c : (m, 3) ndarray
        The points and the triangles' corners, rows aligned.

    Returns
    -------
    (m,) ndarray
    """
    n = np.cross(b - a, c - a)
    nn = np.einsum("ij,ij->i", n, n)
    safe = np.where(nn > 0, nn, 1.0)
    ap = p - a
    height = np.einsum("ij,ij->i", ap, n) / safe
    foot = p - height[:, None] * n
    # barycentric signs of the foot point: inside when all three sub-areas agree with n
    inside = nn > 0
    for u, w in ((a, b), (b, c), (c, a)):
        inside &= np.einsum("ij,ij->i", np.cross(w - u, foot - u), n) >= 0
    out = np.minimum(np.minimum(_segment_distance(p, a, b), _segment_distance(p, b, c)),
                     _segment_distance(p, c, a))
    return np.where(inside, np.abs(height) * np.sqrt(nn), out)


def faces_within(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray,
                 radius: float | np.ndarray,
                 tree: RTree | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Point-face pairs closer than ``radius``.

    Parameters
    ----------
    points : (p, 3) ndarray
    vertices : (k, 3) ndarray
    faces : (f, 3) int ndarray
    radius : float or (p,) ndarray
    tree : RTree, optional
        Over the faces' bounding boxes (built when not given).

    Returns
    -------
    point, face : (m,) int64 ndarray
        Pairs at distance ``<= radius``.
    distance : (m,) ndarray
    """
    if tree is None:
        tree = face_tree(vertices, faces)
    offsets, cand = tree.query_ball(points, radius)
    point = np.repeat(np.arange(len(points)), np.diff(offsets))
    tri = vertices[faces[cand]]
    dist = triangle_distance(points[point], tri[:, 0], tri[:, 1], tri[:, 2])
    r = np.broadcast_to(radius, (len(points),))[point]
    keep = dist <= r
    return point[keep], cand[keep], dist[keep]


def face_tree(vertices: np.ndarray, faces: np.ndarray, dims: int = 3) -> RTree:
    """`RTree` over the faces' bounding boxes (the first ``dims`` coordinates)."""
    tri = vertices[faces][:, :, :dims]
    return RTree(tri.min(axis=1), tri.max(axis=1))


def region_weights(face_regions: np.ndarray, n_regions: int) -> np.ndarray:
    """(f, r) matrix: +1 for the region a face points out of, -1 for the one on its
    other side (none for the outside, -1)."""
    w = np.zeros((len(face_regions), n_regions))
    rows = np.arange(len(face_regions))
    w[rows, face_regions[:, 0]] = 1.0
    inner = face_regions[:, 1] >= 0
    w[rows[inner], face_regions[inner, 1]] = -1.0
    return w


def solid_angle_winding(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray,
                        weights: np.ndarray | None = None) -> np.ndarray:
    """Generalised winding numbers: the solid angles of the faces seen from each point
    over 4 pi (van Oosterom and Strackee's formula).

    Exact for a closed surface (1 inside, 0 outside) up to round-off, whatever its
    shape; undefined on the surface itself.

    Parameters
    ----------
    points : (p, 3) ndarray
    vertices : (k, 3) ndarray
    faces : (f, 3) int ndarray
        Oriented with the normals (right-hand rule) pointing out of the enclosed body.
    weights : (f, r) ndarray, optional
        Sum the faces' angles into ``r`` columns with these weights (`region_weights`
        gives one column per region).

    Returns
    -------
    (p,) or (p, r) ndarray
    """
    tri = vertices[faces]
    cols = 1 if weights is None else weights.shape[1]
    out = np.zeros((len(points), cols))
    step = max(1, _CHUNK_PAIRS // max(1, len(faces)))
    for start in range(0, len(points), step):
        p = points[start:start + step]
        a, b, c = (tri[None, :, k, :] - p[:, None, :] for k in range(3))
        la, lb, lc = (np.linalg.norm(x, axis=2) for x in (a, b, c))
        num = np.einsum("pfi,pfi->pf", a, np.cross(b, c))
        den = (la * lb * lc + np.einsum("pfi,pfi->pf", a, b) * lc
               + np.einsum("pfi,pfi->pf", a, c) * lb + np.einsum("pfi,pfi->pf", b, c) * la)
        omega = 2.0 * np.arctan2(num, den) / (4.0 * np.pi)
        out[start:start + step] = omega.sum(axis=1, keepdims=True) if weights is None \
            else omega @ weights
    return out[:, 0] if weights is None else out


def _edge_signs(pxy, u, w, iu, iw):
    """Sign of the orientation of ``p`` against each directed edge ``u -> w`` in the xy
    plane, with ties (``p`` exactly on the edge's line) broken as if ``p`` were moved by
    ``(eps, eps^2)``. Each edge is evaluated in the order of its vertex numbers, so that the
    two faces that share it see the same value (the surface stays watertight).

    Returns
    -------
    sign : (m,) int8 ndarray
        +1, -1, or 0 for a degenerate (vertical) edge.
    certain : (m,) bool ndarray
        False where round-off could have flipped the sign.
    """
    flip = iu > iw
    a = np.where(flip[:, None], w, u)
    b = np.where(flip[:, None], u, w)
    left = (a[:, 0] - pxy[:, 0]) * (b[:, 1] - pxy[:, 1])
    right = (a[:, 1] - pxy[:, 1]) * (b[:, 0] - pxy[:, 0])
    det = left - right
    bound = _ORIENT_BOUND * (np.abs(left) + np.abs(right))
    tie = np.where(b[:, 1] != a[:, 1], np.sign(a[:, 1] - b[:, 1]), np.sign(b[:, 0] - a[:, 0]))
    exact_zero = bound == 0.0
    sign = np.where(exact_zero, tie, np.sign(det))
    certain = exact_zero | (np.abs(det) > bound)
    return (np.where(flip, -sign, sign)).astype(np.int8), certain


def region_winding(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray,
                   weights: np.ndarray, xy_tree: RTree | None = None) -> np.ndarray:
    """Winding numbers per region by a ray cast upwards (+z) from each point.

    Each face that the ray crosses adds its region weights with the sign of its normal's
    z component. Rays through edges and vertices are decided by a symbolic perturbation
    of the point, evaluated identically for the faces that share an edge, so every ray
    crosses a closed surface a whole number of times; the points whose decision round-off
    could flip get the solid-angle sum (`solid_angle_winding`) instead.

    Parameters
    ----------
    points : (p, 3) ndarray
        Not on the surface (the caller takes those out by distance first).
    vertices : (k, 3) ndarray
    faces : (f, 3) int ndarray
    weights : (f, r) ndarray
        `region_weights`.
    xy_tree : RTree, optional
        Over the faces' xy bounding boxes (``face_tree(vertices, faces, 2)``).

    Returns
    -------
    (p, r) ndarray
        Whole numbers.
    """
    if xy_tree is None:
        xy_tree = face_tree(vertices, faces, 2)
    offsets, cand = xy_tree.query(points[:, :2], points[:, :2])
    point = np.repeat(np.arange(len(points)), np.diff(offsets))
    pxy = points[point, :2]
    ids = faces[cand]
    signs, certain = [], []
    for k in range(3):
        s, c = _edge_signs(pxy, vertices[ids[:, k], :2], vertices[ids[:, (k + 1) % 3], :2],
                           ids[:, k], ids[:, (k + 1) % 3])
        signs.append(s)
        certain.append(c)
    signs, certain = np.stack(signs, axis=1), np.stack(certain, axis=1)
    # covered when every edge agrees; unsure when the certain edges agree and one is not
    agree_certain = np.where(certain, signs, 0)
    pos = ((agree_certain > 0) | ~certain).all(axis=1)
    neg = ((agree_certain < 0) | ~certain).all(axis=1)
    unsure = (pos | neg) & ~certain.all(axis=1)
    covered = certain.all(axis=1) & (signs[:, 0] != 0) & (signs == signs[:, :1]).all(axis=1)
    tri = vertices[ids[covered]]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    height = np.einsum("ij,ij->i", points[point[covered]] - tri[:, 0], normal)
    sigma = signs[covered, 0].astype(float)
    above = height * sigma < 0
    out = np.zeros((len(points), weights.shape[1]))
    hit = np.flatnonzero(covered)[above]
    np.add.at(out, point[hit], sigma[above][:, None] * weights[cand[hit]])
    redo = distinct(point[unsure])
    if len(redo):
        out[redo] = np.rint(solid_angle_winding(points[redo], vertices, faces, weights))
    return out
