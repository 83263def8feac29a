"""`CPD`: continuum-kinematics-inspired peridynamics, residual and consistent tangent with
hyper-dual numbers.

A point ``a`` interacts with each neighbour (one-neighbour: the bond vector
``xi = y_i - y_a``, eq. 2), each unordered pair of neighbours (two-neighbour: the area
``a = xi_i x xi_j``, eq. 3, a scalar in 2-D) and, in 3-D, each unordered triplet (three-
neighbour: the volume ``v = (xi_i x xi_j) . xi_k``, eq. 4). The discrete energy (eq. 8) is

    Psi = sum_a V_a [ 1/2 sum_i psi1 V^i + 1/3 sum_{i != j} psi2 V^i V^j
                      + 1/4 sum_{i != j != k} psi3 V^i V^j V^k ],

``V^i = beta_ai V_i`` (partial volumes of the body), each unordered pair (triplet) evaluated
once with weight 2/3 (3/2). The interaction energies are ``psi1 = C1 |Xi| p1(lam_xi)``,
``psi2 = C2 |A| p2(lam_a)``, ``psi3 = C3 |V| p3(lam_v)`` with the stretches of eq. 40
(``lam_xi = |xi| / |Xi|``, ``lam_a = |a| / |A|``, ``lam_v = v / V``) and, by default,
the Seth-Hill energies ``p(lam) = S_n(lam)^2 / 2`` of eq. 41-42.

The residual is ``R = dPsi/du - f_ext`` (eq. 19) and the tangent ``K = d2Psi/du2``
(eq. 20). As in §4 of the paper, the first and second derivatives of each interaction
energy with respect to its deformation measure (``xi``, ``a``, ``v``: eq. 35 and 39) come
from hyper-dual numbers (`cnem.hyperdual`: ``c (c + 1) / 2`` seeded evaluations for a
measure of ``c`` components, one for the 2-D area and the volume), so that any energy
written with ``hd`` functions works unchanged. The exact, model-independent geometry of
eq. 37-38 (the measures are linear, bilinear and trilinear in the bond vectors) maps
them to the bond vectors and the fixed +-1 incidence of a bond to its two points maps
those to the nodes (`cnem.pd.cpd.Interactions`). All interactions are evaluated in
vectorised chunks and their blocks scattered into a precomputed block pattern.
``derivatives="analytic"`` uses hand-derived Seth-Hill derivatives instead and ``"fd"``
central finite differences (for comparison).

>>> import numpy as np, cnem.pd as pd
>>> g = np.arange(4.0)
>>> body = pd.Body(np.array([(x, y) for x in g for y in g]), 1.0, 1.5)
>>> inter = pd.CPD(1.0, 0.5).interactions(body)
>>> energy, force, K = inter.evaluate(np.zeros((16, 2)))
>>> energy, float(np.abs(force).max()), K.shape
(0.0, 0.0, (32, 32))
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .. import config
from .. import hyperdual as hd
from ..errors import MaterialError, check_choice
from ._cpd_assembly import Interactions
from .behaviour import CPDBehaviour

if TYPE_CHECKING:
    from typing import Any, Callable

    from .body import Body

__all__ = ["CPD", "Interactions", "seth_hill", "DERIVATIVES"]

#: How the derivatives of the interaction energies are computed.
DERIVATIVES = ("hyperdual", "analytic", "fd")


def seth_hill(exponent: float) -> Callable[[np.ndarray], np.ndarray]:
    """Seth-Hill energy ``p(lam) = S(lam)^2 / 2``, ``S = (lam^n - 1) / n`` or ``ln lam`` (n = 0).

    Works on arrays and on `cnem.hyperdual.HyperDual` numbers (eq. 41-42 per unit
    constant and reference measure).
    """
    n = float(exponent)

    def psi(lam):
        s = hd.log(lam) if n == 0 else (hd.power(lam, n) - 1.0) / n
        return 0.5 * s * s
    psi.__name__ = f"seth_hill_{n:g}"
    return psi


def _seth_hill_derivatives(lam, n):
    """``p, p', p''`` of `seth_hill` in closed form."""
    s = np.log(lam) if n == 0 else (lam ** n - 1.0) / n
    s1 = lam ** (n - 1.0)
    s2 = (n - 1.0) * lam ** (n - 2.0)
    return 0.5 * s * s, s * s1, s1 * s1 + s * s2


