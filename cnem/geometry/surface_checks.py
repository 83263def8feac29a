"""Checks of triangle surfaces: edges, closure, orientation, degenerate and crossing faces.

Every check raises a `cnem.GeometryError` that names the faces at fault by the
caller's names for them (``names[i]``, e.g. ``"region 0 face 12"``).

>>> import numpy as np
>>> from cnem.errors import GeometryError
>>> from cnem.geometry.surface_checks import check_closed
>>> tet = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
>>> try:
...     check_closed(tet[:3], [f"face {i}" for i in range(3)])
... except GeometryError as exc:
...     print(str(exc)[:80])
the surface is open: 3 edges belong to one face only, first the edge between ver
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from ..errors import GeometryError
from .surface_queries import face_tree

__all__ = ["edge_table", "check_closed", "face_components", "check_faces",
           "check_self_intersections"]

#: Faces named in full in a message before "...".
_SHOWN = 5


def edge_table(faces: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The undirected edges of a triangle surface.

    Parameters
    ----------
    faces : (f, 3) int ndarray

    Returns
    -------
    edges : (e, 2) int64 ndarray
        Vertex pairs, smaller number first.
    face_edge : (f, 3) int64 ndarray
        Edge ``k`` of face ``i`` runs from ``faces[i, k]`` to ``faces[i, (k + 1) % 3]``.
    forward : (f, 3) bool ndarray
        Whether face ``i`` runs along its edge ``k`` from the smaller vertex number.
    """
    start, end = faces, np.roll(faces, -1, axis=1)
    pairs = np.stack([np.minimum(start, end), np.maximum(start, end)], axis=2).reshape(-1, 2)
    edges, inverse = np.unique(pairs, axis=0, return_inverse=True)
    return edges, inverse.reshape(-1, 3).astype(np.int64), (start < end)


def _listed(items):
    text = ", ".join(items[:_SHOWN])
    return text + (", ..." if len(items) > _SHOWN else "")


def check_closed(faces: np.ndarray, names: Sequence[str]) -> None:
    """Refuse an open, non-manifold or inconsistently oriented surface.

    Parameters
    ----------
    faces : (f, 3) int ndarray
    names : sequence of str
        How a message names face ``i``.
    """
    edges, face_edge, forward = edge_table(faces)
    uses = np.bincount(face_edge.ravel(), minlength=len(edges))
    ahead = np.bincount(face_edge.ravel(), weights=forward.ravel(), minlength=len(edges))
    owner = np.full(len(edges), -1)
    owner[face_edge.ravel()[::-1]] = np.repeat(np.arange(len(faces)), 3)[::-1]

    def where(ids):
        return [f"the edge between vertices {edges[e, 0]} and {edges[e, 1]} of {names[owner[e]]}"
                for e in ids]

    def faces_at(e):
        return [names[i] for i in np.flatnonzero((face_edge == e).any(axis=1))]

    open_ = np.flatnonzero(uses == 1)
    if open_.size:
        raise GeometryError(
            f"the surface is open: {open_.size} edges belong to one face only, first "
            f"{_listed(where(open_))}; close the surface (every edge shared by exactly two faces)")
    many = np.flatnonzero(uses > 2)
    if many.size:
        e = many[0]
        raise GeometryError(
            f"the surface is not manifold: {many.size} edges belong to more than two faces, "
            f"first the edge between vertices {edges[e, 0]} and {edges[e, 1]}, shared by "
            f"{_listed(faces_at(e))}; split the surface into closed surfaces "
            "that share no edge (regions of their own)")
    same = np.flatnonzero(ahead != 1)
    if same.size:
        e = same[0]
        raise GeometryError(
            f"the surface is not consistently oriented: {same.size} edges are run along in the "
            f"same direction by both of their faces, first the edge between vertices "
            f"{edges[e, 0]} and {edges[e, 1]} of {' and '.join(faces_at(e))}; "
            "reverse one of the faces (number every face's vertices counter-clockwise seen from "
            "outside)")


def face_components(faces: np.ndarray) -> tuple[np.ndarray, int]:
    """(f,) int64 label of the edge-connected surface each face belongs to, and their count."""
    _, face_edge, _ = edge_table(faces)
    n = len(faces)
    rows = np.repeat(np.arange(n), 3)
    graph = coo_matrix((np.ones(3 * n), (rows, face_edge.ravel() + n)),
                       shape=(n + face_edge.max() + 1, n + face_edge.max() + 1))
    count, labels = connected_components(graph, directed=False)
    used, labels = np.unique(labels[:n], return_inverse=True)
    return labels.astype(np.int64), len(used)


def check_faces(vertices: np.ndarray, faces: np.ndarray, tol: float,
                names: Sequence[str]) -> None:
    """Refuse degenerate faces (a height below ``tol``: collinear or repeated vertices)
    and faces given twice.

    Parameters
    ----------
    vertices : (k, 3) ndarray
    faces : (f, 3) int ndarray
    tol : float
        Length below which two points are one.
    names : sequence of str
    """
    tri = vertices[faces]
    double_area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    longest = np.linalg.norm(tri - np.roll(tri, 1, axis=1), axis=2).max(axis=1)
    flat = np.flatnonzero((double_area <= tol * longest) | (faces == np.roll(faces, 1, axis=1))
                          .any(axis=1))
    if flat.size:
        raise GeometryError(
            f"{flat.size} faces are degenerate (zero area: repeated or collinear vertices, "
            f"height below {tol:.3g}), first {_listed([names[i] for i in flat])}; remove them "
            "and close the surface without them")
    key = np.sort(faces, axis=1)
    _, first, counts = np.unique(key, axis=0, return_index=True, return_counts=True)
    if (counts > 1).any():
        dup = first[counts > 1][0]
        twins = np.flatnonzero((key == key[dup]).all(axis=1))
        raise GeometryError(
            f"the same triangle is given twice: {' and '.join(names[i] for i in twins)}; "
            "remove the copy")


