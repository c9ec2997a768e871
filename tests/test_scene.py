"""Scenes (rollqp.scene): derived quantities, validation, TOML round trip, built-ins."""
from __future__ import annotations

import copy
import json
import math

import numpy as np
import pytest

from rollqp.errors import InputError
from rollqp.histories import Constant, Harmonic, Ramp, Table
from rollqp.scene import (METHODS, Body, Contact, Discretization, Load, Scene, SolverSettings,
                          builtin_scenes, load_scene, scene_from_dict)


def base_dict() -> dict:
    """The paper's §6.1.1 scene as a dict (similar steel rollers)."""
    return {
        "name": "test",
        "description": "steel on steel",
        "bodies": {"A": {"radius": 150.0, "E": 210000.0, "nu": 0.3, "shaft_radius": 15.0},
                   "B": {"radius": 300.0, "E": 210000.0, "nu": 0.3, "shaft_radius": 30.0}},
        "contact": {"friction": 0.1, "model": "halfspace", "coupling": "auto"},
        "load": {"normal": 1000.0, "normal_history": {"kind": "constant"},
                 "tangential": {"kind": "constant", "value": 0.75},
                 "start": "braked", "direction": -1},
        "discretization": {"elements": 40, "element": "quadratic", "zone": 1.25, "step": 0.5,
                           "formulation": "material", "distance": 6.0},
        "solver": {"method": "qp-clarabel", "tolerance": 1e-10},
    }


def with_value(d: dict, dotted: str, value) -> dict:
    """A deep copy of ``d`` with ``dotted`` set (or removed if value is ``DELETE``)."""
    d = copy.deepcopy(d)
    parts = dotted.split(".")
    node = d
    for p in parts[:-1]:
        node = node.setdefault(p, {})
    if value is DELETE:
        del node[parts[-1]]
    else:
        node[parts[-1]] = value
    return d


DELETE = object()


def expect_error(d: dict, key: str, *words: str) -> InputError:
    with pytest.raises(InputError) as info:
        scene_from_dict(d)
    msg = str(info.value)
    assert info.value.key == key, f"error key {info.value.key!r}, expected {key!r}: {msg}"
    assert key in msg, f"message names the key {key!r}: {msg}"
    for w in words:
        assert w in msg, f"message mentions {w!r}: {msg}"
    return info.value


ALU = {"radius": 150.0, "E": 70000.0, "nu": 0.33}
STEEL = {"radius": 300.0, "E": 210000.0, "nu": 0.3}


def alu_on_steel(swap: bool = False) -> Scene:
    d = base_dict()
    d["bodies"] = {"A": STEEL, "B": ALU} if swap else {"A": ALU, "B": STEEL}
    d["load"]["tangential"] = {"kind": "constant", "value": 0.0}
    return scene_from_dict(d)


# =========================================================================== derived
def test_steel_on_steel_derived_quantities():
    s = scene_from_dict(base_dict())
    Estar = 1.0 / (2 * (1 - 0.3 ** 2) / 210000.0)
    assert s.Estar == pytest.approx(Estar, rel=1e-14), "E* of similar bodies is E/(2(1-nu^2))"
    assert s.R == pytest.approx(100.0, rel=1e-14), "1/R = 1/150 + 1/300 gives R = 100"
    assert s.beta == 0.0, "beta vanishes for similar materials"
    assert s.kappa == 0.0, "kappa = 2 beta"
    assert s.coupling_level == "off", "auto coupling is off when beta = 0"
    assert s.A.G == pytest.approx(210000.0 / 2.6, rel=1e-14), "G = E/(2(1+nu))"
    a = math.sqrt(4 * 1000.0 * 100.0 / (math.pi * Estar))
    assert s.a_H == pytest.approx(a, rel=1e-14), "a_H = sqrt(4 P R/(pi E*))"
    assert s.p0 == pytest.approx(s.a_H * s.Estar / (2 * s.R), rel=1e-13), "p0 = a E*/(2R)"
    assert math.pi * s.a_H * s.p0 / 2 == pytest.approx(1000.0, rel=1e-13), "P = pi a p0 / 2"


