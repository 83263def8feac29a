"""Numba kernels of the convex 3-D cells (`.cells3d_convex`): a convex polytope clipped by
planes exactly as `.polytope.Polytope.clip` does it (same vertices, faces and their
order), and many cells at once, each the cube about its node clipped by the planes of
the boundary faces in reach and by the bisectors that cut it, nearest first (the convex,
unblocked case of `.cells3d_clip.GeneralCells`).

A polytope lives in flat scratch arrays: ``vx (V, 3)`` its vertices; face ``f`` the
indices ``idx[start[f]:start[f + 1]]`` (counter-clockwise from outside), its plane
``normal[f] . x <= offset[f]`` and its tag ``(kind[f], ident[f])``: `BOX` and the
cube's face, `FACE` and the boundary face, `BISECTOR` and the other node.
"""

import numba
import numpy as np

from .. import _compile  # noqa: F401  (says once when the kernels compile)
from .._parallel import parallel_kernel

#: Distance (local unit) below which a vertex is on a cutting plane (`.polytope._ON`).
ON = 1e-12
#: Face vertices beyond another face's plane by more than this make the neighbourhood
#: non-convex (`.cells3d_clip._REFLEX`).
REFLEX = 1e-9
#: Face tags.
BOX, FACE, BISECTOR = 0, 1, 2
#: Cell statuses: clipped; grow the cube; the general path; more neighbours needed.
DONE, GROW, REFUSED, MORE = 0, 1, 2, 3
#: The cube's faces (`.polytope.Polytope.box`): vertex indices and outward axis.
_QUADS = np.array([[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4],
                   [1, 5, 7, 3]], dtype=np.int64)
_AXES = np.array([[-1, 0, 0], [1, 0, 0], [0, -1, 0], [0, 1, 0], [0, 0, -1], [0, 0, 1]],
                 dtype=np.float64)


@numba.njit(cache=True)
def _box(half, vx, start, idx, normal, offset, kind, ident):
    """The cube ``[-half, half]^3`` into the scratch arrays; its vertex and face counts."""
    v = 0
    for x in (-1.0, 1.0):
        for y in (-1.0, 1.0):
            for z in (-1.0, 1.0):
                vx[v, 0], vx[v, 1], vx[v, 2] = half * x, half * y, half * z
                v += 1
    for f in range(6):
        start[f] = 4 * f
        for k in range(4):
            idx[4 * f + k] = _QUADS[f, k]
            normal[f, k % 3] = _AXES[f, k % 3]
        offset[f], kind[f], ident[f] = half, BOX, f
    start[6] = 24
    return 8, 6


