"""Fuzz: seeded mutations of scene files, step and solution files, result files and the
one-step API.

The property, for every case: a result, or one rollqp error — ``InputError`` or ``SolverError``
with a one-line message (on the command line: exit 2 or 3 and one line on stderr) — and never
another exception, a traceback, a warning, a NaN or infinite value in a result, or a case that
outlives its time bound. Every case is a seed: ``pytest tests/test_fuzz.py -k "scene-417"``
replays it, and :func:`scene_case` and friends print what the seed does.

Mutations (:data:`HOSTILE` values, scaled magnitudes, deleted or unknown keys, wrong types,
truncated or garbled TOML, deep nesting, a byte-order mark; for files: NaN, infinite, complex,
string, object, empty, reshaped and out-of-range arrays, missing and unknown keys, flipped bits,
truncated archives) are drawn by :class:`random.Random` from the seed, starting from the built-in
scenes made short (a few steps) so that a valid case also runs. A valid scene whose work is
beyond :data:`RUN_BUDGET` is validated, not run: its cost is the user's request, and what the
property asks of it is a prompt validation (bounded by :data:`VALIDATE_SECONDS`).

Fast subset (CI): :data:`FAST` cases per family. The slow suite runs :data:`SLOW` per family,
1,560 cases in all (``python -m pytest -q -m slow tests/test_fuzz.py``).
"""
from __future__ import annotations

import contextlib
import io
import json
import math
import os
import random
import signal
import subprocess
import sys
import time
import tomllib
import warnings
import zipfile

import numpy as np
import pytest

import rollqp
from rollqp.errors import InputError, RollqpError, SolverError
from rollqp.fields import FIELDS
from rollqp.result import load_result
from rollqp.stepfile import StepFile, check_step, export_step, load_solution

tomli_w = pytest.importorskip("tomli_w")

#: Cases per family: in CI (fast) and in the slow suite (scenes, CLI, step files, API).
FAST = {"scene": 60, "cli": 6, "file": 60, "api": 60}
SLOW = {"scene": 700, "cli": 60, "file": 400, "api": 400}
#: Work (nodes² × states) above which a valid scene is validated but not run: 81 nodes × 200
#: states is 1.3e6; 4e7 keeps a fuzzed run under ~2 s here.
RUN_BUDGET = 4e7
#: A case (validation, a short run or a step solve) must end within this many seconds; the runs
#: allowed by RUN_BUDGET take ≤ 2 s, validation ≤ 0.1 s, so a case near the bound is a hang.
CASE_SECONDS = 60
#: Validation alone (load_scene of any mutated file) must be prompt.
VALIDATE_SECONDS = 10

HOSTILE = [0, -1, 1, 2, 0.5, -0.5, 1e-300, -1e-300, 1e-30, 1e30, 1e300, -1e300, math.inf, -math.inf, math.nan,
           2 ** 63 - 1, -(2 ** 63), 10 ** 6, 10 ** 9, "", "x", "../x", "/etc/passwd", "a\"b'c", "quadratic",
           "newton", "harmonic", True, False, [], [1.0, 2.0], ["a"], {}, {"kind": "constant"},
           {"kind": "constant", "value": 1e300}, {"kind": "harmonic", "mean": 1.0, "amplitude": 2.0},
           {"kind": "harmonic", "mean": 1.0, "amplitude": 0.1, "wavelength": 1e-9},
           {"kind": "ramp", "start": 0.0, "end": 1e-300, "from": 0.0, "to": 1.0}, {"a": {"b": {"c": 1}}}]


# =========================================================================== the time bound
@contextlib.contextmanager
def time_bound(seconds, what):
    """Fail a case that runs longer than ``seconds`` (SIGALRM: the main thread, POSIX)."""
    def _alarm(signum, frame):
        raise TimeoutError(f"{what}: still running after {seconds} s (a hang)")
    old = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(int(seconds))
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def one_line(err: BaseException, case: str) -> str:
    msg = str(err)
    assert msg and "\n" not in msg, f"{case}: not a one-line message: {msg!r}"
    assert "Traceback" not in msg, f"{case}: {msg!r}"
    return msg


