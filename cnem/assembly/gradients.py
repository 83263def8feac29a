"""The SCNI smoothed gradient operator ``B~`` (C-NEM paper §4.2, eq. 26-32; the
operator itself is `SmoothedGradient`, in `.smoothed_gradient`), and
`GradientCache`, the owner that computes it once for a model."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .._aliases import renamed_attributes
from ..errors import GeometryError
from .edge_quadrature import boundary_quadratures, check_gauss
from .facet_gradients import cell_gradient_3d, model_interface_pieces
from .pyramid_cells import sub_cell_gradient_3d
from .fan_quadrature import fan_quadratures
from .passes import cell_runs, gradients_in_passes
from .smoothed_gradient import SmoothedGradient
from .subdivision import subdivide, tip_cells

if TYPE_CHECKING:
    from .interface_facets import InterfacePieces
    from ..geometry.model import Cells, Model

__all__ = ["SmoothedGradient", "GradientCache", "smoothed_gradient", "fan_gradient"]


def smoothed_gradient(model: Model, *, gauss: int = 2, cells: Cells | None = None
                      ) -> SmoothedGradient:
    """The smoothed gradient operator ``B~`` of a model's cells, computed afresh
    (`GradientCache` keeps it for the next users).

    Parameters
    ----------
    model : Model
        ``n`` nodes, ``m`` integration cells.
    gauss : int
        Gauss points on each piece of a cell edge between circumcircle
        crossings (in 3-D each facet takes one point, see
        `cnem.assembly.facet_gradients`). The patch test holds for any value; more points make
        ``b~`` converge to the exact boundary integrals (see docs/elasticity.md).
    cells : Cells, optional
        Integration cells other than ``model.cells``.

    Returns
    -------
    SmoothedGradient
        ``x, y`` sparse ``(m, n)`` (``dim`` 2).
    """
    gauss = check_gauss(gauss)
    every = model.cells if cells is None else cells
    if model.nodes.shape[1] == 3:
        return cell_gradient_3d(model, every)
    runs = cell_runs(model, every)
    (grad,), points = gradients_in_passes(
        model, [every], lambda sets, _: boundary_quadratures(model, sets, gauss=gauss),
        None if runs is None else [[run] for run in runs])
    return SmoothedGradient(*grad, points=points)


def fan_gradient(model: Model, *, gauss: int = 2) -> tuple[Cells, SmoothedGradient]:
    """Smoothed gradients on the fan sub-cells of the model's cells, computed afresh
    (`GradientCache.fan` computes them with the cells' and keeps them).

    The sub-cells (`cnem.assembly.subdivision.subdivide`, spokes marked; crack-tip
    cells fanned from their node) share every edge but their spokes with their
    cells: only the spokes add points to the cells' (`fan_quadratures`).

    Parameters
    ----------
    model : Model
    gauss : int
        As in `smoothed_gradient`.

    Returns
    -------
    sub : Cells
        ``s`` fan sub-cells.
    grad : SmoothedGradient
        ``x, y`` sparse ``(s, n)``.
    """
    _, sub, grad = _fan_gradients(model, check_gauss(gauss), with_cells=False)
    return sub, grad


def _fan_gradients(model, gauss, with_cells, interface=None):
    """``(cells' B~ or None, fan sub-cells, their B~)``, the two from one set of
    points in the same passes (the sub-cells go with their cells' runs); in 3-D from
    one set of interface pieces (``interface``, else computed here)."""
    if model.nodes.shape[1] == 3:
        if interface is None:
            interface = model_interface_pieces(model, model.cells)
        sub, grad, of_cells = sub_cell_gradient_3d(model, interface, with_cells=with_cells)
        return of_cells, sub, grad
    cells = model.cells
    sub, parent = subdivide(cells, model.nodes, node_apex=tip_cells(model), mark_spokes=True)
    runs = cell_runs(model, cells)
    passes = None
    if runs is not None:
        run_of = np.empty(len(cells), dtype=np.int64)
        place = np.empty(len(cells), dtype=np.int64)       # of a cell in its run
        for r, run in enumerate(runs):
            run_of[run], place[run] = r, np.arange(len(run))
        key_of = run_of[parent]
        sub_order = np.argsort(key_of, kind="stable")
        cuts = np.searchsorted(key_of[sub_order], np.arange(len(runs) + 1))
        passes = [[run, sub_order[cuts[r]:cuts[r + 1]]] for r, run in enumerate(runs)]

    def quadratures(sets, index):
        local = parent if index is None else place[parent[index[1]]]
        return fan_quadratures(model, *sets, local, gauss=gauss)

    (of_cells, of_sub), points = gradients_in_passes(model, [cells, sub], quadratures, passes,
                                                     wanted=[with_cells, True])
    return (None if of_cells is None else SmoothedGradient(*of_cells, points=points),
            sub, SmoothedGradient(*of_sub, points=points))


class GradientCache:
    """The smoothed gradients of one model at one Gauss order, each computed when
    first asked for and kept: the owner of ``B~`` for everyone who needs it.

    Give one object to every user on the model (`CellBasis` through
    ``gradient=``, `cnem.Elasticity` through ``gradients=``) and nothing is
    computed twice: ``B~`` of the cells comes along with the fan sub-cells'
    (`fan`) from one set of shape-function values, and is kept; the sub-cells'
    (about six times as large) is handed to its last user and dropped
    (``release=True``).

    Parameters
    ----------
    model : Model
        ``n`` nodes, ``m`` integration cells.
    gauss : int
        Gauss points per piece of cell edge (see `smoothed_gradient`).
    cells : SmoothedGradient, optional
        ``B~`` of ``model.cells`` at this Gauss order when it is already known (a
        local update computes it from the previous model's): kept as `cells`.

    Attributes
    ----------
    model : Model
    gauss : int
    """

    def __init__(self, model: Model, *, gauss: int = 2, cells: SmoothedGradient | None = None):
        self.model = model
        self.gauss = check_gauss(gauss)
        if cells is not None and cells.shape != (len(model.cells.measure), len(model.nodes)):
            raise GeometryError(f"cells: expected the smoothed gradient of this model's "
                                f"{len(model.cells.measure)} cells and {len(model.nodes)} nodes, "
                                f"received shape {cells.shape}")
        self._cells = cells
        self._fan = None
        self._interface = None

    def interface(self) -> InterfacePieces:
        """The pieces on which a 3-D model's cells integrate their material interfaces
        (`cnem.assembly.facet_gradients.model_interface_pieces`): computed once for the
        cells' and sub-cells' ``B~`` and the traction points."""
        if self._interface is None:
            self._interface = model_interface_pieces(self.model, self.model.cells)
        return self._interface

    def cells(self) -> SmoothedGradient:
        """``B~`` of ``model.cells``, ``(m, n)`` (computed on first call, then kept)."""
        if self._cells is None:
            self._cells = (cell_gradient_3d(self.model, self.model.cells, self.interface())
                           if self.model.nodes.shape[1] == 3
                           else smoothed_gradient(self.model, gauss=self.gauss))
        return self._cells

    def of(self, cells: Cells) -> SmoothedGradient:
        """``B~`` of some integration cells: the kept `cells` one for ``model.cells``,
        computed afresh (and not kept) for others (the sub-cells of an enriched
        problem, say)."""
        if cells is self.model.cells:
            return self.cells()
        return smoothed_gradient(self.model, gauss=self.gauss, cells=cells)

    def fan(self, *, release: bool = False) -> tuple[Cells, SmoothedGradient]:
        """Smoothed gradients on the fan sub-cells of the model's cells (`fan_gradient`),
        computed on first call together with the cells' `cells` when those are not
        there yet (kept too), from one set of points.

        Parameters
        ----------
        release : bool
            Hand the result over and keep no reference to it (its last user: about
            as large as ``B~`` six times over, so a large model does not keep it
            alive); a later call computes it again.

        Returns
        -------
        sub, grad : Cells, SmoothedGradient
            As `fan_gradient` returns them.
        """
        if self._fan is None:
            interface = self.interface() if self.model.nodes.shape[1] == 3 else None
            of_cells, sub, grad = _fan_gradients(self.model, self.gauss,
                                                 with_cells=self._cells is None,
                                                 interface=interface)
            if of_cells is not None:
                self._cells = of_cells
            self._fan = sub, grad
        fan = self._fan
        if release:
            self._fan = None
        return fan

    def __repr__(self):
        kept = [name for name, value in (("cells", self._cells), ("fan", self._fan))
                if value is not None]
        return (f"<GradientCache gauss {self.gauss} of a {len(self.model.nodes)}-node model, "
                f"kept: {', '.join(kept) or 'none'}>")


#: Old names (one release): see `cnem._aliases`.
__getattr__ = renamed_attributes(__name__, {"SmoothedGradients": (__name__, "GradientCache")})
