"""Numba kernels of the cells cut by their region's tetrahedra (`.cells3d_curved`): the
non-convex, unblocked case of `.cells3d_clip.GeneralCells` (a curved cavity's or hole's
shallow re-entrant edges nearby), done as `.tet_pieces.RegionTets.cut`,
`.tet_pieces.open_facets` and `.tet_pieces.connected` do it.

For node ``i`` (local frame: ``(x - x0) / s``) the cube of half-side ``half`` is clipped
by the bisectors of the region's nodes that cut it, nearest first (its Voronoi
polytope, `voronoi_balls`); then each tetrahedron of the region near it is clipped by
that polytope's planes, one convex piece per tetrahedron (`tet_cut_cells`). The pieces'
faces between two tetrahedra of the region (tag `TET`, ident the face's key) cancel and
are dropped; they also tell whether the pieces form one cell. Polytopes live in the
scratch arrays of `._polytope_kernels` and are clipped by its `clip`.
"""

import numba
import numpy as np

from .. import _compile  # noqa: F401  (says once when the kernels compile)
from .._parallel import parallel_kernel
from ._polytope_kernels import (BOX, DONE, GROW, ON, _box, _face_planes, bisectors, clip,
                                in_convex_position, outputs, scratch, volume, widest,
                                write_fan)
from .tetrahedra import _FACES

#: Tag of a face between two tetrahedra of the region (its ident: the face's key).
TET = 3
#: The routes of `voronoi_balls`.
CUT, CONVEX, FAILED = 0, 1, 2
#: A tetrahedron whose ``|6 V|`` (local unit) is below this is flat (`.tet_pieces._FLAT`).
FLAT = 1e-10
#: Face vertex indices counter-clockwise from outside, for each orientation of a tetrahedron.
_TURNED = (np.ascontiguousarray(_FACES.astype(np.int64)),
           np.ascontiguousarray(_FACES[:, ::-1].astype(np.int64)))


@numba.njit(cache=True)
def _voronoi(points, i, x0, s, half, near, y, dist, yid, poly, work):
    """The cube of half-side ``half`` clipped by the bisectors of the nodes ``near`` (those
    that cut it, nearest first, ``i`` skipped) into ``poly``; its counts ``(nv, nf)``
    (``nv <= 0`` when `._polytope_kernels.clip` failed)."""
    nv, nf = _box(half, *poly)
    nv, nf, _ = bisectors(points, i, x0, s, near, y, dist, yid, nv, nf, poly, work)
    return nv, nf


@numba.njit(cache=True)
def _convex_faces(points, faces, x0, s, reach, rows, table_face, table_normal, table_bent,
                  fx, fn, fo, key, fid, order):
    """Whether the faces among ``rows`` within ``reach`` are in convex position with no
    re-entrant edge (the single-polytope case of `.cells3d_clip.GeneralCells`)."""
    w, p = _face_planes(points, faces, x0, s, reach, rows, table_face, table_normal, fx, fn,
                        fo, key, fid, order)
    a = 0
    for row in rows:                    # the rows `_face_planes` kept, in their order
        if a < w and table_face[row] == fid[a]:
            if table_bent[row]:
                return False
            a += 1
    return in_convex_position(w, p, fx, fn, fo, order)


