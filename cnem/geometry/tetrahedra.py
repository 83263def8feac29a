"""Boundary-conforming Delaunay tetrahedrisation of a 3-D node cloud (scipy's Qhull).

Every boundary (and interface) triangle becomes a face of the tetrahedrisation:

1. Qhull's Delaunay tetrahedrisation of the nodes (eight far corners added, so that
   Qhull does not merge the coplanar nodes of the cloud's hull; `_delaunay`);
2. a boundary face missing only because of a tie (four cospherical nodes, a lattice
   square triangulated the other way) is recovered by re-triangulating the
   tetrahedra around the crossing diagonal (a cone from the face's far vertex;
   accepted only when it tiles the same volume with empty circumspheres);
3. a face still missing is split (`face_refinement.refine_faces`: at its circumcentre,
   or at an edge's midpoint; its planar patch flipped back to Delaunay): the new nodes
   are boundary nodes, returned after the input points. Qhull runs again, at most
   ``max_rounds`` times. No interior Steiner point is ever added;
4. a flat sliver (four coplanar, cocircular nodes: Qhull's tie on a lattice square)
   holds both diagonals of its quadrilateral, one towards each side. The tetrahedra
   around one diagonal are re-coned from an end of the other (step 2's flip), so that
   both sides share one diagonal, and the sliver goes; the side whose faces are
   boundary faces is kept, and no boundary face is flipped away.

Tetrahedra outside the body are removed by a walk: tetrahedra connected through
faces that are not boundary faces form components, and each component takes the
region that the boundary faces' orientation names on its side.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import numpy as np
from numpy.typing import ArrayLike
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import Delaunay

from .._sets import distinct, isin
from ..errors import GeometryError
from ._kernels import solid_tetrahedra
from .face_refinement import refine_faces

__all__ = ["Tetrahedrisation", "conforming_tetrahedra", "signed_volumes", "region_volumes",
           "tet_neighbors"]

#: The faces of a tetrahedron (a, b, c, d), each opposite one vertex.
_FACES = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]])
#: Relative tolerance of the tie tests (cospherical, coplanar), in units of the model's size.
_TIE = 1e-8
#: Half-width of the cube whose corners Qhull gets beside the nodes (`_delaunay`), in units
#: of the nodes' bounding-box diagonal (the nodes lie within 1/2 of its centre).
_FAR = 4.0
#: The most nodes for which `_face_keys` packs a triangle's nodes directly (``n^3 <= 2^63``).
_DIRECT_KEYS = 2 ** 21

@dataclass(frozen=True)
class Tetrahedrisation:
    """A boundary-conforming Delaunay tetrahedrisation.

    Attributes
    ----------
    points : (n, 3) float64 ndarray
        The input points followed by the boundary nodes that splitting added.
    n_input : int
        How many of ``points`` were given.
    boundary_faces : (b, 3) int64 ndarray
        The boundary faces, refined where they were split, oriented like the input.
    boundary_face_regions : (b, 2) int64 ndarray
        Region inside (the normal points away from it) and region outside (-1: none).
    tetrahedra : (t, 4) int64 ndarray
        Positively oriented tetrahedra inside the body (none flat: the slivers of
        cospherical nodes are flipped away).
    tet_region : (t,) int64 ndarray
    """

    points: np.ndarray
    n_input: int
    boundary_faces: np.ndarray
    boundary_face_regions: np.ndarray
    tetrahedra: np.ndarray
    tet_region: np.ndarray

    def __repr__(self) -> str:
        return (f"<Tetrahedrisation {len(self.points)} nodes ({len(self.points) - self.n_input} "
                f"added), {len(self.tetrahedra)} tetrahedra, {len(self.boundary_faces)} boundary "
                f"faces, {int(self.tet_region.max()) + 1 if len(self.tet_region) else 0} regions>")


def _cross(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``np.cross`` of vectors on the last axis (size 3), the same arithmetic without its
    per-call overhead (the tie recovery calls it on a few vectors at a time, 500k times
    on a 5k-node sphere)."""
    return np.stack([u[..., 1] * v[..., 2] - u[..., 2] * v[..., 1],
                     u[..., 2] * v[..., 0] - u[..., 0] * v[..., 2],
                     u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]], axis=-1)