class CPD:
    """Continuum-kinematics-inspired peridynamic material (Javili et al.).

    Parameters
    ----------
    C1 : float
        One-neighbour constant (> 0: without it the pair and triplet interactions alone
        leave zero-energy modes).
    C2, C3 : float
        Two- and three-neighbour constants (>= 0). C3 needs 3-D bodies.
    exponent : float
        ``n`` of the default Seth-Hill energies (eq. 42): 2 Green-Lagrange-like, 1
        Biot-like, 0 logarithmic.
    psi1, psi2, psi3 : callable, optional
        Energies per unit constant and reference measure as functions of the stretch,
        ``p(lam) -> same shape``, written with `cnem.hyperdual` functions (they receive
        HyperDual numbers with ``derivatives="hyperdual"``, arrays with ``"fd"``); they
        replace the Seth-Hill energy of that interaction. Should vanish with their first
        derivative at ``lam = 1`` for a stress-free reference state.
    derivatives : {"hyperdual", "analytic", "fd"}
        Hyper-dual numbers (any energy), hand-written derivatives (Seth-Hill only) or
        central finite differences of relative step `cnem.config.FD_STEP` (approximate).

    Notes
    -----
    Surface corrections do not apply: the plain body volumes are used.
    """

    #: A label of the model (the problem asks the `behaviour`, not the label).
    kind = "cpd"
    #: The energy-method surface correction does not apply (plain volumes).
    correctable = False

    def __init__(self, C1: float, C2: float = 0.0, C3: float = 0.0, *, exponent: float = 2.0,
                 psi1: Callable[..., np.ndarray] | None = None,
                 psi2: Callable[..., np.ndarray] | None = None,
                 psi3: Callable[..., np.ndarray] | None = None, derivatives: str = "hyperdual"):
        C = [float(C1), float(C2), float(C3)]
        if not (np.isfinite(C).all() and C[0] > 0 and C[1] >= 0 and C[2] >= 0):
            raise MaterialError(f"CPD: expected C1 > 0, C2 >= 0, C3 >= 0 (finite), received "
                                f"C1={C1}, C2={C2}, C3={C3}")
        self.C1, self.C2, self.C3 = C
        self.exponent = float(exponent)
        if not np.isfinite(self.exponent):
            raise MaterialError(f"exponent: expected a finite number, received {exponent}")
        check_choice("derivatives", derivatives, DERIVATIVES)
        self.derivatives = derivatives
        given = (psi1, psi2, psi3)
        for k, (psi, c) in enumerate(zip(given, C), start=1):
            if psi is not None and not callable(psi):
                raise MaterialError(f"psi{k}: expected a function of the stretch, received "
                                    f"{type(psi).__name__}")
            if psi is not None and c == 0:
                raise MaterialError(f"psi{k} is given but C{k} = 0, so it would never be used; "
                                    f"give C{k} > 0 or drop psi{k}")
        if derivatives == "analytic" and any(p is not None for p in given):
            raise MaterialError("derivatives='analytic' is written for the Seth-Hill energies "
                                "only; with user energies psi1/psi2/psi3 use 'hyperdual'")
        default = seth_hill(self.exponent)
        self.psi = tuple(default if p is None else p for p in given)
        self.user = tuple(p is not None for p in given)

    def behaviour(self, problem: Any) -> CPDBehaviour:
        """The interactions of ``problem``'s body (a `cnem.pd.Problem`) as its behaviour
        (`cnem.pd.behaviour.CPDBehaviour`)."""
        return CPDBehaviour(problem)

    def interactions(self, body: Body) -> Interactions:
        """The interactions of ``body`` this material needs.

        Returns
        -------
        Interactions
            Bonds, pairs (C2 or C3 > 0) and triplets (C3 > 0) with their reference
            measures, and ``evaluate(u) -> (energy, force, tangent)``.

        Raises
        ------
        MaterialError
            C3 > 0 on a 2-D body.
        LimitError
            More pairs or triplets than `cnem.config.MAX_INTERACTIONS`.
        """
        if body.dim == 2 and self.C3 != 0:
            raise MaterialError(f"C3 = {self.C3:g}: three-neighbour (volume) interactions exist "
                                f"in 3-D only; for a 2-D body set C3=0")
        return Interactions(body, self)

    def measure_derivatives(self, order: int, g: np.ndarray,
                            ref: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Energy of ``order``-neighbour interactions, ``phi = C |R| p(lam)``, and its
        first and second derivatives with respect to the deformation measure
        (eq. 35, 39).

        Parameters
        ----------
        order : {1, 2, 3}
        g : (m, c) ndarray
            Measures: bond vectors (c = d), areas (c = 1 in 2-D, 3 in 3-D), volumes (c = 1).
        ref : (m,) ndarray
            Reference measures ``R``: lengths, areas ``|A|``, signed volumes ``V``.

        Returns
        -------
        value : (m,) ndarray
        first : (m, c) ndarray
        second : (m, c, c) ndarray
        """
        C, psi = (self.C1, self.C2, self.C3)[order - 1], self.psi[order - 1]
        weight = C * np.abs(ref)
        signed = order == 3
        vector = g.shape[1] > 1

        def energy(x):
            size = hd.norm(x) if vector else (x if signed else abs(x))
            return weight * psi(size / ref)
        if self.derivatives == "analytic":
            value, first, second = _seth_hill_measure(g if vector else g[:, 0], ref, C,
                                                      self.exponent, signed)
        elif self.derivatives == "hyperdual":
            value, first, second = (hd.derivatives(energy, g) if vector else
                                    hd.derivative(energy, g[:, 0]))
        else:
            value, first, second = _finite_differences(energy, g if vector else g[:, 0],
                                                       config.FD_STEP * np.abs(ref))
        return value, first.reshape(g.shape), second.reshape(len(g), g.shape[1], -1)

    def __repr__(self):
        energy = "user energies" if any(self.user) else f"Seth-Hill n={self.exponent:g}"
        return (f"<CPD C1={self.C1:g}, C2={self.C2:g}, C3={self.C3:g}, {energy}, "
                f"{self.derivatives} derivatives>")


def _seth_hill_measure(g, ref, C, n, signed):
    """`CPD.measure_derivatives` of the Seth-Hill energies by hand: ``phi = C |R| p(lam)``
    with ``lam = |g| / R`` (vector or unsigned scalar measures, R > 0) or ``g / R``."""
    if g.ndim == 1:
        lam = g / ref if signed else np.abs(g) / ref
        p, p1, p2 = _seth_hill_derivatives(lam, n)
        slope = 1.0 / ref if signed else np.sign(g) / ref             # dlam/dg
        scale = C * np.abs(ref)
        return scale * p, scale * p1 * slope, scale * p2 / (ref * ref)
    size = np.sqrt(np.einsum("mk,mk->m", g, g))
    lam = size / ref
    p, p1, p2 = _seth_hill_derivatives(lam, n)
    unit = g / size[:, None]
    nn = unit[:, :, None] * unit[:, None, :]
    eye = np.eye(g.shape[1])
    second = (C * p2 / ref)[:, None, None] * nn + (C * p1 / size)[:, None, None] * (eye - nn)
    return C * ref * p, (C * p1)[:, None] * unit, second


def _finite_differences(f, g, h):
    """Value, central-difference gradient and Hessian of ``f`` at ``g`` ((m,) or (m, k)),
    steps ``h (m,)``."""
    f0 = f(g)
    if g.ndim == 1:
        fp, fm = f(g + h), f(g - h)
        return f0, (fp - fm) / (2 * h), (fp - 2 * f0 + fm) / (h * h)
    k = g.shape[1]
    step = h[:, None] * np.eye(k)[:, None, :]                           # (k, m, k)
    fp = np.array([f(g + s) for s in step])
    fm = np.array([f(g - s) for s in step])
    grad = ((fp - fm) / (2 * h)).T
    hess = np.empty((len(g), k, k))
    for p in range(k):
        hess[:, p, p] = (fp[p] - 2 * f0 + fm[p]) / (h * h)
        for q in range(p + 1, k):
            mixed = (f(g + step[p] + step[q]) - f(g + step[p] - step[q])
                     - f(g - step[p] + step[q]) + f(g - step[p] - step[q]))
            hess[:, p, q] = hess[:, q, p] = mixed / (4 * h * h)
    return f0, grad, hess
