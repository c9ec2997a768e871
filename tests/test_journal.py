"""Every completed state on disk as the run goes (rollqp.journal, docs/results.md): the journal survives a
writer killed at any byte, a run resumes from it to the uninterrupted result, the result file is written
from it in blocks and reads back whatever the scene's tables, a run keeps every k-th state with the sums
right, and a run with a result file holds no state in memory."""
from __future__ import annotations

import json
import os
import tracemalloc

import numpy as np
import pytest

import rollqp
from rollqp.errors import InputError
from rollqp.journal import Journal, journal_path
from rollqp import cli
from rollqp.result import load_result, resume_source

#: §6.1.1 at 81 nodes, 3 a_H (96 rolling steps): a second here.
SHORT = {"discretization.distance": 3.0, "solver.method": "newton"}
#: Two runs of one scene from the same states agree to the methods' tolerance (1e-10 of the residual: the
#: resumed march rebuilds Newton's factorizations, whose directions differ at round-off; measured 1e-11).
ROUND_OFF = 1e-10


@pytest.fixture(scope="module")
def short():
    scene = rollqp.load_scene("cattaneo-carter").replace(**SHORT)
    return scene, rollqp.run(scene).arrays()


class _Killed(BaseException):
    """Stops a run where nothing is caught: what a SIGKILL leaves (its journal, no result file)."""


def _journal_of(scene, path, stop):
    """The journal of a run of ``scene`` to ``path`` stopped right after state ``stop`` was added."""
    def observe(rec, ops):
        if rec.k == stop:
            raise _Killed
    with pytest.raises(_Killed):
        rollqp.run(scene, out=path, observe=observe)
    assert not os.path.exists(path)
    return journal_path(path)


def _same(a, b, scene, K1=None):
    """``b`` equals ``a`` (its first ``K1`` states) to round-off, with the same stick/slip zones."""
    K1 = len(a["q"]) if K1 is None else K1
    mu, p0 = scene.contact.mu, scene.p0
    assert np.array_equal(a["q"][:K1], b["q"]) and np.array_equal(a["state"][:K1], b["state"])
    assert np.max(np.abs(a["pt"][:K1] - b["pt"])) <= ROUND_OFF * mu * p0
    assert np.max(np.abs(a["pn"][:K1] - b["pn"])) <= ROUND_OFF * p0


def _journal_with(scene, method, path, stop):
    """The journal of a run of ``scene`` with ``method`` to ``path``, stopped right after state ``stop``."""
    def observe(rec, ops):
        if rec.k == stop:
            raise _Killed
    with pytest.raises(_Killed):
        rollqp.run(scene, method=method, out=path, observe=observe)


def _differences(a, b) -> dict:
    """The largest difference of every numeric array of two results (``step_time`` and ``meta`` apart)."""
    out = {}
    for key, value in a.items():
        if key in ("meta", "step_time") or np.asarray(value).dtype.kind not in "fiub":
            continue
        x, y = np.asarray(value, dtype=float), np.asarray(b[key], dtype=float)
        assert x.shape == y.shape, key
        out[key] = float(np.max(np.abs(x - y), initial=0.0)) if not np.array_equal(x, y, equal_nan=True) else 0.0
    return out


#: Scenes that a resumed march once left by 4e-12 to 6e-11 μp0 (the kept factorizations of a stick zone of more
#: than 64 nodes, a coupled warm start, the history operators of load.rolled, the coupled step's factorization
#: from 200 unknowns on), with each method that resumes.
BITWISE = [("newton", "ramp", {}), ("newton", "stop-reverse", {}), ("newton", "goodman-bentall", {}),
           ("newton", "goodman-bentall", {"discretization.elements": 160, "discretization.distance": 0.5}),
           ("nt-newton", "goodman-bentall", {}), ("nt-newton", "stop-reverse", {}), ("qp-clarabel", "stop-reverse", {})]


@pytest.mark.parametrize("method, name, over", BITWISE,
                         ids=[f"{m}-{n}" + ("-321" if o else "") for m, n, o in BITWISE])
