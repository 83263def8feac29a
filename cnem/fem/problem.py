"""`P1Elasticity`: the elasticity problem on scikit-fem P1 triangles or tetrahedra (the
anchor of C-NEM).

The same problem definition as `cnem.Elasticity` (Dirichlet conditions on nodes,
tractions on boundary edges or faces, body forces), on the mesh of
`cnem.fem.mesh.mesh_domain` or on a C-NEM model's own nodes and triangulation
(`P1Elasticity.from_model`, 2-D and 3-D).
"""

from __future__ import annotations

import logging
import time
from typing import TYPE_CHECKING, Literal, Sequence

import numpy as np
from skfem import (Basis, ElementTetP1, ElementTriP1, ElementVector, FacetBasis, LinearForm,
                   MeshTet, MeshTri)
from skfem.helpers import dot
from skfem.models.elasticity import linear_elasticity

from ..solvers.constrained import solve_constrained
from ..solvers.conditions import Conditions, per_point, traction_at
from ..errors import GeometryError, InputError
from ..geometry.domain import Domain
from ..geometry.model import check_model
from ..material import check_plane, lame, moduli, parse_materials
from .mesh import mesh_domain
from .solution import P1Solution

if TYPE_CHECKING:
    import scipy.sparse as sp
    from ..geometry.domain3d import Domain3D
    from ..geometry.model import Model
    from ..geometry.model3d import Model3D

__all__ = ["P1Elasticity"]

log = logging.getLogger(__name__)

#: The scikit-fem mesh and scalar P1 element of each dimension.
_P1 = {2: (MeshTri, ElementTriP1), 3: (MeshTet, ElementTetP1)}


