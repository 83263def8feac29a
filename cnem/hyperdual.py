"""Vectorised hyper-dual numbers: exact first and second derivatives (paper §3, eq. 22-31).

A hyper-dual number is ``a + b eps1 + c eps2 + d eps1eps2`` with ``eps1**2 = eps2**2 = 0`` and
``eps1eps2 != 0``; here ``a, b, c, d`` are NumPy arrays of one shape. A smooth function obeys
``g(x) = g(a) + g'(a) b eps1 + g'(a) c eps2 + (g'(a) d + g''(a) b c) eps1eps2``, so an energy
written once with the operators and functions of this module returns its exact first and
second derivatives, free of the truncation and cancellation errors of finite differences.

>>> import numpy as np
>>> from cnem import hyperdual as hd
>>> x = hd.HyperDual([1.0, 2.0], e1=1.0, e2=1.0)      # seed d/dx in both directions
>>> y = x ** 3 + hd.sin(x)
>>> np.allclose(y.e1, 3 * x.re ** 2 + np.cos(x.re)), np.allclose(y.e12, 6 * x.re - np.sin(x.re))
(True, True)
>>> value, grad, hess = hd.derivatives(hd.norm, np.array([[3.0, 4.0]]))   # |y|, y = (3, 4)
>>> value, grad, hess * 125
(array([5.]), array([[0.6, 0.8]]), array([[[ 16., -12.],
        [-12.,   9.]]]))
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import ArrayLike

from . import config
from .errors import HyperDualError, check_array, check_real

__all__ = ["HyperDual", "HyperDualError", "sqrt", "exp", "log", "sin", "cos", "tan", "arcsin",
           "arccos", "arctan", "sinh", "cosh", "tanh", "power", "dot", "cross", "norm", "stack",
           "concatenate", "trace", "transpose", "matmul", "det", "inv", "derivatives",
           "derivative"]

_PARTS = ("re", "e1", "e2", "e12")


def _broadcast(shapes, what):
    """Common broadcast shape of ``shapes``, or a HyperDualError naming ``what``."""
    try:
        return np.broadcast_shapes(*shapes)
    except ValueError:
        raise HyperDualError(
            f"{what}: expected operands whose shapes broadcast, got shapes "
            f"{', '.join(map(str, shapes))}; add axes (e.g. a[:, None]) or reshape so that NumPy "
            f"broadcasting applies") from None


class HyperDual:
    """Array of hyper-dual numbers ``re + e1 eps1 + e2 eps2 + e12 eps1eps2``.

    Parameters
    ----------
    re, e1, e2, e12 : array_like
        Real part and the three non-real parts; they are converted to float64 and broadcast
        to one shape (read-only views where broadcasting repeats data).

    Notes
    -----
    Arithmetic (``+ - * / **``, unary ``-``, ``abs``) mixes freely with Python scalars and
    ndarrays on either side and broadcasts like NumPy. Comparisons compare the real parts and
    return bool arrays. Objects are immutable: operations return new ones.
    """

    __slots__ = _PARTS
    __array_ufunc__ = None        # ndarray <op> HyperDual defers to the reflected method here
    __hash__ = None

    def __init__(self, re: ArrayLike, e1: ArrayLike = 0.0, e2: ArrayLike = 0.0,
                 e12: ArrayLike = 0.0) -> None:
        parts = [np.asarray(p) for p in (re, e1, e2, e12)]
        for name, part in zip(_PARTS, parts):
            if part.dtype.kind not in "fiu":      # complex, boolean, text: named, not cast
                check_real(f"HyperDual {name}", part, error=HyperDualError)
        parts = [p.astype(np.float64, copy=False) for p in parts]
        shape = _broadcast([p.shape for p in parts], "HyperDual(re, e1, e2, e12)")
        for name, p in zip(_PARTS, parts):
            object.__setattr__(self, name, p if p.shape == shape else np.broadcast_to(p, shape))

    def __setattr__(self, name, value):
        raise AttributeError("HyperDual is immutable; build a new one with HyperDual(re, e1, ...)")

    @property
    def shape(self) -> tuple[int, ...]:
        """tuple : Shape of every part."""
        return self.re.shape

    @property
    def ndim(self) -> int:
        """int : Number of dimensions."""
        return self.re.ndim

    def __len__(self):
        return len(self.re)

    def __getitem__(self, index):
        return HyperDual(*(getattr(self, p)[index] for p in _PARTS))

    def __repr__(self):
        return "HyperDual(" + ", ".join(f"{p}={getattr(self, p)!r}" for p in _PARTS) + ")"

    def sum(self, axis: int | tuple[int, ...] | None = None) -> HyperDual:
        """Sum over ``axis`` (all axes when None), each part separately."""
        return HyperDual(*(getattr(self, p).sum(axis=axis) for p in _PARTS))

    def reshape(self, *shape: int | tuple[int, ...]) -> HyperDual:
        """Same numbers in a new shape (as ``ndarray.reshape``)."""
        return HyperDual(*(getattr(self, p).reshape(*shape) for p in _PARTS))

    def _chain(self, g0, g1, g2):
        """g(self) from g(re), g'(re), g''(re)."""
        return HyperDual(g0, g1 * self.e1, g1 * self.e2, g1 * self.e12 + g2 * self.e1 * self.e2)

    def _operand(self, other, op):
        """``other`` as a HyperDual (or float ndarray) after checking the shapes broadcast."""
        if not isinstance(other, HyperDual):
            other = np.asarray(other, dtype=np.float64)
        _broadcast([self.shape, other.shape], f"HyperDual {op}")
        return other

    def __add__(self, other):
        o = self._operand(other, "+")
        if isinstance(o, HyperDual):
            return HyperDual(*(getattr(self, p) + getattr(o, p) for p in _PARTS))
        return HyperDual(self.re + o, self.e1, self.e2, self.e12)

    __radd__ = __add__

    def __neg__(self):
        return HyperDual(-self.re, -self.e1, -self.e2, -self.e12)

    def __sub__(self, other):
        return self + (-self._operand(other, "-"))

    def __rsub__(self, other):
        return (-self) + other

    def __mul__(self, o):
        o = self._operand(o, "*")
        if not isinstance(o, HyperDual):
            return HyperDual(*(getattr(self, p) * o for p in _PARTS))
        return HyperDual(self.re * o.re, self.re * o.e1 + self.e1 * o.re,
                         self.re * o.e2 + self.e2 * o.re,
                         self.re * o.e12 + self.e1 * o.e2 + self.e2 * o.e1 + self.e12 * o.re)

    __rmul__ = __mul__

    def _reciprocal(self):
        r = 1.0 / self.re
        return self._chain(r, -r * r, 2.0 * r * r * r)

    def __truediv__(self, other):
        o = self._operand(other, "/")
        return self * (o._reciprocal() if isinstance(o, HyperDual) else 1.0 / o)

    def __rtruediv__(self, other):
        return self._reciprocal() * self._operand(other, "/")

    def __pow__(self, p):
        p = self._operand(p, "**")
        if isinstance(p, HyperDual):
            return exp(p * log(self))
        a = self.re
        with np.errstate(divide="ignore", invalid="ignore"):   # 0 ** negative -> inf, as NumPy
            g1 = np.where(p == 0, 0.0, p * a ** (p - 1))
            g2 = np.where(p * (p - 1) == 0, 0.0, p * (p - 1) * a ** (p - 2))
        return self._chain(a ** p, g1, g2)

    def __rpow__(self, base):
        return exp(self * log(self._operand(base, "**")))

    def __abs__(self):
        return self._chain(np.abs(self.re), np.sign(self.re), np.zeros(self.shape))

    def _compare(self, other, op):
        o = other.re if isinstance(other, HyperDual) else self._operand(other, "comparison")
        return np.asarray(op(self.re, o))

    def __lt__(self, other):
        return self._compare(other, np.less)

    def __le__(self, other):
        return self._compare(other, np.less_equal)

    def __gt__(self, other):
        return self._compare(other, np.greater)

    def __ge__(self, other):
        return self._compare(other, np.greater_equal)

    def __eq__(self, other):
        return self._compare(other, np.equal)

    def __ne__(self, other):
        return self._compare(other, np.not_equal)


