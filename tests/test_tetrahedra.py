"""Boundary-conforming Delaunay tetrahedrisation (`cnem.geometry.tetrahedra`)."""

import numpy as np
import pytest

import cases3d
import cnem
from cnem.errors import GeometryError
from scipy.spatial import ConvexHull, Delaunay

from cnem.geometry.tetrahedra import (_FACES, _face_keys, conforming_tetrahedra, signed_volumes,
                                     tet_neighbors)

#: case -> (builder, exact volume of each region)
CASES = {
    "box": (cases3d.box, [1.0]),
    "l_block": (cases3d.l_block, [0.75]),
    "cavity": (cases3d.box_with_cavity, [1.0 - (1.0 / 3.0) ** 3]),
    "stacked": (cases3d.stacked, [0.5, 0.5]),
    "slotted": (cases3d.slotted, [0.99]),
}


def _build(name, jitter):
    builder, volumes = CASES[name]
    p, f, r = builder(jitter=jitter)
    return p, f, r, conforming_tetrahedra(p, f, r), np.array(volumes)


@pytest.mark.parametrize("jitter", [0.0, 0.3])
@pytest.mark.parametrize("name", sorted(CASES))
def test_volumes_faces_and_orientation(name, jitter):
    p, f, r, tet, volumes = _build(name, jitter)
    vol = signed_volumes(tet.points, tet.tetrahedra)
    assert vol.min() >= 0.0                                   # positively oriented (slivers 0)
    got = np.bincount(tet.tet_region, weights=vol, minlength=len(volumes))
    np.testing.assert_allclose(got, volumes, rtol=1e-12)
    # every boundary face is a face of a kept tetrahedron on its inner side
    n = len(tet.points)
    faces = tet.tetrahedra[:, _FACES].reshape(-1, 3)
    owner = np.repeat(np.arange(len(tet.tetrahedra)), 4)
    key = {tuple(sorted(x)): k for k, x in zip(owner.tolist(), faces.tolist())}
    for face, (inner, _) in zip(tet.boundary_faces.tolist(), tet.boundary_face_regions.tolist()):
        t = key[tuple(sorted(face))]
        side = np.dot(np.cross(tet.points[face[1]] - tet.points[face[0]],
                               tet.points[face[2]] - tet.points[face[0]]),
                      tet.points[tet.tetrahedra[t]].mean(axis=0) - tet.points[face[0]])
        assert tet.tet_region[t] in tet.boundary_face_regions[
            np.flatnonzero((np.sort(tet.boundary_faces, axis=1) == sorted(face)).all(axis=1))
        ].ravel() and (side <= 0 or tet.tet_region[t] != inner)
    # the input points come first, unchanged, and every node is a vertex
    np.testing.assert_array_equal(tet.points[:len(p)], p)
    assert len(np.unique(tet.tetrahedra)) == n


def test_a_face_hiding_a_node_is_split_on_the_boundary():
    """A node just below an interface face leaves no empty sphere through the face (the
    nodes above close it): the face is split; the new nodes lie on the interface (no
    interior Steiner point) and the faces still tile it."""
    p, f, r = cases3d.stacked(4, jitter=0.0)
    interface = np.flatnonzero(r[:, 1] >= 0)[0]
    below = p[f[interface]].mean(axis=0) - [0.0, 0.0, 0.02]
    p2 = np.vstack([p, below])
    tet = conforming_tetrahedra(p2, f, r)
    added = tet.points[len(p2):]
    assert len(added) > 0
    on_surface = (np.isclose(added, 0.0, atol=1e-15) | np.isclose(added, 1.0)).any(axis=1)
    assert (on_surface | np.isclose(added[:, 2], 0.5)).all()
    assert np.isin(np.arange(len(p2), len(tet.points)), tet.boundary_faces).all()
    vol = signed_volumes(tet.points, tet.tetrahedra)
    np.testing.assert_allclose(np.bincount(tet.tet_region, weights=vol), [0.5, 0.5], rtol=1e-12)
    x = tet.points[tet.boundary_faces]
    area = np.linalg.norm(np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), axis=1) / 2
    np.testing.assert_allclose(area[tet.boundary_face_regions[:, 1] >= 0].sum(), 1.0, rtol=1e-12)
    np.testing.assert_allclose(area.sum(), 7.0, rtol=1e-12)


