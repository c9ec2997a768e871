"""qpsolvers backends (rollqp.methods.qp_qpsolvers): registered when installed, same answers as Newton."""
from __future__ import annotations

import numpy as np
import pytest

import rollqp
from rollqp import cli, get_method, load_scene
from rollqp.errors import MissingBackendError
from rollqp.methods import available_methods
from rollqp.methods import qp_qpsolvers as qps

INSTALLED = [m for m in qps.SOLVERS if m in available_methods()]
needs_any = pytest.mark.skipif(not INSTALLED, reason="no qpsolvers backend installed (pip install 'rollqp[qpsolvers]')")


@pytest.fixture(scope="module")
def short_runs():
    scene = load_scene("cattaneo-carter").replace(**{"discretization.distance": 0.5})
    return scene, rollqp.run(scene, method="newton").arrays()


@needs_any
@pytest.mark.parametrize("name", INSTALLED)
def test_backend_matches_newton_on_a_transient(short_runs, name):
    scene, ref = short_runs
    res = rollqp.run(scene, method=name).arrays()
    # QPMethod's residual limit: 100 × tolerance 1e-10
    assert res["residual"].max() <= 1e-8, f"{name}: residual {res['residual'].max():.2e}"
    # both solve the same collocation problem: agree to the residual limit times the
    # conditioning of the step (measured ≤ 1e-11 p0; 1e-8 leaves room for the interior points)
    assert np.max(np.abs(res["pt"] - ref["pt"])) <= 1e-8 * scene.p0, name
    assert np.max(np.abs(res["pn"] - ref["pn"])) <= 1e-8 * scene.p0, name
    assert f'"method": "{name}"' in str(res["meta"]), "the method run is recorded"


@needs_any
def test_coupled_scene_runs_the_alternation():
    scene = load_scene("goodman-bentall").replace(**{"discretization.distance": 0.05})
    name = INSTALLED[0]
    res = rollqp.run(scene, method=name).arrays()
    ref = rollqp.run(scene, method="newton").arrays()
    assert res["residual"].max() <= 1e-8
    # rolling steps are N-T outer iterations: several per step at 2β = 1, μ = 0.3 (paper §6.3: ≈ 6)
    assert np.all(res["iterations"][1:] >= 2), f"outer iterations {res['iterations']}"
    # the alternation stops at the QP residual limit 1e-8: differences of that order (measured 3e-10 p0)
    assert np.max(np.abs(res["pt"] - ref["pt"])) <= 1e-7 * scene.p0


def test_uninstalled_backend_is_a_clear_error(monkeypatch, capsys):
    monkeypatch.setattr(qps, "_available", lambda solver, package: False)
    assert "qps-daqp" not in available_methods()
    with pytest.raises(MissingBackendError, match=r"qps-daqp.*rollqp\[qpsolvers\]"):
        get_method("qps-daqp")
    assert cli.main(["run", "cattaneo-carter", "--method", "qps-daqp", "--quiet", "--out", "/nonexistent/x.npz"]) == 2
    err = capsys.readouterr().err
    assert "qps-daqp" in err and "pip install 'rollqp[qpsolvers]'" in err and len(err.strip().splitlines()) == 1


def test_unknown_solver_name():
    with pytest.raises(rollqp.InputError, match="solver.method: must be one of .*qps-daqp"):
        get_method("qps-nosuch")


@needs_any
def test_cli_run_with_a_qpsolvers_backend(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    path = tmp_path / "short.toml"
    path.write_text(load_scene("cattaneo-carter").replace(name="short", **{"discretization.distance": 0.2})
                    .to_toml(), encoding="utf-8")
    name = INSTALLED[0]
    assert cli.main(["run", str(path), "--method", name, "--out", "r.npz"]) == 0
    assert name in capsys.readouterr().out, "the summary names the method"
    assert (tmp_path / "r.npz").is_file()


@pytest.mark.integration
@pytest.mark.skipif("qps-highs" not in INSTALLED, reason="HiGHS not installed")
def test_highs_banner_stays_off_stdout(tmp_path):
    """HiGHS prints its banner on the C-level stdout when a process builds its first solver
    object; rollqp discards it, so the summary (and anything piped from it) starts with rollqp's
    own table and the terminal shows no licence text. A real process: the banner is written below
    Python's sys.stdout."""
    import subprocess
    import sys
    scene = tmp_path / "short.toml"
    scene.write_text(load_scene("cattaneo-carter").replace(**{"discretization.distance": 0.1}).to_toml())
    out = subprocess.run([sys.executable, "-m", "rollqp.cli", "run", str(scene), "--method", "qps-highs",
                          "--no-cross-check", "--out", str(tmp_path / "r.npz")],
                         capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert out.returncode == 0, out.stderr
    assert "HiGHS" not in out.stdout, out.stdout[:300]
    assert "HiGHS" not in out.stderr, out.stderr[:300]
    assert out.stdout.lstrip().startswith("scene"), out.stdout[:300]
