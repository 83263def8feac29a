"""The smoothed gradients of 3-D cells from quadratures on their boundary facets.

A 3-D cell's boundary is given as triangles with outward unit normals (the
cells' facets, cut into triangles); the smoothed derivative of shape function
``phi_I`` on cell ``k`` (the C-NEM paper's eq. 30 in 3-D) is

    b~_Ii(k) = 1 / V_k  sum_f  int_f phi_I n_i dA

integrated by one point per facet, its centroid (`facet_points`). The rule is
exact for linear functions, which keeps the divergence consistency (the shape
functions reproduce ``x`` and ``int_dV x (x) n dA = V I`` over a closed
surface), and it depends on the facet polygon alone, so the two cells that share
a facet evaluate it at the same point and the integration constraint holds
whatever triangles each cell's facets were cut into.

The stabilisation's pyramid sub-cells, whose boundaries add spokes to these
facets, are in `.pyramid_cells`.

A facet on a material interface is not shared: the cells of the two regions cut
the interface into different polygons. Those facets are integrated on the common
refinement of the two sides (`.interface_facets`), one point per piece, used by
both cells with opposite normals, so the integration constraint holds across
interfaces too.
"""

from __future__ import annotations

from itertools import chain
from typing import Any, Callable, NamedTuple

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree
from .. import config
from .._parallel import work_chunks
from ..errors import GeometryError
from ..shape.natural3d import inside_tetrahedra
from . import _facet_kernels as FK
from .interface_facets import InterfacePieces, interface_pieces, on_triangles
from .smoothed_gradient import SmoothedGradient
from .._sets import isin

__all__ = ["facet_points", "facet_gradient", "FacetRule", "facet_rule", "gradients_of_rules",
           "boundary_points_3d", "cell_gradient_3d", "model_interface_pieces"]

#: Facet normals are told apart to ``1 / PLANE_RESOLUTION`` (unit normals of one
#: cell's distinct Voronoi facets differ by far more).
PLANE_RESOLUTION = 2.0 ** 24

#: A cell's triangles of one outward normal whose planes are further apart than this
#: fraction of the triangles' extent belong to different facets.
FACET_PLANE_RTOL = 1e-9

#: Two facet points closer than this fraction of the model's size are one point (the
#: two sides of a shared facet, computed from the same polygon), or closer than
#: ``config.ROUNDOFF_ULPS`` round-offs of the coordinates far from the origin
#: (`_pair_tolerance`).
PAIR_RTOL = 1e-10

#: Shape functions at points: ``evaluate(points (q, 3)) -> csr (q, n)``.
Evaluate = Callable[[np.ndarray], sp.csr_matrix]


