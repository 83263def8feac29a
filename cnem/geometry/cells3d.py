"""Constrained Voronoi integration cells in 3-D, with their boundaries as triangles.

A point ``x`` of region ``r`` belongs to the cell of node ``i`` when ``i`` is visible
from ``x`` (the segment between them crosses no blocking boundary or interface face:
one of a patch with a sharp re-entrant edge, `.smooth_patches`; the facets of a
curved cavity or hole hide nothing) and no node visible from ``x`` is nearer. A
node on an interface owns one cell per region.

Two paths compute the cells:

* the *fast path* (numba kernels, `._cells3d_kernels`), for an interior node whose
  ball of radius ``R`` (its farthest circumcentre) meets no boundary face: its cell
  is its Voronoi cell, the polyhedron of the circumcentres of its tetrahedra. Each
  facet is the dual of a Delaunay edge, the circumcentres of the tetrahedra around
  the edge ordered by angle and fan-triangulated; the volume is ``sum(A d) / 6`` over the facets;
* the *general path* (`.cells3d_clip`), for every other node: exact clipping of
  convex polytopes by bisectors, boundary planes or the region's tetrahedra, and
  the shadows of the blocking faces (see there); its convex case (no face in reach
  hides points or bends the region: a box's faces, edges and corners) for many
  cells at once in numba (`.cells3d_convex`), and so its unblocked case near a curved
  cavity or hole (the Voronoi polytope cut by the region's tetrahedra,
  `.cells3d_curved`).

The cells partition each region: their volumes sum to the region's volume to
round-off.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.spatial import cKDTree

from .._parallel import work_chunks
from ..errors import GeometryError
from ._cells3d_kernels import clear_of_faces, dual_facets
from .cells3d_clip import GeneralCells
from .cells3d_convex import convex_cells
from .cells3d_curved import curved_cells
from .tetrahedra import signed_volumes, tet_neighbors
from .._sets import distinct

__all__ = ["Cells3D", "constrained_voronoi_cells"]

#: A tetrahedron is flat when ``|6 V| <= _FLAT * L^3`` (``L`` its longest edge).
_FLAT = 1e-10


@dataclass(frozen=True)
class Cells3D:
    """Constrained Voronoi cells of a 3-D model.

    Attributes
    ----------
    node : (m,) int64 ndarray
        The node each cell belongs to (an interface node owns one cell per region).
    region : (m,) int64 ndarray
    volume : (m,) float64 ndarray
    facet_triangles : (q, 3, 3) float64 ndarray
        The cells' boundaries as triangles (coordinates), counter-clockwise seen from
        outside their cell.
    facet_cell : (q,) int64 ndarray
        The cell each triangle bounds.
    facet_normal : (q, 3) float64 ndarray
        Outward unit normal of each triangle.
    apex : (m, 3) float64 ndarray or None
        A point each cell is star-shaped from, whose cones over the facets make the
        cell (sub-cells: the pyramids of `cnem.assembly.pyramid_cells`, whose
        spokes are not among the facets); None for closed cells.
    """

    node: np.ndarray
    region: np.ndarray
    volume: np.ndarray
    facet_triangles: np.ndarray
    facet_cell: np.ndarray
    facet_normal: np.ndarray
    apex: np.ndarray | None = None

    def __repr__(self) -> str:
        return (f"<Cells3D {len(self.node)} cells, {len(self.facet_cell)} facet triangles, "
                f"volume {self.volume.sum():.6g}>")

    def __len__(self) -> int:
        return len(self.node)

    @property
    def measure(self) -> np.ndarray:
        """``(m,)`` the cells' volumes (as the areas of 2-D cells), for dimension-generic code."""
        return self.volume

    def centroid(self) -> np.ndarray:
        """Centroids ``(m, 3)``: the sum over the facet triangles of the tetrahedra they
        make with the cell's `apex` (else its first facet vertex), weighted by their
        signed volumes (exact for any closed facet surface, and for a pyramid from
        its apex over its facets)."""
        tri = self.facet_triangles
        if self.apex is not None:
            apex = self.apex[self.facet_cell]
        else:
            first = np.full(len(self.node), -1, dtype=np.int64)
            first[self.facet_cell[::-1]] = np.arange(len(tri))[::-1]
            apex = tri[first[self.facet_cell], 0]
        a, b, c = (tri[:, i] - apex for i in range(3))
        six_v = np.einsum("ij,ij->i", a, np.cross(b, c))
        moment = six_v[:, None] * (apex + tri.sum(axis=1)) / 4.0
        total = np.bincount(self.facet_cell, weights=six_v, minlength=len(self.node))
        return np.column_stack([np.bincount(self.facet_cell, weights=moment[:, i],
                                            minlength=len(self.node)) for i in range(3)]) \
            / total[:, None]

    def facet_areas(self) -> np.ndarray:
        """Area ``(q,)`` of each facet triangle."""
        t = self.facet_triangles
        return 0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1)