def signed_volumes(points: np.ndarray, tets: np.ndarray) -> np.ndarray:
    """Signed volumes ``(t,)`` of tetrahedra ``(t, 4)``, relative to their first vertex."""
    a = points[tets[:, 0]]
    return np.einsum("ij,ij->i", points[tets[:, 1]] - a,
                     _cross(points[tets[:, 2]] - a, points[tets[:, 3]] - a)) / 6.0


def region_volumes(points: np.ndarray, faces: np.ndarray, face_regions: np.ndarray,
                   n_regions: int) -> np.ndarray:
    """Volume ``(n_regions,)`` of each region enclosed by oriented boundary faces.

    Divergence theorem about the centre of the points' bounds, so that the sum does
    not lose digits far from the origin.
    """
    centre = 0.5 * (points.min(axis=0) + points.max(axis=0))
    p = points - centre
    v = np.einsum("ij,ij->i", p[faces[:, 0]], np.cross(p[faces[:, 1]], p[faces[:, 2]])) / 6.0
    out = np.zeros(n_regions)
    np.add.at(out, face_regions[:, 0], v)
    outer = face_regions[:, 1] >= 0
    np.add.at(out, face_regions[outer, 1], -v[outer])
    return out


def _face_keys(triangles: list[np.ndarray], n: int) -> list[np.ndarray]:
    """An int64 key ``(...)`` for each triangle ``(..., 3)`` of every array of
    ``triangles`` (indices into ``n`` nodes, in any order), equal exactly when two
    triangles, of the same array or not, have the same three nodes.

    The key is ``(a n + b) n + c`` of the sorted nodes ``a < b < c`` while ``n^3`` fits
    in int64 (``n <= 2^21``); above, the pairs ``(a, b)`` of all the arrays are numbered
    in sorted order first and the key is ``rank(a, b) n + c``.
    """
    n = int(n)
    sorted_ = [np.sort(np.asarray(t, dtype=np.int64), axis=-1) for t in triangles]
    if n <= _DIRECT_KEYS:
        return [(s[..., 0] * n + s[..., 1]) * n + s[..., 2] for s in sorted_]
    pair = np.concatenate([(s[..., 0] * n + s[..., 1]).ravel() for s in sorted_])
    order = np.argsort(pair, kind="stable")
    new = np.ones(len(pair), dtype=bool)
    np.not_equal(pair[order][1:], pair[order][:-1], out=new[1:])
    rank = np.empty(len(pair), dtype=np.int64)
    rank[order] = np.cumsum(new) - 1
    ends = np.cumsum([0] + [s[..., 0].size for s in sorted_])
    return [rank[ends[i]:ends[i + 1]].reshape(s.shape[:-1]) * n + s[..., 2]
            for i, s in enumerate(sorted_)]


def tet_neighbors(tets: np.ndarray, n: int) -> np.ndarray:
    """Neighbour ``(t, 4)`` across the face opposite each vertex, -1 if none.

    Parameters
    ----------
    tets : (t, 4) int ndarray
    n : int
        Number of nodes (``tets`` index ``0 .. n-1``).
    """
    keys, = _face_keys([tets[:, _FACES].reshape(-1, 3)], n)
    order = np.argsort(keys, kind="stable")
    pair = np.flatnonzero(keys[order][1:] == keys[order][:-1])
    a, b = order[pair], order[pair + 1]
    nb = np.full(4 * len(tets), -1, dtype=np.int64)
    nb[a], nb[b] = b // 4, a // 4
    return nb.reshape(-1, 4)


