"""3-D constrained Voronoi cells (`cnem.geometry.cells3d`)."""

import functools

import numpy as np
import pytest
from scipy.optimize import linprog
from scipy.spatial import ConvexHull, HalfspaceIntersection, Voronoi

import cases3d
from cnem.geometry.cells3d import constrained_voronoi_cells
from cnem.geometry.tetrahedra import conforming_tetrahedra

VOLUMES = {"box": [1.0], "l_block": [0.75], "box_with_cavity": [1.0 - (1.0 / 4.0) ** 3],   # n=4
           "stacked": [0.5, 0.5], "slotted": [0.99]}


@functools.lru_cache(maxsize=None)
def _cells(name, jitter, n=None, shift=0.0, scale=1.0, seed=None):
    kwargs = {"jitter": jitter} if n is None else {"jitter": jitter, "n": n}
    if seed is not None:
        kwargs["seed"] = seed
    p, f, r = getattr(cases3d, name)(**kwargs)
    tet = conforming_tetrahedra(p * scale + shift, f, r)
    cells = constrained_voronoi_cells(tet.points, tet.tetrahedra, tet.tet_region,
                                      tet.boundary_faces, tet.boundary_face_regions)
    return tet, cells


@pytest.mark.parametrize("jitter", [0.0, 0.3])
@pytest.mark.parametrize("name", ["box", "stacked", "l_block", "box_with_cavity", "slotted"])
def test_cells_partition_each_region_and_are_closed(name, jitter):
    tet, cells = _cells(name, jitter, 4 if name in ("box_with_cavity", "slotted") else None)
    np.testing.assert_allclose(np.bincount(cells.region, weights=cells.volume), VOLUMES[name],
                               rtol=1e-12)
    assert cells.volume.min() > 0
    area = cells.facet_areas()
    m = len(cells.node)
    # closed: the normals times the areas sum to zero over each cell
    flux, scale = cases3d.facet_flux(cells)
    assert np.abs(flux).max(axis=1).max() <= 1e-12 * scale.max()
    # divergence theorem: the volume is (1/3) sum (x - x_i) . n A over the facets
    rel = cells.facet_triangles.mean(axis=1) - tet.points[cells.node[cells.facet_cell]]
    div = np.bincount(cells.facet_cell, weights=np.einsum("ij,ij->i", rel, cells.facet_normal)
                      * area / 3.0, minlength=m)
    np.testing.assert_allclose(div, cells.volume, rtol=1e-10, atol=1e-14)
    # unit normals, and the triangles turn counter-clockwise about them
    np.testing.assert_allclose(np.linalg.norm(cells.facet_normal, axis=1), 1.0, rtol=1e-12)
    t = cells.facet_triangles
    turn = np.einsum("ij,ij->i", np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), cells.facet_normal)
    assert turn.min() >= -1e-12 * scale.max()


def test_interior_cells_are_scipy_voronoi_cells():
    tet, cells = _cells("box", 0.3, 8)
    vor = Voronoi(tet.points)
    checked = 0
    for k, i in enumerate(cells.node.tolist()):
        region = vor.regions[vor.point_region[i]]
        if -1 in region or len(region) == 0:
            continue
        v = vor.vertices[region]
        if v.min() < 0 or v.max() > 1:
            continue
        np.testing.assert_allclose(cells.volume[k], ConvexHull(v).volume, rtol=1e-10)
        checked += 1
    assert checked > 100


def _voronoi_in_box(points, i):
    """Volume of node ``i``'s Voronoi cell intersected with the unit cube (half-spaces)."""
    others = np.delete(points, i, axis=0)
    normal = others - points[i]
    offset = -0.5 * np.einsum("ij,ij->i", normal, others + points[i])
    cube = np.array([[-1, 0, 0, 0], [1, 0, 0, -1], [0, -1, 0, 0], [0, 1, 0, -1],
                     [0, 0, -1, 0], [0, 0, 1, -1]], dtype=float)
    hs = np.vstack([np.column_stack([normal, offset]), cube])
    norm = np.linalg.norm(hs[:, :3], axis=1)
    # a strictly interior point: the centre of the largest inscribed ball (Chebyshev)
    res = linprog(np.r_[0, 0, 0, -1], A_ub=np.column_stack([hs[:, :3], norm]), b_ub=-hs[:, 3],
                  bounds=[(None, None)] * 3 + [(0, None)])
    inter = HalfspaceIntersection(hs, res.x[:3])
    return ConvexHull(inter.intersections).volume


def test_convex_body_cells_are_voronoi_cut_by_the_body():
    tet, cells = _cells("box", 0.3, 4)
    for k, i in enumerate(cells.node.tolist()):
        np.testing.assert_allclose(cells.volume[k], _voronoi_in_box(tet.points, i), rtol=1e-9)


