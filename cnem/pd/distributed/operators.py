"""Bond operators of the bond- and state-based materials on one rank's points.

The same quantities as `cnem.pd.Problem` (weights, energy-method factors, moment
tensors, dilatation vectors), computed for the owned points from their complete
families; the per-point values a bond also needs at its other end (correction
coefficients, inverse moment tensors, ``alpha``) are copied to the ghosts once.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .. import _kernels as PK
from ..moments import live_inverse, moment_tensors
from ...errors import InputError
from ..correction import classical_density, fit, state_test_fields, unit_strain_targets
from . import _kernels as K

if TYPE_CHECKING:
    from typing import Literal
    from ..materials import BondBased, StateBased
    from .body import Body

__all__ = ["LocalOperators"]


def _agree(comm, ok, message):
    """Raise ``InputError(message)`` on every rank if ``ok`` is False on any."""
    if not comm.allreduce(bool(ok), op=_land()):
        raise InputError(message)


def _land():
    from .comm import mpi
    return mpi().LAND


class LocalOperators:
    """Bond data of one rank's owned points.

    Parameters
    ----------
    body : cnem.pd.distributed.Body
    material : cnem.pd.BondBased or cnem.pd.StateBased
    plane : {"stress", "strain"}
    surface_correction : bool

    Attributes
    ----------
    weight, factor : (b,) ndarray
        ``beta V_j`` and the energy-method factors, as `cnem.pd.Problem`.
    stiffness : (b,) ndarray
        Bond-based: the PMB bond stiffness ``c factor beta`` passed to the force kernel.
    g, g_reverse : (b, d) ndarray
        State-based: ``M_i^-1 xi_b w_b`` and the same for the reverse bond (``M_j``,
        ``-xi_b``, ``beta V_i``).
    c, c_reverse : (b,) ndarray
        State-based: deviatoric bond moduli ``alpha f w V`` of the bond and its reverse.
    bulk_volume : (o,) ndarray
        State-based: ``k V_i``.
    """

    def __init__(self, body: Body, material: BondBased | StateBased,
                 plane: Literal['stress', 'strain'], surface_correction: bool | None):
        self.body, self.material, self.plane, self.dim = body, material, plane, body.dim
        b = body
        o = b.n_owned
        self.weight = b.beta * b.volumes[b.bond_j]
        if material.kind == "bond":
            self.bond_stiffness = float(material.micromodulus(self.dim, plane, b.horizon,
                                                              b.thickness))
            self.factor = self._pmb_correction() if surface_correction else \
                np.ones(len(b.bond_j))
            self.stiffness = np.ascontiguousarray(self.bond_stiffness * self.factor * b.beta)
            return
        d = self.dim
        #: unit bond directions (state-based only)
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

    # -- the energy method, as in cnem.pd.Problem, with the ghosts' coefficients copied
    def _coefficients(self, Q, target):
        """Per-point fits of the owned rows, copied to the ghosts: ``(o + g, k)``."""
        b = self.body
        coef = np.zeros((len(b.points), Q.shape[-1]))
        coef[:b.n_owned] = fit(Q[:b.n_owned], target)
        return b.halo.exchange(coef)

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

    # -- state-based fields ------------------------------------------------------------
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

    # -- Gershgorin bounds of the stiffness rows -----------------------------------------
    def row_bound(self) -> np.ndarray:
        """``sum_j |K_ij|`` of every owned dof, ``(o, d)``: exact for the PMB, an upper
        bound (the triangle inequality through the bond operators) for the state-based
        solid (all bonds alive)."""
        b, d, o = self.body, self.dim, self.body.n_owned
        n = b.xi / b.length[:, None]
        if self.material.kind == "bond":
            w = self.bond_stiffness * self.factor * self.weight * b.volumes[b.bond_i] / b.length
            # both directions of a bond carry 0.5 w; |n_a n_c| summed over c, once off
            # the diagonal block and once in it (the diagonal block sums every bond)
            off = np.abs(n) * np.abs(n).sum(axis=1)[:, None] * w[:, None]
            diag = np.zeros((o, d, d))
            np.add.at(diag, b.bond_i, w[:, None, None] * n[:, :, None] * n[:, None, :])
            return np.abs(diag).sum(axis=2) + _rows(b.bond_i, off, o)
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

