"""Bond operators of the bond- and state-based materials on one rank's points: the
distributed behaviours (``material.local_operators``).

The same quantities as `cnem.pd.Problem` (weights, energy-method factors, moment
tensors, dilatation vectors), computed for the owned points from their complete
families; the per-point values a bond also needs at its other end (correction
coefficients, inverse moment tensors, ``alpha``) are copied to the ghosts once.
`BondOperators` (PMB) and `StateOperators` (LPS) give what the distributed problem asks
of a material: the forces with bond breaking, the elastic energy, the stable time step
and the bounds of the stiffness rows.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .. import _kernels as PK
from ..moments import live_inverse, moment_tensors
from ...errors import InputError
from ..correction import classical_density, fit, state_test_fields, unit_strain_targets
from .._pmb_kernels import pmb_forces_rows
from . import _kernels as K

if TYPE_CHECKING:
    from typing import Any, Literal

    from .body import Body

__all__ = ["LocalOperators", "BondOperators", "StateOperators", "ENERGY_BLOCK"]

#: Points per block of the energy sums (their bonds' temporaries stay small).
ENERGY_BLOCK = 65536


def _agree(comm, ok, message):
    """Raise ``InputError(message)`` on every rank if ``ok`` is False on any."""
    if not comm.allreduce(bool(ok), op=_land()):
        raise InputError(message)


def _land():
    from .comm import mpi
    return mpi().LAND


class LocalOperators:
    """Bond data of one rank's owned points, what both models share.

    Parameters
    ----------
    body : cnem.pd.distributed.Body
    material : cnem.pd.BondBased or cnem.pd.StateBased
    plane : {"stress", "strain"}

    Attributes
    ----------
    weight : (b,) ndarray
        ``beta V_j``, as `cnem.pd.Problem`.
    grows_when_breaking : bool
        Whether the stiffness rows (`row_bound`) can grow when bonds break.
    round_off_stiffness : (b,) ndarray or None
        The bond stiffnesses whose round-off bounds the force balance
        (`cnem.pd.relaxation.force_round_off`), None where the force at rest says it.
    """

    grows_when_breaking = False
    round_off_stiffness = None

    def __init__(self, body: Body, material: Any,
                 plane: Literal['stress', 'strain']):
        self.body, self.material, self.plane, self.dim = body, material, plane, body.dim
        self.weight = body.beta * body.volumes[body.bond_j]

    def follow_breaking(self, alive: np.ndarray) -> None:
        """After bonds broke (collective): nothing to update here."""

    # -- the energy method, as in cnem.pd.Problem, with the ghosts' coefficients copied
    def _coefficients(self, Q, target):
        """Per-point fits of the owned rows, copied to the ghosts: ``(o + g, k)``."""
        b = self.body
        coef = np.zeros((len(b.points), Q.shape[-1]))
        coef[:b.n_owned] = fit(Q[:b.n_owned], target)
        return b.halo.exchange(coef)


class BondOperators(LocalOperators):
    """The PMB bonds of one rank's owned points.

    Parameters
    ----------
    body, material, plane
        As `LocalOperators`.
    surface_correction : bool

    Attributes
    ----------
    bond_stiffness : float
        The micromodulus.
    factor : (b,) ndarray
        The energy-method factors, as `cnem.pd.Problem`.
    stiffness : (b,) ndarray
        The PMB bond stiffness ``c factor beta`` passed to the force kernel.
    """

    def __init__(self, body: Body, material: Any, plane: Literal['stress', 'strain'],
                 surface_correction: bool):
        super().__init__(body, material, plane)
        b = body
        self.bond_stiffness = float(material.micromodulus(self.dim, plane, b.horizon,
                                                          b.thickness))
        self.factor = self._pmb_correction() if surface_correction else \
            np.ones(len(b.bond_j))
        self.stiffness = np.ascontiguousarray(self.bond_stiffness * self.factor * b.beta)
        self.round_off_stiffness = self.stiffness

    def _pmb_correction(self):
        b, d = self.body, self.dim
        pairs, target = unit_strain_targets(d, *self.material.moduli(d, self.plane))
        Q = np.zeros((len(b.points), len(pairs), len(pairs)))
        PK.pmb_correction_moments(b.xi, b.length, self.weight, b.offsets, pairs, Q)
        Q *= 0.25 * self.bond_stiffness
        coef = self._coefficients(Q, target)
        factor = np.empty(len(b.bond_j))
        PK.pmb_bond_factors(b.xi, b.length, b.offsets, b.bond_j, pairs, coef, factor)
        return factor

    def forces(self, u: np.ndarray, limit: float, alive: np.ndarray,
               alive_reverse: np.ndarray) -> tuple[np.ndarray, int]:
        """Force per unit volume of the owned points ``(o, d)`` and the owned bonds broken
        (beyond ``limit``): the halo exchange of ``u (o + g, d)`` runs while the bonds of
        the interior points (`Body.interior`, no ghost in their families) are computed,
        and the boundary points follow it."""
        b = self.body
        pending = b.halo.start(u)
        out = np.empty((b.n_owned, self.dim))
        args = (u, b.points, b.image, b.length, b.offsets, b.bond_j, self.stiffness,
                b.volumes, alive, limit, out)
        broken = pmb_forces_rows(b.interior, *args)
        b.halo.finish(pending)
        broken += pmb_forces_rows(b.boundary, *args)
        return out, int(broken)

    def elastic_energy(self, u: np.ndarray, alive: np.ndarray) -> float:
        """The exact PMB energy of the owned points' deformed bonds (this rank)."""
        b, o = self.body, self.body.n_owned
        elastic = 0.0
        for start in range(0, o, ENERGY_BLOCK):      # blocks of points: small temporaries
            stop = min(start + ENERGY_BLOCK, o)
            sl = slice(b.offsets[start], b.offsets[stop])
            i, j = b.bond_i[sl], b.bond_j[sl]
            y = b.xi[sl] + u[j] - u[i]
            s = np.sqrt((y * y).sum(axis=1)) / b.length[sl] - 1
            per = 0.25 * self.bond_stiffness * self.factor[sl] * b.beta[sl] * s * s * \
                b.length[sl] * b.volumes[j] * alive[sl]
            elastic += float(b.volumes[start:stop] @ np.bincount(
                i - start, weights=per, minlength=stop - start))
        return elastic

    def stable_diagonal(self) -> np.ndarray:
        """``(o,)`` ``sum_j c_ij V_j / L_ij`` per owned point (the stable time step)."""
        b = self.body
        per = self.bond_stiffness * self.factor * b.beta * b.volumes[b.bond_j] / b.length
        return np.bincount(b.bond_i, weights=per, minlength=b.n_owned)

    def row_bound(self) -> np.ndarray:
        """``sum_j |K_ij|`` of every owned dof, ``(o, d)``, exact."""
        b, d, o = self.body, self.dim, self.body.n_owned
        n = b.xi / b.length[:, None]
        w = self.bond_stiffness * self.factor * self.weight * b.volumes[b.bond_i] / b.length
        # both directions of a bond carry 0.5 w; |n_a n_c| summed over c, once off
        # the diagonal block and once in it (the diagonal block sums every bond)
        off = np.abs(n) * np.abs(n).sum(axis=1)[:, None] * w[:, None]
        diag = np.zeros((o, d, d))
        np.add.at(diag, b.bond_i, w[:, None, None] * n[:, :, None] * n[:, None, :])
        return np.abs(diag).sum(axis=2) + _rows(b.bond_i, off, o)


