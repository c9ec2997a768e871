"""Integration over rolled distance (paper §4.1 Steps 0–8, §4.4; FORMULATION.md §9).

:class:`Model` holds everything that cannot change during a scene — strip, influence
matrices, scales, slip operators — and is built once. :func:`run` then marches:

* **starting state** (step 0):

  - ``start = "braked"``: the normal load is applied (Hertz for similar bodies), then the
    tangential load by static shift in ``load.start_steps`` increments (Cattaneo for
    similar bodies, §4.4): ``s = (w^k − w^{k−1})/Δ + ξ`` with ``Δ = a_H`` and ``ξ·Δ`` the
    rigid shift;
  - ``start = "rolling"``: steady rolling at the initial loads. ``newton`` and ``nt-newton``
    solve the steady problem directly (slip ``s = ξ e + d·D_up w``, :meth:`Model.steady_operators`);
    the QP methods reach it by marching the transient at constant loads from the braked state
    until the tractions stop changing (the steady slip operator is far from symmetric, and
    their splitting does not converge on it).
* **rolling steps** ``k = 1..K`` at ``q_k = k Δq``: the history vector
  ``c^{k−1} = −M w^{k−1}`` (:meth:`~rollqp.strip.Strip.history_operator`), the loads
  ``P(q_k)``, ``Q(q_k)``, and each half warm-started from the previous step.
* **contact lost** (``P(q) = 0``): an unloaded state (:func:`_unloaded`), nothing solved;
  **frictionless** (``μ = 0``): the normal half alone, ``t = 0`` (:func:`_frictionless`);
* **gross sliding** (only with a prescribed creepage beyond the sliding creepage; a prescribed
  ``|Q| >= μP`` is rejected by the scene): solved, and the states where every contact node slips
  are listed in ``meta["gross_sliding"]``;
* **failures**: a :class:`SolverError` names the step (0: the start) and rollqp's residual;
  ``err.partial`` keeps the completed states (the CLI writes them to the result file).

Only what the scene needs is modelled: with β = 0 (or ``coupling = "off"``) and a
constant normal load the normal QP is solved once and reused; coupling matrices are
built only for the coupling level asked for.

QP methods solve the collocation problem itself by symmetric–skew splitting
(:class:`rollqp.methods._qp.QPMethod`). With their ``operator="symmetrized"`` setting they
solve the problem with ``F⁻¹ sym(F A)`` instead, and the driver then uses that operator for
the whole transient (history vectors included), so that every step's residual refers to
one discrete model. The measured asymmetry is kept in the result's ``meta``.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from .errors import InputError, SolverError
from .influence import build_influence
from .methods import QP_METHODS, get_method
from .methods.alternation import Alternation
from .problem import (CoupledStep, NormalStep, Scales, StepSolution, TangentialStep, asymmetry, classify,
                      symmetrized, trust_matrix)
from .result import Result
from .scene import Scene, load_scene
from .strip import Strip

#: Rolling start by marching: stop when max|Δt| per step is below this fraction of μp0
#: (a hundred times above the QP solvers' step-to-step noise of ~1e-10, and far below
#: the discretization error of ~1e-3) …
STEADY_TOL = 1e-8
#: … or after this many a_H of rolling (Carter's transient dies out within ~3 a_H).
STEADY_MAX_DISTANCE = 40.0


@dataclass
class Model:
    """What a scene's transient needs, built once: strip, influence, scales, operators."""

    scene: Scene
    strip: Strip
    Ann: np.ndarray
    Att: np.ndarray
    Atn: np.ndarray | None
    Ant: np.ndarray | None
    h: np.ndarray
    scales: Scales
    history: np.ndarray
    symmetric: bool
    info: dict = field(default_factory=dict)
    _cache: dict = field(default_factory=dict, repr=False)

    @classmethod
    def build(cls, scene: Scene, symmetric: bool) -> "Model":
        """Discretize ``scene``; ``symmetric`` selects the QP operator ``F⁻¹ sym(F A)``."""
        d = scene.discretization
        strip = Strip(scene.half_width, d.elements, d.element)
        t0 = time.perf_counter()
        kw = {}
        if scene.contact.model == "bem":  # true geometry: the rollers and their BEM meshes
            kw = dict(A=scene.A, B=scene.B, n_outer=scene.bem_mesh[0], n_inner=scene.bem_mesh[1])
        infl = build_influence(scene.contact.model, strip, Estar=scene.Estar, beta=scene.beta,
                               R_A=scene.A.radius, R_B=scene.B.radius, coupling=scene.coupling_level,
                               d_ref=scene.reference_distance_value, **kw)
        f = strip.weights
        info = dict(infl.info)
        info["asymmetry_Ann"] = asymmetry(infl.Ann, f)
        info["asymmetry_Att"] = asymmetry(infl.Att, f)
        Ann, Att = infl.Ann, infl.Att
        if symmetric:
            Ann = symmetrized(Ann, f)
            Att = Ann if infl.Att is infl.Ann or np.array_equal(infl.Att, infl.Ann) else symmetrized(Att, f)
        info["influence_seconds"] = time.perf_counter() - t0
        info["operator"] = "symmetrized" if symmetric else "collocation"
        history = strip.history_operator(d.formulation, scene.dq, scene.load.direction)
        # finite, fixed for the scene: validated once here, read-only from now on (problem.trust_matrix)
        Ann, Att, Atn, Ant = (None if M is None else trust_matrix(M, "influence")
                              for M in (Ann, Att, infl.Atn, infl.Ant))
        return cls(scene=scene, strip=strip, Ann=Ann, Att=Att, Atn=Atn, Ant=Ant, h=infl.h,
                   scales=Scales(scene.a_H, scene.p0, scene.Estar), history=history, symmetric=symmetric,
                   info=info)

    @property
    def f(self) -> np.ndarray:
        return self.strip.weights

    # ------------------------------------------------------------ step problems
    def normal_step(self, P, t=None, delta=None) -> NormalStep:
        offset = None if (self.Ant is None or t is None) else self.Ant @ t
        return NormalStep(A=self.Ann, f=self.f, h=self.h, P=P, delta=delta, offset=offset, scales=self.scales)

    def tangential_step(self, p, c, dq, Q=None, xi=None, steady=False) -> TangentialStep:
        Atn, Att = self.steady_operators() if steady else (self.Atn, self.Att)
        if Atn is not None:
            c = c + Atn @ p
        return TangentialStep(A=Att, f=self.f, p=p, mu=self.scene.contact.friction, c=c, dq=dq,
                              Q=Q, xi=xi, scales=self.scales)

    @property
    def coupled(self) -> bool:
        """Full coupling (``A_nt`` present): each step is one :class:`CoupledStep`."""
        return self.Ant is not None

    def coupled_step(self, P, c, dq, Q=None, xi=None, steady=False, delta=None) -> CoupledStep:
        """The coupled step (FORMULATION.md §6); ``steady``: slip ``s = ξ e + d·D_up w``."""
        Atn, Att = self.steady_operators() if steady else (self.Atn, self.Att)
        return CoupledStep(Ann=self.Ann, Att=Att, Ant=self.Ant, Atn=Atn, f=self.f, h=self.h,
                           mu=self.scene.contact.friction, c=c, dq=dq, P=P, Q=Q, xi=xi, delta=delta,
                           scales=self.scales)

    def steady_operators(self):
        """``(Δ·d·D_up·A_tn, Δ·d·D_up·A_tt)`` with ``Δ = a_H``: the steady slip operators.

        With ``dq = Δ`` and ``c = 0`` the step problems' slip ``ξ e + (c + A_tn p + A_tt t)/dq``
        is then the steady-rolling slip ``ξ e + d·D_up w`` (FORMULATION.md §4). Built once.
        """
        if "steady" not in self._cache:
            T = self.scales.length * self.strip.steady_operator(self.scene.load.direction)
            self._cache["steady"] = (None if self.Atn is None else T @ self.Atn, T @ self.Att)
        return self._cache["steady"]

    def w(self, p, t) -> np.ndarray:
        """Relative tangential displacement ``w = A_tn p + A_tt t`` (eq. 28)."""
        out = self.Att @ t
        return out if self.Atn is None else out + self.Atn @ p

    def check_inside(self, p, step: int):
        """The contact must not reach the ends of the potential contact zone."""
        ends = (p[0], p[-1])
        if max(ends) > 1e-8 * self.scales.stress:
            raise InputError("discretization.zone",
                             f"the contact reaches the edge of the zone at step {step} "
                             f"(p/p0 = {max(ends) / self.scales.stress:.2e} at an end node): increase zone "
                             f"(now {self.scene.discretization.zone})")


