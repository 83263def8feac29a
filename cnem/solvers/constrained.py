"""The one constrained linear solve: ``K x = f`` with ``x[D]`` prescribed.

Every linear problem (C-NEM elasticity, the P1 anchor, a Newton step of
peridynamics) ends here: the supports are checked for free rigid motions (named in
the error), the system is condensed onto the free dofs (`free_system`, without a
copy of ``K``) and solved by `solve_spd` with the rigid motions as near-null space.

>>> import numpy as np, scipy.sparse as sp
>>> from cnem.solvers.constrained import solve_constrained
>>> K = sp.csr_matrix(np.array([[2.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 2.0]]))
>>> solve_constrained(K, np.zeros(3), [0, 2], [1.0, 3.0], points=None).round(12)
array([1., 2., 3.])
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp

from ..errors import InputError, SolveError
from .condensation import free_system
from .linsolve import free_rigid_motions, rigid_modes, solve_spd
from .symmetric import UpperTriangle

if TYPE_CHECKING:
    from typing import Callable

    from numpy.typing import ArrayLike

__all__ = ["check_supports", "solve_constrained"]


def check_supports(K: sp.spmatrix, points: np.ndarray, fixed: np.ndarray) -> None:
    """Raise `SolveError` when the fixed dofs leave a rigid motion free.

    Parameters
    ----------
    K : sparse (N, N) or UpperTriangle
        The stiffness (its pattern tells which nodes hang together); its first
        ``d n`` dofs are the nodes' (``d`` per node, node-major), any further ones
        (enrichment) are not looked at.
    points : (n, d) ndarray
        The nodes, d = 2 or 3.
    fixed : (k,) int array_like
        The prescribed dofs.

    Raises
    ------
    SolveError
        Naming each free motion and how to fix it.
    """
    points = np.asarray(points)
    nodal = points.size
    fixed = np.asarray(fixed, dtype=np.int64)
    if isinstance(K, UpperTriangle):           # its pattern, one triangle: the same parts
        K = sp.csr_matrix((K.data, K.indices, K.indptr), shape=K.shape)
    if nodal < K.shape[0]:
        K = K[:nodal, :nodal]
    free = free_rigid_motions(K, points, fixed[fixed < nodal])
    if free:
        raise SolveError("the system is singular: the Dirichlet conditions leave free the "
                         + "; ".join(free) + ". Fix them with add_dirichlet")


def solve_constrained(K: sp.spmatrix, f: np.ndarray, fixed: ArrayLike, values: ArrayLike, *,
                      points: np.ndarray | None, tol: float = 1e-10, method: str = "auto",
                      options: Callable[[np.ndarray], dict] | None = None,
                      check: bool = True) -> np.ndarray:
    """Solve ``K x = f`` on the free dofs with ``x[fixed] = values``.

    Parameters
    ----------
    K : sparse (N, N) or UpperTriangle
        Symmetric positive definite on the free dofs once the supports are fixed; its
        upper triangle alone is enough (`cnem.solvers.condensation.free_system`).
    f : (N,) ndarray
    fixed : (k,) int array_like
        Prescribed dofs (a later repeat of a dof wins).
    values : (k,) array_like
        Their values.
    points : (n, d) ndarray or None
        The nodes, whose dofs come first in ``K`` (``d`` per node): their rigid motions
        are checked (`check_supports`) and passed to the solver as near-null space.
        None for a system without nodes (no check, no near-null space).
    tol : float
        Relative residual of the iterative solver.
    method : {"auto", "direct", "amg"}
        See `solve_spd`.
    options : callable, optional
        ``options(free) -> dict`` of further keywords of `solve_spd` for the system on
        the free dofs ``free`` (a preconditioner matrix, which dofs are nodal, ...).
    check : bool
        Check the supports first (skip it when the caller has already, e.g. at each
        Newton step).

    Returns
    -------
    x : (N,) float64 ndarray

    Raises
    ------
    SolveError
        Free rigid motions (named), or a linear solve that fails.
    """
    N = K.shape[0]
    tol = float(tol)
    if not (np.isfinite(tol) and tol > 0):
        raise InputError(f"tol: expected a positive relative residual, received {tol}; pass "
                         f"e.g. 1e-10")
    fixed = np.asarray(fixed, dtype=np.int64).reshape(-1)
    values = np.asarray(values, dtype=float).reshape(-1)
    if fixed.shape != values.shape:
        raise InputError(f"expected one value per prescribed dof, received {len(fixed)} dofs "
                         f"and {len(values)} values")
    if check and points is not None:
        check_supports(K, points, fixed)
    x = np.zeros(N)
    x[fixed] = values
    A, b, free = free_system(K, f, x=x, D=fixed)
    modes = None
    if points is not None:
        nodal = rigid_modes(np.asarray(points))
        modes = np.zeros((N, nodal.shape[1]))
        modes[:len(nodal)] = nodal
        modes = modes[free]
    extra = options(free) if options is not None else {}
    x[free] = solve_spd(A, b, modes=modes, tol=tol, method=method, **extra)
    return x
