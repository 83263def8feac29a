"""`ElasticSolution`: displacements, SCNI cell strains and stresses, errors, files and pictures."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Any, Callable, Literal

import numpy as np

from ..assembly.quadrature import cell_quadrature
from .. import config
from ..assembly.recovery import NodalValues, recover_at_nodes, values_at
from ..solvers.solution import (Solution, energy_error_density, engineering_strain, vector3,
                                von_mises)
from ..solvers.conditions import Where, select_nodes
from ..errors import ConditionError, GeometryError, check_choice, check_points

__all__ = ["CellSolution", "ElasticSolution", "von_mises", "energy_error_density"]


@dataclass(eq=False, repr=False)
class CellSolution(Solution):
    """What the solutions of the C-NEM problems on a model share: displacements through
    the shape functions (and the problem's enrichment, if any), cell values at the nodes,
    pictures and files of the nodes and integration cells. Subclasses hold ``model``,
    ``cells`` (``stress`` and ``strain`` live there) and their fields."""

    stress_places = "cells"

    def stress_at(self, points: np.ndarray) -> np.ndarray:
        """Voigt stress at any points of the body, recovered from the cell stresses.

        The cells' stresses are fitted, around every node and in each of its regions,
        by a linear polynomial through the cells of the node and of its neighbours
        (at their centroids) and evaluated at the node; these nodal stresses are then
        interpolated at the points by the shape functions, with the values of the
        point's region (`cnem.assembly.recovery`). Exact for a constant or linear
        stress; at a boundary it extrapolates from the inside, so the peaks at
        holes and notches are read where the cell means under-read them (a plate
        with a hole under tension, default graded nodes: 2.995 for the exact 3).
        Not for singular fields: near a crack tip use `cnem.fracture.sif`.

        Parameters
        ----------
        points : (p, d) array_like
            In the closure of the domain (on the boundary too; reference
            configuration for finite strain); a point on a material interface takes
            the region of lowest index.

        Returns
        -------
        (p, 3) or (p, 6) ndarray
            ``[sxx, syy, sxy]`` (3-D: ``[sxx, syy, szz, syz, sxz, sxy]``).

        Raises
        ------
        GeometryError
            Points outside the domain (counted, the first ones named).
        """
        return values_at(self.model, self.nodal_stress, points)

    @cached_property
    def nodal_stress(self) -> NodalValues:
        """The cell stresses recovered at the nodes, one row per node and region
        (`cnem.assembly.recovery.recover_at_nodes`; computed once)."""
        return recover_at_nodes(self.model, self.cells, self.stress)

    def displacement(self, points: np.ndarray) -> np.ndarray:
        """Displacements ``(p, d)`` at points ``(p, d)`` through the shape functions (and
        the enrichment functions)."""
        phi = self.model.shape_functions(points)
        out = phi @ self.u
        enrichment = self.problem.enrichment
        if enrichment is not None:
            out += enrichment.values(np.asarray(points, dtype=float), phi) @ self.enriched
        return out

    def nodal_average(self, values: np.ndarray) -> np.ndarray:
        """Cell values ``(m, ...)`` at the nodes: each node's cell (area-weighted over the
        cells of a node on an interface), ``(n, ...)``."""
        cells, n = self.cells, len(self.model.nodes)
        values = self._place_values(values)
        weight = np.bincount(cells.node, weights=cells.measure, minlength=n)
        flat = values.reshape(len(values), -1)
        out = np.stack([np.bincount(cells.node, weights=cells.measure * col, minlength=n) / weight
                        for col in flat.T], axis=1)
        return out.reshape((n,) + values.shape[1:])

    def plot_mesh(self) -> tuple:
        """The nodes, the constrained Delaunay triangles and the domain's diameter."""
        return self.model.nodes, self.model.triangles, self.model.domain.diameter

    def write_fields(self, path: str, point_data: dict[str, np.ndarray],
                     cell_data: dict[str, np.ndarray]) -> None:
        """Nodes and integration cells with the fields (`cnem.io.write`); the
        ``displacement`` and the other nodal values (``stress_nodal``) also at the
        cells' vertices (interpolated just inside each vertex's cell,
        `cnem.config.VERTEX_NUDGE`), so that the cells warp with the body and show the
        nodal values."""
        from .. import io
        inside = self._inside_vertices()
        phi = self.model.shape_functions(inside)
        n, extended = len(self.model.nodes), {}
        for name, value in point_data.items():
            if name == "displacement":
                extended[name] = np.concatenate([value, vector3(self.displacement(inside))])
            elif len(value) == n and np.issubdtype(np.asarray(value).dtype, np.floating):
                extended[name] = np.concatenate([value, phi @ value])
            else:
                extended[name] = value
        io.write(self.model, path, point_data=extended, cell_data=cell_data)

    def vertex_displacement(self) -> np.ndarray:
        """Displacements ``(q, d)`` at the cell vertices of `cnem.io.cell_points`, each
        interpolated just inside a cell it bounds (`cnem.config.VERTEX_NUDGE` of the way
        to the cell's node), so that a vertex on a crack face takes that cell's side."""
        return self.displacement(self._inside_vertices())

    def _inside_vertices(self) -> np.ndarray:
        """The cell vertices of `cnem.io.cell_points` moved `cnem.config.VERTEX_NUDGE`
        of the way to their cell's node, ``(q, d)``; in 3-D a vertex whose way to its
        node leaves the body (a cell beside a faceted hole, not star-shaped from its
        node) stays where it is."""
        from .. import io
        vertices, cell = io.cell_points(self.model)
        node = self.model.nodes[self.model.cells.node[cell]]
        nudged = vertices + config.VERTEX_NUDGE * (node - vertices)
        if vertices.shape[1] == 3:
            from ..shape.natural3d import inside_tetrahedra
            astray = ~inside_tetrahedra(self.model.tet_mesh(), nudged)
            nudged[astray] = vertices[astray]
        return nudged


