"""Bentall–Johnson: the free-rolling creepage of dissimilar cylinders as ``μ → 0``.

Symbols: ``κ = 2β`` (``β`` Dundurs' parameter), ``a`` Hertz half-width, ``R`` relative radius.
Source: :data:`SOURCE`.
"""
from __future__ import annotations

import math

from ..errors import InputError
from ._common import _JOHNSON, _positive, _scalar


#: Bentall and Johnson (1967) in Johnson's form.
SOURCE = ("R. H. Bentall and K. L. Johnson, Slip in the rolling contact of two dissimilar elastic "
          "rollers, Int. J. Mech. Sci. 9, 389–404 (1967); as in " + _JOHNSON
          + ", Ch. 8 (free rolling of dissimilar bodies); μ → 0 limit quoted in docs/formulation.md §12")


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
