"""The transient: integration over the rolled distance as a stream of step records (paper §4.1, §4.4).

:func:`march` yields one :class:`StepRecord` per state of the result file; :func:`run`
collects them into a :class:`~rollqp.result.Result`. Anything that observes or extends the
transient — the step files (:mod:`rollqp.stepfile`), the cross-validation report, the
benchmarks, post-processing — consumes the records; it needs no private call. The phases
(docs/formulation.md §9):

* **starting state** (record ``k = 0``):

  - ``start = "braked"`` (phase ``"static-shift"``): the normal load is applied (Hertz for
    similar bodies), then the tangential load by static shift in ``load.start_steps``
    increments (Cattaneo for similar bodies, §4.4): ``s = (w^k − w^{k−1})/Δ + ξ`` with
    ``Δ = a_H`` and ``ξ·Δ`` the rigid shift;
  - ``start = "rolling"``: steady rolling at the initial loads, the fixed point of the rolling
    steps that follow. From the loads' normal half at zero shear (:meth:`_March.pressed`; no
    braked start: the steady state does not depend on the loading path), a method that declares
    ``"steady"`` (:attr:`Capabilities.solves <rollqp.methods.base.Capabilities.solves>`) solves the
    steady problem directly (phase ``"steady"``; slip ``s = ξ e + T w``, ``T = (I − M)/Δq``,
    :meth:`SceneOperators.steady <rollqp.operators.SceneOperators.steady>`); the others
    (the QP backends: the steady operator is far from symmetric and their splitting does not
    converge on it) reach it by marching the transient at constant loads until the tractions
    stop changing (phase ``"rolling"``).
* **rolling steps** ``k = 1..K`` at ``q_k = k Δq`` (phase ``"rolling"``): the history vector
  ``c^{k−1} = −M w^{k−1}`` (:meth:`~rollqp.strip.Strip.history_operator`), the loads
  ``P(q_k)``, ``Q(q_k)``, and each half warm-started from the previous step. With
  ``load.rolled`` (:mod:`rollqp.kinematics`) the steps are ``τ_k``, the loads ``P(τ_k)``, …, each
  step's ``M`` is that of its own ``|Δq_k|`` and direction (a reversal flips the shift and upwind
  operators, eq. 32–40), and a stop (Δq_k = 0) is a static-shift step (phase ``"static-shift"``);
  a profile that moves (:mod:`rollqp.profiles`) gives each step its own undeformed gap.
* **contact lost** (``P(q) = 0``): an unloaded state (:func:`_unloaded`), nothing solved;
  **frictionless** (``μ = 0``): the normal half alone, ``t = 0`` (:func:`_frictionless`);
* **gross sliding** (only with a prescribed creepage beyond the sliding creepage; a prescribed
  ``|Q| >= μP`` is rejected by the scene): solved, and marked in the record (``gross_sliding``);
* **failures**: a :class:`~rollqp.errors.SolverError` names the step (0: the start) and
  rollqp's residual; :func:`run` attaches the completed states as ``err.partial``.

Only what the scene needs is modelled: with no shear feedback (``A_nt`` absent) and a constant
normal load the normal half is solved once and reused; coupling operators exist only for the
coupling level asked for (:class:`~rollqp.operators.SceneOperators`).
"""
from __future__ import annotations

import dataclasses
import os
import time
from dataclasses import dataclass, field
from typing import Iterator

import numpy as np

from ..advice import fast_path
from ..atomic import stop_once
from ..errors import InputError, SolverError
from ..fields import fields_for
from ..friction.bound import steady_branches
from ..kinematics import HistoryCache, plan
from ..methods import compose, scene_method
from ..methods.steady_start import accelerated_start, predicting
from ..operators import SceneOperators
from ..problem import SLIP, STICK, State, StepSolution, classify
from ..result import Result, ResumeSource, check_output, resume_source
from ..scene import Scene, load_scene
from ..scene.checks import check_result_memory
from ..solverstate import Recorder, restore
from ..strip import RowSparse
from ..version import __version__
from .loop import RESUME_TOL, check_earlier, check_last, drive, last_index, stored_steps, versions
from .loop import keep_every as _keep_every

__all__ = ["State", "StepRecord", "march", "run", "prepare"]

#: Rolling start by marching: stop when max|Δt| per step is below this fraction of μp0
#: (a hundred times above the QP solvers' step-to-step noise of ~1e-10, and far below
#: the discretization error of ~1e-3) …
STEADY_TOL = 1e-8
#: … or after this many a_H of rolling (Carter's transient dies out within ~3 a_H).
STEADY_MAX_DISTANCE = 40.0
#: A rolling step that is its tangential half alone (a fixed normal half, one Coulomb μ, uncoupled, the
#: scene's Δq and profile) takes :meth:`_March._tangential_only`: the general step written out for
#: that case, the same calls and numbers without the general step's branches (a tenth of the step at 81 nodes:
#: docs/performance.md). ``False``: every step takes the general path (tests/test_perf_paths.py compares them).
FAST_ROLLING_STEP = True


@dataclass
class Counters:
    """What the solves of one state report to the result file."""

    iterations: int = 0          # the method's iterations (N–T: outer iterations), all solves of the state
    residual: float = 0.0        # the largest rollqp residual of those solves
    inner_normal: int = 0        # iterations of the normal halves
    inner_tangential: int = 0    # iterations of the tangential halves
    backtracks: int = 0          # Armijo step reductions (Newton)

    def add(self, sol, half=None):
        """Count a solution of a normal or tangential half (two-QP path)."""
        self.iterations += sol.iterations
        if half == "normal":
            self.inner_normal += sol.iterations
        elif half == "tangential":
            self.inner_tangential += sol.iterations
        self.backtracks += sol.backtracks
        self._residual(sol.residual)

    def add_coupled(self, sol):
        """Count a coupled solution: Newton iterations, or N–T outer and inner iterations."""
        self.iterations += sol.iterations
        self.inner_normal += sol.inner_normal
        self.inner_tangential += sol.inner_tangential
        self.backtracks += sol.backtracks
        self._residual(sol.residual)

    def _residual(self, r: float) -> None:
        """The largest residual so far; a NaN stays (the builtin ``max`` would drop it when it comes second)."""
        if r > self.residual or r != r:
            self.residual = r


