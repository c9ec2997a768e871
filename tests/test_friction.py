"""Friction laws (rollqp.friction; docs/friction.md): limits, Newton against the fixed point, failures, input."""
from __future__ import annotations

import numpy as np
import pytest

from rollqp.errors import InputError, SolverError
from friction_cases import VELDEP, patch_scene, veldep_scene
from rollqp.methods.fixedpoint import BoundFixedPoint
from rollqp.march import march, prepare, run
from rollqp.methods import compose, get_method
from rollqp.scene import load_scene

LAW = {"static": 0.1, "kinetic": 0.1, "velocity": 1.0, "rolling_speed": 1000.0}


@pytest.fixture(scope="module")
def ramp():
    return load_scene("ramp").replace(**{"discretization.distance": 1.5})


@pytest.fixture(scope="module")
def coulomb(ramp):
    return {m: run(ramp, m).arrays() for m in ("newton", "qp-osqp")}


def test_coulomb_table_is_the_number(ramp, coulomb):
    sc = ramp.replace(**{"contact.friction": {"law": "coulomb", "mu": 0.1}})
    assert sc.contact.friction == 0.1 and isinstance(sc.contact.friction, float)
    assert np.array_equal(run(sc, "newton").arrays()["pt"], coulomb["newton"]["pt"])


@pytest.mark.parametrize("law", ["linear", "rational", "exponential"])
@pytest.mark.parametrize("method", ["newton", "qp-osqp"])
def test_static_equals_kinetic_is_coulomb(ramp, coulomb, law, method):
    """μ_s = μ_k: the slip-dependent path (dense Newton; the fixed point: one QP) gives Coulomb's result."""
    r = run(ramp.replace(**{"contact.friction": {"law": law, **LAW}}), method).arrays()
    d = np.max(np.abs(r["pt"] - coulomb[method]["pt"])) / (0.1 * ramp.p0)
    # QP: the same QP (μ array equal to the number): bitwise. Newton: another linear algebra path
    # (dense J instead of the reduced system) on a piecewise-linear Φ: round-off, measured 1e-13.
    assert d <= (0.0 if method != "newton" else 1e-12), f"{method} {law}: {d:.2e} mu p0"


@pytest.mark.parametrize("method", ["newton", "qp-osqp"])
def test_patch_over_the_whole_zone_is_constant(ramp, coulomb, method):
    # one replace: the patch with the ramp's own tangential (0.75 of 0.3) would be beyond the patch's sliding
    # limit 0.1 P (rollqp.scene.checks.check_tangential), so the load changes with the law
    sc = ramp.replace(**{"contact.friction": {"law": "patch", "mu": 0.3, "inside": 0.1, "start": -50.0,
                                              "end": 50.0, "frame": "material"},
                         "load.tangential": {"kind": "ramp", "start": 0.0, "end": 0.25, "over": 8 / 3}})
    r = run(sc, method)
    base = run(ramp.replace(**{"contact.friction": 0.1,
                               "load.tangential": {"kind": "ramp", "start": 0.0, "end": 0.75, "over": 8 / 3}}), method)
    # Q/(μ_ref P̄) with μ_ref = 0.3 (the outside value): 0.25 of 0.3 is 0.75 of 0.1, the same loads
    assert np.allclose(r.arrays()["Q"], base.arrays()["Q"], rtol=1e-15)
    assert np.max(np.abs(r.arrays()["pt"] - base.arrays()["pt"])) <= 1e-12 * ramp.p0  # same QPs up to Q's round-off


def test_patch_transient_returns_to_carter():
    """The patch (examples/friction_patch.py) disturbs the creepage only while it is in the contact."""
    sc = patch_scene(elements=44, distance=6.0)
    xi = run(sc).arrays()["creepage"]
    xi0 = run(sc.replace(**{"contact.friction": 0.1})).arrays()["creepage"]
    q = sc.q_steps / sc.a_H
    before, during = q < 0.9, (q > 1.0) & (q < 3.6)
    assert np.array_equal(xi[before], xi0[before])                  # the patch is not in the contact yet
    assert np.max(np.abs(xi[during] / xi0[during] - 1)) > 0.3       # measured 0.66 on 88 elements
    assert abs(xi[-1] / xi0[-1] - 1) < 1e-3                         # measured 2.7e-5 at 8 a_H (88 el.)


def test_newton_and_fixed_point_agree():
    """Each step of a falling-friction transient (V = 450 mm/s: the fixed point contracts) re-solved by the
    fixed point on the bound around qp-clarabel: within 1e-8 μ_s p0 (measured 1.9e-10 over 2 a_H)."""
    sc = veldep_scene(elements=46, start="braked", distance=0.5).replace(**{"contact.friction.rolling_speed": 450.0})
    fp = BoundFixedPoint(get_method("qp-clarabel", tolerance=1e-10))
    fp.setup(prepare(sc, "qp-clarabel")[2])
    worst, n = 0.0, 0
    for rec in march(sc, "newton"):
        if rec.k > 0:
            sol = fp.solve(rec.problem, warm=rec.previous.tsol)
            worst = max(worst, np.max(np.abs(sol.t - rec.solution.t)) / (sc.contact.mu * sc.p0))
            n += 1
    assert n == sc.n_steps and worst <= 1e-8, f"{worst:.2e} mu_s p0"


