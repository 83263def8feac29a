"""Node spacing: checks of a spacing, a seed and a node count, and the local spacing of
a point cloud, shared by the 2-D and 3-D node clouds (`cnem.nodes`).

>>> import numpy as np
>>> from cnem.geometry.spacing import point_spacing
>>> point_spacing(np.arange(6.0)[:, None] * [1.0, 0.0]).round(2).tolist()
[2.5, 1.75, 1.5, 1.5, 1.75, 2.5]
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.spatial import cKDTree

from .. import config
from ..errors import GeometryError, LimitError, check_array, check_count

__all__ = ["check_seed", "check_spacing", "check_grading", "check_node_count", "point_spacing",
           "count_along", "SpacingLaw"]


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


def check_grading(dom: object, h: float, h_min: float, growth: float, near: object,
                  dim: int) -> tuple[float, float, np.ndarray]:
    """The arguments of a graded cloud checked: ``(h, h_min, centres (q, dim))``."""
    h = check_spacing(dom, h)
    h_min = check_spacing(dom, h_min, "h_min")
    if h_min > h:
        raise GeometryError(f"h_min ({h_min:g}) must not exceed h ({h:g})")
    if not 0 < growth <= 1:
        raise GeometryError(f"growth must lie in (0, 1], received {growth!r}")
    centres = check_array("near", near, finite=True, error=GeometryError,
                          fix=f"give the refinement points as a (q, {dim}) array, e.g. dom.tips")
    if centres.size and (centres.ndim not in (1, 2) or centres.shape[-1] != dim):
        raise GeometryError(f"near: expected refinement points (q, {dim}) or one point ({dim},), "
                            f"received shape {centres.shape}; give e.g. dom.tips")
    centres = centres.reshape(-1, dim)
    if len(centres) == 0:
        raise GeometryError("graded: `near` is empty; give at least one refinement point")
    return h, h_min, centres


def point_spacing(pts: np.ndarray) -> np.ndarray:
    """(p,) local spacing at each point: the mean distance to its
    `cnem.config.SPACING_NEIGHBOURS` nearest others (``inf`` for a lone point); a
    single nearest neighbour is too noisy a measure on irregular clouds."""
    k = min(config.SPACING_NEIGHBOURS, len(pts) - 1)
    if k < 1:
        return np.full(len(pts), np.inf)
    return cKDTree(pts).query(pts, k=k + 1)[0][:, 1:].mean(axis=1)


def count_along(pa: np.ndarray, pb: np.ndarray,
                spacing_of: Callable) -> tuple[np.ndarray, np.ndarray]:
    """Cumulative node count along segment ``pa-pb`` under the spacing law.

    The density ``length / spacing_of(x)`` is integrated by the trapezoid rule
    on 65 samples, each interval bisected again while its midpoint changes its
    count by more than `cnem.config.SPACING_COUNT_TOL` nodes: a law that shrinks
    to a tiny spacing at a tip is followed down to it (a fixed rule gave the
    first 1/64 of the segment one uniform tiny spacing).

    Returns
    -------
    t : (m,) ndarray
        Increasing parameters in [0, 1].
    cum : (m,) ndarray
        Nodes expected between ``pa`` and ``pa + t (pb - pa)``.
    """
    length = np.linalg.norm(pb - pa)

    def density(t):
        return length / spacing_of(pa + t[:, None] * (pb - pa))

    t = np.linspace(0.0, 1.0, 65)
    dens = density(t)
    for _ in range(config.SPACING_BISECTIONS):
        mid = 0.5 * (t[1:] + t[:-1])
        dmid = density(mid)
        error = np.abs(dmid - 0.5 * (dens[1:] + dens[:-1])) * np.diff(t)
        split = error > config.SPACING_COUNT_TOL
        if not split.any():
            break
        t, dens = np.concatenate([t, mid[split]]), np.concatenate([dens, dmid[split]])
        order = np.argsort(t, kind="stable")
        t, dens = t[order], dens[order]
    else:
        raise LimitError(
            f"the node spacing along the segment {pa.tolist()} - {pb.tolist()} is not resolved "
            f"after {config.SPACING_BISECTIONS} bisections of its samples; expected a spacing "
            "law that is bounded below by a positive h_min")
    return t, np.concatenate([[0.0], np.cumsum(0.5 * (dens[1:] + dens[:-1]) * np.diff(t))])


class SpacingLaw:
    """A node spacing: uniform ``h``, or ``s(x) = min(h, h_min + growth d(x))`` graded
    towards refinement centres (``d``: the distance to the nearest one).

    Parameters
    ----------
    h : float
    h_min, growth : float, optional
        For a graded law.
    centres : (q, d) ndarray, optional
        The refinement centres (graded law).

    Examples
    --------
    >>> law = SpacingLaw(1.0, h_min=0.25, growth=0.5, centres=np.zeros((1, 2)))
    >>> law(np.array([[0.0, 0.0], [1.0, 0.0], [5.0, 0.0]])).tolist()
    [0.25, 0.75, 1.0]
    >>> len(SpacingLaw(0.5).lattice(np.zeros(2), np.ones(2)))
    9
    """

    def __init__(self, h: float, *, h_min: float | None = None, growth: float | None = None,
                 centres: np.ndarray | None = None) -> None:
        self.h = h
        self.uniform = centres is None
        if not self.uniform:
            self.h_min, self.growth, self.centres = h_min, growth, centres
            self._tree = cKDTree(centres)
        self.levels = 0 if self.uniform or h_min >= h else int(np.floor(np.log2(h / h_min)))

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """(m,) spacing at the points ``x (m, d)``."""
        if self.uniform:
            return np.full(len(x), self.h)
        return np.minimum(self.h, self.h_min + self.growth * self._tree.query(x)[0])

    def lattice(self, lo: np.ndarray, hi: np.ndarray, *, lift: Callable | None = None,
                centres: np.ndarray | None = None, offset: float = 0.0) -> np.ndarray:
        """Lattice points over the box ``[lo, hi]`` whose spacing follows the law: level
        ``k`` (spacing ``h / 2^k``) is kept where the law's spacing lies between
        ``h / 2^(k+1)`` and ``h / 2^k`` (as the 2-D graded clouds).

        Parameters
        ----------
        lo, hi : (d,) ndarray
            The box, in the lattice's coordinates.
        lift : callable, optional
            Maps lattice points to the law's coordinates (a plane's 2-D frame into 3-D).
        centres : (q, d) ndarray, optional
            The refinement centres in the lattice's coordinates (default: the law's).
        offset : float
            Shift of each level's lattice, in its spacings (0.5: cell centres).

        Returns
        -------
        (m, d) ndarray
        """
        lift = (lambda y: y) if lift is None else lift
        centres = getattr(self, "centres", None) if centres is None else centres
        out = []
        for k in range(self.levels + 1):           # bounded by log2(h / h_min)
            hk = self.h / 2**k
            corner = lo + offset * hk
            top = np.ceil((hi - lo) / hk).astype(np.int64)
            if k == 0:
                axes = [np.arange(t + 1) for t in top]
                ij = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, len(lo))
            else:
                # level k is used only where s(x) < 2 hk, i.e. near the centres
                reach = (2 * hk - self.h_min) / self.growth
                first = np.clip(np.floor((centres - reach - corner) / hk), 0, top).astype(np.int64)
                last = np.clip(np.ceil((centres + reach - corner) / hk), 0, top).astype(np.int64)
                boxes = [np.stack(np.meshgrid(*[np.arange(a, b + 1) for a, b in zip(f, g)],
                                              indexing="ij"), axis=-1).reshape(-1, len(lo))
                         for f, g in zip(first, last)]
                ij = np.unique(np.concatenate(boxes), axis=0)
            pts = corner + hk * ij
            if self.levels:
                level = np.clip(np.floor(np.log2(self.h / self(lift(pts)))), 0, self.levels)
                pts = pts[level == k]
            out.append(pts)
        return np.concatenate(out)
