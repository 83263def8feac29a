"""The L-shape (2-D), C-NEM against CPD on the same nodes: the example of
`cnem.demos.cnem_vs_cpd` after the seed paper's §6.4 (Figure 10).

The unit square without its top-right quarter (`cnem.geometry.l_shape`), the bottom edge
clamped, the top of the left arm pulled up by ``pull`` (``u_x = 0`` there): the set-up of
`cnem.demos.cpd.structures.lshape`, a small ("infinitesimal") displacement with the
seed's ``n = 1`` bond energy and C2 = 0 (2-D Cauchy solid, in-plane Poisson ratio 1/3,
the seed's nu = 0.33). C-NEM solves `cnem.demos.cpd.bond_law.BondContinuum` (the same
energy), CPD the bonds with C1 calibrated on its interior points. The displacements are
compared along the seed's two lines through the re-entrant corner (1/2, 1/2): the row
``y = 1/2`` leftwards and the column ``x = 1/2`` downwards.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import shapely

import cnem

from .bond_law import BondContinuum
from .versus import run_cnem, run_cpd

if TYPE_CHECKING:
    from typing import Sequence

__all__ = ["lshape_conditions", "profile_nodes", "lshape_runs"]

#: The seed's ``n = 1`` energy (``S = lambda - 1``) with ``mu = 1``.
LAW = BondContinuum(1.0, exponent=1.0)


def lshape_conditions(pull: float) -> list[tuple]:
    """Dirichlet conditions ``[(where, component, value)]`` of the unit L-shape: bottom
    clamped, the top of the left arm (``y = 1``) at ``u_x = 0``, ``u_y = pull``."""
    tol = 1e-9
    bottom = lambda p: p[:, 1] < tol                                    # noqa: E731
    grip = lambda p: p[:, 1] > 1.0 - tol                                # noqa: E731
    return [(bottom, None, 0.0), (grip, 0, 0.0), (grip, 1, pull)]


def profile_nodes(points: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    """Indices of the nodes on the row ``y = 1/2, x <= 1/2`` (ordered leftwards from the
    corner) and on the column ``x = 1/2, y <= 1/2`` (downwards), within ``h / 4`` of the
    line."""
    near = 0.25 * h
    row = np.flatnonzero((np.abs(points[:, 1] - 0.5) < near) & (points[:, 0] < 0.5 + near))
    column = np.flatnonzero((np.abs(points[:, 0] - 0.5) < near) & (points[:, 1] < 0.5 + near))
    return row[np.argsort(-points[row, 0])], column[np.argsort(-points[column, 1])]


def _interior(domain):
    """``inside(body)``: the points farther than a horizon plus half a spacing from the
    L's boundary (every bond, partial ones included, ends inside)."""
    edge = domain.polygon.boundary

    def inside(body):
        depth = shapely.distance(shapely.points(body.points), edge)
        reach = body.horizon + 0.5 * np.sqrt(np.median(body.volumes) / body.thickness)
        return depth > min(reach, depth.max() * (1 - 1e-9))
    return inside


def lshape_runs(h: float, factors: Sequence[float], cloud: str, pull: float = 1e-3) -> dict:
    """C-NEM and CPD (one per horizon factor) of the L-shape on one cloud of spacing
    ``h`` (``"regular"`` or ``"irregular"``), one load step.

    Returns
    -------
    dict
        ``model``, ``runs`` (`cnem.demos.cpd.versus.Run` per method), ``row``,
        ``column`` (node indices, `profile_nodes`), ``distance`` (of the row's and the
        column's nodes from the corner), ``triangles`` (of the nodes, the notch left out,
        for pictures).
    """
    domain = cnem.geometry.l_shape(1.0, 0.5)
    nodes = cnem.nodes.regular(domain, h) if cloud == "regular" else \
        cnem.nodes.irregular(domain, h, seed=1)
    model = cnem.discretize(nodes, progress=False)
    dirichlet = lshape_conditions(pull)
    runs = {"C-NEM": run_cnem(model, LAW, dirichlet, None, 1)}
    for m in factors:
        runs[f"CPD {m:g}h"] = run_cpd(nodes, m, LAW, _interior(domain), dirichlet, None, 1)
    p = model.nodes
    row, column = profile_nodes(p, h)
    from matplotlib.tri import Triangulation
    tri = Triangulation(p[:, 0], p[:, 1]).triangles
    centre = p[tri].mean(axis=1)
    triangles = tri[shapely.contains_xy(domain.polygon, centre[:, 0], centre[:, 1])]
    return dict(model=model, runs=runs, row=row, column=column, triangles=triangles,
                distance=(0.5 - p[row, 0], 0.5 - p[column, 1]), pull=pull)
