"""`HeatSolution`: nodal temperatures, cell fluxes, pointwise values, errors, files and
pictures of a `cnem.HeatConduction` problem."""

from __future__ import annotations

import os
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from ..assembly.recovery import NodalValues, recover_at_nodes, values_at
from ..assembly.scalar_error import h1_error
from ..errors import GeometryError, check_points

if TYPE_CHECKING:
    import pyvista

__all__ = ["HeatSolution"]


@dataclass(eq=False, repr=False)
class HeatSolution:
    """The solution of a `cnem.HeatConduction` problem.

    Attributes
    ----------
    problem : HeatConduction
    model : Model
    T : (n,) ndarray
        Nodal temperatures (the temperature at node ``i`` is ``T[i]``).
    gradient : (m, 2) ndarray
        Smoothed temperature gradient per integration cell.
    flux : (m, 2) ndarray
        Heat flux ``-k grad T`` per integration cell.
    """

    problem: Any
    model: Any
    T: np.ndarray
    gradient: np.ndarray
    flux: np.ndarray

    @classmethod
    def from_temperature(cls, problem: Any, T: np.ndarray) -> HeatSolution:
        """The solution of ``problem`` with nodal temperatures ``T (n,)``."""
        basis = problem.basis()
        gradient = basis.interpolate(T).grad.T.copy()
        k = problem.conductivity[problem.model.cells.region]
        return cls(problem=problem, model=problem.model, T=T, gradient=gradient,
                   flux=-k[:, None] * gradient)

    def __repr__(self):
        return (f"<HeatSolution {len(self.T)} nodes, T in [{self.T.min():.4g}, "
                f"{self.T.max():.4g}], max |flux| {np.linalg.norm(self.flux, axis=1).max():.4g}>")

    def temperature(self, points: np.ndarray) -> np.ndarray:
        """Temperatures ``(p,)`` at points ``(p, 2)`` of the body, through the shape
        functions."""
        pts = check_points("points", points, dims=(2,), error=GeometryError)
        return self.model.shape_functions(pts) @ self.T

    @cached_property
    def nodal_flux(self) -> NodalValues:
        """The cell fluxes recovered at the nodes (one row per node and region; see
        `cnem.assembly.recovery`)."""
        return recover_at_nodes(self.model, self.model.cells, self.flux)

    def flux_at(self, points: np.ndarray) -> np.ndarray:
        """Heat flux ``(p, 2)`` at points of the body (on the boundary too), recovered
        from the cell fluxes as `cnem.ElasticSolution.stress_at` recovers stresses."""
        return values_at(self.model, self.nodal_flux, points)

    def h1_error(self, exact_gradient: Callable[[np.ndarray], np.ndarray], *,
                 order: int = 4) -> float:
        """``sqrt(sum_k int_cell |grad~ T_h - grad T|^2)`` against the exact gradient
        ``(q, 2) -> (q, 2)`` (`cnem.assembly.h1_error`)."""
        return h1_error(self.problem.basis(), self.T, exact_gradient, order=order)

    def write(self, path: str | os.PathLike) -> str | os.PathLike:
        """Nodes and cells with ``T`` at the nodes and ``flux`` and ``region`` on the
        cells, to a ``.vtu`` file (`cnem.io.write`)."""
        from .. import io
        io.write(self.model, path, point_data={"T": self.T}, cell_data={"flux": self.flux})
        return path

    def plot(self, path: str | os.PathLike | None = None, **kwargs: Any) -> pyvista.Plotter:
        """Off-screen picture of the temperature (`cnem.plot.scalar_field`; keywords
        ``title``, ``cmap``, ``bounds``, ``window_size``, ``length_unit`` go there)."""
        from .. import plot
        kwargs.setdefault("title", "T")
        return plot.scalar_field(self.model, self.T, path, **kwargs)
