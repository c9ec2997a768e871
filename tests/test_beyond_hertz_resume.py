"""A 3D sweep store is resumable as a 2D one is (rollqp.sweep.three; docs/sweeps.md, "Three dimensions"): a
sweep interrupted (Ctrl-C through the API, SIGKILL of ``rollqp sweep``) and run again computes only the points
it had not saved and writes the same Dataset as a sweep that never stopped (the wall times aside); a finished
store of the same sweep is opened without computing; another sweep's store is refused naming ``--out``."""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

xr = pytest.importorskip("xarray")
pytest.importorskip("zarr")

import rollqp  # noqa: E402
from rollqp import load_scene  # noqa: E402
from rollqp.errors import InputError  # noqa: E402
from rollqp.sweep.three import POINTS, sweep_3d  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
TIMES = ("step_time", "point_time")     # wall seconds: the only variables that differ between two runs
VARY = ["load.creepage.longitudinal=1e-4,3e-4,1e-3", "contact.friction=0.2,0.3"]


def _circle(n=10):
    return load_scene("kalker-circular").replace(**{"discretization.elements": [n, n]})


def _same(a, b):
    assert set(a.data_vars) == set(b.data_vars) and set(a.coords) == set(b.coords)
    for name in list(a.data_vars) + list(a.coords):
        if name not in TIMES:
            np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)
    assert {k: v for k, v in a.attrs.items()} == {k: v for k, v in b.attrs.items()}


def test_an_interrupted_3d_sweep_resumes_with_only_the_missing_points(tmp_path):
    whole, s0 = sweep_3d(_circle(), VARY, tmp_path / "whole.zarr", workers=0)
    assert s0.done == 6 and s0.kept == 0

    def stop_after_two(i, out, seen=[]):
        seen.append(i)
        if len(seen) == 2:
            raise KeyboardInterrupt
    ds, s1 = sweep_3d(_circle(), VARY, tmp_path / "cut.zarr", workers=0, on_point=stop_after_two)
    assert ds is None and s1.interrupted and s1.done == 2
    assert sorted(os.listdir(tmp_path / "cut.zarr" / POINTS)) == ["0.npz", "1.npz"]
    ran = []
    ds, s2 = sweep_3d(_circle(), VARY, tmp_path / "cut.zarr", workers=0, on_point=lambda i, out: ran.append(i))
    assert ran == [2, 3, 4, 5] and s2.kept == 2 and s2.done == 4 and "2 kept" in s2.table()
    _same(xr.open_zarr(tmp_path / "cut.zarr", chunks=None).load(), whole)
    assert not (tmp_path / "cut.zarr" / POINTS).exists()      # the Dataset replaced the saved points
    # a finished store of the same sweep: opened, nothing computed
    ds, s3 = sweep_3d(_circle(), VARY, tmp_path / "cut.zarr", workers=0, on_point=lambda i, out: ran.append(i))
    assert len(ran) == 4 and s3.done == 0 and s3.kept == 6
    _same(ds, whole)


def test_a_failed_point_is_tried_again_by_the_same_sweep(tmp_path, monkeypatch):
    """A point that fails (here: made to, once) leaves the Dataset with status 2 there; the same sweep again
    computes that point only and writes the uninterrupted sweep's Dataset."""
    import rollqp.sweep.three as three
    whole, _ = sweep_3d(_circle(), VARY, tmp_path / "whole.zarr", workers=0)
    real = three.run_point_3d

    def flaky(scene):
        if scene["contact"]["friction"] == 0.3 and scene["load"]["creepage"]["longitudinal"] == 3e-4:
            return {"error": "SolverError: made to fail", "time": 0.0}
        return real(scene)
    monkeypatch.setattr(three, "run_point_3d", flaky)
    ds, s1 = sweep_3d(_circle(), VARY, tmp_path / "f.zarr", workers=0)
    assert s1.done == 5 and [i for i, _ in s1.failed] == [3] and int((ds["status"].values == 2).sum()) == 1
    monkeypatch.setattr(three, "run_point_3d", real)
    ran = []
    ds, s2 = sweep_3d(_circle(), VARY, tmp_path / "f.zarr", workers=0, on_point=lambda i, out: ran.append(i))
    assert ran == [3] and s2.kept == 5 and not s2.failed
    _same(xr.open_zarr(tmp_path / "f.zarr", chunks=None).load(), whole)
    assert not (tmp_path / "f.zarr" / POINTS).exists()