def test_a_resumed_run_is_the_uninterrupted_run_bit_for_bit(method, name, over, tmp_path):
    """Stopped after 20 states (what a SIGKILL leaves: the journal) and resumed: every array of the result is
    the uninterrupted run's, bit for bit (Newton's kept factorizations, its last products and the march's
    history operators are rebuilt from the journal's records: rollqp.solverstate)."""
    scene = rollqp.load_scene(name).replace(**over)
    if name == "goodman-bentall" and not over:
        scene = scene.replace(**{"discretization.distance": 3.0})
    full = rollqp.run(scene, method=method).arrays()
    _journal_with(scene, method, tmp_path / "r.npz", stop=20)
    res = rollqp.run(scene, method=method, resume=tmp_path / "r.npz", out=tmp_path / "r.npz").arrays()
    assert json.loads(str(res["meta"]))["resumed_from"] == 20
    diff = _differences(full, res)
    if method == "qp-clarabel":  # Clarabel equilibrates a solver object's data with the QP it was built for, so
        for key in ("iterations", "inner_normal", "inner_tangential"):  # its iteration counts depend on the step
            diff.pop(key)  # that built it (an object of the resumed march's); its answers, refined, do not
    assert not any(diff.values()), {k: v for k, v in diff.items() if v}


def test_a_resumed_3d_run_is_the_uninterrupted_run_bit_for_bit(tmp_path):
    """The 3D run (its Newton method on the disc projection) stopped after 3 states and resumed: the step after
    the stored state sets out from it as the uninterrupted step did (pressure, approach, tractions and
    creepages), so every array is the uninterrupted run's, bit for bit."""
    scene = rollqp.load_scene("cattaneo-3d")
    full = rollqp.run(scene).arrays()
    def observe(rec, ops):
        if rec.k == 3:
            raise _Killed
    with pytest.raises(_Killed):
        rollqp.run(scene, out=tmp_path / "r.npz", observe=observe)
    src = resume_source(tmp_path / "r.npz")
    try:
        res = rollqp.run(scene, resume=src, out=tmp_path / "r.npz").arrays()
    finally:
        src.close()
    diff = _differences(full, res)
    assert not any(diff.values()), {k: v for k, v in diff.items() if v}


def test_a_resumed_qp_osqp_run_agrees_to_its_tolerance(tmp_path):
    """OSQP keeps its ADMM iterates (the duals, ``z``, the adapted ``rho``) inside the solver object between
    steps and warm-starts the next QP from them; its Python interface neither returns nor sets them as they
    are, so a resumed march starts its first QPs from other iterates and its answers differ within OSQP's
    accuracy (the polished QP answer, then rollqp's refinement): measured 3e-11 to 1.5e-10 μp0, the stick/slip
    states identical. The bound is the method's residual limit (1e-9 μp0)."""
    scene = rollqp.load_scene("stop-reverse")
    full = rollqp.run(scene, method="qp-osqp").arrays()
    _journal_with(scene, "qp-osqp", tmp_path / "r.npz", stop=20)
    res = rollqp.run(scene, method="qp-osqp", resume=tmp_path / "r.npz", out=tmp_path / "r.npz").arrays()
    assert np.array_equal(res["state"], full["state"]) and np.array_equal(res["q"], full["q"])
    assert np.max(np.abs(res["pt"] - full["pt"])) <= 1e-9 * scene.contact.mu * scene.p0
    assert np.max(np.abs(res["pn"] - full["pn"])) <= 1e-9 * scene.p0


def test_a_journal_without_the_methods_records_resumes_to_the_tolerance(tmp_path, monkeypatch):
    """A journal written without the method's records (rollqp before them) still resumes: the march sets out
    without Newton's factorizations, and the result agrees to the solver's tolerance (not bit for bit)."""
    from rollqp import solverstate
    scene = rollqp.load_scene("ramp")
    full = rollqp.run(scene).arrays()
    with monkeypatch.context() as mp:
        mp.setattr(solverstate.Recorder, "note", lambda self, k, state, cache=None: None)
        _journal_with(scene, "newton", tmp_path / "r.npz", stop=20)
    res = rollqp.run(scene, resume=tmp_path / "r.npz", out=tmp_path / "r.npz").arrays()
    assert json.loads(str(res["meta"]))["resumed_from"] == 20
    _same(full, res, scene)


def test_result_file_of_a_run_is_the_in_memory_result(short, tmp_path):
    scene, full = short
    res = rollqp.run(scene, out=tmp_path / "r.npz")
    got = load_result(tmp_path / "r.npz")
    assert not os.path.exists(journal_path(tmp_path / "r.npz")), "the journal is removed"
    for key, value in full.items():
        if key in ("meta", "step_time"):
            continue
        assert np.array_equal(np.asarray(value), np.asarray(got[key]), equal_nan=True), key
    assert len(res) == len(full["q"]) and res["pn"].shape == full["pn"].shape


