"""Nothing lost, nothing trusted — in 3D as in 2D: the 3D run goes through the one result and the one run/resume
path (rollqp.result, rollqp.march.drive), so its states are streamed to the journal, a resumed run re-solves
and checks its last state, and what a file says is range-checked (docs/results.md). Each test here was a
failure of an earlier rollqp (a crash, a forged state resumed, a traceback, a lost Ctrl-C, a resumed run
that differed in its last bits, memory that grew with the run). Coarse grids: each run takes well under a
second with Newton."""
from __future__ import annotations

import json
import os
import signal
import struct
import subprocess
import sys
import time
import tracemalloc
import warnings
import zipfile
import zlib

import numpy as np
import pytest

import rollqp
from rollqp import cli
from rollqp.cli import reporting
from rollqp.errors import InputError
from rollqp.journal import HEAD_BYTES, Journal
from rollqp.result import load_result, resume_source
from rollqp.march.grid import run


def coarse(name: str, **changes):
    """A built-in 3D scene on a coarse grid (12 × 12 elements across a circle)."""
    s = rollqp.load_scene(name)
    nx, ny = s.discretization.elements
    k = 12 / min(nx, ny)
    base = {"discretization.elements": [round(nx * k), round(ny * k)], "discretization.zone": [1.3, 1.3],
            "name": f"{name}-coarse", "discretization.distance": 1.0}
    return s.replace(**{**base, **changes})


class _Killed(BaseException):
    """Stands for SIGKILL: nothing of the run's own handling runs after it."""


def _killed_at(scene, out, k, method=None):
    """Run ``scene`` to ``out`` and kill it (nothing handled) right after state ``k`` is journaled."""
    def observe(rec, contact):
        if rec.k == k:
            raise _Killed
    with pytest.raises(_Killed):
        run(scene, method, observe=observe, out=str(out))


def _resume(scene, path, out=None, method=None, **kw):
    """``run`` resumed from the result file or journal ``path`` (a :class:`~rollqp.result.ResumeSource`, as
    ``rollqp run --resume`` hands it), written to ``out`` (default: ``path``)."""
    src = resume_source(path)
    try:
        return run(scene, method, resume=src, out=str(out or path), **kw)
    finally:
        src.close()


def _bit_for_bit(res, full):
    """Every array but the wall times and ``meta`` equal, bit for bit."""
    for key, value in full.items():
        if key in ("meta", "step_time") or np.asarray(value).dtype.kind not in "fiub":
            continue
        assert np.array_equal(np.asarray(res[key]), np.asarray(value), equal_nan=True), key


# ----------------------------------------------------------------------------- a documented key crashed
def test_a_braked_start_in_several_shift_steps_runs_and_is_state_0():
    scene = coarse("cattaneo-3d", **{"load.start_steps": 2})
    res = run(scene).arrays()
    assert res["q"].size == scene.n_steps + 1 and res["step"][0] == 0
    one = run(coarse("cattaneo-3d")).arrays()              # the same load in one shift step: the same state 0
    assert abs(res["Fx"][0] - one["Fx"][0]) <= 1e-9 * scene.mu * scene.load.normal   # Fx is prescribed


# ----------------------------------------------------------------------------- a resume trusts nothing
@pytest.fixture(scope="module")
def part(tmp_path_factory):
    """A braked 3D run, its full arrays, and a result file of its first 4 states (as an interruption writes)."""
    folder = tmp_path_factory.mktemp("part")
    scene = coarse("cattaneo-3d", **{"discretization.distance": 1.5})
    full = run(scene).arrays()
    _killed_at(scene, folder / "k.npz", 3)
    journal_bytes = (folder / "k.npz.journal").read_bytes()
    arrays = {k: (v[:4] if np.ndim(v) and k not in ("x", "y") else v) for k, v in full.items()}
    return scene, full, arrays, journal_bytes


def _stop_at(k):
    def observe(rec, contact):
        if rec.k == k:
            raise KeyboardInterrupt
    return observe


def _forge(arrays, key, how):
    out = dict(arrays)
    v = np.array(out[key])
    out[key] = how(v)
    return out