def _elementwise(name, real, rule):
    """A function of one argument: ``real`` on plain input, chain rule ``rule(a)`` on HyperDual."""
    def func(x: HyperDual | ArrayLike) -> HyperDual | np.ndarray:
        if isinstance(x, HyperDual):
            return x._chain(*rule(x.re))
        return real(np.asarray(x, dtype=np.float64))
    func.__name__ = func.__qualname__ = name
    func.__doc__ = (f"Elementwise ``{name}``: of a HyperDual (exact derivatives) or of real input "
                    f"(then a plain NumPy result, as ``numpy.{name}``).")
    return func


def _sqrt_rule(a):
    s = np.sqrt(a)
    return s, 0.5 / s, -0.25 / (s * a)


def _exp_rule(a):
    e = np.exp(a)
    return e, e, e


def _tan_rule(a):
    t = np.tan(a)
    return t, 1 + t * t, 2 * t * (1 + t * t)


def _tanh_rule(a):
    t = np.tanh(a)
    return t, 1 - t * t, -2 * t * (1 - t * t)


def _arcsin_rule(a):
    w = 1 - a * a
    return np.arcsin(a), 1 / np.sqrt(w), a / w ** 1.5


def _arccos_rule(a):
    w = 1 - a * a
    return np.arccos(a), -1 / np.sqrt(w), -a / w ** 1.5


