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
from ..solvers.symmetric import UpperTriangle
from . import _sparse_kernels as SK

if TYPE_CHECKING:
    from typing import Any, Sequence
    from .basis import CellBasis

__all__ = ["BilinearForm", "LinearForm", "Functional", "asm", "gradient_gram",
           "GradientGram"]


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
        if basis.vector and not other and basis.component_gradients() is not None:
            return GradientGram([basis]).matrix(grad_coeff, group)    # dim x dim node blocks
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

    def assemble_over(self, bases: Sequence[CellBasis], *, groups: np.ndarray,
                      upper: bool = False, **kwargs: Any) -> sp.csr_matrix | UpperTriangle:
        """The matrix of a form that sees only gradients (``grad(u)``, ``grad(v)``) over
        the cells of several vector bases on the same dofs (cells and their sub-cells,
        say), in one pass (`GradientGram`), the bases' operators not copied into one.

        Parameters
        ----------
        bases : sequence of CellBasis
            Vector bases of one dimension on the same dofs, ``m_1, m_2, ...`` cells,
            taken in this order.
        groups : (m_1 + m_2 + ...,) int array_like
            The group of every cell, as in `assemble` (the form evaluated once per group).
        upper : bool
            Return the upper triangle alone (`cnem.solvers.symmetric.UpperTriangle`,
            half the work and bytes): for a symmetric form.
        **kwargs
            Extras ``w`` of the form, per group.

        Returns
        -------
        scipy.sparse.csr_matrix or UpperTriangle, shape (N, N)
        """
        bases = tuple(bases)
        if not bases:
            raise FormError("assemble_over: expected at least one basis, received none")
        first = bases[0]
        group, count = _check_groups(groups, sum(len(b.dx) for b in bases), kwargs)
        g = first.ncomp
        coeff = np.zeros((count, first.descriptors - g, first.descriptors - g))
        for a, b, value in self._nonzero_coefficients(first, kwargs, count):
            if a < g or b < g:
                raise FormError(f"assemble_over: form {self.__name__} uses the field values; "
                                f"expected a form of the gradients alone, use assemble")
            coeff[:, a - g, b - g] = value
        return GradientGram(bases, upper=upper).matrix(coeff, group)


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
    whose coefficients differ from cell to cell (a tangent of finite strain, say;
    `GradientGram` keeps its pattern for repeated calls).

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
    return GradientGram([basis]).matrix(coeff)


