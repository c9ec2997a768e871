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

    Attributes
    ----------
    displacement : float
        ``u0 = a_H p0 / E*``: gaps, displacements, approach.
    slip : float
        ``p0 / E*``: slips and creepages.
    force : float
        ``a_H p0``: loads per unit axial length.
    """

    length: float = 1.0
    stress: float = 1.0
    modulus: float = 1.0

    def __post_init__(self):
        for name in ("length", "stress", "modulus"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"scales.{name}", f"must be a finite number > 0, got {v!r}")
        # the derived units, computed once (read for every step and residual): not fields, so they take no
        # part in equality, hashing or the repr
        object.__setattr__(self, "displacement", self.length * self.stress / self.modulus)
        object.__setattr__(self, "slip", self.stress / self.modulus)
        object.__setattr__(self, "force", self.length * self.stress)

    @classmethod
    def hertz(cls, P: float, R: float, Estar: float) -> "Scales":
        """Hertz half-width ``a`` and peak pressure ``p0`` for load ``P`` (docs/formulation.md §12)."""
        from ..closedforms import hertz_half_width, hertz_peak_pressure
        a = hertz_half_width(P, R, Estar)
        return cls(length=a, stress=hertz_peak_pressure(P, a), modulus=float(Estar))
