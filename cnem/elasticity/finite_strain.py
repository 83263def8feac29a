"""`FiniteStrainOperator`: internal forces and consistent tangent of a hyperelastic body
on SCNI cells (total Lagrangian).

Per integration cell ``k`` of reference volume ``V_k`` the smoothed deformation gradient
is ``F~_k = I + grad~ u`` (the smoothed gradients ``B~`` of the reference configuration,
as in linear SCNI: a linear displacement gives its exact ``F`` in every cell). The energy
``Pi(u) = sum_k V_k W(F~_k)`` gives the internal forces and tangent

    f_int = sum_k V_k B~_k^T P(F~_k),      K = sum_k V_k B~_k^T A(F~_k) B~_k,

``P = dW/dF`` and ``A = dP/dF`` flattened row-major (``(i, J) -> d i + J``, the order of
the basis' gradient descriptors). Both are formed for every cell at once, ``P`` as
``(m, d d)`` and ``A`` as ``(m, d d, d d)``, then summed by sparse products.

>>> import numpy as np, cnem
>>> from cnem.assembly import CellBasis
>>> model = cnem.discretize(cnem.nodes.irregular(cnem.geometry.rectangle(), 0.2, seed=0))
>>> basis = CellBasis(model, vector=True)
>>> op = FiniteStrainOperator(basis, [cnem.material.NeoHookean(1.0, 2.0)],
...                           np.zeros(len(basis.dx), dtype=np.int64))
>>> F = np.array([[1.2, 0.1], [0.0, 0.9]])
>>> u = (model.nodes @ (F - np.eye(2)).T).reshape(-1)           # homogeneous
>>> bool(np.allclose(op.deformation_gradient(u), F))
True
"""

from __future__ import annotations

from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np

from ..assembly.forms import GradientGram
from ..errors import InputError, MaterialError
from ..material import Hyperelastic

if TYPE_CHECKING:
    from typing import Sequence

    import scipy.sparse as sp

    from ..assembly.basis import CellBasis

__all__ = ["FiniteStrainOperator", "EnergySum"]


