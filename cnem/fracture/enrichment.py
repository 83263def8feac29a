"""Near-tip enrichment of the C-NEM approximation (paper eq. 47).

    u^h(x) = sum_i phi_i(x) u_i + sum_{j in J} sum_k psi_jk(x) a_jk,
    psi_jk(x) = (F_k(x) - F_k(x_j)) phi_j(x)

with ``F = sqrt(r)`` (the paper's eq. 47, ``functions="sqrt"``) or the four
branch functions ``sqrt(r) {sin(t/2), cos(t/2), sin(t/2) sin(t), cos(t/2) sin(t)}``
(``functions="branch"``, Fleming et al.; they span the angular parts of the
Williams fields), ``r, t`` polar about the crack tip of node ``j`` (``t = ±pi``
on the two crack faces) and ``J`` the nodes within a radius of the tips. The
shift by ``F_k(x_j)`` makes every ``psi_jk`` vanish at every node, so nodal
values stay displacements (Kronecker delta: Dirichlet conditions are imposed
directly), and ``psi_jk`` vanishes on every boundary edge that does not end at
``j``. The ``psi_jk`` are smoothed by the same SCNI boundary integrals as the
shape functions, on fan sub-cells of the integration cells (one smoothed
strain per cell would leave the extra dofs without stiffness).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
import scipy.sparse as sp

from .. import config
from ..assembly.edge_quadrature import boundary_quadrature
from ..errors import FractureError, InputError, check_choice, check_real
from ..geometry.topology import circumcenters
from .williams import sided_polar
from .._sets import isin

if TYPE_CHECKING:
    from typing import Callable
    from numpy.typing import ArrayLike
    from ..geometry.model import Model

__all__ = ["Enrichment", "FUNCTIONS"]

#: Enrichment function sets and their sizes.
FUNCTIONS = {"sqrt": 1, "branch": 4}


class Enrichment:
    """Near-tip enrichment of the nodes close to some crack tips.

    Parameters
    ----------
    model : Model
    tips : (t, 2) array_like
        Points; each is replaced by the nearest crack tip of the domain.
    radius : float
        Nodes closer than this to a tip are enriched.
    functions : {"sqrt", "branch"}
        ``sqrt(r)`` (eq. 47) or the four branch functions.

    Attributes
    ----------
    nodes : (e,) int64 ndarray
        The enriched nodes.
    tips, directions : (t, 2) ndarray
        The tips and their crack directions.
    tip_of : (e,) int64 ndarray
        The tip each enriched node belongs to (the nearest).
    size : int
        Number of enrichment functions per node (1 or 4); function ``k`` of
        enriched node ``j`` is column ``j * size + k``.
    """

    def __init__(self, model: Model, tips: np.ndarray, radius: float, *, functions: str = "sqrt"):
        check_choice("enrich functions", functions, FUNCTIONS)
        self.functions, self.size = functions, FUNCTIONS[functions]
        pts = np.atleast_2d(np.asarray(check_real("enrich tips", tips, error=FractureError),
                                       dtype=float))
        if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) == 0:
            raise FractureError(f"enrich tips: expected points (t, 2), received shape {pts.shape}")
        frames = [model.domain.tip_frame(p) for p in pts]
        self.tips = np.array([f[0] for f in frames])
        self.directions = np.array([f[1] for f in frames])
        radius = float(radius)
        if not np.isfinite(radius) or radius <= 0:
            raise FractureError(f"enrich radius: expected a positive number, received {radius}")
        self.model, self.radius = model, radius
        dist = np.hypot(*(model.nodes[:, None, :] - self.tips[None]).transpose(2, 0, 1))
        self.nodes = np.flatnonzero(dist.min(axis=1) < radius)
        if self.nodes.size == 0:
            raise FractureError(f"enrich radius {radius:g} holds no node about the tips "
                                f"{self.tips.tolist()}; choose a larger radius")
        self.tip_of = dist.argmin(axis=1)[self.nodes]
        # F_k at the nodes, each on its own crack face
        self._at_nodes = np.zeros((len(self.nodes), self.size))
        sides = model.node_sides()[self.nodes]
        for t in range(len(self.tips)):
            mine = self.tip_of == t
            self._at_nodes[mine] = self.evaluate(model.nodes[self.nodes[mine]], t, sides[mine])

    @classmethod
    def from_spec(cls, model: Model, spec: Any) -> Enrichment | None:
        """An `Enrichment` from ``None``, an `Enrichment`, or
        ``dict(tips=..., radius=..., functions=...)``."""
        if spec is None or isinstance(spec, cls):
            return spec
        if isinstance(spec, dict) and set(spec) <= {"tips", "radius", "functions"} \
                and "radius" in spec:
            return cls(model, spec.get("tips", model.domain.tips), spec["radius"],
                       functions=spec.get("functions", "sqrt"))
        raise FractureError(f"enrich: expected dict(tips=..., radius=..., functions=...) or an "
                            f"Enrichment, received {spec!r}")

    def __len__(self):
        """Number of enrichment functions (enriched nodes times `size`)."""
        return len(self.nodes) * self.size

    def __repr__(self):
        return (f"<Enrichment {self.functions}, {len(self.nodes)} nodes within {self.radius:g} "
                f"of {len(self.tips)} tip(s)>")

    def evaluate(self, points: np.ndarray, tip: np.ndarray, sides: np.ndarray, *,
                 gradient: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
        """The functions ``F_k`` about one tip, ``(p, size)``; ``sides`` are points on
        the side wanted for points on the crack faces. With ``gradient=True`` also
        their gradients ``(p, size, 2)`` (points off the tip)."""
        r, theta = sided_polar(points, self.tips[tip], self.directions[tip], sides,
                               self.model.domain.tolerance)
        root = np.sqrt(r)
        if self.functions == "sqrt":
            angular, slope = np.ones((len(r), 1)), np.zeros((len(r), 1))
        else:
            s, c, st, ct = np.sin(theta / 2), np.cos(theta / 2), np.sin(theta), np.cos(theta)
            angular = np.column_stack([s, c, s * st, c * st])
            slope = np.column_stack([c / 2, -s / 2, c / 2 * st + s * ct, -s / 2 * st + c * ct])
        F = root[:, None] * angular
        if not gradient:
            return F
        # F = sqrt(r) g(theta): grad F = g / (2 sqrt(r)) e_r + g'(theta) / sqrt(r) e_theta
        e_r = (points - self.tips[tip]) / r[:, None]
        e_theta = np.column_stack([-e_r[:, 1], e_r[:, 0]])
        dF = (angular[:, :, None] * e_r[:, None, :] / 2 + slope[:, :, None] * e_theta[:, None, :]) \
            / root[:, None, None]
        return F, dF

    def values(self, points: np.ndarray, phi: sp.spmatrix, sides: np.ndarray | None = None, *,
               gradient: np.ndarray | None = None) -> sp.spmatrix:
        """The functions ``psi_jk`` at points from the shape functions there.

        Parameters
        ----------
        points : (p, 2) ndarray
        phi : sparse (p, n)
            The shape functions at the points (crack sides already chosen).
        sides : (p, 2) ndarray, optional
            For points on a crack face, a point on the side wanted (default
            the points themselves).
        gradient : (dphi_dx, dphi_dy), sparse (p, n) with phi's pattern, optional
            The shape-function gradients: then the gradients of ``psi_jk``
            are returned too (points inside cells, off the tips).

        Returns
        -------
        scipy.sparse.csr_matrix, shape (p, len(self))
            Or ``(psi, dpsi_dx, dpsi_dy)`` with ``gradient``.
        """
        sides = points if sides is None else sides
        columns = phi.tocsc()[:, self.nodes]
        sub = columns.tocoo()
        F = np.zeros((len(sub.row), self.size))
        dF = np.zeros((len(sub.row), self.size, 2))
        for t in range(len(self.tips)):
            mine = self.tip_of[sub.col] == t
            got = self.evaluate(points[sub.row[mine]], t, sides[sub.row[mine]],
                                gradient=gradient is not None)
            if gradient is None:
                F[mine] = got
            else:
                F[mine], dF[mine] = got
        shifted = F - self._at_nodes[sub.col]
        cols = (sub.col[:, None] * self.size + np.arange(self.size)).reshape(-1)
        rows = np.repeat(sub.row, self.size)

        def matrix(data):
            return sp.csr_matrix((data.reshape(-1), (rows, cols)), shape=(len(points), len(self)))

        psi = matrix(sub.data[:, None] * shifted)
        if gradient is None:
            return psi
        out = [psi]
        for axis, dphi in enumerate(gradient):
            # dphi has phi's pattern: its entries line up with sub's
            d = dphi.tocsc()[:, self.nodes].tocoo()
            if not (np.array_equal(d.row, sub.row) and np.array_equal(d.col, sub.col)):
                raise InputError("gradient: expected shape-function gradients with the "
                                 "sparsity pattern of phi; take both from one shape_functions call")
            out.append(matrix(d.data[:, None] * shifted + sub.data[:, None] * dF[:, :, axis]))
        return tuple(out)

    def support_radius(self) -> np.ndarray:
        """Per tip, a radius about it holding the supports of its enriched functions
        (the circumcircles of the triangles at the enriched nodes)."""
        tri = self.model.triangles
        at = isin(tri, self.nodes).any(axis=1)
        centre = circumcenters(self.model.nodes, tri[at])
        reach = np.hypot(*(self.model.nodes[tri[at, 0]] - centre).T)
        out = np.zeros(len(self.tips))
        for t in range(len(self.tips)):
            mine = isin(tri[at], self.nodes[self.tip_of == t]).any(axis=1)
            if mine.any():
                out[t] = (np.hypot(*(centre[mine] - self.tips[t]).T) + reach[mine]).max()
        return out

    def in_support(self, points: np.ndarray) -> np.ndarray:
        """``(p,)`` bool: points within `support_radius` of a tip (where enrichment
        functions may be non-zero)."""
        reach = self.support_radius()
        near = np.zeros(len(points), dtype=bool)
        for t, tip in enumerate(self.tips):
            near |= np.hypot(*(points - tip).T) <= reach[t] * (1 + 1e-9)
        return near

    def smoothed_gradient(self, gauss: int = 2, cells: np.ndarray | None = None) -> sp.spmatrix:
        """SCNI smoothed gradients of the enrichment functions, with at least
        `cnem.config.MIN_GAUSS` points per piece of cell edge, graded towards the tips.

        Returns
        -------
        gx, gy : scipy.sparse.csr_matrix, shape (m, len(self))
        """
        quad = boundary_quadrature(self.model, gauss=max(gauss, config.MIN_GAUSS), cells=cells,
                                   singular=self.tips)
        select = np.flatnonzero(self.in_support(quad.points))
        points, hint = quad.points[select], quad.hint[select]
        sides = points.copy()                     # on a crack face: its triangle's side
        on_face = hint >= 0
        sides[on_face] = self.model.nodes[self.model.triangles[hint[on_face]]].mean(axis=1)
        phi, order = quad.shape_functions(self.model, select)
        psi = self.values(points[order], phi, sides[order]).tocoo()
        select = select[order]
        full = sp.csr_matrix((psi.data, (select[psi.row], psi.col)),
                             shape=(len(quad.points), len(self)))
        gx, gy = quad.cell_integrals(full)
        return gx.tocsr(), gy.tocsr()

    def edge_loads(self, edges: np.ndarray, normal: np.ndarray,
                   t: ArrayLike | Callable[..., np.ndarray], what: str = "traction") -> np.ndarray:
        """Loads on the enriched dofs from tractions on boundary edges.

        ``∫_edge psi_jk t`` for the edges ending at an enriched node ``j``
        (``phi_j`` is linear along a boundary edge), by 8-point Gauss quadrature.

        Returns
        -------
        (len(self), 2) ndarray
        """
        from ..solvers.conditions import per_point
        x = self.model.nodes
        slot = np.full(len(x), -1)
        slot[self.nodes] = np.arange(len(self.nodes))
        out = np.zeros((len(self.nodes), self.size, 2))
        g, w = np.polynomial.legendre.leggauss(8)
        s, w = 0.5 * (g + 1.0), 0.5 * w
        for end in (0, 1):
            pick = slot[edges[:, end]] >= 0
            if not pick.any():
                continue
            e, nrm = edges[pick], normal[pick]
            j = slot[e[:, end]]
            a, b = x[e[:, 0]], x[e[:, 1]]
            length = np.hypot(*(b - a).T)
            for sk, wk in zip(s, w):
                pts = a + sk * (b - a)
                # just inside the body, farther than the round-off of the coordinates
                inward = np.maximum(1e-6 * length, 4 * self.model.domain.tolerance)
                sides = pts - inward[:, None] * nrm
                phi = sk if end == 1 else 1.0 - sk
                tr = per_point(t(pts, nrm) if callable(t) else t, pts, 2, what)
                F = np.zeros((len(pts), self.size))
                for tip in range(len(self.tips)):
                    mine = self.tip_of[j] == tip
                    F[mine] = self.evaluate(pts[mine], tip, sides[mine])
                psi = (F - self._at_nodes[j]) * phi
                np.add.at(out, j, (wk * length)[:, None, None] * psi[:, :, None] * tr[:, None, :])
        return out.reshape(-1, 2)