def test_fixed_point_failure_is_a_solver_error():
    """V = 45 m/s (docs/friction.md's snippet): at step 10 the bound's slope overwhelms the elastic stiffness and the
    fixed point on the bound alone cycles — a SolverError naming it and the residual (docs/stability.md). Composed by
    the registry, qp-clarabel solves that step through the path from the frozen bound, as newton does."""
    sc = load_scene("cattaneo-carter").replace(**{
        "load.tangential": 0.5, "contact.friction": {"law": "exponential", "static": 0.30, "kinetic": 0.18,
                                                     "velocity": 100.0, "rolling_speed": 45000.0}})
    sc = sc.replace(**{"discretization.distance": 11 * sc.dq / sc.a_H})
    recs = list(march(sc, "newton"))
    ops = prepare(sc, "qp-clarabel")[2]
    fp = BoundFixedPoint(get_method("qp-clarabel", tolerance=1e-10))
    fp.setup(ops)
    with pytest.raises(SolverError) as err:
        for rec in recs[1:]:  # rec: at the error, the step the bare fixed point does not solve
            fp.solve(rec.problem, warm=rec.previous.tsol)
    e = err.value
    assert e.method == "qp-clarabel" and np.isfinite(e.residual) and "fixed point" in str(e) and "cycles" in str(e)
    composed = compose(get_method("qp-clarabel", tolerance=1e-10), False, friction="slip")
    composed.setup(ops)
    sol = composed.solve(rec.problem, warm=rec.previous.tsol)
    # both solve the step to 1e-10 (measured 1.8e-12 apart over the 11 steps)
    assert sol.residual <= 1e-10 and np.max(np.abs(sol.t - rec.solution.t)) <= 1e-8 * 0.3 * sc.p0


def test_contact_veldep_steady():
    """CONTACT's veldep_fric case 1 on its grid (element centres from XC1 = −4.6 mm) with its law mapped
    (v_h = SABSH1/ln 2): rollqp's direct steady Newton solution against CONTACT's printed case 1."""
    r = run(veldep_scene(), "newton").arrays()
    ratio = r["Q"][-1] / (0.30 * VELDEP["FN"])
    # CONTACT prints FX/(FSTAT FN) to 4 digits (0.5941: ±8e-5 relative) and stops its outer iteration at
    # |S_k − S_k−1| <= 1e-3 |S_k|; the same grid and law agree within 0.1 % (measured 3.9e-4)
    assert abs(ratio / VELDEP["ratio_case1"] - 1) < 1e-3, ratio
    counts = np.bincount(r["state"][-1], minlength=3)
    assert (92 - counts[0], counts[1], counts[2]) == (81, 45, 36)  # CONTACT's NCON, NADH, NSLIP


def test_newton_refuses_a_law_on_a_coupled_step():
    sc = load_scene("goodman-bentall").replace(**{"contact.coupling": "full", "contact.friction": {
        "law": "patch", "mu": 0.3, "inside": 0.1, "start": -0.5, "end": 0.5}})
    with pytest.raises(InputError, match="nt-newton"):
        prepare(sc, "newton")


@pytest.mark.parametrize("friction, key", [
    ({"law": "patch", "mu": -0.1, "inside": 0.1, "start": 0, "end": 1}, "contact.friction.mu"),
    ({"law": "patch", "mu": 0.1, "inside": -1.0, "start": 0, "end": 1}, "contact.friction.inside"),
    ({"law": "table", "x": [0, 1], "values": [0.1, -0.2]}, "contact.friction.values[1]"),
    ({"law": "exponential", "static": 0.1, "kinetic": 0.2, "velocity": 1.0, "rolling_speed": 1.0}, "contact.friction.static"),
    ({"law": "exponential", "static": 0.3, "kinetic": 0.2, "velocity": 1.0}, "contact.friction.rolling_speed"),
    ({"law": "patch", "mu": 0.1, "inside": 0.0, "start": 50, "end": 60}, "contact.friction.start"),
    ({"law": "patch", "mu": 0.1, "inside": 0.0, "start": 2, "end": 1}, "contact.friction.end"),
    ({"law": "plateau", "static": 0.3, "kinetic": 0.2, "velocity": 1.0, "rolling_speed": 1.0}, "contact.friction.plateau"),
    ({"law": "stribeck"}, "contact.friction.law"),
    ({"law": "patch", "mu": 0.1, "inside": 0.0, "start": 0, "end": 1, "rolling_speed": 1.0}, "contact.friction.rolling_speed"),
    ({"law": "linear", "static": 0.3, "kinetic": 0.2, "velocity": 1.0, "rolling_speed": 1.0, "sped": 1}, "contact.friction.sped"),
])
def test_bad_input(ramp, friction, key):
    with pytest.raises(InputError) as err:
        ramp.replace(**{"contact.friction": friction})
    assert err.value.key == key and "\n" not in str(err.value)


