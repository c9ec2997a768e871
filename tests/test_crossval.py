"""The cross-validation report (rollqp.crossval): every method on one stored step, side by side."""
from __future__ import annotations

import re

import pytest

from rollqp import cli, load_scene
from rollqp.crossval import report
from rollqp.methods import available_methods, get_method

FAST = [m for m in ("qp-osqp", "nt-newton", "qps-daqp", "qps-quadprog") if m in available_methods()]


@pytest.mark.parametrize("name, changes, step", [
    ("cattaneo-carter", {"discretization.distance": 0.2}, 2),   # §6.1.1, uncoupled
    ("goodman-bentall", {"discretization.distance": 0.05}, 1),  # §6.2.1, coupled: QP halves alternate
])
def test_report_lists_methods_and_agrees(name, changes, step):
    rep = report(load_scene(name).replace(**changes), step=step, methods=FAST)
    assert [r.method for r in rep.rows] == ["newton"] + FAST, "newton first, then the others in order"
    for r in rep.rows:
        assert r.ok, f"{r.method}: {r.error}"
        assert max(r.residuals.values()) <= 1e-8, f"{r.method}: QP residual limit 1e-8"
        # same collocation step: differences bounded by the residual limit (measured ≤ 7e-10)
        assert r.dp <= 1e-7 and r.dt <= 1e-7, f"{r.method}: Δp {r.dp:.1e}, Δt {r.dt:.1e}"
        assert r.states == 0, f"{r.method}: node states as Newton's"
    text = str(rep)
    assert "| method | Signorini |" in text and all(f"| {m} |" in text for m in FAST)
    assert (", coupled step" in text) == (name == "goodman-bentall")


def test_cli_crossval(capsys):
    assert cli.main(["crossval", "cattaneo-carter", "--step", "1"]) == 0
    out = capsys.readouterr().out
    for m in available_methods():
        assert f"| {m} |" in out, m
    assert "failed" not in out, out


def test_cli_crossval_methods_and_step_file(tmp_path, capsys):
    from rollqp.stepfile import export_step
    path = tmp_path / "s.npz"
    export_step(load_scene("cattaneo-carter").replace(**{"discretization.distance": 0.2}), 2).save(path, native=False)
    assert cli.main(["crossval", str(path), "--methods", "qp-osqp"]) == 0
    out = capsys.readouterr().out
    assert "| qp-osqp |" in out and "| newton |" in out and "| qp-clarabel |" not in out
    assert cli.main(["crossval", str(path), "--methods", "qp-nosuch"]) == 2
    err = capsys.readouterr().err
    assert "--methods" in err and "qp-nosuch" in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("name, step, coupled", [("cattaneo-carter", 32, False), ("goodman-bentall", 64, True)])
def test_docs_tables(name, step, coupled):
    """The tables of docs/stepfiles.md (``rollqp crossval NAME --step K``): every method agrees."""
    rep = report(name, step=step)
    assert [r.method for r in rep.rows] == ["newton"] + [m for m in available_methods() if m != "newton"]
    outer = set()
    for r in rep.rows:
        assert r.ok and r.states == 0, f"{r.method}: {r.error}"
        # uncoupled: every backend solves the same collocation step (measured ≤ 1.5e-11);
        # coupled: the alternations stop at the coupled residual 1e-10 (measured 1e-9 from Newton)
        assert max(r.dp, r.dt) <= (1e-8 if coupled else 1e-10), r.method
        # (a method with its own coupled_limit, mf-newton's 0.01 tol, stops its alternation later)
        if coupled and r.method != "newton" and get_method(r.method).capabilities.coupled_limit is None:
            outer.add(r.iterations.split()[0])
    assert len(outer) <= 1, f"all alternations at the same limit take the same outer iterations: {outer}"


def test_steady_step_is_marched_by_the_qp_methods():
    """The direct rolling start (§6.2.2) is a steady rolling step, which no convex QP poses: the QP
    methods reach it by marching the scene at its starting loads, as their runs do, and their state
    is evaluated on the same stored step — no failure blamed on the influence matrix."""
    methods = [m for m in ("qp-clarabel", "qp-osqp", "nt-newton") if m in available_methods()]
    rep = report(load_scene("harmonic"), step=0, methods=methods)
    assert "steady" in rep.kind and "not a convex QP" in str(rep)
    for r in rep.rows:
        assert r.ok, f"{r.method}: {r.error}"
        # the march stops when a step changes t by < 1e-8 μp0 (rollqp.march.strip.STEADY_TOL, measured 2e-11)
        assert r.dt <= 1e-8 and r.dp <= 1e-8, f"{r.method}: Δp {r.dp:.1e}, Δt {r.dt:.1e}"
        assert max(r.residuals.values()) <= 1e-9, f"{r.method}: residuals on the steady step {r.residuals}"
    assert any("march to steady" in r.iterations for r in rep.rows)


def test_run_cross_check_of_a_steady_start_agrees(tmp_path, capsys, monkeypatch):
    """``rollqp run harmonic``: the cross-check covers the steady start and reports agreement, no failure."""
    monkeypatch.chdir(tmp_path)
    scene = tmp_path / "h.toml"
    scene.write_text(load_scene("harmonic").replace(**{"discretization.distance": 0.5}).to_toml())
    assert cli.main(["run", str(scene), "--out", "h.npz"]) == 0
    line = next(ln for ln in capsys.readouterr().out.splitlines() if "cross-check" in ln)
    assert "failed" not in line and "step 0 steady" in line, line
    dp, dt = (float(v) for v in re.findall(r"\|d[pt]\| ([0-9.e+-]+)", line))
    assert dp < 1e-8 and dt < 1e-8, line   # the march's steady tolerance (see above)


def test_spot_check_prints_whole_messages():
    """A failure is printed in full on a line of its own (it was cut at 60 characters)."""
    from rollqp.crossval import SpotCheck
    long = "the QP methods need something long enough that a cut at sixty characters loses its end: THE END"
    text = str(SpotCheck([0, 5], {"qp-osqp": {"error": f"step 0: {long}"}}))
    assert text.splitlines()[-1] == f"qp-osqp failed: step 0: {long}"
