"""Linear solves for assembled systems: direct for small, pyamg + CG for large,
with a check for rigid motions that the boundary conditions leave free.

Enriched systems (``nodal`` given to `solve_spd`) are preconditioned by smoothed
aggregation on the nodal block plus an exact solve of the enriched block (additive
Schwarz); an iterative solve that stalls falls back to a direct one when its factor
fits in `cnem.config.DIRECT_MEMORY`, and otherwise says what to change.
"""

from __future__ import annotations

import logging
import os
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp
import scipy.sparse.csgraph as csgraph
import scipy.sparse.linalg as spla

from .. import config
from ..errors import InputError, SolveError, check_choice
from .condensation import FreeBlock
from .multigrid import VCycle, hierarchy

if TYPE_CHECKING:
    from typing import Callable, Literal

__all__ = ["rigid_modes", "free_rigid_motions", "solve_spd", "direct_factor_bytes"]

log = logging.getLogger(__name__)


def rigid_modes(points: np.ndarray) -> np.ndarray:
    """Rigid motions of a 2-D or 3-D body, interleaved dofs.

    2-D: translations in x, y and the rotation about the centroid; 3-D:
    translations in x, y, z and the rotations about the x, y and z axes
    through the centroid (``u = w x (p - centroid)``).

    Parameters
    ----------
    points : (n, d) ndarray
        d = 2 or 3.

    Returns
    -------
    (2 n, 3) or (3 n, 6) ndarray
    """
    n, d = np.shape(points)
    if d not in (2, 3):
        raise InputError(f"points: expected an (n, 2) or (n, 3) array, received shape "
                         f"{np.shape(points)}; pass the node coordinates")
    rel = points - points.mean(axis=0)
    if d == 2:
        rel = np.column_stack([rel, np.zeros(n)])
    nrot = 1 if d == 2 else 3
    modes = np.zeros((n, d, d + nrot))
    modes[:, :, :d] = np.eye(d)
    for k, axis in enumerate(range(3 - nrot, 3)):            # 2-D: the z axis only
        modes[:, :, d + k] = np.cross(np.eye(3)[axis], rel)[:, :d]
    return modes.reshape(d * n, d + nrot)


def _rref(rows, tol):
    """Reduced row echelon form of a small matrix (partial pivoting, entries below
    ``tol`` taken as zero)."""
    rows = np.array(rows, dtype=float)
    top = 0
    for col in range(rows.shape[1]):
        if top == len(rows):
            break
        pivot = top + np.argmax(np.abs(rows[top:, col]))
        if abs(rows[pivot, col]) <= tol:
            rows[top:, col] = 0.0
            continue
        rows[[top, pivot]] = rows[[pivot, top]]
        rows[top] /= rows[top, col]
        others = np.arange(len(rows)) != top
        rows[others] -= rows[others, col][:, None] * rows[top]
        top += 1
    rows[np.abs(rows) <= tol] = 0.0
    return rows[:top]


def _direction(v):
    """``x``, ``y``, ``z`` for a coordinate axis, else the unit vector in brackets."""
    v = v / np.abs(v).max()
    if np.count_nonzero(v) == 1:
        return "xyz"[np.flatnonzero(v)[0]]
    return "(" + ", ".join(f"{c:.3g}" for c in v) + ")"


def _describe(t, w, centre, size):
    """Name the rigid motion ``u(p) = t + w x (p - centre)`` (``w`` a scalar in 2-D) of a
    part of extent ``size``."""
    if not np.any(w):
        name = _direction(t)
        return f"translation {'in' if len(name) == 1 else 'along'} {name}"
    d = len(t)
    w3 = np.array([0.0, 0.0, w[0]]) if d == 2 else w
    # the point of the axis nearest the centre, and the slip along the axis (a screw)
    pivot = centre + np.cross(w3, np.append(t, 0.0) if d == 2 else t)[:d] / (w3 @ w3)
    pivot = np.where(np.abs(pivot) < 1e-12 * size, 0.0, pivot) + 0.0      # no -0, no 1e-17
    where = "(" + ", ".join(f"{c:.6g}" for c in pivot) + ")"
    if d == 2:
        return f"rotation about {where}"
    slip = " with a slip along the axis" if abs(t @ w) > 1e-8 * np.abs(t).max() * \
        np.linalg.norm(w) else ""
    return f"rotation about {_direction(w)} through {where}{slip}"


