"""`Interactions`: the one-, two- and three-neighbour interactions of a `cnem.pd.CPD`
material on a body, and the assembly of the CPD energy, internal force and tangent.

Each interaction energy depends on the displacements only through the deformed bond
vectors ``xi_s = y_{j_s} - y_a`` of its ``r`` bonds (r = 1, 2, 3) and on those through
its deformation measure ``g`` (``xi``, the area ``a`` or the volume ``v``, eq. 2-4). The
material gives ``phi, dphi/dg, d2phi/dg2`` (hyper-dual numbers by default); the exact
geometry of eq. 37 gives ``J_s = dg/dxi_s`` and the second derivatives of ``g``, so that

    dE/dxi_s = J_s^T phi_g,   d2E/dxi_s dxi_t = J_s^T phi_gg J_t + phi_g . d2g/dxi_s dxi_t

(eq. 38). A bond-level block ``G_st`` of point ``a`` lands on the nodes through the fixed
incidence of ``xi_s``: ``K[j_s, j_t] += G_st``, ``K[j_s, a] -= G_st``,
``K[a, j_t] -= G_st``, ``K[a, a] += G_st``; the last three are summed per bond first.
"""

from __future__ import annotations

import copy
from itertools import combinations

import numpy as np
import scipy.sparse as sp

from .. import config
from ..errors import InputError, LimitError, MaterialError
from ._cpd_kernels import add_rows, scatter_hessian

__all__ = ["Interactions"]


_ROT = np.array([[0.0, 1.0], [-1.0, 0.0]])     # d2a / dxi_p dxi_q of the 2-D area


# -- geometry of the measures (eq. 33, 37) -----------------------------------------------
def _skew(v):
    """``[v]x`` with ``[v]x w = v x w``, ``(m, 3) -> (m, 3, 3)``."""
    z = np.zeros(len(v))
    return np.stack([z, -v[:, 2], v[:, 1], v[:, 2], z, -v[:, 0], -v[:, 1], v[:, 0], z],
                    1).reshape(-1, 3, 3)


def _stretch(y):
    """Bond vectors as measures: ``(g, J, curvature)`` (see `_area`)."""
    m, d = y.shape
    jac = np.broadcast_to(np.eye(d), (m, 1, d, d))
    return y, jac, lambda f: np.zeros((m, 0, d, d))


def _area(yp, yq):
    """Area of two bond vectors (eq. 3) with its Jacobian ``J (m, 2, c, d)``
    (``J[:, s] = da/dxi_s``; c = 1 for the 2-D scalar area, 3 in 3-D) and
    ``curvature(f) = f . d2a/dxi_p dxi_q``, ``(m, 1, d, d)``, for ``f = dphi/da (m, c)``."""
    if yp.shape[1] == 2:
        a = yp[:, 0] * yq[:, 1] - yp[:, 1] * yq[:, 0]
        jac = np.stack([yq[:, 1], -yq[:, 0], -yp[:, 1], yp[:, 0]], 1).reshape(-1, 2, 1, 2)
        return a[:, None], jac, lambda f: f[:, :, None, None] * _ROT
    jac = np.stack([-_skew(yq), _skew(yp)], 1)
    return np.cross(yp, yq), jac, lambda f: -_skew(f)[:, None]


def _volume(yp, yq, yr):
    """Volume of three bond vectors (eq. 4), ``J (m, 3, 1, 3)`` and the curvature
    ``(m, 3, 3, 3)`` of the bond pairs (0, 1), (0, 2), (1, 2)."""
    jac = np.stack([np.cross(yq, yr), np.cross(yr, yp), np.cross(yp, yq)], 1)
    v = np.einsum("mk,mk->m", yp, jac[:, 0])
    return v[:, None], jac[:, :, None], lambda f: f[:, :, None, None] * np.stack(
        [-_skew(yr), _skew(yq), -_skew(yp)], 1)


