"""Files for ParaView (issue 39 item 2, issue 37 item 5, issue 38 item 5): `Solution.write`
gives 3-component point vectors, named 9-component tensors and one row of cell data per
cell, read back with meshio and pyvista; 3-D cells are VTK polyhedra whose volumes VTK
measures as ours; a ``.pvd`` lists the load steps or frames with their times.

The fields are checked on patch tests, whose exact values are known: a linear
displacement ``A x + b`` imposed on the whole boundary is reproduced at the nodes, at
the cell vertices and in the constant stress of every cell.
"""

from __future__ import annotations

import meshio
import numpy as np
import pytest

import cnem
import cnem.io
from cnem import config, pd
from cnem.errors import FormatError, InputError, PlotInputError
from cnem.material import LinearElastic, NeoHookean
from cnem.solvers.series import write_pvd

pv = pytest.importorskip("pyvista")

E, NU = 3.0, 0.3
A2 = np.array([[0.3, -0.2], [0.05, -0.4]]) * 1e-2
A3 = np.array([[0.3, -0.2, 0.1], [0.05, -0.4, 0.25], [0.15, 0.2, 0.35]]) * 1e-2


def _linear(A):
    return lambda p: p @ A.T + 1e-3


def _full_tensor(A, dim):
    """The exact stress and (tensor) strain of ``A x + b``, 3 x 3 (in-plane in 2-D)."""
    eps = 0.5 * (A + A.T)
    C = LinearElastic(E, NU).elasticity_matrix(3) if dim == 3 else \
        cnem.material.stiffness_matrix(E, NU, "strain")
    pairs = cnem.solvers.solution.VOIGT[dim]
    voigt = np.array([eps[i, j] * (1 if i == j else 2) for i, j in pairs])
    stress_voigt = C.reshape(len(pairs), len(pairs)) @ voigt
    stress, strain = np.zeros((3, 3)), np.zeros((3, 3))
    for k, (i, j) in enumerate(pairs):
        stress[i, j] = stress[j, i] = stress_voigt[k]
        strain[i, j] = strain[j, i] = eps[i, j]
    return stress, strain


@pytest.fixture(scope="module")
def plane():
    model = cnem.discretize(cnem.nodes.irregular(cnem.geometry.rectangle(1.0, 0.6), 0.1, seed=2))
    prob = cnem.Elasticity(model, (E, NU), plane="strain")
    prob.add_dirichlet(np.unique(prob.boundary_edges()[0]), None, _linear(A2))
    return prob.solve(progress=False)


@pytest.fixture(scope="module")
def solid():
    model = cnem.discretize(cnem.nodes.irregular(cnem.geometry.box((0, 0, 0), (1.0, 0.8, 0.6)),
                                                 0.25, seed=3))
    prob = cnem.Elasticity(model, (E, NU))
    faces, _ = prob.boundary_edges()
    prob.add_dirichlet(np.unique(faces), None, _linear(A3))
    return prob.solve(progress=False)


def _cells_in_order(mesh, name):
    """Cell data ``name`` of the integration cells in the order of ``model.cells``."""
    cell = np.concatenate(mesh.cell_data["cell"])
    values = np.concatenate(mesh.cell_data[name])
    keep = cell >= 0                                   # not the node vertex cells (2-D)
    out = np.empty_like(values[keep])
    out[cell[keep]] = values[keep]
    return out


