"""What the Newton iterations share: the Armijo floor and the errors of an iteration that stops short."""
from __future__ import annotations

from ...errors import SolverError

__all__ = ["ALPHA_MIN", "Stalled", "not_converged"]

#: Smallest Armijo step tried before the full step is taken anyway (see the package docstring).
ALPHA_MIN = 1e-10


class Stalled(Exception):
    """The Armijo search failed from a warm start (the step is then restarted cold)."""


def not_converged(meth, kind: str, merits, it: int, nrm: float, stop: float) -> SolverError:
    """The error of an iteration that reached ``max_iterations``: the merit, the iterations, ``‖Φ‖∞``."""
    theta = merits[-1]
    return SolverError(f"the {kind} Newton iteration did not converge: merit θ = {theta:.3e} after {it} iterations "
                       f"(‖Φ‖∞ = {nrm:.3e} > {stop:.1e})", method=meth.name, status=f"merit {theta:.3e}",
                       iterations=it, residual=nrm)