@dataclass
class StepRecord:
    """One state of the transient and the last solve that produced it.

    Attributes
    ----------
    k : int
        Index of the state in the result file (0: the starting state).
    phase : {"static-shift", "steady", "rolling"}
        How the last solve posed the slip: static shift (braked start), the steady-rolling
        problem (direct rolling start), or a rolling step.
    q : float
        Rolled distance (length units).
    P : float
        Normal load (prescribed, or ``fᵀp`` when the approach is prescribed).
    Q : float
        Tangential load ``fᵀt`` on body A.
    state : State
        The state after the step.
    previous : State
        The state the last solve started from.
    problem : NormalStep, TangentialStep or CoupledStep or None
        The last tangential or coupled problem solved (``None``: nothing was solved, contact lost).
    solution : StepSolution or None
        Its solution.
    counters : Counters
    shift : float
        Rigid static shift of a braked start (zero for rolling states).
    step_time : float
        Wall seconds of the state (every solve behind it).
    nodes : ndarray of int8
        0 separation, 1 stick, 2 slip.
    gross_sliding : bool
        Every contact node slips (possible only with a prescribed creepage).
    tau : float or None
        The time-like parameter τ_k (length units; :mod:`rollqp.kinematics`), None for the start.
    direction : int
        Direction of the material in the step (±1), 0 for a static shift.
    note : str or None
        What the record's solve did instead of the usual (a rolling start marched because the
        direct steady solve failed: :meth:`_March.rolling_start`); the result keeps it in
        ``meta["start_note"]``.
    """

    k: int
    phase: str
    q: float
    P: float
    Q: float
    state: State
    previous: State
    problem: object
    solution: StepSolution | None
    counters: Counters
    shift: float
    step_time: float
    nodes: np.ndarray = field(repr=False, default=None)
    gross_sliding: bool = False
    tau: float | None = None
    direction: int = 0
    note: str | None = None
    #: What the method carries to the next step, for the journal (:mod:`rollqp.solverstate`; ``None``
    #: unless the march records it)
    solver: dict | None = field(repr=False, default=None)

    @property
    def normal(self):
        """``(NormalStep, StepSolution)`` of the normal half in effect, or ``None`` (coupled step, no contact)."""
        st = self.state
        return None if st.normal is None else (st.normal, st.nsol)


