"""The ``rollqp`` command (rollqp.cli; SPEC.md "Command line").

Through the installed entry point (subprocess: what a user's shell sees — exit codes, one-line
messages, no traceback) and through :func:`rollqp.cli.main` in-process (fast, and able to
inject a failure deterministically).
"""
from __future__ import annotations

import importlib

import shutil
import subprocess
import sys

import numpy as np
import pytest

import rollqp
from rollqp import cli, load_result, load_scene
from conftest import Delegate
from rollqp.scene import builtin_scenes, scene_from_toml

SPEC_KEYS = {"x", "q", "pn", "pt", "slip", "gap", "state", "P", "Q", "creepage", "approach", "iterations",
             "step_time", "residual", "a_H", "p0", "R", "Estar", "beta", "leading_edge", "meta"}
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def rollqp_cmd(*args, cwd):
    """Run the installed ``rollqp`` script (or ``python -m rollqp.cli`` if it is not on PATH)."""
    exe = shutil.which("rollqp")
    cmd = [exe] if exe else [sys.executable, "-m", "rollqp.cli"]
    return subprocess.run(cmd + [str(a) for a in args], cwd=cwd, capture_output=True, text=True, timeout=120)


def write_scene(folder, name="short", **changes):
    """A cattaneo-carter variant rolled 1 a_H with qp-osqp, as a TOML file."""
    base = {"discretization.distance": 1.0, "solver.method": "qp-osqp", "name": name}
    scene = load_scene("cattaneo-carter").replace(**{**base, **changes})
    path = folder / f"{name}.toml"
    path.write_text(scene.to_toml(), encoding="utf-8")
    return path, scene


def one_line_error(proc, code, *words):
    """Exit ``code``, one line on stderr containing ``words``, no traceback."""
    err = proc.stderr
    assert proc.returncode == code, f"exit {proc.returncode}, expected {code}; stderr: {err!r}"
    assert "Traceback" not in err, f"no traceback: {err!r}"
    assert len(err.strip().splitlines()) == 1, f"one line: {err!r}"
    assert err.startswith("rollqp: "), f"prefixed with the program: {err!r}"
    for w in words:
        assert w in err, f"{w!r} in the message: {err!r}"


# ------------------------------------------------------------------------------- run
@pytest.mark.integration
def test_run_writes_result_and_figure(tmp_path):
    path, scene = write_scene(tmp_path)
    proc = rollqp_cmd("run", path, "--out", "r.npz", "--plot", "r.png", "--quiet", cwd=tmp_path)
    assert proc.returncode == 0, f"exit 0: {proc.stderr}"
    assert proc.stdout == "" and proc.stderr == "", f"--quiet prints nothing: {proc.stdout!r} {proc.stderr!r}"
    png = (tmp_path / "r.png").read_bytes()
    assert png[:8] == PNG_MAGIC and len(png) > 10_000, "a PNG figure with content"
    res = load_result(tmp_path / "r.npz")
    assert SPEC_KEYS <= set(res), f"SPEC.md keys missing: {SPEC_KEYS - set(res)}"
    K, n = scene.n_steps, 2 * scene.discretization.elements + 1
    assert res["pt"].shape == (K + 1, n) and res["q"].shape == (K + 1,), f"shapes {res['pt'].shape}, {res['q'].shape}"
    assert res["meta"]["method"] == "qp-osqp" and res["meta"]["scene"]["name"] == "short", "meta: method, scene"
    assert res["residual"].max() <= 1e-8, "solved to the backend's residual limit (100 × tolerance 1e-10)"


def test_run_prints_summary(tmp_path, capsys, monkeypatch):
    path, _ = write_scene(tmp_path)
    monkeypatch.chdir(tmp_path)
    assert cli.main(["run", str(path), "--method", "qp-clarabel"]) == 0, "exit 0"
    out = capsys.readouterr().out
    for label in ("steps", "iterations", "wall time", "max residual", "error: hertz", "error: cattaneo"):
        assert label in out, f"the summary shows {label!r}:\n{out}"
    assert "qp-clarabel" in out, "--method overrides [solver].method"
    assert (tmp_path / "short.npz").is_file(), "default result file <scene name>.npz in the current folder"
    assert load_result(tmp_path / "short.npz")["meta"]["method"] == "qp-clarabel", "the method run is recorded"


# ------------------------------------------------------------------------------- scenes, show
def test_scenes_lists_builtins(capsys):
    assert cli.main(["scenes"]) == 0, "exit 0"
    lines = capsys.readouterr().out.strip().splitlines()
    names = builtin_scenes()
    assert len(lines) == len(names) >= 2, f"one line per built-in scene: {lines}"
    for line, (name, desc) in zip(lines, names.items()):
        assert line.split()[0] == name and desc in line, f"name and description: {line!r}"


@pytest.mark.parametrize("name", ["cattaneo-carter", "ramp"])
def test_show_round_trips(name, capsys, tmp_path):
    assert cli.main(["show", name]) == 0, "exit 0"
    text = capsys.readouterr().out
    shown = tmp_path / "shown.toml"
    shown.write_text(text, encoding="utf-8")
    assert load_scene(shown) == load_scene(name), f"show's TOML reads back to the same scene:\n{text}"
    assert "[solver]" in text and "start_steps" in text, "defaults are filled in"


