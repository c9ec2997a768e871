"""The QP methods' accelerated rolling start (rollqp.methods.steady_start).

* The march map's Jacobian from the QPs' active sets (MapJacobian) is the map's derivative:
  against finite differences of the map itself, coupled and uncoupled.
* The Newton phase (active_set_newton inside fixed_point) on an affine map lands on its fixed point at
  once; with a wrong Jacobian the iteration still converges (Anderson takes over).
* A coupled rolling start with qp-osqp is newton's direct steady state (constant elements, Δq = Le:
  the same discrete problem, tests/test_steady.py), uses the Newton phase (fewer sweeps than without
  it), and leaves the active-set prediction off.
* The march to the steady state predicts its QPs' active sets and takes its last step with the
  backend: the same state as without the prediction, within the march's tolerance.
"""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import rollqp
from rollqp.march import prepare
from rollqp.methods.alternation import Alternation
from rollqp.methods.steady_start import MapJacobian, fixed_point, sweep_map
from refcases import bentall_scene

#: Tolerance of the march on the change of t per step (rollqp.march.strip.STEADY_TOL): the rolling start's
#: answer is within it of the steady state (measured 1e-12, see the test).
MARCH_TOL = 1e-8


def _steady_map(scene, method="qp-osqp"):
    """``(G, t, jacobian, scale)``: the march map of ``scene``'s rolling start from its braked state, near
    steady (Anderson to 1e-9 μp0), with the active-set prediction on as in the accelerated start."""
    braked = scene.replace(**{"load.start": "braked", "discretization.distance": 0.0})
    _, meth, ops = prepare(braked, method)
    state = next(rollqp.march(braked, meth)).state
    inner = meth.inner if isinstance(meth, Alternation) else meth
    inner.predicting(True)
    data = dict(P=float(scene.normal_load(0.0)), Q=float(scene.tangential_load(0.0)), xi=None, dq=scene.dq,
                M=ops.history())
    G = sweep_map(meth, ops, state, **data)
    scale = ops.mu * ops.scales.stress
    best, _, r = fixed_point(G, state.t, scale, target=1e-9, max_evaluations=600)
    assert r <= 1e-9, f"the map's fixed point is reached ({r:.1e})"
    return G, best[1], MapJacobian(ops, delta=None, **data), scale


@pytest.mark.parametrize("case", ["coupled", "uncoupled", "coupled-quadratic"])
def test_map_jacobian_is_the_maps_derivative(case):
    """K v against G(t + v) − G(t) near the steady state, where the active sets hold for a small v.

    Step 1e-6 μp0: the QP answers are exact KKT solves (rounding ~1e-14 p0, i.e. ~1e-12 μp0), so
    the difference quotient is good to ~1e-6 of |Kv|; bound 1e-4. A Jacobian that missed the
    coupling (A_nt, A_tn), the history or the moving bounds μp is off by far more (the coupling
    alone is ~10 % of K on this scene). Coupled: Bentall–Johnson, free rolling; uncoupled: §6.1.1's
    similar rollers at Q = 0.75 μP; both 40 constant elements (F·A symmetric). Coupled-quadratic: 20 QCE,
    F·A asymmetric, where K is exact only with the collocation operator (measured 1e-8 of |K v|; with the
    QP Hessian alone 1.4e-2)."""
    if case == "uncoupled":
        scene = rollqp.load_scene("cattaneo-carter").replace(**{"discretization.element": "constant",
                                                                 "discretization.elements": 40})
    else:
        scene = bentall_scene(0.05, elements=40 if case == "coupled" else 20, coupling="full",
                              element="constant" if case == "coupled" else "quadratic")
    G, t, jac, scale = _steady_map(scene)
    out = G(t)
    K = jac(t, *out[1:])
    v = 1e-6 * scale * np.random.default_rng(3).standard_normal(t.size)
    diff = G(t + v)[0] - out[0]
    Kv = K @ v
    assert np.abs(Kv).max() > 1e-3 * np.abs(v).max(), "the map does depend on t"
    err = np.abs(diff - Kv).max() / np.abs(Kv).max()
    assert err <= 1e-4, f"K v differs from the map's difference by {err:.1e} of |K v|"


