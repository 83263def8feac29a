"""`CellBasis`: the C-NEM shape functions seen at the SCNI integration cells."""

from __future__ import annotations

import copy
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp
from skfem.element import DiscreteField

from ..errors import ConditionError, InputError, check_array
from ..solvers.conditions import select_nodes
from .gradients import smoothed_gradient

if TYPE_CHECKING:
    from typing import Callable, Literal, Sequence
    from numpy.typing import ArrayLike
    from ..geometry.cells import Cells
    from ..geometry.model import Model
    from .gradients import SmoothedGradient

__all__ = ["CellBasis", "spread_component"]


def spread_component(op: sp.csr_matrix, component: int, ncomp: int) -> sp.csr_matrix:
    """Move the columns of a node operator ``(m, n)`` to the dofs of one
    component of an interleaved vector field ``(m, ncomp * n)``.

    The result shares ``op``'s values and row pointers (the components of a vector
    basis share one copy), so ``op`` must be in canonical format (`_canonical`): scipy
    sorts a non-canonical operand's indices in place (``abs``, ``+``, ...), which
    would reorder the values under the other components' unsorted indices."""
    op = op.tocsr()
    return sp.csr_matrix((op.data, op.indices * ncomp + component, op.indptr),
                         shape=(op.shape[0], op.shape[1] * ncomp))


def _canonical(op: sp.spmatrix) -> sp.csr_matrix:
    """``op`` as CSR in canonical format (sorted indices, no duplicates): itself when
    it already is, else a canonical copy (the input is left untouched).

    Parameters
    ----------
    op : scipy.sparse matrix, shape (m, n)

    Returns
    -------
    scipy.sparse.csr_matrix, shape (m, n)
    """
    op = op.tocsr()
    if not op.has_canonical_format:
        op = op.copy()
        op.sum_duplicates()
    return op


