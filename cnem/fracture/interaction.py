"""Stress intensity factors by the domain form of the interaction integral, checked on nested discs.

With the SCNI solution (cell stresses ``σ`` and smoothed displacement
gradients ``∇u``, constant per integration cell) and the Williams auxiliary
fields of unit K_I or K_II (`williams`), in crack-tip coordinates::

    I = ∫_A [σ_ij ∂u_i^aux/∂x_1 + σ_ij^aux ∂u_i/∂x_1 - σ^aux_ij ε_ij δ_1j] ∂q/∂x_j dA
    K = E' I / 2

with the weight ``q = (1 - (r/R)^2)^2`` on the disc of radius ``R`` about the
tip (1 at the tip, 0 with a zero slope on the circle), integrated by a
quadrature on every cell polygon that reaches into the disc.

The integral is the same on every disc that stays in one material and clear of
other boundaries and cracks (`cnem.fracture.discs`), so `sif` evaluates it on a
few nested discs below that limit: K is taken from the largest disc (the most
accurate on every cloud measured: the near-tip error of the field weighs less
the larger the disc), and the spread of K over the discs is the check.
"""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING

import numpy as np

from .. import config
from ..assembly.quadrature import cell_quadrature
from ..errors import FractureError, SIFWarning, check_array, check_real
from ..material import effective_modulus
from .discs import clearance, default_radii, local_spacing
from .williams import williams
from .._sets import distinct

if TYPE_CHECKING:
    from typing import Any

__all__ = ["sif", "SIFResult"]


class SIFResult(tuple):
    """``(KI, KII)`` with the details: ``tip``, ``direction``, ``radius`` (the disc K is
    taken from), ``region``, ``radii`` (every disc), ``values`` (``(k, 2)`` K_I, K_II per
    disc), ``spread`` (largest range of K_I or K_II over the discs, relative to
    ``hypot(KI, KII)``; NaN for one disc) and ``clearance`` (the radius at which a disc
    meets an obstacle, `cnem.fracture.discs.Clearance`)."""

    def __new__(cls, KI, KII, **details):
        obj = super().__new__(cls, (float(KI), float(KII)))
        obj.__dict__.update(details)
        return obj

    @property
    def KI(self) -> float:
        return self[0]

    @property
    def KII(self) -> float:
        return self[1]


def _near_cells(cells, at, radius):
    """Indices of the cells whose bounding box reaches into the disc."""
    start = cells.offsets[:-1]
    lo = np.minimum.reduceat(cells.vertices, start, axis=0)
    hi = np.maximum.reduceat(cells.vertices, start, axis=0)
    gap = np.maximum(np.maximum(lo - at, at - hi), 0.0)
    return np.flatnonzero(np.hypot(gap[:, 0], gap[:, 1]) < radius)


def _tensor(voigt):
    """``(q, 3)`` ``[s11, s22, s12]`` -> ``(q, 2, 2)``."""
    t = np.empty((len(voigt), 2, 2))
    t[:, 0, 0], t[:, 1, 1], t[:, 0, 1] = voigt[:, 0], voigt[:, 1], voigt[:, 2]
    t[:, 1, 0] = t[:, 0, 1]
    return t


