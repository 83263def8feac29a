"""Numba kernel of the half-plane path over many cells at once (`clip_cells`): each cell's
candidates gathered from lists shared by nearby cells, then clipped by `._clip_kernels.clip_cell`
or, at a reflex corner, by `._reflex_kernels.reflex_cell`."""

import numba
import numpy as np

from .. import _compile  # noqa: F401  (says once when the kernels compile)
from .._parallel import parallel_kernel
from ._clip_kernels import GROW, REFUSED, clip_cell, collinear_reach
from ._reflex_kernels import reflex_cell

#: Lists longer than this are sorted by numba's sort, shorter ones by insertion.
_SHORT = 32


@numba.njit(cache=True)
def _within(nodes, j, x, reach):
    """Whether node ``j`` lies within ``reach`` of ``x`` (squared, as a k-d tree tests)."""
    dx, dy = nodes[j, 0] - x[0], nodes[j, 1] - x[1]
    return dx * dx + dy * dy <= reach * reach


@parallel_kernel("cell_node")
def clip_cells(nodes, cell_node, cell_region, size, extent, prev, nxt, node_wedge, member, safe,
               reflex, kind, twin, edges, edge_region, edge_half, edge_ptr, edge_idx, group,
               near_ptr, near_idx, tol, line_tol, chunks):
    """`clip_cell` (`reflex_cell` at a reflex corner) of many (node, region) cells, each in
    its own box, from candidate lists shared by groups of nearby cells.

    The box of cell ``s`` has half-size ``size[s]`` and circumradius ``reach =
    sqrt(2) size[s]``; its chords are the constraint edges of its region whose
    midpoints lie within ``reach + edge_half``, its neighbours the region's nodes within
    ``reach`` (nearest first, ties by index), its constraint ends the nodes that are not
    ``safe`` within ``reach``. They are found among the candidates within ``reach +
    edge_half + tol``: an end of every constraint edge that meets the box (the edges
    further away that the midpoint test lets through cannot meet the box, and a chord
    that does not meet the cell changes nothing).

    Parameters
    ----------
    nodes : (n, 2) float64
    cell_node, cell_region : (w,) int64
        The cells: a ``safe`` or ``reflex`` node and one of its regions.
    size : (w,) float64
        Half-size of each cell's box (clipped to ``extent``).
    extent : (4,) float64
        The nodes' bounding box.
    prev, nxt : (n,) int64
        A boundary node's constraint neighbours before and after it (region on the
        left), -1 for an interior node.
    node_wedge : (n, 4) float64
        A convex boundary node's incoming and outgoing edge directions, zeros for
        every other node (`clip_cell`'s ``near_wedge``).
    member : (n, m) bool
        Whether node ``j`` is a vertex of a triangle of region ``r``.
    safe : (n,) bool
        Nodes with no constraint edge or on a convex boundary (the others are
        constraint ends: reflex corners, tips, interface nodes, crack-face copies).
    edges : (e, 2) int64
        Constraint edges ``u -> v`` (their region on the left).
    edge_region : (e,) int64
    edge_half : float
        Half the longest constraint edge.
    edge_ptr, edge_idx : (n + 1,), (2 e,) int64
        CSR of the constraint edges at each node (leaving or entering it).
    group : (w,) int64
        The candidate list of each cell.
    near_ptr, near_idx : (g + 1,), (k,) int64
        CSR of the candidate lists, in any order: each holds at least every node
        within ``reach + edge_half + tol`` of each cell of its group.
    tol : float
        Absolute length under which points are on a line.
    line_tol : float
        The same for the nodes of a straight boundary (`collinear_reach`): ``tol`` or
        the coordinates' round-off, the larger.
    chunks : int
        Work chunks the cells are cut into (`cnem._parallel.work_chunks`).

    Returns
    -------
    status : (w,) int8
        `CLIPPED`, `GROW` (retry with a larger box) or `REFUSED` (the exact path;
        also a cell that would grow beyond a box covering ``extent``).
    counts : (w,) int64
        Vertices of each clipped cell (0 otherwise).
    starts : (w + 1,) int64
        Where each cell's vertices start in ``out``.
    out : (k, 2) float64
        The counter-clockwise cells, cell ``s`` at ``out[starts[s]:starts[s] + counts[s]]``.
    """
    w = cell_node.shape[0]
    status = np.full(w, REFUSED, dtype=np.int8)
    counts = np.zeros(w, dtype=np.int64)
    starts = np.zeros(w + 1, dtype=np.int64)
    found = np.zeros(w, dtype=np.int64)
    for s in range(w):                   # as `clip_cell`'s scratch: one vertex per chord
        m = 0                            # and node at most
        x = nodes[cell_node[s]]
        for j in near_idx[near_ptr[group[s]]:near_ptr[group[s] + 1]]:
            if _within(nodes, j, x, size[s] * np.sqrt(2.0) + edge_half + tol):
                m += 1 + edge_ptr[j + 1] - edge_ptr[j]
                found[s] += 1
        starts[s + 1] = starts[s] + 2 * (6 + m) + 8
    out = np.empty((starts[w], 2))
    nch = max(1, min(chunks, w))
    for ch in numba.prange(nch):
        first, last = ch * w // nch, (ch + 1) * w // nch
        big = most = 0
        for s in range(first, last):
            big = max(big, starts[s + 1] - starts[s])
            most = max(most, found[s])
        box = np.empty(4)
        wedge = np.empty((2, 4))
        keep = np.empty(most, dtype=np.int64)
        dist = np.empty(most)
        ends = np.empty((most, 2))
        near = np.empty((most, 2))
        near_wedge = np.empty((most, 4))
        seg = np.empty(big, dtype=np.int64)
        chords = np.empty((big, 6))
        poly, work, seen = np.empty((big, 2)), np.empty((big, 2)), np.empty((big, 3))
        for s in range(first, last):
            status[s], counts[s] = _batch_cell(
                s, nodes, cell_node, cell_region, size, extent, prev, nxt, node_wedge, member, safe,
                reflex, kind, twin, edges, edge_region, edge_half, edge_ptr, edge_idx, group,
                near_ptr, near_idx, tol, line_tol, box, wedge, keep, dist, ends, near, near_wedge,
                seg, chords, poly, work, seen)
            for k in range(counts[s]):
                out[starts[s] + k, 0] = poly[k, 0]
                out[starts[s] + k, 1] = poly[k, 1]
    return status, counts, starts, out


