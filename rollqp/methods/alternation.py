r"""Normal–tangential alternation (paper §6.3, the PANA process; docs/formulation.md §10).

The coupled step (:class:`~rollqp.problem.CoupledStep`) is not a QP: the friction bound
``μ p`` depends on the unknown pressure, and with ``A_nt ≠ 0`` the gap depends on the
unknown shear. The alternation solves it as a block Gauss–Seidel iteration over its two
halves, each an ordinary step problem that any method solves (Newton, or a convex QP):

.. math::
    p^{(m)} = \mathrm{solve}\ \text{normal}(t^{(m-1)}):\quad
        g = h - \delta e + A_{nn} p + A_{nt} t^{(m-1)},

    t^{(m)} = \mathrm{solve}\ \text{tangential}(p^{(m)}):\quad
        |t| \le \mu p^{(m)},\ s = \xi e + (c + A_{tn} p^{(m)} + A_{tt} t)/\Delta q,

until rollqp's residual of the *coupled* problem at ``(p^{(m)}, t^{(m)})`` is below the
limit. After the tangential half only the normal rows can be violated (they saw
``t^{(m−1)}``), so that residual measures exactly the coupling mismatch ``A_nt (t^{(m)} −
t^{(m−1)})``. Each outer iteration warm-starts both halves from the previous one.

The outer iteration is a fixed-point iteration: it converges linearly, with a rate that
grows with ``|β|`` and ``μ`` (the paper reports about 6 outer iterations for 2β = 1, μ = 0.3;
``benchmarks/coupled_table.py`` measures it). It is not guaranteed to converge: it raises
:class:`~rollqp.errors.SolverError` with the residual when it does not within ``max_outer``,
and earlier when it stalls or cycles (no 10 % gain of its best residual over 20 outer
iterations) or diverges (``Alternation._check_progress``).
"""
from __future__ import annotations

import dataclasses
import time

import numpy as np

from ..errors import InputError, SolverError
from .base import FRICTION_KINDS


def sweep(method, problem, t, warm_n=None, warm_t=None):
    """One N–T sweep of a :class:`~rollqp.problem.CoupledStep` (paper §6.3): ``(normal, tangential)``.

    The normal half with the shear ``t`` fixed (eq. 53: gap offset ``A_nt t``), then the
    tangential half at the pressure found (eq. 61/62: bound ``μ p⁺``, history ``c + A_tn p``),
    each solved by ``method`` and warm-started from ``warm_n`` and ``warm_t``. The one sweep of
    rollqp: the alternation's outer iteration, and the coupled Newton method's cold start and
    its fallback when a line search fails.
    """
    nsol = method.solve(problem.normal_half(t), warm=warm_n)
    tsol = method.solve(problem.tangential_half(nsol.p), warm=warm_t)
    return nsol, tsol


