"""Convex polytopes clipped by planes: the exact general path of the 3-D cells.

A `Polytope` is a convex polyhedron given by its vertices and its faces, each face
a polygon (vertex indices counter-clockwise seen from outside) lying in a tagged
plane. `Polytope.clip` keeps the part on one side of a plane and closes the cut by
a new face, so a cell is built exactly by successive half-spaces (bisectors,
boundary planes, shadow planes); `subtract` removes a convex polytope given by its
planes, leaving disjoint convex pieces. Coordinates are local (a node at the origin,
lengths of order one): the tolerance is relative.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from .._sets import distinct

__all__ = ["Polytope", "Plane", "cut", "subtract"]

#: Distance (in the local unit) below which a vertex counts as on a cutting plane.
_ON = 1e-12


@dataclass(frozen=True)
class Plane:
    """The half-space ``normal . x <= offset``, tagged by what made it.

    ``tag`` is hashable and the same for both orientations of one plane (a
    bisector, a boundary face, a shadow side, a tetrahedron face).
    """

    normal: np.ndarray
    offset: float
    tag: tuple

    def flipped(self) -> Plane:
        return Plane(-self.normal, -self.offset, self.tag)


@dataclass(frozen=True)
class Polytope:
    """A convex polyhedron.

    Attributes
    ----------
    vertices : (v, 3) ndarray
    faces : list of (int ndarray, Plane)
        Each face's vertex indices (counter-clockwise from outside) and its plane,
        oriented with the normal pointing outwards.
    """

    vertices: np.ndarray
    faces: list

    @classmethod
    def box(cls, half: float) -> Polytope:
        """The cube ``[-half, half]^3`` (faces tagged ``("box", k)``)."""
        v = half * np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)],
                            dtype=float)
        quads = [([0, 1, 3, 2], (-1, 0, 0)), ([4, 6, 7, 5], (1, 0, 0)), ([0, 4, 5, 1], (0, -1, 0)),
                 ([2, 3, 7, 6], (0, 1, 0)), ([0, 2, 6, 4], (0, 0, -1)), ([1, 5, 7, 3], (0, 0, 1))]
        faces = [(np.array(q), Plane(np.array(n, dtype=float), half, ("box", k)))
                 for k, (q, n) in enumerate(quads)]
        return cls(v, faces)

    @classmethod
    def tetrahedron(cls, x: np.ndarray, tags: list) -> Polytope:
        """The tetrahedron of vertices ``x (4, 3)`` (any orientation); ``tags[k]`` names the
        face opposite vertex ``k``."""
        x = np.asarray(x, dtype=float)
        if np.dot(x[1] - x[0], np.cross(x[2] - x[0], x[3] - x[0])) < 0:
            x, tags = x[[0, 1, 3, 2]], [tags[0], tags[1], tags[3], tags[2]]
        faces = []
        for k, f in enumerate(([1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1])):
            n = np.cross(x[f[1]] - x[f[0]], x[f[2]] - x[f[0]])
            n /= np.linalg.norm(n)
            faces.append((np.array(f), Plane(n, float(n @ x[f[0]]), tags[k])))
        return cls(x, faces)

    def clip(self, plane: Plane) -> Polytope | None:
        """The part with ``plane.normal . x <= plane.offset``; None when empty or flat."""
        s = self.vertices @ plane.normal - plane.offset
        if s.max() <= _ON:
            return self
        if s.min() >= -_ON:
            return None
        verts = list(self.vertices)
        made: dict[tuple[int, int], int] = {}
        cap: list[int] = [int(i) for i in np.flatnonzero(np.abs(s) <= _ON)]
        faces = []
        for idx, pl in self.faces:
            out = []
            m = len(idx)
            for k in range(m):
                a, b = int(idx[k]), int(idx[(k + 1) % m])
                if s[a] <= _ON:
                    out.append(a)
                if (s[a] < -_ON and s[b] > _ON) or (s[a] > _ON and s[b] < -_ON):
                    key = (min(a, b), max(a, b))
                    if key not in made:
                        t = s[a] / (s[a] - s[b])
                        made[key] = len(verts)
                        verts.append(self.vertices[a] + t * (self.vertices[b] - self.vertices[a]))
                        cap.append(made[key])
                    out.append(made[key])
            if len(out) >= 3:
                faces.append((np.array(out), pl))
        verts = np.array(verts)
        spread = 0.0
        if len(cap) >= 3:
            pts = verts[cap]
            centre = pts.mean(axis=0)
            u = pts[np.argmax(np.linalg.norm(pts - centre, axis=1))] - centre
            spread = float(np.linalg.norm(u))
        if spread > _ON:                        # else the cut only grazes a point
            u /= spread
            n = plane.normal
            w = np.array([n[1] * u[2] - n[2] * u[1], n[2] * u[0] - n[0] * u[2], n[0] * u[1] - n[1] * u[0]])
            ang = np.arctan2((pts - centre) @ w, (pts - centre) @ u)
            faces.append((np.array(cap)[np.argsort(ang)], plane))
        if len(faces) < 4:
            return None
        used = distinct(np.concatenate([f for f, _ in faces]))
        renum = np.full(len(verts), -1)
        renum[used] = np.arange(len(used))
        return Polytope(verts[used], [(renum[f], pl) for f, pl in faces])

    def split(self, plane: Plane) -> tuple[Polytope | None, Polytope | None]:
        """The parts inside and outside ``plane``."""
        return self.clip(plane), self.clip(plane.flipped())

    def triangles(self) -> tuple[np.ndarray, list]:
        """Fan triangles ``(q, 3, 3)`` of the faces and the plane of each."""
        tris, planes = [], []
        for idx, pl in self.faces:
            x = self.vertices[idx]
            for k in range(1, len(idx) - 1):
                tris.append((x[0], x[k], x[k + 1]))
                planes.append(pl)
        return np.array(tris).reshape(-1, 3, 3), planes

    def volume(self) -> float:
        """Volume by the divergence theorem over the faces' fans (about the centroid)."""
        x = self.vertices - self.vertices.mean(axis=0)
        fan = np.concatenate([np.column_stack([np.full(len(idx) - 2, idx[0]), idx[1:-1], idx[2:]])
                              for idx, _ in self.faces])
        a, b, c = x[fan[:, 0]], x[fan[:, 1]], x[fan[:, 2]]
        return float((a[:, 0] * (b[:, 1] * c[:, 2] - b[:, 2] * c[:, 1])
                      + a[:, 1] * (b[:, 2] * c[:, 0] - b[:, 0] * c[:, 2])
                      + a[:, 2] * (b[:, 0] * c[:, 1] - b[:, 1] * c[:, 0])).sum()) / 6.0

    def radius(self) -> float:
        """Largest distance of a vertex from the origin."""
        return float(np.sqrt((self.vertices ** 2).sum(axis=1).max()))


def cut(piece: Polytope, planes: list) -> tuple[Polytope | None, list]:
    """The part of ``piece`` inside every plane (None if empty) and the disjoint convex
    pieces of the rest."""
    for pl in planes:                           # wholly outside one plane: untouched, unsplit
        if (piece.vertices @ pl.normal).min() >= pl.offset - _ON:
            return None, [piece]
    outside = []
    inner = piece
    for pl in planes:
        inner, outer = inner.split(pl)
        if outer is not None:
            outside.append(outer)
        if inner is None:
            break
    return inner, outside


def subtract(pieces: list, planes: list) -> list:
    """Disjoint convex pieces of ``pieces`` minus the convex set ``planes`` bound."""
    return [q for p in pieces for q in cut(p, planes)[1]]