# =========================================================================== scenes
def _short(name: str) -> dict:
    """A built-in scene as plain data, made short: a few steps and one start step."""
    d = tomllib.loads(rollqp.load_scene(name).to_toml())
    d["discretization"]["distance"] = 4 * d["discretization"]["step"] * 2.0 / d["discretization"]["elements"] \
        * d["discretization"]["zone"]
    d["load"]["start_steps"] = 1
    return d


@pytest.fixture(scope="module")
def bases():
    out = {name: _short(name) for name in sorted(rollqp.builtin_scenes())}
    bem = json.loads(json.dumps(out["cattaneo-carter"]))
    bem["contact"]["model"] = "bem"
    bem["discretization"]["elements"] = 12
    out["bem"] = bem
    return out


def _leaves(d, prefix=()):
    for k, v in d.items():
        if isinstance(v, dict) and v:
            yield from _leaves(v, prefix + (k,))
        yield prefix + (k,), v


def _set(d, path, value):
    for k in path[:-1]:
        d = d[k]
    d[path[-1]] = value


def _delete(d, path):
    for k in path[:-1]:
        d = d[k]
    del d[path[-1]]


def _mutate_dict(d, rng):
    """1–3 structural mutations of a scene's data; returns what was done."""
    done = []
    for _ in range(rng.randint(1, 3)):
        leaves = list(_leaves(d))
        if not leaves:
            break
        path, value = rng.choice(leaves)
        op = rng.choice(["hostile", "hostile", "scale", "scale", "delete", "unknown", "type"])
        if op == "hostile":
            v = rng.choice(HOSTILE)
            _set(d, path, json.loads(json.dumps(v)) if isinstance(v, (dict, list)) else v)
        elif op == "scale" and isinstance(value, (int, float)) and not isinstance(value, bool):
            f = 10.0 ** rng.randint(-40, 40) * rng.choice([1, -1, 0.5, 3])
            v = value * f
            _set(d, path, int(v) if isinstance(value, int) and abs(v) < 2 ** 62 else v)
        elif op == "delete":
            _delete(d, path)
        elif op == "unknown":
            target = d
            for k in path[:-1]:
                target = target[k]
            target[rng.choice(["extra", "Friction", "elemnts", "mu", "__class__"])] = 1
        elif op == "type":
            _set(d, path, str(value) if not isinstance(value, str) else [value])
        else:
            continue
        done.append(f"{op} {'.'.join(map(str, path))}")
    return done


def _mutate_text(text, rng):
    """A text-level mutation: what a dict cannot express."""
    op = rng.choice(["truncate", "garbage", "duplicate", "bom", "deep-array", "deep-table", "bytes", "swap"])
    lines = text.splitlines()
    if op == "truncate":
        text = text[: rng.randint(0, len(text))]
    elif op == "garbage":
        lines.insert(rng.randint(0, len(lines)), rng.choice(["=", "[[", "x = ", "[a.b", "\x00", "a = 1 = 2", "]]]"]))
        text = "\n".join(lines)
    elif op == "duplicate" and lines:
        k = rng.randrange(len(lines))
        lines.insert(k, lines[k])
        text = "\n".join(lines)
    elif op == "bom":
        text = "\ufeff" + text
    elif op == "deep-array":
        n = rng.choice([10, 300, 3000, 30000])
        text += "\nextra = " + "[" * n + "]" * n + "\n"
    elif op == "deep-table":
        n = rng.choice([10, 300, 3000])
        text += "\nextra = " + "{a = " * n + "1" + "}" * n + "\n"
    elif op == "bytes":
        b = bytearray(text.encode())
        for _ in range(rng.randint(1, 8)):
            b[rng.randrange(len(b))] = rng.randrange(256)
        return bytes(b), op
    elif op == "swap" and len(lines) > 2:
        i, j = rng.sample(range(len(lines)), 2)
        lines[i], lines[j] = lines[j], lines[i]
        text = "\n".join(lines)
    return text.encode("utf-8", "surrogatepass"), op


def scene_case(seed, bases):
    """The scene file of case ``seed``: (bytes, description)."""
    rng = random.Random(seed)
    name = rng.choice(sorted(bases))
    d = json.loads(json.dumps(bases[name]))
    done = _mutate_dict(d, rng)
    try:
        text = tomli_w.dumps(d)
    except (TypeError, ValueError) as exc:  # a value TOML cannot hold: keep the unmutated text
        text, done = tomli_w.dumps(bases[name]), done + [f"(not TOML: {type(exc).__name__})"]
    if rng.random() < 0.25:
        data, op = _mutate_text(text, rng)
        done.append(op)
    else:
        data = text.encode()
    return data, f"{name}: {', '.join(done)}"


