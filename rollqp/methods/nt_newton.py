"""``nt-newton``: the normal–tangential alternation (:mod:`.alternation`) with generalized Newton halves (:mod:`.newton`)."""
from __future__ import annotations

import dataclasses

from .alternation import Alternation
from .base import FRICTION_KINDS, check_options
from .continuation import SlipContinuation
from .newton import NewtonMethod

__all__ = ["AlternationNewton"]


class AlternationNewton(Alternation):
    """``nt-newton``: the N–T alternation with Newton (GNMls) halves (paper §6.3)."""

    name = "nt-newton"
    #: Newton's, with coupled steps of any friction law (by the alternation) and one sweep a step on request
    capabilities = dataclasses.replace(NewtonMethod.capabilities, coupled_friction=FRICTION_KINDS, single_sweeps=True)

    def __init__(self, tolerance: float = 1e-10, max_iterations: int = 200, max_outer: int = 200, **newton):
        # the halves composed as the registry composes a method (rollqp.methods.compose): a slip-dependent
        # half's solution selected by the path from the frozen bound (a no-op for every other step)
        super().__init__(SlipContinuation(NewtonMethod(tolerance=tolerance, max_iterations=max_iterations, **newton)),
                         max_outer=max_outer)
        self.name = "nt-newton"

    @classmethod
    def from_settings(cls, settings, **options) -> "AlternationNewton":
        """From a scene's solver settings: ``max_iterations`` bounds both the Newton iterations of each
        half and the outer iterations; ``augmentation`` is the halves' ``r``."""
        check_options(cls.name, options, ("rho", "sigma"))
        return cls(tolerance=settings.tolerance, max_iterations=settings.max_iterations,
                   max_outer=settings.max_iterations, r=settings.augmentation, **options)
