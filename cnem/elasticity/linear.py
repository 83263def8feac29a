"""`Elasticity`: small-strain linear elasticity by C-NEM with SCNI (paper §4.1-4.2)."""

from __future__ import annotations

import logging
import sys
import time
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp
from skfem.helpers import ddot, sym_grad
from skfem.models.elasticity import linear_stress
from tqdm.auto import tqdm

from ..assembly import BilinearForm, CellBasis
from ..solvers.condensation import principal_submatrix
from ..assembly.basis import spread_component
from ..assembly.quadrature import cell_quadrature
from ..assembly.subdivision import subdivide, tip_cells
from ..assembly.gradients import GradientCache
from ..assembly.triangles import simplex_basis
from ..solvers.constrained import solve_constrained
from ..solvers.symmetric import UpperTriangle
from ..errors import InputError
from ..material import check_plane, check_stiffness, lame, moduli, parse_materials, stiffness_matrix
from .model_problem import ModelProblem
from .solution import ElasticSolution
from .stabilization import stabilization_lame

if TYPE_CHECKING:
    from typing import Literal, Sequence
    from ..fracture.enrichment import Enrichment
    from ..geometry.model import Model
    from ..geometry.model_update import ModelUpdate

__all__ = ["Elasticity", "elasticity_form"]

log = logging.getLogger(__name__)


@BilinearForm
def elasticity_form(u, v, w):
    """``sigma(u) : eps(v)`` with per-cell Lamé parameters ``w.lam``, ``w.mu``."""
    return ddot(linear_stress(w.lam, w.mu)(sym_grad(u)), sym_grad(v))


