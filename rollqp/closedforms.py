"""Closed-form solutions of 2D (plane-strain) contact of cylinders, for checking the solvers.

docs/formulation.md §12 restated as functions. Every function uses the project's sign convention
(docs/formulation.md §1):

* ``p ≥ 0`` is the contact pressure (compression positive);
* ``t`` is the tangential traction acting on body A in ``+x`` (B receives ``-t``),
  ``Q = ∫ t dx`` is the tangential load on A;
* ``ξ = (V_A − V_B)/|V|`` is the creepage (rigid slip of A relative to B);
* material moves through the contact with direction ``d = sgn(V)``: it enters at the
  leading edge ``x = −d·a`` and leaves at the trailing edge ``x = +d·a``;
* ``ratio = Q/(μP)`` is the signed tangential load ratio.

Symbols: ``P`` normal load per unit length, ``R`` relative radius (``1/R = 1/R_A + 1/R_B``),
``E*`` contact modulus (``1/E* = (1−ν_A²)/E_A + (1−ν_B²)/E_B``), ``a`` contact half-width,
``p0`` peak Hertz pressure, ``μ`` Coulomb friction coefficient. Any consistent units.

All traction and pressure functions are vectorized over ``x``: they accept a scalar or an
array and return a float or an ndarray of the same shape; they are zero outside
``|x| ≤ a``.

The 2D Hertz approach (rigid-body approach of the axes) is deliberately *not* given: in
plane strain it depends on how the bodies are supported far from the contact (the
logarithmic rigid constant ``d_ref`` of docs/formulation.md §3), so there is no definite
half-space formula to check against.

Sources are in :data:`SOURCES` (function name → citation).
"""
from __future__ import annotations

import math

import numpy as np

from .errors import InputError
from .scene.validate import nonnegative, positive, scalar

__all__ = [
    "hertz_half_width",
    "hertz_peak_pressure",
    "hertz_pressure",
    "cattaneo_stick_half_width",
    "cattaneo_traction",
    "carter_stick_zone",
    "carter_traction",
    "carter_creepage",
    "carter_slip",
    "creep_force_ratio",
    "bentall_johnson_creepage",
    "BENTALL_JOHNSON_COEFFICIENT",
    "lame_ring_displacement",
    "SOURCES",
]

_JOHNSON = "K. L. Johnson, Contact Mechanics, Cambridge University Press, 1985"
_HERTZ = ("H. Hertz, Über die Berührung fester elastischer Körper, J. reine angew. Math. 92, "
          "156–171 (1882); two-dimensional (cylinder) case as in " + _JOHNSON
          + ", Ch. 4 (Hertz theory)")
_CATTANEO = ("C. Cattaneo, Sul contatto di due corpi elastici: distribuzione locale degli sforzi, "
             "Rend. Accad. Naz. Lincei 27 (1938); R. D. Mindlin, Compliance of elastic bodies in "
             "contact, J. Appl. Mech. 16, 259–268 (1949); 2D form as in " + _JOHNSON
             + ", Ch. 7 (incipient sliding)")
_CARTER = ("F. W. Carter, On the action of a locomotive driving wheel, Proc. R. Soc. Lond. A 112, "
           "151–157 (1926); as in " + _JOHNSON + ", Ch. 8 (tractive rolling of elastic cylinders)")
_KALKER = ("J. J. Kalker, Three-Dimensional Elastic Bodies in Rolling Contact, Kluwer, 1990 "
           "(2D theory: Carter's solution is the exact 2D steady state; its small-creepage slope is "
           "the 2D linear creep coefficient)")
_BENTALL = ("R. H. Bentall and K. L. Johnson, Slip in the rolling contact of two dissimilar elastic "
            "rollers, Int. J. Mech. Sci. 9, 389–404 (1967); as in " + _JOHNSON
            + ", Ch. 8 (free rolling of dissimilar bodies); μ → 0 limit quoted in docs/formulation.md §12")

_LAME = ("G. Lamé, Leçons sur la théorie mathématique de l'élasticité des corps solides, 1852; "
         "thick-walled cylinder in plane strain as in S. P. Timoshenko and J. N. Goodier, Theory of "
         "Elasticity, 3rd ed., McGraw-Hill, 1970, §28")

