"""Geometry files to the arguments of a `cnem.Domain` (behind `cnem.Domain.from_file`).

========================  ==========================================  =======================
suffix                    regions                                     named boundaries
========================  ==========================================  =======================
``.msh`` (gmsh)           physical surfaces (`gmsh_reader`)           physical curves
``.dxf``                  closed outlines, nested (`dxf_reader`)      layers
``.geojson``, ``.json``   Polygon / MultiPolygon features; the        LineString features
                          property ``"name"`` names a region          with a ``"name"``
``.wkt``                  a POLYGON, MULTIPOLYGON or a                none
                          GEOMETRYCOLLECTION of them
========================  ==========================================  =======================

>>> import json, pathlib, tempfile
>>> from cnem.geometry.readers import read_geometry
>>> path = pathlib.Path(tempfile.mkdtemp()) / "square.geojson"
>>> _ = path.write_text(json.dumps({"type": "Polygon",
...                                 "coordinates": [[[0, 0], [2, 0], [2, 1], [0, 1], [0, 0]]]}))
>>> geometry = read_geometry(path)
>>> len(geometry["regions"]), geometry["boundaries"]
(1, {})
"""

from __future__ import annotations

import json
import os
import pathlib

import numpy as np
import shapely
from shapely.geometry import shape

from ..errors import FormatError

__all__ = ["read_geometry", "SUFFIXES"]


def _polygon_parts(geom):
    """The polygons of a Polygon or MultiPolygon, as ``(shell, holes)``."""
    parts = geom.geoms if isinstance(geom, shapely.MultiPolygon) else [geom]
    return [(np.asarray(p.exterior.coords)[:-1, :2],
             [np.asarray(h.coords)[:-1, :2] for h in p.interiors]) for p in parts]


def _lines(geom):
    """The ``(k, 2)`` polylines of a LineString or MultiLineString."""
    parts = geom.geoms if isinstance(geom, shapely.MultiLineString) else [geom]
    return [np.asarray(p.coords)[:, :2] for p in parts]


def _features(data, path):
    """``(geometry dict, properties)`` of every feature of a GeoJSON object."""
    kind = data.get("type") if isinstance(data, dict) else None
    if kind == "FeatureCollection":
        return [pair for f in data.get("features", []) for pair in _features(f, path)]
    if kind == "Feature":
        return [(data.get("geometry"), data.get("properties") or {})]
    if kind == "GeometryCollection":
        return [(g, {}) for g in data.get("geometries", [])]
    if kind in ("Polygon", "MultiPolygon", "LineString", "MultiLineString", "Point",
                "MultiPoint"):
        return [(data, {})]
    raise FormatError(f"{path}: expected a GeoJSON FeatureCollection, Feature or geometry, "
                      f"received an object of type {kind!r}")


def read_geojson(path: str | os.PathLike) -> dict:
    """Regions (Polygon, MultiPolygon: one region per polygon, named by the feature's
    ``"name"`` property) and named boundaries (LineString, MultiLineString features with
    a ``"name"``) of a GeoJSON file."""
    try:
        data = json.loads(pathlib.Path(path).read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise FormatError(f"{path}: cannot read it as GeoJSON ({exc}); expected a JSON file "
                          "holding a FeatureCollection, a Feature or a Polygon") from None
    regions, region_names, boundaries = [], [], {}
    for k, (geometry, properties) in enumerate(_features(data, path)):
        name = properties.get("name")
        try:
            geom = shape(geometry)
        except Exception as exc:           # shapely raises GEOSException, ValueError, KeyError
            raise FormatError(f"{path}: feature {k} has no valid geometry ({exc})") from None
        if isinstance(geom, (shapely.Polygon, shapely.MultiPolygon)):
            parts = _polygon_parts(geom)
            regions += parts
            region_names += [None if name is None else str(name)] * len(parts)
        elif isinstance(geom, (shapely.LineString, shapely.MultiLineString)):
            if name is None:
                raise FormatError(f"{path}: feature {k} is a line without a \"name\" property; "
                                  "lines name boundaries: give it {\"name\": \"clamp\"}, say")
            boundaries.setdefault(str(name), []).extend(_lines(geom))
        else:
            raise FormatError(f"{path}: feature {k} is a {geom.geom_type}; expected Polygon or "
                              "MultiPolygon (regions) and named LineString (boundaries)")
    if not regions:
        raise FormatError(f"{path}: holds no Polygon or MultiPolygon; expected at least one")
    return {"regions": regions, "boundaries": boundaries, "region_names": region_names}


def read_wkt(path: str | os.PathLike) -> dict:
    """Regions of a WKT file: one POLYGON, MULTIPOLYGON or GEOMETRYCOLLECTION of them
    (one region per polygon)."""
    try:
        geom = shapely.from_wkt(pathlib.Path(path).read_text().strip())
    except (OSError, UnicodeDecodeError, shapely.errors.GEOSException) as exc:
        raise FormatError(f"{path}: cannot read it as WKT ({exc}); expected text such as "
                          "POLYGON ((0 0, 1 0, 1 1, 0 1, 0 0))") from None
    parts = getattr(geom, "geoms", [geom]) if geom is not None else []
    bad = [g.geom_type for g in parts if not isinstance(g, (shapely.Polygon, shapely.MultiPolygon))]
    if bad or not parts:
        raise FormatError(f"{path}: expected POLYGON or MULTIPOLYGON geometries, received "
                          f"{', '.join(bad) or 'none'}")
    regions = [r for g in parts for r in _polygon_parts(g)]
    return {"regions": regions, "boundaries": {}, "region_names": [None] * len(regions)}


def _gmsh(path):
    from .gmsh_reader import read_gmsh
    return read_gmsh(path)


def _dxf(path, **options):
    from .dxf_reader import read_dxf
    return read_dxf(path, **options)


#: The readers by file suffix (lower case).
SUFFIXES = {".msh": _gmsh, ".dxf": _dxf, ".geojson": read_geojson, ".json": read_geojson,
            ".wkt": read_wkt}


def read_geometry(path: str | os.PathLike, **options: float) -> dict:
    """The regions, named boundaries and region names a geometry file gives.

    Parameters
    ----------
    path : str or os.PathLike
        Its suffix picks the format (see the module's table).
    **options
        ``chord_tolerance`` for DXF (`cnem.geometry.dxf_reader.read_dxf`).

    Returns
    -------
    dict
        ``regions``: list of ``(shell (k, 2), [hole (k, 2), ...])``; ``boundaries``:
        name -> ``(s, 2, 2)`` segments or a list of ``(k, 2)`` polylines;
        ``region_names``: one str or None per region.

    Raises
    ------
    FormatError
        An unknown suffix, a missing or unreadable file, an option the format does
        not take.
    """
    path = pathlib.Path(path)
    suffix = path.suffix.lower()
    if suffix not in SUFFIXES:
        raise FormatError(f"unknown geometry file suffix {suffix or '(none)'!r} in {str(path)!r}; "
                          f"supported: {', '.join(SUFFIXES)} (gmsh, DXF, GeoJSON, WKT); save "
                          "the geometry in one of them")
    if not path.is_file():
        raise FormatError(f"no geometry file {str(path)!r}; expected an existing "
                          f"{suffix} file")
    if options and suffix != ".dxf":
        raise FormatError(f"{', '.join(options)}: options of DXF files only, received for "
                          f"{suffix}; leave them out")
    return SUFFIXES[suffix](path, **options)
