"""Node spacing: checks of a spacing, a seed and a node count, and the local spacing of
a point cloud, shared by the 2-D and 3-D node clouds (`cnem.nodes`).

>>> import numpy as np
>>> from cnem.geometry.spacing import point_spacing
>>> point_spacing(np.arange(6.0)[:, None] * [1.0, 0.0]).round(2).tolist()
[2.5, 1.75, 1.5, 1.5, 1.75, 2.5]
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from .. import config
from ..errors import GeometryError, LimitError, check_array, check_count

__all__ = ["check_seed", "check_spacing", "check_node_count", "point_spacing"]


def check_seed(seed: int | None) -> int | None:
    """``seed`` for `numpy.random.default_rng` once it is a whole number >= 0 (or None)."""
    if seed is None:
        return None
    return check_count("seed", seed, minimum=0, error=GeometryError)


def check_spacing(dom: object, h: float, name: str = "h") -> float:
    """``h`` as a float once it is one positive spacing smaller than ``dom.diameter`` and
    above the smallest spacing the domain resolves (``dom.tolerance``)."""
    if np.ndim(h) != 0:
        raise GeometryError(f"{name}: expected one spacing (a number), received an array of "
                            f"shape {np.shape(h)}; for spacings that vary use graded(...)")
    h = float(check_array(name, h, error=GeometryError, finite=False,
                          fix="pass the node spacing as a number, e.g. 0.1"))
    if not np.isfinite(h) or h <= 0:
        raise GeometryError(f"{name} must be a positive spacing, received {h!r}")
    if h >= dom.diameter:
        raise GeometryError(f"{name} = {h:g} is not smaller than the domain diameter "
                            f"{dom.diameter:g}; choose a spacing that fits several nodes")
    # ten snapping tolerances: the tolerance grows with the coordinates' round-off far
    # from the origin (a body 1 across at 1e8 resolves no spacing below ~4e-6)
    smallest = max(config.MIN_SPACING * dom.diameter, 10 * dom.tolerance)
    if h < smallest:
        raise GeometryError(
            f"{name} = {h:g} is below the smallest spacing this domain resolves, {smallest:.3g} "
            f"(cnem.config.MIN_SPACING = {config.MIN_SPACING:g} times the diameter "
            f"{dom.diameter:.3g}, or ten snapping tolerances {dom.tolerance:.3g}, which far "
            f"from the origin cover the coordinates' round-off; nodes closer are within a few "
            f"tolerances of each other); expected {name} >= {smallest:.3g}, or coordinates "
            f"nearer the origin")
    return h


def check_node_count(estimate: float, what: str, fix: str) -> None:
    """Refuse a cloud of more than `cnem.config.MAX_NODES` nodes before building it."""
    if estimate > config.MAX_NODES:
        raise LimitError(f"{what} would need ~{estimate:.3g} nodes, more than "
                         f"cnem.config.MAX_NODES = {config.MAX_NODES:g}; expected {fix} "
                         "(or raise cnem.config.MAX_NODES)")


def point_spacing(pts: np.ndarray) -> np.ndarray:
    """(p,) local spacing at each point: the mean distance to its
    `cnem.config.SPACING_NEIGHBOURS` nearest others (``inf`` for a lone point); a
    single nearest neighbour is too noisy a measure on irregular clouds."""
    k = min(config.SPACING_NEIGHBOURS, len(pts) - 1)
    if k < 1:
        return np.full(len(pts), np.inf)
    return cKDTree(pts).query(pts, k=k + 1)[0][:, 1:].mean(axis=1)
