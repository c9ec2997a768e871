"""A wheel on a rail: profiles, geometry, the contact search and the patches against closed forms and
CONTACT's Manchester benchmark reference outputs (tests/data/wheelrail/)."""
from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from rollqp.errors import InputError
from rollqp.methods import get_method
from rollqp.scene import load_scene
from rollqp.closedforms.hertz_ellipse import hertz
from rollqp.materials import Materials
from rollqp.wheelrail.benchmark import POSITIONS, read_reference
from rollqp.wheelrail.profiles import Profile, read_profile, resolve_file
from rollqp.wheelrail.run import crossval, solve_scene
from rollqp.wheelrail.search import search
from rollqp.wheelrail.solve import solve_wheel
from rollqp.wheelrail.track import Track
from rollqp.wheelrail.wheelset import State, Wheelset

DATA = Path(__file__).parent / "data" / "wheelrail"
PKG = Path(__file__).resolve().parent.parent / "rollqp" / "wheelrail" / "data"


# ----------------------------------------------------------------------------- profiles
def test_shipped_profiles_read_in_canonical_form():
    rail = read_profile(PKG / "MBench_UIC60_v3.prr", "rail")
    wheel = read_profile(PKG / "MBench_S1002_v3.prw", "wheel")
    # the rail: y ascending towards the field side, its crown (lowest z, z down) at the profile's origin
    assert np.all(np.diff(rail.ys) > 0) and abs(rail.ys[np.argmin(rail.zs)]) < 0.05
    # the wheel: the file's own mirror.y = 1 puts the flange (28 mm deep) on the track-centre side (y < 0)
    assert wheel.ys[np.argmax(wheel.zs)] < -50 and abs(np.max(wheel.zs) - 28.0) < 0.01
    # the interpolating spline passes through the points (a cubic in the chord length, sampled every 0.02 mm:
    # the chord error between samples is 0.02²/(8·13) = 4e-6 mm on the 13 mm gauge corner; measured 5e-6)
    head = (rail.y > -38) & (rail.y < 25)
    assert np.max(np.abs(rail.z_at(rail.y[head]) - rail.z[head])) < 1e-5


