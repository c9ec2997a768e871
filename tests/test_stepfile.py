"""Step files (rollqp.stepfile): export, round trip, check_step's verdicts and diagnoses, CLI."""
from __future__ import annotations

import json
import runpy
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import rollqp
from rollqp import cli, load_scene
from rollqp.problem import SLIP, STICK, classify
from rollqp.stepfile import DEFAULT_TOL, StepFile, check_step, export_step, solve_stored

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
SIMILAR = {"discretization.distance": 0.5}  # §6.1.1, rolled 0.5 a_H: 16 steps
COUPLED = {"discretization.distance": 0.1}  # §6.2.1, full coupling: 7 steps


@pytest.fixture(scope="module")
def similar(tmp_path_factory):
    scene = load_scene("cattaneo-carter").replace(**SIMILAR)
    folder = tmp_path_factory.mktemp("similar")
    step = export_step(scene, 3)
    paths = step.save(folder / "s3.npz")
    return scene, step, folder, paths


@pytest.fixture(scope="module")
def coupled(tmp_path_factory):
    scene = load_scene("goodman-bentall").replace(**COUPLED)
    folder = tmp_path_factory.mktemp("coupled")
    step = export_step(scene, 2)
    step.save(folder / "g2.npz")
    return scene, step, folder


# ------------------------------------------------------------------------------ export
@pytest.mark.parametrize("K", [0, 3])
def test_step_numbering_matches_result_file(similar, K):
    scene = similar[0]
    res = rollqp.run(scene, method="newton").arrays()
    step = export_step(scene, K)
    # the same deterministic Newton march: equal to round-off (1e-12 p0)
    assert np.max(np.abs(step.ref_p - res["pn"][K])) <= 1e-12 * step.p0, "p of step K is state K"
    assert np.max(np.abs(step.ref_t - res["pt"][K])) <= 1e-12 * step.p0, "t of step K is state K"
    assert step.q == pytest.approx(res["q"][K], abs=1e-15), "q of step K"
    if K > 0:
        assert np.max(np.abs(step.prev_t - res["pt"][K - 1])) <= 1e-12 * step.p0, "previous state is state K-1"


def test_round_trip_and_kinds(similar, coupled):
    _, step, folder, paths = similar
    back = StepFile.load(folder / "s3.npz")
    for k in ("A_nn", "A_tt", "f", "h", "c", "ref_p", "ref_t", "prev_t"):
        assert np.array_equal(getattr(back, k), getattr(step, k)), k
    assert (back.P, back.Q, back.delta, back.xi) == (step.P, step.Q, None, None), "loads prescribed, δ/ξ unknown"
    assert back.kind == "uncoupled" and coupled[1].kind == "coupled", "β = 0 uncoupled, §6.2.1 coupled"
    assert {Path(p).name for p in paths} == {"s3.npz", "s3.normal.clarabel.json", "s3.tangential.clarabel.json",
                                             "s3.cvxpy.py"}
    with np.load(folder / "s3.npz", allow_pickle=False) as z:  # no pickles
        assert z["normal_qp_P"].shape == (step.n, step.n)


@pytest.mark.parametrize("which", ["similar", "coupled"])
def test_frozen_qp_is_solved_by_rollqps_solution(similar, coupled, which):
    """KKT of each half's q_frozen QP hold at rollqp's solution (stationarity on free nodes)."""
    step = similar[1] if which == "similar" else coupled[1]
    for half, x in (("normal", step.ref_p), ("tangential", step.ref_t)):
        f = step.qp_forms()[half]
        x = x / f["x_scale"]
        grad = f["P"] @ x + f["q_frozen"]
        free = (x > f["lb"] + 1e-6) & (x < f["ub"] - 1e-6)
        y = -np.mean(grad[free] / f["A"][0, free])
        # Newton's solution to 1e-14 makes the stationarity residual round-off sized (1e-9 of O(1) terms)
        assert np.max(np.abs(grad[free] + y * f["A"][0, free])) < 1e-9, half
        ref = step.ref_delta if half == "normal" else step.ref_xi
        assert y * f["y_scale"] == pytest.approx(ref, rel=1e-6), f"{half}: multiplier maps to δ / ξ"


