"""Results of peridynamic problems: `StaticSolution`, `DynamicRun`, `Relaxation`.

All three are `cnem.solvers.solution.Solution` dataclasses with the fields of
every solver (``u``, ``stress``, ``strain``, ``von_mises``, ``displacement``,
``write``, ``plot``); PD's stresses and strains live at the points.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np

from ..errors import GeometryError, check_points
from ..solvers.solution import Solution, engineering_strain, voigt

__all__ = ["PointSolution", "StaticSolution", "DynamicRun", "Relaxation"]


@dataclass(eq=False, repr=False)
class PointSolution(Solution):
    """Displacements of the points of a peridynamic body, and the fields they give.

    Attributes
    ----------
    problem : cnem.pd.Problem
    u : (n, d) ndarray
        Displacements of the points.
    stress : (n, 3) or (n, 6) ndarray
        Voigt stress of every point, ``[sxx, syy, sxy]`` (2-D) or
        ``[sxx, syy, szz, syz, sxz, sxy]`` (3-D): `stress_tensor` in Voigt form
        (BondBased and StateBased; CPD raises NotImplementedError).
    strain : (n, 3) or (n, 6) ndarray
        Engineering strain of every point (``2 exy``) from the nonlocal
        displacement gradient (`cnem.pd.Problem.displacement_gradient`).
    """

    stress_places = "points"

    def stress_tensor(self) -> np.ndarray:
        """Stress of every point, ``(n, d, d)`` (see `cnem.pd.Problem.stress_tensor`; not
        for CPD)."""
        return self.problem.stress_tensor(self.u)

    @cached_property
    def stress(self) -> np.ndarray:
        """``(n, 3)`` or ``(n, 6)`` Voigt stress of every point (not for CPD)."""
        return voigt(self.stress_tensor())

    @cached_property
    def strain(self) -> np.ndarray:
        """``(n, 3)`` or ``(n, 6)`` engineering strain of every point."""
        return engineering_strain(self.problem.displacement_gradient(self.u))

    def fields(self) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
        """`Solution.fields` at the points (``u`` and ``strain`` only for CPD, which has
        no stress of its own here)."""
        if not self.problem.behaviour.has_stress:
            return {"u": self.u, "strain": self.strain}, {}
        return super().fields()

    def displacement(self, points: np.ndarray) -> np.ndarray:
        """Displacements at points of the body.

        A body made from a C-NEM node cloud (`cnem.pd.Body.from_cloud`)
        interpolates through the model's shape functions (which see the cracks);
        any other body linearly on the Delaunay triangulation (tetrahedra in 3-D)
        of its points, which ignores cracks and periodicity.

        Parameters
        ----------
        points : (p, d) array_like
            Inside the body (the convex hull of its points without a model).

        Returns
        -------
        (p, d) ndarray

        Raises
        ------
        ValueError
            Points outside the convex hull of the body's points.
        """
        pts = check_points("points", points, dims=(self.u.shape[1],), error=GeometryError)
        body = self.problem.body
        model = getattr(body, "model", None)
        if model is not None:
            return model.shape_functions(pts) @ self.u
        from scipy.interpolate import LinearNDInterpolator
        out = LinearNDInterpolator(body.points, self.u)(pts)
        outside = np.isnan(out).any(axis=1)
        if outside.any():
            raise GeometryError(f"displacement: {int(outside.sum())} of {len(pts)} points lie "
                                f"outside the convex hull of the body's points, the first at "
                                f"{pts[outside][0].tolist()}; give points inside the body")
        return out

    def nodal_average(self, values: np.ndarray) -> np.ndarray:
        """Point values are the nodal values: ``values`` itself (checked)."""
        return self._place_values(values)

    def plot_mesh(self) -> tuple:
        """The points, the C-NEM model's triangles for a body made from a node cloud
        (else None: the points are drawn alone), and the points' bounding-box diagonal."""
        body = self.problem.body
        model = getattr(body, "model", None)
        diameter = float(np.linalg.norm(np.ptp(body.points, axis=0)))
        return body.points, None if model is None else model.triangles, diameter

    def write_fields(self, path: str, point_data: dict[str, np.ndarray],
                     cell_data: dict[str, np.ndarray]) -> None:
        """The points as vertex cells with the fields (`cnem.io.write_points`)."""
        from .. import io
        io.write_points(self.problem.body.points, path, point_data=point_data)