def _disc_integrals(sol, at, d, radii, order):
    """K_I and K_II on discs of every radius about the tip ``at`` (direction ``d``).

    Returns
    -------
    values : (k, 2) ndarray
    region : int
        The material region of the discs.
    """
    big = float(np.max(radii))
    near = _near_cells(sol.cells, at, big)
    cells = sol.cells.subset(near)
    cell, points, weights = cell_quadrature(cells, sol.model.nodes, order)
    rot = np.array([[d[0], d[1]], [-d[1], d[0]]])            # global -> crack-tip frame
    local = (points - at) @ rot.T
    r = np.hypot(local[:, 0], local[:, 1])
    inside = r < big
    if not (r < np.min(radii)).any():
        raise FractureError(f"radius {np.min(radii):g} holds no integration point about the tip "
                            f"{at.tolist()}; expected at least one: choose a larger radius")
    cell, local, r, w = near[cell[inside]], local[inside], r[inside], weights[inside]
    regions = distinct(sol.cells.region[cell])
    if len(regions) > 1:
        raise FractureError(f"the disc of radius {big:g} about the tip {at.tolist()} reaches "
                            f"into regions {regions.tolist()}; the interaction integral needs one "
                            "material: choose a smaller radius")
    theta = np.arctan2(local[:, 1], local[:, 0])
    E, nu = sol.problem.materials[regions[0]]
    sig = rot @ _tensor(sol.stress[cell]) @ rot.T              # the solution in the tip frame
    grad_u = rot @ sol.gradient[cell] @ rot.T
    eps = 0.5 * (grad_u + np.swapaxes(grad_u, 1, 2))
    integrands = []
    for KI, KII in ((1.0, 0.0), (0.0, 1.0)):
        _, s_aux, du_aux = williams(r, theta, KI, KII, E, nu, sol.plane)
        sa = _tensor(s_aux)
        # P_j = σ_ij du_aux_i/dx1 + σaux_ij du_i/dx1 - W δ_1j
        p = np.einsum("qij,qi->qj", sig, du_aux) + np.einsum("qij,qi->qj", sa, grad_u[:, :, 0])
        p[:, 0] -= np.einsum("qij,qij->q", sa, eps)
        integrands.append(np.einsum("qj,qj->q", p, local))
    integrands = np.array(integrands)
    values = np.empty((len(radii), 2))
    for k, R in enumerate(radii):
        # q = (1 - rho^2)^2, grad q = -4 (1 - rho^2) x / R^2
        m = r < R
        grad_q = -4.0 * (1.0 - (r[m] / R) ** 2) / R ** 2
        values[k] = integrands[:, m] @ (w[m] * grad_q)
    return 0.5 * effective_modulus(E, nu, sol.plane) * values, int(regions[0])


def _spread(values):
    """Largest range of K_I or K_II over the discs relative to ``|K|`` of the largest disc."""
    if len(values) < 2:
        return float("nan")
    size = np.hypot(*values[-1])
    return float(np.ptp(values, axis=0).max() / size) if size > 0 else float("nan")


def _check(res, spacing, limited_by, user):
    """Warn (`SIFWarning`) when the discs disagree, hold too few node spacings (the
    default discs or a user's), or a user's disc reaches past an obstacle."""
    lim, at = res.clearance, res.tip.tolist()
    best = config.SIF_REACH * lim.distance
    if user and res.radius >= lim.distance:
        warnings.warn(f"the disc of radius {res.radius:.4g} about the tip {at} reaches "
                      f"{lim.obstacle} at {lim.point.tolist()} ({lim.distance:.4g} from the "
                      f"tip): the interaction integral does not hold across it; use a radius "
                      f"below {lim.distance:.4g}, e.g. {best:.4g} (leave radius=None to check "
                      "nested discs up to it)", SIFWarning, stacklevel=3)
        return
    if user and res.radius < config.SIF_SPACINGS * spacing:
        warnings.warn(f"the disc of radius {res.radius:.4g} about the tip {at} holds only "
                      f"{res.radius / spacing:.2g} local node spacings ({spacing:.4g}): K is not "
                      f"resolved on such a disc; use a radius of at least "
                      f"{config.SIF_SPACINGS * spacing:.4g} (leave radius=None for nested discs "
                      f"up to {lim.obstacle})", SIFWarning, stacklevel=3)
        return
    if not user and res.radius < config.SIF_SPACINGS * spacing:
        warnings.warn(f"only {res.radius / spacing:.2g} local node spacings ({spacing:.4g}) fit "
                      f"between the tip {at} and {limited_by}: K is not resolved on such "
                      f"discs; refine the nodes near the tip (to a spacing below "
                      f"{res.radius / (2 * config.SIF_SPACINGS):.3g})", SIFWarning, stacklevel=3)
    elif res.spread > config.SIF_SPREAD:
        K = ", ".join(f"R = {R:.4g}: ({a:.5g}, {b:.5g})" for R, (a, b) in zip(res.radii, res.values))
        warnings.warn(f"K_I, K_II at the tip {at} vary by {100 * res.spread:.3g} % of |K| over "
                      f"the discs [{K}] (more than {100 * config.SIF_SPREAD:g} %): the largest "
                      f"disc, radius {res.radii[-1]:.4g} (limited by {limited_by}), is "
                      f"the most reliable; use it, or refine the nodes near the tip for a "
                      "converged K", SIFWarning, stacklevel=3)


