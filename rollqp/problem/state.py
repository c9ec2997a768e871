"""The state between two steps of the transient: :class:`State` (what a step starts from and leaves behind)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .solution import StepSolution

__all__ = ["State"]


@dataclass(frozen=True)
class State:
    """An accepted state: tractions, the relative displacement ``w``, and the solutions behind it.

    ``nsol`` is the normal half's solution (``normal`` its problem) and ``tsol`` the tangential
    one; for a coupled step both are the one coupled :class:`~rollqp.problem.StepSolution`.
    They are the warm starts of the next step.
    """

    p: np.ndarray
    t: np.ndarray
    w: np.ndarray
    nsol: StepSolution | None = None
    tsol: StepSolution | None = None
    normal: object = None
