"""Integration over rolled distance (paper §4.1 Steps 0–8, §4.4; FORMULATION.md §9).

:class:`Model` holds everything that cannot change during a scene — strip, influence
matrices, scales, slip operators — and is built once. :func:`run` then marches:

* **starting state** (step 0):
  - ``start = "braked"``: the normal load is applied (Hertz for similar bodies), then the
    tangential load by static shift in ``load.start_steps`` increments (Cattaneo for
    similar bodies, §4.4): ``s = (w^k − w^{k−1})/Δ + ξ`` with ``Δ = a_H`` and ``ξ·Δ`` the
    rigid shift;
  - ``start = "rolling"``: steady rolling at the initial loads, reached by marching the
    transient at constant loads from the braked state until the tractions stop changing
    (the QP methods cannot pose the non-symmetric steady problem directly).
* **rolling steps** ``k = 1..K`` at ``q_k = k Δq``: the history vector
  ``c^{k−1} = −M w^{k−1}`` (:meth:`~rollqp.strip.Strip.history_operator`), the loads
  ``P(q_k)``, ``Q(q_k)``, and each half warm-started from the previous step.

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
from .problem import NormalStep, Scales, TangentialStep, asymmetry, classify, symmetrized
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

    @classmethod
    def build(cls, scene: Scene, symmetric: bool) -> "Model":
        """Discretize ``scene``; ``symmetric`` selects the QP operator ``F⁻¹ sym(F A)``."""
        d = scene.discretization
        strip = Strip(scene.half_width, d.elements, d.element)
        t0 = time.perf_counter()
        infl = build_influence(scene.contact.model, strip, Estar=scene.Estar, beta=scene.beta,
                               R_A=scene.A.radius, R_B=scene.B.radius, coupling=scene.coupling_level,
                               d_ref=scene.reference_distance_value)
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
        return cls(scene=scene, strip=strip, Ann=Ann, Att=Att, Atn=infl.Atn, Ant=infl.Ant, h=infl.h,
                   scales=Scales(scene.a_H, scene.p0, scene.Estar), history=history, symmetric=symmetric,
                   info=info)

    @property
    def f(self) -> np.ndarray:
        return self.strip.weights

    # ------------------------------------------------------------ step problems
    def normal_step(self, P, t=None) -> NormalStep:
        offset = None if (self.Ant is None or t is None) else self.Ant @ t
        return NormalStep(A=self.Ann, f=self.f, h=self.h, P=P, offset=offset, scales=self.scales)

    def tangential_step(self, p, c, dq, Q=None, xi=None) -> TangentialStep:
        if self.Atn is not None:
            c = c + self.Atn @ p
        return TangentialStep(A=self.Att, f=self.f, p=p, mu=self.scene.contact.friction, c=c, dq=dq,
                              Q=Q, xi=xi, scales=self.scales)

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
    """The last accepted step: tractions, solutions (for warm starts), and w."""

    def __init__(self, p, t, nsol, tsol, w):
        self.p, self.t, self.nsol, self.tsol, self.w = p, t, nsol, tsol, w


def _make_method(scene: Scene, name: str):
    if name not in QP_METHODS:
        # The Newton methods register under the same names once implemented (issue 3).
        method = get_method(name, tolerance=scene.solver.tolerance, max_iterations=scene.solver.max_iterations)
    else:
        method = get_method(name, tolerance=scene.solver.tolerance)
    return method


def run(scene, method: str | None = None, progress=None) -> Result:
    """Run a scene's transient and return its :class:`~rollqp.result.Result`.

    Parameters
    ----------
    scene : Scene, str or path
        A scene object, a TOML path, or a built-in name.
    method : str, optional
        Overrides ``[solver].method``.
    progress : callable, optional
        Called as ``progress(k, K)`` after each rolling step.

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
    if scene.coupling_level == "full":
        raise InputError("contact.coupling",
                         f"full normal-tangential coupling (beta = {scene.beta:.4g}) needs the coupled Newton "
                         "method or the N-T alternation, which this version does not have yet; "
                         "use coupling = \"goodman\" or \"off\"")
    model = Model.build(scene, symmetric=getattr(meth, "operator", "exact") == "symmetrized")
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
            "dq": scene.dq, "n_nodes": model.strip.n,
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


def _record(result, model, q, state: _State, *, P, Q, xi, delta, shift, iterations, step_time, residual):
    sc, mu = model.scales, model.scene.contact.friction
    s = state.tsol.s
    result.append(q=q, pn=state.p, pt=state.t, slip=s, gap=state.nsol.g, state=classify(state.p, state.t, s, mu, sc),
                  P=P, Q=Q, creepage=xi, approach=delta, shift=shift, iterations=iterations,
                  step_time=step_time, residual=residual)


