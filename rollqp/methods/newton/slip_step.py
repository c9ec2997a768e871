"""A slip-dependent tangential step, safeguarded: Newton on the slip path (:mod:`.slip`), else the fixed point
on the bound around Newton's constant-bound solves polished by Newton, else a cold start, else the creepage
search (:mod:`.creepage`); the orchestration above both, so that neither imports the other."""
from __future__ import annotations

import time

from ...errors import SolverError
from ..fixedpoint import BoundFixedPoint
from .creepage import tangential_by_creepage
from .slip import POLISH_ITERATIONS, solve_slip

__all__ = ["solve_slip_step"]


def solve_slip_step(meth, pb, warm, t0):
    """A slip-dependent tangential step, safeguarded (module docstring): Newton from ``warm``; else the fixed
    point on the bound around Newton's constant-bound solves, polished by Newton from each iterate that
    improved; else Newton from zero shear; with ``Q`` prescribed, else the creepage search. The first
    error is raised if all fail, with the best residual reached."""
    try:
        return meth.checked(solve_slip(meth, pb, warm, t0))
    except SolverError as err:
        first = err
    try:
        return _by_fixed_point(meth, pb, warm, t0)
    except SolverError as err:
        second = err
    if warm is not None:
        try:
            sol = meth.checked(solve_slip(meth, pb, None, t0))  # the warm start's branch lost
            sol.info["restarts"] = 1
            return sol
        except SolverError:
            pass
    if pb.Q is not None:
        try:
            return meth.checked(tangential_by_creepage(meth, pb, warm, t0, first))
        except SolverError:
            pass
    best = min(r for r in (first.residual, second.residual) if r is not None) if (
        first.residual is not None or second.residual is not None) else None
    inner = second.message.split("; try")[0]  # its advice names newton itself
    raise SolverError(f"{first.message}; the fixed point on the bound failed too ({inner}); the step may "
                      "have no quasi-static solution (a breakaway: docs/friction.md): prescribe the creepage, ramp "
                      "the force or roll slower", method=meth.name, status=first.status, iterations=first.iterations,
                      residual=best)


def _by_fixed_point(meth, pb, warm, t0):
    """The fixed point on the bound with Newton's constant-bound solves, polished by :func:`solve_slip`."""

    def polish(sol):
        try:
            return meth.checked(solve_slip(meth, pb, sol, t0, max_iterations=POLISH_ITERATIONS))
        except SolverError:
            return None

    fixed = BoundFixedPoint(_ConstantBound(meth), polish=polish)
    sol = fixed.solve(pb, warm)
    sol.info["fixed_point"] = sol.info.get("bound_iterations", 0)
    sol.time = time.perf_counter() - t0
    return meth.checked(sol)


class _ConstantBound:
    """Newton on the constant-bound steps of the fixed point (never its own slip path: ``law`` is None there)."""

    def __init__(self, meth):
        self.meth = meth
        self.name, self.capabilities, self.tolerance = meth.name, meth.capabilities, meth.tolerance

    def solve(self, problem, warm=None):
        return self.meth.solve(problem, warm=warm)
