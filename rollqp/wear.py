"""Archard wear of each roller, integrated along its material points (docs/stresses.md §6).

Archard's law with the coefficient ``k/H`` of a body (scene key ``bodies.X.wear``): the worn
depth grows by ``dh = (k/H)·p·|s|·dq`` at a material point under pressure ``p`` slipping at ``s``
(per unit rolled distance) while the roller turns by ``dq``. The result field ``wear_rate_A``
(``_B``) is ``(k/H)·p·|s|`` at the nodes, written when the body has a coefficient.

The material kinematics are the scene's (docs/formulation.md §1–2): a material point moves
through the contact with direction ``d`` by ``Δq`` per step, so the point at node ``x_i`` in
state ``k`` has the surface coordinate ``σ = x_i − Σ_j d_j Δq_j`` (its position at ``q = 0``; the
directions of ``load.rolled`` when the result holds them), taken
modulo the roller's circumference ``2πR``. :func:`profile` adds every step's ``wear_rate·Δq``
at those coordinates (the traction shape functions interpolate between nodes), which gives the
worn depth along each roller's surface. Both rollers move by the same ``Δq`` per step up to the
creepage (``|ξ| ≲ 1e-3``), which is neglected here.
"""
from __future__ import annotations

import numpy as np

from .errors import InputError
from .fields import Field, register
from .result import load_result
from .subsurface import _source
from .subsurface3d import source3d
from .strip import Strip

__all__ = ["wear_rate", "grid_wear_rate", "profile"]


def wear_rate(body: str):
    """``derive(rows)`` of the field ``wear_rate_<body>``: ``(k/H)·p·|s|`` of the rolling states of a block
    (:class:`rollqp.fields.Rows`; 0 for a static-shift or steady state), ``k/H`` the run's constant
    ``wear_<body>``."""
    def derive(rows):
        k = float(rows.constants[f"wear_{body}"])
        rolling = rows["_rolling"].astype(bool)[:, None]
        return np.where(rolling, k * rows["pn"] * np.abs(rows["slip"]), 0.0)
    return derive


for _b in ("A", "B"):
    register(Field(f"wear_rate_{_b}", "state", "1", f"Archard worn-depth rate (k/H) p |s| of body {_b} per unit "
                   f"rolled distance (written when bodies.{_b}.wear is set; 0 for a braked starting state)",
                   derive=wear_rate(_b), needed=(lambda b: lambda scene: getattr(scene, b).wear is not None)(_b)))


def grid_wear_rate(body: str):
    """``derive(rows)`` of the 3D field ``wear_rate_<body>``: ``(k/H)·p·|s|``, ``|s| = √(s_x² + s_y²)``, on the grid
    (0 for the static shift of a braked start, state 0; a steady state is rolling)."""
    def derive(rows):
        k = float(rows.constants[f"wear_{body}"])
        shift = (np.asarray(rows["step"]) == 0) & bool(float(rows.constants.get("braked", 0.0)))
        rate = k * rows["pn"] * np.hypot(rows["sx"], rows["sy"])
        return np.where(shift[:, None, None], 0.0, rate)
    return derive


for _b in ("A", "B"):
    register(Field(f"wear_rate_{_b}", "state", "1", f"Archard worn-depth rate (k/H) p |s| of body {_b} per unit "
                   f"rolled distance on the grid (written when bodies.{_b}.wear is set; 0 for a braked start's shift)",
                   derive=grid_wear_rate(_b), needed=(lambda b: lambda scene: getattr(scene, b).wear is not None)(_b)),
             3)


