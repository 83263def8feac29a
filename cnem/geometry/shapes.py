"""Builders for the domains users need most.

>>> from cnem.geometry import rectangle, annulus
>>> rectangle(2.0, 1.0).area
2.0
>>> round(annulus([1.0, 1.5, 2.0], spacing=0.05).area, 2)
9.42
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from ..errors import GeometryError, check_array
from .domain import Domain

__all__ = ["rectangle", "plate_with_hole", "annulus", "l_shape", "arc"]


def _positive(name, value):
    if not np.isfinite(value) or value <= 0:
        raise GeometryError(f"{name} must be a positive number, received {value!r}")
    return float(value)


def arc(center: ArrayLike, radius: float, start: float, stop: float, spacing: float, *,
        pieces: int | None = None) -> np.ndarray:
    """Points on a circular arc, ends included, about ``spacing`` apart.

    Parameters
    ----------
    center : (2,) array_like
    radius, start, stop, spacing : float
        Angles in radians; the count of pieces depends only on the radius,
        the angle span and the spacing, so arcs of equal radius match.
    pieces : int, optional
        Exact number of chords instead (``spacing`` is then ignored).

    Returns
    -------
    (k, 2) ndarray
    """
    span = stop - start
    if pieces is None:
        _positive("spacing", spacing)
        pieces = max(2, int(np.ceil(abs(span) * radius / spacing)))
    elif int(pieces) < 2:
        raise GeometryError(f"pieces must be an integer >= 2, received {pieces!r}")
    t = np.linspace(start, stop, pieces + 1)
    center = check_array("center", center, shape=(2,), error=GeometryError,
                         fix="pass one point (x, y)")
    return center + radius * np.column_stack([np.cos(t), np.sin(t)])


def rectangle(width: float = 1.0, height: float = 1.0, *, origin: ArrayLike = (0.0, 0.0),
              cracks: Sequence[ArrayLike] = ()) -> Domain:
    """Axis-aligned rectangle ``[x0, x0 + width] x [y0, y0 + height]``.

    Returns
    -------
    Domain
    """
    w, h = _positive("width", width), _positive("height", height)
    x0, y0 = check_array("origin", origin, shape=(2,), error=GeometryError,
                         fix="pass one point (x, y)")
    shell = [[x0, y0], [x0 + w, y0], [x0 + w, y0 + h], [x0, y0 + h]]
    return Domain([shell], cracks=cracks)


def plate_with_hole(width: float = 1.0, height: float = 1.0, radius: float = 0.2, *,
                    center: ArrayLike | None = None, spacing: float | None = None,
                    cracks: Sequence[ArrayLike] = ()) -> Domain:
    """Rectangle ``[0, width] x [0, height]`` with a circular hole.

    Parameters
    ----------
    center : (2,) array_like, optional
        Hole centre, default the plate centre.
    spacing : float, optional
        Length of the chords of the hole, default ``radius / 8``.
    """
    w, h, r = _positive("width", width), _positive("height", height), _positive("radius", radius)
    c = check_array("center", [w / 2, h / 2] if center is None else center, shape=(2,),
                    error=GeometryError, fix="pass one point (x, y)")
    if (c - r < 0).any() or c[0] + r > w or c[1] + r > h:
        raise GeometryError(f"the hole (centre {c.tolist()}, radius {r}) does not fit inside "
                            f"the plate [0, {w}] x [0, {h}]; make it smaller or move it")
    ring = arc(c, r, 0.0, 2 * np.pi, spacing or r / 8)[:-1]
    shell = [[0, 0], [w, 0], [w, h], [0, h]]
    return Domain([(shell, [ring[::-1]])], cracks=cracks)


def annulus(radii: Sequence[float], *, angles: Sequence[float] | None = None,
            center: ArrayLike = (0.0, 0.0), spacing: float | None = None,
            segments: int | None = None, cracks: Sequence[ArrayLike] = ()) -> Domain:
    """Concentric annular regions (a multi-material cylinder section).

    Parameters
    ----------
    radii : sequence of float
        Increasing radii ``r_0 < r_1 < ... < r_k``; region ``i`` lies between
        ``r_i`` and ``r_{i+1}``, so the inner radii are material interfaces.
    angles : (2,) sequence of float, optional
        ``(start, stop)`` in radians for a sector; default a full annulus.
    spacing : float, optional
        Chord length of the arcs, default ``(r_k - r_0) / 10``.
    segments : int, optional
        The same number of chords on every arc instead (polar node lattices).
    """
    radii = check_array("radii", radii, shape=(None,), error=GeometryError,
                        fix="pass increasing radii (r_0, r_1, ...)")
    center = check_array("center", center, shape=(2,), error=GeometryError,
                         fix="pass one point (x, y)")
    if radii.ndim != 1 or len(radii) < 2 or radii[0] <= 0 or (np.diff(radii) <= 0).any():
        raise GeometryError(f"radii must be >= 2 positive increasing numbers, received {radii}")
    spacing = spacing or (radii[-1] - radii[0]) / 10
    regions = []
    for r_in, r_out in zip(radii[:-1], radii[1:]):
        if angles is None:
            outer = arc(center, r_out, 0, 2 * np.pi, spacing, pieces=segments)[:-1]
            inner = arc(center, r_in, 0, 2 * np.pi, spacing, pieces=segments)[:-1]
            regions.append((outer, [inner[::-1]]))
        else:
            a0, a1 = check_array("angles", angles, shape=(2,), error=GeometryError,
                                 fix="pass (start, stop) in radians")
            if not 0 < a1 - a0 < 2 * np.pi:
                raise GeometryError(f"angles must satisfy 0 < stop - start < 2 pi, received {angles}")
            outer = arc(center, r_out, a0, a1, spacing, pieces=segments)
            inner = arc(center, r_in, a0, a1, spacing, pieces=segments)[::-1]
            regions.append(np.concatenate([outer, inner]))
    return Domain(regions, cracks=cracks)


def l_shape(size: float = 1.0, cut: float = 0.5, *, cracks: Sequence[ArrayLike] = ()) -> Domain:
    """Square ``[0, size]^2`` without its top-right ``cut x cut`` corner."""
    s, c = _positive("size", size), _positive("cut", cut)
    if c >= s:
        raise GeometryError(f"cut ({c}) must be smaller than size ({s})")
    shell = [[0, 0], [s, 0], [s, s - c], [s - c, s - c], [s - c, s], [0, s]]
    return Domain([shell], cracks=cracks)