def _add(target, index, values, transpose=False):
    """``target[index] += values`` (or the transposed blocks), indices repeating."""
    size = values[0].size
    perm = np.arange(size)
    if transpose:
        d = values.shape[1]
        perm = perm.reshape(d, d).T.reshape(-1)
    add_rows(target.reshape(len(target), size), np.asarray(index, dtype=np.int64),
             np.ascontiguousarray(values).reshape(len(values), size), perm)


def _later(ends, first):
    """For each bond ``first[r]`` every later bond of the same family: ``(r, later)``."""
    count = ends - first - 1
    rep = np.repeat(np.arange(len(first)), count)
    start = np.repeat(np.cumsum(count) - count, count)
    return rep, first[rep] + 1 + (np.arange(len(rep)) - start)


def _size(g):
    """``|g|`` of (m, c) measures (the absolute value when c = 1)."""
    return np.sqrt(np.einsum("mk,mk->m", g, g))


def _chunks(m):
    """Slices of at most `cnem.config.CPD_CHUNK` interactions."""
    chunk = config.CPD_CHUNK
    return [slice(s, min(s + chunk, m)) for s in range(0, m, chunk)]


def _check_count(count, what):
    """A clear error before lists of more than `cnem.config.MAX_INTERACTIONS` are built."""
    if count > config.MAX_INTERACTIONS:
        raise LimitError(f"CPD: expected at most {config.MAX_INTERACTIONS} {what} "
                         f"(cnem.config.MAX_INTERACTIONS, ~64 bytes each), received {count}; "
                         f"use a smaller horizon or fewer points, or raise the limit")


