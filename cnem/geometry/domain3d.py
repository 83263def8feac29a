"""`Domain3D`: a body bounded by closed triangle surfaces, with regions and cavities.

>>> import numpy as np, cnem
>>> v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
>>> f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
>>> dom = cnem.Domain3D((v, f))
>>> round(dom.volume * 6, 12), dom.contains([[0.1, 0.1, 0.1], [1, 1, 1]]).tolist()
(1.0, [True, False])
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from .. import config
from ..errors import GeometryError, check_array, check_points, check_real
from .surface_checks import (check_closed, check_faces, check_self_intersections,
                             face_components)
from .surface_queries import (face_tree, faces_within, region_weights, region_winding,
                              solid_angle_winding)
from .._sets import distinct

__all__ = ["Domain3D"]

_TRIMESH_SUFFIXES = {".stl", ".obj", ".ply", ".off", ".glb", ".gltf"}
_MESHIO_SUFFIXES = {".vtk", ".vtu", ".msh", ".xdmf", ".inp", ".mesh", ".med"}


def _surface_arrays(obj, what):
    """``(vertices (k, 3), faces (f, 3))`` of one closed surface given as a pair of arrays
    or as a trimesh, pyvista or meshio mesh."""
    if hasattr(obj, "cells_dict") and hasattr(obj, "points"):          # meshio
        tri = obj.cells_dict.get("triangle")
        if tri is None:
            raise GeometryError(f"{what}: the meshio mesh holds no triangles (cell types "
                                f"{sorted(obj.cells_dict)}); give its surface triangles")
        vertices, faces = obj.points, tri
    elif hasattr(obj, "faces") and hasattr(obj, "points") and hasattr(obj, "n_cells"):  # pyvista
        surf = obj.triangulate()                        # a PolyData: polygons into triangles
        vertices, faces = surf.points, np.asarray(surf.faces).reshape(-1, 4)[:, 1:]
    elif hasattr(obj, "vertices") and hasattr(obj, "faces"):           # trimesh
        vertices, faces = obj.vertices, obj.faces
    else:
        vertices, faces = obj
    vertices = np.asarray(check_real(f"{what} vertices", vertices, error=GeometryError),
                          dtype=float)
    if vertices.ndim != 2 or vertices.shape[1] != 3:
        raise GeometryError(f"{what}: expected vertices of shape (k, 3), received shape "
                            f"{vertices.shape}")
    if not np.isfinite(vertices).all():
        bad = np.flatnonzero(~np.isfinite(vertices).all(axis=1))
        raise GeometryError(f"{what}: {bad.size} vertices are not finite (NaN or inf), first "
                            f"{bad[:5].tolist()}; repair or remove them")
    faces = np.asarray(check_real(f"{what} faces", faces, error=GeometryError))
    whole = faces.dtype.kind in "iu" or (faces.dtype.kind == "f" and np.isfinite(faces).all()
                                         and (faces == np.round(faces)).all())
    if faces.ndim != 2 or faces.shape[1] != 3 or not whole:
        raise GeometryError(f"{what}: expected faces as an (f, 3) array of vertex numbers, "
                            f"received shape {faces.shape} of {faces.dtype}")
    faces = faces.astype(np.int64)
    if len(faces) < 4:
        raise GeometryError(f"{what}: a closed surface needs at least 4 faces, received "
                            f"{len(faces)}")
    if faces.min() < 0 or faces.max() >= len(vertices):
        raise GeometryError(f"{what}: face vertex numbers must lie in [0, {len(vertices)}), "
                            f"received {faces.min()} .. {faces.max()}")
    return vertices, faces


def _is_surface(obj):
    if hasattr(obj, "faces") or hasattr(obj, "cells_dict"):
        return True
    if not isinstance(obj, (tuple, list)) or len(obj) != 2:
        return False
    try:
        shapes = [np.shape(np.asarray(x)) for x in obj]
    except (ValueError, TypeError):
        return False
    return all(len(s) == 2 and s[1] == 3 for s in shapes)


def _is_region(obj):
    if _is_surface(obj):
        return True
    return isinstance(obj, tuple) and len(obj) == 2 and _is_surface(obj[0]) \
        and isinstance(obj[1], (list, tuple)) and all(_is_surface(c) for c in obj[1])


def _merge_vertices(vertices, tol):
    """(k,) representative of each vertex (vertices within ``tol`` are one) and the
    distinct vertices."""
    pairs = cKDTree(vertices).query_pairs(tol, output_type="ndarray")
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])),
                       shape=(len(vertices), len(vertices)))
    _, label = connected_components(graph, directed=False)
    first = np.full(label.max() + 1, len(vertices))
    np.minimum.at(first, label, np.arange(len(vertices)))
    return label, vertices[first]


def _signed_volumes(vertices, faces, labels, count):
    tri = vertices[faces]
    six = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2]))
    return np.bincount(labels, weights=six, minlength=count) / 6.0


class Domain3D:
    """A 3-D body: material regions bounded by closed triangle surfaces.

    Parameters
    ----------
    regions : region or list of regions
        A region is a closed surface ``(vertices (k, 3), faces (f, 3))``, a trimesh,
        pyvista or meshio mesh, or a tuple ``(shell, [cavity, ...])`` of those. A surface
        made of several closed pieces is one region whose nested pieces are cavities (and
        bodies inside cavities). Faces that two regions share (the same triangles, given in
        each) are material interfaces.

    Notes
    -----
    Each closed surface is oriented by its role: outer shells with their normals out of
    the body, cavities with their normals into the void. A surface given inside out is
    turned round silently; an inconsistently oriented one is refused.

    Raises
    ------
    GeometryError
        Open, non-manifold, inconsistently oriented or self-intersecting surfaces,
        degenerate or repeated faces, non-finite or complex coordinates, cavities outside
        their shell, overlapping regions, interfaces whose triangles do not match.
    """

    dim = 3

    def __init__(self, regions: object) -> None:
        if _is_region(regions):
            regions = [regions]
        if not isinstance(regions, (list, tuple)) or not regions:
            raise GeometryError(
                "regions: expected a closed surface (vertices (k, 3), faces (f, 3)), a mesh, a "
                f"tuple (shell, [cavity, ...]) or a non-empty list of them, received "
                f"{type(regions).__name__}")
        pieces = []                     # (region, role, vertices, faces); role -1: shell
        for r, region in enumerate(regions):
            if not _is_region(region):
                raise GeometryError(
                    f"region {r}: expected (vertices (k, 3), faces (f, 3)), a mesh or (shell, "
                    f"[cavity, ...]), received {type(region).__name__}")
            if _is_surface(region):
                pieces.append((r, -1, *_surface_arrays(region, f"region {r}")))
            else:
                pieces.append((r, -1, *_surface_arrays(region[0], f"region {r} shell")))
                pieces += [(r, k, *_surface_arrays(c, f"region {r} cavity {k}"))
                           for k, c in enumerate(region[1])]
        self.n_regions = len(regions)
        allv = np.concatenate([p[2] for p in pieces])
        lo, hi = allv.min(axis=0), allv.max(axis=0)
        top = np.abs(np.stack([lo, hi])).max()
        if not top < config.COORDINATE_LIMIT:
            raise GeometryError(
                f"regions: expected coordinates below {config.COORDINATE_LIMIT:g} in magnitude, "
                f"received {top:g}; express the model in other units")
        self._centre = 0.5 * (lo + hi)
        self.size = float(np.linalg.norm(hi - lo))
        if not self.size > 0:
            raise GeometryError("regions: all vertices coincide; give a body")
        self.tolerance = max(config.SNAP_TOL * self.size,
                             config.ROUNDOFF_ULPS * np.finfo(float).eps * top)
        self._build(pieces)

    # ----------------------------------------------------------------- building
    def _build(self, pieces):
        starts = np.cumsum([0] + [len(p[2]) for p in pieces])
        allv = self.to_local(np.concatenate([p[2] for p in pieces]))
        tol = self.tolerance / self.size
        label, local = _merge_vertices(allv, tol)
        region_faces, region_names, self.region_volumes = [], [], []
        for r in range(self.n_regions):
            mine = [(k, p) for k, p in enumerate(pieces) if p[0] == r]
            faces = np.concatenate([label[p[3] + starts[k]] for k, p in mine])
            role = np.concatenate([np.full(len(p[3]), p[1]) for _, p in mine])
            names = [f"region {r} face {i}" if p[1] < 0 else f"region {r} cavity {p[1]} face {i}"
                     for _, p in mine for i in range(len(p[3]))]
            check_faces(local, faces, tol, names)
            check_closed(faces, names)
            check_self_intersections(local, faces, tol, names)
            faces = self._orient(local, faces, role, r)
            region_faces.append(faces)
            region_names.append(names)
        used = distinct(np.concatenate(region_faces))
        renumber = np.full(len(local), -1)
        renumber[used] = np.arange(len(used))
        self._local = np.ascontiguousarray(local[used])
        region_faces = [renumber[f] for f in region_faces]
        self._join(region_faces, region_names)
        self.vertices = self.to_global(self._local)
        self._tree = face_tree(self._local, self.faces)
        self._xy_tree = face_tree(self._local, self.faces, 2)
        self._weights = region_weights(self.face_regions, self.n_regions)
        self._check_overlaps(region_faces, region_names)

    def _orient(self, local, faces, role, r):
        """Turn each closed piece so that shells point out and cavities into the void;
        refuse cavities outside their shell."""
        comp, count = face_components(faces)
        vol = _signed_volumes(local, faces, comp, count)
        outward = np.where((vol >= 0)[comp][:, None], faces, faces[:, ::-1])
        tri = local[outward]
        area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
        depth = np.zeros(count, dtype=np.int64)
        for c in range(count):
            mine = np.flatnonzero(comp == c)
            probe = tri[mine[np.argmax(area[mine])]].mean(axis=0)[None]
            for d in range(count):
                if d != c:
                    w = solid_angle_winding(probe, local, outward[comp == d])[0]
                    depth[c] += w > 0.5
        cavity = depth % 2 == 1
        for c in range(count):
            roles = distinct(role[comp == c])
            if (roles >= 0).any() and not cavity[c]:
                raise GeometryError(
                    f"region {r} cavity {roles.max()} is not inside the region's shell; give "
                    "cavities that lie inside the shell (or make it a region of its own)")
            if (roles < 0).any() and cavity[c] and (role >= 0).any():
                raise GeometryError(f"region {r}: its shell lies inside one of its cavities; "
                                    "swap the shell and the cavity")
        oriented = np.where(cavity[comp][:, None], outward[:, ::-1], outward)
        volume = float(np.abs(vol) @ np.where(cavity, -1.0, 1.0)) * self.size**3
        if not volume > 0:
            raise GeometryError(f"region {r} encloses no volume; give a closed body")
        self.region_volumes.append(volume)
        return oriented

    def _join(self, region_faces, region_names):
        """One face per distinct triangle; shared triangles become interfaces."""
        faces = np.concatenate(region_faces)
        owner = np.concatenate([np.full(len(f), r) for r, f in enumerate(region_faces)])
        names = [n for names in region_names for n in names]
        _, first, inverse, counts = np.unique(np.sort(faces, axis=1), axis=0, return_index=True,
                                              return_inverse=True, return_counts=True)
        inverse = inverse.ravel()
        if (counts > 2).any():
            k = np.flatnonzero(counts[inverse] > 2)
            raise GeometryError(
                f"regions overlap: the triangle of {', '.join(names[i] for i in k[:3])} belongs "
                "to more than two regions; regions may only share faces pairwise")
        index = np.arange(len(faces))
        repeat = index != first[inverse]
        second = np.full(len(first), -1)
        second[inverse[repeat]] = index[repeat]
        pair = np.flatnonzero(second >= 0)
        a, b = first[pair], second[pair]
        # the two copies of an interface triangle must run in opposite directions
        forward = np.zeros(len(pair), dtype=bool)
        for k in range(3):
            forward |= (np.roll(faces[a], k, axis=1) == faces[b]).all(axis=1)
        if forward.any():
            x, y = a[forward][0], b[forward][0]
            raise GeometryError(
                f"regions {owner[x]} and {owner[y]} overlap: {names[x]} and {names[y]} are the "
                "same triangle with both regions on the same side of it; regions must only "
                "share boundaries")
        self.faces = np.ascontiguousarray(faces[first])
        self.face_regions = np.column_stack([owner[first], np.full(len(first), -1)])
        self.face_regions[pair, 1] = owner[b]
        self._face_names = [names[i] for i in first]

    def _check_overlaps(self, region_faces, region_names):
        if self.n_regions == 1:
            return
        tol = self.tolerance / self.size
        tri = self._local[self.faces]
        centroids = tri.mean(axis=1)
        for r in range(self.n_regions):
            mine = np.any(self.face_regions == r, axis=1)
            others = np.flatnonzero(~mine)
            if not len(others):
                continue
            sub = region_faces[r]
            point, face, _ = faces_within(centroids[others], self._local, sub, tol)
            if len(point):
                k = others[point[0]]
                raise GeometryError(
                    f"{self._face_names[k]} lies on the surface of region {r} (near "
                    f"{region_names[r][face[0]]}) without being one of its faces: interfaces "
                    "must be the same triangles on both sides; triangulate them alike")
            w = region_winding(centroids[others], self._local, sub,
                               np.ones((len(sub), 1)))[:, 0]
            inside = np.flatnonzero(w > 0.5)
            if inside.size:
                k = others[inside[0]]
                raise GeometryError(
                    f"regions overlap: {self._face_names[k]} lies inside region {r}; regions "
                    "must only share boundaries: subtract one from the other")
        check_self_intersections(self._local, self.faces, tol, self._face_names)

    # --------------------------------------------------------------- public API
    @classmethod
    def from_file(cls, path: str | Path) -> Domain3D:
        """A one-region domain from a surface file.

        STL, OBJ, PLY, OFF, glTF are read with trimesh; VTK, VTU, gmsh ``.msh``
        (surface triangles), XDMF, Abaqus ``.inp``, Medit ``.mesh`` with meshio.

        Parameters
        ----------
        path : str or Path

        Returns
        -------
        Domain3D
        """
        path = Path(path)
        suffix = path.suffix.lower()
        if not path.is_file():
            raise GeometryError(f"{path}: no such file; give the path of a surface file")
        if suffix in _TRIMESH_SUFFIXES:
            import trimesh

            mesh = trimesh.load(path, force="mesh", process=False)
            return cls((np.asarray(mesh.vertices), np.asarray(mesh.faces)))
        if suffix in _MESHIO_SUFFIXES:
            import meshio

            mesh = meshio.read(path)
            tri = [c.data for c in mesh.cells if c.type == "triangle"]
            if not tri:
                raise GeometryError(f"{path}: the file holds no surface triangles (cell types "
                                    f"{sorted({c.type for c in mesh.cells})}); export the "
                                    "boundary surface as triangles")
            return cls((np.asarray(mesh.points, dtype=float)[:, :3], np.concatenate(tri)))
        raise GeometryError(f"{path}: unknown surface format {suffix!r}; expected one of "
                            f"{', '.join(sorted(_TRIMESH_SUFFIXES | _MESHIO_SUFFIXES))}")

    def to_local(self, points: ArrayLike) -> np.ndarray:
        """(p, 3) ``points`` in the domain's local frame: centred on its bounding box and
        divided by `size` (the frame every geometric test runs in).

        Raises
        ------
        GeometryError
            ``points`` that are not finite real ``(p, 3)`` coordinates.
        """
        pts = check_points("points", points, dims=(3,), error=GeometryError)
        return (pts - self._centre) / self.size

    def to_global(self, local: ArrayLike) -> np.ndarray:
        """(p, 3) points back from the local frame (`to_local`).

        Raises
        ------
        GeometryError
            ``local`` that is not finite real ``(p, 3)`` coordinates.
        """
        return check_points("local", local, dims=(3,), error=GeometryError) * self.size \
            + self._centre

    @property
    def local_vertices(self) -> np.ndarray:
        """(k, 3) ndarray: `vertices` in the local frame (`to_local`), as the tests use them."""
        return self._local

    def near_surface(self, points: ArrayLike, distance: float | ArrayLike) -> np.ndarray:
        """Whether each point lies within ``distance`` of the surface (interfaces included).

        Parameters
        ----------
        points : (p, 3) ndarray
        distance : float or (p,) ndarray
            Non-negative.

        Returns
        -------
        (p,) bool ndarray

        Raises
        ------
        GeometryError
            Points that are not finite real ``(p, 3)`` coordinates, or a distance that is
            not one non-negative number or one per point.
        """
        local = self.to_local(points)
        distance = check_array("distance", distance, shape=(len(local),), broadcast=True,
                               nonnegative=True, error=GeometryError,
                               fix="pass one number, or one per point")
        point, _, _ = faces_within(local, self._local, self.faces, distance / self.size,
                                   self._tree)
        out = np.zeros(len(local), dtype=bool)
        out[point] = True
        return out

    @property
    def diameter(self) -> float:
        """float: `size`, the length of the bounding-box diagonal."""
        return self.size

    @property
    def bounds(self) -> np.ndarray:
        """(2, 3) ndarray: the lower and upper corners of the bounding box."""
        return np.stack([self.vertices.min(axis=0), self.vertices.max(axis=0)])

    @property
    def volume(self) -> float:
        """float: the volume enclosed (all regions)."""
        return float(sum(self.region_volumes))

    @property
    def area(self) -> float:
        """float: area of the outer boundary (interfaces not counted)."""
        tri = self.vertices[self.faces[self.face_regions[:, 1] < 0]]
        return float(0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]),
                                          axis=1).sum())

    def contains(self, points: ArrayLike) -> np.ndarray:
        """Whether points lie in the closed body.

        Parameters
        ----------
        points : (p, 3) or (3,) array_like

        Returns
        -------
        (p,) bool ndarray
        """
        return self.region_of(points) >= 0

    def region_of(self, points: ArrayLike) -> np.ndarray:
        """Index of the region (closure) holding each point, -1 outside.

        Points within `tolerance` of the surface are on it; a point on an interface
        gets the lower region index.

        Parameters
        ----------
        points : (p, 3) or (3,) array_like

        Returns
        -------
        (p,) int64 ndarray
        """
        pts = np.asarray(check_real("points", points, error=GeometryError), dtype=float)
        pts = check_points("points", pts.reshape(1, 3) if pts.shape == (3,) else pts, dims=(3,),
                           error=GeometryError)
        local = self.to_local(pts)
        out = np.full(len(pts), -1, dtype=np.int64)
        point, face, _ = faces_within(local, self._local, self.faces, self.tolerance / self.size,
                                      self._tree)
        regions = self.face_regions[face]
        best = np.where(regions[:, 1] >= 0, regions.min(axis=1), regions[:, 0])
        on = np.zeros(len(pts), dtype=bool)
        on[point] = True
        out[on] = self.n_regions
        np.minimum.at(out, point, best)
        out[~on] = -1
        off = np.flatnonzero(~on)
        w = region_winding(local[off], self._local, self.faces, self._weights, self._xy_tree)
        inside = w.max(axis=1) > 0.5
        out[off[inside]] = np.argmax(w[inside] > 0.5, axis=1)
        return out

    def __repr__(self):
        interfaces = int(np.count_nonzero(self.face_regions[:, 1] >= 0))
        return (f"<Domain3D {self.n_regions} region{'s' * (self.n_regions != 1)}, "
                f"{len(self.faces)} faces ({interfaces} interface), volume {self.volume:.6g}>")
