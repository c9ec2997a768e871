r"""The Hertz ellipse (docs/theory3d.md §2; Hertz 1882, Johnson 1985 §4.2, Kalker 1990 App. E).

A semi-ellipsoidal pressure ``p = p0 √(1 − x²/a² − y²/b²)`` on the ellipse of semi-axes ``a``
(along x) and ``b`` (along y) displaces the half-spaces by ``δ − A x² − B y²`` inside it
(Johnson eq. 3.57–3.58): with ``α ≥ β`` the major and minor semi-axes, ``g = β/α``,
``m = e² = 1 − g²`` and the complete elliptic integrals ``K(m)``, ``E(m)``,

.. math::
    D_{major} = \frac{p_0\,\beta}{E^*\alpha^2}\,\frac{K − E}{m},\qquad
    D_{minor} = \frac{p_0\,\beta}{E^*\alpha^2}\,\frac{E/g^2 − K}{m},\qquad
    \delta = \frac{p_0\,\beta}{E^*}\,K,\qquad F_N = \tfrac23\pi a b\,p_0          \qquad (3D.4)

where ``D_major`` is the curvature (``A`` or ``B`` of eq. 3D.3) in the direction of the major
axis — the flatter one. Given ``A, B``, the ratio ``D_major/D_minor = (K − E)/(E/g² − K)``
(increasing in ``g`` from 0 to 1) fixes ``g``; ``F_N`` then fixes the size (eq. 3D.5):
``α³ = 3 F_N (K − E)/(2π E* m D_major)``. The quotients ``(K − E)/m`` and ``(E/g² − K)/m`` are
evaluated by their power series below ``m = 10⁻³`` (no cancellation; the circle is ``m = 0``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError

__all__ = ["HertzEllipse", "hertz", "curvature_ratio", "curvatures_for_ratio"]

_SERIES = 1e-3   # below: power series of (K−E)/m and (E/(1−m) − K)/m, error O(m⁴) < 1e-12


def _quotients(m: float) -> tuple[float, float, float, float]:
    """``(K, E, (K − E)/m, (E/(1 − m) − K)/m)`` at parameter ``m = 1 − g²``."""
    from scipy.special import ellipe, ellipk   # scipy on first use: ``import rollqp`` loads none
    K, E = float(ellipk(m)), float(ellipe(m))
    if m < _SERIES:
        h = 0.5 * math.pi
        nk = h * (0.5 + m * (3 / 16 + m * (15 / 128 + m * 175 / 2048)))
        nd = h * (0.5 + m * (9 / 16 + m * (75 / 128 + m * 1225 / 2048)))
        return K, E, nk, nd
    return K, E, (K - E) / m, (E / (1 - m) - K) / m


def curvature_ratio(g: float) -> float:
    """``D_major/D_minor`` for the semi-axis ratio ``g = minor/major ∈ (0, 1]`` (eq. 3D.4).

    Examples
    --------
    >>> curvature_ratio(1.0)
    1.0
    >>> round(curvature_ratio(0.5), 6)
    0.351772
    """
    if not 0 < g <= 1:
        raise InputError("g", f"the semi-axis ratio minor/major must be in (0, 1], got {g!r}")
    _, _, nk, nd = _quotients(1 - g * g)
    return nk / nd


def _ratio_to_g(y: float) -> float:
    """The ``g`` with ``curvature_ratio(g) = y`` (``0 < y <= 1``), to round-off."""
    if y >= 1:
        return 1.0
    lo = 1e-6
    if curvature_ratio(lo) > y:
        raise InputError("curvatures", f"curvature ratio {y:.3g} is beyond an ellipse with b/a = 1e-6")
    from scipy.optimize import brentq
    return brentq(lambda g: curvature_ratio(g) - y, lo, 1.0, xtol=1e-15, rtol=4 * np.finfo(float).eps)


@dataclass(frozen=True)
class HertzEllipse:
    """The Hertz solution (eq. 3D.4–3D.5): semi-axes ``a`` (x) and ``b`` (y), peak pressure ``p0``,
    approach ``delta``, for curvatures ``A, B``, contact modulus ``Estar`` and normal force ``FN``."""

    a: float
    b: float
    p0: float
    delta: float
    A: float
    B: float
    Estar: float
    FN: float

    @property
    def c(self) -> float:
        """``√(ab)``: Kalker's length scale of the creep coefficients."""
        return math.sqrt(self.a * self.b)

    def pressure(self, x, y) -> np.ndarray:
        """``p0 √(1 − x²/a² − y²/b²)``, zero outside the ellipse."""
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        return self.p0 * np.sqrt(np.maximum(0.0, 1 - (x / self.a) ** 2 - (y / self.b) ** 2))


def _positive(name, v) -> float:
    try:
        x = float(v)
    except (TypeError, ValueError):
        raise InputError(name, f"must be a finite number > 0, got {v!r}") from None
    if not (math.isfinite(x) and x > 0):
        raise InputError(name, f"must be a finite number > 0, got {v!r}")
    return x


def hertz(A: float, B: float, Estar: float, FN: float) -> HertzEllipse:
    """The Hertz ellipse for ``h = A x² + B y²`` (eq. 3D.3) pressed by ``FN``.

    Examples
    --------
    >>> h = hertz(0.01, 0.01, 200 / 0.58, 9.1954)           # CONTACT's cattaneo: a = b = 1 mm
    >>> round(h.a, 4), round(h.b, 4), round(h.p0, 4)
    (1.0, 1.0, 4.3905)
    """
    A, B = _positive("A", A), _positive("B", B)
    Estar, FN = _positive("Estar", Estar), _positive("FN", FN)
    g = _ratio_to_g(min(A, B) / max(A, B))
    K, _, nk, _ = _quotients(1 - g * g)
    d_major = min(A, B)
    major = (3 * FN * nk / (2 * math.pi * Estar * d_major)) ** (1 / 3)
    minor = g * major
    p0 = 3 * FN / (2 * math.pi * major * minor)
    delta = p0 * minor * K / Estar
    a, b = (minor, major) if A >= B else (major, minor)
    return HertzEllipse(a=a, b=b, p0=p0, delta=delta, A=A, B=B, Estar=Estar, FN=FN)


def curvatures_for_ratio(A: float, a_over_b: float) -> float:
    """The curvature ``B`` that gives the semi-axis ratio ``a/b`` with curvature ``A`` in x
    (CONTACT's ``IPOTCN = −2``: ``A1`` and ``AOB`` prescribed).

    Examples
    --------
    >>> round(curvatures_for_ratio(0.0008, 0.5) * 1e3, 4)        # CONTACT's tractcurv: B1 = 0.2814e-3
    0.2814
    """
    A, r = _positive("A", A), _positive("a_over_b", a_over_b)
    if r <= 1:   # a is the minor axis: x is the more curved direction
        return A * curvature_ratio(r)
    return A / curvature_ratio(1 / r)