def sif(sol: Any, tip: np.ndarray, *, radius: float | None = None, order: int = 4) -> SIFResult:
    """Stress intensity factors K_I, K_II at a crack tip, checked on nested discs.

    Parameters
    ----------
    sol : ElasticSolution
        Plane stress or strain (taken from the solution).
    tip : (2,) array_like
        A point; the crack tip nearest to it is used.
    radius : float, optional
        One integration disc of this radius. Default: ``config.SIF_DISCS`` nested discs
        from half the largest to the largest, ``config.SIF_REACH`` (0.9) times the
        distance from the tip to the first obstacle (the outer boundary, a hole, an
        interface, another crack, the other tip; a kink behind the tip too, but not
        below six node spacings: `cnem.fracture.discs`); K is that of the largest disc.
    order : int
        Degree of the triangle rule on the cells.

    Returns
    -------
    SIFResult
        ``(KI, KII)``, a tuple with attributes ``tip``, ``direction``, ``radius``,
        ``region``, ``radii``, ``values``, ``spread``, ``clearance``.

    Warns
    -----
    SIFWarning
        K varies over the default discs by more than ``config.SIF_SPREAD`` (1 %) of
        ``|K|``, or fewer than ``config.SIF_SPACINGS`` node spacings fit in the largest
        disc, or ``radius`` reaches an obstacle; the message says which radius to use
        or what to refine.

    Raises
    ------
    FractureError
        No tip; a disc that reaches into another material (the interaction
        integral needs one material), leaves no cell, or is not a positive number.
    """
    if not (hasattr(sol, "model") and hasattr(sol, "stress") and hasattr(sol, "u")):
        raise FractureError(f"sif expects the solution of an elasticity problem "
                            f"(prob.solve()), received {type(sol).__name__}; solve the problem "
                            f"first and pass what solve() returns")
    tip_arr = np.asarray(check_real("tip", tip, error=FractureError), dtype=float)
    if tip_arr.shape != (2,):
        raise FractureError(f"tip: expected one point (x, y), received shape {tip_arr.shape}; "
                            f"call sif once per tip")
    tip = check_array("tip", tip_arr, error=FractureError, fix="pass a point near the tip")
    model = sol.model
    at, d = model.domain.tip_frame(tip)
    limit = clearance(model.domain, at, d)
    user = radius is not None
    if user:
        given = radius
        try:
            radius = float(radius)
        except (TypeError, ValueError):
            radius = float("nan")
        if not np.isfinite(radius) or radius <= 0:
            raise FractureError(f"radius: expected a positive number, received {given!r}; leave "
                                f"it None for nested discs up to {limit.obstacle}")
        radii, spacing, limited_by = np.array([radius]), local_spacing(model, at), limit.obstacle
    else:
        radii, spacing, limited_by = default_radii(model, at, limit)
    values, region = _disc_integrals(sol, at, d, radii, order)
    res = SIFResult(*values[-1], tip=at, direction=d, radius=float(radii[-1]), region=region,
                    radii=radii, values=values, spread=_spread(values), clearance=limit)
    _check(res, spacing, limited_by, user)
    return res
