"""`Body`: peridynamic material points, volumes, horizon and bonds."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .. import config
from ..errors import InputError, check_array, check_points
from ..spatial import family_search, remove_crossing
from ._kernels import bond_geometry, image_factors
from .._sets import distinct

if TYPE_CHECKING:
    from ..geometry.cloud import NodeCloud

if TYPE_CHECKING:
    from typing import Sequence
    from numpy.typing import ArrayLike

__all__ = ["Body", "bond_reach", "checked_input", "crack_segments"]


def _past_the_mouths(crack, tips, reach, tol):
    """A crack polyline with each end on the boundary (an edge crack's mouth) pushed
    ``reach`` further out, so that bonds passing through the mouth are cut too; an end
    within ``tol`` (the domain's tolerance) of a tip is a tip."""
    crack = np.array(crack, dtype=float)
    for end, before in ((-1, -2), (0, 1)):
        if not (np.hypot(*(tips - crack[end]).T) <= tol).any() if len(tips) else True:
            d = crack[end] - crack[before]
            crack[end] = crack[end] + reach * d / np.hypot(*d)
    return crack


def checked_input(points: np.ndarray, volumes: float | ArrayLike, horizon: float,
                  thickness: float) -> tuple:
    """The arguments of a `Body`, checked: points ``(n, d)``, volumes ``(n,)``, horizon and
    thickness (1 in 3-D) as floats.

    Raises
    ------
    InputError
        Not a non-empty ``(n, 2)`` or ``(n, 3)`` array of finite coordinates below
        `cnem.config.COORDINATE_LIMIT`, volumes of the wrong length or not positive
        and finite, a horizon not one positive number, a non-positive thickness.
    """
    pts = check_points("points", points)
    if len(pts) == 0:
        raise InputError(f"points: expected a non-empty (n, 2) or (n, 3) array, received "
                         f"shape {pts.shape}")
    n, d = pts.shape
    vol = check_array("volumes", volumes, shape=(n,), broadcast=True, positive=True,
                      fix="pass positive finite volumes, a number or one per point")
    if np.ndim(horizon) != 0:
        raise InputError(f"horizon: expected one positive number (a Body has one horizon), "
                         f"received shape {np.shape(horizon)}; pass a number, typically three "
                         f"node spacings")
    horizon = float(check_array("horizon", horizon, fix="pass a positive number, typically "
                                                         "three node spacings"))
    if horizon <= 0:
        raise InputError(f"horizon: expected a positive number, received {horizon}; "
                         f"typically three node spacings")
    thick = float(thickness) if d == 2 else 1.0
    if thick <= 0:
        raise InputError(f"thickness: expected a positive number, received {thickness}")
    return pts, vol, horizon, thick


def crack_segments(cracks: Sequence[ArrayLike]) -> np.ndarray | None:
    """The ``(s, 2, 2)`` segments of crack polylines (None without cracks)."""
    segs = [np.column_stack([c[:-1], c[1:]]).reshape(-1, 2, 2)
            for c in (np.asarray(c, dtype=float) for c in cracks)]
    return np.concatenate(segs) if segs else None


def bond_reach(points: np.ndarray, horizon: float) -> float:
    """The radius within which a body's bonds are searched: the horizon, a relative
    `cnem.config.HORIZON_RTOL` above it, plus the round-off of the coordinates
    (`cnem.config.ROUNDOFF_ULPS` units in the last place of the largest one).

    The partial volume of a bond is 1/2 at the horizon, so a bond of length equal to it
    belongs to the family; without the margin the round-off of its length decided
    (and a body moved far from the origin, or a horizon moved by 1e-12, lost or gained
    such bonds).

    Parameters
    ----------
    points : (n, d) ndarray
    horizon : float

    Returns
    -------
    float
    """
    scale = max(float(np.abs(points).max(initial=0.0)), horizon)
    return horizon * (1.0 + config.HORIZON_RTOL) + \
        config.ROUNDOFF_ULPS * float(np.finfo(float).eps) * scale


class Body:
    """Material points with volumes and a horizon; bonds from `cnem.spatial.family_search`.

    Parameters
    ----------
    points : (n, d) array_like
        d = 2 (with a thickness) or 3.
    volumes : (n,) array_like or float
        Point volumes (area times thickness in 2-D).
    horizon : float
    thickness : float
        2-D only.
    period : None or (d,) array_like
        Periodic cell ``[0, L_1) x ...``: bonds use the minimum image.
    cracks : sequence of (k, 2) polylines, optional
        2-D pre-cracks: bonds crossing them are removed.
    crossing_points : (n, 2) array_like, optional
        Positions used for that crossing test only (default the points): points
        lying on a crack line can be moved a little to the side they belong to.

    Attributes
    ----------
    family : cnem.spatial.Family
    bond_i, bond_j : (b,) int ndarray
        Bond ``b`` goes from point ``bond_i[b]`` to ``bond_j[b]`` (both directions present).
    xi : (b, d) ndarray
        Reference bond vectors ``x_j - x_i`` (minimum image).
    length : (b,) ndarray
    beta : (b,) ndarray
        Partial-volume factors of bonds cut by the horizon.
    period : (d,) ndarray
        The period of each axis (``inf``: not periodic).
    image : (2, d) ndarray
        Per axis the period twice (0 and 1 on an axis that is not periodic): the minimum
        image of a coordinate difference without a branch (`cnem.pd._kernels.periodic_image`).
    """

    def __init__(self, points: np.ndarray, volumes: float | ArrayLike, horizon: float, *,
                 thickness: float = 1.0, period: ArrayLike | None = None, cracks: tuple = (),
                 crossing_points: int | None = None):
        pts, vol, horizon, self.thickness = checked_input(points, volumes, horizon, thickness)
        n, d = pts.shape
        self.points, self.volumes, self.horizon, self.dim = pts, vol, horizon, d
        fam = family_search(pts, bond_reach(pts, horizon), period=period)
        segments = crack_segments(cracks)
        if segments is not None:
            test = pts if crossing_points is None else np.asarray(crossing_points, dtype=float)
            fam = remove_crossing(fam, test, segments)
        if len(fam.indices) == 0:
            spacing = float(np.median(vol) / self.thickness) ** (1.0 / d)
            raise InputError(f"horizon: expected a horizon that reaches other points (about three "
                             f"node spacings, here ~{3 * spacing:.3g}), received {horizon:.3g}: no "
                             f"point has a neighbour within it, so the body has no bonds")
        self.family = fam
        self.period = fam.period
        self.image = image_factors(self.period)
        index = fam.indices.dtype                  # int32 unless the cloud is huge
        self.bond_i = np.repeat(np.arange(n, dtype=index), fam.counts)
        self.bond_j = fam.indices
        nb = len(self.bond_j)
        self.xi, self.length, self.beta = np.empty((nb, d)), np.empty(nb), np.empty(nb)
        spacing = (vol / self.thickness) ** (1.0 / d)
        bond_geometry(pts, fam.offsets, self.bond_j, self.image, spacing, horizon, self.xi,
                      self.length, self.beta)

    @classmethod
    def from_cloud(cls, cloud: NodeCloud, horizon_factor: float = 3.0, *,
                   thickness: float = 1.0) -> Body:
        """The nodes of a C-NEM node cloud, with their integration-cell areas as volumes.

        Points on a crack face become two points, one per face (as in
        `cnem.discretize`); a bond crossing a crack is removed, and the two
        copies of a face point are not bonded to the other face.

        Parameters
        ----------
        cloud : cnem.NodeCloud
            On a `cnem.Domain` (2-D) or a `cnem.Domain3D` (3-D: the nodes of
            `cnem.discretize`, including any boundary nodes the tetrahedrisation added,
            with their constrained Voronoi cells' volumes).
        horizon_factor : float
            Horizon in units of the mean node spacing (``sqrt(area / n)``, in 3-D
            ``cbrt(volume / n)``).
        thickness : float
            2-D only (a 3-D cloud refuses any other value than 1).
        """
        from ..geometry import discretize
        model = discretize(cloud, progress=False)
        if cloud.dim == 3:
            return cls._from_model_3d(model, horizon_factor, thickness)
        area = np.bincount(model.cells.node, weights=model.cells.area, minlength=len(model.nodes))
        h = np.sqrt(model.domain.area / len(distinct(model.node_of_point)))
        copies = np.bincount(model.node_of_point)[model.node_of_point] > 1
        # a crack-face copy is nudged towards its own face for the crossing test only,
        # in the model's local frame (at 1e8 a nudge of 1e-6 h would round away)
        frame = model.frame
        shift = model.node_sides() - model.nodes
        norm = np.maximum(np.hypot(*shift.T), 1e-300)[:, None]
        nudged = frame.to_local(model.nodes) + np.where(copies[:, None],
                                                        1e-6 * (h / frame.scale) * shift / norm, 0.0)
        horizon = horizon_factor * h
        body = cls(model.nodes, area * thickness, horizon, thickness=thickness,
                   cracks=[frame.to_local(_past_the_mouths(c, model.domain.tips, horizon,
                                                           model.domain.tolerance))
                           for c in model.domain.cracks], crossing_points=nudged)
        body.model = model
        return body

    @classmethod
    def _from_model_3d(cls, model, horizon_factor, thickness):
        """`from_cloud` for a 3-D model: the nodes with their cells' volumes (a node on a
        material interface sums its cells), horizon in units of ``cbrt(volume / n)``."""
        if thickness != 1.0:
            raise InputError(f"thickness: a 3-D cloud has volumes of its own; expected the "
                             f"default 1.0, received {thickness}")
        n = len(model.nodes)
        volume = np.bincount(model.cells.node, weights=model.cells.volume, minlength=n)
        h = float(volume.sum() / n) ** (1.0 / 3.0)
        body = cls(model.nodes, volume, horizon_factor * h)
        body.model = model
        return body

    def __len__(self):
        return len(self.points)

    def __repr__(self):
        return (f"<Body {len(self.points)} points ({self.dim}-D), horizon {self.horizon:g}, "
                f"{len(self.bond_i)} bonds>")
