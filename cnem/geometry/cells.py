"""Constrained Voronoi integration cells (C-NEM paper eq. 13, SCNI cells of §4.2).

A point ``x`` of region ``r`` belongs to the cell of node ``i`` when ``i`` is
visible from ``x`` (the segment between them crosses no boundary, interface or
crack; touching at the node is allowed) and no node visible from ``x`` is
nearer. A node on an interface owns one cell per region.

Three paths compute the cells:

* the *fast path* (numba, `._kernels.fast_cells`): a node whose circumcentres
  are all visible from it and whose dual polygon is star-shaped around it owns
  exactly the polygon of its circumcentres (closed by the node and the
  midpoints of its two constraint edges when it sits on a straight boundary or
  a convex corner);
* the *half-plane path* (`.halfplane`), for a node the fast path refuses whose
  neighbourhood is convex (no reflex corner, tip or interface node within twice
  its cell's radius: a thin strip, circumcentres behind a straight boundary): a
  box cut by its wedge, the constraint chords and the bisectors, in numba; and
  for a node at a reflex corner (a vertex of a hole) whose cell, its wedge cut
  by the bisectors, it proves exact: no constraint crosses the cell, and every
  node whose bisector bounds it sees past it (`._reflex_kernels`);
* the *exact path* (shapely, snap-rounded overlays), for every other node and
  region (reflex corners whose shadows reach into their cells, crack tips,
  interfaces, circumcentres behind a constraint): the cell is the part of a
  bounding box that node ``i`` sees
  (its wedge between its constraint edges minus the shadows of every
  constraint segment), minus, for each nearby node ``j`` of the region, the
  points nearer to ``j`` that ``j`` sees.
"""

from __future__ import annotations

import numpy as np
import shapely
from numpy.typing import ArrayLike
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree
from tqdm.auto import tqdm

from .. import config
from .._predicates import Frame, bounding_box
from ..errors import GeometryError
from ..spatial import RTree
from ._kernels import FAST, fan_regions, fast_cells, place_rows
from ._mesh_kernels import close_neighbours
from .halfplane import HalfPlaneCells
from .topology import circumcenters, constraint_edges, triangle_neighbors, vertex_triangles
from .._sets import distinct, isin

__all__ = ["voronoi_cells"]

#: Relative margin by which the exact path's node distances must clear a search radius
#: for a tree over some of the nodes to stand in for a k-d tree of all (`_ExactCells.near`).
_BAND = 1e-9


def _halfplane_box(box, p, q):
    """The part of box ``(xmin, ymin, xmax, ymax)`` nearer to ``q`` than to ``p``."""
    x0, y0, x1, y1 = box
    poly = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])
    nrm, off = q - p, 0.5 * ((q @ q) - (p @ p))
    val = poly @ nrm - off          # > 0 nearer to q
    out = []
    for k in range(4):
        a, b, va, vb = poly[k], poly[(k + 1) % 4], val[k], val[(k + 1) % 4]
        if va > 0:
            out.append(a)
        if (va > 0) != (vb > 0):
            out.append(a + va / (va - vb) * (b - a))
    return shapely.Polygon(out) if len(out) >= 3 else None


def _union(polygons, grid):
    """The union of ``polygons`` snap-rounded to ``grid``.

    Without a grid GEOS (3.14) can drop a whole polygon from the union of fans
    that share their edges only nearly (rays from one node through the ends of
    adjacent segments, computed from different angles): the shadow of a
    boundary edge went missing and the cell kept a piece behind that edge (a
    cell "not connected"). Snap rounding nodes the near-coincident edges.
    """
    return _polygonal(shapely.union_all(polygons, grid_size=grid))


