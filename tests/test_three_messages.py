"""A 3D scene in the user's words: μ = 0 runs as in 2D, creepages far beyond any rolling contact are
refused naming the key and the range, the summary of a resumed run says whose wall time it is,
``rollqp stresses`` takes a 3D result, and ``rollqp scenes`` tags every scene by its
dimension. Coarse grids: each run takes a fraction of a second."""
from __future__ import annotations

import json

import numpy as np
import pytest

from rollqp import cli, load_scene
from rollqp.errors import InputError
from rollqp.scene import builtin_scenes
from rollqp.report.grid import summary
from rollqp.march.grid import run


def coarse(name: str, **changes):
    s = load_scene(name)
    nx, ny = s.discretization.elements
    k = 12 / min(nx, ny)
    return s.replace(**{"discretization.elements": [round(nx * k), round(ny * k)], "discretization.zone": [1.3, 1.3],
                        **changes})


# ------------------------------------------------------------------------------------------- μ = 0
def test_frictionless_rolling_has_zero_tractions_and_slips_where_the_creepages_move_it(tmp_path):
    scene = coarse("kalker-elliptic", **{"contact.friction": 0.0})
    res = run(scene)
    a = res.arrays()
    assert np.all(a["px"] == 0) and np.all(a["py"] == 0) and np.all(a["Fx"] == 0) and np.all(a["Fy"] == 0)
    np.testing.assert_array_equal(a["creepage"][-1], [-1.4e-3, 6e-4, 1.2e-3])      # as prescribed
    p, st = a["pn"][-1], a["state"][-1]
    # every element in contact slips (the rigid slip w = (ξ − φy, η + φx) is nowhere zero on it), and the
    # slip is the rigid slip (t = 0: no elastic part)
    assert np.all(st[p > 0] == 2) and np.all(st[p <= 0] == 0)
    X, Y = np.meshgrid(a["x"], a["y"])
    np.testing.assert_allclose(a["sx"][-1], -1.4e-3 - 1.2e-3 * Y, rtol=0, atol=1e-15)
    np.testing.assert_allclose(a["sy"][-1], 6e-4 + 1.2e-3 * X, rtol=0, atol=1e-15)
    text = summary(a, scene, "newton", 1.0)
    assert "nan" not in text and "inf" not in text and "frictionless (mu = 0)" in text
    from rollqp.plot import three_figure
    three_figure(a, scene, str(tmp_path / "f.png"))
    assert (tmp_path / "f.png").stat().st_size > 0


def test_frictionless_braked_start_without_force_sticks_as_in_2d():
    """A braked start at μ = 0 with no tangential force: t = 0, ξ = 0, nothing moves, every element in
    contact 'sticks' — 2D's classification (rollqp.problem.solution.classify) at μ = 0 and Q = 0."""
    scene = coarse("cattaneo-3d", **{"contact.friction": 0.0, "load.tangential": 0.0, "discretization.distance": 0.5})
    a = run(scene).arrays()
    assert np.all(a["px"] == 0) and np.all(a["creepage"] == 0)
    assert np.all(a["state"][a["pn"] > 0] == 1)
    two = load_scene("cattaneo-carter").replace(**{"contact.friction": 0.0, "load.tangential": 0.0,
                                                   "discretization.distance": 0.5})
    from rollqp import run as run_any
    b = run_any(two).arrays()
    assert np.all(b["state"][b["pn"] > 0] == 1)


def test_frictionless_with_a_force_is_one_line():
    with pytest.raises(InputError, match=r"^load\.tangential: must be 0 when contact\.friction = 0") as err:
        load_scene("cattaneo-3d").replace(**{"contact.friction": 0.0})
    assert "\n" not in str(err.value)


# ------------------------------------------------------------------------------------ creepage range
@pytest.mark.parametrize("key, value, what", [("longitudinal", 1e30, r"\|xi\| = 1e\+30"),
                                              ("lateral", -3.0, r"\|eta\| = 3"),
                                              ("spin", 1e6, r"\|phi\|·max\(a, b\) = 8\.486e\+05")])
def test_a_creepage_beyond_any_rolling_contact_is_refused(key, value, what):
    with pytest.raises(InputError, match=rf"^load\.creepage\.{key}: {what} at q = 0 a must be <= 1") as err:
        load_scene("kalker-elliptic").replace(**{f"load.creepage.{key}": value})
    assert "\n" not in str(err.value)


def test_a_creepage_history_is_checked_at_its_peak():
    ramp = {"kind": "ramp", "start": 0.0, "end": 5.0, "over": 1.0}
    with pytest.raises(InputError, match=r"^load\.creepage\.longitudinal: \|xi\| = 5 at q = 1 a"):
        load_scene("kalker-circular").replace(**{"load.creepage.longitudinal": ramp})


def test_full_sliding_creepages_are_still_allowed():
    s = load_scene("kalker-elliptic").replace(**{"load.creepage.longitudinal": -0.5, "load.creepage.spin": 1.0})
    assert s.load.creepage.longitudinal(0.0) == -0.5


# ------------------------------------------------------------------------------------ the CLI
def test_resumed_summary_names_the_steps_its_wall_time_covers():
    scene = coarse("cattaneo-3d", **{"discretization.distance": 1.0})
    full = run(scene).arrays()
    part = {k: (v[:3] if np.ndim(v) and k not in ("x", "y") else v) for k, v in full.items()}
    resumed = run(scene, resume=part).arrays()
    assert json.loads(str(resumed["meta"]))["resumed_from"] == 2
    row = next(line for line in summary(resumed, scene, "newton", 0.5).splitlines() if "wall time" in line)
    K = len(resumed["q"]) - 1
    assert f"0.500 s for steps 3..{K} resumed here" in row and f"all {K} steps with the earlier run" in row
    fresh = next(line for line in summary(full, scene, "newton", 0.5).splitlines() if "wall time" in line)
    assert "resumed" not in fresh


def test_stresses_on_a_3d_result_computes_its_field(tmp_path, capsys, monkeypatch):
    """No more "no key 'pt'": a 3D result goes to the 3D subsurface field (docs/stresses.md)."""
    monkeypatch.chdir(tmp_path)
    run(coarse("kalker-elliptic")).save(tmp_path / "k.npz")
    assert cli.main(["stresses", "k.npz", "--step", "0"]) == 0
    out = capsys.readouterr()
    assert "no key 'pt'" not in out.err and "state" in out.out


def test_scenes_tags_every_scene_by_its_dimension(capsys):
    assert cli.main(["scenes"]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    for line in lines:
        name, tag = line.split()[:2]
        assert tag == f"{load_scene(name).dimension}D", line
        assert "3D:" not in line, f"no tag of its own in the description: {line}"
    assert {n for n in builtin_scenes() if load_scene(n).dimension == 3} >= {"kalker-circular", "kalker-elliptic",
                                                                              "cattaneo-3d", "ball-in-groove"}
