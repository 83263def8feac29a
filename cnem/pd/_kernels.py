"""Numba kernels of the peridynamic force loop (arrays and scalars only)."""

import numba
import numpy as np


@numba.njit(cache=True, parallel=True, fastmath=True)
def pmb_forces(u, xi, length, offsets, bond_j, stiffness, volumes, alive, limit, out):
    """Bond-based PMB force density at every point, breaking bonds beyond ``limit``.

    ``out[i] = sum_j stiffness_b s_b (y_b / |y_b|) V_j`` over the live bonds of
    ``i``, with ``y_b = xi_b + u_j - u_i`` and the stretch ``s_b = |y_b| / L_b - 1``.
    A bond whose stretch exceeds ``limit`` is marked dead (``alive[b] = 0``)
    and carries no force from then on. Returns the number of bonds broken.
    """
    n, d = u.shape
    broken = np.zeros(n, dtype=np.int64)
    for i in numba.prange(n):
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
            ly = np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
            s = ly / length[b] - 1.0
            if s > limit:
                alive[b] = 0
                broken[i] += 1
                continue
            g = stiffness[b] * s * volumes[j] / ly
            f0 += g * y0
            f1 += g * y1
            f2 += g * y2
        out[i, 0] = f0
        out[i, 1] = f1
        if d == 3:
            out[i, 2] = f2
    return broken.sum()
