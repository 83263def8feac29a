"""Numba kernel of the 3-D cells' fast dual path (`.cells3d`): which interior nodes'
Voronoi cells no boundary face can cut."""

import numba
import numpy as np

from .. import _compile  # noqa: F401  (says once when the kernels compile)
from .._parallel import parallel_kernel


@parallel_kernel("cand")
def clear_of_faces(points, cand, hit_ptr, hit_idx, star_ptr, star_tet, centre, face_x0,
                   face_normal, face_tol, chunks):
    """Whether each candidate node and every circumcentre of its tetrahedra lie strictly
    on one side of the plane of each face it may reach.

    Parameters
    ----------
    points : (n, 3) float64
    cand : (c,) int64
        The candidate nodes.
    hit_ptr, hit_idx : (c + 1,), (k,) int64
        CSR of the faces each candidate may reach.
    star_ptr, star_tet : (n + 1,), (4 t,) int64
        CSR of the tetrahedra at each node.
    centre : (t, 3) float64
        The tetrahedra's circumcentres.
    face_x0, face_normal : (b, 3) float64
        A vertex of each face and its (unnormalised) normal.
    face_tol : (b,) float64
        Distance (times the normal's length) under which a circumcentre is on a face's
        plane.
    chunks : int
        Work chunks (`cnem._parallel.work_chunks`).

    Returns
    -------
    (c,) bool
    """
    c = cand.shape[0]
    clear = np.ones(c, dtype=np.bool_)
    nch = max(1, min(chunks, c))
    for ch in numba.prange(nch):
        for k in range(ch * c // nch, (ch + 1) * c // nch):
            i = cand[k]
            for h in range(hit_ptr[k], hit_ptr[k + 1]):
                f = hit_idx[h]
                nx, ny, nz = face_normal[f, 0], face_normal[f, 1], face_normal[f, 2]
                ax, ay, az = face_x0[f, 0], face_x0[f, 1], face_x0[f, 2]
                own = (points[i, 0] - ax) * nx + (points[i, 1] - ay) * ny + (points[i, 2] - az) * nz
                for s in range(star_ptr[i], star_ptr[i + 1]):
                    t = star_tet[s]
                    cc = (centre[t, 0] - ax) * nx + (centre[t, 1] - ay) * ny + (centre[t, 2] - az) * nz
                    if not (own * cc > 0 and abs(cc) > face_tol[f]):
                        clear[k] = False
                        break
                if not clear[k]:
                    break
    return clear
