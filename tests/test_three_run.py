"""A 3D scene through rollqp's outer contract: ``rollqp run`` (summary, result file, figure),
``rollqp crossval`` (the SOCP backends and Newton step by step), resume, and the refusals of the
commands that take 2D scenes only. Coarse grids: each run takes a fraction of a second with Newton;
the built-in scenes at their own grids are in the slow suite."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from rollqp import cli, load_scene
from rollqp.errors import InputError
from rollqp.methods import CROSSVAL_METHODS_3D, available_methods
from rollqp.crossval.grid import AGREEMENT, crossval, spot_steps
from rollqp.march.grid import steady
from rollqp.report.grid import summary
from rollqp.march.grid import prepare, run

#: SPEC's keys of a 3D result file (docs/results.md, "Three dimensions"): the contract's (every other key is
#: registered in rollqp.fields.FIELDS_3D, beyond the contract).
SPEC_KEYS_3D = {"x", "y", "pn", "px", "py", "sx", "sy", "state", "FN", "Fx", "Fy", "Mz", "creepage", "approach",
                "q", "iterations", "step_time", "residual", "a", "b", "p0", "Estar", "meta"}
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
#: The Newton tolerance the scenes ask for (solver.tolerance): forces are totals of the tractions, so
#: the prescribed ones are met to it times μFN (and round-off).
TOL = 1e-10


def _spec_keys(keys) -> bool:
    """``keys`` are SPEC's keys and registered ones beyond the contract (rollqp.fields.FIELDS_3D)."""
    from rollqp.fields import FIELDS_3D
    contract = {k for k, f in FIELDS_3D.items() if f.contract} | {"meta"}
    return contract == SPEC_KEYS_3D and SPEC_KEYS_3D <= set(keys) and set(keys) - SPEC_KEYS_3D <= set(FIELDS_3D)


def coarse(name: str, **changes):
    """A built-in 3D scene on a coarse grid (12 × 12 elements across a circle; 12 × 24 for a/b = 0.5)."""
    s = load_scene(name)
    nx, ny = s.discretization.elements
    k = 12 / min(nx, ny)
    base = {"discretization.elements": [round(nx * k), round(ny * k)], "discretization.zone": [1.3, 1.3],
            "name": f"{name}-coarse"}
    return s.replace(**{**base, **changes})


@pytest.fixture(scope="module")
def braked():
    scene = coarse("cattaneo-3d", **{"discretization.distance": 1.5})
    return scene, run(scene)


def test_result_file_has_exactly_spec_s_keys_and_shapes(braked, tmp_path):
    scene, result = braked
    path = result.save(tmp_path / "r.npz")
    with np.load(path, allow_pickle=False) as f:                     # no pickled objects
        arrays = {k: f[k] for k in f.files}
    assert _spec_keys(arrays)
    K1, (ny, nx) = scene.n_steps + 1, (scene.grid.ny, scene.grid.nx)
    assert arrays["x"].shape == (nx,) and arrays["y"].shape == (ny,)
    for k in ("pn", "px", "py", "sx", "sy", "state"):
        assert arrays[k].shape == (K1, ny, nx), k
    for k in ("FN", "Fx", "Fy", "Mz", "approach", "q", "iterations", "step_time", "residual"):
        assert arrays[k].shape == (K1,), k
    assert arrays["creepage"].shape == (K1, 3) and arrays["state"].dtype == np.int8
    assert set(np.unique(arrays["state"])) <= {0, 1, 2}
    assert all(arrays[k].shape == () for k in ("a", "b", "p0", "Estar"))
    e = scene.ellipse
    assert (float(arrays["a"]), float(arrays["b"]), float(arrays["p0"])) == (e.a, e.b, e.p0)
    meta = json.loads(str(arrays["meta"]))
    assert meta["method"] == "newton" and meta["dimension"] == 3 and meta["scene"]["contact"]["dimension"] == 3
    assert np.all(arrays["pn"] >= 0)