sqrt = _elementwise("sqrt", np.sqrt, _sqrt_rule)
exp = _elementwise("exp", np.exp, _exp_rule)
log = _elementwise("log", np.log, lambda a: (np.log(a), 1 / a, -1 / (a * a)))
sin = _elementwise("sin", np.sin, lambda a: (np.sin(a), np.cos(a), -np.sin(a)))
cos = _elementwise("cos", np.cos, lambda a: (np.cos(a), -np.sin(a), -np.cos(a)))
tan = _elementwise("tan", np.tan, _tan_rule)
arcsin = _elementwise("arcsin", np.arcsin, _arcsin_rule)
arccos = _elementwise("arccos", np.arccos, _arccos_rule)
arctan = _elementwise("arctan", np.arctan,
                      lambda a: (np.arctan(a), 1 / (1 + a * a), -2 * a / (1 + a * a) ** 2))
sinh = _elementwise("sinh", np.sinh, lambda a: (np.sinh(a), np.cosh(a), np.sinh(a)))
cosh = _elementwise("cosh", np.cosh, lambda a: (np.cosh(a), np.sinh(a), np.cosh(a)))
tanh = _elementwise("tanh", np.tanh, _tanh_rule)


def power(x: HyperDual | ArrayLike, p: HyperDual | ArrayLike) -> HyperDual | np.ndarray:
    """``x ** p`` for HyperDual or real ``x`` and real or HyperDual ``p`` (HyperDual: x > 0)."""
    if isinstance(x, HyperDual):
        return x ** p
    x = np.asarray(x, dtype=np.float64)
    return p.__rpow__(x) if isinstance(p, HyperDual) else x ** p


def _vectors(a, b, what):
    """Check two vector arrays (last axis = components) of equal length, each a HyperDual
    or real (`_real_operand`); return them."""
    a, b = _real_operand(a, what, "a"), _real_operand(b, what, "b")
    if a.ndim == 0 or b.ndim == 0 or a.shape[-1] != b.shape[-1]:
        raise HyperDualError(
            f"{what} arguments a and b: expected two arrays of vectors with the components on "
            f"the last axis and the same number of components, got shapes {a.shape} and "
            f"{b.shape}; put the components last (shape (..., d)) in both")
    _broadcast([a.shape[:-1], b.shape[:-1]], f"{what} arguments a and b")
    return a, b


def _real_operand(value, what, name):
    """``value`` unchanged if a HyperDual, else as a float64 array once it holds real
    numbers (complex numbers and booleans refused, naming argument ``name`` of ``what``)."""
    if isinstance(value, HyperDual):
        return value
    check_real(f"{what} argument {name}", value, error=HyperDualError)
    return np.asarray(value, dtype=np.float64)


