"""Forms in scikit-fem style, assembled over the SCNI integration cells.

A form is written once for one cell, in terms of `skfem.element.DiscreteField`
arguments (``u``, ``grad(u)``, ``v``, ``grad(v)``) and extras ``w`` (``w.x``
the cell centroids ``(dim, m)``, ``w.h`` a cell size ``(m,)`` (the square root of its area, cube root of its volume), plus any keyword
given to ``assemble``, passed through as it is: use ``basis.interpolate`` for
dof vectors). Since the form is (bi)linear in its field arguments, it is
evaluated with unit fields, one per field descriptor (value and smoothed
gradient components), which gives its coefficients in every cell at once;
the matrix is then ``sum_k A_k P_b^T D_ab P_a`` with the sparse descriptor
operators ``P`` of the basis.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp
from skfem.assembly.form.form import FormExtraParams

from .._parallel import work_chunks
from ..errors import FormError
from . import _sparse_kernels as SK

if TYPE_CHECKING:
    from typing import Any
    from .basis import CellBasis

__all__ = ["BilinearForm", "LinearForm", "Functional", "asm", "gradient_gram"]


def _extras(basis, kwargs):
    size = np.sqrt(basis.dx) if basis.dim == 2 else np.cbrt(basis.dx)
    w = FormExtraParams({"x": basis.x, "h": size})
    w.update(kwargs)
    return w


def _check_groups(groups, m, kwargs):
    """``groups`` as ``(m,)`` int64 and the number of groups: the length of the
    keyword arrays (one value per group; scalars allowed), else the largest group
    index plus one."""
    groups = np.asarray(groups)
    if groups.shape != (m,) or not np.issubdtype(groups.dtype, np.integer) or \
            (m and groups.min() < 0):
        raise FormError(f"groups: expected ({m},) non-negative integers, one per cell, "
                        f"received dtype {groups.dtype} shape {groups.shape}; pass a group "
                        f"index for every cell")
    shapes = {name: np.shape(value) for name, value in kwargs.items()}
    lengths = {shape[0] for shape in shapes.values() if len(shape) == 1}
    if any(len(shape) > 1 for shape in shapes.values()) or len(lengths) > 1:
        raise FormError(f"with groups, the keywords must hold one value per group (the same "
                        f"number for all) or a scalar, received shapes {shapes}; give 1-D "
                        f"arrays of one length")
    count = lengths.pop() if lengths else (int(groups.max()) + 1 if m else 0)
    if m and groups.max() >= count:
        raise FormError(f"groups: index {int(groups.max())} but the keywords hold {count} "
                        "values, one per group; expected indices below the number of values")
    return groups.astype(np.int64, copy=False), count


def _coefficients(values, m, what):
    """Broadcast a form's value to one coefficient per cell."""
    arr = np.asarray(values, dtype=float)
    try:
        return np.broadcast_to(arr, (m,))
    except ValueError:
        raise FormError(f"{what} must return one value per cell ({m},) or a scalar, "
                        f"received shape {arr.shape}; reduce over the other axes") from None


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

    def coefficients(self, basis: CellBasis, **kwargs: Any) -> np.ndarray:
        """``D[a][b]``: the form at unit descriptors ``u = e_a``, ``v = e_b``, per cell."""
        c = basis.descriptors
        out = [[np.zeros(len(basis.dx)) for _ in range(c)] for _ in range(c)]
        for a, b, value in self._nonzero_coefficients(basis, kwargs):
            out[a][b] = value
        return out

    def _nonzero_coefficients(self, basis, kwargs, groups=None):
        """``(a, b, D_ab)`` for the descriptor pairs where the form is not zero in
        every cell, one at a time (a large basis holds only one of them); with
        ``groups`` (their number, the keywords checked by `_check_groups`),
        evaluated once per group (see `assemble`)."""
        if groups is None:
            w, m = _extras(basis, kwargs), len(basis.dx)
        else:
            w, m = FormExtraParams(kwargs), groups
        units = basis.unit_fields()
        zero = basis.zero_field()
        if np.any(np.asarray(self.form(zero, zero, w)) != 0.0):
            raise FormError(f"form {self.__name__} is not bilinear: expected zero for u = v = 0, "
                            f"received a non-zero value; drop the terms without u or v")
        for a, ua in enumerate(units):
            for b, vb in enumerate(units):
                value = _coefficients(self.form(ua, vb, w), m, f"form {self.__name__}")
                if np.any(value != 0.0):
                    yield a, b, value

    def assemble(self, basis: CellBasis, *, groups: np.ndarray | None = None,
                 **kwargs: Any) -> sp.csr_matrix:
        """Sparse matrix ``(N, N)`` (CSR).

        Parameters
        ----------
        basis : CellBasis
            ``m`` integration cells.
        groups : (m,) int array_like, optional
            Cells whose form coefficients are the same (one material each, say):
            the form is evaluated once per group, ``w`` holding the keywords given
            per group (arrays ``(G,)`` or scalars) and neither ``w.x`` nor ``w.h``
            (which differ from cell to cell).
        **kwargs
            Extras ``w`` of the form, per cell (or per group).
        """
        m, g = len(basis.dx), basis.ncomp             # descriptors g, g + 1, ...: gradients
        ng = basis.descriptors - g
        if groups is None:
            group, count = np.arange(m), m
        else:
            group, count = _check_groups(groups, m, kwargs)
        # D_ab per group (per cell without groups), one descriptor pair at a time:
        # gradient pairs in one array, scaled by A_k where used
        grad_coeff = np.zeros((count, ng, ng))
        other, active = {}, set()
        for a, b, value in self._nonzero_coefficients(basis, kwargs,
                                                      None if groups is None else count):
            active.add((a, b))
            if a >= g and b >= g:
                grad_coeff[:, a - g, b - g] = value
            else:
                other[a, b] = basis.dx * value[group]
        if not active:
            return sp.csr_matrix((basis.N, basis.N))
        grads = basis.component_gradients() if basis.vector and not other else None
        if grads is not None:          # dim x dim node blocks from the scalar gradients
            return _gradient_blocks(grads, grad_coeff, group, basis.dx, basis.N)
        ops = basis.operators
        used = sorted({a for a, _ in active} | {b for _, b in active})
        weights = np.zeros((m, len(used), len(used)))
        for i, a in enumerate(used):
            for j, b in enumerate(used):
                if (a, b) in other:
                    weights[:, i, j] = other[a, b]
                elif a >= g and b >= g:
                    weights[:, i, j] = basis.dx * grad_coeff[group, a - g, b - g]
        return _weighted_gram([ops[d] for d in used], weights, basis.N)