def _side(u, w, x, n):
    """Signed distance-like orientation of ``x`` from the line ``u -> w`` in the plane of
    normal ``n`` (rows aligned)."""
    return np.einsum("ij,ij->i", np.cross(w - u, x - u), n)


def _inside(x, a, b, c, n, tol):
    """Whether ``x`` (in the plane of ``abc``) lies in the triangle, edges within ``tol``."""
    ok = np.ones(len(x), dtype=bool)
    nlen = np.linalg.norm(n, axis=1)
    for u, w in ((a, b), (b, c), (c, a)):
        length = np.linalg.norm(w - u, axis=1) * nlen
        ok &= _side(u, w, x, n) >= -tol * length
    return ok


def _segment_hits(p0, p1, a, b, c, tol):
    """(m,) bool: the segment ``p0-p1`` meets the triangle ``abc`` (closed, within ``tol``)."""
    n = np.cross(b - a, c - a)
    nlen = np.linalg.norm(n, axis=1)
    d0 = np.einsum("ij,ij->i", p0 - a, n) / nlen
    d1 = np.einsum("ij,ij->i", p1 - a, n) / nlen
    flat = (np.abs(d0) <= tol) & (np.abs(d1) <= tol)
    hit = np.zeros(len(p0), dtype=bool)
    cross = np.flatnonzero((d0 * d1 <= 0) & ~flat & (d0 != d1))
    t = d0[cross] / (d0[cross] - d1[cross])
    x = p0[cross] + t[:, None] * (p1[cross] - p0[cross])
    hit[cross] = _inside(x, a[cross], b[cross], c[cross], n[cross], tol)
    # a segment in the triangle's plane: an end inside, or crossing one of its edges
    k = np.flatnonzero(flat)
    p0, p1, a, b, c, n = p0[k], p1[k], a[k], b[k], c[k], n[k]
    coplanar = _inside(p0, a, b, c, n, tol) | _inside(p1, a, b, c, n, tol)
    for u, w in ((a, b), (b, c), (c, a)):
        s0, s1 = _side(u, w, p0, n), _side(u, w, p1, n)
        s2, s3 = _side(p0, p1, u, n), _side(p0, p1, w, n)
        coplanar |= (s0 * s1 < 0) & (s2 * s3 < 0)
    hit[k] |= coplanar
    return hit


def check_self_intersections(vertices: np.ndarray, faces: np.ndarray, tol: float,
                             names: Sequence[str]) -> None:
    """Refuse faces that cross or touch away from the vertices they share.

    Candidate pairs come from the faces' bounding boxes (`cnem.spatial.RTree`); a pair
    sharing no vertex is tested edge against triangle both ways, a pair sharing one vertex
    with the edges opposite to it, a pair sharing an edge for a fold (the two faces on
    the same side of it, in one plane).

    Parameters
    ----------
    vertices : (k, 3) ndarray
    faces : (f, 3) int ndarray
    tol : float
        Contact distance.
    names : sequence of str
    """
    tri = vertices[faces]
    tree = face_tree(vertices, faces)
    offsets, other = tree.query(tri.min(axis=1) - tol, tri.max(axis=1) + tol)
    first = np.repeat(np.arange(len(faces)), np.diff(offsets))
    keep = first < other
    i, j = first[keep], other[keep]
    same = faces[i][:, :, None] == faces[j][:, None, :]          # (m, 3, 3)
    shared = same.sum(axis=(1, 2))
    bad = np.zeros(len(i), dtype=bool)
    a, b = tri[i], tri[j]
    apart = np.flatnonzero(shared == 0)
    pa, pb = a[apart], b[apart]
    for k in range(3):
        for s, t in ((pa, pb), (pb, pa)):
            bad[apart] |= _segment_hits(s[:, k], s[:, (k + 1) % 3], t[:, 0], t[:, 1], t[:, 2],
                                        tol)
    one = np.flatnonzero(shared == 1)
    if one.size:
        ka = np.argmax(same[one].any(axis=2), axis=1)       # shared corner of each face
        kb = np.argmax(same[one].any(axis=1), axis=1)
        for s, t, k in ((a[one], b[one], ka), (b[one], a[one], kb)):
            rows = np.arange(len(one))
            bad[one] |= _segment_hits(s[rows, (k + 1) % 3], s[rows, (k + 2) % 3], t[:, 0],
                                      t[:, 1], t[:, 2], tol)
    two = np.flatnonzero(shared == 2)
    if two.size:
        # the corner of each face off the shared edge
        ka = np.argmin(same[two].any(axis=2), axis=1)
        kb = np.argmin(same[two].any(axis=1), axis=1)
        rows = np.arange(len(two))
        pa, pb = a[two][rows, ka], b[two][rows, kb]
        u, w = a[two][rows, (ka + 1) % 3], a[two][rows, (ka + 2) % 3]
        n = np.cross(w - u, pa - u)
        nlen = np.linalg.norm(n, axis=1)
        off_plane = np.abs(np.einsum("ij,ij->i", pb - u, n)) / nlen
        same_side = np.einsum("ij,ij->i", np.cross(w - u, pb - u), n) > 0
        bad[two] |= (off_plane <= tol) & same_side
    if bad.any():
        pairs = [f"{names[x]} and {names[y]}" for x, y in zip(i[bad], j[bad])]
        raise GeometryError(
            f"the surface intersects itself: {int(bad.sum())} pairs of faces cross or touch, "
            f"first {_listed(pairs)}; remove the crossing (faces may meet only along the edges "
            "and at the vertices they share)")