@pytest.mark.parametrize("name", ["l_block", "slotted"])
def test_cells_hold_the_points_whose_nearest_visible_node_is_theirs(name):
    """Brute force: sample the body, find each sample's nearest node that it sees
    (segments against every boundary triangle), count per node."""
    tet, cells = _cells(name, 0.3, 4)
    rng = np.random.default_rng(11)
    x = rng.uniform(0.0, 1.0, (30000, 3))
    if name == "l_block":
        x = x[~((x[:, 0] > 0.5) & (x[:, 1] > 0.5))]
    else:
        x = x[~((x[:, 0] < 0.5) & (x[:, 2] > 0.5) & (x[:, 2] < 0.52))]
    owner = cases3d.nearest_visible(x, tet.points, tet.boundary_faces)
    assert (owner >= 0).all()
    share = np.bincount(owner, minlength=len(tet.points))[cells.node] / len(x)
    expected = cells.volume / VOLUMES[name][0]
    sigma = np.sqrt(expected * (1 - expected) / len(x))
    assert np.abs(share - expected).max() <= 5 * sigma.max()


def test_no_cell_crosses_the_slot():
    tet, cells = _cells("slotted", 0.3, 4)
    x = tet.points[cells.node]
    v = cells.facet_triangles.reshape(-1, 3)
    owner = np.repeat(x[cells.facet_cell], 3, axis=0)
    over = v[:, 0] < 0.5 - 1e-9
    below = (owner[:, 2] <= 0.5) & (owner[:, 0] < 0.5 - 1e-9)
    above = (owner[:, 2] >= 0.52) & (owner[:, 0] < 0.5 - 1e-9)
    assert not (below & over & (v[:, 2] > 0.5 + 1e-9)).any()
    assert not (above & over & (v[:, 2] < 0.52 - 1e-9)).any()
    assert not (over & (v[:, 2] > 0.5 + 1e-9) & (v[:, 2] < 0.52 - 1e-9)).any()


def test_an_interface_node_owns_one_cell_per_region():
    tet, cells = _cells("stacked", 0.3)
    on = np.flatnonzero(np.isclose(tet.points[:, 2], 0.5))
    for i in on.tolist():
        mine = np.flatnonzero(cells.node == i)
        assert sorted(cells.region[mine].tolist()) == [0, 1]
    # a region's cells stay on its side of the interface
    z = cells.facet_triangles[:, :, 2]
    reg = cells.region[cells.facet_cell]
    assert z[reg == 0].max() <= 0.5 + 1e-12 and z[reg == 1].min() >= 0.5 - 1e-12
    # an interface node's two cells are mirror halves on a lattice
    _, lattice = _cells("stacked", 0.0)
    two = np.bincount(lattice.node) == 2
    assert two.sum() == 7 * 7
    halves = lattice.volume[two[lattice.node]].reshape(-1, 2)
    np.testing.assert_allclose(halves[:, 0], halves[:, 1], rtol=1e-12)


@pytest.mark.parametrize("shift, scale", [(1e6, 1.0), (0.0, 1e-3), (0.0, 1e3)])
def test_invariance(shift, scale):
    """Moved and scaled, two stacked regions give the same cells (volumes relative to the
    size to round-off)."""
    tet_ref, ref = _cells("stacked", 0.3, None, 0.0, 1.0, 1)
    tet, moved = _cells("stacked", 0.3, None, shift, scale, 1)
    assert len(tet.points) == len(tet_ref.points)         # this cloud needs no added node
    np.testing.assert_array_equal(moved.node, ref.node)
    tol = 1e-8 if shift else 1e-11
    np.testing.assert_allclose(moved.volume / scale ** 3, ref.volume, rtol=tol,
                               atol=tol * ref.volume.max())


@pytest.mark.parametrize("name", ["box", "stacked"])
def test_convex_cells_in_bulk_equal_the_general_path_cell_by_cell(name):
    """The numba kernel's convex cells (`cells3d_convex`) are those of `GeneralCells.cell`:
    same volume, and per facet plane the same area and centroid."""
    from cnem.geometry.cells3d_clip import GeneralCells
    from cnem.geometry.cells3d_convex import convex_cells
    tet, cells = _cells(name, 0.3)
    general = GeneralCells(tet.points, tet.tetrahedra, tet.tet_region, tet.boundary_faces,
                           tet.boundary_face_regions)
    done, tri, cell, normal, volume = convex_cells(general, cells.node, cells.region)
    assert done.sum() >= len(done) // 2
    for k in np.flatnonzero(done).tolist():
        cases3d.assert_same_cell((tri[cell == k], normal[cell == k], volume[k]),
                                 general.cell(int(cells.node[k]), int(cells.region[k])))


def test_cells_beside_a_re_entrant_edge_tile_the_boundary():
    """An L-block at a coarse spacing: the cell of a node on the re-entrant edge wraps
    round it (facets parallel to the boundary faces beyond it, shadows in a boundary
    face's plane). Its facets must close, cancel inside the body, and those on the
    boundary tile it: their areas sum to the L-block's surface, 5.5."""
    import cnem
    from cnem.assembly.facet_gradients import boundary_points_3d

    p, f, _ = cases3d.l_block(2, jitter=0.0)
    model = cnem.discretize(cnem.nodes.irregular(cnem.Domain3D((p, f)), 0.45, seed=0))
    point, area_normal, _ = boundary_points_3d(model)
    assert np.isclose(np.linalg.norm(area_normal, axis=1).sum(), 5.5, rtol=1e-12)
    np.testing.assert_allclose(area_normal.sum(axis=0), 0.0, atol=1e-12)
