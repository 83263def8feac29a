"""Numba kernel of the half-plane path at a reflex corner (`reflex_cell`).

A node at a reflex corner of a boundary (a vertex of a hole, the inner corner of
an L) sees its wedge, wider than a half-plane. Its cell is that wedge cut by the
bisectors with the nodes around it, *if* every node whose bisector bounds the cut
sees the points beyond that bisector; around a reflex corner some may not (the
corner hides them), and then the cell is larger. Rather than decide that from the
shape of the neighbourhood, the kernel clips the cell ``K`` and then proves it
exact, refusing the node (to the exact path) when it cannot:

1. no constraint edge crosses ``K`` (the fan of triangles from the node to its
   sides): the node sees all of ``K``, and every point of ``K`` is nearer to the
   node than to any other, so ``K`` lies in the cell;
2. for each node ``j`` whose bisector touches ``K``, no constraint edge crosses the
   triangle between ``j`` and the chord of ``K`` on that bisector, and the triangle
   starts into the region from ``j``: ``j`` sees the chord and the points just
   beyond it.

The cell is star-shaped around its node (a point nearer to a node that sees a
point of the segment from the node also sees, or another node nearer still does),
so were it larger than ``K``, a segment from the node would leave ``K`` across one
of those chords into points that ``j``, nearer, sees: they are not in the cell.
"""

import numba
import numpy as np

from .. import _compile  # noqa: F401  (says once when the kernels compile)
from ._clip_kernels import CLIPPED, COMPLEX, GROW, REFUSED, SIMPLE, _clip, _radius

#: Sides of the polygon that covers the wedge (each under 72 degrees, so that a side
#: stays farther than ``cos(36 deg)`` of its radius from the node).
_SIDES = 5


@numba.njit(cache=True)
def _separated(px, py, qx, qy, poly, n, tol):
    """Whether segment ``p-q`` misses the interior of the convex counter-clockwise
    ``poly[:n]`` (``n >= 2``; touching within ``tol`` is missing): a side of the polygon
    or the segment's line separates them."""
    for a in range(n):
        b = (a + 1) % n
        ex, ey = poly[b, 0] - poly[a, 0], poly[b, 1] - poly[a, 1]
        length = np.hypot(ex, ey)
        if length == 0.0:
            continue
        dp = (ex * (py - poly[a, 1]) - ey * (px - poly[a, 0])) / length
        dq = (ex * (qy - poly[a, 1]) - ey * (qx - poly[a, 0])) / length
        if dp <= tol and dq <= tol:
            return True
    dx, dy = qx - px, qy - py
    length = np.hypot(dx, dy)
    if length == 0.0:
        return True
    lo, hi = np.inf, -np.inf
    for a in range(n):
        d = (dx * (poly[a, 1] - py) - dy * (poly[a, 0] - px)) / length
        lo = min(lo, d)
        hi = max(hi, d)
    return lo >= -tol or hi <= tol


@numba.njit(cache=True)
def _meets_any(poly, n, edges, m, own, tol):
    """Whether a constraint edge (``edges[:m]`` and the two of ``own``) crosses the
    interior of the convex counter-clockwise ``poly[:n]``."""
    lox, loy = poly[:n, 0].min() - tol, poly[:n, 1].min() - tol
    hix, hiy = poly[:n, 0].max() + tol, poly[:n, 1].max() + tol
    for k in range(m + 2):
        e = edges[k] if k < m else own[k - m]
        if (max(e[0], e[2]) < lox or min(e[0], e[2]) > hix or max(e[1], e[3]) < loy
                or min(e[1], e[3]) > hiy):
            continue
        if not _separated(e[0], e[1], e[2], e[3], poly, n, tol):
            return True
    return False


@numba.njit(cache=True)
def _faces(nodes, j, prev, nxt, cx, cy, tol):
    """Whether the point ``(cx, cy)`` lies in the wedge of boundary node ``j`` (the
    region's side of its edges ``prev[j] -> j -> nxt[j]``, within ``tol``)."""
    a, b = prev[j], nxt[j]
    ux, uy = nodes[j, 0] - nodes[a, 0], nodes[j, 1] - nodes[a, 1]
    vx, vy = nodes[b, 0] - nodes[j, 0], nodes[b, 1] - nodes[j, 1]
    left_u = (ux * (cy - nodes[j, 1]) - uy * (cx - nodes[j, 0])) / np.hypot(ux, uy) >= -tol
    left_v = (vx * (cy - nodes[j, 1]) - vy * (cx - nodes[j, 0])) / np.hypot(vx, vy) >= -tol
    if ux * vy - uy * vx >= 0.0:
        return left_u and left_v
    return left_u or left_v