class _March:
    """The march of one scene with one method: the step logic, one small method per phase."""

    def __init__(self, scene: Scene, ops: SceneOperators, method):
        self.scene, self.ops, self.method = scene, ops, method
        self.plan = plan(scene)
        self.moving = ops.profiles_move
        self.cache = HistoryCache(ops) if self.plan.rolled else None
        self.frictionless = ops.frictionless  # the scene's law: the same at every step
        self.constant_friction = ops.friction.kind == "constant"  # one μ: the step problems' fast path
        self.at = self._loads_at(self.plan.tau)
        self.fixed = self._normal_fixed()
        # a rolling step is its tangential half alone (:meth:`_tangential_only`): a fixed normal half, Coulomb's one
        # μ, uncoupled, the scene's Δq and profile
        self.plain = (FAST_ROLLING_STEP and self.fixed and self.constant_friction and not ops.coupled
                      and not self.frictionless and not self.moving and not self.plan.rolled)
        self._last_contact = self._negated = None  # (p, p > 1e-7 p0) of the last record; (M, −M dense or None)

    def _loads_at(self, tau) -> list:
        """``(τ, d, P, Q, ξ, δ)`` at each step of the plan: ``d`` its direction; the normal load ``P`` (None
        when the approach ``δ`` is prescribed, else ``δ`` is None); the tangential load ``Q`` or the
        prescribed creepage ``ξ`` (the other None). Each history is evaluated once over the whole plan:
        the same numbers as one τ at a time (tests/test_dense_path.py). Step 0 (τ = 0) is the start's."""
        sc = self.scene
        n = tau.size
        none = [None] * n
        P = none if sc.load.approach is not None else sc.normal_load(tau).tolist()
        Q, xi = (none, sc.prescribed_creepage(tau).tolist()) if sc.load.creepage is not None else \
            (sc.tangential_load(tau).tolist(), none)
        D = none if sc.load.approach is None else sc.prescribed_approach(tau).tolist()
        return list(zip(tau.tolist(), self.plan.d.tolist(), P, Q, xi, D))

    def _normal_fixed(self) -> bool:
        """The normal step cannot change: no shear feedback (A_nt absent), a fixed profile, and the same
        normal load (or approach) at every step."""
        if self.ops.Ant is not None or self.moving:
            return False
        first = self.at[0]
        return all(a[2] == first[2] and a[5] == first[5] for a in self.at)

    # ------------------------------------------------------------ one step
    def step(self, state: State, cnt: Counters, *, P, c, dq, Q=None, xi=None, normal_fixed=False,
             steady=False, delta=None, h=None, q=0.0, transport=None):
        """One step (rolling, static shift or steady): ``(new state, problem, solution)``.

        ``h``: the gap of a moving profile (else the operators' own); ``q`` places a friction law
        that varies along the surface; ``transport`` (the step's rolled distance, rolling steps
        only) carries a friction memory with the material."""
        ops, meth = self.ops, self.method
        if P is not None and P <= 0.0:  # contact lost (the scene allows P = 0 only with Q = 0)
            return _unloaded(ops, xi), None, None
        if self.frictionless:
            return self._frictionless(state, cnt, P=P, c=c, dq=dq, xi=xi, steady=steady, delta=delta, h=h)
        fr = None
        if not self.constant_friction:  # a law: this step's μ (Coulomb keeps the fast path)
            prev = None if state.tsol is None else state.tsol.mu
            fr = ops.step_friction(q, dq=transport, previous=prev, steady=steady)
        if ops.coupled:
            pb = ops.coupled_step(P, c, dq, Q=Q, xi=xi, steady=steady, delta=delta, h=h, friction=fr)
            sol = meth.solve(pb, warm=state.tsol)
            cnt.add_coupled(sol)
            _keep_mu(pb, sol)
            return State(sol.p, sol.t, ops.w(sol.p, sol.t), sol, sol, None), pb, sol
        nsol, npb = state.nsol, state.normal
        if not normal_fixed or nsol is None:
            # goodman/off: the normal half does not see t (A_nt = 0); offset kept for generality
            npb = ops.normal_step(P, state.t, delta=delta, h=h, validate=False)
            nsol = meth.solve(npb, warm=state.nsol)
            cnt.add(nsol, "normal")
        pb = ops.tangential_step(nsol.p, c, dq, Q=Q, xi=xi, steady=steady, friction=fr, validate=False)
        tsol = meth.solve(pb, warm=state.tsol)
        cnt.add(tsol, "tangential")
        _keep_mu(pb, tsol)
        return State(nsol.p, tsol.t, ops.w(nsol.p, tsol.t, _product(tsol, pb, ops.Att)), nsol, tsol, npb), pb, tsol

    def _frictionless(self, state, cnt, *, P, c, dq, xi=None, steady=False, delta=None, h=None):
        """A step at ``μ = 0``: ``t = 0`` (the bound ``μp`` is zero at every node), the normal half alone.

        The tangential problem is degenerate (every node on the kink ``|t| = μp = 0``, no node can
        stick, so the load row ``fᵀt = Q = 0`` has no ``ξ`` column): nothing is solved for it. The
        creepage is not determined by the contact (the surfaces slide freely); it is the prescribed
        one, else reported as 0, and the slip follows from it and ``w`` as in any step. With
        ``t = 0`` the coupled step reduces to its normal half too (``A_nt t = 0``).
        """
        ops = self.ops
        zero = np.zeros(ops.n)
        npb = ops.normal_step(P, zero, delta=delta, h=h)
        nsol = self.method.solve(npb, warm=state.nsol)
        cnt.add(nsol, "normal")
        xi = 0.0 if xi is None else float(xi)
        pb = ops.tangential_step(nsol.p, c, dq, xi=xi, steady=steady)
        tsol = pb.solution(zero, xi)
        tsol.method, tsol.status = "frictionless", "frictionless"
        return State(nsol.p, zero, ops.w(nsol.p, zero), nsol, tsol, npb), pb, tsol

    def record(self, k, phase, q, state, previous, problem, sol, cnt, *, P, shift, t0) -> StepRecord:
        ops = self.ops
        tsol = state.tsol
        mu = ops.mu if problem is None or self.constant_friction else problem.coefficient(tsol.s, tsol.p)
        bound = None if problem is None or problem.kind != "tangential" else \
            problem.bound if problem.law is None else problem.bound_at(tsol.s)
        nodes = classify(state.p, state.t, tsol.s, mu, ops.scales, bound=bound, contact=self._contact(state.p))
        count = np.bincount(nodes, minlength=3).tolist()
        gross = bool(count[SLIP] and not count[STICK])
        f = ops.f
        # (the fields in their order: keywords cost a step as much as a dot product)
        return StepRecord(k, phase, float(q), float(f @ state.p) if P is None else P, float(f @ state.t), state,
                          previous, problem, sol, cnt, shift, time.perf_counter() - t0, nodes, gross)

    def _contact(self, p):
        """``p > 1e-7·p0`` (:func:`~rollqp.problem.classify`'s contact), kept while the pressure is the same array (a
        fixed normal half hands the same one to every step)."""
        last = self._last_contact
        if last is None or last[0] is not p or p is None:
            last = self._last_contact = (p, None if p is None else np.asarray(p, dtype=float) > 1e-7 * self.ops.scales.stress)
        return last[1]

    def history_term(self, M, w):
        """``c = −M w``, the history vector (eq. 37, 48). A :class:`~rollqp.strip.RowSparse` ``M`` small enough to be
        multiplied as a dense matrix (:data:`~rollqp.strip.RowSparse.DENSE_MAX`) is multiplied so, negated once: the
        same numbers (a negation is exact, and so is each sum with every term's sign flipped), one operation less."""
        last = self._negated
        if last is None or last[0] is not M:
            small = isinstance(M, RowSparse) and M.shape[0] * M.shape[1] <= RowSparse.DENSE_MAX
            last = self._negated = (M, -M.dense() if small else None)
        return -(M @ w) if last[1] is None else last[1].dot(w)  # (ndarray.dot: @'s numbers, without matmul's dispatch)

    # ------------------------------------------------------------ the phases
    def start(self) -> StepRecord:
        """State 0: the braked start, or the rolling start (``load.start``)."""
        return self.rolling_start() if self.scene.load.start == "rolling" else self.braked_start()

    def braked_start(self):
        """Step 0 of a braked start (§2.2, §4.4; docs/formulation.md §9), by static shift.

        1. The normal load in ``load.start_steps`` quasi-static increments at ``Q = 0``. With
           coupling (β ≠ 0, ``goodman`` or ``full``) the pressure displaces the surfaces
           tangentially and friction resists: the Goodman-type starting state. Without coupling
           the shear stays zero and the normal load is applied at once (path independent).
        2. The tangential load in ``load.start_steps`` increments (Cattaneo for similar bodies).

        Static-shift slip: ``s = ξ + (w^j − w^{j−1})/Δ`` with ``Δ = a_H`` and ``ξ·Δ`` the rigid
        shift increment, accumulated in the record's ``shift``.
        """
        scene, ops = self.scene, self.ops
        t0 = time.perf_counter()
        _, _, P, Q, _, D = self.at[0]  # a prescribed approach D is applied like the load, in start_steps parts
        Qtarget = Q if Q is not None else 0.0
        n = ops.n
        N = scene.load.start_steps
        delta = ops.scales.length
        cnt = Counters()
        state = previous = State(None, np.zeros(n), np.zeros(n))  # unloaded bodies
        problem = sol = None
        shift = 0.0
        N0 = P if D is None else D
        if ops.Atn is not None:
            loading = [(N0 * j / N, 0.0) for j in range(1, N + 1)]
        else:  # no coupling: the shear of a normal load is zero, so go straight to Q (Hertz, then Cattaneo)
            loading = [] if Qtarget != 0.0 else [(N0, 0.0)]
        if Qtarget != 0.0:
            loading += [(N0, Qtarget * j / N) for j in range(1, N + 1)]
        Pprev = None
        for Pj, Qj in loading:
            # the normal half is re-solved only if P changed or the shear feeds back (A_nt)
            previous = state
            state, problem, sol = self.step(state, cnt, P=None if D is not None else Pj, c=-state.w, dq=delta,
                                            Q=Qj, normal_fixed=(Pj == Pprev and ops.Ant is None),
                                            delta=None if D is None else Pj)
            Pprev = Pj
            shift += state.tsol.xi * delta
        ops.check_inside(state.p, 0)
        return self.record(0, "static-shift", 0.0, state, previous, problem, sol, cnt, P=P, shift=shift, t0=t0)

    def pressed(self) -> State:
        """The starting guess of a rolling start: the loads' normal half at zero shear, nothing else.

        The steady rolling state does not depend on how the loads were applied (the rolling wipes
        the contact's memory), so a rolling start needs no braked start (``load.start_steps``
        static increments, each a coupled step on coupled scenes): the normal half at ``P(0)`` (or
        ``δ(0)``) with ``t = 0`` (one solve; ``w = A_tn p``) is where the direct steady solve and
        the march to the steady state set out from.
        """
        ops = self.ops
        _, _, P, _, xi, D = self.at[0]
        if P is not None and P <= 0.0:
            return _unloaded(ops, xi)
        zero = np.zeros(ops.n)
        npb = ops.normal_step(P, zero, delta=D, validate=False)
        nsol = self.method.solve(npb, warm=None)
        return State(nsol.p, zero, ops.w(nsol.p, zero), nsol, None, None if ops.coupled else npb)

    def guess(self) -> State:
        """Where a rolling start sets out from: :meth:`pressed`, or, with a slip-dependent friction law,
        the braked state (:meth:`braked_start`). A falling law can have two steady states at one force, and
        the guess decides which one the start returns: from the braked state it is the one that grows
        from Coulomb's (docs/friction.md, "Which steady state a rolling start returns")."""
        if self.ops.friction.kind == "slip":
            return self.braked_start().state
        return self.pressed()

    def rolling_start(self) -> StepRecord:
        """Rolling start from the guess (:meth:`guess`): the direct steady solve for a method that declares
        ``"steady"``, else, or if that solve fails, the march to the steady state (its record then says why
        in ``note``: the march reaches the same discrete state, to :data:`STEADY_TOL`). A QP method solves
        the guess's QPs with the active-set prediction on (:meth:`QPMethod.predicting
        <rollqp.methods._qp.QPMethod.predicting>`: a guess, not a state that is kept)."""
        was = predicting(self.method, True)
        try:
            start = self.guess()
        finally:
            if was is not None:
                predicting(self.method, was)
        if "steady" not in self.method.capabilities.solves:
            return self.steady_by_marching(start)
        try:
            return self.steady_direct(start)
        except SolverError as err:
            rec = self.steady_by_marching(start)
            rec.note = f"the direct steady solve failed ({err}); the steady state was reached by marching"
            return rec

    def steady_direct(self, start: State) -> StepRecord:
        """Rolling start: the steady rolling problem ``s = ξ e + T w`` solved directly (``T``: the
        fixed point of the scene's transient step, :meth:`SceneOperators.steady
        <rollqp.operators.SceneOperators.steady>`).

        Not symmetric (``T A`` is not), so only methods that declare ``"steady"`` pose it;
        set out from the guess ``start``.
        """
        t0 = time.perf_counter()
        _, _, P, Q, xi, D = self.at[0]
        cnt = Counters()
        state, problem, sol = self.step(start, cnt, P=P, c=np.zeros(self.ops.n), dq=self.ops.scales.length,
                                        Q=Q, xi=xi, steady=True, delta=D)
        self.ops.check_inside(state.p, 0)
        rec = self.record(0, "steady", 0.0, state, start, problem, sol, cnt, P=P, shift=0.0, t0=t0)
        if problem is not None and problem.law is not None and Q is not None:
            rec.note = steady_branches(problem.law.law, Q, rec.P, rec.gross_sliding)
        return rec

    def steady_by_marching(self, start: State) -> StepRecord:
        """Rolling start: roll at the initial loads until the tractions stop changing.

        For methods that cannot pose the non-symmetric steady problem (``STEADY_TOL``,
        ``STEADY_MAX_DISTANCE``). A QP method first takes the accelerated start
        (:mod:`rollqp.methods.steady_start`), then marches with its QPs solved on their predicted
        active sets (:func:`~rollqp.methods.steady_start.predicting`) until a step changes the state by
        less than ``STEADY_TOL``, and on with the backend (and the N–T alternation converged) until
        one does again: the state kept is the backend's.
        """
        scene, ops = self.scene, self.ops
        t0 = time.perf_counter()
        _, _, P, Q, xi, D = self.at[0]
        cnt = Counters()
        M = ops.history()
        max_steps = int(np.ceil(STEADY_MAX_DISTANCE * scene.a_H / scene.dq))
        change = np.inf
        state = accelerated_start(self.method, ops, start, cnt, P=P, Q=Q, xi=xi, dq=scene.dq, M=M,
                                  delta=D, tol=STEADY_TOL)  # QP methods: Newton on the march's map, Anderson
        # N–T alternation: one sweep a step until near steady
        sweeps = self.method.single_sweeps if self.method.capabilities.single_sweeps else None
        if sweeps is not None:
            sweeps(True)
        was = predicting(self.method, True)  # QP methods: each QP on its predicted active set first, until steady
        try:
            for _ in range(max_steps):
                previous = state
                state, problem, sol = self.step(state, cnt, P=P, c=-(M @ state.w), dq=scene.dq, Q=Q, xi=xi,
                                                normal_fixed=self.fixed, delta=D, transport=scene.dq)
                change = np.max(np.abs(state.t - previous.t)) / (max(ops.mu, 1e-300) * ops.scales.stress)
                if not self.fixed:
                    change = max(change, np.max(np.abs(state.p - previous.p)) / ops.scales.stress)
                if change < STEADY_TOL:
                    one_sweep = sweeps is not None and sweeps(False)
                    if one_sweep:
                        cnt.residual = 0.0  # one sweep stops short of the coupled limit by design: report the converged steps'
                    if one_sweep | bool(predicting(self.method, False)):
                        continue  # then full steps (converged alternation, the backend's QPs) until steady again
                    break
            else:
                if sweeps is not None:
                    sweeps(False)
                raise SolverError(f"the rolling start did not reach a steady state within {STEADY_MAX_DISTANCE} a_H "
                                  f"(last change {change:.2e} mu p0)", method=self.method.name, step=0)
        finally:
            if was is not None:
                predicting(self.method, was)
        return self.record(0, "rolling", 0.0, state, previous, problem, sol, cnt, P=P, shift=0.0, t0=t0)

    def _transport(self, k: int, dq: float) -> float:
        """The step's signed rolled distance ``q_k − q_{k−1}`` (a load path rolls back with ``Δq < 0``),
        which carries a friction law's memory with the material; ``dq`` itself without ``load.rolled``."""
        pl = self.plan
        return float(pl.q[k] - pl.q[k - 1]) if pl.rolled else dq

    def rolling(self, k: int, q: float, state: State, M) -> StepRecord:
        """Step ``k`` of the plan (:mod:`rollqp.kinematics`): rolling by Δq_k in its direction, or a stop.

        Without ``load.rolled``: a rolling step at ``q = k·Δq`` with the scene's ``M``. With it: the
        loads at τ_k; a stop is a static shift (``c = −w^{k−1}``, ``Δ = a_H``, the rigid shift ξ·Δ
        recorded in ``shift``), a rolling step uses ``M`` of its own ``|Δq_k|`` and direction.
        """
        t0 = time.perf_counter()
        tau, d, P, Q, xi, D = self.at[k]
        if self.plain and d != 0 and state.nsol is not None and (P is None or P > 0.0):
            return self._tangential_only(k, q, state, M, t0, tau, d, P, Q, xi)
        scene, pl = self.scene, self.plan
        cnt = Counters()
        h = self.ops.gap(q) if self.moving else None
        if d == 0:  # a stop: static shift under the loads of τ_k (§4.4)
            c, dq, phase = -state.w, self.ops.scales.length, "static-shift"
        elif pl.rolled:
            c, dq, phase = -(self.cache.get(float(pl.dq[k]), d) @ state.w), float(pl.dq[k]), "rolling"
        else:
            c, dq, phase = self.history_term(M, state.w), scene.dq, "rolling"
        new, problem, sol = self.step(state, cnt, P=P, c=c, dq=dq, Q=Q, xi=xi,
                                      normal_fixed=self.fixed, delta=D, h=h,
                                      q=q, transport=self._transport(k, dq) if phase == "rolling" else None)
        if not self.fixed:
            self.ops.check_inside(new.p, k)
        shift = new.tsol.xi * dq if d == 0 else 0.0
        rec = self.record(k, phase, q, new, state, problem, sol, cnt, P=P, shift=shift, t0=t0)
        rec.tau, rec.direction = tau, d
        return rec


    def _tangential_only(self, k, q, state, M, t0, tau, d, P, Q, xi) -> StepRecord:
        """:meth:`rolling` where the step is its tangential half alone (:attr:`plain`: the normal half of ``state``
        kept, Coulomb's one ``μ``, the scene's ``Δq``): :meth:`step` written out for that case, the same calls and
        numbers without the branches and keywords of the general step (at 81 nodes they cost a tenth of the
        step)."""
        ops = self.ops
        nsol = state.nsol
        p = nsol.p
        pb = ops.tangential_step(p, self.history_term(M, state.w), self.scene.dq, Q, xi, False, None, False)
        tsol = self.method.solve(pb, state.tsol)
        cnt = Counters()
        cnt.add(tsol, "tangential")
        t = tsol.t
        new = State(p, t, ops.w(p, t, _product(tsol, pb, ops.Att)), nsol, tsol, state.normal)
        rec = self.record(k, "rolling", q, new, state, pb, tsol, cnt, P=P, shift=0.0, t0=t0)
        rec.tau, rec.direction = tau, d
        return rec


