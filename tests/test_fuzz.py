"""Fuzz: seeded mutations of scene files, step and solution files, result files and the
one-step API; and, family by family, of the keys and arguments added since: body profiles, profile
files, friction laws, load paths, wear coefficients, operators, the ``stresses`` command, ``run
--resume`` (result files and journals) and the sweep and creep-curve arguments.

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

Fast subset (CI): :data:`FAST` cases per family, 296 in all. The slow suite runs :data:`SLOW` per
family, 3,460 cases in all (``python -m pytest -q -m slow tests/test_fuzz.py``): 1,560 of the first
four families and 1,900 of the nine added (:data:`FAMILIES`).
"""
from __future__ import annotations

import contextlib
import io
import json
import math
import os
import random
import re
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
FAST = {"scene": 60, "cli": 6, "file": 60, "api": 60, "profile": 12, "profile-file": 12, "friction": 12,
        "load-path": 12, "wear": 8, "operator": 8, "stresses": 20, "resume": 10, "sweep": 16}
SLOW = {"scene": 700, "cli": 60, "file": 400, "api": 400, "profile": 250, "profile-file": 250, "friction": 250,
        "load-path": 250, "wear": 150, "operator": 150, "stresses": 250, "resume": 150, "sweep": 200}
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
    out = {name: _short(name) for name in sorted(rollqp.builtin_scenes())
           if rollqp.load_scene(name).dimension == 2}    # 3D scenes: tests/test_three_scene.py
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
    """Every float field of a result is finite (approach and creepage too: a run writes no NaN)."""
    arrays = res.arrays() if hasattr(res, "arrays") else res
    for key, f in FIELDS.items():
        if key in arrays and f.dtype == "float64" and f.shape in ("state", "step"):
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



# =========================================================================== the families added since
#: The families below: each case is a scene, files or arguments made from its seed; the property is the
#: module's (a result, or one rollqp error of one line; no warning, no NaN or infinite value written).
FAMILIES = ("profile", "profile-file", "friction", "load-path", "wear", "operator", "stresses", "resume", "sweep")
#: Values a family's keys are set to besides the module's HOSTILE ones.
MORE = [[0.0, 0.0, 0.0], [3.0, 2.0, 1.0], [1e308, -1e308], [math.nan] * 3, [0.0] * 200_001, 1e308, -1e308, 1e-12,
        "table", "material", "contact", "cosine", "exponential", "bump"]


def _hostile(rng):
    v = rng.choice(HOSTILE + MORE)
    return json.loads(json.dumps(v)) if isinstance(v, (dict, list)) and len(v) < 1000 else v


def _mutate_keys(table: dict, rng, n=None) -> list:
    """1–2 of ``table``'s keys (nested) set to hostile values, deleted or renamed; what was done."""
    done = []
    for _ in range(n or rng.randint(1, 2)):
        leaves = list(_leaves(table))
        if not leaves:
            break
        path, _ = rng.choice(leaves)
        op = rng.choice(["hostile", "hostile", "hostile", "delete", "unknown"])
        if op == "hostile":
            _set(table, path, _hostile(rng))
        elif op == "delete":
            _delete(table, path)
        else:
            _set(table, path[:-1] + (path[-1] + "x",), 1.0)
        done.append(f"{op} {'.'.join(map(str, path))}")
    return done


def _scene_family_case(seed, bases, make):
    """A scene case of a family: ``make(rng, scene dict) -> description`` changes a short built-in scene."""
    rng = random.Random(seed)
    done = make(rng)
    d, what = done
    try:
        return tomli_w.dumps(d).encode(), what
    except (TypeError, ValueError) as exc:
        return b"", f"{what} (not TOML: {type(exc).__name__})"


def _a(bases, name):
    return json.loads(json.dumps(bases[name]))


def _strip_half(d) -> float:
    """L of a scene dict (its zone in a_H, a_H from its loads)."""
    return rollqp.load_scene(d).half_width


