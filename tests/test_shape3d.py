"""3-D constrained Laplace and Sibson coordinates (`cnem.shape.natural3d`).

Checked against the slow Voronoi references of `reference.py` (half-space
intersections of the cells with and without the point) and against the
properties the method promises: partition of unity, linear reproduction,
Kronecker delta, continuity (up to the boundary, where the values are the limit
from inside), linearity on feature edges, no weight from a node hidden behind
the boundary, analytic gradients equal to central differences, invariance
under translation and scaling.
"""

from __future__ import annotations

import functools
import itertools

import numpy as np
import pytest
import scipy.spatial

import reference
from cnem.errors import GeometryError
from cnem.shape.natural3d import shape_functions_3d, tet_mesh

KINDS = ("laplace", "sibson")


@functools.lru_cache(maxsize=None)
def jittered_box(m=8, seed=0):
    """Delaunay tetrahedrisation of a jittered ``(m x m x m)`` lattice of the unit cube:
    nodes on the faces move in their face only (no flat tetrahedra)."""
    rng = np.random.default_rng(seed)
    g = np.linspace(0.0, 1.0, m)
    nodes = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
    free = (nodes > 0) & (nodes < 1)
    nodes = nodes + free * rng.uniform(-0.3 / (m - 1), 0.3 / (m - 1), nodes.shape)
    return nodes, scipy.spatial.Delaunay(nodes).simplices


@functools.lru_cache(maxsize=None)
def lattice_box(m=4):
    """The exact lattice of spacing ``1 / m`` in the unit cube, each cube cut into the six
    tetrahedra round its main diagonal (a Delaunay tetrahedrisation: all of a cube's
    corners are cospherical)."""
    g = np.arange(m + 1.0)
    nodes = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3) / m

    def idx(v):
        return (v[0] * (m + 1) + v[1]) * (m + 1) + v[2]

    tets = []
    for corner in itertools.product(range(m), repeat=3):
        for perm in itertools.permutations(range(3)):
            v = np.array(corner)
            path = [idx(v)]
            for axis in perm:
                v = v.copy()
                v[axis] += 1
                path.append(idx(v))
            tets.append(path)
    return nodes, np.array(tets)


def carved(m, removed):
    """The lattice box without the tetrahedra whose centroid lies in one of the
    ``removed`` boxes ``(lo, hi)``; the faces between kept and dropped tetrahedra
    are the constraint faces (the boundary)."""
    nodes, tets = lattice_box(m)
    cen = nodes[tets].mean(axis=1)
    drop = np.zeros(len(tets), dtype=bool)
    for lo, hi in removed:
        drop |= ((cen > lo) & (cen < hi)).all(axis=1)
    kept = tets[~drop]
    used = np.unique(kept)
    renum = np.full(len(nodes), -1)
    renum[used] = np.arange(len(used))
    return nodes[used], renum[kept]


L_REMOVED = [(np.array([0.5, -1, 0.5]), np.array([2, 2, 2]))]
SLOT_REMOVED = [(np.array([0.5, -1, 0.375]), np.array([0.625, 2, 2]))]


def hidden(x, node, removed, eps=1e-9):
    """Whether the segment x-node passes through the inside of a removed box
    (deeper than ``eps``): slab clipping."""
    for lo, hi in removed:
        lo, hi = lo + eps, hi - eps
        d = node - x
        t0, t1 = 0.0, 1.0
        ok = True
        for k in range(3):
            if abs(d[k]) < 1e-300:
                if not lo[k] < x[k] < hi[k]:
                    ok = False
                continue
            a, b = (lo[k] - x[k]) / d[k], (hi[k] - x[k]) / d[k]
            t0, t1 = max(t0, min(a, b)), min(t1, max(a, b))
        if ok and t0 < t1:
            return True
    return False


def inside_carved(points, removed):
    keep = np.ones(len(points), dtype=bool)
    for lo, hi in removed:
        keep &= ~((points > lo) & (points < hi)).all(axis=1)
    return keep


def check_rows(phi, nodes, points, tol=1e-12):
    """Partition of unity and linear reproduction."""
    assert np.abs(np.asarray(phi.sum(axis=1)).ravel() - 1).max() < tol
    assert np.abs(phi @ nodes - points).max() < tol


@pytest.mark.parametrize("kind", KINDS)
def test_equals_voronoi_reference(kind):
    nodes, tets = jittered_box(8)
    mesh = tet_mesh(nodes, tets)
    rng = np.random.default_rng(3)
    points = rng.uniform(0.35, 0.65, (12, 3))
    phi = shape_functions_3d(mesh, points, kind=kind).toarray()
    ref = reference.laplace_reference_3d if kind == "laplace" else reference.sibson_reference_3d
    for k, x in enumerate(points):
        assert np.abs(phi[k] - ref(nodes, x)).max() < 1e-10