@dataclass(eq=False, repr=False)
class StaticSolution(PointSolution):
    """Result of `cnem.pd.Problem.solve` (Newton).

    Attributes
    ----------
    residual_history : list of list of float
        The residual norms of the free dofs at each Newton iterate, one list per
        load step.
    """

    residual_history: list = field(default_factory=list)

    def __repr__(self):
        return (f"<StaticSolution {len(self.u)} points, {len(self.residual_history)} load "
                f"step(s), max |u| {np.abs(self.u).max():.3e}>")


@dataclass(eq=False, repr=False)
class DynamicRun(PointSolution):
    """Result of `cnem.pd.Problem.run_dynamic`: the state after the last step and the
    stored frames.

    Attributes
    ----------
    velocity : (n, d) ndarray
        Final velocities.
    damage : (n,) ndarray
        Final damage of every point.
    times : (f,) ndarray
        Times of the stored frames.
    frames : list of (u (n, d), damage (n,))
        The stored frames.
    energy : (f,) ndarray
        Kinetic plus elastic energy at each stored frame (without breaking).
    broken : int
        Bonds broken during the run.
    files : list of pathlib.Path
        The VTU file of each frame (empty without ``output``).
    """

    velocity: np.ndarray = None
    damage: np.ndarray = None
    times: np.ndarray = None
    frames: list = field(default_factory=list)
    energy: np.ndarray = None
    broken: int = 0
    files: list = field(default_factory=list)

    def fields(self) -> tuple:
        """`Solution.fields` with ``damage`` and ``velocity`` at the points (the stored
        frames of `series` have no velocity)."""
        point_data, cell_data = super().fields()
        extra = {"damage": self.damage}
        if self.velocity is not None:
            extra["velocity"] = self.velocity
        return {**point_data, **extra}, cell_data

    def series(self) -> list[tuple[float, DynamicRun]]:
        """The stored frames at their times, as runs ending there (``u`` and ``damage``;
        no velocity; their stresses and strains through the problem's bonds as they are
        at the end of the run); the final state alone when no frame was stored."""
        if not self.frames:
            return super().series()
        return [(float(time), replace(self, u=u, damage=damage, velocity=None, frames=[],
                                      times=self.times[:k + 1], files=[]))
                for k, (time, (u, damage)) in enumerate(zip(self.times, self.frames))]

    def __repr__(self):
        return (f"<DynamicRun {len(self.u)} points, t = {self.times[-1]:.3e}, "
                f"max damage {self.damage.max():.3f}>")


@dataclass(eq=False, repr=False)
class Relaxation(PointSolution):
    """Result of `cnem.pd.relaxation.relax`.

    Attributes
    ----------
    damage : (n,) ndarray
        ``Problem.damage()`` at the end.
    residual_history : list of list of float
        One list per load step: the residual norm (free dofs) at iteration 0,
        every ``every`` iterations and at the last iteration.
    iterations : int
        Iterations over all load steps.
    broken : int
        Bonds broken during the relaxation.
    """

    damage: np.ndarray = None
    residual_history: list = field(default_factory=list)
    iterations: int = 0
    broken: int = 0

    def fields(self) -> tuple:
        """`Solution.fields` with ``damage`` at the points."""
        point_data, cell_data = super().fields()
        return {**point_data, "damage": self.damage}, cell_data

    def __repr__(self):
        return (f"<Relaxation {len(self.u)} points, {len(self.residual_history)} load step(s), "
                f"{self.iterations} iterations, max damage {self.damage.max():.3f}>")