@numba.njit(cache=True)
def _wedge(nodes, i, a, b, box, poly, work):
    """Write to ``poly`` the wedge of node ``i`` (counter-clockwise from its edge to ``b`` to
    its edge from ``a``) cut to ``box``, starting at the node; its vertex count."""
    x = nodes[i]
    start = np.arctan2(nodes[b, 1] - x[1], nodes[b, 0] - x[0])
    sweep = np.arctan2(nodes[a, 1] - x[1], nodes[a, 0] - x[0]) - start
    if sweep <= 0.0:
        sweep += 2.0 * np.pi
    reach = 0.0
    for cx in (box[0], box[2]):
        for cy in (box[1], box[3]):
            reach = max(reach, np.hypot(cx - x[0], cy - x[1]))
    far = 2.0 * reach / np.cos(0.5 * sweep / _SIDES)
    poly[0, 0], poly[0, 1] = x[0], x[1]
    for k in range(_SIDES + 1):
        angle = start + sweep * k / _SIDES
        poly[k + 1, 0], poly[k + 1, 1] = x[0] + far * np.cos(angle), x[1] + far * np.sin(angle)
    n = _clip(poly, _SIDES + 2, box[2], box[3], 1.0, 0.0, 0.0, work)
    n = _clip(poly, n, box[0], box[1], -1.0, 0.0, 0.0, work)
    n = _clip(poly, n, box[2], box[3], 0.0, 1.0, 0.0, work)
    return _clip(poly, n, box[0], box[1], 0.0, -1.0, 0.0, work)


@numba.njit(cache=True)
def _past(nodes, x, j, poly, n):
    """How far ``poly[:n]`` reaches past the bisector of ``x`` and node ``j``, towards ``j``
    (-inf for a node at ``x``)."""
    ux, uy = nodes[j, 0] - x[0], nodes[j, 1] - x[1]
    dj = np.hypot(ux, uy)
    if dj == 0.0:
        return -np.inf
    top = -np.inf
    for v in range(n):
        top = max(top, ux * (poly[v, 0] - x[0]) + uy * (poly[v, 1] - x[1]))
    return (top - 0.5 * dj * dj) / dj


