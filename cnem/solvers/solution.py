"""`Solution`: what the solution of every problem offers (C-NEM, P1 anchor, peridynamics).

Every solver returns a dataclass derived from `Solution`, with the same names
for the same meanings:

=====================  ===================================================================
``u``                  ``(n, d)`` displacements of the nodes (points)
``stress``             Voigt ``(k, 3)`` ``[sxx, syy, sxy]`` in 2-D, ``(k, 6)``
                       ``[sxx, syy, szz, syz, sxz, sxy]`` in 3-D, at the solution's
                       ``k`` integration places: the SCNI cells (C-NEM, ``k = m``),
                       the triangles (P1) or the points (PD, ``k = n``)
``strain``             the same places and order, engineering shears (``2 exy``)
``stress_places``      ``"cells"``, ``"triangles"`` or ``"points"``: where they live
``stress_at(p)``       ``(p, s)`` stress at any points of the body (C-NEM: a patch recovery)
``von_mises``          ``(k,)``
``displacement(p)``    ``(p, d)`` at any points of the body
``write(path)``        ``.vtu`` with ``u``, ``stress``, ``strain``, ``von_mises``
``plot(path=None)``    off-screen picture of the deformed body (`cnem.plot.solution`)
=====================  ===================================================================
"""

from __future__ import annotations

import inspect
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from ..errors import InputError, UnsupportedError, check_array

__all__ = ["Solution", "von_mises", "engineering_strain", "voigt", "energy_error_density"]

#: The tensor entries of the Voigt order, by dimension.
VOIGT = {2: ((0, 0), (1, 1), (0, 1)),
         3: ((0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1))}


def voigt(tensor: np.ndarray) -> np.ndarray:
    """Voigt form of symmetric tensors ``(..., d, d)``: ``(..., 3)`` ``[xx, yy, xy]`` in
    2-D, ``(..., 6)`` ``[xx, yy, zz, yz, xz, xy]`` in 3-D."""
    return np.stack([tensor[..., i, j] for i, j in VOIGT[tensor.shape[-1]]], axis=-1)


def engineering_strain(gradient: np.ndarray) -> np.ndarray:
    """Engineering strain ``[exx, eyy, 2 exy]`` (3-D: ``[exx, eyy, ezz, 2 eyz, 2 exz,
    2 exy]``) from displacement gradients ``(..., d, d)``, ``[..., i, j] = du_i/dx_j``."""
    g = gradient
    return np.stack([g[..., i, j] if i == j else g[..., i, j] + g[..., j, i]
                     for i, j in VOIGT[g.shape[-1]]], axis=-1)


def von_mises(stress: np.ndarray) -> np.ndarray:
    """Von Mises stress of Voigt stresses: plane ``(..., 3)`` ``[sxx, syy, sxy]`` (the
    in-plane components), or ``(..., 6)`` in 3-D. Returns ``(...)``; NaN entries give NaN."""
    stress = check_array("stress", stress, finite=False, fix="pass Voigt stresses, (..., 3) in "
                         "2-D or (..., 6) in 3-D")
    if stress.ndim == 0 or stress.shape[-1] not in (3, 6):
        raise InputError(f"stress: expected Voigt stresses of shape (..., 3) or (..., 6), "
                         f"received shape {stress.shape}")
    if stress.shape[-1] == 6:
        sxx, syy, szz, syz, sxz, sxy = np.moveaxis(stress, -1, 0)
        return np.sqrt(0.5 * ((sxx - syy) ** 2 + (syy - szz) ** 2 + (szz - sxx) ** 2)
                       + 3.0 * (syz ** 2 + sxz ** 2 + sxy ** 2))
    sxx, syy, sxy = stress[..., 0], stress[..., 1], stress[..., 2]
    return np.sqrt(sxx ** 2 - sxx * syy + syy ** 2 + 3.0 * sxy ** 2)


def energy_error_density(points: np.ndarray, region: np.ndarray, stress: np.ndarray, C: np.ndarray,
                         exact_stress: Callable[..., np.ndarray]) -> np.ndarray:
    """``(σh - σ)ᵀ C⁻¹ (σh - σ)`` at quadrature points.

    Parameters
    ----------
    points : (q, d) ndarray
    region : (q,) int ndarray
        Region of the cell (or element) holding each point.
    stress : (q, s) ndarray
        The approximate stress ``σh`` at the points, Voigt (``s`` = 3 in 2-D, 6 in 3-D).
    C : (q, s, s) ndarray
        The elastic matrix at the points.
    exact_stress : callable ``(q, d) -> (q, s)`` or ``(q, d), (q,) -> (q, s)``

    Returns
    -------
    (q,) ndarray
    """
    if _takes_region(exact_stress):
        exact = exact_stress(points, region)
    else:
        exact = exact_stress(points)
    exact = np.asarray(exact, dtype=float)
    size = np.shape(stress)[-1]
    if exact.shape != (len(points), size):
        names = "[sxx, syy, sxy]" if size == 3 else "[sxx, syy, szz, syz, sxz, sxy]"
        raise InputError(f"exact_stress must return ({len(points)}, {size}) values "
                         f"{names}, received shape {exact.shape}; return one row per point")
    bad = ~np.isfinite(exact).all(axis=1)
    if bad.any():
        raise InputError(f"exact_stress must return finite values, received NaN or inf at "
                         f"{int(bad.sum())} of {len(points)} points, the first at "
                         f"{points[bad][0].tolist()}; check the exact solution there")
    diff = stress - exact
    return np.einsum("qi,qij,qj->q", diff, np.linalg.inv(C), diff)


