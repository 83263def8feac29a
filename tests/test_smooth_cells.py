"""3-D cells on bodies bounded by faceted curved surfaces (`cnem.geometry.smooth_patches`,
`cnem.geometry.tet_pieces`): a spherical cavity and a cylindrical hole hide nothing, so
each cell is the Voronoi cell of its node among the region's nodes cut by the region."""

import functools

import numpy as np
import pytest

import cases3d
import cnem
from cnem.errors import GeometryError
from cnem.geometry.cells3d import constrained_voronoi_cells
from cnem.geometry.smooth_patches import blocking_sides
from cnem.geometry.tetrahedra import conforming_tetrahedra, signed_volumes


def _domain(name):
    if name == "hollow_sphere":
        return cnem.geometry.hollow_sphere(0.5, 1.0, subdivisions=2), 0.35
    if name == "hollow_sphere_fine":
        return cnem.geometry.hollow_sphere(0.5, 1.0), 0.15
    return cnem.Domain3D(cases3d.tube_surface(0.4, 1.0, 1.0, 16)), 0.25


@functools.lru_cache(maxsize=None)
def _cells(name, shift=0.0, scale=1.0):
    dom, h = _domain(name)
    cloud = cnem.nodes.irregular(dom, h, seed=1)
    tet = conforming_tetrahedra(cloud.points * scale + shift, cloud.boundary_faces,
                                cloud.boundary_face_regions)
    cells = constrained_voronoi_cells(tet.points, tet.tetrahedra, tet.tet_region,
                                      tet.boundary_faces, tet.boundary_face_regions)
    return dom, tet, cells


def _winding(x, tri):
    """Winding numbers ``(s,)`` of the closed triangle surface ``tri (q, 3, 3)`` about ``x (s, 3)``
    (Van Oosterom and Strackee's solid angles)."""
    a, b, c = (tri[None, :, k] - x[:, None] for k in range(3))
    la, lb, lc = (np.linalg.norm(v, axis=2) for v in (a, b, c))
    det = np.einsum("sqj,sqj->sq", a, np.cross(b, c))
    den = la * lb * lc + np.einsum("sqj,sqj->sq", a, b) * lc + np.einsum("sqj,sqj->sq", a, c) * lb \
        + np.einsum("sqj,sqj->sq", b, c) * la
    return (2.0 * np.arctan2(det, den)).sum(axis=1) / (4.0 * np.pi)


@pytest.mark.parametrize("name", ["hollow_sphere", "tube"])
def test_curved_boundaries_hide_nothing(name):
    dom, tet, _ = _cells(name)
    blocking, reentrant = blocking_sides(tet.points, tet.boundary_faces, tet.boundary_face_regions)
    assert not blocking.any()
    assert reentrant.any()                  # the cavity's or hole's facets are re-entrant


FINE = pytest.param("hollow_sphere_fine", marks=pytest.mark.slow)


@pytest.mark.parametrize("name", ["hollow_sphere", "tube", FINE])
def test_cells_partition_the_body_and_are_closed(name):
    dom, tet, cells = _cells(name)
    np.testing.assert_allclose(cells.volume.sum(), dom.volume, rtol=1e-10)
    np.testing.assert_allclose(cells.volume.sum(),
                               np.abs(signed_volumes(tet.points, tet.tetrahedra)).sum(), rtol=1e-10)
    assert cells.volume.min() > 0
    area = cells.facet_areas()
    m = len(cells.node)
    flux, surface = cases3d.facet_flux(cells)
    assert (np.abs(flux).max(axis=1) <= 1e-10 * surface).all()
    # divergence theorem: the facets enclose the volume
    rel = cells.facet_triangles.mean(axis=1) - tet.points[cells.node[cells.facet_cell]]
    div = np.bincount(cells.facet_cell, weights=np.einsum("ij,ij->i", rel, cells.facet_normal)
                      * area / 3.0, minlength=m)
    np.testing.assert_allclose(div, cells.volume, rtol=1e-9, atol=1e-14)