def profile(result, body: str = "A", coefficient=None, resolution: int = 4):
    """Worn depth along roller ``body``'s surface after the whole run, in either dimension.

    A material point of the surface moves through the contact in the direction ``d`` by ``|Δq|`` per rolling
    step: at state ``k`` the point of surface coordinate ``σ`` (its position at ``q = 0``) is at
    ``x = σ + Σ_j d_j |Δq_j|`` (``d_j`` the step's direction: ``load.direction``, reversed where ``load.rolled``
    falls). Its worn depth is ``h(σ) = Σ_k rate_k(x_k(σ))·|Δq_k|`` over the rolling steps (not the starting state
    nor a stop), the rate interpolated along x by the discretization's own traction shape: the strip's shape
    functions in 2D, the grid's piecewise constant elements in 3D, where every row of elements (each ``y``)
    is a material line of its own. The sum is the trapezoid-free discrete form of
    ``h = (k/H) ∫ p |s| dq`` along the material line (docs/stresses.md §6, §10).

    Parameters
    ----------
    result : Result, dict (``load_result``) or path
        A 2D or 3D result.
    body : {"A", "B"}
    coefficient : float or None
        k/H; None: the scene's ``bodies.<body>.wear`` (the result's ``wear_rate_<body>`` is used).
    resolution : int
        Surface points per node spacing (2D) or element length ``dx`` (3D).

    Returns
    -------
    (sigma, depth) : ndarrays
        Surface coordinate (length, the material's position at q = 0, modulo 2πR) and the worn depth there
        (length): ``depth`` has the shape of ``sigma`` in 2D and ``(ny, sigma.size)`` in 3D (rows at the
        result's ``y``).

    >>> import rollqp
    >>> s = rollqp.load_scene("cattaneo-3d").replace(**{"discretization.elements": [12, 12],
    ...                                              "discretization.distance": 1.0, "bodies.A.wear": 1e-9})
    >>> sigma, h = profile(rollqp.run(s))
    >>> h.shape == (12, sigma.size) and bool(h.max() > 0)
    True
    """
    if body not in ("A", "B"):
        raise InputError("body", f"must be 'A' or 'B', got {body!r}")
    if isinstance(resolution, bool) or not isinstance(resolution, (int, np.integer)) or not 1 <= resolution <= 100:
        raise InputError("resolution", f"must be a whole number in [1, 100] (surface points per node spacing), "
                                       f"got {resolution!r}")
    arrays, scene, along, lo, hi, spacing, centred = _material_axis(result)
    key = f"wear_rate_{body}"
    p0 = float(np.asarray(arrays["p0"]).reshape(-1)[0]) if "p0" in arrays else float(scene.p0)
    if coefficient is None and key not in arrays:
        raise InputError("coefficient", f"give k/H: the scene has no bodies.{body}.wear and the result no {key!r}")
    if coefficient is not None and (isinstance(coefficient, bool) or not isinstance(coefficient, (int, float, np.integer, np.floating))
                                    or not 0 <= coefficient <= 1.0 / p0):
        raise InputError("coefficient", f"must be a number in [0, 1/p0 = {1.0 / p0:.6g}] (k/H in 1/stress: "
                                        f"Archard's k·p0/H is at most 1), got {coefficient!r}")
    q = np.asarray(arrays["q"], dtype=float)
    dqs = np.abs(np.diff(q, prepend=q[0]))                  # |Δq_k|: q falls when load.rolled reverses
    if "direction" in arrays:                               # 2D: the per-step directions of load.rolled
        d = np.asarray(arrays["direction"], dtype=float)
    else:                                                   # q(τ) itself falls on a reversal
        d = float(scene.load.direction) * np.sign(np.diff(q, prepend=q[0]))
    travel = np.cumsum(d * dqs)                             # the material's signed travel Σ d_k |Δq_k|
    if coefficient is not None:
        slip = np.abs(arrays["slip"]) if "slip" in arrays else np.hypot(arrays["sx"], arrays["sy"])
        rate = coefficient * np.asarray(arrays["pn"], dtype=float) * slip
    else:
        rate = np.asarray(arrays[key], dtype=float)
    h = spacing / resolution
    reach = np.abs(travel).max()
    sigma = np.arange(lo - reach, hi + reach + h / 2, h) + (h / 2 if centred else 0.0)
    depth = np.zeros(rate.shape[1:-1] + sigma.shape)
    for k in np.flatnonzero((dqs > 0) & (d != 0)):            # rolling steps (not the start, not stops)
        x = sigma + travel[k]                                   # where each material point is at q_k
        inside = (x >= lo) & (x <= hi)
        depth[..., inside] += rate[k] @ along(x[inside]).T * dqs[k]
    circ = 2 * np.pi * float(getattr(scene, body).radius)
    if np.isfinite(circ) and sigma.max() - sigma.min() > circ:  # more than one turn: fold onto one circumference
        s = np.mod(sigma, circ)
        grid = np.arange(0.0, circ, h)
        folded = np.zeros(depth.shape[:-1] + grid.shape)
        idx = np.minimum((s / h).astype(int), grid.size - 1)
        for j in np.ndindex(*depth.shape[:-1]):
            np.add.at(folded[j], idx, depth[j])
        return grid, folded
    return sigma, depth


def _material_axis(result):
    """``(arrays, scene, along, lo, hi, spacing, centred)``: a result's arrays and scene, the interpolation
    ``along(x)`` (m, n) of its values along the rolling axis at points ``x`` in ``[lo, hi]``, its node spacing, and
    whether the surface points sit at the centres of the ``resolution`` parts of an element (3D: the grid's
    piecewise constant elements, so that a travel of whole elements gives each element ``resolution`` points and
    the worn volume is the rates' sum exactly) rather than on the nodes (2D)."""
    arrays = result if isinstance(result, dict) else dict(result.arrays()) if hasattr(result, "arrays") \
        else load_result(result, "result")
    if "px" in arrays:                                      # a 3D result: the grid's elements
        arrays, scene = source3d(arrays)
        x = np.asarray(arrays["x"], dtype=float)
        dx = float(x[1] - x[0]) if x.size > 1 else float(scene.grid.dx)
        lo, hi = float(x[0]) - dx / 2, float(x[-1]) + dx / 2

        def along(pts):
            idx = np.minimum(((pts - lo) / dx).astype(int), x.size - 1)
            m = np.zeros((pts.size, x.size))
            m[np.arange(pts.size), idx] = 1.0
            return m
        return arrays, scene, along, lo, hi, dx, True
    if hasattr(result, "arrays"):
        arrays["meta"] = result.meta
    arrays, scene = _source(arrays)
    d = scene.discretization
    strip = Strip(scene.half_width, d.elements, d.element)
    return arrays, scene, strip.traction_matrix, -scene.half_width, scene.half_width, strip.spacing, False
