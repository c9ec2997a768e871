r"""Half-space influence coefficients of uniformly loaded rectangles (docs/theory3d.md §3).

Point loads on the surface of a half-space (Boussinesq 1885, Cerruti 1882; Johnson 1985 §3.2,
Love 1929), summed over the two bodies with the combined constants of eq. 3D.10, give the
displacement difference ``u = u^A − u^B`` at ``(x, y)`` due to a unit force at the origin,
``X = x − x', Y = y − y', ρ = √(X² + Y²)`` (z into body A; tractions on A):

.. math::
    \pi G\,A_{nn} = \frac{1-\nu}{\rho},\qquad
    \pi G\,A_{xx} = \frac{1-\nu}{\rho} + \frac{\nu X^2}{\rho^3},\qquad
    \pi G\,A_{yy} = \frac{1-\nu}{\rho} + \frac{\nu Y^2}{\rho^3},\qquad
    \pi G\,A_{xy} = \pi G\,A_{yx} = \frac{\nu XY}{\rho^3},

    \pi G\,A_{nx} = K\frac{X}{\rho^2},\quad \pi G\,A_{ny} = K\frac{Y}{\rho^2},\quad
    \pi G\,A_{xn} = -K\frac{X}{\rho^2},\quad \pi G\,A_{yn} = -K\frac{Y}{\rho^2}     \qquad (3D.11)

(``A_ij``: displacement difference in direction ``i`` due to a unit load in direction ``j``; a
pressure draws the surface towards the load, ``A_xn < 0`` ahead of it for ``K > 0``; Betti's
reciprocity gives ``A_nx(X) = A_xn(−X)``). For a traction constant on the rectangle
``[x_J ± dx/2] × [y_J ± dy/2]`` the coefficient at the centre ``x_I`` is the integral of the
kernel over ``X ∈ [X_c ± dx/2], Y ∈ [Y_c ± dy/2]``, ``X_c = x_I − x_J``, in closed form as the
corner sum ``F(X₊,Y₊) − F(X₋,Y₊) − F(X₊,Y₋) + F(X₋,Y₋)`` of an antiderivative
``∂²F/∂X∂Y = f`` (Love 1929; Kalker 1990 §4.2):

.. math::
    f = \frac1\rho:\ F = X\,\mathrm{asinh}\frac{Y}{|X|} + Y\,\mathrm{asinh}\frac{X}{|Y|},\qquad
    f = \frac{X^2}{\rho^3}:\ F = Y\,\mathrm{asinh}\frac{X}{|Y|},\qquad
    f = \frac{XY}{\rho^3}:\ F = -\rho,

    f = \frac{X}{\rho^2}:\ F = X\arctan\frac{Y}{X} + \frac{Y}{2}\ln\rho^2          \qquad (3D.12)

(and ``X ↔ Y`` for ``Y²/ρ³``, ``Y/ρ²``). The coefficients depend on ``X_c, Y_c`` only: on the
uniform grid they form a block-Toeplitz matrix, stored as one kernel array of shape
``(2ny − 1, 2nx − 1)`` per component (:func:`kernels`; products by FFT in
:mod:`rollqp.influence.blocktoeplitz`). A kernel may be evaluated with an offset ``(ox, oy)`` added to
``(X_c, Y_c)``: the displacement at ``x_I + ox`` of the tractions on the grid, which the
transient needs where a particle was one step earlier (eq. 3D.16).
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError

__all__ = ["COMPONENTS", "rectangle_integrals", "kernels", "point_load"]

#: The kernels of eq. 3D.11, ``(out, in)`` direction pairs: ``n`` normal, ``x``, ``y`` tangential.
COMPONENTS = ("nn", "xx", "xy", "yx", "yy", "nx", "ny", "xn", "yn")


def _x_asinh(x, y):
    """``x·asinh(y/|x|)``, continuous at ``x = 0`` (value 0)."""
    ax = np.abs(x)
    with np.errstate(divide="ignore", invalid="ignore"):
        v = x * np.arcsinh(y / ax)
    return np.where(ax > 0, v, 0.0)


def _x_atan_log(x, y):
    """``x·atan(y/x) + (y/2)·ln(x² + y²)``, continuous (0 at the origin, ``y ln|y|`` at ``x = 0``)."""
    r2 = x * x + y * y
    with np.errstate(divide="ignore", invalid="ignore"):
        v = np.where(x != 0, x * np.arctan(y / x), 0.0) + np.where(r2 > 0, 0.5 * y * np.log(r2), 0.0)
    return v


_PRIMITIVES = {
    "r": lambda x, y: _x_asinh(x, y) + _x_asinh(y, x),   # 1/ρ
    "xx": lambda x, y: _x_asinh(y, x),                    # X²/ρ³
    "yy": lambda x, y: _x_asinh(x, y),                    # Y²/ρ³
    "xy": lambda x, y: -np.hypot(x, y),                   # XY/ρ³
    "x": _x_atan_log,                                     # X/ρ²
    "y": lambda x, y: _x_atan_log(y, x),                  # Y/ρ²
}


_PARITY = {"r": lambda sx, sy: 1.0, "xx": lambda sx, sy: 1.0, "yy": lambda sx, sy: 1.0,
           "xy": lambda sx, sy: sx * sy, "x": lambda sx, sy: sx, "y": lambda sx, sy: sy}


def rectangle_integrals(X, Y, dx: float, dy: float, which=("r", "xx", "yy", "xy", "x", "y")) -> dict:
    """The integrals of eq. 3D.12 over ``[X ± dx/2] × [Y ± dy/2]`` (``X, Y`` arrays of centres).

    Returns a dict ``{"r": ∫∫1/ρ, "xx": ∫∫X²/ρ³, "yy": ∫∫Y²/ρ³, "xy": ∫∫XY/ρ³, "x": ∫∫X/ρ², "y":
    ∫∫Y/ρ²}`` (the keys asked for), each of the shape of ``X``. Exact (corner sums of closed-form
    antiderivatives); the relative rounding error grows like ``ε·(ρ²/(dx dy))``, 1e-10 at 500
    element widths.

    Examples
    --------
    >>> import math
    >>> r = rectangle_integrals(0.0, 0.0, 2.0, 2.0)["r"]        # a square of side 2, from its centre
    >>> bool(abs(r - 8 * math.asinh(1.0)) < 1e-14)
    True
    """
    X, Y = np.broadcast_arrays(np.asarray(X, dtype=float), np.asarray(Y, dtype=float))
    # evaluated at (|X|, |Y|) and given the kernel's parity: the coefficients are then exactly
    # (bitwise) even or odd, so the assembled matrices are exactly symmetric (Betti) on the grid
    aX, aY, sX, sY = np.abs(X), np.abs(Y), np.sign(X), np.sign(Y)
    hx, hy = 0.5 * dx, 0.5 * dy
    out = {}
    for key in which:
        F = _PRIMITIVES[key]
        v = F(aX + hx, aY + hy) - F(aX - hx, aY + hy) - F(aX + hx, aY - hy) + F(aX - hx, aY - hy)
        out[key] = v * _PARITY[key](sX, sY)
    return out


def kernels(grid, materials, offset=(0.0, 0.0), components=None) -> dict:
    """The influence kernels of eq. 3D.11 on ``grid``, integrated over its elements (eq. 3D.12).

    Parameters
    ----------
    grid : rollqp.discretization.grid.Grid
    materials : rollqp.materials.Materials
    offset : (float, float)
        ``(ox, oy)`` added to the observation point: the kernel gives the displacement at
        ``x_I + ox, y_I + oy`` (0 for the current displacements).
    components : iterable of str, optional
        Subset of :data:`COMPONENTS`; default all nine when ``K ≠ 0``, the five uncoupled ones
        (``nn, xx, xy, yx, yy``) for similar bodies.

    Returns
    -------
    dict
        ``component → (2ny − 1, 2nx − 1)`` array: entry ``[b, a]`` is the displacement (per unit
        traction) at an element ``(a − nx + 1, b − ny + 1)`` elements from the loaded one.
    """
    ox, oy = (float(v) for v in offset)
    if not (np.isfinite(ox) and np.isfinite(oy)):
        raise InputError("offset", f"must be finite, got {offset!r}")
    if components is None:
        components = COMPONENTS if materials.K != 0.0 else COMPONENTS[:5]
    bad = [c for c in components if c not in COMPONENTS]
    if bad:
        raise InputError("components", f"unknown {bad}; allowed {COMPONENTS}")
    Xc = (np.arange(2 * grid.nx - 1) - (grid.nx - 1)) * grid.dx + ox
    Yc = (np.arange(2 * grid.ny - 1) - (grid.ny - 1)) * grid.dy + oy
    X, Y = np.meshgrid(Xc, Yc)
    I = rectangle_integrals(X, Y, grid.dx, grid.dy)
    G, nu, K = materials.G, materials.nu, materials.K
    c = 1.0 / (np.pi * G)
    table = {
        "nn": lambda: c * (1 - nu) * I["r"],
        "xx": lambda: c * ((1 - nu) * I["r"] + nu * I["xx"]),
        "yy": lambda: c * ((1 - nu) * I["r"] + nu * I["yy"]),
        "xy": lambda: c * nu * I["xy"],
        "yx": lambda: c * nu * I["xy"],
        "nx": lambda: c * K * I["x"],
        "ny": lambda: c * K * I["y"],
        "xn": lambda: -c * K * I["x"],
        "yn": lambda: -c * K * I["y"],
    }
    return {k: table[k]() for k in components}


def point_load(X, Y, materials) -> dict:
    """The point-load kernels of eq. 3D.11 at ``(X, Y) ≠ 0`` (per unit force): the far field of
    :func:`kernels` times the element area, for checking it."""
    X, Y = np.broadcast_arrays(np.asarray(X, dtype=float), np.asarray(Y, dtype=float))
    r = np.hypot(X, Y)
    G, nu, K = materials.G, materials.nu, materials.K
    c = 1.0 / (np.pi * G)
    return {"nn": c * (1 - nu) / r, "xx": c * ((1 - nu) / r + nu * X * X / r**3),
            "yy": c * ((1 - nu) / r + nu * Y * Y / r**3), "xy": c * nu * X * Y / r**3,
            "yx": c * nu * X * Y / r**3, "nx": c * K * X / r**2, "ny": c * K * Y / r**2,
            "xn": -c * K * X / r**2, "yn": -c * K * Y / r**2}