#: Citation of each function's closed form.
SOURCES: dict[str, str] = {
    "hertz_half_width": _HERTZ,
    "hertz_peak_pressure": _HERTZ,
    "hertz_pressure": _HERTZ,
    "cattaneo_stick_half_width": _CATTANEO,
    "cattaneo_traction": _CATTANEO,
    "carter_stick_zone": _CARTER,
    "carter_traction": _CARTER,
    "carter_creepage": _CARTER,
    "carter_slip": _CARTER,
    "creep_force_ratio": _CARTER + "; " + _KALKER,
    "bentall_johnson_creepage": _BENTALL,
    "lame_ring_displacement": _LAME,
}


def _bj_coefficient() -> float:
    """Root u of u√(1−u²) + arcsin u = π/4 (bisection), returning √(1−u²)/2."""
    lo, hi = 0.0, 1.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid * math.sqrt(1.0 - mid * mid) + math.asin(mid) < math.pi / 4:
            lo = mid
        else:
            hi = mid
    u = 0.5 * (lo + hi)
    return 0.5 * math.sqrt(1.0 - u * u)


#: Bentall–Johnson free-rolling coefficient at μ → 0, ``|ξ| = C·|κ|·a/R`` with
#: ``C = ½√(1 − u²)`` and ``u`` the root of ``u√(1−u²) + arcsin u = π/4``
#: (``C = 0.45739…``, the ``0.457`` of docs/formulation.md §12). See :func:`bentall_johnson_creepage`.
BENTALL_JOHNSON_COEFFICIENT: float = _bj_coefficient()


# --------------------------------------------------------------------------- validation
# the project's one set of validators (rollqp.scene.validate), lenient: numpy scalars accepted
_scalar, _positive, _nonnegative = scalar, positive, nonnegative


def _ratio(value) -> float:
    v = _scalar("ratio", value)
    if not abs(v) < 1.0:
        raise InputError("ratio", f"Q/(mu P) must satisfy |ratio| < 1 (partial slip), got {value!r}")
    return v


def _ratio_array(value) -> np.ndarray:
    try:
        r = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError("ratio", f"must be real, got {value!r}") from None
    if not np.all(np.isfinite(r)) or not np.all(np.abs(r) < 1.0):
        raise InputError("ratio", "Q/(mu P) must be finite with |ratio| < 1 (partial slip)")
    return r


def _direction(value) -> int:
    if isinstance(value, bool):
        raise InputError("direction", f"must be -1 or +1, got {value!r}")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError("direction", f"must be -1 or +1, got {value!r}") from None
    if v not in (-1.0, 1.0):
        raise InputError("direction", f"must be -1 or +1, got {value!r}")
    return int(v)


def _coords(x) -> np.ndarray:
    try:
        return np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise InputError("x", f"must be real, got {x!r}") from None


def _out(values: np.ndarray):
    return float(values) if values.ndim == 0 else values


def _semi_ellipse(x: np.ndarray, centre: float, half_width: float) -> np.ndarray:
    """√(1 − (x − centre)²/half_width²) inside the interval, 0 outside.

    Written as √((1 − u)(1 + u)), which is exactly 0 at u = ±1 and accurate near the ends.
    """
    if half_width <= 0.0:
        return np.zeros_like(x)
    u = (x - centre) / half_width
    return np.sqrt(np.clip((1.0 - u) * (1.0 + u), 0.0, None))


def _leading_semi_ellipse(x: np.ndarray, a: float, c: float, d: int) -> np.ndarray:
    """√(1 − (x − x_c)²/c²) on Carter's stick zone, x_c = −d(a − c), 0 outside.

    Evaluated through the distance from the leading edge, e = d·x + a, as
    √((e/c)(2 − e/c)): exactly 0 at the leading edge (no rounding of x_c ± c), and
    mirror-exact (x, d) ↔ (−x, −d).
    """
    if c <= 0.0:
        return np.zeros_like(x)
    v = (d * x + a) / c
    return np.sqrt(np.clip(v * (2.0 - v), 0.0, None))


# --------------------------------------------------------------------------- Hertz
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


# --------------------------------------------------------------------------- Cattaneo
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


# --------------------------------------------------------------------------- Carter
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