def test_braked_run_meets_its_loads_and_the_fields_are_consistent(braked):
    scene, result = braked
    a = result.arrays()
    FN, mu = scene.load.normal, scene.mu
    area = scene.grid.dx * scene.grid.dy
    # the prescribed forces (Fx = 0.6 μFN, Fy = 0, FN) at every state, to the solver tolerance
    assert np.allclose(a["FN"], FN, rtol=TOL * 10, atol=0)
    assert np.allclose(a["Fx"], 0.6 * mu * FN, rtol=0, atol=TOL * mu * FN * 10)
    assert np.max(np.abs(a["Fy"])) <= TOL * mu * FN * 10
    # the totals are the sums of the stored fields (the result file is self-consistent)
    assert np.allclose(a["pn"].sum(axis=(1, 2)) * area, a["FN"], rtol=1e-12)
    assert np.allclose(a["px"].sum(axis=(1, 2)) * area, a["Fx"], rtol=1e-12, atol=1e-9 * mu * FN)
    # Coulomb: |t| <= μp element by element (round-off), stick where the slip vanishes
    t = np.hypot(a["px"], a["py"])
    assert np.all(t <= mu * a["pn"] * (1 + 1e-9) + 1e-9 * mu * scene.ellipse.p0)
    assert np.max(a["residual"]) <= 100 * TOL
    # rolling from the braked state: the longitudinal creepage opposes Fx (d = -1, eq. 3D.8's sign)
    assert np.all(a["creepage"][1:, 0] < 0) and np.allclose(a["q"][1:], scene.dq * np.arange(1, scene.n_steps + 1))


def test_summary_rows(braked):
    scene, result = braked
    text = summary(result.arrays(), scene, "newton", 0.5)
    for row in ("scene", "method", "grid", "Hertz", "steps", "forces (end)", "creepages (end)", "stick area (end)",
                "error: hertz", "error: cattaneo", "max residual"):
        assert f"  {row}" in text, row
    assert "raw conic" not in text                       # Newton has no raw conic answer


def test_rolling_start_summary_compares_kalker_and_a_conic_run_shows_its_raw_answers():
    """kalker-circular is all stick at ξ = 1e-5: Kalker's C11 applies (first order in dx: within 5 % on
    12 × 12); run by Clarabel's SOCP the summary states the raw answers' distance from the refined ones."""
    scene = coarse("kalker-circular", **{"discretization.distance": 0.0})
    newton = run(scene)
    text = summary(newton.arrays(), scene, "newton", 0.1)
    line = next(ln for ln in text.splitlines() if "error: kalker" in ln)
    pct = float(line.split("Fx ")[1].split(" %")[0])
    assert abs(pct) < 5, line
    conic = run(scene, method="socp-clarabel")
    a = conic.arrays()
    meta = json.loads(str(a["meta"]))
    assert meta["method"] == "socp-clarabel" and meta["raw_distance"]["steps"] >= 1
    assert 0 <= meta["raw_distance"]["dt"] < 1e-5        # an interior point answer: about sqrt(gap)
    assert "raw conic" in summary(a, scene, "socp-clarabel", 1.0)
    # the conic route's steady state (Newton on the march map) is Newton's, to the tolerance
    sc = newton.arrays()
    assert np.max(np.abs(a["px"] - sc["px"])) <= 1e-8 * scene.mu * scene.ellipse.p0


def test_chord_and_anderson_reach_the_same_steady_state():
    """The conic route's two accelerations of the march (Newton on the march map, Anderson) stop at
    the same fixed point (their stopping test: one step changes the tractions by < tolerance), in
    fewer steps for the chord route at small creepage (all stick: the map is linear)."""
    scene, meth, contact = prepare(coarse("kalker-circular", **{"discretization.distance": 0.0}), "socp-clarabel")
    loads = scene.loads_at(0.0)
    chord = steady(contact, meth, scene.load.normal, loads, accelerate="chord")
    anderson = steady(contact, meth, scene.load.normal, loads, accelerate="anderson")
    unit = scene.mu * scene.ellipse.p0
    assert np.max(np.abs(chord.t - anderson.t)) / unit <= 1e-8      # both within ~tolerance × contraction
    assert chord.info["marched"] < anderson.info["marched"]
    with pytest.raises(InputError, match="accelerate"):
        steady(contact, meth, scene.load.normal, loads, accelerate="broyden")


