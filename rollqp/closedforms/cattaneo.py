"""Cattaneo–Mindlin: the braked (static) contact under a tangential load below sliding.

Symbols: ``a`` Hertz half-width, ``p0`` peak pressure, ``μ`` Coulomb coefficient, ``ratio = Q/(μP)``
the signed load ratio (``|ratio| < 1``), ``c`` the stick half-width. Source: :data:`SOURCE`.
"""
from __future__ import annotations

import math

from ._common import _JOHNSON, _coords, _nonnegative, _out, _positive, _ratio, _semi_ellipse


#: Cattaneo (1938) and Mindlin (1949) in Johnson's 2D form.
SOURCE = ("C. Cattaneo, Sul contatto di due corpi elastici: distribuzione locale degli sforzi, "
          "Rend. Accad. Naz. Lincei 27 (1938); R. D. Mindlin, Compliance of elastic bodies in "
          "contact, J. Appl. Mech. 16, 259–268 (1949); 2D form as in " + _JOHNSON
          + ", Ch. 7 (incipient sliding)")


def cattaneo_stick_half_width(a, ratio):
    """Half-width of the central stick zone in Cattaneo–Mindlin, ``c = a√(1 − |ratio|)``.

    Parameters
    ----------
    a : float
        Hertz contact half-width, ``a > 0``.
    ratio : float
        Signed load ratio ``Q/(μP)``, ``|ratio| < 1``.

    Returns
    -------
    float
        ``c``, ``0 < c ≤ a``; the stick zone is ``|x| < c``.

    Notes
    -----
    Similar materials, normal load ``P`` applied first, then ``Q`` increased monotonically
    from 0 with no rolling. Source: Cattaneo (1938), Mindlin (1949); Johnson (1985) Ch. 7,
    see ``SOURCES["cattaneo_stick_half_width"]``.
    """
    a = _positive("a", a)
    ratio = _ratio(ratio)
    return a * math.sqrt(1.0 - abs(ratio))


def cattaneo_traction(x, a, p0, mu, ratio):
    """Cattaneo–Mindlin tangential traction of a static (braked) 2D contact.

    ``t(x) = sgn(ratio)·μ·p0·[√(1 − x²/a²) − (c/a)·√(1 − x²/c²)]``, the second term only in
    the stick zone ``|x| < c``, ``c = a√(1 − |ratio|)``; so ``t = sgn(ratio)·μ·p(x)`` in the
    slip zones ``c ≤ |x| ≤ a`` and ``t = 0`` for ``|x| > a``.

    Parameters
    ----------
    x : float or array_like
        Coordinate along the strip, origin at the contact centre.
    a : float
        Hertz half-width, ``a > 0``.
    p0 : float
        Hertz peak pressure, ``p0 ≥ 0``.
    mu : float
        Coulomb friction coefficient, ``μ ≥ 0``.
    ratio : float
        Signed load ratio ``Q/(μP)``, ``|ratio| < 1``; ``Q`` is the tangential load on
        body A in ``+x``.

    Returns
    -------
    float or ndarray
        ``t(x)``, the traction on body A in ``+x`` (docs/formulation.md §1), shape of ``x``. It is
        even in ``x``, has the sign of ``ratio`` and ``∫ t dx = ratio·μ·P`` with
        ``P = πa·p0/2``.

    Raises
    ------
    InputError
        ``|ratio| ≥ 1`` (gross sliding), ``a ≤ 0``, ``p0 < 0`` or ``μ < 0``.

    Notes
    -----
    Similar materials (no normal–tangential coupling), ``P`` applied first, then ``Q``
    monotonically from 0. In the stick zone the relative tangential displacement is
    uniform (a rigid shift). Source: Cattaneo (1938), Mindlin (1949); Johnson (1985) Ch. 7,
    see ``SOURCES["cattaneo_traction"]``.
    """
    x = _coords(x)
    a = _positive("a", a)
    p0 = _nonnegative("p0", p0)
    mu = _nonnegative("mu", mu)
    ratio = _ratio(ratio)
    c = a * math.sqrt(1.0 - abs(ratio))
    t = _semi_ellipse(x, 0.0, a) - (c / a) * _semi_ellipse(x, 0.0, c)
    return _out(math.copysign(1.0, ratio) * (ratio != 0.0) * mu * p0 * t)