def test_another_sweep_s_3d_store_is_refused_naming_out(tmp_path):
    sweep_3d(_circle(), VARY, tmp_path / "a.zarr", workers=0)
    with pytest.raises(InputError, match=r"^--out: .* holds a different sweep"):
        sweep_3d(_circle(), ["contact.friction=0.2,0.4"], tmp_path / "a.zarr", workers=0)

    def stop(i, out):
        raise KeyboardInterrupt
    sweep_3d(_circle(), VARY, tmp_path / "b.zarr", workers=0, on_point=stop)
    with pytest.raises(InputError, match=r"^--out: .* holds a different 3D sweep being computed"):
        sweep_3d(_circle(12), VARY, tmp_path / "b.zarr", workers=0)


def _saved(store):
    """The points saved in a store being computed (not the temporaries of a write the kill interrupted)."""
    import re
    return [f for f in os.listdir(store / POINTS) if re.fullmatch(r"\d+\.npz", f)]


@pytest.mark.integration
def test_a_killed_rollqp_sweep_of_a_3d_scene_resumes_to_the_same_dataset(tmp_path):
    """SIGKILL of the command once two points are saved; the same command again computes the rest (it says how
    many it kept) and the store equals the uninterrupted sweep's."""
    scene = tmp_path / "base.toml"
    # transient points (a braked start rolled 2 a on 12 x 12): ~0.3 s each, so the kill comes mid-sweep
    base = load_scene("cattaneo-3d").replace(**{"discretization.elements": [12, 12], "discretization.distance": 2.0})
    scene.write_text(base.to_toml())
    vary = "load.tangential=0.1:0.7:8"
    env = dict(os.environ, PYTHONPATH=str(ROOT), OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    cmd = [sys.executable, "-m", "rollqp.cli", "sweep", str(scene), "--vary", vary, "--workers", "0"]
    store = tmp_path / "k.zarr"
    proc = subprocess.Popen(cmd + ["--out", str(store), "--quiet"], env=env, cwd=tmp_path, stderr=subprocess.PIPE)
    deadline = time.time() + 120
    while time.time() < deadline and proc.poll() is None:
        if (store / POINTS).is_dir() and len(_saved(store)) >= 2:
            break
        time.sleep(0.01)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert proc.returncode == -signal.SIGKILL, proc.stderr.read().decode()
    kept = len(_saved(store))
    assert 2 <= kept < 8
    r = subprocess.run(cmd + ["--out", str(store)], env=env, cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    assert f"{8 - kept} done, 0 failed of 8 ({kept} kept from the store" in r.stdout, r.stdout
    r = subprocess.run(cmd + ["--out", str(tmp_path / "whole.zarr"), "--quiet"], env=env, cwd=tmp_path,
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    _same(xr.open_zarr(store, chunks=None).load(), xr.open_zarr(tmp_path / "whole.zarr", chunks=None).load())


def _patch_scene():
    """cattaneo-3d on a coarse grid with a patch whose inside μ (0.6) is above the law's reference μ (0.2)."""
    scene = load_scene("cattaneo-3d")
    return scene.replace(**{"contact.friction": {"law": "patch", "mu": 0.2, "inside": 0.6, "start": -0.6, "end": 0.6},
                            "load.tangential": 0.95, "discretization.elements": [10, 10],
                            "discretization.distance": 1.0})


def test_the_resume_check_takes_each_element_s_own_coefficient(tmp_path):
    """An untouched 3D result whose tractions exceed the reference μ p inside a patch of larger μ is accepted by
    the resume check of earlier states (the disc is each element's stored μ), and a traction pushed beyond its
    own disc is still refused."""
    from rollqp.march.grid import check_states, prepare
    scene, _, contact = prepare(_patch_scene(), None)
    out = tmp_path / "r.npz"
    rollqp.run(scene, out=out)
    arrays = dict(np.load(out))
    t, p = np.hypot(arrays["px"], arrays["py"]), arrays["pn"]
    assert np.max(t[p > 0] / (0.2 * p[p > 0])) > 2.0    # the patch carries more than the reference disc
    check_states(scene, contact, arrays)                  # accepted
    forged = dict(arrays)
    k = np.unravel_index(np.argmax(p[1]), p[1].shape)
    forged["px"] = arrays["px"].copy()
    forged["px"][(1,) + k] = 0.9 * p[(1,) + k]            # beyond μ = 0.6 of every element
    with pytest.raises(InputError, match="friction disc"):
        check_states(scene, contact, forged)
