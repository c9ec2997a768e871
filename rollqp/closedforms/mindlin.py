"""Mindlin–Deresiewicz: tangential load paths at constant normal load — turning points, traction, the rigid displacement and the
energy dissipated per cycle (2D, similar bodies).

Symbols: ``a`` Hertz half-width, ``p0`` peak pressure, ``μ`` Coulomb coefficient, ``ratios`` a path of
``Q/(μP)`` from 0, ``E*`` contact modulus. Source: :data:`SOURCE`.
"""
from __future__ import annotations

import math

import numpy as np

from ._common import _JOHNSON, _coords, _nonnegative, _out, _positive, _ratio, _ratio_array
from .cattaneo import cattaneo_traction


#: Mindlin and Deresiewicz (1953) in Johnson's 2D form.
SOURCE = ("R. D. Mindlin and H. Deresiewicz, Elastic spheres in contact under varying oblique forces, J. Appl. "
          "Mech. 20, 327–344 (1953) (unloading and reloading as superpositions of Cattaneo solutions, with "
          "the memory of the turning points); 2D form as in " + _JOHNSON + ", §7.2 (oscillating tangential "
          "force; the 2D energy per cycle from the 2D tangential compliance of the stick zone)")


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
