"""`FbarOperator`: finite-strain SCNI without volumetric locking, by an energy-based
F-bar over patches of cells (total Lagrangian).

Every cell ``k`` keeps the isochoric part of its smoothed ``F~_k`` but takes the volume
change ``J^_k = sum_l M_kl J_l`` averaged over its patch (``J_l = det F~_l``, ``M`` the
patches' volume weights, rows summing to 1; `patch_average`):

    F^_k = (J^_k / J_k)^(1/d) F~_k,        Pi(u) = sum_k V_k W(F^_k)

(de Souza Neto, Peric, Dutko & Owen, IJSS 33, 1996, with the volume of a patch of
cells in place of the element centre's, as in their F-bar-patch method, IJNME 62,
2005). In plane strain ``F33 = 1`` stays and ``d = 2``, so ``det F^ = J^``. The
incompressibility constraint is then one per patch rather than one per cell. A
homogeneous deformation has equal ``J`` in every cell, so ``F^ = F~ = F``: the
patch test holds. As an energy, its tangent is symmetric. Writing
``phi_k(F, J^) = V_k W(F^)``, ``P^ = P(F^)``, ``A^ = A(F^)``, ``T = F^-T``,
``s = (J^/J)^(1/d)``, ``q = F^ : P^`` and ``R = P^ + A^ : F^``:

    d phi / dF        = V (s P^ - q/d T)
    d phi / dJ^       = V q / (d J^)
    d2 phi / dF dF    = V [s^2 A^ - s/d (R (x) T + T (x) R) + (R:F^)/d^2 T (x) T + q/d T_iL T_kJ]
    d2 phi / dF dJ^   = V / (d J^) (s R - (R:F^)/d T)
    d2 phi / dJ^ dJ^  = V / (d J^2) ((R:F^)/d - q)

and with ``dJ_l/dF_l = J_l T_l``, ``d2 J / dF_iJ dF_kL = J (T_iJ T_kL - T_iL T_kJ)``
the chain rule through ``J^ = M J`` gives the internal forces and the tangent as
sums of sparse products (`FbarOperator.evaluate`).

>>> import numpy as np, cnem
>>> from cnem.assembly import CellBasis
>>> model = cnem.discretize(cnem.nodes.irregular(cnem.geometry.rectangle(), 0.2, seed=0))
>>> basis = CellBasis(model, vector=True)
>>> group = np.zeros(len(basis.dx), dtype=np.int64)
>>> op = FbarOperator(basis, [cnem.material.NeoHookean(1.0, 2.0)], group,
...                   patch_average(basis, model.cells.node, group))
>>> F = np.array([[1.2, 0.1], [0.0, 0.9]])
>>> u = (model.nodes @ (F - np.eye(2)).T).reshape(-1)           # homogeneous
>>> bool(np.allclose(op.constitutive_gradient(u), F))
True
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp

from ..errors import InputError
from .finite_strain import FiniteStrainOperator

if TYPE_CHECKING:
    from typing import Sequence

    from ..assembly.basis import CellBasis
    from ..material import Hyperelastic

__all__ = ["FbarOperator", "patch_average"]


def patch_average(basis: CellBasis, owner: np.ndarray, group: np.ndarray) -> sp.csr_matrix:
    """The volume averages over patches of cells: ``M (m, m)`` with
    ``M_kl = V_l / sum_{l' in p(k)} V_l'`` for the cells ``l`` of cell ``k``'s patch
    ``p(k)``.

    The patches are disjoint and built by aggregation: cells are taken in order;
    a cell not yet in a patch starts one with those of its neighbours (the cells
    whose nodes its smoothed gradient sees, in the same group) not yet in one. Their
    size (about 4 cells in 2-D) leaves about ``2 x 4`` dofs per volume constraint.

    Parameters
    ----------
    basis : CellBasis
        ``m`` cells; its gradient operators give the neighbours.
    owner : (m,) int array_like
        The node of every cell.
    group : (m,) int array_like
        The material group of every cell; patches do not mix groups.

    Returns
    -------
    scipy.sparse.csr_matrix, shape (m, m)
        Rows summing to 1.
    """
    m = len(basis.dx)
    owner, group = np.asarray(owner), np.asarray(group)
    if owner.shape != (m,) or group.shape != (m,):
        raise InputError(f"patch_average: expected owner and group of shape ({m},), one per "
                         f"cell, received {owner.shape} and {group.shape}")
    d = basis.dim
    support = sum(abs(op) for op in basis.operators[d:2 * d])    # d u_0 / d x_j: the nodes seen
    node_cells = sp.csr_matrix((np.ones(m), (owner, np.arange(m))),
                               shape=(basis.nfun, m))
    sees = (sp.csr_matrix(support[:, ::basis.ncomp] != 0) @ node_cells).tocsr()
    patch = np.full(m, -1)
    count = 0
    for k in range(m):
        if patch[k] >= 0:
            continue
        near = sees.indices[sees.indptr[k]:sees.indptr[k + 1]]
        near = near[(patch[near] < 0) & (group[near] == group[k])]
        patch[k] = patch[near] = count
        count += 1
    volume = np.bincount(patch, weights=basis.dx, minlength=count)
    same = sp.csr_matrix((np.ones(m), (patch, np.arange(m))), shape=(count, m))
    return (sp.diags(1.0 / volume[patch]) @ same.T @ same @ sp.diags(basis.dx)).tocsr()


class FbarOperator(FiniteStrainOperator):
    """Energy, internal forces and tangent of hyperelastic cells whose volume change is
    averaged over patches (`cnem.elasticity.fbar`).

    Parameters
    ----------
    basis : CellBasis
        A vector basis, ``m`` cells, ``N`` dofs.
    materials : sequence of cnem.material.Hyperelastic
        One law per group of cells.
    group : (m,) int array_like
        The law of every cell.
    average : scipy.sparse matrix (m, m)
        ``J^ = average @ J``: rows of non-negative weights summing to 1
        (`patch_average`).
    """

    def __init__(self, basis: CellBasis, materials: Sequence[Hyperelastic], group: np.ndarray,
                 average: sp.spmatrix):
        super().__init__(basis, materials, group)
        m = len(basis.dx)
        average = sp.csr_matrix(average)
        if average.shape != (m, m) or not np.allclose(average.sum(axis=1), 1.0, rtol=0,
                                                      atol=1e-12) or (average.data < 0).any():
            raise InputError(f"average: expected an ({m}, {m}) matrix of non-negative weights "
                             f"with rows summing to 1 (patch_average), received shape "
                             f"{average.shape}")
        self.average = average

    def __repr__(self):
        return (f"<FbarOperator {self.dim}-D, {len(self.basis.dx)} cells, "
                f"{len(self.materials)} material(s)>")

    def _kinematics(self, u):
        F = self.deformation_gradient(u)
        with np.errstate(invalid="ignore", divide="ignore"):
            J = np.linalg.det(F)
            J_bar = self.average @ J
            s = (J_bar / J) ** (1.0 / self.dim)
        return F, J, J_bar, s

    def constitutive_gradient(self, u: np.ndarray) -> np.ndarray:
        """``F^ = (J^ / J)^(1/d) F~`` per cell, ``(m, d, d)``, from dofs ``u (N,)``."""
        F, _, _, s = self._kinematics(u)
        return s[:, None, None] * F

    def energy(self, u: np.ndarray) -> float:
        """``Pi(u) = sum_k V_k W(F^_k)``."""
        W, _, _ = self.laws(self.constitutive_gradient(u), tangent=False)
        return float(self.basis.dx @ W)

    def _to_dofs(self, per_cell):
        """``sum_k G_k^T x_k`` ``(N,)``, or ``(N, m)`` sparse for ``x (m, d, d)`` placed in
        column ``k`` when ``per_cell`` is a tuple ``(x,)``."""
        d = self.dim
        if isinstance(per_cell, tuple):
            x = per_cell[0].reshape(-1, d * d)
            return sum(op.T @ sp.diags(x[:, a]) for a, op in enumerate(self._gradient_ops)).tocsr()
        x = per_cell.reshape(-1, d * d)
        return sum(op.T @ x[:, a] for a, op in enumerate(self._gradient_ops))

    def local_evaluate(self, u: np.ndarray, tangent: bool = True
                       ) -> tuple[np.ndarray, np.ndarray | None, sp.spmatrix | None]:
        """Internal forces ``(N,)`` and (with ``tangent``) their symmetric derivative in
        parts (`FiniteStrainOperator.local_evaluate`): the cells' coefficients at fixed
        patch volumes, and the coupling through the patch volumes ``(N, N)``."""
        d, V = self.dim, self.basis.dx
        F, J, J_bar, s = self._kinematics(u)
        Fb = s[:, None, None] * F
        _, P, A = self.laws(Fb, tangent=tangent)
        with np.errstate(invalid="ignore", divide="ignore"):
            T = np.swapaxes(np.linalg.inv(F), 1, 2)
        q = np.einsum("kij,kij->k", Fb, P)
        dphi_dJbar = V * q / (d * J_bar)
        y = self.average.T @ dphi_dJbar                          # d Pi / d J_l through J^
        force = (V * s)[:, None, None] * P + ((y * J - V * q / d))[:, None, None] * T
        f = self._to_dofs(force)
        if not tangent:
            return f, None, None
        R = P + np.einsum("kiJlL,klL->kiJ", A, Fb)
        RF = np.einsum("kij,kij->k", R, Fb)
        outer = np.einsum("kij,klm->kijlm", T, T)                 # T_iJ T_kL
        cross = np.einsum("kiL,klJ->kiJlL", T, T)                 # T_iL T_kJ
        D = (V * s * s)[:, None, None, None, None] * A \
            - (V * s / d)[:, None, None, None, None] * (np.einsum("kij,klm->kijlm", R, T)
                                                        + np.einsum("kij,klm->kijlm", T, R)) \
            + (V * RF / d ** 2 + y * J)[:, None, None, None, None] * outer \
            + (V * q / d - y * J)[:, None, None, None, None] * cross
        local = np.swapaxes(D.reshape(-1, d * d, d * d), 1, 2) / np.where(V > 0, V, 1.0)[:, None, None]
        mixed = (V / (d * J_bar))[:, None, None] * (s[:, None, None] * R
                                                   - (RF / d)[:, None, None] * T)
        curvature = V / (d * J_bar ** 2) * (RF / d - q)
        Lc = self._to_dofs((J[:, None, None] * T,))               # d J_l / d u, (N, m)
        Lb = self._to_dofs((mixed,))
        M = self.average
        coupling = Lb @ M @ Lc.T
        return f, local, coupling + coupling.T + Lc @ (M.T @ sp.diags(curvature) @ M) @ Lc.T
