"""The convex case of the 3-D cells' general path, many cells at once (numba).

Most cells the fast dual path refuses (`.cells3d`: nodes on or near the boundary) have
no face that hides points and convex faces in reach (a box, its edges and corners, a
flat interface). Their cell is then one convex polytope: the cube about the node
clipped by the planes of those faces and by the bisectors that cut it, nearest first
(`.cells3d_clip.GeneralCells`, its unblocked convex case). `convex_cells` computes
these in one kernel (`._polytope_kernels.convex_cells`), clipping as
`.polytope.Polytope.clip` does, so the cells are those of `GeneralCells.cell`: the same
facets in the same order, to round-off. It leaves to `GeneralCells.cell` the cells
with a blocking face within its reach or a face with a re-entrant edge in reach, and
those the kernel refuses (faces not in convex position, an empty cell, a cube grown
past the bound).
"""

from __future__ import annotations

import itertools

import numpy as np
from scipy.spatial import cKDTree

from .._parallel import work_chunks
from ._polytope_kernels import DONE, GROW, MORE
from ._polytope_kernels import convex_cells as _convex_cells_kernel
from .cells3d_clip import GeneralCells

__all__ = ["convex_cells"]

#: Bound on the doublings of the cube (`.cells3d_clip`'s, whose last one it leaves to it).
_GROW = 6
#: Nearest nodes first given to each cell, and the factor when they are not enough.
_NEAR, _MORE = 32, 4
#: Relative widening of the radii of the candidate searches (round-off).
_WIDEN = 1.0 + 1e-9


def convex_cells(general: GeneralCells, node: np.ndarray,
                 region: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray,
                                              np.ndarray]:
    """The cells of the (node, region) pairs that are convex polytopes.

    Parameters
    ----------
    general : GeneralCells
        The general path's tables of the model.
    node, region : (w,) int64 ndarray
        The cells to try.

    Returns
    -------
    done : (w,) bool ndarray
        The cells computed here (the others: `GeneralCells.cell`).
    triangles : (q, 3, 3) float64 ndarray
        Their facet triangles, counter-clockwise from outside, cell by cell in the
        order of ``node``.
    cell : (q,) int64 ndarray
        The position in ``node`` of each triangle's cell.
    normal : (q, 3) float64 ndarray
        Outward unit normals.
    volume : (w,) float64 ndarray
        The cells' volumes (0 where not ``done``).
    """
    w = len(node)
    table = _face_table(general)
    done = np.zeros(w, dtype=bool)
    volume = np.zeros(w)
    parts: list = []
    half = np.ones(w)
    k_near = np.full(w, _NEAR)
    todo = _unblocked(general, node, region, half)
    for _ in range(3 * _GROW):                  # each round doubles a cube or widens `near`
        if len(todo) == 0:
            break
        width = int(k_near[todo].max()) + 1
        status, ntri, vol, _, _ = _run(general, node[todo], region[todo], half[todo], width,
                                       table, None)
        sub = np.flatnonzero(status == DONE)
        if len(sub):
            ptr = np.concatenate([[0], np.cumsum(ntri[sub])])
            *_, tri, nrm = _run(general, node[todo[sub]], region[todo[sub]], half[todo[sub]],
                                width, table, ptr)
            parts.append((todo[sub], ntri[sub], tri, nrm))
            done[todo[sub]] = True
            volume[todo[sub]] = vol[sub]
        grow = todo[status == GROW]
        half[grow] *= 2.0
        grow = grow[half[grow] <= 2.0 ** (_GROW - 1)]
        more = todo[status == MORE]
        k_near[more] *= _MORE
        retry = np.sort(np.concatenate([grow, more]))
        todo = retry[_unblocked(general, node[retry], region[retry], half[retry])]
    return (done,) + _gathered(parts, volume)