def _shadows(origin, edges_xy, reach, grid):
    """Union of the shadows cast by segments seen from ``origin``, up to ``reach``,
    snap-rounded to ``grid``.

    The shadow of segment ``a-b`` is bounded by the segment, the two rays from
    ``origin`` through its ends and an arc of radius ``2 * reach`` drawn as
    three chords (each subtending at most 60 degrees, so the chords stay
    farther than ``reach`` from ``origin`` however wide the segment looks).
    """
    if len(edges_xy) == 0:
        return None
    a, b = edges_xy[:, 0], edges_xy[:, 1]
    da, db = a - origin, b - origin
    la, lb = np.linalg.norm(da, axis=1), np.linalg.norm(db, axis=1)
    cross = da[:, 0] * db[:, 1] - da[:, 1] * db[:, 0]
    keep = (np.minimum(la, lb) > 0) & (np.abs(cross) > 1e-14 * la * lb)
    if not keep.any():
        return None
    a, b, da, db, cross = a[keep], b[keep], da[keep], db[keep], cross[keep]
    start = np.arctan2(da[:, 1], da[:, 0])
    sweep = np.arctan2(cross, np.einsum("ij,ij->i", da, db))
    radius = 2.0 * reach + np.maximum(la[keep], lb[keep])
    t = np.array([1.0, 2.0 / 3.0, 1.0 / 3.0, 0.0])
    ang = start[:, None] + sweep[:, None] * t[None, :]
    arc = origin + radius[:, None, None] * np.stack([np.cos(ang), np.sin(ang)], axis=2)
    ring = np.concatenate([a[:, None], b[:, None], arc, a[:, None]], axis=1)
    return _union(shapely.polygons(ring), grid)


def _overlay(op, a, b, grid):
    """``op(a, b)`` snap-rounded to ``grid``, retried on a coarser grid if GEOS fails."""
    for scale in (1.0, 10.0, 100.0):
        try:
            return _polygonal(op(a, b, grid_size=grid * scale))
        except shapely.errors.GEOSException:
            a = shapely.set_precision(a, grid * scale * 10)
            b = shapely.set_precision(b, grid * scale * 10)
    return _polygonal(op(a, b, grid_size=grid * 1000.0))


def _polygonal(geom):
    """The polygonal part of an overlay result (drops stray points and lines)."""
    if geom.geom_type in ("Polygon", "MultiPolygon"):
        return geom
    parts = [g for g in shapely.get_parts(geom) if g.geom_type == "Polygon"]
    return shapely.MultiPolygon(parts) if parts else shapely.Polygon()


def _drop_repeats(ring, tol):
    """Remove vertices closer than ``tol`` to the previous one (snap-grid leftovers)."""
    step = np.linalg.norm(ring - np.roll(ring, 1, axis=0), axis=1)
    keep = step > tol
    return ring[keep] if keep.sum() >= 3 else ring


def _drop_spikes(ring, tol):
    """Remove the tips of zero-width spikes: vertices where the ring turns straight
    back (the edges in and out anti-parallel, closer than ``tol`` to one line).

    An overlay can leave a sliver a few grid steps wide along a constraint edge
    (two wedges along the same edge, drawn from its two ends); once `_drop_repeats`
    merges the two vertices of its tip, the ring folds back along the edge, which
    is not a valid polygon.
    """
    for _ in range(len(ring)):
        if len(ring) <= 3:
            break
        into = ring - np.roll(ring, 1, axis=0)
        out = np.roll(ring, -1, axis=0) - ring
        cross = into[:, 0] * out[:, 1] - into[:, 1] * out[:, 0]
        dot = np.einsum("ij,ij->i", into, out)
        longest = np.maximum(np.linalg.norm(into, axis=1), np.linalg.norm(out, axis=1))
        spike = np.flatnonzero((dot < 0) & (np.abs(cross) <= tol * longest))
        if spike.size == 0:
            break
        ring = np.delete(ring, spike[0], axis=0)
    return ring


def _splice_hole(ring, hole):
    """Join a hole that touches the outer ring at a vertex into the ring (None if
    it does not touch).

    Snap-rounded overlays return a notch that touches the boundary at one
    point as a hole touching the shell; the cell is the simple ring that walks
    around the notch.
    """
    d = np.linalg.norm(ring[:, None, :] - hole[None, :, :], axis=2)
    a, b = np.unravel_index(np.argmin(d), d.shape)
    if d[a, b] > 0:
        return None
    return np.concatenate([ring[:a + 1], np.roll(hole, -b, axis=0)[1:], hole[b:b + 1], ring[a + 1:]])


