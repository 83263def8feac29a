"""Constrained natural-neighbour (Laplace and Sibson) coordinates on a tetrahedrisation.

>>> import numpy as np, scipy.spatial
>>> from cnem.shape.natural3d import tet_mesh, shape_functions_3d
>>> nodes = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [0.2, 0.2, 0.2]])
>>> mesh = tet_mesh(nodes, scipy.spatial.Delaunay(nodes).simplices)
>>> phi = shape_functions_3d(mesh, [[0.1, 0.3, 0.2]], kind="laplace")
>>> bool(np.allclose(phi @ nodes, [[0.1, 0.3, 0.2]]))
True
"""

from __future__ import annotations

import logging
from typing import Literal, NamedTuple

import numpy as np
import scipy.sparse as sp
import scipy.spatial
from numpy.typing import ArrayLike

from .. import config
from .._parallel import work_chunks
from .._predicates import Frame, local_frame
from ..errors import GeometryError, check_array, check_choice
from . import _cavity3d as C
from . import _kernels3d as K
from .natural import KINDS, ShapeGradients

__all__ = ["TetMesh", "tet_mesh", "shape_functions_3d", "inside_tetrahedra"]

_log = logging.getLogger(__name__)


class TetMesh(NamedTuple):
    """A tetrahedrisation prepared for natural-neighbour coordinates (`tet_mesh`).

    Attributes
    ----------
    nodes : (n, 3) float64
        The nodes as given.
    tetrahedra : (t, 4) int64
        Positively oriented (``det[b - a, c - a, d - a] > 0``).
    tet_region : (t,) int64
    neighbors : (t, 4) int64
        The tetrahedron across the face opposite each vertex, -1 across the
        boundary, a region interface or a constraint face.
    walk_neighbors : (t, 4) int64
        The same, -1 across the boundary only (for point location).
    constraint_edges : (e,) int64
        Sorted keys ``min * n + max`` of the edges of every constraint face.
    feature_edges : (f,) int64
        The same for the edges where constraint faces of different planes meet.
    node_tet : (n,) int64
        A tetrahedron of each node (-1 for a node of none), where walks start.
    node_tree : scipy.spatial.cKDTree
        Of the local nodes: the nearest node of a point.
    frame : Frame
        The local frame the kernels run in.
    local_nodes : (n, 3) float64
    tol : float
        Local distance under which a point is at a node or on a constraint face.
    """

    nodes: np.ndarray
    tetrahedra: np.ndarray
    tet_region: np.ndarray
    neighbors: np.ndarray
    walk_neighbors: np.ndarray
    constraint_edges: np.ndarray
    feature_edges: np.ndarray
    node_tet: np.ndarray
    node_tree: scipy.spatial.cKDTree
    frame: Frame
    local_nodes: np.ndarray
    tol: float


