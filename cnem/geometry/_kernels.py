"""Numba kernels of the geometry layer (arrays and scalars only).

The fast path of the constrained Voronoi cells: for a node whose
circumcentres are all visible from it and whose dual polygon is star-shaped
around it, the cell is exactly the polygon of the circumcentres of its
triangles in counter-clockwise order (the dual of the constrained Delaunay
triangulation); for a node on a straight boundary or a convex corner the
polygon starts at the node and at the midpoint of its first constraint edge
and ends at the midpoint of its last. Every other node (reflex corners, crack
tips, interfaces, circumcentres behind a constraint) is left to the exact
clipping path.
"""

import numba
import numpy as np

from .. import _compile  # noqa: F401  (says once when the kernels compile)
from .._parallel import parallel_kernel
from .._predicates import orient2d as _orient

#: Status codes of the fast path.
FAST, SLOW = 0, 1


@numba.njit(cache=True)
def _local(tri, t, v):
    for k in range(3):
        if tri[t, k] == v:
            return k
    return -1


@numba.njit(cache=True)
def _ordered_fan(i, tri, nb, offsets, star, out):
    """Triangles around interior node ``i`` in CCW order; count, or -1 if open."""
    deg = offsets[i + 1] - offsets[i]
    t0 = star[offsets[i]]
    t = t0
    count = 0
    while True:
        if count >= deg:
            return -1
        out[count] = t
        count += 1
        p = _local(tri, t, i)
        nxt = nb[t, (p + 1) % 3]
        if nxt < 0:
            return -1
        t = nxt
        if t == t0:
            break
    return count if count == deg else -1


@numba.njit(cache=True)
def _visible(i, cx, cy, pts, tri, nb, fan, nfan, first, max_steps):
    """Whether the segment from node ``i`` to ``(cx, cy)`` crosses no constraint.

    The sector of the fan holding the direction is looked for from ``fan[first]``
    outwards (then its neighbours, alternately): a circumcentre lies in its own
    triangle's sector or a neighbouring one. The sectors' cones meet only on their
    common edges, where both give the same answer, so the order does not matter.
    """
    xi, yi = pts[i, 0], pts[i, 1]
    t = -1
    a = -1
    b = -1
    for q in range(nfan):
        step = (q + 1) // 2
        s = fan[(first + (step if q % 2 == 1 else -step)) % nfan]
        p = _local(tri, s, i)
        j, k = tri[s, (p + 1) % 3], tri[s, (p + 2) % 3]
        oj = _orient(xi, yi, pts[j, 0], pts[j, 1], cx, cy)
        ok = _orient(xi, yi, pts[k, 0], pts[k, 1], cx, cy)
        if oj >= 0.0 and ok <= 0.0:
            if _orient(pts[j, 0], pts[j, 1], pts[k, 0], pts[k, 1], cx, cy) >= 0.0:
                return True
            if oj == 0.0 or ok == 0.0:
                return False
            t = nb[s, p]
            a, b = j, k
            break
    if t < 0:
        return False
    for _ in range(max_steps):
        # entered t through edge (a, b): a right of the ray, b left of it
        w = tri[t, 0] + tri[t, 1] + tri[t, 2] - a - b
        pa = _local(tri, t, a)
        pb = _local(tri, t, b)
        inside = True
        for k in range(3):
            u, v = tri[t, k], tri[t, (k + 1) % 3]
            if _orient(pts[u, 0], pts[u, 1], pts[v, 0], pts[v, 1], cx, cy) < 0.0:
                inside = False
        if inside:
            return True
        ow = _orient(xi, yi, cx, cy, pts[w, 0], pts[w, 1])
        if ow > 0.0:      # w left: leave through (a, w), opposite b
            nxt = nb[t, pb]
            b = w
        elif ow < 0.0:    # w right: leave through (w, b), opposite a
            nxt = nb[t, pa]
            a = w
        else:
            return False
        if nxt < 0:
            return False
        t = nxt
    return False


@numba.njit(cache=True)
def _open_fan(i, tri, nb, offsets, star, out):
    """Triangles around boundary node ``i`` in CCW order, one fan only; count or -1."""
    deg = offsets[i + 1] - offsets[i]
    t0 = -1
    for m in range(offsets[i], offsets[i + 1]):
        s = star[m]
        p = _local(tri, s, i)
        if nb[s, (p + 2) % 3] < 0:      # edge (i, next vertex) is a constraint
            if t0 >= 0:
                return -1               # several fans
            t0 = s
    if t0 < 0:
        return -1
    t = t0
    count = 0
    while t >= 0:
        if count >= deg:
            return -1
        out[count] = t
        count += 1
        p = _local(tri, t, i)
        t = nb[t, (p + 1) % 3]
    return count if count == deg else -1