def _check_input(points, faces, face_regions):
    points = np.ascontiguousarray(points, dtype=np.float64)
    faces = np.ascontiguousarray(faces, dtype=np.int64)
    face_regions = np.ascontiguousarray(face_regions, dtype=np.int64)
    if points.ndim != 2 or points.shape[1] != 3 or len(points) < 4:
        raise GeometryError(f"points must be (n, 3) with n >= 4, got shape {points.shape}")
    if not np.isfinite(points).all():
        raise GeometryError("points must be finite; remove NaN / inf coordinates")
    if faces.ndim != 2 or faces.shape[1] != 3 or face_regions.shape != (len(faces), 2):
        raise GeometryError(f"boundary_faces must be (b, 3) and boundary_face_regions (b, 2), got "
                            f"{faces.shape} and {face_regions.shape}")
    if len(faces) and (faces.min() < 0 or faces.max() >= len(points)):
        raise GeometryError(f"boundary_faces index points 0..{len(points) - 1}, got values "
                            f"{faces.min()}..{faces.max()}; index into `points`")
    if len(faces) == 0 or face_regions[:, 0].min() < 0:
        raise GeometryError("every boundary face needs a region inside (boundary_face_regions[:, 0] "
                            ">= 0); give the faces of a closed body")
    return points, faces, face_regions


