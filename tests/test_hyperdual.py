"""Hyper-dual numbers give exact first and second derivatives (paper §3, eq. 22-31, Appendix A).

Every expected value is a hand-derived analytic formula written here.
"""

from __future__ import annotations

import numpy as np
import pytest

import cnem
from cnem import hyperdual as hd
from cnem.hyperdual import HyperDual

RNG = np.random.default_rng(8)
X = RNG.uniform(0.2, 2.5, 200)          # positive arguments
U = RNG.uniform(-0.9, 0.9, 200)         # arguments of the inverse trigonometric functions


def close(got, want, rtol=1e-12):
    """Equal to ``rtol`` relative to the size of ``want`` (absolute if ``want`` is 0)."""
    want = np.asarray(want, dtype=float)
    np.testing.assert_allclose(got, want, rtol=rtol, atol=rtol * (np.abs(want).max() or 1.0))


def _log_sqrt_exp():
    g, g1, g2 = 0.5 * np.log(1 + X * X), X / (1 + X * X), (1 - X * X) / (1 + X * X) ** 2
    e = np.exp(-X)
    return (g * e, (g1 - g) * e, (g2 - 2 * g1 + g) * e)


def _sqrt_tanh_quotient():
    """u / d, u = sqrt(tanh x), d = x - sin x - 5.

    (u/d)'' = u''/d - 2 u'd'/d^2 - u d''/d^2 + 2 u d'^2/d^3.
    """
    t = np.tanh(X)
    u, u1 = np.sqrt(t), (1 - t * t) / (2 * np.sqrt(t))
    u2 = -np.sqrt(t) * (1 - t * t) - (1 - t * t) ** 2 / (4 * t ** 1.5)
    d, d1, d2 = X - np.sin(X) - 5, 1 - np.cos(X), np.sin(X)
    return (u / d, u1 / d - u * d1 / d ** 2,
            u2 / d - 2 * u1 * d1 / d ** 2 - u * d2 / d ** 2 + 2 * u * d1 ** 2 / d ** 3)


# name: (f, x, f(x), f'(x), f''(x))
SCALAR_CASES = {
    "cube": (lambda x: x ** 3, X, X ** 3, 3 * X ** 2, 6 * X),
    "negative power": (lambda x: x ** -2, X, X ** -2, -2 * X ** -3, 6 * X ** -4),
    "fractional power": (lambda x: x ** 2.5, X, X ** 2.5, 2.5 * X ** 1.5, 3.75 * X ** 0.5),
    "cube root": (lambda x: hd.power(x, 1 / 3), X, np.cbrt(X), np.cbrt(X) / (3 * X),
                  -2 * np.cbrt(X) / (9 * X * X)),
    "sqrt": (hd.sqrt, X, np.sqrt(X), 0.5 / np.sqrt(X), -0.25 * X ** -1.5),
    "exp": (hd.exp, X, np.exp(X), np.exp(X), np.exp(X)),
    "log": (hd.log, X, np.log(X), 1 / X, -1 / X ** 2),
    "sin": (hd.sin, X, np.sin(X), np.cos(X), -np.sin(X)),
    "cos": (hd.cos, X, np.cos(X), -np.sin(X), -np.cos(X)),
    "tan": (hd.tan, U, np.tan(U), 1 / np.cos(U) ** 2, 2 * np.sin(U) / np.cos(U) ** 3),
    "arcsin": (hd.arcsin, U, np.arcsin(U), (1 - U * U) ** -0.5, U * (1 - U * U) ** -1.5),
    "arccos": (hd.arccos, U, np.arccos(U), -(1 - U * U) ** -0.5, -U * (1 - U * U) ** -1.5),
    "arctan": (hd.arctan, U, np.arctan(U), 1 / (1 + U * U), -2 * U / (1 + U * U) ** 2),
    "sinh": (hd.sinh, U, np.sinh(U), np.cosh(U), np.sinh(U)),
    "cosh": (hd.cosh, U, np.cosh(U), np.sinh(U), np.cosh(U)),
    "tanh": (hd.tanh, U, np.tanh(U), 1 / np.cosh(U) ** 2, -2 * np.sinh(U) / np.cosh(U) ** 3),
    "quotient": (lambda x: x / (1 + x * x), X, X / (1 + X * X), (1 - X * X) / (1 + X * X) ** 2,
                 2 * X * (X * X - 3) / (1 + X * X) ** 3),
    "reciprocal": (lambda x: 1 / x, X, 1 / X, -1 / X ** 2, 2 / X ** 3),
    "product": (lambda x: x * hd.exp(x), X, X * np.exp(X), (1 + X) * np.exp(X),
                (2 + X) * np.exp(X)),
    "log(sqrt(1+x^2)) exp(-x)": (lambda x: hd.log(hd.sqrt(1 + x ** 2)) * hd.exp(-x), X,
                                 *_log_sqrt_exp()),
    "real base": (lambda x: 2.0 ** x, X, 2 ** X, np.log(2) * 2 ** X, np.log(2) ** 2 * 2 ** X),
    "x^x": (lambda x: x ** x, X, X ** X, X ** X * (np.log(X) + 1),
            X ** X * ((np.log(X) + 1) ** 2 + 1 / X)),
    "abs": (lambda x: abs(x) * x, U, np.abs(U) * U, 2 * np.abs(U), 2 * np.sign(U)),
    "sin^2 + cos^2": (lambda x: hd.sin(x) ** 2 + hd.cos(x) ** 2, X, np.ones_like(X), 0 * X, 0 * X),
    "sqrt(tanh x) / (x - sin x - 5)": (lambda x: hd.sqrt(hd.tanh(x)) / (x - hd.sin(x) - 5), X,
                                        *_sqrt_tanh_quotient()),
}


