"""`HeatConduction`: steady heat conduction (a scalar field) by C-NEM with SCNI.

``-div(k grad T) = s`` in each region (conductivity ``k`` per region, source ``s`` per
unit volume), with fixed temperatures, prescribed heat fluxes into the body and
convection ``-k dT/dn = h (T - T_inf)`` on the boundary. The conduction term is the
scalar form ``k grad(u) . grad(v)`` of `cnem.assembly` on the smoothed gradients of
the cells (with the sub-cell stabilisation of `cnem.Elasticity`), the boundary terms
are integrated exactly on the boundary edges (where the shape functions are the
linear hats of the edge's two nodes), and the source at each node times its cell's
area (nodal integration, as body forces).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp
from skfem.helpers import dot, grad

from ..assembly import BilinearForm, CellBasis
from ..assembly.gradients import GradientCache
from ..elasticity.model_problem import ModelProblem
from ..errors import ConditionError, InputError, SolveError, check_real
from ..solvers.conditions import merged_conditions, per_point, select_nodes
from ..solvers.constrained import solve_constrained
from .solution import HeatSolution

if TYPE_CHECKING:
    from typing import Callable, Literal, Sequence
    from numpy.typing import ArrayLike
    from ..geometry.model import Model
    from ..solvers.conditions import Where

__all__ = ["HeatConduction", "conduction_form"]


@BilinearForm
def conduction_form(u, v, w):
    """``k grad(u) . grad(v)`` with the conductivity ``w.k``."""
    return w.k * dot(grad(u), grad(v))


#: 2-point Gauss rule on [0, 1]: exact for the quadratic products of an edge's hats.
_S, _W = (np.array([0.5 - 0.5 / np.sqrt(3.0), 0.5 + 0.5 / np.sqrt(3.0)]), np.array([0.5, 0.5]))


class HeatConduction:
    """Steady heat conduction on a 2-D C-NEM model.

    Parameters
    ----------
    model : Model
        From `cnem.discretize`: ``n`` nodes, ``m`` integration cells.
    conductivity : float or sequence of float
        Thermal conductivity ``k > 0``, one for every region or one per region.
    gauss : int
        Gauss points per cell-edge piece in the smoothed gradients.
    stabilization : float
        Weight ``a`` of the sub-cell stabilisation: ``K = (1 - a) K_cells + a
        sum_s K_s`` over the fan sub-cells ``s`` of each cell (as `cnem.Elasticity`);
        it vanishes for linear fields (the patch test holds) and controls the
        oscillating modes one smoothed gradient per cell does not see.
    gradients : GradientCache, optional
        The model's smoothed gradients at ``gauss``, to share with other problems.

    Examples
    --------
    >>> import numpy as np, cnem
    >>> model = cnem.discretize(cnem.nodes.regular(cnem.geometry.rectangle(2.0, 1.0), 0.25))
    >>> prob = cnem.HeatConduction(model, 50.0)
    >>> prob.add_temperature("left", 100.0)
    >>> prob.add_convection("right", h=25.0, ambient=20.0)
    >>> sol = prob.solve()
    >>> x = 2.0; exact = 100.0 + (20.0 - 100.0) * 25.0 * x / (50.0 + 25.0 * 2.0)
    >>> bool(np.isclose(sol.temperature([[2.0, 0.5]])[0], exact))
    True
    """

    def __init__(self, model: Model, conductivity: float | Sequence[float], *, gauss: int = 2,
                 stabilization: float = 1.0, gradients: GradientCache | None = None):
        self._problem = ModelProblem(model, gauss=gauss, gradients=gradients,
                                     caller="HeatConduction")
        self.model = model
        if model.nodes.shape[1] != 2:
            raise InputError("HeatConduction: expected a 2-D model, received a 3-D one; "
                             "heat conduction is 2-D for now")
        regions = model.domain.n_regions
        k = np.asarray(check_real("conductivity", conductivity, error=InputError), dtype=float)
        if k.ndim == 0:
            k = np.full(regions, float(k))
        if k.shape != (regions,) or not (np.isfinite(k).all() and (k > 0).all()):
            raise InputError(f"conductivity: expected one positive number, or one per region "
                             f"({regions}), received {conductivity!r}")
        self.conductivity = k
        self.stabilization = float(stabilization)
        if not (np.isfinite(self.stabilization) and 0 <= self.stabilization <= 1):
            raise InputError(f"stabilization: expected a number in [0, 1], received "
                             f"{stabilization!r}")
        self.temperatures = []        # (nodes, values)
        self.fluxes = []              # (edges, normal, q)
        self.convections = []         # (edges, normal, h, ambient)
        self.sources = []             # constants or callables s(x) -> (p,)

    def __repr__(self):
        return (f"<HeatConduction {len(self.model.nodes)} nodes, {len(self.temperatures)} "
                f"temperature, {len(self.fluxes)} flux, {len(self.convections)} convection, "
                f"{len(self.sources)} source conditions>")

    @property
    def gradients(self) -> GradientCache:
        """The owner of the smoothed gradients this problem uses."""
        return self._problem.gradients

    def boundary_edges(self) -> tuple[np.ndarray, np.ndarray]:
        """The boundary edges ``(e, 2)`` (node pairs, the body on the left) and their
        outward unit normals ``(e, 2)``: what `add_flux` and `add_convection` select."""
        return self._problem.boundary_edges()

    # -- conditions -----------------------------------------------------------------------
    def add_temperature(self, where: Where, value: float | Callable[..., np.ndarray] = 0.0
                        ) -> None:
        """Fix the temperature at nodes.

        Parameters
        ----------
        where : str, callable ``(n, 2) -> (n,) bool``, or a boolean mask / index array
            over ``model.nodes``; a str names a boundary of the domain.
        value : float or callable ``(p, 2) -> (p,)``
        """
        nodes = select_nodes(self.model.nodes, where, named=self._problem.named_nodes)
        if nodes.size == 0:
            raise ConditionError("add_temperature: `where` selects no node; check the predicate "
                                 "against model.nodes (boundary nodes lie exactly on the boundary)")
        values = per_point(value, self.model.nodes[nodes], 1, "add_temperature value")
        self.temperatures.append((nodes, values[:, 0]))

    def add_flux(self, where: Where, q: float | Callable[..., np.ndarray]) -> None:
        """Prescribe the heat flux into the body through boundary edges (``k dT/dn``,
        ``n`` the outward normal; positive heats the body, W/m^2 say).

        Parameters
        ----------
        where : str, callable ``(x, nrm) -> (e,) bool``, or an ``(e,)`` bool mask
            A boundary name, or a predicate of the midpoints and outward unit normals
            of the boundary edges (as `cnem.Elasticity.add_traction`).
        q : float or callable ``(x, nrm) -> (q,)``
        """
        _, edges, normal = self._problem.select_facets(where, "add_flux")
        self._check_scalar(q, "add_flux: q", edges, normal)
        self.fluxes.append((edges, normal, q))

    def add_convection(self, where: Where, h: float,
                       ambient: float | Callable[..., np.ndarray]) -> None:
        """Convection through boundary edges: ``-k dT/dn = h (T - ambient)``.

        Parameters
        ----------
        where : str, callable ``(x, nrm) -> (e,) bool``, or an ``(e,)`` bool mask
            As `add_flux`.
        h : float
            Heat transfer coefficient, ``> 0``.
        ambient : float or callable ``(x, nrm) -> (q,)``
            The surrounding temperature ``T_inf``.
        """
        h = float(np.asarray(check_real("add_convection: h", h, error=ConditionError)))
        if not (np.isfinite(h) and h > 0):
            raise ConditionError(f"add_convection: h must be a positive number, received {h!r}")
        _, edges, normal = self._problem.select_facets(where, "add_convection")
        self._check_scalar(ambient, "add_convection: ambient", edges, normal)
        self.convections.append((edges, normal, h, ambient))

    def add_source(self, s: float | Callable[..., np.ndarray]) -> None:
        """Heat source per unit volume (area in 2-D): a number or ``s(x) -> (p,)``."""
        per_point(s, self.model.nodes, 1, "add_source: s")         # checked at the nodes
        self.sources.append(s)

    def _check_scalar(self, value, what, edges, normal):
        """Refuse a boundary value that is not one number per point."""
        if not callable(value):
            arr = np.asarray(check_real(what, value, error=ConditionError))
            if arr.ndim:
                raise ConditionError(f"{what}: expected a number or a callable (x, nrm) -> (q,), "
                                     f"received shape {arr.shape}")
            return
        mid = self.model.nodes[edges].mean(axis=1)
        per_point(value(mid, normal), mid, 1, what)

    # -- assembly -------------------------------------------------------------------------
    def basis(self) -> CellBasis:
        """The scalar `CellBasis` of the model's cells."""
        return CellBasis(self.model, gradient=self.gradients.cells())

    def conduction_matrix(self) -> sp.csr_matrix:
        """``(n, n)`` conduction matrix with the sub-cell stabilisation (see the class)."""
        a, k, cells = self.stabilization, self.conductivity, self.model.cells
        K = sp.csr_matrix((len(self.model.nodes),) * 2)
        if a < 1:
            K = K + conduction_form.assemble(self.basis(), groups=cells.region, k=(1 - a) * k)
        if a > 0:
            sub, gradient = self.gradients.fan()
            fine = CellBasis(self.model, cells=sub, gradient=gradient)
            K = K + conduction_form.assemble(fine, groups=sub.region, k=a * k)
        return K.tocsr()

    def system(self) -> tuple[sp.csr_matrix, np.ndarray]:
        """The matrix ``(n, n)`` (conduction and convection) and right-hand side
        ``(n,)`` (sources, fluxes, convection)."""
        x, cells = self.model.nodes, self.model.cells
        n = len(x)
        K = self.conduction_matrix()
        f = np.zeros(n)
        for s in self.sources:
            f += np.bincount(cells.node, weights=cells.measure * per_point(
                s, x[cells.node], 1, "add_source: s")[:, 0], minlength=n)
        for edges, normal, q in self.fluxes:
            f += self._edge_load(edges, normal, q, 1.0)
        rows, cols, vals = [], [], []
        for edges, normal, h, ambient in self.convections:
            f += self._edge_load(edges, normal, ambient, h)
            length = np.linalg.norm(x[edges[:, 1]] - x[edges[:, 0]], axis=1)
            for i in range(2):
                for j in range(2):
                    rows.append(edges[:, i])
                    cols.append(edges[:, j])
                    vals.append(h * length * (2.0 if i == j else 1.0) / 6.0)
        if rows:
            K = K + sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows),
                                                          np.concatenate(cols))), shape=(n, n))
        return K.tocsr(), f

    def _edge_load(self, edges, normal, value, factor):
        """``factor * int_e value phi_i ds`` on every edge, to its two nodes (Gauss)."""
        x = self.model.nodes
        a, b = x[edges[:, 0]], x[edges[:, 1]]
        length = np.linalg.norm(b - a, axis=1)
        f = np.zeros(len(x))
        for s, w in zip(_S, _W):
            pts = a + s * (b - a)
            val = per_point(value(pts, normal) if callable(value) else value, pts, 1,
                            "boundary value")[:, 0]
            np.add.at(f, edges[:, 0], factor * w * (1 - s) * length * val)
            np.add.at(f, edges[:, 1], factor * w * s * length * val)
        return f

    def solve(self, *, method: Literal["auto", "direct", "amg"] = "auto",
              tol: float = 1e-10) -> HeatSolution:
        """Solve for the nodal temperatures.

        Parameters
        ----------
        method : {"auto", "direct", "amg"}
            See `cnem.solvers.linsolve.solve_spd`.
        tol : float
            Relative residual of the iterative solver.

        Returns
        -------
        HeatSolution

        Raises
        ------
        SolveError
            Neither a fixed temperature nor a convection boundary: the temperature is
            known only up to a constant.
        """
        if not self.temperatures and not self.convections:
            raise SolveError("HeatConduction: expected a fixed temperature (add_temperature) "
                             "or a convection boundary (add_convection), received neither: the "
                             "temperature is then known only up to a constant; fix it somewhere")
        K, f = self.system()
        fixed, values = merged_conditions(
            [(nodes, vals) for nodes, vals in self.temperatures], 1, "add_temperature")
        T = solve_constrained(K, f, fixed, values, points=None, tol=tol, method=method)
        return HeatSolution.from_temperature(self, T)