def _on_boundary_points(nodes, rng, count):
    """Points on the faces, on the edges and at the corners of the unit cube."""
    face = rng.uniform(0, 1, (count, 3))
    axis = rng.integers(0, 3, count)
    face[np.arange(count), axis] = rng.integers(0, 2, count)
    edge = rng.uniform(0, 1, (count, 3))
    fix = rng.integers(0, 2, (count, 3)).astype(float)
    free = rng.integers(0, 3, count)
    fix[np.arange(count), free] = edge[np.arange(count), free]
    return np.vstack([face, fix])


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("cloud", ["jittered", "lattice"])
def test_properties(kind, cloud):
    nodes, tets = jittered_box(7) if cloud == "jittered" else lattice_box(4)
    mesh = tet_mesh(nodes, tets)
    rng = np.random.default_rng(5)
    h = 0.25
    points = np.vstack([
        rng.uniform(0, 1, (2000, 3)),
        _on_boundary_points(nodes, rng, 300),
        (rng.integers(0, 4, (300, 3)) + 0.5) * h,                  # cube centres
        (rng.integers(0, 5, (300, 3)) + [0.5, 0.5, 0.0]) * h,      # face centres
        (rng.integers(0, 5, (300, 3)) + [0.5, 0.0, 0.0]) * h,      # edge midpoints
    ]).clip(0, 1)
    phi = shape_functions_3d(mesh, points, kind=kind)
    check_rows(phi, nodes, points)
    at = shape_functions_3d(mesh, nodes, kind=kind).toarray()
    assert np.array_equal(at, np.eye(len(nodes)))
    # continuous: a step of 1e-9 changes nothing by more than a few 1e-9
    step = rng.normal(size=points.shape)
    step *= 1e-9 / np.linalg.norm(step, axis=1)[:, None]
    moved = (points + step).clip(0, 1)
    phi2 = shape_functions_3d(mesh, moved, kind=kind)
    check_rows(phi2, nodes, moved, tol=1e-11)
    assert abs(phi2 - phi).max() < 1e-7


@pytest.mark.parametrize("kind", KINDS)
def test_boundary_values_are_the_limit_from_inside(kind):
    nodes, tets = jittered_box(7, seed=1)
    mesh = tet_mesh(nodes, tets)
    rng = np.random.default_rng(1)
    on = np.column_stack([rng.uniform(0.1, 0.9, (200, 2)), np.zeros(200)])
    phi = shape_functions_3d(mesh, on, kind=kind)
    for delta in (1e-6, 1e-9):
        near = shape_functions_3d(mesh, on + [0, 0, delta], kind=kind)
        assert abs(near - phi).max() < 30 * delta
    # on the face only the nodes of its plane carry weight
    assert np.abs(phi.toarray()[:, nodes[:, 2] > 0]).max() == 0.0
    # on a feature edge: linear between its ends
    line = np.column_stack([rng.uniform(0, 1, 50), np.zeros(50), np.zeros(50)])
    edge = shape_functions_3d(mesh, line, kind=kind)
    assert max(np.count_nonzero(row) for row in edge.toarray()) <= 2
    check_rows(edge, nodes, line)


@pytest.mark.parametrize("kind", KINDS)
def test_gradients_equal_central_differences(kind):
    nodes, tets = jittered_box(7, seed=2)
    mesh = tet_mesh(nodes, tets)
    points = np.random.default_rng(7).uniform(0.05, 0.95, (200, 3))
    out = shape_functions_3d(mesh, points, kind=kind, gradient=True)
    assert out.dim == 3
    h = 1e-6
    for d, g in enumerate(out.gradient):
        e = np.zeros(3)
        e[d] = h
        fd = (shape_functions_3d(mesh, points + e, kind=kind)
              - shape_functions_3d(mesh, points - e, kind=kind)).toarray() / (2 * h)
        err = np.abs(g.toarray() - fd).max(axis=1)
        assert np.median(err) < 1e-8 and err.max() < 1e-5
        assert np.abs(np.asarray(g.sum(axis=1)).ravel()).max() < 1e-12
        assert np.abs(g @ nodes - e / h).max() < 1e-12


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("removed", [L_REMOVED, SLOT_REMOVED], ids=["L-block", "slot"])
def test_no_weight_from_hidden_nodes(kind, removed):
    nodes, tets = carved(8, removed)
    mesh = tet_mesh(nodes, tets)
    rng = np.random.default_rng(11)
    points = rng.uniform(0, 1, (3000, 3))
    points = points[inside_carved(points, removed)][:1500]
    phi = shape_functions_3d(mesh, points, kind=kind)
    check_rows(phi, nodes, points, tol=1e-11)
    rows = phi.tocoo()
    seen = rows.data != 0
    bad = [k for k, (p, j) in enumerate(zip(rows.row[seen], rows.col[seen]))
           if hidden(points[p], nodes[j], removed)]
    assert not bad


