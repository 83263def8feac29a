"""Numba kernels of the constrained 3-D natural-neighbour coordinates (arrays and scalars only).

For a query point ``x`` in tetrahedron ``t`` of a constrained Delaunay
tetrahedrisation (every face between regions, on the boundary or listed as a
constraint has no neighbour in ``nb``):

* ``x`` at a vertex: the Kronecker delta;
* ``x`` on a constraint face: linear interpolation between its three nodes
  (barycentric), on a constraint edge: between its two ends;
* otherwise the constrained Bowyer-Watson cavity of ``x``
  (`cnem.shape._cavity3d`, star-shaped from ``x``: every natural neighbour is
  visible). The natural neighbours are its vertices.

Everything is computed relative to ``x``. The Voronoi vertex of the new
tetrahedron ``(x, f)`` over a cavity-boundary face ``f = (a, b, c)`` is
``q_f = (|a|^2 b x c + |b|^2 c x a + |c|^2 a x b) / (2 a . b x c)`` and
moves with ``x`` as ``dq_f/dx = s_f q_f^T`` with
``s_f = (b x c + c x a + a x b) / (a . b x c)``.

* Laplace: ``w_i = A_i . p_i / |p_i|^2`` with ``A_i`` the vector area of the
  Voronoi facet between ``x`` and ``i`` (the polygon of the ``q_f`` of the
  boundary faces around ``i``, signed, so that partition of unity and linear
  reproduction hold to round-off even where the facet degenerates) and
  ``p_i = x_i - x``.
* Sibson: ``w_i = V_i`` the volume of ``x``'s cell taken from ``i``'s, by
  the divergence theorem about the facet's foot ``p_i / 2``:
  ``V_i = 1/6 sum_j P_ij . p_j`` over the pieces ``P_ij`` of the old facets
  ``(i, j)`` inside the new cell (chains of old circumcentres of the cavity
  tetrahedra around the edge ``(i, j)``, closed by ``q_f``). Gradient
  ``grad V_i = M_i / |p_i|`` with ``M_i`` the first moment of facet ``i``.
"""

import numba
import numpy as np

from .. import _compile  # noqa: F401  (says once when the kernels compile)
from .._parallel import parallel_kernel
from ._cavity3d import (AT_NODE, CAVITY, FACES, FALLBACK, MAX_CAVITY, ON_EDGE, ON_FACE,
                        PAIRS, _cavity, _cross, _face_side, _rel, _special)

#: A weight below ``-NEGATIVE_RTOL`` times the largest makes a row `FALLBACK`.
NEGATIVE_RTOL = 1e-9

_HASH = 4096                     # half-edge table, a power of two > 3 * 2 * MAX_CAVITY / 2

#: At a constraint face, relative size of the determinant (and of the sine of the
#: angle) under which a cavity face counts as in the plane of the point's face (its
#: new Voronoi vertex at infinity).
FLAT_RTOL = 1e-9


@numba.njit(cache=True, inline="always")
def _product(u, ku, v, kv, nu, limit):
    """``u x v``, or at a constraint face its leading ``1 / delta`` coefficient when
    ``u = u0 + (ku / delta) nu`` and ``v = v0 + (kv / delta) nu`` (``delta -> 0``)."""
    if not limit:
        return _cross(u, v)
    a = _cross(nu, v)
    b = _cross(nu, u)
    return (ku * a[0] - kv * b[0], ku * a[1] - kv * b[1], ku * a[2] - kv * b[2])


@numba.njit(cache=True)
def _in_plane(pa, pb, pc, det, lengths2, nu, fq, fs, nf):
    """Whether the face ``(pa, pb, pc)`` (relative to x) lies in the plane through x of
    normal ``nu``; if so ``fq[nf]`` gets its circumcentre and ``fs[nf, 0]`` the
    coefficient ``k = (|o|^2 - r^2) / 2`` of its Voronoi vertex at infinity."""
    ab = (pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2])
    ac = (pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2])
    nn = _cross(ab, ac)
    n2 = nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]
    along = nn[0] * nu[0] + nn[1] * nu[1] + nn[2] * nu[2]
    if abs(det) > FLAT_RTOL * np.sqrt(lengths2) or along * along < (1.0 - FLAT_RTOL) * n2:
        return False
    l1 = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2]
    l3 = ac[0] * ac[0] + ac[1] * ac[1] + ac[2] * ac[2]
    u1 = _cross(nn, ab)
    u2 = _cross(ac, nn)
    o2 = 0.0
    r2 = 0.0
    for d in range(3):
        off = (l1 * u2[d] + l3 * u1[d]) / (2.0 * n2)
        fq[nf, d] = pa[d] + off
        o2 += fq[nf, d] ** 2
        r2 += off * off
    fs[nf, 0] = 0.5 * (o2 - r2)
    return True


