r"""Closed forms and published tables that the 3D solutions are held against
(docs/theory3d.md §2, docs/validation3d.md).

* **Cattaneo–Mindlin** (a circle of radius ``a`` pressed by ``FN``, then shifted by ``Q < μ FN``
  along x; Cattaneo 1938, Mindlin 1949; Johnson 1985 §7.2):

  .. math::
      t_x = \mu p_0\Big[\sqrt{1 − r^2/a^2} − \frac{c}{a}\sqrt{1 − r^2/c^2}\Big]\ (r < c),\quad
      \mu p\ (c \le r \le a),\qquad \frac{c}{a} = \Big(1 − \frac{Q}{\mu F_N}\Big)^{1/3},

      \delta_x = \frac{3\mu F_N (2 − \nu)}{8 G a}\Big[1 − \Big(1 − \frac{Q}{\mu F_N}\Big)^{2/3}\Big]   \qquad (3D.7)

  with the combined ``G, ν`` of eq. 3D.10 (``δ_x``: the rigid shift of A relative to B, opposite to
  the force on A). It takes the traction parallel to the force; that is exact for ``ν = 0`` and
  an approximation otherwise (the Cerruti kernel's ``νX²/ρ³`` term adds a small ``t_y``, Johnson
  §7.2 and Kalker 1990 §5.2.1.1), so the convergence checks use ``ν = 0``.

* **Kalker's linear theory** (Kalker 1967; 1990, Table E.3; Johnson 1985, Table 8.1): at vanishing
  creepage the contact sticks everywhere and

  .. math::
      F_x = −G c^2 C_{11}\,\xi,\qquad F_y = −G c^2 (C_{22}\,\eta + c\,C_{23}\,\phi),\qquad
      M_z = G c^3 (C_{23}\,\eta − c\,C_{33}\,\phi),\qquad c = \sqrt{ab}                 \qquad (3D.8)

  in the conventions of docs/theory3d.md §1 (CONTACT's; the signs of the η–φ coupling are those
  the solutions show, docs/validation3d.md). :data:`KALKER_TABLE` holds the published values used.

* **Full sliding** (``φ = 0``, creepage beyond the sliding limit): every element slips and
  ``t_i = −μ p_i s_i/|s_i|``. For ``ν = 0`` the tangential kernel is isotropic (``A_xy = 0``,
  ``A_xx = A_yy``), so a traction field of one direction ``e`` displaces the surfaces along ``e``
  only, the slip ``w + S t`` stays along the rigid slip ``w``, and ``t_i = −μ p_i w/|w|`` exactly.
  For ``ν ≠ 0`` the ``νXY/ρ³`` coupling turns the slip by an angle that falls like ``1/|w|``
  (docs/validation3d.md measures it); ``Σ|t_i|·area = μ F_N`` holds in every case.
"""
from __future__ import annotations


import numpy as np

from ..errors import InputError

__all__ = ["cattaneo_traction", "cattaneo_stick_radius", "cattaneo_shift", "KALKER_TABLE", "kalker_coefficients",
           "kalker_interpolated", "SOURCES"]

SOURCES = {
    "cattaneo": "C. Cattaneo, Rend. Accad. Naz. Lincei 27 (1938); R. D. Mindlin, J. Appl. Mech. 16 (1949) "
                "259–268; K. L. Johnson, Contact Mechanics (1985) §7.2, eq. 7.39–7.42",
    "kalker": "J. J. Kalker, On the rolling contact of two elastic bodies in the presence of dry friction, "
              "thesis, Delft (1967); J. J. Kalker, Three-dimensional elastic bodies in rolling contact, "
              "Kluwer (1990), Table E.3; K. L. Johnson, Contact Mechanics (1985), Table 8.1",
}

#: Kalker's creep coefficients ``(C11, C22, C23, C33)`` for the semi-axis ratios ``a/b`` and Poisson's
#: ratios used in docs/validation3d.md (Kalker 1990, Table E.3). C11, C22, C23 as tabulated (two
#: independent transcriptions of the table agree digit for digit); C33 only where we could check
#: the quoted value (``None``: not checked, not compared).
KALKER_TABLE = {
    # (a/b, ν): (C11, C22, C23, C33)
    (1.0, 0.0): (3.40, 3.40, 1.33, None),
    (1.0, 0.25): (4.12, 3.67, 1.47, 1.19),
    (1.0, 0.5): (5.20, 3.98, 1.63, None),
    (0.5, 0.0): (2.88, 2.88, 0.827, None),
    (0.5, 0.25): (3.62, 3.01, 0.929, 1.93),
    (0.5, 0.5): (4.83, 3.14, 1.07, None),
    (2.0, 0.0): (4.37, 4.37, 2.35, None),
    (2.0, 0.25): (5.10, 4.90, 2.62, None),
    (2.0, 0.5): (6.11, 5.56, 2.96, None),
}


def cattaneo_stick_radius(a: float, ratio: float) -> float:
    """``c = a (1 − Q/(μFN))^{1/3}`` (eq. 3D.7); ``ratio = Q/(μFN)`` in [0, 1)."""
    if not 0 <= ratio < 1:
        raise InputError("ratio", f"Q/(μ FN) must be in [0, 1), got {ratio!r}")
    return a * (1 - ratio) ** (1 / 3)


def cattaneo_traction(r, a: float, p0: float, mu: float, ratio: float) -> np.ndarray:
    """The traction magnitude along the force at radius ``r`` (eq. 3D.7)."""
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


def kalker_coefficients(a_over_b: float, nu: float) -> tuple:
    """``(C11, C22, C23, C33)`` of :data:`KALKER_TABLE` (``None`` where not tabulated here).

    Examples
    --------
    >>> kalker_coefficients(1.0, 0.25)
    (4.12, 3.67, 1.47, 1.19)
    """
    key = (float(a_over_b), float(nu))
    if key not in KALKER_TABLE:
        raise InputError("a_over_b / nu", f"tabulated here for {sorted(KALKER_TABLE)}, got {key}")
    return KALKER_TABLE[key]



def kalker_interpolated(a_over_b: float, nu: float) -> tuple:
    """``(C11, C22, C23)`` at any ``ν ∈ [0, 0.5]`` for a tabulated ``a/b``: ``1/C`` interpolated by the
    parabola through the table's ``ν = 0, 0.25, 0.5`` (Kalker's table has no other ν; this is an
    interpolation, not a published value)."""
    if not 0 <= nu <= 0.5:
        raise InputError("nu", f"must be in [0, 0.5], got {nu!r}")
    rows = [kalker_coefficients(a_over_b, v)[:3] for v in (0.0, 0.25, 0.5)]
    w = ((nu - 0.25) * (nu - 0.5) / 0.125, -nu * (nu - 0.5) / 0.0625, nu * (nu - 0.25) / 0.125)
    return tuple(1.0 / sum(wi / r[j] for wi, r in zip(w, rows)) for j in range(3))
