"""Boundary faces split where a tetrahedrisation misses them, kept Delaunay in their planes.

A boundary face is a face of the Delaunay tetrahedrisation when some sphere through its
three nodes holds no other node. `refine_faces` splits the faces that are missing
(Ruppert's rule: at the circumcentre, or at the midpoint of an edge when the
circumcentre falls outside the face or on its border, or encroaches an edge that cannot
flip), then restores the Delaunay property of every planar patch by edge flips
(Lawson). Without the flips a node inserted at one face's circumcentre falls inside its
neighbours' circumcircles: they go missing in turn, and the splitting runs along the
surface without end.

Edges shared by exactly two coplanar faces with the same regions flip; feature edges,
region borders and interface borders (three or more faces) never do. The refined faces
tile the same surface, with the same orientation and regions.
"""

from __future__ import annotations

import numpy as np

__all__ = ["refine_faces"]

#: Two faces are coplanar when their unit normals' dot product is above ``1 - _COPLANAR``.
_COPLANAR = 1e-10
#: An edge flips when the far node lies inside the circumcircle by more than this
#: fraction of its squared radius (cocircular ties do not flip back and forth).
_IN_CIRCLE = 1e-9
#: A face splits at its circumcentre only when the centre's barycentric coordinates
#: exceed this: a centre on an edge (a right triangle's, on its hypotenuse) would make a
#: face of no area there, so the edge splits at its midpoint instead (the same point).
_INSIDE = 1e-9


def _circle(x):
    """Circumcentre ``(3,)`` and squared radius of the triangle ``x (3, 3)``."""
    e1, e2 = x[1] - x[0], x[2] - x[0]
    nrm = np.cross(e1, e2)
    centre = x[0] + (np.cross(nrm, e1) * (e2 @ e2) + np.cross(e2, nrm) * (e1 @ e1)) / (2 * (nrm @ nrm))
    return centre, float(np.sum((x[0] - centre) ** 2))