class P1Elasticity(Conditions):
    """Linear elasticity with linear triangles or tetrahedra (scikit-fem), the reference
    for `cnem.Elasticity`.

    Built on a quality mesh of a 2-D domain (this constructor), or on the nodes and
    triangulation of a C-NEM model in 2-D or 3-D (`from_model`). The mesh exists at
    construction, so that conditions can be given on its nodes (`nodes`, `mesh`).

    Parameters
    ----------
    domain : Domain
    materials : (E, nu) pair or `cnem.material.LinearElastic`, or a list of either indexed by region
    plane : {"stress", "strain"}
    nodes : int, optional
        Target node count of the mesh (within about 5 %).
    max_area : float, optional
        Maximum triangle area instead.
    quality : float
        Minimum angle of the triangles in degrees.

    Attributes
    ----------
    dim : int
        2 or 3.
    mesh : skfem.MeshTri or skfem.MeshTet
        ``n`` nodes (``mesh.p`` is ``(dim, n)``), ``t`` elements.
    region : (t,) int64 ndarray
        Region index of each element.
    basis : skfem.Basis
        Vector P1 basis; dofs interleaved ``[u0x, u0y, (u0z,) u1x, ...]``.
    model : Model or Model3D or None
        The C-NEM model whose nodes and triangulation are used (`from_model`), None
        when the domain was meshed.
    timings : dict
        Seconds spent meshing (``"mesh"``; empty for `from_model`).
    region_materials : tuple of cnem.material.LinearElastic
        One per region.
    materials : (r, 2) ndarray
        Their ``(E, nu)``.
    """

    def __init__(self, domain: Domain,
                 materials: tuple[float, float] | Sequence[tuple[float, float]], *,
                 plane: str = "stress", nodes: int | None = None,
                 max_area: float | None = None, quality: float = 30.0):
        if not isinstance(domain, Domain):
            raise InputError(f"P1Elasticity meshes a 2-D cnem.Domain, received "
                             f"{type(domain).__name__}; for P1 on the nodes of a model (2-D or "
                             f"3-D) call P1Elasticity.from_model(model, materials)")
        self._set_problem(domain, materials, 2, plane)
        t0 = time.perf_counter()
        points, tri, region = mesh_domain(domain, nodes=nodes, max_area=max_area,
                                          quality=quality)
        self._set_mesh(points, tri, region, {"mesh": time.perf_counter() - t0})

    @classmethod
    def from_model(cls, model: Model | Model3D,
                   materials: tuple[float, float] | Sequence[tuple[float, float]], *,
                   plane: str | None = None) -> P1Elasticity:
        """P1 elements on a C-NEM model's own nodes: its constrained Delaunay triangles
        (2-D, cracks opened as in the model) or its boundary-conforming tetrahedra
        (3-D), one material per region as `cnem.Elasticity` takes them.

        The nodes are ``model.nodes`` in their order, so that ``sol.u`` compares
        with the C-NEM solution node by node, and conditions select the same nodes
        and boundary faces as on `cnem.Elasticity(model, ...)`.

        Parameters
        ----------
        model : Model or Model3D
            From `cnem.discretize`.
        materials : (E, nu) pair or `cnem.material.LinearElastic`, or a list of either
            indexed by region
        plane : {"stress", "strain"} or None
            2-D only (default "stress"); None in 3-D.

        Returns
        -------
        P1Elasticity

        Raises
        ------
        InputError
            ``model`` is not a model (a cloud or a domain is named with the call
            that makes one).
        GeometryError
            A node of the model lies in no triangle or tetrahedron.
        OptionError, MaterialError
            A plane in 3-D (or none of "stress", "strain" in 2-D), or not one
            material per region.

        Examples
        --------
        >>> import cnem, cnem.fem
        >>> model = cnem.discretize(cnem.nodes.regular(cnem.geometry.rectangle(), 0.25))
        >>> prob = cnem.fem.P1Elasticity.from_model(model, (1000.0, 0.3))
        >>> bool((prob.nodes == model.nodes).all()), len(prob.mesh.t.T) == len(model.triangles)
        (True, True)
        """
        model = check_model(model, "P1Elasticity.from_model")
        dim = model.nodes.shape[1]
        if dim == 2 and plane is None:
            plane = "stress"
        if dim == 3:
            elements, region = model.tetrahedra, model.tet_region
        else:
            elements, region = model.triangles, model.triangle_region
        used = np.zeros(len(model.nodes), dtype=bool)
        used[np.asarray(elements).ravel()] = True
        if not used.all():
            raise GeometryError(f"P1Elasticity.from_model: expected every node of the model in "
                                f"a {'tetrahedron' if dim == 3 else 'triangle'}, received "
                                f"{int((~used).sum())} nodes in none (the first "
                                f"{model.nodes[~used][0].tolist()}); rebuild the model with "
                                f"cnem.discretize")
        problem = cls.__new__(cls)
        problem._set_problem(model.domain, materials, dim, plane)
        problem._set_mesh(model.nodes, elements, region, {})
        problem.model = model
        return problem

    def _set_problem(self, domain, materials, dim, plane):
        """The domain, dimension, plane and materials (checked before any meshing)."""
        self.domain = domain
        self.dim = dim
        check_plane(dim, plane)
        self.region_materials = parse_materials(materials, domain.n_regions, plane, dim=dim)
        self.materials = moduli(self.region_materials)
        self.plane = plane
        self.model = None

    def _set_mesh(self, points, elements, region, timings):
        """The scikit-fem mesh and vector P1 basis on ``points (n, d)`` and ``elements
        (t, d + 1)`` with their ``region (t,)``; then the (empty) conditions."""
        mesh_type, element = _P1[self.dim]
        self.mesh = mesh_type(np.ascontiguousarray(np.asarray(points, dtype=float).T),
                              np.ascontiguousarray(np.asarray(elements).T))
        self.region = np.asarray(region, dtype=np.int64)
        self.basis = Basis(self.mesh, ElementVector(element()))
        self.timings = timings
        self._boundary = None
        super().__init__()

    def __repr__(self):
        kind = "tetrahedra" if self.dim == 3 else "triangles"
        return (f"<P1Elasticity plane {self.plane}, {len(self.nodes)} nodes, "
                f"{self.mesh.t.shape[1]} {kind}, {len(self.prescribed()[0])} prescribed dofs, "
                f"{self.conditions_repr()}>")

    @property
    def nodes(self) -> np.ndarray:
        """``(n, dim)`` node coordinates (crack nodes once per face)."""
        return self.mesh.p.T

    # -- conditions (`Conditions`: add_dirichlet, add_traction, add_body_force) ---------
    points_name = "prob.nodes"
    edges_name = "boundary facet"

    @property
    def condition_points(self) -> np.ndarray:
        """``(n, dim)`` the nodes that conditions refer to (`nodes`)."""
        return self.nodes

    @property
    def condition_domain(self) -> Domain | Domain3D:
        """The domain meshed (or the model's): its named boundaries may be given as
        ``where``."""
        return self.domain

    def boundary_edges(self) -> tuple:
        """The mesh's boundary facets and their outward normals (see
        `Conditions.boundary_edges`; `boundary_facets` in the same order): node pairs
        with the body on the left in 2-D, node triples counter-clockwise seen from
        outside in 3-D."""
        facets, _, normal = self.boundary_facets()
        edges = self.mesh.facets[:, facets].T.astype(np.int64)
        corners = self.nodes[edges]
        if self.dim == 2:
            d = corners[:, 1] - corners[:, 0]
            flip = d[:, 1] * normal[:, 0] - d[:, 0] * normal[:, 1] < 0     # normal on the left
            edges[flip] = edges[flip][:, ::-1]
        else:
            area = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
            flip = (area * normal).sum(axis=1) < 0                         # normal outward
            edges[flip] = edges[flip][:, [0, 2, 1]]
        return edges, normal

    def boundary_facets(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The boundary edges (faces in 3-D) as scikit-fem facets (the older name of
        `boundary_edges`, in the same order).

        Returns
        -------
        facets : (e,) int ndarray
            Indices into ``mesh.facets``.
        midpoint : (e, dim) ndarray
            Edge midpoints (face centroids).
        normal : (e, dim) ndarray
            Outward unit normals.
        """
        if self._boundary is None:
            facets = self.mesh.boundary_facets()
            fb = FacetBasis(self.mesh, _P1[self.dim][1](), facets=facets, intorder=1)
            midpoint = self.mesh.p[:, self.mesh.facets[:, facets]].mean(axis=1).T
            self._boundary = facets, midpoint, np.asarray(fb.normals)[:, :, 0].T
        return self._boundary

    # -- assembly -----------------------------------------------------------------------
    def element_materials(self) -> np.ndarray:
        """``(t, 2)`` ``(E, nu)`` of every element."""
        return self.materials[self.region]

    def stiffness(self) -> sp.csr_matrix:
        """Global stiffness ``(dim n, dim n)`` CSR, per-element Lamé parameters."""
        E, nu = self.element_materials().T
        lam, mu = lame(E, nu, self.plane)
        return linear_elasticity(lam[:, None], mu[:, None]).assemble(self.basis)

    def load(self) -> np.ndarray:
        """Load vector ``(dim n,)`` of the tractions and body forces."""
        f = np.zeros(self.basis.N)
        element = ElementVector(_P1[self.dim][1]())
        facets = self.boundary_facets()[0]
        for traction in self.tractions:
            fb = FacetBasis(self.mesh, element, facets=facets[traction.index], intorder=5)
            f += _vector_load(traction.value, "traction", normal=True).assemble(fb)
        for b in self.body_forces:
            f += _vector_load(b, "body force", normal=False).assemble(self.basis)
        return f

    # -- solve --------------------------------------------------------------------------
    def solve(self, *, method: Literal["auto", "direct", "amg"] = "auto",
              tol: float = 1e-10) -> P1Solution:
        """Solve ``K u = f`` with the Dirichlet values imposed.

        Parameters
        ----------
        method : {"auto", "direct", "amg"}
            See `cnem.solvers.linsolve.solve_spd`.
        tol : float
            Relative residual of the iterative solver.

        Returns
        -------
        P1Solution

        Raises
        ------
        SolveError
            Rigid motions not fixed by the Dirichlet conditions (named).
        """
        t0 = time.perf_counter()
        K = self.stiffness()
        f = self.load()
        t1 = time.perf_counter()
        D, values = self.prescribed()
        x = solve_constrained(K, f, D, values, points=self.nodes, tol=tol, method=method)
        t2 = time.perf_counter()
        timings = dict(self.timings, assembly=t1 - t0, solve=t2 - t1)
        log.info("P1 elasticity: %s", ", ".join(f"{k} {v:.3f} s" for k, v in timings.items()))
        return P1Solution.from_dofs(self, x, timings)


def _vector_load(value, what, *, normal):
    """`LinearForm` of ``value . v`` with ``value`` a constant ``(dim,)`` or a callable
    of the quadrature points (and the outward normals when ``normal``)."""

    @LinearForm
    def form(v, w):
        shape = w.x.shape                                   # (dim, elements, points)
        dim = shape[0]
        x = w.x.reshape(dim, -1).T
        if normal:
            vals = traction_at(value, x, w.n.reshape(dim, -1).T, what)
        else:
            vals = per_point(value, x, dim, what)
        return dot(vals.T.reshape(shape), v)

    return form


# ----------------------------------------------------------------------- solution
