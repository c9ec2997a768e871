"""Step problems and solutions (rollqp.problem; docs/formulation.md §4–6, paper eq. 49–71).

No solver is called here: every check uses a solution known exactly by construction.

* Residuals vanish at a known solution and measure each violated condition by its size
  (Signorini, friction law, load equations).
* classify, compare and Scales.hertz on hand-computable data.
* Input validation: a bad argument is an InputError that names it.
* QPForm's multiplier sign conventions: the approach and the creepage recovered from the
  equality multiplier equal those read off the gap and the slip.

The toy problems use a diagonal ``A = 2 I``, unit weights and dyadic numbers, so that every
expected residual is exact in floating point (tolerance 0); the Hertz-scaled problems are
checked to round-off, with the size of the numbers involved stated beside each tolerance.
"""
from __future__ import annotations

import numpy as np
import pytest

import rollqp
from rollqp import InputError, NormalStep, Residuals, Scales, StepSolution, TangentialStep, classify, compare
from rollqp.problem import SEPARATION, SLIP, STICK

from conftest import MU, P, R, ESTAR

# ------------------------------------------------------------------------------- toy data
N_TOY = 4
A_TOY = 2.0 * np.eye(N_TOY)
F_TOY = np.ones(N_TOY)
# Normal: nodes 0 and 3 separated, 1 and 2 in contact.
P_TOY = np.array([0.0, 1.0, 3.0, 0.0])
G_TOY = np.array([2.0, 0.0, 0.0, 1.0])
DELTA_TOY = 5.0
# Tangential: μ = 0.5 on p = (0, 2, 2, 2): bounds (0, 1, 1, 1). Node 0 carries no friction
# (any slip), node 1 slips with t = +μp and s < 0, node 2 sticks, node 3 slips with t = −μp, s > 0.
MU_TOY = 0.5
PT_TOY = np.array([0.0, 2.0, 2.0, 2.0])
T_TOY = np.array([0.0, 1.0, 0.5, -1.0])
S_TOY = np.array([0.5, -0.5, 0.0, 0.25])
XI_TOY = 0.25
DQ_TOY = 1.0


def normal_toy(p=P_TOY, g=G_TOY, delta=DELTA_TOY, prescribe="P", **kw) -> NormalStep:
    """The normal step whose gap at ``(p, delta)`` is ``g``: ``h = g + δ − A p``.

    ``prescribe="P"``: the load P = fᵀp (unless given); ``"delta"``: the approach δ.
    """
    p, g = np.asarray(p, float), np.asarray(g, float)
    if prescribe == "delta":
        kw["delta"] = delta
    else:
        kw.setdefault("P", float(F_TOY @ p))
    return NormalStep(A=A_TOY, f=F_TOY, h=g + delta - A_TOY @ p, **kw)


def tangential_toy(t=T_TOY, s=S_TOY, xi=XI_TOY, prescribe="Q", **kw) -> TangentialStep:
    """The tangential step whose slip at ``(t, xi)`` is ``s``: ``c = Δq(s − ξ) − A t``.

    ``prescribe="Q"``: the load Q = fᵀt (unless given); ``"xi"``: the creepage ξ.
    """
    t, s = np.asarray(t, float), np.asarray(s, float)
    if prescribe == "xi":
        kw["xi"] = xi
    else:
        kw.setdefault("Q", float(F_TOY @ t))
    return TangentialStep(A=A_TOY, f=F_TOY, p=PT_TOY, mu=MU_TOY, c=DQ_TOY * (s - xi) - A_TOY @ t,
                          dq=DQ_TOY, **kw)


def with_node(v, i, value):
    out = np.array(v, dtype=float)
    out[i] = value
    return out


# ------------------------------------------------------------------------------- residuals
def test_normal_residuals_zero_at_known_solution():
    prob = normal_toy()
    assert np.array_equal(prob.gap(P_TOY, DELTA_TOY), G_TOY), "the toy is built with this gap"
    res = prob.residuals(P_TOY, DELTA_TOY)
    # dyadic data: every operation is exact, so the residual is exactly zero
    assert res.signorini == 0.0, f"Signorini residual at the exact solution: {res}"
    assert res.load_normal == 0.0, f"load residual at the exact solution: {res}"
    assert res.max == 0.0, f"max residual at the exact solution: {res}"


