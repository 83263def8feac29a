"""`Domain`: material regions, holes and cracks, validated.

>>> import cnem
>>> dom = cnem.Domain([[0, 0], [1, 0], [1, 1], [0, 1]], cracks=[[[0, 0.5], [0.5, 0.5]]])
>>> dom.area, dom.tips.tolist()
(1.0, [[0.5, 0.5]])
"""

from __future__ import annotations

import os
from collections.abc import Sequence

import numpy as np
import shapely
from shapely.geometry import LineString, MultiPolygon, Polygon
from shapely.geometry.polygon import orient
from shapely.validation import explain_validity
from numpy.typing import ArrayLike

from .. import config
from .._predicates import Frame, local_frame
from ..errors import GeometryError, check_array, check_real
from .names import (as_named_segments, check_named_segments, check_region_names,
                    points_on_segments, unknown_name)
from .pslg import CRACK, PSLG, build_pslg, ring_coordinates

__all__ = ["Domain"]


def _fmt(p):
    return f"({p[0]:.6g}, {p[1]:.6g})"


def _check_ring(coords, what):
    arr = np.asarray(check_real(what, coords, error=GeometryError), dtype=float)
    if arr.ndim != 2 or arr.shape[1] != 2 or len(arr) < 3:
        raise GeometryError(f"{what}: expected a (k, 2) array of at least 3 vertices, "
                            f"received shape {arr.shape}")
    if not np.isfinite(arr).all():
        raise GeometryError(f"{what}: vertices must be finite, received NaN or inf")
    if np.array_equal(arr[0], arr[-1]):      # an explicitly closed ring
        arr = arr[:-1]
    return arr


def _check_zero_length(arr, closed, what, tol):
    nxt = np.roll(arr, -1, axis=0) if closed else arr[1:]
    cur = arr if closed else arr[:-1]
    short = np.flatnonzero(np.linalg.norm(nxt - cur, axis=1) <= tol)
    if short.size:
        k = short[0]
        raise GeometryError(
            f"{what}: zero-length segment between vertex {k} and vertex {(k + 1) % len(arr)} "
            f"at {_fmt(cur[k])}; remove the repeated vertex")


def _check_rings_apart(shell, holes, what, tol):
    """Rings of one polygon that touch (closer than ``tol``): a hole on the shell or on
    another hole. shapely accepts a single touching point, but the body there is
    pinched to nothing and no cloud can resolve it."""
    rings = [shapely.LinearRing(r) for r in [shell] + holes]
    left, right = shapely.STRtree(rings).query(rings, predicate="dwithin", distance=tol)
    for a, b in sorted(zip(left.tolist(), right.tolist())):
        if a >= b:
            continue
        where = _fmt(shapely.shortest_line(rings[a], rings[b]).coords[0])
        if a == 0:
            raise GeometryError(
                f"{what} hole {b - 1} touches the outer boundary at {where}: rings must not "
                "touch; move it inside or merge it into the outline")
        raise GeometryError(
            f"{what} holes {a - 1} and {b - 1} touch at {where}: rings must not touch; move "
            "them apart or merge them into one hole")


def _as_polygon(obj, index, tol):
    """Coerce one region description into a valid, CCW-oriented shapely Polygon."""
    what = f"region {index}"
    if isinstance(obj, Polygon):
        shell = np.asarray(obj.exterior.coords, dtype=float)[:, :2]
        holes = [np.asarray(h.coords, dtype=float)[:, :2] for h in obj.interiors]
    elif isinstance(obj, tuple) and len(obj) == 2:
        shell, holes = obj[0], list(obj[1])
    else:
        shell, holes = obj, []
    shell = _check_ring(shell, f"{what} shell")
    holes = [_check_ring(h, f"{what} hole {k}") for k, h in enumerate(holes)]
    if tol is not None:
        _check_zero_length(shell, True, f"{what} shell", tol)
        for k, h in enumerate(holes):
            _check_zero_length(h, True, f"{what} hole {k}", tol)
    poly = Polygon(shell, holes)
    if tol is not None and holes and poly.is_valid:
        _check_rings_apart(shell, holes, what, tol)
    spread = np.linalg.svd(shell - shell.mean(axis=0), compute_uv=False)
    if spread[-1] <= config.SHAPE_TOL * spread[0]:
        raise GeometryError(f"{what} encloses no area: the {len(shell)} vertices of its shell "
                            f"lie on one line (from {_fmt(shell[0])}); give the corners of a "
                            f"region")
    if not poly.is_valid:
        raise GeometryError(f"{what} is not a valid polygon: {explain_validity(poly)}; "
                            "a ring must not cross or touch itself (bow-tie) and holes must lie "
                            "strictly inside the shell")
    if poly.is_empty or poly.area <= 0:
        raise GeometryError(f"{what}: polygon has zero area; expected a non-degenerate polygon")
    return orient(poly, 1.0)


