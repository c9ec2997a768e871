r"""The creepage search: a tangential step with ``Q`` prescribed that GNMls cannot solve, solved for ``ξ``.

Used by the Newton method when the iteration on the load row fails (:func:`tangential_by_creepage`):
a root search on the creepage, each evaluation a ξ-prescribed solve by :mod:`.uncoupled` (or
:mod:`.slip` for a slip-dependent bound).
"""
from __future__ import annotations

import numpy as np

from ...errors import SolverError
from .common import Stalled
from .slip import solve_slip
from .uncoupled import solve_tangential, solve_uncoupled

__all__ = ["tangential_by_creepage"]


def tangential_by_creepage(meth, pb, warm, t0, err, slip_solve=None):
    r"""Fallback when GNMls fails on a tangential step with ``Q`` prescribed: solve for ``ξ``.

    The failure this repairs: with a single stick node (free rolling at μ ≲ 3e-4) the load
    row's only ``ξ̂`` entry is that node's, and the "nearest node onto its kink" repair (package
    docstring) makes Newton cycle between active sets. With ``ξ`` prescribed instead the load
    row is gone and GNMls converges (CONTACT's workaround: solve with ξ given first). The
    load is then met by a root search on ``F(ξ̂) = f̂ᵀt̂(ξ̂) − Q̂``, continuous, piecewise
    linear and monotone (friction opposes slip), each evaluation a ξ-prescribed solve warm
    started from the previous one: bracketing by doubling steps from the warm ``ξ``, then
    Brent's method. The root's traction then warm-starts the Q-prescribed GNMls (one or two
    iterations on the right active set); if that fails too, the ξ-prescribed solution at the
    root is kept when rollqp's residual of the original problem is within tolerance.
    Counted in ``info["creepage_search"]`` (evaluations). Otherwise ``err`` is raised.
    ``slip_solve(meth, problem, warm, t0)``: the ξ-prescribed solve of a slip-dependent bound (default
    :func:`~.slip.solve_slip`; the safeguarded step passes itself, :mod:`.slip_step`).
    """
    search = _CreepageSearch(meth, pb, warm, t0, int(err.iterations or 0), slip_solve)
    try:
        at_root = search.root()
    except (SolverError, ValueError, RuntimeError):  # a ξ-prescribed solve failed, or Brent did not converge
        raise err from None
    if at_root is None:
        raise err
    try:
        if pb.law is not None:  # a slip-dependent bound (rollqp.methods.newton.slip)
            sol = solve_slip(meth, pb, at_root, t0)
        else:
            sol = solve_tangential(meth, pb, at_root, t0)
    except (SolverError, Stalled):
        sol = pb.solution(at_root.t, at_root.xi)
        if not sol.residual <= meth.tolerance:
            raise err from None
        sol = meth.finish(sol, at_root.iterations, dict(at_root.extras, backtracks=at_root.backtracks), t0)
    sol.info["creepage_search"] = search.evals + 1
    sol.iterations += search.its + at_root.iterations  # all Newton iterations of the step
    return sol


class _CreepageSearch:
    """The root search of :func:`tangential_by_creepage` on ``F(ξ̂) = f̂ᵀt̂(ξ̂) − Q̂``."""

    def __init__(self, meth, pb, warm, t0, its, slip_solve=None):
        self.meth, self.pb, self.t0 = meth, pb, t0
        #: the ξ-prescribed slip-dependent solve (the safeguarded step, :mod:`.slip_step`; default plain Newton)
        self.slip_solve = slip_solve or (lambda meth, sub, warm, t0: meth.checked(solve_slip(meth, sub, warm, t0)))
        self.sol, self.evals, self.its = warm, 0, its
        sc = pb.scales
        self.Qhat = pb.Q / sc.force
        self.fhat = pb.f / sc.length

    def solve_at(self, xh):
        sc = self.pb.scales
        sub = self.pb.replace(Q=None, xi=xh * sc.slip)
        if sub.law is not None:  # a slip-dependent bound: safeguarded like the step itself (rollqp.methods.newton.slip)
            return self.slip_solve(self.meth, sub, self.sol, self.t0)
        return solve_uncoupled(self.meth, sub, self.sol, self.t0)

    def F(self, xh):
        self.evals += 1
        sol = self.solve_at(xh)
        self.sol = sol
        self.its += sol.iterations
        return float(self.fhat @ (sol.t / self.pb.scales.stress)) - self.Qhat

    def root(self):
        """The ξ-prescribed solution at the root of ``F``, or ``None`` if no sign change is found."""
        from scipy.optimize import brentq
        pb, sc, warm = self.pb, self.pb.scales, self.sol
        x0 = warm.xi / sc.slip if warm is not None and warm.xi is not None else 0.0
        f0 = self.F(x0)
        h = 2.0 * (pb.mu if np.ndim(pb.mu) == 0 else float(np.max(pb.mu))) * max(float(np.max(pb.p)) / sc.stress, 1e-12) + 1e-6
        lo = hi = x0
        flo = fhi = f0
        for _ in range(80):  # widen both ways until F changes sign
            if flo * fhi <= 0.0:
                break
            lo, hi = lo - h, hi + h
            flo, fhi = self.F(lo), self.F(hi)
            h *= 2.0
        else:
            return None
        root = brentq(self.F, lo, hi, xtol=1e-15, rtol=1e-15, maxiter=200) if flo * fhi < 0 else (lo if flo == 0 else hi)
        return self.solve_at(root)