def _last(f):
    """A change to the last state of a per-state array."""
    def how(v):
        v = v.copy()
        v[-1] = f(v[-1])
        return v
    return how


FORGED_FILES = {
    "pressure doubled": ("pn", _last(lambda r: 2 * r)),
    "tractions zeroed": ("px", _last(lambda r: 0 * r)),
    "pressure negative": ("pn", _last(lambda r: -r)),
    "state 7": ("state", _last(lambda r: np.full_like(r, 7))),
    "pn as int8": ("pn", lambda v: v.astype(np.int8)),
    "a <= 0": ("a", lambda v: np.asarray(0.0)),
    "p0 <= 0": ("p0", lambda v: np.asarray(-1.0)),
    "E* < 0": ("Estar", lambda v: np.asarray(-v)),
    "y shifted": ("y", lambda v: v + 0.5 * (v[1] - v[0])),
    "q reversed": ("q", lambda v: v[::-1].copy()),
    "FN = 0": ("FN", _last(lambda r: 0.0 * r)),
}


@pytest.mark.parametrize("case", sorted(FORGED_FILES))
def test_a_forged_result_file_is_refused_on_resume_in_one_line(part, tmp_path, case):
    scene, full, arrays, _ = part
    key, how = FORGED_FILES[case]
    np.savez(tmp_path / "f.npz", **_forge(arrays, key, how))
    with pytest.raises(InputError) as err:
        _resume(scene, tmp_path / "f.npz")
    assert str(err.value).startswith("--resume") and "\n" not in str(err.value), str(err.value)
    with np.load(tmp_path / "f.npz") as z:               # nothing written over it
        assert np.array_equal(z[key], _forge(arrays, key, how)[key])


def test_two_members_of_one_name_are_a_corrupt_file(part, tmp_path):
    scene, full, arrays, _ = part
    np.savez(tmp_path / "f.npz", **arrays)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")                  # zipfile warns of the duplicate name it writes
        with zipfile.ZipFile(tmp_path / "f.npz", "a") as z:
            with z.open("pn.npy", "w") as fh:
                np.lib.format.write_array(fh, np.full_like(arrays["pn"], 1e300))
    with pytest.raises(InputError, match="twice"):
        load_result(tmp_path / "f.npz", "--resume")


def _frames(data: bytes):
    """``(offset of the payload, length)`` of each state frame of a journal's bytes."""
    pos, out = 8, []
    while pos + HEAD_BYTES <= len(data):
        _, kind, _, length, _, _ = struct.unpack("<2sBBQqI", data[pos:pos + 24])
        if chr(kind) != "H":
            out.append((pos + HEAD_BYTES, length))
        pos += HEAD_BYTES + length
    return out


def _forge_journal(data: bytes, layout, field, how, frame=-1) -> bytes:
    """The journal with ``field`` of one state frame changed and both CRCs of the frame recomputed."""
    data = bytearray(data)
    off, length = _frames(bytes(data))[frame]
    dt = layout
    rec = np.frombuffer(bytes(data[off:off + dt.itemsize]), dtype=dt).copy()
    rec[field] = how(rec[field])
    data[off:off + dt.itemsize] = rec.tobytes()
    payload = bytes(data[off:off + length])
    head = bytearray(data[off - HEAD_BYTES:off - 4])
    head[20:24] = struct.pack("<I", zlib.crc32(payload))
    data[off - HEAD_BYTES:off - 4] = head
    data[off - 4:off] = struct.pack("<I", zlib.crc32(bytes(head)))
    return bytes(data)


FORGED_JOURNALS = {
    "pressure doubled": ("pn", lambda r: 2 * r),
    "tractions zeroed": ("px", lambda r: 0 * r),
    "pressure negative": ("pn", lambda r: -r),
    "state 7": ("state", lambda r: np.full_like(r, 7)),
    "FN = 0": ("FN", lambda r: 0 * r),
    "slip doubled": ("sx", lambda r: 2 * r),
}


