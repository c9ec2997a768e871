r"""Post-processing of 3D solutions: errors against Hertz and Cattaneo–Mindlin, Kalker's creep
coefficients from small-creepage steady solves (docs/validation3d.md).

* **Semi-axes of a computed pressure.** For the Hertz pressure ``∫x²p/∫p = a²/5`` (and ``b²/5``
  for y), so ``a_h = √(5 Σx²p/Σp)`` measures the contact's extent from the whole field, not from
  its staircase edge;
* **creep coefficients.** Three steady solves at creepages small enough that every contact
  element sticks give the columns of ``∂(Fx, Fy, Mz)/∂(ξ, η, φ)``, nondimensionalized as in
  eq. 3D.8. ``area_normalized=True`` divides by powers of the computed contact area over the
  Hertz area instead of ``πab``: the staircase of the discrete contact area is the leading,
  irregular part of the discretization error, and this removes it (docs/validation3d.md).
"""
from __future__ import annotations

import numpy as np

from ..operators.grid import Loads
from .march import normal, steady

__all__ = ["semi_axes", "hertz_errors", "hertz_field_errors", "creep_matrix", "cattaneo_errors"]


def semi_axes(contact, p) -> tuple[float, float]:
    """``(a_h, b_h)``: the semi-axes of an ellipsoidal pressure with the moments of ``p``."""
    p = np.asarray(p, dtype=float)
    P = float(p.sum())
    return float(np.sqrt(5 * np.sum(contact.x ** 2 * p) / P)), float(np.sqrt(5 * np.sum(contact.y ** 2 * p) / P))


def hertz_errors(contact, solution) -> dict:
    """Errors of a normal solution against the Hertz ellipse of the contact (:func:`hertz_field_errors`)."""
    return hertz_field_errors(contact.x, contact.y, solution.p, solution.delta, contact.ellipse)


def hertz_field_errors(x, y, p, delta, ellipse) -> dict:
    """Errors of a pressure field ``p`` at the element centres ``(x, y)`` (flattened) and its approach
    against the Hertz ``ellipse`` (relative to ``a, b, p0, δ``): ``a``, ``b`` (the semi-axes of the
    ellipsoidal pressure with ``p``'s second moments, exact for Hertz's: ``∫x²p/∫p = a²/5``), ``p0``
    (the pressure interpolated to the centre by the quadric through the nine central elements'
    ``p²``), ``delta``, ``rms`` (``p − p_Hertz`` over the grid, in ``p0``), ``max`` (in ``p0``)."""
    e = ellipse
    x, y, p = (np.asarray(v, dtype=float).ravel() for v in (x, y, p))
    P = float(p.sum())
    ah, bh = float(np.sqrt(5 * np.sum(x ** 2 * p) / P)), float(np.sqrt(5 * np.sum(y ** 2 * p) / P))
    ph = e.pressure(x, y)
    # p² is the quadric p0²(1 − x²/a² − y²/b²) for Hertz: fit it on the elements nearest the centre
    near = np.argsort(np.hypot(x / e.a, y / e.b))[:9]
    M = np.column_stack([np.ones(near.size), x[near] ** 2, y[near] ** 2])
    coef = np.linalg.lstsq(M, p[near] ** 2, rcond=None)[0]
    return {"a": ah / e.a - 1, "b": bh / e.b - 1, "p0": float(np.sqrt(coef[0])) / e.p0 - 1,
            "delta": delta / e.delta - 1, "rms": float(np.sqrt(np.mean((p - ph) ** 2))) / e.p0,
            "max": float(np.max(np.abs(p - ph))) / e.p0}


def cattaneo_errors(contact, record, ratio: float, traction) -> dict:
    """``rms`` and ``max`` of ``t_x − t_Cattaneo`` over the grid (in ``μp0``) and the relative error of
    the rigid shift, for a shift along x (``traction(r)``: the closed form's magnitude)."""
    sign = np.sign(record.Fx)
    ref = sign * traction(np.hypot(contact.x, contact.y))
    mp0 = contact.mu * contact.scales.stress
    d = record.t[0] - ref
    return {"rms": float(np.sqrt(np.mean(d ** 2))) / mp0, "max": float(np.max(np.abs(d))) / mp0,
            "ty": float(np.max(np.abs(record.t[1]))) / mp0}


def creep_matrix(contact, method, FN: float, creepage: float = 1e-8, direction: int = -1,
                 area_normalized: bool = False) -> tuple[np.ndarray, dict]:
    """``C`` with ``(Fx/(Gc²), Fy/(Gc²), Mz/(Gc³)) = −C (ξ, η, cφ)`` (eq. 3D.8) from three steady solves.

    Returns ``(C, info)``; ``info["slipping"]`` counts slipping elements (0 for the linear theory:
    lower ``creepage`` if not), ``info["area_ratio"]`` is the computed contact area over ``πab``.
    """
    e, G = contact.ellipse, contact.materials.G
    c = e.c
    C = np.zeros((3, 3))
    slipping = 0
    pressure = None if contact.ops.coupled else normal(contact, method, FN)
    for k, (xi, eta, phi) in enumerate([(creepage, 0.0, 0.0), (0.0, creepage, 0.0), (0.0, 0.0, creepage / c)]):
        rec = steady(contact, method, FN, Loads(xi=xi, eta=eta, phi=phi), direction=direction, pressure=pressure)
        slipping += int(np.sum(rec.state == 2))
        C[:, k] = -np.array([rec.Fx / (G * c * c), rec.Fy / (G * c * c), rec.Mz / (G * c ** 3)]) / creepage
    ratio = float(np.sum(rec.p > 0)) * contact.grid.area / (np.pi * e.a * e.b)
    if area_normalized:
        powers = np.array([[1.0, 1.0, 1.5], [1.0, 1.0, 1.5], [1.5, 1.5, 2.0]])
        C = C / ratio ** powers
    return C, {"slipping": slipping, "area_ratio": ratio}
