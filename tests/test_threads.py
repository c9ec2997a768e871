"""BLAS threads in every entry point (rollqp.threads): the pools a run sees, read as a user would read
them (``threadpoolctl.threadpool_info()``), in a fresh process where numpy and scipy load for real.

Each check runs a small script in a subprocess that records the pool sizes from inside the run (the
run function wrapped) and after it. ``OPENBLAS_NUM_THREADS=3`` is set by the test for the child, as a
user's environment could (OpenBLAS caps it at the cores): rollqp must limit the loaded pools (numpy's and scipy's OpenBLAS, each wheel
bundles one) to ``$ROLLQP_THREADS`` during its run whatever the process started with, and give the
previous sizes back afterwards. Without scipy's BLAS loaded before the limit, scipy's pool stays at 3
(the failure these tests catch).
"""
from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from rollqp.errors import InputError
from rollqp.threads import threads

SCRIPT = r"""
import json, sys
import numpy                                  # a user's numpy, loaded before rollqp (scipy's BLAS not yet)
import rollqp, rollqp.cli
from threadpoolctl import threadpool_info
before = sorted((i["filepath"].rsplit("/", 1)[-1], i["num_threads"]) for i in threadpool_info())
seen = []
def recording(run):
    def wrapped(*a, **k):
        seen.append(sorted((i["filepath"].rsplit("/", 1)[-1], i["num_threads"]) for i in threadpool_info()))
        return run(*a, **k)
    return wrapped
made = rollqp.cli.FAMILIES[3]      # the run's module is still imported by the command: wrapped when it runs
rollqp.cli.FAMILIES[3] = made.replace(run=lambda *a, **k: recording(made.run)(*a, **k))
how = sys.argv[1]
if how == "api":
    from rollqp.march import grid as r3    # (rollqp.march is also the package's function: import the module by from)
    r3.run = recording(r3.run)
    rollqp.run("kalker-elliptic")
    code = 0
else:
    code = rollqp.cli.main(["run", "kalker-elliptic", "--no-cross-check", "--quiet", "--out", sys.argv[2]])
after = sorted((i["filepath"].rsplit("/", 1)[-1], i["num_threads"]) for i in threadpool_info())
print(json.dumps({"code": code, "before": before, "during": seen, "after": after}))
"""


def _child(how, tmp_path, rollqp_threads=None):
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "3"}
    env.pop("ROLLQP_THREADS", None)
    if rollqp_threads is not None:
        env["ROLLQP_THREADS"] = rollqp_threads
    proc = subprocess.run([sys.executable, "-c", SCRIPT, how, str(tmp_path / "r.npz")], capture_output=True,
                          text=True, timeout=300, env=env, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.strip().splitlines()[-1])


@pytest.mark.integration
@pytest.mark.parametrize("how", ["api", "cli"])
def test_every_blas_pool_is_pinned_during_a_run(tmp_path, how):
    out = _child(how, tmp_path)
    assert out["code"] == 0
    (during,) = out["during"]
    libs = [name for name, _ in during]
    assert any("scipy_openblas" in n and "64" not in n for n in libs), f"scipy's own BLAS is loaded: {libs}"
    assert len(during) >= 2, f"numpy's and scipy's pools both seen: {during}"
    assert all(n == 1 for _, n in during), f"every pool at one thread during the run: {during}"
    if how == "api":  # the API gives the user's sizes back
        before = dict(map(tuple, out["before"]))
        assert before and all(dict(map(tuple, out["after"]))[k] == n for k, n in before.items()), \
            f"the user's pool sizes restored: {out}"


@pytest.mark.integration
def test_rollqp_threads_sets_the_pool_size(tmp_path):
    (during,) = _child("api", tmp_path, rollqp_threads="2")["during"]
    assert all(n == 2 for _, n in during), during


@pytest.mark.integration
def test_a_bad_rollqp_threads_is_a_one_line_error(tmp_path):
    env = {**os.environ, "ROLLQP_THREADS": "many"}
    proc = subprocess.run([sys.executable, "-m", "rollqp.cli", "scenes"], capture_output=True, text=True,
                          timeout=120, env=env, cwd=tmp_path)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr, proc.stderr
    assert proc.stderr.strip().splitlines() == [proc.stderr.strip()] and "ROLLQP_THREADS" in proc.stderr


@pytest.mark.parametrize("value", ["0", "-1", "1.5", "", "100000"])
def test_threads_checks_its_range(value):
    with pytest.raises(InputError, match="ROLLQP_THREADS"):
        threads({"ROLLQP_THREADS": value})