class _TieRecovery:
    """Ties resolved by re-coning the tetrahedra around a diagonal: boundary faces
    recovered (`recover`), flat slivers removed (`remove_flat`)."""

    def __init__(self, points, tets, watched, scale):
        self.points, self.scale = points, scale
        self.tets = [tuple(t) for t in tets.tolist()]
        self.alive = [True] * len(self.tets)
        #: which tetrahedra are not flat (known when they are made, never recomputed)
        self.solid = _solid(points, tets).tolist()
        self.watched = {int(v) for v in watched}
        #: flat tetrahedra that flips made (`remove_flat` with ``solid_only=False``)
        self.made_flat: list[int] = []
        self.rng = np.random.default_rng(0)
        ends = tets.ravel()
        self._order = np.argsort(ends, kind="stable")
        self._start = np.searchsorted(ends[self._order], np.arange(len(points) + 1))
        self._stars: dict[int, set[int]] = {}
        self._added: dict[int, set[int]] = {}

    def star(self, v) -> set[int]:
        """The living tetrahedra at node ``v`` (built on first use)."""
        s = self._stars.get(v)
        if s is None:
            first = self._order[self._start[v]:self._start[v + 1]] // 4
            s = {k for k in first.tolist() if self.alive[k]} | self._added.get(v, set())
            self._stars[v] = s
        return s

    def _add(self, tet, solid):
        k = len(self.tets)
        self.tets.append(tet)
        self.alive.append(True)
        self.solid.append(solid)
        for v in tet:
            self._added.setdefault(v, set()).add(k)
            if v in self._stars:
                self._stars[v].add(k)

    def _remove(self, k):
        self.alive[k] = False
        for v in self.tets[k]:
            self._added.get(v, set()).discard(k)
            if v in self._stars:
                self._stars[v].discard(k)

    def _faces_at(self, a):
        """Faces (as frozensets) of the tetrahedra at ``a`` that contain ``a``."""
        out = set()
        for k in self.star(a):
            if not self.solid[k]:
                continue
            t = self.tets[k]
            rest = [v for v in t if v != a]
            for i in range(3):
                out.add(frozenset((a, rest[i], rest[(i + 1) % 3])))
        return out

    def recover(self, face) -> bool:
        """Try to make ``face`` (three node indices) a face; True when it is one."""
        face = [int(v) for v in face]
        for i in range(3):
            a, b, d = face[i], face[(i + 1) % 3], face[(i + 2) % 3]
            if a not in self.watched:
                return False
            at_a = self._faces_at(a)
            if frozenset(face) in at_a:
                return True
            ends_b = {next(iter(f - {a, b})) for f in at_a if b in f}
            ends_d = {next(iter(f - {a, d})) for f in at_a if d in f}
            for c in sorted(ends_b & ends_d):
                if c in (b, d) or c not in self.watched:
                    continue
                if self._flip(a, c, b, d):
                    return True
        return False

    def remove_flat(self, k, keep, *, push=False) -> bool:
        """Remove the flat sliver ``k``: flip one side's tetrahedra to the other side's
        diagonal, or re-cone its whole tie (`_recone_tie`; with ``push`` flat slivers
        may be left on the tie's border, in `made_flat`, for the next tie to take);
        no face of ``keep`` (frozensets) is removed. True when done."""
        if not self.alive[k]:
            return True
        quad = self.tets[k]
        if self._remove_twins(k, keep):
            return True
        for a, c, b, d in _diagonals(self.points, quad):
            side = (frozenset((a, c, b)), frozenset((a, c, d)))
            if side[0] in keep or side[1] in keep:
                continue                       # these faces stay: flip the other side
            others = [set(self.tets[j]) for j in self.star(a) & self.star(c) if j != k]
            held = [any(f <= t for t in others) for f in side]
            if not any(held):                  # nothing on this side (the hull): drop it
                across = [set(self.tets[j]) for j in self.star(b) & self.star(d) if j != k]
                if not all(any(f <= t for t in across) for f in ({a, b, d}, {c, b, d})):
                    continue                   # nothing on the other side either
                self._remove(k)
                return True
            if all(held) and self._flip(a, c, b, d, keep=keep, solid_only=True):
                return True
        return self._recone_tie(k, keep, push)

    def _recone_tie(self, k, keep, push, max_size=256) -> bool:
        """Re-cone the whole tie around the flat sliver ``k``: the tetrahedra reached
        from it across faces not in ``keep`` whose nodes all lie on the circumsphere
        of one of its solid neighbours (a convex polytope inscribed in it, slivers
        included) become cones from one of its nodes, the first that makes no flat
        tetrahedron. True when done."""
        p, quad = self.points, set(self.tets[k])
        for f in combinations(sorted(quad), 3):
            nb = [j for j in set.intersection(*(self.star(v) for v in f)) if j != k]
            if len(nb) != 1 or not self.solid[nb[0]]:
                continue
            x = p[list(self.tets[nb[0]])]
            m = x[1:] - x[0]
            centre = x[0] + np.linalg.solve(m, 0.5 * np.einsum("ij,ij->i", m, m))
            r2 = np.sum((x[0] - centre) ** 2)
            tol = _TIE * self.scale ** 2
            tie, todo = {k}, [k]
            while todo and len(tie) <= max_size:
                t = self.tets[todo.pop()]
                for g in combinations(t, 3):
                    if frozenset(g) in keep:
                        continue
                    for j in set.intersection(*(self.star(v) for v in g)) - tie:
                        if np.abs(np.sum((p[list(self.tets[j])] - centre) ** 2, axis=1)
                                  - r2).max() <= tol:
                            tie.add(j)
                            todo.append(j)
            if len(tie) > max_size:
                continue
            if self._cone(sorted(tie), keep, push):
                return True
        return False

    def _cone(self, tie, keep, push) -> bool:
        """Replace the tetrahedra ``tie`` (a convex polytope) by cones from one of their
        nodes with no flat tetrahedron (with ``push``, the fewest flat ones, none
        holding a face of ``keep``); True when one fits."""
        p = self.points
        old = np.array([self.tets[j] for j in tie])
        count: dict[frozenset, int] = {}
        for t in old.tolist():
            for f in combinations(t, 3):
                key = frozenset(f)
                count[key] = count.get(key, 0) + 1
        if any(m == 2 and f in keep for f, m in count.items()):
            return False
        hull = [sorted(f) for f, m in count.items() if m == 1]
        v_old = np.abs(signed_volumes(p, old)).sum()
        fits = []
        for apex in distinct(old).tolist():
            new = np.array([[apex, *f] for f in hull if apex not in f], dtype=np.int64)
            flat = ~_solid(p, new) if len(new) else np.zeros(0, dtype=bool)
            if len(new) == 0 or (flat.any() and not push) or \
                    abs(np.abs(signed_volumes(p, new)).sum() - v_old) > 1e-6 * v_old or \
                    any(frozenset(f) in keep for t in new[flat].tolist() for f in combinations(t, 3)):
                continue
            fits.append((new, flat))
            if not flat.any():
                break
        if not fits:
            return False
        # pushed slivers walk at random (seeded) among the ties, so that they do not
        # go back and forth between two of them
        new, flat = fits[-1] if not fits[-1][1].any() else fits[self.rng.integers(len(fits))]
        self._replace(tie, new, flat)
        return True

    def _remove_twins(self, k, keep) -> bool:
        """Remove ``k`` and a second flat sliver of the same four nodes when the two are
        glued to each other and their other faces to the same triangles on both
        sides (so both sides already share one diagonal)."""
        quad = set(self.tets[k])
        near = set.intersection(*(self.star(v) for v in quad)) - {k}
        twins = [j for j in near if set(self.tets[j]) == quad]
        if len(twins) != 1:
            return False
        rest = near - set(twins)
        for f in combinations(sorted(quad), 3):
            held = sum(set(f) <= set(self.tets[j]) for j in rest)
            if held == 1 or (held == 0 and frozenset(f) in keep):
                return False
        self._remove(k)
        self._remove(twins[0])
        return True

    def _flip(self, a, c, b, d, *, keep=frozenset(), solid_only=False) -> bool:
        """Replace the tetrahedra around edge ``a-c`` by cones from ``b`` (tie only);
        refused when it would remove a face of ``keep`` or, with ``solid_only``,
        make a flat tetrahedron."""
        p = self.points
        s = self.scale
        if abs(np.dot(p[c] - p[a], _cross(p[b] - p[a], p[d] - p[a]))) > _TIE * s ** 3:
            return False                       # a, b, c, d not coplanar: no tie
        ring = sorted(self.star(a) & self.star(c))
        if keep and any(frozenset(f) in keep for k in ring
                        for f in combinations(self.tets[k], 3) if {a, c} <= set(f)):
            return False
        # a flat sliver of the four nodes themselves holds both diagonals: it goes
        quad = [k for k in ring if set(self.tets[k]) == {a, b, c, d}]
        solid = [k for k in ring if k not in quad]
        if not solid:
            return False
        old = np.array([self.tets[k] for k in solid])
        count: dict[frozenset, int] = {}
        for t in old.tolist():
            for f in _FACES:
                key = frozenset(t[j] for j in f)
                count[key] = count.get(key, 0) + 1
        ends = {f for f, m in count.items() if m == 1 and {a, c} <= f}
        if ends and ends != {frozenset((a, c, b)), frozenset((a, c, d))}:
            return False                       # an open ring must end at the tied pair
        v_old = np.abs(signed_volumes(p, old)).sum()
        verts = distinct(old)
        for apex in (b, d):                        # a cone from either end of the diagonal
            caps = [f for f, m in count.items() if m == 1 and not {a, c} <= f and apex not in f]
            new = np.array([[apex, *sorted(f)] for f in caps], dtype=np.int64).reshape(-1, 4)
            v_new = np.abs(signed_volumes(p, new)).sum()
            # an overlap would differ by a tetrahedron
            flat = ~_solid(p, new)
            if solid_only and flat.any() or any(frozenset(f) in keep for t in new[flat].tolist()
                                                for f in combinations(t, 3)):
                continue                       # a flat sliver would hold a face that stays
            if len(new) and abs(v_new - v_old) <= 1e-6 * v_old and _empty_spheres(p, new, verts, s):
                break
        else:
            return False
        self._replace(ring, new, flat)
        return True

    def _replace(self, old, new, flat):
        """Remove the tetrahedra ``old`` and add ``new``; the ``flat`` ones are noted."""
        for k in old:
            self._remove(k)
        for t, f in zip(new.tolist(), flat.tolist()):
            if f:
                self.made_flat.append(len(self.tets))
            self._add(tuple(t), not f)

    def result(self):
        return np.array([t for t, ok in zip(self.tets, self.alive) if ok], dtype=np.int64)


