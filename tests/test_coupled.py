"""The coupled step (paper eq. 63–64, 80–90): coupled GNMls, N–T alternation, coupling levels.

Tiers as in test_newton.py: the pseudo-Jacobian against finite differences and the case
choice of eq. 82–90 on every kink (consistency, round-off); convergence (quadratic at the
end, clear errors); agreement of coupled Newton, N–T alternation with Newton halves and the
alternation with QP halves on the same discrete coupled step; the coupling levels
of docs/formulation.md §10 in the march.
"""
from __future__ import annotations

import numpy as np
import pytest

import rollqp
from rollqp.operators import SceneOperators
from rollqp.errors import InputError, SolverError
from rollqp.histories import Constant
from rollqp.methods import get_method
from rollqp.methods.alternation import Alternation
from rollqp.methods.nt_newton import AlternationNewton
from rollqp.methods.newton import NewtonMethod
from rollqp.problem import CoupledStep, Scales
from conftest import Delegate, scene_method_of

MU = 0.3

TOL = {
    # Newton ends at round-off (Φ piecewise linear); O(1) nondimensional unknowns.
    "roundoff": 1e-12,
    # central differences of a piecewise-linear function away from its kinks: round-off / h.
    "fd": 1e-7,
    # alternation stops at coupled residual <= its limit (Newton halves: 1e-10; QP halves:
    # residual_limit = 100·tolerance); traction differences follow within a small factor.
    "nt": 1e-9,
    # the agreement required on the exactly symmetric discretization (constant elements).
    "symmetric": 1e-9,
}


def dissimilar(element="constant", elements=40, **changes):
    """§6.2.1-like pair: ν_A = 0 on a practically rigid B (β ≈ 0.5), μ = 0.3, Q = 0."""
    base = {"bodies.A.E": 1000.0, "bodies.A.nu": 0.0, "bodies.B.E": 1e9, "bodies.B.nu": 0.3,
            "contact.friction": MU, "load.tangential": Constant(0.0), "load.start_steps": 10,
            "discretization.step": 0.25, "discretization.element": element,
            "discretization.elements": elements, "discretization.distance": 1.0}
    return rollqp.load_scene("cattaneo-carter").replace(**{**base, **changes})


def _rolling_step(scene, Qratio=0.3):
    """A coupled rolling step after a coupled static loading (the braked start in one step)."""
    model = SceneOperators.build(scene, symmetrized=False)
    P = scene.load.normal
    n = model.strip.n
    static = model.coupled_step(P, np.zeros(n), model.scales.length, Q=0.0)
    s0 = NewtonMethod().solve(static)
    c = -(model.history() @ model.w(s0.p, s0.t))
    step = model.coupled_step(P, c, scene.dq, Q=Qratio * MU * P)
    return model, static, s0, step


@pytest.fixture(scope="module", params=["constant", "quadratic"])
def case(request):
    scene = dissimilar(request.param)
    model, static, s0, step = _rolling_step(scene)
    sol = NewtonMethod().solve(step, warm=s0)
    return dict(scene=scene, model=model, static=static, s0=s0, step=step, sol=sol)


def _z(pb, sol):
    sc = pb.scales
    return np.concatenate([sol.p / sc.stress, sol.t / sc.stress, [sol.delta / sc.displacement],
                           [sol.xi / sc.slip]])


def _phi(pb, z, rN, rT):
    """Φ(z) from the problem's own gap and slip (docs/formulation.md §4), not the method's matrices."""
    sc, n = pb.scales, pb.n
    p, t = z[:n], z[n:2 * n]
    g = pb.gap(p * sc.stress, t * sc.stress, z[2 * n] * sc.displacement) / sc.displacement
    s = pb.slip(p * sc.stress, t * sc.stress, z[2 * n + 1] * sc.slip) / sc.slip
    yN, yT = rN * g, rT * s
    b = pb.mu * np.maximum(0.0, p - yN)
    return np.concatenate([np.minimum(p, yN), t - np.clip(t - yT, -b, b),
                           [(pb.f @ p * sc.stress - pb.P) / sc.force], [(pb.f @ t * sc.stress - pb.Q) / sc.force]])