def tet_mesh(nodes: ArrayLike, tetrahedra: ArrayLike, *, tet_region: ArrayLike | None = None,
             constraint_faces: ArrayLike | None = None) -> TetMesh:
    """Prepare a constrained Delaunay tetrahedrisation for `shape_functions_3d`.

    Parameters
    ----------
    nodes : (n, 3) array_like
    tetrahedra : (t, 4) array_like of int
        Either orientation; reoriented positively.
    tet_region : (t,) array_like of int, optional
        Faces between tetrahedra of different regions are constraints.
    constraint_faces : (b, 3) array_like of int, optional
        Further faces (boundary, interfaces, slots) that no cavity crosses; the
        faces with a tetrahedron on one side only always are.

    Returns
    -------
    TetMesh

    Raises
    ------
    GeometryError
        Bad shapes, indices out of range, flat tetrahedra, a face shared by more
        than two tetrahedra, a constraint face that is no face of the tetrahedra.
    """
    pts = check_array("nodes", nodes, shape=(None, 3), error=GeometryError,
                      fix="give the nodes' coordinates as a (n, 3) array")
    tet = _indices("tetrahedra", tetrahedra, (None, 4), len(pts), "nodes")
    if len(tet) == 0:
        raise GeometryError("tetrahedra: expected a non-empty (t, 4) array of node indices, "
                            "received none")
    region = (np.zeros(len(tet), dtype=np.int64) if tet_region is None
              else _indices("tet_region", tet_region, (len(tet),), None, None))
    if constraint_faces is not None:
        constraint_faces = _indices("constraint_faces", constraint_faces, (None, 3), len(pts),
                                    "nodes")
    frame = local_frame(np.stack([pts.min(axis=0), pts.max(axis=0)]))
    local = frame.to_local(pts)
    v = local[tet]
    vol = np.einsum("ij,ij->i", v[:, 1] - v[:, 0], np.cross(v[:, 2] - v[:, 0], v[:, 3] - v[:, 0]))
    edge = np.linalg.norm(v[:, 1:] - v[:, :1], axis=2).max(axis=1)
    flat = np.flatnonzero(np.abs(vol) <= 1e-12 * edge ** 3)
    if flat.size:
        raise GeometryError(f"tetrahedra: {flat.size} are flat (zero volume), first "
                            f"{tet[flat[:3]].tolist()}; remove them (a Delaunay tetrahedrisation "
                            "of cospherical points may hold such slivers)")
    neg = vol < 0
    tet[neg, 0], tet[neg, 1] = tet[neg, 1], tet[neg, 0].copy()
    walk, cut, boundary_rows = _adjacency(tet, region, constraint_faces, len(pts))
    cedges, features = _constraint_edges(local, boundary_rows)
    diameter = float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0)))
    tol = max(config.SHAPE_TOL * diameter / frame.scale, config.ROUNDOFF_ULPS * frame.resolution)
    node_tet = np.full(len(pts), -1, dtype=np.int64)
    node_tet[tet.ravel()] = np.repeat(np.arange(len(tet)), 4)
    return TetMesh(pts, tet, region, cut, walk, cedges, features, node_tet,
                   scipy.spatial.cKDTree(local), frame, local, tol)


def _indices(name, value, shape, count, of):
    """``value`` as whole numbers of ``shape`` (int64), in ``0..count-1`` when ``count`` is
    given; complex, boolean, fractional or out-of-range entries raise a `GeometryError`."""
    arr = check_array(name, value, shape=shape, error=GeometryError,
                      fix="give whole numbers (indices)")
    if np.any(arr != np.round(arr)):
        raise GeometryError(f"{name}: expected whole numbers (indices), received fractions, "
                            f"first {arr[arr != np.round(arr)][:3].tolist()}")
    if count is not None and arr.size and (arr.min() < 0 or arr.max() >= count):
        raise GeometryError(f"{name}: expected indices into the {count} {of} (0 to "
                            f"{count - 1}), received values from {int(arr.min())} to "
                            f"{int(arr.max())}")
    return arr.astype(np.int64)


def _constraint_edges(local, faces):
    """Sorted keys ``min * n + max`` of the edges of the constraint ``faces (b, 3)``, and
    of the feature edges among them: those whose faces do not all lie in one plane."""
    n = len(local)
    nrm = np.cross(local[faces[:, 1]] - local[faces[:, 0]], local[faces[:, 2]] - local[faces[:, 0]])
    nrm /= np.linalg.norm(nrm, axis=1)[:, None]
    ends = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    keys = ends[:, 0] * n + ends[:, 1]
    normals = np.tile(nrm, (3, 1))
    order = np.argsort(keys, kind="stable")
    keys, normals = keys[order], normals[order]
    first = np.ones(len(keys), dtype=bool)
    first[1:] = keys[1:] != keys[:-1]
    group = np.cumsum(first) - 1
    ref = normals[first][group]                 # the first face's normal in each group
    bent = np.linalg.norm(np.cross(normals, ref), axis=1) > 1e-9
    feature = np.zeros(group[-1] + 1, dtype=bool)
    np.logical_or.at(feature, group, bent)
    unique = keys[first]
    return unique, unique[feature]


