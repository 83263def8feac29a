"""Numba kernels of the peridynamic force loop (arrays and scalars only)."""

import numba
import numpy as np

from .. import _compile  # noqa: F401  (says once when the kernels compile)


@numba.njit(cache=True, fastmath=True, error_model="numpy")
def _pmb_point(i, u, xi, length, offsets, bond_j, stiffness, volumes, alive, limit, out):
    """The PMB force density of point ``i`` into ``out[i]`` (see `pmb_forces`); returns
    the number of its bonds broken.

    One square root and one division per bond: ``s / |y| = (|y| - L) / (L |y|)``, and
    the break test ``|y| / L - 1 > limit`` as ``|y|^2 > (L (1 + limit))^2`` (every bond
    breaks when ``limit < -1``: a stretch is at least -1).
    """
    d = u.shape[1]
    grow = 1.0 + limit
    every = grow < 0.0
    broken = 0
    f0 = 0.0
    f1 = 0.0
    f2 = 0.0
    for b in range(offsets[i], offsets[i + 1]):
        if not alive[b]:
            continue
        j = bond_j[b]
        y0 = xi[b, 0] + u[j, 0] - u[i, 0]
        y1 = xi[b, 1] + u[j, 1] - u[i, 1]
        y2 = 0.0
        if d == 3:
            y2 = xi[b, 2] + u[j, 2] - u[i, 2]
        yy = y0 * y0 + y1 * y1 + y2 * y2
        L = length[b]
        reach = L * grow
        if every or yy > reach * reach:
            alive[b] = 0
            broken += 1
            continue
        ly = np.sqrt(yy)
        g = stiffness[b] * volumes[j] * (ly - L) / (L * ly)
        f0 += g * y0
        f1 += g * y1
        f2 += g * y2
    out[i, 0] = f0
    out[i, 1] = f1
    if d == 3:
        out[i, 2] = f2
    return broken


@numba.njit(cache=True, parallel=True, fastmath=True, error_model="numpy")
def pmb_forces(u, xi, length, offsets, bond_j, stiffness, volumes, alive, limit, out):
    """Bond-based PMB force density at every point, breaking bonds beyond ``limit``.

    ``out[i] = sum_j stiffness_b s_b (y_b / |y_b|) V_j`` over the live bonds of
    ``i``, with ``y_b = xi_b + u_j - u_i`` and the stretch ``s_b = |y_b| / L_b - 1``.
    A bond whose stretch exceeds ``limit`` is marked dead (``alive[b] = 0``)
    and carries no force from then on. Returns the number of bonds broken.
    """
    n = u.shape[0]
    broken = np.zeros(n, dtype=np.int64)
    for i in numba.prange(n):
        broken[i] = _pmb_point(i, u, xi, length, offsets, bond_j, stiffness, volumes, alive,
                               limit, out)
    return broken.sum()


@numba.njit(cache=True, parallel=True, fastmath=True, error_model="numpy")
def pmb_forces_rows(rows, u, xi, length, offsets, bond_j, stiffness, volumes, alive, limit,
                    out):
    """`pmb_forces` at the points ``rows`` only (``out`` written at those rows)."""
    broken = np.zeros(len(rows), dtype=np.int64)
    for k in numba.prange(len(rows)):
        broken[k] = _pmb_point(rows[k], u, xi, length, offsets, bond_j, stiffness, volumes,
                               alive, limit, out)
    return broken.sum()


@numba.njit(cache=True, parallel=True)
def bond_geometry(points, offsets, bond_j, period, spacing, horizon, xi, length, beta):
    """Reference bond vectors (minimum image on periodic axes), lengths and the
    partial-volume factors ``clip((delta + dx/2 - L) / dx, 0, 1)`` with ``dx`` the
    mean spacing of the two points."""
    n, d = points.shape
    for i in numba.prange(n):
        for b in range(offsets[i], offsets[i + 1]):
            j = bond_j[b]
            s = 0.0
            for k in range(d):
                v = points[j, k] - points[i, k]
                if np.isfinite(period[k]):
                    v -= period[k] * np.round(v / period[k])
                xi[b, k] = v
                s += v * v
            L = np.sqrt(s)
            length[b] = L
            dx = 0.5 * (spacing[i] + spacing[j])
            f = (horizon + 0.5 * dx - L) / dx
            beta[b] = 0.0 if f < 0.0 else (1.0 if f > 1.0 else f)


@numba.njit(cache=True, inline="always")
def _direction_function(xi, L, b, p, q):
    """``P(n) = n_p^2`` (p == q) or ``n_p^2 n_q^2`` of bond ``b``'s direction."""
    np_ = xi[b, p] / L
    val = np_ * np_
    if p != q:
        nq = xi[b, q] / L
        val *= nq * nq
    return val


@numba.njit(cache=True, parallel=True)
def pmb_correction_moments(xi, length, weight, offsets, pairs, out):
    """For the energy-method correction of the PMB: ``out[i, t, k] = sum_j w L
    (n . eps_t . n)^2 P_k(n)`` over the bonds of ``i``, with the unit test strains
    ``eps_t`` of the index pairs ``(a, c)`` and ``P_k = n_a^2`` (a == c) or
    ``n_a^2 n_c^2`` (a != c) for the same pairs."""
    n = len(offsets) - 1
    npair = len(pairs)
    for i in numba.prange(n):
        for b in range(offsets[i], offsets[i + 1]):
            L = length[b]
            for t in range(npair):
                a, c = pairs[t, 0], pairs[t, 1]
                na, nc = xi[b, a] / L, xi[b, c] / L
                proj = na * nc if a == c else 2.0 * na * nc          # n . eps_t . n
                e2 = proj * proj
                for k in range(npair):
                    val = _direction_function(xi, L, b, pairs[k, 0], pairs[k, 1])
                    out[i, t, k] += weight[b] * L * e2 * val


@numba.njit(cache=True, parallel=True)
def pmb_bond_factors(xi, length, offsets, bond_j, pairs, coef, out):
    """``out[b] = (g_i(n_b) + g_j(n_b)) / 2`` with ``g_i(n) = sum_k coef[i, k] P_k(n)``
    (``P_k`` as in `pmb_correction_moments`)."""
    n = len(offsets) - 1
    npair = len(pairs)
    for i in numba.prange(n):
        for b in range(offsets[i], offsets[i + 1]):
            j = bond_j[b]
            L = length[b]
            g = 0.0
            for k in range(npair):
                val = _direction_function(xi, L, b, pairs[k, 0], pairs[k, 1])
                g += 0.5 * (coef[i, k] + coef[j, k]) * val
            out[b] = g