def test_aluminium_on_steel_beta_by_hand():
    s = alu_on_steel()
    GA, GB = 70000.0 / (2 * 1.33), 210000.0 / (2 * 1.3)
    beta = 0.5 * ((1 - 0.66) / GA - (1 - 0.6) / GB) / ((1 - 0.33) / GA - 0 + (1 - 0.3) / GB)
    assert beta == pytest.approx(0.11673597, rel=1e-7), "hand value of beta (sanity)"
    assert s.beta == pytest.approx(beta, rel=1e-13), "Dundurs beta for aluminium on steel"
    assert s.kappa == pytest.approx(2 * beta, rel=1e-13), "kappa = 2 beta"
    assert s.coupling_level == "full", "auto coupling is full when beta != 0"
    swapped = alu_on_steel(swap=True)
    assert swapped.beta == pytest.approx(-s.beta, rel=1e-13), "swapping A and B flips beta"
    assert swapped.Estar == pytest.approx(s.Estar, rel=1e-14), "E* is symmetric"
    Estar = 1 / ((1 - 0.33 ** 2) / 70000.0 + (1 - 0.3 ** 2) / 210000.0)
    assert s.Estar == pytest.approx(Estar, rel=1e-14), "E* by hand"
    assert s.R == pytest.approx(100.0, rel=1e-14), "R by hand"


@pytest.mark.parametrize("level", ["full", "goodman", "off"])
def test_explicit_coupling_level_is_kept(level):
    s = alu_on_steel().replace(**{"contact.coupling": level})
    assert s.coupling_level == level, f"explicit coupling {level!r} is kept"


def test_strip_and_step_quantities():
    s = scene_from_dict(base_dict())
    assert s.half_width == pytest.approx(1.25 * s.a_H, rel=1e-15), "L = zone a_H"
    assert s.element_length == pytest.approx(2 * 1.25 * s.a_H / 40, rel=1e-15), "Le = 2L/n"
    assert s.dq == pytest.approx(0.5 * s.element_length, rel=1e-15), "dq = step Le"
    assert s.n_steps == 192, "6 a_H / (Le/2) = 192 steps"
    q = s.q_steps
    assert q.shape == (193,), "q_steps has n_steps + 1 entries"
    assert q[0] == 0.0 and q[-1] == pytest.approx(6.0 * s.a_H, rel=1e-12), "q_steps span"
    assert s.leading_edge == 1, "direction -1: material enters at x = +L"
    assert s.reference_distance_value == s.R, "d_ref defaults to R"
    s2 = s.replace(**{"contact.reference_distance": 42.0})
    assert s2.reference_distance_value == 42.0, "explicit d_ref"


def test_n_steps_rounding():
    s = scene_from_dict(base_dict())
    assert s.replace(**{"discretization.distance": 6.1}).n_steps == 196, \
        "6.1 a_H is 195.2 steps: rounded up"
    assert s.replace(**{"discretization.distance": 0.0}).n_steps == 0, "zero distance"
    assert s.replace(**{"discretization.distance": 0.0}).q_steps.tolist() == [0.0], \
        "zero distance keeps the starting state"
    # 0.7 a_H with 12 elements, zone 1.2, step 0.7 is 5 steps; in floating point the ratio
    # comes out as 5.000000000000001, which ceil would turn into 6
    s3 = s.replace(**{"discretization.distance": 0.7, "discretization.elements": 12,
                      "discretization.zone": 1.2, "discretization.step": 0.7})
    assert s3.n_steps == 5, "a ratio within 1e-9 of an integer is rounded, not ceiled"


def test_load_functions():
    d = base_dict()
    d["load"]["normal_history"] = {"kind": "harmonic", "mean": 1.0, "amplitude": 0.2,
                                   "wavelength": 3.0}
    d["load"]["tangential"] = {"kind": "ramp", "start": 0.0, "end": 0.5, "over": 2.0}
    s = scene_from_dict(d)
    q = np.array([0.0, 0.5, 1.0, 4.0]) * s.a_H
    np.testing.assert_allclose(s.normal_load(q),
                               1000.0 * (1 + 0.2 * np.sin(2 * np.pi * q / s.a_H / 3.0)),
                               rtol=1e-14, err_msg="P(q) = P̄ n(q/a_H)")
    np.testing.assert_allclose(s.tangential_load(q), 0.1 * 1000.0 * np.array(
        [0.0, 0.125, 0.25, 0.5]), rtol=1e-14, atol=1e-12, err_msg="Q(q) = mu P̄ r(q/a_H)")
    assert isinstance(s.normal_load(0.0), float), "scalar q gives a float"
    with pytest.raises(InputError, match="load.creepage"):
        s.prescribed_creepage(0.0)