# --------------------------------------------------------------------------- pseudo-Jacobian
def test_jacobian_matches_finite_differences(case):
    pb, sol = case["step"], case["sol"]
    meth = NewtonMethod()
    rN, rT = sol.info["r"]
    rng = np.random.default_rng(3)
    z = _z(pb, sol) + 1e-3 * rng.standard_normal(2 * pb.n + 2)
    phi, J, (nc, tc) = meth.residual_and_jacobian(pb, z)
    assert np.allclose(phi, _phi(pb, z, rN, rT), atol=TOL["roundoff"]), "Φ as defined in docs/formulation.md §4"
    h = 1e-6
    cols = []
    for k in range(z.size):
        e = np.zeros_like(z)
        e[k] = h
        cols.append((_phi(pb, z + e, rN, rT) - _phi(pb, z - e, rN, rT)) / (2 * h))
    Jfd = np.array(cols).T
    # rows whose case changes within ±h are on a kink: compare the others
    same = np.ones(J.shape[0], bool)
    for k in range(z.size):
        e = np.zeros_like(z)
        e[k] = h
        for sgn in (1, -1):
            _, _, (nc2, tc2) = meth.residual_and_jacobian(pb, z + sgn * e)
            same[:pb.n] &= nc2 == nc
            same[pb.n:2 * pb.n] &= tc2 == tc
    assert same.mean() > 0.9, "the perturbed point is away from most kinks"
    assert set(tc[same[pb.n:2 * pb.n]]) >= {"eq85", "eq86", "eq88"}, f"separation, stick and slip rows covered: {set(tc)}"
    err = np.abs(J - Jfd)[same].max()
    assert err <= TOL["fd"], f"J matches central differences off the kinks: {err:.2e}"


def _tiny(h, c, mu=0.5):
    """n nodes, identity influence, r = 1, δ = ξ = 0 prescribed: y_N = h + p, y_T = c + t.

    Then p − y_N = −h and t − y_T = −c, so h and c put each node in a chosen case of eq. 82–90
    exactly (all numbers are exact binary fractions).
    """
    n = len(h)
    I = np.eye(n)
    return CoupledStep(Ann=I, Att=I, Ant=None, Atn=None, f=np.ones(n), h=np.asarray(h, float), mu=mu,
                       c=np.asarray(c, float), dq=1.0, delta=0.0, xi=0.0, scales=Scales())


def test_every_case_of_eq_82_to_90():
    # node:      82     83    84    85     89    90    86    87    88
    h = np.array([1.0, 0.0, -2.0, 1.0, 0.0, 0.0, -2.0, -2.0, -2.0])
    c = np.array([0.0, 0.0, 0.0, 0.5, 0.5, 0.0, 0.5, 1.0, 3.0])  # bound μ·2 = 1 where h = −2
    pb = _tiny(h, c)
    n = h.size
    z = np.zeros(2 * n)
    phi, J, (nc, tc) = NewtonMethod(r=1.0).residual_and_jacobian(pb, z)
    assert list(nc[:3]) == ["eq82", "eq83", "eq84"], nc
    assert list(tc[3:]) == ["eq85", "eq89", "eq90", "eq86", "eq87", "eq88"], tc
    I = np.eye(2 * n)
    KN = np.hstack([np.eye(n), np.zeros((n, n))])  # ∂y_N = ∂(h + p)
    KT = np.hstack([np.zeros((n, n)), np.eye(n)])  # ∂y_T = ∂(c + t)
    # normal rows: 82 and 83 (modified) → e_p; 84 → ∂y_N
    for i, row in ((0, I[0]), (1, I[1]), (2, KN[2])):
        assert np.array_equal(J[i], row), f"normal node {i}: {nc[i]}"
    # tangential rows: 85, 89, 90 (zero bound) → e_t; 86, 87 (modified) → ∂y_T;
    # 88 → e_t − σμ(e_p − ∂y_N) with σ = sgn(t − y_T) = sgn(−c) = −1
    for i in (3, 4, 5):
        assert np.array_equal(J[n + i], I[n + i]), f"{tc[i]}: row e_t"
    for i in (6, 7):
        assert np.array_equal(J[n + i], KT[i]), f"{tc[i]}: row ∂y_T"
    sigma, mu = -1.0, 0.5
    assert np.array_equal(J[n + 8], I[n + 8] - sigma * mu * (I[8] - KN[8])), "eq. 88: slip row with the bound's derivative"
    # the modified rows are one-sided derivatives: the directional derivative into the case chosen
    for i, k in ((1, 1), (4, 4), (7, n + 7)):
        e = np.zeros(2 * n)
        e[k] = 1e-3  # into p > y_N for node 1, b > 0 for node 4, t inside the stick band for node 7
        d = (NewtonMethod(r=1.0).residual_and_jacobian(pb, z + e)[0] - phi) / 1e-3
        row = n + i if i >= 3 else i
        assert np.isclose(d[row], J[row] @ (e / 1e-3)), f"node {i}: one-sided derivative"


