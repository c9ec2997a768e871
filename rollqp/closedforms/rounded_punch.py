"""A flat punch with rounded edges pressed on a half-space: its load, contact half-width and pressure.

Symbols: ``a`` contact half-width, ``b`` the flat's half-width, ``R`` the edge radius, ``E*`` contact
modulus, ``P`` normal load per unit axial length. Source: :data:`SOURCE`.
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import InputError
from ._common import _JOHNSON, _coords, _nonnegative, _out, _positive


#: Ciavarella, Hills and Monno (1998), derived again in docs/kinematics.md.
SOURCE = ("M. Ciavarella, D. A. Hills and G. Monno, The influence of rounded edges on indentation by a flat "
          "punch, Proc. IMechE C 212, 319–328 (1998) (2D flat punch with rounded corners); derived again "
          "in docs/kinematics.md from the 2D inversion formula (" + _JOHNSON + ", §2.8, eq. 2.49)")


def rounded_punch_load(a, b, R, Estar):
    """Normal load of a flat punch of half-width ``b`` with edges rounded to radius ``R``, contact half-width ``a``.

    Profile ``z = 0`` for ``|x| ≤ b``, ``(|x| − b)²/(2R)`` outside; for ``a > b``:
    ``P = (E* a²/(4R))·(π − 2φ0 − sin 2φ0)``, ``sin φ0 = b/a`` (``b = 0``: Hertz). Source:
    ``SOURCES["rounded_punch_load"]``.

    Parameters
    ----------
    a, b : float
        Contact half-width (> 0) and flat half-width (``0 <= b < a``).
    R, Estar : float
        Edge radius and contact modulus, > 0.

    Returns
    -------
    float
        P per unit axial length.
    """
    a, b = _positive("a", a), _nonnegative("b", b)
    R, Estar = _positive("R", R), _positive("Estar", Estar)
    if not b < a:
        raise InputError("b", f"the flat half-width must be below the contact half-width a = {a!r}, got {b!r}")
    phi0 = math.asin(b / a)
    return Estar * a * a / (4.0 * R) * (math.pi - 2.0 * phi0 - math.sin(2.0 * phi0))


def rounded_punch_half_width(P, b, R, Estar):
    """Contact half-width ``a`` of the rounded punch under ``P`` (:func:`rounded_punch_load` inverted, bisection).

    Source: ``SOURCES["rounded_punch_half_width"]``.

    Parameters
    ----------
    P : float
        Normal load per unit length, > 0.
    b, R, Estar : float
        Flat half-width (>= 0), edge radius and contact modulus (> 0).

    Returns
    -------
    float
        ``a > b``.
    """
    P = _positive("P", P)
    lo, hi = max(_nonnegative("b", b), 0.0), max(2.0 * b, 1.0)
    while rounded_punch_load(hi, b, R, Estar) < P:
        hi *= 2.0
    lo = b * (1 + 1e-15) + 1e-300
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if rounded_punch_load(mid, b, R, Estar) < P:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def rounded_punch_pressure(x, a, b, R, Estar):
    """Pressure under the rounded punch (:func:`rounded_punch_load`) of contact half-width ``a``.

    ``p(x) = (E*/(2πR))·[(π − 2φ0)√(a² − x²) − (x − b)·ln|(t0 − τ)/(1 − t0 τ)| + (x + b)·ln|(t0 + τ)/(1 + t0 τ)|]``
    with ``t0 = tan(φ0/2)``, ``τ = tan(ψ/2)``, ``sin ψ = x/a``; zero for ``|x| ≥ a``; bounded
    (no edge singularity), and Hertz's ``p0√(1 − x²/a²)`` for ``b = 0``. From
    ``p = (E*/(2π))√(a² − x²)·PV∫ z'(s)/((s − x)√(a² − s²)) ds`` (docs/kinematics.md). Source:
    ``SOURCES["rounded_punch_pressure"]``.

    Parameters
    ----------
    x : float or array_like
        Coordinates along the strip.
    a, b, R, Estar : float
        As for :func:`rounded_punch_load`.

    Returns
    -------
    float or ndarray
        ``p(x) >= 0``, zero for ``|x| >= a``.
    """
    x = _coords(x)
    a, b = _positive("a", a), _nonnegative("b", b)
    R, Estar = _positive("R", R), _positive("Estar", Estar)
    if not b < a:
        raise InputError("b", f"the flat half-width must be below the contact half-width a = {a!r}, got {b!r}")
    inside = np.abs(x) < a
    xi = np.where(inside, x, 0.0)
    phi0 = math.asin(b / a)
    t0 = math.tan(0.5 * phi0)
    tau = np.tan(0.5 * np.arcsin(xi / a))
    with np.errstate(divide="ignore"):
        l1 = np.log(np.abs((t0 - tau) / (1.0 - t0 * tau)))
        l2 = np.log(np.abs((t0 + tau) / (1.0 + t0 * tau)))
    term = (math.pi - 2.0 * phi0) * np.sqrt((a - xi) * (a + xi))
    term = term - np.where(xi == b, 0.0, (xi - b) * l1) + np.where(xi == -b, 0.0, (xi + b) * l2)
    return _out(np.where(inside, Estar / (2.0 * math.pi * R) * term, 0.0))