def _loads(scene, q):
    P = float(scene.normal_load(q))
    if scene.load.creepage is not None:
        return P, None, float(scene.prescribed_creepage(q))
    return P, float(scene.tangential_load(q)), None


def _braked_start(scene, model, meth, result):
    """Step 0 of a braked start: normal load, then tangential load by static shift (§4.4)."""
    t0 = time.perf_counter()
    P, Q, xi = _loads(scene, 0.0)
    nsol = meth.solve(model.normal_step(P))
    model.check_inside(nsol.p, 0)
    p = nsol.p
    n = model.strip.n
    t = np.zeros(n)
    w_prev = np.zeros(n)  # unloaded bodies
    Qtarget = Q if Q is not None else 0.0
    iters = nsol.iterations
    tsol = None
    shift = 0.0
    N = scene.load.start_steps
    for j in range(1, N + 1):
        # static shift (V = 0): s = (w^j − w^{j−1})/Δ + ξ, Δ = a_H, ξ·Δ = rigid shift increment
        prob = model.tangential_step(p, -w_prev, model.scales.length, Q=Qtarget * j / N)
        tsol = meth.solve(prob, warm=tsol)
        iters += tsol.iterations
        shift += tsol.xi * model.scales.length
        t = tsol.t
        w_prev = model.w(p, t)
    res = (nsol.residuals | tsol.residuals).max
    state = _State(p, t, nsol, tsol, w_prev)
    _record(result, model, 0.0, state, P=P, Q=float(model.f @ t), xi=0.0, delta=nsol.delta, shift=shift,
            iterations=iters, step_time=time.perf_counter() - t0, residual=res)
    return state


def _rolling_step(scene, model, meth, state: _State, q, normal_fixed):
    P, Q, xi = _loads(scene, q)
    nsol = state.nsol
    it = 0
    if not normal_fixed:
        nsol = meth.solve(model.normal_step(P, state.t), warm=state.nsol)
        it += nsol.iterations
    p = nsol.p
    c = -(model.history @ state.w)
    tsol = meth.solve(model.tangential_step(p, c, scene.dq, Q=Q, xi=xi), warm=state.tsol)
    it += tsol.iterations
    new = _State(p, tsol.t, nsol, tsol, model.w(p, tsol.t))
    return new, P, it, (nsol.residuals | tsol.residuals).max


def _normal_fixed(scene, model) -> bool:
    """The normal step cannot change: no shear feedback (A_nt absent) and constant P."""
    if model.Ant is not None:
        return False
    qs = scene.q_steps
    P = scene.normal_load(qs)
    return bool(np.all(P == P[0]))


def _march(scene, model, meth, result, progress):
    fixed = _normal_fixed(scene, model)
    state = _braked_start(scene, model, meth, result)
    if scene.load.start == "rolling":
        state = _steady_by_marching(scene, model, meth, state, result, fixed)
    qs = scene.q_steps
    K = qs.size - 1
    for k in range(1, K + 1):
        t0 = time.perf_counter()
        state, P, it, res = _rolling_step(scene, model, meth, state, qs[k], fixed)
        if not fixed:
            model.check_inside(state.p, k)
        _record(result, model, qs[k], state, P=P, Q=float(model.f @ state.t), xi=state.tsol.xi,
                delta=state.nsol.delta, shift=0.0, iterations=it, step_time=time.perf_counter() - t0,
                residual=res)
        if progress is not None:
            progress(k, K)


def _steady_by_marching(scene, model, meth, state, result, fixed):
    """Roll at the initial loads until the tractions stop changing; replace state 0 with it."""
    t0 = time.perf_counter()
    q0 = 0.0
    iters = 0
    max_steps = int(np.ceil(STEADY_MAX_DISTANCE * scene.a_H / scene.dq))
    for k in range(max_steps):
        new, P, it, res = _rolling_step(scene, model, meth, state, q0, fixed)
        iters += it
        change = np.max(np.abs(new.t - state.t)) / (max(scene.contact.friction, 1e-300) * model.scales.stress)
        state = new
        if change < STEADY_TOL:
            break
    else:
        raise SolverError(f"the rolling start did not reach a steady state within {STEADY_MAX_DISTANCE} a_H "
                          f"(last change {change:.2e} mu p0)", method=meth.name, step=0)
    result.rows = {key: [] for key in result.rows}
    _record(result, model, 0.0, state, P=P, Q=float(model.f @ state.t), xi=state.tsol.xi, delta=state.nsol.delta,
            shift=0.0, iterations=iters, step_time=time.perf_counter() - t0, residual=res)
    return state