def test_creepage_scene():
    d = base_dict()
    del d["load"]["tangential"]
    d["load"]["creepage"] = {"kind": "constant", "value": -1e-4}
    s = scene_from_dict(d)
    assert s.load.tangential is None, "creepage scene has no tangential history"
    assert s.prescribed_creepage(np.array([0.0, 1.0])).tolist() == [-1e-4, -1e-4], \
        "prescribed creepage"
    with pytest.raises(InputError, match="load.tangential"):
        s.tangential_load(0.0)


# =========================================================================== validation
BAD_VALUES = [
    ("bodies.A.radius", 0.0, "> 0"),
    ("bodies.A.radius", -150.0, "> 0"),
    ("bodies.B.radius", float("inf"), "> 0"),
    ("bodies.A.radius", "150", "number"),
    ("bodies.A.E", 0.0, "> 0"),
    ("bodies.B.E", -210000.0, "> 0"),
    ("bodies.A.nu", 0.5, "(-1, 0.5)"),
    ("bodies.A.nu", 0.7, "(-1, 0.5)"),
    ("bodies.B.nu", -1.0, "(-1, 0.5)"),
    ("bodies.A.nu", True, "number"),
    ("bodies.A.nu", float("nan"), "(-1, 0.5)"),
    ("bodies.A.shaft_radius", 150.0, "(0, radius"),
    ("bodies.B.shaft_radius", 0.0, "(0, radius"),
    ("contact.friction", -0.1, ">= 0"),
    ("contact.friction", float("inf"), ">= 0"),
    ("contact.model", "fem", "'halfspace', 'bem'"),
    ("contact.model", "BEM", "did you mean 'bem'"),
    ("contact.coupling", "goodmann", "did you mean 'goodman'"),
    ("contact.coupling", 1, "'auto', 'full', 'goodman', 'off'"),
    ("contact.reference_distance", 0.0, "> 0"),
    ("load.normal", 0.0, "> 0"),
    ("load.normal", -1000.0, "> 0"),
    ("load.start", "stopped", "'braked', 'rolling'"),
    ("load.direction", 0, "-1 or +1"),
    ("load.direction", 2, "-1 or +1"),
    ("load.direction", 1.0, "-1 or +1"),
    ("load.direction", True, "-1 or +1"),
    ("load.start_steps", 0, ">= 1"),
    ("load.start_steps", 1.5, "integer"),
    ("discretization.elements", "forty", "must be an integer >= 2"),
    ("discretization.elements", 1, ">= 2"),
    ("discretization.elements", 20001, "20000"),
    ("discretization.elements", 40.0, "integer"),
    ("discretization.element", "cubic", "'constant', 'linear', 'quadratic'"),
    ("discretization.zone", 1.0, "> 1"),
    ("discretization.step", 0.0, "(0, 8]"),
    ("discretization.step", 8.5, "(0, 8]"),
    ("discretization.formulation", "eulerian", "'material', 'convective-local'"),
    ("discretization.distance", -1.0, ">= 0"),
    ("solver.method", "gauss", "'newton'"),
    ("solver.method", "qp_osqp", "did you mean 'qp-osqp'"),
    ("solver.tolerance", 1e-16, "[1e-15, 1e-2]"),
    ("solver.tolerance", 0.1, "[1e-15, 1e-2]"),
    ("solver.max_iterations", 0, ">= 1"),
    ("name", 3, "string"),
    ("description", ["x"], "string"),
]


@pytest.mark.parametrize("key, value, word", BAD_VALUES,
                         ids=[f"{k}={v!r}" for k, v, _ in BAD_VALUES])
def test_bad_value_names_key_and_range(key, value, word):
    expect_error(with_value(base_dict(), key, value), key, word, repr(value))


@pytest.mark.parametrize("key", ["bodies.A.radius", "bodies.A.E", "bodies.B.nu",
                                 "contact.friction", "load.normal"])
def test_missing_required_key(key):
    expect_error(with_value(base_dict(), key, DELETE), key, "missing")