def _adjacency(tet, region, constraint_faces, n):
    """Neighbours across faces: ``(walk, cut, constraint_rows)`` with ``cut`` also -1
    across region changes and constraint faces, whose node triples are returned."""
    faces = np.sort(tet[:, C.FACES].reshape(-1, 3), axis=1)       # row 4 t + k: opposite k
    given = (np.zeros((0, 3), dtype=np.int64) if constraint_faces is None
             else np.sort(np.asarray(constraint_faces, dtype=np.int64).reshape(-1, 3), axis=1))
    rows = np.concatenate([faces, given])
    order = np.lexsort(rows.T[::-1])
    srt = rows[order]
    new = np.ones(len(rows), dtype=bool)
    new[1:] = (srt[1:] != srt[:-1]).any(axis=1)
    group = np.cumsum(new) - 1
    is_given = order >= len(faces)
    tets_in = np.bincount(group[~is_given], minlength=group[-1] + 1)
    if (tets_in > 2).any():
        bad = srt[np.flatnonzero(tets_in[group] > 2)[0]]
        raise GeometryError(f"tetrahedra: face {bad.tolist()} is shared by more than two "
                            "tetrahedra; expected a conforming tetrahedrisation")
    if (tets_in[group[is_given]] == 0).any():
        bad = srt[np.flatnonzero(is_given & (tets_in[group] == 0))[0]]
        raise GeometryError(f"constraint_faces: {bad.tolist()} is no face of the tetrahedra; "
                            "expected faces of the tetrahedrisation")
    constrained = np.bincount(group[is_given], minlength=group[-1] + 1) > 0
    walk = np.full(len(faces), -1, dtype=np.int64)
    face_rows = order[~is_given]                  # tet faces, sorted, groups of one or two
    fgroup = group[~is_given]
    pair = np.flatnonzero(fgroup[1:] == fgroup[:-1])
    a, b = face_rows[pair], face_rows[pair + 1]
    walk[a], walk[b] = b // 4, a // 4
    cut = walk.copy()
    owner = np.arange(len(faces)) // 4
    across = walk >= 0
    cut[across & (region[owner] != region[np.maximum(walk, 0)])] = -1
    cut[face_rows[constrained[fgroup]]] = -1
    bounded = cut < 0
    return walk.reshape(-1, 4), cut.reshape(-1, 4), faces[bounded]


def _path_order(points, lo, hi, per_cell=4):
    """Order of points cell by cell in a grid of about ``per_cell`` points a cell."""
    k = max(1, int(np.ceil((len(points) / per_cell) ** (1 / 3))))
    cell = np.clip(((points - lo) * (k / np.maximum(hi - lo, 1e-300))).astype(np.int64), 0, k - 1)
    iy = np.where(cell[:, 2] & 1, k - 1 - cell[:, 1], cell[:, 1])
    ix = np.where((cell[:, 2] * k + iy) & 1, k - 1 - cell[:, 0], cell[:, 0])
    return np.argsort((cell[:, 2] * k + iy) * k + ix, kind="stable")


def _locate(mesh, spts):
    """A tetrahedron holding each local point (-1 outside): a walk from a tetrahedron of
    its nearest node, then the nearest tetrahedra by centroid for the points lost
    (walks stop at the boundary)."""
    nodes, tet = mesh.local_nodes, mesh.tetrahedra
    nearest = mesh.node_tree.query(spts)[1]
    tet_of = C.locate_walk(nodes, tet, mesh.walk_neighbors, spts, mesh.node_tet[nearest])
    lost = np.flatnonzero(tet_of < 0)
    if lost.size:
        centroids = nodes[tet].mean(axis=1)
        tree = scipy.spatial.cKDTree(centroids)
        reach = float(np.linalg.norm(nodes[tet] - centroids[:, None], axis=2).max()) + mesh.tol
        cands = tree.query_ball_point(spts[lost], reach)
        off = np.zeros(lost.size + 1, dtype=np.int64)
        off[1:] = np.cumsum([len(c) for c in cands])
        idx = np.concatenate([np.asarray(c, dtype=np.int64) for c in cands])
        tet_of[lost] = C.locate(nodes, tet, spts[lost], off, idx, mesh.tol)
    return tet_of


def inside_tetrahedra(mesh: TetMesh, points: np.ndarray) -> np.ndarray:
    """Whether each point lies in a tetrahedron of the mesh (on its faces included,
    to the mesh's tolerance): where `shape_functions_3d` is defined.

    Parameters
    ----------
    mesh : TetMesh
    points : (p, 3) ndarray

    Returns
    -------
    (p,) bool ndarray
    """
    pts = check_array("points", points, shape=(None, 3), error=GeometryError,
                      fix="give the points as a (p, 3) array")
    inside = np.zeros(len(pts), dtype=bool)
    if len(pts) == 0:
        return inside
    local = mesh.frame.to_local(pts)
    order = _path_order(local, local.min(axis=0), local.max(axis=0))
    inside[order] = _locate(mesh, np.ascontiguousarray(local[order])) >= 0
    return inside