@pytest.mark.parametrize("case", ["plane", "solid"])
def test_vtu_fields_read_back_with_meshio(case, request, tmp_path):
    sol = request.getfixturevalue(case)
    model, dim = sol.model, sol.u.shape[1]
    A = A2 if dim == 2 else A3
    n, m = len(model.nodes), len(model.cells)
    mesh = meshio.read(sol.write(tmp_path / f"{case}.vtu"))
    vertices, _ = cnem.io.cell_points(model)
    assert len(mesh.points) == n + len(vertices)
    # displacement: 3 components everywhere, z = 0 in 2-D, the linear field at the nodes
    # and (up to the nudge inside the cells) at the cell vertices
    u = mesh.point_data["displacement"]
    assert u.shape == (n + len(vertices), 3) and np.isfinite(u).all()
    np.testing.assert_allclose(u[:n, :dim], sol.u, rtol=0, atol=1e-12)
    if dim == 2:
        assert (u[:, 2] == 0).all()
    exact = _linear(A)(mesh.points[n:, :dim])
    nudge = 10 * config.VERTEX_NUDGE * np.abs(A).max() * np.ptp(model.nodes, axis=0).max()
    np.testing.assert_allclose(u[n:, :dim], exact, rtol=0, atol=nudge + 1e-12)
    # tensors: 9 named components, symmetric, the exact constant stress and strain
    stress_exact, strain_exact = _full_tensor(A, dim)
    for name, exact in (("stress", stress_exact), ("strain", strain_exact)):
        values = _cells_in_order(mesh, name)
        assert values.shape == (m, 9), name
        np.testing.assert_allclose(values.reshape(m, 3, 3),
                                   np.broadcast_to(exact, (m, 3, 3)),
                                   rtol=0, atol=1e-9 * np.abs(exact).max(), err_msg=name)
    np.testing.assert_array_equal(_cells_in_order(mesh, "von_mises"), sol.von_mises)
    # one row of cell data per cell of the file, the integration cells each once
    for name, blocks in mesh.cell_data.items():
        assert [len(b) for b in blocks] == [len(c) for c in mesh.cells], name
    kinds = {b.type.rstrip("0123456789") for b in mesh.cells}
    assert kinds == ({"vertex", "polygon"} if dim == 2 else {"polyhedron"})
    assert sorted(_cells_in_order(mesh, "node")) == sorted(model.cells.node)


@pytest.mark.parametrize("case", ["plane", "solid"])
def test_vtu_reads_in_pyvista_and_warps(case, request, tmp_path):
    sol = request.getfixturevalue(case)
    model = sol.model
    grid = pv.read(sol.write(tmp_path / f"{case}.vtu"))
    assert grid.point_data["displacement"].shape[1] == 3
    for name in ("stress", "strain"):
        assert grid.cell_data[name].shape == (grid.n_cells, 9)
    assert grid.cell_data["von_mises"].ndim == 1
    extra = len(model.nodes) if sol.u.shape[1] == 2 else 0     # the 2-D node vertex cells
    assert grid.n_cells == len(model.cells) + extra
    warped = grid.warp_by_vector("displacement", factor=2.0)
    np.testing.assert_allclose(warped.points, grid.points + 2.0 * grid.point_data["displacement"],
                               rtol=0, atol=1e-12)
    if sol.u.shape[1] == 3:                 # VTK measures the polyhedra as our cells
        order = grid.cell_data["cell"]
        volume = grid.compute_cell_sizes(length=False, area=False)["Volume"]
        np.testing.assert_allclose(volume, model.cells.volume[order], rtol=1e-9)
        np.testing.assert_allclose(grid.cell_data["volume"], model.cells.volume[order])


PAIRS = {"xx": (0, 0), "yy": (1, 1), "zz": (2, 2), "yz": (1, 2), "xz": (0, 2), "xy": (0, 1)}


@pytest.mark.parametrize("case", ["plane", "solid"])
def test_tensor_components_and_nodal_stress_of_a_patch(case, request, tmp_path):
    """Beside each tensor, ``<name>_xx`` ... hold its entries (tensor shears); the
    nodal stress is the patch test's constant stress at the nodes and the cell vertices."""
    sol = request.getfixturevalue(case)
    dim, n = sol.u.shape[1], len(sol.model.nodes)
    path = sol.write(tmp_path / f"{case}.vtu")
    mesh, grid = meshio.read(path), pv.read(path)
    for name in ("stress", "strain"):
        full = _cells_in_order(mesh, name).reshape(-1, 3, 3)
        for suffix, (i, j) in PAIRS.items():
            np.testing.assert_array_equal(_cells_in_order(mesh, f"{name}_{suffix}"), full[:, i, j])
            assert grid.cell_data[f"{name}_{suffix}"].shape == (grid.n_cells,)
    np.testing.assert_allclose(_cells_in_order(mesh, "strain_xy"), 0.5 * sol.strain[:, -1],
                               rtol=1e-12)
    nodal = mesh.point_data["stress_nodal"].reshape(-1, 3, 3)
    for suffix, (i, j) in PAIRS.items():
        np.testing.assert_array_equal(mesh.point_data[f"stress_nodal_{suffix}"], nodal[:, i, j])
    exact, _ = _full_tensor(A2 if dim == 2 else A3, dim)
    np.testing.assert_allclose(nodal, np.broadcast_to(exact, nodal.shape),
                               rtol=0, atol=1e-8 * np.abs(exact).max())
    assert grid.point_data["stress_nodal"].shape == (grid.n_points, 9)
    assert n < grid.n_points