class FiniteStrainOperator:
    """The energy, internal forces and tangent of hyperelastic cells of a vector basis.

    Parameters
    ----------
    basis : CellBasis
        A vector basis (`cnem.assembly.CellBasis`, 2-D or 3-D), ``m`` cells, ``N`` dofs.
    materials : sequence of cnem.material.Hyperelastic
        One law per group of cells.
    group : (m,) int array_like
        The law of every cell (its region).

    Attributes
    ----------
    dim : int
    """

    def __init__(self, basis: CellBasis, materials: Sequence[Hyperelastic], group: np.ndarray):
        if not basis.vector:
            raise InputError("FiniteStrainOperator: expected a vector basis (CellBasis(..., "
                             "vector=True)), received a scalar one")
        materials = tuple(materials)
        other = [type(m).__name__ for m in materials if not isinstance(m, Hyperelastic)]
        if other or not materials:
            raise MaterialError(f"materials: expected hyperelastic laws (cnem.material.NeoHookean, "
                                f"SaintVenantKirchhoff), received {', '.join(other) or 'none'}")
        group = np.asarray(group)
        m = len(basis.dx)
        if group.shape != (m,) or not np.issubdtype(group.dtype, np.integer) or \
                (m and (group.min() < 0 or group.max() >= len(materials))):
            raise InputError(f"group: expected ({m},) integers in [0, {len(materials)}), one "
                             f"material index per cell, received dtype {group.dtype} shape "
                             f"{group.shape}")
        self.basis, self.materials, self.dim = basis, materials, basis.dim
        self._members = [np.flatnonzero(group == g) for g in range(len(materials))]
        self._gradient_ops = basis.operators[self.dim:]

    def __repr__(self):
        return (f"<FiniteStrainOperator {self.dim}-D, {len(self.basis.dx)} cells, "
                f"{len(self.materials)} material(s)>")

    def deformation_gradient(self, u: np.ndarray) -> np.ndarray:
        """``F~ = I + grad~ u`` per cell, ``(m, d, d)``, from dofs ``u (N,)``."""
        d = self.dim
        grad = np.stack([op @ u for op in self._gradient_ops], axis=1)
        return grad.reshape(-1, d, d) + np.eye(d)

    def constitutive_gradient(self, u: np.ndarray) -> np.ndarray:
        """The ``F`` at which each cell's law is evaluated, ``(m, d, d)``: ``F~`` here
        (`cnem.elasticity.fbar.FbarOperator` changes its volume)."""
        return self.deformation_gradient(u)

    def laws(self, F: np.ndarray, *, tangent: bool = True
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """Energy density ``(m,)``, stress ``P (m, d, d)`` and tangent ``A (m, d, d, d, d)``
        (None without ``tangent``) of every cell's law at ``F (m, d, d)``."""
        m, d = len(F), self.dim
        W, P = np.empty(m), np.empty((m, d, d))
        A = np.empty((m, d, d, d, d)) if tangent else None
        for members, law in zip(self._members, self.materials):
            if members.size:
                W[members], P[members], a = law.evaluate(F[members], tangent=tangent)
                if tangent:
                    A[members] = a
        return W, P, A

    def energy(self, u: np.ndarray) -> float:
        """``Pi(u) = sum_k V_k W(F~_k)``."""
        W, _, _ = self.laws(self.deformation_gradient(u), tangent=False)
        return float(self.basis.dx @ W)

    @cached_property
    def gram(self) -> GradientGram:
        """The tangent's assembly on the basis's cells, its pattern kept
        (`cnem.assembly.forms.GradientGram`)."""
        return GradientGram([self.basis])

    def evaluate(self, u: np.ndarray, tangent: bool = True
                 ) -> tuple[np.ndarray, sp.csr_matrix | None]:
        """Internal forces and (with ``tangent``) their derivative: the ``evaluate`` of
        `cnem.solvers.newton.newton`.

        Parameters
        ----------
        u : (N,) ndarray
        tangent : bool

        Returns
        -------
        f_int : (N,) ndarray
        K : scipy.sparse.csr_matrix (N, N), or None
            Symmetric.
        """
        f, coeff, extra = self.local_evaluate(u, tangent)
        if not tangent:
            return f, None
        K = self.gram.matrix(coeff)
        return f, K if extra is None else (K + extra).tocsr()

    def local_evaluate(self, u: np.ndarray, tangent: bool = True
                       ) -> tuple[np.ndarray, np.ndarray | None, sp.spmatrix | None]:
        """`evaluate` (the same ``u (N,)`` and ``tangent``) with the tangent left in
        parts: ``K = gram.matrix(coeff) + extra``.

        Returns
        -------
        f_int : (N,) ndarray
        coeff : (m, d d, d d) ndarray, or None
            Per cell, ``coeff[k, a, b]`` for trial descriptor ``a`` and test ``b``
            (`cnem.assembly.forms.GradientGram`); None without ``tangent``.
        extra : scipy.sparse matrix (N, N), or None
            What the tangent holds besides (None here; the patch coupling of
            `cnem.elasticity.fbar.FbarOperator`).
        """
        d = self.dim
        _, P, A = self.laws(self.deformation_gradient(u), tangent=tangent)
        weighted = self.basis.dx[:, None] * P.reshape(-1, d * d)
        f = np.zeros(self.basis.N)
        for a, op in enumerate(self._gradient_ops):
            f += op.T @ weighted[:, a]
        if not tangent:
            return f, None, None
        # the kernel's coeff[k, a, b] has trial descriptor a and test b: A's transpose
        return f, np.swapaxes(A.reshape(-1, d * d, d * d), 1, 2), None


class EnergySum:
    """A weighted sum of cell energies, ``Pi(u) = sum_t w_t Pi_t(u)``, with their
    internal forces and tangents summed alike: a physical energy plus a stabilisation
    (see `cnem.Hyperelasticity`).

    Parameters
    ----------
    terms : sequence of (float, FiniteStrainOperator)
        Weights and operators on the same dofs.
    """

    def __init__(self, terms: Sequence[tuple[float, FiniteStrainOperator]]):
        self.terms = tuple((float(w), op) for w, op in terms)
        sizes = {op.basis.N for _, op in self.terms}
        if len(sizes) != 1:
            raise InputError(f"EnergySum: expected operators on the same dofs, received "
                             f"{sorted(sizes)} dofs")
        self._bases, self._basis_of_term = [], []       # distinct bases, by identity
        for _, op in self.terms:
            known = [b for b, basis in enumerate(self._bases) if basis is op.basis]
            if not known:
                self._bases.append(op.basis)
            self._basis_of_term.append(known[0] if known else len(self._bases) - 1)

    def __repr__(self):
        return f"<EnergySum of {len(self.terms)} terms>"

    def energy(self, u: np.ndarray) -> float:
        """``sum_t w_t Pi_t(u)``."""
        return sum(w * op.energy(u) for w, op in self.terms)

    @cached_property
    def gram(self) -> GradientGram:
        """The summed tangent's assembly over the cells of the terms' distinct bases,
        in one pass on one pattern (`cnem.assembly.forms.GradientGram`)."""
        return GradientGram(self._bases)

    def evaluate(self, u: np.ndarray, tangent: bool = True
                 ) -> tuple[np.ndarray, sp.csr_matrix | None]:
        """Summed internal forces ``(N,)`` and tangent (see `FiniteStrainOperator.evaluate`):
        the terms' coefficients are summed per basis (the cells' law and the cells'
        stabilisation on one basis) and assembled in one pass."""
        f, coeff, extras = 0.0, [None] * len(self._bases), []
        for (w, op), b in zip(self.terms, self._basis_of_term):
            f_t, c_t, extra = op.local_evaluate(u, tangent)
            f = f + w * f_t
            if tangent:
                coeff[b] = w * c_t if coeff[b] is None else coeff[b] + w * c_t
                if extra is not None:
                    extras.append(w * extra)
        if not tangent:
            return f, None
        K = self.gram.matrix(np.concatenate(coeff))
        return f, sum(extras, K).tocsr() if extras else K