@pytest.mark.parametrize("name", SCALAR_CASES)
def test_scalar_derivatives_match_analytic(name):
    f, x, f0, f1, f2 = SCALAR_CASES[name]
    value, first, second = hd.derivative(f, x)
    close(value, f0)
    close(first, f1)
    close(second, f2)
    out = f(HyperDual(x, 0.3, -1.7))        # eq. 24 with h1 = 0.3, h2 = -1.7
    close(out.e1, 0.3 * f1)
    close(out.e2, -1.7 * f1)
    close(out.e12, 0.3 * -1.7 * f2)


def test_chain_rule_and_product_with_all_parts_seeded():
    a, b, c, d = RNG.uniform(0.5, 2.0, (4, 50))
    y = hd.log(HyperDual(a, b, c, d))
    close(y.re, np.log(a))
    close(y.e1, b / a)
    close(y.e2, c / a)
    close(y.e12, d / a - b * c / a ** 2)
    p, q, r, s = RNG.normal(size=(4, 50))
    z = HyperDual(a, b, c, d) * HyperDual(p, q, r, s)
    close(z.re, a * p)
    close(z.e1, a * q + b * p)
    close(z.e2, a * r + c * p)
    close(z.e12, a * s + b * r + c * q + d * p)


def test_real_input_gives_plain_arrays():
    for f in [hd.sqrt, hd.exp, hd.log, hd.sin, hd.cos, hd.tan, hd.arcsin, hd.arccos, hd.arctan,
              hd.sinh, hd.cosh, hd.tanh]:
        out = f(U + 1.0 if f in (hd.log, hd.sqrt) else U)
        assert not isinstance(out, HyperDual) and out.shape == U.shape
    assert hd.sqrt(4) == 2.0 and hd.power(2, -1) == 0.5
    assert hd.norm(np.array([3.0, 4.0])) == 5.0
    a, b = RNG.normal(size=(2, 7, 3))
    np.testing.assert_array_equal(hd.cross(a, b), np.cross(a, b))
    close(hd.dot(a, b), np.einsum("ij,ij->i", a, b))
    close(hd.cross(a[:, :2], b[:, :2]), a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])


def _levi_civita():
    eps = np.zeros((3, 3, 3))
    for i, j, k in [(0, 1, 2), (1, 2, 0), (2, 0, 1)]:
        eps[i, j, k], eps[i, k, j] = 1.0, -1.0
    return eps