@pytest.mark.parametrize("key", ["bodies", "bodies.A", "bodies.B", "contact", "load"])
def test_missing_required_table(key):
    expect_error(with_value(base_dict(), key, DELETE), key, "missing")


def test_several_missing_keys_are_all_named():
    d = base_dict()
    d["bodies"]["A"] = {"nu": 0.3}
    err = expect_error(d, "bodies.A", "missing")
    assert "bodies.A.radius" in str(err) and "bodies.A.E" in str(err), \
        f"all missing keys are named: {err}"


@pytest.mark.parametrize("key, suggestion", [
    ("bodys", "bodies"),
    ("solvr", "solver"),
    ("bodies.a", "A"),
    ("bodies.A.radious", "radius"),
    ("bodies.B.e", "E"),
    ("contact.frction", "friction"),
    ("load.tangentail", "tangential"),
    ("load.normal_histroy", "normal_history"),
    ("discretization.elemnts", "elements"),
    ("solver.methd", "method"),
    ("solver.max_iteration", "max_iterations"),
])
def test_unknown_key_suggests_closest(key, suggestion):
    expect_error(with_value(base_dict(), key, 1), key, "unknown key",
                 f"did you mean {suggestion!r}?")


def test_unknown_key_without_close_match_lists_allowed():
    err = expect_error(with_value(base_dict(), "contact.zzzzzz", 1), "contact.zzzzzz",
                       "unknown key", "friction")
    assert "did you mean" not in str(err), f"no suggestion when nothing is close: {err}"


@pytest.mark.parametrize("key", ["contact", "solver", "bodies", "bodies.A"])
def test_section_must_be_a_table(key):
    expect_error(with_value(base_dict(), key, 3), key, "table")


def test_history_error_names_full_key():
    d = with_value(base_dict(), "load.normal_history",
                   {"kind": "harmonic", "mean": 1.0, "amplitude": 0.1, "wavelength": 0.0})
    expect_error(d, "load.normal_history.wavelength", "> 0")
    d = with_value(base_dict(), "load.tangential", {"kind": "ramp", "start": 0, "ende": 1,
                                                    "over": 1})
    expect_error(d, "load.tangential.ende", "did you mean 'end'?")


def test_optional_tables_default():
    d = base_dict()
    del d["solver"], d["discretization"], d["description"], d["name"]
    del d["load"]["normal_history"], d["load"]["tangential"]
    s = scene_from_dict(d)
    assert s.solver == SolverSettings(), "absent [solver] gives the defaults"
    assert s.solver.method == "newton", "default method"
    assert s.discretization == Discretization(), "absent [discretization] gives the defaults"
    assert s.load.normal_history == Constant(1.0), "normal history defaults to 1"
    assert s.load.tangential == Constant(0.0), "neither tangential nor creepage: Q = 0"
    assert s.load.start_steps == 1 and s.load.direction == -1, "load defaults"
    assert s.name == "scene" and s.description == "", "name and description defaults"
    assert isinstance(s.A.radius, float) and isinstance(s.discretization.elements, int), \
        "values are normalized"


def test_ints_accepted_for_floats():
    d = with_value(base_dict(), "bodies.A.radius", 150)
    assert scene_from_dict(d).A.radius == 150.0, "an integer radius is a number"
    assert isinstance(scene_from_dict(d).A.radius, float), "and it is stored as a float"


def test_tangential_and_creepage_are_exclusive():
    d = with_value(base_dict(), "load.creepage", {"kind": "constant", "value": 1e-4})
    expect_error(d, "load.creepage", "exactly one")


def test_normal_history_must_stay_nonnegative():
    """P < 0 is rejected; P = 0 (loss of contact) is allowed with Q = 0 there."""
    harm = {"kind": "harmonic", "mean": 0.5, "amplitude": 0.6, "wavelength": 40.0}
    d = with_value(base_dict(), "load.normal_history", harm)
    d["load"]["tangential"]["value"] = 0.0
    d["discretization"]["zone"] = 1.5
    # the trough, at q = 30 a_H, is beyond the rolled distance of 6 a_H
    assert scene_from_dict(d).load.normal_history.extremes(6.0)[0] > 0, \
        "trough not reached: the scene is valid"
    d["discretization"]["distance"] = 31.0
    expect_error(d, "load.normal_history", ">= 0", "minimum is -0.1")
    d = with_value(base_dict(), "load.normal_history", {"kind": "table", "q": [0.0, 3.0],
                                                        "value": [1.0, 0.0]})
    expect_error(d, "load.tangential", "must be 0 where the normal load is 0", "q = 3")  # Q = 0.75 μP̄ at P = 0
    d["load"]["tangential"]["value"] = 0.0
    assert scene_from_dict(d).load.normal_history(3.0) == 0.0, "P = 0 with Q = 0: valid"