def _axis_box(polygon):
    """``(xmin, ymin, xmax, ymax)`` if ``polygon`` is an axis-aligned rectangle (no hole,
    every edge along a side of its bounding box), else None."""
    if len(polygon.interiors):
        return None
    x0, y0, x1, y1 = polygon.bounds
    ring = np.asarray(polygon.exterior.coords)
    a, b = ring[:-1], ring[1:]
    vertical = (a[:, 0] == b[:, 0]) & ((a[:, 0] == x0) | (a[:, 0] == x1))
    horizontal = (a[:, 1] == b[:, 1]) & ((a[:, 1] == y0) | (a[:, 1] == y1))
    return (x0, y0, x1, y1) if (vertical | horizontal).all() else None


def _points_xy(points):
    """``points`` as a ``(p, 2)`` float array (one point ``(2,)`` as one row), checked by
    name: real, finite, rows of two."""
    pts = check_array("points", points, error=GeometryError,
                      fix="pass finite real coordinates, one row (x, y) per point")
    if pts.shape == (2,):
        pts = pts[None]
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise GeometryError(f"points: expected a (2,) or (p, 2) array, received shape "
                            f"{pts.shape}")
    return pts


def _is_single_polygon(obj):
    """Whether ``obj`` is one polygon rather than a list of polygons."""
    if isinstance(obj, Polygon):
        return True
    if isinstance(obj, tuple) and len(obj) == 2 and isinstance(obj[1], (list, tuple)) \
            and not np.isscalar(obj[1]) and all(np.ndim(h) == 2 for h in obj[1]) \
            and np.ndim(obj[0]) == 2:
        return True                          # (shell, [hole, ...])
    try:
        arr = np.asarray(obj)            # no float conversion: complex rings are named later
    except (ValueError, TypeError):
        return False
    return arr.ndim == 2 and arr.shape[1] == 2 and arr.dtype.kind != "O"


