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
from .subsurface import _source
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
    """Worn depth along roller ``body``'s surface after the whole run.

    Parameters
    ----------
    result : Result, dict (``load_result``) or path
    body : {"A", "B"}
    coefficient : float or None
        k/H; None: the scene's ``bodies.<body>.wear`` (the result's ``wear_rate_<body>`` is used).
    resolution : int
        Surface points per node spacing.

    Returns
    -------
    (sigma, depth) : ndarrays
        Surface coordinate (length, the material's position at q = 0, modulo 2πR) and the
        worn depth there (length).
    """
    arrays, scene = _source(result)
    if body not in ("A", "B"):
        raise InputError("body", f"must be 'A' or 'B', got {body!r}")
    if isinstance(resolution, bool) or not isinstance(resolution, (int, np.integer)) or not 1 <= resolution <= 100:
        raise InputError("resolution", f"must be a whole number in [1, 100] (surface points per node spacing), "
                                       f"got {resolution!r}")
    mat = getattr(scene, body)
    key = f"wear_rate_{body}"
    if coefficient is None and key not in arrays:
        raise InputError("coefficient", f"give k/H: the scene has no bodies.{body}.wear and the result no {key!r}")
    if coefficient is not None and (isinstance(coefficient, bool) or not isinstance(coefficient, (int, float, np.integer, np.floating))
                                    or not 0 <= coefficient <= 1.0 / scene.p0):
        raise InputError("coefficient", f"must be a number in [0, 1/p0 = {1.0 / scene.p0:.6g}] (k/H in 1/stress: "
                                        f"Archard's k·p0/H is at most 1), got {coefficient!r}")
    d = scene.discretization
    strip = Strip(scene.half_width, d.elements, d.element)
    q = np.asarray(arrays["q"], dtype=float)
    # the material's signed travel: Σ d_k Δq_k (per-step directions of load.rolled, else load.direction)
    d = np.asarray(arrays["direction"], dtype=float) if "direction" in arrays else \
        np.full(q.size, float(scene.load.direction))
    dqs = np.abs(np.diff(q, prepend=q[0]))                  # |Δq_k|: q falls when load.rolled reverses
    travel = np.cumsum(d * dqs)
    rate = (coefficient * np.asarray(arrays["pn"]) * np.abs(arrays["slip"])) if coefficient is not None \
        else np.asarray(arrays[key])
    L, h = scene.half_width, strip.spacing / resolution
    reach = np.abs(travel).max()
    sigma = np.arange(-L - reach, L + reach + h / 2, h)
    depth = np.zeros_like(sigma)
    for k in np.flatnonzero((dqs > 0) & (d != 0)):            # rolling steps (not the start, not stops)
        x = sigma + travel[k]                                   # where each material point is at q_k
        inside = np.abs(x) <= L
        depth[inside] += strip.traction_matrix(x[inside]) @ rate[k] * dqs[k]
    circ = 2 * np.pi * mat.radius
    if sigma.max() - sigma.min() > circ:  # more than one turn: fold the surface onto one circumference
        s = np.mod(sigma, circ)
        grid = np.arange(0.0, circ, h)
        folded = np.zeros_like(grid)
        np.add.at(folded, np.minimum((s / h).astype(int), grid.size - 1), depth)
        return grid, folded
    return sigma, depth
