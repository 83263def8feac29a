"""The general path of the 3-D cells: exact clipping of convex polytopes.

For node ``i`` of region ``r`` the computation runs in local coordinates (``i`` at
the origin, lengths in units of its longest Delaunay edge) inside a cube of
half-side ``a`` (doubled, a bounded number of times, until the cell does not touch
it):

Only the faces of *blocking* patches (`.smooth_patches`: patches with a sharp
re-entrant edge) hide points; the faceted facets of a curved cavity or hole do not.

* when no blocking face with region beyond its plane is in reach, the cell is the
  Voronoi polytope of ``i`` among the region's nodes, within the region: if the
  faces within reach are in convex position (no vertex of one beyond another's
  plane: a box, its edges and corners, a flat interface), one convex polytope, the
  cube clipped by those faces' planes and by the bisectors that cut it, nearest
  first; else (a curved re-entrant surface nearby) the polytope cut by each of the
  region's tetrahedra it meets (`.tet_pieces`), the faces between tetrahedra
  dropped (they cancel exactly);
* otherwise (a notch, a slot, a cubic cavity nearby) visibility matters. The
  convex pieces are the cube cut to the region's side of ``i`` (or the region's
  tetrahedra in reach, when smooth re-entrant faces are near too); from them the
  shadows of the blocking faces seen from ``i`` are removed (the shadow of a
  triangle is convex: beyond its plane and inside the three planes through ``i``
  and its edges), and each nearer node ``j`` removes the part of the pieces nearer
  to ``j`` that ``j`` sees (its bisector half-space minus ``j``'s shadows). Every
  set operation leaves disjoint convex pieces, so the volume is exact. The faces
  between two pieces of the cell (on a tetrahedron face, a shadow plane, a
  bisector) cancel: per plane, the polygons of one side minus those of the other
  are the cell's boundary there (shapely in the plane), so no facet lies inside
  the cell.
"""

from __future__ import annotations

import functools

import numpy as np
import shapely
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from ..errors import GeometryError
from .polytope import _ON, Plane, Polytope, cut, subtract
from .smooth_patches import blocking_sides
from .tet_pieces import RegionTets, connected, open_facets
from .._sets import distinct

__all__ = ["GeneralCells"]

#: The cube's first half-side (local unit): most cells lie within it, and the cost of a
#: cell grows with the pieces and nodes the cube holds.
_FIRST_HALF = 0.65
#: Bound on the doublings of the cube around a cell (to ``_FIRST_HALF 2^(_GROW-1)``).
_GROW = 8
#: Vertices of a face beyond another face's plane by more than this (local unit) make
#: the neighbourhood non-convex.
_REFLEX = 1e-9
#: A tetrahedron whose edges from the node (local unit) span less than this is flat.
_FLAT = 1e-10
#: A piece whose thickness (``2 V / A``, local unit) is below this is flat: its faces lie
#: in one plane group (`_plane_groups`), where they would cancel its neighbours' faces.
_THIN = 16 * _REFLEX


