"""Boundary conditions written once for every solver (C-NEM, FEM P1, peridynamics).

`Conditions` is the base of every problem class: it stores the Dirichlet,
traction and body-force conditions with the meanings of ``docs/api-contract.md`` and turns
them into prescribed dof values; each solver only integrates the loads in its
own way (`body_forces`, `traction_at`).

>>> import numpy as np
>>> from cnem.solvers.conditions import Conditions
>>> class Points(Conditions):
...     def __init__(self, points):
...         super().__init__()
...         self.condition_points = points
>>> prob = Points(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]))
>>> prob.add_dirichlet(lambda p: p[:, 0] > 0.5, 0, 1.0)
>>> prob.add_dirichlet([2], 1, 2.0)                # a second condition on other dofs
>>> prob.prescribed()
(array([2, 4, 5]), array([1., 1., 2.]))
"""

from __future__ import annotations

import inspect
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable, Union

import numpy as np

from .. import config
from ..errors import ConditionError, UnsupportedError, check_array, check_points, check_real
from .._sets import distinct


if TYPE_CHECKING:
    from numpy.typing import ArrayLike

__all__ = ["Conditions", "select_nodes", "vector_constant", "Traction", "per_point", "traction_at", "dirichlet_dofs", "merged_conditions"]

#: What `where` may be: a boundary name, a predicate over points, a boolean mask or indices.
Where = Union[str, Callable[[np.ndarray], np.ndarray], np.ndarray, list]


def _call_where(where: Callable[..., np.ndarray], *args: np.ndarray) -> np.ndarray:
    """``where(*args)``; a predicate that takes another number of arguments is named with
    the signature expected (it failed with a bare TypeError from inside it)."""
    try:
        inspect.signature(where).bind(*args)
    except TypeError:
        expected = "where(x, nrm)" if len(args) == 2 else "where(x)"
        raise ConditionError(f"where: expected a predicate {expected} of {len(args)} argument"
                             f"{'s' if len(args) > 1 else ''} (points (p, d)"
                             f"{' and outward unit normals (p, d)' if len(args) == 2 else ''}), "
                             f"received one that does not take them; e.g. lambda x"
                             f"{', nrm' if len(args) == 2 else ''}: x[:, 0] < 1e-9") from None
    except ValueError:                        # no signature to read (a builtin): just call
        pass
    return where(*args)


def select_nodes(nodes: np.ndarray, where: str | Callable[..., np.ndarray] | ArrayLike, *,
                 named: Callable[[str], np.ndarray] | None = None) -> np.ndarray:
    """Indices of the nodes picked by a boundary name, a predicate, a boolean mask or an
    index array.

    Parameters
    ----------
    nodes : (n, 2) ndarray
    where : str, callable ``(p, 2) -> (p,) bool``, (n,) bool array_like, or int array_like
    named : callable ``name -> (k,) int ndarray``, optional
        The nodes on a named boundary (`Conditions.named_nodes`); without it a name is
        refused.

    Returns
    -------
    (k,) int64 ndarray, sorted
    """
    nodes = check_points("nodes", nodes, error=ConditionError)
    n = len(nodes)
    if isinstance(where, str):
        if named is None:
            raise ConditionError(f"where={where!r}: boundary names need a problem on a domain; "
                                 "select the nodes with a predicate, a mask or indices")
        return distinct(np.asarray(named(where), dtype=np.int64))
    if callable(where):
        mask = np.asarray(_call_where(where, nodes))
        if mask.shape != (n,) or mask.dtype != bool:
            raise ConditionError(f"where(nodes) must return a (n,) bool array for the {n} nodes, "
                                 f"received dtype {mask.dtype} shape {mask.shape}; return a "
                                 f"comparison such as p[:, 0] < 1e-9")
        return np.flatnonzero(mask)
    arr = np.asarray(where)
    if arr.dtype == bool:
        if arr.shape != (n,):
            raise ConditionError(f"where: a boolean mask needs one entry per node ({n}), "
                                 f"received shape {arr.shape}")
        return np.flatnonzero(arr)
    if arr.size and not np.issubdtype(arr.dtype, np.integer):
        raise ConditionError(f"where: expected a callable, a boolean mask or node indices, "
                             f"received an array of dtype {arr.dtype}")
    if arr.ndim > 1:
        raise ConditionError(f"where: expected a flat array of node indices, received shape "
                             f"{arr.shape}; pass e.g. np.array([0, 4, 7])")
    idx = distinct(arr.astype(np.int64).reshape(-1))
    if idx.size and (idx[0] < 0 or idx[-1] >= n):
        raise ConditionError(f"where: node indices must lie in [0, {n}), received "
                             f"[{idx[0]}, {idx[-1]}]; index the model's nodes")
    return idx