@pytest.mark.parametrize("d", [2, 3])
def test_norm_gradient_and_hessian(d):
    y = RNG.normal(size=(40, d))
    r = np.linalg.norm(y, axis=1)
    n = y / r[:, None]
    value, grad, hess = hd.derivatives(hd.norm, y)
    close(value, r)
    close(grad, n)
    close(hess, (np.eye(d) - n[:, :, None] * n[:, None, :]) / r[:, None, None])


def test_dot_gradient_and_hessian():
    c = RNG.normal(size=3)
    y = RNG.normal(size=(30, 3))
    value, grad, hess = hd.derivatives(lambda v: hd.dot(v, c) + hd.dot(v, v), y)
    close(value, y @ c + (y * y).sum(1))
    close(grad, c + 2 * y)
    close(hess, np.broadcast_to(2 * np.eye(3), (30, 3, 3)))


def test_cross_2d_gradient_and_hessian():
    z = RNG.normal(size=(25, 4))                       # z = (a0, a1, b0, b1)
    value, grad, hess = hd.derivatives(lambda v: hd.cross(v[..., :2], v[..., 2:]), z)
    a0, a1, b0, b1 = z.T
    close(value, a0 * b1 - a1 * b0)
    close(grad, np.stack([b1, -b0, -a1, a0], axis=1))
    h = np.zeros((4, 4))
    h[0, 3] = h[3, 0] = 1.0
    h[1, 2] = h[2, 1] = -1.0
    close(hess, np.broadcast_to(h, (25, 4, 4)))


def test_cross_3d_area_gradient_and_hessian():
    """s = |a x b| (twice a triangle's area): H = J^T (I - n n) J / s + n_i d2c_i."""
    z = RNG.normal(size=(30, 6))
    a, b = z[:, :3], z[:, 3:]
    c = np.cross(a, b)
    s = np.linalg.norm(c, axis=1)
    n = c / s[:, None]
    value, grad, hess = hd.derivatives(lambda v: hd.norm(hd.cross(v[..., :3], v[..., 3:])), z)
    close(value, s)
    close(grad, np.hstack([np.cross(b, c), np.cross(c, a)]) / s[:, None])
    eps = _levi_civita()
    jac = np.concatenate([np.einsum("ijk,pk->pij", eps, b),       # dc_i/da_j = eps_ijk b_k
                          np.einsum("ijk,pj->pik", eps, a)], axis=2)   # dc_i/db_k = eps_ijk a_j
    proj = np.eye(3) - n[:, :, None] * n[:, None, :]
    want = np.einsum("pia,pij,pjb->pab", jac, proj, jac) / s[:, None, None]
    mixed = np.einsum("pi,ijk->pjk", n, eps)              # d2(n.c)/da_j db_k
    want[:, :3, 3:] += mixed
    want[:, 3:, :3] += mixed.transpose(0, 2, 1)
    close(hess, want, rtol=1e-11)


@pytest.mark.parametrize("m", [-2.0, 0.5, 1.0, 2.0, 3.0])
@pytest.mark.parametrize("batch", [True, False])
def test_seth_hill_bond_energy(m, batch):
    """psi = (lam^m - 1)^2 / m^2, lam = |y| / |xi| with per-bond reference lengths."""
    y = RNG.normal(size=(60, 2))
    length = RNG.uniform(0.5, 1.5, 60)

    def psi(v):
        return (hd.power(hd.norm(v) / length, m) - 1) ** 2 / m ** 2

    lam = np.linalg.norm(y, axis=1) / length
    d1 = 2 * (lam ** m - 1) * lam ** (m - 1) / m
    d2 = 2 / m * ((2 * m - 1) * lam ** (2 * m - 2) - (m - 1) * lam ** (m - 2))
    r = np.linalg.norm(y, axis=1)
    n = y / r[:, None]
    nn = n[:, :, None] * n[:, None, :]
    value, grad, hess = hd.derivatives(psi, y, batch=batch)
    close(value, (lam ** m - 1) ** 2 / m ** 2)
    close(grad, (d1 / length)[:, None] * n)
    close(hess, (d2 / length ** 2)[:, None, None] * nn
          + (d1 / (length * r))[:, None, None] * (np.eye(2) - nn))
    close(psi(y), (lam ** m - 1) ** 2 / m ** 2)        # the same energy on real input