class GeneralCells:
    """Cells by exact clipping, for the nodes the fast path refuses.

    Parameters
    ----------
    points : (n, 3) ndarray
    tets : (t, 4) int64 ndarray
    tet_region : (t,) int64 ndarray
    faces : (b, 3) int64 ndarray
    face_regions : (b, 2) int64 ndarray
    """

    def __init__(self, points: np.ndarray, tets: np.ndarray, tet_region: np.ndarray,
                 faces: np.ndarray, face_regions: np.ndarray):
        self.points, self.tets, self.tet_region = points, tets, tet_region
        self.faces = faces
        n_reg = int(tet_region.max()) + 1
        x = points[faces]
        normal = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
        normal /= np.linalg.norm(normal, axis=1)[:, None]
        centroid = x.mean(axis=1)
        radius = np.linalg.norm(x - centroid[:, None], axis=2).max(axis=1)
        self.face_radius = float(radius.max())
        blocking, reentrant = blocking_sides(points, faces, face_regions)
        # per region: its faces with outward normals, whether they block and whether they
        # have a re-entrant edge, its nodes
        self.region_faces, self.region_nodes = [], []
        tet_x = points[tets]
        for r in range(n_reg):
            inner, outer = face_regions[:, 0] == r, face_regions[:, 1] == r
            idx = np.flatnonzero(inner | outer)
            sign = np.where(inner[idx], 1.0, -1.0)
            mine = np.where(inner[idx], 0, 1)
            self.region_faces.append((idx, sign[:, None] * normal[idx], cKDTree(centroid[idx]),
                                      blocking[idx, mine], reentrant[idx, mine]))
            nodes = distinct(tets[tet_region == r])
            self.region_nodes.append((nodes, cKDTree(points[nodes])))
        edge_len = np.zeros(len(points))
        for a, b in ((0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)):
            d = np.linalg.norm(tet_x[:, a] - tet_x[:, b], axis=1)
            np.maximum.at(edge_len, tets[:, a], d)
            np.maximum.at(edge_len, tets[:, b], d)
        self.scale = edge_len
        order = np.argsort(tets.ravel(), kind="stable")
        self.star_tets = order // 4
        self.star_offsets = np.searchsorted(tets.ravel()[order], np.arange(len(points) + 1))

    @functools.cached_property
    def region_tets(self) -> RegionTets:
        """The region's tetrahedra with their faces' tags, built when a cell first needs
        them (only cells near a curved re-entrant surface do)."""
        return RegionTets(self.points, self.tets, self.tet_region, self.faces)

    def cell(self, i: int, r: int) -> tuple[np.ndarray, np.ndarray, float]:
        """Facet triangles ``(q, 3, 3)``, their outward normals ``(q, 3)`` and the volume of
        the cell of node ``i`` in region ``r``."""
        x0, s = self.points[i], self.scale[i]
        half = _FIRST_HALF
        for _ in range(_GROW):
            reach = np.sqrt(3.0) * half
            pieces, joins = self._pieces(i, r, x0, s, half, reach)
            if not any(pl.tag[0] == "box" for p in pieces for _, pl in p.faces):
                break
            half *= 2.0
        else:
            raise GeometryError(
                f"the cell of node {i} at {x0.tolist()} still touches its bounding cube of "
                f"half-side {half * s:.6g} after {_GROW} doublings; the region around it holds "
                f"too few nodes (is the node isolated from its region?)")
        if not pieces:
            raise GeometryError(f"node {i} at {x0.tolist()} has an empty cell in region {r}; "
                                f"it is not visible from any point of its region")
        if joins is None:
            # slivers a round-off thick (from near-tied nodes mapped far from the origin)
            # carry no facet: their volume stays in the cell's
            tri, normal = _boundary([p for p in pieces if not _is_flat(p)])
        elif connected(pieces, joins):
            tri, normal = open_facets(pieces)
        else:
            raise GeometryError(
                f"the cell of node {i} at {x0.tolist()} in region {r} falls apart into pieces "
                f"that do not meet inside the region: its Voronoi cell reaches across a hole, "
                f"gap or wall thinner than the node spacing there; refine the cloud near "
                f"{x0.tolist()} (spacing below the gap's width)")
        volume = sum(p.volume() for p in pieces) * s ** 3
        return tri * s + x0, normal, volume

    def _near_faces(self, r, x0, s, reach):
        idx, normal, tree, block, bent = self.region_faces[r]
        near = np.array(tree.query_ball_point(x0, reach * s + self.face_radius), dtype=np.int64)
        x = (self.points[self.faces[idx[near]]] - x0) / s
        return x.reshape(-1, 3, 3), normal[near], idx[near], block[near], bent[near]

    def _pieces(self, i, r, x0, s, half, reach):
        """The cell's convex pieces in the local frame, and the flat tetrahedra's face keys
        (`RegionTets.cut`) when they are pieces of the region's tetrahedra clipped only by
        bisectors (else None: their shared faces need cancelling by `_boundary`)."""
        fx, fn, fid, block, bent = self._near_faces(r, x0, s, 3.0 * reach)
        offset = np.einsum("ij,ij->i", fn, fx[:, 0])
        nodes, tree = self.region_nodes[r]
        near = nodes[tree.query_ball_point(x0, 2.0 * reach * s)]
        near = near[near != i]
        y = (self.points[near] - x0) / s
        dist = np.linalg.norm(y, axis=1)
        order = np.argsort(dist, kind="stable")
        box = Polytope.box(half)
        # only faces with some of the region beyond their plane can hide points, and of
        # those only the faces of blocking patches do (`smooth_patches`)
        corners = np.concatenate([y, fx.reshape(-1, 3)])
        hides = np.flatnonzero(block)
        hides = hides[(corners @ fn[hides].T - offset[hides] > _REFLEX).any(axis=0)]
        within = _within(fx, reach)
        if len(hides) == 0:
            return self._unblocked(r, x0, s, box, y[order], dist[order], near[order],
                                   fx[within], fn[within], offset[within], fid[within],
                                   bent[within].any())
        behind = (corners @ fn[within].T - offset[within] > _REFLEX).any(axis=0)
        if (behind & ~block[within]).any():
            # smooth re-entrant faces too: the region's tetrahedra clip it exactly
            pieces, _ = self.region_tets.cut(box, self.region_tets.near(r, x0, reach * s), x0, s)
        else:
            pieces = self._wedge(i, r, x0, s, box, fx, fn, offset, fid)
            # the others bound the region: their half-spaces clip like a convex neighbourhood's
            support = within[~behind]
            for k in _distinct_planes(fx[support], fn[support], offset[support], reach):
                k = support[k]
                plane = Plane(fn[k], float(offset[k]), ("f", int(fid[k])))
                pieces = [q for q in (p.clip(plane) for p in pieces) if q is not None]
        fx, fn, offset, fid = fx[hides], fn[hides], offset[hides], fid[hides]
        if pieces:
            corners = np.concatenate([p.vertices for p in pieces])
            for shadow in _shadows(np.zeros(3), fx, fn, offset, fid, ("i", i), corners):
                pieces = subtract(pieces, shadow)
        for k in order.tolist():
            if not pieces or 0.5 * dist[k] >= max(p.radius() for p in pieces) * (1 + 1e-12):
                break
            nearer_i = Plane(y[k] / dist[k], 0.5 * dist[k], ("b", int(near[k])))
            pieces = _claim(pieces, nearer_i, y[k], (fx, fn, offset, fid), ("j", int(near[k])))
        return pieces, None

    def _unblocked(self, r, x0, s, box, y, dist, near, fx, fn, offset, fid, bent):
        """The cell when no face in reach hides points: the node's Voronoi polytope among its
        region's nodes (``y (k, 3)`` at ``dist (k,)``, nearest first) within the region.

        When the faces ``fx`` meeting the ``box``'s ball are in convex position (no vertex
        of one beyond another's plane: a box, its edges and corners, a flat interface), that
        is the box clipped by their planes and by the bisectors: one piece; else the
        polytope is cut by the region's tetrahedra (`RegionTets.cut`), and the flat
        tetrahedra's face keys come back too. ``bent``: a face among them has a re-entrant
        edge (so they are not in convex position)."""
        planes = [] if bent else _distinct_planes(fx, fn, offset, np.inf)
        beyond = fx.reshape(-1, 3) @ fn[planes].T - offset[planes]
        convex = not bent and beyond.max(initial=-np.inf) <= _REFLEX
        poly = box
        if convex:
            for k in planes:
                poly = poly.clip(Plane(fn[k], float(offset[k]), ("f", int(fid[k]))))
                if poly is None:
                    return [], None
        u, half_dist = y / dist[:, None], 0.5 * dist
        todo = np.arange(len(dist))
        for _ in range(len(dist)):          # the bisectors that cut the polytope, nearest first
            cuts = (poly.vertices @ u[todo].T - half_dist[todo]).max(axis=0, initial=-1.0) > _ON
            todo = todo[cuts]
            if len(todo) == 0:
                break
            k = int(todo[0])
            poly = poly.clip(Plane(u[k], float(half_dist[k]), ("b", int(near[k]))))
            todo = todo[1:]
        if convex:
            return [poly], None
        centre = poly.vertices.mean(axis=0)
        ball = float(np.linalg.norm(poly.vertices - centre, axis=1).max())
        ids = self.region_tets.near(r, x0 + s * centre, s * ball)
        return self.region_tets.cut(poly, ids, x0, s)

    def _wedge(self, i, r, x0, s, box, fx, fn, offset, fid):
        """The cube cut to the region's side of node ``i``: by the planes of its faces when
        they are in convex position (an interior node has none), else into cones."""
        mine = np.flatnonzero((self.faces[fid] == i).any(axis=1))
        planes = _distinct_planes(fx[mine], fn[mine], offset[mine], np.inf)
        planes = mine[planes] if len(planes) else mine[:0]
        beyond = fx[mine].reshape(-1, 3) @ fn[planes].T - offset[planes]
        if beyond.max(initial=-np.inf) > _REFLEX:
            return self._cones(i, r, x0, s, box)
        poly = box
        for k in planes.tolist():
            poly = poly.clip(Plane(fn[k], float(offset[k]), ("f", int(fid[k]))))
            if poly is None:
                return []
        return [poly]

    def _cones(self, i, r, x0, s, box):
        """The cube cut into the cones at node ``i`` of its tetrahedra in region ``r``: disjoint
        convex pieces covering the region's side of ``i``'s neighbourhood."""
        star = self.star_tets[self.star_offsets[i]:self.star_offsets[i + 1]]
        star = star[self.tet_region[star] == r]
        pieces = []
        for t in star.tolist():
            v = self.tets[t]
            x = (self.points[v] - x0) / s
            k = int(np.flatnonzero(v == i)[0])
            e = x - x[k]
            if abs(np.linalg.det(e[[q for q in range(4) if q != k]])) <= _FLAT:
                continue                        # a flat sliver: an empty cone
            cone = box
            for m in range(4):
                if m == k:
                    continue
                f = [q for q in range(4) if q != m]
                nrm = np.cross(x[f[1]] - x[f[0]], x[f[2]] - x[f[0]])
                nrm /= np.linalg.norm(nrm)
                if nrm @ (x[m] - x[f[0]]) > 0:
                    nrm = -nrm
                a, b, c = sorted(int(v[q]) for q in f)
                cone = cone.clip(Plane(nrm, float(nrm @ x[k]), ("c", a, b, c)))
                if cone is None:
                    break
            if cone is not None:
                pieces.append(cone)
        return pieces


