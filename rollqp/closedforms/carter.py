"""Carter: steady rolling of similar cylinders under a tangential load — traction, stick zone, creepage,
slip and the creep-force law.

Symbols: ``a`` Hertz half-width, ``p0`` peak pressure, ``R`` relative radius, ``μ`` Coulomb coefficient,
``ratio = Q/(μP)`` (``|ratio| < 1``), ``d = sgn(V)`` the direction of the material (it enters at
``x = −d·a``), ``ξ`` the creepage, ``c`` the stick half-width, ``x_c = −d(a − c)`` its centre.
Sources: :data:`SOURCE` (Carter) and :data:`KALKER` (the 2D creep law).
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import InputError
from ._common import _JOHNSON, _coords, _direction, _leading_semi_ellipse, _nonnegative, _out, _positive, _ratio, _ratio_array, _semi_ellipse


#: Carter (1926) in Johnson's form.
SOURCE = ("F. W. Carter, On the action of a locomotive driving wheel, Proc. R. Soc. Lond. A 112, "
          "151–157 (1926); as in " + _JOHNSON + ", Ch. 8 (tractive rolling of elastic cylinders)")
#: Kalker's 2D theory: Carter's solution is its exact steady state.
KALKER = ("J. J. Kalker, Three-Dimensional Elastic Bodies in Rolling Contact, Kluwer, 1990 "
          "(2D theory: Carter's solution is the exact 2D steady state; its small-creepage slope is "
          "the 2D linear creep coefficient)")


def carter_stick_zone(a, ratio, direction):
    """Stick zone ``(x_from, x_to)`` of Carter's steady rolling solution.

    The stick zone has half-width ``c = a√(1 − |ratio|)`` and touches the leading edge
    ``x = −d·a``; its centre is ``x_c = −d·(a − c)``.

    Parameters
    ----------
    a : float
        Hertz half-width, ``a > 0``.
    ratio : float
        Signed load ratio ``Q/(μP)``, ``|ratio| < 1``.
    direction : {-1, +1}
        ``d = sgn(V)``: material moves through the contact in ``+d·x`` and enters at the
        leading edge ``x = −d·a`` (docs/formulation.md §1).

    Returns
    -------
    tuple of float
        ``(x_from, x_to)`` with ``x_from < x_to``: ``(−a, −a + 2c)`` for ``d = +1``,
        ``(a − 2c, a)`` for ``d = −1``.

    Notes
    -----
    Source: Carter (1926); Johnson (1985) Ch. 8, see ``SOURCES["carter_stick_zone"]``.
    """
    a = _positive("a", a)
    ratio = _ratio(ratio)
    d = _direction(direction)
    c = a * math.sqrt(1.0 - abs(ratio))
    return (-a, -a + 2.0 * c) if d == 1 else (a - 2.0 * c, a)


def _carter_arguments(a, mu, ratio, direction):
    """Checked ``(a, μ, ratio, d)`` of Carter's solution and its stick half-width ``c = a√(1 − |ratio|)``."""
    a = _positive("a", a)
    mu = _nonnegative("mu", mu)
    ratio = _ratio(ratio)
    d = _direction(direction)
    return a, mu, ratio, d, a * math.sqrt(1.0 - abs(ratio))


