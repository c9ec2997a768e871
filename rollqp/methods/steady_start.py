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

:func:`accelerated_start` solves ``G(t) − t = 0`` by Newton's method with the map's Jacobian from the
QPs' own active sets (:class:`MapJacobian`, the QP answers' sensitivity to their data, with the
collocation operator of each half: exact for every element type). ``G`` is piecewise affine (affine
while its QPs keep their active sets), so a full Newton step with the Jacobian of its iterate
(:func:`active_set_newton`) is the active-set Newton step of the steady problem seen through the
march; it is kept where it shrinks the Newton correction, and plain marching steps ``t ← G(t)`` are
taken where it does not (far from steady). From the start's guess (the normal half at zero shear)
this reaches the fixed point in 4–40 map evaluations on the built-in coupled scenes and CONTACT's
Bentall grids, where the plain march needs hundreds (a disturbance is carried through the stick zone
by the rolling and decays by about 10× per 100 steps of ``Δq = Le`` on those grids). If it stops
short (a singular QP sensitivity, Newton steps refused again and again), Anderson acceleration (type II; Walker & Ni, SIAM J. Numer. Anal.
49 (2011): the extrapolation of the last ``m`` differences that minimizes the linearized residual)
continues from its best state with :data:`MEMORY` differences.

Every QP of the map is first solved on the active set of its warm start (:meth:`QPMethod.predicting
<rollqp.methods._qp.QPMethod.predicting>`: the splitting's fixed point by one solve of the
collocation operator's reduced KKT system on cached LU factors, repeated from each candidate's own
active set, accepted at the backend's tolerance; the backend when it is not): the map then costs a
few such solves instead of two QP solver runs of ~5 splitting QPs each. Every iterate the start
returns is a map's *output*, i.e. QP answers within the tolerance; the march then continues with its
own steps, solved by the backend (N–T alternation converged), until a step changes ``t`` by less than
its tolerance, so the state it keeps is a marching step like any other. Measured with ``python
benchmarks/bentall.py --only start`` and ``python benchmarks/speed.py`` (the rolling starts of the
built-in coupled scenes).
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError, SolverError
from ..problem import State
from ._qp import _chol_solve, _kkt_factor, _kkt_lu, _lu_solve, collocation

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
#: steps then change ``t`` by far less than that tolerance; at 1e-4, 1e-12 μp0, the first of them, the
#: backend's N–T alternation, converges in one sweep, where at 1e-2 its coupled residual ``A_nt (t' − t)``
#: was at the alternation's limit and it took two: two QP solver runs saved for one more Newton step), …
TARGET = 1e-4
#: … or when its best residual has not improved by 10 % over this many evaluations (the QP
#: solvers' own accuracy, or a map Anderson does not help): the march takes over from the best state.
PATIENCE = 200


#: The Newton phase (:func:`active_set_newton`) starts once the plain iteration's residual is below this
#: (in μp0): at once (it takes plain steps itself where its Newton steps do not serve) …
NEWTON_FROM = np.inf
#: … and hands over to Anderson after this many Newton steps refused in a row (with 1 + 2 + … + 32 = 63
#: plain steps between them: a Jacobian that does not serve). Measured on the scenes of
#: :func:`active_set_newton`: at most 5 in a row (goodman-bentall from the braked state).
REFUSALS = 6
#: It also hands over when its accepted steps do not halve the Newton correction within this many (a
#: Jacobian that only damps the march). Measured on the same scenes: at most 7 (CONTACT's 216-element grid,
#: where the steps slide down at ~0.88 a step from a correction of 1.3 μp0 before the active sets settle).
HALVING = 20


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
    pressing = ops.coupled_step(P, np.zeros(ops.n), dq, Q=Q, xi=xi, delta=delta) if ops.coupled else None  # once

    def G(t):
        if ops.coupled:
            nsol = inner.solve(pressing.normal_half(t), warm=warm["n"])
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
                                 jacobian=MapJacobian(ops, P=P, Q=Q, xi=xi, dq=dq, M=M, delta=delta,
                                                      caches=method.kkt_caches() if method.capabilities.predicting
                                                      else (None, None))
                                 if method.capabilities.quasi_newton else None)
    finally:
        method.predicting(was)
    return state if best is None else _state(ops, state, best, P=P, Q=Q, xi=xi, dq=dq, M=M, delta=delta)