class _ExactCells:
    """State shared by the exact (clipping) path (``extent``: the nodes' bounding box,
    ``constraints``: `constraint_edges` of ``triangles`` and ``nb``, if already known)."""

    def __init__(self, nodes, triangles, region, nb, offsets, star, cc, frame, extent=None,
                 constraints=None):
        self.nodes, self.tri, self.region, self.frame = nodes, triangles, region, frame
        # every cell lies inside the nodes' box
        self.extent = bounding_box(nodes) if extent is None else extent
        self.grid = config.GRID_TOL * float(np.hypot(*(self.extent[1] - self.extent[0])))
        # vertices nearer than this are one: ten grid steps, and the coordinates' round-off
        # far from the origin (`_shared_centres` merges the fast path's centres alike): a
        # cluster of vertices a few ulps apart in the caller's coordinates folds there
        resolution = 0.0 if frame is None else frame.resolution
        self.merge = max(10 * self.grid, config.ROUNDOFF_ULPS * resolution)
        self.offsets, self.star, self.cc = offsets, star, cc
        edges, owner = constraint_edges(triangles, nb) if constraints is None else constraints
        self.edges, self.edge_region = edges, region[owner]
        mid = 0.5 * (nodes[edges[:, 0]] + nodes[edges[:, 1]])
        self.edge_tree = cKDTree(mid)
        self.edge_half = 0.5 * np.linalg.norm(nodes[edges[:, 0]] - nodes[edges[:, 1]], axis=1).max()
        on_edge = np.column_stack([edges.ravel(), np.repeat(self.edge_region, 2)])
        self.constrained = set(map(tuple, on_edge.tolist()))
        self.boxes = {}          # (node, region) -> its cell's box and reach (`box`)
        self.near_tree = None    # over the nodes near the cells `expected` (`expect`)
        self.expected = set()
        self.node_tree = None    # a cKDTree of all the nodes, built if needed (`near`)

    def box(self, i, r):
        """The box ``(xmin, ymin, xmax, ymax)`` the cell of node ``i`` in region ``r`` is
        clipped from (its triangles' circumcircles, within the extent) and its reach (the
        distance from the node to the box's farthest corner)."""
        if (i, r) not in self.boxes:
            x = self.nodes[i]
            fan = self.fan(i, r)
            circ_r = np.linalg.norm(self.cc[fan] - self.nodes[self.tri[fan, 0]], axis=1)
            lo = (self.cc[fan] - circ_r[:, None]).min(axis=0)
            hi = (self.cc[fan] + circ_r[:, None]).max(axis=0)
            lo = np.clip(np.minimum(lo, x), self.extent[0], self.extent[1])
            hi = np.clip(np.maximum(hi, x), self.extent[0], self.extent[1])
            corners = np.array([[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]])
            reach = float(np.max(np.linalg.norm(corners - x, axis=1)))
            self.boxes[i, r] = (lo[0], lo[1], hi[0], hi[1]), reach
        return self.boxes[i, r]

    def expect(self, node, region):
        """Prepare the cells of the (node, region) pairs: their boxes, and an R-tree over
        the nodes within twice their reach (`near`), not over all the nodes."""
        self.expected = set(zip(np.asarray(node).tolist(), np.asarray(region).tolist()))
        reach = np.array([self.box(int(i), int(r))[1] for i, r in zip(node, region)])
        x = self.nodes[node]
        pad = (2.0 * reach * (1.0 + 4 * _BAND))[:, None] + 8.0 * np.spacing(np.abs(x))
        self.near_tree = RTree.from_points_in(self.nodes, x - pad, x + pad, self.extent)

    def near(self, i, r, radius, tiny):
        """The nodes within ``radius`` of node ``i`` and their distances, in the order a
        k-d tree of all the nodes gives them, as far as it matters: sorted by distance,
        their order is unique but among those within ``tiny`` (the cell skips them all).

        From `near_tree` (`expect`) when every distance lies clear of ``radius`` (by a
        relative ``_BAND``: the test ``d <= radius`` cannot round otherwise) and those
        beyond ``tiny`` are distinct; else from a k-d tree of all the nodes.
        """
        x = self.nodes[i]
        if (i, r) in self.expected:
            tree, subset = self.near_tree
            _, idx = tree.query_ball(x[None], radius * (1.0 + 2 * _BAND))
            near = subset[idx]
            dist = np.linalg.norm(self.nodes[near] - x, axis=1)
            inside = dist <= radius * (1.0 - _BAND)
            far = dist[inside & (dist > tiny)]
            if not (~inside & (dist <= radius * (1.0 + _BAND))).any() and \
                    len(distinct(far)) == len(far):
                return near[inside], dist[inside]
        if self.node_tree is None:
            self.node_tree = cKDTree(self.nodes)
        near = np.asarray(self.node_tree.query_ball_point(x, radius), dtype=np.int64)
        return near, np.linalg.norm(self.nodes[near] - x, axis=1)

    def fan(self, i, r):
        ts = self.star[self.offsets[i]:self.offsets[i + 1]]
        return ts[self.region[ts] == r]

    def member(self, j, r):
        """Whether node ``j`` is a vertex of a triangle of region ``r``."""
        return bool((self.region[self.star[self.offsets[j]:self.offsets[j + 1]]] == r).any())

    def wedge(self, i, r, reach):
        """Directions from node ``i`` into region ``r`` (None: all directions).

        The triangles of the fan, chained counter-clockwise (a triangle's second
        vertex is the previous one's third), make sectors; a sector's polygon is the
        node, then the points ``2 reach`` away towards each triangle's first edge and
        the bisector of its angle, and towards the last edge (consecutive points at
        most 90 degrees apart: the chords stay beyond ``reach``). One polygon per
        sector, not a union of one per triangle: those share their edges only nearly,
        and their snap-rounded union can pinch at the node. A sector closed around the
        node (a crack tip: the two faces' copies of the next node coincide) sees all
        directions; several sectors (a region touching itself at the node) are united.
        """
        if (i, r) not in self.constrained:
            return None
        x = self.nodes[i]
        fan = self.fan(i, r)
        k = np.argmax(self.tri[fan] == i, axis=1)
        first, last = self.tri[fan, (k + 1) % 3], self.tri[fan, (k + 2) % 3]
        u = self.nodes[first] - x
        v = self.nodes[last] - x
        u /= np.linalg.norm(u, axis=1)[:, None]
        v /= np.linalg.norm(v, axis=1)[:, None]
        w = u + v
        w /= np.linalg.norm(w, axis=1)[:, None]
        angle = np.arctan2(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0], (u * v).sum(axis=1))
        after = {int(a): t for t, a in enumerate(first)}
        starts = np.flatnonzero(~isin(first, last))
        sectors = []
        for t in starts:
            chain = [int(t)]
            while len(chain) < len(fan) and int(last[chain[-1]]) in after:
                chain.append(after[int(last[chain[-1]])])
            if angle[chain].sum() >= 2 * np.pi * (1 - 1e-9):
                return None
            ends = np.column_stack([u[chain], w[chain]]).reshape(-1, 2)
            ring = np.vstack([[x], x + 2 * reach * ends, [x + 2 * reach * v[chain[-1]]], [x]])
            sectors.append(shapely.Polygon(ring))
        if not sectors:
            return None                      # the fan closes on itself: every direction
        return sectors[0] if len(sectors) == 1 else _union(sectors, self.grid)

    def visible_part(self, i, r, geom, reach):
        """The part of ``geom`` that node ``i`` sees within region ``r``."""
        w = self.wedge(i, r, reach)
        if w is not None:
            geom = _overlay(shapely.intersection, geom, w, self.grid)
        if geom.is_empty:
            return geom
        hull = shapely.convex_hull(shapely.union_all([geom, shapely.Point(self.nodes[i])]))
        cand = self.edge_tree.query_ball_point(self.nodes[i], 2 * reach + self.edge_half)
        cand = np.asarray(cand, dtype=np.int64)
        cand = cand[self.edge_region[cand] == r]
        if cand.size == 0:
            return geom
        xy = self.nodes[self.edges[cand]]
        hit = shapely.intersects(shapely.linestrings(xy), hull)
        shadow = _shadows(self.nodes[i], xy[hit], 4 * reach, self.grid)
        return geom if shadow is None else _overlay(shapely.difference, geom, shadow, self.grid)

    def cell(self, i, r):
        x = self.nodes[i]
        box, reach = self.box(i, r)
        cell = self.visible_part(i, r, shapely.set_precision(shapely.box(*box), self.grid), reach)
        tiny = config.MERGE_TOL * reach
        near, dist = self.near(i, r, 2 * reach, tiny)
        order = np.argsort(dist)
        near, dist = near[order], dist[order]
        corners = shapely.get_coordinates(cell)
        radius = np.linalg.norm(corners - x, axis=1).max(initial=0.0)
        for j, dj in zip(near, dist):
            if dj > 2 * radius:
                break            # j is farther from every point of the cell than i
            if dj <= tiny or not self.member(j, r):
                continue
            q = self.nodes[j]
            if (corners @ (q - x)).max() <= 0.5 * (q @ q - x @ x):
                continue         # the cell lies on i's side of the bisector
            half = _halfplane_box(box, x, q)
            if half is None:
                continue
            region = _overlay(shapely.intersection, cell, half, self.grid)
            if region.area <= 0:
                continue
            stolen = self.visible_part(j, r, region, reach)
            if not stolen.is_empty:
                cell = _overlay(shapely.difference, cell, stolen, self.grid)
                corners = shapely.get_coordinates(cell)
                radius = np.linalg.norm(corners - x, axis=1).max(initial=0.0)
        return self._polygon(cell, i, r)

    def _polygon(self, cell, i, r):
        parts = [g for g in getattr(cell, "geoms", [cell]) if g.geom_type == "Polygon"]
        parts.sort(key=lambda g: g.area, reverse=True)
        if not parts or parts[0].area <= 0:
            raise GeometryError(f"node {i} at {self._where(i)} has an empty cell in "
                                f"region {r}; is it a duplicate of another node?")
        total = sum(g.area for g in parts)
        if total - parts[0].area > 1e-9 * total:
            raise self._unresolved(i, r, "is not connected")
        poly = shapely.geometry.polygon.orient(parts[0], 1.0)
        ring = _drop_repeats(np.asarray(poly.exterior.coords)[:-1], self.merge)
        for hole in poly.interiors:
            ring = _splice_hole(ring, np.asarray(hole.coords)[:-1])
            if ring is None:
                raise self._unresolved(i, r, "has a hole")
        return _drop_spikes(ring, self.merge)

    def _where(self, i):
        """Node ``i`` in the caller's coordinates, formatted."""
        x = self.nodes[i] if self.frame is None else self.frame.to_global(self.nodes[i])
        return f"({x[0]:.6g}, {x[1]:.6g})"

    def _unresolved(self, i, r, what):
        """The error for a cell the cloud cannot resolve, naming the likely cause: a
        boundary much finer than the nodes inside it, or a cloud too coarse there."""
        head = f"the cell of node {i} at {self._where(i)} in region {r} {what}"
        at_i = (self.edges == i).any(axis=1) & (self.edge_region == r)
        free = np.ones(len(self.nodes), dtype=bool)
        free[self.edges.ravel()] = False
        if at_i.any() and free.any():
            seg = np.linalg.norm(np.diff(self.nodes[self.edges[at_i]], axis=1), axis=2).max()
            inner = cKDTree(self.nodes[free]).query(self.nodes[i])[0]
            if self.frame is not None:                     # lengths in the caller's units
                seg, inner = seg * self.frame.scale, inner * self.frame.scale
            if seg < config.BOUNDARY_FINER * inner:
                return GeometryError(
                    f"{head}: the boundary there is much finer than the node cloud (segments "
                    f"{seg:.3g} long, the nearest interior node {inner:.3g} away); coarsen the "
                    f"outline to vertices about one node spacing apart (e.g. shapely's "
                    f"simplify(tolerance ~ spacing / 10)) or refine the nodes near it to a "
                    f"spacing of about {seg:.3g} (cnem.nodes.graded)")
        return GeometryError(f"{head}; the node cloud is too coarse or degenerate near this "
                             "node: refine it there")