def per_point(value: ArrayLike | Callable[..., np.ndarray], points: np.ndarray, width: int,
              what: str) -> np.ndarray:
    """A constant or a callable evaluated at points, as a ``(p, width)`` array.

    Raises
    ------
    ConditionError
        Values of the wrong shape, or not finite (``what`` names them).
    """
    arr = np.asarray(check_real(what, value(points) if callable(value) else value,
                                error=ConditionError), dtype=float)
    if width == 1 and arr.shape == (len(points),):
        arr = arr[:, None]
    try:
        arr = np.broadcast_to(arr, (len(points), width))
    except ValueError:
        raise ConditionError(f"{what}: expected a number or one value per point, shape "
                             f"({len(points)}, {width}), received shape {arr.shape}; return one "
                             f"row per point") from None
    if not np.isfinite(arr).all():
        raise ConditionError(f"{what}: expected finite values, received NaN or inf; check "
                             f"the value or function given")
    return arr


def vector_constant(value: Any, dim: int, what: str, fix: str, *,
                    points: int | None = None) -> Any:
    """``value`` as given, once it is known not to be an ambiguous constant: a vector
    quantity (a traction, a body force) given as a constant must have ``dim`` components
    (or one row of them per point, when ``points`` is given).

    Parameters
    ----------
    value : callable or array_like
        A callable is returned as it is (its values are checked where it is called).
    dim : int
    what : str
        The argument, named in the error.
    fix : str
        What to pass instead, named in the error.
    points : int, optional
        How many points a ``(points, dim)`` array of values would have.

    Raises
    ------
    ConditionError
        A bare number (which component would it be?), a constant of another shape, or
        one that is not real and finite numbers.
    """
    if callable(value):
        return value
    shape = check_array(what, value, error=ConditionError, fix=fix).shape
    rows = "" if points is None else f" (or {points} rows of them, one per point)"
    if shape == ():
        raise ConditionError(f"{what}: expected a vector of {dim} components{rows} or a "
                             f"callable, received the single number {value!r}, which is "
                             f"ambiguous (the same value on every component is rarely meant); "
                             f"{fix}")
    if shape != (dim,) and shape != (points, dim):
        raise ConditionError(f"{what}: expected a vector of {dim} components{rows} or a "
                             f"callable, received an array of shape {shape}; {fix}")
    return value


def traction_at(t: ArrayLike | Callable[..., np.ndarray], points: np.ndarray, normal: np.ndarray,
                what: str = "traction") -> np.ndarray:
    """Traction vectors ``(q, d)`` of a constant or a callable ``t(x, nrm)`` at boundary
    points ``(q, d)`` with outward unit normals ``(q, d)``."""
    return per_point(t(points, normal) if callable(t) else t, points, points.shape[1], what)