# --------------------------------------------------------------------------- Bentall–Johnson
def bentall_johnson_creepage(kappa, a, R):
    """Magnitude of the free-rolling creepage of dissimilar cylinders as ``μ → 0``.

    ``|ξ| = C·|κ|·a/R`` with ``C =`` :data:`BENTALL_JOHNSON_COEFFICIENT` ``= 0.45739… ≈ 0.457``.

    Parameters
    ----------
    kappa : float
        Bentall–Johnson's dissimilarity constant ``κ = 2β`` (``β`` Dundurs' parameter,
        docs/formulation.md §3; the paper's eq. 92 constant), ``|κ| ≤ 1``.
    a : float
        Hertz half-width, ``a > 0``.
    R : float
        Relative radius, ``R > 0``.

    Returns
    -------
    float
        ``|ξ| ≥ 0``. **This is a magnitude**: the sign of ``ξ`` depends on which body is
        the softer one (the sign of ``κ``) and on the rolling direction.

    Notes
    -----
    Free rolling (``Q = 0``) in the limit ``μ → 0`` quoted in docs/formulation.md §12 (for finite
    μ the creepage is smaller). Derivation: as ``μ → 0``, ``t → 0``, so ``w`` comes from the
    pressure alone, ``∂w/∂x = −(κ/E*)·p(x)`` with §3's ``A_tn``; the steady slip
    ``s = ξ − d·κ·p(x)/E*`` changes sign where ``p(x) = d·ξ·E*/κ``, i.e. at ``|x| = b``, and
    ``t = −μ·p·sgn(s)`` carries no net force only if the central part ``|x| < b`` carries
    half the load: ``u√(1−u²) + arcsin u = π/4``, ``u = b/a = 0.40397…``, whence
    ``|ξ| = κ·p(b)/E* = ½√(1 − u²)·κ·a/R``. With §3's kernel signs this gives
    ``sgn(ξ) = d·sgn(κ)``. Source: Bentall & Johnson (1967); Johnson (1985) Ch. 8, see
    ``SOURCES["bentall_johnson_creepage"]``.
    """
    kappa = _scalar("kappa", kappa)
    if abs(kappa) > 1.0:
        raise InputError("kappa", f"must satisfy |kappa| <= 1 (kappa = 2*beta, |beta| <= 1/2), got {kappa!r}")
    a = _positive("a", a)
    R = _positive("R", R)
    return BENTALL_JOHNSON_COEFFICIENT * abs(kappa) * a / R


def lame_ring_displacement(r, inner, outer, pressure, E, nu):
    """Radial displacement of a thick ring welded to a rigid core, under uniform outer pressure.

    Plane strain, ``u_r = A r + B/r`` with ``u_r(inner) = 0`` and ``σ_rr(outer) = -pressure``:

    ``B = -A·inner²``, ``A = -pressure / (2(λ + G) + 2G·inner²/outer²)``,
    ``G = E/(2(1 + ν))``, ``λ = 2Gν/(1 − 2ν)``.

    The check of the BEM solver alone (:mod:`rollqp.influence.bem`, docs/bem.md); source in
    ``SOURCES["lame_ring_displacement"]``.

    Parameters
    ----------
    r : float or array_like
        Radii, ``inner <= r <= outer``.
    inner, outer : float
        Core (shaft) and outer radius, ``0 < inner < outer``.
    pressure : float
        Uniform outer pressure (compression positive).
    E, nu : float
        Young's modulus ``> 0`` and Poisson's ratio in (−1, 0.5).

    Returns
    -------
    float or ndarray
        ``u_r(r)``, negative (inwards) for a positive pressure.
    """
    inner, outer = _positive("inner", inner), _positive("outer", outer)
    if not inner < outer:
        raise InputError("inner", f"must be smaller than outer = {outer!r}, got {inner!r}")
    E = _positive("E", E)
    nu = _scalar("nu", nu)
    if not -1.0 < nu < 0.5:
        raise InputError("nu", f"must lie in (-1, 0.5), got {nu!r}")
    pressure = _scalar("pressure", pressure)
    G = E / (2.0 * (1.0 + nu))
    lam = 2.0 * G * nu / (1.0 - 2.0 * nu)
    A = -pressure / (2.0 * (lam + G) + 2.0 * G * inner ** 2 / outer ** 2)
    r = np.asarray(r, dtype=float)
    return _out(A * r - A * inner ** 2 / r)


# --------------------------------------------------------------------------- load paths and profiles (docs/kinematics.md)
_MINDLIN = ("R. D. Mindlin and H. Deresiewicz, Elastic spheres in contact under varying oblique forces, J. Appl. "
            "Mech. 20, 327–344 (1953) (unloading and reloading as superpositions of Cattaneo solutions, with "
            "the memory of the turning points); 2D form as in " + _JOHNSON + ", §7.2 (oscillating tangential "
            "force; the 2D energy per cycle from the 2D tangential compliance of the stick zone)")
_CIAVARELLA = ("M. Ciavarella, D. A. Hills and G. Monno, The influence of rounded edges on indentation by a flat "
               "punch, Proc. IMechE C 212, 319–328 (1998) (2D flat punch with rounded corners); derived again "
               "in docs/kinematics.md from the 2D inversion formula (" + _JOHNSON + ", §2.8, eq. 2.49)")