def _empty_spheres(points, tets, verts, scale):
    """True when no vertex of ``verts`` lies strictly inside the tetrahedra's circumspheres."""
    for t in tets:
        a = points[t[0]]
        m = points[t[1:]] - a
        det = np.linalg.det(m)
        if abs(det) <= _TIE * scale ** 3:
            continue                           # a flat sliver of a tie: no sphere
        rhs = 0.5 * np.einsum("ij,ij->i", m, m)
        c = np.linalg.solve(m, rhs)
        r2 = c @ c
        d2 = np.sum((points[verts] - a - c) ** 2, axis=1)
        if (d2 < r2 - _TIE * scale * scale).any():
            return False
    return True


def _diagonals(points, quad):
    """The two diagonals of the convex quadrilateral of four coplanar nodes ``quad``,
    as ``[(a, c, b, d), (b, d, a, c)]`` (``a-c`` and ``b-d`` cross); [] when the four
    are not in convex position."""
    x = points[list(quad)]
    normal = max((_cross(x[i] - x[0], x[j] - x[0]) for i, j in ((1, 2), (1, 3), (2, 3))),
                 key=lambda v: v @ v)
    for i, j, k, m in ((0, 1, 2, 3), (0, 2, 1, 3), (0, 3, 1, 2)):
        # i-j and k-m cross when each separates the other's ends
        s_km = [np.dot(_cross(x[j] - x[i], x[e] - x[i]), normal) for e in (k, m)]
        s_ij = [np.dot(_cross(x[m] - x[k], x[e] - x[k]), normal) for e in (i, j)]
        if s_km[0] * s_km[1] < 0 and s_ij[0] * s_ij[1] < 0:
            a, c, b, d = (quad[e] for e in (i, j, k, m))
            return [(a, c, b, d), (b, d, a, c)]
    return []