def test_newton_phase_on_an_affine_map():
    """G(x) = A x + b with a slow transport mode (spectral radius 0.99): with its Jacobian the Newton
    phase reaches the fixed point in one step (two evaluations after the plain ones); with a wrong
    Jacobian it stops short and Anderson still converges."""
    n = 30
    A = 0.99 * np.eye(n, k=-1) + 0.005 * np.random.default_rng(0).standard_normal((n, n))
    b = np.linspace(-1.0, 1.0, n)
    exact = np.linalg.solve(np.eye(n) - A, b)
    counts = []

    def G(x):
        counts.append(1)
        return A @ x + b, None

    best, evals, r = fixed_point(G, np.zeros(n), 1.0, target=1e-12, jacobian=lambda x, _: A, newton_from=1e9)
    assert r <= 1e-12 and np.abs(best[1] - exact).max() <= 1e-10
    assert evals == len(counts) <= 3, f"Newton on an affine map: {evals} evaluations"
    counts.clear()
    wrong = -5.0 * np.eye(n)
    best, evals, r = fixed_point(G, np.zeros(n), 1.0, target=1e-12, jacobian=lambda x, _: wrong, newton_from=1e9,
                                 max_evaluations=500)
    assert r <= 1e-12 and np.abs(best[1] - exact).max() <= 1e-10, f"Anderson after a failed Newton phase: {r:.1e}"


def test_coupled_rolling_start_is_newtons_steady_state():
    """qp-osqp's accelerated rolling start (Bentall–Johnson, 40 constant elements, μ = 0.05, full
    coupling) against newton's direct steady solve: the same discrete state within the march's
    tolerance (measured 1e-12); in fewer N–T sweeps than without the Newton phase (measured 26
    against 60), and with the active-set prediction off afterwards (the march's own steps, which
    give the state kept, are the backend's)."""
    scene = bentall_scene(0.05, elements=40, coupling="full")
    ref = rollqp.run(scene, method="newton")
    meth = prepare(scene, "qp-osqp")[1]
    r = rollqp.run(scene, method=meth)
    assert r.meta["rolling_start"] == "marching to steady state"
    mu, p0 = scene.contact.friction, scene.p0
    dt = float(np.max(np.abs(r["pt"][0] - ref["pt"][0]))) / (mu * p0)
    dp = float(np.max(np.abs(r["pn"][0] - ref["pn"][0]))) / p0
    assert max(dt, dp) <= MARCH_TOL, f"Δt {dt:.1e} μp0, Δp {dp:.1e} p0"
    assert meth.inner.predicting(False) is False, "prediction off after the start"

    class WithoutNewton(Alternation):
        def __init__(self, *args, **kw):
            super().__init__(*args, **kw)
            self.capabilities = dataclasses.replace(self.capabilities, quasi_newton=False)

    plain = rollqp.run(scene, method=WithoutNewton(rollqp.get_method("qp-osqp", tolerance=scene.solver.tolerance)))
    sweeps, without = int(r["iterations"][0]), int(plain["iterations"][0])
    assert sweeps < without, f"the Newton phase saves sweeps: {sweeps} against {without} without it"


def _recording(base, predict=True):
    """``base``'s class with the accelerated start off (the march does all the work) and a log of whether
    each QP solve was predicted; ``predict=False``: the active-set prediction never switched on."""
    class Recording(type(base)):
        capabilities = dataclasses.replace(type(base).capabilities, accelerated_start=False)

        def solve(self, problem, warm=None):
            sol = super().solve(problem, warm)
            self.log.append(int(sol.info.get("predicted", 0)))
            return sol

        def predicting(self, on):
            return super().predicting(on and predict)

    meth = Recording(tolerance=base.tolerance)
    meth.log = []
    return meth


def test_march_to_steady_predicts_its_qps_and_keeps_the_backends_step():
    """The rolling start's march (here all of it: the accelerated start off) solves its QPs on their
    predicted active sets until steady, then takes its last step with the backend: the state kept is the
    backend's, equal to the march without the prediction within the march's tolerance, and the prediction
    is off afterwards."""
    scene = rollqp.load_scene("cattaneo-carter").replace(**{"load.start": "rolling", "discretization.distance": 0.0})
    base = rollqp.get_method("qp-osqp", tolerance=scene.solver.tolerance)
    with_prediction, without = _recording(base), _recording(base, predict=False)
    r, plain = rollqp.run(scene, method=with_prediction), rollqp.run(scene, method=without)
    assert sum(with_prediction.log) > 0 and not any(without.log)
    assert with_prediction.log[-1] == 0, "the last step's QPs are the backend's"
    assert with_prediction.predicting(False) is False, "prediction off after the start"
    mu_p0 = scene.contact.friction * scene.p0
    # both marches stop at a step change below MARCH_TOL, which leaves each within ~8 MARCH_TOL of the
    # steady state (the change shrinks by only ~12 % a step: measured 7.6e-8 and 7.3e-8 μp0 from newton's
    # direct steady state); so they agree within twice that (measured 3.0e-9 μp0 apart)
    assert np.max(np.abs(r["pt"][0] - plain["pt"][0])) <= 16 * MARCH_TOL * mu_p0