def test_contact_must_stay_inside_the_zone():
    limit = 1.0 / (1.0 - 1.5 / 40)
    ok = with_value(base_dict(), "discretization.zone", limit * 1.0001)
    assert scene_from_dict(ok).discretization.zone > limit, "just inside is accepted"
    bad = with_value(base_dict(), "discretization.zone", limit * 0.9999)
    expect_error(bad, "discretization.zone", "edge of the zone", "needs zone > 1.03896")
    # a larger normal load (4 P̄ at its peak) needs a zone twice as wide
    d = with_value(base_dict(), "load.normal_history", {"kind": "ramp", "start": 1.0, "end": 4.0,
                                                        "over": 3.0})
    d["load"]["tangential"]["value"] = 0.5
    expect_error(d, "discretization.zone", f"needs zone > {2 * limit:.6g}")
    d["discretization"]["distance"] = 0.4  # the load reaches only 1.4 P̄
    assert scene_from_dict(d).discretization.zone == 1.25, "peak load not reached: valid"


@pytest.mark.parametrize("tangential", [
    {"kind": "constant", "value": 1.0},
    {"kind": "constant", "value": -1.2},
    {"kind": "ramp", "start": 0.0, "end": 1.0, "over": 5.0},
    {"kind": "table", "q": [0.0, 2.0, 4.0], "value": [0.0, 1.01, 0.0]},
    {"kind": "harmonic", "mean": 0.0, "amplitude": 1.0, "wavelength": 4.0},
], ids=["const", "negative", "ramp", "table-peak", "harmonic"])
def test_tangential_load_must_allow_stick(tangential):
    expect_error(with_value(base_dict(), "load.tangential", tangential), "load.tangential",
                 "|Q|/(mu P) must stay below 1")


def test_tangential_ratio_uses_the_normal_history():
    d = base_dict()
    d["load"]["normal_history"] = {"kind": "harmonic", "mean": 1.0, "amplitude": -0.3,
                                   "wavelength": 8.0}
    d["discretization"]["distance"] = 1.0  # P/P̄ >= 1 - 0.3 sin(π/4) ≈ 0.79 here: 0.75 sticks
    assert scene_from_dict(d).load.tangential == Constant(0.75), "0.75 < P/P̄ throughout"
    d["discretization"]["distance"] = 3.0  # P/P̄ reaches 0.7 at q = 2: 0.75/0.7 > 1
    expect_error(d, "load.tangential", "must stay below 1", "q = 2")


def test_frictionless_needs_zero_tangential_load():
    d = with_value(base_dict(), "contact.friction", 0.0)
    expect_error(d, "load.tangential", "friction = 0")
    d["load"]["tangential"]["value"] = 0.0
    assert scene_from_dict(d).contact.friction == 0.0, "frictionless with Q = 0 is valid"


def test_direct_construction_validates():
    s = scene_from_dict(base_dict())
    with pytest.raises(InputError, match="bodies.B.nu"):
        Scene("x", "", s.A, Body(300.0, 210000.0, 0.6), s.contact, s.load)
    t = Scene("x", "", Body(150, 210000, 0.3), Body(300, 210000, 0.3), Contact(0.1),
              Load(1000, tangential={"kind": "constant", "value": 0.5}))
    assert t.load.tangential == Constant(0.5), "dict histories are parsed on construction"
    assert t.discretization == Discretization(), "default discretization"


# =========================================================================== round trip
@pytest.mark.parametrize("name", ["cattaneo-carter", "ramp"])
def test_builtin_round_trip(name, tmp_path):
    s = load_scene(name)
    path = tmp_path / f"{name}.toml"
    path.write_text(s.to_toml(), encoding="utf-8")
    back = load_scene(path)
    assert back == s, f"load_scene(to_toml()) gives back {name}"
    assert back.source == str(path), "source records the file"
    assert back.to_toml() == s.to_toml(), "to_toml is stable"
    assert json.loads(json.dumps(s.to_dict())) == s.to_dict(), "to_dict is JSON-serializable"