class _State:
    """The last accepted step: tractions, solutions (for warm starts), and w.

    For a coupled step ``nsol`` and ``tsol`` are the same :class:`StepSolution`.
    """

    def __init__(self, p, t, nsol, tsol, w):
        self.p, self.t, self.nsol, self.tsol, self.w = p, t, nsol, tsol, w


@dataclass
class _Step:
    """What one step (or a start phase) reports to the result file."""

    iterations: int = 0
    residual: float = 0.0
    inner_normal: int = 0
    inner_tangential: int = 0
    backtracks: int = 0

    def add(self, sol, half=None):
        """Count a solution of a normal or tangential half (two-QP path)."""
        self.iterations += sol.iterations
        if half == "normal":
            self.inner_normal += sol.iterations
        elif half == "tangential":
            self.inner_tangential += sol.iterations
        self.backtracks += int(sol.info.get("backtracks", 0))
        self.residual = max(self.residual, sol.residual)

    def add_coupled(self, sol):
        """Count a coupled solution: Newton iterations, or N–T outer and inner iterations."""
        self.iterations += sol.iterations
        self.inner_normal += int(sol.info.get("inner_normal", 0))
        self.inner_tangential += int(sol.info.get("inner_tangential", 0))
        self.backtracks += int(sol.info.get("backtracks", 0))
        self.residual = max(self.residual, sol.residual)


