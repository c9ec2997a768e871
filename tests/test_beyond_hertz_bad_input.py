"""Every command on a 3D scene refuses bad input in one line naming the key (SPEC, "Three dimensions: beyond
Hertz"; docs/scenes.md): a table of bad scene keys and bad options per command — `run`, `run --keep-every`,
`sweep`, `creep-curve`, `export-step`, `check-step`, `stresses` — each run through the command line
(`rollqp.cli.main`), which must exit with 2 and print exactly one line, `rollqp: error: KEY: …`, with no traceback."""
from __future__ import annotations

import json

import numpy as np
import pytest

import rollqp
from rollqp import cli

pytest.importorskip("xarray")
pytest.importorskip("zarr")

SMALL = {"discretization.elements": [12, 12], "discretization.distance": 0.5}

#: (label, changes to kalker-circular (12 × 12, 0.5 a), the key the one line must name)
SCENE_KEYS = [
    ("radius", {"bodies.A.radius": -1.0}, "bodies.A.radius"),
    ("lateral profile y not increasing", {"bodies.A.radius_y": None, "bodies.A.profile": {"kind": "lateral", "y": [0.0, -1.0, 1.0],
                                                                "z": [0.0, 0.1, 0.1]}}, "bodies.A.profile"),
    ("surface profile of the wrong shape", {"bodies.A.radius": None, "bodies.A.radius_y": None, "bodies.A.profile": {"kind": "surface", "x": [-1.0, 1.0], "y": [-1.0, 1.0],
                                                                  "z": [[0.0, 0.0, 0.0], [0.0, 0.0]]}},
     "bodies.A.profile"),
    ("defect without depth", {"bodies.A.profile": [{"kind": "defect", "x": 0.0, "y": 0.0, "length": 0.5,
                                                    "width": 0.5}]}, "bodies.A.profile"),
    ("wear negative", {"bodies.A.wear": -1e-9}, "bodies.A.wear"),
    ("wear beyond 1/p0", {"bodies.A.wear": 1.0}, "bodies.A.wear"),
    ("friction negative", {"contact.friction": -0.1}, "contact.friction"),
    ("friction table rows", {"contact.friction": {"law": "table", "x": [-1.0, 1.0], "y": [-1.0, 1.0],
                                                  "values": [[0.2, 0.3]]}}, "contact.friction"),
    ("friction patch y bounds", {"contact.friction": {"law": "patch", "mu": 0.3, "inside": 0.1, "start": -0.5,
                                                      "end": 0.5, "y_start": 0.5, "y_end": -0.5}}, "contact.friction.y_"),
    ("friction law unknown", {"contact.friction": {"law": "sticky"}}, "contact.friction.law"),
    ("normal load zero", {"load.normal": 0.0}, "load.normal"),
    ("normal history negative", {"load.normal_history": {"kind": "constant", "value": -1.0}}, "load.normal_history"),
    ("normal history kind", {"load.normal_history": {"kind": "sine"}}, "load.normal_history.kind"),
    ("rolled too fast", {"load.rolled": {"kind": "ramp", "start": 0.0, "end": 40.0, "over": 0.5}}, "load.rolled"),
    ("creepage text", {"load.creepage.longitudinal": "fast"}, "load.creepage.longitudinal"),
    ("tangential beyond sliding", {"load.creepage.longitudinal": None, "load.tangential": 1.2}, "load.tangential"),
    ("lateral beyond sliding", {"load.creepage.lateral": None, "load.lateral": -1.5}, "load.lateral"),
    ("elements", {"discretization.elements": [0, 12]}, "discretization.elements"),
    ("zone below the ellipse", {"discretization.zone": [0.9, 1.25]}, "discretization.zone"),
    ("extent without the origin", {"discretization.zone": None, "discretization.extent": [[0.1, 1.0], [-1.0, 1.0]]},
     "discretization.extent"),
    ("element_size without extent", {"discretization.element_size": [0.1, 0.1]}, "discretization.element_size"),
    ("extent short of the computed contact", {"bodies.A.radius_y": None, "discretization.zone": None,
                                              "bodies.A.profile": {"kind": "lateral", "y": [-3.0, 0.0, 3.0],
                                                                   "z": [0.05, 0.0, 0.05]},
                                              "discretization.extent": [[-0.6, 0.6], [-0.3, 0.3]]},
     "discretization.extent"),
    ("step", {"discretization.step": 0.0}, "discretization.step"),
    ("distance", {"discretization.distance": -1.0}, "discretization.distance"),
]


