"""Non-Hertzian 3D geometry (rollqp.profiles3d, rollqp.patch; docs/validation3d.md, "Non-Hertzian
geometry"): a quadratic profile given as a table reproduces the Hertz scene to round-off, a quartic
lateral profile gives a non-elliptic patch whose area converges as the grid is refined, features roll
through, and bad profiles and grids are one-line errors naming the key."""
from __future__ import annotations

import copy

import numpy as np
import pytest

import rollqp
from rollqp import load_scene
from rollqp.errors import InputError
from rollqp.scene import scene_from_dict


def _base(name="kalker-circular"):
    return load_scene(name).to_dict()


def _lateral(d, y, z, **kw):
    d["bodies"]["A"].pop("radius_y", None)
    d["bodies"]["A"]["profile"] = {"kind": "lateral", "y": list(map(float, y)), "z": list(map(float, z)), **kw}
    return d


def _rel(a, b):
    return float(np.max(np.abs(a - b))) / float(np.max(np.abs(b)))


# ------------------------------------------------------------------- quadratic tables reproduce Hertz
def test_a_quadratic_lateral_table_reproduces_the_hertz_scene_to_round_off():
    """y²/(2R) at 7 points: the not-a-knot spline is that parabola to round-off, so the curvature, the
    ellipse, the grid and the run are Hertz's (measured: pn 8e-15, px 3e-14, py 2e-13 of their peaks; py is
    ~1e-3 of px on this longitudinal-creep scene, so its relative round-off is larger)."""
    base = load_scene("kalker-circular")
    y = np.linspace(-1.5, 1.5, 7)
    s = scene_from_dict(_lateral(base.to_dict(), y, y * y / 60.0))
    assert s.curvatures == pytest.approx(base.curvatures, rel=1e-14)
    assert s.grid.dx == pytest.approx(base.grid.dx, rel=1e-14)
    r1, r0 = rollqp.run(s).arrays(), rollqp.run(base).arrays()
    assert _rel(r1["pn"], r0["pn"]) < 1e-12
    assert _rel(r1["px"], r0["px"]) < 1e-11
    assert float(np.max(np.abs(r1["py"] - r0["py"]))) < 1e-11 * float(np.max(np.abs(r0["px"])))


def test_a_quadratic_surface_table_reproduces_the_hertz_scene_to_round_off():
    """x²/60 + y²/60 on a 9 × 7 table: the bicubic interpolating spline holds every quadratic; the
    curvature at the origin differs from Hertz's in the last bits (2e-15), the grid with it, and both runs
    are solved to solver.tolerance = 1e-13 (measured: pn 2e-14, px 1e-12)."""
    base = load_scene("kalker-circular").replace(**{"solver.tolerance": 1e-13})
    d = base.to_dict()
    x, y = np.linspace(-1, 1, 9), np.linspace(-1, 1, 7)
    d["bodies"]["A"] = {"E": 210000.0, "nu": 0.25,
                        "profile": {"kind": "surface", "x": list(x), "y": list(y),
                                    "z": [list(x * x / 60 + v * v / 60) for v in y]}}
    s = scene_from_dict(d)
    assert s.curvatures == pytest.approx(base.curvatures, rel=1e-13)
    r1, r0 = rollqp.run(s).arrays(), rollqp.run(base).arrays()
    assert _rel(r1["pn"], r0["pn"]) < 1e-12
    assert _rel(r1["px"], r0["px"]) < 1e-10


# ------------------------------------------------------------------- a quartic lateral profile
def _quartic(n, c=0.2):
    d = _base()
    y = np.linspace(-2, 2, 401)
    _lateral(d, y, c * y ** 4)
    d["discretization"] = {"extent": [[-0.7, 0.7], [-0.7, 0.7]], "elements": [n, n]}
    return scene_from_dict(d)


