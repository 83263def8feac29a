"""The cells cut by their region's tetrahedra, many at once (numba).

Near a curved cavity or hole (its faceted surface has shallow re-entrant edges that do
not block: `.smooth_patches`) a node's cell is its Voronoi polytope among its region's
nodes cut by each tetrahedron of the region it meets, the faces between two
tetrahedra dropped (`.cells3d_clip.GeneralCells`, its unblocked non-convex case, by
`.tet_pieces`). `curved_cells` computes these in two kernels
(`._tet_cut_kernels.voronoi_balls`: each polytope's ball, for the search of the
tetrahedra it meets; `._tet_cut_kernels.tet_cut_cells`: the pieces), clipping as
`.polytope.Polytope.clip` does, so the cells are those of `GeneralCells.cell` to
round-off. Cubes grow as there. It leaves to `GeneralCells.cell` the cells with a
blocking face within its face search, those whose faces in reach are in convex
position, and those the kernels refuse (an empty cell, pieces that do not meet, a cube
grown past the bound).
"""

from __future__ import annotations

import itertools

import numpy as np

from .._parallel import work_chunks
from ._polytope_kernels import DONE, FACE, GROW, REFUSED
from ._polytope_kernels import convex_cells as _convex_kernel
from ._tet_cut_kernels import CONVEX, CUT, TET, tet_cut_cells, voronoi_balls
from .cells3d_clip import _FIRST_HALF, _GROW, GeneralCells
from .cells3d_convex import _candidate_faces, _face_table, _gathered, _unblocked

__all__ = ["curved_cells"]


def curved_cells(general: GeneralCells, node: np.ndarray,
                 region: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray,
                                              np.ndarray]:
    """The cells of the (node, region) pairs that are Voronoi polytopes cut by their
    region's tetrahedra.

    Parameters
    ----------
    general : GeneralCells
    node, region : (w,) int64 ndarray

    Returns
    -------
    done, triangles, cell, normal, volume
        As `.cells3d_convex.convex_cells`: the cells computed here ``(w,)`` (the others:
        `GeneralCells.cell`), their facet triangles ``(q, 3, 3)`` cell by cell in the
        order of ``node``, the position in ``node`` of each triangle's cell ``(q,)``,
        the outward unit normals ``(q, 3)`` and the volumes ``(w,)`` (0 where not done).
    """
    w = len(node)
    done = np.zeros(w, dtype=bool)
    volume = np.zeros(w)
    parts: list = []
    half = np.full(w, _FIRST_HALF)
    todo = _unblocked(general, node, region, half, bent=False)
    if len(todo) == 0:
        return (done, np.zeros((0, 3, 3)), np.zeros(0, dtype=np.int64), np.zeros((0, 3)),
                volume)
    table_face, table_normal, first_row = _face_table(general)
    table_bent = np.concatenate([f[4] for f in general.region_faces])
    tags = None                                 # the tetrahedra's tags, when a cell needs them
    for _ in range(_GROW):                      # each round doubles the cubes of some cells
        if len(todo) == 0:
            break
        n, r, hf = node[todo], region[todo], half[todo]
        rows_ptr, rows = _candidate_faces(general, n, r, hf, first_row)
        near_ptr, near_ids = _near_nodes(general, n, r, hf)
        route, centre, radius = voronoi_balls(general.points, general.faces, n, hf,
                                              general.scale, rows_ptr, rows, table_face,
                                              table_normal, table_bent, near_ptr, near_ids,
                                              work_chunks())
        status = np.full(len(todo), REFUSED, dtype=np.int8)
        one = np.flatnonzero(route == CONVEX)
        status[one] = _one_polytope(general, todo[one], n[one], hf[one],
                                    _subset(rows_ptr, rows, one), table_face, table_normal,
                                    _subset(near_ptr, near_ids, one), done, volume, parts)
        cut = np.flatnonzero(route == CUT)
        if len(cut) and tags is None:
            tags = _tet_tags(general)
        status[cut] = _cut_by_tets(general, todo[cut], n[cut], r[cut], hf[cut], tags,
                                   _subset(near_ptr, near_ids, cut), centre[cut], radius[cut],
                                   done, volume, parts)
        grow = todo[status == GROW]
        half[grow] *= 2.0
        grow = grow[half[grow] <= _FIRST_HALF * 2.0 ** (_GROW - 1)]
        todo = grow[_unblocked(general, node[grow], region[grow], half[grow], bent=False)]
    return (done,) + _gathered(parts, volume)


def _one_polytope(general, cells, node, half, rows_csr, table_face, table_normal, near_csr,
                  done, volume, parts):
    """The cells whose faces in reach are in convex position: one polytope each, the cube
    clipped by the faces' planes and the bisectors (`._polytope_kernels.convex_cells`,
    given every candidate node). Their statuses; `_counted_then_written` for the rest."""
    near = _padded(*near_csr)
    far = np.full(len(cells), np.inf)             # every node that may cut is in ``near``
    return _counted_then_written(
        lambda sub, out: _convex_kernel(general.points, general.faces, node[sub], half[sub],
                                        general.scale, *_subset(*rows_csr, sub), table_face,
                                        table_normal, near[sub], far[sub], out, work_chunks()),
        cells, done, volume, parts)


