"""CONTACT's spence35 as a scene file run by the command line (tests/data/contact3d/spence35.toml; docs/validation3d.md
§14): Spence's load stages are scene keys — load.rolled held at 0 (every step a static shift step from the state
before), load.normal_history a table whose breakpoints are the steps — and `rollqp run` reproduces CONTACT's
reference output stage by stage, as the API test (tests/test_spence35.py) does."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from rollqp import load_scene
from rollqp.result import load_result

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "data" / "contact3d"
sys.path.insert(0, str(ROOT / "tests"))
from test_spence35 import _reference  # noqa: E402  (CONTACT's printed stages, parsed once)


def _input_loads():
    return [float(line.split()[0]) for line in (DATA / "spence35.inp").read_text().splitlines() if "FN, CKSI" in line]


def test_the_scene_s_stages_are_contact_s_loads():
    """Step k of the scene is stage k + 1: its normal force is CONTACT's input FN to round-off (measured 1.1e-16),
    and the run has exactly the 35 stages."""
    s = load_scene(DATA / "spence35.toml")
    FN = s.load.normal * s.load.normal_history(s.time_steps / s.ellipse.a)
    assert s.n_steps == 34 and np.allclose(FN, _input_loads(), rtol=1e-15, atol=0)
    assert set(np.diff(s.q_steps)) == {0.0}                     # no rolling: static shift steps only


@pytest.mark.parametrize("n", [12, pytest.param(35, marks=pytest.mark.slow)])
def test_rollqp_run_reproduces_spence35(n, tmp_path):
    """`rollqp run` on the scene (the first n stages): the approach and the peak pressure within CONTACT's 4 printed
    digits at every stage (bound 5e-4, half a unit of the 4th digit at a mantissa of 1; measured over the 35:
    approach 2.5e-4 (stage 4), peak pressure 4.0e-4 (stage 15)), and the contact, adhesion and slip counts equal to
    those CONTACT prints (stages 1, 6, 18 and 35: 1/1/0, 29/5/24, 241/61/180, 921/225/696)."""
    s = load_scene(DATA / "spence35.toml")
    scene = tmp_path / "spence.toml"
    scene.write_text(s.replace(**{"discretization.distance": s.discretization.distance * (n - 1) / 34}).to_toml())
    env = dict(os.environ, PYTHONPATH=str(ROOT), OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    r = subprocess.run([sys.executable, "-m", "rollqp.cli", "run", str(scene), "--out", str(tmp_path / "s.npz")],
                       env=env, cwd=tmp_path, capture_output=True, text=True, timeout=1800)
    assert r.returncode == 0, r.stderr
    assert f"{n - 1} steps: 0 rolling, {n - 1} at rest" in r.stdout      # static steps, not called rolling ones
    assert "spans fewer than two elements" in r.stdout and "error: hertz" not in r.stdout   # stage 1: one element
    a = load_result(tmp_path / "s.npz")
    ref = _reference()[:n]
    assert a["FN"].size == n
    pmax = a["pn"].reshape(n, -1).max(axis=1)
    state = a["state"].reshape(n, -1)
    for i, (k, _, approach, peak, counts) in enumerate(ref):
        assert abs(a["approach"][i] / approach - 1) < 5e-4 and abs(pmax[i] / peak - 1) < 5e-4, (
            k, a["approach"][i], approach, pmax[i], peak)
        if counts is not None:
            assert (int((state[i] > 0).sum()), int((state[i] == 1).sum()), int((state[i] == 2).sum())) == counts, k