def _two_d(scene) -> Scene:
    """``scene`` if it is a 2D scene, else a one-line :class:`InputError` naming the 3D entry points."""
    if not isinstance(scene, Scene):   # another dimension's scene (docs/architecture.md, three dimensions)
        raise InputError("scene", f"{scene.name!r} is a {scene.dimension}D scene: rollqp.march.strip runs the strip; "
                                  "rollqp.march.run and rollqp.march.march run either (on the command line: rollqp run)")
    return scene


def prepare(scene, method=None, *, geometry=None):
    """``(scene, method, operators)``: the scene validated, its method composed and set up on its operators.

    Parameters
    ----------
    scene : Scene, str or path
        A scene object, a TOML path, or a built-in name.
    method : str or Method, optional
        A method name (overrides ``[solver].method``) or a method object (used as it is, composed
        with the N–T alternation if the scene is coupled and it does not solve coupled steps).
    geometry : Memo, optional
        Where the influence model keeps what depends on the bodies alone, shared by the scenes it is
        handed to (:meth:`SceneOperators.build <rollqp.operators.SceneOperators.build>`).
    """
    scene = _two_d(scene if isinstance(scene, Scene) else load_scene(scene))
    if isinstance(method, str) and method != scene.solver.method:
        scene = scene.replace(**{"solver.method": method})
    if method is None or isinstance(method, str):
        scene = fast_path(scene).scene  # matrix-free where the dense path is large or slow (rollqp.advice)
    coupled = scene.coupling_level == "full"
    kind = scene.contact.friction.kind
    if method is None or isinstance(method, str):
        meth = scene_method(scene.solver, coupled=coupled, friction=kind)
    else:
        meth = compose(method, coupled, max_outer=scene.solver.max_iterations, friction=kind)
    caps = meth.capabilities
    ops = SceneOperators.build(scene, symmetrized=caps.operator == "symmetrized", capabilities=caps, geometry=geometry)
    meth.setup(ops)
    return scene, meth, ops


