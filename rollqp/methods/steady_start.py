r"""The QP methods' rolling start: the march toward steady rolling, Anderson-accelerated (issue 18).

A QP method cannot pose the steady rolling problem (its slip operator ``d·D_up·A`` has an
indefinite weighted symmetric part: no convex QP has it as Hessian), so :func:`rollqp.march`
reaches the steady state by rolling at constant loads until the tractions stop changing. One
marching step, as a function of the shear it starts from, is a map ``t ↦ G(t)``: the normal half
with that shear (paper eq. 53), the history ``c = −M w(p, t)`` (eq. 37, 48), the tangential half
at the new pressure (eq. 61/62) — one N–T sweep (paper §6.3), two QPs. The steady state is its
fixed point, and the plain march ``t ← G(t)`` converges to it only linearly and slowly: a
disturbance is carried through the stick zone by the rolling and decays by about 10× per 100
steps of ``Δq = Le`` on the Bentall–Johnson coupled start (216 constant elements; 750 steps).

:func:`accelerated_start` iterates the same map with Anderson acceleration (type II; Walker & Ni,
SIAM J. Numer. Anal. 49 (2011); the extrapolation of the last ``m`` differences that minimizes
the linearized residual): plain steps while the residual ``max|G(t) − t|/(μp0)`` is above
:data:`ANDERSON_FROM` (far from steady the stick and slip zones still move, the map is not
affine, and extrapolating across those kinks costs evaluations: :data:`ANDERSON_FROM`), then Anderson with :data:`MEMORY`
differences. Every iterate it returns is a map's *output*, i.e. QP answers (each state solved
by the QP backend); the march then continues with its own steps (N–T alternation converged)
until a step changes ``t`` by less than its tolerance, so the state it keeps is a marching step
like any other. Measured with ``python benchmarks/bentall.py --only start``.
"""
from __future__ import annotations

import numpy as np

from ._qp import QPMethod
from .alternation import Alternation

#: Anderson extrapolation starts once ``max|G(t) − t|/(μp0)`` is below this. Measured on the
#: Bentall–Johnson coupled start (216 constant elements, μ = 0.05, memory 150; ``python
#: benchmarks/bentall.py --only start``): map evaluations to 1e-10 from 1 (Anderson from the first
#: step): 452; from 1e-1: 316; from 1e-2: 350; plain iteration: not within 800 (5e-9 after 800).
ANDERSON_FROM = 0.1
#: Differences kept (at most the number of nodes). The slow part of the march is transport through
#: the stick zone (many modes near the unit circle): measured (same benchmark) memory 10 from 1e-1:
#: 1.4e-7 after 800 evaluations, no better than the plain march; 60 from 1: 616; 150 from 1e-1: 316;
#: 300 from 1e-1: 333.
MEMORY = 150
#: The fixed-point iteration stops at this fraction of the march's own tolerance (its verification
#: steps then change ``t`` by far less than that tolerance), …
TARGET = 1e-2
#: … or when its best residual has not improved by 10 % over this many evaluations (the QP
#: solvers' own accuracy, or a map Anderson does not help): the march takes over from the best state.
PATIENCE = 200


def applies(method, ops) -> bool:
    """Whether :func:`accelerated_start` handles this method and scene: a QP backend (or the N–T
    alternation of one) whose ``accelerated_start`` attribute is not False (benchmarks switch it off to
    measure the plain march), with Coulomb friction (a fixed μ), friction, and a fixed profile."""
    inner = method.inner if isinstance(method, Alternation) else method
    return (isinstance(inner, QPMethod) and getattr(method, "accelerated_start", True) and isinstance(ops.friction, float) and not ops.frictionless
            and not ops.profiles_move and ops.coupled == isinstance(method, Alternation))


def sweep_map(method, ops, state, counters=None, *, P, Q, xi, dq, M, delta=None):
    """``G(t) -> (t_new, nsol, tsol)``: one marching step from the shear ``t`` (module docstring), each
    half warm-started from the previous evaluation (first from ``state``); its solves are counted in
    ``counters`` if given (rollqp.march's ``Counters`` of the starting state: a coupled evaluation is
    one N–T outer iteration, as in the alternation)."""
    inner = method.inner if isinstance(method, Alternation) else method
    warm = {"n": state.nsol, "t": state.tsol}
    zero = np.zeros(ops.n)

    def G(t):
        if ops.coupled:
            nsol = inner.solve(ops.coupled_step(P, zero, dq, Q=Q, xi=xi, delta=delta).normal_half(t), warm=warm["n"])
        else:  # the normal half does not see the shear: solved once, before the start
            nsol = state.nsol
        c = -(M @ ops.w(nsol.p, t))
        if ops.coupled:
            half = ops.coupled_step(P, c, dq, Q=Q, xi=xi, delta=delta).tangential_half(nsol.p)
        else:
            half = ops.tangential_step(nsol.p, c, dq, Q=Q, xi=xi)
        tsol = inner.solve(half, warm=warm["t"])
        warm["n"], warm["t"] = nsol, tsol
        if counters is None:
            pass
        elif ops.coupled:  # a sweep's coupled residual is not the alternation's: not counted (as in the march)
            counters.iterations += 1
            counters.inner_normal += nsol.iterations
            counters.inner_tangential += tsol.iterations
        else:
            counters.add(tsol, "tangential")
        return tsol.t, nsol, tsol

    return G


