"""The felupe side of `benchmarks/finite_strain.py`: compressible neo-Hookean P1/P2
triangles (plane strain) or tetrahedra, a dead end-face traction ramped in load steps,
felupe's own Newton (`felupe.newtonraphson`, its default sparse direct solve), timed per
iteration.

felupe is GPL-3.0-or-later: it is an optional extra of the benchmarks only
(``pip install -e .[compare]``), never imported by ``cnem/`` or ``tests/``.

Its `felupe.NeoHookeCompressible` is ``W = mu/2 tr C - mu ln J + lmbda/2 (ln J)^2``,
cnem's `NeoHookean` less the constant ``3 mu / 2``: the same stresses and tangents.
"""
import time

import numpy as np

#: Local node indices of the facets of each cell type, vertices first (VTK order); the
#: weights are the consistent nodal loads of a constant traction per unit facet measure.
FACETS = {
    "triangle": ([(0, 1), (1, 2), (2, 0)], [1 / 2, 1 / 2]),
    "triangle6": ([(0, 1, 3), (1, 2, 4), (2, 0, 5)], [1 / 6, 1 / 6, 2 / 3]),
    "tetra": ([(0, 1, 2), (0, 1, 3), (1, 2, 3), (0, 2, 3)], [1 / 3] * 3),
    "tetra10": ([(0, 1, 2, 4, 5, 6), (0, 1, 3, 4, 8, 7), (1, 2, 3, 5, 9, 8),
                 (0, 2, 3, 6, 9, 7)], [0.0, 0.0, 0.0, 1 / 3, 1 / 3, 1 / 3]),
}


def available():
    """True when felupe is importable."""
    try:
        import felupe  # noqa: F401 - probing the optional extra
    except ImportError:
        return False
    return True


def end_load(points, cells, cell_type, length, traction):
    """Consistent nodal forces of the constant ``traction`` on the face ``x = length``.

    Parameters
    ----------
    points : (n, d) ndarray
    cells : (c, k) int ndarray
    cell_type : str
        A key of `FACETS`.
    length : float
    traction : (d,) array_like

    Returns
    -------
    (n, d) ndarray
    """
    local, weights = FACETS[cell_type]
    on_end = points[:, 0] > length * (1 - 1e-9)
    forces = np.zeros_like(points)
    for facet in local:
        nodes = cells[:, facet]
        nodes = nodes[on_end[nodes].all(axis=1)]
        corners = points[nodes[:, :points.shape[1]]]
        if points.shape[1] == 2:
            measure = np.linalg.norm(corners[:, 1] - corners[:, 0], axis=1)
        else:
            measure = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0],
                                                    corners[:, 2] - corners[:, 0]), axis=1)
        for column, w in enumerate(weights):
            np.add.at(forces, nodes[:, column], w * measure[:, None] * np.asarray(traction))
    return forces


def positive_tetrahedra(points, tets):
    """``tets`` with two nodes swapped where the signed volume is negative."""
    a, b, c, d = (points[tets[:, k]] for k in range(4))
    negative = np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a) < 0
    tets = tets.copy()
    tets[negative, 1], tets[negative, 2] = tets[negative, 2], tets[negative, 1].copy()
    return tets


class _IterationClock:
    """Timestamps of felupe's Newton hooks: tangent, solve and residual per iteration."""

    def __init__(self):
        import felupe as fem
        clock = self
        self.rows = []

        class Hooks(fem.Plugin):
            def before_iteration(self, context, state):
                clock.t = [time.perf_counter()]

            def before_linear_solve(self, context, state):
                clock.t.append(time.perf_counter())

            def after_linear_solve(self, context, state):
                clock.t.append(time.perf_counter())

            def after_iteration(self, context, state):
                t = clock.t + [time.perf_counter()]
                clock.rows.append((t[1] - t[0], t[2] - t[1], t[3] - t[2]))

        self.plugin = Hooks()


def solve(points, cells, cell_type, material, length, traction, steps, tol):
    """Clamp ``x = 0``, load the end face, Newton over ``steps`` load steps.

    Parameters
    ----------
    points : (n, d) ndarray
    cells : (c, k) int ndarray
    cell_type : {"triangle", "triangle6", "tetra", "tetra10"}
    material : (mu, lam)
    length : float
        The clamped face is ``x = 0``, the loaded one ``x = length``.
    traction : (d,) array_like
        Dead traction on the loaded face under the whole load.
    steps : int
    tol : float
        felupe's relative residual (free residual over reactions).

    Returns
    -------
    dict
        ``setup`` and ``newton`` seconds, ``its``, the medians ``tangent``, ``solve``,
        ``residual`` (s per iteration), ``dofs``, and ``tip``: the load-weighted mean
        displacement of the loaded face along the traction.
    """
    import felupe as fem
    t0 = time.perf_counter()
    dim = points.shape[1]
    mesh = fem.Mesh(points, cells, cell_type)
    region = {"triangle": fem.RegionTriangle, "triangle6": fem.RegionQuadraticTriangle,
              "tetra": fem.RegionTetra, "tetra10": fem.RegionQuadraticTetra}[cell_type](mesh)
    field = fem.FieldContainer([fem.FieldPlaneStrain(region, dim=2) if dim == 2
                                else fem.Field(region, dim=3)])
    clamp = fem.Boundary(field[0], mask=points[:, 0] < 1e-9 * length)
    dof0, dof1 = fem.dof.partition(field, {"clamp": clamp})
    solid = fem.SolidBody(fem.NeoHookeCompressible(mu=material[0], lmbda=material[1]), field)
    forces = end_load(points, cells, cell_type, length, traction)
    loaded = np.flatnonzero(np.abs(forces).sum(axis=1))
    load = fem.PointLoad(field, loaded)
    setup = time.perf_counter() - t0
    clock = _IterationClock()
    t0 = time.perf_counter()
    for step in range(1, steps + 1):
        load.update(step / steps * forces[loaded])
        result = fem.newtonraphson(items=[solid, load], x0=field, dof1=dof1, dof0=dof0,
                                   tol=tol, verbose=0, plugins=[clock.plugin])
        if not result.success:
            raise RuntimeError(f"felupe {cell_type}: Newton failed in load step {step}")
    newton = time.perf_counter() - t0
    u = field[0].values
    tangent, linear, residual = np.median(np.array(clock.rows), axis=0)
    return dict(setup=setup, newton=newton, its=len(clock.rows), tangent=tangent,
                solve=linear, residual=residual, dofs=u.size,
                tip=float((forces * u).sum() / abs(forces.sum())))


def structured(dim, length, width, k):
    """A structured felupe P1 mesh (triangles or tetrahedra) of the beam
    ``[0, length] x [0, width]^(dim-1)``, ``k`` squares or cubes across the section."""
    import felupe as fem
    n = (round(length / width * k) + 1,) + (k + 1,) * (dim - 1)
    if dim == 2:
        mesh = fem.Rectangle(b=(length, width), n=n).triangulate()
    else:
        mesh = fem.Cube(b=(length, width, width), n=n).triangulate()
    return mesh


def quadratic(mesh):
    """``mesh`` (felupe P1) with edge midpoints: points, cells, cell type."""
    mesh2 = mesh.add_midpoints_edges()
    return mesh2.points, mesh2.cells, mesh2.cell_type