@numba.njit(cache=True)
def clip(nv, nf, vx, start, idx, normal, offset, kind, ident, pn, po, pkind, pident, side,
         tv, made, cap, ang, used, tstart, tidx):
    """Clip the polytope ``(nv, nf)`` in place by the half-space ``pn . x <= po`` tagged
    ``(pkind, pident)``, as `.polytope.Polytope.clip`; the remaining scratch arguments are
    work arrays (``side``, ``ang``, ``used`` at least ``V``; ``tv`` and ``cap`` ``V`` plus
    the edges; ``made (E, 3)``; ``tstart``, ``tidx`` as ``start``, ``idx``).

    Returns
    -------
    (nv, nf) : int, int
        The clipped polytope's counts; ``(0, 0)`` when it is empty or flat; ``(-1, -1)``
        when the scratch arrays are too small.
    """
    smax, smin = -np.inf, np.inf
    for v in range(nv):
        side[v] = vx[v, 0] * pn[0] + vx[v, 1] * pn[1] + vx[v, 2] * pn[2] - po
        smax, smin = max(smax, side[v]), min(smin, side[v])
    if smax <= ON:
        return nv, nf
    if smin >= -ON:
        return 0, 0
    ntv, nmade, ncap = nv, 0, 0
    tv[:nv] = vx[:nv]
    for v in range(nv):
        if abs(side[v]) <= ON:
            cap[ncap] = v
            ncap += 1
    nf2, pos = 0, 0
    for f in range(nf):
        first, m = start[f], start[f + 1] - start[f]
        mark = pos
        for k in range(m):
            a, b = idx[first + k], idx[first + (k + 1) % m]
            if side[a] <= ON:
                if pos >= tidx.shape[0]:
                    return -1, -1
                tidx[pos] = a
                pos += 1
            if (side[a] < -ON and side[b] > ON) or (side[a] > ON and side[b] < -ON):
                lo, hi = min(a, b), max(a, b)
                new = -1
                for e in range(nmade):
                    if made[e, 0] == lo and made[e, 1] == hi:
                        new = made[e, 2]
                        break
                if new < 0:
                    if ntv >= tv.shape[0] or nmade >= made.shape[0] or pos >= tidx.shape[0]:
                        return -1, -1
                    t = side[a] / (side[a] - side[b])
                    for c in range(3):
                        tv[ntv, c] = vx[a, c] + t * (vx[b, c] - vx[a, c])
                    made[nmade, 0], made[nmade, 1], made[nmade, 2] = lo, hi, ntv
                    nmade += 1
                    cap[ncap] = ntv
                    ncap += 1
                    new = ntv
                    ntv += 1
                if pos >= tidx.shape[0]:
                    return -1, -1
                tidx[pos] = new
                pos += 1
        if pos - mark >= 3:
            tstart[nf2] = mark
            for c in range(3):
                normal[nf2, c] = normal[f, c]
            offset[nf2], kind[nf2], ident[nf2] = offset[f], kind[f], ident[f]
            nf2 += 1
        else:
            pos = mark
    spread = 0.0
    c0 = c1 = c2 = u0 = u1 = u2 = 0.0
    if ncap >= 3:
        for k in range(ncap):
            c0 += tv[cap[k], 0]
            c1 += tv[cap[k], 1]
            c2 += tv[cap[k], 2]
        c0, c1, c2 = c0 / ncap, c1 / ncap, c2 / ncap
        best = -1.0
        for k in range(ncap):
            d0, d1, d2 = tv[cap[k], 0] - c0, tv[cap[k], 1] - c1, tv[cap[k], 2] - c2
            d = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            if d > best:
                best, u0, u1, u2 = d, d0, d1, d2
        spread = np.sqrt(u0 * u0 + u1 * u1 + u2 * u2)
    if spread > ON:
        if nf2 >= tstart.shape[0] - 1 or pos + ncap > tidx.shape[0]:
            return -1, -1
        u0, u1, u2 = u0 / spread, u1 / spread, u2 / spread
        w0, w1, w2 = pn[1] * u2 - pn[2] * u1, pn[2] * u0 - pn[0] * u2, pn[0] * u1 - pn[1] * u0
        for k in range(ncap):
            d0, d1, d2 = tv[cap[k], 0] - c0, tv[cap[k], 1] - c1, tv[cap[k], 2] - c2
            ang[k] = np.arctan2(d0 * w0 + d1 * w1 + d2 * w2, d0 * u0 + d1 * u1 + d2 * u2)
        order = np.argsort(ang[:ncap])
        tstart[nf2] = pos
        for k in range(ncap):
            tidx[pos] = cap[order[k]]
            pos += 1
        normal[nf2, 0], normal[nf2, 1], normal[nf2, 2] = pn[0], pn[1], pn[2]
        offset[nf2], kind[nf2], ident[nf2] = po, pkind, pident
        nf2 += 1
    if nf2 < 4:
        return 0, 0
    tstart[nf2] = pos
    used[:ntv] = -1
    for k in range(pos):
        used[tidx[k]] = 0
    nv2 = 0
    for v in range(ntv):                        # renumbered in the old order
        if used[v] == 0:
            used[v] = nv2
            for c in range(3):
                vx[nv2, c] = tv[v, c]
            nv2 += 1
    for k in range(pos):
        idx[k] = used[tidx[k]]
    start[:nf2 + 1] = tstart[:nf2 + 1]
    return nv2, nf2


@numba.njit(cache=True)
def volume(nv, nf, vx, start, idx):
    """Volume of the polytope by its faces' fans about its vertices' mean (`.polytope`)."""
    m0 = m1 = m2 = 0.0
    for v in range(nv):
        m0, m1, m2 = m0 + vx[v, 0], m1 + vx[v, 1], m2 + vx[v, 2]
    m0, m1, m2 = m0 / nv, m1 / nv, m2 / nv
    total = 0.0
    for f in range(nf):
        p = idx[start[f]]
        a0, a1, a2 = vx[p, 0] - m0, vx[p, 1] - m1, vx[p, 2] - m2
        for k in range(start[f] + 1, start[f + 1] - 1):
            q, r = idx[k], idx[k + 1]
            b0, b1, b2 = vx[q, 0] - m0, vx[q, 1] - m1, vx[q, 2] - m2
            c0, c1, c2 = vx[r, 0] - m0, vx[r, 1] - m1, vx[r, 2] - m2
            total += (a0 * (b1 * c2 - b2 * c1) + a1 * (b2 * c0 - b0 * c2)
                      + a2 * (b0 * c1 - b1 * c0))
    return total / 6.0