def _check_result(res, case):
    arrays = res.arrays() if hasattr(res, "arrays") else res
    for key in ("pn", "pt", "slip", "creepage", "P", "Q", "residual"):
        v = np.asarray(arrays[key], dtype=float)
        assert np.all(np.isfinite(v)), f"{case}: non-finite {key}"


def _run_scene_file(path, case):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a warning is a failure of the property
        t0 = time.perf_counter()
        try:
            scene = rollqp.load_scene(str(path))
        except RollqpError as err:
            one_line(err, case)
            return "refused"
        assert time.perf_counter() - t0 <= VALIDATE_SECONDS, f"{case}: validation took too long"
        work = scene.n_nodes ** 2 * (scene.n_steps + scene.load.start_steps + 1)
        if work > RUN_BUDGET:
            return "valid, large"
        try:
            res = rollqp.run(scene, method=scene.solver.method)
        except SolverError as err:
            one_line(err, case)
            return "solver error"
        except InputError as err:  # e.g. a method that cannot solve this scene, said up front
            one_line(err, case)
            return "refused at run"
        _check_result(res, case)
        return "ran"


def _seeds(family, offset=0, slow=False):
    """The seeds of a family's cases (FAST or SLOW count), each with its id ``family-seed``."""
    n = (SLOW if slow else FAST)[family]
    return [pytest.param(offset + k, id=f"{family}-{offset + k}") for k in range(n)]