def shape_functions_3d(mesh: TetMesh, points: ArrayLike, *,
                       kind: Literal["laplace", "sibson"] = "laplace",
                       gradient: bool = False) -> sp.csr_matrix | ShapeGradients:
    """Constrained Laplace or Sibson coordinates of points in a tetrahedrised body.

    Parameters
    ----------
    mesh : TetMesh
        From `tet_mesh`.
    points : (p, 3) array_like
        Points of the closed body.
    kind : {"laplace", "sibson"}
    gradient : bool
        Also return the analytic derivatives, for points inside the cells
        (not at nodes nor on constraint faces or edges, where they are not defined).

    Returns
    -------
    Phi : scipy.sparse.csr_matrix, shape (p, n)
        With ``gradient=True`` a `ShapeGradients` ``(Phi, dPhi_dx, dPhi_dy,
        dPhi_dz)`` of four CSR matrices of one pattern. Rows sum to 1,
        ``Phi @ nodes`` gives back the points, a point at a node gets its unit
        row, a point on a constraint face interpolates linearly between the
        face's three nodes (on a constraint edge between its two ends), and no
        node has weight at a point it cannot see.

    Raises
    ------
    GeometryError
        Points outside the body, or gradients asked at nodes / on constraint faces.
    """
    check_choice("kind", kind, KINDS)
    pts = check_array("points", points, shape=(None, 3), error=GeometryError,
                      fix="give the points as a (p, 3) array")
    n = len(mesh.nodes)
    if len(pts) == 0:
        empty = sp.csr_matrix((0, n))
        return ShapeGradients(empty, empty.copy(), empty.copy(), empty.copy()) if gradient \
            else empty
    local = mesh.frame.to_local(pts)
    order = _path_order(local, local.min(axis=0), local.max(axis=0))
    spts = np.ascontiguousarray(local[order])
    tet_of = _locate(mesh, spts)
    outside = np.sort(order[tet_of < 0])
    if outside.size:
        raise GeometryError(
            f"{outside.size} of {len(pts)} points lie outside the body, first (index: point) "
            + ", ".join(f"{i}: {pts[i].tolist()}" for i in outside[:5]))
    slots = 2 * config.ROW_SLOTS
    while True:
        start, size, cols, vals, grads, kinds, full = K.natural(
            mesh.local_nodes, mesh.tetrahedra, mesh.neighbors, mesh.constraint_edges,
            mesh.feature_edges, spts,
            tet_of, mesh.tol, work_chunks(), kind == "laplace", gradient, slots)
        if not full:
            break
        slots *= 2
    fallback = np.sort(order[kinds == C.FALLBACK])
    if fallback.size:
        _log.warning("%d of %d points lie where the constrained %s coordinates are not "
                     "non-negative shares (beside a re-entrant edge, near the plane of a "
                     "boundary face) or where their cavity broke on a circumsphere's round-off; "
                     "they interpolate linearly in their tetrahedron, first %s",
                     fallback.size, len(pts), kind, pts[fallback[:3]].tolist())
    offsets, cols, vals, grads = K.permute_rows(start, size, cols, vals, grads, order)
    phi = sp.csr_matrix((vals, cols, offsets), shape=(len(pts), n))
    if not gradient:
        return phi
    singular = np.sort(order[(kinds != C.CAVITY) & (kinds != C.FALLBACK)])
    if singular.size:
        raise GeometryError(
            f"{singular.size} points lie at a node or on a constraint face or edge, where the "
            f"gradients are not defined, first {pts[singular[:3]].tolist()}; evaluate "
            "gradients inside the cells")
    grads /= mesh.frame.scale
    return ShapeGradients(phi, *(sp.csr_matrix((grads[:, d].copy(), cols.copy(), offsets.copy()),
                                               shape=phi.shape) for d in range(3)))
