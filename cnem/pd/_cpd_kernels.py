"""Numba kernels of the CPD assembly (arrays only): scattered sums of blocks."""

import numba
import numpy as np

from .. import _compile  # noqa: F401  (says once when the kernels compile)


@numba.njit(cache=True)
def add_rows(target, index, values, perm):
    """``target[index[r], k] += values[r, perm[k]]`` for every row ``r`` (repeated indices
    add up; ``perm`` transposes flattened blocks or is the identity).

    Parameters
    ----------
    target : (N, c) float64, C-contiguous
    index : (m,) int64
    values : (m, c) float64, C-contiguous
    perm : (c,) int64
    """
    c = target.shape[1]
    for r in range(index.shape[0]):
        row = index[r]
        for k in range(c):
            target[row, k] += values[r, perm[k]]


@numba.njit(cache=True)
def scatter_hessian(idx, slots, pos_pq, pos_qp, jac, second, curvature, diag, rows, data):
    """Hessian blocks of interactions of ``r`` bonds of one point (eq. 38), scattered.

    Interaction ``i`` has bonds ``p_s = idx[i, s]`` and blocks
    ``G_st = J_s^T second J_t + curvature`` (``curvature[i, k]`` for the k-th pair
    ``s < t`` in lexicographic order, its transpose for ``s > t``). Adds
    ``diag[p_s] += G_ss``, ``rows[p_s] += G_st`` (``t != s``), and
    ``data[pos_pq[slots[i, k]]] += G_st``, ``data[pos_qp[slots[i, k]]] += G_ts``.

    Parameters
    ----------
    idx : (m, r) int64
    slots : (m, r (r - 1) / 2) int64
    pos_pq, pos_qp : (P,) int64
    jac : (m, r, c, d) float64
        ``dg/dxi_s`` of the measure ``g`` (c components).
    second : (m, c, c) float64
        Weighted ``d2phi/dg2``.
    curvature : (m, r (r - 1) / 2, d, d) float64
    diag, rows : (nb, d, d) float64, accumulated
    data : (nblocks, d, d) float64, accumulated
    """
    m, r, c, d = jac.shape
    block = np.empty((d, d))
    for i in range(m):
        for s in range(r):
            p = idx[i, s]
            for t in range(r):
                for a in range(d):
                    for b in range(d):
                        v = 0.0
                        for e in range(c):
                            for f in range(c):
                                v += jac[i, s, e, a] * second[i, e, f] * jac[i, t, f, b]
                        block[a, b] = v
                if s == t:
                    for a in range(d):
                        for b in range(d):
                            diag[p, a, b] += block[a, b]
                    continue
                lo, hi = min(s, t), max(s, t)
                k = lo * r - lo * (lo + 1) // 2 + hi - lo - 1
                far = pos_pq[slots[i, k]] if s < t else pos_qp[slots[i, k]]
                for a in range(d):
                    for b in range(d):
                        v = block[a, b] + (curvature[i, k, a, b] if s < t else
                                           curvature[i, k, b, a])
                        rows[p, a, b] += v
                        data[far, a, b] += v