@pytest.mark.parametrize("p, g, expected", [
    pytest.param(with_node(P_TOY, 0, -0.5), G_TOY, 0.5, id="negative-pressure"),
    pytest.param(P_TOY, with_node(G_TOY, 1, -0.25), 0.25, id="negative-gap"),
    pytest.param(with_node(P_TOY, 3, 0.25), G_TOY, 0.25, id="pressure-and-gap"),
])
def test_signorini_residual_measures_the_violation(p, g, expected):
    # δ prescribed: no load equation, so the Signorini row alone is violated
    prob = normal_toy(p=p, g=g, prescribe="delta")
    res = prob.residuals(np.asarray(p, float), DELTA_TOY)
    assert res.signorini == expected, f"max |min(p, g)| should be {expected}: {res}"
    assert res.load_normal == 0.0, f"no load equation with δ prescribed: {res}"


def test_normal_load_residual():
    prob = normal_toy().replace(P=float(F_TOY @ P_TOY) + 0.5)
    res = prob.residuals(P_TOY, DELTA_TOY)
    assert res.load_normal == 0.5, f"|fᵀp − P|/(a_H p0) should be 0.5: {res}"
    assert res.signorini == 0.0, f"Signorini still holds: {res}"


def test_tangential_residuals_zero_at_known_solution():
    prob = tangential_toy()
    assert np.array_equal(prob.slip(T_TOY, XI_TOY), S_TOY), "the toy is built with this slip"
    res = prob.residuals(T_TOY, XI_TOY)
    assert res.friction == 0.0, f"friction residual at the exact solution (dyadic data): {res}"
    assert res.load_tangential == 0.0, f"load residual at the exact solution: {res}"


@pytest.mark.parametrize("t, s, expected", [
    pytest.param(with_node(T_TOY, 2, 1.5), S_TOY, 0.5, id="above-friction-bound"),
    pytest.param(T_TOY, with_node(S_TOY, 2, 0.25), 0.25, id="stick-node-slips"),
    pytest.param(T_TOY, with_node(S_TOY, 1, 0.5), 0.5, id="slip-along-traction"),
    pytest.param(with_node(T_TOY, 0, 0.125), S_TOY, 0.125, id="traction-without-pressure"),
])
def test_friction_residual_measures_the_violation(t, s, expected):
    # ξ prescribed: no load equation, so the friction row alone is violated
    prob = tangential_toy(t=t, s=s, prescribe="xi")
    res = prob.residuals(np.asarray(t, float), XI_TOY)
    assert res.friction == expected, f"max |t − Proj(t − s)| should be {expected}: {res}"
    assert res.load_tangential == 0.0, f"no load equation with ξ prescribed: {res}"


def test_tangential_load_residual():
    prob = tangential_toy().replace(Q=float(F_TOY @ T_TOY) - 0.25)
    res = prob.residuals(T_TOY, XI_TOY)
    assert res.load_tangential == 0.25, f"|fᵀt − Q|/(a_H p0) should be 0.25: {res}"
    assert res.friction == 0.0, f"the friction law still holds: {res}"


def test_residuals_are_nondimensional():
    """Pressures are measured in p0, gaps in u0 = a p0/E*, loads in a p0."""
    sc = Scales(length=2.0, stress=8.0, modulus=4.0)   # u0 = 4, a p0 = 16
    prob = normal_toy(p=with_node(P_TOY, 3, 0.5), P=float(F_TOY @ P_TOY) + 0.5 + 4.0, scales=sc)
    res = prob.residuals(with_node(P_TOY, 3, 0.5), DELTA_TOY)
    # node 3: p = 0.5, g = 1 + 2·0.5 = 2 → min(0.5/8, 2/4) = 1/16; load off by 4 → 4/16
    assert res.signorini == 1 / 16, f"Signorini residual in p0 and u0: {res}"
    assert res.load_normal == 1 / 4, f"load residual in a·p0: {res}"


