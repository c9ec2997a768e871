"""Body profiles (rollqp.profiles): the rounded punch against its closed form with a slope,
the circle reproduced (zero-depth defect, sampled table), a dent and a flat rolling through a
Carter contact under every method, and bad input."""
from __future__ import annotations

import numpy as np
import pytest

import rollqp
from rollqp import closedforms as cf
from rollqp.errors import InputError
from rollqp.profiles import Profile, Table, circle_height, parse_profile
from rollqp.report import rms_in_contact

MU = 0.1
PUNCH_R = 100.0       # edge radius of the punch (the scene's relative radius)
PUNCH_B = 0.6         # flat half-width / a_H


def base(**changes):
    return rollqp.load_scene("cattaneo-carter").replace(**changes)


def punch_scene(elements, element="constant"):
    """Body A: a flat of half-width 0.6 a_H with edges of radius 100 mm (a table of 6001 points:
    its interpolation error ≤ Δx²/(8R) = 1.4e-9 mm = 2.5e-7 u0); body B: a plane."""
    s0 = rollqp.load_scene("cattaneo-carter")
    xs = np.linspace(-3 * s0.a_H, 3 * s0.a_H, 6001)
    b = PUNCH_B * s0.a_H
    z = np.where(np.abs(xs) > b, (np.abs(xs) - b) ** 2 / (2 * PUNCH_R), 0.0)
    return base(**{"bodies.A.profile": {"kind": "table", "x": list(xs), "h": list(z)},
                   "bodies.B.profile": {"kind": "table", "x": [-5.0, 5.0], "h": [0.0, 0.0]},
                   "load.tangential": 0.0, "discretization.distance": 0.0, "discretization.zone": 1.6,
                   "discretization.elements": elements, "discretization.element": element})


def test_rounded_punch_matches_its_closed_form_with_a_slope():
    """40 constant elements: rms(p − closed form)/p0 = 0.0059 (measured), halving at each doubling
    (slope −0.9: 0.0111, 0.0059, 0.0033)."""
    errs = []
    for ne in (20, 40, 80):
        s = punch_scene(ne)
        a = rollqp.run(s).arrays()
        ac = cf.rounded_punch_half_width(float(a["P"][0]), PUNCH_B * s.a_H, PUNCH_R, s.Estar)
        pe = cf.rounded_punch_pressure(a["x"], ac, PUNCH_B * s.a_H, PUNCH_R, s.Estar)
        errs.append(rms_in_contact(a["x"], ac, a["pn"][0] - pe) / s.p0)
    assert errs[1] < 0.0065, errs
    slope = np.polyfit(np.log([20, 40, 80]), np.log(errs), 1)[0]
    assert slope < -0.8, (errs, slope)


def test_rounded_punch_closed_form_is_consistent():
    """The pressure integrates to the load; b = 0 is Hertz."""
    a, b, R, E = 1.0, 0.4, 100.0, 1e5
    xs = np.linspace(-a, a, 400001)
    assert np.trapezoid(cf.rounded_punch_pressure(xs, a, b, R, E), xs) == pytest.approx(
        cf.rounded_punch_load(a, b, R, E), rel=1e-5)
    x = np.linspace(-0.9, 0.9, 7)
    np.testing.assert_allclose(cf.rounded_punch_pressure(x, a, 0.0, R, E), E * a / (2 * R) * np.sqrt(1 - x * x),
                               rtol=1e-13)
    assert cf.rounded_punch_half_width(cf.rounded_punch_load(1.3, 0.5, R, E), 0.5, R, E) == pytest.approx(1.3)


def test_zero_depth_defect_reproduces_the_circle():
    s = base(**{"discretization.distance": 1.0})
    ref = rollqp.run(s).arrays()
    d = rollqp.run(s.replace(**{"bodies.A.profile": {"kind": "defect", "depth": 0.0, "width": 0.5,
                                                     "position": 1.0}})).arrays()
    for k in ("pn", "pt", "creepage"):
        # the gap is the circle's bit for bit; the normal half is re-solved each step (the profile moves)
        assert np.max(np.abs(d[k] - ref[k])) <= 1e-12 * np.max(np.abs(ref[k])), k