def test_material_patch_that_never_reaches_the_strip(ramp):
    with pytest.raises(InputError, match="outside the strip"):
        ramp.replace(**{"contact.friction": {"law": "patch", "mu": 0.1, "inside": 0.0, "start": 10, "end": 11,
                                             "frame": "material"}})


def test_memory_needs_marching():
    sc = veldep_scene(elements=46, memory=1.0)
    with pytest.raises(InputError, match="memory"):
        run(sc, "newton")
    r = run(sc.replace(**{"load.start": "braked", "discretization.distance": 0.3}), "newton")
    assert r.arrays()["Q"][-1] > 0


def test_examples_run(monkeypatch, tmp_path):
    import runpy
    from pathlib import Path
    ex = Path(__file__).resolve().parent.parent / "examples"
    monkeypatch.setattr("sys.argv", ["friction_creep.py", "--elements", "46", "--points", "8"])
    out = runpy.run_path(str(ex / "friction_creep.py"), run_name="__main__")["results"]
    xs = [q for _, q, _ in out["by_creepage"] if q is not None]
    peak = int(np.argmax(xs))
    assert 0 < peak < len(xs) - 1, "the creep curve rises to a peak and falls (falling friction)"
    assert xs[-1] > VELDEP["FKIN"] / 0.30 - 1e-9, "never below the kinetic limit"
    assert any(x is None for _, x in out["by_force"]), "a force above the peak has no steady state"


def test_long_memory_keeps_the_static_coefficient():
    """Memory L → ∞: the material keeps the static value it enters with (w = L/(L + Δq) → 1): Coulomb at μ_s,
    to O(Δq/L) (L = 1e6 a_H: measured 1e-8 μ_s p0)."""
    sc = veldep_scene(elements=46, memory=1e6, start="braked", distance=0.5)
    r = run(sc, "newton").arrays()
    c = run(sc.replace(**{"contact.friction": 0.30}), "newton").arrays()
    assert np.max(np.abs(r["pt"] - c["pt"])) <= 1e-6 * 0.3 * sc.p0
    assert np.all(r["friction_coefficient"][-1] > 0.3 - 1e-6)


def test_patch_on_a_coupled_scene_by_alternation():
    """A law on a coupled scene: nt-newton and qp-osqp (both in the N–T alternation) agree."""
    sc = load_scene("goodman-bentall").replace(**{"contact.coupling": "full", "discretization.distance": 1.0,
                                                   "load.start_steps": 2, "discretization.elements": 20,
                                                   "discretization.step": 1.0,
                                                   "contact.friction": {"law": "patch", "mu": 0.3, "inside": 0.2,
                                                                        "start": 0.5, "end": 1.5, "frame": "material"}})
    a = run(sc, "nt-newton").arrays()
    b = run(sc, "qp-osqp").arrays()
    assert not np.allclose(a["friction_coefficient"][0], a["friction_coefficient"][-1])  # the patch moved
    # the alternation stops at the coupled residual 1e-8 (qp-osqp's residual_limit); measured below 1e-7 μ p0
    assert np.max(np.abs(a["pt"] - b["pt"])) <= 1e-6 * 0.3 * sc.p0


def test_slip_law_on_a_coupled_scene_by_alternation():
    """A slip-velocity law on a coupled scene: nt-newton (Newton halves with eq. 88s) and qp-osqp (the fixed
    point on the bound inside the N–T alternation) agree (measured 3.6e-11 μ_s p0); newton refuses up front."""
    sc = load_scene("goodman-bentall").replace(**{
        "contact.coupling": "full", "discretization.distance": 1.0, "load.start_steps": 2,
        "discretization.elements": 20, "discretization.step": 1.0,
        "contact.friction": {"law": "exponential", "static": 0.3, "kinetic": 0.2, "velocity": 1.0, "rolling_speed": 10.0}})
    a, b = run(sc, "nt-newton").arrays(), run(sc, "qp-osqp").arrays()
    assert np.ptp(a["friction_coefficient"][-1][a["state"][-1] == 2]) > 0  # μ varies over the slip zone
    assert np.max(np.abs(a["pt"] - b["pt"])) <= 1e-8 * 0.3 * sc.p0  # the alternation's limit 1e-8 (qp-osqp)
    with pytest.raises(InputError, match="nt-newton"):
        prepare(sc, "newton")
