"""Load paths: stops, reversals and variable steps (rollqp.kinematics), and cyclic
tangential loading at rest against Mindlin–Deresiewicz (closed form with a convergence slope)."""
from __future__ import annotations

import numpy as np
import pytest

import rollqp
from rollqp import closedforms as cf
from rollqp.errors import InputError
from rollqp.kinematics import hysteresis, plan
from rollqp.report import rms_in_contact

MU = 0.1
#: the fretting cycle: Q/(μP) from +0.6 (Cattaneo start) to −0.6, +0.6, −0.6 at rest
TQ, TV = [0.0, 1.0, 3.0, 5.0], [0.6, -0.6, 0.6, -0.6]


def base(**changes):
    return rollqp.load_scene("cattaneo-carter").replace(**changes)


def fretting(elements, element="quadratic", **more):
    return base(**{"load.rolled": {"kind": "constant", "value": 0.0},
                   "load.tangential": {"kind": "table", "q": TQ, "value": TV},
                   "discretization.distance": 5.0, "discretization.elements": elements,
                   "discretization.element": element, **more})


def mindlin_errors(res, scene):
    """rms(pt − Mindlin)/(μp0) of every state, with the exact turning points of the path."""
    a = res.arrays()
    tau = a["time"] / scene.a_H
    out = []
    for k in range(tau.size):
        path = [v for q, v in zip(TQ, TV) if q < tau[k]] + [float(np.interp(tau[k], TQ, TV))]
        tc = cf.mindlin_traction(a["x"], scene.a_H, scene.p0, MU, path)
        out.append(rms_in_contact(a["x"], scene.a_H, a["pt"][k] - tc) / (MU * scene.p0))
    return tau, np.array(out)


def test_without_rolled_the_plan_is_the_old_grid():
    """A scene without load.rolled: τ = q = k·Δq, every step the scene's Δq and direction."""
    s = base()
    pl = plan(s)
    assert not pl.rolled and np.array_equal(pl.q, s.q_steps) and np.array_equal(pl.tau, s.q_steps)
    assert np.all(pl.dq == s.dq) and np.all(pl.d == -1)


def test_stop_with_constant_loads_leaves_the_state_unchanged():
    """Δq = 0 with constant loads: a static shift of zero; every method keeps the state to round-off."""
    s = base(**{"load.rolled": {"kind": "table", "q": [0, 1, 1.5], "value": [0, 1, 1]}, "discretization.distance": 1.5})
    pl = plan(s)
    k2 = int(np.argmin(np.abs(pl.tau / s.a_H - 1)))
    assert np.all(pl.d[k2 + 1:] == 0) and np.all(pl.d[1:k2 + 1] == -1)
    for method in ("newton", "qp-osqp"):
        a = rollqp.run(s, method).arrays()
        change_t = np.max(np.abs(a["pt"][k2:] - a["pt"][k2])) / (MU * s.p0)
        change_p = np.max(np.abs(a["pn"][k2:] - a["pn"][k2])) / s.p0
        # round-off of the static steps (solver tolerance 1e-10 bounds it; measured 5e-14 newton)
        assert change_t < 1e-9 and change_p < 1e-12, (method, change_t, change_p)
        assert np.all(a["shift"][k2 + 1:] == pytest.approx(0.0, abs=1e-12 * s.a_H))


def test_reversal_converges_to_the_mirrored_carter_state():
    """Roll 3 a_H forward, stop, roll 6 a_H back: Carter with the stick zone at the new leading edge (x < 0)."""
    s = base(**{"load.rolled": {"kind": "table", "q": [0, 3, 4, 10], "value": [0, 3, 3, -3]},
                "discretization.distance": 10.0})
    a = rollqp.run(s).arrays()
    x = a["x"]
    assert a["direction"][-1] == +1 and a["q"][-1] == pytest.approx(-3 * s.a_H)
    e_new = rms_in_contact(x, s.a_H, a["pt"][-1] - cf.carter_traction(x, s.a_H, s.p0, MU, 0.75, +1)) / (MU * s.p0)
    e_old = rms_in_contact(x, s.a_H, a["pt"][-1] - cf.carter_traction(x, s.a_H, s.p0, MU, 0.75, -1)) / (MU * s.p0)
    # the forward run's discretization error against Carter is 0.0064 (docs/formulation.md C5)
    assert e_new < 0.0065 and e_old > 0.3
    fwd = rollqp.run(base()).arrays()
    # mirror of the forward steady state: equal up to the transient left after 6 a_H (measured 7.5e-7)
    assert np.max(np.abs(a["pt"][-1][::-1] - fwd["pt"][-1])) / (MU * s.p0) < 1e-5