def facet_points(facet_triangles: np.ndarray, facet_cell: np.ndarray, facet_normal: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One point per facet of every cell: the centroid of its triangles, with their
    summed area times the facet's normal.

    A facet is the set of a cell's triangles of one outward normal (to
    `PLANE_RESOLUTION`) in one plane (to `FACET_PLANE_RTOL`: a non-convex cell, at a
    re-entrant edge, can have parallel facets with the same outward normal, a
    boundary face and a bisector beyond it, which are two facets). Its centroid and area depend on the polygon only, not on
    how it was cut into triangles, so the two cells that share a facet evaluate
    the shape functions at the same point and their integrals cancel (the
    integration constraint), whichever triangles each was given.

    Parameters
    ----------
    facet_triangles : (f, 3, 3) ndarray
    facet_cell : (f,) int64 ndarray
    facet_normal : (f, 3) ndarray
        Outward unit normals.

    Returns
    -------
    cell : (k,) int64 ndarray
    point : (k, 3) ndarray
    area_normal : (k, 3) ndarray
    """
    return _grouped_facet_points(facet_triangles, facet_cell, facet_normal)[1:]


def _grouped_facet_points(facet_triangles, facet_cell, facet_normal, on_interface=None):
    """`facet_points`, after the facet of every triangle (`_facet_groups`)."""
    tri = facet_triangles
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    group, first = _facet_groups(tri, facet_cell, facet_normal, on_interface)
    total = np.bincount(group, weights=area, minlength=len(first))
    centre = tri.mean(axis=1)
    point = np.column_stack([np.bincount(group, weights=area * centre[:, i], minlength=len(first))
                             for i in range(3)]) / total[:, None]
    normal = np.column_stack([np.bincount(group, weights=area * facet_normal[:, i],
                                          minlength=len(first)) for i in range(3)])
    return group, facet_cell[first], point, normal


def _facet_groups(facet_triangles, facet_cell, facet_normal, on_interface=None):
    """The facet (cell, normal, plane) of each triangle, numbered in the order of the
    cells, and a triangle of each facet. With ``on_interface`` (f,) bool (the triangles
    cut into interface pieces), a cell's triangles cut and not cut in one plane are two
    facets.

    Triangles of one cell and one normal lie in one facet when their planes' offsets,
    sorted, run without a gap above ``FACET_PLANE_RTOL`` times the triangles' extent
    (plus the round-off of their coordinates: far from the origin) — the triangles of
    one polygon agree to round-off; parallel facets of a non-convex cell are apart."""
    columns = [facet_cell, np.round(facet_normal * PLANE_RESOLUTION)]
    if on_interface is not None:
        columns.append(on_interface)
    key = np.column_stack(columns).astype(np.int64)
    if len(key) == 0:
        empty = np.zeros(0, dtype=np.int64)
        return empty, empty
    corners = facet_triangles.reshape(-1, 3)
    low = corners.min(axis=0)
    offset = np.einsum("ij,ij->i", facet_normal, facet_triangles.mean(axis=1) - low)
    # the planes' round-off: relative to the extent, and that of coordinates far from 0
    tol = (FACET_PLANE_RTOL * float(np.ptp(corners, axis=0).max())
           + 64.0 * np.finfo(float).eps * float(np.abs(corners).max()))
    # by key (cell, normal[, cut]), then by offset (a lexsort: sorting the rows as
    # records is several times slower)
    order = np.lexsort((offset, *key.T[::-1]))
    ranked = key[order]
    starts = np.ones(len(order), dtype=bool)
    starts[1:] = ((ranked[1:] != ranked[:-1]).any(axis=1)
                  | (np.diff(offset[order]) > tol))
    group = np.empty(len(order), dtype=np.int64)
    group[order] = np.cumsum(starts) - 1
    return group, order[starts]


def facet_gradient(facet_triangles: np.ndarray, facet_cell: np.ndarray, facet_normal: np.ndarray,
                   volume: np.ndarray, evaluate: Evaluate, *,
                   spokes: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None = None,
                   interface: InterfacePieces | None = None) -> SmoothedGradient:
    """``B~`` of 3-D cells from their boundary triangles.

    Parameters
    ----------
    facet_triangles : (f, 3, 3) ndarray
        The cells' boundary triangles, in the model's local frame (coordinates of the
        size of the body, not of its distance from the origin: the normals and the
        rule's points keep their digits).
    facet_cell : (f,) int64 ndarray
        The cell each bounds.
    facet_normal : (f, 3) ndarray
        Outward unit normals (out of ``facet_cell``).
    volume : (m,) ndarray
        The cells' volumes.
    evaluate : callable ``(q, 3) -> csr (q, n)``
        The shape functions at points.
    spokes : (centroid (s, 3), area-normal (s, 3), cell_a (s,), cell_b (s,)), optional
        Faces integrated by one point (the sub-cells' spokes, `pyramid_sub_cells`),
        with the normal out of ``cell_a`` and, where ``cell_b >= 0``, the opposite
        one out of ``cell_b``.
    interface : InterfacePieces, optional
        The common refinement of the facets on material interfaces
        (`interface_pieces`, on these triangles): it replaces their facet points.

    Returns
    -------
    SmoothedGradient
        ``x, y, z`` sparse ``(m, n)``.

    Raises
    ------
    GeometryError
        A cell of volume not positive.
    """
    rule = facet_rule(facet_triangles, facet_cell, facet_normal, volume, spokes=spokes,
                      interface=interface)
    return gradients_of_rules([rule], evaluate)[0]


class FacetRule(NamedTuple):
    """The boundary quadrature of ``m`` cells: each cell's points and their weights.

    Attributes
    ----------
    points : (q, 3) ndarray
        The quadrature points (a point on a face between two cells is one row, used by both).
    point : (e,) int64 ndarray
        The row of ``points`` of every (cell, point) entry.
    cell : (e,) int64 ndarray
    flux : (e, 3) ndarray
        Area-normal out of ``cell``.
    volume : (m,) ndarray
    """

    points: np.ndarray
    point: np.ndarray
    cell: np.ndarray
    flux: np.ndarray
    volume: np.ndarray


def facet_rule(facet_triangles: np.ndarray, facet_cell: np.ndarray, facet_normal: np.ndarray,
               volume: np.ndarray, *,
               spokes: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None = None,
               interface: InterfacePieces | None = None) -> FacetRule:
    """The quadrature `facet_gradient` integrates with (same parameters), before the
    shape functions are evaluated.

    Returns
    -------
    FacetRule
    """
    if np.any(~(volume > 0)):
        bad = np.flatnonzero(~(volume > 0))[:5]
        raise GeometryError(f"expected cells of positive volume, received volumes "
                            f"{volume[bad].tolist()} at cells {bad.tolist()}")
    group, cell, points, flux = _grouped_facet_points(
        facet_triangles, facet_cell, facet_normal,
        None if interface is None else interface.on_interface)
    two_sided = [] if spokes is None else [(spokes[0], spokes[1], -spokes[1], *spokes[2:])]
    if interface is not None and len(interface.tri_a):
        whole = np.ones(len(points), dtype=bool)
        whole[group[interface.on_interface]] = False
        cell, points, flux = cell[whole], points[whole], flux[whole]
        two_sided.append((interface.point, interface.area_normal_a, interface.area_normal_b,
                          facet_cell[interface.tri_a], facet_cell[interface.tri_b]))
    column = np.arange(len(points), dtype=np.int64)
    for centre, flux_a, flux_b, a, b in two_sided:
        at = len(points) + np.arange(len(centre), dtype=np.int64)
        other = b >= 0                                  # a one-sided spoke has b = -1
        points = np.concatenate([points, centre])
        column = np.concatenate([column, at, at[other]])
        cell = np.concatenate([cell, a, b[other]])
        flux = np.concatenate([flux, flux_a, flux_b[other]])
    return FacetRule(points, column, cell, flux, volume)


def gradients_of_rules(rules: list[FacetRule], evaluate: Evaluate) -> list[SmoothedGradient]:
    """``B~`` of each rule's cells, the shape functions evaluated once at each distinct
    point of all the rules (the cells and their sub-cells share their facet points,
    and the two cells on either side of a facet often compute the same point).

    Parameters
    ----------
    rules : list of FacetRule
    evaluate : callable ``(q, 3) -> csr (q, n)``

    Returns
    -------
    list of SmoothedGradient
        One per rule, equal to evaluating each rule's points on their own.
    """
    every = np.concatenate([rule.points for rule in rules])
    first, label = _distinct_points(every)
    phi = evaluate(every[first]).tocsr()
    v_ptr = phi.indptr.astype(np.int64)
    out, base = [], 0
    for rule in rules:
        m = len(rule.volume)
        # each cell's points in the order of their rows, the three directions on one
        # pattern (what `cnem.assembly.forms` assembles by node blocks)
        order = np.lexsort((rule.point, rule.cell))
        ptr = np.zeros(m + 1, dtype=np.int64)
        np.cumsum(np.bincount(rule.cell, minlength=m), out=ptr[1:])
        weight = np.ascontiguousarray((rule.flux / rule.volume[rule.cell][:, None])[order])
        item = np.ascontiguousarray(label[base + rule.point[order]])
        indptr, indices, data = FK.weighted_rows(ptr, item, weight, v_ptr, phi.indices,
                                                 phi.data, phi.shape[1], work_chunks())
        # canonical (the kernel sorts every row): the three share ``indices``, so nothing
        # may sort one of them in place (`CellBasis` spreads them as they are)
        parts = [sp.csr_matrix((data[i], indices, indptr), shape=(m, phi.shape[1]))
                 for i in range(3)]
        for part in parts:
            part.has_canonical_format = True
        out.append(SmoothedGradient(*parts, points=len(rule.points)))
        base += len(rule.points)
    return out


def _distinct_points(points):
    """The distinct rows of ``points (q, 3)``, bit for bit: the first row of each ``(d,)``,
    increasing, and the distinct row of every point ``(q,)``, in ``0..d-1`` (numbered in
    the order of their first rows: a cell's points stay near each other)."""
    bits = np.ascontiguousarray(points, dtype=np.float64).view(np.uint64)
    order = np.lexsort(bits.T[::-1])                # stable: a group's first row leads it
    ranked = bits[order]
    new = np.ones(len(order), dtype=bool)
    new[1:] = (ranked[1:] != ranked[:-1]).any(axis=1)
    first = order[new]
    number = np.empty(len(first), dtype=np.int64)
    number[np.argsort(first)] = np.arange(len(first))
    label = np.empty(len(order), dtype=np.int64)
    label[order] = number[np.cumsum(new) - 1]
    return np.sort(first), label


def cell_gradient_3d(model: Any, cells: Any,
                     interface: InterfacePieces | None = None) -> SmoothedGradient:
    """``B~`` of a 3-D model's cells (`facet_gradient` on their facet triangles, the
    model's shape functions).

    Parameters
    ----------
    model : Model3D
    cells : Cells3D
        ``model.cells`` or other cells of the model with facets.
    interface : InterfacePieces, optional
        `model_interface_pieces` of these cells, when already known.

    Returns
    -------
    SmoothedGradient
    """
    if interface is None:
        interface = model_interface_pieces(model, cells)
    return facet_gradient(cells.facet_triangles, cells.facet_cell, cells.facet_normal,
                          cells.volume, model.shape_functions, interface=interface)


def model_interface_pieces(model: Any, cells: Any) -> InterfacePieces:
    """`interface_pieces` of a 3-D model's cells on its interface faces and on their
    shadow facets (in the plane of a boundary or interface face beyond its border,
    where the cells of the two sides cut the plane differently: their facet points
    find no partner, and the triangles lie on no boundary face; a cell's facet in a
    face's plane can be partly on the face and partly beyond it, and only the part
    beyond is cut into pieces), and on the facets whose centroid
    lies outside the body (non-convex facets round a re-entrant edge: one point per
    overlap of the two sides' triangles).

    Parameters
    ----------
    model : Model3D
    cells : Cells3D

    Returns
    -------
    InterfacePieces
    """
    tri = cells.facet_triangles
    group, _, point, area_normal = _grouped_facet_points(tri, cells.facet_cell,
                                                         cells.facet_normal)
    size, tol = _pair_tolerance(model)
    # shadow triangles: of an unpaired facet, and on no boundary face (one facet in a
    # face's plane can be partly on the face and partly its shadow beyond the face's
    # border, which the cells on the other side cut differently)
    paired = _paired(point, area_normal, tol)
    lone = np.flatnonzero(~paired[group])
    faces, normal = model.boundary_with_normals()
    outer = _face_holding(tri[lone].mean(axis=1), cells.facet_normal[lone], model.nodes[faces],
                          normal, tol) >= 0
    shadow = np.zeros(len(tri), dtype=bool)
    shadow[lone[~outer]] = True
    # a non-convex facet (wrapping a re-entrant edge) whose centroid lies outside the body:
    # one point per piece of the two sides' triangles, each inside its triangles
    astray = np.flatnonzero(~inside_tetrahedra(model.tet_mesh(), point))
    if (~paired[astray]).any():
        bad = point[astray[~paired[astray]]][:3]
        raise GeometryError(f"expected the centroids of the cells' boundary facets to lie in "
                            f"the body, received {bad.tolist()} outside; refine the cloud there")
    split = isin(group, astray)
    between = model.boundary_face_regions[:, 1] >= 0
    return interface_pieces(tri, cells.facet_normal, group,
                            model.nodes[model.boundary_faces[between]], size,
                            also=shadow | split, split=split)


def _pair_tolerance(model):
    """The model's size and the distance under which two facet points are one:
    ``PAIR_RTOL`` of the size, or ``config.ROUNDOFF_ULPS`` round-offs of the largest
    coordinate (a body far from the origin has its cells' vertices rounded to the
    global coordinates' spacing)."""
    size = float(np.linalg.norm(np.ptp(model.nodes, axis=0)))
    largest = float(np.abs(model.nodes).max())
    return size, max(PAIR_RTOL * size, config.ROUNDOFF_ULPS * np.finfo(float).eps * largest)


def _paired(point, area_normal, tol):
    """Whether each facet point ``(k, 3)`` has another within ``tol`` with an opposite
    area-normal: the two sides of one facet."""
    pairs = cKDTree(point).query_pairs(tol, output_type="ndarray")
    opposite = np.einsum("ij,ij->i", area_normal[pairs[:, 0]], area_normal[pairs[:, 1]]) < 0
    shared = np.zeros(len(point), dtype=bool)
    shared[pairs[opposite].ravel()] = True
    return shared


def boundary_points_3d(model: Any, interface: InterfacePieces | None = None
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The facet points of a 3-D model's cells that lie on its outer boundary, with the
    boundary face each lies on: where tractions are integrated, so that a load
    ``sum_q phi_I(x_q) t_q A_q`` takes the very points of the cells' boundary
    integrals (the patch test with tractions holds to round-off).

    A cell's facet is on the outer boundary when no other cell has a facet at its
    point with the opposite area-normal (interior and interface facets come in
    such pairs).

    Parameters
    ----------
    model : Model3D
    interface : InterfacePieces, optional
        `model_interface_pieces` of ``model.cells``, when already known.

    Returns
    -------
    point : (k, 3) ndarray
    area_normal : (k, 3) ndarray
        Outward, of length the facet's area.
    face : (k,) int64 ndarray
        The row of ``model.boundary_with_normals()`` the point lies on.
    """
    cells = model.cells
    if interface is None:
        interface = model_interface_pieces(model, cells)
    faces, normal = model.boundary_with_normals()
    # only the facets facing like a boundary triangle (either way: their partners too)
    take = _facing_boundary(cells.facet_normal, normal)
    on_interface = interface.on_interface[take]
    group, _, point, area_normal = _grouped_facet_points(
        cells.facet_triangles[take], cells.facet_cell[take], cells.facet_normal[take], on_interface)
    _, tol = _pair_tolerance(model)
    shared = _paired(point, area_normal, tol)
    shared[group[on_interface]] = True
    outer = np.flatnonzero(~shared)
    corners = model.nodes[faces]
    face = _face_holding(point[outer], area_normal[outer], corners, normal, tol)
    keep = face >= 0
    if not keep.all():
        raise GeometryError(f"{int((~keep).sum())} cell facets on the boundary lie on no "
                            f"boundary triangle, first at {point[outer][~keep][:3].tolist()}")
    return point[outer], area_normal[outer], face


def _facing_boundary(facet_normal, boundary_normal, resolution=1e-3):
    """Which facet triangles ``(q,)`` have a unit normal within ``resolution / 2`` (each
    component) of a boundary triangle's outward normal or its opposite, and some
    others nearby: a superset of those that can lie on the boundary, found by rounding
    the normals to a grid of that step (the boundary ones with their 26 neighbours)."""
    def keys(cells):
        side = int(round(2.0 / resolution)) + 3
        c = cells + side // 2
        return (c[:, 0] * side + c[:, 1]) * side + c[:, 2]

    grid = np.round(np.vstack([boundary_normal, -boundary_normal]) / resolution).astype(np.int64)
    shifts = np.array([[i, j, k] for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1)])
    near = keys((grid[:, None, :] + shifts[None]).reshape(-1, 3))
    return isin(keys(np.round(facet_normal / resolution).astype(np.int64)), near)


def _face_holding(points, area_normal, corners, normal, tol):
    """The boundary triangle (of the same outward normal) holding each point (within
    ``tol`` of its plane), -1 if none.

    Candidates are the triangles whose bounding sphere about their centroid (the
    largest one's radius) reaches the point; each (point, candidate) pair is tested
    at once, and a point takes its first candidate that holds it."""
    centre = corners.mean(axis=1)
    reach = np.linalg.norm(corners - centre[:, None], axis=2).max(axis=1)
    tree = cKDTree(centre)
    out = np.full(len(points), -1, dtype=np.int64)
    candidates = tree.query_ball_point(points, r=float(reach.max()) * (1.0 + 1e-9))
    count = np.fromiter(map(len, candidates), dtype=np.int64, count=len(points))
    face = np.fromiter(chain.from_iterable(candidates), dtype=np.int64, count=int(count.sum()))
    point = np.repeat(np.arange(len(points), dtype=np.int64), count)
    unit = area_normal / np.linalg.norm(area_normal, axis=1)[:, None]
    facing = np.einsum("ij,ij->i", normal[face], unit[point]) > 1.0 - 1e-6
    face, point = face[facing], point[facing]
    inside = on_triangles(points[point], corners[face], PAIR_RTOL * 1e3, tol)
    face, point = face[inside], point[inside]
    # the first hit of each point (pairs are in candidate order, grouped by point)
    first = np.flatnonzero(np.r_[True, point[1:] != point[:-1]]) if len(point) else point
    out[point[first]] = face[first]
    return out