@pytest.mark.parametrize("name", ["hollow_sphere", "tube", FINE])
def test_each_point_lies_in_the_cell_of_its_nearest_node(name):
    """Brute force: with no blocking face the owner of a point is its nearest node
    (visibility cut by the empty set of blocking faces); the point must lie inside that
    node's cell (winding number of its facets)."""
    dom, tet, cells = _cells(name)
    rng = np.random.default_rng(5)
    lo, hi = dom.bounds
    x = rng.uniform(lo, hi, (3000, 3))
    x = x[dom.contains(x)][:600]
    owner = cases3d.nearest_visible(x, tet.points, np.zeros((0, 3), dtype=np.int64))
    cell_of = np.full(len(tet.points), -1)
    cell_of[cells.node] = np.arange(len(cells.node))
    order = np.argsort(cells.facet_cell, kind="stable")
    start = np.searchsorted(cells.facet_cell[order], np.arange(len(cells.node) + 1))
    inside = []
    for p, i in zip(x, owner.tolist()):
        k = cell_of[i]
        tri = cells.facet_triangles[order[start[k]:start[k + 1]]]
        inside.append(_winding(p[None], tri)[0])
    np.testing.assert_allclose(inside, 1.0, atol=1e-6)


@pytest.mark.parametrize("shift, scale", [(1e6, 1.0), (0.0, 1e-3)])
def test_cavity_cells_are_invariant(shift, scale):
    _, tet_ref, ref = _cells("hollow_sphere")
    _, tet, moved = _cells("hollow_sphere", shift, scale)
    assert len(tet.points) == len(tet_ref.points)
    np.testing.assert_array_equal(moved.node, ref.node)
    tol = 1e-8 if shift else 1e-11
    np.testing.assert_allclose(moved.volume / scale ** 3, ref.volume, rtol=tol,
                               atol=tol * ref.volume.max())


def test_pieces_join_only_through_shared_internal_faces():
    """Two tetrahedra sharing a face make one cell; moved apart (sharing nothing), two;
    a flat tetrahedron between them joins them again."""
    from cnem.geometry.polytope import Polytope
    from cnem.geometry.tet_pieces import connected
    base = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    up = Polytope.tetrahedron(np.vstack([base, [0, 0, 1]]), [("f", 0), ("f", 1), ("f", 2),
                                                              ("t", 7)])
    down = Polytope.tetrahedron(np.vstack([base, [0, 0, -1]]), [("f", 3), ("f", 4), ("f", 5),
                                                                ("t", 7)])
    apart = Polytope.tetrahedron(np.vstack([base, [0, 0, -1]]) + 5.0,
                                 [("f", 3), ("f", 4), ("f", 5), ("t", 8)])
    none = np.zeros((0, 4), dtype=np.int64)
    assert connected([up, down], none)
    assert not connected([up, apart], none)
    assert connected([up, apart], np.array([[7, 8, 9, 10]]))


def test_the_kernel_joins_pieces_only_through_shared_internal_faces():
    """`_tet_cut_kernels._connected` as `tet_pieces.connected` above: two pieces sharing
    the internal face 7 are one cell; sharing nothing, two; joined by a flat
    tetrahedron's faces (7, 8, 9, 10), one again."""
    from cnem.geometry._tet_cut_kernels import _connected
    piece_of, none = np.array([0, 1]), np.zeros((0, 4), dtype=np.int64)
    assert _connected(2, piece_of, np.array([7, 7]), 2, none, 0)
    assert not _connected(2, piece_of, np.array([7, 8]), 2, none, 0)
    assert _connected(2, piece_of, np.array([7, 8]), 2, np.array([[7, 8, 9, 10]]), 1)
    assert _connected(1, piece_of[:1], np.array([7]), 1, none, 0)


@pytest.mark.parametrize("name", ["hollow_sphere", "tube"])
def test_curved_cells_in_bulk_equal_the_general_path_cell_by_cell(name):
    """The numba kernels' cells (`cells3d_curved`: Voronoi polytopes cut by the region's
    tetrahedra, or one polytope where the faces in reach are convex) are those of
    `GeneralCells.cell`: same volume, and per facet plane the same area and centroid."""
    from cnem.geometry.cells3d_clip import GeneralCells
    from cnem.geometry.cells3d_curved import curved_cells
    _, tet, cells = _cells(name)
    general = GeneralCells(tet.points, tet.tetrahedra, tet.tet_region, tet.boundary_faces,
                           tet.boundary_face_regions)
    on_boundary = np.isin(cells.node, tet.boundary_faces)
    node, region = cells.node[on_boundary], cells.region[on_boundary]
    done, tri, cell, normal, volume = curved_cells(general, node, region)
    assert done.all()                   # nothing blocks: every boundary cell is the kernels'
    for k in range(len(node)):
        cases3d.assert_same_cell((tri[cell == k], normal[cell == k], volume[k]),
                                 general.cell(int(node[k]), int(region[k])))


