"""`discretize`: node cloud -> constrained Delaunay triangulation, opened cracks, cells."""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Callable, Literal

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike

from .._predicates import Frame
from ..errors import GeometryError, InputError
from ._kernels import polygon_moments
from .cells import voronoi_cells
from .cloud import NodeCloud
from .cracks import split_cracks
from .pslg import SegmentKind
from .selection import boundary_subset
from ..shape import shape_functions
from ..spatial.rtree import RTree
from .topology import (circumcenters, constraint_edges, cut_between_regions,
                       triangle_neighbors, vertex_triangles)

from .triangulation import constrained_delaunay
from .._sets import distinct

if TYPE_CHECKING:
    from .domain import Domain

__all__ = ["Cells", "Model", "discretize", "check_model"]

log = logging.getLogger(__name__)


@dataclass(frozen=True, repr=False)
class Cells:
    """SCNI integration cells: constrained Voronoi cells cut by the domain and regions.

    Attributes
    ----------
    node : (m,) int64 ndarray
        Owner node of each cell.
    region : (m,) int64 ndarray
    offsets : (m + 1,) int64 ndarray
    vertices : (k, 2) ndarray
        Cell ``c`` is ``vertices[offsets[c]:offsets[c + 1]]`` (counter-clockwise).
    area : (m,) ndarray
        By the shoelace formula unless given (a subset's, say).
    spokes : (k,) bool ndarray or None
        Fan sub-cells only (`cnem.assembly.subdivide`): the edge from vertex
        ``i`` to the next is a spoke, inside a model cell (integrated by its
        midpoint alone, by `boundary_quadrature`).
    edge_source : (k,) int64 ndarray or None
        Fan sub-cells only: the edge from vertex ``i`` to the next lies on its
        parent cell's edge from vertex ``edge_source[i]`` (a position in the
        parent's polygon) to the next, in the same direction; a spoke joins the
        apex to the parent's vertex ``edge_source[i]``.
    """

    node: np.ndarray
    region: np.ndarray
    offsets: np.ndarray
    vertices: np.ndarray
    spokes: np.ndarray | None = None
    edge_source: np.ndarray | None = None
    area: np.ndarray | None = None

    def __post_init__(self):
        if self.area is None:
            object.__setattr__(self, "area", self._moments()[0])

    def _moments(self):
        """Areas and centroids by the shoelace formula, relative to each cell's first
        vertex (no cancellation far from the origin)."""
        if len(self.vertices) == 0:
            return np.zeros(0), np.zeros((0, 2))
        return polygon_moments(np.asarray(self.offsets, dtype=np.int64),
                               np.ascontiguousarray(self.vertices, dtype=np.float64))

    def __len__(self):
        return len(self.node)

    @property
    def measure(self) -> np.ndarray:
        """``(m,)`` the cells' areas (the volumes of 3-D cells), for dimension-generic code."""
        return self.area

    def subset(self, index: ArrayLike) -> Cells:
        """The cells ``index`` (in that order) as a `Cells` of their own."""
        index = np.asarray(index, dtype=np.int64)
        counts = self.offsets[index + 1] - self.offsets[index]
        offsets = np.zeros(len(index) + 1, dtype=np.int64)
        np.cumsum(counts, out=offsets[1:])
        verts = np.repeat(self.offsets[index] - offsets[:-1], counts) + np.arange(offsets[-1])
        return Cells(self.node[index], self.region[index], offsets, self.vertices[verts],
                     None if self.spokes is None else self.spokes[verts],
                     None if self.edge_source is None else self.edge_source[verts],
                     self.area[index])

    def polygon(self, i: int) -> np.ndarray:
        """Vertices of cell ``i``, ``(k, 2)``, counter-clockwise."""
        return self.vertices[self.offsets[i]:self.offsets[i + 1]]

    def centroid(self) -> np.ndarray:
        """Centroids of all cells, ``(m, 2)``."""
        return self._moments()[1]

    def __repr__(self):
        return f"<Cells {len(self.node)} cells, {len(self.vertices)} vertices>"


