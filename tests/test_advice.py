"""The fast path chosen for the user and the estimates before a run (rollqp.advice, rollqp run)."""
from __future__ import annotations

import numpy as np
import pytest

import rollqp
from rollqp import advice, cli
from rollqp.cli import reporting

BIG = {"discretization.elements": 2500, "discretization.distance": 0.003}   # 5,001 nodes, 6 steps


def test_a_large_dense_scene_runs_matrix_free_and_says_so():
    """newton on 5,001 nodes: the dense path needs > 2 GiB (88 n² bytes), mf-newton does the same work."""
    s = rollqp.load_scene("cattaneo-carter").replace(**BIG)
    assert advice.dense_memory(s) > advice.DENSE_MEMORY_LIMIT
    plan = advice.fast_path(s)
    assert plan.scene.solver.method == "mf-newton"
    assert "chosen for 'newton'" in plan.note and "solver.operator = 'dense'" in plan.note and "GiB" in plan.note
    kept = s.replace(**{"solver.operator": "dense"})
    assert advice.fast_path(kept).scene.solver.method == "newton"
    assert "solver.operator = 'auto' runs it with mf-newton" in advice.estimate_note(kept)
    assert advice.fast_path(rollqp.load_scene("cattaneo-carter")).note is None   # 81 nodes


def test_the_qp_route_is_not_replaced():
    """A QP method is another route to the same steps, not a slow Newton: it is never switched, and the
    estimate before its run names the matrix-free method as an option, not as what 'auto' does."""
    s = rollqp.load_scene("cattaneo-carter").replace(**{**BIG, "solver.method": "qp-osqp"})
    assert advice.fast_path(s).note is None
    assert advice.matrix_free_alternative(s) is None and advice.matrix_free_alternative(s, same_method=False)
    note = advice.estimate_note(s)
    assert "solver.method = 'mf-newton' solves the same scene matrix-free" in note and "'auto' runs it" not in note


def test_no_switch_without_fft_operators():
    """The BEM model has no FFT operators: no matrix-free method can do its work, the scene stays."""
    s = rollqp.load_scene("cattaneo-carter").replace(**{**BIG, "contact.model": "bem"})
    assert advice.matrix_free_alternative(s) is None
    assert advice.fast_path(s).note is None
    assert "fewer discretization.elements" in advice.estimate_note(s)


def test_the_chosen_path_gives_the_same_answer(monkeypatch):
    """Forced on a small strip (both limits at 0), rollqp.run takes the matrix-free path, records it, and
    ends where the dense newton does, to the solvers' tolerance (residuals 1e-10: 1e-8 of p0 and μp0)."""
    s = rollqp.load_scene("cattaneo-carter").replace(**{"discretization.elements": 100,
                                                        "discretization.distance": 0.5})
    dense = rollqp.run(s).arrays()
    monkeypatch.setattr(advice, "DENSE_MEMORY_LIMIT", 0.0)
    monkeypatch.setattr(advice, "DENSE_SECONDS_LIMIT", 0.0)
    run = rollqp.run(s)
    assert run.meta["method"] == "mf-newton" and "chosen for 'newton'" in run.meta["method_note"]
    fast = run.arrays()
    assert np.max(np.abs(fast["pn"] - dense["pn"])) < 1e-8 * s.p0
    assert np.max(np.abs(fast["pt"] - dense["pt"])) < 1e-8 * s.contact.mu * s.p0


def test_run_records_and_prints_the_choice(tmp_path, capsys, monkeypatch):
    """rollqp run on the 5,001-node scene: the summary's method row and its fast-path row."""
    monkeypatch.chdir(tmp_path)
    path = tmp_path / "big.toml"
    path.write_text(rollqp.load_scene("cattaneo-carter").replace(**BIG).to_toml())
    assert cli.main(["run", str(path), "--out", "big.npz"]) == 0
    cap = capsys.readouterr()
    assert "mf-newton, matrix-free, chosen for 'newton'" in cap.err
    method = next(line for line in cap.out.splitlines() if line.strip().startswith("method"))
    assert "mf-newton (the scene names newton" in method
    assert any(line.strip().startswith("fast path") for line in cap.out.splitlines())
    res = rollqp.load_result(tmp_path / "big.npz")
    assert res["meta"]["method"] == "mf-newton" and res["meta"]["scene"]["solver"]["method"] == "newton"


def test_alternation_note_names_the_direct_method():
    s = rollqp.load_scene("goodman-bentall")
    assert advice.alternation_note(s) is None                      # newton solves the coupled step itself
    note = advice.alternation_note(s.replace(**{"solver.method": "qp-clarabel"}))
    assert "N–T alternation" in note and "'newton' solves the coupled step directly" in note


def test_long_runs_announce_their_remaining_time(monkeypatch, capsys):
    """After the first steps, a run whose remaining time exceeds a minute says how long, once."""
    clock = iter(np.arange(0.0, 1000.0, 2.5))                     # 2.5 s a step
    monkeypatch.setattr(reporting.time, "perf_counter", lambda: float(next(clock)))
    seen = []
    cb = reporting.estimate_progress(lambda k, K: seen.append(k), 384)
    for k in range(1, 12):
        cb(k, 384)
    err = capsys.readouterr().err
    assert seen == list(range(1, 12))
    assert err.count("\n") == 1 and "about 16 min to go: 379 of 384 steps left at 2.5 s a step (measured on steps 2..5)" in err, err