@numba.njit(cache=True)
def _key_less(a, b):
    """Lexicographic order of two plane keys (rows of 4 floats), as `numpy.unique`'s rows."""
    for c in range(4):
        if a[c] != b[c]:
            return a[c] < b[c]
    return False


@numba.njit(cache=True)
def _face_planes(points, faces, x0, s, reach, rows, table_face, table_normal, fx, fn, fo, key,
                 fid, order):
    """The faces among ``rows`` whose bounding spheres meet the ball of radius ``reach``
    (local frame: ``(x - x0) / s``) into ``fx``, ``fn``, ``fo`` (corners, outward normal,
    offset), then one per distinct plane (rounded ``(normal, offset)``, first of each, in
    the keys' order) in ``order``; their counts ``(within, planes)``."""
    w = 0
    for row in rows:
        f = table_face[row]
        for v in range(3):
            for c in range(3):
                fx[w, v, c] = (points[faces[f, v], c] - x0[c]) / s
        c0 = (fx[w, 0, 0] + fx[w, 1, 0]) + fx[w, 2, 0]
        c1 = (fx[w, 0, 1] + fx[w, 1, 1]) + fx[w, 2, 1]
        c2 = (fx[w, 0, 2] + fx[w, 1, 2]) + fx[w, 2, 2]
        c0, c1, c2 = c0 / 3.0, c1 / 3.0, c2 / 3.0
        radius = 0.0
        for v in range(3):
            d0, d1, d2 = fx[w, v, 0] - c0, fx[w, v, 1] - c1, fx[w, v, 2] - c2
            radius = max(radius, np.sqrt(d0 * d0 + d1 * d1 + d2 * d2))
        if np.sqrt(c0 * c0 + c1 * c1 + c2 * c2) > reach + radius:
            continue
        for c in range(3):
            fn[w, c] = table_normal[row, c]
        fid[w] = f
        fo[w] = fn[w, 0] * fx[w, 0, 0] + fn[w, 1] * fx[w, 0, 1] + fn[w, 2] * fx[w, 0, 2]
        for c in range(3):
            key[w, c] = np.rint(fn[w, c] * 1e9)
        key[w, 3] = np.rint(fo[w] * 1e9)
        order[w] = w
        w += 1
    for k in range(1, w):                       # stable insertion sort by key
        j, t = order[k], k
        while t > 0 and _key_less(key[j], key[order[t - 1]]):
            order[t] = order[t - 1]
            t -= 1
        order[t] = j
    p = 0
    for k in range(w):
        if k == 0 or _key_less(key[order[p - 1]], key[order[k]]):
            order[p] = order[k]
            p += 1
    return w, p


@numba.njit(cache=True)
def in_convex_position(w, p, fx, fn, fo, order):
    """Whether no corner of the faces ``fx[:w]`` lies beyond (by more than `REFLEX`) the
    plane ``fn[q] . x <= fo[q]`` of a face ``q`` in ``order[:p]`` (`_face_planes`)."""
    for a in range(w):
        for v in range(3):
            for k in range(p):
                q = order[k]
                if (fx[a, v, 0] * fn[q, 0] + fx[a, v, 1] * fn[q, 1] + fx[a, v, 2] * fn[q, 2]
                        - fo[q] > REFLEX):
                    return False
    return True


@numba.njit(cache=True)
def convex_cell(points, faces, i, x0, s, half, rows, table_face, table_normal, near, near_far,
                fx, fn, fo, key, fid, order, y, dist, yid, poly, work):
    """The cell of node ``i`` at ``x0`` (local unit ``s``) in its cube of half-side
    ``half``, when the faces in reach are in convex position: the cube clipped by their
    planes and by the bisectors of the candidate nodes ``near`` (nearest first, -1 past
    the last; the nodes not among them are at least ``near_far`` from ``x0``) that cut it.

    ``poly`` holds the polytope's arrays ``(vx, start, idx, normal, offset, kind,
    ident)``, ``work`` `clip`'s work arrays; the others are scratch.

    Returns
    -------
    status : int
        `DONE`, `GROW` (the cell touches the cube), `MORE` (nodes beyond ``near`` may
        cut it) or `REFUSED` (not convex, empty, or the scratch too small).
    nv, nf : int
        The polytope's vertex and face counts in ``poly``.
    """
    vx, start, idx, normal, offset, kind, ident = poly
    side, tv, made, cap, ang, used, tstart, tidx = work
    reach = np.sqrt(3.0) * half
    w, p = _face_planes(points, faces, x0, s, reach, rows, table_face, table_normal, fx, fn,
                        fo, key, fid, order)
    if not in_convex_position(w, p, fx, fn, fo, order):
        return REFUSED, 0, 0
    nv, nf = _box(half, vx, start, idx, normal, offset, kind, ident)
    for k in range(p):
        q = order[k]
        nv, nf = clip(nv, nf, vx, start, idx, normal, offset, kind, ident, fn[q], fo[q], FACE,
                      fid[q], side, tv, made, cap, ang, used, tstart, tidx)
        if nv <= 0:
            return REFUSED, 0, 0
    nv, nf, radius = bisectors(points, i, x0, s, near, y, dist, yid, nv, nf, poly, work)
    if nv <= 0:
        return REFUSED, 0, 0
    if near[-1] >= 0 and 0.5 * near_far / s * (1.0 - 1e-9) < radius:
        return MORE, nv, nf
    for f in range(nf):
        if kind[f] == BOX:
            return GROW, nv, nf
    return DONE, nv, nf


