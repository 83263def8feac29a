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

The stabilisation's sub-cells are the pyramids from each cell's node to its
facet triangles (tetrahedra: a constrained Voronoi cell is star-shaped from its
node, since every point of it sees the node). A sub-cell's boundary is its facet
triangle plus three *spokes* (node, facet edge), shared with the neighbouring
sub-cells of the same cell, where they cancel; the spokes are integrated by
their centroid alone, exact for the linear fields the shape functions reproduce.

A facet on a material interface is not shared: the cells of the two regions cut
the interface into different polygons. Those facets are integrated on the common
refinement of the two sides (`.interface_facets`), one point per piece, used by
both cells with opposite normals, so the integration constraint holds across
interfaces too; each piece goes to the sub-cell of its facet.
"""

from __future__ import annotations

from itertools import chain
from typing import Any, Callable

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree
from .. import config
from .._parallel import work_chunks
from ..errors import GeometryError
from ..shape.natural3d import inside_tetrahedra
from . import _facet_kernels as FK
from .interface_facets import InterfacePieces, interface_pieces, on_triangles
from .smoothed_gradient import SmoothedGradient
from .._sets import distinct, isin

__all__ = ["facet_points", "facet_gradient", "boundary_points_3d", "pyramid_sub_cells", "cell_gradient_3d",
           "model_interface_pieces", "sub_cell_gradient_3d", "merged_across_holes"]

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
    _, direction = np.unique(key, axis=0, return_inverse=True)
    direction = direction.reshape(-1)
    if len(direction) == 0:
        return direction, direction
    corners = facet_triangles.reshape(-1, 3)
    low = corners.min(axis=0)
    offset = np.einsum("ij,ij->i", facet_normal, facet_triangles.mean(axis=1) - low)
    # the planes' round-off: relative to the extent, and that of coordinates far from 0
    tol = (FACET_PLANE_RTOL * float(np.ptp(corners, axis=0).max())
           + 64.0 * np.finfo(float).eps * float(np.abs(corners).max()))
    order = np.lexsort((offset, direction))
    starts = np.ones(len(order), dtype=bool)
    starts[1:] = ((direction[order[1:]] != direction[order[:-1]])
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
    """
    m = len(volume)
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
    phi = evaluate(points).tocsr()
    q = len(points)
    # each cell's points in the order of their columns, the three directions on one
    # pattern (what `cnem.assembly.forms` assembles by node blocks)
    order = np.lexsort((column, cell))
    ptr = np.zeros(m + 1, dtype=np.int64)
    np.cumsum(np.bincount(cell, minlength=m), out=ptr[1:])
    weight = np.ascontiguousarray((flux / volume[cell][:, None])[order])
    indptr, indices, data = FK.weighted_rows(ptr, column[order], weight,
                                             phi.indptr.astype(np.int64), phi.indices,
                                             phi.data, phi.shape[1], work_chunks())
    # canonical (the kernel sorts every row): the three share ``indices``, so nothing may
    # sort one of them in place (`CellBasis` spreads them as they are)
    parts = [sp.csr_matrix((data[i], indices, indptr), shape=(m, phi.shape[1]))
             for i in range(3)]
    for part in parts:
        part.has_canonical_format = True
    return SmoothedGradient(*parts, points=q)


