"""Fuzz in 3D: seeded mutations of every key of the built-in 3D scenes (run through the Python API), and the
hostile-file set over every 3D reader — result files (``rollqp.load_result`` and ``run --resume``) and
journals (``run --resume`` from ``RESULT.npz.journal``, frames forged with their CRCs recomputed).

The property, for every case: a result that passes the physics checks (:func:`assert_physics` of
``tests/test_three_durable.py``: ∫p dA = FN, |t| <= μp to the tolerance in μp0, the element states those of
p, t, s, stick elements without slip, slip opposite the traction), or one rollqp error (``InputError`` or
``SolverError``) with a one-line message — never another exception, a traceback, a warning, or a case that
outlives :data:`CASE_SECONDS`; a forged file is refused or, where the forgery leaves a consistent state
(a key nothing reads, a value changed within the resume tolerance), its resumed result passes the same checks.
Every case is a seed: ``pytest tests/test_fuzz3d.py -k "scene3d-417"`` replays it.

Fast subset (CI): :data:`FAST` cases per family. The slow suite runs :data:`SLOW` per family, 2,100 cases in
all (``python -m pytest -q -m slow tests/test_fuzz3d.py``).
"""
from __future__ import annotations

import math
import random
import signal
import struct
import warnings
import zlib

import numpy as np
import pytest

import rollqp
from rollqp.errors import RollqpError
from rollqp.journal import HEAD_BYTES, Journal
from rollqp.methods import available_methods, capabilities
from rollqp.result import load_result, resume_source
from rollqp.scene import scene_from_dict
from rollqp.march.grid import run

from test_three_durable import assert_physics

FAST = {"scene3d": 24, "file3d": 12, "journal3d": 12}
SLOW = {"scene3d": 1400, "file3d": 400, "journal3d": 300}
#: A case must end within this many seconds (a short run on a coarse grid takes well under one; a conic method's
#: march to a dissimilar steady state up to ~40 s on 2 loaded cores).
CASE_SECONDS = 120
#: Elements × states above which a valid scene is validated, not run (its cost is the user's request).
RUN_BUDGET = 20_000
#: Contact grids above which a conic method's valid scene is validated, not run; a conic method's march to a
#: steady rolling start is validated, not run (a minute and more on a loaded machine; its runs are in
#: tests/test_three_durable.py).
CONIC_ELEMENTS = 200
#: Values that replace a key's.
HOSTILE = [None, True, False, "x", "", -1, 0, 1, 0.0, -0.0, 1e-300, 5e-324, 1e300, -1e300, math.nan, math.inf,
           -math.inf, 2 ** 63, -(2 ** 63), [], {}, [1, 2], [[1, 2], [3, 4]], "1e3", {"kind": "table"},
           {"kind": "harmonic", "mean": 1.0, "amplitude": 0.3, "wavelength": 4.0}, [math.nan, 1.0], 0.5, 3, 1e-12]
BUILTIN = ("cattaneo-3d", "kalker-circular", "kalker-elliptic", "ball-in-groove", "quartic-roller")


class _Timeout(Exception):
    pass


def _alarm(signum, frame):
    raise _Timeout()


def _short(name: str) -> dict:
    """A built-in 3D scene on a coarse grid, a few steps: the base of the mutations."""
    s = rollqp.load_scene(name)
    d = s.to_dict()
    disc = d["discretization"]
    if "elements" in disc and isinstance(disc["elements"], list):
        nx, ny = disc["elements"]
        k = 10 / min(nx, ny)
        disc["elements"] = [max(4, round(nx * k)), max(4, round(ny * k))]
    disc["distance"] = min(float(disc.get("distance", 0.3)), 0.3)
    return d


@pytest.fixture(scope="module")
def bases():
    return {name: _short(name) for name in BUILTIN}


def _leaves(d, prefix=()):
    for k, v in d.items():
        if isinstance(v, dict) and v:
            yield from _leaves(v, prefix + (k,))
        else:
            yield prefix + (k,)


