"""Numba kernels of the constrained natural-neighbour coordinates (arrays and scalars only).

For a query point ``x`` in triangle ``t`` of the constrained Delaunay
triangulation (cracks opened, neighbours across region boundaries cut):

* ``x`` at a vertex: the Kronecker delta;
* ``x`` on a constraint edge (boundary, interface side, crack face): the
  limit of the coordinates, linear interpolation between the edge's ends
  (C-NEM paper §3.5, Figure 8);
* otherwise the constrained Bowyer-Watson cavity of ``x`` (triangles whose
  circumcircle holds ``x``, reached from ``t`` across unconstrained edges
  only) gives the natural neighbours, its boundary vertices. The Sibson
  coordinate of neighbour ``i`` (eq. 3-4) is the area that ``x``'s Voronoi
  cell takes from ``i``'s: the polygon of the two new Voronoi vertices
  (circumcentres of ``x`` with the two cavity-boundary edges at ``i``) and
  the old ones (circumcentres of the cavity triangles around ``i``), all
  computed relative to ``x`` (Watson's formula).
"""

import numba
import numpy as np

from .. import _compile  # noqa: F401  (says once when the kernels compile)
from .._parallel import parallel_kernel
from .._predicates import orient2d as _orient

#: Row kinds returned by the counting pass.
CAVITY, AT_NODE, ON_EDGE, FAILED = 0, 1, 2, 3

#: Largest cavity (triangles) and neighbour count handled.
MAX_CAVITY = 512


@numba.njit(cache=True, inline="always")
def _circumcentre(ax, ay, bx, by, cx, cy):
    """Circumcentre of (a, b, c), computed relative to ``a``."""
    bx -= ax
    by -= ay
    cx -= ax
    cy -= ay
    d = 2.0 * (bx * cy - by * cx)
    b2 = bx * bx + by * by
    c2 = cx * cx + cy * cy
    return ax + (cy * b2 - by * c2) / d, ay + (bx * c2 - cx * b2) / d


@numba.njit(cache=True, inline="always")
def _in_circle(nodes, tri, t, x, y):
    """Whether (x, y) lies strictly inside the circumcircle of CCW triangle ``t``."""
    ax, ay = nodes[tri[t, 0], 0] - x, nodes[tri[t, 0], 1] - y
    bx, by = nodes[tri[t, 1], 0] - x, nodes[tri[t, 1], 1] - y
    cx, cy = nodes[tri[t, 2], 0] - x, nodes[tri[t, 2], 1] - y
    a2, b2, c2 = ax * ax + ay * ay, bx * bx + by * by, cx * cx + cy * cy
    det = a2 * (bx * cy - by * cx) - b2 * (ax * cy - ay * cx) + c2 * (ax * by - ay * bx)
    # a filtered predicate: when round-off could flip the sign (x on the circle
    # to working precision) the triangle is left out, consistently; its share
    # of the coordinates is zero there anyway (they are C1 across circles)
    permanent = (a2 * (abs(bx * cy) + abs(by * cx)) + b2 * (abs(ax * cy) + abs(ay * cx))
                 + c2 * (abs(ax * by) + abs(ay * bx)))
    return det > 1e-14 * permanent


@numba.njit(cache=True)
def _special(nodes, tri, nb, t, x, y, node_tol, edge_tol):
    """Node or constraint-edge case: ``(kind, a, b, s)`` (phi_a = 1 - s, phi_b = s)."""
    for k in range(3):
        v = tri[t, k]
        if abs(nodes[v, 0] - x) <= node_tol and abs(nodes[v, 1] - y) <= node_tol:
            return AT_NODE, v, v, 0.0
    for k in range(3):
        if nb[t, k] >= 0:
            continue
        a, b = tri[t, (k + 1) % 3], tri[t, (k + 2) % 3]
        ex, ey = nodes[b, 0] - nodes[a, 0], nodes[b, 1] - nodes[a, 1]
        length2 = ex * ex + ey * ey
        rx, ry = x - nodes[a, 0], y - nodes[a, 1]
        dist = abs(ex * ry - ey * rx) / np.sqrt(length2)
        if dist <= edge_tol:
            s = (ex * rx + ey * ry) / length2
            return ON_EDGE, a, b, min(max(s, 0.0), 1.0)
    return CAVITY, -1, -1, 0.0