@numba.njit(cache=True)
def _natural_row(nodes, tet, nb, x, cav, size, stamp, mark, pos, node_mark, node_slot,
                 fq, fs, fv, bf, twin, hkeys, hval, cc, acc, cols, laplace, gradient, nu, limit):
    """Coordinates from a cavity: the neighbour count, -1 if inconsistent.

    Work arrays: ``fq, fs (F, 3)`` the new Voronoi vertices and their motions,
    ``fv (F, 3)`` the boundary faces' nodes (outward), ``bf (C, 4)`` boundary-face
    index of each cavity face (-1 inside), ``twin (F, 3)`` the face across each
    half-edge, ``hkeys, hval`` the half-edge hash, ``cc (C, 3)`` the cavity's
    circumcentres, ``acc (N, 14)`` per neighbour: vector area, Sibson volume, Laplace area gradient,
    Sibson moment, ``|p|^2``, ``p``.

    With ``limit``, ``x`` lies on a constraint face of inward normal ``nu`` and the
    coordinates are the limit from inside: the new tetrahedra on faces through ``x``
    are flat, their Voronoi vertices ``q_f = o_f + (k_f / delta) nu`` (``o_f`` the
    face's circumcentre, ``k_f = (|o_f|^2 - r_f^2) / 2``) go to infinity, and every
    area and volume is replaced by its ``1 / delta`` coefficient (``fs[:, 0]`` holds
    ``k_f``, zero for the other faces).
    """
    n = nodes.shape[0]
    nf = 0
    count = 0
    for m in range(size):
        c = cav[m]
        pos[c] = m
        for k in range(4):
            o = nb[c, k]
            if o >= 0 and mark[o] == stamp:
                bf[m, k] = -1
                continue
            if nf == fq.shape[0]:
                return -1
            bf[m, k] = nf
            pa = _rel(nodes, tet[c, FACES[k, 0]], x)
            pb = _rel(nodes, tet[c, FACES[k, 1]], x)
            pc = _rel(nodes, tet[c, FACES[k, 2]], x)
            bxc, cxa, axb = _cross(pb, pc), _cross(pc, pa), _cross(pa, pb)
            det = pa[0] * bxc[0] + pa[1] * bxc[1] + pa[2] * bxc[2]
            a2 = pa[0] * pa[0] + pa[1] * pa[1] + pa[2] * pa[2]
            b2 = pb[0] * pb[0] + pb[1] * pb[1] + pb[2] * pb[2]
            c2 = pc[0] * pc[0] + pc[1] * pc[1] + pc[2] * pc[2]
            if limit and _in_plane(pa, pb, pc, det, a2 * b2 * c2, nu, fq, fs, nf):
                pass                 # a face in the plane of x's face: its vertex at infinity
            elif limit:
                for d in range(3):
                    fq[nf, d] = (a2 * bxc[d] + b2 * cxa[d] + c2 * axb[d]) / (2.0 * det)
                fs[nf, 0] = 0.0
            else:
                for d in range(3):
                    fq[nf, d] = (a2 * bxc[d] + b2 * cxa[d] + c2 * axb[d]) / (2.0 * det)
                    fs[nf, d] = (bxc[d] + cxa[d] + axb[d]) / det
            for e in range(3):
                v = tet[c, FACES[k, e]]
                fv[nf, e] = v
                if node_mark[v] != stamp:
                    if count == cols.shape[0]:
                        return -1
                    node_mark[v] = stamp
                    node_slot[v] = count
                    cols[count] = v
                    for d in range(14):
                        acc[count, d] = 0.0
                    p2 = 0.0
                    for d in range(3):
                        p2 += (nodes[v, d] - x[d]) ** 2
                    acc[count, 10] = p2
                    count += 1
                key = v * n + tet[c, FACES[k, (e + 1) % 3]]          # half-edge v -> next
                h = (key * 2654435761) & (_HASH - 1)
                for _ in range(_HASH):
                    if hkeys[h] < 0:
                        break
                    h = (h + 1) & (_HASH - 1)
                hkeys[h] = key
                hval[h] = nf * 3 + e
            nf += 1
    # the face across each half-edge (i -> j) holds (j -> i)
    for f in range(nf):
        for e in range(3):
            i, j = fv[f, e], fv[f, (e + 1) % 3]
            key = j * n + i
            h = (key * 2654435761) & (_HASH - 1)
            twin[f, e] = -1
            for _ in range(_HASH):
                if hkeys[h] < 0:
                    break
                if hkeys[h] == key:
                    twin[f, e] = hval[h] // 3
                    break
                h = (h + 1) & (_HASH - 1)
            if twin[f, e] < 0:
                return -1
    for f in range(nf):                      # clear the hash for the next point
        for e in range(3):
            i, j = fv[f, e], fv[f, (e + 1) % 3]
            key = i * n + j
            h = (key * 2654435761) & (_HASH - 1)
            for _ in range(_HASH):
                if hkeys[h] < 0:
                    break
                hkeys[h] = -1
                h = (h + 1) & (_HASH - 1)
    # facets: the Voronoi edge q_f -> q_g dual to (x, i, j), g holding i -> j
    for g in range(nf):
        qg = fq[g]
        for e in range(3):
            i, j = fv[g, e], fv[g, (e + 1) % 3]
            f = twin[g, e]
            qf = fq[f]
            si = node_slot[i]
            cr = _product(qf, fs[f, 0], qg, fs[g, 0], nu, limit)
            for d in range(3):
                acc[si, d] += 0.5 * cr[d]
            pi = _rel(nodes, i, x)
            if gradient and laplace:
                sf, sg = fs[f], fs[g]
                a1 = _cross(sf, qg)
                a2 = _cross(qf, sg)
                c1 = 0.5 * (pi[0] * a1[0] + pi[1] * a1[1] + pi[2] * a1[2])
                c2 = 0.5 * (pi[0] * a2[0] + pi[1] * a2[1] + pi[2] * a2[2])
                for d in range(3):
                    acc[si, 4 + d] += c1 * qf[d] + c2 * qg[d]
            if not laplace:
                pj = _rel(nodes, j, x)
                cg = _product(qg, fs[g, 0], qf, fs[f, 0], nu, limit)   # closing edge of (i, j)
                acc[si, 3] += (cg[0] * pj[0] + cg[1] * pj[1] + cg[2] * pj[2]) / 12.0
                if gradient:                     # first moment of the facet, about x
                    mx, my, mz = 0.5 * pi[0], 0.5 * pi[1], 0.5 * pi[2]
                    tri = _cross((qf[0] - mx, qf[1] - my, qf[2] - mz),
                                 (qg[0] - mx, qg[1] - my, qg[2] - mz))
                    area = 0.5 * (tri[0] * pi[0] + tri[1] * pi[1] + tri[2] * pi[2]) / acc[si, 10]
                    for d in range(3):
                        acc[si, 7 + d] += area * (0.5 * pi[d] + qf[d] + qg[d]) / 3.0
    if not laplace:
        _sibson_chains(nodes, tet, nb, x, cav, size, stamp, mark, pos, node_slot, fq, fs, bf, cc,
                       acc, nu, limit)
    return count