class Domain:
    """A 2-D body: material regions (with holes) and cracks.

    Parameters
    ----------
    regions : polygon or list of polygons
        A polygon is a ``(k, 2)`` array-like shell, a tuple ``(shell, [hole, ...])``
        or a ``shapely.Polygon``. Region ``i`` is ``regions[i]``. Boundaries that
        two regions share are material interfaces.
    cracks : list of (k, 2) array-like
        Traction-free crack polylines inside the closure of the domain. An end on
        the outer boundary or a hole makes an edge crack; an end inside is a tip.
    boundaries : mapping of str to polylines, optional
        Named boundaries (`boundaries`): each name maps to a ``(k, 2)`` polyline or a
        list of them lying on the outer boundary, a hole or an interface; conditions
        take the names as ``where`` (``prob.add_dirichlet("clamp", None)``).
    region_names : sequence of str or None, optional
        A name for each region (`region_names`), e.g. a gmsh physical surface.

    Raises
    ------
    GeometryError
        Invalid or self-intersecting polygons, overlapping regions, cracks leaving
        the domain or crossing each other, zero-length segments, named boundaries
        off the region boundaries.
    """

    def __init__(self, regions: ArrayLike | Polygon | Sequence[ArrayLike | tuple | Polygon],
                 cracks: Sequence[ArrayLike] = (), *, boundaries: dict | None = None,
                 region_names: Sequence[str | None] | None = None) -> None:
        if isinstance(regions, MultiPolygon):
            regions = list(regions.geoms)
        elif _is_single_polygon(regions):
            regions = [regions]
        elif isinstance(regions, tuple) and len(regions) == 2 and np.ndim(regions[0]) == 2:
            regions = list(regions)              # two regions given as a tuple
        if not isinstance(regions, (list, tuple)):
            raise GeometryError(
                f"regions: expected a polygon ((k, 2) array, (shell, [holes]) or shapely "
                f"Polygon) or a list of them, received {type(regions).__name__}")
        regions = list(regions)
        if len(regions) == 0:
            raise GeometryError("expected at least one region, received an empty list")
        raw = [_as_polygon(r, i, None) for i, r in enumerate(regions)]
        minx, miny, maxx, maxy = shapely.union_all(raw).bounds
        top = max(abs(minx), abs(miny), abs(maxx), abs(maxy))
        if not top < config.COORDINATE_LIMIT:
            raise GeometryError(
                f"regions: expected coordinates below {config.COORDINATE_LIMIT:g} in magnitude "
                f"(squared distances must not overflow float64), received {top:g}; express the "
                "model in other units")
        self._diameter = float(np.hypot(maxx - minx, maxy - miny))
        self._origin = np.array([minx, miny])    # buffers are computed in this local frame
        self._frame = local_frame((minx, miny, maxx, maxy))
        # far from the origin the vertices themselves are known only to their round-off
        self._tol = max(config.SNAP_TOL * self._diameter,
                        config.ROUNDOFF_ULPS * self._frame.resolution * self._frame.scale)
        self._regions = tuple(_as_polygon(r, i, self._tol) for i, r in enumerate(regions))
        self._union = shapely.union_all(self._regions)
        self._check_overlaps()
        if isinstance(cracks, (str, bytes)) or not isinstance(cracks, (list, tuple, np.ndarray)):
            raise GeometryError(f"cracks: expected a list of (k, 2) polylines, received "
                                f"{type(cracks).__name__}; pass e.g. cracks=[[[0, 0.5], "
                                f"[0.5, 0.5]]]")
        self._cracks = tuple(self._check_crack(c, i) for i, c in enumerate(cracks))
        self._check_crack_crossings()
        polylines = [(r, True) for p in self._regions for r in ring_coordinates(p)]
        hints = [-1] * len(polylines)
        polylines += [(c, False) for c in self._cracks]
        hints += [CRACK] * len(self._cracks)
        self._pslg = build_pslg(polylines, hints, self._tol,
                                extra_vertices=self._crack_interface_points())
        self._tips = self._find_tips()
        self._named = as_named_segments(boundaries)
        check_named_segments(self._named, self._regions, self._frame, self._tol)
        self._region_names = check_region_names(region_names, len(self._regions))

    @classmethod
    def from_file(cls, path: str | os.PathLike, **options: float) -> Domain:
        """A 2-D domain read from a geometry file, its named groups kept as `boundaries`.

        Parameters
        ----------
        path : str or os.PathLike
            gmsh ``.msh``, ``.dxf``, ``.geojson`` / ``.json`` or ``.wkt``
            (`cnem.geometry.readers.read_geometry` tells what each gives).
        **options
            ``chord_tolerance`` (DXF): the largest distance between an arc and its
            chords, relative to the drawing's diagonal.

        Raises
        ------
        FormatError
            An unknown suffix or a file that cannot be read as its format.
        GeometryError
            An open or self-intersecting outline (the file is named).
        """
        from .readers import read_geometry
        geometry = read_geometry(path, **options)
        try:
            return cls(geometry["regions"], boundaries=geometry["boundaries"],
                       region_names=geometry["region_names"])
        except GeometryError as exc:
            raise GeometryError(f"{path}: {exc}") from None

    # ------------------------------------------------------------------ checks
    def _check_overlaps(self):
        tree = shapely.STRtree(self._regions)
        left, right = tree.query(self._regions, predicate="intersects")
        scale = max(p.area for p in self._regions)
        for i, j in zip(left, right):
            if i >= j:
                continue
            inter = self._regions[i].intersection(self._regions[j])
            if inter.area > config.OVERLAP_TOL * scale:
                raise GeometryError(
                    f"regions {i} and {j} overlap (area {inter.area:.3g} around "
                    f"{_fmt(inter.representative_point().coords[0])}); regions must only "
                    "share boundaries: subtract one from the other")

    def _check_crack(self, crack, index):
        what = f"crack {index}"
        arr = np.asarray(check_real(what, crack, error=GeometryError), dtype=float)
        if arr.ndim != 2 or arr.shape[1] != 2 or len(arr) < 2:
            raise GeometryError(f"{what}: expected a (k, 2) polyline with k >= 2, "
                                f"received shape {arr.shape}")
        if not np.isfinite(arr).all():
            raise GeometryError(f"{what}: vertices must be finite, received NaN or inf")
        _check_zero_length(arr, False, what, self._tol)
        line = LineString(arr - self._origin)
        if not line.is_simple:
            raise GeometryError(f"{what} crosses itself; expected a simple polyline")
        union = shapely.transform(self._union, lambda xy: xy - self._origin)
        outside = line.difference(union.buffer(self._tol))
        if not outside.is_empty:
            where = np.asarray(outside.representative_point().coords[0]) + self._origin
            raise GeometryError(
                f"{what} leaves the domain near {_fmt(where)}; "
                "cracks must lie inside the closure of the domain")
        touch = line.intersection(union.boundary.buffer(self._tol))
        ends = shapely.points(arr[[0, -1]] - self._origin)
        # an end that meets the boundary at a shallow angle theta runs within the
        # tolerance of it for about tol / sin(theta): that approach is the end's, up to
        # config.SHALLOW_END tolerances (angles down to about 1 degree)
        parts = [g for g in getattr(touch, "geoms", [touch]) if not g.is_empty]
        approach = [g for g in parts if min(g.distance(e) for e in ends) <= 2 * self._tol
                    and g.length <= config.SHALLOW_END * self._tol]
        bad = touch.difference(shapely.union_all(list(ends) + approach).buffer(2 * self._tol))
        if not bad.is_empty and bad.length > 2 * self._tol:
            where = np.asarray(bad.representative_point().coords[0]) + self._origin
            raise GeometryError(
                f"{what} touches the outer boundary or a hole away from its ends near "
                f"{_fmt(where)}; only crack ends may lie on it (an end that meets it at less "
                f"than about 1 degree lies along it)")
        return arr

    def _check_crack_crossings(self):
        lines = [LineString(c) for c in self._cracks]
        for i in range(len(lines)):
            for j in range(i + 1, len(lines)):
                if lines[i].distance(lines[j]) <= self._tol:
                    p = lines[i].intersection(lines[j].buffer(self._tol)).representative_point()
                    raise GeometryError(
                        f"cracks {i} and {j} cross or touch near {_fmt(p.coords[0])}; "
                        "expected disjoint cracks (join them into one polyline for a kinked crack)")

    def _crack_interface_points(self):
        """Points where cracks cross interfaces (to become vertices of both)."""
        if not self._cracks or len(self._regions) < 2:
            return np.empty((0, 2))
        inner = shapely.union_all([p.boundary for p in self._regions]).difference(
            self._union.boundary.buffer(self._tol))
        pts = []
        for c in self._cracks:
            inter = LineString(c).intersection(inner)
            for g in getattr(inter, "geoms", [inter]):
                if not g.is_empty:
                    pts.extend(np.asarray(g.coords)[:, :2])
        return np.asarray(pts, dtype=float).reshape(-1, 2)

    def _find_tips(self):
        if not self._cracks:
            return np.empty((0, 2))
        ends = np.concatenate([c[[0, -1]] for c in self._cracks])
        dist = shapely.distance(shapely.points(ends), self._union.boundary)
        return ends[dist > self._tol]

    # -------------------------------------------------------------- properties
    @property
    def regions(self) -> tuple[Polygon, ...]:
        """tuple of shapely.Polygon: the material regions, counter-clockwise."""
        return self._regions

    @property
    def n_regions(self) -> int:
        """int: the number of material regions (as `cnem.Domain3D` has it)."""
        return len(self._regions)

    @property
    def cracks(self) -> tuple[np.ndarray, ...]:
        """tuple of (k, 2) ndarray: the crack polylines."""
        return self._cracks

    @property
    def polygon(self) -> shapely.Geometry:
        """shapely geometry: union of all regions (cracks not cut)."""
        return self._union

    @property
    def pslg(self) -> PSLG:
        """PSLG: vertices and constraint edges (boundaries, interfaces, cracks)."""
        return self._pslg

    @property
    def area(self) -> float:
        """float: total area of the regions."""
        return float(sum(p.area for p in self._regions))

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """(4,) tuple ``(xmin, ymin, xmax, ymax)``."""
        return tuple(float(b) for b in self._union.bounds)

    @property
    def diameter(self) -> float:
        """float: length of the bounding-box diagonal."""
        return self._diameter

    @property
    def tolerance(self) -> float:
        """float: absolute snapping tolerance, ``SNAP_TOL * diameter`` or, far from the
        origin, `cnem.config.ROUNDOFF_ULPS` times the coordinates' round-off if larger
        (a domain 1 across at 1e8 is known only to 1.5e-8)."""
        return self._tol

    @property
    def frame(self) -> Frame:
        """`cnem._predicates.Frame`: the local frame of the domain's bounding box."""
        return self._frame

    @property
    def boundaries(self) -> tuple[str, ...]:
        """tuple of str: the names of the named boundaries (gmsh physical lines, DXF
        layers, the sides of the built-in shapes, ...), usable as ``where``."""
        return tuple(self._named)

    @property
    def region_names(self) -> tuple[str | None, ...]:
        """tuple of str or None: the name of each region (None where unnamed)."""
        return self._region_names

    def boundary_segments(self, name: str) -> np.ndarray:
        """The segments of a named boundary, ``(s, 2, 2)`` (start and end points).

        Raises
        ------
        ConditionError
            An unknown name (the error lists the known ones).
        """
        if name not in self._named:
            raise unknown_name(name, self.boundaries)
        return self._named[name].copy()

    def on_boundary(self, points: ArrayLike, name: str | None = None) -> np.ndarray:
        """Whether points lie on a named boundary (within `tolerance`), or with
        ``name=None`` on the outer boundary or a hole.

        Parameters
        ----------
        points : (p, 2) or (2,) array_like
        name : str, optional

        Returns
        -------
        (p,) bool ndarray

        Raises
        ------
        GeometryError
            Points that are not finite real ``(p, 2)`` coordinates.
        ConditionError
            An unknown name (the error lists the known ones).
        """
        pts = _points_xy(points)
        if name is None:
            ring = shapely.transform(self._union.boundary, self._frame.to_local)
            return shapely.dwithin(ring, shapely.points(self._frame.to_local(pts)),
                                   self._tol / self._frame.scale)
        if name not in self._named:
            raise unknown_name(name, self.boundaries)
        return points_on_segments(pts, self._named[name], self._frame, self._tol)

    @property
    def tips(self) -> np.ndarray:
        """(t, 2) ndarray: crack ends that lie inside the domain."""
        return self._tips

    def tip_frame(self, tip: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """The crack tip nearest to a point, and the crack's direction there.

        Parameters
        ----------
        tip : (2,) array_like
            A point; the nearest crack tip (a crack end inside the domain) is used.

        Returns
        -------
        tip : (2,) ndarray
            The tip.
        direction : (2,) ndarray
            Unit vector along the crack's last segment, pointing out of the crack.
        """
        tips = self.tips
        if len(tips) == 0:
            raise GeometryError("the domain has no crack tip (a crack end inside the body): its "
                                "cracks, if any, end on the boundary; give a crack that ends inside")
        tip = check_array("tip", tip, shape=(2,), error=GeometryError,
                          fix="pass one point (x, y) near the crack tip")
        at = tips[np.argmin(np.hypot(*(tips - tip).T))]
        for crack in self.cracks:
            for end, before in ((crack[-1], crack[-2]), (crack[0], crack[1])):
                if np.array_equal(end, at):
                    d = end - before
                    return at.copy(), d / np.hypot(*d)
        raise AssertionError("a tip that is no crack end")      # pragma: no cover

    def contains(self, points: ArrayLike) -> np.ndarray:
        """Whether points lie in the closed domain.

        Parameters
        ----------
        points : (p, 2) array_like

        Returns
        -------
        (p,) bool ndarray
        """
        return self.region_of(points) >= 0

    def region_of(self, points: ArrayLike) -> np.ndarray:
        """Index of the region (closure) containing each point, -1 outside.

        Parameters
        ----------
        points : (p, 2) array_like

        Returns
        -------
        (p,) int64 ndarray
            The lowest region index for points on an interface.
        """
        pts = _points_xy(points)
        out = np.full(len(pts), -1, dtype=np.int64)
        for i in reversed(range(len(self._regions))):
            box = _axis_box(self._regions[i])
            if box is None:
                shapely.prepare(self._regions[i])
                inside = shapely.intersects_xy(self._regions[i], pts[:, 0], pts[:, 1])
            else:        # the same closed set, by exact comparisons (tens of times faster)
                inside = ((pts[:, 0] >= box[0]) & (pts[:, 0] <= box[2])
                          & (pts[:, 1] >= box[1]) & (pts[:, 1] <= box[3]))
            out[inside] = i
        return out

    def __repr__(self):
        holes = sum(len(p.interiors) for p in self._regions)
        counts = [(len(self._regions), "region"), (holes, "hole"), (len(self._cracks), "crack")]
        text = ", ".join(f"{k} {word}{'s' * (k != 1)}" for k, word in counts)
        tips = len(self._tips)
        return f"<Domain {text} ({tips} tip{'s' * (tips != 1)}), area {self.area:.6g}>"
