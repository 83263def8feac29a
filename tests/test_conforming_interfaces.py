"""Boundary-conforming tetrahedra on bodies with interfaces that used to break them.

Two boxes bonded on x = 1 (finer clouds put interior nodes inside the circumspheres
of interface faces, and splitting those faces at their circumcentres without flipping
their planes back to Delaunay went on without end), and a cube inclusion (its faces
name region 1 only as the region outside them). The cells fill each region, and
bimaterial patch tests hold across the interfaces. The refinement of missing faces
keeps the surface, its orientation and its regions, and leaves each plane Delaunay.
"""

from __future__ import annotations

import numpy as np
import pytest

import cnem
from cnem.geometry.face_refinement import refine_faces
from cnem.geometry.shapes3d import box_surface
from cnem.geometry.tetrahedra import region_volumes
from test_interface_facets import A, LOWER, UPPER, _stress

#: A material with the bulk modulus of ``LOWER`` (E / (3 (1 - 2 nu)) = 2.5) and another
#: shear modulus: under a pure dilatation both carry the same stress.
SAME_BULK = (1.5, 0.4)
DILATATION = 2e-3
#: A small rotation (skew), free of stress.
ROTATION = np.array([[0.0, -0.3, 0.2], [0.3, 0.0, -0.1], [-0.2, 0.1, 0.0]]) * 1e-2


def _on_boundary(prob, n):
    faces, _ = prob.boundary_edges()
    on = np.zeros(n, dtype=bool)
    on[faces.ravel()] = True
    return on


def _kinked_gradient():
    """``A + a e_x^T``: the gradient beyond x = 1 whose field is continuous with ``A x``
    before it and whose traction ``sigma e_x`` matches (3 equations in a)."""
    ex = np.array([1.0, 0.0, 0.0])
    jac = np.column_stack([_stress(np.outer(e, ex), UPPER) @ ex for e in np.eye(3)])
    a = np.linalg.solve(jac, _stress(A, LOWER) @ ex - _stress(A, UPPER) @ ex)
    return A + np.outer(a, ex)


def _side_by_side_field(p):
    beyond = np.maximum(p[:, 0] - 1.0, 0.0)
    return p @ A.T + beyond[:, None] * (_kinked_gradient() - A)[:, 0][None, :]


@pytest.fixture(scope="module", params=[(0.15, 3), (0.1, 0)], ids=["h0.15", "h0.1"])
def side_by_side(request):
    """Boxes [0, 1]^3 (region 0) and [1, 2] x [0, 1]^2 (region 1); both clouds failed
    with faces still missing after 8 rounds."""
    h, seed = request.param
    dom = cnem.Domain3D([box_surface((0, 0, 0), (1, 1, 1)), box_surface((1, 0, 0), (2, 1, 1))])
    return cnem.discretize(cnem.nodes.irregular(dom, h, seed=seed))


@pytest.fixture(scope="module")
def inclusion():
    """A cube [0.35, 0.65]^3 (region 1) inside the box [0, 1]^3 (region 0)."""
    inner = box_surface((0.35, 0.35, 0.35), (0.65, 0.65, 0.65))
    dom = cnem.Domain3D([(box_surface((0, 0, 0), (1, 1, 1)), [inner]), inner])
    return cnem.discretize(cnem.nodes.irregular(dom, 0.25, seed=0))


def test_the_kinked_field_is_continuous_in_displacement_and_traction():
    g = _kinked_gradient()
    ex = np.array([1.0, 0.0, 0.0])
    np.testing.assert_allclose(g[:, 1:], A[:, 1:], rtol=0, atol=0)
    np.testing.assert_allclose(_stress(g, UPPER) @ ex, _stress(A, LOWER) @ ex, atol=1e-15)
    assert np.abs(g - A).max() > 1e-3


def test_same_bulk_materials_carry_the_same_dilatation_stress():
    eps = DILATATION * np.eye(3) + ROTATION
    np.testing.assert_allclose(_stress(eps, SAME_BULK), _stress(eps, LOWER), atol=1e-15)
    assert not np.allclose(_stress(np.diag([1.0, -1.0, 0.0]), SAME_BULK),
                           _stress(np.diag([1.0, -1.0, 0.0]), LOWER))


@pytest.mark.slow
def test_cells_fill_each_box(side_by_side):
    got = np.bincount(side_by_side.cells.region, weights=side_by_side.cells.volume)
    np.testing.assert_allclose(got, [1.0, 1.0], rtol=0, atol=1e-10)


