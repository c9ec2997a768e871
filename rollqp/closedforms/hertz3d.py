"""Stresses below a circular Hertz contact: Huber's axis, Hamilton's field, the sliding traction's axis.

Symbols: a circular contact of radius ``a`` with the Hertz pressure ``p = p0 √(1 − r²/a²)`` on the
half-space ``z > 0`` (z the depth), Poisson's ratio ``ν``; a sliding traction ``q_x = μ p`` along +x on the
body. Stresses tension positive, in the scene's units. Sources: :data:`SOURCES`.
"""
from __future__ import annotations

import numpy as np

#: Where each formula comes from.
SOURCES = {
    "huber_axis": "M. T. Huber, Zur Theorie der Berührung fester elastischer Körper, Ann. Phys. 14, 153-163, "
                  "1904; as written in K. L. Johnson, Contact Mechanics, 1985, eq. 3.45",
    "hamilton_normal": "G. M. Hamilton, Explicit equations for the stresses beneath a sliding spherical contact, "
                       "Proc. IMechE 197C, 53-59, 1983 (the normal-load part, valid off the axis r > 0)",
    "sliding_axis_shear": "the traction on planes z = const of Boussinesq's and Cerruti's point loads, "
                          "σ_iz = −3 z x_i (F·x)/(2π ρ⁵) (Johnson 1985, eq. 3.20, 3.22), integrated over the "
                          "circle: σxz(0, 0, z) = −(3/2) μ p0 z ∫₀^a √(1 − r²/a²) r³ (r² + z²)^(−5/2) dr",
}


def huber_axis(z, a: float, p0: float, nu: float) -> tuple[np.ndarray, np.ndarray]:
    """``(σxx = σyy, σzz)`` on the axis ``r = 0`` below the Hertz pressure (Johnson eq. 3.45):
    ``σzz = −p0/(1 + ζ²)``, ``σxx = −p0[(1 + ν)(1 − ζ atan(1/ζ)) − 1/(2(1 + ζ²))]``, ``ζ = z/a``.

    >>> sxx, szz = huber_axis(0.0, 1.0, 1.0, 0.3)            # the surface: −(1 + 2ν)/2 p0 and −p0
    >>> float(sxx), float(szz)
    (-0.8, -1.0)
    """
    zeta = np.asarray(z, dtype=float) / a
    with np.errstate(divide="ignore"):
        zat = np.where(zeta > 0, zeta * np.arctan2(1.0, zeta), 0.0)
    szz = -p0 / (1 + zeta ** 2)
    sxx = -p0 * ((1 + nu) * (1 - zat) - 0.5 / (1 + zeta ** 2))
    return sxx, szz


def hamilton_normal(x, y, z, a: float, p0: float, nu: float) -> np.ndarray:
    """The six components (σxx, σyy, σzz, σxy, σxz, σyz), shape (6, …), below the Hertz pressure at points
    off the axis (``r = √(x² + y²) > 0``, ``z > 0``), Hamilton's explicit equations (1983) with
    ``A = r² + z² − a²``, ``S = √(A² + 4a²z²)``, ``M = √((S + A)/2)``, ``N = √((S − A)/2)``, ``φ = atan(a/M)``,
    ``G = M² − N² + zM − aN``, ``H = 2MN + aM + zN`` and the factor ``p0/a`` (= 3P/(2πa³))."""
    x, y, z = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (x, y, z)))
    r2 = x * x + y * y
    A = r2 + z * z - a * a
    S = np.sqrt(A * A + 4 * a * a * z * z)
    M, N = np.sqrt((S + A) / 2), np.sqrt((S - A) / 2)
    phi = np.arctan(a / M)
    G = M * M - N * N + z * M - a * N
    H = 2 * M * N + a * M + z * N
    c = p0 / a
    common = (1 - nu) * N * z * z - (1 - 2 * nu) / 3 * (N * S + 2 * A * N + a ** 3) - nu * M * z * a
    sxx = c * ((1 + nu) * z * phi + ((y * y - x * x) / r2 * common - N * (x * x + 2 * nu * y * y)
                                     - M * x * x * z * a / S) / r2)
    syy = c * ((1 + nu) * z * phi + ((x * x - y * y) / r2 * common - N * (y * y + 2 * nu * x * x)
                                     - M * y * y * z * a / S) / r2)
    szz = c * (-N + a * z * M / S)
    sxy = c * (x * y * (1 - 2 * nu) / r2 ** 2 * (-N * r2 + 2 / 3 * N * (S + 2 * A) - z * (z * N + a * M) + 2 / 3 * a ** 3)
               + x * y * z / r2 ** 2 * (-a * M * r2 / S - z * N + a * M))
    shear = -c * z * (N / S - z * H / (G * G + H * H))
    return np.stack([sxx, syy, szz, sxy, x * shear, y * shear])


def sliding_axis_shear(z, a: float, p0: float, mu: float) -> np.ndarray:
    """``σxz`` on the axis below the sliding traction ``q_x = μ p`` (the only component it makes there):
    ``−(3/2) μ p0 ζ ∫₀¹ √(1 − s²) s³ (s² + ζ²)^(−5/2) ds`` (``ζ = z/a``), by adaptive quadrature to 1e-13."""
    from scipy.integrate import quad
    zeta = np.atleast_1d(np.asarray(z, dtype=float)) / a
    out = np.array([quad(lambda s: np.sqrt(1 - s * s) * s ** 3 / (s * s + zt * zt) ** 2.5, 0.0, 1.0,
                         epsabs=0, epsrel=1e-13, limit=200)[0] for zt in zeta.ravel()])
    return (-1.5 * mu * p0 * zeta.ravel() / a * a * out).reshape(np.shape(z))
