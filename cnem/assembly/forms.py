"""Forms in scikit-fem style, assembled over the SCNI integration cells.

A form is written once for one cell, in terms of `skfem.element.DiscreteField`
arguments (``u``, ``grad(u)``, ``v``, ``grad(v)``) and extras ``w`` (``w.x``
the cell centroids ``(2, m)``, ``w.h`` a cell size ``(m,)``, plus any keyword
given to ``assemble``, passed through as it is: use ``basis.interpolate`` for
dof vectors). Since the form is (bi)linear in its field arguments, it is
evaluated with unit fields, one per field descriptor (value and smoothed
gradient components), which gives its coefficients in every cell at once;
the matrix is then ``sum_k A_k P_b^T D_ab P_a`` with the sparse descriptor
operators ``P`` of the basis.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from skfem.assembly.form.form import FormExtraParams

from ..spatial.rtree import work_chunks
from . import _sparse_kernels as SK

__all__ = ["BilinearForm", "LinearForm", "Functional", "asm"]


def _extras(basis, kwargs):
    w = FormExtraParams({"x": basis.x, "h": np.sqrt(basis.dx)})
    w.update(kwargs)
    return w


def _coefficients(values, m, what):
    """Broadcast a form's value to one coefficient per cell."""
    arr = np.asarray(values, dtype=float)
    try:
        return np.broadcast_to(arr, (m,))
    except ValueError:
        raise ValueError(f"{what} must return one value per cell ({m},) or a scalar, "
                         f"received shape {arr.shape}") from None


class _Form:
    """A form function with its name and docstring."""

    def __init__(self, form):
        self.form = form
        self.__doc__ = form.__doc__
        self.__name__ = getattr(form, "__name__", "form")

    def __call__(self, *args):
        return self.form(*args)


class BilinearForm(_Form):
    """A bilinear form ``a(u, v, w)``; ``A[i, j] = a(phi_j, phi_i)`` like scikit-fem.

    Examples
    --------
    >>> import cnem
    >>> from cnem.assembly import BilinearForm, CellBasis
    >>> from skfem.helpers import dot, grad
    >>> @BilinearForm
    ... def laplace(u, v, w):
    ...     return dot(grad(u), grad(v))
    >>> model = cnem.discretize(cnem.nodes.regular(cnem.geometry.rectangle(), 0.25))
    >>> A = laplace.assemble(CellBasis(model))
    >>> A.shape == (len(model.nodes), len(model.nodes))
    True
    """

    def coefficients(self, basis, **kwargs):
        """``D[a][b]``: the form at unit descriptors ``u = e_a``, ``v = e_b``, per cell."""
        w = _extras(basis, kwargs)
        m = len(basis.dx)
        units = basis.unit_fields()
        zero = basis.zero_field()
        if np.any(np.asarray(self.form(zero, zero, w)) != 0.0):
            raise ValueError(f"form {self.__name__} is not bilinear: it is non-zero for u = v = 0")
        return [[_coefficients(self.form(ua, vb, w), m, f"form {self.__name__}")
                 for vb in units] for ua in units]

    def assemble(self, basis, **kwargs):
        """Sparse matrix ``(N, N)`` (CSR)."""
        coeff = self.coefficients(basis, **kwargs)
        m, c = len(basis.dx), len(coeff)
        active = [(a, b) for a in range(c) for b in range(c) if np.any(coeff[a][b] != 0.0)]
        if not active:
            return sp.csr_matrix((basis.N, basis.N))
        only_gradients = basis.vector and min(min(ab) for ab in active) >= 2
        grads = basis.component_gradients() if only_gradients else None
        if grads is not None:          # 2 x 2 node blocks from the scalar gradients
            weights = np.zeros((m, 4, 4))
            for a, b in active:
                weights[:, a - 2, b - 2] = basis.dx * coeff[a][b]
            gx, gy = grads
            indptr, indices, data = SK.gradient_block_gram(gx.indptr, gx.indices, gx.data,
                                                           gy.data, weights, basis.N // 2,
                                                           work_chunks())
            return sp.csr_matrix((data, indices, indptr), shape=(basis.N, basis.N))
        ops = basis.operators
        used = sorted({a for a, _ in active} | {b for _, b in active})
        slot = {d: i for i, d in enumerate(used)}
        weights = np.zeros((m, len(used), len(used)))
        for a, b in active:
            weights[:, slot[a], slot[b]] = basis.dx * coeff[a][b]
        stack = sp.vstack([ops[d] for d in used], format="csr")
        t = stack.T.tocsr()
        indptr, indices, data = SK.weighted_gram(stack.indptr, stack.indices, stack.data,
                                                 t.indptr, t.indices, t.data, weights, m,
                                                 basis.N, work_chunks())
        return sp.csr_matrix((data, indices, indptr), shape=(basis.N, basis.N))


class LinearForm(_Form):
    """A linear form ``l(v, w)``; ``b[i] = l(phi_i)``."""

    def assemble(self, basis, **kwargs):
        """Dense vector ``(N,)``."""
        w = _extras(basis, kwargs)
        m = len(basis.dx)
        out = np.zeros(basis.N)
        for op, v in zip(basis.operators, basis.unit_fields()):
            coeff = _coefficients(self.form(v, w), m, f"form {self.__name__}")
            if np.any(coeff != 0.0):
                out += op.T @ (basis.dx * coeff)
        return out


class Functional(_Form):
    """A functional ``f(w)`` integrated over the cells (one value per cell)."""

    def assemble(self, basis, **kwargs):
        """``sum_k A_k f_k``."""
        return float(basis.dx @ self.elemental(basis, **kwargs))

    def elemental(self, basis, **kwargs):
        """``f`` in every cell, ``(m,)``."""
        return _coefficients(self.form(_extras(basis, kwargs)), len(basis.dx),
                             f"functional {self.__name__}")


def asm(form, basis, **kwargs):
    """``form.assemble(basis, **kwargs)``, like `skfem.asm`."""
    return form.assemble(basis, **kwargs)
