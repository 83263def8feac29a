"""``B~`` and ``K`` of an elasticity problem after a local model update.

``K`` is a sum over the integration cells (eq. 33; with the stabilisation over
their fan sub-cells, which lie inside them), so after `cnem.geometry.model_update.update`::

    K_new = P K_old P^T - K_old(dropped cells) + K_new(recomputed cells)

with ``P`` the renumbering of the nodes: only the cells the change reaches are
integrated, on the old model (to take their part out) and on the new one.
Entries whose cells all went cancel to round-off (about ``1e-16 |K|``) instead
of vanishing from the pattern; those of removed nodes are dropped.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp

from ..assembly import CellBasis
from ..assembly.subdivision import subdivide, tip_cells
from ..assembly.gradients import smoothed_gradient
from ..assembly.gradient_update import renumber_rows, updated_gradient
from .._parallel import one_thread
from ..errors import CNEMError

if TYPE_CHECKING:
    from typing import Any
    from ..assembly.forms import BilinearForm
    from ..assembly.scni import SmoothedGradient
    from ..geometry.model_update import ModelUpdate

__all__ = ["updated_operators", "cells_stiffness"]


def cells_stiffness(prob: Any, index: np.ndarray, gradient: SmoothedGradient,
                    form: BilinearForm) -> sp.spmatrix:
    """The part of ``prob.stiffness()`` that the cells ``index`` contribute.

    Parameters
    ----------
    prob : Elasticity
        Without enrichment.
    index : (c,) int array
        Cells of ``prob.model``.
    gradient : SmoothedGradient
        ``B~`` of those cells, ``(c, n)``.
    form : BilinearForm
        `cnem.elasticity.linear.elasticity_form`.

    Returns
    -------
    scipy.sparse.csr_matrix, shape (2 n, 2 n)
    """
    model = prob.model
    cells = model.cells.subset(index)
    (lam, mu), stabilization = prob.stiffness_moduli()
    n2 = 2 * len(model.nodes)
    K = sp.csr_matrix((n2, n2))
    if len(cells) == 0:
        return K
    if np.any(lam != 0.0) or np.any(mu != 0.0):
        basis = CellBasis(model, vector=True, cells=cells, gradient=gradient)
        K = K + form.assemble(basis, groups=cells.region, lam=lam, mu=mu)
    if stabilization is not None:
        sub, _ = subdivide(cells, model.nodes, node_apex=tip_cells(model)[index], mark_spokes=True)
        grad = smoothed_gradient(model, gauss=prob.gauss, cells=sub)
        fine = CellBasis(model, vector=True, cells=sub, gradient=grad)
        K = K + form.assemble(fine, groups=sub.region, lam=stabilization[0], mu=stabilization[1])
    return K.tocsr()


def updated_operators(old: Any, new: Any, change: ModelUpdate,
                      form: BilinearForm) -> tuple[SmoothedGradient, sp.spmatrix]:
    """``B~`` and ``K`` of ``new`` from those of ``old``, recomputing the changed cells only.

    Parameters
    ----------
    old : Elasticity
        The problem on ``change.old`` (its ``B~`` and ``K`` are computed if not yet).
    new : Elasticity
        The problem on ``change.model``: the same materials, plane, ``gauss`` and
        stabilisation, no enrichment.
    change : cnem.geometry.model_update.ModelUpdate
    form : BilinearForm
        The problem's bilinear form (`cnem.elasticity.linear.elasticity_form`).

    Returns
    -------
    gradient : SmoothedGradient
        ``B~`` of ``change.model``'s cells.
    stiffness : scipy.sparse.csr_matrix, shape (2 n, 2 n)

    Raises
    ------
    CNEMError
        The two problems differ in anything but their models, or use enrichment.
    """
    if old.model is not change.old or new.model is not change.model:
        raise CNEMError("updated_operators: old and new must be the problems on change.old "
                        "and change.model")
    if old.enrichment is not None or new.enrichment is not None:
        raise CNEMError("updated_operators: enriched problems are not updated locally; "
                        "build the new problem's operators from scratch")
    same = (np.array_equal(old.materials, new.materials) and old.plane == new.plane
            and old.gauss == new.gauss and old.stabilization == new.stabilization)
    if not same:
        raise CNEMError("updated_operators: the old and new problems differ in materials, plane, "
                        f"gauss or stabilisation ({old!r} against {new!r}); only the model may change")
    old_grad = old.basis.grad
    gradient = updated_gradient(old_grad, change, gauss=new.gauss)
    dropped = change.dropped_cells
    redo = change.changed_cells
    with one_thread():                  # a few cells
        removed = cells_stiffness(old, dropped, _rows(old_grad, dropped), form)
        added = cells_stiffness(new, redo, _rows(gradient, redo), form)
    dofs = _dof_map(change.new_node())
    n2 = 2 * len(change.model.nodes)
    old_dof = np.full(n2, -1, dtype=np.int64)
    old_dof[dofs[dofs >= 0]] = np.flatnonzero(dofs >= 0)

    def moved(K):
        return renumber_rows(K, old_dof, dofs, (n2, n2), drop=True)

    return gradient, moved(old.stiffness()) + (added - moved(removed))


def _rows(gradient, index):
    """``B~`` of the cells ``index`` alone."""
    from ..assembly.gradients import SmoothedGradient
    return SmoothedGradient(*(g[index] for g in gradient), points=0)


def _dof_map(new_node):
    """New dof of each old dof (interleaved ``[u_x, u_y]`` per node), -1 where none."""
    dofs = np.full(2 * len(new_node), -1, dtype=np.int64)
    have = new_node >= 0
    dofs[0::2][have] = 2 * new_node[have]
    dofs[1::2][have] = 2 * new_node[have] + 1
    return dofs