@parallel_kernel("cell_node")
def voronoi_balls(points, faces, cell_node, half, scale, face_ptr, face_rows, table_face,
                  table_normal, table_bent, near_ptr, near_ids, chunks):
    """The Voronoi polytopes of the cells in their cubes, as balls, for the search of
    the tetrahedra they meet.

    Parameters
    ----------
    points : (n, 3) float64
    faces : (b, 3) int64
    cell_node : (w,) int64
    half : (w,) float64
        Half-side of each cell's cube (local unit).
    scale : (n,) float64
        Each node's local unit.
    face_ptr, face_rows : (w + 1,), (k,) int64
        CSR of each cell's candidate faces (rows of the face table, as
        `._polytope_kernels.convex_cells` takes them).
    table_face, table_normal, table_bent : (r,), (r, 3), (r,)
        The face table: face, outward unit normal, whether it has a re-entrant edge.
    near_ptr, near_ids : (w + 1,), (m,) int64
        CSR of each cell's candidate nodes (its region's within twice the cube's
        circumradius).
    chunks : int

    Returns
    -------
    route : (w,) int8
        `CUT` (for `tet_cut_cells`), `CONVEX` (the faces in reach are in convex position:
        one polytope, `._polytope_kernels.convex_cells`) or `FAILED` (the scratch too
        small, an empty polytope: for `.cells3d_clip.GeneralCells`).
    centre : (w, 3) float64
        The mean of the polytope's vertices (global coordinates).
    radius : (w,) float64
        The largest distance of a vertex from it (global unit).
    """
    w = cell_node.shape[0]
    route = np.full(w, FAILED, dtype=np.int8)
    centre = np.zeros((w, 3))
    radius = np.zeros(w)
    nch = max(1, min(chunks, w))
    for ch in numba.prange(nch):
        first, last = ch * w // nch, (ch + 1) * w // nch
        most_f, most_n = widest(face_ptr, first, last), widest(near_ptr, first, last)
        fx, fn, fo = np.empty((most_f, 3, 3)), np.empty((most_f, 3)), np.empty(most_f)
        key, fid = np.empty((most_f, 4)), np.empty(most_f, dtype=np.int64)
        order = np.empty(most_f, dtype=np.int64)
        y, dist = np.empty((most_n, 3)), np.empty(most_n)
        yid = np.empty(most_n, dtype=np.int64)
        poly, work = scratch(6 + most_n)
        vx = poly[0]
        for t in range(first, last):
            i = cell_node[t]
            x0, s = points[i], scale[i]
            rows = face_rows[face_ptr[t]:face_ptr[t + 1]]
            if _convex_faces(points, faces, x0, s, np.sqrt(3.0) * half[t], rows, table_face,
                             table_normal, table_bent, fx, fn, fo, key, fid, order):
                route[t] = CONVEX
                continue
            nv, nf = _voronoi(points, i, x0, s, half[t], near_ids[near_ptr[t]:near_ptr[t + 1]],
                              y, dist, yid, poly, work)
            if nv <= 0:
                continue
            c = np.zeros(3)
            for v in range(nv):
                for d in range(3):
                    c[d] += vx[v, d]
            c /= nv
            top = 0.0
            for v in range(nv):
                d0, d1, d2 = vx[v, 0] - c[0], vx[v, 1] - c[1], vx[v, 2] - c[2]
                top = max(top, np.sqrt(d0 * d0 + d1 * d1 + d2 * d2))
            route[t] = CUT
            for d in range(3):
                centre[t, d] = x0[d] + s * c[d]
            radius[t] = s * top
    return route, centre, radius


@numba.njit(cache=True)
def _tet_planes(xt, tn, to):
    """The tetrahedron ``xt (4, 3)``'s outward unit normals into ``tn (4, 3)`` and offsets
    into ``to (4,)`` (`.tet_pieces.RegionTets.cut`); its ``6 V``."""
    e1 = xt[1] - xt[0]
    e2 = xt[2] - xt[0]
    e3 = xt[3] - xt[0]
    six_v = (e1[0] * (e2[1] * e3[2] - e2[2] * e3[1]) + e1[1] * (e2[2] * e3[0] - e2[0] * e3[2])
             + e1[2] * (e2[0] * e3[1] - e2[1] * e3[0]))
    for f in range(4):
        a, b, c = xt[_FACES[f, 0]], xt[_FACES[f, 1]], xt[_FACES[f, 2]]
        u, v = b - a, c - a
        n0 = u[1] * v[2] - u[2] * v[1]
        n1 = u[2] * v[0] - u[0] * v[2]
        n2 = u[0] * v[1] - u[1] * v[0]
        if six_v < 0:
            n0, n1, n2 = -n0, -n1, -n2
        size = max(np.sqrt(n0 * n0 + n1 * n1 + n2 * n2), 1e-300)
        tn[f, 0], tn[f, 1], tn[f, 2] = n0 / size, n1 / size, n2 / size
        to[f] = tn[f, 0] * a[0] + tn[f, 1] * a[1] + tn[f, 2] * a[2]
    return six_v


