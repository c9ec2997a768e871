"""Files rollqp did not write itself: step files, candidate solutions and result files are
read without trusting a byte (rollqp.npzfile). Every corruption is a one-line InputError naming
the argument and the key — never a traceback, a silent cast or a huge allocation."""
from __future__ import annotations

import io
import json
import os
import re
import subprocess
import sys
import warnings
import zipfile

import numpy as np
import pytest

import rollqp
from rollqp import cli
from rollqp.errors import InputError
from rollqp.result import load_result
from rollqp.stepfile import StepFile, export_step, load_solution


@pytest.fixture(scope="module")
def step_file(tmp_path_factory):
    folder = tmp_path_factory.mktemp("step")
    path = folder / "s.npz"
    export_step("cattaneo-carter", 3).save(path, native=False)
    return path, dict(np.load(path, allow_pickle=False))


def _write(path, arrays):
    np.savez(path, **arrays)
    return path


def _one_line_cli(capsys, *argv, code=2, words=()):
    assert cli.main(list(argv)) == code
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    for w in words:
        assert w in err, f"{w!r} not in {err!r}"
    return err


def test_flipped_bit_is_a_one_line_error(step_file, tmp_path, capsys):
    path, _ = step_file
    data = bytearray(path.read_bytes())
    data[len(data) // 2] ^= 0x10
    bad = tmp_path / "flip.npz"
    bad.write_bytes(bytes(data))
    _one_line_cli(capsys, "check-step", str(bad), str(path), words=("STEP.npz", "not a readable .npz"))


def test_oversized_header_is_refused_before_allocation(step_file, tmp_path):
    header = np.lib.format.header_data_from_array_1_0(np.zeros(3))
    header["shape"] = (400000, 400000)               # 1.3 TB claimed, 24 bytes present
    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(buf, header)
    buf.write(b"\0" * 24)
    bad = tmp_path / "huge.npz"
    with zipfile.ZipFile(bad, "w") as zf:
        zf.writestr("p.npy", buf.getvalue())
    with pytest.raises(InputError, match="claims .* bytes"):
        load_solution(bad, 81)


@pytest.mark.parametrize("key, value, words", [
    ("A_nn", "nan", "'A_nn' must be finite"),
    ("mu", "text", "'mu' must hold real numbers"),
    ("ref_delta", "nan", "'ref_delta' must be finite"),
    ("normal_qp_P", "shape", "'normal_qp_P' must have shape"),
    ("tangential_qp_q", "nan", "'tangential_qp_q' does not match"),
    ("tangential_qp_q", "edit", "'tangential_qp_q' does not match"),
    ("kind", "other", "'kind' must be one of"),
])
def test_each_step_key_is_checked(step_file, tmp_path, key, value, words):
    path, arrays = step_file
    bad = dict(arrays)
    v = np.array(bad[key])
    if value == "nan":
        v = v.astype(float)
        v.flat[0] = np.nan
    elif value == "text":
        v = np.array("abc")
    elif value == "shape":
        v = np.zeros((3, 3))
    elif value == "edit":
        v = v * 1.01
    else:
        v = np.array(value)
    bad[key] = v
    with pytest.raises(InputError, match=words):
        StepFile.load(_write(tmp_path / "bad.npz", bad))


@pytest.mark.parametrize("make, words", [
    (lambda p, t: dict(p=p.astype(complex) + 1j, t=t), "'p' must hold real numbers"),
    (lambda p, t: dict(p=np.array(["a"] * p.size), t=t), "'p' must hold real numbers"),
    (lambda p, t: dict(p=p, t=t, xi=np.array([np.nan])), "'xi' must be finite"),
    (lambda p, t: dict(p=p[:-1]), "'p' must have shape"),
    (lambda p, t: dict(q=p), "unknown key"),
])
def test_candidate_solutions_are_checked(step_file, tmp_path, capsys, make, words):
    path, arrays = step_file
    sol = _write(tmp_path / "sol.npz", make(arrays["ref_p"], arrays["ref_t"]))
    _one_line_cli(capsys, "check-step", str(path), str(sol), words=("SOLUTION.npz", words))


def test_result_files_are_checked(tmp_path):
    res = rollqp.run("cattaneo-carter", method="newton").arrays()
    good = _write(tmp_path / "r.npz", res)
    assert load_result(good)["meta"]["method"] == "newton"
    for key, value, words in (("pn", res["pn"][:, :-1], "'pn' must have shape"),
                              ("pt", res["pt"].astype(complex), "'pt' must hold real numbers"),
                              ("meta", np.array("{not json"), "'meta' must be a JSON string")):
        with pytest.raises(InputError, match=words):
            load_result(_write(tmp_path / "bad.npz", dict(res, **{key: value})))
    with pytest.raises(InputError, match="not a rollqp result file"):
        load_result(_write(tmp_path / "other.npz", {"a": np.zeros(3)}))


def test_unknown_zip_version_is_a_one_line_error(step_file, tmp_path):
    """A flipped bit in a member's 'version needed' field makes zipfile raise
    NotImplementedError (found by tests/test_fuzz.py, seed file-30205): an InputError here."""
    path, _ = step_file
    data = bytearray(path.read_bytes())
    k = data.find(b"PK\x01\x02")  # first central-directory entry; bytes 6–7: version needed to extract
    data[k + 6] = 109  # version 10.9
    bad = tmp_path / "version.npz"
    bad.write_bytes(bytes(data))
    with pytest.raises(InputError, match="not a readable .npz"):
        StepFile.load(bad)


# --------------------------------------------------------------------------- nothing read is trusted
@pytest.fixture(scope="module")
def result_file(tmp_path_factory):
    folder = tmp_path_factory.mktemp("result")
    scene = rollqp.load_scene("cattaneo-carter").replace(**{"discretization.distance": 0.25, "solver.method": "newton",
                                                            "bodies.A.wear": 1e-9})
    rollqp.run(scene, out=folder / "r.npz")
    return folder / "r.npz", dict(np.load(folder / "r.npz", allow_pickle=False))


@pytest.mark.parametrize("key, value, words", [
    ("a_H", 0.0, "key 'a_H' must be a number > 0, got 0.0"),
    ("p0", 0.0, "key 'p0' must be a number > 0, got 0.0"),
    ("a_H", -1.0, "key 'a_H' must be a number > 0, got -1.0"),
    ("Estar", np.nan, "key 'Estar' must be finite"),
    ("beta", 7.0, "key 'beta' must be a number in [-0.5, 0.5]"),
    ("leading_edge", 0, "key 'leading_edge' must be a number +1 or -1"),
])
def test_the_scalars_readers_divide_by_are_checked(result_file, tmp_path, capsys, key, value, words):
    """A result file whose a_H or p0 is 0 (a division by zero before) or a_H < 0 (stresses on a grid above
    the surface before, exit 0) is a one-line error of every reader: load_result, stresses, resume."""
    _, arrays = result_file
    bad = _write(tmp_path / "bad.npz", dict(arrays, **{key: np.asarray(value)}))
    with pytest.raises(InputError, match=re.escape(words)):
        load_result(bad)
    _one_line_cli(capsys, "stresses", str(bad), "--step", "1", words=("RESULT.npz", words))
    _one_line_cli(capsys, "run", "--resume", str(bad), words=("--resume", words))


def test_a_result_whose_scalars_are_not_its_scenes_is_refused(result_file, tmp_path, capsys):
    _, arrays = result_file
    bad = _write(tmp_path / "bad.npz", dict(arrays, a_H=np.asarray(float(arrays["a_H"]) * 2)))
    _one_line_cli(capsys, "stresses", str(bad), "--step", "1", words=("key 'a_H'", "is not the a_H of the scene"))


@pytest.mark.parametrize("args, words", [
    (("--depth", "1e-300"), "--depth: must be a number in [0.001, 100]"),
    (("--width", "0"), "--width: must be a number in [0.001, 100]"),
    (("--depth", "nan"), "--depth: must be a number in [0.001, 100]"),
    (("--grid", "3," + "9" * 5000), "--grid"),
])
def test_stresses_grid_arguments(result_file, capsys, args, words):
    """``--depth 1e-300`` is a range error (not NaN peaks with exit 0), and the field is checked finite."""
    path, _ = result_file
    _one_line_cli(capsys, "stresses", str(path), "--step", "-1", *args, words=(words,))


def test_stresses_on_a_grid_too_close_to_the_surface_is_an_error_not_nan(result_file):
    path, _ = result_file
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(InputError, match="grid: the stresses are not finite on this grid"):
            rollqp.stresses(path, -1, grid=(np.linspace(-1, 1, 5), np.array([1e-300, 1e-3])))


@pytest.mark.parametrize("wear", [1e305, 1e308, 1.0])
def test_a_wear_coefficient_beyond_archards_range_is_refused(wear):
    """k/H >= 1e305 wrote wear_rate_A = inf with exit 0: k·p0/H must be at most 1."""
    with pytest.raises(InputError, match=r"bodies\.A\.wear: must be a number in \[0, 1/p0"):
        rollqp.load_scene("cattaneo-carter").replace(**{"bodies.A.wear": wear})


def test_wear_profile_checks_its_coefficient(result_file):
    path, _ = result_file
    with pytest.raises(InputError, match="coefficient: must be a number in"):
        rollqp.wear.profile(path, coefficient=1e305)
    sigma, depth = rollqp.wear.profile(path)
    assert np.all(np.isfinite(depth)) and depth.max() > 0


@pytest.fixture
def in_tmp(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # profile files are read from the working folder only
    return tmp_path


def _with_profile_file(name):
    d = rollqp.load_scene("cattaneo-carter").to_dict()
    d["bodies"]["A"]["profile"] = {"kind": "table", "file": name}
    return d


@pytest.mark.parametrize("make, name, words", [
    (lambda p: p.joinpath("loop.csv").symlink_to("loop.csv"), "loop.csv", "cannot be resolved to a file"),
    (lambda p: None, "a\0b.csv", "no NUL character"),
    (lambda p: p.joinpath("e.csv").write_text(""), "e.csv", "holds no rows of numbers x, h (an empty CSV file)"),
    (lambda p: p.joinpath("c.csv").write_text("# x, h\n"), "c.csv", "holds no rows of numbers"),
    (lambda p: p.joinpath("h.csv").write_text("-5,0\n0,1e308\n5,0\n"), "h.csv", "heights must be within ±radius"),
])
def test_profile_files_that_cannot_be_read(in_tmp, make, name, words):
    """Symbolic link loops and NUL characters (tracebacks before), an empty CSV (numpy's warning before the
    error), heights of 1e308 (overflow warnings, then a solver error): one line naming the key, no warning."""
    make(in_tmp)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(InputError, match=r"bodies\.A\.profile\.(file|x)") as err:
            rollqp.load_scene(_with_profile_file(name))
    assert words in str(err.value) and "\n" not in str(err.value), str(err.value)


def test_a_table_from_minus_to_plus_1e308_is_a_flat_punch(in_tmp):
    """x over ±1e308 (the difference overflows) with h = 0: a valid flat contact-frame table, read without a warning."""
    in_tmp.joinpath("x.csv").write_text("-1e308,0\n1e308,0\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        scene = rollqp.load_scene(_with_profile_file("x.csv"))
    assert scene.A.profile.base.x == (-1e308, 1e308)


def test_a_flat_far_away_computes_without_overflow():
    d = rollqp.load_scene("cattaneo-carter").replace(**{"discretization.distance": 0.1}).to_dict()
    d["bodies"]["A"]["profile"] = [{"kind": "flat", "length": 0.2, "position": 1e308},
                                   {"kind": "defect", "depth": 1e-3, "width": 1e-300, "position": -1e308}]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = rollqp.run(rollqp.load_scene(d), method="newton")
    assert np.all(np.isfinite(res["pn"]))


def test_matrix_free_with_method_mf_newton_is_validated_as_it_runs(tmp_path, capsys):
    """``solver.operator = "matrix-free"`` with ``--method mf-newton`` was refused: the scene was validated
    with its own method before the override."""
    scene = rollqp.load_scene("cattaneo-carter").replace(**{"discretization.distance": 0.1})
    text = scene.to_toml().replace("[solver]\n", '[solver]\noperator = "matrix-free"\n')
    (tmp_path / "mf.toml").write_text(text, encoding="utf-8")
    assert cli.main(["run", str(tmp_path / "mf.toml"), "--method", "mf-newton", "--quiet",
                     "--out", str(tmp_path / "r.npz")]) == 0
    assert json.loads(str(np.load(tmp_path / "r.npz")["meta"]))["method"] == "mf-newton"
    _one_line_cli(capsys, "run", str(tmp_path / "mf.toml"), "--quiet", "--out", str(tmp_path / "r.npz"),
                  words=("solver.operator: 'matrix-free' needs a method",))


@pytest.mark.parametrize("key, value", [("a_H", 1e-300), ("a_H", 1e300), ("p0", 0.0), ("Estar", -1.0),
                                        ("prev_delta", 1e300), ("prev_xi", 1e300)])
def test_step_file_scales_are_its_scenes(step_file, tmp_path, capsys, key, value):
    """check-step divides by the step's scales: an edited one is a one-line error, without a warning
    (a_H = 1e-300 printed RuntimeWarnings first; prev_delta = 1e300 overflowed in the methods)."""
    path, arrays = step_file
    np.savez(tmp_path / "sol.npz", p=arrays["ref_p"], t=arrays["ref_t"])
    bad = _write(tmp_path / "bad.npz", dict(arrays, **{key: np.asarray(value)}))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _one_line_cli(capsys, "check-step", str(bad), str(tmp_path / "sol.npz"), words=("STEP.npz", f"'{key}'"))


def test_meta_limit_is_a_scene_files(tmp_path):
    from rollqp.result import META_LIMIT
    from rollqp.scene.io import MAX_FILE_BYTES
    assert META_LIMIT == MAX_FILE_BYTES + (1 << 20)


# --------------------------------------------------------------------------- the memory this process may use
def _fake_proc(tmp_path, cgroup, mountinfo, files):
    (tmp_path / "self").mkdir()
    (tmp_path / "self" / "cgroup").write_text(cgroup)
    (tmp_path / "self" / "mountinfo").write_text(mountinfo)
    for path, text in files.items():
        p = tmp_path / path.lstrip("/")
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text)
    return str(tmp_path)


def test_memory_limits_read_the_cgroup_v2_and_v1_limits(tmp_path):
    from rollqp.scene.checks import memory_limits
    root = tmp_path / "v2"
    root.mkdir()
    mnt = str(root / "cg")
    proc = _fake_proc(root, "0::/job/step\n", f"30 20 0:26 / {mnt} rw - cgroup2 cgroup2 rw\n",
                      {f"cg/job/step/memory.max": "max\n", f"cg/job/memory.max": "536870912\n"})
    assert memory_limits(proc)["cgroup"] == 536870912.0  # the parent's limit binds
    root = tmp_path / "v1"
    root.mkdir()
    mnt = str(root / "mem")
    proc = _fake_proc(root, "4:memory:/batch/7\n1:cpu:/\n",
                      f"35 31 0:32 / {mnt} rw - cgroup cgroup rw,memory\n",
                      {"mem/batch/7/memory.limit_in_bytes": "1073741824\n",
                       "mem/memory.limit_in_bytes": "9223372036854771712\n"})
    assert memory_limits(proc)["cgroup"] == 1073741824.0
    (tmp_path / "none").mkdir()
    assert "cgroup" not in memory_limits(_fake_proc(tmp_path / "none", "0::/\n", "", {}))


def test_a_scene_beyond_ulimit_v_is_refused_in_one_line(tmp_path):
    """Under ``ulimit -v`` (RLIMIT_AS) the check reads the address space left, not only the machine's memory:
    a one-line error naming the key before any work, not an out-of-memory traceback."""
    import resource

    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (1200 << 20, 1200 << 20))
    scene = rollqp.load_scene("cattaneo-carter").replace(**{"discretization.elements": 4000,
                                                            "solver.operator": "dense"})  # 8,001 nodes: 3 GB
    (tmp_path / "big.toml").write_text(scene.to_toml(), encoding="utf-8")
    out = subprocess.run([sys.executable, "-m", "rollqp.cli", "run", "big.toml", "--quiet"], cwd=tmp_path,
                         capture_output=True, text=True, preexec_fn=limit, timeout=120,
                         env=dict(os.environ, OPENBLAS_NUM_THREADS="1"))
    assert out.returncode == 2 and out.stderr.count("\n") == 1, out.stderr[-500:]
    assert "discretization.elements" in out.stderr and "ulimit -v (RLIMIT_AS)" in out.stderr, out.stderr
