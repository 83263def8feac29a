"""Cracks read off a peridynamic damage field on a regular grid of points.

A dynamic PD run (`cnem.pd.Problem.run_dynamic`) stores the damage of every
point; the crack is the set of damaged points connected to where it started.
These functions measure it on a grid image ``image[i, j]``, the point at
``(x0 + i h, y0 + j h)`` (``x`` major, as ``points.reshape(nx, ny, 2)`` of a
grid ordered ``x`` first), for a crack running in the ``+x`` direction from
``start``: its points (`crack_region`), its tip (`crack_tip`), its bands
across ``x`` (`bands`), where it branches and how far apart the branches run
(`branching`), and the times and speeds of the tip (`first_passage`,
`mean_speed`, `local_speeds`). A crack running another way is measured on the
transposed or flipped image.

>>> import numpy as np
>>> image = np.zeros((20, 9))
>>> image[10:16, 4] = 1.0                       # a straight crack from x = 10 to 15
>>> mask = crack_region(image, (0.0, -4.0), 1.0, start=(10.0, 0.0), reach=1.0)
>>> float(crack_tip(mask, (0.0, -4.0), 1.0, start_x=10.0))
15.0
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from scipy import ndimage

from ..errors import GeometryError, check_array
from .._sets import distinct, isin

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

__all__ = ["crack_region", "crack_tip", "bands", "branching", "first_passage", "mean_speed",
           "local_speeds"]

#: Tolerance (in grid spacings) of a point lying on a cell boundary.
_ON_LINE = 1e-9


def _grid(image, origin, spacing):
    """``(x0, y0), h`` of a grid image, checked."""
    if np.ndim(image) != 2:
        raise GeometryError(f"image: expected a 2-D grid image (nx, ny), received shape "
                            f"{np.shape(image)}; reshape the point values with "
                            f"values.reshape(nx, ny)")
    h = float(spacing)
    if not np.isfinite(h) or h <= 0:
        raise GeometryError(f"spacing: expected a positive grid spacing, received {spacing}")
    x0, y0 = (float(c) for c in origin)
    return (x0, y0), h


def _length(name, value, what):
    """``value`` as a positive finite float (a window, a persistence, a reach), or an
    `InputError` naming it: zero would fit nothing and measure nothing."""
    return float(check_array(name, value, shape=(), positive=True, fix=f"pass a positive {what}"))


def _index_at(coordinate, lowest, h):
    """Index of the first grid line at or above ``coordinate``."""
    return int(np.ceil((coordinate - lowest) / h - _ON_LINE))


def crack_region(image: np.ndarray, origin: np.ndarray, spacing: float, start: np.ndarray,
                 reach: float, *, threshold: float = 0.35) -> np.ndarray:
    """The damaged points connected to the start of the crack.

    Points with damage above ``threshold`` are grouped into 8-connected sets;
    the sets with a point among the ``2 r x 2 r`` grid points around
    ``start`` (``r = ceil(reach / h)``, the first point at or above ``start``
    in both directions being the ``(r + 1)``-th) are the crack.

    Parameters
    ----------
    image : (nx, ny) array_like
        Damage of the grid points.
    origin : (2,) array_like
        Coordinates of the point ``image[0, 0]``.
    spacing : float
        Grid spacing ``h``.
    start : (2,) array_like
        Where the crack starts (a notch tip).
    reach : float
        How far from ``start`` a damaged set may begin (typically the horizon).
    threshold : float

    Returns
    -------
    (nx, ny) bool ndarray
    """
    (x0, y0), h = _grid(image, origin, spacing)
    labels, _ = ndimage.label(np.asarray(image) > threshold, structure=np.ones((3, 3)))
    r = int(np.ceil(_length("reach", reach, "distance (typically the horizon)") / h))
    col, row = _index_at(start[0], x0, h), _index_at(start[1], y0, h)
    near = labels[max(col - r, 0):col + r, max(row - r, 0):row + r]
    return isin(labels, distinct(near[near > 0]))


def crack_tip(mask: np.ndarray, origin: ArrayLike, spacing: float, start_x: float) -> float:
    """``x`` of the crack tip: the right-most crack point, or ``start_x`` if none lies
    right of it (``mask`` the crack's ``(nx, ny)`` image, the other parameters as in
    `crack_region`).

    Returns
    -------
    float
    """
    (x0, _), h = _grid(mask, origin, spacing)
    cols = np.flatnonzero(np.asarray(mask).any(axis=1))
    return float(start_x) if len(cols) == 0 else max(float(start_x), x0 + cols[-1] * h)


def bands(mask: np.ndarray, origin: np.ndarray, spacing: float,
          start_x: float) -> tuple[np.ndarray, list]:
    """The damage bands of every grid column at or right of ``start_x``.

    A band is a run of crack points along ``y``, separated from the next by at
    least one undamaged point.

    Parameters
    ----------
    mask : (nx, ny) bool ndarray
        The crack (`crack_region`).
    origin : (2,) array_like
    spacing : float
    start_x : float

    Returns
    -------
    x : (k,) ndarray
        The columns' ``x``.
    centres : list of k ndarrays
        ``y`` of the centres of each column's bands, increasing.
    """
    (x0, y0), h = _grid(mask, origin, spacing)
    mask = np.asarray(mask, dtype=bool)
    y = y0 + np.arange(mask.shape[1]) * h
    first = max(_index_at(start_x, x0, h), 0)
    centres = []
    for column in mask[first:]:
        idx = np.flatnonzero(column)
        runs = np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1) if len(idx) else []
        centres.append(np.array([y[r].mean() for r in runs]))
    return x0 + np.arange(first, mask.shape[0]) * h, centres


def branching(mask: np.ndarray, origin: ArrayLike, spacing: float, start_x: float, *,
              persistence: float, window: float) -> dict | None:
    """Branching point and half-angle of a crack image.

    The two branches are the upper-most and lower-most damage bands of the
    columns right of ``start_x`` (`bands`); the crack has branched where two
    bands persist over ``persistence`` in ``x`` (at least two columns).
    Straight lines fitted to the two branches over ``window`` from there give
    the half-angle (half the angle between them) and, where they meet (not
    left of ``start_x``), the branching point.

    Parameters
    ----------
    mask, origin, spacing, start_x
        As in `bands`.
    persistence : float
        Length along ``x`` over which two bands mark a branching (two horizons
        keep the two faces of a wide band from counting).
    window : float
        Length along ``x`` of the branches fitted.

    Returns
    -------
    dict or None
        ``x, y`` (branching point), ``half_angle`` (degrees); ``None`` if the
        crack has not branched.
    """
    h = _grid(mask, origin, spacing)[1]
    persistence = _length("persistence", persistence, "length along x (e.g. two horizons)")
    window = _length("window", window, "length along x of the branches fitted")
    xs, centres = bands(mask, origin, spacing, start_x)
    two = np.array([len(c) >= 2 for c in centres])
    run = max(2, int(np.ceil(persistence / h)))
    starts = [i for i in range(len(two) - run + 1) if two[i:i + run].all()]
    if not starts:
        return None
    cols = [i for i in range(starts[0], min(len(two), starts[0] + max(3, round(window / h))))
            if two[i]]
    x = xs[cols]
    upper = np.polyfit(x, [centres[i][-1] for i in cols], 1)
    lower = np.polyfit(x, [centres[i][0] for i in cols], 1)
    xb = x[0]
    if upper[0] - lower[0] > 1e-12:           # the lines diverge: they meet upstream
        xb = float(np.clip((lower[1] - upper[1]) / (upper[0] - lower[0]), start_x, x[0]))
    return dict(x=xb, y=0.5 * float(np.polyval(upper, xb) + np.polyval(lower, xb)),
                half_angle=0.5 * float(np.degrees(np.arctan(upper[0]) - np.arctan(lower[0]))))


def first_passage(times: np.ndarray, position: np.ndarray, x: float) -> float:
    """First time a non-decreasing ``position`` reaches ``x`` (linear between samples).

    Parameters
    ----------
    times, position : (k,) array_like
    x : float

    Returns
    -------
    float
        ``nan`` if never reached.
    """
    times, position = np.asarray(times, dtype=float), np.asarray(position, dtype=float)
    k = np.flatnonzero(position >= x)
    if len(k) == 0:
        return float("nan")
    k = k[0]
    if k == 0 or position[k] == position[k - 1]:
        return float(times[k])
    return float(times[k - 1] + (x - position[k - 1]) / (position[k] - position[k - 1])
                 * (times[k] - times[k - 1]))


def mean_speed(times: np.ndarray, position: np.ndarray) -> float:
    """Least-squares slope of ``position(times)``.

    Parameters
    ----------
    times, position : (k,) array_like

    Returns
    -------
    float
        ``nan`` with fewer than 3 samples.
    """
    return float(np.polyfit(times, position, 1)[0]) if len(times) >= 3 else float("nan")


def local_speeds(times: np.ndarray, position: np.ndarray, window: float, *,
                 where: np.ndarray | None = None) -> np.ndarray:
    """Speeds from least-squares fits of ``position`` over ``window`` around each sample.

    Parameters
    ----------
    times, position : (k,) array_like
    window : float
        Duration of each fit (the samples within ``window / 2`` of the sample).
    where : (k,) bool array_like, optional
        The samples used and given a speed (default all).

    Returns
    -------
    (k,) ndarray
        ``nan`` outside ``where`` and where a fit has fewer than 3 samples.
    """
    window = _length("window", window, "duration (a few sampling intervals)")
    times, position = np.asarray(times, dtype=float), np.asarray(position, dtype=float)
    where = np.ones(len(times), bool) if where is None else np.asarray(where, dtype=bool)
    out = np.full(len(times), np.nan)
    for k in np.flatnonzero(where):
        near = where & (np.abs(times - times[k]) <= 0.5 * window * (1 + 1e-6))
        out[k] = mean_speed(times[near], position[near])
    return out