class StateOperators(LocalOperators):
    """The linear peridynamic solid on one rank's owned points.

    Parameters
    ----------
    body, material, plane
        As `LocalOperators`.
    surface_correction : bool

    Attributes
    ----------
    factor : (b,) ndarray
        The energy-method factors, as `cnem.pd.Problem`.
    g, g_reverse : (b, d) ndarray
        ``M_i^-1 xi_b w_b`` and the same for the reverse bond (``M_j``, ``-xi_b``,
        ``beta V_i``).
    c, c_reverse : (b,) ndarray
        Deviatoric bond moduli ``alpha f w V`` of the bond and its reverse.
    bulk_volume : (o,) ndarray
        ``k V_i``.
    """

    grows_when_breaking = True

    def __init__(self, body: Body, material: Any, plane: Literal['stress', 'strain'],
                 surface_correction: bool):
        super().__init__(body, material, plane)
        b = body
        o = b.n_owned
        d = self.dim
        #: unit bond directions
        self.unit = b.xi / b.length[:, None]
        #: the owned points' moment tensors of the reference family, ``(o, d, d)``
        self.moments = moment_tensors(b.bond_i, b.xi, self.weight, o)
        _agree(b.comm, (np.linalg.det(self.moments) > 0).all(),
               "a point has too few bonds to span every direction: enlarge the horizon")
        Minv = np.zeros((len(b.points), d, d))
        Minv[:o] = np.linalg.inv(self.moments)
        self._set_gradient_weights(b.halo.exchange(Minv))
        m = np.bincount(b.bond_i, weights=self.weight * b.length ** 2, minlength=o)
        self.bulk, self.shear = material.moduli(d, plane)
        self.alpha = np.zeros(len(b.points))
        self.alpha[:o] = self.shear * d * (d + 2) / m
        b.halo.exchange(self.alpha)
        self.factor = self._state_correction() if surface_correction else \
            np.ones(len(b.bond_j))
        Vi, Vj = b.volumes[b.bond_i], b.volumes[b.bond_j]
        self.c = np.ascontiguousarray(self.alpha[b.bond_i] * self.factor * self.weight * Vi)
        self.c_reverse = np.ascontiguousarray(self.alpha[b.bond_j] * self.factor *
                                              (b.beta * Vi) * Vj)
        self.bulk_volume = self.bulk * b.volumes[:o]

    def _set_gradient_weights(self, Minv):
        """``g`` and ``g_reverse`` from the inverse moment tensors of owned and ghost points."""
        b = self.body
        self.g = np.einsum("bij,bj->bi", Minv[b.bond_i], b.xi) * self.weight[:, None]
        self.g_reverse = np.einsum("bij,bj->bi", Minv[b.bond_j], -b.xi) * \
            (b.beta * b.volumes[b.bond_i])[:, None]

    def follow_breaking(self, alive: np.ndarray) -> None:
        """After bonds broke (on any rank; collective): the owned points that lost bonds take
        the moment tensors of their live bonds (`cnem.pd.moments.live_inverse`, as the
        serial `cnem.pd.Problem.live_gradient_weights`), copied to the ghosts; ``g`` and
        ``g_reverse`` follow.

        Parameters
        ----------
        alive : (b,) uint8 ndarray
            The owned bonds alive.
        """
        b, o = self.body, self.body.n_owned
        w = self.weight * alive
        hit = np.zeros(o, dtype=bool)
        hit[b.bond_i[alive == 0]] = True
        rows = np.flatnonzero(hit)
        Minv = np.zeros((len(b.points), self.dim, self.dim))
        Minv[:o] = np.linalg.inv(self.moments)
        Minv[rows] = live_inverse(moment_tensors(b.bond_i, b.xi, w, o)[rows], self.moments[rows])
        self._set_gradient_weights(b.halo.exchange(Minv))

    def _state_correction(self):
        b, d = self.body, self.dim
        tests, basis = state_test_fields(self.unit, d)
        rows = []
        for eps in tests:
            u = b.points @ eps.T
            theta = self.dilatation(u)
            ed = self.deviatoric(u, theta)
            w = 0.5 * self.alpha[b.bond_i] * self.weight * ed * ed
            rows.append([np.bincount(b.bond_i, weights=w * P, minlength=b.n_owned)
                         for P in basis])
        Q = np.array(rows).transpose(2, 0, 1)
        target = np.array([classical_density(eps, self.bulk, self.shear) -
                           0.5 * self.bulk * np.trace(eps) ** 2 for eps in tests])
        coef = self._coefficients(Q, target)
        G = np.array(basis)
        gi = (coef[b.bond_i].T * G).sum(axis=0)
        gj = (coef[b.bond_j].T * G).sum(axis=0)
        return 0.5 * (gi + gj)

    def dilatation(self, u: np.ndarray, alive: np.ndarray | None = None) -> np.ndarray:
        """``theta`` of the owned points ``(o,)`` from local displacements ``(o + g, d)``,
        over the live bonds (``alive (b,)`` uint8 of the owned bonds; default all)."""
        b = self.body
        if alive is None:
            alive = np.ones(len(b.bond_j), dtype=np.uint8)
        theta = np.empty(b.n_owned)
        K.dilatation(np.ascontiguousarray(u), b.offsets[:b.n_owned + 1], b.bond_j, self.g,
                     alive, theta)
        return theta

    def deviatoric(self, u: np.ndarray, theta: np.ndarray) -> np.ndarray:
        """``e^d_b`` of the owned bonds (``theta`` of the owned points)."""
        b = self.body
        e = (self.unit * (u[b.bond_j] - u[b.bond_i])).sum(axis=1)
        return e - b.length / self.dim * theta[b.bond_i]

    def forces(self, u: np.ndarray, limit: float, alive: np.ndarray,
               alive_reverse: np.ndarray) -> tuple[np.ndarray, int]:
        """Force per unit volume of the owned points ``(o, d)`` and the owned bonds broken
        (beyond ``limit``): the exchange of ``u (o + g, d)`` first, then the dilatations,
        one more exchange (of them and the pressures) and the forces."""
        b = self.body
        o = b.n_owned
        b.halo.finish(b.halo.start(u))
        broken = K.break_bonds(u, b.xi, b.length, b.offsets[:o + 1], b.bond_j, limit,
                               alive, alive_reverse)
        if b.comm.allreduce(int(broken)):
            self.follow_breaking(alive)
        fields = np.zeros((len(b.points), 2))          # theta and P, copied to the ghosts
        fields[:o, 0] = self.dilatation(u, alive)
        theta = np.ascontiguousarray(fields[:o, 0])
        P = np.empty(o)
        K.pressure(u, b.xi, b.length, b.offsets[:o + 1], b.bond_j, theta, self.bulk_volume,
                   self.c, alive, P)
        fields[:o, 1] = P
        b.halo.exchange(fields)
        out = np.empty((o, self.dim))
        K.lps_forces(u, b.xi, b.length, b.offsets[:o + 1], b.bond_j, b.volumes, self.g,
                     self.g_reverse, np.ascontiguousarray(fields[:, 0]),
                     np.ascontiguousarray(fields[:, 1]), self.c, self.c_reverse, alive,
                     alive_reverse, out)
        return out, int(broken)

    def elastic_energy(self, u: np.ndarray, alive: np.ndarray) -> float:
        """The (linearised) elastic energy of the owned points (this rank)."""
        theta = self.dilatation(u, alive)
        ed = self.deviatoric(u, theta)
        return 0.5 * float(self.bulk_volume @ (theta * theta)) + \
            0.5 * float((self.c * alive) @ (ed * ed))

    def stable_diagonal(self) -> np.ndarray:
        """``(o d,)`` the upper bounds of the stiffness rows per unit volume (`row_bound`),
        so the stable time step is at most the serial one."""
        b = self.body
        return (self.row_bound() / b.volumes[:b.n_owned, None]).reshape(-1)

    def row_bound(self) -> np.ndarray:
        """``sum_j |K_ij|`` of every owned dof, ``(o, d)``: an upper bound (the triangle
        inequality through the bond operators; all bonds alive)."""
        b, d, o = self.body, self.dim, self.body.n_owned
        n = b.xi / b.length[:, None]
        ghost = len(b.points)
        gsum = _rows(b.bond_i, self.g, o)                       # -T_i at i's own dofs
        t = np.zeros(ghost)                                     # |T_p|_1
        t[:o] = np.bincount(b.bond_i, weights=np.abs(self.g).sum(axis=1), minlength=o) + \
            np.abs(gsum).sum(axis=1)
        b.halo.exchange(t)
        D = np.zeros(ghost)
        D[:o] = self.bulk_volume
        b.halo.exchange(D)
        L = b.length
        e1 = 2.0 * np.abs(n).sum(axis=1) + L / d * t[b.bond_i]             # |E_b|_1
        R = np.zeros(ghost)
        R[:o] = np.bincount(b.bond_i, weights=self.c * e1 * L / d, minlength=o)
        b.halo.exchange(R)
        e1_reverse = 2.0 * np.abs(n).sum(axis=1) + L / d * t[b.bond_j]
        out = D[:o, None] * np.abs(gsum) * t[:o, None]
        out += _rows(b.bond_i, (D * t + R)[b.bond_j][:, None] * np.abs(self.g_reverse), o)
        out += _rows(b.bond_i, (self.c * e1)[:, None] * (np.abs(n) + (L / d)[:, None] *
                                                         np.abs(gsum)[b.bond_i]), o)
        out += _rows(b.bond_i, (self.c_reverse * e1_reverse)[:, None] * np.abs(n), o)
        return out


def _rows(rows, values, n):
    """``out[i] = sum of values[b] over rows[b] == i``, ``(n, k)``."""
    return np.stack([np.bincount(rows, weights=values[:, k], minlength=n)
                     for k in range(values.shape[1])], axis=1)