def fixed_point(G, x, scale, *, target, memory=MEMORY, anderson_from=ANDERSON_FROM, patience=PATIENCE,
                max_evaluations=1000, jacobian=None, newton_from=NEWTON_FROM):
    """Iterate ``x ← G(x)`` with Anderson acceleration below ``anderson_from`` (module docstring); with
    ``jacobian`` (``K(x, *extra)``, :class:`MapJacobian`), the Newton phase (:func:`active_set_newton`) once
    the residual is below ``newton_from``, and Anderson from its best state if it stops short.

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
            nb, nk, nr = active_set_newton(G, jacobian, (x, gx, *extra), scale, target=target,
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


def active_set_newton(G, jacobian, start, scale, *, target, max_evaluations):
    """Newton's method on ``G(x) − x = 0`` with the Jacobian of every iterate, plain steps where it does not
    serve: ``d = (I − K)⁻¹ (G(x) − x)``, ``K = jacobian(x, *extra)`` on the active sets of the map's QP
    answers at ``x``.

    ``G`` is piecewise affine (affine while its QPs keep their active sets), so the full step ``x + d`` is
    the active-set (semismooth) Newton step of the steady problem seen through the march: it lands on the
    fixed point of the affine piece it starts on, and once the active sets are the fixed point's, on the
    fixed point itself. Far from it the step can wander between pieces; the step is kept only if the
    correction at its end is smaller, ``|d̄| < |d|`` (the natural monotonicity test of affine-invariant
    Newton methods, Deuflhard, *Newton Methods for Nonlinear Problems* §3.1, with the Jacobian of each
    iterate: the residual ``max|G(x) − x|`` is no measure of the distance here, the march contracting by
    only a few per cent a step). Else the iteration takes plain marching steps ``x ← G(x)`` from ``x`` —
    1, 2, 4, … in a row between two refused Newton steps, so that far from steady it is the march itself,
    with few Jacobians — and tries Newton again. Measured (the march maps of CONTACT's Bentall grid at 216
    and 432 elements, goodman-bentall at μ = 0.3 and 0.05 with full and Goodman coupling, harmonic and
    §6.1.1's rollers, from the rolling start's guess and from the braked state): 4–63 map evaluations,
    where the plain march needs hundreds and full Newton steps alone wandered on the finer grid.

    Stops at the residual ``target``, where ``jacobian`` gives None (a singular QP sensitivity), after
    :data:`REFUSALS` refused Newton steps in a row, after :data:`HALVING` accepted ones that did not halve
    the correction, and after ``max_evaluations``. Returns ``(best,
    evaluations, best residual)`` as :func:`fixed_point`.
    """
    x, gx, *extra = start
    best, best_r, k, plain = start, _residual(x, gx, scale), 0, 1
    refused, since, level = 0, 0, np.inf

    def correction(x, gx, extra):
        K = jacobian(x, *extra)
        if K is None:
            return None
        try:
            return np.linalg.solve(np.eye(x.size) - K, gx - x)
        except np.linalg.LinAlgError:
            return None

    d = correction(x, gx, extra)
    while d is not None and k < max_evaluations and best_r > target:
        k += 1
        out, dt = _evaluate(G, x + d), None
        if out is not None:
            rt = _residual(out[0], out[1], scale)
            if rt < best_r:
                best, best_r = out, rt
            if rt <= target:
                break
            dt = correction(*out[:2], out[2:])
        if dt is not None and np.abs(dt).max() < np.abs(d).max():
            (x, gx, *extra), d, plain, refused = out, dt, 1, 0
            size = float(np.abs(d).max())
            since, level = (0, size) if size <= 0.5 * level else (since + 1, level)
            if since >= HALVING:
                break
            continue
        refused, level = refused + 1, np.inf
        if refused >= REFUSALS:
            break
        for _ in range(min(plain, max_evaluations - k)):  # Newton refused: plain steps of the march
            k += 1
            x, (gx, *extra) = gx, G(gx)
            r = _residual(x, gx, scale)
            if r < best_r:
                best, best_r = (x, gx, *extra), r
            if r <= target:
                break
        plain *= 2
        d = correction(x, gx, extra)
    return best, k, best_r


def _evaluate(G, x):
    """``(x, G(x), *extra)``, or None where the map fails (a QP not solved at an iterate far off)."""
    try:
        return (x, *G(x))
    except (SolverError, InputError):
        return None


def _residual(x, gx, scale) -> float:
    r = float(np.abs(gx - x).max()) / scale
    return r if np.isfinite(r) else np.inf


class MapJacobian:
    r"""``K = ∂G/∂t``: the march map's Jacobian on the active sets of its QP answers (QP sensitivity).

    On fixed active sets each half's answer is affine in its data: with the free set ``F`` and the
    nodes at a bound ``A`` of a QP (:class:`~rollqp.problem.QPForm`), ``dx_A`` is the bounds'
    change and ``dx_F = H_FF⁻¹ dr − z (a_Fᵀ H_FF⁻¹ dr − dβ)/(a_Fᵀ z)``, ``z = H_FF⁻¹ a_F``, with
    ``dr = −dq_F − H_FA dx_A`` and ``dβ = −a_Aᵀ dx_A`` (the load row's right-hand side fixed). The
    map's data depend on ``t`` through the normal half's gap offset ``A_nt t`` (``dq = ∂q/∂e · A_nt dt``,
    :attr:`QPForm.shift_scale`), the history ``c = −M w(p, t)`` of the tangential half, whose own
    history is ``c + A_tn p`` (so ``dc = (I − M) A_tn dp − M A_tt dt``), and its bounds ``±μ p⁺``.
    The operator of each half is the collocation operator of its QP form
    (:func:`~rollqp.methods._qp.collocation_operator`: the Hessian ``sym(F·A)`` with the skew part put
    back, what the splitting's answer solves), so ``K`` is the map's Jacobian for every element type (with
    the Hessian alone it is an approximation for an asymmetric ``F·A``, and the Newton phase converges
    only linearly on QCE: 32 map evaluations on goodman-bentall's rolling start, 9 with the exact ``K``).
    Dense ``n × n`` products, ``O(n³)`` a call.
    """

    def __init__(self, ops, *, P, Q, xi, dq, M, delta, caches=(None, None)):
        self.ops, self.M, self.data = ops, M, dict(P=P, Q=Q, xi=xi, dq=dq, delta=delta)
        self.caches = caches  # (Cholesky, LU) KKTCaches of the map's QP method: the same free sets, factored once
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
            half = step.normal_half(t)
            fn = half.qp_form()
            Jn = qp_response(fn, nsol.p / stress, nsol.info["qp_multiplier"], fn.shift_scale[:, None] * self.Ant,
                             E=_collocation(half, fn), caches=self.caches)
            if Jn is None:
                return None
            Jn *= stress  # dp/dt
            dc = self.ImMAtn @ Jn - self.MAtt
            dbound = (ops.mu / stress) * (nsol.p > 0)[:, None] * Jn
            half = ops.coupled_step(d["P"], c, d["dq"], Q=d["Q"], xi=d["xi"], delta=d["delta"]).tangential_half(nsol.p)
        else:
            dc, dbound = -self.MAtt, None
            half = ops.tangential_step(nsol.p, c, d["dq"], Q=d["Q"], xi=d["xi"])
        ft = half.qp_form()
        Jt = qp_response(ft, tsol.t / stress, tsol.info["qp_multiplier"], ft.shift_scale[:, None] * dc, dbound,
                         E=_collocation(half, ft), caches=self.caches)
        return None if Jt is None else stress * Jt


def _collocation(problem, form):
    """The collocation operator of ``problem``'s QP ``form`` (:func:`~rollqp.methods._qp.collocation`), or None
    where ``F·A`` is symmetric (the Hessian is the operator)."""
    return collocation(problem, form) if problem.A.split(problem.f).asymmetry > 0 else None


def qp_response(form, x, y, dq, dbound=None, E=None, caches=(None, None)):
    """``dx``: the change of the QP answer ``x`` (multiplier ``y``) with ``q`` changed by ``dq`` and the
    bounds' magnitude (``upper = −lower``) by ``dbound`` (columns: directions), on the active set of
    ``(x, y)`` read as :func:`~rollqp.methods._qp.active_set_refine` reads it, and with the nodes on a
    bound counted at it (:class:`MapJacobian`). Solved with :func:`~rollqp.methods._qp.active_set_refine`'s
    factors (the Cholesky factor of ``H_FF`` and the load row's Schur complement); None if singular.
    ``E``: the collocation operator in place of the Hessian (:class:`MapJacobian`; LU factors); ``caches``:
    ``(Cholesky, LU)`` :class:`~rollqp.methods._qp.KKTCache` objects to take the factors from (the QP method's)."""
    H, a = (form.H if E is None else E), form.a
    lam = H @ x + form.q + (0.0 if a is None else float(y) * a)
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
    cache = caches[0 if E is None else 1]
    fac = cache.get(H, free, a) if cache is not None else (_kkt_factor if E is None else _kkt_lu)(H, free, a)
    if fac is None:
        return None
    chol, z2, schur = fac
    z = (_chol_solve if E is None else _lu_solve)(chol, -dq[F] - H[F] @ dx)  # dx is zero on F: H[F] dx = H_FA dx_A
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