@pytest.mark.slow
def test_curved_cells_in_parallel_equal_the_serial_ones():
    """The kernels' parallel copies (`cnem._parallel.always_parallel`) give the cells of
    the serial ones, bit for bit: each cell's work is its own."""
    from cnem._parallel import always_parallel
    from cnem.geometry.cells3d_clip import GeneralCells
    from cnem.geometry.cells3d_curved import curved_cells
    _, tet, cells = _cells("tube")
    general = GeneralCells(tet.points, tet.tetrahedra, tet.tet_region, tet.boundary_faces,
                           tet.boundary_face_regions)
    serial = curved_cells(general, cells.node, cells.region)
    with always_parallel():
        parallel = curved_cells(general, cells.node, cells.region)
    assert serial[0].sum() > 0
    for a, b in zip(serial, parallel):
        np.testing.assert_array_equal(a, b)


def test_a_cell_split_by_the_region_is_refused(monkeypatch):
    """Were the pieces of a cell not to meet inside the region, the error names the node
    and asks for a finer cloud."""
    import cnem.geometry.cells3d as cells3d
    import cnem.geometry.cells3d_clip as clip
    from cnem.geometry.cells3d_curved import curved_cells

    def declined(general, node, region):            # the kernel's cells: by GeneralCells.cell
        done, *rest = curved_cells(general, node[:0], region[:0])
        return (np.zeros(len(node), dtype=bool), *rest[:3], np.zeros(len(node)))

    monkeypatch.setattr(cells3d, "curved_cells", declined)
    monkeypatch.setattr(clip, "connected", lambda pieces, joins: False)
    dom, h = _domain("tube")
    cloud = cnem.nodes.irregular(dom, h, seed=1)
    tet = conforming_tetrahedra(cloud.points, cloud.boundary_faces, cloud.boundary_face_regions)
    with pytest.raises(GeometryError, match="refine the cloud near"):
        constrained_voronoi_cells(tet.points, tet.tetrahedra, tet.tet_region,
                                  tet.boundary_faces, tet.boundary_face_regions)


@pytest.mark.slow
def test_blocking_and_smooth_cavities_side_by_side():
    """A box with a cubic cavity (blocking: sharp re-entrant edges) beside a faceted
    spherical one (not blocking): the cells partition the body and each sample lies in the
    cell of its nearest node seen past the blocking faces only."""
    from cnem.geometry.shapes3d import box_surface, sphere_surface
    dom = cnem.Domain3D((box_surface((0, 0, 0), (2, 1, 1)),
                         [box_surface((0.35, 0.35, 0.35), (0.65, 0.65, 0.65)),
                          sphere_surface(0.2, center=(1.1, 0.5, 0.5), subdivisions=1)]))
    cloud = cnem.nodes.irregular(dom, 0.2, seed=1)
    tet = conforming_tetrahedra(cloud.points, cloud.boundary_faces, cloud.boundary_face_regions)
    cells = constrained_voronoi_cells(tet.points, tet.tetrahedra, tet.tet_region,
                                      tet.boundary_faces, tet.boundary_face_regions)
    np.testing.assert_allclose(cells.volume.sum(), dom.volume, rtol=1e-10)
    blocking, _ = blocking_sides(tet.points, tet.boundary_faces, tet.boundary_face_regions)
    cube = np.abs(tet.points[tet.boundary_faces] - 0.5).max(axis=(1, 2)) <= 0.15 + 1e-9
    np.testing.assert_array_equal(blocking[:, 0], cube)          # exactly the cubic cavity
    rng = np.random.default_rng(3)
    x = rng.uniform(dom.bounds[0], dom.bounds[1], (1500, 3))
    x = x[dom.contains(x)][:300]
    owner = cases3d.nearest_visible(x, tet.points, tet.boundary_faces[blocking[:, 0]])
    assert (owner >= 0).all()
    order = np.argsort(cells.facet_cell, kind="stable")
    start = np.searchsorted(cells.facet_cell[order], np.arange(len(cells.node) + 1))
    cell_of = np.full(len(tet.points), -1)
    cell_of[cells.node] = np.arange(len(cells.node))
    inside = [_winding(p[None], cells.facet_triangles[order[start[cell_of[i]]:
                                                             start[cell_of[i] + 1]]])[0]
              for p, i in zip(x, owner.tolist())]
    np.testing.assert_allclose(inside, 1.0, atol=1e-6)