@numba.njit(cache=True)
def _cavity(nodes, tri, nb, t, x, y, cav):
    """Constrained Bowyer-Watson cavity of (x, y) from triangle ``t``; its size or -1."""
    cav[0] = t
    size = 1
    head = 0
    while head < size:
        c = cav[head]
        head += 1
        for k in range(3):
            o = nb[c, k]
            if o < 0:
                continue
            seen = False
            for m in range(size):
                if cav[m] == o:
                    seen = True
                    break
            if seen or not _in_circle(nodes, tri, o, x, y):
                continue
            if size == cav.shape[0]:
                return -1
            cav[size] = o
            size += 1
    return size


@numba.njit(cache=True)
def _cavity_index(cav, size, o):
    """Position of triangle ``o`` in the cavity, -1 if it is not in it."""
    if o < 0:
        return -1
    for m in range(size):
        if cav[m] == o:
            return m
    return -1


@numba.njit(cache=True)
def _natural_row(nodes, tri, nb, x, y, cav, size, cols, vals, gx, gy, scratch, laplace,
                 need_edges):
    """Sibson (or Laplace) coordinates from a cavity: the neighbour count, -1 if inconsistent.

    Laplace: ``w_i = |Voronoi edge between x and i| / |x - x_i|``, normalised;
    the Voronoi edge joins the two new circumcentres at ``i``.

    Sibson gradients (Piper; Braun and Sambridge) go to ``gx, gy``: the area
    ``A_i`` taken from ``i`` changes as ``grad A_i = s_i / r_i (m_i - x)`` with
    ``s_i`` the length and ``m_i`` the midpoint of that Voronoi edge and
    ``r_i = |x_i - x|``; then ``grad phi_i = (grad A_i - phi_i grad A) / A``.

    ``scratch`` is a ``(MAX_CAVITY, 8)`` float work array: the circumcentres of
    the cavity triangles and of the new triangles, each computed once, and the
    cavity adjacency (everything relative to ``x``).
    """
    # columns 0-1: old Voronoi vertices (cavity), 2-3: new ones (one per boundary edge)
    for m in range(size):
        s = cav[m]
        scratch[m, 0], scratch[m, 1] = _circumcentre(nodes[tri[s, 0], 0] - x, nodes[tri[s, 0], 1] - y,
                                       nodes[tri[s, 1], 0] - x, nodes[tri[s, 1], 1] - y,
                                       nodes[tri[s, 2], 0] - x, nodes[tri[s, 2], 1] - y)
    # boundary edges (i, j), CCW in their cavity triangle m: cols holds i,
    # the adjacency of the cavity goes to scratch columns 4-6 (-1: boundary)
    count = 0
    for m in range(size):
        c = cav[m]
        for k in range(3):
            o = _cavity_index(cav, size, nb[c, k])
            scratch[m, 4 + k] = o
            if o >= 0:
                continue
            if count == cols.shape[0]:
                return -1
            i, j = tri[c, (k + 1) % 3], tri[c, (k + 2) % 3]
            scratch[count, 2], scratch[count, 3] = _circumcentre(
                nodes[i, 0] - x, nodes[i, 1] - y, nodes[j, 0] - x, nodes[j, 1] - y, 0.0, 0.0)
            cols[count] = i
            scratch[count, 7] = m                     # cavity triangle of edge `count`
            count += 1
    total = 0.0
    for e in range(count):
        i = cols[e]
        fx, fy = scratch[e, 2], scratch[e, 3]     # new vertex on the (i, j) bisector
        qx, qy = fx, fy
        area = 0.0
        m = int(scratch[e, 7])
        steps = 0
        while True:                      # counter-clockwise around i through the cavity
            s = cav[m]
            p = 0
            while tri[s, p] != i:
                p += 1
            area += qx * scratch[m, 1] - qy * scratch[m, 0]
            qx, qy = scratch[m, 0], scratch[m, 1]
            nxt = int(scratch[m, 4 + (p + 1) % 3])    # across edge (i, tri[s, p + 2])
            if nxt < 0:
                break
            m = nxt
            steps += 1
            if steps > size:
                return -1
        h = tri[cav[m], (p + 2) % 3]     # the previous boundary edge is (h, i)
        prev = -1
        for f in range(count):
            if cols[f] == h and int(scratch[f, 7]) == m:
                prev = f
                break
        if prev < 0:
            return -1
        ox, oy = scratch[prev, 2], scratch[prev, 3]
        area += qx * oy - qy * ox
        area += ox * fy - oy * fx
        if need_edges:
            edge = np.hypot(fx - ox, fy - oy) / np.hypot(nodes[i, 0] - x, nodes[i, 1] - y)
            gx[e] = 0.5 * edge * (fx + ox)
            gy[e] = 0.5 * edge * (fy + oy)
            weight = edge if laplace else 0.5 * area
        else:
            weight = 0.5 * area
            gx[e] = 0.0
            gy[e] = 0.0
        vals[e] = weight
        total += weight
    if not total > 0.0:
        return -1
    sum_gx, sum_gy = 0.0, 0.0
    for m in range(count):
        sum_gx += gx[m]
        sum_gy += gy[m]
    for m in range(count):
        vals[m] /= total
        gx[m] = (gx[m] - vals[m] * sum_gx) / total
        gy[m] = (gy[m] - vals[m] * sum_gy) / total
    return count