#: Methods that solve non-symmetric step problems directly (the steady rolling start).
DIRECT_STEADY = ("newton", "nt-newton")


def _make_method(scene: Scene, name: str):
    """The scene's step method; QP backends are wrapped in the N–T alternation for full coupling."""
    settings = {"tolerance": scene.solver.tolerance}
    if name not in QP_METHODS:
        settings["max_iterations"] = scene.solver.max_iterations
    if name == "nt-newton":
        settings["max_outer"] = scene.solver.max_iterations
    if name not in QP_METHODS and scene.solver.augmentation is not None:
        settings["r"] = scene.solver.augmentation
    method = get_method(name, **settings)
    if scene.coupling_level == "full" and name in QP_METHODS:
        method = Alternation(method, max_outer=scene.solver.max_iterations)
    return method


def run(scene, method: str | None = None, progress=None, observe=None) -> Result:
    """Run a scene's transient and return its :class:`~rollqp.result.Result`.

    Parameters
    ----------
    scene : Scene, str or path
        A scene object, a TOML path, or a built-in name.
    method : str, optional
        Overrides ``[solver].method``.
    progress : callable, optional
        Called as ``progress(k, K)`` after each rolling step.
    observe : callable, optional
        Called once as ``observe(model, method)`` before the march; it returns the method to
        use (e.g. a wrapper that records step problems: :func:`rollqp.stepfile.export_step`).

    Raises
    ------
    SolverError
        A step failed; ``err.partial`` holds the :class:`Result` of the completed steps and
        ``err.step`` the failing step.
    InputError
        The scene cannot be run with this method, or the contact leaves the zone.
    """
    scene = scene if isinstance(scene, Scene) else load_scene(scene)
    name = method or scene.solver.method
    if method is not None and method != scene.solver.method:
        scene = scene.replace(**{"solver.method": method})
    meth = _make_method(scene, name)
    model = Model.build(scene, symmetric=getattr(meth, "operator", "exact") == "symmetrized")
    if observe is not None:
        meth = observe(model, meth)
    result = _new_result(scene, model, name)
    try:
        _march(scene, model, meth, result, progress)
    except SolverError as err:
        k = len(result)
        e = err.with_step(k) if err.step is None else err
        e.partial = result
        raise e from err
    except InputError as err:
        err.partial = result
        raise
    return result


