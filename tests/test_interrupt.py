"""Nothing lost: a real signal to a real ``rollqp run`` writes the completed states, and
``--resume`` continues from them to the uninterrupted result; SIGKILL at random moments loses at
most the state in flight (the journal, rollqp.journal); a second Ctrl-C right after the first keeps
every completed state; concurrent writers to one ``--out`` are refused, a stale lock is taken over
whatever process has its id now; temporary files of killed writes are cleaned up."""
from __future__ import annotations

import json
import os
import random
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import rollqp
from rollqp.errors import InputError
from rollqp.journal import Journal, journal_path
from rollqp.result import OutputLock, TEMP_PREFIX, load_result, save_npz

#: 641 nodes, 3072 newton steps: about 6 s here, long enough to be interrupted mid-run.
LONG = {"discretization.elements": 320, "discretization.distance": 12.0, "solver.method": "newton"}


def _default_sigint():
    """In the child before exec: SIGINT back to its default, so that Python installs its Ctrl-C handler.
    A test run started in the background by a non-interactive shell (``cmd &``, as a CI script may do)
    inherits SIGINT ignored, and Python then keeps ignoring it (seen: the run finished, exit 0)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _cli(*args, cwd, env=None):
    return subprocess.Popen([sys.executable, "-m", "rollqp.cli", *args], cwd=cwd, stderr=subprocess.PIPE,
                            stdout=subprocess.PIPE, text=True, preexec_fn=_default_sigint,
                            env=dict(os.environ, OPENBLAS_NUM_THREADS="1", **(env or {})))


def _interrupt_mid_run(tmp_path, sig):
    """Start the long run and send ``sig`` once it reports its first progress line (states have been
    computed, whatever the machine's speed); ``(exit code, the last stderr line)``."""
    proc = _cli("run", "scene.toml", "--out", "r.npz", cwd=tmp_path, env={"ROLLQP_PROGRESS_SECONDS": "0.5"})
    line = proc.stderr.readline()                     # "rollqp: step k/K …" after 0.5 s of stepping
    assert line.startswith("rollqp: step "), line
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=120)
    lines = [x for x in err.splitlines() if not x.startswith("rollqp: step ")]
    return proc.returncode, "\n".join(lines) + "\n"


@pytest.fixture(scope="module")
def long_scene(tmp_path_factory):
    folder = tmp_path_factory.mktemp("long")
    scene = rollqp.load_scene("cattaneo-carter").replace(**LONG)
    (folder / "scene.toml").write_text(scene.to_toml(), encoding="utf-8")
    full = rollqp.run(scene).arrays()
    return scene, full


@pytest.mark.integration
@pytest.mark.parametrize("sig, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)], ids=["SIGINT", "SIGTERM"])
def test_signal_writes_completed_states_and_resume_reproduces(long_scene, tmp_path, sig, code):
    scene, full = long_scene
    (tmp_path / "scene.toml").write_text(scene.to_toml(), encoding="utf-8")
    got, err = _interrupt_mid_run(tmp_path, sig)
    assert got == code and err.count("\n") == 1 and "interrupted" in err and "--resume r.npz" in err, (got, err)
    part = load_result(tmp_path / "r.npz")
    K0 = part["q"].size
    assert 1 < K0 < scene.n_steps + 1, f"interrupted mid-run: {K0} of {scene.n_steps + 1} states"
    assert part["meta"]["interrupted"], "the file says it was interrupted"
    assert not (tmp_path / "r.npz.lock").exists(), "the lock is released"
    # the completed states are the uninterrupted run's, bit for bit (same computation)
    assert np.array_equal(part["pt"], full["pt"][:K0]) and np.array_equal(part["pn"], full["pn"][:K0])
    proc = _cli("run", "--resume", "r.npz", "--quiet", cwd=tmp_path)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 0, err
    res = load_result(tmp_path / "r.npz")
    assert res["meta"]["resumed_from"] == K0 - 1 and "interrupted" not in res["meta"]
    _equal_within_the_tolerance(res, full, scene)  # (measured 2.4e-11 μp0)


def test_second_writer_to_the_same_output_is_refused(tmp_path):
    out = tmp_path / "r.npz"
    with OutputLock(out):
        with pytest.raises(InputError, match=r"--out: another rollqp process \(pid \d+\) is writing"):
            with OutputLock(out):
                pass
        proc = _cli("run", "cattaneo-carter", "--out", str(out), "--quiet", cwd=tmp_path)
        _, err = proc.communicate(timeout=60)
        assert proc.returncode == 2 and "another rollqp process" in err and err.count("\n") == 1, err
    with OutputLock(out):  # released: taken again
        pass


def test_stale_lock_and_temporary_files_are_cleaned_up(tmp_path):
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                          text=True).stdout.strip()               # a pid that no longer runs
    (tmp_path / "r.npz.lock").write_text(dead)
    stale = tmp_path / f"{TEMP_PREFIX}{dead}-abc.npz"              # left by a killed write
    stale.write_bytes(b"partial")
    mine = tmp_path / f"{TEMP_PREFIX}{os.getpid()}-live.npz"      # a live process's: kept
    mine.write_bytes(b"in flight")
    with OutputLock(tmp_path / "r.npz"):
        save_npz(tmp_path / "r.npz", {"x": np.zeros(2)})
    assert not stale.exists() and mine.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([mine.name, "r.npz"])