def _within(fx, reach):
    """Indices of the faces ``fx (f, 3, 3)`` whose bounding spheres meet the ball of radius
    ``reach`` about the origin."""
    centre = fx.mean(axis=1)
    radius = np.linalg.norm(fx - centre[:, None], axis=2).max(axis=1, initial=0.0)
    return np.flatnonzero(np.linalg.norm(centre, axis=1) <= reach + radius)


def _distinct_planes(fx, fn, offset, reach):
    """Indices of the faces within ``reach`` of the origin, one per distinct plane."""
    if len(fn) == 0:
        return []
    within = _within(fx, reach)
    key = np.round(np.column_stack([fn[within], offset[within]]) * 1e9)
    return within[np.unique(key, axis=0, return_index=True)[1]].tolist()


def _shadows(origin, fx, fn, offset, fid, who, corners):
    """The shadows (lists of planes) that the faces cast seen from ``origin`` and that
    reach some of ``corners`` (the vertices of the pieces they could cut).

    A face hides a point only if it crosses the segment from ``origin`` to it, inside the
    convex hull of ``origin`` and ``corners``: faces clear of a ball around that hull are
    dropped first."""
    hull = np.vstack([corners, origin])
    centre = 0.5 * (hull.min(axis=0) + hull.max(axis=0))
    ball = np.linalg.norm(hull - centre, axis=1).max()
    face_c = fx.mean(axis=1)
    face_r = np.linalg.norm(fx - face_c[:, None], axis=2).max(axis=1)
    keep = np.linalg.norm(face_c - centre, axis=1) <= ball + face_r + _ON
    fx, fn, offset, fid = fx[keep], fn[keep], offset[keep], fid[keep]
    side = fn @ origin - offset
    a = fx - origin                                     # (f, 3, 3) from the origin
    b = a[:, [1, 2, 0]]
    m = np.stack([a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
                  a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
                  a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]], axis=-1)   # (f, 3 edges, 3)
    norm = np.linalg.norm(m, axis=2)
    ok = (np.abs(side) > _ON * 1e3) & (norm.min(axis=1) > _ON * 1e3)
    m = m / np.where(norm > 0, norm, 1.0)[..., None]
    third = a[:, [2, 0, 1]]
    m = np.where((np.einsum("fej,fej->fe", m, third) > 0)[..., None], -m, m)
    face_n = np.where((side < 0)[:, None], -fn, fn)
    face_d = np.where(side < 0, -offset, offset)
    normals = np.concatenate([face_n[:, None], m], axis=1)          # (f, 4, 3)
    offsets = np.concatenate([face_d[:, None], m @ origin], axis=1)  # (f, 4)
    inside = np.einsum("cj,fkj->fkc", corners, normals) < offsets[..., None] - _ON
    ok &= inside.any(axis=2).all(axis=1)
    out = []
    for k in np.flatnonzero(ok).tolist():
        planes = [Plane(normals[k, 0], float(offsets[k, 0]), ("f", int(fid[k])))]
        planes += [Plane(normals[k, e + 1], float(offsets[k, e + 1]), ("e", who, int(fid[k]), e))
                   for e in range(3)]
        out.append(planes)
    return out


