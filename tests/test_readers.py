"""`cnem.Domain.from_file`: gmsh, DXF, GeoJSON and WKT files give the domain built by hand
(area, vertices), their named groups as boundaries, at any origin and in any units; bad
files raise named errors that say what was expected."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.spatial import cKDTree

import cnem
from cnem import config
from cnem.geometry.dxf_reader import arc_pieces
from geometry_files import WRITERS, by_hand

NAMES = {"msh": {"clamp", "load", "hole"}, "dxf": {"0", "clamp", "load", "hole"},
         "geojson": {"clamp", "load", "hole"}, "wkt": set()}


def vertices(dom):
    """Every ring vertex of a domain, ``(v, 2)``."""
    return np.concatenate([np.asarray(r.coords)[:-1] for reg in dom.regions
                           for r in [reg.exterior, *reg.interiors]])


def assert_same_domain(read, hand):
    """Same area, same vertices (in any order and from any start) within the tolerance."""
    assert len(read.regions) == len(hand.regions)
    assert read.area == pytest.approx(hand.area, rel=1e-12)
    a, b = vertices(read), vertices(hand)
    assert len(a) == len(b)
    assert cKDTree(a).query(b)[0].max() <= hand.tolerance
    assert cKDTree(b).query(a)[0].max() <= hand.tolerance


@pytest.mark.parametrize("suffix", list(WRITERS))
@pytest.mark.parametrize("scale, shift", [(1.0, 0.0), (1e-3, 1e6)])
def test_each_format_gives_the_bracket_built_by_hand(tmp_path, suffix, scale, shift):
    path = WRITERS[suffix](tmp_path / f"bracket.{suffix}", scale, shift)
    dom = cnem.Domain.from_file(path)
    assert_same_domain(dom, by_hand(scale, shift))
    assert set(dom.boundaries) == NAMES[suffix]
    if suffix in ("msh", "geojson"):
        assert dom.region_names == ("bracket",)
    for name in dom.boundaries:         # every named piece lies on the outline
        seg = dom.boundary_segments(name).reshape(-1, 2)
        assert dom.on_boundary(seg).all()


def test_gmsh_4_1_with_physical_groups(tmp_path):
    """A hand-written MSH 4.1 file: two triangles and a mid-side node on the bottom (not
    a corner), a physical curve on the left side and a physical surface."""
    text = """$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