def test_hessian_symmetric_from_either_seeding():
    """H[p, q] seeded (p in eps1, q in eps2) equals H[q, p] seeded the other way round."""
    z = RNG.normal(size=(20, 6))

    def f(v):
        return hd.exp(0.1 * hd.dot(v, v)) * hd.norm(hd.cross(v[..., :3], v[..., 3:])) / v[..., 0]

    _, grad, hess = hd.derivatives(f, z)
    eye = np.eye(6)
    for p in range(6):
        for q in range(6):
            out = f(HyperDual(z, eye[q], eye[p]))           # lower triangle, not computed above
            np.testing.assert_allclose(out.e12, hess[:, p, q], rtol=1e-13, atol=1e-13)
            np.testing.assert_allclose(out.e2, grad[:, p], rtol=1e-13, atol=1e-13)
    np.testing.assert_array_equal(hess, hess.transpose(0, 2, 1))


def test_derivatives_chunks_the_pairs(monkeypatch):
    z = RNG.normal(size=(10, 4))
    calls = []

    def f(v):
        calls.append(v.shape)
        return hd.sin(v[..., 0] * v[..., 1]) + hd.dot(v, v) ** 1.5

    whole = hd.derivatives(f, z)
    assert calls == [(10, 10, 4)]                       # all 10 pairs in one call
    monkeypatch.setattr(cnem.config, "HYPERDUAL_CHUNK", 3 * 10 * 4)
    calls.clear()
    chunked = hd.derivatives(f, z)
    assert calls == [(3, 10, 4)] * 3 + [(1, 10, 4)]
    for w, c in zip(whole, chunked):
        np.testing.assert_array_equal(w, c)


def test_finite_differences_are_beaten():
    """Appendix A: central differences trade truncation for cancellation; HDN has neither."""
    f, x = SCALAR_CASES["log(sqrt(1+x^2)) exp(-x)"][0], np.array([0.7])

    def real(t):
        return np.log(np.sqrt(1 + t * t)) * np.exp(-t)

    g, g1 = 0.5 * np.log(1 + x * x), x / (1 + x * x)
    exact2 = ((1 - x * x) / (1 + x * x) ** 2 - 2 * g1 + g) * np.exp(-x)
    exact1 = (g1 - g) * np.exp(-x)
    _, first, second = hd.derivative(f, x)
    hdn2 = abs(second - exact2)[0] / abs(exact2)[0]
    hdn1 = abs(first - exact1)[0] / abs(exact1)[0]
    steps = 10.0 ** -np.arange(1, 9)
    fd2 = [abs((real(x + h) - 2 * real(x) + real(x - h)) / h ** 2 - exact2)[0] / abs(exact2)[0]
           for h in steps]
    fd1 = [abs((real(x + h) - real(x - h)) / (2 * h) - exact1)[0] / abs(exact1)[0]
           for h in steps]
    assert hdn2 < 1e-13 and hdn1 < 1e-13
    assert min(fd2) > 1e-9 and min(fd2) > 1e3 * hdn2
    assert min(fd1) > 1e-12
    assert fd2[0] > fd2[3] < fd2[-1]                    # truncation, then cancellation


