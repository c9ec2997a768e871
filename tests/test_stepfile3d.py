"""Step files of 3D scenes (rollqp.stepfile.three; docs/stepfiles.md, "Three dimensions"): the step's data,
its conic programs in Clarabel's form and as a cvxpy script, and the element-by-element check of any
candidate with rollqp's residuals; bad files are one-line errors and nothing in them is executed."""
from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from rollqp import load_scene
from rollqp.errors import InputError
from rollqp.stepfile import load_step
from rollqp.stepfile.three import StepFile3D, check_step_3d, export_step_3d


def _small(name="cattaneo-3d", **changes):
    return load_scene(name).replace(**{"discretization.elements": [12, 12], **changes})


@pytest.fixture(scope="module")
def rolling(tmp_path_factory):
    step = export_step_3d(_small(), 2)
    path = str(tmp_path_factory.mktemp("step3d") / "c3d.npz")
    return step, step.save(path)


def _candidate(step, **kw):
    d = {"p": step.ref_p.copy(), "t": step.ref_t.copy(), "delta": step.ref_delta, "xi": step.ref_xi,
         "eta": step.ref_eta}
    d.update(kw)
    return d


@pytest.mark.parametrize("name, k, kind", [("cattaneo-3d", 0, "shift"), ("cattaneo-3d", 3, "rolling"),
                                           ("kalker-circular", 0, "steady")])
def test_rollqp_s_own_solution_passes_its_step(name, k, kind):
    """The stored solution satisfies the stored step to the method's tolerance (1e-10): the file holds the
    problem rollqp solved, not another one."""
    step = export_step_3d(_small(name), k)
    assert step.step_type == kind
    rep = check_step_3d(step, _candidate(step), tol=1e-9)
    assert rep.passed and rep.worst < 1e-9, str(rep)


def test_a_dissimilar_step_stores_its_couplings_and_passes():
    s = _small(**{"bodies.B.E": 70000.0, "bodies.B.nu": 0.33})
    step = export_step_3d(s, 1)
    assert step.coupled and np.any(step.A_nt) and np.any(step.A_tn)
    assert check_step_3d(step, _candidate(step), tol=1e-9).passed
    # the coupling matters: the candidate's normal half sees A_nt t, so a zero traction breaks it
    bad = check_step_3d(step, _candidate(step, t=np.zeros_like(step.ref_t)), tol=1e-9)
    assert "signorini" in bad.failed


def test_the_file_round_trips_and_the_missing_unknowns_are_fitted(rolling):
    step, paths = rolling
    again = load_step(paths[0])
    assert isinstance(again, StepFile3D)
    for k in ("A_nn", "B", "h", "c", "ref_p", "ref_t"):
        assert np.array_equal(getattr(again, k), getattr(step, k))
    rep = check_step_3d(again, {"p": step.ref_p, "t": step.ref_t}, tol=1e-9)
    assert rep.passed and set(rep.fitted) == {"delta", "xi", "eta"}
    assert rep.delta == pytest.approx(step.ref_delta, rel=1e-10)
    assert rep.xi == pytest.approx(step.ref_xi, rel=1e-6)


def test_a_wrong_candidate_fails_element_by_element(rolling):
    step, _ = rolling
    rep = check_step_3d(step, _candidate(step, t=1.02 * step.ref_t), tol=1e-8)
    assert not rep.passed and "friction" in rep.failed and "load_x" in rep.failed
    i = rep.failed["friction"][0]
    assert rep.where["friction"][0] == (step.x[i], step.y[i])
    p = step.ref_p.copy()
    p[np.argmax(p)] *= 0.9
    rep = check_step_3d(step, _candidate(step, p=p), tol=1e-8)
    assert "signorini" in rep.failed and "load_normal" in rep.failed
    assert np.argmax(step.ref_p) in rep.failed["signorini"]
    line = "; ".join(rep.diagnosis())
    assert "signorini" in line and "(x, y)" in line