@pytest.mark.slow
@pytest.mark.parametrize("stabilization", [0.0, 1.0])
def test_bimaterial_patch_test_across_x_equal_one(side_by_side, stabilization):
    m = side_by_side
    prob = cnem.Elasticity(m, [LOWER, UPPER], stabilization=stabilization)
    prob.add_dirichlet(_on_boundary(prob, len(m.nodes)), None, _side_by_side_field)
    sol = prob.solve(progress=False)
    exact = _side_by_side_field(m.nodes)
    assert np.abs(sol.u - exact).max() <= 1e-10 * np.abs(exact).max()


@pytest.mark.slow
def test_cells_fill_the_inclusion_and_its_host(inclusion):
    got = np.bincount(inclusion.cells.region, weights=inclusion.cells.volume)
    np.testing.assert_allclose(got, [1.0 - 0.3 ** 3, 0.3 ** 3], rtol=0, atol=1e-10)


@pytest.mark.slow
@pytest.mark.parametrize("stabilization", [0.0, 1.0])
def test_bimaterial_patch_test_around_an_inclusion(inclusion, stabilization):
    """A dilatation and a rotation: the same stress in both materials (same bulk
    modulus), so the linear field is exact across all six faces of the cube."""
    m = inclusion
    grad = DILATATION * np.eye(3) + ROTATION
    prob = cnem.Elasticity(m, [LOWER, SAME_BULK], stabilization=stabilization)
    prob.add_dirichlet(_on_boundary(prob, len(m.nodes)), None, lambda p: p @ grad.T)
    sol = prob.solve(progress=False)
    exact = m.nodes @ grad.T
    assert np.abs(sol.u - exact).max() <= 1e-10 * np.abs(exact).max()


def _in_circle_violations(points, faces, face_regions):
    """Edges of two coplanar faces with the same regions where the far node of one
    lies strictly inside the other's circumcircle (each edge from both sides)."""
    x = points[faces]
    normal = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
    unit = normal / np.linalg.norm(normal, axis=1)[:, None]
    by_edge: dict[frozenset, list[int]] = {}
    for k, f in enumerate(faces.tolist()):
        for e in range(3):
            by_edge.setdefault(frozenset((f[e], f[(e + 1) % 3])), []).append(k)
    bad = 0
    for shared, pair in by_edge.items():
        for i, j in ((pair[0], pair[-1]), (pair[-1], pair[0])):
            if len(pair) != 2 or unit[i] @ unit[j] < 1 - 1e-10 or \
                    (face_regions[i] != face_regions[j]).any():
                continue
            far = next(v for v in faces[j].tolist() if v not in shared)
            e1, e2 = x[i, 1] - x[i, 0], x[i, 2] - x[i, 0]
            # the circumcentre solves |c - x0|^2 = |c - x1|^2 = |c - x2|^2 in the plane
            m = np.array([e1, e2, normal[i]])
            c = x[i, 0] + np.linalg.solve(m, [0.5 * e1 @ e1, 0.5 * e2 @ e2, 0.0])
            r2 = np.sum((x[i, 0] - c) ** 2)
            bad += np.sum((points[far] - c) ** 2) < r2 * (1 - 1e-8)
    return bad


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_refined_faces_keep_the_surface_and_stay_delaunay_in_their_planes(seed):
    """Two bonded boxes' surface nodes, some faces split: the regions' volumes, the
    area and the oriented area per region pair stay, and no edge that may flip is
    left non-Delaunay."""
    dom = cnem.Domain3D([box_surface((0, 0, 0), (1, 1, 1)), box_surface((1, 0, 0), (2, 1, 1))])
    cloud = cnem.nodes.irregular(dom, 0.3, seed=seed)
    on = np.unique(cloud.boundary_faces)
    remap = np.full(len(cloud.points), -1)
    remap[on] = np.arange(len(on))
    points, faces = cloud.points[on], remap[cloud.boundary_faces]
    regions = cloud.boundary_face_regions
    assert _in_circle_violations(points, faces, regions) == 0
    rng = np.random.default_rng(seed)
    missing = rng.choice(len(faces), size=len(faces) // 4, replace=False)
    p2, f2, r2 = refine_faces(points, faces, regions, missing)
    assert len(f2) > len(faces) and len(p2) > len(points)
    np.testing.assert_array_equal(p2[:len(points)], points)
    np.testing.assert_allclose(region_volumes(p2, f2, r2, 2), [1.0, 1.0], rtol=0, atol=1e-13)

    def area_normals(pts, fs, rs):
        x = pts[fs]
        an = 0.5 * np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
        key = (rs[:, 0] + 1) * 3 + rs[:, 1] + 1
        area = np.linalg.norm(an, axis=1)
        return np.stack([np.bincount(key, weights=w, minlength=9)
                         for w in (an[:, 0], an[:, 1], an[:, 2], area)])

    np.testing.assert_allclose(area_normals(p2, f2, r2), area_normals(points, faces, regions),
                               atol=1e-13)
    assert _in_circle_violations(p2, f2, r2) == 0