def profile_case(seed, bases):
    """A body profile (a defect, a flat, a contact-frame or a material table) with 1–2 hostile keys."""
    def make(rng):
        d = _a(bases, "cattaneo-carter")
        L, R = _strip_half(d), d["bodies"]["A"]["radius"]
        kind = rng.choice(["defect", "flat", "contact", "material"])
        if kind == "defect":
            f = {"kind": "defect", "depth": rng.choice([3e-3, -1e-3]), "width": rng.choice([0.3, 0.8]),
                 "position": rng.uniform(-2, 2), "shape": rng.choice(["cosine", "parabolic", "flat"])}
        elif kind == "flat":
            f = {"kind": "flat", "length": rng.choice([0.2, 0.5]), "position": rng.uniform(-2, 2)}
        else:
            m = rng.choice([3, 50, 2000])
            x = np.linspace(-1.5 * L - 6, 1.5 * L + 6, m)
            h = x * x / (2 * R) if kind == "contact" else 1e-4 * np.sin(x)
            f = {"kind": "table", "frame": kind, "x": x.tolist(), "h": h.tolist()}
        d["bodies"][rng.choice(["A", "B"])]["profile"] = f if rng.random() < 0.5 else [f]
        done = _mutate_keys(f, rng) if rng.random() < 0.9 else ["valid"]
        return d, f"{kind}: {', '.join(done)}"
    return _scene_family_case(seed, bases, make)


def friction_case(seed, bases):
    """The falling-friction scene's law (or another law) with 1–2 hostile parameters."""
    def make(rng):
        d = _a(bases, "falling-friction")
        law = d["contact"]["friction"]
        if rng.random() < 0.3:
            law["law"] = rng.choice(sorted(rollqp.friction.LAWS) + ["Exponential", "", "coulomb "])
        return d, f"{law.get('law')}: {', '.join(_mutate_keys(law, rng))}"
    return _scene_family_case(seed, bases, make)


def load_path_case(seed, bases):
    """A load path (load.rolled of stop-reverse or fretting) or a load history with 1–2 hostile entries."""
    def make(rng):
        name = rng.choice(["stop-reverse", "fretting", "harmonic", "ramp"])
        d = _a(bases, name)
        table = d["load"].get("rolled") or d["load"].get("tangential") or d["load"]["normal_history"]
        if isinstance(table, dict) and rng.random() < 0.3 and isinstance(table.get("q"), list):
            table["q"] = table["q"][::-1]
            done = ["q reversed"]
        else:
            done = _mutate_keys(table, rng) if isinstance(table, dict) else ["as is"]
        return d, f"{name}: {', '.join(done)}"
    return _scene_family_case(seed, bases, make)


def wear_case(seed, bases):
    """Archard coefficients k/H of one or both bodies: valid ones, the bound 1/p0 and beyond, hostile values."""
    def make(rng):
        d = _a(bases, rng.choice(["cattaneo-carter", "ramp", "stop-reverse"]))
        p0 = rollqp.load_scene(d).p0
        done = []
        for body in rng.sample(["A", "B"], rng.randint(1, 2)):
            v = rng.choice([0.0, 1e-9, 1e-4 / p0, 1.0 / p0, 1.0001 / p0, 1e305, 1e308, -1e-9, math.nan, math.inf,
                            "1e-9", True, [1e-9]])
            d["bodies"][body]["wear"] = v
            done.append(f"{body}={v!r}")
        return d, ", ".join(done)
    return _scene_family_case(seed, bases, make)


def _family_scene_property(seed, bases, tmp_path, case_of, family):
    data, case = case_of(seed, bases)
    case = f"{family}-{seed} ({case})"
    if not data:
        return
    path = tmp_path / "fuzz.toml"
    path.write_bytes(data)
    with time_bound(CASE_SECONDS, case):
        outcome = _run_scene_file(path, case)
    assert outcome in ("refused", "valid, large", "ran", "solver error", "refused at run")


_SCENE_FAMILIES = {"profile": profile_case, "friction": friction_case, "load-path": load_path_case, "wear": wear_case}


@pytest.mark.parametrize("family, seed", [pytest.param(f, 50_000 + k, id=f"{f}-{50_000 + k}")
                                          for f in _SCENE_FAMILIES for k in range(FAST[f])])
def test_fuzzed_family_scene(family, seed, bases, tmp_path):
    _family_scene_property(seed, bases, tmp_path, _SCENE_FAMILIES[family], family)


