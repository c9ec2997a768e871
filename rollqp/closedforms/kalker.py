r"""Kalker's linear theory of the elliptic contact, and full sliding: the closed forms the 3D creep forces are held
against (docs/theory3d.md §2, eq. 3D.8; docs/validation3d.md).

* **Kalker's linear theory** (Kalker 1967; 1990, Table E.3; Johnson 1985, Table 8.1): at vanishing
  creepage the contact sticks everywhere and

  .. math::
      F_x = −G c^2 C_{11}\,\xi,\qquad F_y = −G c^2 (C_{22}\,\eta + c\,C_{23}\,\phi),\qquad
      M_z = G c^3 (C_{23}\,\eta − c\,C_{33}\,\phi),\qquad c = \sqrt{ab}                 \qquad (3D.8)

  in the conventions of docs/theory3d.md §1 (CONTACT's; the signs of the η–φ coupling are those
  the solutions show, docs/validation3d.md). :data:`KALKER_E3` holds Kalker's Table E.3 of ``C11, C22,
  C23``; ``C33`` is not in it, and we found no source of it that we could check, so it is computed
  (docs/validation3d.md §3) but not held against a published value.

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

__all__ = ["KALKER_E3", "KALKER_NU", "kalker_coefficients", "kalker_linear", "SOURCES"]

SOURCES = {
    "kalker": "J. J. Kalker, Three-dimensional elastic bodies in rolling contact, Kluwer (1990), Table E.3 "
              "(C11, C22, C23 of the linear theory for elliptical contact areas), as transcribed in CONTACT's "
              "source (E. A. H. Vollebregt, github.com/eve70a/CONTACT, src/m_hertz.f90, subroutine linrol)",
}

#: Kalker's Table E.3 (1990): rows ``g = 0.1, 0.2, …, 1.0``; per row ``(C11, C22, C23)`` at
#: ``ν = (0, 0.25, 0.5)``. ``"a<b"``: ``g = a/b`` (the contact short in the rolling direction), ``"a>b"``:
#: ``g = b/a``; the two tables share the row ``g = 1``. Transcribed from :data:`SOURCES` ``["kalker"]``.
KALKER_E3 = {
    "a<b": (((2.51, 3.31, 4.85), (2.51, 2.52, 2.53), (.334, .473, .731)),
            ((2.59, 3.37, 4.81), (2.59, 2.63, 2.66), (.483, .603, .809)),
            ((2.68, 3.44, 4.80), (2.68, 2.75, 2.81), (.607, .715, .889)),
            ((2.78, 3.53, 4.82), (2.78, 2.88, 2.98), (.720, .823, .977)),
            ((2.88, 3.62, 4.83), (2.88, 3.01, 3.14), (.827, .929, 1.07)),
            ((2.98, 3.72, 4.91), (2.98, 3.14, 3.31), (.930, 1.03, 1.18)),
            ((3.09, 3.81, 4.97), (3.09, 3.28, 3.48), (1.03, 1.14, 1.29)),
            ((3.19, 3.91, 5.05), (3.19, 3.41, 3.65), (1.13, 1.25, 1.40)),
            ((3.29, 4.01, 5.12), (3.29, 3.54, 3.82), (1.23, 1.36, 1.51)),
            ((3.40, 4.12, 5.20), (3.40, 3.67, 3.98), (1.33, 1.47, 1.63))),
    "a>b": (((10.7, 11.7, 12.9), (10.7, 12.8, 16.0), (12.2, 14.6, 18.0)),
            ((6.96, 7.78, 8.82), (6.96, 8.14, 9.79), (5.72, 6.63, 7.89)),
            ((5.57, 6.34, 7.34), (5.57, 6.40, 7.51), (3.79, 4.32, 5.01)),
            ((4.84, 5.57, 6.57), (4.84, 5.48, 6.31), (2.88, 3.24, 3.70)),
            ((4.37, 5.10, 6.11), (4.37, 4.90, 5.56), (2.35, 2.62, 2.96)),
            ((4.06, 4.78, 5.80), (4.06, 4.50, 5.04), (2.01, 2.23, 2.50)),
            ((3.82, 4.54, 5.58), (3.82, 4.21, 4.67), (1.76, 1.95, 2.18)),
            ((3.65, 4.36, 5.42), (3.65, 3.99, 4.39), (1.58, 1.75, 1.94)),
            ((3.51, 4.22, 5.30), (3.51, 3.81, 4.16), (1.44, 1.59, 1.77)),
            ((3.40, 4.12, 5.20), (3.40, 3.67, 3.98), (1.33, 1.47, 1.63))),
}
KALKER_NU = (0.0, 0.25, 0.5)


def _table_row(a_over_b: float):
    """``(case, row)`` of :data:`KALKER_E3` for a tabulated ``a/b`` (``g`` a multiple of 0.1), else None."""
    g = a_over_b if a_over_b <= 1 else 1 / a_over_b
    row = round(10 * g) - 1
    if abs(10 * g - (row + 1)) > 1e-9 or not 0 <= row <= 9:
        return None
    return ("a<b" if a_over_b <= 1 else "a>b"), row


def kalker_coefficients(a_over_b: float, nu: float) -> tuple:
    """``(C11, C22, C23)`` of Kalker's linear law (eq. 3D.8) from Table E.3 (:data:`KALKER_E3`) at a tabulated ``a/b`` (``g`` =
    0.1, 0.2, …, 1) and ``ν`` (0, 0.25, 0.5).

    Examples
    --------
    >>> kalker_coefficients(1.0, 0.25)
    (4.12, 3.67, 1.47)
    >>> kalker_coefficients(2.0, 0.5)
    (6.11, 5.56, 2.96)
    """
    where = _table_row(float(a_over_b))
    if where is None or float(nu) not in KALKER_NU:
        raise InputError("a_over_b / nu", f"Table E.3 has g = min(a/b, b/a) = 0.1, 0.2, …, 1 and nu = 0, 0.25, 0.5, "
                                          f"got a/b = {a_over_b!r}, nu = {nu!r} (kalker_linear interpolates)")
    case, row = where
    i = KALKER_NU.index(float(nu))
    return tuple(c[i] for c in KALKER_E3[case][row])


def kalker_linear(a_over_b: float, nu: float) -> tuple | None:
    """``(C11, C22, C23)`` of eq. 3D.8 at any ``a/b`` with ``0.1 <= min(a/b, b/a) <= 1`` and ``ν ∈ [0, 0.5]``: linear in
    ``g`` between the rows of Table E.3, and ``1/C`` by the parabola in ``ν`` through the table's three
    values (Kalker's table has no other ``ν``; CONTACT interpolates so). ``None`` outside the table.

    Examples
    --------
    >>> [round(c, 4) for c in kalker_linear(1.0, 0.28)]
    [4.2262, 3.7049, 1.4881]
    """
    if not 0 <= nu <= 0.5:
        raise InputError("nu", f"must be in [0, 0.5], got {nu!r}")
    r = float(a_over_b)
    g = r if r <= 1 else 1 / r
    if not 0.1 - 1e-12 <= g <= 1:
        return None
    case = KALKER_E3["a<b" if r <= 1 else "a>b"]
    x = min(max(10 * g - 1, 0.0), 9.0)
    lo = min(int(x), 8)
    f = x - lo
    rows = np.array(case[lo]) * (1 - f) + np.array(case[lo + 1]) * f        # (coefficient, ν)
    w = ((nu - 0.25) * (nu - 0.5) / 0.125, -nu * (nu - 0.5) / 0.0625, nu * (nu - 0.25) / 0.125)
    return tuple(float(1.0 / sum(wi / c[i] for i, wi in enumerate(w))) for c in rows)