@numba.njit(cache=True)
def _fast_polygon(i, pts, tri, nb, offsets, star, cc, merge_tol, fan, path, poly):
    """Write the fast-path cell of node ``i`` into ``poly``; count, or -1 if not fast.

    ``fan`` and ``path`` are scratch arrays of lengths ``max_deg`` and ``max_deg + 2``;
    ``poly`` has room for a vertex per triangle around ``i`` and three more.
    """
    xi, yi = pts[i, 0], pts[i, 1]
    nfan = _ordered_fan(i, tri, nb, offsets, star, fan)
    closed = nfan >= 3
    if not closed:
        nfan = _open_fan(i, tri, nb, offsets, star, fan)
        if nfan < 1:
            return -1
    npath = 0
    angle = 0.0
    if not closed:
        p = _local(tri, fan[0], i)
        a = tri[fan[0], (p + 1) % 3]
        path[0, 0] = 0.5 * (xi + pts[a, 0])
        path[0, 1] = 0.5 * (yi + pts[a, 1])
        npath = 1
    for m in range(nfan):
        t = fan[m]
        if not closed:                  # the angle of an open fan (a closed one has 2 pi)
            p = _local(tri, t, i)
            j, k = tri[t, (p + 1) % 3], tri[t, (p + 2) % 3]
            ux, uy = pts[j, 0] - xi, pts[j, 1] - yi
            vx, vy = pts[k, 0] - xi, pts[k, 1] - yi
            angle += np.arctan2(ux * vy - uy * vx, ux * vx + uy * vy)
        if not _visible(i, cc[t, 0], cc[t, 1], pts, tri, nb, fan, nfan, m, 64):
            return -1
        path[npath, 0] = cc[t, 0]
        path[npath, 1] = cc[t, 1]
        npath += 1
    if not closed:
        if angle > np.pi * (1.0 + 1e-12):
            return -1                   # reflex corner or crack tip
        p = _local(tri, fan[nfan - 1], i)
        b = tri[fan[nfan - 1], (p + 2) % 3]
        path[npath, 0] = 0.5 * (xi + pts[b, 0])
        path[npath, 1] = 0.5 * (yi + pts[b, 1])
        npath += 1
    scale = 0.0
    for m in range(npath):
        scale = max(scale, np.hypot(path[m, 0] - xi, path[m, 1] - yi))
    tol = merge_tol * scale
    last = npath if closed else npath - 1
    count = 0
    if not closed:
        poly[0, 0] = xi
        poly[0, 1] = yi
        poly[1, 0] = path[0, 0]
        poly[1, 1] = path[0, 1]
        count = 2
    for m in range(last):
        q = (m + 1) % npath
        o = _orient(xi, yi, path[m, 0], path[m, 1], path[q, 0], path[q, 1])
        if o < -tol * scale:
            return -1
        if np.hypot(path[q, 0] - path[m, 0], path[q, 1] - path[m, 1]) > tol:
            poly[count, 0] = path[q, 0]
            poly[count, 1] = path[q, 1]
            count += 1
    return count if count >= 3 else -1


