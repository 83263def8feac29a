"""Stress intensity factors by the domain form of the interaction integral.

With the SCNI solution (cell stresses ``σ`` and smoothed displacement
gradients ``∇u``, constant per integration cell) and the Williams auxiliary
fields of unit K_I or K_II (`williams`), in crack-tip coordinates::

    I = ∫_A [σ_ij ∂u_i^aux/∂x_1 + σ_ij^aux ∂u_i/∂x_1 - σ^aux_ij ε_ij δ_1j] ∂q/∂x_j dA
    K = E' I / 2

with the weight ``q = (1 - (r/R)^2)^2`` on the disc of radius ``R`` about the
tip (1 at the tip, 0 with a zero slope on the circle), integrated by a
quadrature on every cell polygon that reaches into the disc.
"""

from __future__ import annotations

import numpy as np

from ..assembly.quadrature import cell_quadrature
from ..errors import FractureError
from ..material import effective_modulus
from .williams import williams

__all__ = ["sif", "SIFResult"]


class SIFResult(tuple):
    """``(KI, KII)`` with the details: ``tip``, ``direction``, ``radius``, ``region``."""

    def __new__(cls, KI, KII, **details):
        obj = super().__new__(cls, (float(KI), float(KII)))
        obj.__dict__.update(details)
        return obj

    @property
    def KI(self):
        return self[0]

    @property
    def KII(self):
        return self[1]


def _local_spacing(model, tip):
    """Median length of the triangle edges at the tip node."""
    node = np.argmin(np.hypot(*(model.nodes - tip).T))
    tri = model.triangles[(model.triangles == node).any(axis=1)]
    edges = model.nodes[tri] - model.nodes[tri[:, [1, 2, 0]]]
    return float(np.median(np.hypot(edges[..., 0], edges[..., 1])))


def sif(sol, tip, *, radius=None, order=4):
    """Stress intensity factors K_I, K_II at a crack tip.

    Parameters
    ----------
    sol : ElasticSolution
        Plane stress or strain (taken from the solution).
    tip : (2,) array_like
        A point; the crack tip nearest to it is used.
    radius : float, optional
        Radius of the integration disc; default 6 local node spacings (the
        median edge length of the triangles at the tip). Path independence
        can be checked by comparing radii.
    order : int
        Degree of the triangle rule on the cells.

    Returns
    -------
    SIFResult
        ``(KI, KII)``, a tuple with attributes ``tip``, ``direction``,
        ``radius``, ``region``.

    Raises
    ------
    FractureError
        No tip; a disc that reaches into another material (the interaction
        integral needs one material), leaves no cell, or is not a positive number.
    """
    model = sol.model
    at, d = model.domain.tip_frame(tip)
    if radius is None:
        radius = 6.0 * _local_spacing(model, at)
    radius = float(radius)
    if not np.isfinite(radius) or radius <= 0:
        raise FractureError(f"radius: expected a positive number, received {radius}; leave it "
                            f"None for a few node spacings")
    cell, points, weights = cell_quadrature(sol.cells, model.nodes, order)
    rot = np.array([[d[0], d[1]], [-d[1], d[0]]])            # global -> crack-tip frame
    local = (points - at) @ rot.T
    r = np.hypot(local[:, 0], local[:, 1])
    near = r < radius
    if not near.any():
        raise FractureError(f"radius {radius:g} holds no integration point about the tip "
                            f"{at.tolist()}; expected at least one: choose a larger radius")
    regions = np.unique(sol.cells.region[cell[near]])
    if len(regions) > 1:
        raise FractureError(f"the disc of radius {radius:g} about the tip {at.tolist()} reaches "
                            f"into regions {regions.tolist()}; the interaction integral needs one "
                            "material: choose a smaller radius")
    cell, local, r, w = cell[near], local[near], r[near], weights[near]
    theta = np.arctan2(local[:, 1], local[:, 0])
    E, nu = sol.problem.materials[regions[0]]
    # q = (1 - rho^2)^2, grad q = -4 (1 - rho^2) x / R^2
    rho2 = (r / radius) ** 2
    grad_q = (-4.0 * (1.0 - rho2) / radius ** 2)[:, None] * local
    # the solution in the crack-tip frame, per point
    s = sol.stress[cell]
    sig = np.empty((len(cell), 2, 2))
    sig[:, 0, 0], sig[:, 1, 1], sig[:, 0, 1] = s[:, 0], s[:, 1], s[:, 2]
    sig[:, 1, 0] = sig[:, 0, 1]
    sig = rot @ sig @ rot.T
    grad_u = rot @ sol.gradient[cell] @ rot.T
    eps = 0.5 * (grad_u + np.swapaxes(grad_u, 1, 2))
    out = []
    for KI, KII in ((1.0, 0.0), (0.0, 1.0)):
        _, s_aux, du_aux = williams(r, theta, KI, KII, E, nu, sol.plane)
        sa = np.empty((len(cell), 2, 2))
        sa[:, 0, 0], sa[:, 1, 1], sa[:, 0, 1] = s_aux[:, 0], s_aux[:, 1], s_aux[:, 2]
        sa[:, 1, 0] = sa[:, 0, 1]
        # P_j = σ_ij du_aux_i/dx1 + σaux_ij du_i/dx1 - W δ_1j
        p = np.einsum("qij,qi->qj", sig, du_aux) + np.einsum("qij,qi->qj", sa, grad_u[:, :, 0])
        p[:, 0] -= np.einsum("qij,qij->q", sa, eps)
        out.append(float(w @ np.einsum("qj,qj->q", p, grad_q)))
    Ep = effective_modulus(E, nu, sol.plane)
    return SIFResult(0.5 * Ep * out[0], 0.5 * Ep * out[1], tip=at, direction=d, radius=radius,
                     region=int(regions[0]))
