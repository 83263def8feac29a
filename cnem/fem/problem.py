"""`P1Elasticity`: the elasticity problem on scikit-fem P1 triangles (the anchor of C-NEM).

The same problem definition as `cnem.Elasticity` (Dirichlet conditions on nodes,
tractions on boundary edges, body forces), on the mesh of `cnem.fem.mesh.mesh_domain`.
"""

from __future__ import annotations

import logging
import time
from typing import TYPE_CHECKING, Literal, Sequence

import numpy as np
from skfem import Basis, ElementTriP1, ElementVector, FacetBasis, LinearForm, MeshTri
from skfem.helpers import dot
from skfem.models.elasticity import linear_elasticity

from ..solvers.constrained import solve_constrained
from ..solvers.conditions import Conditions, per_point, traction_at
from ..material import check_plane, lame, moduli, parse_materials
from .mesh import mesh_domain
from .solution import P1Solution

if TYPE_CHECKING:
    import scipy.sparse as sp
    from ..geometry.domain import Domain

__all__ = ["P1Elasticity"]

log = logging.getLogger(__name__)


class P1Elasticity(Conditions):
    """Plane linear elasticity with linear triangles (scikit-fem), the reference
    for `cnem.Elasticity`.

    The mesh is built at construction, so that conditions can be given on its
    nodes (`nodes`, `mesh`).

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
    mesh : skfem.MeshTri
        ``n`` nodes (``mesh.p`` is ``(2, n)``), ``t`` triangles.
    region : (t,) int64 ndarray
        Region index of each triangle.
    basis : skfem.Basis
        Vector P1 basis; dofs interleaved ``[u0x, u0y, u1x, ...]``.
    timings : dict
        Seconds spent meshing (``"mesh"``).
    region_materials : tuple of cnem.material.LinearElastic
        One per region.
    materials : (r, 2) ndarray
        Their ``(E, nu)``.
    """

    def __init__(self, domain: Domain,
                 materials: tuple[float, float] | Sequence[tuple[float, float]], *,
                 plane: str = "stress", nodes: int | None = None,
                 max_area: float | None = None, quality: float = 30.0):
        self.domain = domain
        check_plane(2, plane)
        self.region_materials = parse_materials(materials, len(domain.regions), plane)
        self.materials = moduli(self.region_materials)
        self.plane = plane
        t0 = time.perf_counter()
        points, tri, self.region = mesh_domain(domain, nodes=nodes, max_area=max_area,
                                               quality=quality)
        self.mesh = MeshTri(np.ascontiguousarray(points.T), np.ascontiguousarray(tri.T))
        self.basis = Basis(self.mesh, ElementVector(ElementTriP1()))
        self.timings = {"mesh": time.perf_counter() - t0}
        self._boundary = None
        super().__init__()

    def __repr__(self):
        return (f"<P1Elasticity plane {self.plane}, {len(self.nodes)} nodes, "
                f"{self.mesh.t.shape[1]} triangles, {len(self.prescribed()[0])} prescribed dofs, "
                f"{self.conditions_repr()}>")

    @property
    def nodes(self) -> np.ndarray:
        """``(n, 2)`` node coordinates (crack nodes once per face)."""
        return self.mesh.p.T

    # -- conditions (`Conditions`: add_dirichlet, add_traction, add_body_force) ---------
    points_name = "prob.nodes"
    edges_name = "boundary facet"

    @property
    def condition_points(self) -> np.ndarray:
        """``(n, 2)`` the nodes that conditions refer to (`nodes`)."""
        return self.nodes

    @property
    def condition_domain(self) -> Domain:
        """The domain meshed: its named boundaries may be given as ``where``."""
        return self.domain

    def boundary_edges(self) -> tuple:
        """The mesh's boundary facets as node pairs with the body on the left, and their
        outward normals (see `Conditions.boundary_edges`; `boundary_facets` in the
        same order)."""
        facets, _, normal = self.boundary_facets()
        edges = self.mesh.facets[:, facets].T.astype(np.int64)
        d = self.nodes[edges[:, 1]] - self.nodes[edges[:, 0]]
        flip = d[:, 1] * normal[:, 0] - d[:, 0] * normal[:, 1] < 0     # normal on the left
        edges[flip] = edges[flip][:, ::-1]
        return edges, normal

    def boundary_facets(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The boundary edges as scikit-fem facets (the older name of `boundary_edges`,
        in the same order).

        Returns
        -------
        facets : (e,) int ndarray
            Indices into ``mesh.facets``.
        midpoint : (e, 2) ndarray
        normal : (e, 2) ndarray
            Outward unit normals.
        """
        if self._boundary is None:
            facets = self.mesh.boundary_facets()
            fb = FacetBasis(self.mesh, ElementTriP1(), facets=facets, intorder=1)
            midpoint = self.mesh.p[:, self.mesh.facets[:, facets]].mean(axis=1).T
            self._boundary = facets, midpoint, np.asarray(fb.normals)[:, :, 0].T
        return self._boundary

    # -- assembly -----------------------------------------------------------------------
    def element_materials(self) -> np.ndarray:
        """``(t, 2)`` ``(E, nu)`` of every triangle."""
        return self.materials[self.region]

    def stiffness(self) -> sp.csr_matrix:
        """Global stiffness ``(2 n, 2 n)`` CSR, per-triangle Lamé parameters."""
        E, nu = self.element_materials().T
        lam, mu = lame(E, nu, self.plane)
        return linear_elasticity(lam[:, None], mu[:, None]).assemble(self.basis)

    def load(self) -> np.ndarray:
        """Load vector ``(2 n,)`` of the tractions and body forces."""
        f = np.zeros(self.basis.N)
        element = ElementVector(ElementTriP1())
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
    """`LinearForm` of ``value . v`` with ``value`` a constant ``(2,)`` or a callable
    of the quadrature points (and the outward normals when ``normal``)."""

    @LinearForm
    def form(v, w):
        shape = w.x.shape                                   # (2, elements, points)
        x = w.x.reshape(2, -1).T
        if normal:
            vals = traction_at(value, x, w.n.reshape(2, -1).T, what)
        else:
            vals = per_point(value, x, 2, what)
        return dot(vals.T.reshape(shape), v)

    return form


# ----------------------------------------------------------------------- solution