def _new_result(scene, model, name) -> Result:
    import rollqp
    meta = {"scene": scene.to_dict(), "method": name, "model": {k: v for k, v in model.info.items()},
            "versions": _versions(), "rollqp": rollqp.__version__,
            "dq": scene.dq, "n_nodes": model.strip.n, "coupling": scene.coupling_level,
            "step_problem": "coupled" if model.coupled else "normal + tangential",
            "slip_note": "step 0 of a braked start: static-shift slip per a_H of shift"}
    scalars = {"a_H": scene.a_H, "p0": scene.p0, "R": scene.R, "Estar": scene.Estar, "beta": scene.beta,
               "leading_edge": scene.leading_edge}
    return Result(x=model.strip.x.copy(), scalars=scalars, meta=meta)


def _versions() -> dict:
    import importlib.metadata as md
    out = {}
    for pkg in ("numpy", "scipy", "clarabel", "osqp", "cvxpy"):
        try:
            out[pkg] = md.version(pkg)
        except md.PackageNotFoundError:  # pragma: no cover
            out[pkg] = None
    return out


def _record(result, model, q, state: _State, st: _Step, *, P, shift, step_time):
    sc, mu = model.scales, model.scene.contact.friction
    s = state.tsol.s
    nodes = classify(state.p, state.t, s, mu, sc)
    if np.any(nodes == 2) and not np.any(nodes == 1):
        # gross sliding (possible with a prescribed creepage, |ξ| beyond the sliding creepage):
        # a valid solution, flagged with the indices of such states
        result.meta.setdefault("gross_sliding", []).append(len(result))
    result.append(q=q, pn=state.p, pt=state.t, slip=s, gap=state.nsol.g, state=nodes,
                  P=float(model.f @ state.p) if P is None else P,  # None: the approach is prescribed
                  Q=float(model.f @ state.t), creepage=state.tsol.xi, approach=state.nsol.delta, shift=shift,
                  iterations=st.iterations, step_time=step_time, residual=st.residual,
                  inner_normal=st.inner_normal, inner_tangential=st.inner_tangential, backtracks=st.backtracks)


def _loads(scene, q):
    """``(P, Q, ξ)`` at ``q``; ``P`` is None when the approach is prescribed (:func:`_approach`)."""
    P = None if scene.load.approach is not None else float(scene.normal_load(q))
    if scene.load.creepage is not None:
        return P, None, float(scene.prescribed_creepage(q))
    return P, float(scene.tangential_load(q)), None


def _approach(scene, q):
    """The prescribed approach δ(q), or None (the normal load is prescribed)."""
    d = scene.prescribed_approach(q)
    return None if d is None else float(d)


def _unloaded(model, xi=None) -> _State:
    """The state at ``P = 0``: out of contact, no tractions, the surfaces relaxed (``w = 0``).

    Nothing is solved: the only solution of the step has ``p = t = 0``. The approach is not
    determined (any ``δ <= min h``); it is recorded as ``min h`` (the bodies just touch, the
    smallest gap 0). The creepage is not determined either (nothing sticks): the prescribed one,
    else 0, and every node is reported as separated (state 0). The slip memory is lost, so the
    next loaded step starts from unloaded surfaces. The scene requires ``Q = 0`` wherever
    ``P = 0`` (:class:`~rollqp.scene.Scene`).
    """
    n = model.strip.n
    delta = float(np.min(model.h))
    zero = np.zeros(n)
    nsol = StepSolution(p=zero, g=model.h - delta, delta=delta, method="unloaded", status="unloaded")
    tsol = StepSolution(t=zero, s=zero, xi=0.0 if xi is None else float(xi), method="unloaded",
                        status="unloaded")
    return _State(zero, zero, nsol, tsol, zero)