@pytest.mark.parametrize("kind", KINDS)
def test_values_jump_across_the_slot(kind):
    nodes, tets = carved(8, SLOT_REMOVED)
    mesh = tet_mesh(nodes, tets)
    rng = np.random.default_rng(2)
    yz = np.column_stack([rng.uniform(0, 1, 100), rng.uniform(0.6, 0.95, 100)])
    left = np.column_stack([np.full(100, 0.5 - 1e-3), yz])
    right = np.column_stack([np.full(100, 0.625 + 1e-3), yz])
    a = shape_functions_3d(mesh, left, kind=kind).toarray()
    b = shape_functions_3d(mesh, right, kind=kind).toarray()
    far_left = nodes[:, 0] >= 0.625
    far_right = nodes[:, 0] <= 0.5
    assert np.abs(a[:, far_left]).max() == 0.0 and np.abs(b[:, far_right]).max() == 0.0
    # a field that is 1 on the far side of the slot: 0 on the near side, about 1 across
    assert (b[:, far_left].sum(axis=1) > 0.9).all()


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("shift, scale", [(1e6, 1.0), (0.0, 1e-3), (0.0, 1e3), (-3e5, 1e3)])
def test_translation_and_scale_invariance(kind, shift, scale):
    nodes, tets = jittered_box(6, seed=4)
    points = np.random.default_rng(4).uniform(0, 1, (500, 3))
    base = shape_functions_3d(tet_mesh(nodes, tets), points, kind=kind, gradient=True)
    moved = shape_functions_3d(tet_mesh(nodes * scale + shift, tets), points * scale + shift,
                               kind=kind, gradient=True)
    assert abs(moved.value - base.value).max() < 1e-9
    for g0, g1 in zip(base.gradient, moved.gradient):
        assert abs(g1 * scale - g0).max() < 1e-7 * abs(g0).max()


def test_errors_name_the_problem():
    nodes, tets = lattice_box(2)
    mesh = tet_mesh(nodes, tets)
    with pytest.raises(GeometryError, match="outside the body"):
        shape_functions_3d(mesh, [[0.5, 0.5, 1.5]])
    with pytest.raises(GeometryError, match="gradients are not defined"):
        shape_functions_3d(mesh, nodes[:2], gradient=True)
    with pytest.raises(GeometryError, match="flat"):
        tet_mesh(nodes, [[0, 1, 2, 2]])
    with pytest.raises(GeometryError, match="no face of the tetrahedra"):
        tet_mesh(nodes, tets, constraint_faces=[[0, 1, 26]])


@pytest.mark.parametrize("kind", KINDS)
def test_regions_do_not_share_weights_across_an_interface(kind):
    nodes, tets = lattice_box(4)
    region = (nodes[tets].mean(axis=1)[:, 0] > 0.5).astype(int)
    mesh = tet_mesh(nodes, tets, tet_region=region)
    rng = np.random.default_rng(8)
    points = rng.uniform(0, 1, (2000, 3))
    phi = shape_functions_3d(mesh, points, kind=kind).toarray()
    check_rows(phi, nodes, points)
    left = points[:, 0] < 0.5
    assert np.abs(phi[np.ix_(left, nodes[:, 0] > 0.5)]).max() == 0.0
    assert np.abs(phi[np.ix_(~left, nodes[:, 0] < 0.5)]).max() == 0.0
    # on the interface both sides agree: only its own nodes, continuous from either side
    on = np.column_stack([np.full(200, 0.5), rng.uniform(0, 1, (200, 2))])
    here = shape_functions_3d(mesh, on, kind=kind)
    assert np.abs(here.toarray()[:, nodes[:, 0] != 0.5]).max() == 0.0
    for side in (-1e-9, 1e-9):
        assert abs(shape_functions_3d(mesh, on + [side, 0, 0], kind=kind) - here).max() < 1e-7


@pytest.mark.parametrize("kind", KINDS)
def test_rows_beside_a_reentrant_edge_are_shares(kind, caplog):
    """Where the cavity's signed coordinates are not non-negative shares (a thin layer
    beside a re-entrant edge) the row is the barycentric one of the tetrahedron, and
    the call says how many."""
    nodes, tets = carved(8, SLOT_REMOVED)
    mesh = tet_mesh(nodes, tets)
    points = np.random.default_rng(0).uniform(0, 1, (40000, 3))
    points = points[inside_carved(points, SLOT_REMOVED)][:20000]
    phi = shape_functions_3d(mesh, points, kind=kind, gradient=True)
    check_rows(phi.value, nodes, points, tol=1e-11)
    assert phi.value.data.min() > -1e-9
    for d, g in enumerate(phi.gradient):
        assert np.abs(g @ nodes - np.eye(3)[d]).max() < 1e-9
    fell = sum(int(r.msg and r.args[0]) for r in caplog.records if "linearly" in r.msg)
    assert fell < 10
