"""The stabilisation's sub-cells of 3-D cells: the pyramids from each cell's node to
its facets, and their smoothed gradients.

The pyramids from each cell's node to its facet triangles are tetrahedra (a
constrained Voronoi cell is star-shaped from its node, since every point of it sees
the node). A sub-cell's boundary is its facet triangle plus three *spokes* (node,
facet edge), shared with the neighbouring sub-cells of the same cell, where they
cancel; the spokes are integrated by their centroid alone, exact for the linear
fields the shape functions reproduce. Each interface piece
(`.interface_facets`) goes to the sub-cell of its facet.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from ..errors import GeometryError
from ..shape.natural3d import inside_tetrahedra
from . import _facet_kernels as FK
from .facet_gradients import (_facet_groups, facet_rule, gradients_of_rules,
                              model_interface_pieces)
from .interface_facets import InterfacePieces
from .smoothed_gradient import SmoothedGradient
from .._sets import distinct

__all__ = ["pyramid_sub_cells", "merged_across_holes", "sub_cell_gradient_3d"]

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


def sub_cell_gradient_3d(model: Any, interface: InterfacePieces | None = None, *,
                         with_cells: bool = False
                         ) -> tuple[Any, SmoothedGradient, SmoothedGradient | None]:
    """The pyramid sub-cells of a 3-D model's cells and their ``B~``, from the cells'
    facet points and one point on each spoke (pyramids whose spoke's point lies
    outside the body merged, `merged_across_holes`); with ``with_cells`` also ``B~``
    of the cells, from the same shape-function values (their facet points are the
    sub-cells').

    Parameters
    ----------
    model : Model3D
    interface : InterfacePieces, optional
        `model_interface_pieces` of ``model.cells``, when already known.
    with_cells : bool
        Also ``B~`` of ``model.cells`` (`cell_gradient_3d`).

    Returns
    -------
    sub : Cells3D
        One cell per kept pyramid, with its parent's node and region.
    grad : SmoothedGradient
    cells_grad : SmoothedGradient or None
        ``B~`` of the cells, None unless ``with_cells``.
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
    rules = [facet_rule(sub.facet_triangles, sub.facet_cell, sub.facet_normal, volume,
                        spokes=spokes, interface=interface)]
    if with_cells:
        rules.append(facet_rule(cells.facet_triangles, cells.facet_cell, cells.facet_normal,
                                cells.volume, interface=interface))
    grads = gradients_of_rules(rules, model.shape_functions)
    return sub, grads[0], (grads[1] if with_cells else None)
