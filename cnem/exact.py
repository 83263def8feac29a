"""Exact solutions used by the demos and tests.

>>> import numpy as np
>>> cyl = LayeredCylinder([0.5, 0.7, 0.9], [(210000.0, 0.3), (105000.0, 0.2)], pressure=1.0)
>>> bool(np.isclose(cyl.radial_stress(np.array([0.5]))[0], -1.0))
True
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from .errors import InputError, MaterialError, check_array, check_points
from .material import effective_modulus, lame

__all__ = ["LayeredCylinder", "ThickSphere", "CentralCrack", "rayleigh_speed",
           "inflated_sphere_pressure", "rivlin_torsion"]


class LayeredCylinder:
    """Hollow cylinder of concentric layers under internal pressure (paper §4.3, eq. 35-41).

    In layer ``i`` (``R_i <= r <= R_{i+1}``) ``u_r = a_i r + b_i / r``,
    ``σ_rr = 2 (λ_i + μ_i) a_i - 2 μ_i b_i / r²``, ``σ_θθ = 2 (λ_i + μ_i) a_i
    + 2 μ_i b_i / r²`` with the 2-D Lamé parameters of the plane law (in plane
    stress ``λ* = 2 λ μ / (λ + 2 μ)``). The ``a_i, b_i`` follow from
    ``σ_rr(R_0) = -P``, ``σ_rr(R_last) = 0`` and continuity of ``u_r`` and
    ``σ_rr`` at every interface (eq. 41).

    Parameters
    ----------
    radii : (k + 1,) array_like
        Increasing radii: inner, interfaces, outer.
    materials : list of k ``(E, nu)`` pairs, inner layer first
    pressure : float
    plane : {"stress", "strain"}
    center : (2,) array_like
    """

    def __init__(self, radii: ArrayLike, materials: ArrayLike, *, pressure: float = 1.0,
                 plane: Literal["stress", "strain"] = "stress", center: ArrayLike = (0.0, 0.0)) -> None:
        self.radii = check_array("radii", radii, shape=(None,),
                                 fix="pass increasing radii: inner, interfaces, outer")
        mats = check_array("materials", materials, error=MaterialError,
                           fix="pass one (E, nu) pair per layer, inner layer first")
        if mats.shape == (2,):
            mats = mats[None, :]                    # one layer, one pair
        if mats.ndim != 2 or mats.shape[1] != 2:
            raise MaterialError(f"materials: expected (E, nu) pairs, shape (k, 2), received "
                                f"shape {mats.shape}; pass one pair per layer")
        if len(mats) != len(self.radii) - 1 or not (np.diff(self.radii) > 0).all():
            raise MaterialError(f"expected increasing radii and one material per layer, received "
                                f"{len(self.radii)} radii and {len(mats)} materials; give "
                                f"len(radii) - 1 (E, nu) pairs")
        self.lam, self.mu = lame(mats[:, 0], mats[:, 1], plane)
        self.center = check_array("center", center, shape=(2,), fix="pass one point (x, y)")
        k = len(mats)
        A = np.zeros((2 * k, 2 * k))
        rhs = np.zeros(2 * k)

        def srr(i, r):      # coefficients of (a_i, b_i) in sigma_rr
            return 2.0 * (self.lam[i] + self.mu[i]), -2.0 * self.mu[i] / r ** 2

        A[0, 0:2] = srr(0, self.radii[0])
        rhs[0] = -pressure
        A[1, 2 * k - 2:] = srr(k - 1, self.radii[-1])
        for i in range(k - 1):
            r = self.radii[i + 1]
            A[2 + 2 * i, 2 * i:2 * i + 2] = [r, 1.0 / r]
            A[2 + 2 * i, 2 * i + 2:2 * i + 4] = [-r, -1.0 / r]
            A[3 + 2 * i, 2 * i:2 * i + 2] = srr(i, r)
            A[3 + 2 * i, 2 * i + 2:2 * i + 4] = np.negative(srr(i + 1, r))
        coef = np.linalg.solve(A, rhs).reshape(k, 2)
        self.a, self.b = coef[:, 0], coef[:, 1]

    def layer(self, r: ArrayLike) -> np.ndarray:
        """Layer index of radii (the inner layer at an interface)."""
        r = _distances("r", r)
        return np.clip(np.searchsorted(self.radii, r, side="left") - 1, 0, len(self.a) - 1)

    def radial_displacement(self, r: ArrayLike) -> np.ndarray:
        r = _distances("r", r)
        i = self.layer(r)
        return self.a[i] * r + self.b[i] / r

    def radial_stress(self, r: ArrayLike) -> np.ndarray:
        r = _distances("r", r)
        i = self.layer(r)
        return 2.0 * (self.lam[i] + self.mu[i]) * self.a[i] - 2.0 * self.mu[i] * self.b[i] / r ** 2

    def hoop_stress(self, r: ArrayLike) -> np.ndarray:
        r = _distances("r", r)
        i = self.layer(r)
        return 2.0 * (self.lam[i] + self.mu[i]) * self.a[i] + 2.0 * self.mu[i] * self.b[i] / r ** 2

    def _polar(self, points):
        rel = check_points("points", points, dims=(2,)) - self.center
        r = np.hypot(rel[:, 0], rel[:, 1])
        return r, rel[:, 0] / r, rel[:, 1] / r

    def _layers(self, layer, count):
        """``layer`` as ``count`` whole layer indices, checked."""
        values = check_array("layer", layer, shape=(count,),
                             fix="pass one layer index per point (0 = inner layer)")
        index = values.astype(np.int64)
        if (index != values).any() or (index < 0).any() or (index >= len(self.a)).any():
            raise InputError(f"layer: expected whole layer indices in [0, {len(self.a)}), "
                             f"received {values.tolist()[:5]}")
        return index

    def displacement(self, points: ArrayLike) -> np.ndarray:
        """``(p, 2)`` Cartesian displacements."""
        r, c, s = self._polar(points)
        ur = self.radial_displacement(r)
        return np.column_stack([ur * c, ur * s])

    def stress(self, points: ArrayLike, *, layer: ArrayLike | None = None) -> np.ndarray:
        """``(p, 3)`` ``[sxx, syy, sxy]``; ``layer`` forces the layer (for cells on an interface)."""
        r, c, s = self._polar(points)
        i = self.layer(r) if layer is None else self._layers(layer, len(r))
        lm = 2.0 * (self.lam[i] + self.mu[i]) * self.a[i]
        dev = 2.0 * self.mu[i] * self.b[i] / r ** 2
        srr, stt = lm - dev, lm + dev
        return np.column_stack([srr * c * c + stt * s * s, srr * s * s + stt * c * c,
                                (srr - stt) * s * c])


class ThickSphere:
    """Hollow sphere under internal pressure (Lamé), linear elastic, in 3-D.

    ``u_r = A r + B / r²``, ``σ_rr = (3 λ + 2 μ) A - 4 μ B / r³``,
    ``σ_θθ = σ_φφ = (3 λ + 2 μ) A + 2 μ B / r³``, with ``A, B`` from ``σ_rr(a) = -p``
    and ``σ_rr(b) = 0``.

    Parameters
    ----------
    inner, outer : float
        Radii ``a < b``.
    E, nu : float
    pressure : float
        ``p`` on the inner surface.
    center : (3,) array_like
    """

    def __init__(self, inner: float, outer: float, E: float, nu: float, *, pressure: float = 1.0,
                 center: ArrayLike = (0.0, 0.0, 0.0)) -> None:
        a, b = (float(check_array(name, v, shape=())) for name, v in (("inner", inner),
                                                                      ("outer", outer)))
        if not 0.0 < a < b:
            raise InputError(f"inner, outer: expected radii 0 < inner < outer, received "
                             f"{a!r}, {b!r}")
        E, nu = (float(check_array(name, v, shape=(), error=MaterialError))
                 for name, v in (("E", E), ("nu", nu)))
        if not (E > 0.0 and -1.0 < nu < 0.5):
            raise MaterialError(f"E, nu: expected E > 0 and -1 < nu < 1/2, received {E!r}, {nu!r}")
        self.inner, self.outer = a, b
        self.lam, self.mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
        p = float(check_array("pressure", pressure, shape=()))
        self.center = check_array("center", center, shape=(3,), fix="pass one point (x, y, z)")
        self.B = p / (4.0 * self.mu * (a ** -3 - b ** -3))
        self.A = 4.0 * self.mu * self.B / (b ** 3 * (3.0 * self.lam + 2.0 * self.mu))

    def radial_displacement(self, r: ArrayLike) -> np.ndarray:
        r = _distances("r", r)
        return self.A * r + self.B / r ** 2

    def radial_stress(self, r: ArrayLike) -> np.ndarray:
        r = _distances("r", r)
        return (3.0 * self.lam + 2.0 * self.mu) * self.A - 4.0 * self.mu * self.B / r ** 3

    def hoop_stress(self, r: ArrayLike) -> np.ndarray:
        r = _distances("r", r)
        return (3.0 * self.lam + 2.0 * self.mu) * self.A + 2.0 * self.mu * self.B / r ** 3

    def _radial(self, points):
        rel = check_points("points", points, dims=(3,)) - self.center
        r = np.linalg.norm(rel, axis=1)
        return r, rel / r[:, None]

    def displacement(self, points: ArrayLike) -> np.ndarray:
        """``(p, 3)`` Cartesian displacements."""
        r, n = self._radial(points)
        return self.radial_displacement(r)[:, None] * n

    def stress(self, points: ArrayLike) -> np.ndarray:
        """``(p, 6)`` Voigt ``[sxx, syy, szz, syz, sxz, sxy]``:
        ``σ = σ_θθ I + (σ_rr - σ_θθ) n ⊗ n``."""
        r, n = self._radial(points)
        srr, stt = self.radial_stress(r), self.hoop_stress(r)
        d = (srr - stt)[:, None]
        return np.column_stack([stt + d[:, 0] * n[:, 0] ** 2, stt + d[:, 0] * n[:, 1] ** 2,
                                stt + d[:, 0] * n[:, 2] ** 2, d[:, 0] * n[:, 1] * n[:, 2],
                                d[:, 0] * n[:, 0] * n[:, 2], d[:, 0] * n[:, 0] * n[:, 1]])


def _distances(name: str, value: ArrayLike) -> np.ndarray:
    """``value`` (coordinates or distances, any shape) as a float64 array: real, finite."""
    return check_array(name, value, fix="pass real, finite distances")


def rayleigh_speed(E: float, nu: float, density: float, plane: Literal["stress", "strain"] = "stress") -> float:
    """Rayleigh (surface) wave speed of an isotropic elastic solid in 2-D.

    Parameters
    ----------
    E, nu, density : float
        Young's modulus, Poisson's ratio and mass density.
    plane : {"stress", "strain"}

    Returns
    -------
    float
        The root ``c`` in ``(0, c_s)`` of ``(2 - k^2)^2 = 4 sqrt(1 - k^2 r^2) sqrt(1 - k^2)``
        with ``k = c / c_s``, ``r = c_s / c_d``, ``c_s = sqrt(mu / density)`` and
        ``c_d`` the dilatational speed of the plane law (``sqrt(E / ((1 - nu^2) density))``
        in plane stress).
    """
    from scipy.optimize import brentq
    mu = E / (2.0 * (1.0 + nu))
    modulus = E / (1.0 - nu ** 2) if plane == "stress" else \
        E * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu))
    cs, cd = np.sqrt(mu / density), np.sqrt(modulus / density)
    r2 = (cs / cd) ** 2

    def rayleigh(k):
        return (2 - k * k) ** 2 - 4 * np.sqrt(1 - k * k * r2) * np.sqrt(1 - k * k)

    return float(brentq(rayleigh, 0.5, 1.0 - 1e-12) * cs)


class CentralCrack:
    """A straight crack ``|x| < a`` (crack axes) in an infinite plate under a remote
    uniaxial stress ``sigma`` at ``gamma`` to the crack's normal (Griffith, Muskhelishvili).

    In the crack's axes the remote load has ``sigma_nn = sigma cos^2 gamma`` and
    ``sigma_nt = sigma sin gamma cos gamma``: ``K_I = sigma_nn sqrt(pi a)``,
    ``K_II = sigma_nt sqrt(pi a)``; the faces open by
    ``4 sigma_nn / E' sqrt(a^2 - x^2)`` and slide by ``4 sigma_nt / E' sqrt(a^2 - x^2)``;
    ahead of a tip (distance ``r``) the normal stress is
    ``sigma_nn (a + r) / sqrt(r (2 a + r))``.

    Parameters
    ----------
    half_length : float
        ``a``.
    sigma : float
        The remote stress.
    gamma : float
        Angle (radians) between the load and the crack's normal (0: pure mode I).
    """

    def __init__(self, half_length: float, sigma: float = 1.0, gamma: float = 0.0) -> None:
        self.a, self.sigma, self.gamma = float(half_length), float(sigma), float(gamma)
        self.normal = self.sigma * np.cos(self.gamma) ** 2
        self.shear = self.sigma * np.sin(self.gamma) * np.cos(self.gamma)

    def sif(self) -> tuple[float, float]:
        """``(K_I, K_II)``."""
        k0 = self.sigma * np.sqrt(np.pi * self.a)
        return k0 * np.cos(self.gamma) ** 2, k0 * np.sin(self.gamma) * np.cos(self.gamma)

    def opening(self, x: ArrayLike, E: float, nu: float = 0.0,
                plane: Literal["stress", "strain"] = "stress") -> np.ndarray:
        """Normal opening ``(p,)`` of the faces at ``x`` (crack axes; 0 outside the crack)."""
        x = _distances("x", x)
        return 4 * self.normal / effective_modulus(E, nu, plane) * \
            np.sqrt(np.clip(self.a * self.a - x * x, 0.0, None))

    def normal_stress_ahead(self, r: ArrayLike) -> np.ndarray:
        """Normal stress ``(p,)`` on the crack line at distance ``r > 0`` ahead of a tip."""
        r = _distances("r", r)
        return self.normal * (self.a + r) / np.sqrt(r * (2 * self.a + r))


def _positive_number(name: str, value: float) -> float:
    """``value`` as a positive finite float, else an `InputError` naming ``name``."""
    number = float(check_array(name, value, shape=(), fix=f"pass one positive number as {name}"))
    if not number > 0.0:
        raise InputError(f"{name}: expected a positive number, received {number!r}")
    return number


def inflated_sphere_pressure(inner_stretch: ArrayLike, inner: float, outer: float,
                             mu: float) -> np.ndarray:
    """Cavity pressure of a thick incompressible neo-Hookean sphere whose inner radius is
    stretched to ``lambda_a inner`` (Green & Zerna; Ogden, *Non-linear elastic
    deformations*, 1984, sec. 5.2.4), the outer surface free:

    ``p = 2 mu [(1/lambda_b + 1/(4 lambda_b^4)) - (1/lambda_a + 1/(4 lambda_a^4))]``,
    ``lambda_b^3 = 1 + (lambda_a^3 - 1) inner^3 / outer^3`` (volume conservation,
    ``r^3 - R^3`` constant), from radial equilibrium
    ``d sigma_rr / dr = 2 mu (lambda^2 - lambda^-4) / r`` with ``lambda = r / R``;
    ``p > 0`` pushes the wall out. ``W = mu/2 (tr C - 3)``.

    Parameters
    ----------
    inner_stretch : array_like, any shape
        ``lambda_a = a / A > 0``.
    inner, outer : float
        Reference radii ``A < B``.
    mu : float
        Shear modulus.

    Returns
    -------
    ndarray, the shape of ``inner_stretch``
    """
    la = check_array("inner_stretch", inner_stretch, fix="pass stretches a / A > 0")
    if not (la > 0).all():
        raise InputError(f"inner_stretch: expected stretches > 0, received minimum {la.min()!r}")
    A, B, mu = (_positive_number(n, v) for n, v in (("inner", inner), ("outer", outer),
                                                    ("mu", mu)))
    if not A < B:
        raise InputError(f"inner, outer: expected radii inner < outer, received {A!r}, {B!r}")
    lb = np.cbrt(1.0 + (la ** 3 - 1.0) * (A / B) ** 3)
    g = lambda s: 1.0 / s + 0.25 / s ** 4                         # noqa: E731
    return 2.0 * mu * (g(lb) - g(la))


def rivlin_torsion(twist: ArrayLike, radius: float, mu: float) -> tuple[np.ndarray, np.ndarray]:
    """Torque and axial force on the ends of an incompressible neo-Hookean solid cylinder
    twisted by ``tau`` per unit length at fixed length (Rivlin, Phil. Trans. A 242,
    1949): ``M = pi/2 mu tau a^4``, ``N = -pi/4 mu tau^2 a^4`` (compressive: the
    Poynting effect). From ``sigma = -p I + mu b``, ``b_zz = b_rr = 1``,
    ``b_thetaz = tau r``, radial equilibrium ``d sigma_rr / dr = mu tau^2 r`` and
    ``sigma_rr(a) = 0``, so ``sigma_zz = mu tau^2 (r^2 - a^2) / 2``.

    Parameters
    ----------
    twist : array_like, any shape
        ``tau``, the angle of twist per unit length (radians per length).
    radius : float
        ``a``.
    mu : float
        Shear modulus.

    Returns
    -------
    torque, axial_force : ndarrays, the shape of ``twist``
    """
    tau = check_array("twist", twist, fix="pass twists per unit length")
    a, mu = _positive_number("radius", radius), _positive_number("mu", mu)
    return 0.5 * np.pi * mu * tau * a ** 4, -0.25 * np.pi * mu * tau ** 2 * a ** 4