def _run(general, node, region, half, width, table, out_ptr):
    """The kernel on these cells, given their ``width`` nearest nodes: counting (``out_ptr``
    None) or writing their triangles."""
    table_face, table_normal, first_row = table
    rows_ptr, rows = _candidate_faces(general, node, region, half, first_row)
    near, near_far = _nearest(general, node, region, width)
    out_ptr = np.zeros(0, dtype=np.int64) if out_ptr is None else out_ptr
    return _convex_cells_kernel(general.points, general.faces, node, half, general.scale, rows_ptr,
                                rows, table_face, table_normal, near, near_far, out_ptr,
                                work_chunks())


def _gathered(parts, volume):
    """The rounds' triangles, cells and normals in the order of the cells, and ``volume``."""
    if not parts:
        return np.zeros((0, 3, 3)), np.zeros(0, dtype=np.int64), np.zeros((0, 3)), volume
    cell = np.concatenate([np.repeat(c, n) for c, n, _, _ in parts])
    order = np.argsort(cell, kind="stable")
    tri = np.concatenate([t for _, _, t, _ in parts])[order]
    nrm = np.concatenate([m for _, _, _, m in parts])[order]
    return tri, cell[order], nrm, volume


def _face_table(general):
    """Every region's faces in one table: face, outward normal, each region's first row."""
    idx = [f[0] for f in general.region_faces]
    first = np.concatenate([[0], np.cumsum([len(i) for i in idx])])
    return (np.concatenate(idx).astype(np.int64),
            np.ascontiguousarray(np.concatenate([f[1] for f in general.region_faces])), first)


def _unblocked(general, node, region, half, bent=True):
    """Positions of the cells with no blocking face within the general path's face search
    (``3 reach``) and (with ``bent``) no face with a re-entrant edge within ``reach``
    (bounding spheres): those may hide points or bend the region, and go to
    `GeneralCells.cell`."""
    keep = np.ones(len(node), dtype=bool)
    reach = np.sqrt(3.0) * half * general.scale[node]
    for r, (idx, _, _, block, bends) in enumerate(general.region_faces):
        mine = np.flatnonzero(region == r)
        for flag, radius in ((block, 3.0 * reach), (bends, reach))[:2 if bent else 1]:
            if not flag.any() or len(mine) == 0:
                continue
            centre = general.points[general.faces[idx[flag]]].mean(axis=1)
            tree = cKDTree(centre)
            near = tree.query_ball_point(general.points[node[mine]],
                                         (radius[mine] + general.face_radius) * _WIDEN,
                                         return_length=True)
            keep[mine[near > 0]] = False
    return np.flatnonzero(keep)


def _candidate_faces(general, node, region, half, first_row):
    """CSR ``(ptr, rows)`` of each cell's region faces (rows of the face table) whose
    centroids lie within the cube's circumradius plus the widest face's radius."""
    lists = np.empty(len(node), dtype=object)
    reach = np.sqrt(3.0) * half * general.scale[node]
    for r, (_, _, tree, _, _) in enumerate(general.region_faces):
        mine = np.flatnonzero(region == r)
        if len(mine) == 0:
            continue
        found = tree.query_ball_point(general.points[node[mine]],
                                     (reach[mine] + general.face_radius) * _WIDEN)
        lists[mine] = [np.asarray(f, dtype=np.int64) + first_row[r] for f in found]
    count = np.fromiter(map(len, lists), dtype=np.int64, count=len(node))
    rows = np.fromiter(itertools.chain.from_iterable(lists), dtype=np.int64, count=count.sum())
    return np.concatenate([[0], np.cumsum(count)]), rows


def _nearest(general, node, region, width):
    """Each cell's ``width`` nearest nodes of its region (itself among them), nearest
    first, -1 past the region's last, and the distance of the farthest (within which
    the region has no other node)."""
    near = np.full((len(node), width), -1, dtype=np.int64)
    far = np.full(len(node), np.inf)
    for r, (nodes, tree) in enumerate(general.region_nodes):
        mine = np.flatnonzero(region == r)
        if len(mine) == 0:
            continue
        k = min(width, len(nodes))
        dist, idx = tree.query(general.points[node[mine]], k=k)
        dist, idx = dist.reshape(len(mine), k), idx.reshape(len(mine), k)
        near[mine, :k] = nodes[idx]
        far[mine] = dist[:, -1] if k < len(nodes) else np.inf
    return near, far
