"""Peridynamic materials: bond-based (PMB) and ordinary state-based (LPS)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..errors import MaterialError
from .behaviour import BondBehaviour, StateBehaviour
from . import critical_stretch as from_energy

if TYPE_CHECKING:
    from typing import Any, Literal

    from .distributed.operators import BondOperators, StateOperators

__all__ = ["BondBased", "StateBased"]


def isotropic_moduli(E: float, nu: float, dim: int,
                     plane: Literal['stress', 'strain']) -> tuple[float, float]:
    """Bulk modulus of the d-dimensional isotropic law (plane stress or strain in 2-D) and
    the shear modulus, from ``E`` and ``nu``."""
    mu = E / (2.0 * (1.0 + nu))
    lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
    if dim == 3:
        return lam + 2.0 * mu / 3.0, mu
    if plane == "stress":
        lam = 2.0 * lam * mu / (lam + 2.0 * mu)
    return lam + mu, mu


def _positive(name, value):
    value = float(value)
    if not np.isfinite(value) or value <= 0:
        raise MaterialError(f"{name}: expected a positive number, received {value}")
    return value


class BondBased:
    """Prototype microelastic brittle (PMB) material.

    The micromodulus follows from E and the horizon: ``c = 9 E / (pi t delta^3)``
    in plane stress (Poisson ratio 1/3), ``48 E / (5 pi t delta^3)`` in plane strain
    and ``12 E / (pi delta^4)`` in 3-D (Poisson ratio 1/4).

    Parameters
    ----------
    E : float
        Young's modulus.
    critical_stretch : float, optional
        Bonds break beyond it (dynamics); ``None``: unbreakable.
    fracture_energy : float, optional
        ``G0``, giving the critical stretch when ``critical_stretch`` is not given
        (`cnem.pd.critical_stretch.bond_based`): ``sqrt(4 pi G0 / (9 E delta))`` in
        plane stress, ``sqrt(5 pi G0 / (12 E delta))`` in plane strain and
        ``sqrt(5 G0 / (9 K delta))`` in 3-D (K the bulk modulus).
    density : float
        Mass density (dynamics).
    """

    #: A label of the model (the problem asks the `behaviour`, not the label).
    kind = "bond"
    #: The energy-method surface correction applies (`cnem.pd.Problem`'s default).
    correctable = True

    def __init__(self, E: float, *, critical_stretch: float | None = None,
                 fracture_energy: float | None = None, density: float = 1.0):
        self.E = _positive("E", E)
        self.critical_stretch = None if critical_stretch is None else _positive(
            "critical_stretch", critical_stretch)
        self.fracture_energy = None if fracture_energy is None else _positive(
            "fracture_energy", fracture_energy)
        self.density = _positive("density", density)

    def behaviour(self, problem: Any) -> BondBehaviour:
        """The PMB bonds of ``problem`` (a `cnem.pd.Problem`;
        `cnem.pd.behaviour.BondBehaviour`)."""
        return BondBehaviour(problem)

    def local_operators(self, body: Any, plane: Literal['stress', 'strain'],
                        surface_correction: bool) -> BondOperators:
        """The PMB bonds of one MPI rank's points (``body`` a `cnem.pd.distributed.Body`):
        a `cnem.pd.distributed.operators.BondOperators`."""
        from .distributed.operators import BondOperators      # (the package imports us)
        return BondOperators(body, self, plane, surface_correction)

    def poisson(self, dim: int, plane: Literal['stress', 'strain']) -> float:
        return 1.0 / 3.0 if (dim == 2 and plane == "stress") else 0.25

    def moduli(self, dim: int, plane: Literal['stress', 'strain']) -> tuple:
        """Bulk and shear modulus of the classical law the PMB matches (Poisson ratio
        `poisson`), as `StateBased.moduli`."""
        return isotropic_moduli(self.E, self.poisson(dim, plane), dim, plane)

    def micromodulus(self, dim: int, plane: Literal['stress', 'strain'], horizon: float,
                     thickness: float) -> float:
        if dim == 3:
            return 12.0 * self.E / (np.pi * horizon ** 4)
        if plane == "stress":
            return 9.0 * self.E / (np.pi * thickness * horizon ** 3)
        return 48.0 * self.E / (5.0 * np.pi * thickness * horizon ** 3)

    def stretch_limit(self, dim: int, plane: Literal['stress', 'strain'], horizon: float) -> float:
        """The critical stretch (given, or from the fracture energy; inf if neither)."""
        if self.critical_stretch is not None:
            return self.critical_stretch
        if self.fracture_energy is None:
            return np.inf
        return from_energy.bond_based(self.fracture_energy, self.E, horizon, plane, dim)

    def __repr__(self):
        return f"<BondBased E={self.E:g}, critical stretch {self.critical_stretch}>"


class StateBased:
    """Ordinary state-based linear peridynamic solid (LPS), any Poisson ratio.

    ``W = k theta^2 / 2 + (alpha / 2) sum_j omega (e^d_j)^2 V_j`` with the 2-D
    (plane stress / strain) or 3-D bulk modulus ``k`` and
    ``alpha = mu d (d + 2) / m``; the dilatation ``theta`` is computed from the
    displacements of the family with the point's moment tensor, so that it
    is exact for uniform strains even where the horizon is cut by a boundary.

    Parameters
    ----------
    E, nu : float
    critical_stretch : float, optional
        Bonds break beyond it (dynamics, relaxation).
    fracture_energy : float, optional
        ``G_c``, giving the critical stretch when ``critical_stretch`` is not given
        (2-D, `cnem.pd.critical_stretch.state_based`).
    density : float
    """

    #: A label of the model (the problem asks the `behaviour`, not the label).
    kind = "state"
    #: The energy-method surface correction applies (`cnem.pd.Problem`'s default).
    correctable = True

    def __init__(self, E: float, nu: float, *, critical_stretch: float | None = None,
                 fracture_energy: float | None = None, density: float = 1.0):
        self.E = _positive("E", E)
        nu = float(nu)
        if not -1.0 < nu < 0.5:
            raise MaterialError(f"nu: expected a Poisson ratio in (-1, 0.5), received {nu}")
        self.nu = nu
        self.critical_stretch = None if critical_stretch is None else _positive(
            "critical_stretch", critical_stretch)
        self.fracture_energy = None if fracture_energy is None else _positive(
            "fracture_energy", fracture_energy)
        self.density = _positive("density", density)

    def behaviour(self, problem: Any) -> StateBehaviour:
        """The linear peridynamic solid on ``problem`` (a `cnem.pd.Problem`;
        `cnem.pd.behaviour.StateBehaviour`)."""
        return StateBehaviour(problem)

    def local_operators(self, body: Any, plane: Literal['stress', 'strain'],
                        surface_correction: bool) -> StateOperators:
        """The linear peridynamic solid on one MPI rank's points (``body`` a
        `cnem.pd.distributed.Body`): a `cnem.pd.distributed.operators.StateOperators`."""
        from .distributed.operators import StateOperators     # (the package imports us)
        return StateOperators(body, self, plane, surface_correction)

    def moduli(self, dim: int, plane: Literal['stress', 'strain']) -> tuple:
        """Bulk modulus of the d-dimensional law and the shear modulus."""
        return isotropic_moduli(self.E, self.nu, dim, plane)

    def stretch_limit(self, dim: int, plane: Literal['stress', 'strain'], horizon: float) -> float:
        """The critical stretch (given, or from the fracture energy; inf if neither)."""
        if self.critical_stretch is not None:
            return self.critical_stretch
        if self.fracture_energy is None:
            return np.inf
        return from_energy.state_based(self.fracture_energy, self.E, self.nu, horizon, plane,
                                            dim)

    def __repr__(self):
        return f"<StateBased E={self.E:g}, nu={self.nu:g}>"