def carter_traction(x, a, p0, mu, ratio, direction):
    """Carter's steady-rolling tangential traction (similar cylinders).

    ``t(x) = sgn(ratio)·μ·p0·[√(1 − x²/a²) − (c/a)·√(1 − (x − x_c)²/c²)]``, the second term
    only inside the stick zone ``|x − x_c| < c``, with ``c = a√(1 − |ratio|)`` and
    ``x_c = −d·(a − c)`` (the stick zone touches the leading edge ``x = −d·a``). Elsewhere
    in the contact ``t = sgn(ratio)·μ·p(x)`` (slip towards the trailing edge); ``t = 0``
    for ``|x| > a``.

    Parameters
    ----------
    x, a, p0, mu, ratio
        As for :func:`cattaneo_traction` (``x`` Eulerian, fixed to the contact).
    direction : {-1, +1}
        ``d = sgn(V)``; material enters at ``x = −d·a`` (docs/formulation.md §1).

    Returns
    -------
    float or ndarray
        ``t(x)``, the traction on body A in ``+x``, shape of ``x``;
        ``∫ t dx = ratio·μ·P`` with ``P = πa·p0/2``. Mirror symmetry:
        ``carter_traction(x, …, d) = carter_traction(−x, …, −d)``.

    Raises
    ------
    InputError
        ``|ratio| ≥ 1``, ``a ≤ 0``, ``p0 < 0``, ``μ < 0`` or ``direction`` not ``±1``.

    Notes
    -----
    In the stick zone the strain difference ``∂w/∂x`` is uniform, so the steady slip
    ``s = ξ + d·∂w/∂x`` vanishes there for the creepage of :func:`carter_creepage`. Source:
    Carter (1926); Johnson (1985) Ch. 8, see ``SOURCES["carter_traction"]``.
    """
    x = _coords(x)
    a, mu, ratio, d, c = _carter_arguments(a, mu, ratio, direction)
    p0 = _nonnegative("p0", p0)
    t = _semi_ellipse(x, 0.0, a) - (c / a) * _leading_semi_ellipse(x, a, c, d)
    return _out(math.copysign(1.0, ratio) * (ratio != 0.0) * mu * p0 * t)


def carter_creepage(a, R, mu, ratio):
    """Carter's steady-rolling creepage for a given load ratio.

    ``ξ = −sgn(ratio)·(μa/R)·(1 − √(1 − |ratio|))``.

    Parameters
    ----------
    a : float
        Hertz half-width, ``a > 0``.
    R : float
        Relative radius, ``R > 0``.
    mu : float
        Coulomb friction coefficient, ``μ ≥ 0``.
    ratio : float or array_like
        Signed load ratio ``Q/(μP)``, ``|ratio| < 1``.

    Returns
    -------
    float or ndarray
        ``ξ = (V_A − V_B)/|V|`` (docs/formulation.md §1), shape of ``ratio``. ``ξ`` and ``Q`` have
        opposite signs; ``ξ`` does not depend on the rolling direction.

    Notes
    -----
    Requires ``p0 = aE*/(2R)`` (Hertz). Derivation in the project's convention: the steady
    slip is ``s = ξ + d·∂w/∂x`` and, inside Carter's stick zone,
    ``∂w/∂x = −(2/(πE*))·PV∫ t(s)/(x − s) ds = −(μ/R)·x_c = d·μ(a − c)/R``, so ``s = 0`` gives
    ``ξ = −μ(a − c)/R`` for ``ratio > 0``. Source: Carter (1926); Johnson (1985) Ch. 8, see
    ``SOURCES["carter_creepage"]``.

    Examples
    --------
    >>> from rollqp.closedforms import carter_creepage, creep_force_ratio
    >>> xi = carter_creepage(1.0, 100.0, 0.1, 0.75)
    >>> round(xi * 1e4, 6), round(float(creep_force_ratio(xi, 1.0, 100.0, 0.1)), 12)
    (-5.0, 0.75)
    """
    a = _positive("a", a)
    R = _positive("R", R)
    mu = _nonnegative("mu", mu)
    r = _ratio_array(ratio)
    xi = -np.sign(r) * (mu * a / R) * (1.0 - np.sqrt(1.0 - np.abs(r)))
    return _out(xi)