@pytest.mark.parametrize("case", sorted(FORGED_JOURNALS))
def test_a_forged_journal_with_its_crcs_recomputed_is_refused(part, tmp_path, case):
    scene, full, arrays, data = part
    j_path = tmp_path / "k.npz.journal"
    j_path.write_bytes(data)
    j = Journal.open(j_path, "journal")
    layout = j.layouts["S"]
    j.close()
    field, how = FORGED_JOURNALS[case]
    j_path.write_bytes(_forge_journal(data, layout, field, how))
    with pytest.raises(InputError) as err:
        _resume(scene, tmp_path / "k.npz")
    assert str(err.value).startswith("--resume") and "the file was changed or is corrupt" in str(err.value), \
        str(err.value)
    assert not (tmp_path / "k.npz").exists()


def test_the_unforged_journal_resumes_bit_for_bit(part, tmp_path):
    scene, full, arrays, data = part
    (tmp_path / "k.npz.journal").write_bytes(data)
    res = _resume(scene, tmp_path / "k.npz").arrays()
    _bit_for_bit(res, full)


def test_a_result_file_of_another_grid_is_one_line(part, tmp_path):
    scene, full, arrays, _ = part
    np.savez(tmp_path / "f.npz", **arrays)
    other = scene.replace(**{"discretization.elements": [16, 16]})
    with pytest.raises(InputError, match=r"^--resume: the result file's grid \(12 x 12 elements\) is not this scene's"):
        _resume(other, tmp_path / "f.npz", tmp_path / "o.npz")


# ----------------------------------------------------------------------------- long lists in meta
def test_a_3d_load_table_of_more_than_64_points_is_restored_and_resumed(tmp_path):
    q = np.linspace(0.0, 2.0, 101)
    table = {"kind": "table", "q": q.tolist(), "value": (0.3 + 0.2 * np.sin(q)).tolist()}
    scene = coarse("cattaneo-3d", **{"load.tangential": table})
    full = run(scene).arrays()
    _killed_at(scene, tmp_path / "r.npz", 2)
    with pytest.raises(KeyboardInterrupt):               # an interruption writes the file (not the journal)
        _resume(scene, tmp_path / "r.npz", observe=_stop_at(3))
    assert not (tmp_path / "r.npz.journal").exists()
    back = load_result(tmp_path / "r.npz")
    assert back["meta"]["scene"]["load"]["tangential"]["q"] == q.tolist()   # the list, not a placeholder
    assert cli.main(["run", "--resume", str(tmp_path / "r.npz"), "--quiet"]) == 0
    _bit_for_bit(load_result(tmp_path / "r.npz"), full)


# ----------------------------------------------------------------------------- bit for bit from a journal
#: The starts: braked (static shift) and rolling (steady state: solved directly by Newton, marched by the conic
#: methods), for similar bodies and dissimilar ones (every step the normal-tangential alternation).
STARTS = {"braked": ("cattaneo-3d", {}), "rolling": ("kalker-circular", {}),
          "braked dissimilar": ("cattaneo-3d", {"bodies.B.E": 70000.0, "bodies.B.nu": 0.33}),
          "rolling dissimilar": ("kalker-circular", {"bodies.B.E": 70000.0, "bodies.B.nu": 0.33})}


def _cases():
    """Newton on every start in the fast suite; the conic methods on the similar bodies' starts, and on the
    dissimilar ones in the slow suite (the march to a dissimilar steady state takes 10-80 s on 2 cores). Every
    3D method that marches is here: ``fastsim`` solves one steady state (nothing to resume) and ``qp-osqp``
    is refused on a 3D scene."""
    for start in sorted(STARTS):
        for method in ("newton", "socp-clarabel", "socp-cvxpy", "socp-scs", "qp-clarabel", "qp-cvxpy"):
            for k in (0, 3):
                slow = method != "newton" and ("dissimilar" in start or method != "socp-clarabel")
                yield pytest.param(start, method, k, marks=[pytest.mark.slow] if slow else [])