class CellBasis:
    """Shape functions of a model on its integration cells, scikit-fem style.

    At cell ``k`` a field has the value at the cell's node (nodal integration,
    the Kronecker delta property) and the smoothed gradient ``b~`` of eq.
    26-32. Vector fields interleave their dofs like scikit-fem and the paper
    (eq. 30): ``[u_x(0), u_y(0), u_x(1), ...]`` (``u_z`` after ``u_y`` in 3-D).
    The dimension ``dim`` (2 or 3) is that of the gradient (of the model's nodes).

    Parameters
    ----------
    model : Model
        ``n`` nodes, ``m`` integration cells.
    vector : bool
        ``dim`` components per node.
    gauss : int
        Gauss points per edge piece for ``b~`` (see `smoothed_gradient`).
    cells : Cells, optional
        Integration cells (default ``model.cells``; sub-cells for enrichment).
    gradient : SmoothedGradient, optional
        ``b~`` on ``cells`` when already computed (from a
        `cnem.assembly.gradients.GradientCache`, which keeps it); by default
        it is computed afresh (`smoothed_gradient`).
    extra : (gx, gy) or (gx, gy, gz) sparse (m, e), optional
        Smoothed gradients of ``e`` more functions that vanish at every node
        (enrichment); their dofs follow the nodes' (function ``n + i``).

    Attributes
    ----------
    dim : int
        2 or 3.
    ncomp : int
        Components per node: ``dim`` for a vector basis, 1 for a scalar one.
    N : int
        Number of dofs, ``ncomp nfun`` (``nfun = n`` without extra functions).
    dx : (m,) ndarray
        Quadrature weights: the cell areas (volumes in 3-D).
    x : (dim, m) ndarray
        Cell centroids (``w.x`` in forms).
    nodes : (dim, m) ndarray
        The node of each cell.
    """

    def __init__(self, model: Model, *, vector: bool = False, gauss: int = 2,
                 extra: tuple[sp.spmatrix, ...] | None = None, cells: Cells | None = None,
                 gradient: SmoothedGradient | None = None):
        cells = model.cells if cells is None else cells
        self.cells = cells
        self.grad = gradient if gradient is not None else \
            smoothed_gradient(model, gauss=gauss, cells=None if cells is model.cells else cells)
        m, n = len(cells.measure), len(model.nodes)
        value = sp.csr_matrix((np.ones(m), (np.arange(m), cells.node)), shape=(m, n))
        grads = tuple(self.grad)
        if extra is not None:           # functions that vanish at the nodes (enrichment)
            value = sp.hstack([value, sp.csr_matrix(extra[0].shape)], format="csr")
            grads = tuple(sp.hstack([g, e], format="csr") for g, e in zip(grads, extra, strict=True))
        self._setup(model, vector, (value,) + grads, cells.measure, cells.centroid().T,
                    model.nodes[cells.node].T)

    def _setup(self, model, vector, node_ops, dx, x, nodes):
        self.model = model
        self.vector = bool(vector)
        self.dim = len(node_ops) - 1
        if self.dim not in (2, 3):
            raise InputError(f"expected the derivatives along 2 or 3 axes, received "
                             f"{self.dim}; pass one gradient operator per axis")
        self.ncomp = self.dim if vector else 1
        self.dx, self.x, self.nodes = dx, x, nodes
        #: number of functions: the nodes' shape functions, then the extra ones
        self.nfun = node_ops[0].shape[1]
        self.N = self.ncomp * self.nfun
        self._node_ops = node_ops
        self._built = None                  # the operators as built from _node_ops

    @classmethod
    def from_operators(cls, model: Model, value: sp.spmatrix, gradient: Sequence[sp.spmatrix],
                       weights: np.ndarray, points: np.ndarray, *,
                       vector: bool = False) -> CellBasis:
        """A basis over other integration points, from the scalar operators of the
        functions there (linear triangles, say: `cnem.assembly.triangles`).

        Parameters
        ----------
        model : Model
            Its ``nodes`` (for `get_dofs`).
        value : sparse (q, nfun)
            Values of the functions at the points.
        gradient : sequence of ``dim`` sparse (q, nfun)
            Their x, y (and z) derivatives there.
        weights : (q,) ndarray
            Quadrature weights (``dx``).
        points : (q, dim) ndarray
            The points (``w.x``).
        vector : bool

        Returns
        -------
        CellBasis
            Without cells (``cells``, ``grad`` and ``nodes`` are None).
        """
        out = cls.__new__(cls)
        out.cells = out.grad = None
        x = np.asarray(points, dtype=float).T
        out._setup(model, vector, tuple(op.tocsr() for op in (value, *gradient)),
                   np.asarray(weights, dtype=float), x, None)
        return out

    def __repr__(self):
        kind = "vector" if self.vector else "scalar"
        return f"<CellBasis {self.dim}-D {kind}, {self.N} dofs, {len(self.dx)} cells>"

    @cached_property
    def operators(self) -> list[sp.spmatrix]:
        """Sparse operators from the dofs to the field descriptors at the cells.

        Returns
        -------
        list of scipy.sparse.csr_matrix, shape (m, N)
            ``(1 + dim) ncomp`` of them. Scalar: ``[value, d/dx, d/dy]`` (then
            ``d/dz`` in 3-D). Vector: ``[u_0, u_1, du_0/dx, du_0/dy, du_1/dx,
            du_1/dy]`` in 2-D, ``[u_0, u_1, u_2, du_0/dx, du_0/dy, du_0/dz, du_1/dx,
            ...]`` in 3-D (row-major ``grad[i, j] = du_i/dx_j``).
        """
        value, *grads = (_canonical(op) for op in self._node_ops)
        if not self.vector:
            self._built = [value, *grads]
        else:
            d = self.ncomp
            values = [spread_component(value, c, d) for c in range(d)]
            self._built = values + [spread_component(g, c, d) for c in range(d) for g in grads]
        return self._built

    def component_gradients(self) -> tuple[sp.csr_matrix, ...] | None:
        """The scalar derivatives ``(m, nfun)`` CSR along each axis behind the
        gradient operators of a vector basis, on one pattern (then forms that see
        only gradients are assembled by ``dim x dim`` node blocks): where the axes'
        patterns differ (3-D smoothed gradients with an exact zero along one axis),
        on their union with explicit zeros. None for a scalar basis or operators set
        otherwise (`at_points`, assignment)."""
        given = self.__dict__.get("operators", self._built)
        if not self.vector or given is not self._built:
            return None
        grads = [g.tocsr() for g in self._node_ops[1:]]
        first = grads[0]
        if all(np.array_equal(first.indptr, g.indptr) and np.array_equal(first.indices, g.indices)
               for g in grads[1:]):
            return tuple(grads)
        return _on_union_pattern(grads)

    def at_points(self, operators: Sequence[sp.spmatrix], weights: np.ndarray,
                  points: np.ndarray) -> CellBasis:
        """The same dofs seen at other integration points: a shallow copy with
        ``operators`` (``(q, N)`` each, in the order of `operators`), quadrature
        ``weights`` ``(q,)`` and ``points`` ``(q, dim)`` (``w.x``), for forms
        integrated by a point quadrature instead of over the cells."""
        out = copy.copy(self)
        out.__dict__["operators"] = [op.tocsr() for op in operators]
        out.dx, out.x = np.asarray(weights, dtype=float), np.asarray(points, dtype=float).T
        return out

    @property
    def descriptors(self) -> int:
        """Number of field descriptors per cell (values and derivatives),
        ``(1 + dim) ncomp``: the length of `operators`."""
        return (1 + self.dim) * self.ncomp

    def _field(self, flat):
        """A DiscreteField from descriptor values ``flat`` (descriptors, ...)."""
        d = self.dim
        if self.vector:
            return DiscreteField(flat[:d], flat[d:d + d * d].reshape((d, d) + flat.shape[1:]))
        return DiscreteField(flat[0], flat[1:1 + d])

    def unit_fields(self) -> list[DiscreteField]:
        """One DiscreteField per descriptor, with that descriptor 1 and the rest 0
        (a trailing axis of length 1 broadcasts against per-cell arrays ``(m,)``)."""
        eye = np.eye(self.descriptors)[:, :, None]
        return [self._field(row) for row in eye]

    def zero_field(self) -> DiscreteField:
        """A DiscreteField with every descriptor 0."""
        return self._field(np.zeros((self.descriptors, 1)))

    def interpolate(self, u: np.ndarray) -> DiscreteField:
        """A dof vector seen at the cells.

        Parameters
        ----------
        u : (N,) array_like

        Returns
        -------
        DiscreteField
            Value ``(m,)`` or ``(dim, m)``, ``grad`` ``(dim, m)`` or ``(dim, dim, m)``.
        """
        u = check_array("u", u, fix="pass one value per dof (e.g. from solve)")
        if u.shape != (self.N,):
            raise InputError(f"u: expected {self.N} dof values, received shape {u.shape}; "
                             f"pass one value per dof of this basis")
        return self._field(np.array([op @ u for op in self.operators]))

    def get_dofs(self, where: str | Callable[..., np.ndarray] | ArrayLike | None = None,
                 component: Literal[0, 1, 2] | None = None) -> np.ndarray:
        """Dofs of the nodes selected by ``where``.

        Parameters
        ----------
        where : None, str, callable ``(p, dim) -> (p,) bool``, or a boolean mask or index
            array over nodes. None: every node of the boundary; a str: the nodes on that
            named boundary (`Model.boundary_nodes`).
        component : {None, 0, 1} (2 too in 3-D)
            For a vector basis: one component, or all.

        Returns
        -------
        (k,) int64 ndarray
        """
        if where is None or isinstance(where, str):
            nodes = self.model.boundary_nodes(where)
        else:
            nodes = select_nodes(self.model.nodes, where)
        if not self.vector:
            if component not in (None, 0):
                raise ConditionError(f"component: a scalar basis has component 0 only, "
                                     f"received {component!r}; pass None or 0")
            return nodes
        d = self.ncomp
        if component is None:
            return np.sort(np.concatenate([d * nodes + c for c in range(d)]))
        if component not in range(d):
            names = {2: "0, 1 or None (both)", 3: "0, 1, 2 or None (all)"}[d]
            raise ConditionError(f"component: expected {names}, received {component!r}")
        return d * nodes + component


def _on_union_pattern(matrices: list[sp.csr_matrix]) -> tuple[sp.csr_matrix, ...]:
    """The same-shape CSR ``matrices`` with one pattern, the union of theirs (entries
    missing from a matrix stored as explicit zeros); sorted indices. The inputs are
    not touched (scipy sorts operands in place, and a basis's operators share their
    values with its node operators)."""
    matrices = [a.copy() for a in matrices]
    union = abs(matrices[0])
    for a in matrices[1:]:
        union = union + abs(a)
    union = union.tocsr()
    union.sort_indices()
    ncol = union.shape[1]
    rows = np.repeat(np.arange(union.shape[0], dtype=np.int64), np.diff(union.indptr))
    keys = rows * ncol + union.indices
    out = []
    for a in matrices:
        a = a.tocoo()
        a.sum_duplicates()
        a.eliminate_zeros()                 # every key left is in the union
        data = np.zeros(union.nnz)
        data[np.searchsorted(keys, a.row.astype(np.int64) * ncol + a.col)] = a.data
        out.append(sp.csr_matrix((data, union.indices.copy(), union.indptr.copy()),
                                 shape=union.shape))
    return tuple(out)