@dataclass(frozen=True, repr=False)
class Model:
    """A discretised domain: nodes (cracks opened), triangulation and integration cells.

    Attributes
    ----------
    cloud : NodeCloud
    nodes : (n, 2) ndarray
        Nodes after splitting cracks (one node per crack face except at tips).
    node_of_point : (n,) int64 ndarray
        Index into ``cloud.points`` of each node.
    triangles : (t, 3) int64 ndarray
        Constrained Delaunay triangles, counter-clockwise.
    triangle_region : (t,) int64 ndarray
    segments : (s, 2) int64 ndarray
        Constraint segments after splitting (each crack segment once per face).
    segment_kind : (s,) int8 ndarray
        `SegmentKind` of each segment: 0 boundary, 1 interface, 2 crack face.
    cells : Cells
    timings : dict
        Seconds spent in each stage.
    """

    cloud: NodeCloud
    nodes: np.ndarray
    node_of_point: np.ndarray
    triangles: np.ndarray
    triangle_region: np.ndarray
    segments: np.ndarray
    segment_kind: np.ndarray
    cells: Cells
    timings: dict
    #: what `neighbors`, `circumcircles` and `triangle_tree` computed, written by them alone
    _derived: dict = field(default_factory=dict, repr=False, compare=False)

    @property
    def domain(self) -> Domain:
        """Domain: the body this model discretises."""
        return self.cloud.domain

    @property
    def frame(self) -> Frame:
        """Frame: the local frame (origin at the domain box's lower-left corner rounded
        to a coarse grid, a power-of-two scale) in which the geometric computations
        run, so that the model answers the same at any origin and in any units."""
        return self.domain.frame

    def local_nodes(self) -> np.ndarray:
        """The nodes in `frame`, ``(n, 2)``. Computed once."""
        return self._derive("local nodes", lambda: self.frame.to_local(self.nodes))

    def neighbors(self, *, across_regions: bool = False) -> np.ndarray:
        """The triangle across each edge, ``(t, 3)`` int64: ``nb[t, k]`` faces vertex
        ``k``; -1 on the boundary, at crack faces and (unless ``across_regions``)
        where the neighbour lies in another region. Computed once (`discretize`
        already has it).
        """
        tables = self._derive("neighbors",
                              lambda: _neighbor_tables(self.triangles, self.triangle_region))
        return tables[1 if across_regions else 0]

    def circumcircles(self) -> tuple[np.ndarray, np.ndarray, RTree]:
        """The circumcircles of the triangles in the local `frame` (centres to
        relative round-off at any origin): centres ``(t, 2)``, squared radii ``(t,)``
        and an R-tree over their boxes (which also holds every triangle: point
        location), all in local coordinates. Computed on first call, then kept."""
        def build():
            nodes = self.local_nodes()
            centre = circumcenters(nodes, self.triangles)
            radius2 = ((nodes[self.triangles[:, 0]] - centre) ** 2).sum(axis=1)
            radius = np.sqrt(radius2)[:, None]
            return centre, radius2, RTree(centre - radius, centre + radius)
        return self._derive("circumcircles", build)

    def triangle_tree(self) -> RTree:
        """An R-tree over the boxes of the triangles: tighter than the circumcircles'
        (`circumcircles`), worth building to locate many points. Built on first
        call, then kept.

        Returns
        -------
        RTree
            Entry ``i`` is the bounding box of ``triangles[i]`` in the local `frame`.
        """
        def build():
            corners = self.local_nodes()[self.triangles]
            return RTree(corners.min(axis=1), corners.max(axis=1))
        return self._derive("triangle tree", build)

    def _derive(self, name, build):
        """``build()``, computed on the first request for ``name`` and kept."""
        if name not in self._derived:
            self._derived[name] = build()
        return self._derived[name]

    def boundary_with_normals(self) -> tuple[np.ndarray, np.ndarray]:
        """The edges of the body's boundary (outer boundary, holes and crack faces;
        interfaces between regions are not) and their outward unit normals.

        Returns
        -------
        edges : (e, 2) int64 ndarray
            Node pairs, the body on the left (counter-clockwise).
        normal : (e, 2) ndarray
        """
        edges, _ = constraint_edges(self.triangles, self.neighbors(across_regions=True))
        d = self.nodes[edges[:, 1]] - self.nodes[edges[:, 0]]
        return edges, np.column_stack([d[:, 1], -d[:, 0]]) / np.linalg.norm(d, axis=1)[:, None]

    def boundary_nodes(self, name_or_predicate: str | Callable | None = None) -> np.ndarray:
        """Indices of the nodes on the boundary, on a named boundary, or on the boundary
        where a predicate holds.

        Parameters
        ----------
        name_or_predicate : None, str or callable ``(p, 2) -> (p,) bool``
            None: every node on the outer boundary and the holes (crack faces and
            interfaces are not the boundary); a str: the nodes on that named boundary
            (`Domain.boundaries`), between its vertices too; a callable: the boundary
            nodes at which it is True.

        Returns
        -------
        (k,) int64 ndarray
            Sorted.

        Raises
        ------
        ConditionError
            An unknown name (the error lists the known ones), or a predicate that does
            not return one bool per point.
        """
        if isinstance(name_or_predicate, str):
            return np.flatnonzero(self.domain.on_boundary(self.nodes, name_or_predicate))
        on = distinct(self.segments[self.segment_kind == SegmentKind.BOUNDARY])
        return boundary_subset(self.nodes, on, name_or_predicate)

    def node_sides(self) -> np.ndarray:
        """A point on the side of each node: the area-weighted centroid of its cells
        (for the two copies of a crack-face node, a point on each one's face).

        Returns
        -------
        (n, 2) ndarray
        """
        cells = self.cells
        n = len(self.nodes)
        weight = np.bincount(cells.node, weights=cells.area, minlength=n)
        return np.column_stack([np.bincount(cells.node, weights=cells.area * c, minlength=n)
                                for c in cells.centroid().T]) / weight[:, None]

    def shape_functions(self, points: ArrayLike, *, kind: Literal["sibson", "laplace"] = "sibson",
                        triangles: ArrayLike | None = None, gradient: bool = False,
                        in_order: bool = True
                        ) -> (sp.csr_matrix | tuple[sp.csr_matrix, np.ndarray]
                              | tuple[sp.csr_matrix, ...]):
        """Constrained natural-neighbour coordinates, see `cnem.shape.shape_functions`.

        Returns
        -------
        scipy.sparse.csr_matrix, shape (p, n)
            Or ``(Phi, dPhi_dx, dPhi_dy)`` with ``gradient=True`` (a
            `cnem.shape.natural.ShapeGradients`: also ``value``, ``gradient``, ``dim``).
        """
        return shape_functions(self, points, kind=kind, triangles=triangles, gradient=gradient,
                               in_order=in_order)

    def __repr__(self):
        dom = self.domain
        nreg, ncr = len(dom.regions), len(dom.cracks)
        return (f"<Model {len(self.nodes)} nodes, {len(self.cells)} cells, {nreg} "
                f"region{'s' * (nreg != 1)}, {ncr} crack{'s' * (ncr != 1)} "
                f"({len(dom.tips)} tip{'s' * (len(dom.tips) != 1)})>")


