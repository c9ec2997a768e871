"""Hertz: the contact half-width, peak pressure and pressure of two cylinders (2D, plane strain).

Symbols: ``P`` normal load per unit axial length, ``R`` relative radius (``1/R = 1/R_A + 1/R_B``),
``E*`` contact modulus (``1/E* = (1−ν_A²)/E_A + (1−ν_B²)/E_B``), ``a`` contact half-width, ``p0``
peak pressure. Source: :data:`SOURCE`.
"""
from __future__ import annotations

import math

from ._common import _JOHNSON, _coords, _nonnegative, _out, _positive, _semi_ellipse


#: Hertz (1882) in Johnson's 2D form.
SOURCE = ("H. Hertz, Über die Berührung fester elastischer Körper, J. reine angew. Math. 92, "
          "156–171 (1882); two-dimensional (cylinder) case as in " + _JOHNSON
          + ", Ch. 4 (Hertz theory)")


def hertz_half_width(P, R, Estar):
    """Hertz contact half-width of two cylinders, ``a = √(4PR/(πE*))``.

    Parameters
    ----------
    P : float
        Normal load per unit axial length, ``P ≥ 0`` (compression).
    R : float
        Relative radius, ``1/R = 1/R_A + 1/R_B``, ``R > 0``.
    Estar : float
        Contact modulus ``E*``, ``1/E* = (1−ν_A²)/E_A + (1−ν_B²)/E_B``, ``E* > 0``.

    Returns
    -------
    float
        ``a`` (same length unit as ``R``).

    Notes
    -----
    Sign convention: docs/formulation.md §1 (``p ≥ 0`` compression). Equivalently
    ``p0 = 2P/(πa) = aE*/(2R)``. Source: Hertz (1882); Johnson (1985) Ch. 4, see
    ``SOURCES["hertz_half_width"]``.

    Examples
    --------
    The paper's steel rollers (R = 100 mm, E* = 230769 MPa) under 1000 N/mm:

    >>> from rollqp.closedforms import hertz_half_width, hertz_peak_pressure
    >>> a = hertz_half_width(1000.0, 100.0, 230769.23)
    >>> round(a, 4), round(hertz_peak_pressure(1000.0, a), 1)
    (0.7428, 857.1)
    """
    P = _nonnegative("P", P)
    R = _positive("R", R)
    Estar = _positive("Estar", Estar)
    return math.sqrt(4.0 * P * R / (math.pi * Estar))


def hertz_peak_pressure(P, a):
    """Peak Hertz pressure of a 2D contact, ``p0 = 2P/(πa)``.

    Parameters
    ----------
    P : float
        Normal load per unit axial length, ``P ≥ 0``.
    a : float
        Contact half-width, ``a > 0``.

    Returns
    -------
    float
        ``p0 ≥ 0`` (compression positive), such that ``∫ p0√(1 − x²/a²) dx = P``.

    Notes
    -----
    With ``a`` from :func:`hertz_half_width`, ``p0 = aE*/(2R)``. Source: Hertz (1882);
    Johnson (1985) Ch. 4, see ``SOURCES["hertz_peak_pressure"]``.
    """
    P = _nonnegative("P", P)
    a = _positive("a", a)
    return 2.0 * P / (math.pi * a)


def hertz_pressure(x, a, p0):
    """Hertz pressure distribution, ``p(x) = p0·√(1 − x²/a²)`` for ``|x| ≤ a``, 0 outside.

    Parameters
    ----------
    x : float or array_like
        Coordinate along the contact strip, origin at the contact centre.
    a : float
        Contact half-width, ``a > 0``.
    p0 : float
        Peak pressure, ``p0 ≥ 0`` (:func:`hertz_peak_pressure`).

    Returns
    -------
    float or ndarray
        ``p(x) ≥ 0`` (compression positive, docs/formulation.md §1), shape of ``x``.

    Notes
    -----
    Source: Hertz (1882); Johnson (1985) Ch. 4, see ``SOURCES["hertz_pressure"]``.
    """
    x = _coords(x)
    a = _positive("a", a)
    p0 = _nonnegative("p0", p0)
    return _out(p0 * _semi_ellipse(x, 0.0, a))
