"""`Hyperelasticity`: finite-strain hyperelasticity by C-NEM with SCNI (total Lagrangian,
Newton with load steps)."""

from __future__ import annotations

import inspect
import logging
import sys
import time
from typing import TYPE_CHECKING

import numpy as np
from tqdm.auto import tqdm

from ..assembly import CellBasis
from ..errors import InputError, MaterialError, OptionError
from ..material import Hyperelastic, NeoHookean, check_plane, parse_materials
from ..solvers.conditions import dirichlet_dofs, merged_conditions, per_point
from ..solvers.linsolve import rigid_modes
from ..solvers.multigrid import hierarchy
from ..solvers.newton import newton
from .fbar import FbarOperator, patch_average
from .finite_strain import EnergySum, FiniteStrainOperator
from .hyperelastic_solution import HyperelasticSolution
from .linear import Elasticity
from .model_problem import ModelProblem
from .stabilization import IsochoricNeoHookean

if TYPE_CHECKING:
    from typing import Callable, Literal, Sequence

    from numpy.typing import ArrayLike

    from ..assembly.gradients import GradientCache
    from ..geometry.model import Model
    from ..solvers.conditions import Where

__all__ = ["Hyperelasticity"]

log = logging.getLogger(__name__)


class Hyperelasticity(ModelProblem):
    """Finite-strain hyperelasticity on a C-NEM model: plane strain in 2-D (``F33 = 1``)
    or 3-D, total Lagrangian with the smoothed deformation gradient
    ``F~ = I + grad~ u`` of each integration cell
    (`cnem.elasticity.finite_strain.FiniteStrainOperator`).

    Conditions are those of `cnem.Elasticity` (`add_dirichlet`, `add_traction`,
    `add_body_force`): the Dirichlet values are reached at the last load step,
    tractions and body forces are dead loads on the reference configuration, all
    ramped in equal load steps; a Dirichlet condition may instead follow a ``path``
    over the load steps (`add_dirichlet`: a rigid rotation of a face, say).

    Parameters
    ----------
    model : Model
        From `cnem.discretize`: ``n`` nodes, ``m`` integration cells.
    materials : cnem.material.Hyperelastic, or a list of them indexed by region
        `cnem.material.NeoHookean`, `cnem.material.SaintVenantKirchhoff`.
    plane : {"strain"}, optional
        The 2-D idealisation: plane strain, the only one (and the default); none
        for a 3-D model.
    gauss : int
        Gauss points per cell-edge piece in the smoothed gradients.
    stabilization : float
        Weight ``a`` of an energy-based sub-cell stabilisation (default 1, as
        `cnem.Elasticity`; 0 is plain SCNI, whose Newton iterations may invert cells or
        end on an indefinite tangent: Cook's membrane, `docs/finite_strain.md`). The
        energy becomes
        ``sum_k V_k W(F~_k) + a [sum_s V_s W_dev(F~_s) - sum_k V_k W_dev(F~_k)]`` over
        the fan sub-cells ``s`` of the cells ``k``, ``W_dev`` the isochoric neo-Hookean
        law ``mu/2 (J^(-2/3) tr C - 3)`` of the region's shear modulus
        (`cnem.elasticity.stabilization.IsochoricNeoHookean`). The sub-cells' gradients
        average to their cell's, so the term vanishes for homogeneous deformations (the
        patch test holds) and, near the reference state, is positive for the
        oscillating modes one gradient per cell does not see; it has no bulk stiffness,
        so it neither locks nor stiffens the volume change as the material becomes
        incompressible. At small strain it is the deviatoric stabilisation of
        `cnem.Elasticity` with the same weight. With ``volumetric="fbar"`` ``W_dev`` is
        instead the neo-Hookean law of ``lam = 0`` (``mu/2 (tr C - 3) - mu ln J``),
        whose volumetric part holds each cell's own volume change, which F-bar frees.
    gradients : GradientCache, optional
        The model's smoothed gradients at ``gauss``, shared with other problems
        on the model (an `Elasticity` on the same model, say).
    volumetric : {"fbar", None}
        ``"fbar"``: every cell's volume change is averaged over a patch of about
        four cells (`cnem.elasticity.fbar`), which removes volumetric locking as the
        material becomes incompressible; None: plain SCNI, one volume change per cell.

    Attributes
    ----------
    dim : int
    region_materials : tuple of cnem.material.Hyperelastic
        One law per region.

    Examples
    --------
    >>> import numpy as np, cnem
    >>> model = cnem.discretize(cnem.nodes.irregular(cnem.geometry.rectangle(2.0, 1.0), 0.2, seed=1))
    >>> prob = cnem.Hyperelasticity(model, cnem.material.NeoHookean(1.0, 1.5))
    >>> prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, 0)
    >>> prob.add_dirichlet(lambda p: (p[:, 0] < 1e-9) & (p[:, 1] < 1e-9), 1)
    >>> prob.add_dirichlet(lambda p: p[:, 0] > 2.0 - 1e-9, 0, 1.0)     # stretch to 2
    >>> sol = prob.solve(steps=2)
    >>> bool(np.allclose(sol.deformation_gradient[:, 0, 0], 1.5))
    True
    """

    #: Finite-strain C-NEM has no crack-tip enrichment.
    enrichment = None

    def __init__(self, model: Model, materials: Hyperelastic | Sequence[Hyperelastic], *,
                 plane: Literal["strain"] | None = None, gauss: int = 2,
                 stabilization: float = 1.0, gradients: GradientCache | None = None,
                 volumetric: Literal["fbar"] | None = None):
        super().__init__(model, gauss=gauss, gradients=gradients, caller="Hyperelasticity")
        if self.dim == 2 and plane is None:
            plane = "strain"
        check_plane(self.dim, plane)
        if plane == "stress":
            raise OptionError("plane: finite-strain C-NEM is written for plane strain (F33 = 1) "
                              "in 2-D, received 'stress'; pass plane='strain' or use a 3-D model")
        self.plane = plane
        self.region_materials = parse_materials(materials, model.domain.n_regions,
                                                dim=self.dim)
        other = [type(m).__name__ for m in self.region_materials
                 if not isinstance(m, Hyperelastic)]
        if other:
            raise MaterialError(f"materials: expected hyperelastic laws (cnem.material."
                                f"NeoHookean, SaintVenantKirchhoff), received {', '.join(other)}"
                                f"; for a small-strain law use cnem.Elasticity")
        self.stabilization = float(stabilization)
        if not (np.isfinite(self.stabilization) and self.stabilization >= 0):
            raise InputError(f"stabilization: expected a number >= 0, received {stabilization!r}")
        if volumetric not in ("fbar", None):
            raise OptionError(f"volumetric: expected 'fbar' or None, received {volumetric!r}")
        self.volumetric = volumetric
        self._operator = None
        self._system = None
        self._preconditioner = None          # (dofs, VCycle) of `solver_options`
        self._paths = {}          # index in self.dirichlet -> (nodes, components, path)

    def __repr__(self):
        idealisation = f"plane {self.plane}" if self.plane else "3-D"
        return (f"<Hyperelasticity {idealisation}, {len(self.model.nodes)} nodes, "
                f"{self.conditions_repr()}>")

    @property
    def basis(self) -> CellBasis:
        """The vector `CellBasis` of the model's cells."""
        return self.operator.basis

    @property
    def operator(self) -> FiniteStrainOperator | FbarOperator:
        """Energy, internal forces and tangent of the cells (built on first use)."""
        if self._operator is None:
            basis = CellBasis(self.model, vector=True, cells=self.cells,
                              gradient=self.gradients.cells())
            region = self.cells.region
            if self.volumetric == "fbar":
                self._operator = FbarOperator(basis, self.region_materials, region,
                                              patch_average(basis, self.cells.node, region))
            else:
                self._operator = FiniteStrainOperator(basis, self.region_materials, region)
        return self._operator

    @property
    def system(self) -> FiniteStrainOperator | EnergySum:
        """What Newton solves: `operator`, plus the sub-cell stabilisation when
        ``stabilization > 0`` (an `cnem.elasticity.finite_strain.EnergySum`)."""
        if self._system is None:
            a = self.stabilization
            if a == 0:
                self._system = self.operator
            else:
                sub, grad = self.gradients.fan(release=True)     # B~ of the cells with it
                fine = CellBasis(self.model, vector=True, cells=sub, gradient=grad)
                shear = [self._stabilization_law(m.lame(self.dim, self.plane)[1])
                         for m in self.region_materials]
                cells = self.operator
                self._system = EnergySum([
                    (1.0, cells), (a, FiniteStrainOperator(fine, shear, sub.region)),
                    (-a, FiniteStrainOperator(cells.basis, shear, self.cells.region))])
        return self._system

    def _stabilization_law(self, mu):
        """The sub-cell stabilisation's energy of shear modulus ``mu``: deviatoric
        (`IsochoricNeoHookean`), or with F-bar the neo-Hookean law of ``lam = 0``, whose
        volumetric part holds the cells' own volume changes that the patches free (with
        the deviatoric law the F-bar patch test of `tests/test_fbar.py` inverts cells
        in Newton's first iterates at two load steps)."""
        return NeoHookean(mu, 0.0) if self.volumetric == "fbar" else IsochoricNeoHookean(mu)

    def solver_options(self, dofs: np.ndarray) -> dict:
        """The keywords of `cnem.solvers.linsolve.solve_spd` for Newton's corrections on
        ``dofs`` (the free ones): those of the linear `cnem.Elasticity` of the laws
        linearised at ``F = I`` (`cnem.Elasticity.solver_options`: smoothed aggregation
        on the P1 stiffness of the nodes), with the hierarchy built once, when the first
        correction takes the iterative path, and kept for every later correction on
        the same dofs. The P1 matrix does not change with the tangent, so the
        hierarchy stays as good as it was (in 3-D and for plain SCNI its finest level
        is smoothed with each correction's tangent itself).

        Returns
        -------
        dict
        """
        dofs = np.asarray(dofs)
        linear = Elasticity(self.model, [m.linearized() for m in self.region_materials],
                            plane=self.plane, gauss=self.gauss,
                            stabilization=self.stabilization, gradients=self.gradients)
        options = linear.solver_options(dofs)
        matrix = options.pop("preconditioner")

        def preconditioner():
            kept = self._preconditioner
            if kept is None or not np.array_equal(kept[0], dofs):
                P = matrix()
                kept = (dofs, None if P is None else
                        hierarchy(P, rigid_modes(np.asarray(self.model.nodes))[dofs]))
                self._preconditioner = kept
            return kept[1]

        return dict(options, preconditioner=preconditioner)

    def add_dirichlet(self, where: Where, component: int | None,
                      value: ArrayLike | Callable[[np.ndarray], np.ndarray] = 0.0, *,
                      path: Callable[[np.ndarray, float], np.ndarray] | None = None) -> None:
        """Prescribe displacements at nodes: ``value``, ramped linearly over the load
        steps, or the displacements of a ``path``.

        Parameters
        ----------
        where : str, callable ``(n, d) -> (n,) bool``, or a boolean mask / index array over
            the nodes
            As `cnem.Elasticity.add_dirichlet`.
        component : {0, ..., d - 1, None}
            ``None`` prescribes every component.
        value : float, or callable ``(p, d) -> (p,)`` (``(p, d)`` for every component)
            The displacement at the last load step; at the load factor
            ``t = step / steps`` it is ``t * value``.
        path : callable ``(points (p, d), t: float) -> (p,)`` (``(p, d)`` for every component), optional
            The displacements of the selected nodes at the load factor
            ``t = step / steps`` of each load step (``t = 1``: the last), in place of
            the linear ramp, for a motion that a ramp would distort: the rigid rotation
            of a face by ``t * theta``, whose linear ramp shrinks the face between the
            steps. Give ``value`` or ``path``, not both.

        Raises
        ------
        InputError
            ``path`` not a callable of the points and the load factor, or given with a
            ``value``; `cnem.errors.ConditionError` (an InputError): nothing selected,
            or values of the wrong shape or not finite (``path``'s are checked at
            ``t = 1`` here and at every load step in `solve`).

        Examples
        --------
        >>> import numpy as np, cnem
        >>> model = cnem.discretize(cnem.nodes.irregular(cnem.geometry.rectangle(1.0, 1.0), 0.25, seed=1))
        >>> prob = cnem.Hyperelasticity(model, cnem.material.NeoHookean(1.0, 1.5))
        >>> def turned(p, t, theta=np.pi / 2):       # the rotation by t theta about the origin
        ...     c, s = np.cos(t * theta), np.sin(t * theta)
        ...     return p @ np.array([[c - 1, s], [-s, c - 1]])
        >>> prob.add_dirichlet(lambda p: (p[:, 0] < 1e-9) | (p[:, 0] > 1 - 1e-9), None, path=turned)
        >>> sol = prob.solve(steps=3)
        >>> bool(np.abs(sol.stress).max() < 1e-8)        # turned rigidly at every step
        True
        """
        if path is None:
            super().add_dirichlet(where, component, value)
            return
        if not callable(path):
            raise InputError(f"add_dirichlet: path: expected a callable (points (p, d), t) -> "
                             f"displacements, received {type(path).__name__}; for a "
                             f"displacement ramped linearly pass it as value")
        if callable(value) or np.any(np.asarray(value) != 0):
            raise InputError("add_dirichlet: received both a value and a path; give the "
                             "displacements as path(points, t) alone (value is what a "
                             "linear ramp reaches at the last load step)")
        try:
            inspect.signature(path).bind(np.zeros((0, self.dim)), 1.0)
        except TypeError:
            raise InputError("add_dirichlet: path: expected a callable of two arguments, the "
                             "points (p, d) and the load factor t in (0, 1], received one "
                             "that does not take them; e.g. lambda p, t: t * p[:, 0]") from None
        except ValueError:                    # no signature to read (a builtin): just call
            pass
        dofs, values = dirichlet_dofs(self.condition_points, where, component,
                                      lambda p: path(p, 1.0), where_to_look=self.points_name,
                                      what="add_dirichlet path", named=self.named_nodes)
        width = self.dim if component is None else 1
        self._paths[len(self.dirichlet)] = (dofs[::width] // self.dim, width, path)
        self.dirichlet.append((dofs, values))

    def prescribed_at(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """The prescribed dofs and their values at the load factor ``t``: the conditions'
        ``value`` times ``t``, their ``path`` at ``t``.

        Returns
        -------
        dofs : (k,) int64 ndarray
            Sorted, distinct (those of `prescribed`).
        values : (k,) ndarray

        Raises
        ------
        ConditionError
            A path's values of the wrong shape or not finite, or two conditions that
            give one dof different values at ``t``.
        """
        points = self.condition_points
        conditions = []
        for k, (dofs, values) in enumerate(self.dirichlet):
            if k in self._paths:
                nodes, width, path = self._paths[k]
                values = per_point(path(points[nodes], t), points[nodes], width,
                                   f"add_dirichlet path at t = {t:g}").reshape(-1)
            else:
                values = t * np.asarray(values)
            conditions.append((dofs, values))
        return merged_conditions(conditions, self.dim, "add_dirichlet")

    def load(self) -> np.ndarray:
        """The whole dead load (tractions and body forces), ``(dim n,)``."""
        return self.nodal_load().reshape(-1)

    def solve(self, *, steps: int = 1, tol: float = 1e-10, max_iterations: int = 20,
              line_search: bool = False, progress: bool | None = None) -> HyperelasticSolution:
        """Newton's method (`cnem.solvers.newton.newton`, exact tangent) over ``steps``
        equal load steps.

        Parameters
        ----------
        steps : int
            Load steps: the Dirichlet values and loads grow by ``1 / steps`` each (the
            values of a Dirichlet ``path`` follow it, `add_dirichlet`).
        tol : float
            Relative residual of each step (see `cnem.solvers.newton.newton`).
        max_iterations : int
            Newton corrections allowed per load step.
        line_search : bool
            Backtrack along each correction until the residual decreases.
        progress : bool, optional
            A tqdm bar over the load steps on stderr (default: when stderr is a
            terminal).

        Returns
        -------
        HyperelasticSolution
            With ``residual_history``, one list of residual norms per load step, and
            ``steps``, the displacements after each (``sol.write("run.pvd")`` writes them
            as a series over the load factor).

        Raises
        ------
        ConvergenceError
            A load step that does not converge or whose cells invert (``J <= 0``);
            the error's ``history`` holds the residuals so far.
        SolveError
            Rigid motions not fixed by the Dirichlet conditions (named).
        """
        t0 = time.perf_counter()
        system = self.system
        t1 = time.perf_counter()
        D, values = self.prescribed()
        values_at = (lambda t: self.prescribed_at(t)[1]) if self._paths else None
        states = []
        show = sys.stderr.isatty() if progress is None else progress
        bar = tqdm(total=steps, desc="hyperelasticity load steps", unit="step",
                   disable=not show, leave=False, mininterval=0.0)

        def on_step(step, dofs):
            states.append((step / steps, dofs))
            bar.update()

        try:
            u, history = newton(system.evaluate, self.load(), D, values, points=self.model.nodes,
                                tol=tol, steps=steps, max_iterations=max_iterations,
                                line_search=line_search, values_at=values_at,
                                on_step=on_step, options=self.solver_options)
        finally:
            bar.close()
        t2 = time.perf_counter()
        timings = dict(gradients=t1 - t0, newton=t2 - t1)
        log.info("hyperelasticity: %d load steps, %d Newton iterations, %s", len(history),
                 sum(len(h) - 1 for h in history),
                 ", ".join(f"{k} {v:.3f} s" for k, v in timings.items()))
        return HyperelasticSolution.from_dofs(self, u, history, timings, steps=states)
