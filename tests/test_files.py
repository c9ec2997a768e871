"""Files rollqp did not write itself: step files, candidate solutions and result files are
read without trusting a byte (rollqp.npzfile). Every corruption is a one-line InputError naming
the argument and the key — never a traceback, a silent cast or a huge allocation."""
from __future__ import annotations

import io
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