def test_a_quartic_lateral_profile_gives_a_non_elliptic_patch_whose_area_converges():
    """z = x²/60 + 0.2 y⁴: no curvature across y at the origin, so a, b, p0 come from the computed contact,
    and the patch is no ellipse (its area is 15 % above πab, the discretization error 0.2 %). The contact
    area of the normal step against the 113-element grid converges at first order or better: the
    least-squares slope of log|A_n − A_113| over n = 10 … 80 (√2 apart) was 1.9 (1.7 against n = 160,
    docs/validation3d.md); the element count quantizes the boundary to dx/2, hence the scatter the bound
    0.9 leaves room for."""
    ns = (10, 14, 20, 28, 40, 56, 80)
    areas = [_quartic(n).patch.area for n in ns]
    ref = _quartic(113)
    e = np.abs(np.array(areas) - ref.patch.area)
    slope = np.polyfit(np.log(1.0 / np.array(ns)), np.log(e), 1)[0]
    assert slope > 0.9, (areas, slope)
    s = ref
    assert s.ellipse.a == pytest.approx(s.patch.a) and s.ellipse.b == pytest.approx(s.patch.b)
    assert s.ellipse.p0 == pytest.approx(3 * s.load.normal / (2 * np.pi * s.patch.a * s.patch.b), rel=1e-12)
    # not an ellipse: the area of the patch is 15 % above pi a b (measured; a discretization error is 0.2 %)
    assert abs(s.patch.area / (np.pi * s.patch.a * s.patch.b) - 1) > 0.1


def test_the_quartic_roller_runs_and_its_contact_is_the_normal_step_s():
    s = load_scene("quartic-roller")
    assert not s.shape.hertzian and s.shape.curvatures()[1] <= 0
    r = rollqp.run(s).arrays()
    assert float(r["FN"][0]) == pytest.approx(s.load.normal, rel=1e-10)
    on = r["pn"][0] > 0
    assert np.array_equal(on, s.patch.contact)
    # the pressure along y has its peaks off the axis (a crowned roller's edges carry more than its middle)
    j0 = np.argmin(np.abs(r["y"]))
    col = r["pn"][0][:, np.argmin(np.abs(r["x"]))]
    assert col.max() > col[j0] * 1.02


def test_a_defect_rolls_through_the_contact():
    """A dent entering at the leading edge (direction −1: material enters at +x) lowers the force on the
    elements it passes and leaves the total FN; the pressure field moves with it."""
    d = _base("cattaneo-3d")
    d["discretization"].update(elements=[16, 16], distance=2.0)
    d["bodies"]["A"]["profile"] = {"kind": "defect", "x": 0.6, "y": 0.0, "depth": 3e-3, "length": 0.3,
                                   "width": 0.3}
    s = scene_from_dict(d)
    assert s.shape.moves
    r = rollqp.run(s).arrays()
    assert np.allclose(r["FN"], s.load.normal, rtol=1e-9)
    lost = [(np.argwhere((r["pn"][k] == 0) & (r["pn"][0] > 0))) for k in range(len(r["q"]))]
    moved = [float(np.mean(r["x"][idx[:, 1]])) for idx in lost if len(idx)]
    assert len(moved) >= 3 and moved[-1] < moved[0]      # the separated spot travels towards −x


def test_a_feature_that_pushes_the_contact_off_the_grid_stops_the_run_naming_the_key():
    """A flat-bottomed dent deeper than the approach (0.03 mm against 0.011) and 0.9 mm wide carries the load on
    its rim, which reaches the grid's outer elements as it passes: the run stops at that step with a one-line
    error naming the grid's key, the completed states kept in ``err.partial``."""
    d = _base("cattaneo-3d")
    d["discretization"].update(elements=[12, 12], distance=2.0)
    d["bodies"]["A"]["profile"] = {"kind": "defect", "x": 0.9, "y": 0.0, "depth": 0.03, "length": 0.9, "width": 0.9,
                                   "shape": "flat"}
    s = scene_from_dict(d)                      # at q = 0 the dent is outside the contact: the scene is fine
    with pytest.raises(InputError, match=r"^discretization.zone: at rolling step \d+ the contact reaches") as err:
        rollqp.run(s)
    assert "\n" not in str(err.value) and len(err.value.partial) >= 2