def test_mixed_operands_and_broadcasting():
    a = RNG.uniform(1, 2, 3)
    x = HyperDual(a, 1.0, 2.0, 0.5)
    arr = np.array([[1.0], [2.0]])                       # (2, 1) with (3,) -> (2, 3)
    cases = [(2 + x, 2 + a, 1, 2, 0.5), (x + 2, 2 + a, 1, 2, 0.5),
             (arr + x, arr + a, 1, 2, 0.5), (x - arr, a - arr, 1, 2, 0.5),
             (arr - x, arr - a, -1, -2, -0.5), (arr * x, arr * a, arr, 2 * arr, 0.5 * arr),
             (np.float64(3) * x, 3 * a, 3, 6, 1.5),
             (x / arr, a / arr, 1 / arr, 2 / arr, 0.5 / arr),
             (arr / x, arr / a, -arr / a ** 2, -2 * arr / a ** 2,
              arr * (-0.5 / a ** 2 + 2 * 2 / a ** 3)),
             (-x, -a, -1, -2, -0.5), (x ** 2, a * a, 2 * a, 4 * a, a + 2 * 2)]
    for got, re, e1, e2, e12 in cases:
        assert isinstance(got, HyperDual)
        for part, want in zip((got.re, got.e1, got.e2, got.e12), (re, e1, e2, e12)):
            close(part, np.broadcast_to(want, got.shape))
    assert (arr * x).shape == (2, 3) and (x ** arr).shape == (2, 3)
    close((x ** arr).e1, arr * a ** (arr - 1))


def test_indexing_length_and_reductions():
    re, e1, e2, e12 = RNG.normal(size=(4, 5, 3))
    x = HyperDual(re, e1, e2, e12)
    assert x.shape == (5, 3) and x.ndim == 2 and len(x) == 5
    for index in [1, slice(1, 4), (Ellipsis, 0), re[:, 0] > 0, ([0, 2], [1, 1])]:
        y = x[index]
        for part, full in zip((y.re, y.e1, y.e2, y.e12), (re, e1, e2, e12)):
            np.testing.assert_array_equal(part, full[index])
    rows = list(x)
    assert len(rows) == 5 and all(r.shape == (3,) for r in rows)
    np.testing.assert_array_equal(x.sum(axis=0).e12, e12.sum(axis=0))
    np.testing.assert_array_equal(x.reshape(15).e1, e1.reshape(15))
    s = hd.stack([x[:, 0], 1.0], axis=-1)
    assert s.shape == (5, 2) and np.all(s.re[:, 1] == 1) and np.all(s.e1[:, 1] == 0)
    c = hd.concatenate([x, x[:, :1]])
    assert c.shape == (5, 4)
    np.testing.assert_array_equal(c.e2[:, 3], e2[:, 0])
    with pytest.raises(TypeError):
        len(HyperDual(1.0))
    with pytest.raises(AttributeError, match="immutable"):
        x.re = re


def test_comparisons_use_real_parts():
    a = np.array([-1.0, 0.0, 2.0])
    x = HyperDual(a, [5.0, 6.0, 7.0])
    y = HyperDual([0.0, 0.0, 0.0], [9.0, 6.0, 1.0])
    for got, want in [(x < 0, a < 0), (x <= 0, a <= 0), (x > 0, a > 0), (x >= 0, a >= 0),
                      (x == y, a == 0), (x != y, a != 0), (x < np.array([0, 1, 1]), [1, 1, 0])]:
        assert isinstance(got, np.ndarray) and got.dtype == bool
        np.testing.assert_array_equal(got, want)