def _remove_flats(points, tets, faces, scale):
    """Tetrahedra ``(t', 4)`` without the flat slivers that flips can remove (see the
    module's step 4); the boundary ``faces`` all stay. A few rounds, for slivers that
    wait on their neighbours."""
    flat = np.flatnonzero(~_solid(points, tets))
    if len(flat) == 0:
        return tets
    fixer = _TieRecovery(points, tets, distinct(tets[flat]), scale)
    keep = {frozenset(f) for f in faces.tolist()}
    todo = flat.tolist()
    for _ in range(16):
        todo = [k for k in todo if not fixer.remove_flat(k, keep)]
        if not todo:
            break
        # stuck: push the slivers to their ties' borders, where the next ties may take them
        todo = [k for k in todo if not fixer.remove_flat(k, keep, push=True)]
        todo = [k for k in todo + fixer.made_flat if fixer.alive[k]]
        fixer.made_flat.clear()
    return fixer.result()


def _delaunay(points, centre, scale, far):
    """Qhull's Delaunay tetrahedra ``(t, 4)`` of ``points``, with eight far corners if
    ``far``, and which nodes ``(n,)`` a tetrahedron with a corner had.

    The nodes are moved and scaled into the ball of diameter 1. With ``far`` the corners
    of the cube ``[-_FAR, _FAR]^3`` join them: the convex hull Qhull builds is then that
    cube's, not the cloud's, whose flat faces (a box's sides: thousands of coplanar
    nodes) Qhull merges slowly (7 times its whole time on the 100k-node cantilever).
    The tetrahedra with a corner are dropped; the others have circumspheres empty of
    every node, so they are Delaunay tetrahedra of the nodes. A face on the cloud's hull
    stays a face when a sphere through it, bulging out, keeps out both the nodes inside
    and the corners (a spacing deep suffices); one with a node very close beneath it
    may go missing (its nodes are then nodes of the corners' tetrahedra): the caller
    then runs Qhull without the corners.
    """
    n = len(points)
    corners = _FAR * np.array([[i, j, k] for i in (-1.0, 1.0) for j in (-1.0, 1.0)
                               for k in (-1.0, 1.0)])
    tri = Delaunay(np.vstack([(points - centre) / scale] + ([corners] if far else [])))
    if len(tri.coplanar):
        dup = tri.coplanar[:, 0]
        raise GeometryError(
            f"{len(dup)} nodes are not vertices of the Delaunay tetrahedrisation (duplicates of "
            f"other nodes), first: " + ", ".join(f"{i}: {points[i].tolist()}" for i in dup[:5])
            + "; remove duplicated nodes")
    tets = tri.simplices
    inner = (tets < n).all(axis=1)
    by_corner = np.zeros(n + 8, dtype=bool)
    by_corner[tets[~inner].ravel()] = True
    return np.ascontiguousarray(tets[inner], dtype=np.int64), by_corner[:n]