def _circumcentres(points, tets):
    """Circumcentres ``(t, 3)`` (NaN for flat tetrahedra), relative to the first vertex."""
    a = points[tets[:, 0]]
    m = points[tets[:, 1:]] - a[:, None, :]
    length = np.sqrt((m ** 2).sum(axis=2).max(axis=1))
    det = np.linalg.det(m)
    flat = np.abs(det) <= _FLAT * length ** 3
    rhs = 0.5 * (m ** 2).sum(axis=2)
    m[flat] = np.eye(3)
    c = np.linalg.solve(m, rhs[..., None])[..., 0] + a
    c[flat] = np.nan
    return c


def _borrow_centres(centre, nb, bound):
    """A flat tetrahedron (four cocircular nodes) takes a neighbour's circumcentre: every
    sphere through three of its nodes passes through the fourth."""
    for _ in range(bound):
        flat = np.flatnonzero(np.isnan(centre[:, 0]))
        if len(flat) == 0:
            break
        cand = nb[flat]
        good = (cand >= 0) & ~np.isnan(centre[np.maximum(cand, 0), 0])
        has = good.any(axis=1)
        if not has.any():
            break
        pick = cand[has, np.argmax(good[has], axis=1)]
        centre[flat[has]] = centre[pick]
    return centre


def _fast_nodes(points, tets, centre, faces, boundary_node, star):
    """Nodes whose Voronoi cell (the hull of their circumcentres) meets no boundary face.

    Sufficient test: every face whose bounding sphere the ball to the farthest
    circumcentre reaches has the node and all its circumcentres strictly on one side
    of its plane.
    """
    n = len(points)
    dist = np.linalg.norm(centre[:, None, :] - points[tets], axis=2)
    far = np.zeros(n)
    np.maximum.at(far, tets.ravel(), np.where(np.isnan(dist), np.inf, dist).ravel())
    x = points[faces]
    cen = x.mean(axis=1)
    rad = np.linalg.norm(x - cen[:, None, :], axis=2).max(axis=1)
    normal = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
    cand = np.flatnonzero(~boundary_node & np.isfinite(far))
    hits = cKDTree(cen).query_ball_point(points[cand], far[cand] + rad.max())
    count = np.fromiter(map(len, hits), dtype=np.int64, count=len(cand))
    hit_idx = np.fromiter(itertools.chain.from_iterable(hits), dtype=np.int64, count=count.sum())
    tol = 1e-9 * np.linalg.norm(normal, axis=1) * rad
    clear = clear_of_faces(points, cand, np.concatenate([[0], np.cumsum(count)]), hit_idx, *star,
                           centre, np.ascontiguousarray(x[:, 0]), normal, tol,
                           work_chunks())
    fast = np.zeros(n, dtype=bool)
    fast[cand[clear]] = True
    return fast


