"""A convex polytope cut into its pieces inside a region's tetrahedra.

Near a curved (smooth, non-blocking) re-entrant boundary the 3-D cell of a node is
its Voronoi polytope among the region's nodes intersected with the region, and the
region is exactly the union of its tetrahedra. `RegionTets.cut` intersects a
polytope (in a node's local frame) with each tetrahedron of the region that it can
meet: one convex piece per tetrahedron. The pieces' faces are tagged by what they
lie on: ``("f", face)`` for a boundary or interface face (a facet of the cell),
``("t", key)`` for a face between two tetrahedra of the region. The two pieces on
either side of such an internal face have the same trace on it (the polytope's
section), so those faces cancel exactly and are dropped (`open_facets`); they also
tell whether the pieces form one connected cell (`connected`).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from .polytope import _ON, Plane, Polytope
from .tetrahedra import _FACES, _face_keys, tet_neighbors

__all__ = ["RegionTets", "open_facets", "connected"]

#: A tetrahedron whose ``|6 V|`` (local unit) is below this is flat: no piece, but it
#: joins the pieces around it.
_FLAT = 1e-10


class RegionTets:
    """The tetrahedra of each region, with their faces' tags.

    Parameters
    ----------
    points : (n, 3) ndarray
    tets : (t, 4) int64 ndarray
    tet_region : (t,) int64 ndarray
    faces : (b, 3) int64 ndarray
        Boundary and interface faces.
    """

    def __init__(self, points: np.ndarray, tets: np.ndarray, tet_region: np.ndarray,
                 faces: np.ndarray):
        n = len(points)
        self.points, self.tets = points, tets
        self.face_key, fkey = _face_keys([tets[:, _FACES], faces], n)     # (t, 4), (b,)
        order = np.argsort(fkey)
        pos = np.minimum(np.searchsorted(fkey[order], self.face_key), len(fkey) - 1)
        #: the boundary face each tetrahedron face lies on, -1 for an internal face
        self.boundary = np.where(fkey[order][pos] == self.face_key, order[pos], -1)
        nb = tet_neighbors(tets, n)
        same = (nb >= 0) & (tet_region[np.maximum(nb, 0)] == tet_region[:, None])
        self.boundary[~same & (self.boundary < 0)] = -2        # a hull face: never internal
        x = points[tets]
        centre = x.mean(axis=1)
        self.radius = np.linalg.norm(x - centre[:, None], axis=2).max(axis=1)
        self.region = []
        for r in range(int(tet_region.max()) + 1):
            ids = np.flatnonzero(tet_region == r)
            self.region.append((ids, cKDTree(centre[ids]), float(self.radius[ids].max(initial=0))))
        self.centre = centre

    def near(self, r: int, centre: np.ndarray, radius: float) -> np.ndarray:
        """The tetrahedra of region ``r`` whose bounding spheres meet the ball
        ``(centre, radius)`` (global coordinates)."""
        ids, tree, widest = self.region[r]
        cand = ids[tree.query_ball_point(centre, radius + widest)]
        keep = np.linalg.norm(self.centre[cand] - centre, axis=1) <= radius + self.radius[cand]
        return cand[keep]

    def cut(self, poly: Polytope, ids: np.ndarray, x0: np.ndarray,
            s: float) -> tuple[list, np.ndarray]:
        """The pieces of ``poly`` (local frame: ``(x - x0) / s``) inside the tetrahedra ``ids``.

        Returns
        -------
        pieces : list of Polytope
            One per tetrahedron that ``poly`` meets in a volume.
        joins : (j, 4) int64 ndarray
            The face keys of the flat tetrahedra among ``ids`` (no piece: they join
            the pieces on their faces).
        """
        x = (self.points[self.tets[ids]] - x0) / s                       # (k, 4, 3)
        six_v = np.einsum("kj,kj->k", x[:, 1] - x[:, 0],
                          np.cross(x[:, 2] - x[:, 0], x[:, 3] - x[:, 0]))
        flat = np.abs(six_v) <= _FLAT
        # the tetrahedra's outward planes, and poly's
        a, b, c = (x[:, _FACES[:, q]] for q in range(3))                   # (k, 4, 3)
        normal = np.cross(b - a, c - a)
        normal = np.where((six_v < 0)[:, None, None], -normal, normal)
        normal /= np.maximum(np.linalg.norm(normal, axis=2), 1e-300)[..., None]
        offset = np.einsum("kfj,kfj->kf", normal, a)
        planes = [pl for _, pl in poly.faces]
        pn = np.array([pl.normal for pl in planes]).reshape(-1, 3)
        po = np.array([pl.offset for pl in planes])
        beyond = np.einsum("kvj,fj->kfv", x, pn) - po[:, None]             # (k, f, 4)
        apart = (beyond >= -_ON).all(axis=2).any(axis=1)                   # a plane of poly
        side = np.einsum("vj,kfj->kfv", poly.vertices, normal) - offset[..., None]
        apart |= (side.min(axis=2) >= -_ON).any(axis=1)                    # a tetrahedron's
        pieces = []
        for k in np.flatnonzero(~apart & ~flat).tolist():
            t = int(ids[k])
            tags = [("f", int(self.boundary[t, f])) if self.boundary[t, f] >= 0
                    else ("t", int(self.face_key[t, f])) for f in range(4)]
            turn = _FACES if six_v[k] > 0 else _FACES[:, ::-1]   # counter-clockwise outside
            piece = Polytope(x[k], [(turn[f], Plane(normal[k, f], float(offset[k, f]), tags[f]))
                                    for f in range(4)])
            for f in np.flatnonzero(beyond[k].max(axis=1) > _ON).tolist():
                piece = piece.clip(planes[f])
                if piece is None:
                    break
            if piece is not None:
                pieces.append(piece)
        joins = self.face_key[ids[flat & ~apart]]
        return pieces, joins


def open_facets(pieces: list) -> tuple[np.ndarray, np.ndarray]:
    """Fan triangles ``(q, 3, 3)`` and outward normals ``(q, 3)`` of the pieces' faces that
    are not between two tetrahedra of the region (bisectors and boundary faces)."""
    tris, normals = [], []
    for p in pieces:
        for idx, pl in p.faces:
            if pl.tag[0] == "t":
                continue
            x = p.vertices[idx]
            for k in range(1, len(idx) - 1):
                tris.append((x[0], x[k], x[k + 1]))
                normals.append(pl.normal)
    if not tris:
        return np.zeros((0, 3, 3)), np.zeros((0, 3))
    return np.array(tris), np.array(normals)


def connected(pieces: list, joins: np.ndarray) -> bool:
    """Whether the pieces form one body through the internal faces they share (a flat
    tetrahedron's faces, rows of ``joins``, all join)."""
    parent: dict = {}

    def root(a):
        while parent.setdefault(a, a) != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    def union(a, b):
        parent[root(a)] = root(b)

    for k, p in enumerate(pieces):
        root(("p", k))
        for _, pl in p.faces:
            if pl.tag[0] == "t":
                union(("p", k), pl.tag)
    for row in joins.tolist():
        for key in row[1:]:
            union(("t", row[0]), ("t", key))
    return len({root(("p", k)) for k in range(len(pieces))}) <= 1