def _claim(pieces, nearer_i, origin_j, faces, who):
    """The pieces minus the points nearer to ``j`` that ``j`` sees."""
    out, theirs = [], []
    for p in pieces:
        mine, other = p.split(nearer_i)
        if mine is not None:
            out.append(mine)
        if other is not None:
            theirs.append(other)
    if not theirs:
        return out
    corners = np.concatenate([p.vertices for p in theirs])
    rest = theirs
    for shadow in _shadows(origin_j, *faces, who, corners):    # the parts hidden from j stay
        nxt = []
        for y in rest:
            inner, outside = cut(y, shadow)
            nxt.extend(outside)
            if inner is not None:
                out.append(inner)
        rest = nxt
        if not rest:
            break
    return out


def _boundary(pieces):
    """Triangles and outward normals of the union's boundary: faces shared by two pieces
    (same plane, opposite sides) cancel where they overlap.

    Faces are grouped by their geometric plane (`_plane_groups`), not by what made
    them: a bisector, a shadow side and a boundary face's plane can coincide (the
    shadow of a face seen from a node in its plane, beyond a re-entrant edge)."""
    faces = [(p.vertices[idx], pl) for p in pieces for idx, pl in p.faces]
    if not faces:
        return np.zeros((0, 3, 3)), np.zeros((0, 3))
    groups: dict = {}
    for (x, pl), g in zip(faces, _plane_groups([pl for _, pl in faces])):
        groups.setdefault(g, []).append((x, pl))
    tris, normals = [], []
    for polys in groups.values():
        ref = polys[0][1].normal
        plus = [x for x, pl in polys if pl.normal @ ref > 0]
        minus = [x for x, pl in polys if pl.normal @ ref <= 0]
        if not minus or not plus:
            for x, pl in polys:
                for k in range(1, len(x) - 1):
                    tris.append((x[0], x[k], x[k + 1]))
                    normals.append(pl.normal)
            continue
        for mine, other, sign in ((plus, minus, 1.0), (minus, plus, -1.0)):
            for t in _difference(mine, other, ref, polys[0][1].offset):
                tris.append(t if sign > 0 else t[[0, 2, 1]])
                normals.append(sign * ref)
    if not tris:
        return np.zeros((0, 3, 3)), np.zeros((0, 3))
    return np.array(tris), np.array(normals)


