"""The benchmark harness and suite (benchmarks/harness.py, benchmarks/suite.py): their bookkeeping, not their timings."""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import suite as bench  # noqa: E402  (benchmarks/suite.py, with harness.py beside it)


def test_failed_case_is_recorded_not_raised():
    """A method that cannot finish a case (one Newton iteration allowed) is a recorded failure."""
    scene = bench.cattaneo_carter(**{"discretization.elements": 10, "solver.max_iterations": 1})
    r = bench.timed_run(scene, "newton", repeats=1)
    assert not r.ok
    assert "SolverError" in r.failed


def test_run_records_errors_and_times():
    scene = bench.cattaneo_carter(**{"discretization.elements": 10})
    r = bench.timed_run(scene, "newton", repeats=2, budget=10.0)
    assert r.ok and r.repeats == 2 and r.n == 21 and r.steps == scene.n_steps
    assert r.stepping > 0 and r.step > 0
    # closed-form errors of 10 QCE: discretization errors of a few percent of μp0
    assert 1e-3 < r.errors["cattaneo"] < 0.1 and 1e-3 < r.errors["carter"] < 0.1
    # distance to itself is zero; to a looser run it is positive
    assert bench.diff_to(r, r, 0.1) == 0.0
    loose = bench.timed_run(scene.replace(**{"solver.tolerance": 1e-3}), "newton", repeats=1)
    assert bench.diff_to(loose, r, 0.1) > 0.0


def test_fit_exponent():
    n = np.array([161, 321, 641, 1281])
    assert abs(bench.fit_exponent(n, 3e-9 * n ** 2.5) - 2.5) < 1e-9  # exact power law: round-off
    assert np.isnan(bench.fit_exponent(n[:1], [1.0]))


def test_write_sections(tmp_path):
    doc = tmp_path / "p.md"
    doc.write_text("a\n<!-- bench:x -->\nold\n<!-- /bench:x -->\nb\n")
    assert bench.write_sections(doc, {"x": "new table", "y": "absent"}) == ["x"]
    assert doc.read_text() == "a\n<!-- bench:x -->\nnew table\n<!-- /bench:x -->\nb\n"


def test_bad_arguments_exit_2(capsys):
    assert bench.main(["--parts", "nonsense"]) == 2
    assert "unknown part" in capsys.readouterr().err


def test_cli_routes_bench(capsys):
    """``rollqp bench ...`` is the harness with its own options (rollqp.cli hands them over)."""
    from rollqp import cli
    assert cli.main(["bench", "--parts", "nope"]) == 2
    assert "unknown part nope" in capsys.readouterr().err


def test_quick_study_draws_its_figures(tmp_path, capsys):
    """``rollqp bench --quick --figures DIR`` ends with the figures drawn and the raw numbers written
    (it once crashed at the first figure, after all the compute)."""
    pytest.importorskip("matplotlib")
    rc = bench.main(["--quick", "--parts", "tolerance,discretization", "--methods", "newton",
                     "--figures", str(tmp_path), "--json", str(tmp_path / "raw.json")])
    assert rc == 0, capsys.readouterr().err
    for name in ("perf-wp-tolerance.png", "perf-wp-discretization.png", "perf-wp-coupled.png"):
        assert (tmp_path / name).stat().st_size > 1000, name
    assert set(json.loads((tmp_path / "raw.json").read_text())) == {"tolerance", "discretization"}


def test_failed_figure_keeps_the_results(tmp_path, capsys, monkeypatch):
    """A figure that fails is reported (exit 1) after the tables are printed and the raw numbers written."""
    def broken(res, path):
        raise RuntimeError("no figure today")
    monkeypatch.setattr(bench, "figure_tolerance", broken)
    rc = bench.main(["--quick", "--parts", "tolerance", "--methods", "newton", "--figures", str(tmp_path),
                     "--json", str(tmp_path / "raw.json")])
    cap = capsys.readouterr()
    assert rc == 1
    assert "## Work–precision: solver tolerance" in cap.out and "| `newton` |" in cap.out
    assert "figure perf-wp-tolerance.png failed: RuntimeError: no figure today" in cap.err
    assert "tolerance" in json.loads((tmp_path / "raw.json").read_text())