def _shared_centres(cc, nb, extent, resolution=0.0):
    """The circumcentres with those of neighbouring triangles closer than
    ``MERGE_TOL`` times the nodes' extent, or than ``ROUNDOFF_ULPS`` times the
    coordinates' round-off ``resolution``, made one (the lowest triangle's): the two
    centres of a cocircular quad are one point, but round-off puts them apart, by
    more than the merge tolerance of the cells in a thin one (a 1e-2 x 1e-6 quad:
    2e-15) or far from the origin (nodes at 1e6 known to 1e-10), and the cells beside
    it would keep different ones (a gap between them) or a vertex twice (which
    of the quad's diagonals the triangulation took decides it, and a fan sub-cell of
    no area beside the pair changed the stabilised stiffness by 5 %)."""
    lo, hi = extent
    tol = max(config.MERGE_TOL * float(np.hypot(*(hi - lo))),
              config.ROUNDOFF_ULPS * resolution)
    t, u = close_neighbours(cc, nb, tol)
    if len(t) == 0:
        return cc
    graph = coo_matrix((np.ones(len(t)), (t, u)), shape=(len(cc), len(cc)))
    _, label = connected_components(graph, directed=False)
    first = np.full(label.max() + 1, len(cc))
    np.minimum.at(first, label, np.arange(len(cc)))
    return np.ascontiguousarray(cc[first[label]])