@parallel_kernel("which")
def fast_cells(pts, tri, nb, offsets, star, cc, merge_tol, max_deg, which, room, poly):
    """Cells of the nodes ``which`` that need no clipping.

    Parameters
    ----------
    pts : (n, 2) float64
    tri : (t, 3) int64
    nb : (t, 3) int64
        Neighbours with region changes cut (-1).
    offsets, star : CSR of the triangles around each node.
    cc : (t, 2) float64
        Circumcentres.
    merge_tol : float
        Relative distance under which consecutive vertices are merged.
    max_deg : int
        Largest vertex degree.
    which : (w,) int64
        The nodes whose cells are wanted.
    room : (w + 1,) int64
        Where each node's room starts in ``poly``: a vertex per triangle of its star
        and three more.
    poly : (room[w], 2) float64
        Written: the cell of ``which[s]``, CCW, is ``poly[room[s]:room[s] + count[s]]``
        (allocated by the caller: NumPy's large arrays get huge pages, numba's do not,
        and first touching 4 KiB pages cost more than the writes).

    Returns
    -------
    status : (w,) int8
        ``FAST`` or ``SLOW``, per entry of ``which``.
    count : (w,) int64
        0 for slow nodes.
    region_tri : (w,) int64
        One triangle of each fast node (for its region).
    """
    w = which.shape[0]
    status = np.full(w, SLOW, dtype=np.int8)
    counts = np.zeros(w, dtype=np.int64)
    region_tri = np.full(w, -1, dtype=np.int64)
    nch = (w + 255) // 256               # chunks of about 256 nodes share work buffers
    for ch in numba.prange(nch):
        fan = np.empty(max_deg, dtype=np.int64)
        path = np.empty((max_deg + 2, 2))
        for s in range(ch * w // nch, (ch + 1) * w // nch):
            i = which[s]
            c = _fast_polygon(i, pts, tri, nb, offsets, star, cc, merge_tol, fan, path,
                              poly[room[s]:room[s + 1]])
            if c > 0:
                status[s] = FAST
                counts[s] = c
                region_tri[s] = star[offsets[i]]
    return status, counts, region_tri


@parallel_kernel("dst_start")
def place_rows(src, src_start, dst, dst_start, length):
    """Copy blocks of rows: ``dst[dst_start[b]:][:length[b]] = src[src_start[b]:][:length[b]]``
    for every block ``b`` (``src``, ``dst``: (k, 2) float64, written in place)."""
    for b in numba.prange(dst_start.shape[0]):
        for k in range(length[b]):
            dst[dst_start[b] + k, 0] = src[src_start[b] + k, 0]
            dst[dst_start[b] + k, 1] = src[src_start[b] + k, 1]


@parallel_kernel("vertices")
def polygon_moments(offsets, vertices):
    """Areas and centroids of polygons by the shoelace formula, each relative to
    its first vertex (no cancellation far from the origin).

    Parameters
    ----------
    offsets : (m + 1,) int64
        Polygon ``c`` is ``vertices[offsets[c]:offsets[c + 1]]``.
    vertices : (k, 2) float64

    Returns
    -------
    area : (m,) float64
        Signed (positive counter-clockwise).
    centroid : (m, 2) float64
    """
    m = offsets.shape[0] - 1
    area = np.empty(m)
    centroid = np.empty((m, 2))
    for c in numba.prange(m):
        lo, hi = offsets[c], offsets[c + 1]
        x0, y0 = vertices[lo, 0], vertices[lo, 1]
        a = cx = cy = 0.0
        for i in range(lo, hi):
            j = i + 1 if i + 1 < hi else lo
            x, y = vertices[i, 0] - x0, vertices[i, 1] - y0
            xn, yn = vertices[j, 0] - x0, vertices[j, 1] - y0
            cross = x * yn - xn * y
            a += cross
            cx += (x + xn) * cross
            cy += (y + yn) * cross
        area[c] = 0.5 * a
        centroid[c, 0] = cx / (3.0 * a) + x0
        centroid[c, 1] = cy / (3.0 * a) + y0
    return area, centroid


@numba.njit(cache=True)
def fan_regions(pts, tri, region, offsets, star, nodes):
    """The regions around each of ``nodes`` (the cells the fast path left), with the
    distance from the node to the farthest vertex of its triangles in that region.

    Parameters
    ----------
    pts : (n, 2) float64
    tri : (t, 3) int64
    region : (t,) int64
    offsets, star : CSR of the triangles around each node.
    nodes : (w,) int64
        Sorted.

    Returns
    -------
    node, reg : (m,) int64
        The (node, region) pairs, sorted by node then region.
    far : (m,) float64
    """
    total = 0
    for i in nodes:
        total += offsets[i + 1] - offsets[i]
    node = np.empty(total, dtype=np.int64)
    reg = np.empty(total, dtype=np.int64)
    far = np.empty(total)
    m = 0
    for i in nodes:
        first = m
        for k in range(offsets[i], offsets[i + 1]):
            t, r = star[k], region[star[k]]
            d = 0.0
            for c in range(3):
                dx, dy = pts[tri[t, c], 0] - pts[i, 0], pts[tri[t, c], 1] - pts[i, 1]
                d = max(d, np.sqrt(dx * dx + dy * dy))
            at = first
            while at < m and reg[at] < r:            # the node's regions, kept sorted
                at += 1
            if at < m and reg[at] == r:
                far[at] = max(far[at], d)
                continue
            for q in range(m, at, -1):
                reg[q], far[q] = reg[q - 1], far[q - 1]
            node[m], reg[at], far[at] = i, r, d
            m += 1
    return node[:m], reg[:m], far[:m]


@numba.njit(cache=True)
def solid_tetrahedra(points, tets, tie):
    """Which tetrahedra ``(t,)`` are not flat: ``|V| > tie L^3``, ``L`` the longest edge
    (`.tetrahedra._solid`)."""
    out = np.empty(len(tets), dtype=np.bool_)
    x = np.empty((4, 3))
    for k in range(len(tets)):
        for i in range(4):
            for c in range(3):
                x[i, c] = points[tets[k, i], c]
        u0, u1, u2 = x[1, 0] - x[0, 0], x[1, 1] - x[0, 1], x[1, 2] - x[0, 2]
        v0, v1, v2 = x[2, 0] - x[0, 0], x[2, 1] - x[0, 1], x[2, 2] - x[0, 2]
        w0, w1, w2 = x[3, 0] - x[0, 0], x[3, 1] - x[0, 1], x[3, 2] - x[0, 2]
        six_v = u0 * (v1 * w2 - v2 * w1) + u1 * (v2 * w0 - v0 * w2) + u2 * (v0 * w1 - v1 * w0)
        longest = 0.0
        for i in range(3):
            for j in range(i + 1, 4):
                e0, e1, e2 = x[i, 0] - x[j, 0], x[i, 1] - x[j, 1], x[i, 2] - x[j, 2]
                longest = max(longest, e0 * e0 + e1 * e1 + e2 * e2)
        out[k] = abs(six_v) / 6.0 > tie * longest ** 1.5
    return out