@numba.njit(cache=True)
def _row_size(nodes, tri, nb, t, x, y, node_tol, edge_tol, cav):
    """Number of natural neighbours of one point (its cavity's boundary edges)."""
    kind, a, b, s = _special(nodes, tri, nb, t, x, y, node_tol, edge_tol)
    if kind == AT_NODE:
        return 1
    if kind == ON_EDGE:
        return 2
    size = _cavity(nodes, tri, nb, t, x, y, cav)
    if size < 0:
        return 0
    count = 0
    for m in range(size):
        for k in range(3):
            if _cavity_index(cav, size, nb[cav[m], k]) < 0:
                count += 1
    return count


@numba.njit(cache=True)
def _row(nodes, tri, nb, t, x, y, node_tol, edge_tol, cav, cols, vals, gx, gy, scratch,
         laplace, need_edges):
    """Coordinates of one point: ``(kind, count)`` with the row in ``cols, vals``."""
    kind, a, b, s = _special(nodes, tri, nb, t, x, y, node_tol, edge_tol)
    if kind == AT_NODE:
        cols[0], vals[0] = a, 1.0
        return kind, 1
    if kind == ON_EDGE:
        cols[0], vals[0] = a, 1.0 - s
        cols[1], vals[1] = b, s
        return kind, 2
    size = _cavity(nodes, tri, nb, t, x, y, cav)
    if size < 0:
        return FAILED, 0
    count = _natural_row(nodes, tri, nb, x, y, cav, size, cols, vals, gx, gy, scratch,
                         laplace, need_edges)
    if count < 0:
        return FAILED, 0
    return CAVITY, count


