"""A discretised 3-D body: nodes, boundary-conforming tetrahedra, constrained Voronoi cells.

`discretize_3d` (what `cnem.discretize` does with a 3-D node cloud) tetrahedrises
the nodes so that every boundary triangle of the cloud is a face
(`conforming_tetrahedra`: boundary nodes are added where the input does not
allow it, and are nodes like the others, ``node_of_point == -1``), then cuts the
constrained Voronoi cells (`constrained_voronoi_cells`). Both run in the model's local frame (`frame`:
the bounding box's corner rounded to a coarse origin, a power-of-two scale), so the
same body moved a million units or in other units gives the same cells to round-off;
the results are mapped back (the nodes are the cloud's points, bit for bit).
`Model3D` answers the
questions the problems ask of a model: shape functions (constrained Laplace or
Sibson coordinates, `cnem.shape.natural3d`), its boundary with outward normals,
its cells.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field
from typing import Callable, Literal

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike

from .. import config
from .._predicates import Frame, bounding_box, local_frame
from ..shape.natural import ShapeGradients
from ..shape.natural3d import TetMesh, shape_functions_3d, tet_mesh
from .cells3d import Cells3D, constrained_voronoi_cells
from ..errors import ConditionError
from .cloud import NodeCloud
from .domain3d import Domain3D
from .selection import boundary_subset
from .tetrahedra import conforming_tetrahedra
from .._sets import distinct

__all__ = ["Model3D", "discretize_3d"]

#: A cell's facet triangle whose sides are below this fraction of the model's size (its
#: area below the square) is flat: round-off of coincident circumcentres.
FLAT_FACET_RTOL = 1e-7

log = logging.getLogger(__name__)


@dataclass(frozen=True, repr=False)
class Model3D:
    """A discretised 3-D body.

    Attributes
    ----------
    cloud : NodeCloud
        The 3-D cloud it was made from (``cloud.domain`` a `cnem.Domain3D`).
    nodes : (n, 3) ndarray
        The cloud's points, then the boundary nodes the tetrahedrisation added.
    node_of_point : (n,) int64 ndarray
        Index into ``cloud.points`` of each node, -1 for an added one.
    tetrahedra : (t, 4) int64 ndarray
        Positively oriented, inside the body.
    tet_region : (t,) int64 ndarray
    boundary_faces : (b, 3) int64 ndarray
        Triangles tiling every boundary and interface, oriented out of
        ``boundary_face_regions[:, 0]``.
    boundary_face_regions : (b, 2) int64 ndarray
        Region inside each face and on its other side (-1: outside the body).
    cells : Cells3D
    timings : dict
        Seconds spent in each stage.
    frame : cnem._predicates.Frame
        The local frame the tetrahedra and cells were computed in (and the facet
        geometry of the assembly is: its coordinates keep their digits far from the
        origin).
    """

    cloud: NodeCloud
    nodes: np.ndarray
    node_of_point: np.ndarray
    tetrahedra: np.ndarray
    tet_region: np.ndarray
    boundary_faces: np.ndarray
    boundary_face_regions: np.ndarray
    cells: Cells3D
    timings: dict
    frame: Frame
    #: what `tet_mesh` computed, kept
    _derived: dict = field(default_factory=dict, repr=False, compare=False)

    @property
    def dim(self) -> int:
        """int: 3."""
        return 3

    @property
    def domain(self) -> Domain3D:
        """Domain3D: the body this model discretises."""
        return self.cloud.domain

    def tet_mesh(self) -> TetMesh:
        """The tetrahedrisation prepared for the shape functions, the boundary and
        interface faces as constraints (built on first call, then kept)."""
        if "tet mesh" not in self._derived:
            self._derived["tet mesh"] = tet_mesh(self.nodes, self.tetrahedra,
                                                 tet_region=self.tet_region,
                                                 constraint_faces=self.boundary_faces)
        return self._derived["tet mesh"]

    def shape_functions(self, points: ArrayLike, *, kind: Literal["laplace", "sibson"] = "laplace",
                        gradient: bool = False) -> sp.csr_matrix | ShapeGradients:
        """Constrained natural-neighbour coordinates at points of the body.

        Parameters
        ----------
        points : (p, 3) array_like
        kind : {"laplace", "sibson"}
        gradient : bool
            Also their derivatives (not at nodes nor on boundary faces).

        Returns
        -------
        scipy.sparse.csr_matrix, shape (p, n)
            Or a `ShapeGradients` ``(Phi, dPhi_dx, dPhi_dy, dPhi_dz)``.
        """
        return shape_functions_3d(self.tet_mesh(), points, kind=kind, gradient=gradient)

    def boundary_with_normals(self) -> tuple[np.ndarray, np.ndarray]:
        """The triangles of the body's outer surface (cavities included, interfaces
        not) and their outward unit normals.

        Returns
        -------
        faces : (e, 3) int64 ndarray
            Counter-clockwise seen from outside.
        normal : (e, 3) ndarray
        """
        outer = self.boundary_face_regions[:, 1] < 0
        faces = self.boundary_faces[outer]
        corners = self.domain.to_local(self.nodes[faces].reshape(-1, 3)).reshape(-1, 3, 3)
        nrm = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        return faces, nrm / np.linalg.norm(nrm, axis=1)[:, None]

    def boundary_nodes(self, name_or_predicate: Callable | None = None) -> np.ndarray:
        """Indices of the nodes on the body's outer surface (cavities included,
        interfaces not), or of those where a predicate holds.

        Parameters
        ----------
        name_or_predicate : None or callable ``(p, 3) -> (p,) bool``
            3-D bodies have no named boundaries yet.

        Returns
        -------
        (k,) int64 ndarray
            Sorted.

        Raises
        ------
        ConditionError
            A name, or a predicate that does not return one bool per point.
        """
        if isinstance(name_or_predicate, str):
            raise ConditionError(f"{name_or_predicate!r}: a 3-D body has no named boundaries "
                                 "yet; select the nodes with a predicate (p, 3) -> (p,) bool")
        faces, _ = self.boundary_with_normals()
        return boundary_subset(self.nodes, distinct(faces), name_or_predicate)

    def __repr__(self):
        added = int(np.count_nonzero(self.node_of_point < 0))
        return (f"<Model3D {len(self.nodes)} nodes ({added} added on the boundary), "
                f"{len(self.tetrahedra)} tetrahedra, {len(self.cells.node)} cells, "
                f"{self.domain.n_regions} region{'s' * (self.domain.n_regions != 1)}>")


def discretize_3d(cloud: NodeCloud) -> Model3D:
    """Boundary-conforming tetrahedrisation and constrained Voronoi cells of a 3-D cloud.

    Parameters
    ----------
    cloud : NodeCloud
        On a `cnem.Domain3D`, with its ``boundary_faces``.

    Returns
    -------
    Model3D
    """
    timings = {}
    t0 = time.perf_counter()
    frame = local_frame(np.stack(bounding_box(cloud.points)))
    tets = conforming_tetrahedra(frame.to_local(cloud.points), cloud.boundary_faces,
                                 cloud.boundary_face_regions)
    t1 = time.perf_counter()
    timings["tetrahedra"] = t1 - t0
    cells = constrained_voronoi_cells(tets.points, tets.tetrahedra, tets.tet_region,
                                      tets.boundary_faces, tets.boundary_face_regions)
    cells = _without_flat_facets(cells, float(np.linalg.norm(np.ptp(tets.points, axis=0))),
                                 config.ROUNDOFF_ULPS * frame.resolution)
    timings["cells"] = time.perf_counter() - t1
    node_of_point = np.full(len(tets.points), -1, dtype=np.int64)
    node_of_point[:tets.n_input] = np.arange(tets.n_input)
    nodes = np.concatenate([np.asarray(cloud.points, dtype=np.float64),
                            frame.to_global(tets.points[tets.n_input:])])
    log.info("discretize: %d nodes, %s", len(tets.points),
             ", ".join(f"{k} {v:.3f} s" for k, v in timings.items()))
    return Model3D(cloud, nodes, node_of_point, tets.tetrahedra, tets.tet_region,
                   tets.boundary_faces, tets.boundary_face_regions, _to_global(cells, frame),
                   timings, frame)


def _to_global(cells: Cells3D, frame: Frame) -> Cells3D:
    """Cells computed in ``frame`` back in global coordinates (the scale is a power of
    two: volumes and normals come back exactly).

    Parameters
    ----------
    cells : Cells3D
        In the local frame; its facet triangles are mapped in place (do not use it
        after).
    frame : cnem._predicates.Frame

    Returns
    -------
    Cells3D
    """
    apex = None if cells.apex is None else frame.to_global(cells.apex)
    # in place: the local cells are not used after, and their triangles are the largest
    # array of the model (a second copy would be a GB at 300k nodes)
    return Cells3D(cells.node, cells.region, cells.volume * frame.scale ** 3,
                   frame.to_global(cells.facet_triangles, out=cells.facet_triangles),
                   cells.facet_cell, cells.facet_normal, apex)


def _without_flat_facets(cells: Cells3D, size: float, resolution: float) -> Cells3D:
    """The cells without their facet triangles of no area (on lattices, cospherical
    tetrahedra share a circumcentre and the dual polygons repeat vertices): they carry
    no flux, and their normals mean nothing.

    Parameters
    ----------
    cells : Cells3D
    size : float
        The model's diameter; a triangle is flat below ``(FLAT_FACET_RTOL size)^2``.
    resolution : float
        The round-off of the global coordinates in the cells' units: a triangle thinner
        than that (its height to its longest side) would be flat, or folded, once its
        corners are mapped back far from the origin.

    Returns
    -------
    Cells3D
    """
    tri = cells.facet_triangles
    # (f, 3) temporaries only: the triangles are the model's largest array
    u, v = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    area = 0.5 * np.linalg.norm(np.cross(u, v), axis=1)
    longest = np.maximum(np.linalg.norm(u, axis=1), np.linalg.norm(v, axis=1))
    del u, v
    np.maximum(longest, np.linalg.norm(tri[:, 2] - tri[:, 1], axis=1), out=longest)
    keep = (area > (FLAT_FACET_RTOL * size) ** 2) & (2.0 * area > resolution * longest)
    if keep.all():
        return cells
    return Cells3D(cells.node, cells.region, cells.volume, tri[keep], cells.facet_cell[keep],
                   cells.facet_normal[keep], cells.apex)
