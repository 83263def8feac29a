"""Tractions on a peridynamic body: boundary loads turned into point forces.

A traction ``t`` is a force per unit boundary area, as in `cnem.Elasticity`; a point
of a peridynamic body takes forces as a body force times its volume. The conversion
keeps the resultant: the point forces sum to the integral of ``t`` over the loaded
boundary (``t`` times its area for a constant traction).

* A body from a node cloud (`Body.from_cloud`) knows its boundary: the edges (3-D: the
  triangles) of its C-NEM model (``body.model``). ``where`` picks them as in
  `cnem.Elasticity.add_traction` (a boundary name, or a predicate of their midpoints and
  outward normals), and each node takes its share ``int t phi_a dA`` by the facets' linear
  hats (`cnem.solvers.facet_loads`), times the thickness in 2-D: the same load means the
  same thing in C-NEM and in PD.
* A plain `Body` (a lattice) does not know its boundary: ``where`` picks the loaded points
  (a predicate of the points, a mask or indices: the outermost row) and the user gives the
  boundary area each of them carries, ``area=`` (per point, or one number), or the lattice
  ``spacing=`` (area ``spacing * thickness`` in 2-D, ``spacing ** 2`` in 3-D: exact for a
  cell-centred lattice, whose outermost row lies half a spacing inside the edge). A
  callable ``t(x, nrm)`` also needs the outward ``normal=`` of those points.

>>> import numpy as np, cnem, cnem.pd as pd
>>> cloud = cnem.nodes.regular(cnem.geometry.rectangle(2.0, 1.0), 0.25)
>>> prob = pd.Problem(pd.Body.from_cloud(cloud), pd.StateBased(1.0, 0.3))
>>> prob.add_traction(lambda x, n: x[:, 0] > 2.0 - 1e-9, [3.0, 0.0])   # edge x = 2, length 1
>>> float(prob.load().reshape(-1, 2)[:, 0].sum())                     # 3 x 1 (thickness 1)
3.0
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import ConditionError, UnsupportedError, check_array
from ..solvers.conditions import Traction, select_nodes, traction_at, vector_constant
from ..solvers.facet_loads import facet_loads

if TYPE_CHECKING:
    from typing import Callable

    from numpy.typing import ArrayLike

__all__ = ["BodyTractions", "PointTraction"]


@dataclass(frozen=True, eq=False)
class PointTraction:
    """A traction on the outermost points of a plain `Body` (a lattice).

    Attributes
    ----------
    nodes : (k,) int64 ndarray
        The loaded points.
    area : (k,) ndarray
        The boundary area each carries (length times thickness in 2-D).
    normal : (k, d) ndarray or None
        Their outward unit normals (given for a callable traction).
    value : (d,) array_like or callable ``(x, nrm) -> (k, d)``
    """

    nodes: np.ndarray
    area: np.ndarray
    normal: np.ndarray | None
    value: Any


class BodyTractions:
    """`add_traction` and the point forces of the tractions, for `cnem.pd.Problem`
    (before `cnem.solvers.conditions.Conditions` in its bases; it needs ``body``,
    ``dim``, ``tractions`` and ``condition_points``)."""

    edges_name = "boundary edge of body.model"

    def boundary_edges(self) -> tuple[np.ndarray, np.ndarray]:
        """The boundary edges (3-D: triangles) of the body's C-NEM model and their outward
        unit normals (`cnem.geometry.Model.boundary_with_normals`).

        Raises
        ------
        UnsupportedError
            A plain `Body`, which has no model (give ``area=`` or ``spacing=`` to
            `add_traction`).
        """
        model = getattr(self.body, "model", None)
        if model is None:
            raise UnsupportedError("boundary_edges: a plain Body has no boundary edges; build "
                                   "it with Body.from_cloud, or give add_traction the boundary "
                                   "area of each loaded point (area=) or the spacing (spacing=)")
        return model.boundary_with_normals()

    def add_traction(self, where: str | Callable[..., np.ndarray] | ArrayLike,
                     t: ArrayLike | Callable[..., np.ndarray], *,
                     area: ArrayLike | None = None, spacing: float | None = None,
                     normal: ArrayLike | None = None) -> None:
        """A traction (force per unit boundary area) on part of the boundary, applied as
        point forces whose sum is its integral over that boundary (see the module
        `cnem.pd.tractions`).

        Parameters
        ----------
        where : str, callable, or a bool mask / index array
            On a body from `Body.from_cloud`: a boundary name, a predicate ``(x, nrm) ->
            (e,) bool`` of the midpoints (3-D: centroids) and outward unit normals
            ``(e, d)`` of ``boundary_edges()``, or an ``(e,)`` bool mask, as in
            `cnem.Elasticity.add_traction`. On a plain `Body`: the loaded points (the
            outermost row), a predicate ``(n, d) -> (n,) bool``, a mask or indices.
        t : (d,) array_like, or callable ``(x, nrm) -> (q, d)``
            The traction; a single number is refused (give a vector, or a pressure ``p``
            as ``lambda x, nrm: -p * nrm``).
        area : float or (k,) array_like, optional
            Plain `Body` only: the boundary area each loaded point carries (in 2-D its
            length along the edge times the thickness).
        spacing : float, optional
            Plain `Body` only, instead of ``area``: the lattice spacing ``dx``; each loaded
            point carries ``dx * thickness`` (2-D) or ``dx ** 2`` (3-D).
        normal : (d,) or (k, d) array_like, optional
            Plain `Body` only: the outward unit normal of the loaded points, passed to a
            callable ``t`` (required then).

        Raises
        ------
        ConditionError
            A scalar ``t``; ``where`` selecting nothing; on a body from a cloud, ``area``,
            ``spacing`` or ``normal`` given (its model gives them); on a plain `Body`,
            neither or both of ``area`` and ``spacing``, non-positive values, or a
            callable ``t`` without ``normal``.
        """
        d = self.dim
        example = ", ".join(["0.0"] * (d - 1) + ["-1.0"])
        t = vector_constant(t, d, "add_traction: t",
                            f"give the traction vector, e.g. [{example}], or a pressure p "
                            f"along the outward normal as lambda x, nrm: -p * nrm")
        given = [name for name, v in (("area", area), ("spacing", spacing), ("normal", normal))
                 if v is not None]
        if getattr(self.body, "model", None) is not None:
            if given:
                raise ConditionError(f"add_traction: a body from Body.from_cloud takes its "
                                     f"boundary areas and normals from its model; expected no "
                                     f"{' or '.join(given)}, received {', '.join(given)}; leave "
                                     f"{'it' if len(given) == 1 else 'them'} out")
            index, edges, nrm = self.select_facets(where, "add_traction")
            self.tractions.append(Traction(index, edges, nrm, t))
            return
        self.tractions.append(self._point_traction(where, t, area, spacing, normal))

    def _point_traction(self, where, t, area, spacing, normal) -> PointTraction:
        """The traction on the points of a plain body that ``where`` picks, with their
        areas from ``area`` or ``spacing`` (exactly one)."""
        if (area is None) == (spacing is None):
            raise ConditionError(
                "add_traction: a plain Body (a lattice) does not know its boundary; expected "
                "exactly one of area= (the boundary area each loaded point carries) or "
                "spacing= (the lattice spacing), received "
                f"{'both' if area is not None else 'neither'}; or build the body with "
                "Body.from_cloud, whose model gives the boundary")
        nodes = select_nodes(self.condition_points, where, named=self.named_nodes)
        if nodes.size == 0:
            raise ConditionError("add_traction: `where` selects no point; check the predicate "
                                 "against body.points (the outermost row of the lattice)")
        if spacing is not None:
            dx = float(check_array("add_traction: spacing", spacing, positive=True,
                                   error=ConditionError, fix="give the lattice spacing dx"))
            area = dx * self.body.thickness if self.dim == 2 else dx * dx
        area = check_array("add_traction: area", area, shape=(nodes.size,), broadcast=True,
                           positive=True, error=ConditionError,
                           fix="give the boundary area of each loaded point, or one number")
        if normal is not None:
            normal = check_array("add_traction: normal", normal, error=ConditionError)
            if normal.shape not in ((self.dim,), (nodes.size, self.dim)):
                raise ConditionError(f"add_traction: normal: expected the outward unit normal "
                                     f"({self.dim},) or one per loaded point ({nodes.size}, "
                                     f"{self.dim}), received shape {normal.shape}; e.g. "
                                     f"normal=[0.0, 1.0] for the top edge")
            normal = np.ascontiguousarray(np.broadcast_to(normal, (nodes.size, self.dim)))
        elif callable(t):
            raise ConditionError("add_traction: a callable t(x, nrm) on a plain Body needs the "
                                 "outward normal of the loaded points; expected normal=, "
                                 "received none; e.g. normal=[0.0, 1.0] for the top edge")
        return PointTraction(nodes, np.array(area, dtype=float), normal, t)

    def traction_forces(self) -> np.ndarray:
        """The point forces of the tractions, ``(n, d)``: on a body from a cloud the
        facets' hat shares times the thickness (2-D), on a plain body the traction at
        each loaded point times its area.

        Returns
        -------
        (n, d) ndarray
        """
        x = self.condition_points
        f = np.zeros(x.shape)
        for traction in self.tractions:
            if isinstance(traction, PointTraction):
                nrm = traction.normal
                tr = traction_at(traction.value, x[traction.nodes],
                                 np.full(x[traction.nodes].shape, np.nan) if nrm is None else nrm)
                np.add.at(f, traction.nodes, traction.area[:, None] * tr)
            else:
                f += self.body.thickness * facet_loads(x, traction.edges, traction.normal,
                                                       traction.value)
        return f