def test_residuals_combine_by_maximum():
    a = Residuals(signorini=1e-3, friction=2e-9, load_normal=0.0, load_tangential=5e-4)
    b = Residuals(signorini=1e-6, friction=3e-2, load_normal=1e-7, load_tangential=0.0)
    c = a | b
    assert (c.signorini, c.friction, c.load_normal, c.load_tangential) == (1e-3, 3e-2, 1e-7, 5e-4), \
        f"| takes the componentwise maximum: {c}"
    assert c.max == 3e-2, f"max is the largest component: {c}"


def test_nan_residual_is_not_reported_as_zero():
    res = Residuals(friction=float("nan"))
    assert not res.max <= 1.0, f"a NaN residual must not pass a residual limit: max = {res.max}"


def test_hertz_scaled_residuals_vanish_at_constructed_solution(constant_problem):
    """A known solution on the §6.1.1 rollers: Hertz pressure, gap opened outside the contact."""
    hp = constant_problem
    p = hp.p_hertz
    delta = 6.0 * hp.scales.displacement
    g = np.where(p > 0, 0.0, (hp.x ** 2 - hp.a ** 2) / (2 * R))
    prob = rollqp.NormalStep(A=hp.influence.Ann, f=hp.f, h=g + delta - hp.influence.Ann @ p,
                             P=float(hp.f @ p), scales=hp.scales)
    res = prob.residuals(p, delta)
    # round-off of h − δ + A p with δ/u0 = 6 and (A p)/u0 of the same size: ~1e-15
    assert res.max <= 1e-13, f"residual at the constructed solution: {res}"
    bad = prob.residuals(p, delta + 1e-3 * hp.scales.displacement)
    # 1e-3 recovered from differences of O(6) numbers: ~1e-15/1e-3 = 1e-12 relative
    # a rigid approach 1e-3 u0 too far closes the gap by 1e-3 u0 at every contact node
    assert bad.signorini == pytest.approx(1e-3, rel=1e-9), f"Signorini residual of a shifted δ: {bad}"


# ------------------------------------------------------------------------------- classify
def test_classify_states():
    state = classify(PT_TOY, T_TOY, S_TOY, MU_TOY)
    assert state.dtype == np.int8, f"states are int8 (SPEC.md): {state.dtype}"
    assert state.tolist() == [SEPARATION, SLIP, STICK, SLIP], f"separation, slip, stick, slip: {state}"
    assert (SEPARATION, STICK, SLIP) == (0, 1, 2), "SPEC.md codes: 0 separation, 1 stick, 2 slip"


def test_classify_slip_needs_the_bound_and_a_slip():
    p = np.array([2.0, 2.0, 2.0])
    t = np.array([0.5, 1.0, 1.0 - 1e-3])
    s = np.array([0.25, 0.0, -0.5])
    # node 0: slips but |t| < μp (a residual, not a state) → stick; node 1: at the bound
    # without slip → stick; node 2: below the bound by 1e-3 → stick despite s ≠ 0.
    assert classify(p, t, s, MU_TOY).tolist() == [STICK, STICK, STICK], "stick unless |t| = μp and s ≠ 0"
    assert classify(p, None, None, MU_TOY).tolist() == [STICK] * 3, "normal problem only: contact is stick"


def test_classify_uses_scales_and_tolerance():
    sc = Scales(stress=1e6, modulus=1e9)          # slips in p0/E* = 1e-3
    p = np.array([5e-2, 1e6, 1e6])                 # 5e-8 p0: below tol 1e-7 → separation
    t = np.array([0.0, 1e5, 1e5])
    s = np.array([0.0, 5e-11, -1e-4])              # 5e-8 and 0.1 in p0/E*
    assert classify(p, t, s, 0.1, sc).tolist() == [SEPARATION, STICK, SLIP], \
        "pressure and slip compared with tol in p0 and p0/E* units"
    assert classify(p, t, s, 0.1, sc, tol=1e-9).tolist() == [STICK, SLIP, SLIP], "a smaller tol"


