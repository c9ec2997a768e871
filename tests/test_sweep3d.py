"""Sweeps and creep-force curves of 3D scenes (rollqp.sweep.three; docs/sweeps.md, "Three dimensions"): the
creep curve's slope at the origin against Kalker's linear theory as the grid is refined, the saturation
at μFN, CONTACT's tractcurv series on CONTACT's grid, the labelled store, and bad input in one line."""
from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

pytest.importorskip("xarray")
pytest.importorskip("zarr")

from rollqp import load_scene  # noqa: E402
from rollqp.errors import InputError  # noqa: E402
from rollqp.sweep.three import creep_curve_3d, sweep_3d  # noqa: E402


def _circle(n):
    return load_scene("kalker-circular").replace(**{"discretization.elements": [n, n]})


def test_the_creep_curve_s_slope_at_the_origin_tends_to_kalker_s(tmp_path):
    """Secant slope through ξ = 1e-6 and 2e-6 (the linear theory is the limit of vanishing creepage) on 10, 20,
    40 elements across: measured 6.1 %, 5.0 %, 1.6 % above Kalker's −G c² C11 (first order in h with the
    staircase scatter of the discrete contact, docs/validation3d.md §3, where 64 across gives 0.3–3 %)."""
    errors = []
    for n in (10, 20, 40):
        c = creep_curve_3d(_circle(n), "longitudinal", "1e-6,2e-6", tmp_path / f"c{n}.zarr", workers=0)
        errors.append(abs(c.origin_slope() / c.kalker_slope() - 1))
    assert errors[-1] < 0.025 and errors[-1] < errors[0] / 2, errors


def test_the_creep_curve_saturates_at_mu_fn(tmp_path):
    """At ξ = 1 every element slips and |Fx| is μFN but for the tilt of each traction by the lateral part of the
    elastic slip (measured 1 − |Fx|/(μFN) = 2.3e-8 on 12 × 12: of order (elastic slip/ξ)²); the curve rises
    monotonically towards it."""
    c = creep_curve_3d(_circle(12), "longitudinal", "1e-4,1e-3,3e-3,1.0", tmp_path / "s.zarr", workers=0)
    s = c.scene
    assert 0 <= 1 - abs(c.Fx[-1]) / (s.mu * s.load.normal) < 1e-7
    assert np.all(np.diff(np.abs(c.Fx)) > 0) and np.all(c.Fx < 0)     # ξ > 0: Fx < 0 (CONTACT's sign)
    table = c.table()
    assert "Kalker's linear theory" in table and "saturation" in table
    sl = c.slope()
    assert np.all(np.isfinite(sl)) and abs(sl[-1]) < abs(sl[0])


def test_the_creep_curve_reproduces_contact_s_tractcurv_series(tmp_path):
    """CONTACT's tractcurv series 1 (Coulomb, 48 × 44 on 1.1·(a, b), a/b = 0.5, wheel radius 625 mm, FN =
    106.7 kN, μ = 0.33): the first three CKSI (1e-5, 4e-4, 8e-4) on CONTACT's grid, Fx within its printed 4
    digits (the steady solves of docs/validation3d.md §5, now through the command's preset)."""
    from rollqp.closedforms.hertz_ellipse import curvatures_for_ratio
    sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[1] / "benchmarks"))
    import contact3d_cases
    ref = []
    import re
    for blk in contact3d_cases.blocks("tractcurv")[:3]:
        kin = re.search(r"CKSI\s+CETA\s+CPHI\n\s*\S+\s+\S+\s+\S+\s+(\S+)", blk)
        tot = re.search(r"FRIC.POWER\n\s*\S+\s+(\S+)", blk)
        ref.append((float(kin.group(1)), float(tot.group(1))))
    B = curvatures_for_ratio(0.0008, 0.5)
    G, nu = 82000.0, 0.28
    body = {"E": 2 * G * (1 + nu), "nu": nu}
    d = {"name": "tractcurv", "bodies": {"A": {"radius": 1 / (2 * 0.0008), "radius_y": 1 / (2 * B), **body},
                                         "B": {"radius": float("inf"), "radius_y": float("inf"), **body}},
         "contact": {"dimension": 3, "friction": 0.33},
         "load": {"normal": 106700.0, "start": "rolling", "creepage": {"longitudinal": 1e-5, "lateral": 0.0}},
         "discretization": {"elements": [48, 44], "zone": [1.1, 1.1], "distance": 0.0}}
    from rollqp.scene import scene_from_dict
    c = creep_curve_3d(scene_from_dict(d), "longitudinal", [r[0] for r in ref], tmp_path / "t.zarr", workers=0)
    for (xi, fx), ours in zip(ref, c.Fx):
        assert abs(ours / fx - 1) < 3e-4, (xi, ours, fx)      # CONTACT prints 4 digits


def test_a_3d_sweep_is_one_labelled_store(tmp_path):
    xr = pytest.importorskip("xarray")
    base = _circle(10)
    ds, summary = sweep_3d(base, ["contact.friction=0.2,0.3", "load.creepage.longitudinal=1e-4,1e-3"],
                           tmp_path / "w.zarr", workers=0)
    assert summary.done == 4 and not summary.failed
    back = xr.open_zarr(tmp_path / "w.zarr")
    assert back["pn"].dims == ("contact.friction", "load.creepage.longitudinal", "step", "y", "x")
    assert back["creepage"].dims[-1] == "component" and list(back["component"].values) == ["longitudinal", "lateral",
                                                                                            "spin"]
    assert np.allclose(back["x"].values, base.grid.x) and np.array_equal(back["status"].values, np.ones((2, 2)))
    fx = back["Fx"].isel(step=0).values
    assert np.all(np.abs(fx[1]) >= np.abs(fx[0]) - 1e-9)       # more friction: no less force at each creepage
    assert back["creepage"].sel(component="longitudinal").isel(step=0).values[0, 1] == pytest.approx(1e-3)


def test_bad_3d_sweep_input_is_one_line(tmp_path):
    base = _circle(10)
    with pytest.raises(InputError, match=r"^--vary: point 1 \(contact.friction=-1"):
        sweep_3d(base, ["contact.friction=0.2,-1"], tmp_path / "a.zarr", workers=0)
    (tmp_path / "b.zarr").mkdir()
    with pytest.raises(InputError, match="^--out:"):
        sweep_3d(base, ["contact.friction=0.2"], tmp_path / "b.zarr", workers=0)
    with pytest.raises(InputError, match="^--creepage:"):
        creep_curve_3d(base, "vertical", "1e-4", tmp_path / "c.zarr", workers=0)
    with pytest.raises(InputError, match="^--values:"):
        creep_curve_3d(base, "spin", "1e-4,nan", tmp_path / "c.zarr", workers=0)


def test_the_command_line_takes_3d_creep_curves_and_refuses_2d_options(tmp_path):
    def run(*a):
        return subprocess.run([sys.executable, "-m", "rollqp.cli", *a], capture_output=True, text=True, timeout=600,
                              cwd=tmp_path)
    r = run("creep-curve", "kalker-circular", "--ratios", "0.1,0.2", "--workers", "0")
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and r.stderr.startswith("rollqp: error: --ratios:"), r.stderr
    r = run("creep-curve", "cattaneo-carter", "--creepage", "spin", "--workers", "0")
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "--creepage:" in r.stderr, r.stderr
    r = run("creep-curve", "kalker-circular", "--creepage", "lateral", "--values", "x", "--workers", "0")
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "--values" in r.stderr, r.stderr