def test_resume_continues_to_the_same_result(braked):
    scene, full = braked
    a = full.arrays()
    part = {k: (v[:3] if np.ndim(v) and k not in ("x", "y") else v) for k, v in a.items()}
    resumed = run(scene, resume=part).arrays()
    assert resumed["q"].shape == a["q"].shape
    assert np.max(np.abs(resumed["px"] - a["px"])) <= 1e-9 * scene.mu * scene.ellipse.p0
    meta = json.loads(str(resumed["meta"]))
    assert meta["resumed_from"] == 2 and meta["static_shift"] == json.loads(str(a["meta"]))["static_shift"]


# ------------------------------------------------------------------------------------ crossval
def test_crossval_socp_backends_and_newton_agree_step_by_step():
    scene = coarse("cattaneo-3d", **{"discretization.distance": 0.5})
    methods = [m for m in CROSSVAL_METHODS_3D if m in available_methods(3) and m != "newton"]
    check = crossval(scene, methods=methods)
    assert check.agrees(), str(check)
    assert {k for _, k in check.per_step} == set(range(scene.n_steps + 1))
    for (m, k), d in check.per_step.items():
        assert max(d["dp"], d["dt"]) <= AGREEMENT and d["residual"] <= 1e-10, (m, k, d)
    assert "socp-clarabel" in check.table()


def test_crossval_of_a_conic_run_is_checked_by_newton():
    scene = coarse("kalker-elliptic", **{"solver.method": "socp-clarabel"})
    check = crossval(scene, step=0, methods=["newton"])
    assert check.agrees() and check.steady and list(check.per_step) == [("newton", 0)], str(check)


def test_crossval_step_out_of_range_is_one_line():
    with pytest.raises(InputError, match=r"^--step: must be an integer in \[0, 0\]"):
        crossval(coarse("kalker-elliptic"), step=3)
    with pytest.raises(InputError, match="^--methods:"):
        crossval(coarse("kalker-elliptic"), methods=["qp-osqp"])


def test_spot_steps_are_the_first_middle_and_last():
    assert spot_steps(10) == [0, 5, 10] and spot_steps(0) == [0]


