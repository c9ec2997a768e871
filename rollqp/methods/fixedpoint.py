r"""The fixed point on a slip-dependent friction bound: each iteration one fixed-bound step (a convex QP).

A step whose bound depends on the slip, ``|t_i| <= μ_i(s_i) p_i``, is a quasi-variational
inequality (docs/theory.md, "Slip-dependent friction"): no QP poses it. Freezing the coefficient
at a slip ``s^{(k)}`` gives an ordinary tangential step — with the per-node coefficient
``μ^{(k)} = μ(s^{(k)})`` a convex QP that any backend solves — whose solution gives the next slip::

    μ^{(k)} = (1 − ω) μ^{(k−1)} + ω μ(s^{(k)}),    (t^{(k+1)}, s^{(k+1)}) = solve step(μ^{(k)})

(``ω = relaxation``, default 1), started from the warm step's slip (else zero slip: the static
bound). Its fixed points are exactly the solutions of the slip-dependent step.

**Stopping test.** rollqp's residual of the *slip-dependent* problem at the iterate
(:meth:`TangentialStep.residuals <rollqp.problem.TangentialStep.residuals>` with the bound at the
iterate's own slip) below the inner method's tolerance, or below its ``residual_limit`` (what its
QP solutions are trusted to) once it has stopped falling (less than a factor :data:`STALL_RATE` over
the last iteration): after a fixed-bound solve only the bound's change ``|μ(s^{(k+1)}) − μ^{(k)}| p``
at slipping nodes remains in it. A map that still contracts, however slowly, is iterated on: a
falling law's map contracts slowly on a ramped transient, and stopping it at the QPs' limit left an
error in the traction that the transient then carried on (docs/friction.md).

**Polishing.** ``polish(solution)`` (optional) is tried on every iterate whose residual fell: a
method that converges fast from near a solution (Newton on the slip-dependent step) returns the
solution, else ``None`` and the fixed point goes on. ``stall_window`` (default ``STALL_WINDOW``) sets
the window of the cycling test: a caller with other ways to go on (Newton) gives up sooner.

**Failure.** The map contracts only where ``|∂b/∂s|`` is small against the elastic stiffness
(the falling branch near saturation is where it does not; docs/stability.md): a
:class:`~rollqp.errors.SolverError` naming the method and the residual when the residual is not finite or
grows ``DIVERGE_FACTOR`` times above the first (diverges), when its best value over the last
``STALL_WINDOW`` iterations is not ``STALL_FACTOR`` below the best before them (cycles), or after
``max_iterations``.
"""
from __future__ import annotations

import dataclasses
import time

import numpy as np

from ..errors import InputError, SolverError

__all__ = ["BoundFixedPoint"]

STALL_WINDOW = 20
STALL_FACTOR = 0.9
#: A residual that falls by less than this factor in one iteration has reached the inner solver's floor.
STALL_RATE = 0.9
DIVERGE_FACTOR = 1e6


