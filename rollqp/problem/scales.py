"""The units of the nondimensional form of a step problem (docs/formulation.md §5, docs/theory3d.md §4):
:class:`Scales`, for a strip (two dimensions) and a grid (three)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..closedforms import hertz_half_width
from ..closedforms import hertz_peak_pressure

__all__ = ["Scales"]


@dataclass(frozen=True)
class Scales:
    """Units of the nondimensional form: ``length`` (a_H in 2D, ``c = √(ab)`` in 3D), ``stress`` (p0),
    ``modulus`` (E*), and the ``dimension`` of the problem (2: a strip, 3: a grid).

    The defaults (all 1) leave an array problem in the user's own units; pass the Hertz
    scales (:meth:`hertz`, :meth:`ellipse`) for residuals that mean the same in every unit system.

    Attributes
    ----------
    displacement : float
        ``u0 = length · p0 / E*``: gaps, displacements, approach.
    slip : float
        ``p0 / E*``: slips and creepages (spin: ``p0/(E* c)``).
    force : float
        ``p0 · length^(dimension − 1)``: loads per unit axial length (2D), forces (3D).
    """

    length: float = 1.0
    stress: float = 1.0
    modulus: float = 1.0
    dimension: int = 2

    def __post_init__(self):
        for name in ("length", "stress", "modulus"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"scales.{name}", f"must be a finite number > 0, got {v!r}")
        if self.dimension not in (2, 3) or isinstance(self.dimension, bool):
            raise InputError("scales.dimension", f"must be 2 or 3, got {self.dimension!r}")
        # the derived units, computed once (read for every step and residual): not fields, so they take no
        # part in equality, hashing or the repr
        object.__setattr__(self, "displacement", self.length * self.stress / self.modulus)
        object.__setattr__(self, "slip", self.stress / self.modulus)
        object.__setattr__(self, "force", self.stress * self.length ** (self.dimension - 1))

    @classmethod
    def hertz(cls, P: float, R: float, Estar: float) -> "Scales":
        """Hertz half-width ``a`` and peak pressure ``p0`` for load ``P`` (docs/formulation.md §12)."""
        a = hertz_half_width(P, R, Estar)
        return cls(length=a, stress=hertz_peak_pressure(P, a), modulus=float(Estar))

    @classmethod
    def ellipse(cls, ellipse) -> "Scales":
        """A grid's scales from a :class:`~rollqp.closedforms.hertz_ellipse.HertzEllipse`: ``c = √(ab)``, ``p0``, ``E*``."""
        return cls(length=ellipse.c, stress=ellipse.p0, modulus=ellipse.Estar, dimension=3)