@pytest.mark.slow
@pytest.mark.parametrize("family, seed", [pytest.param(f, 60_000 + k, id=f"{f}-{60_000 + k}")
                                          for f in _SCENE_FAMILIES for k in range(SLOW[f])])
def test_fuzzed_family_scene_slow(family, seed, bases, tmp_path):
    _family_scene_property(seed, bases, tmp_path, _SCENE_FAMILIES[family], family)


# --------------------------------------------------------------------------- profile files
def _good_profile(L, R, m=40):
    x = np.linspace(-1.5 * L - 6, 1.5 * L + 6, m)
    return x, x * x / (2 * R)


def _profile_file(rng, folder, L, R):
    """Write the file of a case (content and name drawn from ``rng``); ``(name, description)``."""
    x, h = _good_profile(L, R)
    rows = "\n".join(f"{a!r},{b!r}" for a, b in zip(x, h))
    contents = {
        "good": rows, "empty": "", "comments": "# x, h\n# nothing\n", "header": "x,h\n" + rows,
        "nan": rows + "\n1e9,nan", "huge-h": rows.replace(f"{h[3]!r}", "1e308", 1), "three": rows.replace("\n", ",1\n"),
        "one": "\n".join(map(repr, x)), "decreasing": "\n".join(f"{a!r},{b!r}" for a, b in zip(x[::-1], h)),
        "bom": "\ufeff" + rows, "semicolons": rows.replace(",", ";"), "crlf": rows.replace("\n", "\r\n"),
        "huge-x": rows.replace(f"{x[0]!r}", "-1e308", 1), "duplicate": rows + "\n" + rows.splitlines()[-1]}
    what = rng.choice(sorted(contents) + ["npz-good", "npz-nan", "npz-no-h", "npz-object", "npz-2d", "garbage"])
    name = rng.choice(["p.csv", "p.npz", "../p.csv", "/etc/passwd", "loop.csv", "a\u0000b.csv", "dir.csv", "out.csv",
                       "p.txt", "", "P.CSV", "sub/p.csv", "x" * 5000 + ".csv"])
    target = folder / "sub" / "p.csv" if name == "sub/p.csv" else folder / name.split("/")[-1] if name and "\0" not in name \
        and not name.startswith("/") and len(name) < 300 else None
    if name == "loop.csv":
        (folder / "loop.csv").symlink_to("loop.csv")
    elif name == "dir.csv":
        (folder / "dir.csv").mkdir()
    elif name == "out.csv":
        (folder / "out.csv").symlink_to("/etc/hostname")
    elif target is not None and name != "../p.csv":
        target.parent.mkdir(exist_ok=True)
        if what.startswith("npz"):
            arrays = {"x": x, "h": h}
            if what == "npz-nan":
                arrays["h"] = np.where(x > 0, np.nan, h)
            elif what == "npz-no-h":
                del arrays["h"]
            elif what == "npz-object":
                arrays["h"] = np.array([{"a": 1}], dtype=object)
            elif what == "npz-2d":
                arrays["x"] = np.stack([x, x])
            np.savez(target, **arrays) if target.suffix.lower() == ".npz" else target.write_bytes(_npz_bytes(
                {k: v for k, v in arrays.items() if v.dtype != object}))
        elif what == "garbage":
            target.write_bytes(bytes(rng.randrange(256) for _ in range(300)))
        else:
            target.write_text(contents[what], encoding="utf-8")
    return name, f"{what} as {name[:30]!r}"


def _profile_file_property(seed, bases, tmp_path, monkeypatch):
    rng = random.Random(seed)
    d = _a(bases, "cattaneo-carter")
    L, R = _strip_half(d), d["bodies"]["A"]["radius"]
    name, case = _profile_file(rng, tmp_path, L, R)
    d["bodies"]["A"]["profile"] = {"kind": "table", "file": name, "frame": rng.choice(["contact", "material"])}
    case = f"profile-file-{seed} ({case})"
    (tmp_path / "fuzz.toml").write_bytes(tomli_w.dumps(d).encode())
    monkeypatch.chdir(tmp_path)  # files are read only from the scene's folder inside the working folder
    with time_bound(CASE_SECONDS, case):
        outcome = _run_scene_file(tmp_path / "fuzz.toml", case)
    assert outcome in ("refused", "valid, large", "ran", "solver error", "refused at run")


