"""`ElasticSolution`: displacements, SCNI cell strains and stresses, errors, files and pictures."""

from __future__ import annotations

import inspect

import numpy as np

from ..assembly.quadrature import cell_quadrature
from ..errors import InputError, check_choice

__all__ = ["ElasticSolution", "von_mises", "energy_error_density"]


def von_mises(stress):
    """Plane von Mises stress of ``(..., 3)`` ``[sxx, syy, sxy]`` (in-plane components)."""
    sxx, syy, sxy = stress[..., 0], stress[..., 1], stress[..., 2]
    return np.sqrt(sxx ** 2 - sxx * syy + syy ** 2 + 3.0 * sxy ** 2)


def engineering_strain(gradient):
    """``[exx, eyy, 2 exy]`` from displacement gradients ``(..., 2, 2)``, ``(..., 3)``."""
    g = gradient
    return np.stack([g[..., 0, 0], g[..., 1, 1], g[..., 0, 1] + g[..., 1, 0]], axis=-1)


def energy_error_density(points, region, stress, C, exact_stress):
    """``(σh - σ)ᵀ C⁻¹ (σh - σ)`` at quadrature points.

    Parameters
    ----------
    points : (q, 2) ndarray
    region : (q,) int ndarray
        Region of the cell (or element) holding each point.
    stress : (q, 3) ndarray
        The approximate stress ``σh`` at the points.
    C : (q, 3, 3) ndarray
        The elastic matrix at the points.
    exact_stress : callable ``(q, 2) -> (q, 3)`` or ``(q, 2), (q,) -> (q, 3)``

    Returns
    -------
    (q,) ndarray
    """
    if _takes_region(exact_stress):
        exact = exact_stress(points, region)
    else:
        exact = exact_stress(points)
    exact = np.asarray(exact, dtype=float)
    if exact.shape != (len(points), 3):
        raise InputError(f"exact_stress must return ({len(points)}, 3) values "
                         f"[sxx, syy, sxy], received shape {exact.shape}; return one row per point")
    diff = stress - exact
    return np.einsum("qi,qij,qj->q", diff, np.linalg.inv(C), diff)


def _takes_region(func):
    """Whether ``func`` accepts two positional arguments ``(x, region)``."""
    try:
        inspect.signature(func).bind(None, None)
    except (TypeError, ValueError):                  # one argument, or no signature
        return False
    return True