def _set(d, path, value):
    for k in path[:-1]:
        d = d[k]
    d[path[-1]] = value


def _delete(d, path):
    for k in path[:-1]:
        d = d[k]
    d.pop(path[-1], None)


def _get(d, path):
    for k in path:
        d = d[k]
    return d


def scene3d_case(seed, bases) -> dict:
    """The scene dict of seed ``seed``: a built-in 3D scene with one to three mutations."""
    import copy
    rng = random.Random(seed)
    d = copy.deepcopy(bases[rng.choice(sorted(bases))])
    methods = available_methods(3)
    for _ in range(rng.choice((1, 1, 2, 3))):
        leaves = list(_leaves(d))
        path = rng.choice(leaves)
        what = rng.random()
        if what < 0.35:
            _set(d, path, rng.choice(HOSTILE))
        elif what < 0.6:
            v = _get(d, path)
            if isinstance(v, (int, float)) and not isinstance(v, bool):
                _set(d, path, v * 10 ** rng.uniform(-12, 12) * rng.choice((1, 1, -1)))
            elif isinstance(v, list) and v and all(isinstance(x, (int, float)) for x in v):
                _set(d, path, [x * 10 ** rng.uniform(-3, 3) for x in v])
            else:
                _set(d, path, rng.choice(HOSTILE))
        elif what < 0.7:
            _delete(d, path)
        elif what < 0.75:
            _set(d, path[:-1] + ("unknown_key",), 1.0)
        elif what < 0.85:
            d.setdefault("solver", {})["method"] = rng.choice(methods)
        else:  # a valid change of the loading
            ld = d.setdefault("load", {})
            choice = rng.randrange(6)
            if choice == 0:
                ld["start"] = rng.choice(("braked", "rolling"))
            elif choice == 1:
                ld["start_steps"] = rng.choice((1, 2, 3))
            elif choice == 2:
                ld["direction"] = rng.choice((1, -1))
            elif choice == 3:
                ld["tangential"] = rng.uniform(-0.99, 0.99)
            elif choice == 4:
                ld.setdefault("creepage", {})["spin"] = rng.uniform(-0.5, 0.5)
            else:
                d.setdefault("bodies", {}).setdefault("B", {})["E"] = rng.uniform(5e4, 3e5)
    return d


def _one_line(err, case):
    text = str(err)
    assert text and "\n" not in text and "Traceback" not in text, (case, text)


def _scene3d_property(seed, bases):
    case = f"scene3d-{seed}"
    d = scene3d_case(seed, bases)
    old = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(CASE_SECONDS)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            try:
                scene = scene_from_dict(d, source=case)
            except RollqpError as err:
                _one_line(err, case)
                return "refused"
            if scene.dimension != 3:
                return "2d"
            conic = scene.solver.method not in ("newton", "fastsim")
            marched = scene.load.start == "rolling" and "steady" not in capabilities(scene.solver.method, 3).solves
            if scene.grid.n * (scene.n_steps + 1) > RUN_BUDGET or (conic and (scene.contact_elements() > CONIC_ELEMENTS
                                                                             or marched)):
                return "validated"
            try:
                res = run(scene).arrays()
            except RollqpError as err:
                _one_line(err, case)
                return "failed"
            assert_physics(res, scene)
            return "ran"
    except _Timeout:
        pytest.fail(f"{case}: more than {CASE_SECONDS} s")
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def _seeds(family, offset=0, slow=False):
    n = (SLOW if slow else FAST)[family]
    return [pytest.param(offset + i, id=f"{family}-{offset + i}") for i in range(n)]


@pytest.mark.parametrize("seed", _seeds("scene3d"))
def test_fuzzed_3d_scene(seed, bases):
    _scene3d_property(seed, bases)


@pytest.mark.slow
@pytest.mark.parametrize("seed", _seeds("scene3d", 10_000, slow=True))
def test_fuzzed_3d_scene_slow(seed, bases):
    _scene3d_property(seed, bases)