class Elasticity(ModelProblem):
    """Linear elasticity on a C-NEM model: plane stress or strain in 2-D; the dofs,
    the assembly and the solution carry the model's dimension ``dim``.

    Parameters
    ----------
    model : Model
        From `cnem.discretize`: ``n`` nodes, ``m`` integration cells.
    materials : (E, nu) pair or `cnem.material.LinearElastic`, or a list of either indexed by region
    plane : {"stress", "strain"}, optional
        The 2-D idealisation (default "stress"); none for a 3-D model.
    gauss : int
        Gauss points per cell-edge piece in the smoothed gradients.
    enrich : dict(tips=..., radius=..., functions=...) or cnem.fracture.Enrichment, optional
        Near-tip enrichment of the nodes within ``radius`` of the crack tips
        nearest to ``tips`` (default all tips): ``functions="sqrt"`` (paper
        eq. 47) or ``"branch"`` (the four branch functions); two more dofs
        per function and enriched node, after the nodal ones. The integration
        cells are then split into fan sub-cells (`cnem.assembly.subdivide`).
    stabilization : float
        Weight ``a`` of the sub-cell stabilisation of SCNI (after Puso et al. 2008):
        ``K += a sum_s A_s (B~_s - B~_k)^T C_dev (B~_s - B~_k)`` over the fan
        sub-cells ``s`` of every cell ``k``, ``C_dev`` the deviatoric elasticity of the
        shear modulus alone, ``2 mu dev(e) : dev(e)`` of the 3-D strain
        (`cnem.elasticity.stabilization`), so that it neither locks nor stiffens the
        volume change as ``nu -> 1/2``. It vanishes for linear fields (the patch test
        still holds) and stiffens the low-energy oscillating modes that plain SCNI
        (``a = 0``, the paper's method) leaves almost free, which otherwise show as
        node-to-node oscillations along free crack faces. ``a = 1`` gives each sub-cell's
        strain deviation the shear energy of the material.
    gradients : GradientCache, optional
        The model's smoothed gradients at ``gauss``, to share with other
        problems on the model (what it has computed is not computed again); by
        default the problem keeps its own (`gradients`).

    Attributes
    ----------
    dim : int
        The model's dimension.
    region_materials : tuple of cnem.material.LinearElastic
        One material per region.
    materials : (r, 2) ndarray
        Their ``(E, nu)``.

    Examples
    --------
    >>> import numpy as np, cnem
    >>> model = cnem.discretize(cnem.nodes.irregular(cnem.geometry.rectangle(2.0, 1.0), 0.1, seed=1))
    >>> prob = cnem.Elasticity(model, (1000.0, 0.3))
    >>> prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, 0)
    >>> prob.add_dirichlet(lambda p: (p[:, 0] < 1e-9) & (p[:, 1] < 1e-9), 1)
    >>> prob.add_traction(lambda x, n: n[:, 0] > 0.5, [10.0, 0.0])
    >>> sol = prob.solve(progress=False)
    >>> bool(np.allclose(sol.stress[:, 0], 10.0))                  # uniform tension
    True
    """

    def __init__(self, model: Model, materials: tuple[float, float] | Sequence[tuple[float, float]],
                 *, plane: str | None = None, gauss: int = 2, enrich: Enrichment | None = None,
                 stabilization: float = 1.0, gradients: GradientCache | None = None):
        from ..fracture.enrichment import Enrichment
        super().__init__(model, gauss=gauss, gradients=gradients, caller="Elasticity")
        self.enrichment = Enrichment.from_spec(model, enrich)
        #: the integration cells: the model's, or their fan sub-cells with enrichment (one
        #: smoothed strain per cell cannot control the extra dofs)
        if self.enrichment is not None:
            self.cells = subdivide(model.cells, model.nodes, node_apex=tip_cells(model))[0]
        if self.dim == 2 and plane is None:
            plane = "stress"
        check_plane(self.dim, plane)
        self.region_materials = parse_materials(materials, model.domain.n_regions, plane,
                                                dim=self.dim)
        self.materials = moduli(self.region_materials)
        self.stabilization = float(stabilization)
        if not (np.isfinite(self.stabilization) and self.stabilization >= 0):
            raise InputError(f"stabilization: expected a number >= 0, received {stabilization!r}")
        self.plane = plane
        self._basis = None
        self._K = None

    def __repr__(self):
        return (f"<Elasticity plane {self.plane}, {len(self.model.nodes)} nodes, "
                f"{self.conditions_repr()}>")

    # -- conditions (`ModelProblem`: add_dirichlet, add_traction, add_body_force) ------

    # -- assembly -----------------------------------------------------------------------
    @property
    def basis(self) -> CellBasis:
        """The vector `CellBasis` (built on first use)."""
        if self._basis is None:
            if self._sub_cells() and self._K is None:
                # K will need the fan sub-cells' gradients: B~ of the cells comes with them
                self.gradients.fan()
            extra = (None if self.enrichment is None
                     else self.enrichment.smoothed_gradient(self.gauss, self.cells))
            self._basis = CellBasis(self.model, vector=True, extra=extra, cells=self.cells,
                                    gradient=self.gradients.of(self.cells))
        return self._basis

    def update_from(self, old: Elasticity, change: ModelUpdate) -> Elasticity:
        """Take ``B~`` and ``K`` from the problem ``old`` on the model before a local
        update, recomputing only the cells the change reaches
        (`cnem.elasticity.operator_update.updated_operators`); equal to building them here.

        Parameters
        ----------
        old : Elasticity
            On ``change.old``, with the same materials, plane, gauss and stabilisation.
        change : cnem.geometry.model_update.ModelUpdate
            With ``change.model`` this problem's model.

        Returns
        -------
        Elasticity
            ``self``.
        """
        from .operator_update import updated_operators
        gradient, self._K = updated_operators(old, self, change, elasticity_form)
        self.gradients = GradientCache(self.model, gauss=self.gauss, cells=gradient)
        self._basis = CellBasis(self.model, vector=True, cells=self.cells,
                                gradient=self.gradients.cells())
        return self

    def cell_materials(self) -> np.ndarray:
        """``(m, 2)`` ``(E, nu)`` of every integration cell."""
        return self.materials[self.cells.region]

    def stiffness(self, *, upper: bool = False) -> sp.csr_matrix | UpperTriangle:
        """Global stiffness ``K`` (eq. 33), ``(dim n, dim n)`` CSR, or its upper triangle.

        With stabilisation ``a`` it is ``K_cells + a S``, where ``S`` penalises the
        deviator of the difference between each sub-cell's smoothed strain and its
        cell's with the shear modulus alone, ``2 mu dev(e_s - e_k) : dev(e_s - e_k)``:
        independent of ``lam``, so that it never locks, and free of volume change, so
        that it does not stiffen nearly incompressible bodies.

        The problem keeps the form it first made: `solve` asks for the upper triangle in
        3-D (assembled alone, half the work and bytes: 0.9 GB instead of 1.8 at 100k
        nodes), the CSR elsewhere; asking for the other form converts a copy.

        Parameters
        ----------
        upper : bool
            Return the upper triangle, a `cnem.solvers.symmetric.UpperTriangle` (its
            products ``K @ u`` are the whole matrix's).

        Returns
        -------
        scipy.sparse.csr_matrix or UpperTriangle, shape (dim n, dim n)
        """
        if self._K is None:
            (lam, mu), stabilization = self.stiffness_moduli()
            K = None
            if stabilization is not None and self._sub_cells():
                K = self._cell_and_sub_cell_stiffness((lam, mu), stabilization, upper)
            else:
                if np.any(lam != 0.0) or np.any(mu != 0.0):
                    K = elasticity_form.assemble(self.basis, groups=self.cells.region, lam=lam,
                                                 mu=mu)
                if stabilization is not None:
                    extra = self._pointwise_stabilization_stiffness(*stabilization)
                    K = extra if K is None else K + extra
            check_stiffness(K.data, self.materials, "the assembled stiffness")
            self._K = K
        if upper and not isinstance(self._K, UpperTriangle):
            return UpperTriangle.from_matrix(self._K)
        if not upper and isinstance(self._K, UpperTriangle):
            return self._K.tocsr()
        return self._K

    def stiffness_moduli(self) -> tuple[tuple[np.ndarray, np.ndarray],
                                        tuple[np.ndarray, np.ndarray] | None]:
        """Lamé parameters per region of the cells' term of `stiffness` and of its
        stabilisation term (None without stabilisation).

        The sub-cell stabilisation of weight ``a`` is deviatoric in 3-D and plane strain:
        ``a mu`` and ``a lam_s`` with ``lam_s`` of
        `cnem.elasticity.stabilization.stabilization_lame` (``-2 mu / 3``; ``0``, the
        shear-only law, in plane stress, which does not lock). With sub-cells, whose strains average to their cell's,
        ``K_cells(lam, mu) + a sum_s A_s (B~_s - B~_k)^T C_dev (B~_s - B~_k)`` is
        ``K_cells(lam - a lam_s, (1 - a) mu) + a sum_s K_s(lam_s, mu)``
        (`_cell_and_sub_cell_stiffness`). The
        pointwise term of enriched problems (`_pointwise_stabilization_stiffness`)
        keeps the full law ``a lam, a mu``.

        Returns
        -------
        cells : ((r,) ndarray, (r,) ndarray)
        stabilization : ((r,) ndarray, (r,) ndarray) or None
        """
        a = self.stabilization
        lam, mu = lame(*self.materials.T, self.plane)
        if a == 0:
            return (lam, mu), None
        if not self._sub_cells():
            # with enrichment the pointwise term completes the smoothed stiffness towards
            # the Galerkin one on the few cells near the tips: it keeps the full law
            return (lam, mu), (a * lam, a * mu)
        lam_s = a * stabilization_lame(mu, self.materials[:, 1], self.plane)
        return (lam - lam_s, (1.0 - a) * mu), (lam_s, a * mu)

    def _sub_cells(self):
        """Whether the stabilisation uses the fan sub-cells of the model's cells
        (stabilised, not enriched)."""
        return self.enrichment is None and self.stabilization > 0

    def _cell_and_sub_cell_stiffness(self, cells, sub_cells, upper):
        """``sum_k A_k B~_k^T C_k B~_k + sum_s A_s B~_s^T C_s B~_s`` over the cells ``k``
        and their fan sub-cells ``s``, ``C`` of the Lamé parameters given per region
        (``cells`` and ``sub_cells``: the two terms of `stiffness_moduli`), assembled
        in one pass over the cells and the sub-cells (no second matrix to add), its
        upper triangle alone if ``upper``.

        The sub-cells of a cell ``k`` share its boundary integrals and their
        spokes cancel, so ``sum_s A_s B~_s = A_k B~_k`` and the stabilisation
        ``a sum_s A_s (B~_s - B~_k)^T C (B~_s - B~_k)`` equals
        ``a sum_s A_s B~_s^T C B~_s - a A_k B~_k^T C B~_k``: no difference operators
        (whose rows would carry both patterns) are formed, and the cells' own term
        is taken off their stiffness (`stiffness_moduli`). The identity needs a
        constant ``C`` per cell (a linear law); a state-dependent tangent needs the
        difference form.
        """
        coarse = self.basis                      # first: it keeps the fan's for below
        sub, grad = self.gradients.fan(release=True)
        value = sp.csr_matrix((np.ones(len(sub.node)), (np.arange(len(sub.node)), sub.node)),
                              shape=(len(sub.node), len(self.model.nodes)))
        # with groups the form sees no points: the nodes stand for them
        fan = CellBasis.from_operators(self.model, value, grad, sub.measure,
                                       self.model.nodes[sub.node], vector=True)
        del grad
        groups = np.concatenate([self.cells.region, len(self.materials) + sub.region])
        lam, mu = (np.concatenate([c, s]) for c, s in zip(cells, sub_cells))
        return elasticity_form.assemble_over([coarse, fan], groups=groups, upper=upper,
                                             lam=lam, mu=mu)

    def _pointwise_stabilization_stiffness(self, lam, mu, order=4):
        """``sum_q w_q (B(x_q) - B~_k)^T C (B(x_q) - B~_k)`` over quadrature points of
        the cells where enrichment functions live, ``B(x)`` the gradients of the
        displacement field itself (Sibson and enrichment gradients).

        One smoothed strain per sub-cell leaves enriched fields with modes the
        smoothing does not see; this term controls them and vanishes for linear
        fields (the patch test holds). With exact integration the smoothed
        stiffness plus this term would be the Galerkin stiffness on these cells."""
        basis, cells, enrichment = self.basis, self.cells, self.enrichment
        owner, points, weights = cell_quadrature(cells, self.model.nodes, order,
                                                 singular=enrichment.tips)
        near = np.zeros(len(cells.area), dtype=bool)
        near[owner[enrichment.in_support(points)]] = True        # whole cells
        keep = np.flatnonzero(near[owner])
        owner, points = owner[keep], points[keep]
        shape = self.model.shape_functions(points, gradient=True)
        _, *extra = enrichment.values(points, shape.value, gradient=shape.gradient)
        grads = [sp.hstack([g, e], format="csr") for g, e in zip(shape.gradient, extra)]
        to_cell = sp.csr_matrix((np.ones(len(owner)), (np.arange(len(owner)), owner)),
                                shape=(len(owner), len(cells.area)))
        ops, d = basis.operators, basis.ncomp
        pointwise = [spread_component(g, c, d) for c in range(d) for g in grads]
        diff = [p - to_cell @ b for p, b in zip(pointwise, ops[d:])]
        at_points = basis.at_points([to_cell @ op for op in ops[:d]] + diff,
                                    weights[keep], points)
        return elasticity_form.assemble(at_points, groups=cells.region[owner], lam=lam, mu=mu)

    def load(self) -> np.ndarray:
        """Load vector ``f`` (eq. 21), ``(dim n,)`` (then the enriched dofs' loads)."""
        f = self.nodal_load()
        d = self.dim
        enriched = np.zeros((0 if self.enrichment is None else len(self.enrichment), d))
        if self.enrichment is not None:
            for traction in self.tractions:
                enriched += self.enrichment.edge_loads(traction.edges, traction.normal,
                                                       traction.value)
        # (the enrichment functions vanish at the nodes: no nodal body-force share)
        return np.concatenate([f.reshape(-1), enriched.reshape(-1)])

    def prescribed(self) -> tuple[np.ndarray, np.ndarray]:
        """The prescribed dofs and values (`Conditions.prescribed`), with the enriched
        dofs of constrained nodes held at 0.

        Returns
        -------
        dofs : (k,) int64 ndarray
        values : (k,) ndarray
        """
        dofs, values = super().prescribed()
        if self.enrichment is not None:
            # enriched dofs of constrained nodes are held at 0, so that every test
            # function vanishes on the Dirichlet boundary
            n = len(self.model.nodes)
            size = self.enrichment.size
            slot = np.full(n, -1)
            slot[self.enrichment.nodes] = np.arange(len(self.enrichment.nodes))
            d = self.dim
            hit = slot[dofs // d] >= 0
            first = n + slot[dofs[hit] // d] * size               # the node's first function
            extra = (d * (first[:, None] + np.arange(size)) + (dofs[hit] % d)[:, None]).reshape(-1)
            dofs = np.concatenate([dofs, extra])
            values = np.concatenate([values, np.zeros(len(extra))])
        return dofs, values

    def solver_options(self, dofs: np.ndarray) -> dict:
        """The keywords of `cnem.solvers.linsolve.solve_spd` for the system on ``dofs``
        (the free ones): the P1 matrix its smoothed aggregation is built on (made only
        if the iterative path is taken), and for plain SCNI and in 3-D smoothing with
        K itself (its oscillating low-energy modes, which P1 lacks: the stabilised
        3-D cantilever of 10k nodes takes 291 CG iterations with P1 alone, 59 so,
        12.7 s of CPU instead of 24.7; smoothed aggregation on K itself takes 56, its
        set-up ten times P1's); with enrichment, which of the dofs are nodal (the
        enriched block is then solved exactly inside the preconditioner).

        Returns
        -------
        dict
        """
        options = dict(preconditioner=lambda: self.preconditioner_matrix(dofs),
                       smooth_with_matrix=self.stabilization == 0 or self.dim == 3)
        if self.enrichment is not None:
            options["nodal"] = np.asarray(dofs) < self.model.nodes.size
        return options

    def preconditioner_matrix(self, dofs: np.ndarray | None = None) -> sp.spmatrix | None:
        """The P1 stiffness of the nodes on the model's triangles or tetrahedra (same materials):
        where smoothed aggregation is built for large solves (see
        `cnem.assembly.triangles`).

        Parameters
        ----------
        dofs : (k,) int ndarray, optional
            Keep these rows and columns only (the free dofs, strictly increasing).

        Returns
        -------
        scipy.sparse.csr_matrix, shape (dim n, dim n) or (k, k)
            None with enrichment (P1 has no enriched dofs) or degenerate triangles
            (the solver then builds its hierarchy on K).
        """
        if self.enrichment is not None:
            return None
        try:
            basis, region = simplex_basis(self.model, vector=True)
        except ValueError as err:
            log.warning("no P1 preconditioner matrix (%s): smoothed aggregation on K", err)
            return None
        lam, mu = lame(*self.materials.T, self.plane)
        P = elasticity_form.assemble(basis, groups=region, lam=lam, mu=mu)
        return P if dofs is None else principal_submatrix(P, dofs)

    # -- solve --------------------------------------------------------------------------
    def solve(self, *, method: Literal["auto", "direct", "amg"] = "auto", tol: float = 1e-10,
              progress: bool | None = None) -> ElasticSolution:
        """Solve ``K d = f`` with the Dirichlet values imposed.

        Parameters
        ----------
        method : {"auto", "direct", "amg"}
            ``"auto"``: sparse direct up to 2.5M non-zeros in K (~20k nodes), pyamg smoothed
            aggregation (rigid-body modes) + CG above, the hierarchy built on the P1
            stiffness of the same nodes on the model's triangles (without enrichment:
            see `preconditioner_matrix`; for plain SCNI, ``stabilization=0``, and in
            3-D the finest level smoothed with K itself). With enrichment the hierarchy is
            built on the nodal block and the enriched block is factorised (see
            `cnem.solvers.linsolve.solve_spd`). A stalled CG falls back to the direct
            solve when its factor fits in memory (`cnem.config.DIRECT_MEMORY`).
        tol : float
            Relative residual of the iterative solver.
        progress : bool, optional
            Progress bar over the stages (default: on a terminal).

        Returns
        -------
        ElasticSolution

        Raises
        ------
        SolveError
            Rigid motions not fixed by the Dirichlet conditions (named), or a stalled
            iterative solve whose direct fallback would not fit in memory (the message
            says what to change).
        """
        if progress is None:
            progress = sys.stderr.isatty()
        timings = {}
        bar = tqdm(total=3, desc="elasticity", disable=not progress, leave=False)
        t0 = time.perf_counter()
        bar.set_postfix_str("smoothed gradients")
        self.basis.grad
        t1 = time.perf_counter()
        bar.update()
        bar.set_postfix_str("stiffness")
        K = self.stiffness(upper=self.dim == 3)
        f = self.load()
        t2 = time.perf_counter()
        bar.update()
        D, values = self.prescribed()
        bar.set_postfix_str("solve")
        try:
            x = solve_constrained(K, f, D, values, points=self.model.nodes, tol=tol,
                                  method=method, options=self.solver_options)
        finally:
            bar.close()
        t3 = time.perf_counter()
        timings.update(gradients=t1 - t0, assembly=t2 - t1, solve=t3 - t2)
        log.info("elasticity: %s", ", ".join(f"{k} {v:.3f} s" for k, v in timings.items()))
        E, nu = self.cell_materials().T
        C = stiffness_matrix(E, nu, self.plane)
        return ElasticSolution.from_dofs(self, x, C, timings)
