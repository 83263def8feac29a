"""`P1Elasticity`: a linear finite element (scikit-fem P1 triangles) anchor for C-NEM.

The same problem definition as `cnem.Elasticity` (Dirichlet conditions on
nodes, tractions on boundary edges, body forces), solved on a quality mesh
of the domain made by `triangle`: every triangle lies in one region, material
interfaces are mesh edges and cracks are opened (their nodes duplicated, tips
excepted), so that crack faces are traction-free boundaries.

>>> import numpy as np, cnem, cnem.fem
>>> dom = cnem.geometry.rectangle(2.0, 1.0)
>>> prob = cnem.fem.P1Elasticity(dom, (1000.0, 0.3), nodes=200)
>>> prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, 0)
>>> prob.add_dirichlet(lambda p: (p[:, 0] < 1e-9) & (p[:, 1] < 1e-9), 1)
>>> prob.add_traction(lambda x, n: n[:, 0] > 0.5, [10.0, 0.0])
>>> sol = prob.solve()
>>> bool(np.allclose(sol.stress, [10.0, 0.0, 0.0]))           # uniform tension
True
>>> sol.energy_error(lambda x: np.tile([10.0, 0.0, 0.0], (len(x), 1))) < 1e-9
True
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable, Literal, Sequence

import numpy as np
import triangle
from shapely.geometry import Polygon
from skfem import Basis, ElementTriP1, ElementVector, FacetBasis, LinearForm, MeshTri
from skfem.helpers import dot, sym_grad
from skfem.models.elasticity import linear_elasticity


from .assembly.quadrature import triangle_quadrature
from .solvers.constrained import solve_constrained
from . import config
from .errors import GeometryError, InputError
from .geometry.cracks import split_cracks
from .geometry.pslg import BOUNDARY, CRACK
from .solvers.conditions import Conditions, per_point, traction_at
from .material import check_plane, lame, moduli, parse_materials, stiffness_matrix
from .solvers.solution import Solution, energy_error_density

if TYPE_CHECKING:
    import scipy.sparse as sp
    from .geometry.domain import Domain

__all__ = ["P1Elasticity", "P1Solution", "mesh_domain"]

log = logging.getLogger(__name__)

#: Segment markers handed to `triangle` are ``kind + _MARK`` (0 and 1 are its own).
_MARK = 2


# ---------------------------------------------------------------------- meshing
def _hole_points(domain):
    """One point inside each connected empty area enclosed by the domain."""
    union = domain.polygon
    pieces = getattr(union, "geoms", [union])
    points = []
    for piece in pieces:
        for ring in piece.interiors:
            empty = Polygon(ring).difference(union)
            for part in getattr(empty, "geoms", [empty]):
                if part.area > 0:
                    points.append(part.representative_point().coords[0])
    return np.asarray(points, dtype=float).reshape(-1, 2)


def _pslg_input(domain):
    """`triangle` input: PSLG vertices and segments (crack edges between two
    tips split at their midpoint so that they can be opened), region seeds, holes."""
    pslg = domain.pslg
    vertices, edges, kind = pslg.vertices, pslg.edges, pslg.kind
    crack = edges[kind == CRACK]
    degree = np.bincount(crack.ravel(), minlength=len(vertices))
    on_boundary = np.zeros(len(vertices), dtype=bool)
    on_boundary[edges[kind == BOUNDARY].ravel()] = True
    fixed = (degree >= 2) | on_boundary
    lone = np.flatnonzero((kind == CRACK) & ~fixed[edges].any(axis=1))
    if lone.size:
        mid = np.arange(len(vertices), len(vertices) + lone.size)
        vertices = np.concatenate([vertices, vertices[edges[lone]].mean(axis=1)])
        halves = np.column_stack([edges[lone, 0], mid, mid, edges[lone, 1]]).reshape(-1, 2)
        keep = np.ones(len(edges), dtype=bool)
        keep[lone] = False
        edges = np.concatenate([edges[keep], halves])
        kind = np.concatenate([kind[keep], np.full(len(halves), CRACK, dtype=kind.dtype)])
    seeds = [[*region.representative_point().coords[0], i, 0.0]
             for i, region in enumerate(domain.regions)]
    data = {"vertices": np.ascontiguousarray(vertices, dtype=float),
            "segments": np.ascontiguousarray(edges, dtype=np.int32),
            "segment_markers": (kind.astype(np.int32) + _MARK)[:, None],
            "regions": np.asarray(seeds, dtype=float)}
    holes = _hole_points(domain)
    if len(holes):
        data["holes"] = holes
    return data


def _number(value):
    """A positive float as `triangle` parses it: digits and a point, no exponent."""
    return np.format_float_positional(float(value), trim="-")


def _triangulate(data, quality, max_area):
    switches = f"pq{_number(quality)}AQ" + ("" if max_area is None else f"a{_number(max_area)}")
    return triangle.triangulate(data, switches)


def mesh_domain(domain: Domain, *, nodes: int | None = None, max_area: float | None = None,
                quality: float = 30.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Quality triangle mesh of a domain, opened along its cracks.

    Parameters
    ----------
    domain : Domain
    nodes : int, optional
        Target node count (before crack opening): starting from a maximum
        triangle area of ``2 * area / nodes``, the area is corrected (at most
        6 meshes) until the count lies within 2 % of the target; a warning is
        logged if the best mesh is more than 5 % off.
    max_area : float, optional
        Maximum triangle area (``triangle``'s ``a`` switch). Give at most one
        of ``nodes`` and ``max_area``; with neither, only the quality bound
        applies (the coarsest quality mesh).
    quality : float
        Minimum angle in degrees (``triangle``'s ``q`` switch), at most 34.

    Returns
    -------
    points : (n, 2) ndarray
        Node coordinates; crack nodes appear once per crack face.
    triangles : (t, 3) int64 ndarray
        Counter-clockwise triangles.
    region : (t,) int64 ndarray
        Region index of each triangle.

    Raises
    ------
    InputError
        Both ``nodes`` and ``max_area`` given, non-positive values, a quality
        above 34 degrees, or a target node count below the coarsest mesh.
    GeometryError
        If a crack cannot be opened.
    """
    if nodes is not None and max_area is not None:
        raise InputError(f"give either nodes or max_area, received nodes={nodes!r} and "
                         f"max_area={max_area!r}; drop one of them")
    if not 0.0 < float(quality) <= 34.0:
        raise InputError(f"quality: expected a minimum angle in (0, 34] degrees, received "
                         f"{quality!r} (triangle may not terminate above 34)")
    if max_area is not None and not float(max_area) > 0.0:
        raise InputError(f"max_area: expected a positive number, received {max_area!r}")
    data = _pslg_input(domain)
    if nodes is None:
        out = _triangulate(data, quality, max_area)
    else:
        out = _mesh_for_nodes(data, domain.area, int(nodes), quality)
    points = out["vertices"]
    tri = out["triangles"].astype(np.int64)
    region = np.rint(out["triangle_attributes"][:, 0]).astype(np.int64)
    ab, ac = points[tri[:, 1]] - points[tri[:, 0]], points[tri[:, 2]] - points[tri[:, 0]]
    flip = ab[:, 0] * ac[:, 1] - ab[:, 1] * ac[:, 0] < 0
    tri[flip] = tri[flip][:, [0, 2, 1]]
    segments = out["segments"].astype(np.int64)
    kind = (out["segment_markers"].ravel() - _MARK).astype(np.int8)
    if (kind < 0).any():
        raise GeometryError("triangle returned segments that are not in the domain's PSLG; "
                            "check the domain for crossing boundaries")
    points, _, tri, _, _ = split_cracks(points, tri, segments, kind)
    return points, tri, region