def test_errors_say_what_was_expected():
    assert issubclass(hd.HyperDualError, cnem.CNEMError)
    assert issubclass(hd.HyperDualError, ValueError)
    x = HyperDual(np.ones(3))
    with pytest.raises(hd.HyperDualError, match=r"broadcast.*\(2,\), \(3,\)"):
        HyperDual([1.0, 2.0], e1=[1.0, 2.0, 3.0])
    with pytest.raises(hd.HyperDualError, match=r"HyperDual \+.*\(3,\), \(4,\)"):
        x + np.ones(4)
    with pytest.raises(hd.HyperDualError, match=r"HyperDual \*.*\(3,\), \(4,\)"):
        np.ones(4) * x
    with pytest.raises(hd.HyperDualError, match=r"2 or 3 components.*got 4"):
        hd.cross(HyperDual(np.ones((2, 4))), np.ones(4))
    with pytest.raises(hd.HyperDualError, match=r"same number of components.*\(5, 2\) and \(3,\)"):
        hd.dot(HyperDual(np.ones((5, 2))), np.ones(3))
    with pytest.raises(hd.HyperDualError, match=r"shape \(m, k\).*got shape \(4,\).*x\[:, None\]"):
        hd.derivatives(hd.norm, np.ones(4))
    with pytest.raises(hd.HyperDualError, match=r"got a HyperDual"):
        hd.derivatives(hd.norm, HyperDual(np.ones((4, 2))))
    with pytest.raises(hd.HyperDualError,
                       match=r"shape \(3, 4\), got shape \(3, 2\).*y\[\.\.\., j\].*batch=False"):
        hd.derivatives(lambda v: v[:, 0], np.ones((4, 2)))   # y[:, 0] picks a point, not x_0
    with pytest.raises(hd.HyperDualError, match=r"got ndarray.*not numpy's"):
        hd.derivative(lambda v: v.re ** 2, np.ones(3))
    with pytest.raises(hd.HyperDualError, match=r"expected shapes equal except on that axis"):
        hd.concatenate([x, np.ones((2, 2))])
    with pytest.raises(TypeError):
        np.sqrt(x)                                        # numpy ufuncs refuse, use hd.sqrt


# -- matrix functions (finite strain) ----------------------------------------------------
@pytest.mark.parametrize("d", [2, 3])
def test_matrix_functions_match_numpy_on_real_input(d):
    a, b = RNG.normal(size=(2, 9, d, d))
    close(hd.det(a), np.linalg.det(a))
    close(hd.inv(a), np.linalg.inv(a), rtol=1e-11)
    close(hd.trace(a), np.trace(a, axis1=1, axis2=2))
    close(hd.matmul(a, b), a @ b)
    np.testing.assert_array_equal(hd.transpose(a), np.swapaxes(a, 1, 2))
    assert not isinstance(hd.inv(a), HyperDual)


@pytest.mark.parametrize("d", [2, 3])
def test_determinant_and_inverse_derivatives(d):
    """Jacobi's formula: d det A / dA = det A A^-T; d2 det / dA_ij dA_kl = det (A^-1_ji
    A^-1_lk - A^-1_li A^-1_jk); the inverse's directional derivative -A^-1 H A^-1."""
    a = np.eye(d) + 0.4 * RNG.normal(size=(7, d, d))
    det, inv = np.linalg.det(a), np.linalg.inv(a)
    value, grad, hess = hd.derivatives(lambda y: hd.det(y.reshape(y.shape[:-1] + (d, d))),
                                       a.reshape(7, -1))
    close(value, det)
    close(grad.reshape(7, d, d), det[:, None, None] * np.swapaxes(inv, 1, 2))
    second = det[:, None, None, None, None] * (np.einsum("qji,qlk->qijkl", inv, inv)
                                               - np.einsum("qli,qjk->qijkl", inv, inv))
    close(hess.reshape(7, d, d, d, d), second, rtol=1e-11)
    h = RNG.normal(size=(d, d))
    out = hd.inv(HyperDual(a, h, h))
    close(out.re, inv, rtol=1e-11)
    close(out.e1, -inv @ h @ inv, rtol=1e-11)
    close(out.e12, 2 * inv @ h @ inv @ h @ inv, rtol=1e-10)
    t = hd.trace(hd.matmul(hd.transpose(HyperDual(a, h)), HyperDual(a, h)))   # |A|^2
    close(t.re, (a * a).sum(axis=(1, 2)))
    close(t.e1, 2 * (a * h).sum(axis=(1, 2)))


def test_matrix_functions_refuse_wrong_shapes():
    with pytest.raises(cnem.HyperDualError, match=r"square matrices"):
        hd.det(np.ones((4, 2, 3)))
    with pytest.raises(cnem.HyperDualError, match=r"2 x 2 and 3 x 3"):
        hd.inv(np.ones((4, 4, 4)))
    with pytest.raises(cnem.HyperDualError, match=r"\(\.\.\., d, e\) and \(\.\.\., e, f\)"):
        hd.matmul(np.ones((2, 3)), np.ones((2, 3)))
