"""`cnem.Domain3D`: volumes, point location, invariance, bad surfaces, files."""

from __future__ import annotations

import numpy as np
import pytest

import cnem
from cnem import GeometryError
from cnem.geometry import Domain3D, box, cylinder, hollow_sphere, sphere
from cnem.geometry.shapes3d import box_surface, sphere_surface


def polyhedron_volume(vertices, faces, origin):
    """Sum of the signed tetrahedra (origin, face): the divergence theorem."""
    tri = vertices[faces] - origin
    return np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6.0


def convex_inside(points, vertices, faces):
    """Inside a convex outward-oriented polyhedron: behind every face plane."""
    tri = vertices[faces]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    side = np.einsum("fj,pfj->pf", n, points[:, None, :] - tri[None, :, 0])
    return (side < 0).all(axis=1), (np.abs(side) / np.linalg.norm(n, axis=1)).min(axis=1)


# ------------------------------------------------------------------ volumes
def test_box_volume_bounds_and_faces():
    dom = box((1.0, 2.0, 3.0), (2.0, 4.0, 7.0))
    assert dom.volume == pytest.approx(8.0, rel=1e-14)
    assert np.array_equal(dom.bounds, [[1, 2, 3], [2, 4, 7]])
    assert dom.faces.shape == (12, 3) and dom.n_regions == 1
    assert (dom.face_regions == [0, -1]).all()
    assert dom.size == pytest.approx(np.sqrt(1 + 4 + 16))


@pytest.mark.parametrize("subdivisions", [1, 2, 3])
def test_sphere_volume_is_the_polyhedron_volume(subdivisions):
    v, f = sphere_surface(2.0, center=(1.0, -1.0, 0.5), subdivisions=subdivisions)
    dom = sphere(2.0, center=(1.0, -1.0, 0.5), subdivisions=subdivisions)
    assert dom.volume == pytest.approx(polyhedron_volume(v, f, np.array([1.0, -1.0, 0.5])),
                                       rel=1e-13)


def test_sphere_volumes_converge_to_the_ball():
    errors = [abs(sphere(1.0, subdivisions=s).volume - 4 / 3 * np.pi) for s in range(1, 6)]
    assert all(b < 0.3 * a for a, b in zip(errors, errors[1:]))   # ~1/4 per subdivision
    assert errors[-1] < 2e-3 * 4 / 3 * np.pi


def test_hollow_sphere_volume_and_orientation():
    dom = hollow_sphere(0.5, 1.0, subdivisions=2)
    vo, fo = sphere_surface(1.0, subdivisions=2)
    vi, fi = sphere_surface(0.5, subdivisions=2)
    exact = polyhedron_volume(vo, fo, 0) - polyhedron_volume(vi, fi, 0)
    assert dom.volume == pytest.approx(exact, rel=1e-13)
    # the faces of the cavity point into the void (towards the centre)
    tri = dom.vertices[dom.faces]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    radial = np.einsum("ij,ij->i", n, tri.mean(axis=1))
    inner = np.linalg.norm(tri.mean(axis=1), axis=1) < 0.75
    assert (radial[inner] < 0).all() and (radial[~inner] > 0).all()


@pytest.mark.parametrize("segments", [3, 8, 64])
def test_cylinder_volume_is_the_prism_volume(segments):
    dom = cylinder(0.7, 2.5, base=(3.0, 0.0, -1.0), segments=segments)
    prism = segments / 2 * 0.7**2 * np.sin(2 * np.pi / segments) * 2.5
    assert dom.volume == pytest.approx(prism, rel=1e-13)


def test_cylinder_volume_converges():
    err = [abs(cylinder(1.0, 1.0, segments=n).volume - np.pi) for n in (16, 32, 64, 128)]
    assert all(3.5 < a / b < 4.5 for a, b in zip(err, err[1:]))   # second order in 1/n


# ------------------------------------------------------------------ location
def test_box_region_of_known_points():
    dom = box()
    pts = [[0.5, 0.5, 0.5], [1.0, 1.0, 1.0], [0.0, 0.3, 0.2], [1.0 + 1e-6, 0.5, 0.5],
           [-0.1, 0.5, 0.5], [0.5, 0.5, 2.0], [0.5, 0.5, 0.5 + 1e-12]]
    assert dom.region_of(pts).tolist() == [0, 0, 0, -1, -1, -1, 0]
    assert dom.contains([0.2, 0.3, 0.4]).tolist() == [True]


def test_lattice_points_on_box_edges_and_diagonals():
    """Points in line with the box's edges and face diagonals (exact ties of the ray)."""
    dom = box()
    g = np.linspace(-0.5, 1.5, 9)
    pts = np.stack(np.meshgrid(g, g, g, indexing="ij"), axis=-1).reshape(-1, 3)
    inside = ((pts >= 0) & (pts <= 1)).all(axis=1)
    assert np.array_equal(dom.contains(pts), inside)


