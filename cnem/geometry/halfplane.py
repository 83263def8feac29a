"""The half-plane path of the constrained Voronoi cells (`._clip_kernels.clip_cell`,
`._reflex_kernels.reflex_cell`).

Between the fast path (a cell made of circumcentres) and the exact shapely
clipping: a node whose circumcentres lie behind a constraint but whose
neighbourhood is convex (a thin strip, a coarse boundary with nodes
crowded inside), or a node at a reflex corner whose cell its clipping proves
exact (the vertices of a hole, finer than the nodes around it), gets its cell by
clipping a box with half-planes, a few microseconds instead of milliseconds. All
such cells are done at once: an R-tree over the nodes near them only
(`cnem.spatial.RTree.from_points_in`), one query per leaf of it gathers the
candidate nodes of the leaf's cells (and through them their constraint edges), one
kernel (`._batch_clip_kernels.clip_cells`) clips them all, and the cells whose box was
too small are retried together in boxes twice as large.
"""

from __future__ import annotations

import numpy as np

from .. import config
from .._parallel import work_chunks
from .._predicates import bounding_box
from ..spatial import RTree
from ._batch_clip_kernels import clip_cells
from ._clip_kernels import BARE, CLIPPED, COMPLEX, GROW, SIMPLE
from ._mesh_kernels import region_members
from .topology import constraint_edges

__all__ = ["HalfPlaneCells"]

#: The first box of a reflex corner's cell, in half-sizes of its fan (`HalfPlaneCells.cells`).
_REFLEX_START = 1.25


