"""Boundary-condition data shared by every solver (C-NEM, FEM P1, peridynamics)."""

from __future__ import annotations

import numpy as np

from ..errors import ConditionError
from .basis import select_nodes

__all__ = ["per_point", "dirichlet_dofs"]


def per_point(value, points, width, what):
    """A constant or a callable evaluated at points, as a ``(p, width)`` array.

    Raises
    ------
    ConditionError
        Values of the wrong shape, or not finite (``what`` names them).
    """
    arr = np.asarray(value(points) if callable(value) else value, dtype=float)
    if width == 1 and arr.shape == (len(points),):
        arr = arr[:, None]
    try:
        arr = np.broadcast_to(arr, (len(points), width))
    except ValueError:
        raise ConditionError(f"{what}: expected a number or one value per point, shape "
                             f"({len(points)}, {width}), received shape {arr.shape}; return one "
                             f"row per point") from None
    if not np.isfinite(arr).all():
        raise ConditionError(f"{what}: expected finite values, received NaN or inf; check "
                             f"the value or function given")
    return arr


def dirichlet_dofs(points, where, component, value, *, where_to_look="the nodes"):
    """Dofs (interleaved: ``d * node + component``) and values of a Dirichlet condition.

    Parameters
    ----------
    points : (n, d) ndarray
    where : callable ``(n, d) -> (n,) bool``, or a boolean mask / index array over points
    component : None or 0..d-1
        ``None`` prescribes every component.
    value : float or callable ``(p, d) -> (p,)`` (``(p, d)`` for every component)
    where_to_look : str
        Named in the error when nothing is selected.

    Returns
    -------
    dofs : (k,) int64 ndarray
    values : (k,) ndarray
    """
    d = points.shape[1]
    if component is not None and component not in range(d):
        raise ConditionError(f"component: expected None (all) or 0..{d - 1}, received "
                             f"{component!r}")
    nodes = select_nodes(points, where)
    if nodes.size == 0:
        raise ConditionError(f"add_dirichlet: `where` selects no node; check the predicate against "
                         f"{where_to_look} (boundary nodes lie exactly on the boundary)")
    comps = np.arange(d) if component is None else np.array([component])
    vals = per_point(value, points[nodes], len(comps), "add_dirichlet value")
    return (d * nodes[:, None] + comps[None, :]).reshape(-1), np.ascontiguousarray(vals).reshape(-1)