def dirichlet_dofs(points: np.ndarray, where: Where, component: int | None,
                   value: float | Callable[..., np.ndarray], *,
                   where_to_look: str = "the nodes", what: str = "add_dirichlet",
                   named: Callable[[str], np.ndarray] | None = None
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Dofs (interleaved: ``d * node + component``) and values of a Dirichlet condition.

    Parameters
    ----------
    points : (n, d) ndarray
    where : str, callable ``(n, d) -> (n,) bool``, or a boolean mask / index array over points
    component : None or 0..d-1
        ``None`` prescribes every component.
    value : float or callable ``(p, d) -> (p,)`` (``(p, d)`` for every component)
    where_to_look : str
        Named in the error when nothing is selected.
    what : str
        The method named in the errors.
    named : callable ``name -> (k,) int ndarray``, optional
        The points on a named boundary (see `select_nodes`).

    Returns
    -------
    dofs : (k,) int64 ndarray
    values : (k,) ndarray
    """
    d = points.shape[1]
    if component is not None and component not in range(d):
        raise ConditionError(f"component: expected None (all) or 0..{d - 1}, received "
                             f"{component!r}")
    nodes = select_nodes(points, where, named=named)
    if nodes.size == 0:
        raise ConditionError(f"{what}: `where` selects no node; check the predicate against "
                         f"{where_to_look} (boundary nodes lie exactly on the boundary)")
    comps = np.arange(d) if component is None else np.array([component])
    vals = per_point(value, points[nodes], len(comps), f"{what} value")
    return (d * nodes[:, None] + comps[None, :]).reshape(-1), np.ascontiguousarray(vals).reshape(-1)


@dataclass(frozen=True, eq=False)
class Traction:
    """A traction condition on some boundary edges of a problem.

    Attributes
    ----------
    index : (k,) int64 ndarray
        The edges' rows in the problem's ``boundary_edges()``.
    edges : (k, 2) int64 ndarray
        Their node pairs, the body on the left.
    normal : (k, 2) ndarray
        Their outward unit normals.
    value : (2,) array_like or callable ``(x, nrm) -> (q, 2)``
        The traction (see `traction_at`).
    """

    index: np.ndarray
    edges: np.ndarray
    normal: np.ndarray
    value: Any


class Conditions:
    """Dirichlet, traction and body-force conditions of a problem.

    A problem class derives from it, calls ``super().__init__()`` and offers

    * ``condition_points`` : ``(n, d)`` ndarray, the nodes (points) that
      Dirichlet predicates, masks and indices refer to;
    * ``boundary_edges()`` -> ``edges (e, 2)``, ``normal (e, 2)`` (node pairs with
      the body on the left, outward unit normals) if it takes tractions;
    * ``condition_domain``: the domain (`cnem.Domain`, or any object with
      ``on_boundary(points, name)`` and ``boundaries``) whose named boundaries ``where``
      may name, if it has one.

    Attributes
    ----------
    dirichlet : list of (dofs (k,), values (k,))
        The Dirichlet conditions in the order given (`prescribed` merges them).
    tractions : list of Traction
    body_forces : list
        Constants ``(d,)`` or callables ``b(x) -> (p, d)``.
    """

    #: Named in the error of a Dirichlet predicate that selects nothing.
    points_name = "the nodes"
    #: What the error of a traction predicate that selects nothing calls the edges.
    edges_name = "boundary edge"

    #: The domain whose boundary names `where` may give (None: names are refused).
    condition_domain = None
    #: How to do without names, said when a problem has no `condition_domain`.
    names_fix = "select with a predicate, a mask or indices"

    def __init__(self):
        self.dirichlet = []
        self.tractions = []
        self.body_forces = []

    def conditions_repr(self) -> str:
        """``"a Dirichlet, b traction, c body-force conditions"``, for ``__repr__``."""
        return (f"{len(self.dirichlet)} Dirichlet, {len(self.tractions)} traction, "
                f"{len(self.body_forces)} body-force conditions")

    def add_dirichlet(self, where: Where, component: int | None,
                      value: ArrayLike | Callable[..., np.ndarray] = 0.0) -> None:
        """Prescribe displacements at nodes.

        Several conditions may prescribe one dof if they agree on its value;
        `prescribed` refuses conflicting values.

        Parameters
        ----------
        where : str, callable ``(n, d) -> (n,) bool``, or a boolean mask / index array over
            the nodes (``condition_points``)
            A str names a boundary of the domain (``condition_domain.boundaries``): the
            nodes on it, between its vertices too.
        component : {0, ..., d - 1, None}
            ``None`` prescribes every component.
        value : float, or callable ``(p, d) -> (p,)`` (``(p, d)`` for every component)
        """
        self.dirichlet.append(dirichlet_dofs(self.condition_points, where, component, value,
                                             where_to_look=self.points_name,
                                             named=self.named_nodes))

    def _named_domain(self, name: str):
        """The domain whose boundary ``name`` is meant (refused without one)."""
        if self.condition_domain is None:
            raise ConditionError(f"where={name!r}: {type(self).__name__} knows no domain, so "
                                 f"it has no named boundaries; {self.names_fix}")
        return self.condition_domain

    def named_nodes(self, name: str) -> np.ndarray:
        """The condition points on the boundary named ``name``.

        Returns
        -------
        (k,) int64 ndarray

        Raises
        ------
        ConditionError
            An unknown name (the error lists the known ones), or a problem without a
            domain.
        """
        domain = self._named_domain(name)
        return np.flatnonzero(domain.on_boundary(self.condition_points, name))

    def named_facets(self, name: str) -> np.ndarray:
        """Which of ``boundary_edges()`` lie on the boundary named ``name`` (their nodes
        and their midpoint on it).

        Returns
        -------
        (e,) bool ndarray
        """
        domain = self._named_domain(name)
        edges, _ = self.boundary_edges()
        corners = self.condition_points[edges]                     # (e, k, d)
        on = domain.on_boundary(corners.reshape(-1, corners.shape[2]), name)
        return on.reshape(len(edges), -1).all(axis=1) & domain.on_boundary(corners.mean(axis=1),
                                                                          name)

    def boundary_edges(self) -> tuple[np.ndarray, np.ndarray]:
        """Edges of the outer boundary, holes and crack faces (triangles of the boundary
        surfaces in 3-D).

        Returns
        -------
        edges : (e, 2) or (e, 3) int64 ndarray
            Node pairs, the body on the left (counter-clockwise); in 3-D node
            triples, counter-clockwise seen from outside.
        normal : (e, d) ndarray
            Outward unit normals.
        """
        raise UnsupportedError(f"{type(self).__name__} has no boundary edges; give loads as "
                               f"body forces (add_body_force)")

    def add_traction(self, where: Where, t: ArrayLike | Callable[..., np.ndarray]) -> None:
        """Tractions on the boundary edges (outer boundary, holes, crack faces).

        Parameters
        ----------
        where : str, callable ``(x, nrm) -> (e,) bool``, or an ``(e,)`` bool mask
            A boundary name (``condition_domain.boundaries``: the edges on it, see
            `named_facets`), or a predicate of the midpoints ``(e, 2)`` and outward
            unit normals ``(e, 2)`` of the edges of ``boundary_edges()`` (in 3-D the
            centroids and normals ``(e, 3)`` of its triangles).
        t : (d,) array_like, or callable ``(x, nrm) -> (q, d)``
            Traction vectors at boundary points ``x (q, 2)`` with normals
            ``nrm (q, 2)``; each solver integrates them exactly up to quadratic
            tractions along an edge.
        """
        x = self.condition_points
        d = x.shape[1]
        example = ", ".join(["0.0"] * (d - 1) + ["-1.0"])
        t = vector_constant(t, d, "add_traction: t",
                            f"give the traction vector, e.g. [{example}], or a pressure p "
                            f"along the outward normal as lambda x, nrm: -p * nrm")
        index, edges, normal = self.select_facets(where, "add_traction")
        self.tractions.append(Traction(index, edges, normal, t))

    def select_facets(self, where: Where, what: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The boundary edges (3-D: triangles) of ``boundary_edges()`` that ``where``
        picks: a boundary name, a predicate of their midpoints (centroids) and outward
        unit normals, or an ``(e,)`` bool mask.

        Parameters
        ----------
        where : str, callable ``(x, nrm) -> (e,) bool``, or an ``(e,)`` bool mask
        what : str
            The method named in the errors.

        Returns
        -------
        index : (k,) int64 ndarray
            Their rows in ``boundary_edges()``.
        edges : (k, 2) or (k, 3) int64 ndarray
        normal : (k, d) ndarray

        Raises
        ------
        ConditionError
            A predicate that returns no bool per edge, or selects none.
        """
        edges, normal = self.boundary_edges()
        mid = self.condition_points[edges].mean(axis=1)   # edge midpoints; triangle centroids in 3-D
        if isinstance(where, str):
            pick = self.named_facets(where)
        else:
            pick = np.asarray(_call_where(where, mid, normal)) if callable(where) else \
                np.asarray(where)
        if pick.shape != (len(edges),) or pick.dtype != bool:
            raise ConditionError(f"{what}: where(x, nrm) must return a ({len(edges)},) bool "
                                 f"array, received dtype {pick.dtype} shape {pick.shape}")
        if not pick.any():
            raise ConditionError(f"{what}: `where` selects no {self.edges_name}; check the "
                             "predicate against the midpoints and outward normals of "
                             "boundary_edges()")
        index = np.flatnonzero(pick)
        return index, edges[index], normal[index]

    def add_body_force(self, b: ArrayLike | Callable[..., np.ndarray]) -> None:
        """Body force per unit area (2-D) or volume: ``b(x) -> (p, d)``, a constant ``(d,)``,
        or one ``(d,)`` row per condition point (node).

        Raises
        ------
        ConditionError
            A bare number or a constant that is not ``(d,)``.
        """
        d = self.condition_points.shape[1]
        example = ", ".join(["0.0"] * (d - 1) + ["-9.81"])
        self.body_forces.append(vector_constant(b, d, "add_body_force: b",
                                                f"give the force vector, e.g. [{example}]",
                                                points=len(self.condition_points)))

    def body_forces_at(self, points: np.ndarray) -> list:
        """The body forces at points, one ``(p, d)`` array per condition.

        Parameters
        ----------
        points : (p, d) ndarray

        Returns
        -------
        list of (p, d) ndarray
        """
        return [per_point(b, points, points.shape[1], "body force") for b in self.body_forces]

    def prescribed(self) -> tuple[np.ndarray, np.ndarray]:
        """The prescribed dofs (interleaved ``d * node + component``) and their values.

        Returns
        -------
        dofs : (k,) int64 ndarray
            Sorted, distinct.
        values : (k,) ndarray

        Raises
        ------
        ConditionError
            If two conditions prescribe different values on one dof.
        """
        return merged_conditions(self.dirichlet, self.condition_points.shape[1], "add_dirichlet")


def merged_conditions(conditions: list, dim: int, what: str) -> tuple[np.ndarray, np.ndarray]:
    """The dofs of a list of ``(dofs, values)`` conditions (`dirichlet_dofs`) and their
    values; a dof prescribed by several conditions must get one value from all of them.

    Parameters
    ----------
    conditions : list of (dofs (k,), values (k,))
    dim : int
        Components per node (the dofs are ``dim * node + component``).
    what : str
        The method that added the conditions, named in the error.

    Returns
    -------
    dofs : (k,) int64 ndarray
        Sorted, distinct.
    values : (k,) ndarray

    Raises
    ------
    ConditionError
        If two conditions give one dof values that differ by more than
        `config.CONDITION_RTOL` of the largest prescribed value (a corner node
        selected by two predicates with different values, say).
    """
    dofs = np.concatenate([np.zeros(0, dtype=np.int64)] + [d for d, _ in conditions])
    values = np.concatenate([np.zeros(0)] + [np.asarray(v, dtype=float) for _, v in conditions])
    unique, first, group = np.unique(dofs, return_index=True, return_inverse=True)
    low = np.full(unique.size, np.inf)
    high = np.full(unique.size, -np.inf)
    np.minimum.at(low, group, values)
    np.maximum.at(high, group, values)
    scale = np.max(np.abs(values), initial=0.0)
    conflict = np.flatnonzero(high - low > config.CONDITION_RTOL * scale)
    if conflict.size:
        shown = ", ".join(f"node {unique[k] // dim} component {unique[k] % dim}: "
                          f"{low[k]:.6g} and {high[k]:.6g}" for k in conflict[:3])
        raise ConditionError(
            f"{what}: expected one value for every prescribed dof, received conflicting values "
            f"on {conflict.size} dof(s) ({shown}{', ...' if conflict.size > 3 else ''}); "
            "two conditions select the same node with different values: narrow one `where` "
            "(e.g. leave out the corner) or give both the same value")
    return unique, values[first]