@dataclass(eq=False, repr=False)
class ElasticSolution(CellSolution):
    """The solution of an `Elasticity` problem (the fields of `cnem.solvers.solution`).

    Attributes
    ----------
    u : (n, d) ndarray
        Nodal displacements (the displacement at node ``i`` is ``u[i]``).
    stress : (m, 3) or (m, 6) ndarray
        ``[sxx, syy, sxy]`` per integration cell (eq. 34); in 3-D
        ``[sxx, syy, szz, syz, sxz, sxy]``.
    strain : (m, 3) or (m, 6) ndarray
        ``[exx, eyy, 2 exy]`` per integration cell (smoothed, eq. 29); in 3-D
        ``[exx, eyy, ezz, 2 eyz, 2 exz, 2 exy]``.
    cells : Cells
        The integration cells of ``stress`` and ``strain`` (``model.cells``, or
        their sub-cells with enrichment).
    gradient : (m, d, d) ndarray
        Smoothed displacement gradient per cell, ``[k, i, j] = du_i/dx_j``.
    dofs : (d n + d e,) ndarray
        All unknowns.
    enriched : (e, d) ndarray
        Coefficients of the enrichment functions (empty without enrichment).
    C : (m, 3, 3) or (m, 6, 6) ndarray
        Elastic matrix of each cell.
    timings : dict
        Seconds spent in each stage.
    model : Model
    plane : {"stress", "strain"} or None
        None in 3-D.
    """

    stress: np.ndarray
    strain: np.ndarray
    cells: Any
    gradient: np.ndarray
    dofs: np.ndarray
    enriched: np.ndarray
    C: np.ndarray
    timings: dict
    model: Any
    plane: str

    @classmethod
    def from_dofs(cls, problem: Any, dofs: np.ndarray, C: np.ndarray,
                  timings: dict[str, float]) -> ElasticSolution:
        """The solution of ``problem`` with unknowns ``dofs`` and cell elastic matrices ``C``."""
        n, d = problem.model.nodes.shape
        ops = problem.basis.operators[d:]               # du0/dx, du0/dy, du1/dx, du1/dy (2-D)
        gradient = np.stack([op @ dofs for op in ops], axis=1).reshape(-1, d, d)
        strain = engineering_strain(gradient)
        return cls(problem=problem, u=dofs[:d * n].reshape(-1, d),
                   stress=np.einsum("kij,kj->ki", C, strain), strain=strain, cells=problem.cells,
                   gradient=gradient, dofs=dofs, enriched=dofs[d * n:].reshape(-1, d), C=C,
                   timings=timings, model=problem.model, plane=problem.plane)

    def displacement_gradient(self, points: np.ndarray) -> np.ndarray:
        """The gradient of the displacement field itself (not smoothed) at points
        inside the cells: Sibson gradients, plus the enrichment's.

        Parameters
        ----------
        points : (p, d) array_like
            Off the nodes' cell boundaries where the gradients jump, and off the
            crack tips.

        Returns
        -------
        (p, d, d) ndarray
            ``[q, i, j] = du_i/dx_j``.
        """
        pts = check_points("points", points, dims=(self.u.shape[1],), error=GeometryError)
        shape = self.model.shape_functions(pts, gradient=True)
        out = np.stack([g @ self.u for g in shape.gradient], axis=2)
        enrichment = self.problem.enrichment
        if enrichment is not None:
            _, *extra = enrichment.values(pts, shape.value, gradient=shape.gradient)
            out += np.stack([e @ self.enriched for e in extra], axis=2)
        return out

    def energy_error(self, exact_stress: Callable[..., np.ndarray], *, order: int = 4,
                     strain: Literal["smoothed", "pointwise"] = "smoothed") -> float:
        """Error in the energy norm against an exact stress field.

        ``sqrt(sum_k ∫_{cell k} (σh - σ)ᵀ C⁻¹ (σh - σ) dΩ)`` by a quadrature on
        each cell polygon, with either the constant SCNI stress ``σh`` of each
        cell (``strain="smoothed"``, the stress the method computes) or the
        stress of the displacement field's own gradient at every quadrature
        point (``strain="pointwise"``: the energy norm of ``u - u_h`` itself;
        with enrichment it sees the singular part the enrichment adds).

        Parameters
        ----------
        exact_stress : callable ``(q, 2) -> (q, 3)``, or ``(q, 2), (q,) -> (q, 3)``
            ``[sxx, syy, sxy]`` at points (3-D: ``(q, 3) -> (q, 6)``, Voigt
            ``[sxx, syy, szz, syz, sxz, sxy]``); given a second parameter it also
            receives the region of the cell holding each point (for fields
            that jump across a material interface: the polygonal interface
            of the model need not be the exact one).
        order : int
            Degree of the triangle rule on the triangles of each cell (3-D: of the
            tetrahedron rule on the cones from each cell's node over its facets).
        strain : {"smoothed", "pointwise"}

        Returns
        -------
        float
        """
        check_choice("strain", strain, ("smoothed", "pointwise"))
        tips = self.model.domain.tips if self.model.nodes.shape[1] == 2 else None
        cell, points, weights = cell_quadrature(self.cells, self.model.nodes, order,
                                                singular=tips)
        if strain == "smoothed":
            stress = self.stress[cell]
        else:
            eps = engineering_strain(self.displacement_gradient(points))
            stress = np.einsum("qij,qj->qi", self.C[cell], eps)
        density = energy_error_density(points, self.cells.region[cell], stress, self.C[cell],
                                       exact_stress)
        return float(np.sqrt(weights @ density))

    def energy(self) -> float:
        """Strain energy ``1/2 sum_k A_k σ_k · ε_k``."""
        return 0.5 * float(self.cells.measure @ (self.stress * self.strain).sum(axis=1))

    def reaction(self, where: Where) -> np.ndarray:
        """The resultant force the supports exert on the body at the nodes ``where`` picks:
        the sum of ``K u - f`` over those nodes' dofs (zero to the solver's tolerance
        where nothing is prescribed).

        Parameters
        ----------
        where : str, callable ``(n, d) -> (n,) bool``, or a boolean mask / index array over
            the nodes
            As in `cnem.Elasticity.add_dirichlet`: a boundary name (``"clamp"``) picks
            the nodes on that boundary.

        Returns
        -------
        (d,) ndarray
            Force per unit thickness in 2-D (force in 3-D), in the units of the
            tractions times length; with the body's loads it sums to zero.

        Examples
        --------
        >>> import cnem
        >>> dom = cnem.geometry.rectangle(2.0, 1.0)
        >>> prob = cnem.Elasticity(cnem.discretize(cnem.nodes.regular(dom, 0.25)), (1.0, 0.3))
        >>> prob.add_dirichlet("left", None)
        >>> prob.add_traction("right", [0.0, -1.0])       # 1 per unit length, edge length 1
        >>> sol = prob.solve()
        >>> [round(float(r), 9) + 0.0 for r in sol.reaction("left")]
        [0.0, 1.0]
        """
        problem = self.problem
        nodes = select_nodes(problem.condition_points, where, named=problem.named_nodes)
        if nodes.size == 0:
            raise ConditionError("reaction: `where` selects no node; check it against the "
                                 "nodes (boundary nodes lie exactly on the boundary)")
        d = self.u.shape[1]
        residual = problem.stiffness(upper=problem.dim == 3) @ self.dofs - problem.load()
        return residual[:d * len(self.u)].reshape(-1, d)[nodes].sum(axis=0)