def march(scene, method=None, *, prepared=None, resume=None, verify=True, record=False,
          state=None, _march=None) -> Iterator[StepRecord]:
    """The transient of ``scene`` as a stream of :class:`StepRecord` (module docstring).

    Parameters
    ----------
    scene : Scene, str or path
        A scene object, a TOML path, or a built-in name.
    method : str or Method, optional
        A method name (overrides ``[solver].method``) or a method object (:func:`prepare`).
    prepared : tuple, optional
        ``(scene, method, operators)`` from :func:`prepare` (to look at the operators first).
    resume : dict, optional
        The arrays of a result file of this scene (:func:`~rollqp.result.load_result`, or
        :meth:`ResumeSource.tail <rollqp.result.ResumeSource.tail>`): the march continues after its
        last state (:func:`resumed_state`) and yields only the steps after it.
    verify : bool
        With ``resume``: check first that the last stored state solves its own step
        (:func:`check_resumed`, which also rebuilds what the method carried across steps).
    record : bool or Recorder
        Record with each state what the method carries to the next step (``StepRecord.solver``, for the
        journal; :mod:`rollqp.solverstate`); a :class:`~rollqp.solverstate.Recorder` made before.
    state : State, optional
        With ``resume`` and ``verify=False``: the state to continue from (:func:`check_resumed`'s; and
        ``_march``, the march it was checked on).

    Yields
    ------
    StepRecord
        ``k = 0`` (the starting state), then the rolling steps ``k = 1..K``.

    Raises
    ------
    SolverError
        A step failed; ``err.step`` names it (0: the start).
    InputError
        The scene cannot be run with this method, or the contact leaves the zone; ``--resume``: the
        stored states are another scene's, or the last one does not solve its step.
    """
    scene, meth, ops = prepared if prepared is not None else prepare(scene, method)
    m = _march if _march is not None else _March(scene, ops, meth)
    M = ops.history()  # built (on the dense path: from an n × n matrix) before the start's solver holds its systems
    recorder = None if record is None or record is False else record
    if record is True:
        recorder = Recorder(meth, ops)
    if resume is not None:
        if verify:
            state = check_resumed(scene, (scene, meth, ops), resume, march=m, recorder=recorder)
        elif state is None:
            state = _with_normal(m, resumed_state(scene, ops, resume), last_index(resume))
        first = last_index(resume) + 1
    else:
        try:
            start = m.start()
        except SolverError as err:  # the start is state 0
            raise (err.with_step(0) if err.step is None else err) from err
        if recorder is not None:
            start.solver = recorder.note(0, start.state, m.cache)
        yield start
        state, first = start.state, 1
    qs = m.plan.q
    for k in range(first, qs.size):
        try:
            rec = m.rolling(k, float(qs[k]), state, M)
        except SolverError as err:
            raise (err.with_step(k) if err.step is None else err) from err
        if recorder is not None:
            rec.solver = recorder.note(k, rec.state, m.cache)
        state = rec.state
        yield rec