@numba.njit(cache=True)
def _sort_ints(a, n):
    """Sort ``a[:n]`` in place (by insertion: a cell's lists are short)."""
    if n > _SHORT:
        a[:n].sort()
        return
    for k in range(1, n):
        v, t = a[k], k
        while t > 0 and a[t - 1] > v:
            a[t] = a[t - 1]
            t -= 1
        a[t] = v


@numba.njit(cache=True)
def _sort_near(keep, dist, p):
    """Order ``keep[:p]`` and ``dist[:p]`` in place by distance, ties by node index."""
    if p > _SHORT:
        first = np.argsort(keep[:p])
        k0, d0 = keep[:p][first], dist[:p][first]
        then = np.argsort(d0, kind="mergesort")
        keep[:p], dist[:p] = k0[then], d0[then]
        return
    for k in range(1, p):
        j, d, t = keep[k], dist[k], k
        while t > 0 and (dist[t - 1] > d or (dist[t - 1] == d and keep[t - 1] > j)):
            keep[t], dist[t] = keep[t - 1], dist[t - 1]
            t -= 1
        keep[t], dist[t] = j, d


@numba.njit(cache=True)
def _batch_cell(s, nodes, cell_node, cell_region, size, extent, prev, nxt, node_wedge, member, safe,
                reflex, kind, twin, edges, edge_region, edge_half, edge_ptr, edge_idx, group,
                near_ptr, near_idx, tol, line_tol, box, wedge, keep, dist, ends, near, near_wedge,
                seg, chords, poly, work, seen):
    """Cell ``s`` of `clip_cells` in the scratch arrays that follow ``tol``: its
    ``(status, vertex count)``, the cell in ``poly``."""
    i, r = cell_node[s], cell_region[s]
    x = nodes[i]
    reach = size[s] * np.sqrt(2.0)
    box[0] = max(x[0] - size[s], extent[0])
    box[1] = max(x[1] - size[s], extent[1])
    box[2] = min(x[0] + size[s], extent[2])
    box[3] = min(x[1] + size[s], extent[3])
    sides = 0
    if nxt[i] >= 0:
        a, b = prev[i], nxt[i]
        wedge[0, 0], wedge[0, 1], wedge[0, 2], wedge[0, 3] = nodes[a, 0], nodes[a, 1], x[0], x[1]
        wedge[1, 0], wedge[1, 1], wedge[1, 2], wedge[1, 3] = x[0], x[1], nodes[b, 0], nodes[b, 1]
        sides = 2
    far = reach + edge_half
    m = p = q = 0
    for j in near_idx[near_ptr[group[s]]:near_ptr[group[s] + 1]]:
        if not _within(nodes, j, x, reach + edge_half + tol):
            continue
        for k in range(edge_ptr[j], edge_ptr[j + 1]):
            e = edge_idx[k]
            u, v = edges[e, 0], edges[e, 1]
            if v == j and _within(nodes, u, x, reach + edge_half + tol):
                continue                         # a candidate too: found from there
            mx, my = 0.5 * (nodes[u, 0] + nodes[v, 0]), 0.5 * (nodes[u, 1] + nodes[v, 1])
            if (edge_region[e] == r and u != i and v != i
                    and (mx - x[0]) ** 2 + (my - x[1]) ** 2 <= far * far):
                seg[m] = e
                m += 1
        if _within(nodes, j, x, reach):
            if member[j, r] and j != i:
                keep[p] = j
                dist[p] = np.hypot(nodes[j, 0] - x[0], nodes[j, 1] - x[1])
                p += 1
            if not safe[j]:
                ends[q, 0], ends[q, 1] = nodes[j, 0], nodes[j, 1]
                q += 1
    if not reflex[i]:                    # `reflex_cell` only asks whether any edge crosses
        _sort_ints(seg, m)
    for k in range(m):
        u, v = edges[seg[k], 0], edges[seg[k], 1]
        chords[k, 0], chords[k, 1], chords[k, 2], chords[k, 3] = (nodes[u, 0], nodes[u, 1],
                                                                  nodes[v, 0], nodes[v, 1])
        if not reflex[i]:
            chords[k, 4], chords[k, 5] = collinear_reach(nodes, u, v, prev, nxt, kind, i, box,
                                                         line_tol)
    _sort_near(keep, dist, p)
    if reflex[i]:
        st, n = reflex_cell(nodes, i, box, extent, prev, nxt, kind, twin, keep, p, chords, m, tol,
                            poly, work)
    else:
        for k in range(p):
            j = keep[k]
            near[k, 0], near[k, 1] = nodes[j, 0], nodes[j, 1]
            for t in range(4):
                near_wedge[k, t] = node_wedge[j, t]
        st, n = clip_cell(x, box, extent, wedge[:sides], chords[:m], near[:p], near_wedge[:p],
                          ends[:q], tol, poly, work, seen)
    if (st == GROW and box[0] <= extent[0] and box[1] <= extent[1] and box[2] >= extent[2]
            and box[3] >= extent[3]):
        st = REFUSED
    return st, n