def _cut_by_tets(general, cells, node, region, half, tags, near_csr, centre, radius, done,
                 volume, parts):
    """The cells whose Voronoi polytopes (balls ``centre``, ``radius``) are cut by the
    region's tetrahedra near them (`._tet_cut_kernels.tet_cut_cells`). Their statuses;
    `_counted_then_written` for the rest."""
    tet_csr = _near_tets(general, region, centre, radius)
    return _counted_then_written(
        lambda sub, out: tet_cut_cells(general.points, general.tets, *tags, node[sub],
                                       half[sub], general.scale, *_subset(*near_csr, sub),
                                       *_subset(*tet_csr, sub), out, work_chunks()),
        cells, done, volume, parts)


def _counted_then_written(run, cells, done, volume, parts):
    """Run a cell kernel twice: ``run(sub, out_ptr)`` on the rows ``sub`` of ``cells``
    counting (``out_ptr`` empty), then writing the `DONE` ones; their triangles and
    normals appended to ``parts``, ``done`` and ``volume`` set. The statuses ``(w,)``."""
    every = np.arange(len(cells))
    if len(every) == 0:
        return np.zeros(0, dtype=np.int8)
    status, ntri, vol, _, _ = run(every, np.zeros(0, dtype=np.int64))
    sub = np.flatnonzero(status == DONE)
    if len(sub):
        *_, tri, nrm = run(sub, np.concatenate([[0], np.cumsum(ntri[sub])]))
        parts.append((cells[sub], ntri[sub], tri, nrm))
        done[cells[sub]] = True
        volume[cells[sub]] = vol[sub]
    return status


def _tet_tags(general):
    """Each tetrahedron face's tag for the kernel: `FACE` and its boundary face, or `TET`
    and its key (`.tet_pieces.RegionTets.cut`'s ``("f", face)`` and ``("t", key)``)."""
    rt = general.region_tets
    on_face = rt.boundary >= 0
    kind = np.where(on_face, FACE, TET).astype(np.int64)
    ident = np.where(on_face, rt.boundary, rt.face_key).astype(np.int64)
    return kind, ident, np.ascontiguousarray(rt.face_key, dtype=np.int64)


def _near_nodes(general, node, region, half):
    """CSR ``(ptr, ids)`` of each cell's region nodes within twice its cube's circumradius
    (`.cells3d_clip.GeneralCells`'s bisector candidates)."""
    lists = np.empty(len(node), dtype=object)
    reach = np.sqrt(3.0) * half * general.scale[node]
    for r, (nodes, tree) in enumerate(general.region_nodes):
        mine = np.flatnonzero(region == r)
        if len(mine) == 0:
            continue
        found = tree.query_ball_point(general.points[node[mine]], 2.0 * reach[mine])
        lists[mine] = [nodes[np.asarray(f, dtype=np.int64)] for f in found]
    return _csr(lists)


def _near_tets(general, region, centre, radius):
    """CSR ``(ptr, ids)`` of the tetrahedra of each cell's region whose bounding spheres
    meet the ball ``(centre, radius)`` (`.tet_pieces.RegionTets.near`, many at once)."""
    rt = general.region_tets
    lists = np.empty(len(region), dtype=object)
    for r, (ids, tree, widest) in enumerate(rt.region):
        mine = np.flatnonzero(region == r)
        if len(mine) == 0:
            continue
        found = tree.query_ball_point(centre[mine], radius[mine] + widest)
        for k, f in zip(mine.tolist(), found):
            cand = ids[np.asarray(f, dtype=np.int64)]
            keep = (np.linalg.norm(rt.centre[cand] - centre[k], axis=1)
                    <= radius[k] + rt.radius[cand])
            lists[k] = cand[keep]
    return _csr(lists)


def _csr(lists):
    """CSR ``(ptr, ids)`` of a sequence of int64 arrays."""
    count = np.fromiter(map(len, lists), dtype=np.int64, count=len(lists))
    ids = np.fromiter(itertools.chain.from_iterable(lists), dtype=np.int64, count=count.sum())
    return np.concatenate([[0], np.cumsum(count)]), ids


def _padded(ptr, ids):
    """The rows of the CSR ``(ptr, ids)`` as a ``(w, widest)`` array, -1 past each row's end."""
    count = np.diff(ptr)
    out = np.full((len(count), max(int(count.max(initial=0)), 1)), -1, dtype=np.int64)
    out[np.repeat(np.arange(len(count)), count), np.arange(len(ids)) - np.repeat(ptr[:-1], count)] = ids
    return out


def _subset(ptr, ids, rows):
    """The CSR of rows ``rows`` of ``(ptr, ids)``."""
    count = ptr[rows + 1] - ptr[rows]
    take = np.repeat(ptr[rows] - np.concatenate([[0], np.cumsum(count)[:-1]]), count)
    return np.concatenate([[0], np.cumsum(count)]), ids[take + np.arange(count.sum())]