def test_scene_name_cannot_steer_the_output_path(tmp_path):
    """A name with a path in it is refused by the scene (docs/scenes.md); a file stem (the
    default name) and the default output name are reduced to safe characters, so whatever
    the scene, the result is written in the working folder."""
    from rollqp.cli import default_output
    from rollqp.scene.checks import safe_name
    scene = rollqp.load_scene("cattaneo-carter").replace(**{"discretization.distance": 0.0})
    text = scene.to_toml().replace('name = "cattaneo-carter"', 'name = "../../escape"')
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "scene.toml").write_text(text, encoding="utf-8")
    proc = _cli("run", "scene.toml", "--quiet", cwd=tmp_path / "sub")
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 2 and err.startswith("rollqp: error: name: must be") and err.count("\n") == 1, err
    assert not list(tmp_path.rglob("*.npz")) and not (tmp_path.parent / "escape.npz").exists()
    assert default_output("../../escape") == "_.._escape.npz" and default_output("a/b\\c") == "a_b_c.npz"
    stem = "..%2f x;rm -rf"
    (tmp_path / "sub" / f"{stem}.toml").write_text(scene.to_toml().replace('name = "cattaneo-carter"\n', ""),
                                                   encoding="utf-8")
    named = rollqp.load_scene(str(tmp_path / "sub" / f"{stem}.toml"))
    assert named.name == safe_name(stem) == "2f x_rm -rf", named.name


def test_bad_plot_and_output_fail_before_the_run(tmp_path, capsys):
    """``--plot`` with an unknown format and ``--out`` in a missing folder are found before any
    work (no figure library traceback after a long run)."""
    from rollqp import cli
    assert cli.main(["run", "cattaneo-carter", "--plot", str(tmp_path / "f.xyz"), "--out",
                     str(tmp_path / "r.npz")]) == 2
    err = capsys.readouterr().err
    assert "--plot: unknown figure format 'xyz'" in err and err.count("\n") == 1, err
    assert cli.main(["run", "cattaneo-carter", "--out", str(tmp_path / "missing" / "r.npz")]) == 2
    assert "does not exist" in capsys.readouterr().err
    assert not list(tmp_path.iterdir()), "nothing was run or written"


def _states_on_disk(folder) -> int:
    """The states a killed run left: its journal's frames, else its result file's, else none."""
    if (folder / "r.npz.journal").exists():
        j = Journal.open(folder / "r.npz.journal", "journal")
        try:
            return int(j.frames.index[len(j) - 1]) + 1 if len(j) else 0
        finally:
            j.close()
    return load_result(folder / "r.npz")["q"].size if (folder / "r.npz").exists() else 0


def _equal_within_the_tolerance(res, full, scene):
    """Equal to the solver's tolerance, not bit for bit: a run resumed from the result file an interruption wrote
    (which keeps the states, not the method's records) sets out without Newton's kept factorizations, so its
    steps take other (equally valid) iterations and stop elsewhere within the tolerance (1e-10 of the
    nondimensional residual); the tractions must agree to ten times that (measured: 2.4e-11 μp0)."""
    assert np.array_equal(res["q"], full["q"]) and np.array_equal(res["state"], full["state"])
    assert np.max(np.abs(res["pt"] - full["pt"])) <= 1e-9 * scene.contact.mu * scene.p0
    assert np.max(np.abs(res["pn"] - full["pn"])) <= 1e-9 * scene.p0
    for key in ("friction_work", "load_work", "elastic_energy"):  # the derived and computed fields too
        assert np.allclose(res[key], full[key], rtol=1e-7, atol=1e-9 * np.abs(full[key]).max()), key