@numba.njit(cache=True)
def _sibson_chains(nodes, tet, nb, x, cav, size, stamp, mark, pos, node_slot, fq, fs, bf, cc, acc,
                   nu, limit):
    """Adds to ``acc[:, 3]`` the old-facet pieces of the Sibson volumes: around each
    edge (i, j), i < j, of a cavity tetrahedron (turning right-handed about i -> j),
    the Voronoi edge from its circumcentre to the next one (or to the new vertex
    where the chain leaves the cavity, and from the new vertex where it enters)."""
    for m in range(size):
        c = cav[m]
        v0 = nodes[tet[c, 0]]
        u1 = _rel(nodes, tet[c, 1], v0)
        u2 = _rel(nodes, tet[c, 2], v0)
        u3 = _rel(nodes, tet[c, 3], v0)
        c23, c31, c12 = _cross(u2, u3), _cross(u3, u1), _cross(u1, u2)
        det = 2.0 * (u1[0] * c23[0] + u1[1] * c23[1] + u1[2] * c23[2])
        n1 = u1[0] * u1[0] + u1[1] * u1[1] + u1[2] * u1[2]
        n2 = u2[0] * u2[0] + u2[1] * u2[1] + u2[2] * u2[2]
        n3 = u3[0] * u3[0] + u3[1] * u3[1] + u3[2] * u3[2]
        for d in range(3):
            cc[m, d] = nodes[tet[c, 0], d] - x[d] + (n1 * c23[d] + n2 * c31[d] + n3 * c12[d]) / det
    for m in range(size):
        c = cav[m]
        ct = cc[m]
        for e in range(6):
            i, j = tet[c, PAIRS[e, 0]], tet[c, PAIRS[e, 1]]
            kx, lx = PAIRS[e, 2], PAIRS[e, 3]
            if i > j:              # about the edge from its lower node: each Voronoi edge once
                i, j, kx, lx = j, i, lx, kx
            o = nb[c, kx]                            # exit across (i, j, l)
            if o >= 0 and mark[o] == stamp:
                ed = _product(ct, 0.0, cc[pos[o]], 0.0, nu, limit)
            else:
                ed = _product(ct, 0.0, fq[bf[m, kx]], fs[bf[m, kx], 0], nu, limit)
            ex, ey, ez = 0.5 * ed[0], 0.5 * ed[1], 0.5 * ed[2]
            if bf[m, lx] >= 0:                       # entry from outside, across (i, j, k)
                en = _product(fq[bf[m, lx]], fs[bf[m, lx], 0], ct, 0.0, nu, limit)
                ex, ey, ez = ex + 0.5 * en[0], ey + 0.5 * en[1], ez + 0.5 * en[2]
            pi = _rel(nodes, i, x)
            pj = _rel(nodes, j, x)
            acc[node_slot[i], 3] += (ex * pj[0] + ey * pj[1] + ez * pj[2]) / 6.0
            acc[node_slot[j], 3] -= (ex * pi[0] + ey * pi[1] + ez * pi[2]) / 6.0