def _node_components(K, n, d):
    """Connected parts of the nodes of a stiffness on interleaved dofs: the parts of the
    dof graph (K's own pattern, no copy), joined where one node's dofs fall in several.

    Returns
    -------
    ncomp : int
    label : (n,) int ndarray
    """
    _, dof_label = csgraph.connected_components(K.tocsr(), directed=False)
    labels = dof_label[:d * n].reshape(n, d)
    m = dof_label.max() + 1
    # join the parts of each node's dofs (a small graph over the parts)
    join = sp.csr_matrix((np.ones(n * (d - 1)), (np.repeat(labels[:, 0], d - 1),
                                                 labels[:, 1:].reshape(-1))), shape=(m, m))
    _, part = csgraph.connected_components(join, directed=False)
    kinds, label = np.unique(part[labels[:, 0]], return_inverse=True)
    return len(kinds), label


def free_rigid_motions(K: sp.spmatrix, points: np.ndarray, fixed: np.ndarray) -> list:
    """Rigid motions of each connected part of a 2-D or 3-D body left free by fixed dofs.

    Each part's free motions are named in a canonical basis: the free
    translations first (``translation in x``, ``translation along (...)``), then
    the rotations, each about an axis through the point nearest the part's
    centroid (2-D: ``rotation about (x, y)``; 3-D: ``rotation about z through
    (x, y, z)``).

    Parameters
    ----------
    K : sparse (d n, d n)
        Stiffness (its pattern tells which nodes hang together).
    points : (n, d) ndarray
        d = 2 or 3.
    fixed : (k,) int array
        Dofs with prescribed values.

    Returns
    -------
    list of str
        One description per free motion (empty when the system is regular).
    """
    n, d = np.shape(points)
    nrot = 1 if d == 2 else 3
    ncomp, label = _node_components(K, n, d)
    is_fixed = np.zeros(d * n, dtype=bool)
    is_fixed[fixed] = True
    free = []
    for part in range(ncomp):
        nodes = np.flatnonzero(label == part)
        pts = points[nodes]
        size = max(np.ptp(pts, axis=0).max(), 1e-300)
        modes = rigid_modes(pts / size)
        dofs = (d * nodes[:, None] + np.arange(d)).reshape(-1)
        rows = modes[is_fixed[dofs]]
        _, s, vt = np.linalg.svd(rows) if len(rows) else (None, np.zeros(0), np.eye(d + nrot))
        s = np.concatenate([s, np.zeros(d + nrot - len(s))])
        null = vt[s <= 1e-9 * max(s.max(initial=0.0), 1.0)]
        # rotations first in the echelon form: the rows left without a rotation are the
        # free translations, which are then taken out of the rotations
        basis = _rref(np.roll(null, nrot, axis=1), 1e-8)
        where = "" if ncomp == 1 else f" of the part holding node {nodes[0]} ({len(nodes)} nodes)"
        motions = [(row[nrot:], row[:nrot] / size) for row in basis]
        motions.sort(key=lambda m: bool(np.any(m[1])))
        free += [_describe(t, w, pts.mean(axis=0), size) + where for t, w in motions]
    return free