def check_model(model: object, caller: str) -> Model:
    """``model`` once it is known to be a `Model`: a node cloud, a domain or None given
    where a model is expected is named, with the call that makes a model.

    Raises
    ------
    InputError
        Anything but a `Model`.
    """
    from .model3d import Model3D
    if not isinstance(model, (Model, Model3D)):
        hint = ("discretize it first: cnem.discretize(cloud)" if isinstance(model, NodeCloud)
                else "make one with cnem.discretize(cnem.nodes.regular(domain, h))")
        raise InputError(f"{caller} expects a Model, received {type(model).__name__}; {hint}")
    return model


def discretize(cloud: NodeCloud, *, progress: bool | None = None) -> Model:
    """Constrained Delaunay triangulation, crack opening and constrained Voronoi cells.

    Parameters
    ----------
    cloud : NodeCloud
        From `cnem.nodes`.
    progress : bool, optional
        Show a progress bar while clipping cells near constraints
        (default: only on a terminal).

    Returns
    -------
    Model
        A `cnem.geometry.model3d.Model3D` for a cloud on a `cnem.Domain3D`
        (boundary-conforming tetrahedra and constrained Voronoi cells).

    Raises
    ------
    GeometryError
        Crossing constraints (`triangle` would need Steiner points), nodes that
        are not vertices of the triangulation.
    """
    _check_cloud(cloud, "discretize")
    if cloud.dim == 3:
        from .model3d import discretize_3d
        return discretize_3d(cloud)
    timings = {}
    nodes, node_of_point, tri, region, segments, kind, neighbors = triangulate(cloud, timings)
    t2 = time.perf_counter()
    frame = cloud.domain.frame
    local = frame.to_local(nodes)
    node, cell_region, offsets, vertices = voronoi_cells(local, tri, region, progress=progress,
                                                         neighbors=neighbors[0], frame=frame,
                                                         star=neighbors[2])
    vertices = frame.to_global(vertices, out=vertices)     # voronoi_cells' own array
    timings["cells"] = time.perf_counter() - t2
    log.info("discretize: %d nodes, %s", len(nodes),
             ", ".join(f"{k} {v:.3f} s" for k, v in timings.items()))
    cells = Cells(node, cell_region, offsets, vertices)
    return Model(cloud, nodes, node_of_point, tri, region, segments, kind, cells, timings,
                 _derived={"neighbors": neighbors, "local nodes": local})