@numba.njit(cache=True)
def bisectors(points, i, x0, s, near, y, dist, yid, nv, nf, poly, work):
    """Clip the polytope ``(nv, nf)`` in ``poly`` by the bisectors of the nodes ``near``
    that cut it (``i`` skipped, -1 past the last), nearest first; ``y``, ``dist``,
    ``yid`` are scratch (as long as ``near``).

    Returns
    -------
    nv, nf : int
        The clipped polytope's counts (`clip`'s: ``nv <= 0`` when it failed).
    radius : float
        Its largest distance of a vertex from the origin.
    """
    vx, start, idx, normal, offset, kind, ident = poly
    side, tv, made, cap, ang, used, tstart, tidx = work
    m = 0
    for j in near:
        if j < 0:
            break
        if j == i:
            continue
        for c in range(3):
            y[m, c] = (points[j, c] - x0[c]) / s
        dist[m] = np.sqrt(y[m, 0] * y[m, 0] + y[m, 1] * y[m, 1] + y[m, 2] * y[m, 2])
        yid[m] = j
        m += 1
    rank = np.argsort(dist[:m], kind="mergesort")          # stable: nearest first
    radius = _radius(nv, vx)
    u = np.empty(3)
    for k in range(m):
        q = rank[k]
        hd = 0.5 * dist[q]
        if hd >= radius:                                   # no later bisector cuts
            break
        for c in range(3):
            u[c] = y[q, c] / dist[q]
        top = -np.inf
        for v in range(nv):
            top = max(top, vx[v, 0] * u[0] + vx[v, 1] * u[1] + vx[v, 2] * u[2] - hd)
        if top <= ON:
            continue
        nv, nf = clip(nv, nf, vx, start, idx, normal, offset, kind, ident, u, hd, BISECTOR,
                      yid[q], side, tv, made, cap, ang, used, tstart, tidx)
        if nv <= 0:
            return nv, nf, 0.0
        radius = _radius(nv, vx)
    return nv, nf, radius


@numba.njit(cache=True)
def _radius(nv, vx):
    """Largest distance of a vertex from the origin."""
    top = 0.0
    for v in range(nv):
        top = max(top, vx[v, 0] * vx[v, 0] + vx[v, 1] * vx[v, 1] + vx[v, 2] * vx[v, 2])
    return np.sqrt(top)


@numba.njit(cache=True)
def scratch(fcap):
    """A polytope's arrays ``(vx, start, idx, normal, offset, kind, ident)`` and `clip`'s
    work arrays, for polytopes of at most ``fcap`` faces."""
    vcap = 6 * fcap
    poly = (np.empty((vcap, 3)), np.empty(fcap + 1, dtype=np.int64),
            np.empty(12 * fcap, dtype=np.int64), np.empty((fcap, 3)), np.empty(fcap),
            np.empty(fcap, dtype=np.int64), np.empty(fcap, dtype=np.int64))
    work = (np.empty(vcap), np.empty((vcap, 3)), np.empty((3 * fcap, 3), dtype=np.int64),
            np.empty(vcap, dtype=np.int64), np.empty(vcap), np.empty(vcap, dtype=np.int64),
            np.empty(fcap + 1, dtype=np.int64), np.empty(12 * fcap, dtype=np.int64))
    return poly, work


@numba.njit(cache=True)
def outputs(w, out_ptr):
    """A cell kernel's outputs for ``w`` cells (see `convex_cells`): whether it writes
    (``out_ptr`` not empty), ``status`` (all `REFUSED`), ``ntri``, ``vol``, ``tri``,
    ``normal``."""
    write = out_ptr.shape[0] > 0
    q = out_ptr[w] if write else 0
    return (write, np.full(w, REFUSED, dtype=np.int8), np.zeros(w, dtype=np.int64),
            np.zeros(w), np.empty((q, 3, 3)), np.empty((q, 3)))


