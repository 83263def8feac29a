"""meshio round trips of the integration cells (cnem.io)."""

import numpy as np
import pytest

import cnem
import cnem.io
from cases import model

#: A small cracked model (graded, two tips), a kinked crack, an edge crack and
#: the bimaterial annulus (an interface node owns one cell per region).
ROUND_TRIP = ["graded_inclined_crack", "kinked_crack_irregular", "edge_crack_regular",
              "annulus_full_irregular", "annulus_sector_regular", "plate_hole_irregular"]


@pytest.mark.parametrize("name", ROUND_TRIP)
def test_round_trip_reproduces_cells_exactly(name, tmp_path):
    _, _, m = model(name)
    n, c = len(m.nodes), m.cells
    u = np.column_stack([np.sin(m.nodes[:, 0]), m.nodes[:, 1] ** 3])
    stress = np.random.default_rng(0).normal(size=(len(c), 3))
    path = cnem.io.write(m, tmp_path / f"{name}.vtu", point_data={"u": u, "id": np.arange(n)},
                         cell_data={"stress": stress})
    back = cnem.io.read(path)
    for field in ("offsets", "node", "region"):
        got = getattr(back, field)
        assert got.dtype == np.int64
        np.testing.assert_array_equal(got, getattr(c, field))
    assert back.vertices.dtype == np.float64
    np.testing.assert_array_equal(back.vertices, c.vertices)      # bit for bit
    np.testing.assert_array_equal(back.area, c.area)
    np.testing.assert_array_equal(back.nodes, m.nodes)
    np.testing.assert_array_equal(back.node_of_point, m.node_of_point)
    np.testing.assert_array_equal(back.point_data["u"], u)
    np.testing.assert_array_equal(back.point_data["id"], np.arange(n))
    np.testing.assert_array_equal(back.cell_data["stress"], stress)
    for i in (0, len(c) // 2, len(c) - 1):
        np.testing.assert_array_equal(back.polygon(i), c.polygon(i))
    np.testing.assert_array_equal(back.cells.area, c.area)


def test_annulus_interface_nodes_own_two_cells_after_round_trip(tmp_path):
    dom, _, m = model("annulus_full_irregular")
    back = cnem.io.read(cnem.io.write(m, tmp_path / "annulus.vtu"))
    assert set(np.unique(back.region)) == {0, 1}
    owners, counts = np.unique(back.node, return_counts=True)
    on_interface = np.abs(np.hypot(*back.nodes[owners[counts == 2]].T) - 1.5) < 1e-9
    assert counts.max() == 2 and on_interface.all() and on_interface.size > 0
    assert abs(back.area.sum() - dom.area) <= 1e-12 * dom.area


def test_file_is_a_vtu_with_nodes_and_polygons(tmp_path):
    import meshio

    _, _, m = model("graded_inclined_crack")
    mesh = meshio.read(cnem.io.write(m, tmp_path / "m.vtu"))
    types = [b.type for b in mesh.cells]
    assert types[0] == "vertex" and len(mesh.cells[0]) == len(m.nodes)
    assert set(types[1:]) == {"polygon"}
    assert sum(len(b) for b in mesh.cells[1:]) == len(m.cells)
    assert mesh.points.shape[1] == 3 and np.all(mesh.points[:, 2] == 0)


def test_write_nodes_triangulation(tmp_path):
    import meshio

    _, _, m = model("kinked_crack_irregular")
    mesh = meshio.read(cnem.io.write_nodes(m, tmp_path / "tri.vtu"))
    np.testing.assert_array_equal(mesh.points[:, :2], m.nodes)
    np.testing.assert_array_equal(mesh.cells_dict["triangle"], m.triangles)
    np.testing.assert_array_equal(mesh.cells_dict["line"], m.segments)


@pytest.mark.parametrize("suffix", [".xdmf", ".vtk", ".msh", ".txt", ""])
def test_bad_suffix_names_supported_ones(suffix, tmp_path):
    _, _, m = model("graded_inclined_crack")
    with pytest.raises(cnem.CNEMError, match=r"\.vtu"):
        cnem.io.write(m, tmp_path / f"cells{suffix}")
    with pytest.raises(cnem.CNEMError, match=r"supported suffixes"):
        cnem.io.read(tmp_path / f"cells{suffix}")


@pytest.mark.parametrize("suffix", [".dxf", ".msh", ".geojson", ".stl"])
def test_a_geometry_file_is_sent_to_domain_from_file(suffix, tmp_path):
    with pytest.raises(cnem.io.FormatError, match=r"Domain\.from_file"):
        cnem.io.read(tmp_path / f"bracket{suffix}")


def test_wrong_lengths_and_reserved_names(tmp_path):
    _, _, m = model("graded_inclined_crack")
    with pytest.raises(cnem.io.FormatError, match=f"{len(m.nodes)} rows"):
        cnem.io.write(m, tmp_path / "a.vtu", point_data={"u": np.zeros(3)})
    with pytest.raises(cnem.io.FormatError, match="reserved"):
        cnem.io.write(m, tmp_path / "a.vtu", cell_data={"area": np.zeros(len(m.cells))})


def test_read_rejects_foreign_file(tmp_path):
    _, _, m = model("graded_inclined_crack")
    path = cnem.io.write_nodes(m, tmp_path / "tri.vtu")
    with pytest.raises(cnem.io.FormatError, match="not written by cnem.io.write"):
        cnem.io.read(path)


def test_a_file_meshio_cannot_parse_is_a_format_error(tmp_path):
    """meshio ends the interpreter (SystemExit) on a file it cannot parse: cnem.io.read
    names the file instead."""
    bad = tmp_path / "garbage.vtu"
    bad.write_text("not a VTU file")
    with pytest.raises(cnem.FormatError, match="could not be read as vtu"):
        cnem.io.read(bad)


def test_triangles_that_index_past_the_points_are_refused(tmp_path):
    pts = np.random.default_rng(0).random((5, 2))
    with pytest.raises(cnem.FormatError, match=r"indices in \[0, 5\), .* indices 0..9"):
        cnem.io.write_points(pts, tmp_path / "p.vtu", cells=[[0, 1, 9]])
    with pytest.raises(cnem.FormatError, match="received shape"):
        cnem.io.write_points(pts, tmp_path / "p.vtu", cells=[[0.0, 1.0, 2.0]])
