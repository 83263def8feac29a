"""Numba kernel of the half-plane path of the constrained Voronoi cells.

A node whose circumcentres lie behind a constraint (the triangles of a thin
strip, whose nodes sit on its two edges only, have circumcentres far outside
it) but whose neighbourhood is convex owns a convex cell: the part of a box
around it that it sees, cut by the lines of the constraint edges that cross
that part from side to side (beyond such a chord nothing is visible), then by
the bisectors with the nodes inside that visible part. Any constraint end
(a reflex corner, a crack tip, an interface node) within twice the cell's
radius, or a constraint edge ending inside the visible part, sends the node to
the exact clipping path instead.
"""

import numba
import numpy as np

from .. import _compile  # noqa: F401  (says once when the kernels compile)

#: Status codes of `clip_cell`.
CLIPPED, GROW, REFUSED = 0, 1, 2

#: Kinds of node by their constraint edges: none, one in and one out, any other.
BARE, SIMPLE, COMPLEX = 0, 1, 2


@numba.njit(cache=True)
def _clip(poly, n, px, py, nx, ny, off, out):
    """Keep the part of convex ``poly[:n]`` where ``nx x + ny y <= off``; new count."""
    m = 0
    for k in range(n):
        q = (k + 1) % n
        va = nx * (poly[k, 0] - px) + ny * (poly[k, 1] - py) - off
        vb = nx * (poly[q, 0] - px) + ny * (poly[q, 1] - py) - off
        if va <= 0.0:
            out[m, 0] = poly[k, 0]
            out[m, 1] = poly[k, 1]
            m += 1
        if (va <= 0.0) != (vb <= 0.0):
            t = va / (va - vb)
            out[m, 0] = poly[k, 0] + t * (poly[q, 0] - poly[k, 0])
            out[m, 1] = poly[k, 1] + t * (poly[q, 1] - poly[k, 1])
            m += 1
    for k in range(m):
        poly[k, 0] = out[k, 0]
        poly[k, 1] = out[k, 1]
    return m


@numba.njit(cache=True)
def _side(poly, n, ux, uy, vx, vy):
    """Lowest and highest signed distance of ``poly[:n]`` to the line ``u -> v``
    (positive on its left)."""
    dx, dy = vx - ux, vy - uy
    length = np.hypot(dx, dy)
    lo, hi = np.inf, -np.inf
    for k in range(n):
        d = (dx * (poly[k, 1] - uy) - dy * (poly[k, 0] - ux)) / length
        lo = min(lo, d)
        hi = max(hi, d)
    return lo, hi


@numba.njit(cache=True)
def _radius(poly, n, x):
    """Largest distance from ``x`` to a vertex of ``poly[:n]`` (one square root)."""
    r2 = 0.0
    for k in range(n):
        dx, dy = poly[k, 0] - x[0], poly[k, 1] - x[1]
        r2 = max(r2, dx * dx + dy * dy)
    return np.sqrt(r2)