def voronoi_cells(nodes: np.ndarray, triangles: np.ndarray, region: np.ndarray, *,
                  progress: bool | None = None, neighbors: np.ndarray | None = None,
                  only: ArrayLike | None = None, frame: Frame | None = None,
                  star: tuple[np.ndarray, np.ndarray] | None = None
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Constrained Voronoi cells of a (crack-split) constrained Delaunay triangulation.

    Parameters
    ----------
    nodes : (n, 2) ndarray
    triangles : (t, 3) int64 ndarray
        Counter-clockwise, crack faces already split.
    region : (t,) int64 ndarray
    progress : bool, optional
        Progress bar over the clipped cells (default: when on a terminal).
    neighbors : (t, 3) int64 ndarray, optional
        `triangle_neighbors` of the triangles and regions, if already known.
    only : (w,) int array_like, optional
        Compute the cells of these nodes alone (default: of every node); a
        cell depends only on the triangulation, so these are the same cells
        as those of the whole diagram (`cnem.geometry.model_update` relies on it).
    frame : cnem._predicates.Frame, optional
        The local frame ``nodes`` are given in (`cnem._predicates.local_frame`): the
        points and lengths named in errors are mapped back to the caller's coordinates.
    star : (offsets, indices), optional
        `vertex_triangles` of the triangles, if already known.

    Returns
    -------
    node, region : (m,) int64 ndarray
        Sorted by node, then region.
    offsets : (m + 1,) int64 ndarray
    vertices : (k, 2) ndarray
        Cell ``c`` is ``vertices[offsets[c]:offsets[c + 1]]``, counter-clockwise.
    """
    n = len(nodes)
    nb = triangle_neighbors(triangles, region) if neighbors is None else neighbors
    if star is None or len(star[0]) != n + 1:
        star = vertex_triangles(triangles, n)
    offsets, star = star
    cc = circumcenters(nodes, triangles)
    resolution = 0.0 if frame is None else frame.resolution
    max_deg = int(np.diff(offsets).max())
    which = np.arange(n, dtype=np.int64) if only is None else distinct(np.asarray(only, dtype=np.int64))
    extent = bounding_box(nodes)
    # a cell has at most one vertex per triangle of its node plus three: each node
    # writes into its own room of one array (placed by `_in_place_of_slow`)
    room = np.zeros(len(which) + 1, dtype=np.int64)
    np.cumsum(offsets[which + 1] - offsets[which] + 3, out=room[1:])
    poly = np.empty((room[-1], 2))
    status, count, rtri = fast_cells(
        nodes, triangles, nb, offsets, star, _shared_centres(cc, nb, extent, resolution),
        config.MERGE_TOL, max_deg, which, room, poly)
    slow_at = np.flatnonzero(status != FAST)     # positions in `which`
    slow_node, slow_region, reach = fan_regions(nodes, triangles, region, offsets, star,
                                                which[slow_at])
    slow_start = np.zeros(len(slow_node), dtype=np.int64)
    slow_count = np.zeros(len(slow_node), dtype=np.int64)
    slow_verts = np.zeros((0, 2))
    if len(slow_node):
        constraints = constraint_edges(triangles, nb)
        half = HalfPlaneCells(nodes, triangles, region, nb, extent=extent,
                              constraints=constraints, resolution=resolution)
        done, half_count, half_verts = half.cells(slow_node, slow_region, reach)
        rest = np.setdiff1d(np.arange(len(slow_node)), done)
        exact_polys = []
        if len(rest):
            exact = _ExactCells(nodes, triangles, region, nb, offsets, star, cc, frame, extent,
                                constraints)
            exact.expect(slow_node[rest], slow_region[rest])
            exact_polys = [exact.cell(int(slow_node[k]), int(slow_region[k])) for k in tqdm(
                rest, desc="clipping cells", disable=None if progress is None else not progress,
                leave=False)]
        slow_count[done] = half_count
        slow_count[rest] = [len(p) for p in exact_polys]
        blocks = slow_count[np.concatenate([done, rest])]
        slow_start[np.concatenate([done, rest])] = np.cumsum(blocks) - blocks
        slow_verts = np.concatenate([half_verts] + exact_polys)
    fast_region = region[rtri[status == FAST]]
    return _in_place_of_slow(which, slow_at, fast_region, (room, poly, count),
                             (slow_node, slow_region, slow_start, slow_count, slow_verts))


def _in_place_of_slow(which, slow_at, fast_region, fast, slow):
    """The cells sorted by node, then region: the fast cells (one per entry of ``which``,
    none at the positions ``slow_at``; ``fast`` = ``(room, poly, count)`` of `fast_cells`)
    with the slow ones put where their nodes are (``slow`` = ``(node, region, start,
    count, vertices)``: the (node, region) pairs, sorted, and their polygons
    ``vertices[start[k]:][:count[k]]``).

    Returns
    -------
    node, region, offsets, vertices
        As `voronoi_cells`.
    """
    slow_node, slow_region, slow_start, slow_count, slow_verts = slow
    per_slow = np.unique(slow_node, return_counts=True)[1]     # every slow node has a pair
    per_pos = np.ones(len(which), dtype=np.int64)
    per_pos[slow_at] = per_slow
    first = np.zeros(len(which) + 1, dtype=np.int64)
    np.cumsum(per_pos, out=first[1:])
    fast_at = np.ones(len(which), dtype=bool)
    fast_at[slow_at] = False
    fast_cell = first[:-1][fast_at]
    slow_cell = np.ones(first[-1], dtype=bool)
    slow_cell[fast_cell] = False
    cell_region = np.empty(first[-1], dtype=np.int64)
    cell_region[fast_cell] = fast_region
    cell_region[slow_cell] = slow_region
    room, poly, count = fast
    counts = np.empty(first[-1], dtype=np.int64)
    counts[fast_cell] = count[fast_at]
    counts[slow_cell] = slow_count
    offsets = np.zeros(first[-1] + 1, dtype=np.int64)
    np.cumsum(counts, out=offsets[1:])
    src, dst = room[:-1][fast_at], offsets[fast_cell]
    if offsets[-1] <= len(poly) and (dst <= src).all():
        # the fast cells moved down inside `poly` (in order: no block overwrites one not
        # yet read), then `poly` shortened, not copied to new memory (first touching its
        # 100 MB at 1M nodes cost several times the copy)
        place_rows.serial(poly, src, poly, dst, counts[fast_cell])
        poly.resize((offsets[-1], 2), refcheck=False)   # no view of it: the array is ours
        vertices = poly
    else:
        vertices = np.empty((offsets[-1], 2))
        place_rows(poly, src, vertices, dst, counts[fast_cell])
    place_rows(slow_verts, slow_start, vertices, offsets[:-1][slow_cell], slow_count)
    return np.repeat(which, per_pos), cell_region, offsets, vertices