def test_nodal_stress_is_the_mean_of_the_cells_of_each_node(tmp_path):
    """Two materials, a non-uniform stress: ``stress_nodal`` at a node is the
    area-weighted mean of the stresses of its cells (two or more on the interface),
    computed here node by node; at the cell vertices it interpolates the nodal values."""
    dom = cnem.Domain([[[0, 0], [1, 0], [1, 1], [0, 1]], [[1, 0], [2, 0], [2, 1], [1, 1]]])
    model = cnem.discretize(cnem.nodes.irregular(dom, 0.2, seed=1))
    prob = cnem.Elasticity(model, [(1.0, 0.3), (4.0, 0.25)], plane="strain")
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None)
    prob.add_traction(lambda x, n: x[:, 0] > 2 - 1e-9, [0.3, 1.0])
    sol = prob.solve(progress=False)
    n, cells = len(model.nodes), model.cells
    assert np.bincount(cells.node, minlength=n).max() > 1           # interface nodes
    mesh = meshio.read(sol.write(tmp_path / "two.vtu"))
    stress = _cells_in_order(mesh, "stress").reshape(-1, 3, 3)
    assert np.ptp(stress[:, 0, 1]) > 0.1 * np.abs(stress).max()     # not a constant field
    hand = np.empty((n, 3, 3))
    for node in range(n):
        mine = cells.node == node
        hand[node] = np.tensordot(cells.area[mine], stress[mine], axes=1) / cells.area[mine].sum()
    nodal = mesh.point_data["stress_nodal"].reshape(-1, 3, 3)
    np.testing.assert_allclose(nodal[:n], hand, rtol=1e-12, atol=1e-14 * np.abs(hand).max())
    vertices, cell = cnem.io.cell_points(model)
    inside = vertices + config.VERTEX_NUDGE * (model.nodes[cells.node[cell]] - vertices)
    interpolated = model.shape_functions(inside) @ hand.reshape(n, 9)
    np.testing.assert_allclose(nodal[n:].reshape(-1, 9), interpolated, rtol=1e-12,
                               atol=1e-14 * np.abs(hand).max())


def _pulled_cracked_plate(cracks, seed):
    """A unit square with ``cracks``, clamped at the bottom and pulled up at the top."""
    dom = cnem.geometry.rectangle(1.0, 1.0, cracks=cracks)
    model = cnem.discretize(cnem.nodes.irregular(dom, 0.1, seed=seed))
    prob = cnem.Elasticity(model, (E, NU), plane="strain")
    prob.add_dirichlet(lambda p: p[:, 1] < 1e-9, None)
    prob.add_traction(lambda x, n: x[:, 1] > 1 - 1e-9, [0.0, 1.0])
    return prob.solve(progress=False)