@numba.njit(cache=True)
def _normalise(acc, count, laplace, gradient, vals, grads):
    """Weights of the neighbours normalised into ``vals`` (and ``grads (N, 3)``);
    False if they do not sum to a positive total."""
    total = 0.0
    gtot = np.zeros(3)
    for e in range(count):
        p2 = acc[e, 10]
        if laplace:
            w = (acc[e, 0] * acc[e, 11] + acc[e, 1] * acc[e, 12] + acc[e, 2] * acc[e, 13]) / p2
        else:
            w = acc[e, 3]
        vals[e] = w
        total += w
        if gradient:
            for d in range(3):
                if laplace:        # grad w = (G - A) / |p|^2 + 2 w p / |p|^2
                    g = (acc[e, 4 + d] - acc[e, d] + 2.0 * w * acc[e, 11 + d]) / p2
                else:              # grad V_i = M_i / |p_i| (accumulated so)
                    g = acc[e, 7 + d]
                grads[e, d] = g
                gtot[d] += g
    if not total > 0.0:
        return False
    for e in range(count):
        vals[e] /= total
        if gradient:
            for d in range(3):
                grads[e, d] = (grads[e, d] - vals[e] * gtot[d]) / total
    return True


@numba.njit(cache=True)
def _bad_row(vals, count):
    """Whether normalised weights hold a clearly negative one: near a re-entrant edge,
    on the side where a constraint face's plane runs into the body, the flat new
    tetrahedron over that face sends its Voronoi vertex far behind it and the signed
    facet areas stop being a partition into shares."""
    top = 0.0
    low = 0.0
    for e in range(count):
        top = max(top, vals[e])
        low = min(low, vals[e])
    return low < -NEGATIVE_RTOL * top