def test_round_trip_of_every_feature(tmp_path):
    d = base_dict()
    d["name"] = "Prüfung (v2) 6.1.1"
    d["description"] = 'é §6 \n two lines \x7f, "quoted" \\ with\ttabs'

    d["contact"]["reference_distance"] = 123.456789012345678
    d["bodies"]["A"]["nu"] = 0.1 + 0.2  # not a short decimal
    d["load"]["normal_history"] = {"kind": "table", "q": [0.0, 1.0 / 3.0, 2.0],
                                   "value": [1.0, 1.1, 0.9]}
    del d["load"]["tangential"]
    d["load"]["creepage"] = {"kind": "harmonic", "mean": 0.0, "amplitude": 1e-4,
                             "wavelength": 2.0, "phase": -0.25}
    d["load"]["start"] = "rolling"
    d["load"]["direction"] = 1
    d["load"]["start_steps"] = 7
    d["discretization"].update(elements=81, element="constant", step=0.3,
                               formulation="convective-local")
    d["solver"].update(method="qp-osqp", tolerance=1e-12, max_iterations=33)
    s = scene_from_dict(d)
    path = tmp_path / "every.toml"
    path.write_text(s.to_toml(), encoding="utf-8")
    back = load_scene(path)
    assert back == s, "round trip with every optional feature"
    assert back.name == d["name"] and back.description == d["description"], \
        "names in any script, strings with quotes, backslashes and control characters survive"
    assert back.A.nu == 0.1 + 0.2, "floats are written with repr precision"


def test_to_dict_fills_defaults():
    d = base_dict()
    del d["solver"]
    out = scene_from_dict(d).to_dict()
    assert out["solver"] == {"method": "newton", "tolerance": 1e-10}, \
        "solver defaults filled"
    assert out["load"]["normal_history"] == {"kind": "constant", "value": 1.0}, \
        "history written with its value"
    assert "creepage" not in out["load"], "the unused one of tangential/creepage is left out"
    assert "reference_distance" not in out["contact"], "absent optional values are left out"


# =========================================================================== load_scene
def test_builtin_scenes_listed():
    b = builtin_scenes()
    expected = {"cattaneo-carter": "§6.1.1", "ramp": "§6.1.2", "goodman-bentall": "§6.2.1", "harmonic": "§6.2.2"}
    paths = {"stop-reverse", "fretting", "dent"}   # load paths and profiles (docs/kinematics.md)
    paths.add("falling-friction")                  # a slip-velocity law (docs/friction.md)
    paths |= {"kalker-circular", "kalker-elliptic", "cattaneo-3d", "ball-in-groove"}   # 3D (docs/scenes.md, "Three dimensions")
    paths.add("wheel-rail")                        # a wheelset on its track (docs/wheel-rail.md)
    paths.add("quartic-roller")                    # a 3D profile (docs/scenes.md, "Three dimensions: beyond Hertz")
    paths.add("falling-friction-3d")               # a 3D falling-friction creep curve with an interface layer
    paths |= {"aluminium-on-steel", "rolling-stresses"}   # a dissimilar transient, the stresses below (docs/examples.md)
    assert set(b) == set(expected) | paths, f"the built-ins listed: {sorted(b)}"
    for name, section in expected.items():
        assert section in b[name], f"{name}: the description cites the paper section {section}"


def test_builtin_contents():
    cc, ramp = load_scene("cattaneo-carter"), load_scene("ramp")
    for s in (cc, ramp):
        assert s.solver.method == "newton", f"{s.name}: built-ins run Newton (the run cross-checks steps with the QPs)"
        assert s.A == Body(150.0, 210000.0, 0.3, 15.0), f"{s.name}: body A"
        assert s.B == Body(300.0, 210000.0, 0.3, 30.0), f"{s.name}: body B"
        assert s.contact.friction == 0.1 and s.load.normal == 1000.0, f"{s.name}: mu, P"
        assert s.discretization == Discretization(), f"{s.name}: 40 QCE, Le/2, 6 a_H"
        assert s.load.start == "braked" and s.load.direction == -1, f"{s.name}: start"
        assert s.source == f"builtin:{s.name}", "source of a built-in"
    assert cc.load.tangential == Constant(0.75), "Cattaneo-Carter: Q/(mu P) = 0.75"
    assert ramp.load.tangential == Ramp(0.0, 0.75, 8.0 / 3.0), "ramp: 0 to 0.75 over 8/3"