def _frictionless(model, meth, state: _State, st: _Step, *, P, c, dq, xi=None, steady=False, delta=None) -> _State:
    """A step at ``μ = 0``: ``t = 0`` (the bound ``μp`` is zero at every node), the normal half alone.

    The tangential problem is degenerate (every node on the kink ``|t| = μp = 0``, no node can
    stick, so the load row ``fᵀt = Q = 0`` has no ``ξ`` column): nothing is solved for it. The
    creepage is not determined by the contact (the surfaces slide freely); it is the prescribed
    one, else reported as 0, and the slip follows from it and ``w`` as in any step. With
    ``t = 0`` the coupled step reduces to its normal half too (``A_nt t = 0``).
    """
    zero = np.zeros(model.strip.n)
    nsol = meth.solve(model.normal_step(P, zero, delta=delta), warm=state.nsol)
    st.add(nsol, "normal")
    xi = 0.0 if xi is None else float(xi)
    tsol = model.tangential_step(nsol.p, c, dq, xi=xi, steady=steady).solution(zero, xi)
    tsol.method, tsol.status = "frictionless", "frictionless"
    return _State(nsol.p, zero, nsol, tsol, model.w(nsol.p, zero))


def _step(model, meth, state: _State, st: _Step, *, P, c, dq, Q=None, xi=None, normal_fixed=False, steady=False,
          delta=None):
    """One step (rolling, static shift or steady): the coupled problem, or its two halves."""
    if P is not None and P <= 0.0:  # contact lost (the scene allows P = 0 only with Q = 0)
        return _unloaded(model, xi)
    if model.scene.contact.friction == 0.0:
        return _frictionless(model, meth, state, st, P=P, c=c, dq=dq, xi=xi, steady=steady, delta=delta)
    if model.coupled:
        sol = meth.solve(model.coupled_step(P, c, dq, Q=Q, xi=xi, steady=steady, delta=delta), warm=state.tsol)
        st.add_coupled(sol)
        return _State(sol.p, sol.t, sol, sol, model.w(sol.p, sol.t))
    nsol = state.nsol
    if not normal_fixed or nsol is None:
        # goodman/off: the normal half does not see t (A_nt = 0); offset kept for generality
        nsol = meth.solve(model.normal_step(P, state.t, delta=delta), warm=state.nsol)
        st.add(nsol, "normal")
    tsol = meth.solve(model.tangential_step(nsol.p, c, dq, Q=Q, xi=xi, steady=steady), warm=state.tsol)
    st.add(tsol, "tangential")
    return _State(nsol.p, tsol.t, nsol, tsol, model.w(nsol.p, tsol.t))


def _braked_start(scene, model, meth, result):
    """Step 0 of a braked start (§2.2, §4.4; FORMULATION.md §9), by static shift.

    1. The normal load in ``load.start_steps`` quasi-static increments at ``Q = 0``. With
       coupling (β ≠ 0, ``goodman`` or ``full``) the pressure displaces the surfaces
       tangentially and friction resists: the Goodman-type starting state. Without coupling
       the shear stays zero and the normal load is applied at once (path independent).
    2. The tangential load in ``load.start_steps`` increments (Cattaneo for similar bodies).

    Static-shift slip: ``s = ξ + (w^j − w^{j−1})/Δ`` with ``Δ = a_H`` and ``ξ·Δ`` the rigid
    shift increment, accumulated in the result's ``shift``.
    """
    t0 = time.perf_counter()
    P, Q, _ = _loads(scene, 0.0)
    D = _approach(scene, 0.0)   # prescribed approach: applied like the load, in start_steps parts
    Qtarget = Q if Q is not None else 0.0
    n = model.strip.n
    N = scene.load.start_steps
    delta = model.scales.length
    st = _Step()
    state = _State(None, np.zeros(n), None, None, np.zeros(n))  # unloaded bodies
    shift = 0.0
    N0 = P if D is None else D
    if model.Atn is not None:
        loading = [(N0 * j / N, 0.0) for j in range(1, N + 1)]
    else:  # no coupling: the shear of a normal load is zero, so go straight to Q (Hertz, then Cattaneo)
        loading = [] if Qtarget != 0.0 else [(N0, 0.0)]
    if Qtarget != 0.0:
        loading += [(N0, Qtarget * j / N) for j in range(1, N + 1)]
    Pprev = None
    for Pj, Qj in loading:
        # the normal half is re-solved only if P changed or the shear feeds back (A_nt)
        state = _step(model, meth, state, st, P=None if D is not None else Pj, c=-state.w, dq=delta, Q=Qj,
                      normal_fixed=(Pj == Pprev and model.Ant is None), delta=None if D is None else Pj)
        Pprev = Pj
        shift += state.tsol.xi * delta
    model.check_inside(state.p, 0)
    _record(result, model, 0.0, state, st, P=P, shift=shift, step_time=time.perf_counter() - t0)
    return state