def resumed_state(scene, ops: SceneOperators, arrays: dict, row: int = -1, products=None) -> State:
    """A stored state of a result file of ``scene`` (the last one, ``row = -1``), as the march continues from it.

    Tractions, approach and creepage are the stored ones (float64, as the march keeps them), and a
    friction law's memory (the stored ``friction_coefficient``); ``w`` is recomputed from the
    tractions (eq. 28), with the product ``A_tt t`` the method computed for the state if
    ``products`` has it (``{(k, "t"): A_tt t}``, :func:`rollqp.solverstate.restore`). The warm starts are
    the same numbers; what a method built during the first part is rebuilt by :func:`check_resumed`.

    Raises
    ------
    InputError
        ``--resume``: the file belongs to another scene (other nodes or rolled distances).
    """
    x, q = np.asarray(arrays["x"]), np.asarray(arrays["q"])
    steps = stored_steps(arrays)
    qs = scene.q_steps
    if x.shape != (ops.n,) or not np.allclose(x, ops.strip.x, rtol=0, atol=1e-12 * scene.half_width):
        raise InputError("--resume", f"the result file's {x.size} nodes are not this scene's {ops.n}: another scene")
    if (steps.shape != q.shape or q.size == 0 or steps[-1] >= qs.size
            or not np.allclose(q, qs[steps], rtol=1e-12, atol=1e-15 * scene.a_H)):
        raise InputError("--resume", f"the result file's rolled distances are not this scene's "
                                     f"(it has {q.size} states, the scene {qs.size}): another scene")
    p, t = np.array(arrays["pn"][row], dtype=float), np.array(arrays["pt"][row], dtype=float)
    g, slip = np.array(arrays["gap"][row], dtype=float), np.array(arrays["slip"][row], dtype=float)
    delta, xi = float(arrays["approach"][row]), float(arrays["creepage"][row])
    if ops.coupled:  # one solution of both halves: a coupled step's warm start reads p, t, δ and ξ from it
        nsol = tsol = StepSolution(p=p, t=t, g=g, s=slip, delta=delta, xi=xi, method="resumed", status="resumed")
    else:
        nsol = StepSolution(p=p, g=g, delta=delta, method="resumed", status="resumed")
        tsol = StepSolution(t=t, s=slip, xi=xi, method="resumed", status="resumed")
    if "friction_coefficient" in arrays:  # a friction law's memory: the next step's μ starts from it
        tsol.mu = np.array(arrays["friction_coefficient"][row], dtype=float)
    At = None if not products else products.get((int(steps[row]), "t"))
    if At is not None:
        tsol.At = (t, At)
    return State(p, t, ops.w(p, t, At), nsol, tsol, None)


def check_resumed(scene, prepared, arrays: dict, march=None, recorder=None) -> State:
    """The state to continue from: the last stored state of ``arrays``, checked to solve its own step
    (:func:`rollqp.march.loop.check_last`, as the grid's).

    That step is solved again from the state before it (from the start for state 0), with what the
    method carried across steps rebuilt as it was after that state (:func:`rollqp.solverstate.restore`, from
    the journal's records, ``arrays["_notes"]``): the same computation as the uninterrupted run's, so
    it gives the stored state bit for bit, and the march continues from it (and from the method as it
    was). Otherwise (a file without the records, or a method whose state is not all rebuilt: a QP
    solver's internals) it must agree to :data:`~rollqp.march.loop.RESUME_TOL` (pressures in p0, tractions in
    μp0; the gap, approach, slip and creepage it hands on with them) and the march continues from the stored
    state; else the file was changed or is corrupt (an :class:`InputError` on ``--resume``, one line,
    nothing run). ``recorder``: the march's :class:`~rollqp.solverstate.Recorder`, which goes on from the
    records."""
    scene, meth, ops = prepared
    m = march if march is not None else _March(scene, ops, meth)

    def start():
        _restore(m, arrays, -1, recorder)
        return m.start().state

    def step(k):
        products = _restore(m, arrays, k - 1, recorder)
        before = _with_normal(m, resumed_state(scene, ops, arrays, -2, products=products), k - 1)
        return m.rolling(k, float(m.plan.q[k]), before, ops.history()).state

    return check_last(arrays, stored=lambda row: _with_normal(m, resumed_state(scene, ops, arrays, row),
                                                              last_index(arrays)),
                      start=start, step=step, identical=_identical,
                      differences=lambda again, stored: _differences(again, stored, ops), n_steps=scene.n_steps)


def _differences(again: State, stored: State, ops) -> tuple:
    """``(what, again, stored, scale, unit)`` of every field a resumed state is checked by: the pressure and
    traction, and the gap, approach, slip and creepage it hands on (a fixed normal half carries its solution to
    every later step)."""
    sc = ops.scales
    mu = float(getattr(ops, "mu", 0.0) or 0.0)
    return (("pressure", again.p, stored.p, sc.stress, "p0"),
            ("traction", again.t, stored.t, min(mu, 1.0) * sc.stress, "mu p0") if mu > 0 else ("traction", None, None, 1.0, ""),
            ("gap", again.nsol.g, stored.nsol.g, sc.displacement, "u0"),
            ("approach", again.nsol.delta, stored.nsol.delta, sc.displacement, "u0"),
            ("slip", again.tsol.s, stored.tsol.s, sc.slip, "p0/E*"),
            ("creepage", again.tsol.xi, stored.tsol.xi, sc.slip, "p0/E*"))