def test_clarabel_json_solves_to_rollqps_solution(similar):
    clarabel = pytest.importorskip("clarabel")
    step, folder = similar[1], similar[2]
    for half, ref in (("normal", step.ref_p), ("tangential", step.ref_t)):
        sol = clarabel.load_from_file(str(folder / f"s3.{half}.clarabel.json")).solve()
        # interior point without refinement: complementarity stops at sqrt(gap) (≈1e-7 p0, _qp.py)
        assert np.max(np.abs(np.array(sol.x) * step.p0 - ref)) < 1e-6 * step.p0, half


# ------------------------------------------------------------------------------ check: passes
def test_own_solutions_pass(similar, coupled):
    for step in (similar[1], coupled[1]):
        rep = check_step(step, {"p": step.ref_p, "t": step.ref_t})
        assert rep.passed, str(rep)
        assert "PASS" in str(rep)
        osqp = solve_stored(step, "qp-osqp")
        rep = check_step(step, {"p": osqp.p, "t": osqp.t, "delta": osqp.delta, "xi": osqp.xi})
        assert rep.passed and max(rep.residuals.values()) <= 1e-8, str(rep)  # OSQP's residual limit


def test_external_scipy_slsqp_passes(monkeypatch, tmp_path):
    """examples/validate_external.py: SLSQP fed from the .npz alone."""
    monkeypatch.setattr("sys.argv", ["validate_external.py", "4", str(tmp_path)])
    ns = runpy.run_path(str(EXAMPLES / "validate_external.py"), run_name="not_main")
    rep = ns["main"](4, str(tmp_path))
    assert rep.passed, str(rep)
    assert rep.comparisons["newton"]["p"] < 1e-5, "SLSQP ≈ Newton (its ftol gives ≈1e-7 p0)"


def test_external_daqp_direct_passes_on_coupled_step(coupled):
    """DAQP through qpsolvers, called on the exported arrays (no rollqp solver): N-T sweeps."""
    qpsolvers = pytest.importorskip("qpsolvers")
    if "daqp" not in qpsolvers.available_solvers:
        pytest.skip("daqp not installed")
    step, folder = coupled[1], coupled[2]
    z = dict(np.load(folder / "g2.npz", allow_pickle=False))
    g = lambda h, k: z[f"{h}_qp_{k}"]  # noqa: E731
    n = step.n
    p, t = np.zeros(n), np.zeros(n)
    pr, tr = z["ref_p"] / step.p0, z["ref_t"] / step.p0
    for _ in range(300):
        qn = g("normal", "q") + g("normal", "skew") @ p + g("normal", "coupling") @ (t - tr)
        sn = qpsolvers.solve_problem(qpsolvers.Problem(g("normal", "P"), qn, A=g("normal", "A"), b=g("normal", "b"),
                                                       lb=g("normal", "lb"), ub=np.full(n, 1e6)), solver="daqp")
        pn = sn.x
        bound = step.mu * np.maximum(pn, 0.0)
        qt = g("tangential", "q") + g("tangential", "skew") @ t + g("tangential", "coupling") @ (pn - pr)
        st = qpsolvers.solve_problem(qpsolvers.Problem(g("tangential", "P"), qt, A=g("tangential", "A"),
                                                       b=g("tangential", "b"), lb=-bound, ub=bound), solver="daqp")
        change = max(np.max(np.abs(pn - p)), np.max(np.abs(st.x - t)))
        p, t = pn, st.x
        if change < 1e-12:
            break
    cand = {"p": p * step.p0, "t": t * step.p0, "delta": sn.y[0] * float(z["normal_qp_y_scale"]),
            "xi": st.y[0] * float(z["tangential_qp_y_scale"])}
    rep = check_step(step, cand, compare_with=("newton",))
    assert rep.passed, str(rep)
    assert max(rep.residuals.values()) < 1e-9, "an active-set solver: residual at the sweeps' stopping change"