def _scene_file(tmp_path, changes, name="bad"):
    d = rollqp.load_scene("kalker-circular").replace(**SMALL).to_dict()
    for key, value in changes.items():
        *path, leaf = key.split(".")
        node = d
        for p in path:
            node = node.setdefault(p, {})
        if value is None:
            node.pop(leaf, None)
        else:
            node[leaf] = value
    import tomli_w
    f = tmp_path / f"{name}.toml"
    f.write_bytes(tomli_w.dumps(_toml_safe(d)).encode())
    return f


def _toml_safe(v):
    if isinstance(v, dict):
        return {k: _toml_safe(x) for k, x in v.items() if x is not None}
    if isinstance(v, (list, tuple)):
        return [_toml_safe(x) for x in v]
    if isinstance(v, float) and not np.isfinite(v):
        return v
    return v


def _one_line(capsys, argv, key):
    try:
        code = cli.main([str(a) for a in argv])
    except SystemExit as stop:      # an option's type, refused by the parser (one line from the script too)
        code = stop.code
    err = capsys.readouterr().err
    assert code == 2, (code, err)
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert err.startswith((f"rollqp: error: {key}", f"rollqp: error: argument {key}")), err
    return err


@pytest.mark.parametrize("label, changes, key", SCENE_KEYS, ids=[c[0] for c in SCENE_KEYS])
@pytest.mark.parametrize("command", ["run", "sweep", "export-step"])
def test_a_bad_3d_scene_key_is_one_line_naming_it(command, label, changes, key, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    f = _scene_file(tmp_path, changes)
    extra = {"run": ["--quiet", "--out", tmp_path / "r.npz"],
             "sweep": ["--vary", "contact.friction=0.2,0.3", "--workers", "0", "--quiet", "--out", tmp_path / "s.zarr"],
             "export-step": ["--step", "1", "--out", tmp_path / "st.npz"]}[command]
    _one_line(capsys, [command, f, *extra], key)


@pytest.fixture(scope="module")
def result3d(tmp_path_factory):
    folder = tmp_path_factory.mktemp("r3")
    scene = folder / "s.toml"
    scene.write_text(rollqp.load_scene("cattaneo-3d").replace(**SMALL).to_toml())
    out = folder / "r.npz"
    assert cli.main(["run", str(scene), "--quiet", "--out", str(out)]) == 0
    step = folder / "st.npz"
    assert cli.main(["export-step", str(scene), "--step", "1", "--out", str(step)]) == 0
    return scene, out, step


def _bad_solution(folder, step, kind):
    with np.load(step) as z:
        n = int(z["nx"]) * int(z["ny"])
    f = folder / f"sol-{kind}.npz"
    if kind == "shape":
        np.savez(f, p=np.zeros(7), t=np.zeros((2, 7)))
    elif kind == "nan":
        np.savez(f, p=np.full(n, np.nan), t=np.zeros((2, n)))
    elif kind == "good":
        np.savez(f, p=np.zeros(n), t=np.zeros((2, n)))
    else:
        f.write_bytes(b"not an npz")
    return f


OPTIONS = [
    ("run --keep-every 0", lambda r, f: ["run", r[0], "--keep-every", "0", "--quiet", "--out", f / "k.npz"],
     "--keep-every"),
    ("run --keep-every text", lambda r, f: ["run", r[0], "--keep-every", "x", "--quiet", "--out", f / "k.npz"],
     "--keep-every"),
    ("sweep unknown key", lambda r, f: ["sweep", r[0], "--vary", "contact.stickiness=1,2", "--workers", "0",
                                        "--out", f / "a.zarr"], "--vary"),
    ("sweep bad point", lambda r, f: ["sweep", r[0], "--vary", "contact.friction=0.2,-1", "--workers", "0",
                                      "--out", f / "b.zarr"], "--vary"),
    ("sweep store name", lambda r, f: ["sweep", r[0], "--vary", "contact.friction=0.2", "--workers", "0",
                                       "--out", f / "c.npz"], "--out"),
    ("creep-curve axis", lambda r, f: ["creep-curve", r[0], "--creepage", "vertical", "--workers", "0",
                                       "--out", f / "d.zarr"], "--creepage"),
    ("creep-curve values", lambda r, f: ["creep-curve", r[0], "--values", "1e-4,nan", "--workers", "0",
                                         "--out", f / "e.zarr"], "--values"),
    ("creep-curve 2D option", lambda r, f: ["creep-curve", r[0], "--ratios", "0.1", "--workers", "0",
                                            "--out", f / "g.zarr"], "--ratios"),
    ("export-step beyond the run", lambda r, f: ["export-step", r[0], "--step", "999", "--out", f / "x.npz"],
     "--step"),
    ("export-step negative", lambda r, f: ["export-step", r[0], "--step", "-1", "--out", f / "x.npz"], "--step"),
    ("check-step wrong shape", lambda r, f: ["check-step", r[2], _bad_solution(f, r[2], "shape")], "SOLUTION.npz"),
    ("check-step not finite", lambda r, f: ["check-step", r[2], _bad_solution(f, r[2], "nan")], "SOLUTION.npz"),
    ("check-step not an npz", lambda r, f: ["check-step", r[2], _bad_solution(f, r[2], "junk")], "SOLUTION.npz"),
    ("check-step tolerance", lambda r, f: ["check-step", r[2], _bad_solution(f, r[2], "good"), "--tol", "-1"],
     "--tol"),
    ("stresses step", lambda r, f: ["stresses", r[1], "--step", "999"], "--step"),
    ("stresses plane axis", lambda r, f: ["stresses", r[1], "--step", "1", "--plane", "z=1"], "--plane"),
    ("stresses plane value", lambda r, f: ["stresses", r[1], "--step", "1", "--plane", "y=abc"], "--plane"),
    ("stresses line", lambda r, f: ["stresses", r[1], "--step", "1", "--line", "x=0"], "--line"),
    ("stresses depths", lambda r, f: ["stresses", r[1], "--step", "1", "--depths", "0.1,-0.2"], "--depths"),
    ("stresses plane and line", lambda r, f: ["stresses", r[1], "--step", "1", "--plane", "y=0", "--line",
                                              "x=0,y=0"], "--line"),
    ("stresses 2D grid", lambda r, f: ["stresses", r[1], "--step", "1", "--grid", "10,10"], "--grid"),
]


@pytest.mark.parametrize("label, argv, key", OPTIONS, ids=[c[0] for c in OPTIONS])
def test_a_bad_option_on_a_3d_scene_or_result_is_one_line_naming_it(label, argv, key, result3d, tmp_path, capsys,
                                                                      monkeypatch):
    monkeypatch.chdir(tmp_path)
    _one_line(capsys, argv(result3d, tmp_path), key)


def test_the_table_covers_every_command_of_the_section():
    """sweep, creep-curve, export-step, check-step, stresses and --keep-every (SPEC's list) each have rows."""
    commands = {c[0].split()[0] for c in OPTIONS} | {"run"}
    assert commands >= {"run", "sweep", "creep-curve", "export-step", "check-step", "stresses"}
    assert any("--keep-every" in c[0] for c in OPTIONS)
    assert json.dumps([c[2] for c in SCENE_KEYS])   # every scene row names its key
