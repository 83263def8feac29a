"""Numba kernel of the 3-D cells' fast dual path (`.cells3d`): which interior nodes'
Voronoi cells no boundary face can cut."""

import numba
import numpy as np

from .. import _compile  # noqa: F401  (says once when the kernels compile)
from .._parallel import parallel_kernel


@parallel_kernel("cand")
def clear_of_faces(points, cand, hit_ptr, hit_idx, star_ptr, star_tet, centre, face_x0,
                   face_normal, face_tol, chunks):
    """Whether each candidate node and every circumcentre of its tetrahedra lie strictly
    on one side of the plane of each face it may reach.

    Parameters
    ----------
    points : (n, 3) float64
    cand : (c,) int64
        The candidate nodes.
    hit_ptr, hit_idx : (c + 1,), (k,) int64
        CSR of the faces each candidate may reach.
    star_ptr, star_tet : (n + 1,), (4 t,) int64
        CSR of the tetrahedra at each node.
    centre : (t, 3) float64
        The tetrahedra's circumcentres.
    face_x0, face_normal : (b, 3) float64
        A vertex of each face and its (unnormalised) normal.
    face_tol : (b,) float64
        Distance (times the normal's length) under which a circumcentre is on a face's
        plane.
    chunks : int
        Work chunks (`cnem._parallel.work_chunks`).

    Returns
    -------
    (c,) bool
    """
    c = cand.shape[0]
    clear = np.ones(c, dtype=np.bool_)
    nch = max(1, min(chunks, c))
    for ch in numba.prange(nch):
        for k in range(ch * c // nch, (ch + 1) * c // nch):
            i = cand[k]
            for h in range(hit_ptr[k], hit_ptr[k + 1]):
                f = hit_idx[h]
                nx, ny, nz = face_normal[f, 0], face_normal[f, 1], face_normal[f, 2]
                ax, ay, az = face_x0[f, 0], face_x0[f, 1], face_x0[f, 2]
                own = ((points[i, 0] - ax) * nx + (points[i, 1] - ay) * ny
                       + (points[i, 2] - az) * nz)
                for s in range(star_ptr[i], star_ptr[i + 1]):
                    t = star_tet[s]
                    cc = ((centre[t, 0] - ax) * nx + (centre[t, 1] - ay) * ny
                          + (centre[t, 2] - az) * nz)
                    if not (own * cc > 0 and abs(cc) > face_tol[f]):
                        clear[k] = False
                        break
                if not clear[k]:
                    break
    return clear


@numba.njit(cache=True)
def _edge_fans(a, points, tets, star_ptr, star_tet, centre, fast, pair, ang, rank, emit, tri,
               nrm, cell, cell_of, lo_at, hi_at):
    """The Voronoi facets of the edges ``(a, b)``, ``b > a``, with a fast end: counts
    ``(lo, hi)`` of triangles for ``a`` and for the ``b`` ends, written from ``lo_at`` and
    ``hi_at`` when ``emit``. ``pair (k, 2)``, ``ang``, ``rank`` are scratch."""
    m = 0
    for s in range(star_ptr[a], star_ptr[a + 1]):
        t = star_tet[s]
        for v in range(4):
            b = tets[t, v]
            if b > a and (fast[a] or fast[b]):
                pair[m, 0], pair[m, 1] = b, t
                m += 1
    for k in range(1, m):                                   # by end, then tetrahedron
        b, t, j = pair[k, 0], pair[k, 1], k
        while j > 0 and (pair[j - 1, 0] > b or (pair[j - 1, 0] == b and pair[j - 1, 1] > t)):
            pair[j, 0], pair[j, 1] = pair[j - 1, 0], pair[j - 1, 1]
            j -= 1
        pair[j, 0], pair[j, 1] = b, t
    n_lo = n_hi = 0
    first = 0
    while first < m:
        b = pair[first, 0]
        last = first
        while last < m and pair[last, 0] == b:
            last += 1
        count = last - first
        if count >= 3:
            u = points[b] - points[a]
            u = u / np.sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2])
            helper = np.zeros(3)
            helper[np.argmin(np.abs(u))] = 1.0
            e1 = np.cross(u, helper)
            e1 = e1 / np.sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2])
            e2 = np.cross(u, e1)
            mean = np.zeros(3)
            for k in range(first, last):
                mean += centre[pair[k, 1]]
            mean /= count
            for k in range(first, last):
                r = centre[pair[k, 1]] - mean
                ang[k - first] = np.arctan2(r[0] * e2[0] + r[1] * e2[1] + r[2] * e2[2],
                                            r[0] * e1[0] + r[1] * e1[1] + r[2] * e1[2])
            order = np.argsort(ang[:count], kind="mergesort")
            for k in range(count):
                rank[k] = pair[first + order[k], 1]
            for k in range(1, count - 1):
                for end, at, sign in ((a, lo_at + n_lo, 1.0), (b, hi_at + n_hi, -1.0)):
                    if not fast[end]:
                        continue
                    if emit:
                        p, q = (k, k + 1) if sign > 0 else (k + 1, k)
                        tri[at, 0] = centre[rank[0]]
                        tri[at, 1] = centre[rank[p]]
                        tri[at, 2] = centre[rank[q]]
                        nrm[at] = sign * u
                        cell[at] = cell_of[end]
                    if sign > 0:
                        n_lo += 1
                    else:
                        n_hi += 1
        first = last
    return n_lo, n_hi


@numba.njit(cache=True)
def dual_facets(points, tets, star_ptr, star_tet, centre, fast, cell_of):
    """Facet triangles of the fast cells: for each Delaunay edge ``(a, b)``, ``a < b``, with
    a fast end, in the order of ``(a, b)``, the circumcentres around it ordered by angle
    about ``u = (b - a) / |b - a|`` and fanned from the first; first all of the ``a``
    ends' (normal ``u``), then all of the ``b`` ends' (reversed, normal ``-u``).

    Returns
    -------
    tri : (q, 3, 3) float64
    cell : (q,) int64
        ``cell_of`` of each triangle's node.
    normal : (q, 3) float64
    """
    n = points.shape[0]
    most = 1
    for a in range(n):
        most = max(most, 3 * (star_ptr[a + 1] - star_ptr[a]))
    pair = np.empty((most, 2), dtype=np.int64)
    ang, rank = np.empty(most), np.empty(most, dtype=np.int64)
    lo_n, hi_n = np.zeros(n + 1, dtype=np.int64), np.zeros(n + 1, dtype=np.int64)
    tri, nrm, cell = np.empty((0, 3, 3)), np.empty((0, 3)), np.empty(0, dtype=np.int64)
    for a in range(n):
        lo, hi = _edge_fans(a, points, tets, star_ptr, star_tet, centre, fast, pair, ang, rank,
                            False, tri, nrm, cell, cell_of, 0, 0)
        lo_n[a + 1], hi_n[a + 1] = lo_n[a] + lo, hi_n[a] + hi
    total = lo_n[n] + hi_n[n]
    tri, nrm, cell = np.empty((total, 3, 3)), np.empty((total, 3)), np.empty(total, dtype=np.int64)
    for a in range(n):
        _edge_fans(a, points, tets, star_ptr, star_tet, centre, fast, pair, ang, rank, True, tri,
                   nrm, cell, cell_of, lo_n[a], lo_n[n] + hi_n[a])
    return tri, cell, nrm
