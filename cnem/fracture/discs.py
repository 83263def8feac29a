"""The integration discs of the interaction integral: how far a disc about a tip may reach.

The domain form of the interaction integral (`cnem.fracture.interaction`) holds on
any disc about the tip whose weight ``q`` vanishes on every boundary the disc meets,
except straight traction-free crack faces through the tip (where the Williams
auxiliary fields are traction-free too). A disc must therefore stay

* inside the tip's material region: clear of the outer boundary, the holes and the
  interfaces (free edges and supports alike);
* clear of every other crack, and of the other tip of its own crack;
* on the straight part of its own crack: the crack inside the disc of radius ``R``
  may leave the line through the tip by at most ``SIF_STRAIGHTNESS * R``
  (`cnem.config`), so a kink or a curved crack path behind the tip limits ``R``
  (a soft limit: not below ``SIF_BEND_SPACINGS`` node spacings).

`clearance` measures that limit on the domain's geometry; `default_radii` spreads
a few nested discs below it (`cnem.config.SIF_DISCS`, ``SIF_INNER``,
``SIF_REACH``, ``SIF_BEND_SPACINGS``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

import numpy as np
import shapely

from .. import config
from ..errors import FractureError

if TYPE_CHECKING:
    from ..geometry.domain import Domain
    from ..geometry.model import Model

__all__ = ["Clearance", "clearance", "default_radii", "local_spacing"]

#: Samples per crack segment when the straightness of the own crack is measured.
_SAMPLES = 256


class Clearance(NamedTuple):
    """How far a disc about a tip may reach.

    Attributes
    ----------
    distance : float
        Radius at which the disc first meets an obstacle it must not cross: the outer
        boundary, a hole, an interface, another crack, the other tip of its crack.
    obstacle : str
        What it meets (for messages).
    point : (2,) ndarray
        Where.
    straight : float
        Radius up to which the own crack stays on the straight line through the tip
        (``inf`` when it does up to ``distance``): beyond it the auxiliary fields are
        no longer traction-free on the crack faces, a soft limit (`default_radii`).
    bend : (2,) ndarray
        Where the crack leaves that line (NaN when it does not).
    """

    distance: float
    obstacle: str
    point: np.ndarray
    straight: float = np.inf
    bend: np.ndarray = np.full(2, np.nan)


def local_spacing(model: Model, tip: np.ndarray) -> float:
    """Median length of the triangle edges at the node nearest to ``tip``."""
    node = np.argmin(np.hypot(*(model.nodes - tip).T))
    tri = model.triangles[(model.triangles == node).any(axis=1)]
    edges = model.nodes[tri] - model.nodes[tri[:, [1, 2, 0]]]
    return float(np.median(np.hypot(edges[..., 0], edges[..., 1])))


def _own_crack(domain, tip):
    """Index of the crack that ends at ``tip`` and the crack ordered to end there."""
    for j, crack in enumerate(domain.cracks):
        if np.array_equal(crack[-1], tip):
            return j, crack
        if np.array_equal(crack[0], tip):
            return j, crack[::-1]
    raise FractureError(f"{tip.tolist()} is no crack end of the domain")   # pragma: no cover


def _off_line(crack, tip, direction):
    """The nearest point of the own crack (ordered to end at ``tip``) that leaves the
    straight line behind the tip by more than ``SIF_STRAIGHTNESS`` times its distance,
    or lies ahead of the tip: ``(distance, point)`` or None."""
    eps = config.SIF_STRAIGHTNESS
    t = np.linspace(0.0, 1.0, _SAMPLES + 1)[1:]
    a, b = crack[-1:0:-1], crack[-2::-1]            # segments from the tip backwards
    pts = (a[:, None, :] + t[None, :, None] * (b - a)[:, None, :]).reshape(-1, 2)
    rel = pts - tip
    along = rel @ direction
    across = np.abs(rel[:, 0] * direction[1] - rel[:, 1] * direction[0])
    rho = np.hypot(rel[:, 0], rel[:, 1])
    bad = (across > eps * rho) | (along > 0)
    if not bad.any():
        return None
    k = np.flatnonzero(bad)[np.argmin(rho[bad])]
    return float(rho[k]), pts[k]


def clearance(domain: Domain, tip: np.ndarray, direction: np.ndarray) -> Clearance:
    """Radius at which a disc about a crack tip first meets something the interaction
    integral must not cross (see the module docstring).

    Parameters
    ----------
    domain : Domain
    tip : (2,) ndarray
        A crack tip of ``domain`` (as `Domain.tip_frame` returns it).
    direction : (2,) ndarray
        Unit vector along the crack's last segment, out of the crack.

    Returns
    -------
    Clearance
    """
    tip = np.asarray(tip, dtype=float)
    point = shapely.Point(tip)
    found = []
    region = int(domain.region_of(tip)[0])
    ring = domain.regions[region].boundary
    near = np.asarray(shapely.shortest_line(point, ring).coords[1])
    on_outside = shapely.distance(shapely.Point(near), domain.polygon.boundary) <= domain.tolerance
    found.append((float(point.distance(ring)),
                  "the outer boundary or a hole" if on_outside or len(domain.regions) == 1
                  else f"the interface of region {region}", near))
    own, crack = _own_crack(domain, tip)
    for j, other in enumerate(domain.cracks):
        if j != own:
            line = shapely.LineString(other)
            found.append((float(point.distance(line)), f"crack {j}",
                          np.asarray(shapely.shortest_line(point, line).coords[1])))
    start = crack[0]
    if (np.hypot(*(domain.tips - start).T) == 0).any():
        found.append((float(np.hypot(*(start - tip))), f"the other tip of crack {own}", start))
    distance, obstacle, where = min(found, key=lambda f: f[0])
    bend = _off_line(crack, tip, direction)
    if bend is None or bend[0] >= distance:
        return Clearance(distance, obstacle, np.asarray(where, dtype=float))
    return Clearance(distance, obstacle, np.asarray(where, dtype=float), bend[0], bend[1])


def default_radii(model: Model, tip: np.ndarray, limit: Clearance) -> tuple[np.ndarray, float, str]:
    """Nested disc radii about a tip: ``SIF_DISCS`` radii in geometric progression from
    ``SIF_INNER`` times the largest to the largest, ``SIF_REACH`` times the clearance.

    A kink or bend of the own crack closer than that (``limit.straight``) limits the
    discs too, but not below ``SIF_BEND_SPACINGS`` local node spacings: a disc of a
    spacing or less cannot resolve the field, while a kink inside the disc only
    perturbs K by a few % (docs/fracture.md); the hard limit still holds.

    Parameters
    ----------
    model : Model
    tip : (2,) ndarray
    limit : Clearance
        Of the tip (`clearance`).

    Returns
    -------
    radii : (k,) ndarray
        Increasing.
    spacing : float
        The local node spacing at the tip (`local_spacing`), to check the discs against.
    limited_by : str
        What limits the largest disc (for messages).
    """
    spacing = local_spacing(model, tip)
    outer = config.SIF_REACH * limit.distance
    limited_by = f"{limit.obstacle} ({limit.distance:.4g} from the tip)"
    bent = max(config.SIF_REACH * limit.straight, config.SIF_BEND_SPACINGS * spacing)
    if bent < outer:
        outer = bent
        limited_by = (f"the bend of the crack at {limit.bend.tolist()} "
                      f"({limit.straight:.4g} from the tip)")
    if not outer > 0:
        raise FractureError(f"the crack tip {tip.tolist()} lies on {limit.obstacle} (at "
                            f"{limit.point.tolist()}): no integration disc fits about it; "
                            "expected a tip inside one material, away from other cracks")
    return np.geomspace(config.SIF_INNER * outer, outer, config.SIF_DISCS), spacing, limited_by
