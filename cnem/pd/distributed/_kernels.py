"""Numba kernels of the distributed peridynamic solvers (arrays and scalars only).

Local arrays: rows ``0..o-1`` are the owned points, the ghosts follow; bonds are
those of the owned points (CSR ``offsets``, ``bond_j`` local). For the
state-based forces every bond ``b = (i, j)`` also stands for its reverse
``(j, i)``, whose data come from ``b`` (``xi_ji = -xi_b``, same length) and from
the ghost values of ``j``.
"""

import numba
import numpy as np

from ... import _compile  # noqa: F401  (says once when the kernels compile)


@numba.njit(cache=True, parallel=True)
def sort_rows(offsets, keys):
    """Sort each CSR row of ``keys`` in place (insertion sort: rows are short)."""
    n = len(offsets) - 1
    for i in numba.prange(n):
        for a in range(offsets[i] + 1, offsets[i + 1]):
            k = keys[a]
            b = a - 1
            while b >= offsets[i] and keys[b] > k:
                keys[b + 1] = keys[b]
                b -= 1
            keys[b + 1] = k


@numba.njit(cache=True, inline="always")
def _extension(u, xi, length, b, i, j, sign):
    """``|y| / L - 1`` of bond ``b`` (``sign = 1``) or of its reverse (``sign = -1``),
    computed as the serial code does: ``y = (xi + u_end) - u_start``."""
    d = u.shape[1]
    s = 0.0
    for k in range(d):
        if sign > 0:
            y = (xi[b, k] + u[j, k]) - u[i, k]
        else:
            y = (-xi[b, k] + u[i, k]) - u[j, k]
        s += y * y
    return np.sqrt(s) / length[b] - 1.0


@numba.njit(cache=True, parallel=True)
def break_bonds(u, xi, length, offsets, bond_j, limit, alive, alive_reverse):
    """Kill the bonds (and reverse bonds) stretched beyond ``limit``; returns the number of
    owned bonds killed."""
    n = len(offsets) - 1
    broken = np.zeros(n, dtype=np.int64)
    for i in numba.prange(n):
        for b in range(offsets[i], offsets[i + 1]):
            j = bond_j[b]
            if alive[b] and _extension(u, xi, length, b, i, j, 1) > limit:
                alive[b] = 0
                broken[i] += 1
            if alive_reverse[b] and _extension(u, xi, length, b, i, j, -1) > limit:
                alive_reverse[b] = 0
    return broken.sum()


@numba.njit(cache=True, parallel=True)
def dilatation(u, offsets, bond_j, g, alive, theta):
    """``theta_i = sum_b g_b . (u_j - u_i)`` over the live bonds of owned ``i`` (as the
    serial operator ``T``: a broken bond carries no dilatation)."""
    n = len(offsets) - 1
    d = u.shape[1]
    for i in numba.prange(n):
        t = 0.0
        for b in range(offsets[i], offsets[i + 1]):
            if not alive[b]:
                continue
            j = bond_j[b]
            for k in range(d):
                t += g[b, k] * (u[j, k] - u[i, k])
        theta[i] = t


@numba.njit(cache=True, inline="always")
def _deviatoric(u, xi, length, b, i, j, theta_start, d):
    """Linearised deviatoric extension ``n_b . (u_j - u_i) - L_b / d theta_start``."""
    e = 0.0
    for k in range(d):
        e += xi[b, k] / length[b] * (u[j, k] - u[i, k])
    return e - length[b] / d * theta_start


@numba.njit(cache=True, parallel=True)
def pressure(u, xi, length, offsets, bond_j, theta, bulk_volume, c, alive, out):
    """``P_i = k V_i theta_i - sum_b c_b live_b e^d_b L_b / d`` at the owned points: the
    derivative of the energy with respect to ``theta_i``."""
    n = len(offsets) - 1
    d = u.shape[1]
    for i in numba.prange(n):
        s = 0.0
        for b in range(offsets[i], offsets[i + 1]):
            if alive[b]:
                s += c[b] * _deviatoric(u, xi, length, b, i, bond_j[b], theta[i], d) * \
                    length[b] / d
        out[i] = bulk_volume[i] * theta[i] - s


@numba.njit(cache=True, parallel=True)
def lps_forces(u, xi, length, offsets, bond_j, volumes, g, g_reverse, theta, P, c, c_reverse,
               alive, alive_reverse, out):
    """Force per unit volume ``-(K u)_i / V_i`` of the linear peridynamic solid at the owned
    points, from the dilatations ``theta`` and pressures ``P`` of owned and ghost points.

    ``(K u)_i = -P_i sum_b g_b + sum_b P_j g'_b - sum_b c_b e^d_b n_b
    + sum_b c'_b e'^d_b (-n_b)`` over the bonds ``b = (i, j)``, primes for the reverse
    bonds ``(j, i)``; each term only while its bond (or reverse bond) lives.
    """
    n = len(offsets) - 1
    d = u.shape[1]
    for i in numba.prange(n):
        f = np.zeros(d)
        for b in range(offsets[i], offsets[i + 1]):
            j = bond_j[b]
            if alive[b]:
                for k in range(d):
                    f[k] -= P[i] * g[b, k]
            if alive_reverse[b]:
                for k in range(d):
                    f[k] += P[j] * g_reverse[b, k]
            if alive[b]:
                e = c[b] * _deviatoric(u, xi, length, b, i, j, theta[i], d)
                for k in range(d):
                    f[k] -= e * xi[b, k] / length[b]
            if alive_reverse[b]:
                e = c_reverse[b] * _deviatoric(u, xi, length, b, i, j, theta[j], d)
                for k in range(d):
                    f[k] -= e * xi[b, k] / length[b]
        for k in range(d):
            out[i, k] = -f[k] / volumes[i]