def pyramid_sub_cells(node_xyz: np.ndarray, facet_triangles: np.ndarray, facet_cell: np.ndarray,
                      facet_normal: np.ndarray, rtol: float = 1e-12
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray, tuple]:
    """The pyramids from each cell's node to its facets, as sub-cells.

    A facet is a group of triangles of one cell, one normal and one plane (`facet_points`).
    Its pyramid's boundary is the facet itself and one spoke triangle (node, edge)
    per edge of its outline, shared with the pyramid of the neighbouring facet,
    where the two cancel. A facet through the node (a node on the cell's
    boundary) makes a flat pyramid: it joins the largest neighbouring pyramid
    (not a sliver, whose gradient it would make ill-conditioned), whose
    boundary then takes that facet instead of the spoke between them. So every
    facet point of a cell belongs to exactly one of its sub-cells, and
    ``sum_s V_s b~_s = V_k b~_k`` holds for any functions.

    Parameters
    ----------
    node_xyz : (m, 3) ndarray
        The node of every cell.
    facet_triangles : (f, 3, 3) ndarray
        The cells' boundary triangles, oriented with outward normals (right-hand rule).
    facet_cell : (f,) int64 ndarray
    facet_normal : (f, 3) ndarray
    rtol : float
        Pyramids thinner than this fraction of their facet's size are flat.

    Returns
    -------
    sub_parent : (s,) int64 ndarray
        The cell each sub-cell belongs to.
    triangle_sub : (f,) int64 ndarray
        The sub-cell of each facet triangle.
    volume : (s,) ndarray
    spokes : (centroid (e, 3), area-normal (e, 3), sub_a (e,), sub_b (e,))
        The spoke faces between two sub-cells, oriented out of ``sub_a``. Where the
        neighbouring facet cut the edge otherwise (a T-junction), the spokes are the
        pieces of the common refinement of the collinear edges; ``sub_b`` is -1 only
        for an edge no other edge of the cell runs along (each side then closes its
        own sub-cell).

    Raises
    ------
    GeometryError
        A cell all of whose facets pass through its node (no volume).
    """
    group, _ = _facet_groups(facet_triangles, facet_cell, facet_normal)
    apex = node_xyz[facet_cell]
    a, b, c = (facet_triangles[:, i] - apex for i in range(3))
    six_v = np.einsum("ij,ij->i", a, np.cross(b, c))            # > 0: apex behind the facet
    size = np.max(np.linalg.norm(facet_triangles - facet_triangles[:, [1, 2, 0]], axis=2), axis=1)
    n_groups = group.max() + 1 if len(group) else 0
    volume = np.bincount(group, weights=six_v, minlength=n_groups) / 6.0
    scale = np.zeros(n_groups)
    np.maximum.at(scale, group, size)
    # the directed edges of every triangle; an edge met both ways in one facet is inside it
    p = np.concatenate([facet_triangles[:, i] for i in range(3)])
    q = np.concatenate([facet_triangles[:, (i + 1) % 3] for i in range(3)])
    edge_group = np.tile(group, 3)
    edge_cell = np.tile(facet_cell, 3)
    outline = ~_has_reverse(edge_group, p, q)
    p, q, edge_group, edge_cell = p[outline], q[outline], edge_group[outline], edge_cell[outline]
    # an edge's twin is the same edge the other way in a neighbouring facet; a facet
    # cut differently on the two sides of an edge leaves it without (its spokes are then
    # cut at the T-junction, `_t_junction_pieces`)
    twin = _reverse_in(edge_cell, p, q)
    paired = twin >= 0
    # flat facets join the largest neighbouring pyramid (through flat neighbours, a
    # bounded walk)
    owner = np.where(volume > rtol * scale ** 3, np.arange(n_groups), -1)
    for _ in range(n_groups):
        todo = owner[edge_group] < 0
        if not todo.any():
            break
        across = np.where(paired, owner[edge_group[np.maximum(twin, 0)]], -1)
        give = todo & (across >= 0)
        if not give.any():
            bad = distinct(edge_cell[todo])[:5]
            raise GeometryError(f"cells {bad.tolist()}: every facet passes through the cell's "
                                "node; expected cells of positive volume")
        largest = np.full(n_groups, -np.inf)
        np.maximum.at(largest, edge_group[give], volume[across[give]])
        best = give & (volume[np.maximum(across, 0)] == largest[edge_group])
        owner[edge_group[best]] = across[best]
    kept, sub_of_owner = np.unique(owner, return_inverse=True)
    triangle_sub = sub_of_owner[group]
    edge_sub = sub_of_owner[owner[edge_group]]
    other = np.where(paired, edge_sub[np.maximum(twin, 0)], -1)
    # a T-junction (one facet cut the edge where its neighbour did not): the spokes
    # are cut at the common refinement of the collinear edges, in pairs
    lone = np.flatnonzero(~paired)
    pa, pb, pieces = _t_junction_pieces(p[lone], q[lone], edge_cell[lone], scale[edge_group[lone]])
    alone = np.ones(len(lone), dtype=bool)
    alone[pa] = False
    alone[pb] = False
    between = (paired & (edge_sub != other) & (np.arange(len(p)) < twin))
    between[lone[alone]] = True
    start, end = [np.concatenate([x[between], y]) for x, y in ((p, pieces[0]), (q, pieces[1]))]
    sub_a = np.concatenate([edge_sub[between], edge_sub[lone[pa]]])
    sub_b = np.concatenate([other[between], edge_sub[lone[pb]]])
    apex_of = node_xyz[np.concatenate([edge_cell[between], edge_cell[lone[pa]]])]
    # seen from its sub-cell the spoke (apex, q, p) has the outward normal (q - apex) x (p - apex)
    area_normal = 0.5 * np.cross(end - apex_of, start - apex_of)
    centroid = (apex_of + start + end) / 3.0
    inner = sub_a != sub_b
    sub_volume = np.bincount(triangle_sub, weights=six_v, minlength=len(kept)) / 6.0
    parent = np.zeros(len(kept), dtype=np.int64)
    parent[triangle_sub] = facet_cell
    return parent, triangle_sub, sub_volume, (centroid[inner], area_normal[inner], sub_a[inner],
                                             sub_b[inner])