2
1 1 "clamp"
2 2 "plate"
$EndPhysicalNames
$Entities
0 4 1 0
1 0 0 0 0 1 0 1 1 0
2 0 0 0 2 0 0 0 0
3 2 0 0 2 1 0 0 0
4 0 1 0 2 1 0 0 0
1 0 0 0 2 1 0 1 2 4 1 2 3 4
$EndEntities
$Nodes
1 5 1 5
2 1 0 5
1
2
3
4
5
0 0 0
2 0 0
2 1 0
0 1 0
1 0 0
$EndNodes
$Elements
2 4 1 4
1 1 1 1
1 4 1
2 1 2 3
2 1 5 3
3 5 2 3
4 1 3 4
$EndElements
"""
    path = tmp_path / "square.msh"
    path.write_text(text)
    dom = cnem.Domain.from_file(path)
    assert dom.boundaries == ("clamp",) and dom.region_names == ("plate",)
    assert_same_domain(dom, cnem.geometry.rectangle(2.0, 1.0))
    assert dom.on_boundary([[0.0, 0.3], [1.0, 0.0]], "clamp").tolist() == [True, False]


def test_gmsh_without_surfaces_closes_its_lines(tmp_path):
    """Only line elements (a physical curve for the whole outline): they must close."""
    nodes = "\n".join(f"{i + 1} {x} {y} 0" for i, (x, y) in
                      enumerate([(0, 0), (2, 0), (2, 1), (0, 1)]))
    lines = "\n".join(f"{k + 1} 1 2 7 7 {k + 1} {(k + 1) % 4 + 1}" for k in range(4))
    path = tmp_path / "outline.msh"
    path.write_text(f"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n{nodes}\n$EndNodes\n"
                    f"$Elements\n4\n{lines}\n$EndElements\n")
    dom = cnem.Domain.from_file(path)
    assert dom.boundaries == ("7",)                  # an unnamed group: its tag
    assert_same_domain(dom, cnem.geometry.rectangle(2.0, 1.0))
    path.write_text(f"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n{nodes}\n$EndNodes\n"
                    f"$Elements\n3\n{lines.rsplit(chr(10), 1)[0]}\n$EndElements\n")
    with pytest.raises(cnem.GeometryError, match="open"):
        cnem.Domain.from_file(path)


def test_dxf_bulges_and_arcs_lie_on_their_circles(tmp_path):
    """An obround (LWPOLYLINE with two bulges of 1: half circles) and a half disc from a LINE
    and an ARC mirrored by its extrusion: vertices on the circles, chords within the
    tolerance, the fewest chords that keep them so."""
    import ezdxf
    doc = ezdxf.new()
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0, 0), (2, 0, 1), (2, 1, 0), (0, 1, 1)], format="xyb", close=True)
    msp.add_line((-1, 3), (1, 3))
    msp.add_arc((0, 3), 1.0, 0, 180, dxfattribs={"extrusion": (0, 0, -1)})   # OCS x = -x
    path = tmp_path / "arcs.dxf"
    doc.saveas(path)
    dom = cnem.Domain.from_file(path)
    assert len(dom.regions) == 2
    diagonal = np.hypot(3.5, 4.0)                      # box (-1, 0) to (2.5, 4)
    sagitta = config.CHORD_TOLERANCE * diagonal
    for region, (center, radius, sweep) in zip(
            sorted(dom.regions, key=lambda r: r.bounds[1]),
            [([2.0, 0.5], 0.5, np.pi), ([0.0, 3.0], 1.0, np.pi)]):
        ring = np.asarray(region.exterior.coords)[:-1]
        on_arc = np.abs(np.hypot(*(ring - center).T) - radius) < 1e-12
        n = arc_pieces(radius, sweep, sagitta)
        assert radius * (1 - np.cos(sweep / n / 2)) <= sagitta < radius * (1 - np.cos(sweep / (n - 1) / 2))
        assert np.count_nonzero(on_arc) == n + 1
    obround = min(dom.regions, key=lambda r: r.bounds[1])
    x0, y0, x1, y1 = obround.bounds                     # the chords stay inside the arcs
    assert (y0, y1) == (0.0, 1.0) and -0.5 <= x0 <= -0.5 + sagitta and 2.5 - sagitta <= x1 <= 2.5
    half = max(dom.regions, key=lambda r: r.bounds[1])
    assert half.bounds[:3] == pytest.approx((-1.0, 3.0, 1.0), abs=1e-12)
    n = arc_pieces(1.0, np.pi, sagitta)
    assert half.area == pytest.approx(0.5 * n * np.sin(np.pi / n), rel=1e-12)


def test_geojson_regions_by_name_and_multipolygons(tmp_path):
    square = [[[0, 0], [1, 0], [1, 1], [0, 1], [0, 0]]]
    right = [[[1, 0], [2, 0], [2, 1], [1, 1], [1, 0]]]
    data = {"type": "Feature", "properties": {"name": "steel"},
            "geometry": {"type": "MultiPolygon", "coordinates": [square, right]}}
    path = tmp_path / "two.json"
    path.write_text(json.dumps(data))
    dom = cnem.Domain.from_file(path)
    assert dom.region_names == ("steel", "steel") and dom.area == pytest.approx(2.0)


@pytest.mark.parametrize("name, text, error, match", [
    ("shape.step", "", cnem.FormatError, "unknown geometry file suffix"),
    ("broken.msh", "$MeshFormat\n9.9 0 8\n", cnem.FormatError, "gmsh"),
    ("garbage.msh", "garbage", cnem.FormatError, "gmsh"),
    ("broken.dxf", "not a drawing", cnem.FormatError, "DXF"),
    ("broken.geojson", "{", cnem.FormatError, "GeoJSON"),
    ("point.geojson", '{"type": "Point", "coordinates": [0, 0]}', cnem.FormatError, "Polygon"),
    ("line.geojson", '{"type": "LineString", "coordinates": [[0, 0], [1, 0]]}',
     cnem.FormatError, "name"),
    ("broken.wkt", "POLYGON ((0 0, 1", cnem.FormatError, "WKT"),
    ("line.wkt", "LINESTRING (0 0, 1 1)", cnem.FormatError, "POLYGON"),
    ("bowtie.wkt", "POLYGON ((0 0, 1 1, 1 0, 0 1, 0 0))", cnem.GeometryError,
     "bowtie.wkt.*Self-intersection"),
])
def test_bad_files_raise_named_errors(tmp_path, name, text, error, match):
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(error, match=match):
        cnem.Domain.from_file(path)


def test_missing_file_and_options_of_other_formats(tmp_path):
    with pytest.raises(cnem.FormatError, match="no geometry file"):
        cnem.Domain.from_file(tmp_path / "absent.geojson")
    path = WRITERS["wkt"](tmp_path / "bracket.wkt")
    with pytest.raises(cnem.FormatError, match="DXF files only"):
        cnem.Domain.from_file(path, chord_tolerance=1e-4)


def test_dxf_open_and_self_crossing_outlines(tmp_path):
    import ezdxf
    doc = ezdxf.new()
    msp = doc.modelspace()
    msp.add_line((0, 0), (1, 0))
    msp.add_line((1, 0), (1, 1))
    msp.add_line((1, 1), (0, 1))                  # the left side is missing
    open_path = tmp_path / "open.dxf"
    doc.saveas(open_path)
    with pytest.raises(cnem.GeometryError, match="outline is open.*at \\(0, 0\\)"):
        cnem.Domain.from_file(open_path)
    doc = ezdxf.new()
    doc.modelspace().add_lwpolyline([(0, 0), (1, 1), (1, 0), (0, 1)], close=True)
    bowtie = tmp_path / "bowtie.dxf"
    doc.saveas(bowtie)
    with pytest.raises(cnem.GeometryError, match="not a simple closed curve"):
        cnem.Domain.from_file(bowtie)


def test_dxf_chord_tolerance_refines_the_arcs(tmp_path):
    path = WRITERS["dxf"](tmp_path / "bracket.dxf")
    coarse = cnem.Domain.from_file(path)
    fine = cnem.Domain.from_file(path, chord_tolerance=1e-5)
    holes = [len(d.regions[0].interiors[0].coords) - 1 for d in (coarse, fine)]
    assert holes == [arc_pieces(0.35, 2 * np.pi, t * 5.0) for t in (config.CHORD_TOLERANCE, 1e-5)]
    assert holes[1] > holes[0]
    with pytest.raises(cnem.FormatError, match="chord_tolerance"):
        cnem.Domain.from_file(path, chord_tolerance=2.0)