def solve_spd(A: sp.spmatrix | FreeBlock, b: np.ndarray, *, modes: np.ndarray | None = None,
              tol: float = 1e-10,
              method: Literal["auto", "direct", "amg"] = "auto",
              preconditioner: sp.spmatrix | Callable[..., np.ndarray] | None = None,
              smooth_with_matrix: bool = False, nodal: np.ndarray | None = None) -> np.ndarray:
    """Solve a symmetric positive definite system.

    Parameters
    ----------
    A : sparse (N, N) or FreeBlock
        A `cnem.solvers.condensation.FreeBlock` (the system on the free dofs) is
        multiplied on its stiffness; its entries are formed only for the direct
        solve, a hierarchy on it or smoothing with it.
    b : (N,) ndarray
    modes : (N, k) ndarray, optional
        Near-null space for smoothed aggregation (rigid motions).
    tol : float
        Relative residual for the iterative solver.
    method : {"auto", "direct", "amg"}
        ``"auto"``: direct up to `cnem.config.DIRECT_NNZ` non-zeros, pyamg + CG above.
    preconditioner : sparse (N, N), VCycle, or callable returning one, optional
        A sparser SPD matrix spectrally close to ``A`` (the P1 stiffness of the
        same nodes, `cnem.assembly.triangles`): the smoothed-aggregation
        hierarchy is built on it and preconditions CG on ``A``; or such a hierarchy
        already built (`cnem.solvers.multigrid.hierarchy` of that matrix and
        ``modes``), kept by a caller that solves several systems close to one
        another (Newton's corrections). Should CG not reach ``tol`` so, the
        hierarchy is built on ``A`` itself. A callable is called only when the
        iterative path is taken.
    smooth_with_matrix : bool
        With a preconditioner matrix: smooth the finest level with ``A`` itself,
        held once as its upper triangle (`FreeBlock.upper`), on which CG's products
        then run too (its coarse levels stay the preconditioner's), for matrices whose
        low-energy oscillating modes the preconditioner matrix lacks (plain SCNI
        against P1: 35 CG iterations instead of 246 at 100k nodes; stabilised 3-D
        SCNI: 59 instead of 291 at 10k nodes).
    nodal : (N,) bool array_like, optional
        The dofs of the nodal shape functions; the others are enrichment dofs.
        With enrichment dofs, CG is preconditioned by the sum of smoothed aggregation
        on the nodal block and a sparse LU of the enriched block (additive Schwarz:
        the enriched dofs are what makes a hierarchy built on ``A`` stall; 30 CG
        iterations instead of 2000 on a branch-enriched plate of 16k nodes).

    Returns
    -------
    (N,) ndarray

    Raises
    ------
    SolveError
        CG stalled (relative residual above ten times ``tol``) and the direct factor
        would not fit in `cnem.config.DIRECT_MEMORY`: the message says what to change.
    """
    A = A if isinstance(A, FreeBlock) else FreeBlock(A)
    if method == "auto":
        method = "direct" if A.nnz <= config.DIRECT_NNZ else "amg"
    if method == "direct":
        return spla.spsolve(A.matrix().tocsc(), b)
    check_choice("method", method, ("auto", "direct", "amg"))
    enriched = nodal is not None and not np.all(nodal)
    if enriched:
        nodal = np.asarray(nodal, dtype=bool)
        if nodal.shape != (A.shape[0],):
            raise InputError(f"nodal: expected a ({A.shape[0]},) boolean mask like the matrix's "
                             f"rows, received shape {nodal.shape}; mark the nodal dofs")
        x, rel, its = _schwarz_cg(A, b, nodal, modes, tol)
        if rel <= 10 * tol:
            return x
        return _fall_back(A, b, rel, its, tol, "smoothed aggregation on the nodal block + LU "
                          "of the enriched block")
    if callable(preconditioner) and not isinstance(preconditioner, VCycle):
        preconditioner = preconditioner()
    if preconditioner is not None:
        if preconditioner.shape != A.shape:
            raise InputError(f"preconditioner: expected shape {A.shape} like the matrix, "
                             f"received {preconditioner.shape}; build it on the same dofs")
        x, rel, its = _amg_cg(A, b, preconditioner, modes, tol, smooth_with_matrix)
        if rel <= 10 * tol:
            return x
        log.warning("pyamg on the preconditioner matrix: CG stopped at relative residual "
                    "%.2e after %d iterations; building the hierarchy on the matrix itself",
                    rel, its)
    x, rel, its = _amg_cg(A, b, A, modes, tol)
    if rel <= 10 * tol:
        return x
    return _fall_back(A, b, rel, its, tol, "pyamg")


def direct_factor_bytes(A: sp.spmatrix | FreeBlock) -> float:
    """Estimated bytes of SuperLU's factors of ``A`` (`cnem.config.DIRECT_FILL`: 12 bytes
    per stored entry, value and index)."""
    fill, unknowns, exponent = config.DIRECT_FILL
    return 12.0 * A.nnz * fill * (A.shape[0] / unknowns) ** exponent