def _stack_any(items):
    if any(isinstance(v, HyperDual) for v in items):
        return stack(items, axis=-1)
    return np.stack(np.broadcast_arrays(*items), axis=-1)


def dot(a: HyperDual | ArrayLike, b: HyperDual | ArrayLike) -> HyperDual | np.ndarray:
    """Dot product over the last axis: ``(..., d), (..., d) -> (...)``; either may be real."""
    a, b = _vectors(a, b, "hd.dot")
    return (a * b).sum(axis=-1)


def norm(a: HyperDual | ArrayLike) -> HyperDual | np.ndarray:
    """Euclidean norm over the last axis: ``(..., d) -> (...)``."""
    a = _real_operand(a, "hd.norm", "a")
    if a.ndim == 0:
        raise HyperDualError("hd.norm argument a: expected vectors with the components on the "
                             "last axis, shape (..., d), got a number; pass e.g. [x, y]")
    return sqrt(dot(a, a))


def cross(a: HyperDual | ArrayLike, b: HyperDual | ArrayLike) -> HyperDual | np.ndarray:
    """Cross product over the last axis.

    Parameters
    ----------
    a, b : (..., 2) or (..., 3) HyperDual or ndarray

    Returns
    -------
    (...) for 2-D vectors (``a0 b1 - a1 b0``), (..., 3) for 3-D vectors.
    """
    a, b = _vectors(a, b, "hd.cross")
    d = a.shape[-1]
    if d == 2:
        return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    if d == 3:
        return _stack_any([a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
                           a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
                           a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]])
    raise HyperDualError(f"hd.cross: expected vectors of 2 or 3 components on the last axis, got "
                         f"{d} (shapes {a.shape} and {b.shape}); pass 2-D or 3-D vectors")


def _matrices(a, what, name="a", *, square=True):
    """``a`` (HyperDual or real array, `_real_operand`) after checking it holds matrices
    ``(..., d, e)``, square (``d == e``) unless ``square`` is False."""
    a = _real_operand(a, what, name)
    if a.ndim < 2 or (square and a.shape[-1] != a.shape[-2]):
        form = "square matrices on the last two axes, shape (..., d, d)" if square else \
            "matrices on the last two axes, shape (..., d, e)"
        raise HyperDualError(f"{what} argument {name}: expected {form}, got shape {a.shape}; "
                             f"reshape to {'(..., d, d)' if square else '(..., d, e)'}")
    return a


def _small(a, what):
    """``a`` as square matrices of size 2 or 3 (`_matrices`)."""
    a = _matrices(a, what)
    if a.shape[-1] not in (2, 3):
        raise HyperDualError(f"{what} argument a: written for 2 x 2 and 3 x 3 matrices, got "
                             f"shape {a.shape}; pass (..., 2, 2) or (..., 3, 3)")
    return a


def trace(a: HyperDual | ArrayLike) -> HyperDual | np.ndarray:
    """Trace of matrices ``(..., d, d) -> (...)``."""
    a = _matrices(a, "hd.trace")
    total = a[..., 0, 0]
    for i in range(1, a.shape[-1]):
        total = total + a[..., i, i]
    return total


def transpose(a: HyperDual | ArrayLike) -> HyperDual | np.ndarray:
    """Matrices ``(..., d, e)`` transposed to ``(..., e, d)``."""
    a = _matrices(a, "hd.transpose", square=False)
    if isinstance(a, HyperDual):
        return HyperDual(*(np.swapaxes(getattr(a, p), -1, -2) for p in _PARTS))
    return np.swapaxes(a, -1, -2)