def _weighted_gram(ops, weights, N):
    """``sum_k sum_ab P_b[k]^T weights[k, a, b] P_a[k]`` ``(N, N)`` CSR from descriptor
    operators ``ops`` (each ``(m, N)``) and ``weights (m, len(ops), len(ops))``."""
    stack = sp.vstack(ops, format="csr")
    t = stack.T.tocsr()
    indptr, indices, data = SK.weighted_gram(stack.indptr, stack.indices, stack.data,
                                             t.indptr, t.indices, t.data, weights,
                                             len(weights), N, work_chunks())
    return sp.csr_matrix((data, indices, indptr), shape=(N, N))


def gradient_gram(basis: CellBasis, coeff: np.ndarray) -> sp.csr_matrix:
    """``sum_k dx_k G_k^T coeff_k G_k`` for a vector basis, ``G_k`` the ``d^2`` gradient
    descriptors at cell ``k`` (``du_i/dx_j`` at ``d i + j``): the matrix of a form
    whose coefficients differ from cell to cell (a tangent of finite strain, say).

    Parameters
    ----------
    basis : CellBasis
        A vector basis, ``m`` cells.
    coeff : (m, d d, d d) ndarray
        ``coeff[k, a, b]``: trial descriptor ``a``, test descriptor ``b``.

    Returns
    -------
    scipy.sparse.csr_matrix, shape (N, N)
    """
    m, d = len(basis.dx), basis.ncomp
    coeff = np.ascontiguousarray(coeff, dtype=float)
    if not basis.vector or coeff.shape != (m, d * d, d * d):
        raise FormError(f"gradient_gram: expected a vector basis and coefficients of shape "
                        f"({m}, {d * d}, {d * d}), received a {'vector' if basis.vector else 'scalar'} "
                        f"basis and shape {coeff.shape}")
    grads = basis.component_gradients()
    if grads is not None:              # d x d node blocks from the scalar gradients
        return _gradient_blocks(grads, coeff, np.arange(m), basis.dx, basis.N)
    return _weighted_gram(basis.operators[d:], basis.dx[:, None, None] * coeff, basis.N)


def _gradient_blocks(grads, coeff, group, weight, N):
    """``K`` ``(N, N)`` CSR of a vector form that sees only gradients, by node blocks
    (`cnem.assembly._sparse_kernels.gradient_block_gram`, its 2-D specialisation, or
    `gradient_block_gram_nd`) from the scalar derivatives ``grads`` (one pattern)."""
    first, d = grads[0], len(grads)
    if d == 2:
        indptr, indices, data = SK.gradient_block_gram(first.indptr, first.indices, first.data,
                                                       grads[1].data, coeff, group, weight,
                                                       N // 2, work_chunks())
    else:
        stacked = np.stack([g.data for g in grads])
        indptr, indices, data = SK.gradient_block_gram_nd(first.indptr, first.indices, stacked,
                                                          coeff, group, weight, N // d,
                                                          work_chunks())
    return sp.csr_matrix((data, indices, indptr), shape=(N, N))


class LinearForm(_Form):
    """A linear form ``l(v, w)``; ``b[i] = l(phi_i)``."""

    def assemble(self, basis: CellBasis, **kwargs: Any) -> np.ndarray:
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

    def assemble(self, basis: CellBasis, **kwargs: Any) -> float:
        """``sum_k A_k f_k``."""
        return float(basis.dx @ self.elemental(basis, **kwargs))

    def elemental(self, basis: CellBasis, **kwargs: Any) -> np.ndarray:
        """``f`` in every cell, ``(m,)``."""
        return _coefficients(self.form(_extras(basis, kwargs)), len(basis.dx),
                             f"functional {self.__name__}")


def asm(form: BilinearForm | LinearForm | Functional, basis: CellBasis,
        **kwargs: Any) -> sp.csr_matrix | np.ndarray | float:
    """``form.assemble(basis, **kwargs)``, like `skfem.asm`."""
    return form.assemble(basis, **kwargs)