def test_cracked_cells_warp_with_their_own_side(tmp_path):
    """In a cracked model every polygon has its own vertices, each with the displacement
    inside that polygon, so the crack faces part in ParaView's Warp By Vector (shared
    vertices took one face's displacement for both)."""
    sol = _pulled_cracked_plate([[[0.0, 0.5], [0.5, 0.5]]], seed=1)
    model = sol.model
    mesh = meshio.read(sol.write(tmp_path / "crack.vtu"))
    u = mesh.point_data["displacement"][:, :2]
    n, cells = len(model.nodes), model.cells
    for block, ids in zip(mesh.cells[1:], mesh.cell_data["cell"][1:]):
        corners = mesh.points[block.data, :2]                          # (b, k, 2)
        node = model.nodes[cells.node[ids]][:, None, :]
        inside = (corners + config.VERTEX_NUDGE * (node - corners)).reshape(-1, 2)
        np.testing.assert_allclose(u[block.data.reshape(-1)], sol.displacement(inside),
                                   rtol=0, atol=1e-12 * np.abs(sol.u).max())
    points = np.round(mesh.points[n:, :2], 12)
    _, first, group = np.unique(points, axis=0, return_index=True, return_inverse=True)
    jump = np.linalg.norm(u[n:] - u[n:][first[group.reshape(-1)]], axis=1)
    on_crack = np.isclose(points[:, 1], 0.5) & (points[:, 0] < 0.45)
    assert jump[on_crack].max() > 0.1 * np.abs(sol.u).max()          # the faces part
    assert jump[~on_crack & (np.abs(points[:, 1] - 0.5) > 0.05)].max() < 1e-6 * np.abs(sol.u).max()


def test_a_3d_file_is_not_read_as_2d_cells(solid, tmp_path):
    with pytest.raises(FormatError, match="polyhedra of a 3-D model"):
        cnem.io.read(solid.write(tmp_path / "s.vtu"))


def test_hyperelastic_load_steps_as_a_pvd_series(tmp_path):
    """A homogeneous deformation imposed on the boundary: after load step k of 3 the
    displacement is (k/3) (F - I) X at every point of the file (nodes and cell vertices)."""
    F = np.array([[1.3, 0.2], [0.1, 0.9]])
    model = cnem.discretize(cnem.nodes.irregular(cnem.geometry.rectangle(1.0, 0.6), 0.15, seed=1))
    prob = cnem.Hyperelasticity(model, NeoHookean(1.0, 1.0), plane="strain")
    prob.add_dirichlet(np.unique(prob.boundary_edges()[0]), None, _linear(F - np.eye(2)))
    sol = prob.solve(steps=3)
    assert [factor for factor, _ in sol.steps] == [1 / 3, 2 / 3, 1.0]
    path = sol.write(tmp_path / "out" / "run.pvd")
    reader = pv.get_reader(str(path))
    assert reader.time_values == [1 / 3, 2 / 3, 1.0]
    n = len(model.nodes)
    for k, time in enumerate(reader.time_values, start=1):
        reader.set_active_time_value(time)
        grid = reader.read()[0]
        mesh = meshio.read(tmp_path / "out" / f"run_{k - 1}.vtu")
        u = mesh.point_data["displacement"]
        np.testing.assert_array_equal(u, grid.point_data["displacement"])
        exact = k / 3 * _linear(F - np.eye(2))(mesh.points[:, :2])
        np.testing.assert_allclose(u[:n, :2], exact[:n], atol=1e-9)
        np.testing.assert_allclose(u[n:, :2], exact[n:], atol=1e-5)
        Fk = np.eye(2) + k / 3 * (F - np.eye(2))
        F9 = _cells_in_order(mesh, "F").reshape(-1, 3, 3)
        np.testing.assert_allclose(F9[:, :2, :2], np.broadcast_to(Fk, (len(F9), 2, 2)), atol=1e-9)
        np.testing.assert_array_equal(F9[:, 2, 2], 1.0)


def test_pd_frames_as_a_pvd_series(tmp_path):
    g = np.arange(0.0, 1.0 + 1e-9, 0.1)
    pts = np.stack(np.meshgrid(g, g[:6], indexing="ij"), -1).reshape(-1, 2)
    prob = pd.Problem(pd.Body(pts, 0.01, 0.3015), pd.BondBased(1.0))
    v0 = lambda p: 1e-3 * np.column_stack([np.sin(np.pi * p[:, 0]), 0 * p[:, 1]])
    run = prob.run_dynamic(0.5 * prob.stable_time_step(), 20, velocity=v0, every=5, progress=False)
    reader = pv.get_reader(str(run.write(tmp_path / "pd.pvd")))
    assert len(reader.time_values) == len(run.frames) == 5
    np.testing.assert_allclose(reader.time_values, run.times)
    assert np.all(np.diff(reader.time_values) > 0)
    for time, (u, damage) in zip(run.times, run.frames):
        reader.set_active_time_value(time)
        grid = reader.read()[0]
        np.testing.assert_array_equal(grid.point_data["displacement"][:, :2], u)
        assert (grid.point_data["displacement"][:, 2] == 0).all()
        np.testing.assert_array_equal(grid.point_data["damage"], damage)
        assert grid.point_data["stress"].shape == (len(pts), 9)


