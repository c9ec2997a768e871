r"""Cattaneo–Mindlin on the circle: the 3D shift of a Hertz contact below full sliding (docs/theory3d.md §2,
"Two closed forms on the ellipse", eq. 3D.6–3D.7; docs/validation3d.md).

* **Cattaneo–Mindlin** (a circle of radius ``a`` pressed by ``FN``, then shifted by ``Q < μ FN``
  along x; Cattaneo 1938, Mindlin 1949; Johnson 1985 §7.2):

  .. math::
      t_x = \mu p_0\Big[\sqrt{1 − r^2/a^2} − \frac{c}{a}\sqrt{1 − r^2/c^2}\Big]\ (r < c),\quad
      \mu p\ (c \le r \le a),\qquad \frac{c}{a} = \Big(1 − \frac{Q}{\mu F_N}\Big)^{1/3}   \qquad (3D.6)

      \delta_x = \frac{3\mu F_N (2 − \nu)}{8 G a}\Big[1 − \Big(1 − \frac{Q}{\mu F_N}\Big)^{2/3}\Big]   \qquad (3D.7)

  with the combined ``G, ν`` of eq. 3D.10 (``δ_x``: the rigid shift of A relative to B, opposite to
  the force on A). It takes the traction parallel to the force; that is exact for ``ν = 0`` and
  an approximation otherwise (the Cerruti kernel's ``νX²/ρ³`` term adds a small ``t_y``, Johnson
  §7.2 and Kalker 1990 §5.2.1.1), so the convergence checks use ``ν = 0``.
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError

__all__ = ["cattaneo_traction", "cattaneo_stick_radius", "cattaneo_shift", "SOURCES"]

SOURCES = {
    "cattaneo": "C. Cattaneo, Rend. Accad. Naz. Lincei 27 (1938); R. D. Mindlin, J. Appl. Mech. 16 (1949) "
                "259–268; K. L. Johnson, Contact Mechanics (1985) §7.2, eq. 7.39–7.42",
}


def cattaneo_stick_radius(a: float, ratio: float) -> float:
    """``c = a (1 − Q/(μFN))^{1/3}`` (eq. 3D.6); ``ratio = Q/(μFN)`` in [0, 1)."""
    if not 0 <= ratio < 1:
        raise InputError("ratio", f"Q/(μ FN) must be in [0, 1), got {ratio!r}")
    return a * (1 - ratio) ** (1 / 3)


def cattaneo_traction(r, a: float, p0: float, mu: float, ratio: float) -> np.ndarray:
    """The traction magnitude along the force at radius ``r`` (eq. 3D.6)."""
    r = np.asarray(r, dtype=float)
    c = cattaneo_stick_radius(a, ratio)
    outer = np.sqrt(np.maximum(0.0, 1 - (r / a) ** 2))
    inner = (c / a) * np.sqrt(np.maximum(0.0, 1 - (r / c) ** 2)) if c > 0 else 0.0
    return mu * p0 * (outer - inner)


def cattaneo_shift(FN: float, a: float, mu: float, ratio: float, G: float, nu: float) -> float:
    """The rigid shift magnitude ``δ_x`` of eq. 3D.7 (combined ``G, ν``)."""
    if not 0 <= ratio < 1:
        raise InputError("ratio", f"Q/(μ FN) must be in [0, 1), got {ratio!r}")
    return 3 * mu * FN * (2 - nu) / (8 * G * a) * (1 - (1 - ratio) ** (2 / 3))