def _is_flat(piece):
    """Whether a convex piece is thinner than ``_THIN`` (``2 V / A``: a slab's thickness)."""
    tri, _ = piece.triangles()
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1).sum()
    return 2.0 * piece.volume() <= _THIN * area


def _plane_groups(planes):
    """A label ``(k,)`` per plane: planes equal up to orientation (normals and offsets to
    ``_REFLEX``, local unit) share it, whatever their tags."""
    normal = np.array([pl.normal for pl in planes])
    offset = np.array([pl.offset for pl in planes])
    aligned = np.where(normal @ normal.T < 0.0, -1.0, 1.0)
    apart = np.linalg.norm(normal[:, None, :] - aligned[..., None] * normal[None, :, :], axis=2)
    same = (apart <= _REFLEX) & (np.abs(offset[:, None] - aligned * offset[None, :]) <= _REFLEX)
    return connected_components(csr_matrix(same), directed=False)[1]


def _difference(mine, other, normal, offset):
    """Triangles ``(3, 3)`` (counter-clockwise about ``normal``) of the union of the polygons
    ``mine`` minus the union of ``other``, all lying in one plane.

    A polygon of ``mine`` that overlaps none of ``other`` (they may touch) is kept as the
    fan of its own vertices, bit for bit: its edges stay the twins of its neighbours'."""
    helper = np.eye(3)[np.argmin(np.abs(normal))]
    e1 = np.cross(normal, helper)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(normal, e1)
    base = normal * offset

    def flat(x):
        return shapely.Polygon(np.column_stack([(x - base) @ e1, (x - base) @ e2]))

    grid = 1e-13
    b = shapely.union_all([flat(x) for x in other], grid_size=grid)
    out, cut = [], []
    for x in mine:
        if shapely.intersection(flat(x), b, grid_size=grid).area <= 1e-20:
            for k in range(1, len(x) - 1):
                t = np.array([x[0], x[k], x[k + 1]])
                out.append(t if np.cross(t[1] - t[0], t[2] - t[0]) @ normal >= 0 else t[[0, 2, 1]])
        else:
            cut.append(flat(x))
    if not cut:
        return out
    rest = shapely.difference(shapely.union_all(cut, grid_size=grid), b, grid_size=grid)
    if rest.is_empty or rest.area <= 1e-20:
        return out
    for tri in shapely.get_parts(shapely.constrained_delaunay_triangles(rest)):
        xy = np.asarray(tri.exterior.coords)[:3]
        if abs(shapely.area(tri)) <= 1e-24:
            continue
        x = base + xy[:, :1] * e1 + xy[:, 1:] * e2
        if np.cross(x[1] - x[0], x[2] - x[0]) @ normal < 0:
            x = x[[0, 2, 1]]
        out.append(x)
    return out