@parallel_kernel("points")
def natural(nodes, tri, nb, points, tri_of, node_tol, edge_tol, nch, laplace, gradient,
            slots):
    """Sibson (or Laplace) coordinates of many points, one pass, rows in visit order.

    Each chunk of points writes its rows one after the other into its own
    region of the output, ``slots`` entries per point (the rows are moved to
    their final places by `permute_rows`, or read where they are); a chunk
    whose rows do not fit stops and is reported (call again with more slots).

    Parameters
    ----------
    nodes : (n, 2) float64
    tri : (t, 3) int64, counter-clockwise
    nb : (t, 3) int64
        Neighbour across the edge opposite each vertex; -1 across constraints.
    points : (p, 2) float64
        The points in the order they are visited (neighbouring points one
        after the other keep the triangulation in cache).
    tri_of : (p,) int64
        A triangle containing each point (same order).
    node_tol, edge_tol : float
        Distances under which a point is at a node / on a constraint edge.
    nch : int
        Work chunks shared between threads.
    laplace : bool
        Laplace (non-Sibsonian) instead of Sibson coordinates.
    gradient : bool
        Also return the Sibson gradients (rows at nodes and on constraint
        edges, where they are not defined, stay zero).
    slots : int
        Room per point in the chunks' regions.

    Returns
    -------
    start, size : (p,) int64
        Row ``s`` is ``cols[start[s]:start[s] + size[s]]`` (same for the values).
    cols : (p * slots,) int32
    vals, gx, gy : (p * slots,) float64
        Values and gradients (``gx, gy`` empty unless ``gradient``).
    kinds : (p,) int8
        ``CAVITY``, ``AT_NODE``, ``ON_EDGE`` or ``FAILED`` (an inconsistent
        cavity; the row is empty).
    full : bool
        Some chunk ran out of room (the result is incomplete).
    """
    p = points.shape[0]
    start = np.zeros(p, dtype=np.int64)
    size = np.zeros(p, dtype=np.int64)
    kinds = np.zeros(p, dtype=np.int8)
    nch = max(1, min(p, nch))
    out_cols = np.empty(p * slots, dtype=np.int32)
    out_vals = np.empty(p * slots)
    out_gx = np.zeros(p * slots if gradient else 0)
    out_gy = np.zeros(p * slots if gradient else 0)
    full = np.zeros(nch, dtype=np.bool_)
    for ch in numba.prange(nch):
        cav = np.empty(MAX_CAVITY, dtype=np.int64)
        cols = np.empty(MAX_CAVITY, dtype=np.int64)
        vals, gx, gy = np.empty(MAX_CAVITY), np.empty(MAX_CAVITY), np.empty(MAX_CAVITY)
        scratch = np.empty((MAX_CAVITY, 8))
        lo, hi = ch * p // nch, (ch + 1) * p // nch
        a, end = lo * slots, hi * slots
        for s in range(lo, hi):
            kind, c = _row(nodes, tri, nb, tri_of[s], points[s, 0], points[s, 1], node_tol,
                           edge_tol, cav, cols, vals, gx, gy, scratch, laplace,
                           laplace or gradient)
            kinds[s] = kind
            start[s] = a
            if kind == FAILED:
                continue
            if a + c > end:
                full[ch] = True
                break
            size[s] = c
            for e in range(c):           # element-wise: slices would cost atomic
                out_cols[a + e] = cols[e]    # reference counts in a parallel loop
                out_vals[a + e] = vals[e]
            if gradient and kind == CAVITY:
                for e in range(c):
                    out_gx[a + e] = gx[e]
                    out_gy[a + e] = gy[e]
            a += c
    return start, size, out_cols, out_vals, out_gx, out_gy, kinds, full.any()


@parallel_kernel("points")
def locate(nodes, tri, points, cand_off, cand_idx, tol):
    """The candidate triangle that contains each point best (-1 if none within ``tol``).

    "Best" is the largest smallest-barycentric-orientation, so a point on an
    edge or at a node picks a triangle deterministically.
    """
    p = points.shape[0]
    out = np.full(p, -1, dtype=np.int64)
    for q in numba.prange(p):
        x, y = points[q, 0], points[q, 1]
        best = -np.inf
        for c in range(cand_off[q], cand_off[q + 1]):
            t = cand_idx[c]
            worst = np.inf
            for k in range(3):
                a, b = tri[t, k], tri[t, (k + 1) % 3]
                ex, ey = nodes[b, 0] - nodes[a, 0], nodes[b, 1] - nodes[a, 1]
                o = _orient(nodes[a, 0], nodes[a, 1], nodes[b, 0], nodes[b, 1], x, y)
                o /= np.sqrt(ex * ex + ey * ey)      # signed distance to the edge
                worst = min(worst, o)
            if worst > best:
                best = worst
                if worst >= -tol:
                    out[q] = t
    return out