def check_states(scene, ops: SceneOperators, source) -> None:
    """Every state of an earlier part of the run (``source``: a :class:`~rollqp.result.ResumeSource` or a result
    file's arrays) consistent in itself (:func:`rollqp.march.loop.check_earlier`, as the grid's): its fields
    finite, pressures >= 0 and tractions within ``μp`` (to :data:`~rollqp.march.loop.RESUME_TOL` of p0 and
    μp0; a friction law's own ``μ`` where the file holds it), the tangential load ``Q`` that of its tractions.
    The nodes, rolled distances and the last state are checked by :func:`resumed_state` and
    :func:`check_resumed`."""
    sc, f = ops.scales, ops.f
    law = scene.contact.friction.kind != "constant"
    mu = float(getattr(ops, "mu", 0.0) or 0.0)
    tunit = (min(mu, 1.0) if mu > 0 else 1.0) * sc.stress
    names = ("pn", "pt", "slip", "Q", "step") + (("friction_coefficient",) if law else ())

    def inconsistent(b, k):
        p, t = np.asarray(b["pn"], dtype=float), np.asarray(b["pt"], dtype=float)
        if not (np.all(np.isfinite(p)) and np.all(np.isfinite(t)) and np.all(np.isfinite(np.asarray(b["slip"], dtype=float)))):
            return "its fields are not finite"
        if np.min(p, initial=0.0) < -RESUME_TOL * sc.stress:
            return f"a pressure of {np.min(p) / sc.stress:.3g} p0 < 0"
        coefficient = np.asarray(b["friction_coefficient"], dtype=float) if law and "friction_coefficient" in b else \
            (None if law else mu)
        if coefficient is not None and np.max(np.abs(t) - coefficient * np.maximum(p, 0.0), initial=0.0) > RESUME_TOL * tunit:
            return "a traction beyond the friction bound mu p"
        Q = t @ f
        bad = np.flatnonzero(~(np.abs(Q - np.asarray(b["Q"], dtype=float)) <= 1e-12 * (np.abs(t) @ np.abs(f) + tunit * f.sum())))
        if bad.size:
            return f"state {int(k[bad[0]])}: its tangential load Q is not that of its tractions"
        return None

    check_earlier(source, names, inconsistent)


def _restore(m: _March, arrays, upto, recorder):
    """:func:`rollqp.solverstate.restore` on the march ``m`` from the records of ``arrays``: the method's systems
    and the march's history operators as they were after state ``upto``; the products of
    :func:`rollqp.solverstate.restore` (``None`` without records). A record that cannot be rebuilt leaves the
    method as set up (the march then sets out without what it carried)."""
    notes = arrays.get("_notes")
    if not notes:
        return None
    meth, ops = m.method, m.ops
    try:
        got = restore(meth, ops, notes, upto, arrays["_state_at"], recorder)
        if got is None:
            return None
        products, hist = got
        if hist and m.cache is not None:
            form = m.scene.discretization.formulation
            m.cache.items = [(float(dq), int(d), ops.build_history(form, float(dq), int(d))) for dq, d in hist]
        return products
    except (KeyError, IndexError, TypeError, ValueError, AttributeError, OverflowError, ArithmeticError):
        meth.setup(ops)  # (a record that is not rollqp's: the check below then decides, to the tolerance)
        return None


def _with_normal(m: _March, state: State, k: int) -> State:
    """A stored state with the normal problem of its step (``State.normal``), which a stored state lacks and a
    fixed normal half carries from step to step (its gap gives the elastic energy: :mod:`rollqp.energy`)."""
    ops = m.ops
    if ops.coupled or state.normal is not None or state.nsol is None or not np.any(state.p):
        return state
    _, _, P, _, _, D = m.at[k]
    if P is not None and P <= 0.0:
        return state
    h = ops.gap(float(m.plan.q[k])) if m.moving else None
    return dataclasses.replace(state, normal=ops.normal_step(P, state.t, delta=D, h=h, validate=False))


def _identical(again: State, stored: State) -> bool:
    """``again`` is ``stored`` bit for bit (pressures, tractions, gaps, slips, approach, creepage, μ)."""
    a, b = again, stored
    same = all(np.array_equal(np.asarray(x, dtype=float), np.asarray(y, dtype=float)) for x, y in (
        (a.p, b.p), (a.t, b.t), (a.tsol.s, b.tsol.s), (a.nsol.g, b.nsol.g), (a.nsol.delta, b.nsol.delta),
        (a.tsol.xi, b.tsol.xi)))
    mu = getattr(b.tsol, "mu", None)
    return same and (mu is None or np.array_equal(np.broadcast_to(getattr(a.tsol, "mu", np.nan), mu.shape), mu))


