"""Moment (shape) tensors ``M_i = sum_b w_b xi_b xi_b^T`` of the bonds of every point, and
their inverses over the live bonds.

The dilatation of the state-based solid is the trace of a nonlocal gradient,
``theta_i = sum_b w_b (u_j - u_i) . M_i^-1 xi_b``. When bonds break, the sum runs over the
live bonds and ``M_i`` must be theirs too (as the shape tensor of the correspondence
models): with the reference ``M_i`` a rigid rotation of a cracked body would dilate the
points along the crack. A point left with too few bonds in a direction (eigenvalue of its
live tensor below `cnem.config.LIVE_MOMENT_CUTOFF` times the largest of its reference
tensor) gets the pseudo-inverse without that direction.

>>> import numpy as np
>>> xi = np.array([[1.0, 0.0], [0.0, 2.0], [-1.0, 0.0]])
>>> M = moment_tensors(np.zeros(3, dtype=int), xi, np.ones(3), 1)
>>> M[0].tolist()
[[2.0, 0.0], [0.0, 4.0]]
>>> live_inverse(np.array([[[2.0, 0.0], [0.0, 0.1]]]), M)[0].tolist()
[[0.5, 0.0], [0.0, 0.0]]
"""

from __future__ import annotations

import numpy as np

from .. import config

__all__ = ["moment_tensors", "live_inverse"]


def moment_tensors(bond_i: np.ndarray, xi: np.ndarray, weight: np.ndarray, n: int) -> np.ndarray:
    """``M_i = sum_b w_b xi_b xi_b^T`` over the bonds ``b`` of every point ``i``.

    Parameters
    ----------
    bond_i : (b,) int ndarray
        The point of every bond.
    xi : (b, d) ndarray
        Reference bond vectors.
    weight : (b,) ndarray
        ``w_b`` (zero for a bond left out).
    n : int
        Number of points.

    Returns
    -------
    (n, d, d) ndarray
    """
    d = xi.shape[1]
    M = np.empty((n, d, d))
    for a in range(d):
        for c in range(a, d):
            M[:, a, c] = M[:, c, a] = np.bincount(bond_i, weights=weight * xi[:, a] * xi[:, c],
                                                  minlength=n)
    return M


def live_inverse(live: np.ndarray, reference: np.ndarray,
                 cutoff: float = config.LIVE_MOMENT_CUTOFF) -> np.ndarray:
    """Pseudo-inverses of live-bond moment tensors over their well-filled directions.

    Parameters
    ----------
    live : (k, d, d) ndarray
        Moment tensors of the live bonds.
    reference : (k, d, d) ndarray
        Those of all bonds of the same points.
    cutoff : float
        Eigen-directions of ``live`` whose eigenvalue is below ``cutoff`` times the
        largest eigenvalue of ``reference`` are dropped.

    Returns
    -------
    (k, d, d) ndarray
        ``sum_k v_k v_k^T / lambda_k`` over the kept eigenpairs (symmetric; zero for a
        point without live bonds).
    """
    vals, vecs = np.linalg.eigh(live)
    top = np.linalg.eigvalsh(reference)[:, -1:]
    keep = vals > cutoff * top
    inv = np.where(keep, 1.0 / np.where(keep, vals, 1.0), 0.0)
    return np.einsum("kij,kj,klj->kil", vecs, inv, vecs)
