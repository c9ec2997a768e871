r"""The brush: steady rolling of a contact whose tangential compliance is a bed of independent springs,
under a Hertz pressure — the limit of a soft interface layer on stiff bodies (:mod:`rollqp.influence.layer`).

Springs of stiffness ``k`` (traction per displacement, stress per length: ``k = G₃/h`` for a layer) enter the
contact at its leading edge unstrained. In steady rolling with creepage ``ξ`` a spring that sticks is
strained by ``ξ`` per unit rolled distance, so its traction grows linearly from the leading edge,
``|t| = k|ξ| s`` (``s`` the distance from the leading edge), until it reaches ``μp``; from there to the
trailing edge it slides at ``μp``. With ``p = p₀√(1 − u²)`` along a row (``u = x/a`` measured towards the
leading edge, ``a`` its half-length) the stick zone ends where ``κ(1 − u) = √(1 − u²)``,

.. math::
    κ = \frac{k|ξ|a}{μ p_0},\qquad u^* = \frac{κ^2 − 1}{κ^2 + 1},\qquad
    \frac{|F|}{μN} = \frac{2}{π}\Big[\frac{κ(1 − u^*)^2}{2} + \frac{u^*\sqrt{1 − u^{*2}} + \arcsin u^*}{2}
        + \frac{π}{4}\Big]                                                          \qquad (\text{B.1})

— in 2D (a strip, ``N`` the load per unit length) and in 3D alike: on a Hertz ellipse every row ``y`` has the
half-length ``a√(1 − y²/b²)`` and peak ``p₀√(1 − y²/b²)``, so the same ``κ`` and ``u^*``, and the rows' forces
sum to the same fraction of ``μN``. The force opposes the creepage (``F`` has the sign of ``−ξ``, CONTACT's
convention). Small creepage: ``|F| = (4/π) μN κ`` (``(8/3) k|ξ|a²b`` in 3D, ``2k|ξ|a²`` in 2D); ``κ → ∞``:
``μN`` (full sliding).
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError

__all__ = ["SOURCE", "brush_kappa", "brush_creep_ratio"]

#: The brush model of rolling contact.
SOURCE = ("J. J. Kalker, Three-Dimensional Elastic Bodies in Rolling Contact, Kluwer, 1990, §3.2 (the "
          "simplified theory: a bed of independent springs); K. L. Johnson, Contact Mechanics, Cambridge "
          "University Press, 1985, §8.4 (the brush under a Hertz pressure)")


def _positive(name, v):
    v = float(v)
    if not np.isfinite(v) or v <= 0:
        raise InputError(name, f"must be a finite number > 0, got {v!r}")
    return v


def brush_kappa(xi, a, p0, mu, stiffness):
    """``κ = k|ξ|a/(μp₀)`` of eq. B.1: the brush's stick strain at the leading edge over the friction bound.

    Parameters
    ----------
    xi : float or array_like
        Creepage (finite).
    a, p0, mu, stiffness : float
        As for :func:`brush_creep_ratio` (each ``> 0``).

    Returns
    -------
    ndarray
        ``κ >= 0``, of ``xi``'s shape.

    Notes
    -----
    Source: ``SOURCES["brush_kappa"]``.
    """
    a, p0, mu, k = (_positive(n, v) for n, v in (("a", a), ("p0", p0), ("mu", mu), ("stiffness", stiffness)))
    xi = np.asarray(xi, dtype=float)
    if not np.all(np.isfinite(xi)):
        raise InputError("xi", "must be finite")
    return k * np.abs(xi) * a / (mu * p0)


def brush_creep_ratio(xi, a, p0, mu, stiffness):
    """``F/(μN)`` of the brush under a Hertz pressure (eq. B.1), of sign ``−sgn(ξ)``.

    Parameters
    ----------
    xi : float or array_like
        Creepage (rigid slip of A relative to B per rolled distance).
    a, p0 : float
        Half-length along the rolling direction and peak of the Hertz pressure (2D: the half-width; 3D: the
        semi-axis along x).
    mu : float
        Coulomb's coefficient (``> 0``).
    stiffness : float
        ``k``, traction per displacement (``G₃/h`` of a layer).

    Returns
    -------
    float or ndarray
        ``F/(μN)`` in ``[−1, 1]``, of sign opposite to ``ξ``, shape of ``xi``.

    Notes
    -----
    Source: ``SOURCES["brush_creep_ratio"]``.

    Examples
    --------
    >>> r = brush_creep_ratio([1e-9, 1e3], 1.0, 1.0, 0.3, 1.0)
    >>> round(float(r[0]) / (-4 / np.pi * 1e-9 / 0.3), 6), round(float(r[1]), 4)   # linear start; μN
    (1.0, -1.0)
    """
    kappa = brush_kappa(xi, a, p0, mu, stiffness)
    k2 = kappa * kappa
    u = (k2 - 1.0) / (k2 + 1.0)
    g = 0.5 * kappa * (1.0 - u) ** 2 + 0.5 * (u * np.sqrt(np.clip(1.0 - u * u, 0.0, None)) + np.arcsin(u)) + np.pi / 4
    out = -np.sign(np.asarray(xi, dtype=float)) * (2.0 / np.pi) * g
    return float(out) if np.ndim(out) == 0 else out
