r"""The QP methods' rolling start: the march toward steady rolling, accelerated.

A QP method cannot pose the steady rolling problem (its slip operator ``T·A``, docs/formulation.md §9, has an
indefinite weighted symmetric part: no convex QP has it as Hessian), so :func:`rollqp.march`
reaches the steady state by rolling at constant loads until the tractions stop changing. One
marching step, as a function of the shear it starts from, is a map ``t ↦ G(t)``: the normal half
with that shear (paper eq. 53), the history ``c = −M w(p, t)`` (eq. 37, 48), the tangential half
at the new pressure (eq. 61/62) — one N–T sweep (paper §6.3), two QPs. The steady state is its
fixed point, and the plain march ``t ← G(t)`` converges to it only linearly and slowly: a
disturbance is carried through the stick zone by the rolling and decays by about 10× per 100
steps of ``Δq = Le`` on the Bentall–Johnson coupled start (216 constant elements; 750 steps).

:func:`accelerated_start` iterates the same map in three phases. Plain steps while the residual
``max|G(t) − t|/(μp0)`` is above :data:`NEWTON_FROM` (far from steady the stick and slip zones
still move and the map is far from affine). Then Newton's method on ``G(t) − t = 0``
(:func:`chord_newton`: damped, the Jacobian kept while it serves), with the map's Jacobian from the
QPs' own active sets (:class:`MapJacobian`, the QP answers' sensitivity to their data): on fixed
active sets the map is affine, and Newton lands on its fixed point in a step or two, where
Anderson needs about as many evaluations as there are nodes (the slow modes, transport through the
stick zone, span the space). If the Newton phase stops short (the active sets still change under
its steps), Anderson acceleration continues from its best state (type II; Walker & Ni, SIAM J.
Numer. Anal. 49 (2011): the extrapolation of the last ``m`` differences that minimizes the
linearized residual) with :data:`MEMORY` differences.

Every QP of the map is first solved on the active set of the previous evaluation
(:meth:`QPMethod.predicting <rollqp.methods._qp.QPMethod.predicting>`: an exact KKT solve on cached
factors, accepted at the backend's tolerance; the backend when it is not): near steady state the
active sets no longer change, and the map costs two such solves instead of two QP solver runs.
Every iterate the start returns is a map's *output*, i.e. QP answers within the tolerance; the
march then continues with its own steps, solved by the backend (N–T alternation converged), until
a step changes ``t`` by less than its tolerance, so the state it keeps is a marching step like any
other. Measured with ``python benchmarks/bentall.py --only start``.
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError, SolverError
from ..problem import State
from ._qp import _chol_solve, _kkt_factor

#: Anderson extrapolation starts once ``max|G(t) − t|/(μp0)`` is below this (without the Newton phase,
#: or after it stopped short). Measured on the
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


#: The quasi-Newton phase (:func:`chord_newton`) starts once the plain iteration's residual is below this
#: (in μp0). Measured on the Bentall–Johnson coupled start (``python benchmarks/bentall.py --only start``):
#: from the braked state (residual 0.6) the Newton steps overshoot to where the stick and slip zones are
#: elsewhere and the iteration diverges; from 0.3 and 0.1 it converges (see :data:`REFRESH`).
NEWTON_FROM = 0.1
#: The Jacobian is computed anew when an accepted step reduces the Newton correction by less than this
#: factor, or when the damping factor falls below MIN_STEP …
REFRESH, MIN_STEP = 0.2, 1 / 16
#: … at most this many times: then Anderson continues from the best state.
MAX_JACOBIANS = 10


def applies(method, ops) -> bool:
    """Whether :func:`accelerated_start` handles this method and scene: a method that declares
    :attr:`~rollqp.methods.base.Capabilities.accelerated_start` (a QP backend, or the N–T alternation of
    one; benchmarks switch it off to measure the plain march) and solves the scene's steps as they are
    posed (coupled steps on a coupled scene, the halves on the others), with a constant friction
    coefficient, friction, and a fixed profile."""
    caps = method.capabilities
    return (caps.accelerated_start and ops.friction.kind == "constant" and not ops.frictionless
            and not ops.profiles_move and ops.coupled == ("coupled" in caps.solves))


def predicting(method, on: bool) -> bool | None:
    """Switch the active-set prediction of ``method``'s QPs on or off (:meth:`QPMethod.predicting
    <rollqp.methods._qp.QPMethod.predicting>`, for a method that declares
    :attr:`~rollqp.methods.base.Capabilities.predicting`); return whether it was on, or None for a
    method without it. rollqp.march's rolling start keeps it on while it marches to the steady state
    and takes its last steps with it off, so that the state it keeps is the backend's."""
    return method.predicting(on) if method.capabilities.predicting else None


def sweep_map(method, ops, state, counters=None, *, P, Q, xi, dq, M, delta=None):
    """``G(t) -> (t_new, nsol, tsol)``: one marching step from the shear ``t`` (module docstring), each
    half warm-started from the previous evaluation (first from ``state``); its solves are counted in
    ``counters`` if given (rollqp.march's ``Counters`` of the starting state: a coupled evaluation is
    one N–T outer iteration, as in the alternation)."""
    inner = method  # its halves' solver (the N–T alternation hands the halves to its inner method as they are)
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
    else the best map output (smallest ``max|G(t) − t|``) of the accelerated iteration from the
    starting ``state`` (module docstring), as a march ``State``.

    ``tol``: the march's tolerance on the change of ``t`` per step, in μp0; the iteration stops at
    :data:`TARGET`·tol, after :data:`PATIENCE` evaluations without progress, or ``max_evaluations``.
    A method that does not declare :attr:`~rollqp.methods.base.Capabilities.quasi_newton` skips the Newton
    phase (benchmarks measure Anderson alone so).
    """
    if not applies(method, ops):
        return state
    G = sweep_map(method, ops, state, counters, P=P, Q=Q, xi=xi, dq=dq, M=M, delta=delta)
    was = method.predicting(True)  # the map's QPs: active-set prediction first (module docstring)
    try:
        best, _, _ = fixed_point(G, state.t, ops.mu * ops.scales.stress, target=TARGET * tol,
                                 max_evaluations=max_evaluations,
                                 jacobian=MapJacobian(ops, P=P, Q=Q, xi=xi, dq=dq, M=M, delta=delta)
                                 if method.capabilities.quasi_newton else None)
    finally:
        method.predicting(was)
    return state if best is None else _state(ops, state, best, P=P, Q=Q, xi=xi, dq=dq, M=M, delta=delta)


def fixed_point(G, x, scale, *, target, memory=MEMORY, anderson_from=ANDERSON_FROM, patience=PATIENCE,
                max_evaluations=1000, jacobian=None, newton_from=NEWTON_FROM):
    """Iterate ``x ← G(x)`` with Anderson acceleration below ``anderson_from`` (module docstring); with
    ``jacobian`` (``K(x, *extra)``, :class:`MapJacobian`), the quasi-Newton phase (:func:`chord_newton`)
    once the residual is below ``newton_from``, and Anderson from its best state if it stops short.

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
        if jacobian is not None and r <= newton_from:
            nb, nk, nr = chord_newton(G, jacobian, (x, gx, *extra), scale, target=target,
                                      max_evaluations=max_evaluations - k)
            jacobian, k = None, k + nk  # once: Anderson (below) from the best state if it stopped short
            if nr < best_r:
                best, best_r, since = nb, nr, 0
            if best_r <= target:
                break
            x = best[1]  # Anderson from the best state's output
            if acc is not None:
                acc.reset()
            continue
        if acc is None or r > anderson_from or r > 1e3 * best_r:  # far from steady, or the extrapolation went astray
            if acc is not None:
                acc.reset()
            x = gx
        else:
            x = acc.next(x, gx)
    return best, k, best_r


def chord_newton(G, jacobian, start, scale, *, target, max_evaluations, refresh=REFRESH,
                 max_jacobians=MAX_JACOBIANS, min_step=MIN_STEP):
    """Newton's method on ``G(x) − x = 0``, damped, with the Jacobian kept while it serves: the
    correction ``d = (I − K)⁻¹ (G(x) − x)``, ``K = jacobian(x, *extra)``, and the step ``x + α d``.

    A step is accepted when the next correction with the same ``K`` is smaller, ``|d̄| ≤ (1 − α/4)|d|``
    (the natural monotonicity test of affine-invariant Newton methods, Deuflhard, *Newton Methods for
    Nonlinear Problems* §3.1: the residual ``max|G(x) − x|`` is no measure of the distance to the fixed
    point here, the march contracting by ~2.5 % a step), else ``α`` is halved; ``α`` doubles again
    after an accepted step. ``K`` is computed at the start, where an accepted step reduced the
    correction by less than ``refresh``, and where ``α`` fell below ``min_step``. Stops at the residual
    ``target``, on a failed evaluation (a QP not solved at an iterate far off), after ``max_jacobians``
    or ``max_evaluations``, and where ``jacobian`` gives None (a singular QP sensitivity). Returns ``(best, evaluations, best residual)`` as :func:`fixed_point`.
    """
    from scipy.linalg import lu_factor, lu_solve
    x, gx, *extra = start
    best, best_r, lu, jacobians, k, alpha = start, float(np.abs(gx - x).max()) / scale, None, 0, 0, 1.0
    while k < max_evaluations:
        if lu is None:
            K = jacobian(x, *extra) if jacobians < max_jacobians else None
            if K is None:  # enough Jacobians, or none to be had here (a singular QP sensitivity)
                break
            lu, jacobians = lu_factor(np.eye(x.size) - K, check_finite=False), jacobians + 1
            d = lu_solve(lu, gx - x, check_finite=False)
        xt = x + alpha * d
        k += 1
        try:
            gt, *et = G(xt)
        except (SolverError, InputError):  # an iterate far off
            gt = None
        rt = np.inf if gt is None else float(np.abs(gt - xt).max()) / scale
        if rt < best_r:
            best, best_r = (xt, gt, *et), rt
        if rt <= target:
            break
        dt = lu_solve(lu, gt - xt, check_finite=False) if np.isfinite(rt) else None
        if dt is not None and np.abs(dt).max() <= (1 - alpha / 4) * np.abs(d).max():
            if np.abs(dt).max() > (1 - alpha * (1 - refresh)) * np.abs(d).max():  # slower than refresh a full step
                lu = None  # slow: a new Jacobian at the accepted point
            x, gx, extra, d, alpha = xt, gt, et, dt, min(1.0, 2 * alpha)
        else:
            alpha /= 2
            if alpha < min_step:
                lu, alpha = None, 1.0  # a new Jacobian where we are
    return best, k, best_r


class MapJacobian:
    r"""``K = ∂G/∂t``: the march map's Jacobian on the active sets of its QP answers (QP sensitivity).

    On fixed active sets each half's answer is affine in its data: with the free set ``F`` and the
    nodes at a bound ``A`` of a QP (:class:`~rollqp.problem.QPForm`), ``dx_A`` is the bounds'
    change and ``dx_F = H_FF⁻¹ dr − z (a_Fᵀ H_FF⁻¹ dr − dβ)/(a_Fᵀ z)``, ``z = H_FF⁻¹ a_F``, with
    ``dr = −dq_F − H_FA dx_A`` and ``dβ = −a_Aᵀ dx_A`` (the load row's right-hand side fixed). The
    map's data depend on ``t`` through the normal half's gap offset ``A_nt t`` (``dq = ∂q/∂e · A_nt dt``,
    :attr:`QPForm.shift_scale`), the history ``c = −M w(p, t)`` of the tangential half, whose own
    history is ``c + A_tn p`` (so ``dc = (I − M) A_tn dp − M A_tt dt``), and its bounds ``±μ p⁺``.
    The Hessians are the QPs' own (the symmetric part ``sym(F·A)`` for an asymmetric ``F·A``: an
    approximate Jacobian there, exact for constant elements). Dense ``n × n`` products, ``O(n³)`` a call.
    """

    def __init__(self, ops, *, P, Q, xi, dq, M, delta):
        self.ops, self.M, self.data = ops, M, dict(P=P, Q=Q, xi=xi, dq=dq, delta=delta)
        self.MAtt = np.asarray(M @ ops.Att.dense())  # fixed for the start: once (M has ≤ 3 entries a row)
        if ops.coupled:
            Atn = ops.Atn.dense()
            self.Ant, self.ImMAtn = ops.Ant.dense(), Atn - np.asarray(M @ Atn)

    def __call__(self, t, nsol, tsol):
        """``K`` at the map output ``(t, nsol, tsol)``, or None if a QP's reduced KKT system there is singular."""
        ops, d, stress = self.ops, self.data, self.ops.scales.stress
        c = -(self.M @ ops.w(nsol.p, t))
        if ops.coupled:
            step = ops.coupled_step(d["P"], np.zeros(ops.n), d["dq"], Q=d["Q"], xi=d["xi"], delta=d["delta"])
            fn = step.normal_half(t).qp_form()
            Jn = qp_response(fn, nsol.p / stress, nsol.info["qp_multiplier"], fn.shift_scale[:, None] * self.Ant)
            if Jn is None:
                return None
            Jn *= stress  # dp/dt
            dc = self.ImMAtn @ Jn - self.MAtt
            dbound = (ops.mu / stress) * (nsol.p > 0)[:, None] * Jn
            ft = ops.coupled_step(d["P"], c, d["dq"], Q=d["Q"], xi=d["xi"], delta=d["delta"]).tangential_half(nsol.p)
        else:
            dc, dbound = -self.MAtt, None
            ft = ops.tangential_step(nsol.p, c, d["dq"], Q=d["Q"], xi=d["xi"])
        ft = ft.qp_form()
        Jt = qp_response(ft, tsol.t / stress, tsol.info["qp_multiplier"], ft.shift_scale[:, None] * dc, dbound)
        return None if Jt is None else stress * Jt


def qp_response(form, x, y, dq, dbound=None):
    """``dx``: the change of the QP answer ``x`` (multiplier ``y``) with ``q`` changed by ``dq`` and the
    bounds' magnitude (``upper = −lower``) by ``dbound`` (columns: directions), on the active set of
    ``(x, y)`` read as :func:`~rollqp.methods._qp.active_set_refine` reads it, and with the nodes on a
    bound counted at it (:class:`MapJacobian`). Solved with :func:`~rollqp.methods._qp.active_set_refine`'s
    factors (the Cholesky factor of ``H_FF`` and the load row's Schur complement); None if singular."""
    H, a = form.H, form.a
    lam = form.multipliers(x, y)
    width = form.upper - form.lower  # a bound pair closer than rounding (μp of ~1e-21 p0 at the contact's
    fixed = form.fixed | (width <= 1e-12 * np.max(width, initial=0.0, where=np.isfinite(width)))  # edge): fixed
    # at a bound also where x is on it with a zero multiplier (a node at the edge of a zone): its
    # derivative is one-sided, and the answer's traction is clipped to the bound
    at_lo = np.isfinite(form.lower) & ((x - form.lower < lam) | (x <= form.lower)) & ~fixed
    at_up = np.isfinite(form.upper) & ((form.upper - x < -lam) | (x >= form.upper)) & ~fixed
    dx = np.zeros(dq.shape)
    if dbound is not None:
        dx[at_up], dx[at_lo] = dbound[at_up], -dbound[at_lo]
    free = ~(fixed | at_lo | at_up)
    F = np.flatnonzero(free)
    if F.size == 0:
        return dx
    fac = _kkt_factor(H, free, a)
    if fac is None:
        return None
    chol, z2, schur = fac
    z = _chol_solve(chol, -dq[F] - H[F] @ dx)  # dx is zero on F: H[F] dx = H_FA dx_A
    if a is not None:
        z -= np.outer(z2, (a[F] @ z + a @ dx) / schur)  # a_Fᵀ dx_F = −a_Aᵀ dx_A
    dx[F] = z
    return dx


def _state(ops, start, best, *, P, Q, xi, dq, M, delta):
    """The march ``State`` of a map output ``G(x)`` (its solutions warm-start the march's next step)."""
    x, t, nsol, tsol = best
    p = nsol.p
    if not ops.coupled:
        return State(p, t, ops.w(p, t), nsol, tsol, start.normal)
    sol = ops.coupled_step(P, -(M @ ops.w(p, x)), dq, Q=Q, xi=xi, delta=delta).solution(p, t, nsol.delta, tsol.xi)
    return State(p, t, ops.w(p, t), sol, sol, None)
