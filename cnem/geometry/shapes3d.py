"""Built-in 3-D bodies: box, sphere, hollow sphere, cylinder.

>>> from cnem.geometry import box, cylinder
>>> round(box((0, 0, 0), (1, 2, 3)).volume, 12)
6.0
>>> len(cylinder(1.0, 2.0, segments=8).faces)
32
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ..errors import GeometryError, check_array, check_count
from .domain3d import Domain3D
from .surface_checks import edge_table

__all__ = ["box", "sphere", "hollow_sphere", "cylinder", "box_surface", "sphere_surface"]


def _positive(name, value):
    value = float(check_array(name, value, error=GeometryError, fix=f"pass {name} as a number"))
    if not value > 0:
        raise GeometryError(f"{name} must be a positive number, received {value!r}")
    return value


def _point(name, value):
    return check_array(name, value, shape=(3,), error=GeometryError,
                       fix=f"pass {name} as three coordinates")


def box_surface(lo: ArrayLike, hi: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """The 8 corners and 12 outward triangles of the box ``[lo, hi]``.

    Each square side is cut along the diagonal through its corner of smallest
    coordinates, so boxes that share a whole side share its two triangles.

    Returns
    -------
    vertices : (8, 3) ndarray
    faces : (12, 3) int64 ndarray
    """
    lo, hi = _point("lo", lo), _point("hi", hi)
    if not (hi > lo).all():
        raise GeometryError(f"box: expected hi > lo in every coordinate, received lo = "
                            f"{lo.tolist()}, hi = {hi.tolist()}")
    corner = np.array([[i & 1, (i >> 1) & 1, (i >> 2) & 1] for i in range(8)])
    vertices = np.where(corner == 1, hi, lo)
    faces = []
    for a in range(3):
        b, c = (a + 1) % 3, (a + 2) % 3
        for side in (0, 1):
            quad = []
            for ub, uc in ((0, 0), (1, 0), (1, 1), (0, 1)):
                bits = np.zeros(3, dtype=int)
                bits[a], bits[b], bits[c] = side, ub, uc
                quad.append(bits[0] + 2 * bits[1] + 4 * bits[2])
            if side == 0:
                quad = [quad[0], quad[3], quad[2], quad[1]]
            faces += [[quad[0], quad[1], quad[2]], [quad[0], quad[2], quad[3]]]
    return vertices, np.array(faces, dtype=np.int64)


def box(lo: ArrayLike = (0.0, 0.0, 0.0), hi: ArrayLike = (1.0, 1.0, 1.0)) -> Domain3D:
    """The axis-aligned box ``[lo, hi]`` (12 triangles, see `box_surface`).

    Returns
    -------
    Domain3D
    """
    return Domain3D(box_surface(lo, hi))


def sphere_surface(radius: float, *, center: ArrayLike = (0.0, 0.0, 0.0),
                   subdivisions: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """An icosphere: the icosahedron with each triangle cut into four ``subdivisions``
    times, its vertices on the sphere.

    Returns
    -------
    vertices : (10 4^s + 2, 3) ndarray
    faces : (20 4^s, 3) int64 ndarray
        Outward.
    """
    radius = _positive("radius", radius)
    center = _point("center", center)
    levels = check_count("subdivisions", subdivisions, minimum=0, error=GeometryError)
    if levels > 7:
        raise GeometryError(f"subdivisions = {levels} would make {20 * 4**levels} faces; "
                            "expected at most 7")
    g = (1.0 + np.sqrt(5.0)) / 2.0
    v = np.array([[-1, g, 0], [1, g, 0], [-1, -g, 0], [1, -g, 0], [0, -1, g], [0, 1, g],
                  [0, -1, -g], [0, 1, -g], [g, 0, -1], [g, 0, 1], [-g, 0, -1], [-g, 0, 1]],
                 dtype=float)
    f = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9],
                  [5, 11, 4], [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2],
                  [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10],
                  [8, 6, 7], [9, 8, 1]], dtype=np.int64)
    v /= np.linalg.norm(v, axis=1)[:, None]
    for _ in range(levels):
        edges, face_edge, _ = edge_table(f)
        mid = v[edges].mean(axis=1)
        mid /= np.linalg.norm(mid, axis=1)[:, None]
        m = face_edge + len(v)
        v = np.concatenate([v, mid])
        f = np.concatenate([np.column_stack([f[:, 0], m[:, 0], m[:, 2]]),
                            np.column_stack([f[:, 1], m[:, 1], m[:, 0]]),
                            np.column_stack([f[:, 2], m[:, 2], m[:, 1]]), m])
    return center + radius * v, f


def sphere(radius: float = 1.0, *, center: ArrayLike = (0.0, 0.0, 0.0),
           subdivisions: int = 3) -> Domain3D:
    """A ball bounded by an icosphere (`sphere_surface`).

    Returns
    -------
    Domain3D
    """
    return Domain3D(sphere_surface(radius, center=center, subdivisions=subdivisions))


def hollow_sphere(inner: float = 0.5, outer: float = 1.0, *,
                  center: ArrayLike = (0.0, 0.0, 0.0), subdivisions: int = 3) -> Domain3D:
    """A spherical shell: the ball of radius ``outer`` less the ball of radius ``inner``.

    Returns
    -------
    Domain3D
    """
    inner, outer = _positive("inner", inner), _positive("outer", outer)
    if not inner < outer:
        raise GeometryError(f"hollow_sphere: expected inner < outer, received {inner:g} and "
                            f"{outer:g}")
    return Domain3D((sphere_surface(outer, center=center, subdivisions=subdivisions),
                     [sphere_surface(inner, center=center, subdivisions=subdivisions)]))


def cylinder(radius: float = 1.0, height: float = 1.0, *, base: ArrayLike = (0.0, 0.0, 0.0),
             segments: int = 32) -> Domain3D:
    """A circular cylinder along z from ``base`` to ``base + (0, 0, height)``, its
    section the regular polygon of ``segments`` sides inscribed in the circle (caps
    cut into a fan about their centres).

    Returns
    -------
    Domain3D
    """
    radius, height = _positive("radius", radius), _positive("height", height)
    base = _point("base", base)
    n = check_count("segments", segments, minimum=3, error=GeometryError)
    t = 2.0 * np.pi * np.arange(n) / n
    ring = np.column_stack([radius * np.cos(t), radius * np.sin(t), np.zeros(n)])
    top = ring + [0.0, 0.0, height]
    vertices = base + np.concatenate([ring, top, [[0.0, 0.0, 0.0], [0.0, 0.0, height]]])
    i, j = np.arange(n), (np.arange(n) + 1) % n
    faces = np.concatenate([np.column_stack([i, j, n + j]), np.column_stack([i, n + j, n + i]),
                            np.column_stack([np.full(n, 2 * n), j, i]),
                            np.column_stack([np.full(n, 2 * n + 1), n + i, n + j])])
    return Domain3D((vertices, faces))