@pytest.mark.parametrize("seed", _seeds("profile-file", 70_000))
def test_fuzzed_profile_file(seed, bases, tmp_path, monkeypatch):
    _profile_file_property(seed, bases, tmp_path, monkeypatch)


@pytest.mark.slow
@pytest.mark.parametrize("seed", _seeds("profile-file", 71_000, slow=True))
def test_fuzzed_profile_file_slow(seed, bases, tmp_path, monkeypatch):
    _profile_file_property(seed, bases, tmp_path, monkeypatch)


# --------------------------------------------------------------------------- commands, in process
def _command(argv, case, capfd, codes=(0, 2, 3)) -> tuple[int, str, str]:
    """``rollqp ARGV`` in this process: ``(exit code, stdout, stderr)``, held to the property (an error is one
    line; no warning, no traceback, no NaN or infinite number printed)."""
    from rollqp import cli
    with time_bound(CASE_SECONDS, case), warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            code = cli.main(argv)
        except SystemExit as exc:  # argparse: a bad argument
            code = exc.code
    out, err = capfd.readouterr()
    assert code in codes, f"{case}: exit {code}: {err[-300:]}"
    if code == 0:
        assert "Warning" not in err and "Traceback" not in err, f"{case}: {err[-300:]}"
        assert not re.search(r"\b(nan|inf)\b", out, re.IGNORECASE), f"{case}: printed {out[-300:]}"
    else:
        assert err.count("\n") == 1 and err.startswith("rollqp: ") and "Traceback" not in err, f"{case}: {err!r}"
    return code, out, err


def operator_case(seed, bases):
    """``solver.operator`` and ``solver.method`` in the scene and ``--method`` on the command line."""
    rng = random.Random(seed)
    d = _a(bases, rng.choice(["cattaneo-carter", "goodman-bentall"]))
    from rollqp.methods import METHOD_NAMES
    ops = ("auto", "dense", "matrix-free")
    d["solver"]["operator"] = rng.choice(ops + ("Matrix-free", "", 1, None))
    if d["solver"]["operator"] is None:
        del d["solver"]["operator"]
    if rng.random() < 0.5:
        d["solver"]["method"] = rng.choice(METHOD_NAMES + ("mf_newton", 3))
    method = rng.choice([None, "newton", "mf-newton", "qp-osqp", "qp-clarabel", "mf-Newton"])
    return d, method, f"operator {d['solver'].get('operator')!r}, method {d['solver'].get('method')!r}, --method {method}"


def _operator_property(seed, bases, tmp_path, capfd):
    d, method, case = operator_case(seed, bases)
    case = f"operator-{seed} ({case})"
    path = tmp_path / "fuzz.toml"
    path.write_bytes(tomli_w.dumps(d).encode())
    argv = ["run", str(path), "--quiet", "--no-cross-check", "--out", str(tmp_path / "r.npz")]
    code, _, _ = _command(argv + (["--method", method] if method else []), case, capfd)
    if code == 0:
        _check_result(load_result(tmp_path / "r.npz"), case)


@pytest.mark.parametrize("seed", _seeds("operator", 80_000))
def test_fuzzed_operator(seed, bases, tmp_path, capfd):
    _operator_property(seed, bases, tmp_path, capfd)


@pytest.mark.slow
@pytest.mark.parametrize("seed", _seeds("operator", 81_000, slow=True))
def test_fuzzed_operator_slow(seed, bases, tmp_path, capfd):
    _operator_property(seed, bases, tmp_path, capfd)


@pytest.fixture(scope="module")
def run_file(tmp_path_factory, bases):
    """A short run's result file (with wear), and its arrays."""
    folder = tmp_path_factory.mktemp("fuzzrun")
    d = _a(bases, "cattaneo-carter")
    d["discretization"]["distance"] *= 4
    scene = rollqp.load_scene(d).replace(**{"bodies.A.wear": 1e-9, "solver.method": "newton"})
    rollqp.run(scene, out=folder / "r.npz")
    return folder / "r.npz", dict(np.load(folder / "r.npz", allow_pickle=False)), scene