def _bit_for_bit(res, full):
    """Every array of the result (``step_time`` and ``meta`` apart) is the uninterrupted run's, bit for bit: a march
    resumed from its journal rebuilds what the method carried across steps (rollqp.solverstate)."""
    for key, value in full.items():
        if key in ("meta", "step_time") or np.asarray(value).dtype.kind not in "fiub":
            continue
        assert np.array_equal(np.asarray(res[key]), np.asarray(value), equal_nan=True), key


def _journal_bytes(folder) -> int:
    path = folder / "r.npz.journal"
    return path.stat().st_size if path.exists() else 0


@pytest.mark.integration
def test_sigkill_at_random_moments_then_resume_equals_the_uninterrupted_run(long_scene, tmp_path):
    """SIGKILL (nothing can be caught, nothing is written at the end) at four random moments of a real
    ``rollqp run`` — each a random 0–0.5 s after the run (or its resumption) has appended a state to its
    journal — each time continued with ``run --resume``: the states on disk only grow, and the last resume
    completes the run to the uninterrupted result, bit for bit."""
    scene, full = long_scene
    (tmp_path / "scene.toml").write_text(scene.to_toml(), encoding="utf-8")
    rng = random.Random(20250127)
    proc, kills, seen = _cli("run", "scene.toml", "--out", "r.npz", "--quiet", cwd=tmp_path), 0, 0
    while kills < 4:
        before, t0 = _journal_bytes(tmp_path), time.monotonic()
        while proc.poll() is None and _journal_bytes(tmp_path) <= before and time.monotonic() - t0 < 120:
            time.sleep(0.005)
        # the moment: a step, a frame's write, the file's; within 0.5 s, so that four kills land in the run
        # however fast the machine (quiet, its 3,073 steps take ~7 s; with up to 1 s the run could end first)
        time.sleep(rng.uniform(0.0, 0.5))
        if proc.poll() is not None:
            break
        proc.kill()
        proc.wait()
        kills += 1
        on_disk = _states_on_disk(tmp_path)
        assert on_disk >= seen, f"kill {kills}: {on_disk} states on disk after {seen} before"
        seen = on_disk
        proc = _cli("run", "--resume", "r.npz", "--quiet", cwd=tmp_path)
    _, err = proc.communicate(timeout=600)
    if proc.returncode != 0 or not (tmp_path / "r.npz").exists() or (tmp_path / "r.npz.journal").exists():
        proc = _cli("run", "--resume", "r.npz", "--quiet", cwd=tmp_path)  # the last kill came after the file
        _, err = proc.communicate(timeout=600)
    assert proc.returncode == 0 and not err, err
    assert kills == 4 and seen > 1, (kills, seen)
    assert not (tmp_path / "r.npz.journal").exists()
    res = load_result(tmp_path / "r.npz")
    assert res["meta"]["resumed_from"] >= seen - 1
    _bit_for_bit(res, full)


def _file_size_limit(nbytes):
    """In the child before exec: files may not grow beyond ``nbytes`` (RLIMIT_FSIZE), and a write beyond fails
    with EFBIG (SIGXFSZ ignored, as a full disk fails with ENOSPC), as on a disk that fills up mid-run."""
    def limit():
        import resource
        _default_sigint()
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (nbytes, nbytes))
    return limit