@numba.njit(cache=True)
def _apart(xt, tn, to, nv, nf, vx, normal, offset):
    """Whether the tetrahedron and the polytope are separated by a plane of either."""
    for f in range(nf):
        out = True
        for v in range(4):
            if (xt[v, 0] * normal[f, 0] + xt[v, 1] * normal[f, 1] + xt[v, 2] * normal[f, 2]
                    - offset[f] < -ON):
                out = False
                break
        if out:
            return True
    for f in range(4):
        out = True
        for v in range(nv):
            if vx[v, 0] * tn[f, 0] + vx[v, 1] * tn[f, 1] + vx[v, 2] * tn[f, 2] - to[f] < -ON:
                out = False
                break
        if out:
            return True
    return False


@numba.njit(cache=True)
def _root(parent, a):
    """Root of ``a`` in the union-find forest ``parent`` (halving the path)."""
    while parent[a] != a:
        parent[a] = parent[parent[a]]
        a = parent[a]
    return a


@numba.njit(cache=True)
def _connected(n_pieces, piece_of, piece_key, n_links, join_key, n_joins):
    """Whether pieces ``0 .. n_pieces - 1`` form one body: piece ``piece_of[k]`` has the
    internal face ``piece_key[k]`` (``n_links`` of them); each of the ``n_joins`` rows of
    ``join_key (j, 4)`` (a flat tetrahedron's faces) all join (`.tet_pieces.connected`)."""
    keys = np.concatenate((piece_key[:n_links], join_key[:n_joins].ravel()))
    uniq = np.unique(keys)
    parent = np.arange(n_pieces + uniq.shape[0])
    for k in range(n_links):
        a = _root(parent, piece_of[k])
        b = _root(parent, n_pieces + np.searchsorted(uniq, piece_key[k]))
        parent[a] = b
    for row in range(n_joins):
        first = n_pieces + np.searchsorted(uniq, join_key[row, 0])
        for c in range(1, 4):
            a = _root(parent, first)
            b = _root(parent, n_pieces + np.searchsorted(uniq, join_key[row, c]))
            parent[a] = b
    top = _root(parent, 0)
    for k in range(1, n_pieces):
        if _root(parent, k) != top:
            return False
    return True