@pytest.mark.integration
def test_cvxpy_script_passes(similar):
    step, folder = similar[1], similar[2]
    proc = subprocess.run([sys.executable, str(folder / "s3.cvxpy.py")], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    rep = check_step(step, folder / "s3.cvxpy-solution.npz", compare_with=("newton",))
    assert rep.passed, str(rep)


# ------------------------------------------------------------------------------ check: diagnoses
def _states(step):
    ref = step.reference()
    return classify(ref.p, ref.t, ref.s, step.mu, step.scales)


def _check(step, p=None, t=None):
    sol = {"p": step.ref_p if p is None else p, "t": step.ref_t if t is None else t,
           "delta": step.ref_delta, "xi": step.ref_xi}
    rep = check_step(step, sol, compare_with=("newton",))
    assert not rep.passed
    return rep, {f.condition: f for f in rep.failures}


def test_negative_pressure_is_signorini_at_that_node(similar):
    step = similar[1]
    i = int(np.flatnonzero(step.ref_p > 0)[0]) - 1  # the first separated node before the contact
    p = step.ref_p.copy()
    p[i] = -0.01 * step.p0
    rep, fails = _check(step, p=p)
    assert "signorini" in fails and i in fails["signorini"].nodes
    assert fails["signorini"].reasons[list(fails["signorini"].nodes).index(i)] == "negative pressure"
    assert "load_normal" in fails, "the load changed too"
    assert f"node {i} " in rep.diagnosis()[0] and "negative pressure" in rep.diagnosis()[0], "worst node first"


@pytest.mark.parametrize("which", ["similar", "coupled"])
def test_traction_above_bound_is_friction_at_that_node(similar, coupled, which):
    step = similar[1] if which == "similar" else coupled[1]
    slip = np.flatnonzero(_states(step) == SLIP)
    i = int(slip[len(slip) // 2])
    t = step.ref_t.copy()
    t[i] *= 1.5  # at the bound already: now 1.5 μp
    _, fails = _check(step, t=t)
    f = fails["friction"]
    assert i in f.nodes and f.reasons[list(f.nodes).index(i)] == "|t| above the bound mu p"


def test_wrong_load_is_the_load_equation(similar):
    step = similar[1]
    rep, fails = _check(step, p=1.01 * step.ref_p)
    f = fails["load_normal"]
    # 1 % of P in units of a_H p0 (P = π a_H p0 / 2)
    assert f.value == pytest.approx(0.01 * step.P / (step.a_H * step.p0), rel=1e-9)
    assert "f'p" in f.line(rep.tol)


def test_stick_node_given_slip(similar):
    step = similar[1]
    st = _states(step)
    stick = np.flatnonzero(st == STICK)
    i = int(stick[len(stick) // 2])
    t = step.ref_t.copy()
    t[i] = np.sign(t[i]) * step.mu * step.ref_p[i]  # pushed to the bound
    rep, fails = _check(step, t=t)
    assert i in fails["friction"].nodes
    assert i in rep.state_differs and rep.states[0][i] == SLIP and rep.states[1][i] == STICK
    assert f"node {i:3d}" in str(rep) and "(newton: stick)" in str(rep)


def test_partial_solutions(similar):
    step = similar[1]
    rep = check_step(step, {"p": step.ref_p}, compare_with=())
    assert rep.passed and set(rep.residuals) == {"signorini", "load_normal"}
    rep = check_step(step, {"t": step.ref_t}, compare_with=())
    assert rep.passed and set(rep.residuals) == {"friction", "load_tangential"}
    assert "xi" in rep.fitted, "ξ fitted on the stick nodes"
    assert rep.xi == pytest.approx(step.ref_xi, rel=1e-9)


# ------------------------------------------------------------------------------ CLI
def one_line(err, *words):
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    for w in words:
        assert w in err, (w, err)


def test_cli_export_and_check(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    path = tmp_path / "short.toml"
    path.write_text(load_scene("cattaneo-carter").replace(name="short", **SIMILAR).to_toml(), encoding="utf-8")
    assert cli.main(["export-step", str(path), "--step", "2"]) == 0
    assert (tmp_path / "short-step2.npz").is_file() and (tmp_path / "short-step2.cvxpy.py").is_file()
    step = StepFile.load(tmp_path / "short-step2.npz")
    np.savez(tmp_path / "good.npz", p=step.ref_p, t=step.ref_t)
    capsys.readouterr()
    assert cli.main(["check-step", "short-step2.npz", "good.npz"]) == 0
    assert "PASS" in capsys.readouterr().out
    t = step.ref_t.copy()
    t[np.argmax(np.abs(t))] *= 2
    np.savez(tmp_path / "bad.npz", p=step.ref_p, t=t)
    assert cli.main(["check-step", "short-step2.npz", "bad.npz"]) == 1
    cap = capsys.readouterr()
    lines = cap.err.strip().splitlines()
    assert lines and all(line.startswith("rollqp: check failed: ") for line in lines), cap.err
    assert any("friction" in line for line in lines) and "FAIL" in cap.out
    # a looser --tol does not hide a factor-2 traction (residual ~ μ ~ 0.1)
    assert cli.main(["check-step", "short-step2.npz", "bad.npz", "--tol", "1e-3"]) == 1


@pytest.mark.parametrize("args, words", [
    (["check-step", "missing.npz", "good.npz"], ["STEP.npz", "no such file"]),
    (["check-step", "s.npz", "missing.npz"], ["SOLUTION.npz", "no such file"]),
    (["check-step", "s.npz", "wrongkey.npz"], ["SOLUTION.npz", "'pressure'"]),
    (["check-step", "s.npz", "wrongshape.npz"], ["SOLUTION.npz", "'p'", "shape"]),
    (["check-step", "good.npz", "good.npz"], ["STEP.npz", "not a rollqp step file"]),
    (["check-step", "junk.npz", "good.npz"], ["STEP.npz", "not a .npz file"]),
    (["check-step", "s.npz", "s.npz"], ["SOLUTION.npz", "a step file, not a solution"]),
    (["check-step", "s.npz", "nan.npz"], ["SOLUTION.npz", "'t'", "finite"]),
    (["check-step", "s.npz", "good.npz", "--tol", "-1"], ["--tol"]),
    (["export-step", "cattaneo-carter", "--step", "100000"], ["--step", "0.."]),
    (["export-step", "cattaneo-carter", "--step", "-1"], ["--step"]),
    (["export-step", "cattaneo-carter", "--step", "1", "--out", "x.txt"], ["--out", ".npz"]),
    (["run", "cattaneo-carter", "--method", "qps-nosuch"], ["--method"]),
])
def test_cli_bad_input(similar, tmp_path, monkeypatch, capsys, args, words):
    step = similar[1]
    monkeypatch.chdir(tmp_path)
    step.save(tmp_path / "s.npz", native=False)
    np.savez(tmp_path / "good.npz", p=step.ref_p)
    np.savez(tmp_path / "wrongkey.npz", pressure=step.ref_p)
    np.savez(tmp_path / "wrongshape.npz", p=step.ref_p[:-1])
    np.savez(tmp_path / "nan.npz", t=np.full(step.n, np.nan))
    (tmp_path / "junk.npz").write_text("not an archive", encoding="utf-8")
    capsys.readouterr()
    try:
        code = cli.main(args)
    except SystemExit as exc:  # argparse's own errors (one line, exit 2: cli._Parser)
        code = exc.code
    assert code == 2, f"exit 2 for invalid input, got {code}"
    one_line(capsys.readouterr().err, "rollqp: ", *words)


def test_step_types_and_steady_start():
    """Step 0: the braked start's last static-shift increment, or a rolling start's steady solve."""
    braked = export_step(load_scene("cattaneo-carter").replace(**SIMILAR), 0)
    assert braked.step_type == "static-shift" and braked.dq == pytest.approx(braked.a_H), "shift per a_H"
    steady = export_step(load_scene("harmonic").replace(**{"discretization.distance": 0.1}), 0)
    assert steady.step_type == "steady" and steady.kind == "coupled"
    rep = check_step(steady, {"p": steady.ref_p, "t": steady.ref_t}, compare_with=("newton",))
    assert rep.passed, str(rep)
    assert export_step(load_scene("harmonic").replace(**{"discretization.distance": 0.1}), 1).step_type == "rolling"