def test_degenerate_cases_still_solve():
    """Nodes on kinks (p = g = 0, bound exactly zero) do not stop the iteration."""
    n = 9
    pb = _tiny(np.array([1.0, 0.0, -2.0, 1.0, 0.0, 0.0, -2.0, -2.0, -2.0]),
               np.array([0.0, 0.0, 0.0, 0.5, 0.5, 0.0, 0.5, 1.0, 3.0]))
    sol = NewtonMethod(r=1.0).solve(pb, warm=rollqp.StepSolution(p=np.zeros(n), t=np.zeros(n), delta=0.0, xi=0.0))
    assert sol.residual <= TOL["roundoff"]
    # closed form of the tiny problem: p = max(0, −h) (g = h + p = 0 in contact), t from the box
    assert np.allclose(sol.p, np.maximum(0.0, -pb.h))


# --------------------------------------------------------------------------- convergence
def test_quadratic_convergence_at_the_end(case):
    """From a perturbed start the residual history ends quadratically (indeed finitely)."""
    pb, sol = case["step"], case["sol"]
    start = rollqp.StepSolution(p=sol.p * 1.02, t=sol.t * 0.9, delta=sol.delta * 1.01, xi=sol.xi)
    s = NewtonMethod().solve(pb, warm=start)
    hist = np.array(s.info["history"])
    assert hist[-1] <= 1e-10 * min(1.0, *s.info["r"]), f"converged: {hist}"
    assert len(hist) >= 3, f"a real iteration: {hist}"
    # the last two reductions: e_{k+1} <= C e_k² with a modest C, or exact termination
    tail = hist[-3:]
    assert tail[2] <= max(10.0 * tail[1] ** 2, 1e-13), f"quadratic at the end: {hist}"
    assert s.residual <= 1e-10
    assert np.max(np.abs(s.t - sol.t)) / (MU * pb.scales.stress) <= TOL["roundoff"] * 100


def test_armijo_and_counts(case):
    s = case["sol"]
    assert s.iterations == len(s.info["steps"]) and s.iterations >= 1
    merits = s.info["merits"]
    for k, a in enumerate(s.info["steps"]):
        assert merits[k + 1] <= (1 - 2 * 0.1 * a) * merits[k] + 1e-30 or s.info["nonmonotone"], "Armijo (eq. 78)"
    assert {"merit", "history", "start"} <= set(s.extras) and s.backtracks >= 0


def test_cold_start_converges(case):
    s = NewtonMethod().solve(case["step"])
    assert s.info["start"] == "cold" and s.residual <= 1e-10
    assert np.max(np.abs(s.t - case["sol"].t)) / (MU * case["step"].scales.stress) <= 1e-9


def test_non_convergence_names_merit_and_iterations(case):
    with pytest.raises(SolverError) as info:
        NewtonMethod(max_iterations=1).solve(case["step"], warm=rollqp.StepSolution(
            p=case["sol"].p * 1.05, t=0.5 * case["sol"].t, delta=case["sol"].delta, xi=0.0))
    err = info.value
    assert "coupled" in str(err) and "merit" in str(err) and err.iterations == 1 and err.residual > 0


def test_prescribed_delta_and_xi(case):
    """δ and ξ prescribed at the solution's values give back the same tractions."""
    pb, sol = case["step"], case["sol"]
    pb2 = pb.replace(P=None, delta=sol.delta, Q=None, xi=sol.xi)
    s2 = NewtonMethod().solve(pb2, warm=sol)
    assert s2.residual <= 1e-10
    assert np.max(np.abs(s2.p - sol.p)) / pb.scales.stress <= 1e-8  # conditioning of δ → p, ~1e2
    assert np.max(np.abs(s2.t - sol.t)) / (MU * pb.scales.stress) <= 1e-8