class ElasticSolution:
    """The solution of an `Elasticity` problem.

    Attributes
    ----------
    u : (n, 2) ndarray
        Nodal displacements (the displacement at node ``i`` is ``u[i]``).
    enriched : (e, 2) ndarray
        Coefficients of the enrichment functions, if any.
    dofs : (2 n + 2 e,) ndarray
        All unknowns.
    gradient : (m, 2, 2) ndarray
        Smoothed displacement gradient per cell, ``[k, i, j] = du_i/dx_j``.
    strain : (m, 3) ndarray
        ``[exx, eyy, 2 exy]`` per integration cell (smoothed, eq. 29).
    stress : (m, 3) ndarray
        ``[sxx, syy, sxy]`` per integration cell (eq. 34).
    C : (m, 3, 3) ndarray
        Elastic matrix of each cell.
    timings : dict
        Seconds spent in each stage.
    """

    def __init__(self, problem, dofs, C, timings):
        self.problem = problem
        self.model = problem.model
        #: the integration cells of ``stress`` and ``strain`` (``model.cells``, or their
        #: sub-cells with enrichment)
        self.cells = problem.cells
        self.plane = problem.plane
        n = len(self.model.nodes)
        self.dofs = dofs
        self.u = dofs[:2 * n].reshape(-1, 2)
        #: (e, 2) coefficients of the enrichment functions (empty without enrichment)
        self.enriched = dofs[2 * n:].reshape(-1, 2)
        self.C = C
        self.timings = timings
        ops = problem.basis.operators[2:]               # du0/dx, du0/dy, du1/dx, du1/dy
        self.gradient = np.stack([op @ dofs for op in ops], axis=1).reshape(-1, 2, 2)
        self.strain = engineering_strain(self.gradient)
        self.stress = np.einsum("kij,kj->ki", C, self.strain)

    def __repr__(self):
        return (f"<ElasticSolution {len(self.u)} nodes, {len(self.stress)} cells, "
                f"max |u| {np.abs(self.u).max():.3e}, max von Mises {self.von_mises.max():.3e}>")

    @property
    def von_mises(self):
        """``(m,)`` von Mises stress per cell."""
        return von_mises(self.stress)

    def displacement(self, points):
        """Displacements at points through the shape functions.

        Parameters
        ----------
        points : (p, 2) array_like

        Returns
        -------
        (p, 2) ndarray
        """
        phi = self.model.shape_functions(points)
        out = phi @ self.u
        enrichment = self.problem.enrichment
        if enrichment is not None:
            out += enrichment.values(np.asarray(points, dtype=float), phi) @ self.enriched
        return out

    def displacement_gradient(self, points):
        """The gradient of the displacement field itself (not smoothed) at points
        inside the cells: Sibson gradients, plus the enrichment's.

        Parameters
        ----------
        points : (p, 2) array_like
            Off the nodes' cell boundaries where the gradients jump, and off the
            crack tips.

        Returns
        -------
        (p, 2, 2) ndarray
            ``[q, i, j] = du_i/dx_j``.
        """
        pts = np.asarray(points, dtype=float)
        phi, dx, dy = self.model.shape_functions(pts, gradient=True)
        out = np.stack([dx @ self.u, dy @ self.u], axis=2)
        enrichment = self.problem.enrichment
        if enrichment is not None:
            _, ex, ey = enrichment.values(pts, phi, gradient=(dx, dy))
            out += np.stack([ex @ self.enriched, ey @ self.enriched], axis=2)
        return out

    def energy_error(self, exact_stress, *, order=4, strain="smoothed"):
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
            ``[sxx, syy, sxy]`` at points; given a second parameter it also
            receives the region of the cell holding each point (for fields
            that jump across a material interface: the polygonal interface
            of the model need not be the exact one).
        order : int
            Degree of the triangle rule on the triangles of each cell.
        strain : {"smoothed", "pointwise"}

        Returns
        -------
        float
        """
        check_choice("strain", strain, ("smoothed", "pointwise"))
        cell, points, weights = cell_quadrature(self.cells, self.model.nodes, order,
                                                singular=self.model.domain.tips)
        if strain == "smoothed":
            stress = self.stress[cell]
        else:
            eps = engineering_strain(self.displacement_gradient(points))
            stress = np.einsum("qij,qj->qi", self.C[cell], eps)
        density = energy_error_density(points, self.cells.region[cell], stress, self.C[cell],
                                       exact_stress)
        return float(np.sqrt(weights @ density))

    def energy(self):
        """Strain energy ``1/2 sum_k A_k σ_k · ε_k``."""
        return 0.5 * float(self.cells.area @ (self.stress * self.strain).sum(axis=1))

    def fields(self):
        """Nodal and cell fields for files and pictures.

        Returns
        -------
        point_data : dict of str -> (n, ...) ndarray
        cell_data : dict of str -> (m, ...) ndarray
        """
        return ({"u": self.u},
                {"stress": self.stress, "strain": self.strain, "von_mises": self.von_mises})

    def write(self, path):
        """Write nodes and cells with ``u``, ``stress``, ``strain`` and
        ``von_mises`` (``.vtu``, see `cnem.io.write`)."""
        from .. import io
        point_data, cell_data = self.fields()
        io.write(self.model, path, point_data=point_data, cell_data=cell_data)
        return path

    def plot(self, path=None, *, field="von_mises", scale=None, **kwargs):
        """Off-screen picture of the deformed cells coloured by a field
        (see `cnem.plot.solution`)."""
        from .. import plot
        return plot.solution(self, path, field=field, scale=scale, **kwargs)