def test_the_clarabel_files_solve_to_rollqp_s_solution(rolling):
    """Clarabel on the JSON files (load_from_file): its raw interior-point answer is within √gap-like
    distance of rollqp's refined one (measured 1e-7 μp0 at the rim, docs/stepfiles.md)."""
    clarabel = pytest.importorskip("clarabel")
    step, paths = rolling
    z = step.arrays()
    for half, path in zip(("normal", "tangential"), paths[1:3]):
        sol = clarabel.load_from_file(path).solve()
        assert str(sol.status) in ("Solved", "AlmostSolved")
        V = z[f"{half}_socp_elements"].astype(int)
        ref = step.ref_p[V] if half == "normal" else step.ref_t[:, V].ravel()
        assert np.max(np.abs(np.array(sol.x) - ref / step.stress)) < 1e-5


def test_the_cvxpy_script_solves_the_step_and_check_step_judges_it(rolling, tmp_path):
    """The script's answer passes at 1e-6 (measured friction residual 1.4e-7 on the rim elements: an interior
    point's answer before any refinement) and the checker names those elements at 1e-9."""
    pytest.importorskip("cvxpy")
    step, paths = rolling
    out = subprocess.run([sys.executable, paths[-1]], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    sol_path = paths[0][:-4] + ".cvxpy-solution.npz"
    assert check_step_3d(step, sol_path, tol=1e-6).passed
    cli = subprocess.run([sys.executable, "-m", "rollqp.cli", "check-step", paths[0], sol_path, "--tol", "1e-6"],
                         capture_output=True, text=True, timeout=300)
    assert cli.returncode == 0 and "PASS" in cli.stdout, cli.stdout + cli.stderr


# ------------------------------------------------------------------- bad files
def _edit(paths, tmp_path, **changes):
    z = dict(np.load(paths[0], allow_pickle=False))
    z.update(changes)
    p = str(tmp_path / "edited.npz")
    np.savez(p, **z)
    return p


def test_an_edited_step_file_is_refused(rolling, tmp_path):
    step, paths = rolling
    with pytest.raises(InputError, match="does not match the step's own data"):
        load_step(_edit(paths, tmp_path, h=step.h * 1.01))
    with pytest.raises(InputError, match="key 'B' must have shape"):
        load_step(_edit(paths, tmp_path, B=step.B[:-1]))
    with pytest.raises(InputError, match="'mu' must be in"):
        load_step(_edit(paths, tmp_path, mu=np.asarray(-1.0)))
    with pytest.raises(InputError, match="'nx', 'ny'"):
        load_step(_edit(paths, tmp_path, nx=np.asarray(1e9)))


def test_a_pickle_in_a_step_file_is_never_loaded(rolling, tmp_path):
    step, paths = rolling
    z = dict(np.load(paths[0], allow_pickle=False))
    z["scene"] = np.array([{"evil": 1}], dtype=object)
    p = str(tmp_path / "pickled.npz")
    np.savez(p, **z)
    with pytest.raises(InputError) as err:
        load_step(p)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("sol, match", [({"p": np.zeros(3), "t": np.zeros((2, 3))}, "shape"),
                                        ({"p": None}, "missing key 't'"),
                                        ({"q": 1.0}, "unknown key")])
def test_bad_candidates_are_one_line_errors(rolling, sol, match):
    step, _ = rolling
    d = dict(sol)
    if d.get("p", 0) is None:
        d["p"] = step.ref_p
    with pytest.raises(InputError, match=match):
        check_step_3d(step, d)


def test_the_command_line_refuses_bad_3d_input_in_one_line(tmp_path):
    def run(*a):
        return subprocess.run([sys.executable, "-m", "rollqp.cli", *a], capture_output=True, text=True, timeout=300,
                              cwd=tmp_path)
    r = run("export-step", "kalker-circular", "--step", "9999")
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "--step" in r.stderr, r.stderr
    (tmp_path / "junk.npz").write_bytes(b"not a zip")
    r = run("check-step", "junk.npz", "junk.npz")
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "STEP.npz" in r.stderr, r.stderr


def test_the_script_takes_the_file_name_as_data_only():
    from rollqp.stepfile.three import cvxpy_script_3d
    name = 'a"""; import os; os.system("x") #.npz'
    text = cvxpy_script_3d(name)
    compile(text, "script", "exec")
    assert repr(name) in text and 'os.system("x")' not in text.split(repr(name))[0]


def test_a_step_file_records_its_scene(rolling):
    step, paths = rolling
    z = np.load(paths[0], allow_pickle=False)
    assert json.loads(str(z["scene"]))["name"] == "cattaneo-3d"
    assert os.path.basename(paths[-1]).endswith(".cvxpy.py")