# --------------------------------------------------------------------------- alternation
@pytest.mark.parametrize("inner", ["newton", "qp-osqp", "qp-clarabel"])
def test_alternation_agrees_with_coupled_newton(case, inner):
    pb, sol = case["step"], case["sol"]
    meth = AlternationNewton() if inner == "newton" else Alternation(get_method(inner, tolerance=1e-11))
    s = meth.solve(pb, warm=case["s0"])
    sc = pb.scales
    assert s.outer >= 2, "the halves really alternate (β ≠ 0)"
    assert s.inner_normal >= 0 and s.inner_tangential >= 1
    assert s.residual <= meth.stall_limit
    dt = np.max(np.abs(s.t - sol.t)) / (MU * sc.stress)
    dp = np.max(np.abs(s.p - sol.p)) / sc.stress
    assert dt <= TOL["nt"] and dp <= TOL["nt"], f"{inner}: |Δt| {dt:.1e} μp0, |Δp| {dp:.1e} p0"


def test_alternation_passes_uncoupled_problems_through(case):
    meth = AlternationNewton()
    normal = case["step"].normal_half(case["sol"].t)
    assert meth.solve(normal).method == "newton", "normal halves go to the inner method"


def test_alternation_gives_up_clearly(case):
    meth = Alternation(NewtonMethod(), max_outer=1)
    with pytest.raises(SolverError) as info:
        meth.solve(case["step"])
    assert "N-T alternation" in str(info.value) and info.value.residual > meth.limit


# --------------------------------------------------------------------------- coupling levels, driver
def _kinds(monkeypatch, scene, method):
    """Run ``scene`` and return the set of step-problem kinds the method was asked to solve."""
    seen = set()

    class Spy(Delegate):
        def solve(self, problem, warm=None):
            seen.add(problem.kind)
            return self.inner.solve(problem, warm=warm)

    r = rollqp.run(scene, method=Spy(scene_method_of(scene, method)))
    return seen, r


@pytest.mark.parametrize("level", ["off", "goodman"])
@pytest.mark.parametrize("method", ["qp-osqp", "newton"])
def test_goodman_and_off_keep_the_two_half_path(monkeypatch, level, method):
    seen, r = _kinds(monkeypatch, dissimilar(**{"contact.coupling": level}), method)
    assert seen == {"normal", "tangential"}, f"{level}: only the two halves: {seen}"
    if level == "off":
        assert np.all(r["pt"] == 0.0), "no coupling, Q = 0: no shear at all"
    else:
        assert np.max(np.abs(r["pt"])) > 1e-3 * MU * r["p0"], "goodman: the pressure makes shear"


def test_full_coupling_uses_the_coupled_step(monkeypatch):
    seen, _ = _kinds(monkeypatch, dissimilar(), "newton")
    # (its cold start at the first loading step is one sweep of the halves)
    assert "coupled" in seen, f"newton gets coupled steps: {seen}"
    seen, _ = _kinds(monkeypatch, dissimilar(), "qp-osqp")
    assert seen == {"normal", "tangential"}, f"QP methods get the halves of the alternation: {seen}"


def test_model_builds_only_what_the_level_needs():
    for level, (tn, nt) in {"off": (False, False), "goodman": (True, False), "full": (True, True)}.items():
        m = SceneOperators.build(dissimilar(**{"contact.coupling": level}), symmetrized=False)
        assert (m.Atn is not None, m.Ant is not None) == (tn, nt), level
    m = SceneOperators.build(rollqp.load_scene("cattaneo-carter"), symmetrized=False)
    assert m.Atn is None and m.Ant is None, "similar bodies: auto → off, no coupling matrices"


@pytest.mark.parametrize("method", ["newton", "nt-newton", "qp-osqp"])
def test_full_coupling_methods_agree_over_a_transient(method):
    """Every step of a short coupled transient, against coupled Newton (constant elements)."""
    scene = dissimilar(**{"discretization.distance": 0.5})
    ref = rollqp.run(scene, method="newton")
    r = rollqp.run(scene, method=method)
    dt = np.max(np.abs(r["pt"] - ref["pt"])) / (MU * ref["p0"])
    dp = np.max(np.abs(r["pn"] - ref["pn"])) / ref["p0"]
    assert dt <= TOL["symmetric"] and dp <= TOL["symmetric"], f"{method}: {dt:.1e} μp0, {dp:.1e} p0"
    if method != "newton":
        assert np.all(r["iterations"][1:] >= 2), "outer iterations are recorded"
        assert np.all(r["inner_tangential"][1:] >= 1)