def _takes_region(func):
    """Whether ``func`` accepts two positional arguments ``(x, region)``."""
    try:
        inspect.signature(func).bind(None, None)
    except (TypeError, ValueError):                  # one argument, or no signature
        return False
    return True


@dataclass(eq=False, repr=False)
class Solution:
    """Base of every solution (see the module docstring for the shared names).

    A subclass declares ``stress`` and ``strain`` (fields, or properties where they
    are computed on demand), sets ``stress_places``, and implements `displacement`,
    `nodal_average` (its per-place values at the nodes, for pictures),
    `plot_mesh` and `write_fields`.

    Attributes
    ----------
    problem : object
        The problem solved.
    u : (n, d) ndarray
        Displacements of the nodes (points).
    """

    problem: Any
    u: np.ndarray

    #: Where ``stress`` and ``strain`` live: "cells", "triangles" or "points".
    stress_places = "points"

    def __repr__(self):
        return (f"<{type(self).__name__} {len(self.u)} nodes, {len(self.stress)} "
                f"{self.stress_places}, max |u| {np.abs(self.u).max():.3e}, "
                f"max von Mises {self.von_mises.max():.3e}>")

    @property
    def von_mises(self) -> np.ndarray:
        """``(k,)`` von Mises stress at the places of ``stress``."""
        return von_mises(self.stress)

    def displacement(self, points: np.ndarray) -> np.ndarray:
        """Displacements at points of the body, through the solver's interpolation.

        Parameters
        ----------
        points : (p, d) array_like

        Returns
        -------
        (p, d) ndarray
        """
        raise NotImplementedError

    def stress_at(self, points: np.ndarray) -> np.ndarray:
        """Voigt stress ``(p, s)`` at points ``(p, d)`` of the body (see the C-NEM
        solutions' `cnem.elasticity.solution.CellSolution.stress_at`).

        Raises
        ------
        UnsupportedError
            For a solution that has no pointwise stress (here: any but C-NEM's).
        """
        raise UnsupportedError(f"{type(self).__name__} has no stress_at(points): its stress "
                               f"lives at its {self.stress_places} (sol.stress); use those "
                               f"values, or solve the problem with cnem.Elasticity")

    def nodal_average(self, values: np.ndarray) -> np.ndarray:
        """Values ``(k, ...)`` at the places of ``stress`` as ``(n, ...)`` at the nodes."""
        raise NotImplementedError

    def _place_values(self, values: np.ndarray) -> np.ndarray:
        """``values`` ``(k, ...)``, one row per place of ``stress``, as float64: refused
        with an `InputError` when complex, boolean, not numbers or of another row count
        (NaN entries stay: they average to NaN)."""
        count = len(self.u) if self.stress_places == "points" else len(self.stress)
        arr = check_array("values", values, finite=False,
                          fix=f"pass one value (or row) per {self.stress_places[:-1]}")
        if arr.ndim == 0 or len(arr) != count:
            raise InputError(f"values: expected one row per {self.stress_places[:-1]} ({count} "
                             f"rows), received shape {arr.shape}")
        return arr

    def plot_mesh(self) -> None:
        """What a picture draws: ``nodes (n, d)``, ``triangles (t, 3)`` (or None: the
        points alone) and the body's diameter."""
        raise NotImplementedError

    def fields(self) -> tuple[dict, dict]:
        """Fields for files and pictures.

        Returns
        -------
        point_data : dict of str -> (n, ...) ndarray
        cell_data : dict of str -> (k, ...) ndarray
            Values at the places of ``stress`` (merged into ``point_data`` when they
            are the points).
        """
        point_data = {"u": self.u}
        cell_data = {"stress": self.stress, "strain": self.strain, "von_mises": self.von_mises}
        if self.stress_places == "points":
            return {**point_data, **cell_data}, {}
        return point_data, cell_data

    def write_fields(self, path: str, point_data: dict[str, np.ndarray],
                     cell_data: dict[str, np.ndarray]) -> None:
        """Write `fields` to ``path`` (see `write`)."""
        raise NotImplementedError

    def write(self, path: str) -> str:
        """Write the nodes (points), their ``u`` and the ``stress``, ``strain`` and
        ``von_mises`` fields to a ``.vtu`` file (see `cnem.io`).

        Returns
        -------
        path
        """
        self.write_fields(path, *self.fields())
        return path

    def plot(self, path: str | None = None, *, field: str = "von_mises", scale: float | None = None,
             **kwargs: Any) -> Any:
        """Off-screen picture of the deformed body coloured by a field (see
        `cnem.plot.solution`)."""
        from .. import plot
        return plot.solution(self, path, field=field, scale=scale, **kwargs)