def test_sphere_contains_against_plane_tests():
    v, f = sphere_surface(1.0, subdivisions=2)
    dom = Domain3D((v, f))
    pts = np.random.default_rng(1).uniform(-1.1, 1.1, (3000, 3))
    inside, gap = convex_inside(pts, v, f)
    clear = gap > 1e-9
    assert np.array_equal(dom.contains(pts)[clear], inside[clear])


def test_hollow_sphere_region_of():
    dom = hollow_sphere(0.5, 1.0, subdivisions=2)
    vo, fo = sphere_surface(1.0, subdivisions=2)
    vi, fi = sphere_surface(0.5, subdivisions=2)
    pts = np.random.default_rng(2).uniform(-1.05, 1.05, (3000, 3))
    in_o, g_o = convex_inside(pts, vo, fo)
    in_i, g_i = convex_inside(pts, vi, fi)
    clear = (g_o > 1e-9) & (g_i > 1e-9)
    assert np.array_equal(dom.contains(pts)[clear], (in_o & ~in_i)[clear])
    assert dom.region_of([0.0, 0.0, 0.0]).tolist() == [-1]


def two_boxes():
    return Domain3D([box_surface((0, 0, 0), (1, 1, 1)), box_surface((1, 0, 0), (2, 1, 1))])


def test_two_regions_share_an_interface():
    dom = two_boxes()
    assert dom.n_regions == 2 and dom.volume == pytest.approx(2.0)
    assert len(dom.faces) == 22
    interface = dom.face_regions[:, 1] >= 0
    assert interface.sum() == 2 and (dom.face_regions[interface] == [0, 1]).all()
    # interface faces point out of region 0: along +x
    tri = dom.vertices[dom.faces[interface]]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    assert (n[:, 0] > 0).all()
    pts = [[0.5, 0.5, 0.5], [1.5, 0.5, 0.5], [1.0, 0.5, 0.5], [2.5, 0.5, 0.5], [1.7, 0.0, 1.0]]
    assert dom.region_of(pts).tolist() == [0, 1, 0, -1, 1]


# ------------------------------------------------------------------ invariance
@pytest.mark.parametrize("shift, scale", [(1e6, 1.0), (0.0, 1e-3), (0.0, 1e3), (-1e6, 1e3)])
def test_location_invariant_under_translation_and_scale(shift, scale):
    v, f = sphere_surface(1.0, subdivisions=2)
    vo, fo = sphere_surface(1.0, subdivisions=2)
    ref = hollow_sphere(0.5, 1.0, subdivisions=2)
    moved = Domain3D(((v * scale + shift, f), [(sphere_surface(0.5, subdivisions=2)[0] * scale
                                                + shift, f)]))
    assert moved.volume == pytest.approx(ref.volume * scale**3, rel=1e-9)
    pts = np.random.default_rng(3).uniform(-1.1, 1.1, (2000, 3))
    _, g_o = convex_inside(pts, vo, fo)
    _, g_i = convex_inside(pts, *sphere_surface(0.5, subdivisions=2))
    clear = (g_o > 1e-6) & (g_i > 1e-6)
    assert np.array_equal(moved.region_of(pts * scale + shift)[clear], ref.region_of(pts)[clear])


# ------------------------------------------------------------------ bad surfaces
def test_open_surface_names_the_faces():
    v, f = box_surface((0, 0, 0), (1, 1, 1))
    with pytest.raises(GeometryError, match=r"open.*region 0 face \d+"):
        Domain3D((v, f[1:]))


def test_non_manifold_edge():
    v, f = box_surface((0, 0, 0), (1, 1, 1))
    v2, f2 = box_surface((1, 1, 0), (2, 2, 1))        # touches the first along an edge
    with pytest.raises(GeometryError, match="not manifold.*region 0 face"):
        Domain3D((np.concatenate([v, v2]), np.concatenate([f, f2 + 8])))


def test_inconsistent_orientation_names_the_faces():
    v, f = box_surface((0, 0, 0), (1, 1, 1))
    f = f.copy()
    f[3] = f[3, ::-1]
    with pytest.raises(GeometryError, match="not consistently oriented.*region 0 face 3"):
        Domain3D((v, f))


def test_inside_out_shell_is_turned_round():
    v, f = box_surface((0, 0, 0), (1, 2, 3))
    dom = Domain3D((v, f[:, ::-1]))
    assert dom.volume == pytest.approx(6.0)
    assert polyhedron_volume(dom.vertices, dom.faces, 0) == pytest.approx(6.0)


def test_self_intersection_names_the_faces():
    v, f = box_surface((0, 0, 0), (1, 1, 1))
    v2, f2 = box_surface((0.5, 0.5, 0.5), (1.5, 1.5, 1.5))
    with pytest.raises(GeometryError, match=r"intersects itself.*region 0 face \d+ and region 0 "
                                            r"face \d+"):
        Domain3D((np.concatenate([v, v2]), np.concatenate([f, f2 + 8])))


def test_degenerate_face():
    # a tetrahedron with one vertex on the opposite edge's line: flat faces
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0.5, 0.5, 0.0]], float)
    f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    with pytest.raises(GeometryError, match="degenerate.*region 0 face 3"):
        Domain3D((v, f))


