"""`P1Solution`: displacements, strains and stresses of a `P1Elasticity` solve."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
from skfem.helpers import sym_grad

from ..assembly.quadrature import triangle_quadrature
from ..material import stiffness_matrix
from ..errors import GeometryError, check_points
from ..solvers.solution import Solution, energy_error_density

__all__ = ["P1Solution"]


@dataclass(eq=False, repr=False)
class P1Solution(Solution):
    """The solution of a `P1Elasticity` problem (the fields of `cnem.solvers.solution`).

    Attributes
    ----------
    u : (n, 2) ndarray
        Nodal displacements.
    stress : (t, 3) ndarray
        ``[sxx, syy, sxy]`` per triangle (constant on each).
    strain : (t, 3) ndarray
        ``[exx, eyy, 2 exy]`` per triangle.
    C : (t, 3, 3) ndarray
        Elastic matrix of each triangle.
    mesh : skfem.MeshTri
    region : (t,) int64 ndarray
        Region index of each triangle.
    basis : skfem.Basis
    plane : {"stress", "strain"}
    timings : dict
        Seconds spent in ``"mesh"``, ``"assembly"`` and ``"solve"``.
    """

    stress: np.ndarray
    strain: np.ndarray
    C: np.ndarray
    mesh: Any
    region: np.ndarray
    basis: Any
    plane: str
    timings: dict

    stress_places = "triangles"

    @classmethod
    def from_dofs(cls, problem: Any, x: np.ndarray,
                  timings: dict[str, float]) -> P1Solution:
        """The solution of ``problem`` (a `P1Elasticity`) with the interleaved nodal unknowns
        ``x (2 n,)``."""
        eps = sym_grad(problem.basis.interpolate(x))[:, :, :, 0]          # (2, 2, t)
        strain = np.column_stack([eps[0, 0], eps[1, 1], 2.0 * eps[0, 1]])
        E, nu = problem.element_materials().T
        C = stiffness_matrix(E, nu, problem.plane)
        return cls(problem=problem, u=x.reshape(-1, 2), stress=np.einsum("kij,kj->ki", C, strain),
                   strain=strain, C=C, mesh=problem.mesh, region=problem.region,
                   basis=problem.basis, plane=problem.plane, timings=timings)

    def displacement(self, points: np.ndarray) -> np.ndarray:
        """Displacements ``(p, 2)`` at points ``(p, 2)`` inside the mesh, through the P1
        shape functions."""
        pts = check_points("points", points, dims=(2,), error=GeometryError)
        values = self.basis.probes(np.ascontiguousarray(pts.T)) @ self.u.reshape(-1)
        return values.reshape(2, -1).T                      # probes give x values, then y

    def energy_error(self, exact_stress: Callable[..., np.ndarray], *, order: int = 4) -> float:
        """Error in the energy norm against an exact stress field.

        ``sqrt(sum_T ∫_T (σh - σ)ᵀ C⁻¹ (σh - σ) dΩ)`` with a triangle rule of
        degree ``order`` on every triangle, collapsed at the crack tips (see
        `cnem.assembly.quadrature.triangle_quadrature`) like the C-NEM error.

        Parameters
        ----------
        exact_stress : callable ``(q, 2) -> (q, 3)`` or ``(q, 2), (q,) -> (q, 3)``
            ``[sxx, syy, sxy]`` at points; a function of two arguments also
            receives the region of the triangle holding each point (for
            fields discontinuous across material interfaces).
        order : int
            Degree of the quadrature rule.

        Returns
        -------
        float
        """
        corners = self.mesh.p.T[self.mesh.t.T]                      # (t, 3, 2)
        e1, e2 = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
        clockwise = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0] < 0
        corners[clockwise] = corners[clockwise][:, ::-1]
        owner, points, weights = triangle_quadrature(corners, order,
                                                     singular=self.problem.domain.tips)
        density = energy_error_density(points, self.region[owner], self.stress[owner],
                                       self.C[owner], exact_stress)
        return float(np.sqrt(weights @ density))

    def energy(self) -> float:
        """Strain energy ``1/2 sum_T A_T σ_T · ε_T``."""
        area = self.basis.dx.sum(axis=1)
        return 0.5 * float(area @ (self.stress * self.strain).sum(axis=1))

    def nodal_average(self, values: np.ndarray) -> np.ndarray:
        """Triangle values ``(t, ...)`` at the nodes: the area-weighted mean over the
        triangles around each node, ``(n, ...)``."""
        values = self._place_values(values)
        n, tri = self.mesh.p.shape[1], self.mesh.t.T
        area = np.repeat(self.basis.dx.sum(axis=1), 3)
        flat = values.reshape(len(values), -1)
        weight = np.bincount(tri.ravel(), weights=area, minlength=n)
        out = np.stack([np.bincount(tri.ravel(), weights=area * np.repeat(col, 3), minlength=n)
                        for col in flat.T], axis=1) / weight[:, None]
        return out.reshape((n,) + values.shape[1:])

    def plot_mesh(self) -> tuple:
        """The mesh nodes and triangles and the domain's diameter."""
        return self.mesh.p.T, self.mesh.t.T, self.problem.domain.diameter

    def write_fields(self, path: str, point_data: dict[str, np.ndarray],
                     cell_data: dict[str, np.ndarray]) -> None:
        """The mesh with the fields (`cnem.io.write_points` with its triangles)."""
        from .. import io
        io.write_points(self.mesh.p.T, path, triangles=self.mesh.t.T, point_data=point_data,
                        cell_data=cell_data)