@numba.njit(cache=True)
def reflex_cell(nodes, i, box, extent, prev, nxt, kind, twin, near, p, edges, m, tol, poly, work):
    """The cell of reflex corner node ``i``, clipped and proved exact (module docstring).

    Parameters
    ----------
    nodes : (n, 2) float64
    i : int
        A node with one constraint edge in, ``prev[i] -> i``, and one out,
        ``i -> nxt[i]`` (the region on their left), turning right (reflex).
    box : (4,) float64
        ``xmin, ymin, xmax, ymax`` around it, within the nodes' extent.
    extent : (4,) float64
        The nodes' bounding box.
    prev, nxt : (n,) int64
        A boundary node's constraint neighbours (`clip_cells`).
    kind : (n,) int8
        ``BARE``, ``SIMPLE`` or ``COMPLEX`` (`._clip_kernels`): the node's constraint edges.
    twin : (n,) bool
        Nodes within ``tol`` of another (the copies of a crack-face node).
    near : (p,) int64
        The region's nodes in the box but ``i``, nearest first (ties by index).
    p : int
    edges : (m, 4 or more) float64
        The region's constraint edges but ``i``'s two that may meet the box (``u``, ``v``).
    m : int
    tol : float
        Absolute length under which points are on a line.
    poly, work : (2 (8 + p) + 8, 2) float64
        Scratch; the cell is written to ``poly[:k]``.

    Returns
    -------
    status : int
        `CLIPPED`, `GROW` (the cell may reach beyond the box) or `REFUSED`.
    k : int
        Vertices of the counter-clockwise cell ``poly[:k]`` when `CLIPPED`, else 0.
    """
    if twin[i]:
        return REFUSED, 0
    x = nodes[i]
    a, b = prev[i], nxt[i]
    own = np.empty((2, 4))
    own[0, 0], own[0, 1], own[0, 2], own[0, 3] = nodes[a, 0], nodes[a, 1], x[0], x[1]
    own[1, 0], own[1, 1], own[1, 2], own[1, 3] = x[0], x[1], nodes[b, 0], nodes[b, 1]
    n = _wedge(nodes, i, a, b, box, poly, work)
    radius = _radius(poly, n, x)
    touching = np.empty(p, dtype=np.int64)      # the nodes whose bisectors come near the cell
    t = 0
    for k in range(p):
        j = near[k]
        dj = np.hypot(nodes[j, 0] - x[0], nodes[j, 1] - x[1])
        if dj > 2.0 * radius:
            break
        past = _past(nodes, x, j, poly, n)
        if past < -tol or dj <= tol:
            continue                             # nor will it come near the smaller cell to be
        touching[t] = j
        t += 1
        if past > 0.0:
            n = _clip(poly, n, 0.5 * (nodes[j, 0] + x[0]), 0.5 * (nodes[j, 1] + x[1]),
                      nodes[j, 0] - x[0], nodes[j, 1] - x[1], 0.0, work)
            if n < 3:
                return REFUSED, 0
            radius = _radius(poly, n, x)
    grow = 2.0 * radius + tol
    if ((x[0] - grow < box[0] and box[0] > extent[0]) or (x[1] - grow < box[1] and box[1] > extent[1])
            or (x[0] + grow > box[2] and box[2] < extent[2])
            or (x[1] + grow > box[3] and box[3] < extent[3])):
        return GROW, 0
    # 1. the node sees its cell: no constraint crosses a triangle of its fan
    tri = np.empty((3, 2))
    for k in range(1, n - 1):
        tri[0, 0], tri[0, 1] = x[0], x[1]
        tri[1, 0], tri[1, 1] = poly[k, 0], poly[k, 1]
        tri[2, 0], tri[2, 1] = poly[k + 1, 0], poly[k + 1, 1]
        if _meets_any(tri, 3, edges, m, own, tol):
            return REFUSED, 0
    # 2. each node whose bisector bounds the cell sees beyond its chord
    for k in range(t):
        j = touching[k]
        qx, qy = nodes[j, 0], nodes[j, 1]
        dj = np.hypot(qx - x[0], qy - x[1])
        nx, ny = (qx - x[0]) / dj, (qy - x[1]) / dj
        mx, my = 0.5 * (qx + x[0]), 0.5 * (qy + x[1])
        lo, hi = np.inf, -np.inf
        for v in range(n):
            if nx * (poly[v, 0] - mx) + ny * (poly[v, 1] - my) >= -tol:
                along = nx * (poly[v, 1] - my) - ny * (poly[v, 0] - mx)
                if along > hi:                   # counter-clockwise: j, then the
                    hi = along                   # chord's end on j's right, then its left
                    tri[1, 0], tri[1, 1] = poly[v, 0], poly[v, 1]
                if along < lo:
                    lo = along
                    tri[2, 0], tri[2, 1] = poly[v, 0], poly[v, 1]
        if lo > hi:
            continue                             # the bisector misses the cell
        if twin[j] or kind[j] == COMPLEX:
            return REFUSED, 0
        tri[0, 0], tri[0, 1] = qx, qy
        corners = 3 if hi - lo > tol else 2
        if kind[j] == SIMPLE and not _faces(nodes, j, prev, nxt, (qx + tri[1, 0] + tri[2, 0]) / 3.0,
                                            (qy + tri[1, 1] + tri[2, 1]) / 3.0, tol):
            return REFUSED, 0
        if _meets_any(tri, corners, edges, m, own, tol):
            return REFUSED, 0
    count = 1                                    # drop repeated vertices
    for v in range(1, n):
        if np.hypot(poly[v, 0] - poly[count - 1, 0], poly[v, 1] - poly[count - 1, 1]) > tol:
            poly[count, 0], poly[count, 1] = poly[v, 0], poly[v, 1]
            count += 1
    while count > 3 and np.hypot(poly[count - 1, 0] - x[0], poly[count - 1, 1] - x[1]) <= tol:
        count -= 1
    return (CLIPPED, count) if count >= 3 else (REFUSED, 0)