class Interactions:
    """The interactions of a `CPD` material on a `Body`: which bonds, pairs and triplets,
    their reference measures and volume weights, and the block pattern of the tangent.

    Built by `CPD.interactions`. Energy (eq. 8): bonds carry ``V_a V^i / 2``, each
    unordered pair of bonds of a point ``2/3 V_a V^i V^j``, each unordered triplet
    ``3/2 V_a V^i V^j V^k`` with ``V^i = beta_ai V_i``.

    Parameters
    ----------
    body : Body
    material : CPD

    Attributes
    ----------
    pairs : (m2, 2) int64 ndarray
        Bonds ``p < q`` of one point spanning a non-degenerate area (present when
        C2 > 0 or C3 > 0).
    triplets : (m3, 3) int64 ndarray
        Bonds ``p < q < r`` of one point spanning a non-degenerate volume (C3 > 0).
    pair_ref : (m2,) ndarray
        Reference areas ``|A|``.
    triplet_ref : (m3,) ndarray
        Signed reference volumes ``V``.
    """

    def __init__(self, body, material):
        self.body, self.material = body, material
        n, d, nb = len(body), body.dim, len(body.bond_i)
        self.shape = (n * d, n * d)
        bi, bj = body.bond_i.astype(np.int64), body.bond_j.astype(np.int64)
        partial = body.beta * body.volumes[bj]                          # V^i
        own = body.volumes[bi]
        pairs = np.zeros((0, 2), dtype=np.int64)
        triplets = np.zeros((0, 3), dtype=np.int64)
        slots = np.zeros((0, 3), dtype=np.int64)
        if material.C2 > 0 or material.C3 > 0:
            ends = body.family.offsets[1:].astype(np.int64)[bi]
            k = body.family.counts.astype(np.int64)
            _check_count(int((k * (k - 1) // 2).sum()), "pairs of bonds")
            pairs = np.column_stack(_later(ends, np.arange(nb)))
            if material.C3 > 0:
                _check_count(int((k * (k - 1) * (k - 2) // 6).sum()), "triplets of bonds")
                t, r = _later(ends[pairs[:, 1]], pairs[:, 1])
                triplets = np.column_stack([pairs[t], r])
                triplets = triplets[self._regular(triplets)]
            pairs = pairs[self._regular(pairs)]
            key = pairs[:, 0] * nb + pairs[:, 1]                        # sorted
            slots = np.column_stack([np.searchsorted(key, triplets[:, s] * nb + triplets[:, t])
                                     for s, t in combinations(range(3), 2)])
        self.pairs, self.triplets, self.triplet_slots = pairs, triplets, slots
        self.bond_weight = 0.5 * own * partial
        self.pair_weight = (2.0 / 3.0) * own[pairs[:, 0]] * partial[pairs[:, 0]] * \
            partial[pairs[:, 1]]
        self.triplet_weight = 1.5 * own[triplets[:, 0]] * partial[triplets[:, 0]] * \
            partial[triplets[:, 1]] * partial[triplets[:, 2]]
        self.pair_ref = _size(self._measure(pairs))
        self.triplet_ref = self._measure(triplets)[:, 0]
        self._pattern(n, bi, bj)

    def _measure(self, idx):
        """Reference areas (pairs) or volumes (triplets), ``(m, c)``."""
        if len(idx) == 0:
            return np.zeros((0, 1))
        geometry = _area if idx.shape[1] == 2 else _volume
        return geometry(*(self.body.xi[idx[:, s]] for s in range(idx.shape[1])))[0]

    def _regular(self, idx):
        """Mask of the non-degenerate pairs or triplets."""
        return _size(self._measure(idx)) > config.CPD_DEGENERATE * np.prod(self.body.length[idx], axis=1)

    def _pattern(self, n, bi, bj):
        """Block pattern (BSR ``indptr``, ``indices``) and the block of each contribution:
        ``pos_pq``/``pos_qp`` of a pair's far points, ``pos_ap``/``pos_pa`` of a bond,
        ``pos_diag`` of each point."""
        pi, pj = bj[self.pairs[:, 0]], bj[self.pairs[:, 1]]
        m, nb = len(pi), len(bi)
        keys, pos = np.unique(np.concatenate([pi * n + pj, pj * n + pi, bi * n + bj,
                                              bj * n + bi, np.arange(n) * (n + 1)]),
                              return_inverse=True)
        self.indices = keys % n
        self.indptr = np.concatenate([[0], np.cumsum(np.bincount(keys // n, minlength=n))])
        self.pos_pq, self.pos_qp = pos[:m], pos[m:2 * m]
        self.pos_ap, self.pos_pa = pos[2 * m:2 * m + nb], pos[2 * m + nb:2 * m + 2 * nb]
        self.pos_diag = pos[2 * m + 2 * nb:]

    # -- evaluation ----------------------------------------------------------------------
    def evaluate(self, u, *, tangent=True):
        """Energy, internal force ``dPsi/du`` (eq. 19) and tangent ``d2Psi/du2`` (eq. 20).

        Parameters
        ----------
        u : (n, d) or (n d,) array_like
            Displacements.
        tangent : bool
            Also assemble the tangent.

        Returns
        -------
        energy : float
        force : (n d,) ndarray
        K : (n d, n d) scipy.sparse.csr_matrix (symmetric) or None
        """
        body, mat = self.body, self.material
        n, d, nb = len(body), body.dim, len(body.bond_i)
        u = np.asarray(u, dtype=float)
        if u.size != n * d:
            raise InputError(f"u: expected {n * d} displacements (shape ({n}, {d})), "
                             f"received shape {u.shape}; pass one vector per point")
        u = u.reshape(n, d)
        y = body.xi + u[body.bond_j] - u[body.bond_i]                 # deformed bonds
        sums = {"energy": 0.0, "grad": np.zeros((nb, d))}
        if tangent:
            sums.update(diag=np.zeros((nb, d, d)), rows=np.zeros((nb, d, d)),
                        data=np.zeros((len(self.indices), d, d)))
        kinds = [(np.arange(nb)[:, None], np.zeros((nb, 0), dtype=np.int64), body.length,
                  self.bond_weight, _stretch, 1)]
        if mat.C2 > 0:
            kinds.append((self.pairs, np.arange(len(self.pairs))[:, None], self.pair_ref,
                          self.pair_weight, _area, 2))
        if mat.C3 > 0:
            kinds.append((self.triplets, self.triplet_slots, self.triplet_ref,
                          self.triplet_weight, _volume, 3))
        for idx, slots, ref, weight, geometry, order in kinds:
            for sl in _chunks(len(idx)):
                g, jac, curvature = geometry(*(y[idx[sl, s]] for s in range(order)))
                value, first, second = mat.measure_derivatives(order, g, ref[sl])
                w = weight[sl]
                self._scatter(sums, idx[sl], slots[sl], w @ value, w[:, None] * first,
                              w[:, None, None] * second if tangent else None, jac, curvature)
        force = np.zeros((n, d))
        _add(force, body.bond_j, sums["grad"])
        _add(force, body.bond_i, -sums["grad"])
        return sums["energy"], force.reshape(-1), self._tangent(sums) if tangent else None

    def _scatter(self, sums, idx, slots, energy, first, second, jac, curvature):
        """Add one chunk: energy, bond gradients ``J_s^T phi_g`` and (when ``second`` is
        given) the Hessian blocks of eq. 38, per bond and into the pair blocks."""
        sums["energy"] += float(energy)
        m, r = idx.shape
        grads = np.einsum("mc,mrcd->mrd", first, jac)
        _add(sums["grad"], idx.reshape(-1), grads.reshape(m * r, -1))
        if second is not None:
            scatter_hessian(idx, slots, self.pos_pq, self.pos_qp, np.ascontiguousarray(jac),
                            np.ascontiguousarray(second),
                            np.ascontiguousarray(curvature(first)),
                            sums["diag"], sums["rows"], sums["data"])

    def _tangent(self, sums):
        """Nodal tangent from the bond blocks: with ``S_p`` the row sums of bond p's blocks,
        ``K[j_p, j_p] += G_pp``, ``K[j_p, a] -= S_p``, ``K[a, j_p] -= S_p^T``,
        ``K[a, a] += sum_p S_p``."""
        body, data = self.body, sums["data"]
        S = sums["diag"] + sums["rows"]
        _add(data, self.pos_diag[body.bond_j], sums["diag"])
        _add(data, self.pos_pa, -S)
        _add(data, self.pos_ap, -S, transpose=True)
        point = np.zeros((len(body), body.dim, body.dim))
        _add(point, body.bond_i, S)
        data[self.pos_diag] += point
        return sp.bsr_matrix((data, self.indices, self.indptr), shape=self.shape).tocsr()

    def with_material(self, material):
        """The same interactions and pattern with another `CPD` material (e.g. other
        constants or ``derivatives``) that needs no other kinds of interactions."""
        needs = (material.C2 > 0 or material.C3 > 0, material.C3 > 0)
        have = (self.material.C2 > 0 or self.material.C3 > 0, self.material.C3 > 0)
        if needs != have:
            raise MaterialError(f"material: expected one with the same kinds of interactions "
                                f"(C2 or C3 > 0: {have[0]}, C3 > 0: {have[1]}), received "
                                f"{material!r}; build new ones with material.interactions(body)")
        other = copy.copy(self)
        other.material = material
        return other

    def internal_force(self, u):
        """``dPsi/du``, ``(n d,)``."""
        return self.evaluate(u, tangent=False)[1]

    def tangent(self, u):
        """``d2Psi/du2``, sparse ``(n d, n d)``."""
        return self.evaluate(u)[2]

    def pattern(self):
        """Sparsity pattern of the tangent (ones), sparse ``(n d, n d)``."""
        d = self.body.dim
        ones = np.ones((len(self.indices), d, d))
        return sp.bsr_matrix((ones, self.indices, self.indptr), shape=self.shape).tocsr()

    def __repr__(self):
        return (f"<CPD interactions: {len(self.body.bond_i)} bonds, {len(self.pairs)} pairs, "
                f"{len(self.triplets)} triplets, {len(self.indices)} tangent blocks>")