def test_swapping_bodies_flips_beta_shear_and_creepage():
    """A ↔ B: β and the shear on 'A' change sign, the pressure does not (docs/formulation.md §3)."""
    scene = dissimilar(**{"discretization.distance": 0.5})
    d = scene.to_dict()
    swapped = scene.replace(**{f"bodies.A.{k}": d["bodies"]["B"][k] for k in ("E", "nu")},
                            **{f"bodies.B.{k}": d["bodies"]["A"][k] for k in ("E", "nu")})
    assert swapped.beta == pytest.approx(-scene.beta, rel=1e-12)
    a, b = rollqp.run(scene, method="newton"), rollqp.run(swapped, method="newton")
    # radii are not swapped (h is symmetric in them), so the problems are exact mirrors
    assert np.max(np.abs(a["pn"] - b["pn"])) / a["p0"] <= 1e-10
    assert np.max(np.abs(a["pt"] + b["pt"])) / (MU * a["p0"]) <= 1e-10
    assert np.max(np.abs(a["creepage"] + b["creepage"])) <= 1e-10 * MU * a["a_H"] / a["R"]


def test_braked_start_goodman_state():
    """Normal load in N steps with β ≠ 0: shear with Q = 0, |t| <= μp, slip at the edges."""
    for N in (1, 10):
        r = rollqp.run(dissimilar(**{"load.start_steps": N, "discretization.distance": 0.0}), method="newton")
        p, t, st = r["pn"][0], r["pt"][0], r["state"][0]
        assert abs(r["Q"][0]) <= 1e-10 * r["a_H"] * r["p0"], "free: Q = 0"
        assert np.max(np.abs(t)) > 0.05 * MU * r["p0"], "the pressure makes shear (β = 0.5)"
        assert np.all(np.abs(t) <= MU * np.maximum(p, 0) * (1 + 1e-10) + 1e-12 * r["p0"])
        assert (st == 2).any() and (st == 1).any(), "stick in the middle, slip at the edges"
    # similar bodies: the normal load makes no shear at all, whatever N
    r = rollqp.run(rollqp.load_scene("cattaneo-carter").replace(
        **{"load.tangential": Constant(0.0), "discretization.distance": 0.0, "load.start_steps": 5}), method="newton")
    assert np.all(r["pt"][0] == 0.0)


def test_coupled_step_validates_input():
    n = 3
    I = np.eye(n)
    with pytest.raises(InputError, match="Q"):
        CoupledStep(Ann=I, Att=I, Ant=None, Atn=None, f=np.ones(n), h=np.zeros(n), mu=0.1, c=np.zeros(n),
                    dq=1.0, P=1.0, Q=0.2)
    with pytest.raises(InputError, match="P / delta"):
        CoupledStep(Ann=I, Att=I, Ant=None, Atn=None, f=np.ones(n), h=np.zeros(n), mu=0.1, c=np.zeros(n),
                    dq=1.0, Q=0.0)
    with pytest.raises(InputError, match="Ant"):
        CoupledStep(Ann=I, Att=I, Ant=np.eye(2), Atn=None, f=np.ones(n), h=np.zeros(n), mu=0.1, c=np.zeros(n),
                    dq=1.0, P=1.0, Q=0.0)


@pytest.mark.parametrize("mu", [0.01, 0.03])
def test_small_friction_goodman_loading(mu):
    """At small μ almost every node slips during the Goodman loading; a warm Newton start
    can then fall on a Newton fixed point with a wrong active set (Armijo fails, the full step
    reproduces the point). Newton sweeps the halves (coupled) or restarts cold (halves) there
    and must agree with the alternation."""
    scene = rollqp.load_scene("goodman-bentall").replace(
        **{"contact.friction": mu, "discretization.distance": 0.0, "load.start_steps": 10})
    a, b = rollqp.run(scene, method="newton"), rollqp.run(scene, method="nt-newton")
    assert a["residual"].max() <= 1e-10
    # the alternation stops at a coupled residual of 1e-10 (p0 units): /μ in μp0 units
    assert np.max(np.abs(a["pt"] - b["pt"])) / (mu * a["p0"]) <= 1e-9 / mu