def stresses_case(seed, arrays):
    """``rollqp stresses`` arguments (step, grid, width, depth, body) and, sometimes, a result file whose
    scalars or tractions are changed."""
    rng = random.Random(seed)
    args = ["--step", str(rng.choice([0, -1, 3, 10 ** 9, -10 ** 9, "x", 1.5, True, "-0"]))]
    if rng.random() < 0.7:
        args += ["--grid", rng.choice(["20,20", "0,5", "1,1", "4001,1", "a,b", "1e3,5", "20", "-5,5", "20,20,20", "",
                                       "3," + "9" * 5000])]
    for opt in ("--width", "--depth"):
        if rng.random() < 0.5:
            args += [opt, rng.choice(["1e-300", "0", "-1", "nan", "inf", "1e308", "1.5", "0.001", "100", "1e-3", "x"])]
    if rng.random() < 0.3:
        args += ["--body", rng.choice(["A", "B", "C", ""])]
    changed = dict(arrays)
    done = []
    if rng.random() < 0.4:
        key = rng.choice(["a_H", "p0", "R", "Estar", "beta", "leading_edge", "pn", "pt", "x", "q"])
        changed[key], what = (np.asarray(rng.choice([0.0, -1.0, np.nan, 1e308, 1e-300]), dtype=float), "value") \
            if np.ndim(arrays[key]) == 0 else _mutate_array(arrays[key], rng)
        done.append(f"{what} {key}")
    return args, changed, f"{' '.join(a[:20] for a in args)}; {', '.join(done) or 'file as written'}"


def _stresses_property(seed, run_file, tmp_path, capfd):
    path, arrays, _ = run_file
    args, changed, case = stresses_case(seed, arrays)
    case = f"stresses-{seed} ({case})"
    target = tmp_path / "r.npz"
    target.write_bytes(_npz_bytes(changed))
    _command(["stresses", str(target), *args], case, capfd)


@pytest.mark.parametrize("seed", _seeds("stresses", 90_000))
def test_fuzzed_stresses(seed, run_file, tmp_path, capfd):
    _stresses_property(seed, run_file, tmp_path, capfd)


@pytest.mark.slow
@pytest.mark.parametrize("seed", _seeds("stresses", 91_000, slow=True))
def test_fuzzed_stresses_slow(seed, run_file, tmp_path, capfd):
    _stresses_property(seed, run_file, tmp_path, capfd)


def resume_case(seed, run_file, folder):
    """What ``run --resume`` continues from: the first states of a run (changed: an array, the last state
    scaled, bytes), or the journal of a run stopped at a random state (its bytes changed)."""
    rng = random.Random(seed)
    path, arrays, scene = run_file
    K1 = len(arrays["q"])
    if rng.random() < 0.3:  # a killed run's journal
        stop = rng.randrange(0, K1 - 1)

        class Stop(BaseException):
            pass

        def observe(rec, ops):
            if rec.k == stop:
                raise Stop
        with contextlib.suppress(Stop):
            rollqp.run(scene, out=folder / "r.npz", observe=observe)
        j = folder / "r.npz.journal"
        data, op = _mutate_bytes(j.read_bytes(), rng) if rng.random() < 0.6 else (j.read_bytes(), "as killed")
        j.write_bytes(data)
        return f"journal stopped at {stop}, {op}"
    k = rng.randrange(1, K1)
    part = {key: (v[:k].copy() if np.ndim(v) and len(v) == K1 and key != "x" else v) for key, v in arrays.items()}
    done = [f"{k} states"]
    op = rng.choice(["none", "array", "array", "scale", "bytes"])
    if op == "array":
        key = rng.choice(["pn", "pt", "gap", "slip", "approach", "creepage", "q", "x", "step", "meta", "state"])
        part[key], what = _mutate_array(part[key], rng)
        done.append(f"{what} {key}")
    elif op == "scale":
        key = rng.choice(["pn", "pt", "approach", "creepage"])
        part[key] = np.asarray(part[key], dtype=float).copy()
        part[key][-1] = part[key][-1] * rng.choice([2.0, -1.0, 1 + 1e-3, 0.0])
        done.append(f"last {key} scaled")
    data = _npz_bytes(part)
    if op == "bytes":
        data, what = _mutate_bytes(data, rng)
        done.append(what)
    (folder / "r.npz").write_bytes(data)
    return ", ".join(done)