class _Surface:
    """Oriented faces with their regions and an edge table, refined in place."""

    def __init__(self, points, faces, face_regions):
        self.points = list(points)
        self.faces: list[tuple | None] = [tuple(f) for f in faces.tolist()]
        self.regions = [tuple(r) for r in face_regions.tolist()]
        self.edges: dict[frozenset, set[int]] = {}
        for k, f in enumerate(self.faces):
            self._index(k, f)

    def _index(self, k, f):
        for i in range(3):
            self.edges.setdefault(frozenset((f[i], f[(i + 1) % 3])), set()).add(k)

    def _add(self, face, regions) -> int:
        k = len(self.faces)
        self.faces.append(face)
        self.regions.append(regions)
        self._index(k, face)
        return k

    def _remove(self, k):
        f = self.faces[k]
        for i in range(3):
            self.edges[frozenset((f[i], f[(i + 1) % 3]))].discard(k)
        self.faces[k] = None

    def _normal(self, f):
        x = np.array([self.points[v] for v in f])
        return np.cross(x[1] - x[0], x[2] - x[0])

    def _flippable(self, edge) -> tuple[int, int] | None:
        """The two faces of ``edge`` when it may flip (two coplanar faces, same regions)."""
        pair = self.edges.get(edge, ())
        if len(pair) != 2:
            return None
        k, m = sorted(pair)
        if self.regions[k] != self.regions[m]:
            return None
        nk, nm = self._normal(self.faces[k]), self._normal(self.faces[m])
        if nk @ nm < (1 - _COPLANAR) * np.sqrt((nk @ nk) * (nm @ nm)):
            return None
        return k, m

    def split_face(self, k) -> list[int]:
        """Split face ``k`` (Ruppert's rule); the new faces' indices."""
        f = self.faces[k]
        if f is None:
            return []
        x = np.array([self.points[v] for v in f])
        centre, _ = _circle(x)
        e1, e2 = x[1] - x[0], x[2] - x[0]
        bary = np.linalg.lstsq(np.column_stack([e1, e2]), centre - x[0], rcond=None)[0]
        lengths = [float(np.sum((x[(i + 1) % 3] - x[i]) ** 2)) for i in range(3)]
        for i in range(3):                     # an edge that cannot flip, encroached
            u, v = f[i], f[(i + 1) % 3]
            mid = 0.5 * (x[i] + x[(i + 1) % 3])
            if np.sum((centre - mid) ** 2) < 0.25 * lengths[i] and \
                    self._flippable(frozenset((u, v))) is None:
                return self.split_edge(u, v)
        if bary.min() > _INSIDE and bary.sum() < 1 - _INSIDE:
            c = len(self.points)
            self.points.append(centre)
            self._remove(k)
            return [self._add((f[i], f[(i + 1) % 3], c), self.regions[k]) for i in range(3)]
        i = int(np.argmax(lengths))
        return self.split_edge(f[i], f[(i + 1) % 3])

    def split_edge(self, u, v) -> list[int]:
        """Split edge ``u-v`` at its midpoint in every face that holds it."""
        c = len(self.points)
        self.points.append(0.5 * (self.points[u] + self.points[v]))
        new = []
        for k in sorted(self.edges[frozenset((u, v))]):
            f = self.faces[k]
            j = f.index(u)
            a, b = (u, v) if f[(j + 1) % 3] == v else (v, u)
            w = f[(f.index(a) + 2) % 3]
            self._remove(k)
            new += [self._add((a, c, w), self.regions[k]), self._add((c, b, w), self.regions[k])]
        return new

    def flip_to_delaunay(self, faces, max_flips):
        """Flip edges of ``faces`` (and of the faces flips make) until each planar patch
        is Delaunay around them; at most ``max_flips`` flips."""
        todo = [frozenset((f[i], f[(i + 1) % 3])) for k in faces
                if (f := self.faces[k]) is not None for i in range(3)]
        flips = 0
        while todo and flips < max_flips:
            edge = todo.pop()
            pair = self._flippable(edge)
            if pair is None:
                continue
            k, m = pair
            fk, fm = self.faces[k], self.faces[m]
            d = next(v for v in fm if v not in edge)
            centre, r2 = _circle(np.array([self.points[v] for v in fk]))
            if np.sum((self.points[d] - centre) ** 2) >= r2 * (1 - _IN_CIRCLE):
                continue
            j = next(i for i in range(3) if fk[i] not in edge)
            c, a, b = fk[j], fk[(j + 1) % 3], fk[(j + 2) % 3]      # fk = (c, a, b)
            new = [(a, d, c), (d, b, c)]
            nrm = self._normal(fk)
            if any(self._normal(g) @ nrm <= 0 for g in new):
                continue                       # the quadrilateral is not convex
            regions = self.regions[k]
            self._remove(k)
            self._remove(m)
            for g in new:
                self._add(g, regions)
            flips += 1
            todo += [frozenset(e) for e in ((a, d), (d, b), (b, c), (c, a))]

    def arrays(self):
        keep = [k for k, f in enumerate(self.faces) if f is not None]
        return (np.array(self.points, dtype=np.float64),
                np.array([self.faces[k] for k in keep], dtype=np.int64).reshape(-1, 3),
                np.array([self.regions[k] for k in keep], dtype=np.int64).reshape(-1, 2))


def refine_faces(points: np.ndarray, faces: np.ndarray, face_regions: np.ndarray,
                 missing: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Split the ``missing`` boundary faces and flip their planar patches back to Delaunay.

    Parameters
    ----------
    points : (n, 3) float64 ndarray
    faces : (b, 3) int64 ndarray
        Oriented boundary faces into ``points``.
    face_regions : (b, 2) int64 ndarray
        Region inside and outside each face.
    missing : (k,) int ndarray
        Indices into ``faces`` of the faces to split.

    Returns
    -------
    points : (n', 3) float64 ndarray
        ``points`` followed by the new boundary nodes.
    faces : (b', 3) int64 ndarray
    face_regions : (b', 2) int64 ndarray
    """
    surface = _Surface(points, faces, face_regions)
    new = []
    for k in np.asarray(missing).tolist():
        new += surface.split_face(k)
    surface.flip_to_delaunay(new, max_flips=16 * len(surface.faces))
    return surface.arrays()