def matmul(a: HyperDual | ArrayLike, b: HyperDual | ArrayLike) -> HyperDual | np.ndarray:
    """Matrix products ``(..., d, e) @ (..., e, f) -> (..., d, f)``, broadcast over the
    leading axes; either may be real."""
    a, b = (_matrices(v, "hd.matmul", name, square=False) for v, name in ((a, "a"), (b, "b")))
    if a.shape[-1] != b.shape[-2]:
        raise HyperDualError(f"hd.matmul: expected matrices (..., d, e) and (..., e, f) as "
                             f"arguments a and b, got a of shape {a.shape} and b of shape "
                             f"{b.shape}; the columns of a must match the rows of b")
    _broadcast([a.shape[:-2], b.shape[:-2]], "hd.matmul arguments a and b (leading axes)")
    return (a[..., :, :, None] * b[..., None, :, :]).sum(axis=-2)


def det(a: HyperDual | ArrayLike) -> HyperDual | np.ndarray:
    """Determinants of 2 x 2 or 3 x 3 matrices ``(..., d, d) -> (...)`` (cofactor
    expansion, so that the derivative parts are exact)."""
    a = _small(a, "hd.det")
    if a.shape[-1] == 2:
        return a[..., 0, 0] * a[..., 1, 1] - a[..., 0, 1] * a[..., 1, 0]
    return (a[..., 0, 0] * (a[..., 1, 1] * a[..., 2, 2] - a[..., 1, 2] * a[..., 2, 1])
            - a[..., 0, 1] * (a[..., 1, 0] * a[..., 2, 2] - a[..., 1, 2] * a[..., 2, 0])
            + a[..., 0, 2] * (a[..., 1, 0] * a[..., 2, 1] - a[..., 1, 1] * a[..., 2, 0]))


def inv(a: HyperDual | ArrayLike) -> HyperDual | np.ndarray:
    """Inverses of 2 x 2 or 3 x 3 matrices ``(..., d, d)``: adjugate over determinant
    (singular matrices give inf or NaN, as a division by zero does)."""
    a = _small(a, "hd.inv")
    d = a.shape[-1]
    if d == 2:
        rows = [[a[..., 1, 1], -a[..., 0, 1]], [-a[..., 1, 0], a[..., 0, 0]]]
    else:
        def cofactor(i, j):                 # of entry (j, i): the adjugate's (i, j)
            r, c = [k for k in range(3) if k != j], [k for k in range(3) if k != i]
            minor = a[..., r[0], c[0]] * a[..., r[1], c[1]] - a[..., r[0], c[1]] * a[..., r[1], c[0]]
            return minor if (i + j) % 2 == 0 else -minor
        rows = [[cofactor(i, j) for j in range(3)] for i in range(3)]
    # both stacks put their items on the last axis: transpose to rows first
    adjugate = transpose(_stack_any([_stack_any(row) for row in rows]))
    size = det(a)
    return adjugate / (size[..., None, None] if isinstance(size, HyperDual)
                       else np.asarray(size)[..., None, None])


def _items(items, what):
    """``items`` (a sequence of HyperDuals or real arrays, `_real_operand`) as a list of
    HyperDuals."""
    try:
        items = list(items)
    except TypeError:                        # a number: nothing to iterate over
        raise HyperDualError(f"{what} argument items: expected a sequence of HyperDuals or "
                             f"arrays, got {type(items).__name__}; pass e.g. [a, b]") from None
    return [HyperDual(_real_operand(v, what, f"items[{i}]")) if not isinstance(v, HyperDual)
            else v for i, v in enumerate(items)]


def stack(items: Sequence[HyperDual | ArrayLike], axis: int = -1) -> HyperDual:
    """Stack HyperDuals (or reals) of broadcast-compatible shapes along a new ``axis``."""
    items = _items(items, "hd.stack")
    shape = _broadcast([v.shape for v in items], "hd.stack argument items")
    return HyperDual(*(np.stack([np.broadcast_to(getattr(v, p), shape) for v in items], axis)
                       for p in _PARTS))


def concatenate(items: Sequence[HyperDual | ArrayLike], axis: int = -1) -> HyperDual:
    """Join HyperDuals (or reals) along the existing ``axis`` (default the last, components)."""
    items = _items(items, "hd.concatenate")
    try:
        return HyperDual(*(np.concatenate([getattr(v, p) for v in items], axis)
                           for p in _PARTS))
    except ValueError as exc:      # includes numpy AxisError
        raise HyperDualError(f"hd.concatenate argument items along axis {axis}: expected "
                             f"shapes equal except on that axis, got {[v.shape for v in items]} ({exc})") from None