@parallel_kernel("cell_node")
def tet_cut_cells(points, tets, tet_kind, tet_ident, face_key, cell_node, half, scale, near_ptr,
                  near_ids, tet_ptr, tet_ids, out_ptr, chunks):
    """The cells of ``cell_node``: each one's Voronoi polytope in its cube (as
    `voronoi_balls`) cut by the region's tetrahedra ``tet_ids`` near it.

    Parameters
    ----------
    points : (n, 3) float64
    tets : (t, 4) int64
    tet_kind, tet_ident : (t, 4) int64
        The tag of each tetrahedron face (opposite each vertex): `FACE` and the boundary
        face it lies on, or `TET` and its key ``face_key``.
    face_key : (t, 4) int64
        Each tetrahedron face's key (`.tet_pieces.RegionTets.face_key`).
    cell_node : (w,) int64
    half : (w,) float64
        Half-side of each cell's cube (local unit).
    scale : (n,) float64
    near_ptr, near_ids : (w + 1,), (m,) int64
        CSR of each cell's candidate nodes, as `voronoi_balls` took them.
    tet_ptr, tet_ids : (w + 1,), (k,) int64
        CSR of the tetrahedra of each cell's region whose bounding spheres meet its
        polytope's ball (`voronoi_balls`).
    out_ptr : (0,) or (w + 1,) int64
        Empty: count only; else where each `DONE` cell's triangles start in the output.
    chunks : int

    Returns
    -------
    status : (w,) int8
        `DONE`, `GROW` (a piece touches the cube) or `REFUSED` (no piece, pieces
        that do not meet, or the scratch too small: for `.cells3d_clip.GeneralCells`).
    ntri : (w,) int64
        Facet triangles of each `DONE` cell.
    vol : (w,) float64
        Volume of each `DONE` cell.
    tri : (q, 3, 3) float64
        With ``out_ptr``: the facet triangles (fans of the pieces' faces that are not
        between two tetrahedra, counter-clockwise from outside), cell ``c`` at
        ``tri[out_ptr[c]:out_ptr[c] + ntri[c]]``.
    normal : (q, 3) float64
        Their outward unit normals.
    """
    w = cell_node.shape[0]
    write, status, ntri, vol, tri, normal_out = outputs(w, out_ptr)
    nch = max(1, min(chunks, w))
    for ch in numba.prange(nch):
        first, last = ch * w // nch, (ch + 1) * w // nch
        most_n, most_t = widest(near_ptr, first, last), widest(tet_ptr, first, last)
        y, dist = np.empty((most_n, 3)), np.empty(most_n)
        yid = np.empty(most_n, dtype=np.int64)
        poly, work = scratch(10 + most_n)           # the cube's faces, a tetrahedron's
        piece, _ = scratch(10 + most_n)
        vx, start, idx, normal, offset, kind, ident = poly
        pvx, pstart, pidx, pnormal, poffset, pkind, pident = piece
        side, tv, made, cap, ang, used, tstart, tidx = work
        xt, tn, to = np.empty((4, 3)), np.empty((4, 3)), np.empty(4)
        piece_of, piece_key = np.empty(4 * most_t, dtype=np.int64), np.empty(4 * most_t,
                                                                            dtype=np.int64)
        join_key = np.empty((most_t, 4), dtype=np.int64)
        for c in range(first, last):
            i = cell_node[c]
            x0, s = points[i], scale[i]
            nv, nf = _voronoi(points, i, x0, s, half[c], near_ids[near_ptr[c]:near_ptr[c + 1]],
                              y, dist, yid, poly, work)
            if nv <= 0:
                continue
            n_pieces = n_links = n_joins = n_tri = 0
            total, boxed, failed = 0.0, False, False
            at = out_ptr[c] if write else 0
            for t in tet_ids[tet_ptr[c]:tet_ptr[c + 1]]:
                for v in range(4):
                    for d in range(3):
                        xt[v, d] = (points[tets[t, v], d] - x0[d]) / s
                six_v = _tet_planes(xt, tn, to)
                if _apart(xt, tn, to, nv, nf, vx, normal, offset):
                    continue
                if abs(six_v) <= FLAT:
                    join_key[n_joins] = face_key[t]
                    n_joins += 1
                    continue
                turn = _TURNED[0] if six_v > 0 else _TURNED[1]
                pvx[:4] = xt
                for f in range(4):
                    pstart[f] = 3 * f
                    pidx[3 * f:3 * f + 3] = turn[f]
                    pnormal[f] = tn[f]
                    poffset[f], pkind[f], pident[f] = to[f], tet_kind[t, f], tet_ident[t, f]
                pstart[4] = 12
                pv, pf = 4, 4
                for f in range(nf):
                    top = -np.inf
                    for v in range(4):
                        top = max(top, xt[v, 0] * normal[f, 0] + xt[v, 1] * normal[f, 1]
                                  + xt[v, 2] * normal[f, 2] - offset[f])
                    if top <= ON:
                        continue
                    pv, pf = clip(pv, pf, pvx, pstart, pidx, pnormal, poffset, pkind, pident,
                                  normal[f], offset[f], kind[f], ident[f], side, tv, made, cap,
                                  ang, used, tstart, tidx)
                    if pv <= 0:
                        break
                if pv < 0:
                    failed = True
                    break
                if pv == 0:
                    continue
                total += volume(pv, pf, pvx, pstart, pidx)
                for f in range(pf):
                    if pkind[f] == BOX:
                        boxed = True
                    if pkind[f] == TET:
                        piece_of[n_links], piece_key[n_links] = n_pieces, pident[f]
                        n_links += 1
                        continue
                    n_tri += pstart[f + 1] - pstart[f] - 2
                    if write:
                        at = write_fan(f, pvx, pstart, pidx, pnormal, s, x0, tri, normal_out, at)
                n_pieces += 1
            if failed or n_pieces == 0:
                continue
            if boxed:
                status[c] = GROW
            elif _connected(n_pieces, piece_of, piece_key, n_links, join_key, n_joins):
                status[c] = DONE
                ntri[c] = n_tri
                vol[c] = total * s ** 3
    return status, ntri, vol, tri, normal_out