def _solid(points, tets):
    """Which tetrahedra ``(t,)`` are not flat slivers (four coplanar nodes): ``|V| >
    _TIE L^3``, ``L`` the longest edge."""
    return solid_tetrahedra(points, np.ascontiguousarray(tets, dtype=np.int64).reshape(-1, 4),
                            _TIE)


def _missing_faces(points, tets, faces):
    """Faces that no solid tetrahedron has (a face of flat slivers only does not separate)."""
    n = len(points)
    tets = tets[_solid(points, tets)]
    keys, face_keys = _face_keys([tets[:, _FACES].reshape(-1, 3), faces], n)
    return np.flatnonzero(~isin(face_keys, keys))


def _classify(points, tets, faces, face_regions):
    """Region of each tetrahedron (-1 outside), by components between boundary faces."""
    n, t = len(points), len(tets)
    slots = tets[:, _FACES].reshape(-1, 3)
    keys, bkeys = _face_keys([slots, faces], n)
    order = np.argsort(keys, kind="stable")
    sk = keys[order]
    pair = np.flatnonzero(sk[1:] == sk[:-1])
    inner = ~isin(sk[pair], bkeys)
    i0, i1 = order[pair[inner]] // 4, order[pair[inner] + 1] // 4
    # a flat sliver (four coplanar nodes) of boundary nodes may lie in an interface plane,
    # on both sides at once: it does not connect
    flat = ~_solid(points, tets)
    on_boundary = np.zeros(n, dtype=bool)
    on_boundary[faces.ravel()] = True
    flat &= on_boundary[tets].all(axis=1)
    solid = ~flat[i0] & ~flat[i1]
    nb_flat = (i0[~solid], i1[~solid])
    i0, i1 = i0[solid], i1[solid]
    graph = coo_matrix((np.ones(len(i0)), (i0, i1)), shape=(t, t))
    n_comp, label = connected_components(graph, directed=False)
    # every slot holding a boundary face votes for the region on its tetrahedron's side
    pos = np.searchsorted(sk, bkeys)
    votes_f, votes_s = [], []
    for shift in (0, 1):
        at = np.minimum(pos + shift, len(sk) - 1)
        hit = sk[at] == bkeys
        votes_f.append(np.flatnonzero(hit))
        votes_s.append(order[at[hit]])
    vf, vs = np.concatenate(votes_f), np.concatenate(votes_s)
    solid_vote = ~flat[vs // 4]         # a flat sliver's side of a face means nothing
    vf, vs = vf[solid_vote], vs[solid_vote]
    tet, far = vs // 4, tets[vs // 4, vs % 4]
    x = points[faces[vf]]
    side = np.einsum("ij,ij->i", np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]),
                     points[far] - x[:, 0])
    region = np.where(side < 0, face_regions[vf, 0], face_regions[vf, 1])
    n_reg = int(face_regions.max()) + 2
    weight = np.zeros((n_comp, n_reg))
    np.add.at(weight, (label[tet], region + 1), np.abs(side))
    best = np.argmax(weight, axis=1)
    top = weight[np.arange(n_comp), best]
    rest = weight.sum(axis=1) - top
    bad = np.flatnonzero(rest > 1e-6 * top)
    if len(bad):
        raise GeometryError(
            f"the boundary faces do not enclose consistent regions: {len(bad)} groups of "
            f"tetrahedra lie on both sides of the faces' orientation; orient every face with its "
            f"normal pointing out of boundary_face_regions[:, 0] and close every surface")
    comp_region = np.where(top > 0, best - 1, -1)
    region = comp_region[label]
    region[flat] = -1
    return _flat_regions(region, flat, *nb_flat)


def _flat_regions(region, flat, i0, i1):
    """A flat sliver takes the region of its solid neighbours (through faces that are not
    boundary faces) when they agree, else it is dropped (it has no volume)."""
    for _ in range(8):
        todo = flat & (region < 0)
        a = np.concatenate([i0, i1])
        b = np.concatenate([i1, i0])
        take = todo[a] & (region[b] >= 0)
        if not take.any():
            break
        lo = np.full(len(region), np.iinfo(np.int64).max)
        hi = np.full(len(region), -1)
        np.minimum.at(lo, a[take], region[b[take]])
        np.maximum.at(hi, a[take], region[b[take]])
        agree = todo & (hi >= 0) & (lo == hi)
        if not agree.any():
            break
        region[agree] = hi[agree]
        flat = flat & ~agree
    return region