def _normal_fixed(scene, model) -> bool:
    """The normal step cannot change: no shear feedback (A_nt absent) and constant P."""
    if model.Ant is not None:
        return False
    qs = scene.q_steps
    P = scene.normal_load(qs) if scene.load.approach is None else scene.prescribed_approach(qs)
    return bool(np.all(P == P[0]))


def _march(scene, model, meth, result, progress):
    fixed = _normal_fixed(scene, model)
    state = _braked_start(scene, model, meth, result)
    if scene.load.start == "rolling":
        try:
            if getattr(meth, "name", None) in DIRECT_STEADY:
                state = _steady_direct(scene, model, meth, state, result)
            else:
                state = _steady_by_marching(scene, model, meth, state, result, fixed)
        except SolverError as err:  # the rolling start is state 0, not step 1
            raise (err.with_step(0) if err.step is None else err) from err
    qs = scene.q_steps
    K = qs.size - 1
    for k in range(1, K + 1):
        t0 = time.perf_counter()
        P, Q, xi = _loads(scene, qs[k])
        st = _Step()
        state = _step(model, meth, state, st, P=P, c=-(model.history @ state.w), dq=scene.dq, Q=Q, xi=xi,
                      normal_fixed=fixed, delta=_approach(scene, qs[k]))
        if not fixed:
            model.check_inside(state.p, k)
        _record(result, model, qs[k], state, st, P=P, shift=0.0, step_time=time.perf_counter() - t0)
        if progress is not None:
            progress(k, K)


def _steady_direct(scene, model, meth, state, result):
    """Rolling start: the steady rolling problem ``s = ξ e + d·D_up w`` solved directly.

    Not symmetric (``D_up A`` is not), so only the Newton methods pose it; warm-started from
    the braked state. Replaces state 0.
    """
    t0 = time.perf_counter()
    P, Q, xi = _loads(scene, 0.0)
    st = _Step()
    state = _step(model, meth, state, st, P=P, c=np.zeros(model.strip.n), dq=model.scales.length, Q=Q, xi=xi,
                  steady=True, delta=_approach(scene, 0.0))
    model.check_inside(state.p, 0)
    result.rows = {key: [] for key in result.rows}
    result.meta.pop("gross_sliding", None)  # state 0 is replaced
    result.meta["rolling_start"] = "direct steady solve"
    _record(result, model, 0.0, state, st, P=P, shift=0.0, step_time=time.perf_counter() - t0)
    return state


def _steady_by_marching(scene, model, meth, state, result, fixed):
    """Rolling start: roll at the initial loads until the tractions stop changing; replace state 0.

    The QP methods cannot pose the non-symmetric steady problem, so they march the
    transient at constant loads (``STEADY_TOL``, ``STEADY_MAX_DISTANCE``).
    """
    t0 = time.perf_counter()
    P, Q, xi = _loads(scene, 0.0)
    st = _Step()
    max_steps = int(np.ceil(STEADY_MAX_DISTANCE * scene.a_H / scene.dq))
    change = np.inf
    for _ in range(max_steps):
        new = _step(model, meth, state, st, P=P, c=-(model.history @ state.w), dq=scene.dq, Q=Q, xi=xi,
                    normal_fixed=fixed, delta=_approach(scene, 0.0))
        change = np.max(np.abs(new.t - state.t)) / (max(scene.contact.friction, 1e-300) * model.scales.stress)
        if not fixed:
            change = max(change, np.max(np.abs(new.p - state.p)) / model.scales.stress)
        state = new
        if change < STEADY_TOL:
            break
    else:
        raise SolverError(f"the rolling start did not reach a steady state within {STEADY_MAX_DISTANCE} a_H "
                          f"(last change {change:.2e} mu p0)", method=meth.name, step=0)
    result.rows = {key: [] for key in result.rows}
    result.meta.pop("gross_sliding", None)  # state 0 is replaced
    result.meta["rolling_start"] = "marching to steady state"
    _record(result, model, 0.0, state, st, P=P, shift=0.0, step_time=time.perf_counter() - t0)
    return state
