"""Nodes on the surface of a `Domain3D` and the triangles between them.

The surface is cut into planar patches (adjacent faces in one plane with the same
regions on both sides; on a curved surface each face is its own patch). Every input
vertex is a node; the patches' borders (feature edges and region borders) get nodes
about ``h`` apart, each patch a lattice in its plane (kept half a spacing from its
border), and each patch is triangulated with ``triangle`` (constrained by its border),
so that the triangles tile every input face exactly.

>>> from cnem.geometry import box
>>> from cnem.geometry.spacing import SpacingLaw
>>> from cnem.geometry.surface_nodes import sample_surface
>>> dom = box()
>>> nodes, faces, regions, _, _ = sample_surface(dom, SpacingLaw(0.5 / dom.size))
>>> len(nodes), len(faces)
(26, 48)
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import shapely
import triangle
from scipy.spatial import cKDTree

from .. import config
from .pslg import SegmentKind
from .face_batch import fill_faces
from .spacing import SpacingLaw, count_along
from .surface_checks import edge_table
from .._sets import distinct, isin

if TYPE_CHECKING:
    from .domain3d import Domain3D

__all__ = ["surface_patches", "sample_surface"]

#: Two adjacent faces are one patch when their unit normals' dot product is above
#: ``1 - PLANAR_TOL`` (about 1.4e-5 rad) and the patch stays within the domain's
#: tolerance of its plane.
PLANAR_TOL = 1e-10


def _unit_normals(vertices, faces):
    tri = vertices[faces]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    return n / np.linalg.norm(n, axis=1)[:, None], 0.5 * np.linalg.norm(n, axis=1)


def surface_patches(vertices: np.ndarray, faces: np.ndarray, face_regions: np.ndarray,
                    tol: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Planar patches of a surface.

    Parameters
    ----------
    vertices : (k, 3) ndarray
    faces : (f, 3) int ndarray
    face_regions : (f, 2) int ndarray
    tol : float
        Largest distance of a patch's vertices from its plane.

    Returns
    -------
    patch : (f,) int64 ndarray
        The patch of each face.
    edges : (e, 2) int64 ndarray
        The surface's edges (`edge_table`).
    face_edge : (f, 3) int64 ndarray
    border : (e,) bool ndarray
        Edges on a patch's border (feature edges).
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    edges, face_edge, _ = edge_table(faces)
    normal, _ = _unit_normals(vertices, faces)
    uses = np.bincount(face_edge.ravel(), minlength=len(edges))
    order = np.argsort(face_edge.ravel(), kind="stable")
    owner = np.repeat(np.arange(len(faces)), 3)[order]
    start = np.concatenate([[0], np.cumsum(uses)])
    two = np.flatnonzero(uses == 2)
    fa, fb = owner[start[two]], owner[start[two] + 1]
    join = ((face_regions[fa] == face_regions[fb]).all(axis=1)
            & (np.einsum("ij,ij->i", normal[fa], normal[fb]) >= 1.0 - PLANAR_TOL))
    graph = coo_matrix((np.ones(join.sum()), (fa[join], fb[join])), shape=(len(faces),) * 2)
    _, patch = connected_components(graph, directed=False)
    # a patch that bends (a chain of nearly flat angles) is split back into its faces
    count = patch.max() + 1
    _, area = _unit_normals(vertices, faces)
    mean = np.zeros((count, 3))
    np.add.at(mean, patch, normal * area[:, None])
    mean /= np.linalg.norm(mean, axis=1)[:, None]
    anchor = vertices[faces[np.unique(patch, return_index=True)[1], 0]]
    off = np.abs(np.einsum("fkj,fj->fk", vertices[faces] - anchor[patch][:, None],
                           mean[patch])).max(axis=1)
    bent = np.zeros(count, dtype=bool)
    np.logical_or.at(bent, patch, off > tol)
    lone = bent[patch]
    patch = np.where(lone, count + np.arange(len(faces)), patch)
    patch = np.unique(patch, return_inverse=True)[1].astype(np.int64)
    border = np.ones(len(edges), dtype=bool)
    border[two] = patch[fa] != patch[fb]
    return patch, edges, face_edge, border


def _edge_nodes(vertices, edges, law, rng, pinned_t, pinned_edge, pin_clearance):
    """Nodes along the border edges: ``(t, edge)`` of the generated ones (``pinned`` ones
    are kept, generated ones closer than ``pin_clearance`` to them dropped)."""
    length = np.linalg.norm(vertices[edges[:, 1]] - vertices[edges[:, 0]], axis=1)
    if law.uniform:
        pieces = np.maximum(1, np.rint(length / law.h)).astype(np.int64)
        edge = np.repeat(np.arange(len(edges)), pieces - 1)
        first = np.concatenate([[0], np.cumsum(pieces - 1)])[:-1]
        j = np.arange(len(edge)) - np.repeat(first, pieces - 1) + 1
        t = j / pieces[edge]
    else:
        t, edge, pieces = [], [], np.ones(len(edges), dtype=np.int64)
        for k, (a, b) in enumerate(edges):               # bounded by the border edges
            samples, cum = count_along(vertices[a], vertices[b], law)
            pieces[k] = max(1, int(round(cum[-1])))
            t.append(np.interp(np.linspace(0, cum[-1], pieces[k] + 1)[1:-1], cum, samples))
            edge.append(np.full(pieces[k] - 1, k))
        t, edge = np.concatenate(t), np.concatenate(edge).astype(np.int64)
    if rng is not None:
        t = t + rng.uniform(-0.2, 0.2, len(t)) / pieces[edge]
    if len(pinned_t):
        key = np.lexsort((pinned_t, pinned_edge))
        pe, pt = pinned_edge[key], pinned_t[key]
        lo = np.searchsorted(pe, edge, side="left")
        hi = np.searchsorted(pe, edge, side="right")
        near = np.zeros(len(t), dtype=bool)
        for k in range(int((hi - lo).max(initial=0))):       # bounded by the pins per edge
            has = lo + k < hi
            idx = np.minimum(lo + k, len(pt) - 1)
            near |= has & (np.abs(pt[idx] - t) * length[edge] < pin_clearance)
        t, edge = t[~near], edge[~near]
    return t, edge


def _patch_frame(points, normal, border_pairs):
    """Origin and in-plane axes (u along the longest border edge, v = n x u)."""
    d = points[border_pairs[:, 1]] - points[border_pairs[:, 0]]
    u = d[np.argmax(np.einsum("ij,ij->i", d, d))]
    u = u - (u @ normal) * normal
    u /= np.linalg.norm(u)
    return points[border_pairs[0, 0]], u, np.cross(normal, u)


def _triangulate_patch(points, first_new, normal, patch_faces, segs, inner, law, rng,
                       pin_clearance):
    """Triangles of one planar patch.

    Parameters
    ----------
    points : (n, 3) ndarray
        The surface nodes on the patches' borders and the pinned ones (local frame).
    first_new : int
        The number the first new node gets.
    normal : (3,) ndarray
    patch_faces : (m, 3) int ndarray
        The input faces of the patch (vertex numbers are node numbers).
    segs : (s, 2) int ndarray
        Border pieces (node pairs).
    inner : (q,) int ndarray
        Nodes that lie inside the patch already (the user's points).
    law : SpacingLaw or None
        Spacing of the patch's lattice (None: no lattice).
    rng : numpy.random.Generator or None
        Jitter the lattice by up to 0.35 h (uniform laws).
    pin_clearance : float
        Lattice points closer than this to an inner node are dropped.

    Returns
    -------
    triangles : (t, 3) int ndarray
        Node numbers; new nodes are numbered from ``first_new`` on.
    new : (a, 3) ndarray
        New nodes (lattice points, and any point ``triangle`` had to add).
    """
    origin, u, v = _patch_frame(points, normal, segs)
    # the patch's own vertices off its border (a fan's centre) are nodes inside it too
    inner = np.setdiff1d(np.concatenate([inner, patch_faces.ravel()]), segs.ravel())
    ids = distinct(np.concatenate([segs.ravel(), inner]))
    xy = np.column_stack([(points[ids] - origin) @ u, (points[ids] - origin) @ v])
    tri2d = np.stack([np.column_stack([(points[f] - origin) @ u, (points[f] - origin) @ v])
                      for f in patch_faces.T], axis=1)
    region = shapely.union_all(shapely.polygons(tri2d))
    lattice = np.empty((0, 2))
    if law is not None:
        def lift(y):
            return origin + y[:, :1] * u + y[:, 1:] * v

        centres = None if law.uniform else np.column_stack(
            [(law.centres - origin) @ u, (law.centres - origin) @ v])
        lattice = law.lattice(xy.min(axis=0), xy.max(axis=0), lift=lift, centres=centres,
                              offset=0.0 if rng is None and law.uniform else 0.5)
        if rng is not None:
            lattice = lattice + rng.uniform(-0.35 * law.h, 0.35 * law.h, lattice.shape)
        shapely.prepare(region)
        keep = shapely.contains_xy(region, lattice[:, 0], lattice[:, 1])
        lattice = lattice[keep]
        clear = config.CLEARANCE * law(lift(lattice)) * (1 - 1e-9)
        near = shapely.dwithin(region.boundary, shapely.points(lattice), clear)
        if len(inner) and len(lattice):
            near |= cKDTree(xy[np.searchsorted(ids, inner)]).query(lattice)[0] < pin_clearance
        lattice = lattice[~near]
    local = np.full(len(points), -1)
    local[ids] = np.arange(len(ids))
    out = triangle.triangulate({"vertices": np.concatenate([xy, lattice]),
                                "segments": local[segs]}, "pQ")
    verts, tris = out["vertices"], out["triangles"]
    centroid = verts[tris].mean(axis=1)
    inside = shapely.contains_xy(region, centroid[:, 0], centroid[:, 1])
    tris = tris[inside]
    extra = verts[len(ids):]
    new = origin + extra[:, :1] * u + extra[:, 1:] * v
    number = np.concatenate([ids, first_new + np.arange(len(extra))])
    return number[tris], new


def sample_surface(dom: Domain3D, law: SpacingLaw, rng: np.random.Generator | None = None,
                   pinned: tuple | None = None, fill: bool = True,
                   pin_clearance: float | None = None) -> tuple[np.ndarray, ...]:
    """Surface nodes of a domain at the spacing of ``law``, and their triangulation.

    Parameters
    ----------
    dom : Domain3D
    law : SpacingLaw
        The spacing in the domain's local frame (`Domain3D.to_local`: lengths over its
        size).
    rng : numpy.random.Generator, optional
        Jitter the nodes (irregular clouds, uniform laws only); None for lattices.
    pinned : tuple, optional
        ``(points (q, 3), edge (q,), t (q,), patch (q,))``: the user's surface points in the
        local frame, on border edge ``edge`` at parameter ``t`` (-1 if not on one) or inside
        patch ``patch`` (-1 if not). Generated nodes keep half a spacing from them.
    fill : bool
        Generate nodes (else only the vertices and the pinned points).
    pin_clearance : float, optional
        Generated nodes closer than this to a pinned point (or a vertex inside a patch)
        are dropped; by default `cnem.config.CLEARANCE` times ``law.h``.

    Returns
    -------
    nodes : (n, 3) ndarray
        The local frame: ``dom``'s vertices, the pinned points, then the generated nodes.
    faces : (b, 3) int64 ndarray
        Oriented like the input faces.
    face_regions : (b, 2) int64 ndarray
    segments : (s, 2) int64 ndarray
        The border edges split at their nodes.
    segment_kind : (s,) int8 ndarray
        `SegmentKind`: interface where every face at the edge is an interface.
    """
    vertices = dom.local_vertices
    tol = dom.tolerance / dom.size
    patch, edges, face_edge, border = surface_patches(vertices, dom.faces, dom.face_regions, tol)
    bedges = np.flatnonzero(border)
    if pinned is None:
        pinned = (np.empty((0, 3)), np.empty(0, np.int64), np.empty(0), np.empty(0, np.int64))
    ppts, pedge, pt, ppatch = pinned
    if pin_clearance is None:
        pin_clearance = config.CLEARANCE * law.h
    on_edge = pedge >= 0
    local_edge = np.full(len(edges), -1)
    local_edge[bedges] = np.arange(len(bedges))
    t, e = _edge_nodes(vertices, edges[bedges], law, rng, pt[on_edge], local_edge[pedge[on_edge]],
                       pin_clearance)
    if not fill:
        t, e = t[:0], e[:0]
    a, b = vertices[edges[bedges[e], 0]], vertices[edges[bedges[e], 1]]
    nodes = np.concatenate([vertices, ppts, a + t[:, None] * (b - a)])
    n_fixed = len(vertices) + len(ppts)
    # chains along each border edge: its ends, its pinned points and its samples by t
    chain_edge = np.concatenate([np.arange(len(bedges)), np.arange(len(bedges)),
                                 local_edge[pedge[on_edge]], e])
    chain_t = np.concatenate([np.zeros(len(bedges)), np.ones(len(bedges)), pt[on_edge], t])
    chain_node = np.concatenate([edges[bedges, 0], edges[bedges, 1],
                                 len(vertices) + np.flatnonzero(on_edge),
                                 n_fixed + np.arange(len(t))])
    order = np.lexsort((chain_t, chain_edge))
    ce, cn = chain_edge[order], chain_node[order]
    link = ce[1:] == ce[:-1]
    segments = np.column_stack([cn[:-1][link], cn[1:][link]])
    seg_edge = bedges[ce[:-1][link]]
    interface = np.ones(len(edges), dtype=bool)
    np.logical_and.at(interface, face_edge.ravel(), np.repeat(dom.face_regions[:, 1] >= 0, 3))
    kind = np.where(interface[seg_edge], SegmentKind.INTERFACE, SegmentKind.BOUNDARY)
    # the border pieces of each patch, in the direction its faces run along them
    faces_out, regions_out, new_nodes = [], [], []
    count = len(nodes)
    normal, area = _unit_normals(vertices, dom.faces)
    by_edge = np.argsort(seg_edge, kind="stable")
    seg_start = np.searchsorted(seg_edge[by_edge], np.arange(len(edges) + 1))
    inner_of = np.argsort(ppatch, kind="stable")
    inner_start = np.searchsorted(ppatch[inner_of], np.arange(patch.max() + 2))
    plain = _plain_faces(dom.faces, patch, face_edge, border, seg_start, ppatch, area, edges,
                         vertices, law if fill else None)
    faces_out.append(dom.faces[plain])
    regions_out.append(dom.face_regions[plain])
    todo = distinct(patch[~plain])
    members = np.argsort(patch, kind="stable")
    member_start = np.searchsorted(patch[members], np.arange(patch.max() + 2))
    # single faces (curved surfaces) at a uniform spacing, with no user's point inside: at once
    batch = (member_start[todo + 1] - member_start[todo] == 1) \
        & (inner_start[todo + 1] == inner_start[todo]) & (law.uniform or not fill)
    if batch.any():
        one = members[member_start[todo[batch]]]
        piece_face, pieces = _face_pieces(dom.faces[one], face_edge[one], edges, segments,
                                          by_edge, seg_start)
        tris, tri_face, new = fill_faces(nodes, count, dom.faces[one], piece_face, pieces,
                                         law.h if fill else None, rng)
        faces_out.append(tris)
        regions_out.append(dom.face_regions[one[tri_face]])
        new_nodes.append(new)
        count += len(new)
    for p in todo[~batch]:                           # bounded by the number of patches
        mine = members[member_start[p]:member_start[p + 1]]
        pieces = []
        for f in mine:
            for k in np.flatnonzero(border[face_edge[f]]):
                ed = face_edge[f, k]
                piece = segments[by_edge[seg_start[ed]:seg_start[ed + 1]]]
                pieces.append(piece if dom.faces[f, k] == edges[ed, 0] else piece[::-1, ::-1])
        n = (normal[mine] * area[mine, None]).sum(axis=0)
        inner = len(vertices) + inner_of[inner_start[p]:inner_start[p + 1]]
        tris, new = _triangulate_patch(nodes, count, n / np.linalg.norm(n),
                                       dom.faces[mine], np.concatenate(pieces), inner,
                                       law if fill else None, rng, pin_clearance)
        faces_out.append(tris)
        regions_out.append(np.repeat(dom.face_regions[mine[:1]], len(tris), axis=0))
        new_nodes.append(new)
        count += len(new)
    nodes = np.concatenate([nodes] + new_nodes)
    return (nodes, np.concatenate(faces_out).astype(np.int64),
            np.concatenate(regions_out).astype(np.int64), segments.astype(np.int64),
            kind.astype(np.int8))


def _plain_faces(faces, patch, face_edge, border, seg_start, ppatch, area, edges, vertices, law):
    """(f,) bool: faces that are a patch of their own with no node but their corners
    (no sample on their edges, no pinned point, too small for a lattice point kept half a
    spacing from their edges): they are boundary triangles as they are."""
    size = np.bincount(patch)
    alone = size[patch] == 1
    pieces = seg_start[1:] - seg_start[:-1]
    split = (pieces[face_edge] > 1).any(axis=1)
    pinned = isin(patch, ppatch[ppatch >= 0])
    length = np.linalg.norm(vertices[edges[face_edge, 1]] - vertices[edges[face_edge, 0]],
                            axis=2).sum(axis=1)
    inradius = 2 * area / length
    roomy = np.zeros(len(faces), dtype=bool) if law is None \
        else inradius > config.CLEARANCE * law(vertices[faces].mean(axis=1)) * (1 - 1e-9)
    return alone & ~split & ~pinned & ~roomy


def _face_pieces(faces, face_edge, edges, segments, by_edge, seg_start):
    """The border pieces of single-face patches, running along each face:
    ``(face (s,), pieces (s, 2))`` with ``face`` a row of ``faces``."""
    e = face_edge.ravel()
    forward = faces.ravel() == edges[e, 0]
    count = seg_start[e + 1] - seg_start[e]
    row = np.repeat(np.arange(len(e)), count)
    j = np.arange(len(row)) - np.repeat(np.cumsum(count) - count, count)
    j = np.where(forward[row], j, count[row] - 1 - j)
    pieces = segments[by_edge[seg_start[e[row]] + j]]
    pieces = np.where(forward[row][:, None], pieces, pieces[:, ::-1])
    return row // 3, pieces