class HalfPlaneCells:
    """The constraint structure the half-plane path needs, built once per diagram.

    Parameters
    ----------
    nodes : (n, 2) ndarray
    triangles : (t, 3) int64 ndarray
        Counter-clockwise.
    region : (t,) int64 ndarray
    nb : (t, 3) int64 ndarray
        Neighbours with region changes cut (-1).
    extent : two (2,) ndarray, optional
        The nodes' bounding box (`cnem._predicates.bounding_box`), if already known.
    constraints : two ndarray, optional
        `constraint_edges` of ``triangles`` and ``nb``, if already known.
    resolution : float, optional
        The round-off of the caller's coordinates in those of ``nodes``
        (`cnem._predicates.Frame.resolution`): constraint edges within
        ``ROUNDOFF_ULPS`` of it of one line are one line (`collinear_reach`).
    """

    def __init__(self, nodes: np.ndarray, triangles: np.ndarray, region: np.ndarray,
                 nb: np.ndarray, *, extent: tuple[np.ndarray, np.ndarray] | None = None,
                 constraints: tuple[np.ndarray, np.ndarray] | None = None,
                 resolution: float = 0.0) -> None:
        n = len(nodes)
        self.nodes = nodes
        lo, hi = bounding_box(nodes) if extent is None else extent
        self.box = (lo, hi)
        self.extent = np.array([lo[0], lo[1], hi[0], hi[1]])
        self.tol = config.MERGE_TOL * float(np.hypot(*(hi - lo)))
        self.line_tol = max(self.tol, config.ROUNDOFF_ULPS * resolution)
        edges, owner = constraint_edges(triangles, nb) if constraints is None else constraints
        self.edges, self.edge_region = edges, region[owner]
        self.member = region_members(np.ascontiguousarray(triangles, dtype=np.int64),
                                     np.ascontiguousarray(region, dtype=np.int64), n,
                                     int(region.max()) + 1)
        out_deg = np.bincount(edges[:, 0], minlength=n)
        in_deg = np.bincount(edges[:, 1], minlength=n)
        simple = (out_deg == 1) & (in_deg == 1)
        self.prev = np.full(n, -1, dtype=np.int64)
        self.next = np.full(n, -1, dtype=np.int64)
        self.prev[edges[:, 1]] = edges[:, 0]
        self.next[edges[:, 0]] = edges[:, 1]
        self.wedge = np.zeros((n, 4))              # incoming, outgoing edge directions
        b = np.flatnonzero(simple)
        u = nodes[b] - nodes[self.prev[b]]
        v = nodes[self.next[b]] - nodes[b]
        cross = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
        dot = (u * v).sum(axis=1)
        size = np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1)
        convex = (cross >= -1e-12 * size) & ((dot > 0) | (cross > 1e-12 * size))
        self.wedge[b] = np.column_stack([u, v])
        # constraint ends that are not convex boundary nodes: reflex corners, crack tips,
        # interface nodes, several fans; the two copies of a crack-face node (nodes
        # within `tol` of another: their faces are coincident constraint edges of one
        # region, which the clipping does not tell apart) are found near the cells
        # asked for (`_near`)
        self.safe = (out_deg == 0) & (in_deg == 0)
        self.safe[b[convex]] = True
        self.wedge[~self.safe] = 0.0
        # reflex corners: one edge in and one out, turning right (not a crack tip, whose
        # edges run back along each other)
        self.reflex = np.zeros(n, dtype=bool)
        self.reflex[b[cross < -1e-12 * size]] = True
        self.kind = np.full(n, COMPLEX, dtype=np.int8)
        self.kind[self.safe & ~simple] = BARE
        self.kind[simple] = SIMPLE
        self.twin = np.zeros(n, dtype=bool)      # found near the cells asked for (`_near`)
        self.edge_idx = np.argsort(edges.ravel(), kind="stable") // 2
        self.edge_ptr = np.zeros(n + 1, dtype=np.int64)
        np.cumsum(out_deg + in_deg, out=self.edge_ptr[1:])
        self.edge_half = 0.5 * float(np.linalg.norm(nodes[edges[:, 0]] - nodes[edges[:, 1]],
                                                    axis=1).max(initial=0.0))

    def cells(self, node: np.ndarray, region: np.ndarray, start: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The cells of nodes ``node`` in regions ``region``, those the half-plane path
        can take (the others need the exact path).

        Parameters
        ----------
        node, region : (w,) int64 ndarray
            The (node, region) pairs.
        start : (w,) float64 ndarray
            Half-size of the first box tried for each (e.g. the distance to the
            farthest neighbour); a cell that may reach beyond its box is retried in
            a box twice as large, at most until the box covers the nodes.

        Returns
        -------
        done : (c,) int64 ndarray
            Positions in ``node`` of the cells clipped, in no particular order.
        counts : (c,) int64 ndarray
            Their vertex counts.
        vertices : (counts.sum(), 2) ndarray
            Their counter-clockwise vertices, one cell after another in the order of
            ``done``.
        """
        node = np.asarray(node, dtype=np.int64)
        region = np.asarray(region, dtype=np.int64)
        size = np.array(start, dtype=np.float64)
        # a reflex corner's cell reaches about half its fan's size past it (beyond a hole's
        # fine edges, to the circumcentres), and its box must hold twice the cell's radius: a
        # box a quarter larger than the fan, not a first try that fails
        size[self.reflex[node]] *= _REFLEX_START
        todo = np.arange(len(node))
        done, counts, vertices = [], [], []
        # at most 64 doublings (boxes up to 1.8e19 times the first): a cell still growing
        # then, like one whose box covers the extent, is left to the exact path
        for _ in range(64):
            if todo.size:
                tree, subset = self._near(node[todo], size[todo])
                at = node[todo]
                todo = todo[self.safe[at] | (self.reflex[at] & ~self.twin[at])]
            if todo.size == 0:
                break
            group, near_ptr, near_idx = self._candidates(node[todo], size[todo], tree, subset)
            status, count, first, out = clip_cells(
                self.nodes, node[todo], region[todo], size[todo], self.extent, self.prev,
                self.next, self.wedge, self.member, self.safe, self.reflex, self.kind, self.twin,
                self.edges, self.edge_region, self.edge_half, self.edge_ptr, self.edge_idx, group,
                near_ptr, near_idx, self.tol, self.line_tol, work_chunks())
            ok = np.flatnonzero(status == CLIPPED)
            done.append(todo[ok])
            counts.append(count[ok])
            vertices.append(out[np.repeat(first[ok] - np.cumsum(count[ok]) + count[ok], count[ok])
                                + np.arange(count[ok].sum())])
            todo = todo[status == GROW]
            size[todo] *= 2.0
        if not done:
            return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64), np.zeros((0, 2))
        return np.concatenate(done), np.concatenate(counts), np.concatenate(vertices)

    def _reach(self, node: np.ndarray, size: np.ndarray) -> np.ndarray:
        """Half-sizes ``(w, 2)`` of the boxes around the nodes that hold the discs of radius
        ``sqrt(2) size + edge_half + tol`` (`clip_cells`' candidates), rounding of the
        corners included."""
        radius = size * np.sqrt(2.0) + self.edge_half + self.tol
        return radius[:, None] * (1.0 + 1e-12) + 8.0 * np.spacing(np.abs(self.nodes[node]))

    def _near(self, node: np.ndarray, size: np.ndarray) -> tuple[RTree, np.ndarray]:
        """An R-tree over the nodes near the cells of ``node`` (boxes of half-size
        ``size``): every node within ``2 tol`` of the boxes that hold their candidates'
        discs is in it; those within ``tol`` of another node are marked not `safe` (the
        other one is in the tree too).

        Returns
        -------
        tree : RTree
        subset : (m,) int64 ndarray
            The nodes of the tree's entries.
        """
        x = self.nodes[node]
        pad = self._reach(node, size) + 2.0 * self.tol
        tree, subset = RTree.from_points_in(self.nodes, x - pad, x + pad, self.box)
        ptr, _ = tree.query_ball(self.nodes[subset], max(self.tol, 0.0))
        twins = subset[np.diff(ptr) > 1]           # a node finds itself
        self.safe[twins] = False
        self.twin[twins] = True
        self.wedge[twins] = 0.0
        return tree, subset

    def _candidates(self, node: np.ndarray, size: np.ndarray, tree: RTree, subset: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Candidate lists for the cells of ``node`` with boxes of half-size ``size``: one
        list per leaf of ``tree`` (`_near`, whose nodes include ``node``), every node of
        the box holding the discs of radius ``sqrt(2) size + edge_half + tol`` around that
        leaf's cells (one query per leaf, not per cell).

        Returns
        -------
        group : (w,) int64 ndarray
            Each cell's list.
        ptr, idx : (g + 1,), (k,) int64 ndarray
            CSR of the lists.
        """
        x = self.nodes[node]
        pad = self._reach(node, size)
        leaf = np.empty(len(subset), dtype=np.int64)
        leaf[tree.order] = np.arange(len(subset)) // tree.fanout
        leaves, group = np.unique(leaf[np.searchsorted(subset, node)], return_inverse=True)
        lo = np.full((len(leaves), 2), np.inf)
        hi = np.full((len(leaves), 2), -np.inf)
        np.minimum.at(lo, group, x - pad)
        np.maximum.at(hi, group, x + pad)
        ptr, idx = tree.query(lo, hi)
        return group, ptr, subset[idx]