def creep_force_ratio(xi, a, R, mu):
    """Carter's creep-force law: load ratio ``Q/(μP)`` for a given creepage.

    ``Q/(μP) = −sgn(ξ)·[1 − (1 − |ξ|R/(μa))²]`` for ``|ξ| ≤ μa/R``, and ``−sgn(ξ)`` (full
    sliding) for ``|ξ| > μa/R``. The inverse of :func:`carter_creepage` on ``|ratio| < 1``.

    Parameters
    ----------
    xi : float or array_like
        Creepage ``ξ = (V_A − V_B)/|V|`` (finite).
    a : float
        Hertz half-width, ``a > 0``.
    R : float
        Relative radius, ``R > 0``.
    mu : float
        Coulomb friction coefficient, ``μ ≥ 0``; with ``μ = 0`` every nonzero ``ξ`` is
        full sliding.

    Returns
    -------
    float or ndarray
        ``Q/(μP)`` in ``[−1, 1]``, of sign opposite to ``ξ``, shape of ``xi``. Monotone
        non-increasing in ``ξ``; the small-creepage slope is ``d(Q/μP)/dξ = −2R/(μa)``,
        i.e. ``dQ/dξ = −2PR/a = −πaE*/2`` (the 2D linear creep coefficient).

    Notes
    -----
    Source: Carter (1926); Johnson (1985) Ch. 8; Kalker's 2D theory, see
    ``SOURCES["creep_force_ratio"]``.
    """
    try:
        xi_arr = np.asarray(xi, dtype=float)
    except (TypeError, ValueError):
        raise InputError("xi", f"must be real, got {xi!r}") from None
    if not np.all(np.isfinite(xi_arr)):
        raise InputError("xi", "must be finite")
    a = _positive("a", a)
    R = _positive("R", R)
    mu = _nonnegative("mu", mu)
    if mu == 0.0:
        return _out(-np.sign(xi_arr))
    u = np.minimum(np.abs(xi_arr) * R / (mu * a), 1.0)
    return _out(-np.sign(xi_arr) * (1.0 - (1.0 - u) ** 2))


def carter_slip(x, a, R, mu, ratio, direction):
    """Carter's steady-rolling slip per unit rolled distance (similar cylinders).

    ``s(x) = −d·sgn(ratio)·(μ/R)·sgn(y)·√(y² − c²)`` in the slip zone (``|x| < a``,
    ``|y| > c`` with ``y = x − x_c``), ``s = 0`` in the stick zone ``|y| ≤ c``, and NaN
    outside the contact (separated: no slip is defined). ``c = a√(1 − |ratio|)`` and
    ``x_c = −d·(a − c)`` as in :func:`carter_traction`.

    Parameters
    ----------
    x : float or array_like
        Positions (Eulerian, fixed to the contact).
    a, R, mu, ratio, direction
        As for :func:`carter_traction` and :func:`carter_creepage`.

    Returns
    -------
    float or ndarray
        ``s`` (dimensionless, as the result file's ``slip``), shape of ``x``. Its sign is
        opposite to the traction's, ``t = −μp·sgn(s)`` (the friction law of
        docs/formulation.md §5).

    Notes
    -----
    Derivation in the project's convention (the same steps as :func:`carter_creepage`): the
    steady slip is ``s = ξ + d·∂w/∂x`` with ``∂w/∂x = −(2/(πE*))·PV∫ t(s')/(x − s') ds'``.
    With ``(1/π)·PV∫_{−c}^{c} √(c² − s²)/(y − s) ds = y − sgn(y)·√(y² − c²)·[|y| > c]``
    and ``p0 = aE*/(2R)``, the two semi-ellipses of Carter's traction give
    ``∂w/∂x = −sgn(ratio)·(μ/R)·[x_c + sgn(y)√(y² − c²)·[|y| > c]]``; the constant part
    cancels ξ, what remains is the formula above. Source: Carter (1926); Johnson (1985)
    Ch. 8, see ``SOURCES["carter_slip"]``.
    """
    x = _coords(x)
    a, mu, ratio, d, c = _carter_arguments(a, mu, ratio, direction)
    R = _positive("R", R)
    y = x - (-d * (a - c))
    sign_r = math.copysign(1.0, ratio) * (ratio != 0.0)
    s = -d * sign_r * (mu / R) * np.sign(y) * np.sqrt(np.maximum(y * y - c * c, 0.0))
    return _out(np.where(np.abs(x) < a, s, np.nan))
