"""Geometric predicates shared by the numba kernels (arrays and scalars only)."""

import numba

from . import _compile  # noqa: F401  (says once when the kernels compile)


@numba.njit(cache=True, inline="always")
def orient2d(ax, ay, bx, by, cx, cy):
    """Twice the signed area of triangle (a, b, c): > 0 when counter-clockwise."""
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
