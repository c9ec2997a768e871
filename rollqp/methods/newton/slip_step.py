"""A slip-dependent tangential step, safeguarded: Newton on the slip path (:mod:`.slip`), else the fixed point
on the bound around Newton's constant-bound solves polished by Newton, else a cold start, else the creepage
search (:mod:`.creepage`); the orchestration above both, so that neither imports the other. A solution with
modes the falling law makes unstable (:func:`.slip.unstable_modes`) is kept only if no attempt finds another
(:mod:`.slip`, "Which solution")."""
from __future__ import annotations

import time

from ...errors import SolverError
from ..fixedpoint import BoundFixedPoint
from .creepage import tangential_by_creepage
from .slip import FIXED_POINT_WINDOW, POLISH_ITERATIONS, solve_slip, unstable_modes

__all__ = ["solve_slip_step"]


def solve_slip_step(meth, pb, warm, t0):
    """A slip-dependent tangential step, safeguarded (module docstring): Newton from ``warm``; else the fixed
    point on the bound around Newton's constant-bound solves, polished by Newton from each iterate that
    improved; else Newton from zero shear (run to the iteration limit); with ``Q`` prescribed, else the
    creepage search (its ξ-prescribed solves safeguarded alike). A solution with unstable modes is kept only
    if no attempt finds a stable one (``info["unstable"]`` says how many). The first error is raised if all
    fail, with the best residual reached. A step whose bound is a point of the path from the frozen bound
    (:attr:`~rollqp.friction.bound.SlipBound.on_path`, :mod:`rollqp.methods.continuation`) is solved by the
    Newton iteration from ``warm`` alone: the path has chosen the solution."""
    if pb.law.on_path:  # a point of the path from the frozen bound: the solution near the warm start, no other
        return meth.checked(solve_slip(meth, pb, warm, t0))
    found = []  # unstable solutions, in the order found

    def stable(sol):
        sol.info["unstable"] = unstable_modes(meth, pb, sol)
        if sol.info["unstable"]:
            found.append(sol)
            return None
        return sol

    attempts = [lambda: meth.checked(solve_slip(meth, pb, warm, t0)),
                lambda: _by_fixed_point(meth, pb, warm, t0, stable)]
    if warm is not None:
        attempts.append(lambda: _restarted(meth.checked(solve_slip(meth, pb, None, t0, stall=False))))
    if pb.Q is not None:
        attempts.append(lambda: meth.checked(_by_creepage(meth, pb, warm, t0)))
    errors = []
    for attempt in attempts:
        try:
            sol = stable(attempt())
        except SolverError as err:
            errors.append(err)
            continue
        if sol is not None:
            return sol
    if found:
        return found[0]
    first, second = errors[0], errors[1]
    best = min((e.residual for e in errors if e.residual is not None), default=None)
    inner = second.message.split("; try")[0]  # its advice names newton itself
    raise SolverError(f"{first.message}; the fixed point on the bound failed too ({inner}); the step may "
                      "have no quasi-static solution (a breakaway: docs/friction.md): prescribe the creepage, ramp "
                      "the force or roll slower", method=meth.name, status=first.status, iterations=first.iterations,
                      residual=best)


def _restarted(sol):
    sol.info["restarts"] = 1  # the warm start's branch lost
    return sol


def _by_creepage(meth, pb, warm, t0):
    err = SolverError("the slip-dependent tangential step", method=meth.name)
    return tangential_by_creepage(meth, pb, warm, t0, err, slip_solve=solve_slip_step)


def _by_fixed_point(meth, pb, warm, t0, stable=lambda sol: sol):
    """The fixed point on the bound with Newton's constant-bound solves, polished by :func:`solve_slip` (a polished
    solution is taken if ``stable`` keeps it)."""

    def polish(sol):
        try:
            return stable(meth.checked(solve_slip(meth, pb, sol, t0, max_iterations=POLISH_ITERATIONS)))
        except SolverError:
            return None

    fixed = BoundFixedPoint(_ConstantBound(meth), polish=polish, stall_window=FIXED_POINT_WINDOW)
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
