"""Values of a cell field at any point: patch recovery at the nodes, then the shape functions.

SCNI gives one value per integration cell (a smoothed strain, its stress, a heat flux):
the field's mean over the cell, which under-reads peaks at boundaries, where a cell holds
the values on one side of its node only. `recover_at_nodes` fits, for every node and
region, a linear polynomial through the cell values of the node's patch — the cells of
that region whose nodes are the node itself and its neighbours up to `PATCH_RINGS` edges
of the triangulation away (a crack separates faces: its two sides share no edge) — taken
at the cells' centroids (where a cell's mean of a linear field is exact), and evaluates it
at the node (superconvergent patch recovery, Zienkiewicz and Zhu 1992, on the SCNI cells).
`values_at` interpolates these nodal values at points with the shape functions, taking at
each neighbour node its value in the region of the point, so that jumps across material
interfaces stay sharp. Both are exact for a linear field (a constant stress too: the
patch test), and at a boundary the linear fit extrapolates from the inside instead of
averaging.

>>> import numpy as np, cnem
>>> model = cnem.discretize(cnem.nodes.irregular(cnem.geometry.rectangle(), 0.2, seed=1))
>>> linear = model.cells.centroid() @ [2.0, -1.0] + 3.0          # a linear cell field
>>> at_nodes = recover_at_nodes(model, model.cells, linear[:, None])
>>> point = np.array([[0.5, 0.0]])                                 # on the boundary
>>> bool(np.allclose(values_at(model, at_nodes, point), point @ [2.0, -1.0] + 3.0))
True
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import scipy.sparse as sp
import shapely

from ..errors import GeometryError, InputError, check_points

if TYPE_CHECKING:
    from ..geometry.model import Model

__all__ = ["NodalValues", "recover_at_nodes", "values_at", "PATCH_RINGS"]

#: Rings of triangulation neighbours around a node whose cells enter its patch.
PATCH_RINGS = 1


@dataclass(frozen=True)
class NodalValues:
    """A cell field recovered at the nodes, one row per (node, region) pair present
    in the cells.

    Attributes
    ----------
    node : (k,) int64 ndarray
    region : (k,) int64 ndarray
    values : (k, s) ndarray
    """

    node: np.ndarray
    region: np.ndarray
    values: np.ndarray


def _simplices(model):
    """The triangles (tetrahedra in 3-D) of a model."""
    return model.triangles if model.nodes.shape[1] == 2 else model.tetrahedra


def _node_rings(model, rings):
    """``(n, n)`` CSR pattern: node ``j`` within ``rings`` edges of node ``i`` (itself too)."""
    n = len(model.nodes)
    simplex = np.asarray(_simplices(model), dtype=np.int64)
    k = simplex.shape[1]
    a = np.concatenate([simplex[:, i] for i in range(k) for j in range(k) if i != j])
    b = np.concatenate([simplex[:, j] for i in range(k) for j in range(k) if i != j])
    step = sp.csr_matrix((np.ones(len(a) + n), (np.concatenate([a, np.arange(n)]),
                                                 np.concatenate([b, np.arange(n)]))),
                         shape=(n, n))
    step.data[:] = 1.0
    out = step
    for _ in range(rings - 1):
        out = out @ step
        out.data[:] = 1.0
    return out.tocsr()


def recover_at_nodes(model: Model, cells: Any, values: np.ndarray, *,
                     rings: int = PATCH_RINGS) -> NodalValues:
    """A cell field at the nodes by linear patch fits (see the module docstring).

    Parameters
    ----------
    model : Model
        ``n`` nodes, its triangles (tetrahedra) define the patches.
    cells : Cells
        ``m`` integration cells (``model.cells``, or sub-cells) with ``node``,
        ``region`` and ``centroid()``.
    values : (m, s) array_like
        One row per cell.
    rings : int
        Neighbour rings of a patch.

    Returns
    -------
    NodalValues
        A patch whose centroids do not span the space (a thin row of cells) gives
        the mean of its cells.
    """
    values = np.asarray(values, dtype=float)
    m = len(cells.node)
    if values.ndim != 2 or len(values) != m:
        raise InputError(f"values: expected one row per cell ({m}, s), received shape "
                         f"{values.shape}; pass a cell field")
    n, d = model.nodes.shape
    regions = int(cells.region.max()) + 1 if m else 1
    key = cells.node.astype(np.int64) * regions + cells.region
    keys, key_of_cell = np.unique(key, return_inverse=True)
    node, region = keys // regions, keys % regions
    to_node = sp.csr_matrix((np.ones(len(keys)), (np.arange(len(keys)), node)),
                            shape=(len(keys), n))
    node_cells = sp.csr_matrix((np.ones(m), (cells.node, np.arange(m))), shape=(n, m))
    patch = (to_node @ _node_rings(model, rings) @ node_cells).tocoo()
    same = cells.region[patch.col] == region[patch.row]
    row, col = patch.row[same], patch.col[same]
    size = np.cbrt(cells.measure) if d == 3 else np.sqrt(cells.measure)
    scale = np.bincount(key_of_cell, weights=size, minlength=len(keys)) / \
        np.bincount(key_of_cell, minlength=len(keys))
    offset = (cells.centroid()[col] - model.nodes[node[row]]) / scale[row][:, None]
    basis = np.column_stack([np.ones(len(row)), offset])                  # (q, d + 1)
    normal = np.zeros((len(keys), d + 1, d + 1))
    right = np.zeros((len(keys), d + 1, values.shape[1]))
    np.add.at(normal, row, basis[:, :, None] * basis[:, None, :])
    np.add.at(right, row, basis[:, :, None] * values[col][:, None, :])
    count = normal[:, 0, 0]
    mean = right[:, 0, :] / count[:, None]
    eig = np.linalg.eigvalsh(normal)
    fit = eig[:, 0] > 1e-6 * eig[:, -1]
    out = mean.copy()
    if fit.any():
        out[fit] = np.linalg.solve(normal[fit], right[fit])[:, 0, :]
    return NodalValues(node, region, out)


def _regions_of(domain, points):
    """``domain.region_of(points)``, with the points that round-off puts just outside a
    2-D boundary (within ``domain.tolerance``: a point on a chord computed from its
    ends) in the region nearest to them; -1 for the points outside."""
    region = np.asarray(domain.region_of(points), dtype=np.int64)
    off = np.flatnonzero(region < 0)
    if off.size and points.shape[1] == 2:
        xy = shapely.points(points[off])
        gap = np.stack([shapely.distance(poly, xy) for poly in domain.regions])
        near = gap.min(axis=0) <= domain.tolerance
        region[off[near]] = gap.argmin(axis=0)[near]
    return region


def values_at(model: Model, nodal: NodalValues, points: np.ndarray) -> np.ndarray:
    """Recovered nodal values interpolated at points by the shape functions.

    Parameters
    ----------
    model : Model
    nodal : NodalValues
        From `recover_at_nodes`.
    points : (p, d) array_like
        In the closure of the domain (within ``domain.tolerance`` of it in 2-D);
        a point on a material interface takes the lowest region index
        (`Domain.region_of`).

    Returns
    -------
    (p, s) ndarray

    Raises
    ------
    GeometryError
        Points outside the domain (counted, the first few named).
    """
    d = model.nodes.shape[1]
    pts = check_points("points", points, dims=(d,), error=GeometryError)
    region = _regions_of(model.domain, pts)
    outside = np.flatnonzero(region < 0)
    if outside.size:
        raise GeometryError(f"points: expected points inside the domain (bounds "
                            f"{np.asarray(model.domain.bounds).tolist()}), received "
                            f"{outside.size} of {len(pts)} outside, the first "
                            f"{pts[outside[:3]].tolist()}; keep the points in the body "
                            f"(check them with model.domain.contains)")
    phi = sp.coo_matrix(model.shape_functions(pts))
    regions = int(max(nodal.region.max(), region.max())) + 1
    slot = np.full(len(model.nodes) * regions, -1, dtype=np.int64)
    slot[nodal.node * regions + nodal.region] = np.arange(len(nodal.node))
    take = slot[phi.col * regions + region[phi.row]]
    missing = take < 0             # a neighbour node without a cell in the point's region
    if missing.any():
        first = np.full(len(model.nodes), -1, dtype=np.int64)
        first[nodal.node[::-1]] = np.arange(len(nodal.node))[::-1]
        take[missing] = first[phi.col[missing]]
    out = np.zeros((len(pts), nodal.values.shape[1]))
    np.add.at(out, phi.row, phi.data[:, None] * nodal.values[take])
    return out