# ------------------------------------------------------------------------------- compare
def test_compare_reports_scaled_differences():
    sc = Scales(length=2.0, stress=4.0, modulus=8.0)   # u0 = 1, p0/E* = 0.5
    p = np.array([0.0, 4.0, 4.0])
    a = StepSolution(p=p, t=np.array([0.0, 0.4, -0.4]), s=np.array([0.0, 0.0, 1.0]), delta=3.0, xi=0.25)
    b = StepSolution(p=p + np.array([0.0, 0.5, 0.0]), t=np.array([0.0, 0.4, -0.3]),
                     s=np.array([0.0, 0.0, 1.0]), delta=2.5, xi=0.0)
    d = compare(a, b, mu=0.1, scales=sc)
    # dyadic data except μ = 0.1: exact, or one rounding of 0.1 (rel 1e-12 for Δt)
    assert d["p"] == pytest.approx(0.5 / 4.0, rel=1e-15), f"max|Δp|/p0: {d}"
    assert d["t"] == pytest.approx(0.1 / (0.1 * 4.0), rel=1e-12), f"max|Δt|/(μ p0): {d}"
    assert d["delta"] == pytest.approx(0.5, rel=1e-15), f"|Δδ|/u0: {d}"
    assert d["xi"] == pytest.approx(0.5, rel=1e-15), f"|Δξ|/(p0/E*): {d}"
    # node 2 slips in a (|t| = μp = 0.4, s = 1) and sticks in b (|t| = 0.3 < 0.4)
    assert d["state_differs"].tolist() == [2], f"nodes whose state differs: {d}"


def test_compare_normal_only():
    a = StepSolution(p=np.array([1.0, 2.0]), delta=1.0)
    b = StepSolution(p=np.array([1.0, 2.5]), delta=1.0)
    d = compare(a, b)
    assert set(d) == {"p", "delta", "state_differs"}, f"only what both solutions have: {sorted(d)}"
    assert (d["p"], d["delta"], d["state_differs"].size) == (0.5, 0.0, 0), f"differences: {d}"


# ------------------------------------------------------------------------------- Scales
def test_scales_hertz():
    sc = Scales.hertz(P, R, ESTAR)
    a = np.sqrt(4 * P * R / (np.pi * ESTAR))
    # closed forms evaluated two ways: round-off only
    assert sc.length == pytest.approx(a, rel=1e-15), "a_H² = 4PR/(πE*)"
    assert sc.stress == pytest.approx(a * ESTAR / (2 * R), rel=1e-14), "p0 = 2P/(πa) = aE*/(2R)"
    assert sc.modulus == ESTAR, "modulus is E*"
    assert sc.displacement == pytest.approx(a * a / (2 * R), rel=1e-14), "u0 = a p0/E* = a²/(2R)"
    assert sc.slip == pytest.approx(a / (2 * R), rel=1e-14), "slip unit p0/E* = a/(2R)"
    assert sc.force == pytest.approx(2 * P / np.pi, rel=1e-14), "force unit a p0 = 2P/π"


@pytest.mark.parametrize("field, value", [
    pytest.param("length", 0.0, id="zero-length"),
    pytest.param("stress", -1.0, id="negative-stress"),
    pytest.param("modulus", float("inf"), id="infinite-modulus"),
])
def test_scales_reject_bad_values(field, value):
    with pytest.raises(InputError) as info:
        Scales(**{field: value})
    assert info.value.key == f"scales.{field}", f"the error names scales.{field}: {info.value}"


# ------------------------------------------------------------------------------- validation
def _normal_kw(**changes):
    kw = dict(A=A_TOY, f=F_TOY, h=np.ones(N_TOY), P=1.0)
    kw.update(changes)
    return {k: v for k, v in kw.items() if v is not None}


def _tangential_kw(**changes):
    kw = dict(A=A_TOY, f=F_TOY, p=PT_TOY, mu=MU_TOY, c=np.zeros(N_TOY), dq=1.0, Q=0.5)
    kw.update(changes)
    return {k: v for k, v in kw.items() if v is not None}


