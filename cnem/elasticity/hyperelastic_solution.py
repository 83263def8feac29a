"""`HyperelasticSolution`: the finite-strain fields of a `Hyperelasticity` problem per cell."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..solvers.solution import voigt
from .solution import CellSolution

__all__ = ["HyperelasticSolution"]


@dataclass(eq=False, repr=False)
class HyperelasticSolution(CellSolution):
    """The solution of a `cnem.Hyperelasticity` problem (the fields of
    `cnem.solvers.solution`, on the reference configuration's cells).

    Attributes
    ----------
    u : (n, d) ndarray
        Nodal displacements; the deformed nodes are ``model.nodes + u``.
    deformation_gradient : (m, d, d) ndarray
        The smoothed ``F~ = I + grad~ u`` per cell (in-plane block in plane strain,
        ``F33 = 1``).
    stress : (m, 3) or (m, 6) ndarray
        Cauchy stress ``P F^T / J`` per cell (at the F-bar gradient with
        ``volumetric="fbar"``), Voigt ``[sxx, syy, sxy]`` (in-plane
        components in plane strain) or ``[sxx, syy, szz, syz, sxz, sxy]``.
    strain : (m, 3) or (m, 6) ndarray
        Green-Lagrange strain ``(F^T F - I) / 2`` per cell, Voigt with engineering
        shears (``2 E12``).
    first_piola : (m, d, d) ndarray
        First Piola-Kirchhoff stress ``P`` per cell (of the law's ``F``, see ``stress``).
    residual_history : list of list of float
        Newton's residual norms, one list per load step.
    steps : list of (float, (d n,) ndarray)
        The load factor (``k / steps``) and the unknowns after each load step (the
        last is ``dofs``); `series` makes them solutions, ``write("run.pvd")`` files.
    energy : float
        Stored energy ``sum_k V_k W(F~_k)``.
    cells : Cells
    dofs : (d n,) ndarray
    timings : dict
        Seconds spent in each stage.
    model : Model
    plane : {"strain"} or None
        None in 3-D.
    """

    deformation_gradient: np.ndarray
    stress: np.ndarray
    strain: np.ndarray
    first_piola: np.ndarray
    residual_history: list
    energy: float
    cells: Any
    dofs: np.ndarray
    timings: dict
    model: Any
    plane: Any
    steps: list = field(default_factory=list)

    @classmethod
    def from_dofs(cls, problem: Any, dofs: np.ndarray, history: list,
                  timings: dict[str, float], *, steps: list | None = None
                  ) -> HyperelasticSolution:
        """The solution of ``problem`` (a `cnem.Hyperelasticity`) with unknowns ``dofs``,
        Newton's residual ``history`` and the load ``steps`` (``(factor, dofs)``)."""
        operator = problem.operator
        F = operator.deformation_gradient(dofs)
        F_law = operator.constitutive_gradient(dofs)          # F~, or F-bar's
        W, P, _ = operator.laws(F_law, tangent=False)
        J = np.linalg.det(F_law)
        cauchy = P @ np.swapaxes(F_law, 1, 2) / J[:, None, None]
        d = F.shape[1]
        green = 0.5 * (np.swapaxes(F, 1, 2) @ F - np.eye(d))
        strain = voigt(green)
        strain[:, d:] *= 2.0
        return cls(problem=problem, u=dofs.reshape(-1, d), deformation_gradient=F,
                   stress=voigt(cauchy), strain=strain, first_piola=P,
                   residual_history=history, energy=float(operator.basis.dx @ W),
                   cells=problem.cells, dofs=dofs, timings=timings, model=problem.model,
                   plane=problem.plane, steps=list(steps or []))

    def series(self) -> list[tuple[float, HyperelasticSolution]]:
        """The solution after each load step, with its load factor (for a ``.pvd``
        file; the solution alone at 1 when it has no steps)."""
        if not self.steps:
            return [(1.0, self)]
        return [(factor, self if k == len(self.steps) - 1 else
                 HyperelasticSolution.from_dofs(self.problem, dofs,
                                                self.residual_history[:k + 1], self.timings))
                for k, (factor, dofs) in enumerate(self.steps)]

    def fields(self) -> tuple[dict, dict]:
        """`cnem.solvers.solution.Solution.fields` and, per cell, the deformation
        gradient ``F`` ``(m, 9)`` (row-major 3 x 3, ``F33 = 1`` in plane strain) and
        ``J = det F``."""
        point_data, cell_data = super().fields()
        F = self.deformation_gradient
        full = np.broadcast_to(np.eye(3), (len(F), 3, 3)).copy()      # F33 = 1 in plane strain
        full[:, :F.shape[1], :F.shape[2]] = F
        cell_data.update(F=full.reshape(len(F), 9), J=np.linalg.det(F))
        return point_data, cell_data