@numba.njit(cache=True)
def _walk(nodes, tri, nb, t, x, y, max_steps):
    """Visibility walk from triangle ``t`` to the one holding (x, y); -1 if it leaves
    the triangulation (a hole, a crack face, the outside) or takes too long."""
    for _ in range(max_steps):
        moved = False
        for k in range(3):
            a, b = tri[t, (k + 1) % 3], tri[t, (k + 2) % 3]
            if _orient(nodes[a, 0], nodes[a, 1], nodes[b, 0], nodes[b, 1], x, y) < 0.0:
                t = nb[t, k]
                if t < 0:
                    return -1
                moved = True
                break
        if not moved:
            return t
    return -1


@parallel_kernel("points")
def locate_walk(nodes, tri, nb, points, seeds, nch):
    """Triangles holding points by walking from one point to the next.

    The points are ordered along a space-filling path; chunk ``c`` of them
    starts from triangle ``seeds[c]``. Points the walk cannot reach get -1
    (locate them with the R-tree).
    """
    p = points.shape[0]
    out = np.full(p, -1, dtype=np.int64)
    for ch in numba.prange(nch):
        t = seeds[ch]
        for s in range(ch * p // nch, (ch + 1) * p // nch):
            if t < 0:
                break
            found = _walk(nodes, tri, nb, t, points[s, 0], points[s, 1], 4096)
            if found >= 0:
                out[s] = found
                t = found
    return out


@parallel_kernel("order")
def permute_rows(start, size, cols, vals, gx, gy, order):
    """Rows ``s`` (``cols[start[s]:start[s] + size[s]]``) moved to CSR rows ``order[s]``.

    Filling rows in the order the points were visited and moving them
    afterwards (reads in that order, each row written to its place) is much
    cheaper than computing them in the order of the rows.

    Returns
    -------
    offsets : (p + 1,) int64
    cols : (k,) int32
    vals, gx, gy : (k,) float64
    """
    p = order.shape[0]
    moved = np.empty(p, dtype=np.int64)
    for s in numba.prange(p):
        moved[order[s]] = size[s]
    new = np.zeros(p + 1, dtype=np.int64)
    for q in range(p):                    # sequential reads only in the serial loop
        new[q + 1] = new[q] + moved[q]
    out_cols = np.empty(new[p], dtype=np.int32)
    out_vals = np.empty(new[p])
    grad = gx.shape[0] > 0
    out_gx = np.empty(new[p] if grad else 0)
    out_gy = np.empty(new[p] if grad else 0)
    for s in numba.prange(p):
        a, b = start[s], new[order[s]]
        for e in range(size[s]):
            out_cols[b + e] = cols[a + e]
            out_vals[b + e] = vals[a + e]
            if grad:
                out_gx[b + e] = gx[a + e]
                out_gy[b + e] = gy[a + e]
    return new, out_cols, out_vals, out_gx, out_gy


@numba.njit(cache=True)
def path_order(points, x0, y0, sx, sy, k):
    """Order of points along a serpentine path through a ``k x k`` grid.

    A counting sort by grid cell, rows of cells alternating in direction, so
    that consecutive points are close (cheap walks, cache-friendly).
    """
    p = points.shape[0]
    key = np.empty(p, dtype=np.int64)
    count = np.zeros(k * k + 1, dtype=np.int64)
    for q in range(p):
        ix = min(max(int((points[q, 0] - x0) * sx), 0), k - 1)
        iy = min(max(int((points[q, 1] - y0) * sy), 0), k - 1)
        if iy & 1:
            ix = k - 1 - ix
        key[q] = iy * k + ix
        count[key[q] + 1] += 1
    for c in range(k * k):
        count[c + 1] += count[c]
    order = np.empty(p, dtype=np.int64)
    for q in range(p):
        order[count[key[q]]] = q
        count[key[q]] += 1
    return order


@parallel_kernel("order")
def gather_rows(points, order):
    """``points[order]`` for a ``(p, 2)`` array, in parallel."""
    out = np.empty((order.shape[0], 2))
    for s in numba.prange(order.shape[0]):
        out[s, 0] = points[order[s], 0]
        out[s, 1] = points[order[s], 1]
    return out