def test_a_journal_cut_at_any_byte_keeps_every_complete_state(short, tmp_path):
    """A SIGKILL can stop the write of a frame at any byte: every complete frame before it is read, the torn
    one is ignored (and cut off before the next append), and the run resumes to the uninterrupted result."""
    scene, full = short
    path = _journal_of(scene, tmp_path / "r.npz", stop=40)
    data = open(path, "rb").read()
    whole = Journal.open(path, "j")
    ends = [int(o) + int(n) for o, n in zip(whole.frames.offset[:len(whole)], whole.frames.length[:len(whole)])]
    whole.close()
    rng = np.random.default_rng(7)
    head = ends[-2]  # every byte around the last frame's head and end, and 30 anywhere
    cuts = sorted(set(range(head - 4, head + 40)) | set(range(ends[-1] - 40, ends[-1] + 1))
                  | set(rng.integers(ends[0], ends[-1], 30).tolist()))
    for cut in cuts:
        with open(tmp_path / "cut.journal", "wb") as fh:
            fh.write(data[:cut])
        j = Journal.open(tmp_path / "cut.journal", "j")
        assert len(j) == sum(e <= cut for e in ends), cut
        j.close()
    cut = ends[-1] - 5  # the last frame torn: state 39 is the last whole one
    with open(path, "wb") as fh:
        fh.write(data[:cut])
    res = rollqp.run(scene, resume=tmp_path / "r.npz", out=tmp_path / "r.npz").arrays()
    assert json.loads(str(res["meta"]))["resumed_from"] == 39
    _same(full, res, scene)


def test_a_corrupt_frame_inside_the_journal_is_an_error(short, tmp_path):
    scene, _ = short
    path = _journal_of(scene, tmp_path / "r.npz", stop=10)
    j = Journal.open(path, "j")
    middle = int(j.frames.offset[5]) + 100
    j.close()
    data = bytearray(open(path, "rb").read())
    data[middle] ^= 0x40
    open(path, "wb").write(bytes(data))
    with pytest.raises(InputError, match=r"--resume: .*fails its CRC: corrupt journal"):
        resume_source(tmp_path / "r.npz")


def test_resume_from_a_result_file_and_from_its_journal(short, tmp_path):
    """An interrupted run's file (some states) and the journal a killed one leaves both continue to the
    uninterrupted result; the journal wins when it holds more."""
    scene, full = short
    part = {k: (v[:30] if k in full and np.ndim(v) and len(v) == len(full["q"]) and k != "x" else v)
            for k, v in full.items()}
    np.savez(tmp_path / "part.npz", **part)
    res = rollqp.run(scene, resume=tmp_path / "part.npz", out=tmp_path / "part.npz").arrays()
    _same(full, res, scene)
    _journal_of(scene, tmp_path / "k.npz", stop=50)
    np.savez(tmp_path / "k.npz", **part)  # an older file beside a journal that holds more
    src = resume_source(tmp_path / "k.npz")
    assert src.journal is not None and src.last == 50
    src.close()
    _same(full, rollqp.run(scene, resume=tmp_path / "k.npz", out=tmp_path / "k.npz").arrays(), scene)