def merged_across_holes(parent: np.ndarray, triangle_sub: np.ndarray, volume: np.ndarray,
                        spokes: tuple, spoke_inside: np.ndarray) -> tuple:
    """Pyramid sub-cells (`pyramid_sub_cells`) merged across the spokes whose point
    lies outside the body.

    Faces of a smooth curved hole or cavity do not cut visibility, so the cell of a
    node near one need not be star-shaped from its node: a spoke (node, facet edge)
    can cross the hole, and its one integration point fall where no shape function
    is defined. The two pyramids on either side of such a spoke become one sub-cell
    (the spoke, between two parts of one sub-cell, cancels and is dropped); the rule
    stays exact for linear fields.

    Parameters
    ----------
    parent : (s,) int64 ndarray
    triangle_sub : (f,) int64 ndarray
    volume : (s,) ndarray
    spokes : (centroid (e, 3), area-normal (e, 3), sub_a (e,), sub_b (e,))
        As `pyramid_sub_cells` returns them.
    spoke_inside : (e,) bool ndarray
        Whether each spoke's centroid lies in the body.

    Returns
    -------
    parent, triangle_sub, volume, spokes
        The same, for the merged sub-cells.

    Raises
    ------
    GeometryError
        A spoke outside the body with a sub-cell on one side only (a T-junction).
    """
    centroid, area_normal, sub_a, sub_b = spokes
    out = ~spoke_inside
    if not out.any():
        return parent, triangle_sub, volume, spokes
    if (sub_b[out] < 0).any():
        bad = centroid[out & (sub_b < 0)][:3]
        raise GeometryError(f"expected the spokes of the pyramid sub-cells that leave the body "
                            f"to lie between two sub-cells, received one-sided spokes at "
                            f"{bad.tolist()}; refine the cloud near them")
    n = len(volume)
    graph = sp.coo_matrix((np.ones(int(out.sum())), (sub_a[out], sub_b[out])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    merged_volume = np.bincount(label, weights=volume)
    merged_parent = np.zeros(len(merged_volume), dtype=np.int64)
    merged_parent[label] = parent
    keep = label[sub_a] != np.where(sub_b >= 0, label[np.maximum(sub_b, 0)], -1)
    b = np.where(sub_b >= 0, label[np.maximum(sub_b, 0)], -1)
    return (merged_parent, label[triangle_sub], merged_volume,
            (centroid[keep], area_normal[keep], label[sub_a[keep]], b[keep]))


def _t_junction_pieces(p, q, cell, size):
    """The common refinement of the edges ``p -> q`` of each cell that run along each
    other the opposite way (collinear to ``1e-9 size``).

    Parameters
    ----------
    p, q : (e, 3) ndarray
        The edges' ends.
    cell : (e,) int64 ndarray
    size : (e,) ndarray
        The size of each edge's facet.

    Returns
    -------
    a, b : (k,) int64 ndarray
        The overlapping pairs (each once): a piece of edge ``a`` (its direction) and
        of edge ``b`` (the other way).
    pieces : (start (k, 3), end (k, 3))
        Each piece along ``a``'s direction.
    """
    order = np.argsort(cell, kind="stable")
    bounds = np.searchsorted(cell[order], distinct(cell), side="left")
    count = np.diff(np.append(bounds, len(order)))
    # all pairs of edges within a cell
    first = np.repeat(bounds, count * count)
    within = np.arange(int((count * count).sum())) - np.repeat(np.cumsum(count * count)
                                                              - count * count, count * count)
    per_cell = np.repeat(count, count * count)
    i, j = order[first + within // per_cell], order[first + within % per_cell]
    d = q[i] - p[i]
    dd = np.einsum("ij,ij->i", d, d)
    tol = 1e-9 * size[i]
    t_start = np.einsum("ij,ij->i", q[j] - p[i], d) / dd
    t_end = np.einsum("ij,ij->i", p[j] - p[i], d) / dd
    off = np.maximum(np.linalg.norm(np.cross(q[j] - p[i], d), axis=1),
                     np.linalg.norm(np.cross(p[j] - p[i], d), axis=1)) / np.sqrt(dd)
    lo, hi = np.maximum(t_start, 0.0), np.minimum(t_end, 1.0)
    keep = (i < j) & (off <= tol) & ((hi - lo) * np.sqrt(dd) > tol) & \
        (np.einsum("ij,ij->i", q[j] - p[j], d) < 0)
    i, j, lo, hi, d = i[keep], j[keep], lo[keep], hi[keep], d[keep]
    return i, j, (p[i] + lo[:, None] * d, p[i] + hi[:, None] * d)


def _has_reverse(owner, p, q):
    """Whether each directed edge ``p -> q`` of ``owner`` is met as ``q -> p`` in the same owner."""
    return _reverse_in(owner, p, q) >= 0


def _reverse_in(owner, p, q):
    """The index of the edge ``q -> p`` of the same owner for each edge ``p -> q``, -1 if none."""
    bits = [np.ascontiguousarray(x, dtype=np.float64).view(np.uint64) for x in (p, q)]
    return FK.reverse_edges(np.asarray(owner, dtype=np.int64), *bits)


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


def sub_cell_gradient_3d(model: Any, interface: InterfacePieces | None = None
                         ) -> tuple[Any, SmoothedGradient]:
    """The pyramid sub-cells of a 3-D model's cells and their ``B~``, from the cells'
    facet points and one point on each spoke (pyramids whose spoke's point lies
    outside the body merged, `merged_across_holes`).

    Parameters
    ----------
    model : Model3D
    interface : InterfacePieces, optional
        `model_interface_pieces` of ``model.cells``, when already known.

    Returns
    -------
    sub : Cells3D
        One cell per kept pyramid, with its parent's node and region.
    grad : SmoothedGradient
    """
    cells = model.cells
    parent, triangle_sub, volume, spokes = pyramid_sub_cells(
        model.nodes[cells.node], cells.facet_triangles, cells.facet_cell, cells.facet_normal)
    parent, triangle_sub, volume, spokes = merged_across_holes(
        parent, triangle_sub, volume, spokes, inside_tetrahedra(model.tet_mesh(), spokes[0]))
    sub = type(cells)(cells.node[parent], cells.region[parent], volume, cells.facet_triangles,
                      triangle_sub, cells.facet_normal, apex=model.nodes[cells.node[parent]])
    # the sub-cells' triangles are the cells': the interface pieces go to their sub-cells
    if interface is None:
        interface = model_interface_pieces(model, cells)
    grad = facet_gradient(sub.facet_triangles, sub.facet_cell, sub.facet_normal, volume,
                          model.shape_functions, spokes=spokes, interface=interface)
    return sub, grad


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