@pytest.mark.parametrize("kw, key", [
    pytest.param(_normal_kw(A=np.eye(3)), "A", id="A-shape"),
    pytest.param(_normal_kw(A=np.full((N_TOY, N_TOY), np.nan)), "A", id="A-nan"),
    pytest.param(_normal_kw(h=np.ones(N_TOY + 1)), "h", id="h-shape"),
    pytest.param(_normal_kw(f=np.array([1.0, 1.0, 0.0, 1.0])), "f", id="f-zero-weight"),
    pytest.param(_normal_kw(f=np.ones((N_TOY, 1))), "f", id="f-2d"),
    pytest.param(_normal_kw(offset=np.ones(2)), "offset", id="offset-shape"),
    pytest.param(_normal_kw(P=0.0), "P", id="P-zero"),
    pytest.param(_normal_kw(P=-1.0), "P", id="P-negative"),
    pytest.param(_normal_kw(P=float("nan")), "P", id="P-nan"),
    pytest.param(_normal_kw(delta=1.0), "P / delta", id="P-and-delta"),
    pytest.param(_normal_kw(P=None), "P / delta", id="neither-P-nor-delta"),
])
def test_normal_step_validation(kw, key):
    with pytest.raises(InputError) as info:
        NormalStep(**kw)
    assert info.value.key == key, f"the error names {key!r}: {info.value}"
    assert str(info.value).startswith(f"{key}: "), f"the message starts with the name: {info.value}"


@pytest.mark.parametrize("kw, key", [
    pytest.param(_tangential_kw(A=np.eye(N_TOY + 1)), "A", id="A-shape"),
    pytest.param(_tangential_kw(p=np.ones(3)), "p", id="p-shape"),
    pytest.param(_tangential_kw(c=np.ones(5)), "c", id="c-shape"),
    pytest.param(_tangential_kw(f=-F_TOY), "f", id="f-negative"),
    pytest.param(_tangential_kw(mu=-0.1), "mu", id="mu-negative"),
    pytest.param(_tangential_kw(dq=0.0), "dq", id="dq-zero"),
    # μ fᵀp = 0.5·6 = 3: the sliding limit itself and beyond it have no stick solution
    pytest.param(_tangential_kw(Q=3.0), "Q", id="Q-at-sliding-limit"),
    pytest.param(_tangential_kw(Q=-3.5), "Q", id="Q-beyond-sliding-limit"),
    pytest.param(_tangential_kw(xi=0.1), "Q / xi", id="Q-and-xi"),
    pytest.param(_tangential_kw(Q=None), "Q / xi", id="neither-Q-nor-xi"),
])
def test_tangential_step_validation(kw, key):
    with pytest.raises(InputError) as info:
        TangentialStep(**kw)
    assert info.value.key == key, f"the error names {key!r}: {info.value}"
    assert str(info.value).startswith(f"{key}: "), f"the message starts with the name: {info.value}"


def test_load_just_below_the_sliding_limit_is_accepted():
    prob = TangentialStep(**_tangential_kw(Q=-3.0 * (1 - 1e-12)))
    assert prob.Q < 0 and prob.n == N_TOY, "|Q| < μ fᵀp is a valid stick problem"


@pytest.mark.parametrize("make", [
    pytest.param(lambda: NormalStep(**_normal_kw(P=None, delta=float("nan"))), id="delta-nan"),
    pytest.param(lambda: TangentialStep(**_tangential_kw(Q=None, xi=float("inf"))), id="xi-inf"),
])
def test_non_finite_prescribed_approach_or_creepage_rejected(make):
    with pytest.raises(InputError):
        make()