def _mesh_for_nodes(data, area, target, quality):
    """Mesh whose node count is within `cnem.config.MESH_NODES_STOP` of ``target`` if possible
    (secant on ``log count`` against ``log max_area``)."""
    if target < 3:
        raise InputError(f"nodes: expected a target node count >= 3, received {target}")
    coarsest = _triangulate(data, quality, None)
    if len(coarsest["vertices"]) >= (1.0 - config.MESH_NODES_RTOL) * target:
        if len(coarsest["vertices"]) <= (1.0 + config.MESH_NODES_RTOL) * target:
            return coarsest
        raise InputError(f"nodes: the coarsest quality-{quality:g} mesh of this domain already "
                         f"has {len(coarsest['vertices'])} nodes, more than the target {target}; "
                         "ask for more nodes or a coarser domain description")
    tries = []
    max_area = 2.0 * area / target
    for _ in range(config.MESH_NODES_TRIES):
        out = _triangulate(data, quality, max_area)
        count = len(out["vertices"])
        tries.append((abs(count / target - 1.0), count, max_area, out))
        if abs(count / target - 1.0) <= config.MESH_NODES_STOP:
            break
        slope = -1.0
        if len(tries) >= 2 and tries[-1][2] != tries[-2][2] and tries[-1][1] != tries[-2][1]:
            slope = (np.log(tries[-1][1] / tries[-2][1])
                     / np.log(tries[-1][2] / tries[-2][2]))
            slope = min(max(slope, -2.0), -0.5)
        max_area *= (target / count) ** (1.0 / slope)
    best = min(tries, key=lambda item: item[0])
    if best[0] > config.MESH_NODES_RTOL:
        log.warning("mesh_domain: %d nodes for a target of %d (max area %.3g)",
                    best[1], target, best[2])
    log.info("mesh_domain: %d nodes (target %d) after %d meshes", best[1], target, len(tries))
    return best[3]