def _check_cloud(cloud, caller):
    """Refuse anything but a `NodeCloud`, naming how to make one."""
    if not isinstance(cloud, NodeCloud):
        raise GeometryError(f"{caller} expects a NodeCloud from cnem.nodes, received "
                            f"{type(cloud).__name__}; build one with cnem.nodes.from_points")


def triangulate(cloud, timings, caller="discretize"):
    """The stages of `discretize` before the cells: constrained Delaunay
    triangulation, crack opening and the neighbour tables.

    Parameters
    ----------
    cloud : NodeCloud
    timings : dict
        Receives the seconds of ``triangulation`` and ``splitting``.
    caller : str
        Named in the error when ``cloud`` is not a `NodeCloud`.

    Returns
    -------
    nodes, node_of_point, triangles, triangle_region, segments, segment_kind
        As the `Model` attributes.
    neighbors : tuple
        Two (t, 3) int64 ndarray, the neighbours within regions and across them
        (`Model.neighbors`), then the vertex star they were found from
        (`cnem.geometry.topology.vertex_triangles`).
    """
    _check_cloud(cloud, caller)
    t0 = time.perf_counter()
    tri, region = constrained_delaunay(cloud)
    t1 = time.perf_counter()
    nodes, node_of_point, tri, segments, kind = split_cracks(
        cloud.points, tri, cloud.segments, cloud.segment_kind)
    neighbors = _neighbor_tables(tri, region)
    timings.update(triangulation=t1 - t0, splitting=time.perf_counter() - t1)
    return nodes, node_of_point, tri, region, segments, kind, neighbors


def _neighbor_tables(triangles, region):
    """`Model.neighbors` within regions and across them, and the vertex star they were
    found from: ``(cut, every, (offsets, star))``."""
    star = vertex_triangles(triangles, int(triangles.max()) + 1 if len(triangles) else 0)
    every = triangle_neighbors(triangles, star=star)
    return cut_between_regions(every, region), every, star