# ------------------------------------------------------------------- bad input
BAD = [
    ("lateral and radius_y", lambda d: d["bodies"]["A"].update(profile={"kind": "lateral", "y": [-1, 0, 1],
                                                                         "z": [1, 0, 1]}),
     "bodies.A.radius_y:", "must be absent"),
    ("lateral without radius", lambda d: (d["bodies"]["A"].pop("radius"), d["bodies"]["A"].pop("radius_y"),
                                          d["bodies"]["A"].update(profile={"kind": "lateral", "y": [-1, 0, 1],
                                                                           "z": [1, 0, 1]})),
     "bodies.A.radius:", "missing"),
    ("y not increasing", lambda d: _lateral(d, [-1, 1, 0], [1, 1, 0]), "bodies.A.profile.y:", "strictly increasing"),
    ("negative height", lambda d: _lateral(d, [-1, 0, 1], [1, -1e-3, 1]), "bodies.A.profile.z:", "[0, 1e6]"),
    ("short table", lambda d: _lateral(d, [-0.1, 0.0, 0.1], [1e-3, 0, 1e-3]), "bodies.A.profile.y:", "not extrapolated"),
    ("unknown interpolation", lambda d: _lateral(d, [-1, 0, 1], [1, 0, 1], interpolation="akima"),
     "bodies.A.profile.interpolation:", "spline"),
    ("unknown kind", lambda d: d["bodies"]["A"].update(profile={"kind": "dent"}), "bodies.A.profile.kind:", "defect"),
    ("unknown key", lambda d: d["bodies"]["A"].update(profile={"kind": "defect", "x": 1, "depth": 1e-3, "length": 1,
                                                               "width": 1, "position": 2}),
     "bodies.A.profile.position:", "allowed"),
    ("surface rows", lambda d: d["bodies"].update(A={"E": 2e5, "nu": 0.3, "profile": {
        "kind": "surface", "x": [-1, 0, 1], "y": [-1, 1], "z": [[1, 0, 1]]}}), "bodies.A.profile.z:", "2 rows"),
    ("flat needs a radius", lambda d: d["bodies"]["B"].update(profile={"kind": "flat", "x": 1.0, "length": 0.2}),
     "bodies.B.profile.kind:", "finite radius"),
    ("zone and extent", lambda d: d["discretization"].update(extent=[[-1, 1], [-1, 1]]), "discretization.zone:",
     "not both"),
    ("element_size without extent", lambda d: d["discretization"].update(element_size=[0.1, 0.1]),
     "discretization.element_size:", "needs discretization.extent"),
    ("extent without the origin", lambda d: (d["discretization"].pop("zone"),
                                             d["discretization"].update(extent=[[0.1, 1], [-1, 1]])),
     "discretization.extent[0]:", "origin"),
    ("extent aspect", lambda d: (d["discretization"].pop("zone"), d["discretization"].pop("elements"),
                                 d["discretization"].update(extent=[[-1, 1], [-1, 1]], element_size=[0.5, 0.05])),
     "discretization.element_size:", "aspect"),
    ("extent cuts the contact", lambda d: (d["discretization"].pop("zone"),
                                           d["discretization"].update(extent=[[-0.5, 0.5], [-1, 1]])),
     "discretization.extent:", "row of elements to spare"),
]


@pytest.mark.parametrize("mod, key, allowed", [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_profiles_and_grids_are_one_line_errors_naming_the_key(mod, key, allowed):
    d = copy.deepcopy(_base())
    mod(d)
    with pytest.raises(InputError) as err:
        scene_from_dict(d)
    msg = str(err.value)
    assert "\n" not in msg and msg.startswith(key), msg
    assert allowed in msg, msg


def test_a_quartic_profile_needs_an_extent():
    d = _base()
    y = np.linspace(-2, 2, 401)
    _lateral(d, y, 0.2 * y ** 4)
    with pytest.raises(InputError, match=r"^discretization.extent: required"):
        scene_from_dict(d)


def test_profile_scenes_round_trip_through_toml():
    from rollqp.scene import scene_from_toml
    s = load_scene("quartic-roller")
    again = scene_from_toml(s.to_toml(), default_name=s.name)
    assert again.to_dict() == s.to_dict()
    assert np.array_equal(again.patch.p, s.patch.p)
