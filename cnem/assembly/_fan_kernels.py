"""Numba kernels of the fans of triangles that cover the integration cells."""

import numba
import numpy as np

from .. import _compile  # noqa: F401  (says once when the kernels compile)
from .._parallel import parallel_kernel


@numba.njit(cache=True)
def _min_fan(ax, ay, verts, lo, hi):
    """Smallest twice-signed area of the triangles (apex, v_i, v_i+1) of a polygon."""
    least = np.inf
    for i in range(lo, hi):
        j = i + 1 if i + 1 < hi else lo
        bx, by = verts[i, 0] - ax, verts[i, 1] - ay
        cx, cy = verts[j, 0] - ax, verts[j, 1] - ay
        least = min(least, bx * cy - by * cx)
    return least


@parallel_kernel("offsets")
def fan_apexes(offsets, verts, centroid, node_xy, node_first, area):
    """The apex of every cell's fan.

    The centroid where every triangle of its fan has a positive area (more than
    1e-12 of the cell's) and ``node_first`` is not set, else the cell's node
    where no triangle of its fan is negative beyond that, else the first vertex
    (a fan with signed areas).

    Parameters
    ----------
    offsets : (m + 1,) int64
    verts : (k, 2) float64
    centroid, node_xy : (m, 2) float64
    node_first : (m,) bool
    area : (m,) float64

    Returns
    -------
    (m, 2) float64
    """
    m = offsets.shape[0] - 1
    apex = np.empty((m, 2))
    for c in numba.prange(m):
        lo, hi = offsets[c], offsets[c + 1]
        tol = 1e-12 * area[c]
        if not node_first[c] and _min_fan(centroid[c, 0], centroid[c, 1], verts, lo, hi) > tol:
            apex[c, 0], apex[c, 1] = centroid[c, 0], centroid[c, 1]
        elif _min_fan(node_xy[c, 0], node_xy[c, 1], verts, lo, hi) >= -tol:
            apex[c, 0], apex[c, 1] = node_xy[c, 0], node_xy[c, 1]
        else:
            apex[c, 0], apex[c, 1] = verts[lo, 0], verts[lo, 1]
    return apex


@numba.njit(cache=True)
def _kept(ax, ay, verts, i, j, floor):
    """Twice the area of (apex, v_i, v_j) exceeds ``floor``."""
    bx, by = verts[i, 0] - ax, verts[i, 1] - ay
    cx, cy = verts[j, 0] - ax, verts[j, 1] - ay
    return bx * cy - by * cx > floor


@numba.njit(cache=True)
def _same_point(verts, i, ax, ay):
    return verts[i, 0] == ax and verts[i, 1] == ay