# ------------------------------------------------------------------------------- QPForm signs
def test_normal_multiplier_is_minus_the_approach(constant_problem):
    """At a known solution, ∇ = Hx + q = −y a on the contact nodes, and −y maps to δ.

    The Lagrangian is ½xᵀHx + qᵀx + y(aᵀx − b) − λᵀx with λ ≥ 0 the multipliers of x ≥ 0
    (QPForm docstring); KKT gives F̂ĝ ∝ λ, so λ > 0 exactly where the gap is open.
    """
    hp = constant_problem
    p = hp.p_hertz
    delta = 6.0 * hp.scales.displacement
    g = np.where(p > 0, 0.0, (hp.x ** 2 - hp.a ** 2) / (2 * R))     # open outside the contact
    prob = rollqp.NormalStep(A=hp.influence.Ann, f=hp.f, h=g + delta - hp.influence.Ann @ p,
                             P=float(hp.f @ p), scales=hp.scales)
    form = prob.qp_form()
    x = p / hp.p0
    grad = form.H @ x + form.q
    contact = p > 0
    y_nodes = -grad[contact] / form.a[contact]
    y = float(np.mean(y_nodes))
    # the gradient is F̂(ĥ + Âp̂)/obj with entries ~10: round-off ~1e-14 relative
    assert np.ptp(y_nodes) <= 1e-12 * abs(y), f"−∇/a is one constant on the contact: spread {np.ptp(y_nodes)}"
    assert y < 0, f"a positive approach is a negative multiplier: y = {y}"
    lam = grad + y * form.a
    assert np.all(lam[~contact] > 0), "bound multipliers are positive where the gap is open"
    sol = prob.solution_from_qp(form, x, y)
    assert sol.delta == pytest.approx(delta, rel=1e-12), f"δ from the multiplier {sol.delta} vs {delta}"
    assert np.max(np.abs(sol.g[contact])) <= 1e-12 * delta, "the recovered δ closes the gap on the contact"
    assert form.unscaled_multiplier(y) * hp.scales.displacement == pytest.approx(-delta, rel=1e-12), \
        "unscaled_multiplier(y) is −δ̂ for the normal step"


def test_tangential_multiplier_is_the_creepage(constant_problem):
    """At a known solution, ∇ = −y a on the stick nodes and y maps to ξ; bound multipliers
    ν = −(∇ + y a) are ≥ 0 where t = +μp (slip s < 0) and ≤ 0 where t = −μp (s > 0)."""
    hp = constant_problem
    p = hp.p_hertz
    bound = MU * p
    c_stick = 0.5 * hp.a
    stick = np.abs(hp.x) < c_stick
    # Cattaneo-like: stick in the middle, t = +μp slipping backwards (s < 0) outside it
    t = np.where(stick, 0.6 * bound, bound)
    s = np.where(stick, 0.0, -(np.abs(hp.x) - c_stick) / hp.a * hp.scales.slip)
    s = np.where(p > 0, s, 0.3 * hp.scales.slip)        # separated nodes slip freely
    xi = -4.0 * hp.scales.slip
    dq = hp.dq
    prob = rollqp.TangentialStep(A=hp.influence.Att, f=hp.f, p=p, mu=MU,
                                 c=dq * (s - xi) - hp.influence.Att @ t, dq=dq,
                                 Q=float(hp.f @ t), scales=hp.scales)
    assert prob.residuals(t, xi).max <= 1e-12, "the construction is a solution (round-off of c)"
    form = prob.qp_form()
    x = t / hp.p0
    grad = form.H @ x + form.q
    y_nodes = -grad[stick] / form.a[stick]
    y = float(np.mean(y_nodes))
    # round-off of F̂(ĉ + Ât̂)/Δq̂ with entries ~ξ̂ = 4: ~1e-14 relative
    assert np.ptp(y_nodes) <= 1e-12 * abs(y), f"−∇/a is one constant on the stick zone: {np.ptp(y_nodes)}"
    sol = prob.solution_from_qp(form, x, y)
    assert sol.xi == pytest.approx(xi, rel=1e-12), f"ξ from the multiplier {sol.xi} vs {xi}"
    assert np.sign(y) == np.sign(xi), f"y has the sign of ξ (ξ̂ = y·obj/eq): y = {y}, ξ = {xi}"
    assert np.max(np.abs(sol.s[stick])) <= 1e-12 * abs(xi), "the recovered ξ gives no slip on the stick zone"
    nu = -(grad + y * form.a)                         # multiplier of x <= u (t <= μp)
    upper = (p > 0) & ~stick                          # t = +μp, s < 0
    assert np.all(nu[upper] > 0), "upper-bound multipliers are positive where t = +μp slips backwards"
    # and they are F̂ŝ scaled: ν = −f̂ ŝ/obj (KKT of the QP, docs/formulation.md §6)
    fh = hp.f / hp.a
    expected = -fh[upper] * (s[upper] / hp.scales.slip) / form.obj_scale
    # ν is a difference of O(ξ̂ = 4) terms; where ŝ ~ 1e-2 the cancellation leaves ~1e-13 relative
    assert np.allclose(nu[upper], expected, rtol=1e-9, atol=0), "bound multipliers equal −F̂ŝ/obj"