@pytest.mark.parametrize("formulation, element", [("convective-local", "constant"), ("material", "linear")])
def test_reversal_mirrors_the_forward_run(formulation, element):
    """The upwind difference and the shift turn with the material: rolling back 6 a_H gives the
    forward steady state mirrored (measured 2.5e-8, 3.5e-8 μp0: the transient left)."""
    ch = {"discretization.formulation": formulation, "discretization.element": element}
    a = rollqp.run(rollqp.load_scene("stop-reverse").replace(**ch)).arrays()
    f = rollqp.run(base(**ch)).arrays()
    assert np.max(np.abs(a["pt"][-1][::-1] - f["pt"][-1])) / (MU * rollqp.load_scene("stop-reverse").p0) < 1e-6


def test_variable_steps_and_methods_agree_on_a_load_path():
    """Variable Δq (a table with three slopes), a stop, a reversal: QP backends against Newton
    on constant elements (F·A exactly symmetric) to the backends' accuracy 1e-8 μp0."""
    s = base(**{"load.rolled": {"kind": "table", "q": [0, 1, 1.5, 2.5, 4], "value": [0, 0.5, 0.5, 1.5, 0.75]},
                "load.tangential": {"kind": "table", "q": [0, 1.2, 1.4], "value": [0.5, -0.3, 0.4]},
                "discretization.element": "constant", "discretization.distance": 4.0, "discretization.step": 1.0})
    pl = plan(s)
    assert set(np.round(pl.dq[1:] / s.element_length, 9)) >= {0.0, 0.5, 1.0} and set(pl.d[1:]) == {-1, 0, 1}
    ref = rollqp.run(s, "newton").arrays()
    for method in ("qp-clarabel", "qp-osqp"):
        a = rollqp.run(s, method).arrays()
        assert np.max(np.abs(a["pt"] - ref["pt"])) / (MU * s.p0) < 1e-8, method
        assert np.max(np.abs(a["pn"] - ref["pn"])) / s.p0 < 1e-8, method


def test_mindlin_on_the_papers_mesh():
    """40 QCE: 0.50 % μp0 at the turning points (Cattaneo's own error, mirrored), at most 1.6 % in
    between (measured 0.0160; the convergence study is the slow test below)."""
    s = fretting(40)
    tau, err = mindlin_errors(rollqp.run(s), s)
    turning = max(err[np.argmin(np.abs(tau - t))] for t in (1.0, 3.0, 5.0))
    assert turning < 0.0051 and err.max() < 0.017, (turning, err.max())


def cattaneo_state(ratio, elements=40):
    """The discrete Cattaneo traction at ``Q/(μP) = ratio``, one static step from rest (fretting's mesh)."""
    s = fretting(elements, **{"load.tangential": {"kind": "constant", "value": float(ratio)},
                              "discretization.distance": 0.0625})
    return rollqp.run(s).arrays()["pt"][-1]


def test_discrete_mindlin_is_the_superposition_of_discrete_cattaneo_states():
    """Mindlin–Deresiewicz holds for the discretized problem itself: every state of the fretting
    cycle (40 QCE) is ``±t_C(0.6) ∓ 2 t_C(|Δr|/2)`` with the *discrete* Cattaneo states of the same
    mesh, to the solver's tolerance (measured 3.7e-13 μp0; bound 1e-10 = solver.tolerance). So the
    cycle's error against the closed form is exactly Cattaneo's discretization error, composed by
    the superposition: at most e_C(0.6) + 2 max e_C (docs/kinematics.md)."""
    s = fretting(40)
    a = rollqp.run(s).arrays()
    tau = a["time"] / s.a_H
    t06 = cattaneo_state(0.6)
    worst = 0.0
    for t in (0.0, 0.125, 0.5, 1.0, 1.219, 2.5, 3.0, 3.219, 4.75):
        k = int(np.argmin(np.abs(tau - t)))
        r = float(np.interp(tau[k], TQ, TV))
        sign = 1.0 if (tau[k] <= 1.0 or tau[k] > 3.0) else -1.0   # the branch: unloading from +0.6 or from −0.6
        sup = sign * (t06 - 2.0 * cattaneo_state((0.6 - sign * r) / 2.0))
        worst = max(worst, float(np.max(np.abs(a["pt"][k] - sup)) / (MU * s.p0)))
    assert worst < 1e-10, worst