def test_unknown_scene_lists_builtins():
    with pytest.raises(InputError) as info:
        load_scene("catteneo-carter")
    msg = str(info.value)
    assert info.value.key == "SCENE", f"key SCENE: {msg}"
    assert "no such file or built-in scene 'catteneo-carter'" in msg, msg
    assert "cattaneo-carter" in msg.split("built-in scenes:")[1] and "ramp" in msg, \
        f"lists the built-ins: {msg}"
    with pytest.raises(InputError, match="SCENE"):
        load_scene(42)


def test_toml_syntax_error_names_file(tmp_path):
    path = tmp_path / "broken.toml"
    path.write_text("name = 'x'\n[bodies.A\nradius = 1\n", encoding="utf-8")
    with pytest.raises(InputError) as info:
        load_scene(path)
    msg = str(info.value)
    assert str(path) in msg and "invalid TOML" in msg, f"names the file: {msg}"
    assert "line" in msg, f"carries tomllib's message with the position: {msg}"


def test_file_takes_precedence_and_names_scene(tmp_path, monkeypatch):
    d = base_dict()
    del d["name"]
    text = scene_from_dict(d).to_toml().replace('name = "scene"\n', "")
    (tmp_path / "ramp").write_text(text, encoding="utf-8")
    (tmp_path / "mine.toml").write_text(text, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    assert load_scene("ramp").description == "steel on steel", \
        "an existing file wins over a built-in of the same name"
    assert load_scene(str(tmp_path / "mine.toml")).name == "mine", "name defaults to the stem"
    assert load_scene(d).name == "scene", "a dict source works"


# =========================================================================== replace
def test_replace_changes_and_validates():
    s = load_scene("cattaneo-carter")
    t = s.replace(**{"solver.method": "qp-osqp", "discretization.elements": 80})
    assert t.solver.method == "qp-osqp" and t.discretization.elements == 80, "values replaced"
    assert s.solver.method == "newton", "the original is unchanged"
    assert t.A == s.A and t.load == s.load, "everything else is kept"
    assert {m for m in METHODS if s.replace(**{"solver.method": m})} == set(METHODS), \
        "every listed method is accepted"
    with pytest.raises(InputError, match="solver.method.*'qp-osqp'"):
        s.replace(**{"solver.method": "osqp"})
    with pytest.raises(InputError, match="did you mean 'method'"):
        s.replace(**{"solver.methd": "newton"})
    with pytest.raises(InputError, match="bodies.A.nu"):
        s.replace(**{"bodies.A.nu": 0.5})
    with pytest.raises(InputError, match="solver.method"):
        s.replace(**{"solver.method.x": 1})


def test_replace_histories_and_removal():
    s = load_scene("cattaneo-carter")
    t = s.replace(**{"load.creepage": Harmonic(0.0, 1e-4, 2.0)})
    assert t.load.tangential is None and t.load.creepage == Harmonic(0.0, 1e-4, 2.0), \
        "setting creepage drops the tangential load"
    u = t.replace(**{"load.tangential": {"kind": "table", "q": [0, 1], "value": [0, 0.5]}})
    assert u.load.creepage is None and u.load.tangential == Table([0, 1], [0, 0.5]), \
        "and back"
    v = s.replace(**{"bodies.A.shaft_radius": None, "load.tangential": Ramp(0, 0.5, 1)})
    assert v.A.shaft_radius is None, "None removes an optional key"
    with pytest.raises(InputError, match="exactly one"):
        s.replace(**{"load.creepage": 1e-4, "load.tangential": 0.5})


@pytest.mark.parametrize("name", ["../escape", "a/b", 'quo"te', "back\\slash", "tab\tname", "", " lead", ".hidden",
                                  "x" * 101])
def test_scene_name_alphabet(name):
    """A scene's name names output files and appears in generated scripts: letters, digits,
    space and ._+()- only, starting with a letter or digit (docs/scenes.md)."""
    d = base_dict()
    d["name"] = name
    expect_error(d, "name", "letters, digits")
