"""Progress of long solves inside one step: who listens to the iterations of an iterative method.

A step of a large grid can take minutes (a 300 × 300 steady rolling step: about a dozen Newton
iterations on FFT products). The method tells :func:`iteration` after each of its iterations; the
command line listens (:func:`listening`) and prints a line now and then, with a remaining-time estimate
once a solve has run for a minute. Without a listener :func:`iteration` costs one list lookup.

Examples
--------
>>> seen = []
>>> with listening(lambda *a: seen.append(a)):
...     iteration("steady", 1, 1e-3, 0.5, 1e-10)
>>> seen
[('steady', 1, 0.001, 0.5, 1e-10)]
>>> iteration("steady", 2, 1e-5, 1.0, 1e-10)     # nobody listens: nothing happens
"""
from __future__ import annotations

import math
from contextlib import contextmanager

__all__ = ["listening", "iteration", "remaining_iterations"]

_LISTENERS: list = []


@contextmanager
def listening(fn):
    """``with listening(fn):`` ``fn(what, iteration, residual, seconds, target)`` is told of every iteration
    of the solves made in the block (``seconds``: since the solve started; ``target``: its stopping residual)."""
    _LISTENERS.append(fn)
    try:
        yield fn
    finally:
        _LISTENERS.remove(fn)


def iteration(what: str, it: int, residual: float, seconds: float, target: float) -> None:
    """Tell the listeners that iteration ``it`` of a ``what`` solve ended at ``residual`` after ``seconds``."""
    for fn in _LISTENERS:
        fn(what, it, residual, seconds, target)


def remaining_iterations(residuals, target: float) -> int | None:
    """Iterations still needed to bring the last of ``residuals`` to ``target``, extrapolating the last
    decrease (a generalized Newton method converges at least that fast near the solution: a pessimistic
    estimate); None while the residual has not decreased.

    >>> remaining_iterations([1e-2, 1e-4], 1e-10)
    3
    >>> remaining_iterations([1e-2, 1e-2], 1e-10) is None
    True
    """
    if len(residuals) < 2 or not residuals[-1] < residuals[-2] or residuals[-1] <= 0:
        return None if len(residuals) < 2 or not residuals[-1] < residuals[-2] else 0
    if residuals[-1] <= target:
        return 0
    rate = math.log(residuals[-1] / residuals[-2])
    return max(1, math.ceil(math.log(target / residuals[-1]) / rate))