def test_pvd_times_must_increase(tmp_path):
    with pytest.raises(InputError, match="strictly increasing"):
        write_pvd(tmp_path / "a.pvd", [(1.0, "a.vtu"), (1.0, "b.vtu")])
    with pytest.raises(InputError, match=r"\.pvd"):
        write_pvd(tmp_path / "a.vtu", [(1.0, "a.vtu")])


def test_3d_picture(solid, tmp_path):
    path = tmp_path / "box.png"
    sol = solid
    sol.plot(path, field="von_mises", window_size=(400, 300), length_unit="mm").close()
    assert path.stat().st_size > 1000
    image = pv.read(str(path))
    colours = np.unique(np.asarray(image.point_data[image.array_names[0]]).reshape(-1, 3), axis=0)
    assert len(colours) > 20                           # a coloured body, not a blank window
    sol.plot(tmp_path / "uz.png", field="uz", clip=None, window_size=(300, 200)).close()
    with pytest.raises(PlotInputError, match="clip"):
        sol.plot(tmp_path / "bad.png", clip="w")
    with pytest.raises(PlotInputError, match="field"):
        sol.plot(tmp_path / "bad.png", field="gxy")


def test_crack_face_ids_pair_the_copies_by_the_crack_normal(tmp_path):
    """``crack_face`` is +-(k + 1) on the two copies of each crack-face node of crack k,
    + on the side its normal (``b - a`` turned counter-clockwise) points to: crack 0
    runs left to right (normal up), crack 1 right to left (normal down)."""
    cracks = [[[0.3, 0.6], [0.7, 0.6]], [[0.7, 0.3], [0.3, 0.3]]]
    sol = _pulled_cracked_plate(cracks, seed=2)
    model = sol.model
    mesh = meshio.read(sol.write(tmp_path / "faces.vtu"))
    n = len(model.nodes)
    face = mesh.point_data["crack_face"]
    assert face.shape == (len(mesh.points),) and np.issubdtype(face.dtype, np.integer)
    assert not face[n:].any()
    copies = np.bincount(model.node_of_point)[model.node_of_point] > 1
    assert np.array_equal(face[:n] != 0, copies)
    owner = np.concatenate(mesh.cell_data["node"][1:])
    corners = [block.data for block in mesh.cells[1:]]
    for k, y in enumerate((0.6, 0.3)):
        plus, minus = np.flatnonzero(face == k + 1), np.flatnonzero(face == -(k + 1))
        assert len(plus) == len(minus) >= 3
        order_p = np.lexsort(mesh.points[plus, :2].T)
        order_m = np.lexsort(mesh.points[minus, :2].T)
        np.testing.assert_array_equal(mesh.points[plus[order_p]], mesh.points[minus[order_m]])
        np.testing.assert_allclose(mesh.points[plus, 1], y, atol=1e-12)
        up = 1.0 if k == 0 else -1.0                       # the crack's normal, y component
        opening = up * (sol.u[plus[order_p], 1] - sol.u[minus[order_m], 1])
        assert opening.min() > 0                           # the + face is the one pulled along n
        for node, sign in [(i, 1.0) for i in plus] + [(i, -1.0) for i in minus]:
            polygons, start = [], 0
            for block in corners:                          # the cells of this node, from the file
                mine = owner[start:start + len(block)] == node
                polygons += list(mesh.points[block[mine].reshape(-1), 1])
                start += len(block)
            assert polygons and (sign * up * (np.array(polygons) - y)).min() >= -1e-9