def run(scene, method=None, progress=None, resume=None, observe=None, *, out=None, keep_every=None,
        geometry=None, start_progress=None) -> Result:
    """Run a scene's transient and return its :class:`~rollqp.result.Result`.

    Parameters
    ----------
    scene : Scene, str or path
        A scene object, a TOML path, or a built-in name.
    method : str or Method, optional
        Overrides ``[solver].method`` (:func:`prepare`).
    progress : callable, optional
        Called as ``progress(k, K)`` after each rolling step.
    resume : dict, path or ResumeSource, optional
        An earlier, incomplete part of this run: the arrays of its result file
        (:func:`~rollqp.result.load_result`), the path of its result file or journal, or a
        :class:`~rollqp.result.ResumeSource`. Its states are kept and the run continues after the last
        one (:func:`resumed_state`, once :func:`check_resumed` has passed); ``meta["resumed_from"]``
        records where.
    observe : callable, optional
        Called as ``observe(record, operators)`` with every :class:`StepRecord` (to keep some
        steps' problems, e.g. for a cross-check: :func:`rollqp.crossval.spot_check`).
    out : path, optional
        The result file: every state is appended to its journal as it is completed (nothing kept in
        memory), and the file is written at the end, or when the run fails or is interrupted, with
        ``meta["failed"]`` or ``meta["interrupted"]`` (docs/results.md). Without it, the states stay in
        memory and nothing is written.
    keep_every : int, optional
        Keep every k-th state (and the last two); the steps in between are combined into the kept
        ones (``Field.reduce``). Default 1, or the resumed file's.
    geometry : Memo, optional
        Shared by the runs it is handed to: what the influence model keeps of the bodies (:func:`prepare`).
    start_progress : callable, optional
        The 3D run's report of the steps of its start (:func:`rollqp.march.grid.run`); a 2D start (its
        problems on a strip: milliseconds to seconds) is not reported.

    Raises
    ------
    SolverError
        A step failed; ``err.partial`` holds the :class:`Result` of the completed steps and
        ``err.step`` the failing step.
    InputError
        The scene cannot be run with this method, or the contact leaves the zone
        (``err.partial`` as above).
    KeyboardInterrupt
        Interrupted (Ctrl-C, or SIGTERM in the command line): ``partial`` as above.
    """
    asked = _two_d(scene if isinstance(scene, Scene) else load_scene(scene))
    if isinstance(method, str) and method != asked.solver.method:
        asked = asked.replace(**{"solver.method": method})
    if out is not None:
        out = check_output(out, key="out")
    source = resume_source(resume) if isinstance(resume, (str, os.PathLike)) else resume
    keep = _keep_every(keep_every, source)
    if out is None:  # before any work: the states it would hold, on the operators it would build
        check_result_memory(fast_path(asked).scene if method is None or isinstance(method, str) else asked, keep)
    scene, meth, ops = prepared = prepare(asked, None if isinstance(method, str) else method, geometry=geometry)
    tail = state = recorder = None
    if out is not None:  # a journal: each state with what the method carries (rollqp.solverstate)
        recorder = Recorder(meth, ops)
    if source is not None:
        tail = source.tail() if isinstance(source, ResumeSource) else source
        resumed_state(scene, ops, tail)                 # the nodes and the rolled distances: this scene's
        check_states(scene, ops, source)                # every state consistent, before any is solved from
        checked = _March(scene, ops, meth)  # the march goes on from it (its history operators)
        state = check_resumed(scene, prepared, tail, march=checked, recorder=recorder)
    result = new_result(asked, ops, meth.name, keep_every=keep, out=out)  # meta: the scene as given, the method that ran it
    if scene.solver.method != asked.solver.method:
        result.meta["method_note"] = fast_path(asked).note
    with stop_once():  # a second Ctrl-C never interrupts the writing of what the first one saves
        return _run(scene, prepared, result, source, (tail, state, recorder, checked if source is not None else None),
                    observe, progress)


def _run(scene, prepared, result, source, resumed, observe, progress) -> Result:
    """:func:`run`'s loop over the 2D march (:func:`drive`)."""
    tail, state, recorder, checked = resumed
    records = march(scene, prepared=prepared, resume=tail, verify=False, record=recorder, state=state, _march=checked)
    return drive(result, records, source=source, resumed_from=None if tail is None else last_index(tail),
                 operators=prepared[2], observe=observe, progress=progress, steps=scene.n_steps)


def new_result(scene, ops: SceneOperators, method_name: str, keep_every: int = 1, out=None) -> Result:
    """An empty :class:`Result` with the scene's scalars, metadata and the computed fields it needs
    (``out``: written to that file through its journal, :func:`run`)."""
    meta = {"scene": scene.to_dict(), "method": method_name, "model": dict(ops.info), "dimension": 2,
            "versions": versions(), "rollqp": __version__,
            "dq": scene.dq, "n_nodes": ops.n, "coupling": scene.coupling_level,
            "step_problem": "coupled" if ops.coupled else "normal + tangential",
            "slip_note": ("step 0 of a braked start: static-shift slip per a_H of shift" if scene.load.start == "braked"
                          else "step 0 of a rolling start: steady-rolling slip per unit rolled distance")
                         + ("; stops of load.rolled: static-shift slip per a_H of shift" if scene.load.rolled is not None
                            else "")}
    scalars = {"a_H": scene.a_H, "p0": scene.p0, "R": scene.R, "Estar": scene.Estar, "beta": scene.beta,
               "leading_edge": scene.leading_edge}
    constants = {"f": ops.f, "wear_A": scene.A.wear or 0.0, "wear_B": scene.B.wear or 0.0}
    return Result(x=ops.strip.x.copy(), scalars=scalars, meta=meta, extra=fields_for(scene), constants=constants,
                  keep_every=keep_every, out=out, operators=ops)


def _unloaded(ops: SceneOperators, xi=None) -> State:
    """The state at ``P = 0``: out of contact, no tractions, the surfaces relaxed (``w = 0``).

    Nothing is solved: the only solution of the step has ``p = t = 0``. The approach is not
    determined (any ``δ <= min h``); it is recorded as ``min h`` (the bodies just touch, the
    smallest gap 0). The creepage is not determined either (nothing sticks): the prescribed one,
    else 0, and every node is reported as separated (state 0). The slip memory is lost, so the
    next loaded step starts from unloaded surfaces. The scene requires ``Q = 0`` wherever
    ``P = 0`` (:class:`~rollqp.scene.Scene`).
    """
    n = ops.n
    delta = float(np.min(ops.h))
    zero = np.zeros(n)
    nsol = StepSolution(p=zero, g=ops.h - delta, delta=delta, method="unloaded", status="unloaded")
    tsol = StepSolution(t=zero, s=zero, xi=0.0 if xi is None else float(xi), method="unloaded",
                        status="unloaded")
    return State(zero, zero, zero, nsol, tsol, None)


def _product(sol, problem, A):
    """``A t`` of the tangential solution ``sol``, if its method handed it back (``sol.At``, a pair
    ``(t, A t)``) for this very operator ``A`` (not a steady slip operator), else None."""
    got = sol.At
    if got is None or problem.A is not A:
        return None
    t, At = got
    return At if (t is sol.t or np.array_equal(t, sol.t)) else None


def _keep_mu(problem, sol) -> None:
    """With a friction law, the step's ``μ`` at the nodes in ``sol.mu`` (the next step's memory,
    the result field ``friction_coefficient``); Coulomb steps are left as they were."""
    if problem.law is not None or (type(problem.mu) is not float and np.ndim(problem.mu) != 0):
        sol.mu = np.broadcast_to(problem.coefficient(sol.s, sol.p), (problem.n,)).astype(float)
