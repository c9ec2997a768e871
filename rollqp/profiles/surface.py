r"""Body geometry: principal radii, the combined curvatures, the undeformed distance
(docs/theory3d.md §2).

Each body has principal radii ``R_x`` (in the x–z plane, the rolling direction) and ``R_y``
(y–z plane); ``inf`` is a straight generator (a flat body has both infinite). Near the first
point of contact both surfaces are paraboloids and the undeformed distance (gap before
deformation, at zero approach) is

.. math::
    h(x, y) = A x^2 + B y^2,\qquad A = \tfrac12\Big(\frac1{R_x^A} + \frac1{R_x^B}\Big),\quad
    B = \tfrac12\Big(\frac1{R_y^A} + \frac1{R_y^B}\Big)                          \qquad (3D.1)

(CONTACT's ``A1, B1``). :class:`QuadraticProfile` is that ``h``; any callable ``h(x, y)`` of
the element centres can take its place in a step problem (the seam for non-Hertzian profiles).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError

__all__ = ["Body", "curvatures", "QuadraticProfile"]


def _radius(name, v) -> float:
    try:
        r = float(v)
    except (TypeError, ValueError):
        raise InputError(name, f"must be a number > 0 or inf, got {v!r}") from None
    if math.isnan(r) or r <= 0:
        raise InputError(name, f"must be > 0 (or inf for a straight generator), got {v!r}")
    return r


@dataclass(frozen=True)
class Body:
    """Principal radii of one body at the contact point: ``radius`` (x–z plane), ``radius_y``
    (y–z plane), both ``> 0`` or ``inf``. ``name`` (``"A"``/``"B"``) is used in error messages."""

    radius: float
    radius_y: float
    name: str = "A"

    def __post_init__(self):
        object.__setattr__(self, "radius", _radius(f"bodies.{self.name}.radius", self.radius))
        object.__setattr__(self, "radius_y", _radius(f"bodies.{self.name}.radius_y", self.radius_y))


def curvatures(A: Body, B: Body) -> tuple[float, float]:
    """The combined curvatures ``(A, B)`` of eq. 3D.1; an :class:`InputError` if either is zero
    (two bodies flat in one direction have no concentrated contact).

    Examples
    --------
    >>> curvatures(Body(30.0, 30.0, "A"), Body(float("inf"), float("inf"), "B"))
    (0.016666666666666666, 0.016666666666666666)
    """
    a = 0.5 * (1 / A.radius + 1 / B.radius)
    b = 0.5 * (1 / A.radius_y + 1 / B.radius_y)
    if a <= 0:
        raise InputError("bodies.A.radius", "both bodies are straight in x (radius = inf): no concentrated contact")
    if b <= 0:
        raise InputError("bodies.A.radius_y", "both bodies are straight in y (radius_y = inf): no concentrated contact")
    return a, b


@dataclass(frozen=True)
class QuadraticProfile:
    """``h(x, y) = A x² + B y²`` (eq. 3D.1), the Hertzian undeformed distance."""

    A: float
    B: float

    def __call__(self, x, y) -> np.ndarray:
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        return self.A * x * x + self.B * y * y
