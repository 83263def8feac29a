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

from typing import TYPE_CHECKING

import numpy as np

from ..assembly.forms import gradient_gram
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
        d = self.dim
        _, P, A = self.laws(self.deformation_gradient(u), tangent=tangent)
        weighted = self.basis.dx[:, None] * P.reshape(-1, d * d)
        f = np.zeros(self.basis.N)
        for a, op in enumerate(self._gradient_ops):
            f += op.T @ weighted[:, a]
        if not tangent:
            return f, None
        # the kernel's coeff[k, a, b] has trial descriptor a and test b: A's transpose
        coeff = np.swapaxes(A.reshape(-1, d * d, d * d), 1, 2)
        return f, gradient_gram(self.basis, coeff)


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

    def __repr__(self):
        return f"<EnergySum of {len(self.terms)} terms>"

    def energy(self, u: np.ndarray) -> float:
        """``sum_t w_t Pi_t(u)``."""
        return sum(w * op.energy(u) for w, op in self.terms)

    def evaluate(self, u: np.ndarray, tangent: bool = True
                 ) -> tuple[np.ndarray, sp.csr_matrix | None]:
        """Summed internal forces ``(N,)`` and tangent (see `FiniteStrainOperator.evaluate`)."""
        f, K = 0.0, None
        for w, op in self.terms:
            f_t, K_t = op.evaluate(u, tangent)
            f = f + w * f_t
            if tangent:
                K = w * K_t if K is None else K + w * K_t
        return f, K
