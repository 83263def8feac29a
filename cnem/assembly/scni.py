"""SCNI smoothed gradients (C-NEM paper §4.2, eq. 26-32): where each part lives.

For integration cell ``k`` (area ``A_k``, boundary ``Γ_k``) and node ``j``::

    b~_kj = (1 / A_k) ∮_{Γ_k} φ_j n dΓ                       (eq. 31-32)

Every cell edge is cut where it crosses a circumcircle of the triangulation:
between two crossings the natural neighbours of a point do not change and φ
is a smooth rational function of the position along the edge, which Gauss
quadrature integrates with fast (geometric) convergence. The linear patch test
holds to round-off for any number of points, because φ reproduces linear
fields exactly and Gauss quadrature integrates linear functions exactly.

- `cnem.assembly.edges`: cell edges, their pieces between circumcircle
  crossings, the distinct edges (each integrated once);
- `cnem.assembly.crack_faces`: crack faces seen from a cell's side, slits in
  crack-tip cells;
- `cnem.assembly.edge_quadrature`: `BoundaryQuadrature`, the Gauss points on
  the cell boundaries;
- `cnem.assembly.fan_quadrature`: the quadratures of cells and their fan
  sub-cells from one set of points;
- `cnem.assembly.passes`: the memory-bounded passes over runs of cells;
- `cnem.assembly.gradients`: the operator `SmoothedGradient` and its owner
  `GradientCache`.

This module gathers their public names under one roof.
"""

from __future__ import annotations

from .edge_quadrature import BoundaryQuadrature, boundary_quadrature, boundary_quadratures
from .edges import cell_edges
from .fan_quadrature import fan_quadratures
from .gradients import SmoothedGradient, GradientCache, fan_gradient, smoothed_gradient

__all__ = ["SmoothedGradient", "GradientCache", "smoothed_gradient", "fan_gradient",
           "fan_quadratures", "BoundaryQuadrature", "boundary_quadrature", "boundary_quadratures",
           "cell_edges"]