def _write(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_two_column_table_mirroring_and_scale(tmp_path):
    y = np.linspace(-0.03, 0.03, 31)                       # metres
    text = "% a rail head in metres\n" + "\n".join(f"{a:.6f}, {a * a / 0.6:.9f}" for a in y)
    p = read_profile(_write(tmp_path, "head.txt", text), "rail", scale=1000.0, mirror_y=True)
    assert p.span == pytest.approx((-30.0, 30.0))
    assert float(p.z_at(np.array([10.0]))[0]) == pytest.approx(100 / 600, abs=1e-6)   # the file: 1e-9 m


@pytest.mark.parametrize("text, message", [
    ("0 0\n1 x\n2 0\n3 0\n", "row 2: expected 2 numbers"),
    ("0 0\n1 0\n1 0.1\n3 0\n4 0\n5 0\n6 0\n", "row 3: the lateral coordinate"),
    ("0 0\n0.001 0\n0.002 0\n0.003 0\n", "wrong units"),
    ("0 0\n1 0\n", "at least 4 points"),
    ("0 0\n10 nan\n20 0\n30 0\n", "row 2"),
])
def test_bad_table_files_are_one_line_errors_naming_file_and_row(tmp_path, text, message):
    with pytest.raises(InputError) as err:
        read_profile(_write(tmp_path, "bad.txt", text), "rail", name="bad.txt")
    assert message in str(err.value) and "bad.txt" in str(err.value) and "\n" not in str(err.value)


def test_bad_simpack_files(tmp_path):
    good = (PKG / "MBench_UIC60_v3.prr").read_text()
    with pytest.raises(InputError, match="used here as the wheel profile"):
        read_profile(_write(tmp_path, "r.prr", good), "wheel")
    with pytest.raises(InputError, match=r"r2.prr: row \d+: expected 2 or 3 numbers, got 'spline.end'"):
        read_profile(_write(tmp_path, "r2.prr", good.replace("point.end", "")), "rail")
    bad = good.replace("-4.3702864E+01\t3.8429267E+01", "-4.3702864E+01\tpi")
    with pytest.raises(InputError, match=r"row \d+: expected 2 or 3 numbers"):
        read_profile(_write(tmp_path, "r3.prr", bad), "rail")
    # a wheel with its flange on the field side: mirroring forgotten
    wheel = (PKG / "MBench_S1002_v3.prw").read_text().replace("mirror.y       =  1", "mirror.y       =  0")
    with pytest.raises(InputError, match="flange is on the field side"):
        read_profile(_write(tmp_path, "w.prw", wheel), "wheel")


def test_nothing_outside_the_scene_folder(tmp_path):
    (tmp_path / "inner").mkdir()
    _write(tmp_path, "outside.prr", "0 0\n")
    with pytest.raises(InputError, match="inside the scene file's folder"):
        resolve_file("../outside.prr", "wheelset.rail_profile", tmp_path / "inner")
    with pytest.raises(InputError, match="inside the scene file's folder"):
        resolve_file(str(tmp_path / "outside.prr"), "wheelset.rail_profile", tmp_path / "inner")
    with pytest.raises(InputError, match="no such file"):
        resolve_file("missing.prr", "wheelset.rail_profile", tmp_path)


def test_smoothing_spline_removes_measurement_noise():
    rng = np.random.default_rng(1)
    y = np.linspace(-30, 30, 601)
    z = y ** 2 / 600.0
    noisy = z + 2e-3 * rng.standard_normal(y.size)
    raw = Profile.from_points(y, noisy, "rail")
    smooth = Profile.from_points(y, noisy, "rail", smooth=5.0)
    yy = np.linspace(-20, 20, 401)
    # the curvature (what the contact sees) of the smoothed profile is near 1/300, the raw one's is noise
    curv = lambda p: np.gradient(p.slope_at(yy), yy)              # noqa: E731
    assert np.median(np.abs(curv(smooth) - 1 / 300)) < 0.2 / 300 < np.median(np.abs(curv(raw) - 1 / 300))


# ----------------------------------------------------------------------------- geometry against closed forms
def _crown_rail(R=300.0):
    y = np.concatenate([[-36.0, -35.5], np.linspace(-35.0, 35.0, 701), [35.5, 36.0]])
    z = R - np.sqrt(R ** 2 - np.clip(y, -35, 35) ** 2)
    z[:2], z[-2:] = [40.0, 20.0], [20.0, 40.0]
    return Profile.from_points(y, z, "rail", name="crown")


def _cylinder_wheel(conicity=0.0):
    y = np.linspace(-40.0, 40.0, 161)
    return Profile.from_points(y, -conicity * y, "wheel", name="cylinder")


def _aligned(track, ws):
    return track.rail_y0 - ws.offset


@pytest.mark.parametrize("element", [0.5, 0.25])
def test_cylinder_on_a_crowned_rail_is_hertz(element):
    """A cylindrical wheel (R 460) on a rail head of radius 300: the Hertz ellipse of A = 1/920, B = 1/600.
    The peak pressure and the approach converge to Hertz's as the elements halve (centre collocation:
    O(dx) in pmax, measured 1.1 % at 0.5 mm and 0.5 % at 0.25 mm)."""
    track, ws = Track(_crown_rail(), 1435.0, 14.0), Wheelset(_cylinder_wheel(), 1360.0, -70.0, 460.0)
    mat = Materials.from_young(210e3, 0.3, 210e3, 0.3)
    st = State(lateral=_aligned(track, ws), speed=2000.0, pitch_rate=-2000.0 / 460.0)
    res = solve_wheel(track, ws, st, mat, 0.3, 10000.0, element, element, get_method("newton", 3), side="right")
    (p,) = res.patches
    e = hertz(1 / 920, 1 / 600, mat.Estar, 10000.0)
    assert p.angle == pytest.approx(0.0, abs=1e-6) and abs(p.y_rail) < 0.01
    assert res.force_rail[2] == pytest.approx(10000.0, rel=1e-7) and p.FN == pytest.approx(10000.0, rel=1e-7)
    err_p, err_d = abs(p.pmax / e.p0 - 1), abs(p.approach / e.delta - 1)
    assert err_p < 0.025 * element / 0.5 and err_d < 0.02 * element / 0.5
    # free rolling at the nominal radius with no yaw: no creepage, no creep force
    assert max(abs(c) for c in p.creepage) < 1e-12 and abs(p.Fx) < 1e-6 * p.FN and abs(p.Fs) < 1e-6 * p.FN


def test_conical_wheel_contact_angle_and_creepages_closed_form():
    """A cone of conicity 1:40 on the crown, laterally shifted by 2 mm and yawed: the contact point sits
    where the crown's slope is the cone's (y_rail = R·tan γ, δ = −γ), ξ from the rolling radius there,
    η = ψ cos δ, φ = Ω sin δ / V (WR.3)."""
    gamma = math.atan(1 / 40)
    track, ws = Track(_crown_rail(), 1435.0, 14.0), Wheelset(_cylinder_wheel(1 / 40), 1360.0, -70.0, 460.0)
    psi, V, Om = 2e-3, 2000.0, -2000.0 / 460.0
    st = State(lateral=_aligned(track, ws) + 2.0, yaw=psi, speed=V, pitch_rate=Om)
    (p,) = search(track, ws, State(lateral=st.lateral, yaw=psi, vertical=0.05, speed=V, pitch_rate=Om), 0.25, 0.25)
    y_rail = p.origin[1] - track.rail_y0
    assert p.angle == pytest.approx(-gamma, abs=2e-4) and y_rail == pytest.approx(-300 * math.tan(gamma), abs=0.05)
    ex, es, en = p.axes
    xi, eta, phi = ws.creepages(st, p.wheel_point, ex, es, en)
    Vr = ws.rolling_speed(st, p.wheel_point, ex, es)
    rho = math.hypot(*((p.wheel_point - ws.centre(st)) @ ws.rotation(st))[[0, 2]])
    assert eta == pytest.approx(V * psi * math.cos(p.angle) / Vr, rel=2e-3)
    assert phi == pytest.approx(Om * math.cos(psi) * math.sin(p.angle) / Vr, rel=1e-9)
    assert xi == pytest.approx((-V - Om * math.cos(psi) * rho) / Vr, rel=1e-3, abs=1e-9)


# ----------------------------------------------------------------------------- CONTACT's benchmark
def _ref(side, case):
    return next(c for c in read_reference(DATA / f"mbench_a22_{side}.ref_out") if c["case"] == case)


def _bench(side, case, element=0.2):
    y, yaw, roll, pitch = POSITIONS[case - 1]
    scene = load_scene("wheel-rail").replace(**{"wheelset.lateral": y, "wheelset.yaw": yaw, "wheelset.roll": roll,
                                               "wheelset.pitch_rate": pitch, "wheelset.side": side,
                                               "discretization.element_size": element})
    (w,) = solve_scene(scene)
    return w


@pytest.mark.parametrize("side, case", [("left", 1), ("right", 5), ("left", 14)])
def test_benchmark_positions_against_contact(side, case):
    """Positions of A-2.2 at CONTACT's 0.2 mm elements: every patch's normal force and creep forces within 1 %
    of the wheel load, the contact reference within 0.2 mm (docs/validation-wheel-rail.md: measured ≤ 0.15 %
    and ≤ 0.03 mm on these)."""
    w, ref = _bench(side, case), _ref(side, case)
    assert len(w.patches) == len(ref["patches"]) == 1
    p, r = w.patches[0], ref["patches"][0]
    for ours, theirs in ((p.FN, r["FN"]), (p.Fx, r["FX"]), (p.Fs, r["FS"])):
        assert abs(ours - theirs) <= 0.01 * 10000.0
    assert abs(p.y_rail - r["YCP_R"]) <= 0.2 and abs(p.origin[0] - r["XCP_TR"]) <= 0.2
    assert abs(p.angle - r["DELTCP"]) <= 2e-3
    assert np.allclose(w.force_rail, [ref["FX_TR"], ref["FY_TR"], ref["FZ_TR"]], atol=100.0)


def test_reference_reader():
    cases = read_reference(DATA / "mbench_a22_right.ref_out")
    assert len(cases) == 21 and all(c["wheel"] == "right" and len(c["patches"]) == 1 for c in cases)
    assert cases[0]["patches"][0]["FN"] == 9997.0 and cases[0]["patches"][0]["APPROACH"] == pytest.approx(1.596e-2)


def test_tangential_steps_cross_checked_by_clarabel():
    rows = crossval(load_scene("wheel-rail"), ["socp-clarabel"], tolerance=1e-10)
    assert len(rows) == 2
    for side, k, name, dp, dt, res, sec, raw in rows:
        assert dp < 1e-7 and dt < 1e-7 and res < 1e-9           # the 3D cross-check's agreement (AGREEMENT)
        assert raw is None or raw < 1e-5                        # Clarabel's own answer at its tolerance


# ----------------------------------------------------------------------------- scenes and errors
def test_no_contact_and_bad_scene_keys_name_the_key(tmp_path):
    scene = load_scene("wheel-rail")
    with pytest.raises(InputError, match="wheelset.vertical: the right wheel does not touch its rail"):
        solve_scene(scene.replace(**{"wheelset.load": None, "wheelset.vertical": -5.0, "wheelset.side": "right"}))
    with pytest.raises(InputError, match="wheelset.load"):
        scene.replace(**{"wheelset.vertical": 0.1})
    with pytest.raises(InputError, match="wheelset.sidee"):
        scene.replace(**{"wheelset.sidee": "left"})
    with pytest.raises(InputError, match="discretization.element_size"):
        scene.replace(**{"discretization.element_size": 0.0})
    with pytest.raises(InputError, match="discretization.element_size"):
        solve_scene(scene.replace(**{"discretization.element_size": 0.001, "wheelset.side": "left"}))
    text = scene.to_toml().replace('"MBench_UIC60_v3.prr"', '"../MBench_UIC60_v3.prr"')
    (tmp_path / "s.toml").write_text(text)
    with pytest.raises(InputError, match="inside the scene file's folder"):
        solve_scene(load_scene(tmp_path / "s.toml"))


def test_rollqp_run_prints_patches_and_writes_the_keys(tmp_path):
    out = tmp_path / "wr.npz"
    r = subprocess.run([sys.executable, "-m", "rollqp.cli", "run", "wheel-rail", "--out", str(out)], capture_output=True,
                       text=True, cwd=tmp_path, env={**os.environ, "PYTHONPATH": str(Path(__file__).parent.parent)})
    assert r.returncode == 0, r.stderr
    assert "left wheel" in r.stdout and "contact angle" in r.stdout and "pmax" in r.stdout
    z = np.load(out)
    for k in ("patch_wheel", "patch_FN", "patch_Fx", "patch_Fy", "patch_Mz", "patch_y_rail", "patch_angle",
              "patch_area", "patch_pmax", "wheel_force", "patch0_pn", "patch0_px", "patch0_py", "patch0_state"):
        assert k in z.files
    assert z["wheel_force"].shape == (2, 3) and np.allclose(z["wheel_force"][:, 2], -10000.0)


def test_tread_and_flange_two_patches_share_the_wheel_load():
    """Case 11 of A-2.2, right wheel: flange root and tread both overlap, 7 mm apart. Two patches (default
    combine = 4 mm) share one vertical position: their vertical forces add up to the load; with combine =
    8 mm (CONTACT's D_SEP) one patch, whose forces agree with CONTACT's combined patch within 0.5 % of the load
    (docs/validation-wheel-rail.md, "Case 11")."""
    w = _bench("right", 11)
    assert len(w.patches) == 2 and all(p.FN > 0 for p in w.patches)
    assert w.force_rail[2] == pytest.approx(10000.0, rel=1e-7)
    assert {round(p.y_rail) for p in w.patches} == {-34, -24}
    y, yaw, roll, pitch = POSITIONS[10]
    scene = load_scene("wheel-rail").replace(**{"wheelset.lateral": y, "wheelset.yaw": yaw, "wheelset.roll": roll,
                                               "wheelset.pitch_rate": pitch, "wheelset.side": "right",
                                               "discretization.element_size": 0.2, "discretization.combine": 8.0})
    (one,) = solve_scene(scene)
    (p,), (r,) = one.patches, _ref("right", 11)["patches"]
    for ours, theirs in ((p.FN, r["FN"]), (p.Fx, r["FX"]), (p.Fs, r["FS"])):
        assert abs(ours - theirs) <= 0.005 * 10000.0


def test_a_profile_files_own_file_key_is_never_opened(tmp_path):
    """SIMPACK's ``file = '…'`` names the profile's original data: read as text, never used as a path."""
    text = (PKG / "MBench_UIC60_v3.prr").read_text().replace("'UIC60_v3.rai.txt'", "'/nonexistent/../../etc/passwd'")
    p = read_profile(_write(tmp_path, "r.prr", text), "rail")
    assert p.span == read_profile(PKG / "MBench_UIC60_v3.prr", "rail").span


def test_smoothed_profiles_in_a_scene():
    """``wheel_smooth``/``rail_smooth`` (mm): the smoothing spline through the scene; a 1 mm wavelength barely
    moves the benchmark's smooth profiles (the contact's normal force within 1 % of the load)."""
    base = load_scene("wheel-rail").replace(**{"wheelset.side": "right"})
    (a,) = solve_scene(base)
    (b,) = solve_scene(base.replace(**{"wheelset.wheel_smooth": 1.0, "wheelset.rail_smooth": 1.0}))
    assert abs(a.patches[0].FN - b.patches[0].FN) < 100.0 and abs(a.patches[0].y_rail - b.patches[0].y_rail) < 0.2


def test_python_api_runs_a_wheel_rail_scene_with_its_method():
    """rollqp.run takes a wheel–rail scene as the command line does (its own runner, the method by name);
    rollqp.march refuses it in one line (one state per wheel, nothing to march)."""
    import rollqp
    scene = load_scene("wheel-rail").replace(**{"wheelset.side": "right"})
    res = rollqp.run(scene, method="newton")
    arrays = res.arrays()
    assert arrays["patch_FN"].size >= 1 and np.all(arrays["patch_FN"] > 0)
    with pytest.raises(InputError, match=r"^scene: .*rollqp\.run"):
        rollqp.march(scene)
    with pytest.raises(InputError, match=r"^solver\.method"):
        rollqp.run(scene, method="qp-osqp")