def test_newton_phase_without_a_jacobian_hands_back_its_start():
    """Where no Jacobian can be formed (MapJacobian gives None: a QP's reduced KKT system singular) the
    Newton phase stops at once, without an evaluation, and the fixed-point iteration goes on from its start."""
    from rollqp.methods.steady_start import active_set_newton
    B = 0.5 * np.eye(3)
    G = lambda x: (B @ x + 1.0,)  # noqa: E731 - fixed point x = 2
    x = np.zeros(3)
    best, k, r = active_set_newton(G, lambda *a: None, (x, *G(x)), 1.0, target=1e-12, max_evaluations=10)
    assert k == 0 and best[0] is x and r == 1.0
    best, k, r = fixed_point(G, x, 1.0, target=1e-12, jacobian=lambda *a: None, newton_from=10.0)
    assert r <= 1e-12 and np.abs(best[1] - 2.0).max() <= 1e-11  # Anderson: an affine map in a few steps


def test_active_set_newton_on_a_piecewise_affine_map():
    """``G(x) = clip(A x + b, −1, 1)``, a contraction with a slow mode, piecewise affine like the march map:
    full Newton steps with the Jacobian of each iterate (``diag(free)·A``) land on the fixed point once
    they are on its piece — in far fewer evaluations than the plain iteration needs to 1e-12."""
    from rollqp.methods.steady_start import active_set_newton
    n = 20
    rng = np.random.default_rng(1)
    A = 0.98 * np.eye(n, k=-1) + 0.01 * rng.standard_normal((n, n))
    b = 0.3 * rng.standard_normal(n) + 0.1
    G = lambda x: (np.clip(A @ x + b, -1.0, 1.0),)  # noqa: E731
    jac = lambda x, *_: (np.abs(A @ x + b) < 1.0)[:, None] * A  # noqa: E731
    x0 = np.zeros(n)
    best, k, r = active_set_newton(G, jac, (x0, *G(x0)), 1.0, target=1e-12, max_evaluations=50)
    plain, kp, rp = fixed_point(G, x0, 1.0, target=1e-12, memory=0, max_evaluations=5000)
    assert r <= 1e-12 and np.abs(best[1] - plain[1]).max() <= 1e-10
    assert k <= 10 < kp, f"Newton {k} evaluations, plain iteration {kp}"


def test_active_set_newton_refuses_a_cycling_step_and_marches():
    """A piecewise-linear ``F = x − G(x)`` on which full Newton steps cycle (1 → −1 → 1: slope 1/3 outside
    |x| ≤ 1/2, 1 inside): the step to −1 does not shrink the Newton correction (|d| = 2 at both ends), so
    it is refused and a plain step ``x ← G(x)`` taken instead (to 1/3, inside), from which Newton lands on
    the root: three evaluations."""
    from rollqp.methods.steady_start import active_set_newton

    def F(x):
        return np.where(np.abs(x) <= 0.5, x, np.sign(x) * ((np.abs(x) - 0.5) / 3 + 0.5))

    G = lambda x: (x - F(x),)  # noqa: E731
    jac = lambda x, *_: np.diag(np.where(np.abs(x) <= 0.5, 0.0, 2 / 3))  # noqa: E731 - G' = 1 − F'
    x0 = np.array([1.0])
    best, k, r = active_set_newton(G, jac, (x0, *G(x0)), 1.0, target=1e-12, max_evaluations=50)
    assert r <= 1e-12 and abs(float(best[1][0])) <= 1e-12 and k == 3, f"{k} evaluations, residual {r:.1e}"


def test_predicted_quadratic_step_is_the_splittings_answer():
    """A rolling step of §6.1.1 (40 QCE: F·A asymmetric, solved by the symmetric–skew splitting) with the
    active-set prediction on, warm-started from the previous step: one solve of the collocation operator on
    the predicted active set (``qp_solves`` 1, ``predicted``) and the backend's splitting answer to its
    residual limit (measured 2.5e-13 μp0 apart; the splitting takes 6 QPs)."""
    scene = rollqp.load_scene("cattaneo-carter").replace(**{"discretization.distance": 0.2})
    meth = rollqp.get_method("qp-osqp", tolerance=scene.solver.tolerance)
    recs = list(rollqp.march(scene, meth))
    prev, rec = recs[-2], recs[-1]
    backend = meth.solve(rec.problem, warm=prev.solution)
    meth.predicting(True)
    try:
        predicted = meth.solve(rec.problem, warm=prev.solution)
    finally:
        meth.predicting(False)
    assert predicted.info["predicted"] == 1 and predicted.info["qp_solves"] == 1 < backend.info["qp_solves"]
    assert predicted.residual <= meth.tolerance
    mu_p0 = scene.contact.friction * scene.p0
    assert np.abs(predicted.t - backend.t).max() <= 2 * meth.residual_limit * mu_p0