def test_resume_refuses_a_last_state_that_does_not_solve_its_step(short, tmp_path, capsys):
    """A tampered last state (its pressure doubled: ∫p = 2P) is a one-line error, nothing is run or written."""
    scene, full = short
    part = {k: (v[:30].copy() if k in full and np.ndim(v) and len(v) == len(full["q"]) and k != "x" else v)
            for k, v in full.items()}
    part["pn"][-1] *= 2.0
    np.savez(tmp_path / "bad.npz", **part)
    before = (tmp_path / "bad.npz").read_bytes()
    assert cli.main(["run", "--resume", str(tmp_path / "bad.npz"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--resume: the last state (29) does not solve its own step" in err, err
    assert (tmp_path / "bad.npz").read_bytes() == before and not os.path.exists(journal_path(tmp_path / "bad.npz"))


#: Forgeries of an earlier state (state 10 of a file of 30): what each makes of it, and the message's words (a
#: field that is not finite the result reader refuses already).
FORGED_EARLIER = {
    "tractions beyond mu p": (lambda a: a["pt"].__setitem__(10, 3.0 * a["pt"][10]), "a traction beyond the friction bound"),
    "a negative pressure": (lambda a: a["pn"].__setitem__((10, 40), -1e-3 * a["pn"][10].max()), "p0 < 0"),
    "Q not that of its tractions": (lambda a: a["Q"].__setitem__(10, a["Q"][10] + 1e-9 * abs(a["P"][10])),
                                    "state 10: its tangential load Q is not that of its tractions"),
}


@pytest.mark.parametrize("case", sorted(FORGED_EARLIER))
def test_resume_refuses_a_forged_earlier_state(short, tmp_path, case):
    """An earlier state changed (not the last one, which is solved again) is refused in one line before anything
    is run: the strip's states are checked in themselves as the grid's are (rollqp.march.loop.check_earlier)."""
    scene, full = short
    part = {k: (v[:30].copy() if k in full and np.ndim(v) and len(v) == len(full["q"]) and k != "x" else v)
            for k, v in full.items()}
    forge, words = FORGED_EARLIER[case]
    forge(part)
    np.savez(tmp_path / "bad.npz", **part)
    with pytest.raises(InputError) as err:
        rollqp.run(scene, resume=tmp_path / "bad.npz", out=tmp_path / "bad.npz")
    msg = str(err.value)
    assert msg.startswith("--resume: ") and words in msg and msg.endswith("the file was changed or is corrupt"), msg
    assert "\n" not in msg and not os.path.exists(journal_path(tmp_path / "bad.npz"))
    clean = {k: (v[:30].copy() if k in full and np.ndim(v) and len(v) == len(full["q"]) and k != "x" else v)
             for k, v in full.items()}
    np.savez(tmp_path / "good.npz", **clean)     # the same file unforged resumes
    _same(full, rollqp.run(scene, resume=tmp_path / "good.npz").arrays(), scene)


def test_march_resume_continues_from_the_scene_in_the_file(short, tmp_path):
    """``rollqp.march.resume(path)`` reads the scene from the file and continues it (as ``rollqp run --resume``);
    a file without a scene is one line naming --resume."""
    from rollqp.march import resume
    scene, full = short
    part = {k: (v[:30] if k in full and np.ndim(v) and len(v) == len(full["q"]) and k != "x" else v)
            for k, v in full.items()}
    np.savez(tmp_path / "part.npz", **part)
    _same(full, resume(tmp_path / "part.npz").arrays(), scene)
    part["meta"] = np.asarray(json.dumps({"method": "newton"}))
    np.savez(tmp_path / "nameless.npz", **part)
    with pytest.raises(InputError, match=r"^--resume: the result file holds no scene"):
        resume(tmp_path / "nameless.npz")


def test_keep_every_k_keeps_the_sums(short, tmp_path):
    """keep_every = 7: states 0, 7, 14, … and the last two; works, times and iteration counts summed over the
    steps in between, the residual the largest, the rest the state's own (the same in memory and in the file)."""
    scene, full = short
    K = len(full["q"]) - 1
    for res in (rollqp.run(scene, keep_every=7).arrays(),
                rollqp.run(scene, keep_every=7, out=tmp_path / "r.npz").arrays()):
        idx = np.array(sorted(set(range(0, K + 1, 7)) | {K - 1, K}))
        assert np.array_equal(res["step"], idx)
        for key in ("pn", "pt", "slip", "state", "friction_power", "q", "P", "creepage", "elastic_energy"):
            assert np.array_equal(res[key], full[key][idx]), key
        for key in ("friction_work", "load_work", "iterations", "backtracks"):
            assert np.allclose(np.cumsum(res[key]), np.cumsum(full[key])[idx], rtol=1e-13, atol=0), key
        assert res["residual"][1] == full["residual"][1:8].max()


def test_a_thinned_run_resumes(short, tmp_path):
    scene, full = short
    path = _journal_of(scene, tmp_path / "r.npz", stop=33)
    del path
    src = resume_source(tmp_path / "r.npz")
    assert src.keep_every == 1
    src.close()
    a = rollqp.run(scene, keep_every=5, out=tmp_path / "t.npz")
    part = {k: (v[:-3] if np.ndim(v) and len(v) == len(a["q"]) and k != "x" else v) for k, v in a.arrays().items()}
    part["meta"] = np.asarray(json.dumps(dict(load_result(tmp_path / "t.npz")["meta"])))
    np.savez(tmp_path / "t2.npz", **part)   # ends at a kept state (a multiple of 5): its predecessor is not there
    with pytest.raises(InputError, match="does not hold the state before its last one"):
        rollqp.run(scene, resume=tmp_path / "t2.npz", out=tmp_path / "t2.npz")
    res = rollqp.run(scene, keep_every=5, out=tmp_path / "u.npz")  # a complete one, resumed: nothing to do
    again = rollqp.run(scene, resume=tmp_path / "u.npz", out=tmp_path / "u.npz")
    assert np.array_equal(again["pt"], res["pt"]) and np.array_equal(again["friction_work"], res["friction_work"])


def test_a_run_with_a_result_file_holds_no_state_in_memory(tmp_path):
    """The peak memory (tracemalloc) of a run with ``out`` grows with its length by its per-step numbers only
    (~200 bytes a state), not by its states: 4× the steps, 10 MB more states, at most 1 MB more peak (a block
    of rows, 2 MB, is written at a time, and the file is read back mapped)."""
    base = rollqp.load_scene("cattaneo-carter").replace(**{"solver.method": "newton", "discretization.elements": 80})
    peaks = []
    for distance in (8.0, 32.0):
        scene = base.replace(**{"discretization.distance": distance})
        rollqp.run(scene.replace(**{"discretization.distance": 0.25}), out=tmp_path / "warm.npz")  # imports first
        tracemalloc.start()
        res = rollqp.run(scene, out=tmp_path / f"r{distance}.npz")
        res["pn"][-1].sum()  # the summary's reads
        peaks.append(tracemalloc.get_traced_memory()[1])
        tracemalloc.stop()
    states = res["pn"].nbytes * 5
    assert states > 13e6 and peaks[1] - peaks[0] < 1e6, (peaks, states)


def test_a_dense_newton_run_holds_three_n_by_n_matrices(tmp_path):
    """Newton on the dense path holds the influence matrix, one scaled copy ``K`` and LU factors within ``K``'s
    size: three n × n matrices (measured 3.17 at 1,281 nodes). A fourth — the start's ``K`` still held while the
    rolling steps' is built, a kept factorization beside the one being factored, the dense history operator
    made beside them — is 3.98 or more; the bound sits between (the rest: the step's vectors, the strip)."""
    scene = rollqp.load_scene("cattaneo-carter").replace(**{"discretization.elements": 640, "solver.operator": "dense",
                                                            "discretization.distance": 0.1})
    rollqp.run(scene.replace(**{"discretization.elements": 20}), out=tmp_path / "warm.npz")  # imports first
    tracemalloc.start()
    try:
        rollqp.run(scene, method="newton", out=tmp_path / "r.npz")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    n = scene.n_nodes
    assert peak <= 3.5 * 8 * n * n, f"peak {peak / 1e6:.1f} MB: {peak / (8 * n * n):.2f} n x n matrices"


def test_large_profile_table_reads_back(tmp_path, capsys):
    """A valid scene with a profile table of 200,000 points: the result file holds the table as an array
    (meta stays small), reads back, and stresses and resume take it."""
    scene = rollqp.load_scene("cattaneo-carter").replace(**{"discretization.distance": 0.25, "solver.method": "newton"})
    L = 1.3 * scene.half_width
    x = np.linspace(-L, L, 200_000)
    d = scene.to_dict()
    d["bodies"]["A"]["profile"] = {"kind": "table", "frame": "contact", "x": x.tolist(),
                                  "h": (x * x / (2 * scene.A.radius)).tolist()}
    big = rollqp.load_scene(d)
    rollqp.run(big, out=tmp_path / "r.npz")
    z = np.load(tmp_path / "r.npz")
    assert len(str(z["meta"])) < 20_000 and z["meta.scene.bodies.A.profile.0.x"].size == 200_000
    res = load_result(tmp_path / "r.npz")
    assert res["meta"]["scene"]["bodies"]["A"]["profile"][0]["x"] == x.tolist()
    assert cli.main(["stresses", str(tmp_path / "r.npz"), "--step", "-1", "--grid", "20,20"]) == 0
    assert "peak von Mises" in capsys.readouterr().out
    assert cli.main(["run", "--resume", str(tmp_path / "r.npz"), "--quiet"]) == 0
    assert "nothing to resume" in capsys.readouterr().err
