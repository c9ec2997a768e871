"""The units of the nondimensional form of a step problem (docs/formulation.md §5): :class:`Scales`."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError

__all__ = ["Scales"]


@dataclass(frozen=True)
class Scales:
    """Units of the nondimensional form: ``length`` (a_H), ``stress`` (p0), ``modulus`` (E*).

    The defaults (all 1) leave an array problem in the user's own units; pass the Hertz
    scales (:meth:`hertz`) for residuals that mean the same in every unit system.
    """

    length: float = 1.0
    stress: float = 1.0
    modulus: float = 1.0

    def __post_init__(self):
        for name in ("length", "stress", "modulus"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"scales.{name}", f"must be a finite number > 0, got {v!r}")

    @classmethod
    def hertz(cls, P: float, R: float, Estar: float) -> "Scales":
        """Hertz half-width ``a`` and peak pressure ``p0`` for load ``P`` (docs/formulation.md §12)."""
        from ..closedforms import hertz_half_width, hertz_peak_pressure
        a = hertz_half_width(P, R, Estar)
        return cls(length=a, stress=hertz_peak_pressure(P, a), modulus=float(Estar))

    @property
    def displacement(self) -> float:
        """``u0 = a_H p0 / E*``: gaps, displacements, approach."""
        return self.length * self.stress / self.modulus

    @property
    def slip(self) -> float:
        """``p0 / E*``: slips and creepages."""
        return self.stress / self.modulus

    @property
    def force(self) -> float:
        """``a_H p0``: loads per unit axial length."""
        return self.length * self.stress