@numba.njit(cache=True)
def fan_sub_cells(offsets, verts, apex, area, whole):
    """The fan triangles of every cell as cells of their own.

    A cell stays whole where ``whole`` is set or a triangle of its fan is
    negative; triangles of twice-area at most 1e-9 of the cell's (slivers) are
    left out.

    Returns
    -------
    parent : (s,) int64
        The cell of each sub-cell, sorted (a cell's triangles in the order of
        its vertices).
    sub_offsets : (s + 1,) int64
    sub_verts : (k, 2) float64
        Triangles run ``apex, v_i, v_i+1``; whole cells keep their polygon.
    spokes : (k,) bool
        The edge from a vertex to the next is a spoke (from or to the apex)
        that is not also an edge of the cell (an apex on a cell vertex).
    source : (k,) int64
        Where the edge from a vertex to the next comes from, as a position in
        its parent's polygon: the cell edge from vertex ``source`` to the next
        (the same direction), or for a spoke the vertex it joins to the apex.
    """
    m = offsets.shape[0] - 1
    keep_whole = whole.copy()
    nsub, nvert = 0, 0
    for c in range(m):
        lo, hi = offsets[c], offsets[c + 1]
        if not keep_whole[c] and _min_fan(apex[c, 0], apex[c, 1], verts, lo, hi) < 0.0:
            keep_whole[c] = True
        if keep_whole[c]:
            nsub += 1
            nvert += hi - lo
            continue
        floor = 1e-9 * area[c]
        for i in range(lo, hi):
            if _kept(apex[c, 0], apex[c, 1], verts, i, i + 1 if i + 1 < hi else lo, floor):
                nsub += 1
                nvert += 3
    parent = np.empty(nsub, dtype=np.int64)
    sub_offsets = np.empty(nsub + 1, dtype=np.int64)
    sub_verts = np.empty((nvert, 2))
    spokes = np.zeros(nvert, dtype=np.bool_)
    source = np.empty(nvert, dtype=np.int64)
    s, v = 0, 0
    sub_offsets[0] = 0
    for c in range(m):
        lo, hi = offsets[c], offsets[c + 1]
        if keep_whole[c]:
            for i in range(lo, hi):
                sub_verts[v, 0], sub_verts[v, 1] = verts[i, 0], verts[i, 1]
                source[v] = i - lo
                v += 1
            parent[s] = c
            s += 1
            sub_offsets[s] = v
            continue
        floor = 1e-9 * area[c]
        ax, ay = apex[c, 0], apex[c, 1]
        for i in range(lo, hi):
            j = i + 1 if i + 1 < hi else lo
            if not _kept(ax, ay, verts, i, j, floor):
                continue
            h = i - 1 if i > lo else hi - 1
            k = j + 1 if j + 1 < hi else lo
            sub_verts[v, 0], sub_verts[v, 1] = ax, ay
            sub_verts[v + 1, 0], sub_verts[v + 1, 1] = verts[i, 0], verts[i, 1]
            sub_verts[v + 2, 0], sub_verts[v + 2, 1] = verts[j, 0], verts[j, 1]
            source[v + 1] = i - lo                   # v_i -> v_i+1: the cell's edge
            if _same_point(verts, h, ax, ay):        # apex -> v_i is the edge v_i-1 -> v_i
                source[v] = h - lo
            else:
                spokes[v], source[v] = True, i - lo
            if _same_point(verts, k, ax, ay):        # v_i+1 -> apex is the edge v_i+1 -> v_i+2
                source[v + 2] = j - lo
            else:
                spokes[v + 2], source[v + 2] = True, j - lo
            v += 3
            parent[s] = c
            s += 1
            sub_offsets[s] = v
    return parent, sub_offsets, sub_verts, spokes, source


@numba.njit(cache=True)
def fan_spokes(sub_offsets, sub_verts, spokes, vertex, nvert):
    """The distinct spokes of fan sub-cells: one per cell vertex joined to its apex.

    Parameters
    ----------
    sub_offsets : (s + 1,) int64
    sub_verts : (k, 2) float64
    spokes : (k,) bool
        The edge from a sub-cell vertex to the next is a spoke.
    vertex : (k,) int64
        For a spoke, the cell vertex it joins to the apex (an index among the
        ``nvert`` vertices of the cells).
    nvert : int

    Returns
    -------
    rows : (u, 5) float64
        Every distinct spoke from its lexicographically smaller end, as
        ``[x0, y0, x1, y1, -1]`` (the rows of `canonical_rows`).
    index : (k,) int64
        The distinct spoke of every spoke edge (-1 for other edges).
    sign : (k,) float64
        -1 where the edge runs against its distinct spoke, else 1.
    """
    number = np.full(nvert, -1, dtype=np.int64)
    u = 0
    for e in range(spokes.shape[0]):
        if spokes[e] and number[vertex[e]] < 0:
            number[vertex[e]] = u
            u += 1
    rows = np.empty((u, 5))
    index = np.full(spokes.shape[0], -1, dtype=np.int64)
    sign = np.ones(spokes.shape[0])
    for s in range(sub_offsets.shape[0] - 1):
        lo, hi = sub_offsets[s], sub_offsets[s + 1]
        for e in range(lo, hi):
            if not spokes[e]:
                continue
            f = e + 1 if e + 1 < hi else lo
            ax, ay, bx, by = sub_verts[e, 0], sub_verts[e, 1], sub_verts[f, 0], sub_verts[f, 1]
            if ax > bx or (ax == bx and ay > by):
                ax, ay, bx, by = bx, by, ax, ay
                sign[e] = -1.0
            d = number[vertex[e]]
            index[e] = d
            rows[d, 0], rows[d, 1], rows[d, 2], rows[d, 3], rows[d, 4] = ax, ay, bx, by, -1.0
    return rows, index, sign