class BoundFixedPoint:
    """The fixed point on the bound (module docstring) around ``inner``, a method that solves fixed-bound steps.

    Steps without a slip-dependent ``law`` go to ``inner`` unchanged (bitwise its own results).
    ``info`` of a solution: ``bound_iterations``, ``bound_history`` (residual per iteration).
    """

    def __init__(self, inner, max_iterations: int = 200, relaxation: float = 1.0, polish=None,
                 stall_window: int = STALL_WINDOW):
        if int(max_iterations) != max_iterations or max_iterations < 1:
            raise InputError("max_iterations", f"must be an integer >= 1, got {max_iterations!r}")
        if not (0.0 < relaxation <= 1.0):
            raise InputError("relaxation", f"must be in (0, 1], got {relaxation!r}")
        self.inner = inner
        self.max_iterations = int(max_iterations)
        self.relaxation = float(relaxation)
        self.polish = polish
        self.stall_window = int(stall_window)
        self.name = inner.name
        #: the inner method's, with slip-dependent bounds (posed by this fixed point), without the switches of
        #: a march to the steady state (the prediction, the accelerated start: fixed-bound QPs only)
        self.capabilities = dataclasses.replace(inner.capabilities, slip_dependent=True, predicting=False,
                                                single_sweeps=False, accelerated_start=False, quasi_newton=False)
        self.tolerance = inner.tolerance
        self.limit = float(inner.capabilities.residual_limit or inner.tolerance)

    def carrier(self):
        """The inner method's (called only where the capabilities declare ``carries_state``)."""
        return self.inner.carrier()

    def setup(self, operators) -> None:
        self.inner.setup(operators)

    def solve(self, problem, warm=None):
        if problem.kind != "tangential" or getattr(problem, "law", None) is None:   # a grid's normal step has none
            return self.inner.solve(problem, warm=warm)
        t0 = time.perf_counter()
        law, shape = problem.law, getattr(problem, "slip_shape", (problem.n,))   # (2, n) on a grid
        s = warm.s if warm is not None and warm.s is not None and np.shape(warm.s) == shape else np.zeros(shape)
        mu = law.mu(s)
        history, its, sol = [], 0, warm
        for k in range(1, self.max_iterations + 1):
            sol = self.inner.solve(self._frozen(problem, mu, history), warm=sol)
            its += sol.iterations
            true = problem.evaluate(sol)
            history.append(true.residual)
            if true.residual <= self.tolerance or (true.residual <= self.limit and len(history) > 1
                                                   and true.residual >= STALL_RATE * history[-2]):
                break  # converged, or stalled at the inner QPs' own accuracy (their residual_limit)
            if self.polish is not None and (len(history) == 1 or true.residual < history[-2]):
                done = self.polish(true)
                if done is not None:
                    done.info.update(bound_iterations=len(history), bound_history=history, polished=True)
                    return done
            self._check(history, k)
            mu = (1.0 - self.relaxation) * mu + self.relaxation * law.mu(sol.s)
        else:
            raise SolverError(f"the fixed point on the friction bound did not converge: residual "
                              f"{history[-1]:.3e} > {self.limit:.1e} after {self.max_iterations} QPs",
                              method=self.name, status="bound iteration limit", residual=history[-1], iterations=its)
        true.method, true.status, true.iterations = self.name, "solved", its
        true.extras.update(sol.extras)  # the last inner solve's statistics and data
        true.backtracks, true.At = sol.backtracks, sol.At
        true.extras.update(bound_iterations=len(history), bound_history=history)
        true.time = time.perf_counter() - t0
        return true

    def _frozen(self, problem, mu, history):
        """The step with the bound frozen at ``mu``; a frozen bound whose sliding limit ``μ fᵀp`` is below ``|Q|``
        poses no step with stick (an InputError of the step problem): the iteration cannot go on (SolverError)."""
        try:
            return problem.replace(mu=mu, law=None)
        except InputError as err:
            if err.key != "Q":
                raise
            last = history[-1] if history else float("nan")
            raise SolverError(f"the fixed point on the friction bound reached a bound below the load ({err}); "
                              "try method newton", method=self.name, status="bound below the load",
                              residual=last, iterations=len(history)) from None

    def _check(self, h, k):
        last = h[-1]
        if not np.isfinite(last) or last > DIVERGE_FACTOR * h[0]:
            raise SolverError(f"the fixed point on the friction bound diverges: residual {last:.3e} after {k} QPs "
                              f"(first {h[0]:.3e}); try method newton", method=self.name, status="diverged",
                              residual=float(last), iterations=k)
        W = self.stall_window
        if len(h) >= 2 * W and min(h[-W:]) > STALL_FACTOR * min(h[:-W]):
            raise SolverError(f"the fixed point on the friction bound cycles: best residual {min(h[-W:]):.3e} over "
                              f"the last {W} QPs, {min(h[:-W]):.3e} before them; try method newton or a smaller "
                              f"relaxation", method=self.name, status="stalled", residual=float(last), iterations=k)