# ------------------------------------------------------------------------------- command line
def test_cli_run_writes_result_summary_and_figure(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    scene = coarse("kalker-elliptic")
    path = tmp_path / "ke.toml"
    path.write_text(scene.to_toml(), encoding="utf-8")
    assert cli.main(["run", str(path), "--out", "ke.npz", "--plot", "ke.png"]) == 0
    out = capsys.readouterr().out
    assert "three-dimensional" in out and "cross-check" in out and "agree" in out and "DISAGREE" not in out
    assert (tmp_path / "ke.png").read_bytes()[:8] == PNG_MAGIC
    with np.load(tmp_path / "ke.npz", allow_pickle=False) as f:
        assert _spec_keys(f.files)


def test_cli_crossval_of_a_3d_scene(tmp_path, capsys):
    path = tmp_path / "c.toml"
    path.write_text(coarse("cattaneo-3d", **{"discretization.distance": 0.2}).to_toml(), encoding="utf-8")
    assert cli.main(["crossval", str(path), "--methods", "socp-clarabel"]) == 0
    out = capsys.readouterr().out
    assert "socp-clarabel: agree" in out and "reference: newton" in out


@pytest.mark.parametrize("argv", [["creep-curve", "kalker-circular", "--ratios", "0.1", "--workers", "0"]])
# a 2D-only option; export-step, sweep, creep-curve and run --stresses take 3D scenes (tests/test_stepfile3d.py,
# tests/test_sweep3d.py, tests/test_beyond_hertz_scenes.py)
def test_2d_only_commands_refuse_a_3d_scene_in_one_line(argv, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert cli.main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "3D" in err and "Traceback" not in err


def test_cli_refuses_osqp_on_a_3d_scene(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert cli.main(["run", "kalker-circular", "--method", "qp-osqp"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "solver.method" in err and "socp-clarabel" in err


# ------------------------------------------------------------------------------- the built-ins
@pytest.mark.slow
@pytest.mark.parametrize("name", ["kalker-circular", "kalker-elliptic", "cattaneo-3d", "ball-in-groove"])
def test_builtin_3d_scene_runs_and_crossvalidates(name, tmp_path):
    """The built-in scene at its own grid: run with Newton (seconds), its figure, and every step
    solved again by the SOCP backends (the conic solves take minutes on the 40 × 40 grid)."""
    from rollqp.plot import three_figure
    scene = load_scene(name)
    result = run(scene)
    three_figure(result.arrays(), scene, str(tmp_path / "f.png"))
    assert (tmp_path / "f.png").read_bytes()[:8] == PNG_MAGIC
    step = None if scene.grid.n <= 1200 else scene.n_steps // 2
    check = crossval(scene, step=step)
    assert check.agrees(), str(check)
    assert math.isfinite(float(result.arrays()["Fx"][-1]))


def test_the_strip_march_refuses_a_3d_scene_in_one_line():
    """rollqp.march.strip.run is the strip's run; rollqp.march.run hands a scene to its discretization's march."""
    from rollqp.march import family
    from rollqp.march.strip import run as run_2d
    with pytest.raises(InputError, match=r"^scene: 'kalker-elliptic' is a 3D scene: rollqp.march.strip runs the strip; "
                                         r"rollqp.march.run and rollqp.march.march run either"):
        run_2d("kalker-elliptic")
    assert family("kalker-elliptic").__name__ == "rollqp.march.grid"
    assert family("cattaneo-carter").__name__ == "rollqp.march.strip"


def test_load_result_reads_a_3d_file_and_the_cli_resumes_it(braked, tmp_path, capsys, monkeypatch):
    import rollqp
    scene, result = braked
    monkeypatch.chdir(tmp_path)
    full = result.arrays()
    back = rollqp.load_result(result.save(tmp_path / "full.npz"))
    assert back["meta"]["method"] == "newton" and np.array_equal(back["px"], full["px"])
    part = {k: (v[:2] if np.ndim(v) and k not in ("x", "y") else v) for k, v in full.items()}
    np.savez(tmp_path / "part.npz", **part)
    assert cli.main(["run", "--resume", "part.npz", "--quiet"]) == 0
    again = rollqp.load_result(tmp_path / "part.npz")
    assert again["q"].shape == full["q"].shape
    assert np.max(np.abs(again["px"] - full["px"])) <= 1e-9 * scene.mu * scene.ellipse.p0
    bad = dict(part, px=part["px"][:, :3])                   # a field of the wrong shape
    np.savez(tmp_path / "bad.npz", **bad)
    with pytest.raises(InputError, match=r"^R: key 'px' must have shape"):
        rollqp.load_result(tmp_path / "bad.npz", "R")


def test_docs_results_table_is_the_registry_s():
    from pathlib import Path
    from rollqp.fields import markdown_table
    text = (Path(__file__).resolve().parents[1] / "docs" / "results.md").read_text(encoding="utf-8")
    table = text.split("<!-- fields3d table: begin -->\n", 1)[1].split("<!-- fields3d table: end -->", 1)[0]
    assert table.strip() == markdown_table(3).strip()


def test_an_interrupted_run_writes_its_completed_states(tmp_path):
    import rollqp
    scene = coarse("cattaneo-3d", **{"discretization.distance": 1.5})
    out = tmp_path / "cut.npz"

    def stop(rec, contact):
        if rec.k == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt) as err:
        run(scene, observe=stop, out=str(out))
    assert len(err.value.partial) == 3
    back = rollqp.load_result(out)
    assert back["q"].shape == (3,) and "interrupted" in back["meta"]
    kept = run(scene, keep_every=2).arrays()          # every 2nd state and the last two, as in 2D
    full = run(scene).arrays()
    steps = np.asarray(kept["step"])
    assert steps[0] == 0 and np.all(steps[1:-2] % 2 == 0) and steps[-1] == scene.n_steps
    assert np.array_equal(kept["px"], full["px"][steps]) and kept["iterations"].sum() == full["iterations"].sum()


class _Killed(BaseException):
    """Stands for SIGKILL: nothing of the run's own handling runs after it."""


def test_a_killed_run_resumes_from_its_journal(tmp_path, capsys, monkeypatch):
    """Every state is in ``out.journal`` as soon as it is completed: a run stopped with no chance to
    write its file (here an exception nothing handles, as SIGKILL) resumes from the journal to the
    same result as an uninterrupted run, and the journal is removed when the file is written."""
    import rollqp
    monkeypatch.chdir(tmp_path)
    scene = coarse("cattaneo-3d", **{"discretization.distance": 1.5})
    full = run(scene).arrays()

    def kill(rec, contact):
        if rec.k == 3:
            raise _Killed

    with pytest.raises(_Killed):
        run(scene, observe=kill, out="k.npz")
    assert not (tmp_path / "k.npz").exists() and (tmp_path / "k.npz.journal").stat().st_size > 0
    assert cli.main(["run", "--resume", "k.npz", "--quiet"]) == 0
    back = rollqp.load_result("k.npz")
    assert back["q"].shape == full["q"].shape and back["meta"]["resumed_from"] == 3
    assert np.max(np.abs(back["px"] - full["px"])) <= 1e-9 * scene.mu * scene.ellipse.p0
    assert not (tmp_path / "k.npz.journal").exists()


def test_a_conic_run_is_cross_checked_by_the_other_route_only(tmp_path, capsys, monkeypatch):
    """socp-clarabel and qp-clarabel are one class: a socp-clarabel run is cross-checked by Newton."""
    monkeypatch.chdir(tmp_path)
    path = tmp_path / "ke.toml"
    path.write_text(coarse("kalker-elliptic", **{"solver.method": "socp-clarabel"}).to_toml(), encoding="utf-8")
    assert cli.main(["run", str(path)]) == 0
    out = capsys.readouterr().out
    line = next(ln for ln in out.splitlines() if "cross-check" in ln)
    assert "newton on steps 0" in line and "qp-clarabel" not in line, line
    assert "raw conic" in out


def test_the_package_run_and_march_take_a_scene_of_either_dimension():
    """``rollqp.run``/``rollqp.march`` dispatch on the scene's dimension: a 3D scene gives the 3D run's
    result (the same arrays as :func:`rollqp.march.grid.run`, bitwise: one deterministic computation), a
    2D scene the 2D run's."""
    import rollqp
    from rollqp.march.strip import run as run_2d
    scene = coarse("kalker-circular", **{"discretization.distance": 0.5})
    mine, theirs = rollqp.run(scene).arrays(), run(scene).arrays()
    assert _spec_keys(mine)
    for key in ("pn", "px", "py", "state", "Fx"):
        np.testing.assert_array_equal(mine[key], theirs[key])
    records = list(rollqp.march(scene))
    assert len(records) == mine["q"].size
    flat = rollqp.load_scene("cattaneo-carter").replace(**{"discretization.distance": 1.0})
    np.testing.assert_array_equal(rollqp.run(flat).arrays()["pt"], run_2d(flat).arrays()["pt"])