@pytest.mark.parametrize("start, method, k", list(_cases()))
def test_a_journal_resume_is_the_uninterrupted_run_bit_for_bit(tmp_path, start, method, k):
    """Killed right after state k (0: the start) and resumed from the journal: the last state solved again and
    the next steps set out as in a run that never stopped (the first rolling step from nothing, every later one
    from the state before; a conic solver object scaled from its matrices alone), so every array but the wall
    times is the uninterrupted run's, bit for bit."""
    if method in ("socp-cvxpy", "socp-scs", "qp-cvxpy"):
        pytest.importorskip("cvxpy")
    name, changes = STARTS[start]
    scene = coarse(name, **changes)
    full = run(scene, method).arrays()
    _killed_at(scene, tmp_path / "r.npz", k, method)
    res = _resume(scene, tmp_path / "r.npz", method=method).arrays()
    _bit_for_bit(res, full)
    assert json.loads(str(res["meta"]))["resumed_from"] == k


# ----------------------------------------------------------------------------- memory
def test_a_3d_run_with_a_result_file_holds_no_state_in_memory(tmp_path):
    """Python's allocations held during a run with a result file, after state 20 and after state 220: the 200
    states in between (200 × 12 × 12 × 41 bytes = 1.2 MB) must not be among them. (The file is written from
    the journal a block of rows at a time, ``BLOCK_BYTES``, and read back memory-mapped above ``MAP_ABOVE``:
    bounded, whatever the length; ``benchmarks/run_memory_3d.py`` measures the whole process.)"""
    base = coarse("cattaneo-3d")
    scene = base.replace(**{"discretization.distance": 220 * base.dq / base.ellipse.a})
    assert scene.n_steps == 220
    held = {}

    def observe(rec, contact):
        if rec.k in (20, scene.n_steps):
            held[rec.k] = tracemalloc.get_traced_memory()[0]
    tracemalloc.start()
    try:
        run(scene, observe=observe, out=str(tmp_path / "r.npz"))
    finally:
        tracemalloc.stop()
    states = 200 * scene.grid.n * 41
    assert held[220] - held[20] < 0.25 * states, (held, states)


# ----------------------------------------------------------------------------- signals
def _default_sigint():
    signal.signal(signal.SIGINT, signal.SIG_DFL)


@pytest.mark.integration
@pytest.mark.parametrize("gap_ms", [5, 20])
def test_a_second_ctrl_c_keeps_every_completed_3d_state(tmp_path, gap_ms):
    """Ctrl-C twice, the second 5–20 ms after the first: exit 130, one line naming the completed states, the file
    holding them and no journal left beside it (the second signal is ignored while the first one's states are
    written)."""
    # long enough to be running when the signals come on a quiet machine (about 1 ms a step on 12 x 12: 1,850
    # steps), the first progress line after 0.05 s of stepping
    scene = coarse("cattaneo-3d", **{"discretization.distance": 400.0})
    (tmp_path / "scene.toml").write_text(scene.to_toml(), encoding="utf-8")
    proc = subprocess.Popen([sys.executable, "-m", "rollqp.cli", "run", "scene.toml", "--out", "r.npz"], cwd=tmp_path,
                            stderr=subprocess.PIPE, stdout=subprocess.PIPE, text=True, preexec_fn=_default_sigint,
                            env=dict(os.environ, OPENBLAS_NUM_THREADS="1", ROLLQP_PROGRESS_SECONDS="0.05"))
    line = proc.stderr.readline()
    while line and not line.startswith("rollqp: step "):
        line = proc.stderr.readline()
    assert line.startswith("rollqp: step "), line
    proc.send_signal(signal.SIGINT)
    time.sleep(gap_ms / 1000)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    lines = [x for x in err.splitlines() if not x.startswith("rollqp: step ")]
    assert proc.returncode == 130 and "completed states are in r.npz" in lines[-1], err
    part = load_result(tmp_path / "r.npz")
    assert part["q"].size > 1 and part["meta"]["interrupted"]
    assert not (tmp_path / "r.npz.journal").exists() and not (tmp_path / "r.npz.lock").exists()


# ----------------------------------------------------------------------------- smaller ones
def test_an_output_name_too_long_for_its_lock_or_journal_is_refused_before_the_run(tmp_path):
    from rollqp.result import check_output
    name = "r" * 247 + ".npz"                              # 251 characters: the file fits, its journal does not
    with pytest.raises(InputError, match=r"^--out: .*too long"):
        check_output(tmp_path / name)


