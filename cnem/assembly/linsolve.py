"""Linear solves for assembled systems: direct for small, pyamg + CG for large,
with a check for rigid motions that the boundary conditions leave free."""

from __future__ import annotations

import logging

import numpy as np
import scipy.sparse as sp
import scipy.sparse.csgraph as csgraph
import scipy.sparse.linalg as spla

from ..errors import SolveError

__all__ = ["rigid_modes", "free_rigid_motions", "solve_spd", "DIRECT_NNZ"]

log = logging.getLogger(__name__)

#: Above this many matrix non-zeros `solve_spd` uses pyamg-preconditioned CG: about
#: 200k unknowns of linear triangles (12 non-zeros per row), about 40k unknowns of an
#: SCNI stiffness (~65 per row), whose sparse factors fill in much faster (at 200k
#: unknowns: 74 s direct against 7 s for smoothed aggregation + CG, 36 iterations).
DIRECT_NNZ = 2_500_000


def rigid_modes(points):
    """Rigid motions of a 2-D body, interleaved dofs: translations x, y and the
    rotation about the centroid.

    Returns
    -------
    (2 n, 3) ndarray
    """
    n = len(points)
    rel = points - points.mean(axis=0)
    modes = np.zeros((2 * n, 3))
    modes[0::2, 0] = 1.0
    modes[1::2, 1] = 1.0
    modes[0::2, 2] = -rel[:, 1]
    modes[1::2, 2] = rel[:, 0]
    return modes


def _describe(mode, centre):
    tx, ty, rot = mode
    scale = max(abs(tx), abs(ty), abs(rot), 1e-300)
    if abs(rot) < 1e-8 * scale:
        if abs(ty) < 1e-8 * scale:
            return "translation in x"
        if abs(tx) < 1e-8 * scale:
            return "translation in y"
        return f"translation along ({tx / scale:.3g}, {ty / scale:.3g})"
    pivot = centre + np.array([-ty, tx]) / rot
    return f"rotation about ({pivot[0]:.6g}, {pivot[1]:.6g})"


def free_rigid_motions(K, points, fixed):
    """Rigid motions of each connected part of a 2-D body left free by fixed dofs.

    Parameters
    ----------
    K : sparse (2 n, 2 n)
        Stiffness (its pattern tells which nodes hang together).
    points : (n, 2) ndarray
    fixed : (k,) int array
        Dofs with prescribed values.

    Returns
    -------
    list of str
        One description per free motion (empty when the system is regular).
    """
    n = len(points)
    node_graph = sp.csr_matrix((np.ones(K.nnz), (K.tocoo().row // 2, K.tocoo().col // 2)),
                               shape=(n, n))
    ncomp, label = csgraph.connected_components(node_graph, directed=False)
    is_fixed = np.zeros(2 * n, dtype=bool)
    is_fixed[fixed] = True
    free = []
    for part in range(ncomp):
        nodes = np.flatnonzero(label == part)
        pts = points[nodes]
        size = max(np.ptp(pts, axis=0).max(), 1e-300)
        modes = rigid_modes(pts / size)
        dofs = np.column_stack([2 * nodes, 2 * nodes + 1]).reshape(-1)
        rows = modes[is_fixed[dofs]]
        _, s, vt = np.linalg.svd(rows) if len(rows) else (None, np.zeros(0), np.eye(3))
        s = np.concatenate([s, np.zeros(3 - len(s))])
        where = "" if ncomp == 1 else f" of the part holding node {nodes[0]} ({len(nodes)} nodes)"
        for k in np.flatnonzero(s <= 1e-9 * max(s.max(initial=0.0), 1.0)):
            mode = vt[k] * np.array([1.0, 1.0, 1.0 / size])
            free.append(_describe(mode, pts.mean(axis=0)) + where)
    return free


def solve_spd(A, b, *, modes=None, tol=1e-10, method="auto"):
    """Solve a symmetric positive definite system.

    Parameters
    ----------
    A : sparse (N, N)
    b : (N,) ndarray
    modes : (N, k) ndarray, optional
        Near-null space for smoothed aggregation (rigid motions).
    tol : float
        Relative residual for the iterative solver.
    method : {"auto", "direct", "amg"}
        ``"auto"``: direct up to `DIRECT_NNZ` non-zeros, pyamg + CG above.

    Returns
    -------
    (N,) ndarray
    """
    if method == "auto":
        method = "direct" if A.nnz <= DIRECT_NNZ else "amg"
    if method == "direct":
        return spla.spsolve(A.tocsc(), b)
    if method != "amg":
        raise ValueError(f"method: expected 'auto', 'direct' or 'amg', received {method!r}")
    import pyamg
    ml = pyamg.smoothed_aggregation_solver(A.tocsr(), B=modes, symmetry="symmetric")
    residuals = []
    x = ml.solve(b, tol=tol, accel="cg", maxiter=2000, residuals=residuals)
    rel = residuals[-1] / max(residuals[0], 1e-300)
    log.info("pyamg CG: %d iterations, relative residual %.2e", len(residuals) - 1, rel)
    if not rel <= 10 * tol:
        raise SolveError(f"pyamg + CG stopped at relative residual {rel:.2e} after "
                         f"{len(residuals) - 1} iterations (wanted {tol:.0e})")
    return x
