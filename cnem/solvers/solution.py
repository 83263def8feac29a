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
``write(path)``        ``.vtu`` for ParaView (`paraview_fields`): ``displacement``
                       ``(n, 3)``, ``stress`` and ``strain`` as ``(k, 9)`` tensors and
                       their components ``stress_xx`` ..., ``stress_nodal`` (the
                       `nodal_average` of ``stress``), ``von_mises`` (and, from
                       `cnem.io.write`, ``crack_face`` of a cracked model); ``.pvd``: the
                       `series` of states
``plot(path=None)``    off-screen picture of the deformed body (`cnem.plot.solution`)
=====================  ===================================================================
"""

from __future__ import annotations

import inspect
import os
import pathlib
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from ..errors import InputError, UnsupportedError, check_array

__all__ = ["Solution", "von_mises", "engineering_strain", "voigt", "energy_error_density"]

#: The tensor entries of the Voigt order, by dimension.
VOIGT = {2: ((0, 0), (1, 1), (0, 1)),
         3: ((0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1))}

#: Point vectors of the solutions -> their names in the files.
VECTORS = {"u": "displacement", "velocity": "velocity"}

#: Voigt fields written as tensors, and whether their shears are engineering ones (2 e_xy).
TENSORS = {"stress": False, "strain": True, "stress_nodal": False}

#: The component arrays written beside each tensor: suffix -> entry of the 3 x 3 tensor.
COMPONENTS = {"xx": (0, 0), "yy": (1, 1), "zz": (2, 2), "yz": (1, 2), "xz": (0, 2), "xy": (0, 1)}


def vector3(values: np.ndarray) -> np.ndarray:
    """Vectors ``(k, d)`` as ``(k, 3)`` float64 (``z = 0`` when ``d = 2``)."""
    values = np.asarray(values, dtype=np.float64)
    out = np.zeros((len(values), 3))
    out[:, :values.shape[1]] = values
    return out


def tensor9(voigt: np.ndarray, *, engineering: bool = False) -> np.ndarray:
    """Voigt ``(k, 3)`` ``[xx, yy, xy]`` or ``(k, 6)`` ``[xx, yy, zz, yz, xz, xy]`` as full
    symmetric tensors ``(k, 9)``, row-major; ``engineering`` halves the shears."""
    voigt = np.asarray(voigt, dtype=np.float64)
    dim = {3: 2, 6: 3}[voigt.shape[1]]
    out = np.zeros((len(voigt), 3, 3))
    for column, (i, j) in enumerate(VOIGT[dim]):
        value = voigt[:, column] * (0.5 if engineering and i != j else 1.0)
        out[:, i, j] = out[:, j, i] = value
    return out.reshape(-1, 9)


def paraview_fields(point_data: dict[str, np.ndarray],
                    cell_data: dict[str, np.ndarray]) -> tuple[dict, dict]:
    """A solution's fields (`Solution.fields`) in the form written to files.

    Parameters
    ----------
    point_data : dict of str -> (n, ...) ndarray
    cell_data : dict of str -> (k, ...) ndarray

    Returns
    -------
    point_data, cell_data : dict of str -> ndarray
        The vectors of `VECTORS` renamed and ``(n, 3)``; the Voigt fields of
        `TENSORS` ``(k, 9)`` (in 2-D the in-plane components, ``zz``, ``xz`` and
        ``yz`` 0: the out-of-plane stress of plane strain is not part of the 2-D
        solution), each followed by its components ``<name>_xx``, ``_yy``, ``_zz``,
        ``_yz``, ``_xz``, ``_xy`` ``(k,)`` (tensor shears, `COMPONENTS`); every other
        array as given.
    """
    def convert(data):
        out = {}
        for name, value in data.items():
            if name in VECTORS:
                out[VECTORS[name]] = vector3(value)
            elif name in TENSORS:
                full = tensor9(value, engineering=TENSORS[name])
                out[name] = full
                for suffix, (i, j) in COMPONENTS.items():
                    out[f"{name}_{suffix}"] = full[:, 3 * i + j]
            else:
                out[name] = value
        return out
    return convert(point_data), convert(cell_data)


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
            are the points; otherwise ``point_data`` also holds ``stress_nodal``, their
            `nodal_average`).
        """
        point_data = {"u": self.u}
        cell_data = {"stress": self.stress, "strain": self.strain, "von_mises": self.von_mises}
        if self.stress_places == "points":
            return {**point_data, **cell_data}, {}
        point_data["stress_nodal"] = self.nodal_average(self.stress)
        return point_data, cell_data

    def write_fields(self, path: str, point_data: dict[str, np.ndarray],
                     cell_data: dict[str, np.ndarray]) -> None:
        """Write `fields` to ``path`` (see `write`)."""
        raise NotImplementedError

    def write(self, path: str | os.PathLike) -> str | os.PathLike:
        """Write the solution for ParaView.

        A ``.vtu`` path gets the nodes (points) and the fields of `paraview_fields`:
        point vectors ``displacement`` ``(n, 3)`` (``z = 0`` in 2-D), the tensors
        ``stress`` and ``strain`` ``(k, 9)`` and their components ``stress_xx`` ...,
        the point tensor ``stress_nodal`` (`nodal_average` of ``stress``, when it lives
        on cells or triangles), ``von_mises`` and the solution's other scalars (see
        `cnem.io`). A ``.pvd`` path gets one ``.vtu`` per state of
        `series` beside it, ``<stem>_<i>.vtu``, and the collection with their times.

        Returns
        -------
        path
        """
        if pathlib.Path(path).suffix.lower() == ".pvd":
            from .series import write_series
            write_series(path, self.series())
            return path
        self.write_fields(path, *paraview_fields(*self.fields()))
        return path

    def series(self) -> list[tuple[float, Solution]]:
        """The states a ``.pvd`` file holds, ``(time or load factor, solution)`` in
        increasing time: here the solution alone at 1; solutions with load steps or
        frames give each of them."""
        return [(1.0, self)]

    def plot(self, path: str | None = None, *, field: str = "von_mises", scale: float | None = None,
             **kwargs: Any) -> Any:
        """Off-screen picture of the deformed body coloured by a field (see
        `cnem.plot.solution`; a solution on 3-D cells: `cnem.plot.solution3d`, the body
        clipped by a plane, ``clip="-y"`` by default)."""
        from .. import plot
        if hasattr(getattr(self, "cells", None), "facet_triangles"):
            return plot.solution3d(self, path, field=field, scale=scale, **kwargs)
        return plot.solution(self, path, field=field, scale=scale, **kwargs)
