"""`P1Solution`: displacements, strains and stresses of a `P1Elasticity` solve."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
from skfem.helpers import grad

from ..assembly.quadrature import tetrahedron_quadrature, triangle_quadrature
from ..material import stiffness_matrix
from ..errors import GeometryError, check_points
from ..solvers.solution import Solution, energy_error_density, engineering_strain

__all__ = ["P1Solution"]


@dataclass(eq=False, repr=False)
class P1Solution(Solution):
    """The solution of a `P1Elasticity` problem (the fields of `cnem.solvers.solution`).

    Attributes
    ----------
    u : (n, d) ndarray
        Nodal displacements.
    stress : (t, 3) or (t, 6) ndarray
        Voigt ``[sxx, syy, sxy]`` (3-D: ``[sxx, syy, szz, syz, sxz, sxy]``) per
        triangle (tetrahedron), constant on each.
    strain : (t, 3) or (t, 6) ndarray
        ``[exx, eyy, 2 exy]`` (3-D: ``[exx, eyy, ezz, 2 eyz, 2 exz, 2 exy]``) per element.
    C : (t, 3, 3) or (t, 6, 6) ndarray
        Elastic matrix of each element.
    mesh : skfem.MeshTri or skfem.MeshTet
    region : (t,) int64 ndarray
        Region index of each element.
    basis : skfem.Basis
    plane : {"stress", "strain"} or None
        None in 3-D.
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
        ``x (d n,)``."""
        gradient = grad(problem.basis.interpolate(x))[:, :, :, 0]       # (d, d, t): du_i/dx_j
        strain = engineering_strain(np.moveaxis(gradient, 2, 0))
        E, nu = problem.element_materials().T
        C = stiffness_matrix(E, nu, problem.plane)
        return cls(problem=problem, u=x.reshape(-1, problem.dim),
                   stress=np.einsum("kij,kj->ki", C, strain),
                   strain=strain, C=C, mesh=problem.mesh, region=problem.region,
                   basis=problem.basis, plane=problem.plane, timings=timings)

    def displacement(self, points: np.ndarray) -> np.ndarray:
        """Displacements ``(p, d)`` at points ``(p, d)`` inside the mesh, through the P1
        shape functions."""
        dim = self.u.shape[1]
        pts = check_points("points", points, dims=(dim,), error=GeometryError)
        values = self.basis.probes(np.ascontiguousarray(pts.T)) @ self.u.reshape(-1)
        return values.reshape(dim, -1).T                    # probes give x values, then y

    def energy_error(self, exact_stress: Callable[..., np.ndarray], *, order: int = 4) -> float:
        """Error in the energy norm against an exact stress field.

        ``sqrt(sum_T ∫_T (σh - σ)ᵀ C⁻¹ (σh - σ) dΩ)`` with a rule of degree
        ``order`` on every element: on triangles collapsed at the crack tips (see
        `cnem.assembly.quadrature.triangle_quadrature`) like the C-NEM error, on
        tetrahedra scikit-fem's rule.

        Parameters
        ----------
        exact_stress : callable ``(q, d) -> (q, s)`` or ``(q, d), (q,) -> (q, s)``
            Voigt stresses at points (``s`` = 3 in 2-D, 6 in 3-D); a function of
            two arguments also receives the region of the element holding each
            point (for fields discontinuous across material interfaces).
        order : int
            Degree of the quadrature rule.

        Returns
        -------
        float
        """
        corners = self.mesh.p.T[self.mesh.t.T]                      # (t, d + 1, d)
        if corners.shape[2] == 3:
            owner, points, weights = tetrahedron_quadrature(corners, order)
        else:
            e1, e2 = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
            clockwise = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0] < 0
            corners[clockwise] = corners[clockwise][:, ::-1]
            owner, points, weights = triangle_quadrature(corners, order,
                                                         singular=self.problem.domain.tips)
        density = energy_error_density(points, self.region[owner], self.stress[owner],
                                       self.C[owner], exact_stress)
        return float(np.sqrt(weights @ density))

    def energy(self) -> float:
        """Strain energy ``1/2 sum_T |T| σ_T · ε_T``."""
        area = self.basis.dx.sum(axis=1)
        return 0.5 * float(area @ (self.stress * self.strain).sum(axis=1))

    def nodal_average(self, values: np.ndarray) -> np.ndarray:
        """Element values ``(t, ...)`` at the nodes: the area- (volume-) weighted mean over
        the elements around each node, ``(n, ...)``."""
        values = self._place_values(values)
        n, tri = self.mesh.p.shape[1], self.mesh.t.T
        corners = tri.shape[1]
        area = np.repeat(self.basis.dx.sum(axis=1), corners)
        flat = values.reshape(len(values), -1)
        weight = np.bincount(tri.ravel(), weights=area, minlength=n)
        out = np.stack([np.bincount(tri.ravel(), weights=area * np.repeat(col, corners),
                                     minlength=n)
                        for col in flat.T], axis=1) / weight[:, None]
        return out.reshape((n,) + values.shape[1:])

    def plot_mesh(self) -> tuple:
        """The mesh nodes and triangles and the domain's diameter."""
        return self.mesh.p.T, self.mesh.t.T, self.problem.domain.diameter

    def write_fields(self, path: str, point_data: dict[str, np.ndarray],
                     cell_data: dict[str, np.ndarray]) -> None:
        """The mesh (triangles or tetrahedra) with the fields (`cnem.io.write_points`)."""
        from .. import io
        io.write_points(self.mesh.p.T, path, cells=self.mesh.t.T, point_data=point_data,
                        cell_data=cell_data)