@pytest.mark.integration
def test_show_a_file_through_the_entry_point(tmp_path):
    path, scene = write_scene(tmp_path)
    proc = rollqp_cmd("show", path, cwd=tmp_path)
    assert proc.returncode == 0, f"exit 0: {proc.stderr}"
    assert scene_from_toml(proc.stdout) == scene, "the file's scene, defaults filled in"


# ------------------------------------------------------------------------------- bad input
def _edit(path, old, new):
    text = path.read_text(encoding="utf-8")
    assert old in text, f"precondition: {old!r} in the scene file"
    path.write_text(text.replace(old, new, 1), encoding="utf-8")
    return path


@pytest.mark.integration
@pytest.mark.parametrize("case", ["nu", "unknown-key", "missing-file", "out-not-npz"])
def test_bad_input_exits_2_with_one_line(case, tmp_path):
    path, _ = write_scene(tmp_path)
    if case == "nu":
        proc = rollqp_cmd("run", _edit(path, "nu = 0.3", "nu = 0.7"), cwd=tmp_path)
        one_line_error(proc, 2, "bodies.A.nu", "0.7", "(-1, 0.5)")
    elif case == "unknown-key":
        proc = rollqp_cmd("run", _edit(path, "friction = ", "frction = "), cwd=tmp_path)
        one_line_error(proc, 2, "contact.frction", "did you mean 'friction'")
    elif case == "missing-file":
        proc = rollqp_cmd("run", tmp_path / "nowhere.toml", cwd=tmp_path)
        one_line_error(proc, 2, "SCENE", "nowhere.toml")
    else:
        proc = rollqp_cmd("run", path, "--out", "result.txt", cwd=tmp_path)
        one_line_error(proc, 2, "--out", ".npz")
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name], "nothing written on bad input"


@pytest.mark.parametrize("argv", [
    pytest.param(["run"], id="no-scene"),
    pytest.param(["run", "cattaneo-carter", "--method", "simplex"], id="unknown-method"),
    pytest.param(["frobnicate"], id="unknown-command"),
])
def test_bad_arguments_exit_2(argv, capsys):
    try:
        code = cli.main(argv)                   # rollqp's own check (run without a scene)
    except SystemExit as exit_:                 # argparse's
        code = exit_.code
    err = capsys.readouterr().err
    assert code == 2, f"exit 2: {code}"
    assert len(err.strip().splitlines()) == 1 and "usage" not in err, f"one line, no usage dump: {err!r}"


def test_builtin_name_typo_suggests(capsys):
    assert cli.main(["show", "cattaneo-cartr"]) == 2, "exit 2"
    err = capsys.readouterr().err
    assert "did you mean 'cattaneo-carter'" in err, f"suggests the built-in: {err!r}"


# ------------------------------------------------------------------------------- solver failure
@pytest.mark.integration
def test_solver_failure_exits_3_and_writes_partial(tmp_path):
    # A genuine non-convergence after the starting state: the §6.1.2 ramp (Q = 0 at the start,
    # so the braked start is trivial) with Newton allowed 3 iterations per step; the growing
    # load needs more within a few steps (measured: step 4).
    from rollqp.histories import Ramp
    path, _ = write_scene(tmp_path, **{"solver.method": "newton", "solver.max_iterations": 3,
                                       "load.tangential": Ramp(start=0.0, end=0.75, over=8 / 3)})
    proc = rollqp_cmd("run", path, "--out", "partial.npz", cwd=tmp_path)
    one_line_error(proc, 3, "solver error", "step ", "newton", "merit", "partial.npz")
    step = int(proc.stderr.split("step ")[1].split(",")[0])
    assert step >= 1, f"fails after the starting state: step {step}"
    res = load_result(tmp_path / "partial.npz")
    assert res["q"].shape == (step,), f"states 0..{step - 1} written: {res['q'].shape}"
    assert f"step {step}" in res["meta"]["failed"], f"the failure is recorded in meta: {res['meta'].get('failed')}"


def test_injected_failure_exits_3_and_writes_partial(tmp_path, capsys, monkeypatch):
    path, scene = write_scene(tmp_path)
    real = rollqp.methods.scene_method

    class Failing(Delegate):
        calls = 0

        def solve(self, problem, warm=None):
            if problem.kind == "tangential":
                self.calls += 1
                if self.calls == 4:                        # tangential solve 4 = rolling step 3
                    raise rollqp.SolverError("injected", method=self.name, status="test")
            return self.inner.solve(problem, warm=warm)

    monkeypatch.setattr(importlib.import_module("rollqp.march.strip"), "scene_method", lambda settings, coupled=False, **kw: Failing(real(settings, coupled, **kw)))
    out = tmp_path / "p.npz"
    assert cli.main(["run", str(path), "--out", str(out), "--quiet"]) == 3, "exit 3 on a solver failure"
    err = capsys.readouterr().err
    assert err.startswith("rollqp: solver error: step 3") and len(err.strip().splitlines()) == 1, err
    res = load_result(out)
    assert np.allclose(res["q"], np.arange(3) * scene.dq, rtol=1e-14), f"states 0..2 (round-off): {res['q']}"
    assert "injected" in res["meta"]["failed"], "meta records the failure"