@numba.njit(cache=True)
def _barycentric_row(nodes, tet, t, x, cols, vals, grads):
    """The barycentric coordinates of ``x`` in tetrahedron ``t`` and their gradients;
    the row's length (4)."""
    total = 0.0
    for k in range(4):
        a, b, c = tet[t, FACES[k, 0]], tet[t, FACES[k, 1]], tet[t, FACES[k, 2]]
        det, perm = _face_side(nodes, a, b, c, x)
        cols[k] = tet[t, k]
        vals[k] = max(det, 0.0)
        total += vals[k]
        v0 = nodes[a]
        nrm = _cross(_rel(nodes, b, v0), _rel(nodes, c, v0))
        for d in range(3):
            grads[k, d] = -nrm[d]
    volume6 = 0.0
    for k in range(4):
        a = tet[t, FACES[k, 0]]
        volume6 += (nodes[tet[t, k], 0] - nodes[a, 0]) * grads[k, 0] + \
            (nodes[tet[t, k], 1] - nodes[a, 1]) * grads[k, 1] + \
            (nodes[tet[t, k], 2] - nodes[a, 2]) * grads[k, 2]
    volume6 /= 4.0
    for k in range(4):
        vals[k] /= total
        for d in range(3):
            grads[k, d] /= volume6
    return 4