def test_table_sampled_from_a_circle_reproduces_the_circle():
    """Body A's circle as a contact-frame table of N points on ±2 a_H: the gap's interpolation error is
    ≤ Δx²·max z''/8 (z'' = 1/(R(1 − x²/R²)^{3/2})): 9.2e-8 mm = 1.7e-5 u0 at N = 401. The nodal
    tractions amplify the gap's small-wavelength error (measured 2.6e-4 p0 at 401 points, 1.0e-4 at
    801: order 1.4, the interpolation error aliasing on the mesh)."""
    s = base(**{"discretization.distance": 0.0})
    r = rollqp.run(s).arrays()
    ref_h = rollqp.SceneOperators.build(s).h
    errs = []
    for n in (401, 801):
        xs = np.linspace(-2 * s.a_H, 2 * s.a_H, n)
        dx = xs[1] - xs[0]
        bound = dx * dx / (8 * s.A.radius * (1 - (xs[-1] / s.A.radius) ** 2) ** 1.5)
        t = s.replace(**{"bodies.A.profile": {"kind": "table", "x": list(xs),
                                              "h": list(circle_height(xs, s.A.radius))}})
        assert np.max(np.abs(rollqp.SceneOperators.build(t).h - ref_h)) <= bound * (1 + 1e-9)
        a = rollqp.run(t).arrays()
        errs.append(max(np.max(np.abs(a["pn"] - r["pn"])) / s.p0, np.max(np.abs(a["pt"] - r["pt"])) / (MU * s.p0)))
    assert errs[0] < 5e-4 and errs[1] < errs[0] / 2, errs


@pytest.mark.parametrize("profile", [
    {"kind": "defect", "depth": 0.003, "width": 0.8, "position": 2.0},
    pytest.param({"kind": "flat", "length": 1.2, "position": 2.0}, marks=pytest.mark.slow),
    pytest.param([{"kind": "defect", "depth": -0.001, "width": 0.4, "position": 1.6, "shape": "parabolic"},
                  {"kind": "defect", "depth": 0.004, "width": 0.6, "position": 2.6}], marks=pytest.mark.slow),
], ids=["dent", "flat", "bump-and-dent"])
def test_features_roll_through_under_every_method(profile):
    """A dent, a flat and a bump with a dent roll through the braked Carter contact (constant elements,
    F·A exactly symmetric): the QP backends agree with Newton to 1e-8 μp0 at every step."""
    disc = {"discretization.element": "constant", "discretization.distance": 3.0, "discretization.step": 1.0,
            "discretization.zone": 1.6}   # the bump meets the other body earlier than the circle would
    s = base(**disc, **{"bodies.A.profile": profile})
    ref = rollqp.run(s, "newton").arrays()
    circle = rollqp.run(base(**disc), "newton").arrays()
    assert np.max(np.abs(ref["pn"] - circle["pn"])) / s.p0 > 0.05      # the feature did pass through
    for method in ("qp-clarabel", "qp-osqp"):
        a = rollqp.run(s, method).arrays()
        assert np.max(np.abs(a["pt"] - ref["pt"])) / (MU * s.p0) < 1e-8, method
        assert np.max(np.abs(a["pn"] - ref["pn"])) / s.p0 < 1e-8, method