def test_an_output_path_with_a_nul_byte_is_one_line():
    with pytest.raises(InputError, match="^out: "):
        rollqp.run(coarse("cattaneo-3d"), out="r\x00.npz")


def test_a_journal_with_only_its_header_says_so(part, tmp_path):
    scene, full, arrays, data = part
    first = _frames(data)[0][0] - HEAD_BYTES
    (tmp_path / "k.npz.journal").write_bytes(data[:first])
    with pytest.raises(InputError, match="holds no completed state"):
        resume_source(tmp_path / "k.npz")


def test_a_complete_last_frame_that_fails_its_crc_is_corrupt_not_torn(part, tmp_path):
    scene, full, arrays, data = part
    off, length = _frames(data)[-1]
    bad = bytearray(data)
    bad[off + 10] ^= 0xFF                                  # a complete frame, one byte changed: not a torn write
    (tmp_path / "k.npz.journal").write_bytes(bytes(bad))
    with pytest.raises(InputError, match="fails its CRC"):
        resume_source(tmp_path / "k.npz")
    torn = bytearray(data)
    end = off + length
    start = max(off, (end - 1) // 4096 * 4096)             # its last page never reached the disk: torn, dropped
    torn[start:end] = bytes(end - start)
    (tmp_path / "k.npz.journal").write_bytes(bytes(torn))
    src = resume_source(tmp_path / "k.npz")
    assert len(src.journal) == len(_frames(data)) - 1
    src.close()


# ----------------------------------------------------------------------------- physics at extreme inputs
def physics_violations(res, scene) -> dict:
    """The physics checks of a 3D result, each as a number to hold below its tolerance: the stored normal force
    against ∫p dA (relative to FN), the tractions beyond the friction disc (in mu p0; in p0 when mu = 0), the
    stored element states against those of the stored p, t, s (the number that differ), stick elements' slip
    (in mu p0/E*) and slipping elements' slip not opposite their traction (the largest
    |t/|t| + s/|s|| where both are resolved)."""
    from rollqp.problem.grid import Scales, element_states
    a = res
    K1 = len(a["q"])
    area = float((a["x"][1] - a["x"][0]) * (a["y"][1] - a["y"][0])) if a["x"].size > 1 and a["y"].size > 1 else \
        scene.grid.area
    p0, Estar, mu = float(a["p0"]), float(a["Estar"]), scene.mu
    FN = area * a["pn"].reshape(K1, -1).sum(1)
    out = {"FN": float(np.max(np.abs(FN - a["FN"]))) / scene.load.normal}
    tn, bound = np.hypot(a["px"], a["py"]), mu * np.maximum(a["pn"], 0.0)
    out["disc"] = float(np.max(tn - bound)) / (mu * p0 if mu > 0 else p0)
    unit = mu * p0 if mu > 0 else p0                   # (the states do not depend on the unit: |t - E* s| > b)
    sc = Scales(float(np.sqrt(a["a"] * a["b"])), unit, Estar)
    states = np.stack([element_states(np.stack([a["px"][i].ravel(), a["py"][i].ravel()]),
                                      np.stack([a["sx"][i].ravel(), a["sy"][i].ravel()]),
                                      bound[i].ravel(), sc) for i in range(K1)])
    out["states"] = int(np.sum(states != a["state"].reshape(K1, -1)))
    sn = np.hypot(a["sx"], a["sy"])
    stick, slip = a["state"] == 1, a["state"] == 2
    out["stick slip"] = float(np.max(sn[stick], initial=0.0)) / sc.slip
    big = slip & (sn > 1e-6 * sc.slip) & (tn > 1e-6 * mu * p0)
    with np.errstate(invalid="ignore", divide="ignore"):
        d = np.hypot(a["px"] / tn + a["sx"] / sn, a["py"] / tn + a["sy"] / sn)
    out["direction"] = float(np.max(d[big], initial=0.0))
    return out


#: What the physics checks allow: the stored forces are sums of the stored pressures (round-off); the tractions
#: are inside the disc to the tangential steps' tolerance (1e-10 of their unit, at most 100 mu p0 below mu = 0.01)
#: with a margin of 100 for the steps that stop below it (measured: 1.2e-10 mu p0); the states are those of p, t, s;
#: a stick element's slip is its step's residual (1e-10 of the steps' slip unit, at most 100 mu p0/E*: measured 3e-17
#: to 3e-12 mu p0/E*); a slipping
#: element's slip is opposite its traction to 1e-6 where both are resolved.
PHYSICS_TOL = {"FN": 1e-12, "disc": 1e-8, "states": 0, "stick slip": 1e-8, "direction": 1e-6}


#: The checks of an approximate method's result (FASTSIM, Kalker's simplified theory: its slips are those of its own
#: flexibility, not of the half-space's steps, so stick and slip follow its model, not these checks).
APPROXIMATE = ("FN", "disc")


def assert_physics(res, scene):
    got = physics_violations(res, scene)
    if scene.solver.method == "fastsim":
        got = {k: v for k, v in got.items() if k in APPROXIMATE}
    bad = {k: v for k, v in got.items() if not v <= PHYSICS_TOL[k]}
    assert not bad, (scene.name, bad)


@pytest.mark.parametrize("mu", [1e-6, 1e-12])
def test_tiny_friction_keeps_the_tractions_in_the_disc_in_mu_p0(mu):
    for name in ("cattaneo-3d", "kalker-circular"):
        scene = coarse(name, **{"contact.friction": mu})
        assert_physics(run(scene).arrays(), scene)


def test_a_load_where_the_creepage_sets_no_resolvable_traction_is_refused_in_one_line():
    with pytest.raises(InputError, match=r"^load\.creepage\.longitudinal: .*below 100 times solver\.tolerance"):
        coarse("kalker-circular", **{"load.normal": 1e30})
    scene = coarse("kalker-circular", **{"load.normal": 1e15})      # resolvable: a right answer
    assert_physics(run(scene).arrays(), scene)


def test_extreme_moduli_and_subnormal_loads_give_no_warning_and_name_the_key():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(InputError, match=r"^bodies\.B\.E: the contact's compliance"):
            coarse("cattaneo-3d", **{"bodies.B.E": 1e-300})
        with pytest.raises(InputError, match=r"^load\.normal: "):
            coarse("cattaneo-3d", **{"bodies.A.E": 1e300, "bodies.B.E": 1e300, "load.normal": 1e-300})
        scene = coarse("cattaneo-3d", **{"load.tangential": 5e-324})
        assert_physics(run(scene).arrays(), scene)


def test_stresses_of_a_3d_result(tmp_path, capsys):
    scene = coarse("cattaneo-3d", **{"discretization.distance": 0.3})
    run(scene, out=str(tmp_path / "r.npz"))
    assert cli.main(["stresses", str(tmp_path / "r.npz"), "--step", "1"]) == 0
    assert "peak" in capsys.readouterr().out


# ----------------------------------------------------------------------------- a long start says so
def test_a_marched_start_reports_its_steps_and_an_estimate(tmp_path, capsys, monkeypatch):
    """A conic method marches to a rolling start's steady state (minutes on a fine grid with dissimilar bodies):
    ``rollqp run`` says how long the start will take, measured on its first steps, and reports its steps."""
    scene = coarse("kalker-circular", **{"solver.method": "socp-clarabel", "discretization.distance": 0.2})
    ticks = []
    run(scene, start_progress=lambda j, expected: ticks.append((j, expected)))
    assert ticks and ticks[0][0] == 1 and all(e == ticks[0][1] > 1 for _, e in ticks)
    assert [j for j, _ in ticks] == list(range(1, len(ticks) + 1))
    (tmp_path / "s.toml").write_text(scene.to_toml(), encoding="utf-8")
    monkeypatch.setattr(reporting, "START_ESTIMATE_SECONDS", 0.0)
    monkeypatch.setattr(reporting, "ANNOUNCE_SECONDS", 0.0)
    monkeypatch.setenv("ROLLQP_PROGRESS_SECONDS", "0")
    assert cli.main(["run", str(tmp_path / "s.toml"), "--out", str(tmp_path / "r.npz")]) == 0
    err = capsys.readouterr().err
    assert "rollqp: the starting state: about " in err and "rollqp: the starting state: step 1 " in err, err