@parallel_kernel("points")
def natural(nodes, tet, nb, cedges, features, points, tet_of, tol, nch, laplace, gradient, slots):
    """Laplace (or Sibson) coordinates of many points, one pass, rows in visit order.

    Each chunk of points writes its rows one after the other into its own
    region of the output, ``slots`` entries per point; a chunk whose rows do not
    fit stops and is reported (call again with more slots).

    Parameters
    ----------
    nodes : (n, 3) float64
    tet : (t, 4) int64, positively oriented
    nb : (t, 4) int64
        Neighbour across the face opposite each vertex; -1 across constraints.
    cedges : (e,) int64
        Sorted keys ``min * n + max`` of the edges of the constraint faces.
    features : (f,) int64
        The same for the feature edges (where constraint faces of different planes
        meet): a point on one interpolates linearly between its ends.
    points : (p, 3) float64
        The points in the order they are visited.
    tet_of : (p,) int64
        A tetrahedron containing each point (same order).
    tol : float
        Distance under which a point is at a node / on a constraint face or edge.
    nch : int
        Work chunks shared between threads.
    laplace, gradient : bool
        Laplace instead of Sibson; also the gradients (zero at nodes and on
        constraint faces and edges, where they are not defined).
    slots : int
        Room per point in the chunks' regions.

    Returns
    -------
    start, size : (p,) int64
        Row ``s`` is ``cols[start[s]:start[s] + size[s]]`` (same for the values).
    cols : (p * slots,) int32
    vals : (p * slots,) float64
    grads : (p * slots, 3) float64
        Empty unless ``gradient``.
    kinds : (p,) int8
        ``CAVITY``, ``AT_NODE``, ``ON_FACE``, ``ON_EDGE`` or ``FALLBACK`` (a cavity whose
        weights are not non-negative shares, or that round-off broke: barycentric; on a
        face such a point takes the face's linear interpolation and stays ``ON_FACE``).
    full : bool
        Some chunk ran out of room (the result is incomplete).
    """
    p = points.shape[0]
    n = nodes.shape[0]
    nt = tet.shape[0]
    start = np.zeros(p, dtype=np.int64)
    size = np.zeros(p, dtype=np.int64)
    kinds = np.zeros(p, dtype=np.int8)
    nch = max(1, min(p, nch))
    out_cols = np.empty(p * slots, dtype=np.int32)
    out_vals = np.empty(p * slots)
    out_grad = np.zeros((p * slots if gradient else 0, 3))
    full = np.zeros(nch, dtype=np.bool_)
    for ch in numba.prange(nch):
        mark = np.zeros(nt, dtype=np.int64)
        pos = np.zeros(nt, dtype=np.int32)
        node_mark = np.zeros(n, dtype=np.int64)
        node_slot = np.zeros(n, dtype=np.int32)
        cav = np.empty(MAX_CAVITY, dtype=np.int64)
        nfmax = 2 * MAX_CAVITY + 4
        fq = np.empty((nfmax, 3))
        fs = np.empty((nfmax, 3))
        fv = np.empty((nfmax, 3), dtype=np.int64)
        bf = np.empty((MAX_CAVITY, 4), dtype=np.int64)
        twin = np.empty((nfmax, 3), dtype=np.int64)
        hkeys = np.full(_HASH, -1, dtype=np.int64)
        hval = np.empty(_HASH, dtype=np.int64)
        cc = np.empty((MAX_CAVITY, 3))
        acc = np.empty((MAX_CAVITY, 14))
        cols = np.empty(MAX_CAVITY, dtype=np.int64)
        vals = np.empty(MAX_CAVITY)
        grads = np.empty((MAX_CAVITY, 3))
        foot = np.empty(3)
        nu = np.zeros(3)
        sph = np.empty((4, 4))
        lo, hi = ch * p // nch, (ch + 1) * p // nch
        a, end = lo * slots, hi * slots
        for s in range(lo, hi):
            x = points[s]
            start[s] = a
            kind, na, nb_, nc, la, lb, lc = _special(nodes, tet, nb, cedges, features,
                                                     tet_of[s], x, tol)
            c = 0
            if kind == AT_NODE:
                cols[0], vals[0], c = na, 1.0, 1
            elif kind == ON_EDGE:
                cols[0], cols[1], vals[0], vals[1], c = na, nb_, la, lb, 2
            else:
                stamp = s + 1
                t0 = tet_of[s]
                limit = kind == ON_FACE
                if limit:                    # the foot of x on the face, the inward normal
                    t0 = na
                    v0 = tet[t0, FACES[nb_, 0]]
                    nrm = np.cross(nodes[tet[t0, FACES[nb_, 1]]] - nodes[v0],
                                   nodes[tet[t0, FACES[nb_, 2]]] - nodes[v0])
                    nrm /= -np.sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2])
                    dist = ((nodes[v0, 0] - x[0]) * nrm[0] + (nodes[v0, 1] - x[1]) * nrm[1]
                            + (nodes[v0, 2] - x[2]) * nrm[2])
                    for d in range(3):
                        foot[d] = x[d] + dist * nrm[d]
                        nu[d] = nrm[d]
                else:
                    for d in range(3):
                        foot[d] = x[d]
                csize = _cavity(nodes, tet, nb, t0, foot, stamp, mark, cav, limit, sph)
                if csize > 0:
                    c = _natural_row(nodes, tet, nb, foot, cav, csize, stamp, mark, pos,
                                     node_mark, node_slot, fq, fs, fv, bf, twin, hkeys, hval, cc,
                                     acc, cols, laplace, gradient and not limit, nu, limit)
                ok = csize > 0 and c > 0
                if ok:
                    for e in range(c):
                        for d in range(3):
                            acc[e, 11 + d] = nodes[cols[e], d] - foot[d]
                    ok = _normalise(acc, c, laplace, gradient and not limit, vals, grads)
                if not ok and limit:        # the face's own linear interpolation (API.md)
                    c = _barycentric_row(nodes, tet, tet_of[s], x, cols, vals, grads)
                elif not ok:                # a cavity broke on round-off: barycentric below
                    kind, c = FALLBACK, 0
                if not limit and (kind == FALLBACK or (kind == CAVITY and _bad_row(vals, c))):
                    kind = FALLBACK
                    c = _barycentric_row(nodes, tet, tet_of[s], x, cols, vals, grads)
            kinds[s] = kind
            if a + c > end:
                full[ch] = True
                break
            size[s] = c
            for e in range(c):
                out_cols[a + e] = cols[e]
                out_vals[a + e] = vals[e]
            if gradient and (kind == CAVITY or kind == FALLBACK):
                for e in range(c):
                    for d in range(3):
                        out_grad[a + e, d] = grads[e, d]
            a += c
    return start, size, out_cols, out_vals, out_grad, kinds, full.any()


@parallel_kernel("order")
def permute_rows(start, size, cols, vals, grads, order):
    """Rows ``s`` moved to CSR rows ``order[s]``: ``(offsets, cols, vals, grads)``."""
    p = order.shape[0]
    moved = np.empty(p, dtype=np.int64)
    for s in numba.prange(p):
        moved[order[s]] = size[s]
    new = np.zeros(p + 1, dtype=np.int64)
    for q in range(p):
        new[q + 1] = new[q] + moved[q]
    out_cols = np.empty(new[p], dtype=np.int32)
    out_vals = np.empty(new[p])
    grad = grads.shape[0] > 0
    out_grad = np.empty((new[p] if grad else 0, 3))
    for s in numba.prange(p):
        a, b = start[s], new[order[s]]
        for e in range(size[s]):
            out_cols[b + e] = cols[a + e]
            out_vals[b + e] = vals[a + e]
            if grad:
                for d in range(3):
                    out_grad[b + e, d] = grads[a + e, d]
    return new, out_cols, out_vals, out_grad