def _memory_budget():
    """Bytes of `cnem.config.DIRECT_MEMORY`: itself above 1, else that fraction of the
    memory available now."""
    share = float(config.DIRECT_MEMORY)
    if share > 1.0:
        return share
    try:
        return share * os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):        # no sysconf: of a modest 4 GB
        return share * 4e9


def _fall_back(A, b, rel, its, tol, what):
    """The direct solve after a stalled CG when its factor fits in memory, else the
    `SolveError` saying what to change."""
    need, budget = direct_factor_bytes(A), _memory_budget()
    stalled = (f"{what} + CG stopped at relative residual {rel:.2e} after {its} iterations "
               f"(wanted {tol:.0e})")
    if need <= budget:
        log.warning("%s; solving directly instead (factor ~%.2g GB)", stalled, need / 1e9)
        return spla.spsolve(A.matrix().tocsc(), b)
    raise SolveError(f"{stalled}, and a direct solve would need about {need / 1e9:.2g} GB "
                     f"(budget {budget / 1e9:.2g} GB, cnem.config.DIRECT_MEMORY). Pass "
                     f"method='direct' if that memory is there (or raise DIRECT_MEMORY), a "
                     f"looser tol, a smaller enrichment radius, or fewer nodes")


def _schwarz_cg(A, b, nodal, modes, tol):
    """CG on ``A x = b`` preconditioned by smoothed aggregation on the ``nodal`` block
    plus a sparse LU of the other (enriched) block, the two added.

    Returns
    -------
    x : (N,) ndarray
    rel : float
    its : int
    """
    inner, outer = np.flatnonzero(nodal), np.flatnonzero(~nodal)
    amg = hierarchy(A.submatrix(inner), None if modes is None else modes[inner])
    lu = spla.splu(A.submatrix(outer).tocsc(), permc_spec="MMD_AT_PLUS_A",
                   diag_pivot_thresh=0.0, options=dict(SymmetricMode=True))

    def apply(r):
        r = np.asarray(r, dtype=float).reshape(-1)
        z = np.empty(len(r))
        z[inner] = amg.matvec(r[inner])
        z[outer] = lu.solve(r[outer])
        return z

    return _cg(A, b, spla.LinearOperator(A.shape, apply, dtype=float), tol,
               f"nodal block, {len(outer)} enriched dofs by LU")


def _cg(A, b, M, tol, label):
    """CG from zero with the preconditioner ``M`` (at most `cnem.config.CG_MAXITER`
    iterations): ``x``, relative residual, iterations."""
    its = [0]

    def count(_):
        its[0] += 1

    x, _ = spla.cg(A, b, rtol=tol, atol=0.0, maxiter=config.CG_MAXITER, M=M,
                   callback=count)
    norm = np.linalg.norm(b)
    rel = np.linalg.norm(b - A @ x) / norm if norm > 0 else 0.0
    log.info("pyamg (%s) + CG: %d iterations, relative residual %.2e", label, its[0], rel)
    return x, rel, its[0]


def _amg_cg(A, b, P, modes, tol, smooth_with_A=False):
    """CG on ``A x = b`` preconditioned by a smoothed-aggregation V-cycle built on ``P``,
    or by ``P`` itself if it is one (its finest level smoothed with ``A`` if
    ``smooth_with_A``), `cnem.solvers.multigrid`.

    Returns
    -------
    x : (N,) ndarray
    rel : float
        Final relative residual ``|b - A x| / |b|``.
    its : int
        Iterations.
    """
    same = P is A
    if isinstance(P, VCycle):
        cycle = P.smoothing_with(A.upper()) if smooth_with_A else P
    else:
        cycle = hierarchy(A.matrix() if same else P, modes,
                          top=A.upper() if smooth_with_A and not same else None)
    label = "hierarchy on " + ("the matrix" if same else "the preconditioner matrix" +
                               (", smoothing with the matrix" if smooth_with_A else ""))
    return _cg(A, b, cycle, tol, label)