class Anderson:
    """Anderson acceleration of ``x = G(x)`` (type II), ``memory`` differences (module docstring).

    The differences of the residuals ``f = G(x) − x`` are kept normalized (``u = Δf/|Δf|``, and
    ``ΔG`` divided by the same norm) in a ring buffer with their Gram matrix ``UᵀU``, updated by one
    column a step (``O(n m)``); ``γ`` solves the regularized normal equations
    ``(UᵀU + REG·I) γ = Uᵀ f``. Measured: a least-squares solve of the ``n × m`` system each step
    (216 × 150) took 5.6 ms, more than the step's two QPs together.
    """

    #: Tikhonov regularization of the normalized Gram matrix (unit diagonal): directions whose
    #: residual differences are linearly dependent to 1e-5 are damped instead of amplified.
    REG = 1e-10

    def __init__(self, memory: int, n: int):
        self.memory = int(memory)
        self.U, self.V = np.zeros((n, self.memory)), np.zeros((n, self.memory))
        self.gram = np.zeros((self.memory, self.memory))
        self.count, self.last = 0, None

    def reset(self):
        self.count, self.last = 0, None

    def next(self, x, gx):
        """The next iterate from ``x`` and ``G(x)``: ``G(x) − ΔG γ``, ``γ`` minimizing ``|f − ΔF γ|``."""
        f = gx - x
        if self.last is not None:
            df = f - self.last[1]
            norm = float(np.linalg.norm(df))
            if norm > 0:
                slot = self.count % self.memory
                self.U[:, slot] = df / norm
                self.V[:, slot] = (gx - self.last[0]) / norm
                k = min(self.count + 1, self.memory)
                row = self.U[:, :k].T @ self.U[:, slot]
                self.gram[slot, :k] = row
                self.gram[:k, slot] = row
                self.count += 1
        self.last = (gx, f)
        k = min(self.count, self.memory)
        if k == 0:
            return gx
        gamma = np.linalg.solve(self.gram[:k, :k] + self.REG * np.eye(k), self.U[:, :k].T @ f)
        return gx - self.V[:, :k] @ gamma


def accelerated_start(method, ops, state, counters, *, P, Q, xi, dq, M, delta=None, tol=1e-8,
                      max_evaluations=1000):
    """The state to continue rollqp.march's rolling start from: ``state`` itself unless :func:`applies`,
    else the best map output (smallest ``max|G(t) − t|``) of the accelerated iteration from the braked
    starting ``state`` (module docstring), as a march ``State``.

    ``tol``: the march's tolerance on the change of ``t`` per step, in μp0; the iteration stops at
    :data:`TARGET`·tol, after :data:`PATIENCE` evaluations without progress, or ``max_evaluations``.
    """
    if not applies(method, ops):
        return state
    G = sweep_map(method, ops, state, counters, P=P, Q=Q, xi=xi, dq=dq, M=M, delta=delta)
    inner = method.inner if isinstance(method, Alternation) else method
    was = inner.predicting(True)  # the map's QPs: active-set prediction first (module docstring)
    try:
        best, _, _ = fixed_point(G, state.t, ops.mu * ops.scales.stress, target=TARGET * tol,
                                 max_evaluations=max_evaluations)
    finally:
        inner.predicting(was)
    return state if best is None else _state(ops, state, best, P=P, Q=Q, xi=xi, dq=dq, M=M, delta=delta)


def fixed_point(G, x, scale, *, target, memory=MEMORY, anderson_from=ANDERSON_FROM, patience=PATIENCE,
                max_evaluations=1000):
    """Iterate ``x ← G(x)`` with Anderson acceleration below ``anderson_from`` (module docstring).

    ``G(x)`` returns ``(G(x), *extra)``; the residual is ``max|G(x) − x|/scale``. Returns ``(best,
    evaluations, best residual)`` with ``best = (x, G(x), *extra)`` of the smallest residual (None if
    none was finite). ``memory = 0``: the plain iteration.
    """
    x = np.asarray(x, dtype=float)
    acc = Anderson(min(memory, x.size), x.size) if memory else None
    best, best_r, since, k = None, np.inf, 0, 0
    while k < max_evaluations:
        k += 1
        gx, *extra = G(x)
        r = float(np.abs(gx - x).max()) / scale
        if not np.isfinite(r):
            break
        since = 0 if r < 0.9 * best_r else since + 1
        if r < best_r:
            best, best_r = (x, gx, *extra), r
        if r <= target or since >= patience:
            break
        if acc is None or r > anderson_from or r > 1e3 * best_r:  # far from steady, or the extrapolation went astray
            if acc is not None:
                acc.reset()
            x = gx
        else:
            x = acc.next(x, gx)
    return best, k, best_r


def _state(ops, start, best, *, P, Q, xi, dq, M, delta):
    """The march ``State`` of a map output ``G(x)`` (its solutions warm-start the march's next step)."""
    from ..march import State
    x, t, nsol, tsol = best
    p = nsol.p
    if not ops.coupled:
        return State(p, t, ops.w(p, t), nsol, tsol, start.normal)
    sol = ops.coupled_step(P, -(M @ ops.w(p, x)), dq, Q=Q, xi=xi, delta=delta).solution(p, t, nsol.delta, tsol.xi)
    return State(p, t, ops.w(p, t), sol, sol, None)