SOURCES.update({"mindlin_turning_points": _MINDLIN, "mindlin_traction": _MINDLIN, "mindlin_dissipation": _MINDLIN,
                "mindlin_displacement": _MINDLIN,
                "rounded_punch_load": _CIAVARELLA, "rounded_punch_half_width": _CIAVARELLA,
                "rounded_punch_pressure": _CIAVARELLA})
__all__ += ["mindlin_turning_points", "mindlin_traction", "mindlin_dissipation", "mindlin_displacement", "rounded_punch_load",
            "rounded_punch_half_width", "rounded_punch_pressure"]


def mindlin_turning_points(ratios) -> tuple[list, float]:
    """The turning points a path of ``Q/(μP)`` values (from 0, at constant P) is remembered by.

    Masing's memory rule for Mindlin–Deresiewicz: a reversal from ``r_m`` is forgotten, with the
    one before it, once the load goes past ``r_{m−1}`` (the slip annulus of the earlier branch is
    swept again); the first (virgin) turning point ``r_1`` is forgotten once the load passes
    ``−r_1``. Source: ``SOURCES["mindlin_turning_points"]``.

    Parameters
    ----------
    ratios : sequence of float
        The path of ``Q/(μP)`` from 0, each ``|r| < 1``, piecewise linear between the values.

    Returns
    -------
    (list of float, float)
        The remembered turning points (``stack[0] = 0``) and the current value.
    """
    vals = _ratio_array(ratios).ravel()
    stack, cur = [0.0], 0.0
    for v in vals:
        v = float(v)
        if v == cur:
            continue
        if cur != stack[-1] and np.sign(v - cur) != np.sign(cur - stack[-1]):
            stack.append(cur)
        cur = v
        while True:
            m = len(stack) - 1
            if m >= 2 and abs(cur - stack[m]) >= abs(stack[m] - stack[m - 1]):
                del stack[-2:]
            elif m == 1 and abs(cur - stack[1]) >= 2.0 * abs(stack[1]):
                del stack[-1]
            else:
                break
    return stack, cur


def mindlin_traction(x, a, p0, mu, ratios):
    """Tangential traction at constant P after the path of load ratios ``Q/(μP)`` (Mindlin–Deresiewicz).

    Superposition of Cattaneo solutions ``t_C(x; r)`` (:func:`cattaneo_traction`) over the
    remembered turning points ``0 = r_0, r_1, …, r_m`` and the current value ``r``
    (:func:`mindlin_turning_points`):

    ``t = t_C(r_1 − r_0) + Σ_{i≥2} 2·t_C((r_i − r_{i−1})/2) + 2·t_C((r − r_m)/2)``

    (the first term with factor 1 and without halving when it is the virgin branch, ``m = 0``:
    ``t = t_C(r)``). Unloading from ``r*`` to ``r``: ``t = t_C(r*) − 2 t_C((r* − r)/2)``; at
    ``r = −r*``, ``t = −t_C(r*)``.

    Parameters
    ----------
    x : float or array_like
        Coordinate along the strip.
    a, p0 : float
        Hertz half-width (> 0) and peak pressure (>= 0) of the constant normal load.
    mu : float
        Friction coefficient, >= 0.
    ratios : sequence of float
        The path of ``Q/(μP)`` from 0, each ``|r| < 1``; piecewise linear between the values
        (its turning points among them). The last value is the current load.

    Returns
    -------
    float or ndarray
        ``t(x)`` on body A in +x.

    Notes
    -----
    Similar materials (no normal–tangential coupling), P held constant while Q varies. Source:
    ``SOURCES["mindlin_traction"]``.
    """
    stack, cur = mindlin_turning_points(ratios)
    x = _coords(x)
    nodes = stack + [cur]
    t = np.zeros_like(x, dtype=float)
    for i in range(1, len(nodes)):
        dr = nodes[i] - nodes[i - 1]
        if dr == 0.0:
            continue
        factor = 1.0 if i == 1 else 2.0
        t = t + factor * cattaneo_traction(x, a, p0, mu, dr / factor)
    return _out(np.asarray(t))