# ------------------------------------------------------------------------ problem
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
                 plane: str = "stress", nodes: np.ndarray | None = None,
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
@dataclass(eq=False, repr=False)
class P1Solution(Solution):
    """The solution of a `P1Elasticity` problem (the fields of `cnem.solvers.solution`).

    Attributes
    ----------
    u : (n, 2) ndarray
        Nodal displacements.
    stress : (t, 3) ndarray
        ``[sxx, syy, sxy]`` per triangle (constant on each).
    strain : (t, 3) ndarray
        ``[exx, eyy, 2 exy]`` per triangle.
    C : (t, 3, 3) ndarray
        Elastic matrix of each triangle.
    mesh : skfem.MeshTri
    region : (t,) int64 ndarray
        Region index of each triangle.
    basis : skfem.Basis
    plane : {"stress", "strain"}
    timings : dict
        Seconds spent in ``"mesh"``, ``"assembly"`` and ``"solve"``.
    """

    stress: np.ndarray
    strain: np.ndarray
    C: np.ndarray
    mesh: Any
    region: np.ndarray
    basis: Any
    plane: str
    timings: dict

    stress_at = "triangles"

    @classmethod
    def from_dofs(cls, problem: P1Elasticity, x: np.ndarray,
                  timings: dict[str, float]) -> P1Solution:
        """The solution of ``problem`` with the interleaved nodal unknowns ``x (2 n,)``."""
        eps = sym_grad(problem.basis.interpolate(x))[:, :, :, 0]          # (2, 2, t)
        strain = np.column_stack([eps[0, 0], eps[1, 1], 2.0 * eps[0, 1]])
        E, nu = problem.element_materials().T
        C = stiffness_matrix(E, nu, problem.plane)
        return cls(problem=problem, u=x.reshape(-1, 2), stress=np.einsum("kij,kj->ki", C, strain),
                   strain=strain, C=C, mesh=problem.mesh, region=problem.region,
                   basis=problem.basis, plane=problem.plane, timings=timings)

    def displacement(self, points: np.ndarray) -> np.ndarray:
        """Displacements ``(p, 2)`` at points ``(p, 2)`` inside the mesh, through the P1
        shape functions."""
        pts = np.asarray(points, dtype=float).reshape(-1, 2)
        values = self.basis.probes(np.ascontiguousarray(pts.T)) @ self.u.reshape(-1)
        return values.reshape(2, -1).T                      # probes give x values, then y

    def energy_error(self, exact_stress: Callable[..., np.ndarray], *, order: int = 4) -> float:
        """Error in the energy norm against an exact stress field.

        ``sqrt(sum_T ∫_T (σh - σ)ᵀ C⁻¹ (σh - σ) dΩ)`` with a triangle rule of
        degree ``order`` on every triangle, collapsed at the crack tips (see
        `cnem.assembly.quadrature.triangle_quadrature`) like the C-NEM error.

        Parameters
        ----------
        exact_stress : callable ``(q, 2) -> (q, 3)`` or ``(q, 2), (q,) -> (q, 3)``
            ``[sxx, syy, sxy]`` at points; a function of two arguments also
            receives the region of the triangle holding each point (for
            fields discontinuous across material interfaces).
        order : int
            Degree of the quadrature rule.

        Returns
        -------
        float
        """
        corners = self.mesh.p.T[self.mesh.t.T]                      # (t, 3, 2)
        e1, e2 = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
        clockwise = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0] < 0
        corners[clockwise] = corners[clockwise][:, ::-1]
        owner, points, weights = triangle_quadrature(corners, order,
                                                     singular=self.problem.domain.tips)
        density = energy_error_density(points, self.region[owner], self.stress[owner],
                                       self.C[owner], exact_stress)
        return float(np.sqrt(weights @ density))

    def energy(self) -> float:
        """Strain energy ``1/2 sum_T A_T σ_T · ε_T``."""
        area = self.basis.dx.sum(axis=1)
        return 0.5 * float(area @ (self.stress * self.strain).sum(axis=1))

    def nodal_average(self, values: np.ndarray) -> np.ndarray:
        """Triangle values ``(t, ...)`` at the nodes: the area-weighted mean over the
        triangles around each node, ``(n, ...)``."""
        values = np.asarray(values, dtype=float)
        n, tri = self.mesh.p.shape[1], self.mesh.t.T
        area = np.repeat(self.basis.dx.sum(axis=1), 3)
        flat = values.reshape(len(values), -1)
        weight = np.bincount(tri.ravel(), weights=area, minlength=n)
        out = np.stack([np.bincount(tri.ravel(), weights=area * np.repeat(col, 3), minlength=n)
                        for col in flat.T], axis=1) / weight[:, None]
        return out.reshape((n,) + values.shape[1:])

    def plot_mesh(self) -> tuple:
        """The mesh nodes and triangles and the domain's diameter."""
        return self.mesh.p.T, self.mesh.t.T, self.problem.domain.diameter

    def write_fields(self, path: str, point_data: dict[str, np.ndarray],
                     cell_data: dict[str, np.ndarray]) -> None:
        """The mesh with the fields (`cnem.io.write_points` with its triangles)."""
        from . import io
        io.write_points(self.mesh.p.T, path, triangles=self.mesh.t.T, point_data=point_data,
                        cell_data=cell_data)