@numba.njit(cache=True)
def clip_cell(x, box, extent, wedge, edges, near, near_wedge, ends, tol, poly, work, seen):
    """The half-plane cell of one node (see the module docstring).

    Parameters
    ----------
    x : (2,) float64
        The node.
    box : (4,) float64
        ``xmin, ymin, xmax, ymax`` around it, within the nodes' extent.
    extent : (4,) float64
        The nodes' bounding box (no point of the region lies beyond it).
    wedge : (w, 4) float64
        The node's own constraint edges ``u -> v`` (region on their left); none for
        an interior node, two at a convex boundary node.
    edges : (e, 6) float64
        The other constraint edges of the region that may meet the box: ``u``, ``v``,
        then how far the boundary runs on along their line (`collinear_reach`).
    near : (p, 2) float64
        Nodes of the region in the box, nearest first (the node itself excluded).
    near_wedge : (p, 4) float64
        For a node on a boundary, its incoming edge direction and its outgoing one
        (the region on their left); zeros for an interior node.
    ends : (q, 2) float64
        Constraint ends that are not convex boundary nodes (reflex corners, crack
        tips, interface nodes) near the box.
    tol : float
        Absolute length under which points are on a line.
    poly, work, seen : (2 (4 + w + e + p) + 8, 2), (same, 2), (same, 3) float64
        Scratch; the cell is written to ``poly[:k]``.

    Returns
    -------
    status : int
        `CLIPPED`, `GROW` (the cell may reach beyond the box: retry a larger one)
        or `REFUSED` (leave the node to the exact path).
    k : int
        Vertices of the counter-clockwise cell ``poly[:k]`` when `CLIPPED`, else 0.
    """
    poly[0, 0], poly[0, 1] = box[0], box[1]
    poly[1, 0], poly[1, 1] = box[2], box[1]
    poly[2, 0], poly[2, 1] = box[2], box[3]
    poly[3, 0], poly[3, 1] = box[0], box[3]
    n = 4
    for k in range(wedge.shape[0]):
        ux, uy, vx, vy = wedge[k, 0], wedge[k, 1], wedge[k, 2], wedge[k, 3]
        nx, ny = vy - uy, ux - vx                  # outward normal (region on the left)
        n = _clip(poly, n, ux, uy, nx, ny, 0.0, work)
    # chords: a constraint edge across the visible part hides what lies beyond it
    for _ in range(edges.shape[0] + 1):
        changed = False
        for k in range(edges.shape[0]):
            ux, uy, vx, vy = edges[k, 0], edges[k, 1], edges[k, 2], edges[k, 3]
            lo, hi = _side(poly, n, ux, uy, vx, vy)
            if lo >= -tol or hi <= tol:
                continue                           # the line misses the interior
            dx, dy = vx - ux, vy - uy
            length = np.hypot(dx, dy)
            tmin, tmax = np.inf, -np.inf           # the line's chord, along u -> v
            for a in range(n):
                b = (a + 1) % n
                da = (dx * (poly[a, 1] - uy) - dy * (poly[a, 0] - ux)) / length
                db = (dx * (poly[b, 1] - uy) - dy * (poly[b, 0] - ux)) / length
                if (da <= 0.0) != (db <= 0.0):
                    s = da / (da - db)
                    px = poly[a, 0] + s * (poly[b, 0] - poly[a, 0])
                    py = poly[a, 1] + s * (poly[b, 1] - poly[a, 1])
                    t = ((px - ux) * dx + (py - uy) * dy) / length
                    tmin = min(tmin, t)
                    tmax = max(tmax, t)
            if tmax <= tol or tmin >= length - tol:
                continue                           # the segment lies beside the part
            if tmin < edges[k, 4] - tol or tmax > edges[k, 5] + tol:
                return REFUSED, 0                  # it ends inside the visible part
            di = (dx * (x[1] - uy) - dy * (x[0] - ux)) / length
            if abs(di) <= tol:
                return REFUSED, 0
            sign = 1.0 if di > 0 else -1.0         # keep the node's side
            n = _clip(poly, n, ux, uy, sign * dy, -sign * dx, 0.0, work)
            changed = True
        if not changed:
            break
    ns = n                                         # the visible part, its sides' lengths
    for k in range(n):
        seen[k, 0], seen[k, 1] = poly[k, 0], poly[k, 1]
    for a in range(n):
        b = (a + 1) % n
        seen[a, 2] = np.hypot(seen[b, 0] - seen[a, 0], seen[b, 1] - seen[a, 1])
    cx, cy = 0.0, 0.0
    for k in range(n):
        cx += seen[k, 0] / ns
        cy += seen[k, 1] / ns
    radius = _radius(poly, n, x)
    for j in range(near.shape[0]):
        qx, qy = near[j, 0], near[j, 1]
        dj = np.hypot(qx - x[0], qy - x[1])
        if dj > 2.0 * radius:
            break
        if dj <= tol:
            continue
        lo = np.inf                                # is q in the visible part?
        for a in range(ns):
            b = (a + 1) % ns
            ex, ey = seen[b, 0] - seen[a, 0], seen[b, 1] - seen[a, 1]
            length = seen[a, 2]
            if length > 0.0:
                lo = min(lo, (ex * (qy - seen[a, 1]) - ey * (qx - seen[a, 0])) / length)
        if lo < -tol:
            continue
        w = near_wedge[j]
        if w[0] != 0.0 or w[1] != 0.0:             # on a boundary: does it face the part?
            if w[0] * (cy - qy) - w[1] * (cx - qx) < 0.0 or w[2] * (cy - qy) - w[3] * (cx - qx) < 0.0:
                continue
        nx, ny = qx - x[0], qy - x[1]
        mx, my = 0.5 * (qx + x[0]), 0.5 * (qy + x[1])
        n = _clip(poly, n, mx, my, nx, ny, 0.0, work)
        if n < 3:
            return REFUSED, 0
        radius = _radius(poly, n, x)
    for k in range(ends.shape[0]):
        if np.hypot(ends[k, 0] - x[0], ends[k, 1] - x[1]) <= 2.0 * radius + tol:
            return REFUSED, 0
    reach = 2.0 * radius + tol
    if ((x[0] - reach < box[0] and box[0] > extent[0]) or (x[1] - reach < box[1] and box[1] > extent[1])
            or (x[0] + reach > box[2] and box[2] < extent[2])
            or (x[1] + reach > box[3] and box[3] < extent[3])):
        return GROW, 0
    return CLIPPED, n


@numba.njit(cache=True)
def collinear_reach(nodes, u, v, prev, nxt, kind, stop, box, tol):
    """How far the constraint edge ``u -> v`` runs on along its line: the boundary
    before ``u`` and after ``v`` through nodes with one edge in and one out, while it
    stays within ``tol`` of the line and inside ``box`` (and short of node ``stop``).

    A straight boundary cut into many edges (the long side of a sliver, seen from a node
    across it) crosses a cell from side to side though none of its edges does.

    Returns
    -------
    lo, hi : float
        Its extent along ``u -> v`` from ``u``: ``lo <= 0``, ``hi >= |v - u|``.
    """
    dx, dy = nodes[v, 0] - nodes[u, 0], nodes[v, 1] - nodes[u, 1]
    length = np.hypot(dx, dy)
    lo, hi = 0.0, length
    for forward in (True, False):
        w = v if forward else u
        for _ in range(nodes.shape[0]):
            inside = box[0] <= nodes[w, 0] <= box[2] and box[1] <= nodes[w, 1] <= box[3]
            if kind[w] != SIMPLE or not inside:
                break
            z = nxt[w] if forward else prev[w]
            if z == stop:
                break
            off = (dx * (nodes[z, 1] - nodes[u, 1]) - dy * (nodes[z, 0] - nodes[u, 0])) / length
            t = (dx * (nodes[z, 0] - nodes[u, 0]) + dy * (nodes[z, 1] - nodes[u, 1])) / length
            if abs(off) > tol or (t <= hi if forward else t >= lo):
                break
            if forward:
                hi = t
            else:
                lo = t
            w = z
    return lo, hi