def test_dent_lifting_the_middle_makes_two_patches():
    """A dent deeper than the approach in the middle of the contact: two contact patches at once."""
    s = base(**{"discretization.distance": 0.0, "bodies.A.profile": {"kind": "defect", "depth": 0.02, "width": 0.6,
                                                                     "position": 0.0}})
    for method in ("newton", "qp-clarabel", "qp-osqp"):
        a = rollqp.run(s, method).arrays()
        # in contact: above the backends' accuracy (OSQP leaves ~1e-14 p0 on separated nodes)
        inside = (a["pn"][0] > 1e-8 * s.p0).astype(int)
        assert np.count_nonzero(np.diff(inside) == 1) == 2, method
        assert a["pn"][0][a["x"].size // 2] < 1e-8 * s.p0


def test_profile_api_for_other_modules():
    """Profile.gap(x, shift): what a matrix-free path needs from a rough table."""
    x = np.linspace(-1, 1, 11)
    rough = Profile(150.0, (Table((-3.0, 0.0, 3.0), (0.0, 1e-3, 0.0), frame="material"),))
    assert rough.moves and not rough.is_circle
    np.testing.assert_allclose(rough.gap(x, 0.5), circle_height(x, 150.0) + np.interp(x - 0.5, [-3, 0, 3], [0, 1e-3, 0]))
    assert parse_profile(None, "k", 150.0).is_circle


def test_profile_files(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    s = rollqp.load_scene("cattaneo-carter")
    xs = np.linspace(-2 * s.a_H, 2 * s.a_H, 201)
    np.savetxt(tmp_path / "a.csv", np.c_[xs, circle_height(xs, 150.0)], delimiter=",", header="x, h")
    np.savez(tmp_path / "b.npz", x=xs, h=circle_height(xs, 300.0))
    text = s.to_toml().replace("[bodies.A]\n", '[bodies.A]\nprofile = { kind = "table", file = "a.csv" }\n') \
        .replace("[bodies.B]\n", '[bodies.B]\nprofile = { kind = "table", file = "b.npz" }\n')
    (tmp_path / "s.toml").write_text(text)
    t = rollqp.load_scene(tmp_path / "s.toml")
    assert t.A.profile.base.x[0] == pytest.approx(xs[0]) and t.B.profile is not None
    for name, match in (("../a.csv", "inside the scene file's folder"), ("/etc/passwd", "inside"),
                        ("c.csv", "no such file"), ("s.toml", ".csv or .npz")):
        (tmp_path / "bad.toml").write_text(text.replace('file = "a.csv"', f'file = "{name}"'))
        with pytest.raises(InputError, match=match):
            rollqp.load_scene(tmp_path / "bad.toml")


@pytest.mark.parametrize("profile, key, match", [
    ({"kind": "table", "x": [0.0, -1.0, 2.0], "h": [0, 0, 0]}, "bodies.A.profile.x", "strictly increasing"),
    ({"kind": "table", "x": [-1.0, 1.0], "h": [0, 0]}, "bodies.A.profile.x", r"covers \[-1, 1\] but the strip needs"),
    ({"kind": "table", "x": [-2.0, 2.0], "h": [0, 0], "frame": "material"}, "bodies.A.profile.x",
     "the material that passes through the strip needs"),
    ({"kind": "defect", "depth": 0.001, "width": 5.0, "position": 2.0}, "bodies.A.profile.width", r"must be in \(0, 2\.6"),
    ({"kind": "flat", "length": 3.0, "position": 2.0}, "bodies.A.profile.length", r"must be in \(0, 2\.6"),
    ({"kind": "defect", "depth": 0.001, "width": 0.5}, "bodies.A.profile.position", "missing"),
    ({"kind": "dent"}, "bodies.A.profile.kind", "one of"),
    ({"kind": "defect", "depth": 0.001, "width": 0.5, "position": 1.0, "shape": "square"},
     "bodies.A.profile.shape", "one of"),
])
def test_bad_profiles(profile, key, match):
    with pytest.raises(InputError, match=match) as err:
        base(**{"bodies.A.profile": profile})
    assert err.value.key == key and "\n" not in str(err.value)


def test_profiles_need_the_halfspace():
    with pytest.raises(InputError, match="circle") as err:
        base(**{"contact.model": "bem", "bodies.A.profile": {"kind": "defect", "depth": 0.001, "width": 0.5,
                                                              "position": 1.0}})
    assert err.value.key == "bodies.A.profile"


def test_scene_with_profile_round_trips():
    s = base(**{"bodies.A.profile": {"kind": "flat", "length": 0.8, "position": 2.0},
                "load.rolled": {"kind": "table", "q": [0, 1, 2], "value": [0, 1, 0.5]}})
    assert rollqp.load_scene(s.to_dict()) == s
    assert "profile" not in base().to_dict()["bodies"]["A"] and "rolled" not in base().to_dict()["load"]