def test_cattaneo_error_bounds_the_cycle_error_on_the_papers_mesh():
    """Cattaneo's own error on 40 QCE over monotone loading 0 → 0.6 (32 states) is at most 0.0081
    μp0 (at r = 0.075: a slip annulus one element wide; 0.0050 at 0.6), and the fretting cycle's worst
    state stays within the superposition's bound e_C(0.6) + 2 max e_C (the test above makes it exact)."""
    s = base(**{"load.rolled": {"kind": "constant", "value": 0.0},
                "load.tangential": {"kind": "table", "q": [0, 1], "value": [0, 0.6]},
                "discretization.distance": 1.0, "discretization.elements": 40})
    a = rollqp.run(s).arrays()
    r = 0.6 * a["time"][1:] / s.a_H
    e = np.array([rms_in_contact(a["x"], s.a_H, a["pt"][k + 1] - cf.cattaneo_traction(a["x"], s.a_H, s.p0, MU, rk))
                  for k, rk in enumerate(r)]) / (MU * s.p0)
    assert e.max() < 0.0085 and e[-1] < 0.0051, (e.max(), e[-1])     # measured 0.00805, 0.00497
    tau, err = mindlin_errors(rollqp.run(fretting(40)), s)
    assert err.max() <= e[-1] + 2.0 * e.max(), (err.max(), e[-1], e.max())   # measured 0.0160 <= 0.0211


@pytest.mark.slow
def test_mindlin_turning_points_and_in_between_converge():
    """Q cycling ±0.6 μP at rest (40 QCE, the paper's mesh, and 20, 80): at the turning points the
    state is Cattaneo's mirrored (its 0.50 % error); in between the error is twice Cattaneo's at half the
    increment (the superposition), largest just after a reversal (a slip annulus one element wide);
    the worst state's error halves as the mesh doubles."""
    worst, turning = [], []
    for ne in (20, 40, 80):
        s = fretting(ne)
        tau, err = mindlin_errors(rollqp.run(s), s)
        worst.append(err.max())
        turning.append(max(err[np.argmin(np.abs(tau - t))] for t in (1.0, 3.0, 5.0)))
    # measured: turning 0.0099, 0.0050, 0.0018; worst 0.030, 0.016, 0.0081
    assert turning[1] <= 0.01 and turning[2] < turning[1] < turning[0]
    slope = np.polyfit(np.log([20, 40, 80]), np.log(worst), 1)[0]
    assert slope < -0.85, (worst, slope)
    assert worst[2] < 0.01


def test_mindlin_closed_form_limits():
    x = np.linspace(-1.2, 1.2, 49)
    # virgin loading is Cattaneo; the mirrored turning point is minus Cattaneo
    assert np.array_equal(cf.mindlin_traction(x, 1, 1, MU, [0.4]), cf.cattaneo_traction(x, 1, 1, MU, 0.4))
    np.testing.assert_allclose(cf.mindlin_traction(x, 1, 1, MU, [0.6, -0.6]), -cf.cattaneo_traction(x, 1, 1, MU, 0.6),
                               atol=1e-15)
    # going past the earlier turning point forgets it (Masing): 0.5 -> 0.2 -> 0.7 is virgin 0.7
    np.testing.assert_allclose(cf.mindlin_traction(x, 1, 1, MU, [0.5, 0.2, 0.7]), cf.cattaneo_traction(x, 1, 1, MU, 0.7),
                               atol=1e-15)
    assert cf.mindlin_turning_points([0.5, 0.2, 0.4]) == ([0.0, 0.5, 0.2], 0.4)
    # the load of the superposed traction is the current Q
    xs = np.linspace(-1, 1, 200001)
    t = cf.mindlin_traction(xs, 1, 1, MU, [0.6, -0.2, 0.3])
    assert np.trapezoid(t, xs) == pytest.approx(0.3 * MU * np.pi / 2, rel=1e-6)
    with pytest.raises(InputError, match="ratio"):
        cf.mindlin_traction(x, 1, 1, MU, [0.5, 1.2])


