"""`Problem`: a peridynamic body, its material and conditions; the bond operators and
statics (the solver layer's Newton). What differs between the materials is the material's
behaviour (`cnem.pd.behaviour`); explicit dynamics live in `cnem.pd.dynamics`."""

from __future__ import annotations

import logging
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp

from ..solvers.conditions import Conditions
from ..solvers.newton import LINE_SEARCH_HALVINGS, newton
from ..errors import InputError, MaterialError, UnsupportedError, check_array, check_choice
from .dynamics import Dynamics
from .moments import moment_tensors, live_inverse
from ..material import PLANES
from .solution import StaticSolution
from .tractions import BodyTractions
from .velocity import VelocityConditions

if TYPE_CHECKING:
    from typing import Callable

    from numpy.typing import ArrayLike

    from .behaviour import BondBehaviour, CPDBehaviour, StateBehaviour
    from ..geometry.domain import Domain
    from .body import Body
    from .cpd import CPD, Interactions
    from .materials import BondBased, StateBased

__all__ = ["Problem"]

log = logging.getLogger(__name__)


class Problem(BodyTractions, Conditions, VelocityConditions, Dynamics):
    """A peridynamic body with a material, loads and displacement conditions.

    Parameters
    ----------
    body : Body
    material : BondBased, StateBased or CPD
        CPD (nonlinear) supports `solve` (`solve_static`) only; its 2-D energies are defined on
        the plane directly (``plane`` is not used).
    plane : {"stress", "strain"}
        2-D only.
    surface_correction : bool, optional
        Energy method (Le & Bobaru): every point's bonds are scaled so that
        uniform test strains store the classical energy density at that point
        (this also removes the discretisation error of the horizon sums in the
        bulk). Default on for BondBased and StateBased; it does not apply to CPD,
        which uses the plain volumes.
    """

    def __init__(self, body: Body, material: BondBased | StateBased | CPD, *,
                 plane: str = "stress", surface_correction: bool | None = None):
        check_choice("plane", plane, PLANES)
        if not callable(getattr(material, "behaviour", None)):
            raise MaterialError(f"material: expected cnem.pd.BondBased, StateBased or CPD, "
                                f"received {type(material).__name__}")
        if not material.correctable and surface_correction:
            raise MaterialError(f"surface_correction=True: the surface correction does not apply "
                                f"to {type(material).__name__} (its energies use the plain "
                                f"volumes); leave it unset")
        self.body, self.material, self.plane = body, material, plane
        self.dim = body.dim
        self.surface_correction = material.correctable if surface_correction is None else \
            bool(surface_correction)
        super().__init__()
        self.alive = np.ones(len(body.bond_i), dtype=np.uint8)
        self._live_operators = None
        self._operators()

    def __repr__(self):
        return f"<Problem {self.body!r}, {self.material!r}, {self.conditions_repr()}>"

    # -- operators ----------------------------------------------------------------------
    def _operators(self):
        b = self.body
        self.weight = b.beta * b.volumes[b.bond_j]            # omega beta V_j, omega = 1
        #: how the material responds on these bonds (`cnem.pd.behaviour`)
        self.behaviour: BondBehaviour | StateBehaviour | CPDBehaviour = \
            self.material.behaviour(self)
        #: the energy-method bond factors (`cnem.pd.correction`), ones without the correction
        self.factor = self.behaviour.correction() if self.surface_correction else \
            np.ones(len(b.bond_i))

    # the behaviour's constants, where users have read them
    @property
    def bond_stiffness(self) -> float:
        """BondBased: the PMB micromodulus (one value for every bond)."""
        return self.behaviour.bond_stiffness

    @property
    def m(self) -> np.ndarray:
        """StateBased: ``(n,)`` weighted volumes."""
        return self.behaviour.m

    @property
    def bulk(self) -> float:
        """StateBased: the d-dimensional bulk modulus."""
        return self.behaviour.bulk

    @property
    def shear(self) -> float:
        """StateBased: the shear modulus."""
        return self.behaviour.shear

    @property
    def alpha(self) -> np.ndarray:
        """StateBased: ``(n,)`` ``mu d (d + 2) / m``."""
        return self.behaviour.alpha

    @property
    def interactions(self) -> Interactions:
        """CPD: the interactions of the body (`cnem.pd.cpd.Interactions`)."""
        return self.behaviour.interactions

    @cached_property
    def unit(self) -> np.ndarray:
        """``(b, d)`` unit bond directions."""
        return self.body.xi / self.body.length[:, None]

    @cached_property
    def A(self) -> sp.csr_matrix:
        """Extension operator ``e = A u``, sparse ``(b, d n)``."""
        b, d, n = self.body, self.dim, len(self.body)
        nb = len(b.bond_i)
        rows = np.repeat(np.arange(nb), 2 * d)
        cols = np.concatenate([d * b.bond_j[:, None] + np.arange(d),
                               d * b.bond_i[:, None] + np.arange(d)], axis=1).reshape(-1)
        vals = np.concatenate([self.unit, -self.unit], axis=1).reshape(-1)
        return sp.csr_matrix((vals, (rows, cols)), shape=(nb, d * n))

    @cached_property
    def moments(self) -> tuple[np.ndarray, np.ndarray]:
        """``(M, M^-1)``, ``(n, d, d)`` each: the moment tensors ``M_i = sum_b w_b xi_b
        xi_b^T`` of every point's reference family (``w = beta V_j``) and their inverses.

        Raises
        ------
        InputError
            A point whose bonds do not span every direction.
        """
        b = self.body
        M = moment_tensors(b.bond_i, b.xi, self.weight, len(b))
        if (np.linalg.det(M) <= 0).any():
            raise InputError(f"expected bonds spanning every direction at each point, received "
                             f"{int((np.linalg.det(M) <= 0).sum())} points with too few bonds; "
                             f"enlarge the horizon")
        return M, np.linalg.inv(M)

    @cached_property
    def gradient_weights(self) -> np.ndarray:
        """``(b, d)`` ``g_b = w_b M_i^-1 xi_b`` of every bond ``b = (i, j)``, with the moment
        tensors ``M_i`` of the reference family (`moments`): the nonlocal displacement
        gradient of point ``i`` is ``sum_b (u_j - u_i) g_b^T``, exact for linear fields
        also where the horizon is cut by a boundary.

        Raises
        ------
        InputError
            A point whose bonds do not span every direction.
        """
        b = self.body
        return np.einsum("bij,bj->bi", self.moments[1][b.bond_i], b.xi) * self.weight[:, None]

    def live_gradient_weights(self) -> np.ndarray:
        """``(b, d)`` `gradient_weights` of the live bonds: ``alive_b w_b M_i^+ xi_b`` with the
        moment tensor of the live bonds of ``i`` (`cnem.pd.moments.live_inverse`) at the
        points that lost bonds, the reference ``M_i^-1`` elsewhere."""
        b = self.body
        g = self.gradient_weights * self.alive[:, None]
        dead = self.alive == 0
        if not dead.any():
            return g
        hit = np.zeros(len(b), dtype=bool)
        hit[b.bond_i[dead]] = True
        rows = np.flatnonzero(hit)
        w = self.weight * self.alive
        live = moment_tensors(b.bond_i, b.xi, w, len(b))[rows]
        inv = np.zeros_like(self.moments[1])
        inv[rows] = live_inverse(live, self.moments[0][rows])
        sel = hit[b.bond_i]
        g[sel] = np.einsum("bij,bj->bi", inv[b.bond_i[sel]], b.xi[sel]) * w[sel, None]
        return g

    def displacement_gradient(self, u: np.ndarray) -> np.ndarray:
        """Nonlocal displacement gradient of every point, ``(n, d, d)``,
        ``[i, a, c] = du_a/dx_c`` (see `gradient_weights`; all bonds of the family).

        Parameters
        ----------
        u : (n, d) array_like
        """
        b = self.body
        u = np.asarray(u, dtype=float).reshape(len(b), self.dim)
        per = (u[b.bond_j] - u[b.bond_i])[:, :, None] * self.gradient_weights[:, None, :]
        out = np.zeros((len(b), self.dim, self.dim))
        np.add.at(out, b.bond_i, per)
        return out

    def _state_live(self) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """``(T, Edev)`` of the bonds alive now (built again only after a bond broke)."""
        cached = self._live_operators
        if cached is not None and np.array_equal(cached[0], self.alive):
            return cached[1], cached[2]
        b, d, n = self.body, self.dim, len(self.body)
        # the dilatation theta_i = sum over the live bonds of w (u_j - u_i) . M_i^-1 xi,
        # M_i of the live bonds: the trace of their nonlocal gradient
        g = self.live_gradient_weights()
        rows = np.repeat(b.bond_i, 2 * d)
        cols = np.concatenate([d * b.bond_j[:, None] + np.arange(d),
                               d * b.bond_i[:, None] + np.arange(d)], axis=1).reshape(-1)
        vals = np.concatenate([g, -g], axis=1).reshape(-1)
        T = sp.csr_matrix((vals, (rows, cols)), shape=(n, d * n))
        # deviatoric extension e^d = E u = A u - (L / d) theta_i
        S = sp.csr_matrix((b.length / d, (np.arange(len(b.bond_i)), b.bond_i)),
                          shape=(len(b.bond_i), n))
        Edev = (self.A - S @ T).tocsr()
        self._live_operators = (self.alive.copy(), T, Edev)
        return T, Edev

    @property
    def T(self) -> sp.csr_matrix:
        """Dilatation operator ``theta = T u`` of the live bonds, sparse ``(n, d n)``: a broken
        bond carries no dilatation (nor force) across a crack."""
        return self._state_live()[0]

    @property
    def Edev(self) -> sp.csr_matrix:
        """Deviatoric extension operator ``e^d = Edev u = A u - (L / d) theta_i`` (``theta``
        of the live bonds), sparse ``(b, d n)``."""
        return self._state_live()[1]

    def _linear_only(self, what):
        """Refuse a nonlinear behaviour (CPD) in the methods of the linear (bond- and
        state-based) models."""
        if not self.behaviour.linear:
            raise UnsupportedError(
                f"{what} is available for BondBased and StateBased materials, not for CPD "
                "(nonlinear, nonlocal measures): use solve, its displacements u, or "
                "Problem.interactions.evaluate(u) for energy, forces and tangent")

    # -- energies -----------------------------------------------------------------------
    def energy_density(self, u: np.ndarray, factor: np.ndarray | None = None) -> np.ndarray:
        """Strain energy density of every point, ``(n,)``."""
        self._linear_only("energy_density")
        return self.behaviour.energy_density(u, self.factor if factor is None else factor)

    def stiffness(self) -> sp.csr_matrix:
        """Sparse stiffness ``(d n, d n)``: the Hessian of the total strain energy
        ``sum_i V_i W_i`` (exact tangent of the linear models), live bonds only."""
        self._linear_only("stiffness")
        return self.behaviour.stiffness()

    def pmb_weights(self) -> np.ndarray:
        """``(b,)`` the PMB stiffness of every bond, live or not: the stiffness is
        ``A^T diag(w alive) A`` (`stiffness`; BondBased only)."""
        return self.behaviour.pmb_weights()

    def stress_tensor(self, u: np.ndarray) -> np.ndarray:
        """Stress of every point from its bonds, ``(n, d, d)`` (``dW_i / d eps`` for a
        uniform strain: the classical stress in a uniform field). The solutions give
        it in Voigt form as ``stress``."""
        self._linear_only("stress_tensor")
        return self.behaviour.stress_tensor(u)

    # -- conditions (`Conditions`: add_dirichlet, add_body_force; `BodyTractions`) ------
    points_name = "body.points"

    @property
    def condition_points(self) -> np.ndarray:
        """``(n, d)`` the points that conditions refer to (``body.points``)."""
        return self.body.points

    names_fix = ("build the body with Body.from_cloud(cloud), which keeps the domain, or "
                 "select with a predicate, a mask or indices")

    @property
    def condition_domain(self) -> Domain | None:
        """The domain of a body from a node cloud (`Body.from_cloud`), else None: its
        named boundaries may be given as ``where``."""
        model = getattr(self.body, "model", None)
        return None if model is None else model.domain

    def load(self) -> np.ndarray:
        """External forces ``(d n,)``: body forces times volumes, and the point forces of
        the tractions (`traction_forces`)."""
        f = self.traction_forces()
        for b in self.body_forces_at(self.body.points):
            f += self.body.volumes[:, None] * b
        return f.reshape(-1)

    # -- statics ------------------------------------------------------------------------
    #: Most step halvings of the backtracking line search of `solve`.
    LINE_SEARCH_HALVINGS = LINE_SEARCH_HALVINGS

    def solve_static(self, *, tol: float = 1e-10, steps: int = 1, initial: ArrayLike | None = None,
                     max_iterations: int = 20, line_search: bool = False) -> StaticSolution:
        """The former name of `solve` (the static Newton solve), kept as an alias:
        the same parameters and result."""
        return self.solve(tol=tol, steps=steps, initial=initial, max_iterations=max_iterations,
                          line_search=line_search)

    def solve(self, *, tol: float = 1e-10, steps: int = 1, initial: np.ndarray | None = None,
              max_iterations: int = 20, line_search: bool = False) -> StaticSolution:
        """Newton-Raphson with the exact tangent, Dirichlet values and loads ramped in
        ``steps`` equal increments.

        The residual is ``R(u) = f_int(u) - f_ext`` on the free dofs (``K u - f_ext`` for
        BondBased and StateBased, solved by the first correction). Each load step starts
        with a tangent predictor: the increments of the Dirichlet values and loads,
        spread over the free dofs by a solve with the last tangent; its linearised
        residual is the step's first entry. A step has converged when ``|R| <= tol``
        times the largest of the norms of its load, of the reactions at the prescribed
        dofs and of that first entry.
        Nonlinear materials (CPD) solve each correction to a relative tolerance
        ``min(NEWTON_FORCING, |R| / reference)`` (`cnem.config`; inexact Newton, still quadratic).

        Parameters
        ----------
        tol : float
        steps : int
            Load steps.
        initial : (n, d) array_like, optional
            Starting displacements (the Dirichlet values replace theirs).
        max_iterations : int
            Newton corrections allowed per load step.
        line_search : bool
            Backtrack along each correction (halving the step up to
            ``LINE_SEARCH_HALVINGS`` times) until the residual norm decreases.

        Returns
        -------
        StaticSolution
            ``u (n, d)``, ``residual_history``: the residual norms of the free dofs at
            each Newton iterate, one list per load step.

        Raises
        ------
        SolveError
            Rigid motions not fixed (named), or a linear solve that fails.
        ConvergenceError
            A load step that does not converge, or whose residual goes non-finite
            (named, with its residuals; the error's ``history`` holds those of every
            load step so far).
        """
        self.static_only("solve")
        if initial is not None:
            initial = check_array("initial", initial, shape=(len(self.body), self.dim),
                                  fix="pass a displacement of every point, e.g. a previous "
                                      "solution's u")
        evaluate, pattern = self.behaviour.static_system()
        D, values = self.prescribed()
        u, history = newton(evaluate, self.load(), D, values, points=self.body.points,
                            pattern=pattern, initial=initial, tol=tol, steps=steps,
                            max_iterations=max_iterations, line_search=line_search,
                            linear=self.behaviour.linear,
                            halvings=self.LINE_SEARCH_HALVINGS)
        return StaticSolution(self, u.reshape(len(self.body), self.dim),
                              residual_history=history)