# ----------------------------------------------------------------------------- hostile files
@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """A 3D run killed after state 3 (its journal's bytes) and its full result file's arrays."""
    folder = tmp_path_factory.mktemp("fuzz3d")
    scene = rollqp.load_scene("cattaneo-3d").replace(**{"discretization.elements": [10, 10],
                                                        "discretization.zone": [1.3, 1.3],
                                                        "discretization.distance": 1.0})

    class Killed(BaseException):
        pass

    def observe(rec, contact):
        if rec.k == 3:
            raise Killed
    try:
        run(scene, observe=observe, out=str(folder / "k.npz"))
    except Killed:
        pass
    journal = (folder / "k.npz.journal").read_bytes()
    run(scene, out=str(folder / "f.npz"))
    with np.load(folder / "f.npz", allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    return scene, journal, arrays, (folder / "f.npz").read_bytes()


def _mutate_array(v, rng):
    v = np.array(v)
    what = rng.randrange(12)
    if v.dtype.kind not in "fiu" or v.size == 0:
        return np.asarray(rng.choice(("x", 1.0, [1.0, 2.0])))
    if what == 0:
        return v.astype(complex)
    if what == 1:
        return v.astype(rng.choice((np.int8, np.float32, np.int64, np.bool_)))
    if what == 2:
        return v.reshape(-1)
    if what == 3:
        return v[..., :-1] if v.ndim else np.zeros(2)
    w = v.astype(float).copy()
    flat = w.reshape(-1)
    if flat.size == 0:
        return w
    i = rng.randrange(flat.size) if rng.random() < 0.6 else slice(None)
    flat[i] = {4: math.nan, 5: math.inf, 6: -1.0, 7: 0.0, 8: 1e300}.get(what, 0.0) if what < 9 else \
        flat[i] * rng.choice((2.0, -1.0, 1 + 1e-9, 1 + 1e-3, 0.0))
    return w


def file3d_case(seed, written) -> dict:
    """The arrays of seed ``seed``'s hostile 3D result file (the full result, its first states kept)."""
    rng = random.Random(seed)
    scene, _, arrays, _ = written
    K = rng.randrange(1, len(arrays["q"]) + 1)
    out = {k: (v[:K] if np.ndim(v) and k not in ("x", "y") and np.shape(v)[0] == len(arrays["q"]) else v)
           for k, v in arrays.items()}
    for _ in range(rng.choice((1, 1, 2))):
        key = rng.choice(sorted(out))
        what = rng.random()
        if what < 0.1:
            del out[key]
        elif what < 0.15:
            out["unknown"] = np.zeros(3)
        elif key == "meta":
            out["meta"] = np.asarray(rng.choice(('{"dimension": 3}', "[]", "{", '{"dimension": 7}',
                                                 str(out["meta"]).replace('"dimension": 3', '"dimension": 2'),
                                                 str(out["meta"]).replace('"keep_every": 1', '"keep_every": -4'))))
        else:
            out[key] = _mutate_array(out[key], rng)
    return out


def _file_property(seed, written, tmp_path):
    case = f"file3d-{seed}"
    scene = written[0]
    arrays = file3d_case(seed, written)
    np.savez(tmp_path / "r.npz", **arrays)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            load_result(tmp_path / "r.npz", "RESULT.npz")
        except RollqpError as err:
            _one_line(err, case)
        try:
            src = resume_source(tmp_path / "r.npz")
        except RollqpError as err:
            _one_line(err, case)
            return "refused"
        try:
            res = run(scene, resume=src, out=str(tmp_path / "o.npz")).arrays()
        except RollqpError as err:
            _one_line(err, case)
            return "refused"
        finally:
            src.close()
        assert_physics(res, scene)
        return "resumed"


@pytest.mark.parametrize("seed", _seeds("file3d"))
def test_fuzzed_3d_result_file(seed, written, tmp_path):
    _file_property(seed, written, tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("seed", _seeds("file3d", 30_000, slow=True))
def test_fuzzed_3d_result_file_slow(seed, written, tmp_path):
    _file_property(seed, written, tmp_path)


def _frames(data: bytes):
    pos, out = 8, []
    while pos + HEAD_BYTES <= len(data):
        _, kind, _, length, _, _ = struct.unpack("<2sBBQqI", data[pos:pos + 24])
        out.append((chr(kind), pos, length))
        pos += HEAD_BYTES + length
    return out


def _recrc(data: bytearray, pos: int, length: int) -> None:
    payload = bytes(data[pos + HEAD_BYTES:pos + HEAD_BYTES + length])
    head = bytearray(data[pos:pos + HEAD_BYTES - 4])
    head[20:24] = struct.pack("<I", zlib.crc32(payload))
    data[pos:pos + HEAD_BYTES - 4] = head
    data[pos + HEAD_BYTES - 4:pos + HEAD_BYTES] = struct.pack("<I", zlib.crc32(bytes(head)))


def journal3d_case(seed, written, layout) -> bytes:
    """The bytes of seed ``seed``'s hostile journal: bits flipped, cut, zeros appended, or a state frame's field
    changed with the frame's CRCs recomputed (a forgery the CRCs cannot see)."""
    rng = random.Random(seed)
    data = bytearray(written[1])
    frames = [f for f in _frames(bytes(data)) if f[0] != "H"]
    what = rng.random()
    if what < 0.2:
        for _ in range(rng.randrange(1, 4)):
            i = rng.randrange(len(data))
            data[i] ^= 1 << rng.randrange(8)
    elif what < 0.3:
        data = data[:rng.randrange(8, len(data))]
    elif what < 0.35:
        data += bytes(rng.randrange(1, 9000))
    else:
        kind, pos, length = rng.choice(frames[-2:] if rng.random() < 0.7 else frames)
        off = pos + HEAD_BYTES
        rec = np.frombuffer(bytes(data[off:off + layout.itemsize]), dtype=layout).copy()
        field = rng.choice(layout.names)
        v = np.asarray(rec[field]).astype(float)
        flat = v.reshape(-1)
        i = rng.randrange(flat.size) if rng.random() < 0.5 else slice(None)
        flat[i] = rng.choice((0.0, -1.0, 7.0, math.nan, math.inf, 1e300)) if rng.random() < 0.4 else \
            flat[i] * rng.choice((2.0, -1.0, 1 + 1e-9, 1 + 1e-4, 0.5))
        with np.errstate(all="ignore"):
            rec[field] = v.astype(rec[field].dtype) if rec[field].dtype.kind == "f" else \
                np.nan_to_num(v, nan=0, posinf=127, neginf=-127).astype(rec[field].dtype)
        data[off:off + layout.itemsize] = rec.tobytes()
        _recrc(data, pos, length)
    return bytes(data)


def _journal_property(seed, written, tmp_path):
    case = f"journal3d-{seed}"
    scene = written[0]
    (tmp_path / "k.npz.journal").write_bytes(written[1])
    j = Journal.open(tmp_path / "k.npz.journal", "journal")
    layout = j.layouts["S"]
    j.close()
    (tmp_path / "k.npz.journal").write_bytes(journal3d_case(seed, written, layout))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            src = resume_source(tmp_path / "k.npz")
        except RollqpError as err:
            _one_line(err, case)
            return "refused"
        try:
            res = run(scene, resume=src, out=str(tmp_path / "k.npz")).arrays()
        except RollqpError as err:
            _one_line(err, case)
            return "refused"
        finally:
            src.close()
        assert_physics(res, scene)
        return "resumed"


@pytest.mark.parametrize("seed", _seeds("journal3d"))
def test_fuzzed_3d_journal(seed, written, tmp_path):
    _journal_property(seed, written, tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("seed", _seeds("journal3d", 40_000, slow=True))
def test_fuzzed_3d_journal_slow(seed, written, tmp_path):
    _journal_property(seed, written, tmp_path)