def test_overlapping_regions():
    with pytest.raises(GeometryError, match="regions overlap.*inside region 0"):
        Domain3D([box_surface((0, 0, 0), (2, 2, 2)), box_surface((0.5, 0.5, 0.5), (1, 1, 1))])
    with pytest.raises(GeometryError, match="intersects itself"):
        Domain3D([box_surface((0, 0, 0), (2, 2, 2)), box_surface((1, 1, 1), (3, 3, 3))])


def test_non_conforming_interface():
    with pytest.raises(GeometryError, match="interfaces must be the same triangles"):
        Domain3D([box_surface((0, 0, 0), (1, 1, 1)), box_surface((1, 0, 0), (2, 2, 2))])


def test_cavity_outside_the_shell():
    with pytest.raises(GeometryError, match="cavity 0 is not inside"):
        Domain3D((box_surface((0, 0, 0), (1, 1, 1)), [box_surface((2, 2, 2), (3, 3, 3))]))


@pytest.mark.parametrize("bad, message", [(np.nan, "not finite"), (1j, "real numbers"),
                                          (1e200, "below")])
def test_bad_coordinates(bad, message):
    v, f = box_surface((0, 0, 0), (1, 1, 1))
    v = v.astype(complex if isinstance(bad, complex) else float)
    v[5, 1] = bad
    with pytest.raises(GeometryError, match=message):
        Domain3D((v, f))


def test_faces_as_whole_floats_and_bad_faces():
    v, f = box_surface((0, 0, 0), (1, 1, 1))
    assert Domain3D((v, f.astype(float))).volume == pytest.approx(1.0)
    with pytest.raises(GeometryError, match="vertex numbers"):
        Domain3D((v, f + 0.5))
    with pytest.raises(GeometryError, match=r"must lie in \[0, 8\)"):
        Domain3D((v, f + 1))


def test_bad_query_points():
    dom = box()
    with pytest.raises(GeometryError, match="real numbers"):
        dom.contains([[0.5, 0.5, 0.5j]])
    with pytest.raises(GeometryError, match="finite"):
        dom.region_of([[np.nan, 0.5, 0.5]])


# ------------------------------------------------------------------ inputs and files
def _same_domain(a, b, digits=12):
    """The same vertices and triangles (to ``digits``: STL and PLY store float32)."""
    assert a.volume == pytest.approx(b.volume, rel=10.0**-digits)
    assert len(a.faces) == len(b.faces) and len(a.vertices) == len(b.vertices)
    key_a = np.sort(np.sort(a.vertices[a.faces].round(digits - 3), axis=1)
                    .reshape(len(a.faces), -1), axis=0)
    key_b = np.sort(np.sort(b.vertices[b.faces].round(digits - 3), axis=1)
                    .reshape(len(b.faces), -1), axis=0)
    assert np.array_equal(key_a, key_b)


@pytest.mark.parametrize("suffix", [".stl", ".obj", ".ply"])
def test_trimesh_files(tmp_path, suffix):
    trimesh = pytest.importorskip("trimesh")
    v, f = sphere_surface(1.0, subdivisions=1)
    path = tmp_path / f"ball{suffix}"
    trimesh.Trimesh(v, f, process=False).export(path)
    _same_domain(Domain3D.from_file(path), Domain3D((v, f)), digits=6)


@pytest.mark.parametrize("suffix, fmt", [(".vtu", None), (".msh", "gmsh22"), (".vtk", None)])
def test_meshio_files(tmp_path, suffix, fmt):
    import meshio

    v, f = sphere_surface(1.0, subdivisions=1)
    path = tmp_path / f"ball{suffix}"
    meshio.write(path, meshio.Mesh(v, [("triangle", f)]), file_format=fmt, binary=False) \
        if fmt else meshio.write(path, meshio.Mesh(v, [("triangle", f)]))
    _same_domain(Domain3D.from_file(path), Domain3D((v, f)))


def test_mesh_objects_are_regions():
    trimesh = pytest.importorskip("trimesh")
    import meshio

    v, f = box_surface((0, 0, 0), (1, 1, 1))
    ref = Domain3D((v, f))
    _same_domain(Domain3D(trimesh.Trimesh(v, f, process=False)), ref)
    _same_domain(Domain3D(meshio.Mesh(v, [("triangle", f)])), ref)
    pyvista = pytest.importorskip("pyvista")
    flat = np.column_stack([np.full(len(f), 3), f]).ravel()
    _same_domain(Domain3D(pyvista.PolyData(v, flat)), ref)


def test_unknown_file(tmp_path):
    path = tmp_path / "a.xyz"
    path.write_text("")
    with pytest.raises(GeometryError, match="unknown surface format"):
        Domain3D.from_file(path)


def test_public_names():
    assert cnem.Domain3D is Domain3D
    assert "Domain3D" in cnem.__all__
    assert "<Domain3D 2 regions, 22 faces (2 interface)" in repr(two_boxes())