def _resume_property(seed, run_file, tmp_path, capfd):
    case = f"resume-{seed} ({resume_case(seed, run_file, tmp_path)})"
    code, _, _ = _command(["run", "--resume", str(tmp_path / "r.npz"), "--quiet", "--no-cross-check"], case, capfd)
    if code == 0:
        _check_result(load_result(tmp_path / "r.npz"), case)


@pytest.mark.parametrize("seed", _seeds("resume", 100_000))
def test_fuzzed_resume(seed, run_file, tmp_path, capfd):
    _resume_property(seed, run_file, tmp_path, capfd)


@pytest.mark.slow
@pytest.mark.parametrize("seed", _seeds("resume", 101_000, slow=True))
def test_fuzzed_resume_slow(seed, run_file, tmp_path, capfd):
    _resume_property(seed, run_file, tmp_path, capfd)


def _values_text(rng) -> str:
    """A ``VALUES`` text of ``--vary``, ``--ratios`` or ``--friction``: lists and ranges, some hostile."""
    numbers = ["0.1", "0.2", "0.5", "0", "-1", "nan", "inf", "1e308", "1e-300", "x", "", " ", "9" * 4400, "1_000",
               "0x10", "1e3", "0.1", "True"]
    kind = rng.choice(["list", "list", "range", "log", "odd"])
    if kind == "list":
        return ",".join(rng.choice(numbers) for _ in range(rng.randint(1, 4)))
    count = rng.choice(["2", "3", "5", "0", "-3", "1", "10000000", "2.5", "x", "9" * 4400])
    if kind == "range":
        return f"{rng.choice(numbers)}:{rng.choice(numbers)}:{count}"
    if kind == "log":
        return f"{rng.choice(['0.01', '1e-3', '0', '-1'])}:{rng.choice(['0.5', '1', '0'])}:{count}:log"
    return rng.choice([":", "::", "1:2", "1:2:3:4:5", "a=b", "1,,2", "0.1:0.2:3:lin", "\u0000", "1" * 200])


def sweep_case(seed):
    rng = random.Random(seed)
    if rng.random() < 0.4:  # creep-curve
        return "creep", _values_text(rng) if rng.random() < 0.8 else "0.05:0.95:19", \
            (_values_text(rng) if rng.random() < 0.6 else None)
    keys = ["contact.friction", "load.tangential", "discretization.elements", "bodies.A.E", "solver.method",
            "no.such.key", "", "a..b", "x" * 300, "load.normal"]
    vary = [f"{rng.choice(keys)}={_values_text(rng)}" for _ in range(rng.randint(1, 2))]
    if rng.random() < 0.1:
        vary.append(rng.choice(["novalue", "=0.1", "contact.friction"]))
    return "sweep", vary, None


def _sweep_property(seed, bases):
    pytest.importorskip("zarr")
    from rollqp.sweep.creep import creep_sweep
    from rollqp.sweep.spec import build_sweep
    what, a, b = sweep_case(seed)
    case = f"sweep-{seed} ({what}: {str(a)[:80]!r}, {str(b)[:40]!r})"
    scene = rollqp.load_scene(_a(bases, "cattaneo-carter"))
    with time_bound(CASE_SECONDS, case), warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            if what == "creep":
                base, axes = creep_sweep(scene, a, b)
                sw = build_sweep(base, axes)
            else:
                sw = build_sweep(scene, a)
            assert sw.size >= 1, case
        except RollqpError as err:
            one_line(err, case)


@pytest.mark.parametrize("seed", _seeds("sweep", 110_000))
def test_fuzzed_sweep_arguments(seed, bases):
    _sweep_property(seed, bases)


@pytest.mark.slow
@pytest.mark.parametrize("seed", _seeds("sweep", 111_000, slow=True))
def test_fuzzed_sweep_arguments_slow(seed, bases):
    _sweep_property(seed, bases)