def test_a_full_disk_mid_run_keeps_every_written_state_and_resumes_bit_for_bit(tmp_path):
    """The journal's write fails mid-run (a file size limit): one line naming the file and the reason, exit 4
    (the result could not be written), every state written before it kept in the journal; once the limit is
    lifted, ``run --resume`` completes the run to the uninterrupted result, bit for bit."""
    from rollqp.cli import EXIT_WRITE
    scene = rollqp.load_scene("ramp")
    (tmp_path / "scene.toml").write_text(scene.to_toml(), encoding="utf-8")
    full = rollqp.run(scene).arrays()
    proc = subprocess.run([sys.executable, "-m", "rollqp.cli", "run", "scene.toml", "--out", "r.npz", "--quiet"],
                          cwd=tmp_path, capture_output=True, text=True, preexec_fn=_file_size_limit(200_000),
                          env=dict(os.environ, OPENBLAS_NUM_THREADS="1"), timeout=120)
    assert proc.returncode == EXIT_WRITE == 4, proc.stderr
    assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr, proc.stderr
    assert proc.stderr.startswith("rollqp: error: cannot write r.npz.journal (File too large): the "), proc.stderr
    j = Journal.open(tmp_path / "r.npz.journal", "journal")
    kept = len(j)
    j.close()
    assert 1 < kept < scene.n_steps and f"the {kept} completed states are in" in proc.stderr, (kept, proc.stderr)
    assert not (tmp_path / "r.npz").exists() and os.path.getsize(tmp_path / "r.npz.journal") <= 200_000
    again = _cli("run", "--resume", "r.npz", "--quiet", cwd=tmp_path)
    _, err = again.communicate(timeout=120)
    assert again.returncode == 0 and not err, err
    res = load_result(tmp_path / "r.npz")
    assert res["meta"]["resumed_from"] == kept - 1 and not (tmp_path / "r.npz.journal").exists()
    for key in ("pn", "pt", "slip", "gap", "state", "creepage", "iterations", "friction_work"):
        assert np.array_equal(res[key], full[key]), key


@pytest.mark.integration
@pytest.mark.parametrize("gap_ms", [0, 5, 20, 40])
def test_a_second_ctrl_c_keeps_every_completed_state(long_scene, tmp_path, gap_ms):
    """Ctrl-C twice, the second 0–40 ms after the first (while the first one's states are being written):
    the run exits 130 with one line, and its file holds every state completed when the first came."""
    scene, full = long_scene
    (tmp_path / "scene.toml").write_text(scene.to_toml(), encoding="utf-8")
    proc = _cli("run", "scene.toml", "--out", "r.npz", cwd=tmp_path, env={"ROLLQP_PROGRESS_SECONDS": "0.3"})
    line = proc.stderr.readline()
    assert line.startswith("rollqp: step "), line
    done = int(line.split()[2].split("/")[0])       # "rollqp: step k/K …": k rolling steps were complete
    proc.send_signal(signal.SIGINT)
    time.sleep(gap_ms / 1000)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    lines = [x for x in err.splitlines() if not x.startswith("rollqp: step ")]
    assert proc.returncode == 130 and len(lines) == 1 and "completed states are in r.npz" in lines[0], (err,)
    part = load_result(tmp_path / "r.npz")
    K0 = part["q"].size
    assert K0 >= done + 1 and part["meta"]["interrupted"]
    assert np.array_equal(part["pt"], full["pt"][:K0]) and np.array_equal(part["pn"], full["pn"][:K0])
    assert not (tmp_path / "r.npz.journal").exists() and not (tmp_path / "r.npz.lock").exists()


@pytest.mark.integration
def test_a_lock_whose_process_id_now_belongs_to_another_process_is_taken_over(tmp_path):
    """A killed run's lock file names its process id; that id may now be another process (here: a live
    ``sleep``): the lock is the kernel's (flock), gone with its holder, so the next run takes it."""
    other = subprocess.Popen(["sleep", "30"])
    try:
        (tmp_path / "r.npz.lock").write_text(f"{other.pid} 12345")
        proc = _cli("run", "cattaneo-carter", "--out", "r.npz", "--quiet", cwd=tmp_path)
        _, err = proc.communicate(timeout=120)
        assert proc.returncode == 0 and not err, err
        assert load_result(tmp_path / "r.npz")["q"].size > 1 and not (tmp_path / "r.npz.lock").exists()
    finally:
        other.kill()
        other.wait()


def test_a_lock_file_naming_a_live_process_that_holds_no_lock_is_taken(tmp_path):
    """The lock file names a process that runs (this test's parent) but holds no lock on it: the id was
    reused after the run that wrote it was killed. The lock is the kernel's, so it is free."""
    (tmp_path / "r.npz.lock").write_text(f"{os.getppid()} 1")
    with OutputLock(tmp_path / "r.npz") as lock:
        assert lock.fd >= 0
        with pytest.raises(InputError, match=rf"another rollqp process \(pid {os.getpid()}\)"):
            with OutputLock(tmp_path / "r.npz"):
                pass
    assert not (tmp_path / "r.npz.lock").exists()
