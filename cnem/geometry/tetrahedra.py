"""Boundary-conforming Delaunay tetrahedrisation of a 3-D node cloud (scipy's Qhull).

Every boundary (and interface) triangle becomes a face of the tetrahedrisation:

1. Qhull's Delaunay tetrahedrisation of the nodes;
2. a boundary face missing only because of a tie (four cospherical nodes, a lattice
   square triangulated the other way) is recovered by re-triangulating the
   tetrahedra around the crossing diagonal (a cone from the face's far vertex;
   accepted only when it tiles the same volume with empty circumspheres);
3. a face still missing is split at its circumcentre (or at the midpoint of its
   longest edge when the circumcentre falls outside it): the new nodes are boundary
   nodes, returned after the input points, and the faces are refined. Qhull runs
   again, at most ``max_rounds`` times. No interior Steiner point is ever added.

Tetrahedra outside the body are removed by a walk: tetrahedra connected through
faces that are not boundary faces form components, and each component takes the
region that the boundary faces' orientation names on its side.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import Delaunay

from ..errors import GeometryError

__all__ = ["Tetrahedrisation", "conforming_tetrahedra", "signed_volumes", "region_volumes",
           "tet_neighbors"]

#: The faces of a tetrahedron (a, b, c, d), each opposite one vertex.
_FACES = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]])
#: Relative tolerance of the tie tests (cospherical, coplanar), in units of the model's size.
_TIE = 1e-8


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
        Positively oriented tetrahedra inside the body (zero-volume slivers of
        cospherical nodes may occur).
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


def signed_volumes(points: np.ndarray, tets: np.ndarray) -> np.ndarray:
    """Signed volumes ``(t,)`` of tetrahedra ``(t, 4)``, relative to their first vertex."""
    a = points[tets[:, 0]]
    return np.einsum("ij,ij->i", points[tets[:, 1]] - a,
                     np.cross(points[tets[:, 2]] - a, points[tets[:, 3]] - a)) / 6.0


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


def _face_keys(tri: np.ndarray, n: int) -> np.ndarray:
    s = np.sort(tri, axis=1).astype(np.int64)
    return (s[:, 0] * n + s[:, 1]) * n + s[:, 2]


def tet_neighbors(tets: np.ndarray, n: int) -> np.ndarray:
    """Neighbour ``(t, 4)`` across the face opposite each vertex, -1 if none.

    Parameters
    ----------
    tets : (t, 4) int ndarray
    n : int
        Number of nodes (``tets`` index ``0 .. n-1``).
    """
    keys = _face_keys(tets[:, _FACES].reshape(-1, 3), n)
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
    """Tied boundary faces recovered by re-coning the tetrahedra around a diagonal."""

    def __init__(self, points, tets, watched, scale):
        self.points, self.scale = points, scale
        self.tets = [tuple(t) for t in tets.tolist()]
        self.alive = [True] * len(self.tets)
        self.solid = _solid(points, tets).tolist()
        self.star: dict[int, set[int]] = {int(v): set() for v in watched}
        flat = tets.ravel()
        hit = np.flatnonzero(np.isin(flat, watched))
        for pos in hit.tolist():
            self.star[int(flat[pos])].add(pos // 4)

    def _add(self, tet, solid):
        k = len(self.tets)
        self.tets.append(tet)
        self.alive.append(True)
        self.solid.append(solid)
        for v in tet:
            if v in self.star:
                self.star[v].add(k)

    def _remove(self, k):
        self.alive[k] = False
        for v in self.tets[k]:
            if v in self.star:
                self.star[v].discard(k)

    def _faces_at(self, a):
        """Faces (as frozensets) of the tetrahedra at ``a`` that contain ``a``."""
        out = set()
        for k in self.star.get(a, ()):
            t = self.tets[k]
            if not self.solid[k]:
                continue
            rest = [v for v in t if v != a]
            for i in range(3):
                out.add(frozenset((a, rest[i], rest[(i + 1) % 3])))
        return out

    def recover(self, face) -> bool:
        """Try to make ``face`` (three node indices) a face; True when it is one."""
        face = [int(v) for v in face]
        for i in range(3):
            a, b, d = face[i], face[(i + 1) % 3], face[(i + 2) % 3]
            if a not in self.star:
                return False
            at_a = self._faces_at(a)
            if frozenset(face) in at_a:
                return True
            ends_b = {next(iter(f - {a, b})) for f in at_a if b in f}
            ends_d = {next(iter(f - {a, d})) for f in at_a if d in f}
            for c in sorted(ends_b & ends_d):
                if c in (b, d) or c not in self.star:
                    continue
                if self._flip(a, c, b, d):
                    return True
        return False

    def _flip(self, a, c, b, d) -> bool:
        """Replace the tetrahedra around edge ``a-c`` by cones from ``b`` (tie only)."""
        p = self.points
        s = self.scale
        if abs(np.dot(p[c] - p[a], np.cross(p[b] - p[a], p[d] - p[a]))) > _TIE * s ** 3:
            return False                       # a, b, c, d not coplanar: no tie
        ring = sorted(self.star[a] & self.star[c])
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
        verts = np.unique(old)
        for apex in (b, d):                        # a cone from either end of the diagonal
            caps = [f for f, m in count.items() if m == 1 and not {a, c} <= f and apex not in f]
            new = np.array([[apex, *sorted(f)] for f in caps], dtype=np.int64).reshape(-1, 4)
            v_new = np.abs(signed_volumes(p, new)).sum()
            # an overlap would differ by a tetrahedron
            if len(new) and abs(v_new - v_old) <= 1e-6 * v_old and _empty_spheres(p, new, verts, s):
                break
        else:
            return False
        for k in ring:
            self._remove(k)
        for t, solid in zip(new.tolist(), _solid(p, new).tolist()):
            self._add(tuple(t), solid)
        return True

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


def _split(points, faces, face_regions, missing):
    """Split the ``missing`` faces (indices into ``faces``); return the refined arrays."""
    pts = list(points)
    fl = [tuple(f) for f in faces.tolist()]
    rl = [tuple(r) for r in face_regions.tolist()]
    for f in missing.tolist():
        tri = fl[f]
        if tri is None:
            continue
        x = np.array([pts[v] for v in tri])
        e1, e2 = x[1] - x[0], x[2] - x[0]
        nrm = np.cross(e1, e2)
        n2 = nrm @ nrm
        centre = x[0] + (np.cross(nrm, e1) * (e2 @ e2) + np.cross(e2, nrm) * (e1 @ e1)) / (2 * n2)
        bary = np.linalg.lstsq(np.column_stack([e1, e2]), centre - x[0], rcond=None)[0]
        inside = bary.min() > 0.05 and bary.sum() < 0.95
        k = len(pts)
        if inside:
            pts.append(centre)
            fl[f] = None
            for i in range(3):
                fl.append((tri[i], tri[(i + 1) % 3], k))
                rl.append(rl[f])
            continue
        lengths = [np.sum((x[(i + 1) % 3] - x[i]) ** 2) for i in range(3)]
        i = int(np.argmax(lengths))
        u, v = tri[i], tri[(i + 1) % 3]
        pts.append(0.5 * (x[i] + x[(i + 1) % 3]))
        for g, other in enumerate(fl):
            if other is None or u not in other or v not in other:
                continue
            j = other.index(u)
            w = other[(j + 2) % 3]
            if other[(j + 1) % 3] != v:        # the face runs v -> u
                u2, v2, w = v, u, other[(other.index(v) + 2) % 3]
            else:
                u2, v2 = u, v
            fl[g] = None
            fl.extend([(u2, k, w), (k, v2, w)])
            rl.extend([rl[g], rl[g]])
    keep = [i for i, f in enumerate(fl) if f is not None]
    return (np.array(pts, dtype=np.float64), np.array([fl[i] for i in keep], dtype=np.int64),
            np.array([rl[i] for i in keep], dtype=np.int64))


def _delaunay(points, centre, scale):
    tri = Delaunay((points - centre) / scale)
    if len(tri.coplanar):
        dup = tri.coplanar[:, 0]
        raise GeometryError(
            f"{len(dup)} nodes are not vertices of the Delaunay tetrahedrisation (duplicates of "
            f"other nodes), first: " + ", ".join(f"{i}: {points[i].tolist()}" for i in dup[:5])
            + "; remove duplicated nodes")
    return np.ascontiguousarray(tri.simplices, dtype=np.int64)


def _solid(points, tets):
    """Which tetrahedra ``(t,)`` are not flat slivers (four coplanar nodes)."""
    x = points[tets]
    length = np.linalg.norm(x[:, None] - x[:, :, None], axis=3).max(axis=(1, 2))
    return np.abs(signed_volumes(points, tets)) > _TIE * length ** 3


def _missing_faces(points, tets, faces):
    """Faces that no solid tetrahedron has (a face of flat slivers only does not separate)."""
    n = len(points)
    tets = tets[_solid(points, tets)]
    keys = np.unique(_face_keys(tets[:, _FACES].reshape(-1, 3), n))
    return np.flatnonzero(~np.isin(_face_keys(faces, n), keys))


def _classify(points, tets, faces, face_regions):
    """Region of each tetrahedron (-1 outside), by components between boundary faces."""
    n, t = len(points), len(tets)
    slots = tets[:, _FACES].reshape(-1, 3)
    keys = _face_keys(slots, n)
    order = np.argsort(keys, kind="stable")
    sk = keys[order]
    bkeys = _face_keys(faces, n)
    pair = np.flatnonzero(sk[1:] == sk[:-1])
    inner = ~np.isin(sk[pair], bkeys)
    i0, i1 = order[pair[inner]] // 4, order[pair[inner] + 1] // 4
    # a flat sliver (four coplanar nodes) of boundary nodes may lie in an interface plane,
    # on both sides at once: it does not connect
    x = points[tets]
    length = np.linalg.norm(x[:, None] - x[:, :, None], axis=3).max(axis=(1, 2))
    flat = np.abs(signed_volumes(points, tets)) <= _TIE * length ** 3
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
        tets = _delaunay(points, centre, scale)
        missing = _missing_faces(points, tets, faces)
        if len(missing):
            fixer = _TieRecovery(points, tets, np.unique(faces[missing]), scale)
            still = [f for f in missing.tolist() if not fixer.recover(faces[f])]
            tets = fixer.result()
            missing = _missing_faces(points, tets, faces) if still else still
        if len(missing) == 0:
            break
        points, faces, face_regions = _split(points, faces, face_regions, np.asarray(missing))
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
    n_reg = int(face_regions[:, 0].max()) + 1
    want = region_volumes(points, faces, face_regions, n_reg)
    got = np.bincount(region, weights=np.abs(vol), minlength=n_reg)
    if np.abs(got - want).max() > 1e-9 * np.abs(want).sum():
        raise GeometryError(
            f"the tetrahedra's volumes per region {got.tolist()} differ from the volumes the "
            f"boundary faces enclose {want.tolist()}; check that the faces are closed, do not "
            f"intersect and are oriented outwards of boundary_face_regions[:, 0]")
    return Tetrahedrisation(points, n_input, faces, face_regions, tets, region)
