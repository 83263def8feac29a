"""Numba kernels of the peridynamic bond geometry and its surface correction (arrays and
scalars only); the bond-based force loop is in `_pmb_kernels`."""

import numba
import numpy as np

from .. import _compile  # noqa: F401  (says once when the kernels compile)


def image_factors(period):
    """``(2, d)``: per axis the period twice, or 0 and 1 on an axis of infinite ``period
    (d,)`` (not periodic), for `periodic_image`."""
    period = np.asarray(period, dtype=float)
    finite = np.isfinite(period)
    return np.ascontiguousarray(np.stack([np.where(finite, period, 0.0),
                                          np.where(finite, period, 1.0)]))


@numba.njit(cache=True, inline="always")
def periodic_image(v, period, divisor):
    """The coordinate difference ``v`` on an axis of ``period`` (``divisor`` the period too;
    0 and 1 on an axis that is not periodic): its minimum image ``v - period round(v /
    period)``, with no branch (``v`` itself when not periodic)."""
    return v - period * np.round(v / divisor)


@numba.njit(cache=True, parallel=True)
def bond_geometry(points, offsets, bond_j, image, spacing, horizon, xi, length, beta):
    """Reference bond vectors (minimum image on periodic axes, ``image (2, d)`` from
    `image_factors`), lengths and the partial-volume factors ``clip((delta + dx/2 - L) /
    dx, 0, 1)`` with ``dx`` the mean spacing of the two points."""
    n, d = points.shape
    for i in numba.prange(n):
        for b in range(offsets[i], offsets[i + 1]):
            j = bond_j[b]
            s = 0.0
            for k in range(d):
                v = periodic_image(points[j, k] - points[i, k], image[0, k], image[1, k])
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
