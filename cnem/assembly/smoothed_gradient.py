"""The smoothed gradient operator ``B~`` as data: one sparse matrix per direction."""

from __future__ import annotations

import scipy.sparse as sp

from ..errors import GeometryError

__all__ = ["SmoothedGradient"]


class SmoothedGradient:
    """The operator ``B~`` of eq. 30: smoothed derivatives of every shape function,
    one sparse matrix per direction: ``SmoothedGradient(x, y, points)`` in 2-D,
    ``SmoothedGradient(x, y, z, points)`` in 3-D (``points`` also by keyword).

    Parameters
    ----------
    *parts : scipy.sparse matrices, shape (m, n), then int
        ``d`` derivative matrices (d = 2 or 3), along x, y (and z), then
        ``points`` unless given by keyword.
    points : int
        Number of quadrature points evaluated for it on the cell boundaries (with
        the other sets of cells computed in the same passes, `fan_gradient`: their
        shared count).

    Attributes
    ----------
    components : tuple of scipy.sparse.csr_matrix, shape (m, n)
        ``components[i][k, j] = b~_ij(cell k)``, the derivative along axis ``i``.
    dim : int
    x, y, z : scipy.sparse.csr_matrix, shape (m, n)
        ``components[0]``, ``[1]``, ``[2]`` (``z`` in 3-D only).
    points : int

    Examples
    --------
    >>> import scipy.sparse as sp
    >>> g = SmoothedGradient(sp.eye(2, format="csr"), sp.eye(2, format="csr"), points=0)
    >>> g.dim, g.y is g.components[1]
    (2, True)
    """

    def __init__(self, *parts: sp.csr_matrix | int, points: int | None = None):
        if points is None:
            *components, points = parts or (None,)
        else:
            components = parts
        shapes = [getattr(c, "shape", None) for c in components]
        if len(components) not in (2, 3) or None in shapes or len(set(shapes)) != 1:
            raise GeometryError(f"expected 2 or 3 derivative matrices of one shape (m, n) and "
                                f"the number of points, received {len(parts)} arguments, "
                                f"shapes {shapes}")
        self.components, self.points = tuple(components), points

    @property
    def dim(self) -> int:
        """The dimension: the number of `components`."""
        return len(self.components)

    @property
    def shape(self) -> tuple[int, int]:
        """``(m, n)``: cells by functions."""
        return self.components[0].shape

    @property
    def x(self) -> sp.csr_matrix:
        """The derivatives along x, ``(m, n)``."""
        return self.components[0]

    @property
    def y(self) -> sp.csr_matrix:
        """The derivatives along y, ``(m, n)``."""
        return self.components[1]

    @property
    def z(self) -> sp.csr_matrix:
        """The derivatives along z, ``(m, n)`` (3-D only)."""
        if self.dim < 3:
            raise AttributeError("a 2-D SmoothedGradient has no z component")
        return self.components[2]

    def __iter__(self):
        return iter(self.components)

    def __repr__(self):
        m, n = self.shape
        return (f"<SmoothedGradient {self.dim}-D, {m} cells x {n} nodes, {self.x.nnz} "
                f"non-zeros, {self.points} points>")