class GradientGram:
    """``sum_k dx_k G_k^T coeff_k G_k`` over the cells of one or more vector bases on the
    same dofs (cells and their sub-cells, say), in one pass on one pattern that is
    computed once: between calls only the coefficients change (Newton's tangents).

    Parameters
    ----------
    bases : sequence of CellBasis
        Vector bases of the same dimension and dofs, ``m_1, m_2, ...`` cells; their
        cells are taken in this order (``m = m_1 + m_2 + ...``).
    upper : bool
        `matrix` gives the upper triangle of the (symmetric) matrix, a
        `cnem.solvers.symmetric.UpperTriangle`, computed alone: half the work and the
        bytes. The coefficients must then make a symmetric matrix (``coeff[k]``
        symmetric).

    Examples
    --------
    >>> import numpy as np, cnem
    >>> from cnem.assembly import CellBasis
    >>> model = cnem.discretize(cnem.nodes.regular(cnem.geometry.rectangle(), 0.25))
    >>> basis = CellBasis(model, vector=True)
    >>> gram = GradientGram([basis, basis])
    >>> coeff = np.tile(np.eye(4), (2 * len(basis.dx), 1, 1))
    >>> twice = 2 * gradient_gram(basis, coeff[:len(basis.dx)])
    >>> bool(abs(gram.matrix(coeff) - twice).max() < 1e-12)
    True
    >>> upper = GradientGram([basis, basis], upper=True).matrix(coeff)
    >>> bool(abs(upper.tocsr() - twice).max() < 1e-12)
    True
    """

    def __init__(self, bases: Sequence[CellBasis], *, upper: bool = False):
        bases = tuple(bases)
        shapes = {(b.vector, b.ncomp, b.N) for b in bases}
        if not bases or len(shapes) != 1 or not bases[0].vector:
            raise FormError(f"GradientGram: expected vector bases of one dimension on the same "
                            f"dofs, received (vector, components, dofs) {sorted(shapes)}")
        self.d, self.N, self.upper = bases[0].ncomp, bases[0].N, bool(upper)
        self.size = sum(len(b.dx) for b in bases)
        self.weight = np.concatenate([b.dx for b in bases])
        grads = [b.component_gradients() for b in bases]
        if any(g is None for g in grads):          # no node blocks: by descriptors
            self._pattern = None
            self._ops = [sp.vstack(ops, format="csr") for ops in
                         zip(*(b.operators[self.d:] for b in bases))]
            return
        # each basis's axes share one pattern: the bases' patterns one after the other,
        # the axes' values in one (d, nnz) array (one copy of the gradients)
        self._ptr = np.concatenate([[0]] + [g[0].indptr[1:].astype(np.int64) + offset
                                            for g, offset in zip(grads, np.cumsum(
                                                [0] + [g[0].nnz for g in grads[:-1]]))])
        self._idx = np.concatenate([g[0].indices for g in grads])
        self._values = np.empty((self.d, len(self._idx)))
        at = 0
        for g in grads:
            for axis in range(self.d):
                self._values[axis, at:at + g[axis].nnz] = g[axis].data
            at += g[0].nnz
        del grads
        self._pattern = SK.gradient_block_pattern(self._ptr, self._idx, self.d, self.N // self.d,
                                                  work_chunks(), self.upper)

    def __repr__(self):
        return f"<GradientGram {self.d}-D, {self.size} cells, {self.N} dofs>"

    def matrix(self, coeff: np.ndarray, group: np.ndarray | None = None
               ) -> sp.csr_matrix | UpperTriangle:
        """The matrix of the coefficients ``coeff`` (``coeff[k, a, b]``: trial descriptor
        ``a``, test descriptor ``b``), per cell ``(m, d d, d d)`` or, with ``group``
        ``(m,)`` int, per group ``(G, d d, d d)`` (cell ``k`` takes
        ``coeff[group[k]]``); ``(N, N)`` CSR, or its upper triangle as an
        `cnem.solvers.symmetric.UpperTriangle` if the gram was made with ``upper``."""
        d, m = self.d, self.size
        coeff = np.ascontiguousarray(coeff, dtype=float)
        group = np.arange(m) if group is None else np.asarray(group, dtype=np.int64)
        if coeff.ndim != 3 or coeff.shape[1:] != (d * d, d * d) or group.shape != (m,) or \
                (m and (group.min() < 0 or group.max() >= len(coeff))):
            raise FormError(f"gradient_gram: expected coefficients of shape ({m}, {d * d}, "
                            f"{d * d}) (or one per group with a ({m},) group index), received "
                            f"shape {coeff.shape} with group shape {group.shape}")
        if self._pattern is None:
            K = _weighted_gram(self._ops, self.weight[:, None, None] * coeff[group], self.N)
            return UpperTriangle.from_matrix(K) if self.upper else K
        out_ptr, out_idx, indptr, indices, t_ptr, t_row, t_pos = self._pattern
        args = (coeff, group, self.weight, t_ptr, t_row, t_pos, indptr, indices, out_ptr,
                self.N // d, work_chunks())
        if self.upper:
            data = SK.gradient_block_values_nd(self._ptr, self._idx, self._values, *args, True)
            return UpperTriangle(out_ptr, out_idx.view(np.uint32), data)
        if d == 2:
            data = SK.gradient_block_values(self._ptr, self._idx, *self._values, *args)
        else:
            data = SK.gradient_block_values_nd(self._ptr, self._idx, self._values, *args)
        return sp.csr_matrix((data, out_idx, out_ptr), shape=(self.N, self.N))


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
