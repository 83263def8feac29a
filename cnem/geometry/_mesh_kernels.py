"""Numba kernels of a triangulation's tables (arrays and scalars only): the canonical
triangle order, vertex stars, adjacency, circumcentres.

Each one computes what a few NumPy calls did with sorts of every triangle edge (a
sort of ``3 t`` keys at 1M nodes cost about as much as `triangle` itself), in linear
time and with the same results bit for bit: the same arithmetic in the same order.
"""

import numba
import numpy as np

from .. import _compile  # noqa: F401  (says once when the kernels compile)
from .._parallel import parallel_kernel


@parallel_kernel("tri")
def orient_and_centroids(points, tri):
    """Turn clockwise triangles counter-clockwise (in place) and return their centroids.

    Parameters
    ----------
    points : (n, 2) float64
    tri : (t, 3) int32 or int64
        Modified: a clockwise triangle ``(a, b, c)`` becomes ``(a, c, b)``.

    Returns
    -------
    (t, 2) float64
        The centroid of each triangle as oriented, its vertices summed in their order.
    """
    t = tri.shape[0]
    centroid = np.empty((t, 2))
    for s in numba.prange(t):
        a, b, c = tri[s, 0], tri[s, 1], tri[s, 2]
        ax, ay = points[a, 0], points[a, 1]
        if (points[b, 0] - ax) * (points[c, 1] - ay) - (points[b, 1] - ay) * (points[c, 0] - ax) < 0:
            b, c = c, b
            tri[s, 1], tri[s, 2] = b, c
        centroid[s, 0] = (ax + points[b, 0] + points[c, 0]) / 3.0
        centroid[s, 1] = (ay + points[b, 1] + points[c, 1]) / 3.0
    return centroid


@parallel_kernel("tri")
def canonical_order(tri, n):
    """The triangles each from its smallest node on (counter-clockwise kept), sorted
    by their nodes (first, second, third): a stable counting sort by the first node,
    then an insertion sort of each node's few triangles.

    Parameters
    ----------
    tri : (t, 3) int32 or int64
    n : int
        Number of nodes (> every entry of ``tri``).

    Returns
    -------
    rotated : (t, 3) int64
        Sorted.
    order : (t,) int64
        ``rotated[k]`` is a rotation of ``tri[order[k]]``.
    """
    t = tri.shape[0]
    rot = np.empty((t, 3), dtype=np.int64)
    for s in numba.prange(t):
        first = 0
        for k in range(1, 3):
            if tri[s, k] < tri[s, first]:
                first = k
        for k in range(3):
            rot[s, k] = tri[s, (first + k) % 3]
    start = np.zeros(n + 1, dtype=np.int64)
    for s in range(t):
        start[rot[s, 0] + 1] += 1
    for v in range(n):
        start[v + 1] += start[v]
    fill = start[:n].copy()
    order = np.empty(t, dtype=np.int64)
    for s in range(t):
        order[fill[rot[s, 0]]] = s
        fill[rot[s, 0]] += 1
    for v in numba.prange(n):
        for p in range(start[v] + 1, start[v + 1]):
            s = order[p]
            q = p
            while q > start[v] and (rot[order[q - 1], 1] > rot[s, 1] or (
                    rot[order[q - 1], 1] == rot[s, 1] and rot[order[q - 1], 2] > rot[s, 2])):
                order[q] = order[q - 1]
                q -= 1
            order[q] = s
    out = np.empty((t, 3), dtype=np.int64)
    for p in numba.prange(t):
        for k in range(3):
            out[p, k] = rot[order[p], k]
    return out, order


@numba.njit(cache=True)
def vertex_star(tri, n):
    """CSR of the triangles around each vertex, each vertex's in increasing order.

    Returns
    -------
    offsets : (n + 1,) int64
    star : (3 t,) int64
    """
    t = tri.shape[0]
    offsets = np.zeros(n + 1, dtype=np.int64)
    for s in range(t):
        for k in range(3):
            offsets[tri[s, k] + 1] += 1
    for v in range(n):
        offsets[v + 1] += offsets[v]
    fill = offsets[:n].copy()
    star = np.empty(3 * t, dtype=np.int64)
    for s in range(t):
        for k in range(3):
            v = tri[s, k]
            star[fill[v]] = s
            fill[v] += 1
    return offsets, star


@parallel_kernel("tri")
def edge_neighbors(tri, offsets, star):
    """The triangle across each edge, found in the star of the edge's first end.

    Parameters
    ----------
    tri : (t, 3) int64
        A triangulation: each edge in at most two triangles.
    offsets, star : CSR of the triangles around each vertex (`vertex_star`).

    Returns
    -------
    (t, 3) int64
        ``nb[s, k]``: the other triangle with the edge opposite vertex ``k``, -1 if none.
    """
    t = tri.shape[0]
    nb = np.full((t, 3), -1, dtype=np.int64)
    for s in numba.prange(t):
        for k in range(3):
            a, b = tri[s, (k + 1) % 3], tri[s, (k + 2) % 3]
            for p in range(offsets[a], offsets[a + 1]):
                u = star[p]
                if u != s and (tri[u, 0] == b or tri[u, 1] == b or tri[u, 2] == b):
                    nb[s, k] = u
                    break
    return nb