def mindlin_dissipation(ratio, mu, P, Estar):
    """Energy dissipated per cycle of ``Q`` between ``±ratio·μP`` at constant P (2D, similar bodies).

    ``W = (4(μP)²/(πE*))·[(1 − r)ln(1 − r) + r − r²/2]``, ``r = |ratio|`` (≈ ``2(μP)² r³/(3πE*)``
    for small r), per unit axial length. From the Masing loop ``W = 4[Q*u(Q*) − 2∫₀^{Q*} u dQ]``
    of the Cattaneo displacement, whose part not linear in Q is ``(μP/(πE*))(1 − r)ln(1 − r)``
    in 2D (the part linear in Q and the constant, which depend on the reference distance of the
    2D half-space, do no work over a closed cycle; docs/kinematics.md). Source:
    ``SOURCES["mindlin_dissipation"]``.

    Parameters
    ----------
    ratio : float
        Amplitude ``Q*/(μP)``, ``|ratio| < 1``.
    mu, P, Estar : float
        Friction coefficient (>= 0), normal load per unit length (> 0), contact modulus (> 0).

    Returns
    -------
    float
        Energy per cycle and unit axial length (force units).
    """
    r = abs(_ratio(ratio))
    mu, P, Estar = _nonnegative("mu", mu), _positive("P", P), _positive("Estar", Estar)
    g = (1.0 - r) * math.log1p(-r) + r - 0.5 * r * r
    return 4.0 * (mu * P) ** 2 / (math.pi * Estar) * g


def mindlin_displacement(ratios, mu, P, Estar):
    """The part of the rigid tangential displacement not linear in Q along a path of ``Q/(μP)`` (2D, Masing).

    On the virgin branch ``u_v(r) = (μP/(πE*))·sgn(r)(1 − |r|)ln(1 − |r|)`` (the 2D Cattaneo
    compliance of the stick zone, the same expression :func:`mindlin_dissipation` integrates);
    after turning points the superposition of :func:`mindlin_traction`:
    ``u = u_v(r_1) + Σ_{i≥2} 2·u_v((r_i − r_{i−1})/2) + 2·u_v((r − r_m)/2)`` over the remembered
    turning points (:func:`mindlin_turning_points`). The 2D half-space adds to it a part linear in
    Q and a constant, both set by its reference distance, that do no work over a closed cycle:
    compare loops with their secant compliance removed (``rollqp run fretting --plot``). Source:
    ``SOURCES["mindlin_displacement"]``.

    Parameters
    ----------
    ratios : sequence of float
        The path of ``Q/(μP)`` from 0 (each ``|r| < 1``), one value per state.
    mu, P, Estar : float
        Friction coefficient (>= 0), normal load per unit length (> 0), contact modulus (> 0).

    Returns
    -------
    ndarray
        ``u`` after each prefix of the path (length units), same length as ``ratios``.

    Examples
    --------
    >>> u = mindlin_displacement([0.3, 0.6, 0.0, -0.6, 0.0, 0.6], 0.1, 1000.0, 1.15e5)
    >>> bool(abs(u[-1] - u[1]) < 1e-15)       # the loop closes at the turning point it left
    True
    """
    vals = [float(v) for v in _ratio_array(ratios).ravel()]
    mu, P, Estar = _nonnegative("mu", mu), _positive("P", P), _positive("Estar", Estar)
    c = mu * P / (math.pi * Estar)

    def virgin(r):
        return c * math.copysign(1.0, r) * (1.0 - abs(r)) * math.log1p(-abs(r))  # odd: u_v(−r) = −u_v(r)

    out = np.empty(len(vals))
    for j in range(len(vals)):
        stack, cur = mindlin_turning_points(vals[:j + 1])
        nodes = stack + [cur]
        out[j] = sum((1.0 if i == 1 else 2.0) * virgin((nodes[i] - nodes[i - 1]) / (1.0 if i == 1 else 2.0))
                     for i in range(1, len(nodes)))
    return out


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


# --------------------------------------------------------------------------- subsurface stresses
_MCEWEN = ("E. McEwen, Stresses in elastic cylinders in contact along a generatrix (including the effect of "
           "tangential friction), Phil. Mag. (7) 40, 454-459, 1949; as written in K. L. Johnson, Contact "
           "Mechanics, Cambridge University Press, 1985, §4.2 (eq. 4.49-4.50, frictionless) and §7.2 "
           "(eq. 7.18, the traction q = mu p)")
SOURCES["hertz_subsurface_stresses"] = _MCEWEN
SOURCES["mcewen_stresses"] = _MCEWEN
__all__ += ["mcewen_stresses", "hertz_subsurface_stresses", "HERTZ_MAX_SHEAR"]

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
        body), the sign convention of :mod:`rollqp.stresses` (Flamant kernels, Johnson eq. 2.23,
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
