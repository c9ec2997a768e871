"""Lamé: a thick ring on a rigid core under uniform outer pressure (the check of the BEM solver alone).

Symbols: ``r`` radius, ``inner``/``outer`` the core and outer radii, ``E``, ``ν`` the ring's moduli.
Source: :data:`SOURCE`.
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError
from ._common import _out, _positive, _scalar


#: Lamé's thick-walled cylinder (plane strain).
SOURCE = ("G. Lamé, Leçons sur la théorie mathématique de l'élasticité des corps solides, 1852; "
          "thick-walled cylinder in plane strain as in S. P. Timoshenko and J. N. Goodier, Theory of "
          "Elasticity, 3rd ed., McGraw-Hill, 1970, §28")


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
