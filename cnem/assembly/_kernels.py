"""Numba kernels of the SCNI boundary quadrature (arrays and scalars only)."""

import numba
import numpy as np


@numba.njit(cache=True, parallel=True)
def circle_crossings(a, b, centre, radius2, cand_off, cand_idx, out_off, out_t, fill):
    """Parameters ``t`` in (0, 1) where segments ``a + t (b - a)`` cross circles.

    Two passes: with ``fill=False`` writes the count of crossings of segment
    ``k`` to ``out_off[k + 1]``; with ``fill=True`` writes them to
    ``out_t[out_off[k]:out_off[k + 1]]`` (unsorted). Candidates are circles
    ``cand_idx[cand_off[k]:cand_off[k + 1]]``. Crossings closer than 1e-12
    (relative) to an end are left out: they would make empty pieces.
    """
    for k in numba.prange(len(a)):
        dx = b[k, 0] - a[k, 0]
        dy = b[k, 1] - a[k, 1]
        length2 = dx * dx + dy * dy
        count = 0
        for p in range(cand_off[k], cand_off[k + 1]):
            c = cand_idx[p]
            fx = a[k, 0] - centre[c, 0]
            fy = a[k, 1] - centre[c, 1]
            half_b = fx * dx + fy * dy
            disc = half_b * half_b - length2 * (fx * fx + fy * fy - radius2[c])
            if disc <= 0.0:
                continue
            root = np.sqrt(disc)
            for t in ((-half_b - root) / length2, (-half_b + root) / length2):
                if 1e-12 < t < 1.0 - 1e-12:
                    if fill:
                        out_t[out_off[k] + count] = t
                    count += 1
        if not fill:
            out_off[k + 1] = count