@pytest.mark.parametrize("seed", _seeds("scene"))
def test_fuzzed_scene(seed, bases, tmp_path):
    _scene_property(seed, bases, tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("seed", _seeds("scene", 10_000, slow=True))
def test_fuzzed_scene_slow(seed, bases, tmp_path):
    _scene_property(seed, bases, tmp_path)


def _scene_property(seed, bases, tmp_path):
    data, case = scene_case(seed, bases)
    path = tmp_path / "fuzz.toml"
    path.write_bytes(data)
    case = f"scene-{seed} ({case})"
    with time_bound(CASE_SECONDS, case):
        outcome = _run_scene_file(path, case)
    assert outcome in ("refused", "valid, large", "ran", "solver error", "refused at run")


def test_fuzzed_scenes_reach_every_outcome(bases, tmp_path):
    """The mutations are neither all refused nor all harmless: over the fast seeds, both
    refused and valid-and-run scenes occur (else the fuzzer tests nothing)."""
    seen = set()
    for seed in range(FAST["scene"]):
        data, case = scene_case(seed, bases)
        path = tmp_path / f"f{seed}.toml"
        path.write_bytes(data)
        with time_bound(CASE_SECONDS, case):
            seen.add(_run_scene_file(path, case))
    assert {"refused", "ran"} <= seen, seen


# =========================================================================== the command line
def _cli_property(seed, bases, tmp_path):
    data, case = scene_case(seed, bases)
    path = tmp_path / "fuzz.toml"
    path.write_bytes(data)
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", MPLBACKEND="Agg", ROLLQP_PROGRESS_SECONDS="1e9")
    scene = None
    with contextlib.suppress(RollqpError), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = rollqp.load_scene(str(path))
    if scene is not None and scene.n_nodes ** 2 * (scene.n_steps + scene.load.start_steps + 1) > RUN_BUDGET:
        pytest.skip("valid and large: the in-process cases check its validation")
    out = subprocess.run([sys.executable, "-m", "rollqp.cli", "run", str(path), "--no-cross-check", "--quiet",
                          "--out", str(tmp_path / "r.npz")], capture_output=True, text=True, cwd=tmp_path,
                         env=env, timeout=CASE_SECONDS)
    case = f"cli-{seed} ({case})"
    assert out.returncode in (0, 2, 3), f"{case}: exit {out.returncode}: {out.stderr[-500:]}"
    assert "Traceback" not in out.stderr and "Warning" not in out.stderr, f"{case}: {out.stderr[-500:]}"
    if out.returncode == 0:
        assert out.stderr == "", f"{case}: {out.stderr!r}"
        _check_result(load_result(tmp_path / "r.npz"), case)
    else:
        assert out.stderr.count("\n") == 1 and out.stderr.startswith("rollqp: "), f"{case}: {out.stderr!r}"


@pytest.mark.integration
@pytest.mark.parametrize("seed", _seeds("cli"))
def test_fuzzed_cli(seed, bases, tmp_path):
    _cli_property(seed, bases, tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("seed", _seeds("cli", 20_000, slow=True))
def test_fuzzed_cli_slow(seed, bases, tmp_path):
    _cli_property(seed, bases, tmp_path)


# =========================================================================== step, solution and result files
@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("fuzzfiles")
    step = folder / "step.npz"
    export_step("cattaneo-carter", 3).save(step, native=False)
    arrays = dict(np.load(step, allow_pickle=False))
    solution = {"p": arrays["ref_p"], "t": arrays["ref_t"]}
    result = rollqp.run(rollqp.load_scene("cattaneo-carter").replace(**{"discretization.distance": 0.1}),
                        method="newton").arrays()
    return arrays, solution, result


def _mutate_array(v, rng):
    v = np.asarray(v)
    op = rng.choice(["nan", "inf", "complex", "string", "empty", "reshape", "huge", "negative", "scalar",
                     "bool", "int", "transpose", "long"])
    if op in ("nan", "inf", "huge", "negative") and v.size and v.dtype.kind in "fiu":
        w = v.astype(float).copy()
        w.flat[rng.randrange(w.size)] = {"nan": np.nan, "inf": -np.inf, "huge": 1e308, "negative": -1.0}[op]
        return w, op
    if op == "complex" and v.dtype.kind in "fiu":
        return v.astype(complex) + 1j, op
    if op == "string":
        return np.array(["x"] * max(v.size, 1)), op
    if op == "empty":
        return np.zeros((0,)), op
    if op == "reshape" and v.size > 1:
        return v.reshape(-1)[:-1], op
    if op == "scalar":
        return np.array(rng.choice([0.0, -1.0, np.nan, 1e300])), op
    if op == "bool":
        return np.ones(v.shape, dtype=bool), op
    if op == "int" and v.dtype.kind == "f" and np.all(np.isfinite(v)):
        return v.astype(np.int64), op
    if op == "transpose" and v.ndim == 1:
        return v[:, None], op
    if op == "long":
        return np.concatenate([np.ravel(v), np.ravel(v)]) if v.dtype.kind != "U" else v, op
    return v, "unchanged"


def _mutate_arrays(arrays, rng):
    a = dict(arrays)
    done = []
    for _ in range(rng.randint(1, 3)):
        op = rng.choice(["array", "array", "array", "drop", "add"])
        key = rng.choice(sorted(a)) if a else None
        if op == "array" and key is not None:
            a[key], what = _mutate_array(a[key], rng)
            done.append(f"{what} {key}")
        elif op == "drop" and key is not None:
            del a[key]
            done.append(f"drop {key}")
        else:
            a[rng.choice(["extra", "p2", "__proto__"])] = np.zeros(3)
            done.append("add key")
    return a, done


def _mutate_bytes(data: bytes, rng):
    b = bytearray(data)
    op = rng.choice(["flip", "truncate", "append", "zero"])
    if op == "flip":
        for _ in range(rng.randint(1, 16)):
            k = rng.randrange(len(b))
            b[k] ^= 1 << rng.randrange(8)
    elif op == "truncate":
        b = b[: rng.randrange(len(b))]
    elif op == "append":
        b += bytes(rng.randrange(256) for _ in range(64))
    else:
        k = rng.randrange(len(b))
        b[k:k + 256] = bytes(min(256, len(b) - k))
    return bytes(b), op


def _npz_bytes(arrays) -> bytes:
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    return buf.getvalue()


def file_case(seed, files):
    """The files of case ``seed``: (which, step bytes, solution bytes, result bytes, description)."""
    rng = random.Random(seed)
    step, solution, result = files
    which = rng.choice(["step", "solution", "result"])
    src = {"step": step, "solution": solution, "result": result}[which]
    mutated, done = _mutate_arrays(src, rng)
    data = _npz_bytes(mutated)
    if rng.random() < 0.3:
        data, op = _mutate_bytes(data, rng)
        done.append(op)
    if rng.random() < 0.05:  # an object array: np.load without pickles must refuse it, as ours does
        obj = dict(mutated)
        obj["p" if which == "solution" else "kind"] = np.array([{"x": 1}], dtype=object)
        buf = io.BytesIO()
        np.savez(buf, **obj)
        data, done = buf.getvalue(), done + ["object array"]
    return which, data, f"{which}: {', '.join(done)}"


def _file_property(seed, files, tmp_path):
    which, data, case = file_case(seed, files)
    case = f"file-{seed} ({case})"
    step_arrays, solution, _ = files
    path = tmp_path / f"{which}.npz"
    path.write_bytes(data)
    good_step = tmp_path / "good-step.npz"
    good_step.write_bytes(_npz_bytes(step_arrays))
    with time_bound(CASE_SECONDS, case), warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            if which == "result":
                res = load_result(path)  # checks shapes, kinds and finiteness of every field it knows
                missing = [k for k, f in FIELDS.items() if f.contract and k not in res]
                assert not missing, f"{case}: accepted without {missing}"
            elif which == "step":
                step = StepFile.load(path)
                report = check_step(step, {"p": solution["p"], "t": solution["t"]})
                assert report is not None
            else:
                sol = load_solution(path, len(solution["p"]))
                report = check_step(StepFile.load(good_step), sol)
                assert report is not None
        except RollqpError as err:
            one_line(err, case)


@pytest.mark.parametrize("seed", _seeds("file"))
def test_fuzzed_file(seed, files, tmp_path):
    _file_property(seed, files, tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("seed", _seeds("file", 30_000, slow=True))
def test_fuzzed_file_slow(seed, files, tmp_path):
    _file_property(seed, files, tmp_path)


# =========================================================================== the one-step API
N = 9
_X = np.linspace(-1.0, 1.0, N)
#: A valid normal and tangential step: a symmetric positive definite log-kernel-like matrix.
_A = np.eye(N) + 0.3 * np.exp(-np.abs(_X[:, None] - _X[None, :]))
NORMAL = dict(A=_A, f=np.full(N, 2.0 / N), h=0.2 * _X ** 2, P=1.0)
TANGENTIAL = dict(A=_A, f=np.full(N, 2.0 / N), p=np.maximum(1 - _X ** 2, 0.0), mu=0.3, c=np.zeros(N),
                  dq=0.1, xi=None)
API_VALUES = [None, 0, -1.0, np.nan, np.inf, 1e300, -1e300, 1e-300, "x", [1.0], [], True, 1j, np.zeros(0),
              np.zeros((N, N)), np.full(N, np.nan), np.ones(N + 1), -np.eye(N), np.ones((N, N)), np.ones(N) * 1e300,
              np.ones(N, dtype=complex), np.array(["a"] * N), np.triu(np.ones((N, N))) + np.eye(N), {"a": 1}]


def api_case(seed):
    rng = random.Random(seed)
    kind = rng.choice(["normal", "tangential"])
    args = dict(NORMAL if kind == "normal" else TANGENTIAL)
    done = []
    for _ in range(rng.randint(1, 2)):
        key = rng.choice(sorted(args))
        args[key] = rng.choice(API_VALUES)
        done.append(key)
    method = rng.choice(["newton", "qp-osqp", "qp-clarabel"])
    return kind, args, method, f"{kind} {method}: {', '.join(done)}"


def _api_property(seed, capfd):
    kind, args, method, case = api_case(seed)
    case = f"api-{seed} ({case})"
    with time_bound(CASE_SECONDS, case), warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            pb = rollqp.NormalStep(**args) if kind == "normal" else rollqp.TangentialStep(**args)
            sol = rollqp.solve_step(pb, method)
            values = [sol.p] if kind == "normal" else [sol.t]
            assert all(np.all(np.isfinite(np.asarray(v, dtype=float))) for v in values), f"{case}: NaN in the solution"
            assert np.isfinite(sol.residual), case
        except RollqpError as err:
            one_line(err, case)
    out = capfd.readouterr()
    assert out.out == "" and out.err == "", f"{case}: printed {out}"


@pytest.mark.parametrize("seed", _seeds("api"))
def test_fuzzed_api(seed, capfd):
    _api_property(seed, capfd)


@pytest.mark.slow
@pytest.mark.parametrize("seed", _seeds("api", 40_000, slow=True))
def test_fuzzed_api_slow(seed, capfd):
    _api_property(seed, capfd)