def _recovered(points, faces, centre, scale, far):
    """Qhull's tetrahedra (`_delaunay`), the missing faces recovered through ties and the
    flat slivers removed; the faces ``(k,)`` still missing; which nodes ``(n,)`` a
    tetrahedron with a far corner had."""
    tets, by_corner = _delaunay(points, centre, scale, far)
    missing = _missing_faces(points, tets, faces)
    for _ in range(3):                # each pass may leave a face held by a sliver only
        if len(missing):
            fixer = _TieRecovery(points, tets, distinct(faces[missing]), scale)
            for f in missing.tolist():
                fixer.recover(faces[f])
            tets = fixer.result()
        before = tets
        tets = _remove_flats(points, tets, faces, scale)
        if len(missing) or tets is not before:        # else nothing changed
            missing = _missing_faces(points, tets, faces)
        if len(missing) == 0:
            break
    return tets, missing, by_corner


def conforming_tetrahedra(points: ArrayLike, boundary_faces: ArrayLike,
                          boundary_face_regions: ArrayLike, *,
                          max_rounds: int = 8) -> Tetrahedrisation:
    """Delaunay tetrahedrisation of ``points`` that contains every boundary face.

    Parameters
    ----------
    points : (n, 3) array_like
    boundary_faces : (b, 3) array_like of int
        Triangles into ``points`` tiling every boundary and interface, oriented so
        that the normal (right-hand rule) points out of ``boundary_face_regions[:, 0]``.
    boundary_face_regions : (b, 2) array_like of int
        Region inside each face and region on its other side (-1: outside the body).
    max_rounds : int, optional
        Bound on the rounds of face splitting and re-tetrahedrisation.

    Returns
    -------
    Tetrahedrisation

    Raises
    ------
    GeometryError
        Duplicated nodes, faces that enclose no consistent region, faces still missing
        after ``max_rounds`` rounds, or tetrahedra whose volume differs from the
        volume the faces enclose.
    """
    points, faces, face_regions = _check_input(points, boundary_faces, boundary_face_regions)
    n_input = len(points)
    lo, hi = points.min(axis=0), points.max(axis=0)
    centre, scale = 0.5 * (lo + hi), float(np.linalg.norm(hi - lo))
    for _ in range(max_rounds):
        # far corners first (fast); without them when faces are missing, before splitting
        for far in (True, False):
            tets, missing, by_corner = _recovered(points, faces, centre, scale, far)
            if not by_corner[faces[missing]].all(axis=1).any():
                break                 # no missing face where the corners' tetrahedra reach
        if len(missing) == 0:
            break
        points, faces, face_regions = refine_faces(points, faces, face_regions, missing)
    else:
        raise GeometryError(
            f"{len(missing)} boundary faces are still not faces of the Delaunay tetrahedrisation "
            f"after {max_rounds} rounds of splitting, first "
            + ", ".join(str(points[faces[f]].tolist()) for f in missing[:3])
            + "; sample the boundary more finely near these faces or raise max_rounds")
    region = _classify(points, tets, faces, face_regions)
    keep = region >= 0
    tets, region = tets[keep], region[keep]
    vol = signed_volumes(points, tets)
    flip = vol < 0
    tets[flip] = tets[flip][:, [0, 1, 3, 2]]
    n_reg = int(face_regions.max()) + 1
    want = region_volumes(points, faces, face_regions, n_reg)
    got = np.bincount(region, weights=np.abs(vol), minlength=n_reg)
    if np.abs(got - want).max() > 1e-9 * np.abs(want).sum():
        raise GeometryError(
            f"the tetrahedra's volumes per region {got.tolist()} differ from the volumes the "
            f"boundary faces enclose {want.tolist()}; check that the faces are closed, do not "
            f"intersect and are oriented outwards of boundary_face_regions[:, 0]")
    return Tetrahedrisation(points, n_input, faces, face_regions, tets, region)
