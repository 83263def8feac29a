"""`update`: the model of a changed node cloud, its cells recomputed only where the change reaches.

When a crack grows, its new vertex becomes a node and a few nodes near the tip
may move, appear or go; everything else stays. `update` takes the old `Model`
and the new `NodeCloud` and returns the model that `discretize` would build from
scratch -- the same nodes in the same order, triangles, crack faces and cells --
with the integration cells copied from the old model wherever the change cannot
reach them:

* the constrained Delaunay triangulation and the crack opening are redone
  whole (`triangle` takes a fraction of a second at 100k nodes and gives the
  node order of `discretize`);
* points are the same when they lie within ``MERGE_TOL`` times the diameter
  (`cnem.nodes.from_points` snaps the points on a boundary again, which may
  move them by round-off);
* a *changed* triangle is one of the old or of the new triangulation that the
  other has not (the same points), or one with a corner on a changed point (a
  new, moved or removed point, or an end of a constraint segment that the two
  clouds do not share: the old tip, which the grown crack now splits) --
  except where `triangle` only cut a cocircular quadrilateral by its other
  diagonal (the same circumcircle on both sides, to round-off);
* the changed region is the union of the circumcircles of the changed
  triangles. A Voronoi cell lies in the circumcircles of its node's triangles,
  so a cell that does not meet the changed region (nor has a changed triangle
  at its node) is the same cell; the natural neighbours of a point outside
  the region are the same nodes, so the smoothed gradient of such a cell is the
  same row too (`cnem.assembly.gradient_update`).

A sliver along a constraint (a node almost on a crack segment) has a large
circumcircle, and the update then recomputes the cells it covers: still exact,
less local.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from scipy.spatial import cKDTree

from .. import config
from .._parallel import one_thread
from ..errors import GeometryError
from .cells import voronoi_cells
from .model import Cells, Model, triangulate
from .topology import circumcenters

if TYPE_CHECKING:
    from .cloud import NodeCloud

__all__ = ["ModelUpdate", "update"]


@dataclass(frozen=True, repr=False)
class ModelUpdate:
    """The model of a changed cloud and what it took from the old one.

    Attributes
    ----------
    model : Model
        Equal to ``discretize(cloud)``.
    old : Model
        The model it was updated from.
    old_node : (n,) int64 ndarray
        The old model's node at the same point on the same crack face, -1 for
        a node the old model has not (or whose faces changed).
    old_cell : (m,) int64 ndarray
        The old cell copied into each new cell, -1 where the cell was recomputed.
    """

    model: Model
    old: Model
    old_node: np.ndarray
    old_cell: np.ndarray

    @property
    def changed_cells(self) -> np.ndarray:
        """New cells that were recomputed, ``(c,)`` int64."""
        return np.flatnonzero(self.old_cell < 0)

    @property
    def dropped_cells(self) -> np.ndarray:
        """Old cells that no new cell copies, ``(d,)`` int64."""
        kept = np.zeros(len(self.old.cells), dtype=bool)
        kept[self.old_cell[self.old_cell >= 0]] = True
        return np.flatnonzero(~kept)

    def new_node(self) -> np.ndarray:
        """The new node of each old node, ``(n_old,)`` int64, -1 where none."""
        out = np.full(len(self.old.nodes), -1, dtype=np.int64)
        have = self.old_node >= 0
        out[self.old_node[have]] = np.flatnonzero(have)
        return out

    def __repr__(self):
        return (f"<ModelUpdate {len(self.model.nodes)} nodes ({np.count_nonzero(self.old_node < 0)} "
                f"new), {len(self.changed_cells)} of {len(self.model.cells)} cells recomputed>")


def _match_rows(a, b):
    """For each row of ``a`` ``(p, k)`` the index of an equal row of ``b`` ``(q, k)``, else -1."""
    if len(a) == 0 or len(b) == 0:
        return np.full(len(a), -1, dtype=np.int64)
    both = np.concatenate([a, b])
    _, inverse = np.unique(both, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    where = np.full(inverse.max() + 1, -1, dtype=np.int64)
    where[inverse[len(a):]] = np.arange(len(b))
    return where[inverse[:len(a)]]


def _point_map(old, new, tol):
    """Index into ``new`` of the point of ``old`` within ``tol`` (the same point snapped
    again, off by round-off), -1 if none."""
    dist, index = cKDTree(new).query(old, distance_upper_bound=tol)
    return np.where(np.isfinite(dist), index, -1).astype(np.int64)


def _sorted_key(rows, extra=None):
    key = np.sort(rows, axis=1)
    return key if extra is None else np.column_stack([key, extra])


def _changed_points(old, cloud, new_of_old):
    """New points that are new, or ends of constraint segments that only one cloud has."""
    changed = np.ones(len(cloud.points), dtype=bool)
    changed[new_of_old[new_of_old >= 0]] = False
    seg_old = new_of_old[old.cloud.segments]
    whole = (seg_old >= 0).all(axis=1)
    seg_old = _sorted_key(seg_old[whole], old.cloud.segment_kind[whole])
    seg_new = _sorted_key(cloud.segments, cloud.segment_kind)
    lone = _match_rows(seg_new, seg_old) < 0
    changed[cloud.segments[lone].ravel()] = True
    lost = np.ones(len(old.cloud.segments), dtype=bool)
    lost[whole] = _match_rows(seg_old, seg_new) < 0
    ends = new_of_old[old.cloud.segments[lost].ravel()]
    changed[ends[ends >= 0]] = True
    return changed


def _same_triangles(old, new_points_tri, new_of_old, changed):
    """Old triangle of each new triangle with the same (unchanged) points, -1 if none."""
    old_tri = new_of_old[old.node_of_point[old.triangles]]
    old_ok = (old_tri >= 0).all(axis=1)
    old_ok[old_ok] = ~changed[old_tri[old_ok]].any(axis=1)
    match = np.full(len(new_points_tri), -1, dtype=np.int64)
    new_ok = ~changed[new_points_tri].any(axis=1)
    candidates = np.flatnonzero(old_ok)
    hit = _match_rows(np.sort(new_points_tri[new_ok], axis=1), np.sort(old_tri[candidates], axis=1))
    rows = np.flatnonzero(new_ok)
    match[rows[hit >= 0]] = candidates[hit[hit >= 0]]
    return match, old_tri


def _same_circles(old, nodes, tri, points_tri, match, old_tri, changed):
    """Flips between cocircular triangles: the unmatched triangles (of unchanged points)
    whose circumcircle the other triangulation has too, to round-off.

    `triangle` may cut a cocircular quadrilateral (a lattice's square) by the other
    diagonal when points elsewhere change; the Voronoi diagram and the natural
    neighbours there stay the same.

    Returns
    -------
    new_flip : (t,) bool ndarray
    old_flip : (t_old,) bool ndarray
    """
    kept = np.zeros(len(old.triangles), dtype=bool)
    kept[match[match >= 0]] = True
    new_c = np.flatnonzero((match < 0) & ~changed[points_tri].any(axis=1))
    old_ok = (old_tri >= 0).all(axis=1) & ~kept
    old_ok[old_ok] = ~changed[old_tri[old_ok]].any(axis=1)
    old_c = np.flatnonzero(old_ok)
    new_flip = np.zeros(len(tri), dtype=bool)
    old_flip = np.zeros(len(old.triangles), dtype=bool)
    if len(new_c) == 0 or len(old_c) == 0:
        return new_flip, old_flip
    cn, rn = _circles(nodes, tri[new_c])
    co, ro = _circles(old.nodes, old.triangles[old_c])
    tol = config.MERGE_TOL * min(rn.min(), ro.min())
    for centre, radius, other, other_radius, index, flip in (
            (cn, rn, co, ro, new_c, new_flip), (co, ro, cn, rn, old_c, old_flip)):
        dist, near = cKDTree(other).query(centre, distance_upper_bound=tol)
        hit = np.flatnonzero(np.isfinite(dist))
        hit = hit[np.abs(other_radius[near[hit]] - radius[hit]) <= tol]
        flip[index[hit]] = True
    return new_flip, old_flip


def _node_map(old, tri, new_points_tri, match, old_tri, n):
    """Old node of each new node through the corners of the triangles both have."""
    old_node = np.full(n, -1, dtype=np.int64)
    j = np.flatnonzero(match >= 0)
    i = match[j]
    for k in range(3):          # the corner of the old triangle at new corner k
        for s in range(3):
            at = old_tri[i, s] == new_points_tri[j, k]
            old_node[tri[j[at], k]] = old.triangles[i[at], s]
    return old_node


def _circles(nodes, triangles):
    """Circumcentres ``(t, 2)`` and circumradii ``(t,)`` of ``triangles``."""
    centre = circumcenters(nodes, triangles)
    return centre, np.sqrt(((nodes[triangles[:, 0]] - centre) ** 2).sum(axis=1))


def _disc_boxes(nodes, triangles):
    """Bounding boxes ``(t, 4)`` of the circumcircles of ``triangles``."""
    centre, radius = _circles(nodes, triangles)
    return np.hstack([centre - radius[:, None], centre + radius[:, None]])


def _cell_boxes(cells):
    """Bounding boxes ``(m, 4)`` of the cell polygons."""
    start = cells.offsets[:-1]
    lo = np.minimum.reduceat(cells.vertices, start, axis=0)
    hi = np.maximum.reduceat(cells.vertices, start, axis=0)
    return np.hstack([lo, hi])


def _boxes_meet(boxes, targets, pad):
    """Whether each of ``boxes`` ``(m, 4)`` meets one of ``targets`` ``(d, 4)`` (grown by ``pad``)."""
    hit = np.zeros(len(boxes), dtype=bool)
    if len(targets) == 0:
        return hit
    lo, hi = targets[:, :2].min(axis=0) - pad, targets[:, 2:].max(axis=0) + pad
    near = np.flatnonzero((boxes[:, :2] <= hi).all(axis=1) & (boxes[:, 2:] >= lo).all(axis=1))
    for chunk in np.array_split(near, max(1, len(near) * len(targets) // 4_000_000 + 1)):
        b = boxes[chunk]
        meet = ((b[:, None, :2] <= targets[None, :, 2:] + pad).all(axis=2)
                & (b[:, None, 2:] >= targets[None, :, :2] - pad).all(axis=2))
        hit[chunk] = meet.any(axis=1)
    return hit


def update(model: Model, cloud: NodeCloud, *, progress: bool | None = None) -> ModelUpdate:
    """The model of a changed node cloud, recomputing only the cells the change reaches.

    Parameters
    ----------
    model : Model
        The model before the change (``discretize`` or an earlier `update`).
    cloud : NodeCloud
        The new cloud: the same regions, cracks possibly extended; points kept,
        added, moved or removed (a kept point has exactly its old coordinates).
    progress : bool, optional
        As in `discretize`.

    Returns
    -------
    ModelUpdate
        ``.model`` equals ``discretize(cloud)``: the same nodes in the same
        order, triangles, segments and cells (node, region, area and polygon;
        the recomputed cells by the same code; a copied polygon may start at
        another of its vertices, since `discretize` starts a cell at the
        triangle that `triangle` numbers first around the node, and its
        vertices may differ by round-off where a point was snapped again);
        ``old_node`` and ``old_cell`` say what was taken from ``model``.

    Raises
    ------
    GeometryError
        As `discretize`; also when ``model`` is not a `Model`.
    """
    if not isinstance(model, Model):
        raise GeometryError(f"update expects the old Model, received {type(model).__name__}; "
                            "build the first one with cnem.discretize")
    timings = {}
    nodes, node_of_point, tri, region, segments, kind, neighbors = triangulate(cloud, timings,
                                                                               "update")
    t0 = time.perf_counter()
    size = float(np.hypot(*np.ptp(cloud.points, axis=0)))
    new_of_old = _point_map(model.cloud.points, cloud.points, config.MERGE_TOL * size)
    changed = _changed_points(model, cloud, new_of_old)
    points_tri = node_of_point[tri]
    match, old_tri = _same_triangles(model, points_tri, new_of_old, changed)
    old_node = _node_map(model, tri, points_tri, match, old_tri, len(nodes))
    new_flip, kept_old = _same_circles(model, nodes, tri, points_tri, match, old_tri, changed)
    kept_old[match[match >= 0]] = True
    gone = (match < 0) & ~new_flip
    discs = np.concatenate([_disc_boxes(model.nodes, model.triangles[~kept_old]),
                            _disc_boxes(nodes, tri[gone])])
    pad = cloud.domain.tolerance
    touched = np.zeros(len(model.nodes), dtype=bool)
    touched[model.cells.node[_boxes_meet(_cell_boxes(model.cells), discs, pad)]] = True
    redo = old_node < 0
    redo[tri[gone].ravel()] = True
    redo[old_node >= 0] |= touched[old_node[old_node >= 0]]
    timings["matching"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    frame = cloud.domain.frame                         # the frame of `discretize`
    with one_thread():                  # a few cells
        node, cell_region, offsets, vertices = voronoi_cells(
            frame.to_local(nodes), tri, region, progress=progress, neighbors=neighbors[0],
            star=neighbors[2], only=np.flatnonzero(redo), frame=frame)
        fresh = Cells(node, cell_region, offsets, frame.to_global(vertices))
    new_of_old_node = np.full(len(model.nodes), -1, dtype=np.int64)
    new_of_old_node[old_node[old_node >= 0]] = np.flatnonzero(old_node >= 0)
    owner = new_of_old_node[model.cells.node]
    reuse = np.flatnonzero(owner >= 0)
    reuse = reuse[~redo[owner[reuse]]]
    cells, old_cell = _merge_cells(model.cells.subset(reuse), owner[reuse], fresh, reuse)
    timings["cells"] = time.perf_counter() - t0
    new = Model(cloud, nodes, node_of_point, tri, region, segments, kind, cells, timings,
                _derived={"neighbors": neighbors})
    return ModelUpdate(new, model, old_node, old_cell)


def _merge_cells(kept, kept_node, fresh, kept_index):
    """The copied and the recomputed cells in the order of `discretize` (node, then region).

    Returns
    -------
    cells : Cells
    old_cell : (m,) int64 ndarray
        ``kept_index`` of each copied cell, -1 for the recomputed ones.
    """
    node = np.concatenate([kept_node, fresh.node])
    region = np.concatenate([kept.region, fresh.region])
    order = np.lexsort((region, node))
    source = np.concatenate([kept_index, np.full(len(fresh), -1, dtype=np.int64)])[order]
    counts = np.concatenate([np.diff(kept.offsets), np.diff(fresh.offsets)])
    starts = np.concatenate([kept.offsets[:-1], fresh.offsets[:-1] + len(kept.vertices)])[order]
    counts = counts[order]
    offsets = np.zeros(len(counts) + 1, dtype=np.int64)
    np.cumsum(counts, out=offsets[1:])
    gather = np.repeat(starts - offsets[:-1], counts) + np.arange(offsets[-1])
    vertices = np.concatenate([kept.vertices, fresh.vertices])[gather]
    area = np.concatenate([kept.area, fresh.area])[order]
    return Cells(node[order], region[order], offsets, vertices, area=area), source