def constrained_voronoi_cells(points: ArrayLike, tetrahedra: ArrayLike, tet_region: ArrayLike,
                              boundary_faces: ArrayLike,
                              boundary_face_regions: ArrayLike) -> Cells3D:
    """The constrained Voronoi cells of a boundary-conforming tetrahedrisation.

    Parameters
    ----------
    points : (n, 3) array_like
    tetrahedra : (t, 4) array_like of int
        A Delaunay tetrahedrisation of ``points`` inside the body that contains every
        boundary face (`conforming_tetrahedra` gives one).
    tet_region : (t,) array_like of int
    boundary_faces : (b, 3) array_like of int
    boundary_face_regions : (b, 2) array_like of int
        As `conforming_tetrahedra` takes them.

    Returns
    -------
    Cells3D
        One cell per (node, region) pair, ordered by node then region.
    """
    points = np.ascontiguousarray(points, dtype=np.float64)
    tets = np.ascontiguousarray(tetrahedra, dtype=np.int64)
    tet_region = np.ascontiguousarray(tet_region, dtype=np.int64)
    faces = np.ascontiguousarray(boundary_faces, dtype=np.int64)
    face_regions = np.ascontiguousarray(boundary_face_regions, dtype=np.int64)
    n = len(points)
    n_reg = int(tet_region.max()) + 1
    pair = distinct(np.repeat(tet_region, 4) + n_reg * tets.ravel())
    cell_node, cell_region = pair // n_reg, pair % n_reg
    single = np.bincount(cell_node, minlength=n) == 1
    cell_of = np.full(n, -1, dtype=np.int64)
    cell_of[cell_node[single[cell_node]]] = np.flatnonzero(single[cell_node])
    boundary_node = np.zeros(n, dtype=bool)
    boundary_node[faces.ravel()] = True
    centre = _borrow_centres(_circumcentres(points, tets), tet_neighbors(tets, n), 64)
    order = np.argsort(tets.ravel(), kind="stable")         # the tetrahedra at each node
    star = np.searchsorted(tets.ravel()[order], np.arange(n + 1)), order // 4
    fast = _fast_nodes(points, tets, centre, faces, boundary_node, star) & single
    # the fast cells' facets: the Voronoi facets dual to their edges
    tri, fcell, nrm = dual_facets(points, tets, *star, centre, fast, cell_of)
    general = GeneralCells(points, tets, tet_region, faces, face_regions)
    volume = np.zeros(len(cell_node))
    slow = np.flatnonzero(~fast[cell_node])
    done, b_tri, b_cell, b_nrm, b_vol = convex_cells(general, cell_node[slow], cell_region[slow])
    volume[slow[done]] = b_vol[done]
    parts_t, parts_c, parts_n = [b_tri], [slow[b_cell]], [b_nrm]
    rest = slow[~done]
    done, c_tri, c_cell, c_nrm, c_vol = curved_cells(general, cell_node[rest], cell_region[rest])
    volume[rest[done]] = c_vol[done]
    parts_t.append(c_tri)
    parts_c.append(rest[c_cell])
    parts_n.append(c_nrm)
    for k in rest[~done].tolist():
        t, nr, vol = general.cell(int(cell_node[k]), int(cell_region[k]))
        parts_t.append(t)
        parts_c.append(np.full(len(t), k, dtype=np.int64))
        parts_n.append(nr)
        volume[k] = vol
    # the general cells in the order of the cells, after the fast ones
    order = np.argsort(np.concatenate(parts_c), kind="stable")
    tri = np.concatenate([tri, np.concatenate(parts_t)[order]])
    fcell = np.concatenate([fcell, np.concatenate(parts_c)[order]])
    nrm = np.concatenate([nrm, np.concatenate(parts_n)[order]])
    # the fast cells' volumes: pyramids from the node over each facet triangle
    rel = tri - points[cell_node[fcell]][:, None, :]
    pyramid = np.einsum("ij,ij->i", rel[:, 0], np.cross(rel[:, 1], rel[:, 2])) / 6.0
    is_fast = fast[cell_node]
    volume[is_fast] = np.bincount(fcell, weights=pyramid, minlength=len(cell_node))[is_fast]
    want = np.bincount(tet_region, weights=np.abs(signed_volumes(points, tets)), minlength=n_reg)
    got = np.bincount(cell_region, weights=volume, minlength=n_reg)
    if np.abs(got - want).max() > 1e-8 * want.sum():
        raise GeometryError(
            f"the cells' volumes per region {got.tolist()} do not sum to the regions' volumes "
            f"{want.tolist()}; the tetrahedrisation must be Delaunay and contain every "
            f"boundary face (use conforming_tetrahedra)")
    return Cells3D(cell_node, cell_region, volume, tri, fcell, nrm)
