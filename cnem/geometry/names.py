"""Named boundaries: a name stands for a set of boundary pieces of a domain (segments
in 2-D), so that conditions can say ``where="clamp"``.

A name is checked once against the domain (its pieces must lie on the domain's region
boundaries: the outer boundary, holes or interfaces) and later picks points by their
distance to its pieces, within the domain's tolerance (relative to its size): nodes
placed anywhere along a named segment, not only at its ends, are found.

>>> import numpy as np
>>> from cnem.geometry.names import as_named_segments
>>> named = as_named_segments({"left": [[0, 0], [0, 1]], "bottom": [[[0, 0], [1, 0]]]})
>>> {name: seg.shape for name, seg in named.items()}
{'left': (1, 2, 2), 'bottom': (1, 2, 2)}
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import shapely

from .._predicates import Frame
from ..errors import ConditionError, GeometryError, check_real

__all__ = ["as_named_segments", "check_named_segments", "check_region_names", "points_on_segments",
           "unknown_name"]


def _polylines(value, name):
    """The polylines of one name: one ``(k, 2)`` polyline or a list of them (complex
    numbers and booleans refused by name)."""
    what = f"boundaries[{name!r}]"
    check_real(what, value, error=GeometryError)       # a ragged list: each polyline below
    try:
        arr = np.asarray(value, dtype=float)
    except (ValueError, TypeError):
        arr = None                              # ragged: a list of polylines of several lengths
    if arr is not None and arr.ndim == 2:
        return [arr]
    if arr is not None and arr.ndim == 3:
        return list(arr)
    if arr is None and isinstance(value, (list, tuple)):
        return [np.asarray(check_real(f"{what} polyline {k}", v, error=GeometryError),
                           dtype=float) for k, v in enumerate(value)]
    raise GeometryError(f"boundaries[{name!r}]: expected a (k, 2) polyline or a list of them, "
                        f"received {type(value).__name__} of shape {np.shape(value)}")


def as_named_segments(boundaries: Mapping | None) -> dict[str, np.ndarray]:
    """The segments of each named boundary.

    Parameters
    ----------
    boundaries : mapping of str to polylines, or None
        Each name maps to one ``(k, 2)`` polyline or a list of them (a ``(s, 2, 2)``
        array of segments is a list of two-point polylines).

    Returns
    -------
    dict of str to (s, 2, 2) ndarray
        The segments (start and end point) of each name, in the order given.

    Raises
    ------
    GeometryError
        A name that is not a non-empty string, a polyline of fewer than two points or
        with values that are not finite.
    """
    if boundaries is None:
        return {}
    if not isinstance(boundaries, Mapping):
        raise GeometryError(f"boundaries: expected a mapping of names to polylines, e.g. "
                            f"{{'clamp': [[0, 0], [0, 1]]}}, received {type(boundaries).__name__}")
    named = {}
    for name, value in boundaries.items():
        if not isinstance(name, str) or not name:
            raise GeometryError(f"boundaries: expected names that are non-empty strings, "
                                f"received {name!r}")
        segments = []
        for k, line in enumerate(_polylines(value, name)):
            if line.ndim != 2 or line.shape[1] != 2 or len(line) < 2:
                raise GeometryError(f"boundaries[{name!r}] polyline {k}: expected a (k, 2) array "
                                    f"with k >= 2, received shape {line.shape}")
            if not np.isfinite(line).all():
                raise GeometryError(f"boundaries[{name!r}] polyline {k}: expected finite "
                                    f"coordinates, received NaN or inf")
            segments.append(np.stack([line[:-1], line[1:]], axis=1))
        named[name] = np.concatenate(segments) if segments else np.empty((0, 2, 2))
    return named


def _lines(segments, frame):
    """shapely LineStrings of ``(s, 2, 2)`` segments in the local frame."""
    local = frame.to_local(segments.reshape(-1, 2)).reshape(-1, 2, 2)
    return shapely.linestrings(local)


def check_named_segments(named: dict[str, np.ndarray], regions: Sequence[shapely.Polygon],
                         frame: Frame, tol: float) -> None:
    """Every named segment lies on the boundary of a region within ``tol``.

    Parameters
    ----------
    named : dict of str to (s, 2, 2) ndarray
    regions : sequence of shapely.Polygon
    frame : cnem._predicates.Frame
    tol : float
        Absolute tolerance (global units).

    Raises
    ------
    GeometryError
        Naming the first segment off the boundary and where.
    """
    if not named:
        return
    edges = shapely.union_all([r.boundary for r in regions])
    band = shapely.transform(edges, frame.to_local).buffer(tol / frame.scale)
    shapely.prepare(band)
    for name, segments in named.items():
        if len(segments) == 0:
            raise GeometryError(f"boundaries[{name!r}]: expected at least one segment, "
                                f"received none")
        off = np.flatnonzero(~shapely.covered_by(_lines(segments, frame), band))
        if off.size:
            a, b = segments[off[0]]
            raise GeometryError(
                f"boundaries[{name!r}]: {off.size} of its {len(segments)} segments do not lie on "
                f"the domain's boundary, first from {a.tolist()} to {b.tolist()}; a named "
                "boundary must follow the outer boundary, a hole or an interface: move it onto "
                "them or leave it out")


def points_on_segments(points: np.ndarray, segments: np.ndarray, frame: Frame,
                       tol: float) -> np.ndarray:
    """Which points lie within ``tol`` of any of the segments.

    Parameters
    ----------
    points : (p, 2) ndarray
    segments : (s, 2, 2) ndarray
    frame : cnem._predicates.Frame
        The local frame in which distances are measured.
    tol : float
        Absolute tolerance (global units).

    Returns
    -------
    (p,) bool ndarray
    """
    tree = shapely.STRtree(_lines(segments, frame))
    hit, _ = tree.query(shapely.points(frame.to_local(points)), predicate="dwithin",
                        distance=tol / frame.scale)
    mask = np.zeros(len(points), dtype=bool)
    mask[hit] = True
    return mask


def unknown_name(name: object, known: tuple[str, ...]) -> ConditionError:
    """The error for a boundary name the domain does not know, listing the known ones."""
    if not known:
        return ConditionError(
            f"where={name!r}: the domain has no named boundaries; names come from "
            "Domain.from_file (gmsh physical groups, DXF layers, GeoJSON line features), the "
            "built-in shapes (rectangle: 'left', 'right', 'bottom', 'top', ...) or "
            "Domain(..., boundaries={name: polylines}); else select with a predicate")
    return ConditionError(f"where={name!r}: no boundary of that name; the domain's named "
                          f"boundaries are {', '.join(repr(k) for k in known)}")


def check_region_names(names: object, count: int) -> tuple[str | None, ...]:
    """``names`` as a tuple of one str (or None) per region; None names none."""
    if names is None:
        return (None,) * count
    names = tuple(names)
    if len(names) != count or not all(n is None or isinstance(n, str) for n in names):
        raise GeometryError(f"region_names: expected one str (or None) per region ({count}), "
                            f"received {names!r}")
    return names