@numba.njit(cache=True)
def widest(ptr, first, last):
    """The longest of the rows ``first .. last - 1`` of the CSR ``ptr`` (at least 1)."""
    most = 1
    for s in range(first, last):
        most = max(most, ptr[s + 1] - ptr[s])
    return most


@numba.njit(cache=True)
def write_fan(f, vx, start, idx, normal, s, x0, tri, normal_out, t):
    """Face ``f`` of a polytope (local frame, unit ``s``, origin ``x0``) as the fan of its
    vertices into ``tri[t:]`` (global coordinates) and its normal into ``normal_out[t:]``;
    the next free row."""
    a = idx[start[f]]
    for k in range(start[f] + 1, start[f + 1] - 1):
        for c in range(3):
            tri[t, 0, c] = vx[a, c] * s + x0[c]
            tri[t, 1, c] = vx[idx[k], c] * s + x0[c]
            tri[t, 2, c] = vx[idx[k + 1], c] * s + x0[c]
            normal_out[t, c] = normal[f, c]
        t += 1
    return t


@parallel_kernel("cell_node")
def convex_cells(points, faces, cell_node, half, scale, face_ptr, face_rows, table_face,
                 table_normal, near, near_far, out_ptr, chunks):
    """`convex_cell` of many cells; with ``out_ptr`` empty it counts, else it also writes.

    Parameters
    ----------
    points : (n, 3) float64
    faces : (b, 3) int64
        Boundary and interface faces.
    cell_node : (w,) int64
    half : (w,) float64
        Half-side of each cell's cube (local unit).
    scale : (n,) float64
        Each node's local unit (its longest Delaunay edge).
    face_ptr, face_rows : (w + 1,), (k,) int64
        CSR of each cell's candidate faces: rows of ``table_face``, a superset of its
        region's faces whose bounding spheres meet the cube's circumscribed ball.
    table_face : (r,) int64
        The boundary face of each row (faces of several regions may repeat).
    table_normal : (r, 3) float64
        Its unit normal pointing out of the row's region.
    near : (w, K) int64
        Each cell's nearest nodes of its region, nearest first, -1 past the last.
    near_far : (w,) float64
        A distance within which every node of the region is in ``near``.
    out_ptr : (0,) or (w + 1,) int64
        Empty: count only; else where each `DONE` cell's triangles start in the output.
    chunks : int
        Work chunks (`cnem._parallel.work_chunks`).

    Returns
    -------
    status : (w,) int8
    ntri : (w,) int64
        Facet triangles of each `DONE` cell.
    vol : (w,) float64
        Volume of each `DONE` cell.
    tri : (q, 3, 3) float64
        With ``out_ptr``: the facet triangles, fans of the faces counter-clockwise from
        outside, cell ``s`` at ``tri[out_ptr[s]:out_ptr[s] + ntri[s]]``.
    normal : (q, 3) float64
        Their outward unit normals.
    """
    w, k_near = cell_node.shape[0], near.shape[1]
    write, status, ntri, vol, tri, normal_out = outputs(w, out_ptr)
    nch = max(1, min(chunks, w))
    for ch in numba.prange(nch):
        first, last = ch * w // nch, (ch + 1) * w // nch
        most = widest(face_ptr, first, last)
        fx, fn, fo = np.empty((most, 3, 3)), np.empty((most, 3)), np.empty(most)
        key, fid = np.empty((most, 4)), np.empty(most, dtype=np.int64)
        order = np.empty(most, dtype=np.int64)
        y, dist = np.empty((k_near, 3)), np.empty(k_near)
        yid = np.empty(k_near, dtype=np.int64)
        poly, work = scratch(6 + most + k_near)
        vx, start, idx, normal = poly[0], poly[1], poly[2], poly[3]
        for s in range(first, last):
            i = cell_node[s]
            x0, sc = points[i], scale[i]
            st, nv, nf = convex_cell(points, faces, i, x0, sc, half[s],
                                     face_rows[face_ptr[s]:face_ptr[s + 1]], table_face,
                                     table_normal, near[s], near_far[s], fx, fn, fo, key, fid,
                                     order, y, dist, yid, poly, work)
            status[s] = st
            if st != DONE:
                continue
            vol[s] = volume(nv, nf, vx, start, idx) * sc ** 3.0
            ntri[s] = start[nf] - 2 * nf
            if not write:
                continue
            t = out_ptr[s]
            for f in range(nf):
                t = write_fan(f, vx, start, idx, normal, sc, x0, tri, normal_out, t)
    return status, ntri, vol, tri, normal_out