@parallel_kernel("nb")
def cut_regions(nb, region):
    """``nb`` with -1 where the neighbour lies in another region (a new array)."""
    t = nb.shape[0]
    out = np.empty((t, 3), dtype=np.int64)
    for s in numba.prange(t):
        for k in range(3):
            u = nb[s, k]
            out[s, k] = u if u < 0 or region[u] == region[s] else -1
    return out


@parallel_kernel("tri")
def circumcentres(points, tri):
    """Circumcentres ``(t, 2)`` of the triangles, relative to the vertex opposite their
    longest edge: the squared lengths of the two others are the smallest terms the
    formula can subtract (relative to another vertex of a sliver, ``|b|^2 c_x`` and
    ``|c|^2 b_x`` agree in all but their last digits, and the centre of a 0.1 x 4e-9
    right triangle moved by 1 % of its height)."""
    t = tri.shape[0]
    out = np.empty((t, 2))
    for s in numba.prange(t):
        k, longest = 0, -1.0
        for e in range(3):
            u, v = tri[s, (e + 1) % 3], tri[s, (e + 2) % 3]
            length = (points[u, 0] - points[v, 0]) ** 2 + (points[u, 1] - points[v, 1]) ** 2
            if length > longest:
                k, longest = e, length
        a, b, c = tri[s, k], tri[s, (k + 1) % 3], tri[s, (k + 2) % 3]
        ax, ay = points[a, 0], points[a, 1]
        bx, by = points[b, 0] - ax, points[b, 1] - ay
        cx, cy = points[c, 0] - ax, points[c, 1] - ay
        d = 2.0 * (bx * cy - by * cx)
        b2, c2 = bx * bx + by * by, cx * cx + cy * cy
        out[s, 0] = ax + (cy * b2 - by * c2) / d
        out[s, 1] = ay + (bx * c2 - cx * b2) / d
    return out


@numba.njit(cache=True)
def close_neighbours(cc, nb, tol):
    """Pairs of neighbouring triangles (lower index first) whose points ``cc`` lie
    within ``tol`` of each other.

    Returns
    -------
    low, high : (q,) int64
        In the order of the lower triangle, then of its edge.
    """
    t = nb.shape[0]
    close = np.zeros((t, 3), dtype=np.bool_)
    count = 0
    for s in range(t):
        for k in range(3):
            u = nb[s, k]
            if u > s:
                dx, dy = cc[s, 0] - cc[u, 0], cc[s, 1] - cc[u, 1]
                # hypot >= max(|dx|, |dy|): the cheap test first
                if abs(dx) <= tol and abs(dy) <= tol and np.hypot(dx, dy) <= tol:
                    close[s, k] = True
                    count += 1
    low = np.empty(count, dtype=np.int64)
    high = np.empty(count, dtype=np.int64)
    q = 0
    for s in range(t):
        for k in range(3):
            if close[s, k]:
                low[q], high[q] = s, nb[s, k]
                q += 1
    return low, high


@numba.njit(cache=True)
def _opposite(tri, s, a, b):
    """The vertex position of triangle ``s`` opposite its edge ``{a, b}``, or -1."""
    for k in range(3):
        x, y = tri[s, (k + 1) % 3], tri[s, (k + 2) % 3]
        if (x == a and y == b) or (x == b and y == a):
            return k
    return -1


@numba.njit(cache=True)
def edge_triangles(tri, offsets, star, edges):
    """The triangles with each edge, found in the star of its first end.

    Parameters
    ----------
    tri : (t, 3) int64
    offsets, star : CSR of the triangles around each vertex (`vertex_star`).
    edges : (e, 2) int64

    Returns
    -------
    ptr : (e + 1,) int64
    slot : (ptr[e],) int64
        ``3 s + k`` for each triangle ``s`` (in increasing order) whose edge opposite
        vertex ``k`` is the edge.
    """
    e = edges.shape[0]
    ptr = np.zeros(e + 1, dtype=np.int64)
    for g in range(e):
        a = edges[g, 0]
        ptr[g + 1] = ptr[g]
        for p in range(offsets[a], offsets[a + 1]):
            if _opposite(tri, star[p], a, edges[g, 1]) >= 0:
                ptr[g + 1] += 1
    slot = np.empty(ptr[e], dtype=np.int64)
    for g in range(e):
        a = edges[g, 0]
        q = ptr[g]
        for p in range(offsets[a], offsets[a + 1]):
            k = _opposite(tri, star[p], a, edges[g, 1])
            if k >= 0:
                slot[q] = 3 * star[p] + k
                q += 1
    return ptr, slot


@numba.njit(cache=True)
def region_members(tri, region, n, m):
    """``(n, m)`` bool: whether node ``j`` is a vertex of a triangle of region ``r``
    (``region`` in ``[0, m)``)."""
    member = np.zeros((n, m), dtype=np.bool_)
    for s in range(tri.shape[0]):
        for k in range(3):
            member[tri[s, k], region[s]] = True
    return member