@pytest.mark.parametrize("shift, scale", [(1e6, 1.0), (0.0, 1e-3), (0.0, 1e3)])
def test_invariance(shift, scale):
    """Moved and scaled, the body is tetrahedrised with the same volume, without added
    nodes (ties of the lattice faces may be broken otherwise: the cells, which are
    unique, are compared in test_cells3d)."""
    p, f, r = cases3d.l_block(jitter=0.3)
    ref = conforming_tetrahedra(p, f, r)
    moved = conforming_tetrahedra(p * scale + shift, f, r)
    v = signed_volumes(moved.points - shift, moved.tetrahedra) / scale ** 3
    assert len(ref.points) == len(p)
    # moved or scaled, the lattice's ties are broken by round-off and a few tied faces
    # may be split: the added nodes lie on the boundary
    added = (moved.points[len(p):] - shift) / scale
    assert np.isin(np.arange(len(p), len(moved.points)), moved.boundary_faces).all()
    assert ((np.abs(added) < 1e-9) | (np.abs(added - 1) < 1e-9)
            | (np.abs(added - 0.5) < 1e-9)).any(axis=1).all()
    np.testing.assert_allclose(v.sum(), 0.75, rtol=1e-9)
    assert v.min() >= -1e-9 * v.max()


def test_open_surface_and_duplicates_are_named():
    p, f, r = cases3d.box(3, jitter=0.0)
    with pytest.raises(GeometryError, match="volume|enclose|regions"):
        conforming_tetrahedra(p, f[2:], r[2:])
    with pytest.raises(GeometryError, match="duplicate"):
        conforming_tetrahedra(np.vstack([p, p[5]]), f, r)
    with pytest.raises(GeometryError, match=r"\(n, 3\)"):
        conforming_tetrahedra(p[:, :2], f, r)


def test_flat_slivers_in_a_faceted_surface_do_not_vote():
    """Four coplanar nodes of one icosphere facet make a flat sliver lying in the surface;
    its two sides of a boundary face carry no region (it used to make the classification
    refuse a valid hollow sphere)."""
    dom = cnem.geometry.hollow_sphere(0.5, 1.0, subdivisions=1)
    cloud = cnem.nodes.irregular(dom, 0.3, seed=0)
    tets = conforming_tetrahedra(cloud.points, cloud.boundary_faces, cloud.boundary_face_regions)
    volume = np.abs(signed_volumes(tets.points, tets.tetrahedra)).sum()
    np.testing.assert_allclose(volume, dom.volume, rtol=1e-12)


def test_face_keys_do_not_wrap_past_two_million_nodes():
    """With n = 2^22 nodes, ``(a n + b) n + c`` wraps in int64: (1, b, c) and
    (1 + 2^20, b, c) would share a key. The keys tell every pair of triangles apart
    exactly when their node sets differ, across the arrays given together."""
    n = 2 ** 22
    rng = np.random.default_rng(0)
    tris = np.vstack([[[1, 2_000_000, 3_000_000], [1 + 2 ** 20, 2_000_000, 3_000_000]],
                      rng.integers(0, n, (200, 3)), rng.integers(0, 50, (200, 3))])
    faces = tris[rng.permutation(len(tris))[:50]][:, ::-1]            # the same, reordered
    keys, face_keys = _face_keys([tris, faces], n)
    same = (np.sort(tris, axis=1)[:, None] == np.sort(tris, axis=1)[None]).all(axis=2)
    np.testing.assert_array_equal(keys[:, None] == keys[None], same)
    same = (np.sort(faces, axis=1)[:, None] == np.sort(tris, axis=1)[None]).all(axis=2)
    np.testing.assert_array_equal(face_keys[:, None] == keys[None], same)


def test_tet_neighbors_with_keys_past_two_million_nodes():
    p, f, r = cases3d.box(jitter=0.3)
    tets = conforming_tetrahedra(p, f, r).tetrahedra
    np.testing.assert_array_equal(tet_neighbors(tets, 3_000_000), tet_neighbors(tets, len(p)))


def test_generic_points_give_qhulls_delaunay_tetrahedra():
    """Points in general position inside their convex hull (the body): the conforming
    tetrahedrisation is the unique Delaunay one, the tetrahedra Qhull gives without the
    far corners."""
    rng = np.random.default_rng(1)
    p = rng.normal(size=(400, 3)) * [3.0, 1.0, 0.2] + 1e3
    hull = ConvexHull(p)
    faces = hull.simplices.copy()
    inward = np.einsum("ij,ij->i", hull.equations[:, :3],
                       np.cross(p[faces[:, 1]] - p[faces[:, 0]], p[faces[:, 2]] - p[faces[:, 0]]))
    faces[inward < 0] = faces[inward < 0][:, ::-1]                     # normals outwards
    regions = np.column_stack([np.zeros(len(faces), dtype=np.int64),
                               np.full(len(faces), -1, dtype=np.int64)])
    got = conforming_tetrahedra(p, faces, regions)
    assert got.n_input == len(got.points)
    want = {tuple(sorted(t)) for t in Delaunay(p).simplices.tolist()}
    assert {tuple(sorted(t)) for t in got.tetrahedra.tolist()} == want