def test_hysteresis_energy_against_mindlin():
    """∮ Q du over one cycle: the half-space (any reference distance) and the BEM rollers (rigid
    shafts) against the 2D Mindlin energy."""
    W = cf.mindlin_dissipation(0.6, MU, 1000.0, rollqp.load_scene("cattaneo-carter").Estar)
    for model, tol in (("halfspace", 5e-3), ("bem", 2e-2)):
        s = fretting(40, **{"contact.model": model, "discretization.step": 2.0})
        h = hysteresis(rollqp.run(s), (1.0, 5.0))
        # half-space: the trapezoidal rule over 16 states per half cycle (measured 3.2e-3; 1e-4 at
        # step 0.5); BEM: finite rollers on shafts against the half-space closed form (measured 0.8 %)
        assert h["energy"] == pytest.approx(W, rel=tol), model
    with pytest.raises(InputError):
        cf.mindlin_dissipation(1.0, MU, 1000.0, 1e5)


def test_bad_kinematics_input():
    with pytest.raises(InputError, match=r"load\.rolled\.q.*strictly increasing"):
        base(**{"load.rolled": {"kind": "table", "q": [0, 2, 1], "value": [0, 1, 2]}})
    with pytest.raises(InputError, match=r"load\.rolled.*\[0, 8\] Le"):
        base(**{"load.rolled": {"kind": "table", "q": [0, 1], "value": [0, 20]}})
    with pytest.raises(InputError, match=r"load\.rolled.*\[0, 0\.5\] Le"):
        base(**{"discretization.formulation": "convective-local",
                "load.rolled": {"kind": "table", "q": [0, 1], "value": [0, 1.5]}})


@pytest.mark.parametrize("method", ["nt-newton", pytest.param("qp-osqp", marks=pytest.mark.slow),
                                    pytest.param("qp-clarabel", marks=pytest.mark.slow)])
def test_coupled_load_path_methods_agree(method):
    """Dissimilar rollers (goodman-bentall, full coupling), constant elements: roll 1 a_H, stop while Q
    rises to 0.3 μP̄, roll back 1 a_H. Each method against newton to the N–T alternation's accuracy
    (its residual tolerance 1e-10 leaves ~1e-9 in the tractions, docs/formulation.md §11; measured 8.5e-10)."""
    s = rollqp.load_scene("goodman-bentall").replace(**{
        "discretization.element": "constant", "discretization.step": 1.0, "load.start_steps": 5,
        "load.rolled": {"kind": "table", "q": [0, 1, 1.5, 2.5], "value": [0, 1, 1, 0]}, "discretization.distance": 2.5,
        "load.tangential": {"kind": "table", "q": [0, 1, 1.25, 1.5], "value": [0, 0, 0.3, 0.3]}})
    mu = s.contact.friction
    ref = rollqp.run(s, "newton").arrays()
    assert set(ref["direction"][1:]) == {-1, 0, 1}
    a = rollqp.run(s, method).arrays()
    assert np.max(np.abs(a["pt"] - ref["pt"])) / (mu * s.p0) < 1e-8
    assert np.max(np.abs(a["pn"] - ref["pn"])) / s.p0 < 1e-8


def test_resume_a_load_path(tmp_path):
    """--resume continues a load path after its last state (the plan's q and τ, not k·Δq)."""
    from rollqp.result import load_result
    s = base(**{"load.rolled": {"kind": "table", "q": [0, 1, 1.5, 2.5], "value": [0, 1, 1, 0]},
                "discretization.distance": 2.5})
    full = rollqp.run(s).arrays()
    path = rollqp.run(s.replace(**{"discretization.distance": 1.25})).save(tmp_path / "part.npz")
    res = rollqp.run(s, resume=load_result(path)).arrays()
    assert np.array_equal(res["time"], full["time"]) and np.array_equal(res["q"], full["q"])
    # the continuation rebuilds what the method keeps between steps (round-off, 2.4e-11 measured on
    # cattaneo-carter, docs/results.md)
    assert np.max(np.abs(res["pt"] - full["pt"])) / (MU * s.p0) < 1e-9
