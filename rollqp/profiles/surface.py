r"""Body geometry: principal radii, the combined curvatures, the undeformed distance
(docs/theory3d.md §2).

Each body has principal radii ``R_x`` (in the x–z plane, the rolling direction) and ``R_y``
(y–z plane); ``inf`` is a straight generator (a flat body has both infinite), a negative radius a
concave surface (a groove, a conformal rail head: ``radius_y = -10.5`` for a groove of 10.5). Near
the first point of contact both surfaces are paraboloids and the undeformed distance (gap before
deformation, at zero approach) is

.. math::
    h(x, y) = A x^2 + B y^2,\qquad A = \tfrac12\Big(\frac1{R_x^A} + \frac1{R_x^B}\Big),\quad
    B = \tfrac12\Big(\frac1{R_y^A} + \frac1{R_y^B}\Big)                          \qquad (3D.3)

(CONTACT's ``A1, B1``). Only these summed curvatures enter the contact problem: a body may be
concave in a direction as long as the sum ``A`` (or ``B``) stays positive — the convex body more
curved than the concave one holding it. :class:`QuadraticProfile` is that ``h``; any callable ``h(x, y)`` of
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
        raise InputError(name, f"must be a nonzero number or inf, got {v!r}") from None
    if math.isnan(r) or r == 0:
        raise InputError(name, f"must be a nonzero number (> 0 convex, < 0 concave, inf for a straight generator), "
                               f"got {v!r}")
    return r


@dataclass(frozen=True)
class Body:
    """Principal radii of one body at the contact point: ``radius`` (x–z plane), ``radius_y``
    (y–z plane), each ``> 0`` (convex), ``< 0`` (concave) or ``inf`` (straight). ``name``
    (``"A"``/``"B"``) is used in error messages."""

    radius: float
    radius_y: float
    name: str = "A"

    def __post_init__(self):
        object.__setattr__(self, "radius", _radius(f"bodies.{self.name}.radius", self.radius))
        object.__setattr__(self, "radius_y", _radius(f"bodies.{self.name}.radius_y", self.radius_y))


def curvatures(A: Body, B: Body) -> tuple[float, float]:
    """The combined curvatures ``(A, B)`` of eq. 3D.3; an :class:`InputError` naming both radii if
    either sum is not positive (both bodies straight in one direction, or a concave body more curved
    than the convex one: no concentrated contact).

    Examples
    --------
    >>> curvatures(Body(30.0, 30.0, "A"), Body(float("inf"), float("inf"), "B"))
    (0.016666666666666666, 0.016666666666666666)
    >>> A, B = curvatures(Body(10.0, 10.0, "A"), Body(float("inf"), -10.5, "B"))     # a ball in a groove
    >>> round(A, 6), round(B, 6)
    (0.05, 0.002381)
    >>> curvatures(Body(10.0, 10.0, "A"), Body(float("inf"), -9.5, "B"))
    Traceback (most recent call last):
    ...
    rollqp.errors.InputError: bodies.B.radius_y: bodies.A.radius_y = 10 and bodies.B.radius_y = -9.5 give the summed curvature 1/R_A + 1/R_B = -0.005263 in the y–z plane: it must be > 0 for a concentrated contact (a concave body must be flatter than the convex one it holds)
    """
    out = []
    for attr, plane in (("radius", "x–z"), ("radius_y", "y–z")):
        ra, rb = getattr(A, attr), getattr(B, attr)
        k = 1 / ra + 1 / rb
        if not k > 0:
            key = f"bodies.{B.name}.{attr}" if rb < 0 else f"bodies.{A.name}.{attr}"
            if math.isinf(ra) and math.isinf(rb):
                why = "both bodies are straight there (inf)"
            else:
                why = "a concave body must be flatter than the convex one it holds"
            raise InputError(key, f"bodies.{A.name}.{attr} = {ra:g} and bodies.{B.name}.{attr} = {rb:g} give the summed "
                                  f"curvature 1/R_A + 1/R_B = {k:.4g} in the {plane} plane: it must be > 0 for a "
                                  f"concentrated contact ({why})")
        out.append(0.5 * k)
    return out[0], out[1]


@dataclass(frozen=True)
class QuadraticProfile:
    """``h(x, y) = A x² + B y²`` (eq. 3D.3), the Hertzian undeformed distance."""

    A: float
    B: float

    def __call__(self, x, y) -> np.ndarray:
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        return self.A * x * x + self.B * y * y
