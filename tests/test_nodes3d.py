"""3-D node clouds: vertices kept, boundary triangles tiling the input faces, interior
clearance, interfaces, the user's points, invariance."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree

import cnem
from cnem import GeometryError
from cnem.geometry import Domain3D, box, cylinder, hollow_sphere, sphere
from cnem.geometry.shapes3d import box_surface, sphere_surface
from cnem.geometry.surface_checks import check_closed
from cnem.geometry.surface_nodes import surface_patches
from cnem.geometry.surface_queries import faces_within

KINDS = {"regular": lambda d, h: cnem.nodes.regular(d, h),
         "irregular": lambda d, h: cnem.nodes.irregular(d, h, seed=4),
         "graded": lambda d, h: cnem.nodes.graded(d, h, near=d.vertices[:1], h_min=h / 4,
                                                  growth=0.5, seed=3)}


def two_boxes():
    return Domain3D([box_surface((0, 0, 0), (1, 1, 1)), box_surface((1, 0, 0), (2, 1, 1))])


DOMAINS = {"box": lambda: box((0, 0, 0), (1.0, 0.6, 0.8)), "sphere": lambda: sphere(subdivisions=2),
           "hollow": lambda: hollow_sphere(0.5, 1.0, subdivisions=2),
           "cylinder": lambda: cylinder(0.5, 1.0, segments=12), "two boxes": two_boxes}
SPACING = {"box": 0.13, "sphere": 0.3, "hollow": 0.2, "cylinder": 0.15, "two boxes": 0.3}


def _areas(points, faces):
    tri = points[faces]
    return 0.5 * np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])


def _canonical(faces):
    """Oriented triangles, each started at its smallest node, in sorted order."""
    start = np.argmin(faces, axis=1)
    rolled = np.stack([faces[np.arange(len(faces)), (start + k) % 3] for k in range(3)], axis=1)
    return rolled[np.lexsort(rolled.T[::-1])]


def _region_surface(faces, face_regions, r):
    """Triangles bounding region ``r``, oriented out of it."""
    out = faces[face_regions[:, 0] == r]
    inward = faces[face_regions[:, 1] == r][:, ::-1]
    return np.concatenate([out, inward])


@pytest.fixture(scope="module", params=[(d, k) for d in DOMAINS for k in KINDS],
                ids=lambda p: f"{p[0]}-{p[1]}")
def case(request):
    name, kind = request.param
    dom = DOMAINS[name]()
    h = SPACING[name]
    return dom, h, KINDS[kind](dom, h)


def test_vertices_are_the_first_nodes(case):
    dom, _, cloud = case
    assert cloud.points.shape[1] == 3 and cloud.dim == 3
    assert np.array_equal(cloud.points[:len(dom.vertices)], dom.vertices)


def test_boundary_triangles_tile_each_patch(case):
    dom, _, cloud = case
    tol = dom.tolerance
    patch, *_ = surface_patches(dom.vertices, dom.faces, dom.face_regions, tol)
    vec = _areas(cloud.points, cloud.boundary_faces)
    # each boundary triangle lies in the plane of the input face under its centroid,
    # points the same way, and has the same regions on its sides
    cent = cloud.points[cloud.boundary_faces].mean(axis=1)
    point, face, dist = faces_within(cent, dom.vertices, dom.faces, 10 * tol)
    first = np.unique(point, return_index=True)[1]
    assert len(first) == len(cent)
    face = face[first]
    tri = dom.vertices[dom.faces[face]]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.linalg.norm(n, axis=1)[:, None]
    off = np.einsum("bkj,bj->bk", cloud.points[cloud.boundary_faces] - tri[:, :1], n)
    assert np.abs(off).max() <= 10 * tol
    assert (np.einsum("ij,ij->i", vec, n) > 0).all()
    assert np.array_equal(cloud.boundary_face_regions, dom.face_regions[face])
    # the areas per patch add up to the patch's area
    in_area = np.bincount(patch, weights=np.linalg.norm(_areas(dom.vertices, dom.faces), axis=1))
    out_area = np.bincount(patch[face], weights=np.linalg.norm(vec, axis=1),
                           minlength=len(in_area))
    assert np.allclose(out_area, in_area, rtol=1e-12, atol=1e-14 * dom.size**2)


def test_boundary_triangles_have_no_slivers(case):
    _, _, cloud = case
    tri = cloud.points[cloud.boundary_faces]
    area = np.linalg.norm(_areas(cloud.points, cloud.boundary_faces), axis=1)
    longest = np.linalg.norm(tri - np.roll(tri, 1, axis=1), axis=2).max(axis=1)
    assert (area / longest**2).min() > 0.02          # equilateral: 0.433


def test_boundary_triangles_close_each_region(case):
    dom, _, cloud = case
    for r in range(dom.n_regions):
        faces = _region_surface(cloud.boundary_faces, cloud.boundary_face_regions, r)
        check_closed(faces, [f"triangle {i}" for i in range(len(faces))])
        tri = cloud.points[faces] - dom.vertices.mean(axis=0)
        volume = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6
        assert volume == pytest.approx(dom.region_volumes[r], rel=1e-12)


def test_surface_and_interior_nodes(case):
    dom, h, cloud = case
    on_surface = np.zeros(len(cloud.points), dtype=bool)
    on_surface[cloud.boundary_faces.ravel()] = True
    # surface nodes lie on the surface, the others inside, half a spacing away
    assert dom.near_surface(cloud.points[on_surface], 10 * dom.tolerance).all()
    inner = cloud.points[~on_surface]
    assert (dom.region_of(inner) >= 0).all()
    assert not dom.near_surface(inner, 0.5 * cloud.spacing[~on_surface] * (1 - 1e-6)).any()
    assert (cloud.spacing <= h).all()


def test_spacing(case):
    dom, h, cloud = case
    d = cKDTree(cloud.points).query(cloud.points, k=2)[0][:, 1]
    assert (d > 0.1 * cloud.spacing).all()
    if cloud.spacing.min() < h:                       # graded: see test_graded_spacing
        return
    assert np.median(d) == pytest.approx(h, rel=0.35)
    # the nodes' count is about volume / h^3 and the surface's nodes about area / h^2
    assert 0.5 < len(cloud.points) / (dom.volume / h**3 + dom.area / h**2) < 2.5


@pytest.mark.parametrize("kind", list(KINDS))
def test_box_clearance_by_coordinates(kind):
    """In a box the distance to the surface is the least distance to its six planes."""
    lo, hi = np.array([0.0, 0.0, 0.0]), np.array([1.0, 0.6, 0.8])
    cloud = KINDS[kind](box(lo, hi), 0.13)
    gap = np.minimum(cloud.points - lo, hi - cloud.points).min(axis=1)
    on = np.zeros(len(gap), dtype=bool)
    on[cloud.boundary_faces.ravel()] = True
    assert np.abs(gap[on]).max() < 1e-15
    assert (gap[~on] >= 0.5 * cloud.spacing[~on] * (1 - 1e-9)).all()


def test_graded_spacing():
    dom = box()
    centre = np.array([0.5, 0.5, 1.0])
    cloud = cnem.nodes.graded(dom, 0.2, near=centre, h_min=0.02, growth=0.4)
    law = np.minimum(0.2, 0.02 + 0.4 * np.linalg.norm(cloud.points - centre, axis=1))
    assert np.allclose(cloud.spacing, law)
    d = cKDTree(cloud.points).query(cloud.points, k=2)[0][:, 1]
    near = np.linalg.norm(cloud.points - centre, axis=1) < 0.1
    far = np.linalg.norm(cloud.points - centre, axis=1) > 0.6
    # nodes near the centre are several times closer than far from it, about s(x) apart
    assert np.median(d[near]) < 0.3 * np.median(d[far])
    assert 0.4 < np.median(d / law) < 1.5
    with pytest.raises(GeometryError, match=r"near: expected refinement points \(q, 3\)"):
        cnem.nodes.graded(dom, 0.2, near=[[0.5, 0.5]], h_min=0.02)
    with pytest.raises(GeometryError, match="must not exceed"):
        cnem.nodes.graded(dom, 0.2, near=centre, h_min=0.3)


def test_interface_nodes_are_shared():
    dom = two_boxes()
    cloud = cnem.nodes.regular(dom, 0.25)
    at = np.isclose(cloud.points[:, 0], 1.0)
    assert np.unique(cloud.points[at].round(12), axis=0).shape[0] == at.sum() == 25
    interface = cloud.boundary_face_regions[:, 1] >= 0
    assert (cloud.boundary_face_regions[interface] == [0, 1]).all()
    assert np.isclose(cloud.points[cloud.boundary_faces[interface]][..., 0], 1.0).all()


def test_irregular_is_reproducible_and_seeded():
    dom = sphere(subdivisions=2)
    a, b = cnem.nodes.irregular(dom, 0.3, seed=1), cnem.nodes.irregular(dom, 0.3, seed=1)
    c = cnem.nodes.irregular(dom, 0.3, seed=2)
    assert np.array_equal(a.points, b.points) and np.array_equal(a.boundary_faces, b.boundary_faces)
    assert len(a.points) != len(c.points) or not np.array_equal(a.points, c.points)
    with pytest.raises(GeometryError, match="seed"):
        cnem.nodes.irregular(dom, 0.3, seed=1.5)


@pytest.mark.parametrize("surface", ["box", "sphere"])
@pytest.mark.parametrize("kind", list(KINDS))
@pytest.mark.parametrize("shift, scale", [(1e6, 1.0), (0.0, 1e-3), (0.0, 1e3)])
def test_invariance(surface, kind, shift, scale):
    v, f = box_surface((0, 0, 0), (1.0, 0.6, 0.8)) if surface == "box" \
        else sphere_surface(0.5, subdivisions=2)
    ref = KINDS[kind](Domain3D((v, f)), 0.13)
    moved = KINDS[kind](Domain3D((v * scale + shift, f)), 0.13 * scale)
    assert len(moved.points) == len(ref.points)
    assert np.array_equal(_canonical(moved.boundary_faces), _canonical(ref.boundary_faces))
    assert np.abs((moved.points - shift) / scale - ref.points).max() < 1e-8


def test_spacing_checks():
    dom = box()
    with pytest.raises(GeometryError, match="not smaller than the domain diameter"):
        cnem.nodes.regular(dom, 10.0)
    with pytest.raises(GeometryError, match="positive spacing"):
        cnem.nodes.regular(dom, -0.1)
    with pytest.raises(cnem.LimitError, match="MAX_NODES"):
        cnem.nodes.regular(dom, 1e-4)


def test_from_points_keeps_a_full_cloud():
    dom = cylinder(0.5, 1.0, segments=12)
    full = cnem.nodes.regular(dom, 0.15)
    again = cnem.nodes.from_points(dom, full.points[::-1])
    assert len(again.points) == len(full.points)
    assert np.allclose(again.points, full.points[::-1], rtol=0, atol=1e-14)
    faces = _region_surface(again.boundary_faces, again.boundary_face_regions, 0)
    check_closed(faces, [str(i) for i in range(len(faces))])


def test_from_points_fills_the_surface():
    dom = box()
    g = np.linspace(0.125, 0.875, 7)
    inner = np.stack(np.meshgrid(g, g, g, indexing="ij"), axis=-1).reshape(-1, 3)
    cloud = cnem.nodes.from_points(dom, inner)
    assert np.array_equal(cloud.points[:len(inner)], inner)
    assert len(cloud.points) > len(inner) + 8
    surface = np.unique(cloud.boundary_faces)
    assert surface.min() >= len(inner)           # the user gave no surface point
    tri = cloud.points[cloud.boundary_faces] - 0.5
    assert np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6 == \
        pytest.approx(1.0, rel=1e-12)
    bare = cnem.nodes.from_points(dom, inner, fill=False)
    assert len(bare.points) == len(inner) + 8 and len(bare.boundary_faces) == 12


def test_from_points_snaps_and_refuses():
    dom = box()
    eps = 1e-11
    pts = np.array([[0.5, 0.5, 0.5], [1 + eps, 0.5, 0.5], [0.3, 0.0, 1.0 - eps], [eps, 1, 1]])
    cloud = cnem.nodes.from_points(dom, pts, fill=False)
    assert cloud.points[1].tolist() == [1.0, 0.5, 0.5]
    assert cloud.points[2].tolist() == [0.3, 0.0, 1.0]
    assert cloud.points[3].tolist() == [0.0, 1.0, 1.0]
    assert len(cloud.points) == 4 + 7                       # one vertex given by the user
    with pytest.raises(GeometryError, match="outside the domain, first.*1: "):
        cnem.nodes.from_points(dom, [[0.5, 0.5, 0.5], [2.0, 0.5, 0.5]])
    with pytest.raises(GeometryError, match="duplicated points"):
        cnem.nodes.from_points(dom, [[0.5, 0.5, 0.5], [0.5, 0.5, 0.5]])
    with pytest.raises(GeometryError, match="real numbers"):
        cnem.nodes.from_points(dom, [[0.5, 0.5, 0.5j]])
