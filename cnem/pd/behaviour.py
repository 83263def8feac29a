"""How a peridynamic material responds on one problem's bonds: its behaviour object.

Each material builds its behaviour for a `cnem.pd.Problem` (``material.behaviour(problem)``):
`BondBehaviour` (PMB), `StateBehaviour` (LPS) and `CPDBehaviour`. The problem asks it,
never the material's kind, for what differs between the models: the internal forces and
tangent (``evaluate``), and for the linear models the energy density, stiffness, stress,
surface-correction factors, stable time step and the forces of explicit dynamics. A
behaviour reads the problem's kinematic operators (``A``, ``T``, ``Edev``, ``unit``,
``weight``) and its state (``alive``, ``factor``) when it is asked, so it follows bonds
breaking.

>>> import numpy as np, cnem.pd as pd
>>> g = np.arange(4.0)
>>> prob = pd.Problem(pd.Body(np.array([(x, y) for x in g for y in g]), 1.0, 1.5),
...                   pd.StateBased(1.0, 0.25))
>>> force, K = prob.behaviour.evaluate(np.zeros(32), tangent=True)
>>> prob.behaviour.linear, float(np.abs(force).max()), K.shape
(True, 0.0, (32, 32))
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp

from ._pmb_kernels import pmb_forces
from .correction import fit, pmb_factors, state_test_fields, classical_density

if TYPE_CHECKING:
    from typing import Any, Callable

__all__ = ["LinearBehaviour", "BondBehaviour", "StateBehaviour", "CPDBehaviour"]


class LinearBehaviour:
    """A linear (small-displacement) peridynamic model: the internal forces are ``K u``
    with the stiffness of the live bonds.

    Parameters
    ----------
    problem : cnem.pd.Problem
        The problem whose bonds these are (its material, operators and state are read).

    Subclasses give `stiffness`, `energy_density`, `_stress_parts`, `correction`,
    `stable_diagonal`, `force_state`, `internal_force`, `elastic_energy` and
    `stiffness_without`.

    Attributes
    ----------
    problem : cnem.pd.Problem
    linear : bool
        True: one solve with ``K`` is the equilibrium; the linear-only methods of the
        problem (energies, stress, dynamics) are available.
    has_stress : bool
        The solutions write ``stress`` (and its invariants) besides ``u`` and ``strain``.
    """

    linear = True
    has_stress = True

    def __init__(self, problem: Any):
        self.problem = problem

    def evaluate(self, u: np.ndarray, tangent: bool = True) -> tuple[np.ndarray, sp.csr_matrix]:
        """Internal forces ``K u`` ``(d n,)`` and the stiffness ``K`` of the live bonds (given
        also when ``tangent`` is False)."""
        K = self.stiffness()
        return K @ u, K

    def static_system(self) -> tuple[Callable, sp.csr_matrix]:
        """``evaluate(u, tangent) -> (K u, K)`` with the stiffness of the live bonds
        assembled once, and that stiffness (its pattern): for one static solve."""
        K = self.stiffness()
        return lambda u, tangent: (K @ u, K), K

    def stress_tensor(self, u: np.ndarray) -> np.ndarray:
        """Stress of every point from its bonds, ``(n, d, d)`` (``dW_i / d eps`` for a
        uniform strain): the points' own part and their live bonds' (`_stress_parts`)."""
        p = self.problem
        x = np.asarray(u, dtype=float).reshape(-1)
        nn = p.unit[:, :, None] * p.unit[:, None, :]
        live = p.alive.astype(bool)
        out, per = self._stress_parts(x, nn, live)
        np.add.at(out, p.body.bond_i, per)
        return out

    def stable_diagonal(self) -> np.ndarray:
        """``(n d,)`` or ``(n,)``: the row sums ``sum_j C_ij V_j`` per unit volume whose largest
        sets the stable time step ``sqrt(2 rho / max)``."""
        p = self.problem
        K = self.stiffness()
        return np.abs(K).sum(axis=1).A.reshape(-1) / np.repeat(p.body.volumes, p.dim)

    def force_state(self) -> dict:
        """What `internal_force` keeps between calls: the stiffness of the live bonds."""
        return {"K": self.stiffness()}

    def internal_force(self, u: np.ndarray, limit: float, state: dict) -> tuple[np.ndarray, int]:
        """Force per unit volume ``(n, d)`` at ``u (n, d)``, breaking the bonds stretched
        beyond ``limit`` first; and the number broken."""
        p = self.problem
        b = p.body
        stretch = np.sqrt(((b.xi + u[b.bond_j] - u[b.bond_i]) ** 2).sum(axis=1)) / b.length - 1
        broken = int(((stretch > limit) & (p.alive == 1)).sum())
        if broken:
            p.alive[stretch > limit] = 0
            state["K"] = self.stiffness()
        return -(state["K"] @ u.reshape(-1)).reshape(u.shape) / b.volumes[:, None], broken

    def elastic_energy(self, u: np.ndarray) -> float:
        """The elastic energy of the body at ``u (n, d)`` (linearised)."""
        return float(self.problem.body.volumes @ self.problem.energy_density(u))

    def stiffness_without(self, K: sp.csr_matrix, over: np.ndarray) -> sp.csr_matrix:
        """The stiffness after the bonds ``over`` broke (``alive`` already updated),
        ``K`` the one before: assembled again."""
        return self.stiffness()


class BondBehaviour(LinearBehaviour):
    """The prototype microelastic brittle (PMB) bonds of `cnem.pd.BondBased`.

    Attributes
    ----------
    bond_stiffness : float
        The micromodulus ``c`` (one value for every bond).
    """

    def __init__(self, problem: Any):
        super().__init__(problem)
        b = problem.body
        c = problem.material.micromodulus(problem.dim, problem.plane, b.horizon, b.thickness)
        self.bond_stiffness = float(c)

    def pmb_weights(self) -> np.ndarray:
        """``(b,)`` the PMB stiffness of every bond, live or not: the stiffness is
        ``A^T diag(w alive) A``."""
        p = self.problem
        b = p.body
        return 0.5 * self.bond_stiffness * p.factor * p.weight * b.volumes[b.bond_i] / \
            b.length

    def energy_density(self, u: np.ndarray, factor: np.ndarray) -> np.ndarray:
        """Strain energy density of every point, ``(n,)``, with the bond factors ``factor``."""
        p = self.problem
        b = p.body
        x = np.asarray(u, dtype=float).reshape(-1)
        live = p.alive.astype(bool)
        e = p.A @ x
        per = 0.25 * self.bond_stiffness * factor * e * e / b.length * p.weight * live
        return np.bincount(b.bond_i, weights=per, minlength=len(b))

    def stiffness(self) -> sp.csr_matrix:
        """Sparse ``(d n, d n)`` ``A^T diag(w alive) A`` (`pmb_weights`)."""
        p = self.problem
        w = self.pmb_weights() * p.alive.astype(float)
        return (p.A.T @ sp.diags(w) @ p.A).tocsr()

    def _stress_parts(self, x, nn, live):
        """No stress of the points' own, ``(n, d, d)``, and the bonds' ``(b, d, d)``."""
        p = self.problem
        e = p.A @ x
        per = (0.5 * self.bond_stiffness * p.factor * p.weight * e * live)[:, None, None] * nn
        return np.zeros((len(p.body), p.dim, p.dim)), per

    def correction(self) -> np.ndarray:
        """The energy-method bond factors ``(b,)`` (`cnem.pd.correction.pmb_factors`)."""
        p = self.problem
        return pmb_factors(p.body, p.weight, self.bond_stiffness,
                           *p.material.moduli(p.dim, p.plane))

    def stable_diagonal(self) -> np.ndarray:
        """``(n,)`` ``sum_j c_ij V_j / L_ij`` per point."""
        p = self.problem
        b = p.body
        per = self.bond_stiffness * p.factor * b.beta * b.volumes[b.bond_j] / b.length
        return np.bincount(b.bond_i, weights=per, minlength=len(b))

    def force_state(self) -> dict:
        """The PMB bond stiffnesses ``c factor beta`` of the force kernel."""
        p = self.problem
        return {"stiffness": np.ascontiguousarray(self.bond_stiffness * p.factor *
                                                  p.body.beta)}

    def internal_force(self, u: np.ndarray, limit: float, state: dict) -> tuple[np.ndarray, int]:
        """Force per unit volume ``(n, d)`` of the deformed PMB bonds (exact stretches),
        breaking those beyond ``limit``; and the number broken."""
        p = self.problem
        b = p.body
        out = np.empty_like(u)
        broken = pmb_forces(u, b.points, b.image, b.length, b.family.offsets, b.bond_j,
                            state["stiffness"], b.volumes, p.alive, limit, out)
        return out, broken

    def elastic_energy(self, u: np.ndarray) -> float:
        """The exact PMB energy of the deformed bonds at ``u (n, d)``."""
        p = self.problem
        b = p.body
        y = b.xi + u[b.bond_j] - u[b.bond_i]
        s = np.sqrt((y * y).sum(axis=1)) / b.length - 1
        per = 0.25 * self.bond_stiffness * p.factor * b.beta * s * s * b.length * \
            b.volumes[b.bond_j] * p.alive
        return float(b.volumes @ np.bincount(b.bond_i, weights=per, minlength=len(b)))

    def stiffness_without(self, K: sp.csr_matrix, over: np.ndarray) -> sp.csr_matrix:
        """``K`` less the stiffness of the bonds ``over``."""
        p = self.problem
        A = p.A[over]
        return (K - A.T @ sp.diags(self.pmb_weights()[over]) @ A).tocsr()


class StateBehaviour(LinearBehaviour):
    """The linear peridynamic solid of `cnem.pd.StateBased`.

    The weighted volume ``m`` is of the reference family and stays so when bonds break
    (Silling et al. 2007, as Peridigm): damage softens the deviatoric energy through its
    live bonds only. The dilatation (`cnem.pd.Problem.T`) sums the live bonds with their
    own moment tensors: with the reference ones a rotation would dilate.

    Attributes
    ----------
    m : (n,) ndarray
        Weighted volumes.
    bulk, shear : float
        The d-dimensional bulk modulus and the shear modulus.
    alpha : (n,) ndarray
        ``mu d (d + 2) / m``.
    """

    def __init__(self, problem: Any):
        super().__init__(problem)
        b, d, n = problem.body, problem.dim, len(problem.body)
        self.m = np.bincount(b.bond_i, weights=problem.weight * b.length ** 2, minlength=n)
        self.bulk, self.shear = problem.material.moduli(d, problem.plane)
        self.alpha = self.shear * d * (d + 2) / self.m

    def energy_density(self, u: np.ndarray, factor: np.ndarray) -> np.ndarray:
        """Strain energy density of every point, ``(n,)``, with the bond factors ``factor``."""
        p = self.problem
        b = p.body
        x = np.asarray(u, dtype=float).reshape(-1)
        live = p.alive.astype(bool)
        theta = p.T @ x
        ed = p.Edev @ x
        per = 0.5 * self.alpha[b.bond_i] * factor * p.weight * ed * ed * live
        return 0.5 * self.bulk * theta ** 2 + np.bincount(b.bond_i, weights=per, minlength=len(b))

    def stiffness(self) -> sp.csr_matrix:
        """Sparse ``(d n, d n)``: dilatation and deviatoric parts of the live bonds."""
        p = self.problem
        b = p.body
        live = p.alive.astype(float)
        Vi = b.volumes[b.bond_i]
        w = self.alpha[b.bond_i] * p.factor * p.weight * Vi * live
        dil = p.T.T @ sp.diags(self.bulk * b.volumes) @ p.T
        return (dil + p.Edev.T @ sp.diags(w) @ p.Edev).tocsr()

    def _stress_parts(self, x, nn, live):
        """The dilatation's pressure of every point ``(n, d, d)`` and the bonds'
        deviatoric stress ``(b, d, d)``."""
        p = self.problem
        b, d = p.body, p.dim
        theta = p.T @ x
        ed = p.Edev @ x
        L = b.length[:, None, None]
        per = (self.alpha[b.bond_i] * p.factor * p.weight * ed * live)[:, None, None] * \
            (L * nn - (L / d) * np.eye(d))
        return self.bulk * theta[:, None, None] * np.eye(d), per

    def correction(self) -> np.ndarray:
        """The energy-method bond factors ``(b,)``: at every point, a function of the bond
        direction (`cnem.pd.correction.state_test_fields`) fitted so that the deviatoric
        test strains store the classical deviatoric energy there; a bond takes the mean of
        its two points' functions."""
        p = self.problem
        b = p.body
        tests, basis = state_test_fields(p.unit, p.dim)
        rows = []
        for eps in tests:
            u = b.points @ eps.T
            dil = 0.5 * self.bulk * (p.T @ u.reshape(-1)) ** 2
            rows.append([self.energy_density(u, P) - dil for P in basis])
        Q = np.array(rows).transpose(2, 0, 1)                       # (n, tests, basis)
        target = np.array([classical_density(eps, self.bulk, self.shear) -
                           0.5 * self.bulk * np.trace(eps) ** 2 for eps in tests])
        coef = fit(Q, target)
        G = np.array(basis)                                          # (basis, bonds)
        gi = (coef[b.bond_i].T * G).sum(axis=0)
        gj = (coef[b.bond_j].T * G).sum(axis=0)
        return 0.5 * (gi + gj)


class CPDBehaviour:
    """The nonlinear interactions of `cnem.pd.CPD`: forces and tangent from the energy
    (`cnem.pd.cpd.Interactions`); no linear-only quantities.

    Attributes
    ----------
    interactions : cnem.pd.cpd.Interactions
    """

    linear = False
    has_stress = False

    def __init__(self, problem: Any):
        self.problem = problem
        self.interactions = problem.material.interactions(problem.body)

    def evaluate(self, u: np.ndarray, tangent: bool = True
                 ) -> tuple[np.ndarray, sp.csr_matrix | None]:
        """Internal forces ``dPsi/du`` ``(d n,)`` and, with ``tangent``, ``d2Psi/du2``."""
        return self.interactions.evaluate(u, tangent=tangent)[1:]

    def static_system(self) -> tuple[Callable, sp.csr_matrix]:
        """`evaluate` and a matrix with the tangent's pattern: for one static solve."""
        return self.evaluate, self.interactions.pattern()