def test_scene_matrices_are_checked_once_and_read_only():
    """SceneOperators.build validates the influence matrices once, as read-only Operators; step
    problems then reuse them as they are (no O(n²) check or copy per step), and so do the
    splittings derived from them (kept in the operator's memo). A user's writeable array is
    copied and checked on every construction, so changing it afterwards changes no problem."""
    from rollqp.influence.operator import Operator
    from rollqp.operators import SceneOperators
    model = SceneOperators.build(rollqp.load_scene("cattaneo-carter"), symmetrized=False)
    assert isinstance(model.Ann, Operator) and isinstance(model.Att, Operator)
    with pytest.raises(ValueError):
        model.Ann.dense()[0, 0] = 1.0  # read-only: it cannot change after the check
    step = model.normal_step(1000.0)
    assert step.A is model.Ann
    assert step.A.split(step.f) is model.normal_step(900.0).A.split(model.f), "one splitting per scene"
    bad = np.array(model.Ann)          # a writeable copy: checked again
    bad[3, 4] = np.nan
    with pytest.raises(InputError, match="finite"):
        rollqp.NormalStep(A=bad, f=model.f, h=model.h, P=1000.0, scales=model.scales)
    mine = np.array(model.Ann)
    prob = rollqp.NormalStep(A=mine, f=model.f, h=model.h, P=1000.0, scales=model.scales)
    mine[0, 0] = 1e9                   # the user's array changes; the problem does not
    assert np.asarray(prob.A)[0, 0] == model.Ann.dense()[0, 0]


# ------------------------------------------------------------------ trusted construction
def _tangential_toy(**kw):
    return TangentialStep(A=A_TOY, f=F_TOY, p=PT_TOY, mu=MU_TOY, c=np.zeros(N_TOY), dq=1.0, Q=0.5, **kw)


def test_trusted_construction_skips_the_checks_and_keeps_the_values():
    """``trusted=True`` is the same constructor without the checks: the values are kept as given (a list stays a
    list, a load out of range is not refused); without it they are checked and converted."""
    checked = NormalStep(A=A_TOY, f=list(F_TOY), h=np.zeros(N_TOY), P=1)
    assert isinstance(checked.f, np.ndarray) and isinstance(checked.P, float)
    trusted = NormalStep(A=A_TOY, f=list(F_TOY), h=np.zeros(N_TOY), P=-1.0, trusted=True)
    assert isinstance(trusted.f, list) and trusted.P == -1.0
    with pytest.raises(InputError, match="normal load"):
        NormalStep(A=A_TOY, f=F_TOY, h=np.zeros(N_TOY), P=-1.0)
    with pytest.raises(InputError, match="normal load"):
        checked.replace(P=-1.0)          # replace checks
    assert checked.derived(P=-1.0).P == -1.0  # derived is trusted


def test_a_known_bound_is_used_by_a_trusted_step_only_and_never_carried():
    """``known_bound`` (the bound of the very same pressure and μ, computed before) is what a trusted step
    returns as its bound; a checked step computes its own, and a copy never carries it."""
    ref = _tangential_toy()
    fake = rollqp.problem.FrictionBound(np.full(N_TOY, 7.0), (np.full(N_TOY, 7.0), np.full(N_TOY, -7.0)))
    trusted = _tangential_toy(trusted=True, known_bound=fake)
    assert trusted.bound is fake.values and trusted.bound_hat is fake.hat
    assert np.array_equal(_tangential_toy(known_bound=fake).bound, ref.bound)
    np.testing.assert_array_equal(ref.bound, MU_TOY * PT_TOY)
    for copy in (trusted.derived(Q=0.25), trusted.replace(Q=0.25), trusted.shifted(np.zeros(N_TOY))):
        np.testing.assert_array_equal(copy.bound, ref.bound)