def _check_output(out, shape, what, hint=""):
    if not isinstance(out, HyperDual) or out.shape != shape:
        got = f"shape {out.shape}" if isinstance(out, HyperDual) else type(out).__name__
        raise HyperDualError(
            f"{what}: f must return a HyperDual of shape {shape}, got {got}; write f with the "
            f"hd functions (not numpy's, which drop the derivative parts), act row by row and "
            f"index components as y[..., j]{hint}")


def derivatives(f: Callable[[HyperDual], HyperDual], x: ArrayLike, *,
                batch: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Value, gradient and Hessian of a scalar function of ``k`` variables at ``m`` points.

    Seeds ``eps1`` along variable p and ``eps2`` along q for every pair p <= q (eq. 30):
    ``k (k + 1) / 2`` evaluations of ``f``, vectorised over the points and the pairs.

    Parameters
    ----------
    f : callable
        ``f(y) -> HyperDual`` for ``y`` a HyperDual of shape ``(..., m, k)``, returning shape
        ``(..., m)``: the function of each row, written with this module's functions.
        With ``batch=True`` the pairs are batched on a leading axis (``y`` has shape
        ``(n, m, k)``), so f must index components as ``y[..., j]`` and per-point data of
        shape ``(m,)`` or ``(m, d)`` broadcasts. With ``batch=False`` f is called with exactly
        ``(m, k)`` once per pair.
    x : (m, k) array_like
        Real points.

    Returns
    -------
    value : (m,) ndarray
    gradient : (m, k) ndarray
    hessian : (m, k, k) ndarray, symmetric
    """
    if isinstance(x, HyperDual) or np.ndim(x) != 2 or np.shape(x)[1] == 0:
        raise HyperDualError(
            f"hd.derivatives: expected real x of shape (m, k) (m points, k >= 1 variables), got "
            f"{'a HyperDual' if isinstance(x, HyperDual) else 'shape'} {np.shape(x)}; pass "
            f"x[:, None] for one variable or x.reshape(m, -1) for several")
    x = check_array("x", x, finite=False, error=HyperDualError)
    m, k = x.shape
    first, second = np.triu_indices(k)
    eye = np.eye(k)
    value, grad, hess = np.empty(m), np.empty((m, k)), np.empty((m, k, k))
    step = max(1, config.HYPERDUAL_CHUNK // max(m * k, 1)) if batch else 1
    for start in range(0, len(first), step):
        p, q = first[start:start + step], second[start:start + step]
        if batch:
            shape = (len(p), m, k)
            out = f(HyperDual(np.broadcast_to(x, shape), eye[p][:, None], eye[q][:, None]))
            _check_output(out, shape[:2], "hd.derivatives", "; with batch=True f receives y of "
                          f"shape {shape} (pairs, points, variables), batch=False calls f with "
                          f"exactly {(m, k)} once per pair")
        else:
            out = f(HyperDual(x, eye[p[0]], eye[q[0]]))
            _check_output(out, (m,), "hd.derivatives")
            out = out.reshape(1, m)
        hess[:, p, q] = hess[:, q, p] = out.e12.T
        diag = p == q
        grad[:, p[diag]] = out.e1[diag].T
        value[:] = out.re[0]
    return value, grad, hess


def derivative(f: Callable[[HyperDual], HyperDual],
               x: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Value, first and second derivative of an elementwise scalar function (eq. 27).

    Parameters
    ----------
    f : callable
        ``f(y) -> HyperDual`` of the same shape as ``y``, applied elementwise.
    x : (m,) array_like
        Real arguments (any shape).

    Returns
    -------
    value, first, second : (m,) ndarrays
    """
    x = check_array("x", x, finite=False, error=HyperDualError)
    out = f(HyperDual(x, 1.0, 1.0))
    _check_output(out, x.shape, "hd.derivative")
    return np.array(out.re), np.array(out.e1), np.array(out.e12)