class Alternation:
    """N–T alternation around an inner step method (paper §6.3).

    Parameters
    ----------
    inner : method
        Any rollqp method that solves :class:`NormalStep` and :class:`TangentialStep`
        (``NewtonMethod``, or a QP backend).
    max_outer : int
        Outer iterations before :class:`SolverError`.
    limit : float, optional
        Residual (rollqp's, nondimensional max norm) of the coupled problem at which the
        alternation stops. Default: the inner method's ``tolerance``. With QP halves it also
        stops once the residual is below their ``residual_limit`` (what their solutions are
        trusted to) and no longer halves per outer iteration: stalled at the halves' accuracy.

    Notes
    -----
    Uncoupled problems are passed to ``inner`` unchanged. ``info`` of a coupled solution:
    ``outer`` (outer iterations), ``inner_normal`` and ``inner_tangential`` (iterations of
    the inner method summed over the halves), ``history`` (coupled residual after each
    outer iteration).
    """

    def __init__(self, inner, max_outer: int = 200, limit: float | None = None):
        if max_outer is None:
            max_outer = 200
        if int(max_outer) != max_outer or max_outer < 1:
            raise InputError("max_outer", f"must be an integer >= 1, got {max_outer!r}")
        self.inner = inner
        inner_caps = inner.capabilities
        self.max_outer = int(max_outer)
        self.limit = float(limit) if limit is not None else float(inner.tolerance)
        self.stall_limit = max(self.limit, float(inner_caps.residual_limit or 0.0))
        self.name = inner.name
        self.tolerance = inner.tolerance
        #: coupled steps by alternation, with any friction law its halves take; the steady (non-symmetric)
        #: problem only if the halves pose it; the halves' operators, slip-dependent bounds (a bound reaches
        #: them unchanged), QP prediction and accelerated start; one sweep a step on request
        #: (:meth:`single_sweeps`)
        self.capabilities = dataclasses.replace(inner_caps, solves=frozenset({"coupled"}) | inner_caps.solves,
                                                coupled_friction=FRICTION_KINDS, coupled_limit=None,
                                                residual_limit=None, single_sweeps=True)
        self._single = False  # single_sweeps

    def single_sweeps(self, on: bool) -> bool:
        """Switch the one-sweep mode on or off; return whether it was on.

        In it :meth:`solve` makes one N–T sweep per coupled step and returns its state without
        iterating to the limit. For a march toward a steady rolling state (``rollqp.march``'s
        rolling start), where only the fixed point counts: the march's own steps continue the
        alternation, whose fixed point with the history of the previous step is the coupled steady
        state, in about as many steps as with the full alternation and fewer QPs (docs/performance.md,
        "Measured settings of the methods"). The march ends with full steps (mode off), so the state it
        keeps is a converged coupled step.
        """
        was, self._single = self._single, bool(on)
        return was

    def predicting(self, on: bool) -> bool:
        """The halves' active-set prediction on or off (:attr:`Capabilities.predicting
        <rollqp.methods.base.Capabilities.predicting>` of the inner method); whether it was on."""
        return self.inner.predicting(on)

    def kkt_caches(self) -> tuple:
        """The inner QP method's factor caches (:meth:`QPMethod.kkt_caches <rollqp.methods._qp.QPMethod.kkt_caches>`),
        for a method that declares :attr:`~rollqp.methods.base.Capabilities.predicting`."""
        return self.inner.kkt_caches()

    def carrier(self):
        """The inner method's (called only where the capabilities declare ``carries_state``)."""
        return self.inner.carrier()

    def setup(self, operators) -> None:
        """A new scene: the inner method's set-up (and the one-sweep mode off)."""
        self._single = False
        self.inner.setup(operators)

    def solve(self, problem, warm=None):
        if problem.kind != "coupled":
            return self.inner.solve(problem, warm=warm)
        t_start = time.perf_counter()
        n = problem.n
        if warm is not None and warm.t is not None and np.shape(warm.t) == (n,):
            t = np.asarray(warm.t, dtype=float)
        else:
            t = np.zeros(n)
        nwarm = twarm = warm
        it_n = it_t = 0
        history = []
        outer = 0
        while True:
            outer += 1
            nsol, tsol = sweep(self.inner, problem, t, nwarm, twarm)
            it_n += nsol.iterations
            it_t += tsol.iterations
            t = tsol.t
            sol = problem.solution(nsol.p, t, nsol.delta, tsol.xi)
            history.append(sol.residual)
            if sol.residual <= self.limit or self._single:
                break
            if (len(history) > 1 and sol.residual <= self.stall_limit
                    and sol.residual >= 0.5 * history[-2]):
                break  # stalled at the accuracy of the halves (QP solvers)
            self._check_progress(history)  # raises on a non-finite, diverging or cycling residual
            if outer >= self.max_outer:
                raise SolverError(f"the N-T alternation did not converge: coupled residual {sol.residual:.3e} "
                                  f"> {self.limit:.1e} after {outer} outer iterations",
                                  method=self.name, status="outer limit", residual=sol.residual,
                                  iterations=outer)
            nwarm, twarm = nsol, tsol
        sol.method, sol.status, sol.iterations = self.name, "solved", outer
        sol.time = time.perf_counter() - t_start
        sol.solver_time = nsol.solver_time + tsol.solver_time
        sol.outer, sol.inner_normal, sol.inner_tangential = outer, it_n, it_t
        sol.extras.update(history=history, limit=self.limit,
                        # inner counts are meaningful only if the halves' solver reports them
                        iterations_reported=nsol.info.get("iterations_reported", True)
                        and tsol.info.get("iterations_reported", True))
        return sol

    def _check_progress(self, history):
        """Stop early when the outer iteration cycles or diverges (it is a fixed-point iteration).

        * **stall**: after ``2·STALL_WINDOW`` outer iterations, the best residual of the last
          ``STALL_WINDOW`` is not below ``STALL_FACTOR`` times the best one before them. A linear
          contraction passes even at rate 0.99 (0.99^20 = 0.82 < 0.9); a cycle does not (§6.2.1 with
          μ = 5, 2β = 1: docs/stability.md, "Strong coupling");
        * **divergence**: a non-finite residual, or one above ``DIVERGE_FACTOR`` times the first.
        """
        h = history
        last = h[-1]
        if not np.isfinite(last) or last > DIVERGE_FACTOR * max(h[0], self.limit):
            raise SolverError(f"the N-T alternation diverges: coupled residual {last:.3e} after {len(h)} outer "
                              f"iterations (first {h[0]:.3e}); try method newton", method=self.name,
                              status="diverged", residual=float(last), iterations=len(h))
        W = STALL_WINDOW
        if len(h) >= 2 * W:
            recent, before = min(h[-W:]), min(h[:-W])
            if recent > STALL_FACTOR * before:
                raise SolverError(f"the N-T alternation stalls (cycles): best coupled residual {recent:.3e} over the "
                                  f"last {W} outer iterations, {before:.3e} before them, limit {self.limit:.1e}; "
                                  f"try method newton", method=self.name, status="stalled",
                                  residual=float(last), iterations=len(h))


#: Outer iterations over which the alternation must improve its best residual (``_check_progress``).
STALL_WINDOW = 20
#: … by at least this factor.
STALL_FACTOR = 0.9
#: A residual this many times the first one is divergence.
DIVERGE_FACTOR = 1e6
