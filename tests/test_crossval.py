"""The cross-validation report (rollqp.crossval): every method on one stored step, side by side."""
from __future__ import annotations

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
