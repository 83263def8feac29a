"""A bracket (an L-shaped plate with a round hole) built by hand, and the same bracket
written as a gmsh, DXF, GeoJSON and WKT file, for the reader and named-boundary tests.

The outline is ``(0, 0) (4, 0) (4, 1) (1.5, 1) (1.5, 3) (0, 3)``; the hole, of radius
0.35 about (0.75, 1.5), is a polygon of ``HOLE_PIECES`` chords. Named boundaries:
``clamp`` (the top of the arm, y = 3), ``load`` (the end, x = 4) and ``hole``.
Every file can be written moved by ``shift`` and scaled by ``scale``
(``x -> scale * x + shift``).
"""

from __future__ import annotations

import json

import numpy as np
import triangle

import cnem
from cnem.geometry.dxf_reader import arc_pieces
from cnem import config

SHELL = np.array([[0, 0], [4, 0], [4, 1], [1.5, 1], [1.5, 3], [0, 3]], dtype=float)
CENTER, RADIUS = np.array([0.75, 1.5]), 0.35
#: the chords the DXF reader makes of the hole (the drawing's diagonal is 5)
HOLE_PIECES = arc_pieces(RADIUS, 2 * np.pi, config.CHORD_TOLERANCE * 5.0)


def hole(scale=1.0, shift=0.0):
    """The hole's vertices, counter-clockwise from angle 0 (as the DXF reader makes them)."""
    return cnem.geometry.arc(scale * CENTER + shift, scale * RADIUS, 0, 2 * np.pi,
                             0.0, pieces=HOLE_PIECES)[:-1]


def by_hand(scale=1.0, shift=0.0):
    """The bracket as a Domain without names."""
    return cnem.Domain([(scale * SHELL + shift, [hole(scale, shift)[::-1]])])


def predicates(scale=1.0, shift=0.0):
    """Node predicates of ``clamp``, ``load`` and ``hole`` for the hand-built bracket
    (edge midpoints on the hole lie at ``RADIUS cos(pi / n)``)."""
    tol = 1e-9 * scale
    return {"clamp": lambda x: np.abs(x[:, 1] - (3 * scale + shift)) < tol,
            "load": lambda x: np.abs(x[:, 0] - (4 * scale + shift)) < tol,
            "hole": lambda x: np.hypot(*(x - (scale * CENTER + shift)).T) < 1.01 * scale * RADIUS}


def write_gmsh(path, scale=1.0, shift=0.0, max_area=0.05):
    """The bracket meshed with triangles (Steiner points on its sides) as MSH 2.2 text, with
    the physical curves ``clamp``, ``load``, ``hole`` and the physical surface ``bracket``."""
    ring = np.concatenate([SHELL, hole()])
    n = len(SHELL)
    seg = [[k, (k + 1) % n] for k in range(n)]
    seg += [[n + k, n + (k + 1) % HOLE_PIECES] for k in range(HOLE_PIECES)]
    mesh = triangle.triangulate({"vertices": ring, "segments": seg, "holes": [CENTER]},
                                f"pqa{max_area}")
    pts, tri = mesh["vertices"], mesh["triangles"]
    edges = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    unique, counts = np.unique(edges, axis=0, return_counts=True)
    boundary = unique[counts == 1]
    a, b = pts[boundary[:, 0]], pts[boundary[:, 1]]
    groups = {1: (a[:, 1] == 3) & (b[:, 1] == 3), 2: (a[:, 0] == 4) & (b[:, 0] == 4),
              3: (np.hypot(*(a - CENTER).T) < 1.01 * RADIUS)
              & (np.hypot(*(b - CENTER).T) < 1.01 * RADIUS)}
    xy = scale * pts + shift
    lines = [f"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n4\n1 1 \"clamp\"\n"
             f"1 2 \"load\"\n1 3 \"hole\"\n2 4 \"bracket\"\n$EndPhysicalNames\n$Nodes\n{len(xy)}"]
    lines += [f"{i + 1} {x!r} {y!r} 0" for i, (x, y) in enumerate(xy.tolist())]
    elements = [(1, tag, e) for tag, pick in groups.items() for e in boundary[pick]]
    elements += [(2, 4, t) for t in tri]
    lines += ["$EndNodes", "$Elements", str(len(elements))]
    lines += [f"{k + 1} {kind} 2 {tag} {tag} " + " ".join(str(v + 1) for v in nodes)
              for k, (kind, tag, nodes) in enumerate(elements)]
    lines.append("$EndElements")
    path.write_text("\n".join(lines) + "\n")
    return path


def write_dxf(path, scale=1.0, shift=0.0):
    """The bracket as DXF: the outline in open LWPOLYLINEs on layer "0" and LINEs on the
    layers ``clamp`` and ``load``, the hole a CIRCLE on layer ``hole``."""
    import ezdxf
    doc = ezdxf.new()
    msp = doc.modelspace()
    p = scale * SHELL + shift
    msp.add_lwpolyline([p[5], p[0], p[1]])
    msp.add_line(p[1], p[2], dxfattribs={"layer": "load"})
    msp.add_lwpolyline([p[2], p[3], p[4]])
    msp.add_line(p[4], p[5], dxfattribs={"layer": "clamp"})
    msp.add_circle(scale * CENTER + shift, scale * RADIUS, dxfattribs={"layer": "hole"})
    doc.saveas(path)
    return path


def write_geojson(path, scale=1.0, shift=0.0):
    """The bracket as a GeoJSON FeatureCollection: the polygon named ``bracket``, the
    named boundaries as LineString features."""
    p, h = scale * SHELL + shift, hole(scale, shift)
    def close(r):
        return np.concatenate([r, r[:1]]).tolist()

    def feature(geometry, name):
        return {"type": "Feature", "geometry": geometry, "properties": {"name": name}}

    data = {"type": "FeatureCollection", "features": [
        feature({"type": "Polygon", "coordinates": [close(p), close(h[::-1])]}, "bracket"),
        feature({"type": "LineString", "coordinates": [p[4].tolist(), p[5].tolist()]}, "clamp"),
        feature({"type": "LineString", "coordinates": [p[1].tolist(), p[2].tolist()]}, "load"),
        feature({"type": "LineString", "coordinates": close(h)}, "hole")]}
    path.write_text(json.dumps(data))
    return path


def write_wkt(path, scale=1.0, shift=0.0):
    """The bracket as a WKT POLYGON (no names)."""
    def ring(r):
        return "(" + ", ".join(f"{x!r} {y!r}" for x, y in np.concatenate([r, r[:1]]).tolist()) + ")"
    path.write_text(f"POLYGON ({ring(scale * SHELL + shift)}, {ring(hole(scale, shift)[::-1])})")
    return path


WRITERS = {"msh": write_gmsh, "dxf": write_dxf, "geojson": write_geojson, "wkt": write_wkt}
