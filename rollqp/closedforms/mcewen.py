"""McEwen: subsurface stresses under a Hertz pressure with a proportional traction ``t = μp``.

Symbols: ``x`` along the strip, ``z ≥ 0`` the depth, ``a`` Hertz half-width, ``p0`` peak pressure, ``μ``
the traction's ratio to the pressure. Stresses tension positive. Source: :data:`SOURCE`.
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError
from ._common import _coords, _nonnegative, _out, _positive, _scalar


#: McEwen (1949) as written by Johnson.
SOURCE = ("E. McEwen, Stresses in elastic cylinders in contact along a generatrix (including the effect of "
          "tangential friction), Phil. Mag. (7) 40, 454-459, 1949; as written in K. L. Johnson, Contact "
          "Mechanics, Cambridge University Press, 1985, §4.2 (eq. 4.49-4.50, frictionless) and §7.2 "
          "(eq. 7.18, the traction q = mu p)")


#: Frictionless 2D Hertz contact: the largest in-plane maximum shear τ1/p0 and its depth z/a
#: (Johnson 1985 §4.2 gives 0.30 p0 at 0.78 a; these digits are the maximum of
#: :func:`hertz_subsurface_stresses` on the axis, found by ``tests/test_stresses.py``).
HERTZ_MAX_SHEAR = (0.300283, 0.786151)


def _mcewen_mn(x, z, a):
    """McEwen's m, n ≥ 0: m² = ½[√(A² + 4x²z²) + A], n² = ½[√(A² + 4x²z²) − A], A = a² − x² + z²;
    m ≥ 0 (z ≥ 0) and n has the sign of x (each product written without cancellation)."""
    A = a * a - x * x + z * z
    S = np.hypot(A, 2.0 * x * z)
    big = np.where(A >= 0, S + A, S - A)           # the larger of S ± A, no cancellation
    with np.errstate(divide="ignore", invalid="ignore"):
        other = np.where(big > 0, 2.0 * (x * z) ** 2 / big, 0.0)  # (S² − A²)/(2 big) = the smaller
    m2 = np.where(A >= 0, big / 2.0, other)
    n2 = np.where(A >= 0, other, big / 2.0)
    return np.sqrt(m2), np.where(x < 0, -1.0, 1.0) * np.sqrt(n2)  # z >= 0: m >= 0 (its limit at z = 0 too)


def mcewen_stresses(x, z, a, p0, mu=0.0):
    """Stresses under a Hertz pressure with a proportional traction ``t = μp`` (McEwen 1949).

    Parameters
    ----------
    x, z : float or array_like
        Point (broadcast together); ``z >= 0`` is the depth into the body.
    a, p0 : float
        Hertz half-width ``> 0`` and peak pressure ``>= 0``: ``p = p0√(1 − x²/a²)``.
    mu : float
        Traction ``t = μ p`` acting on the body in ``+x`` (full slip; a negative μ reverses it).

    Returns
    -------
    (sxx, szz, txz) : floats or ndarrays
        Plane stresses, tension positive, in the body's frame (x along the strip, z into the
        body), the sign convention of :mod:`rollqp.subsurface` (Flamant kernels, Johnson eq. 2.23,
        2.25), so ``szz = −p`` and ``txz = −t`` at the surface.

    Notes
    -----
    With McEwen's m, n (:func:`_mcewen_mn`) and ``k = (z² + n²)/(m² + n²)``,
    ``l = (m² − z²)/(m² + n²)``::

        pressure:  σxx = −(p0/a)[m(1 + k) − 2z],  σzz = −(p0/a) m (1 − k),   τxz = −(p0/a) n l
        traction:  σxx = +(q0/a)[n(2 + l) − 2x],  σzz = −(q0/a) n l,         τxz = −(q0/a)[m(1 + k) − 2z]

    with ``q0 = μp0``. Source: ``SOURCES["mcewen_stresses"]``. σyy = ν(σxx + σzz) in plane strain.
    """
    x, z = np.broadcast_arrays(_coords(x), _coords(z))
    if np.any(z < 0):
        raise InputError("z", "must be >= 0 (the depth into the body)")
    a = _positive("a", a)
    p0 = _nonnegative("p0", p0)
    mu = _scalar("mu", mu)
    m, n = _mcewen_mn(x, z, a)
    den = m * m + n * n
    with np.errstate(divide="ignore", invalid="ignore"):
        k = np.where(den > 0, (z * z + n * n) / den, 1.0)
        ll = np.where(den > 0, (m * m - z * z) / den, 0.0)
    c, q = p0 / a, mu * p0 / a
    sxx = -c * (m * (1 + k) - 2 * z) + q * (n * (2 + ll) - 2 * x)
    szz = -c * m * (1 - k) - q * n * ll
    txz = -c * n * ll - q * (m * (1 + k) - 2 * z)
    return _out(sxx), _out(szz), _out(txz)


def hertz_subsurface_stresses(x, z, a, p0):
    """Frictionless 2D Hertz field: :func:`mcewen_stresses` with ``μ = 0``.

    Parameters
    ----------
    x, z : float or array_like
        Point (broadcast together); ``z >= 0`` is the depth into the body.
    a, p0 : float
        Hertz half-width ``> 0`` and peak pressure ``>= 0``.

    Returns
    -------
    (sxx, szz, txz) : floats or ndarrays
        Plane stresses, tension positive (frame and signs of :func:`mcewen_stresses`).

    Notes
    -----
    On the axis ``σxx = −p0[(1 + 2z²/a²)/√(1 + z²/a²) − 2z/a]``, ``σzz = −p0/√(1 + z²/a²)``; the
    in-plane maximum shear τ1 has its maximum :data:`HERTZ_MAX_SHEAR` = 0.300 p0 at z = 0.786 a
    (Johnson §4.2). Source: ``SOURCES["hertz_subsurface_stresses"]``.
    """
    return mcewen_stresses(x, z, a, p0, 0.0)
