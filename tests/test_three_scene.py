"""3D scene files: parsing, the built-in scenes as SPEC describes them, and bad input as one-line
InputErrors naming the key and the allowed range (docs/scenes.md, "Three dimensions")."""
from __future__ import annotations

import copy
import math

import pytest

from rollqp import builtin_scenes, load_scene
from rollqp.errors import InputError
from rollqp.methods import available_methods, capabilities, cone_methods, get_method, method_class
from rollqp.scene import scene_from_dict, scene_from_toml

BUILTIN_3D = ("kalker-circular", "kalker-elliptic", "cattaneo-3d", "ball-in-groove")


def _base():
    return load_scene("kalker-circular").to_dict()


def _error(mod, base=None) -> str:
    d = copy.deepcopy(base or _base())
    mod(d)
    with pytest.raises(InputError) as err:
        scene_from_dict(d)
    msg = str(err.value)
    assert "\n" not in msg, msg
    return msg


# ----------------------------------------------------------------------------- the built-in scenes
def test_builtin_3d_scenes_are_listed_and_three_dimensional():
    names = builtin_scenes()
    for name in BUILTIN_3D:
        assert name in names
        assert load_scene(name).dimension == 3


def test_kalker_circular_is_spec_s_example():
    """The scene file of docs/scenes.md's 3D section, key by key."""
    s = load_scene("kalker-circular")
    assert s.description == "Circular Hertz contact, steady rolling at small creepage (Kalker's linear theory)"
    assert (s.A.radius, s.A.radius_y, s.A.E, s.A.nu) == (30.0, 30.0, 210000.0, 0.25)
    assert math.isinf(s.B.radius) and math.isinf(s.B.radius_y) and (s.B.E, s.B.nu) == (210000.0, 0.25)
    assert s.mu == 0.3 and s.load.normal == 1000.0 and s.load.start == "rolling"
    loads = s.loads_at(0.0)
    assert (loads.xi, loads.eta, loads.phi) == (1e-5, 0.0, 0.0)
    d = s.discretization
    assert tuple(d.elements) == (40, 40) and tuple(d.zone) == (1.25, 1.25) and d.step == 1.0 and d.distance == 4.0
    e = s.ellipse
    assert e.a == pytest.approx(e.b, rel=1e-12)


def test_kalker_elliptic_and_cattaneo_3d_are_what_spec_names():
    s = load_scene("kalker-elliptic")
    e = s.ellipse
    assert e.a / e.b == pytest.approx(0.5, abs=1e-3)       # radius_y given to 5 digits
    ld = s.loads_at(0.0)
    assert s.load.start == "rolling" and all(v not in (None, 0.0) for v in (ld.xi, ld.eta, ld.phi))
    c = load_scene("cattaneo-3d")
    assert c.load.start == "braked" and c.ellipse.a == pytest.approx(c.ellipse.b, rel=1e-12)
    ld = c.loads_at(0.0)
    assert ld.Fx == pytest.approx(0.6 * c.mu * c.load.normal) and ld.Fy == 0.0 and c.n_steps > 0


@pytest.mark.parametrize("name", BUILTIN_3D)
def test_builtin_3d_round_trip_through_toml(name):
    s = load_scene(name)
    again = scene_from_toml(s.to_toml(), default_name=name)
    assert again.to_dict() == s.to_dict() and again.dimension == 3


# ------------------------------------------------------------------------------------ bad input
BAD = [
    ("radius zero", lambda d: d["bodies"]["A"].update(radius=0.0), "bodies.A.radius:", "> 0"),
    ("radius_y concave, more curved", lambda d: d["bodies"]["B"].update(radius_y=-2.0), "bodies.B.radius_y:", "> 0"),
    ("radius text", lambda d: d["bodies"]["A"].update(radius="big"), "bodies.A.radius:", "> 0"),
    ("both straight in x", lambda d: d["bodies"]["A"].update(radius=math.inf), "bodies.A.radius:", "concentrated"),
    ("zone below the ellipse", lambda d: d["discretization"].update(zone=[1.0, 1.25]), "discretization.zone",
     "> 1"),
    ("no row to spare", lambda d: d["discretization"].update(zone=[1.05, 1.05], elements=[10, 10]),
     "discretization.zone:", "cover the Hertz ellipse"),
    ("aspect ratio", lambda d: d["discretization"].update(elements=[40, 4]), "discretization.elements:",
     "[0.2, 5]"),
    ("elements not a pair", lambda d: d["discretization"].update(elements=40), "discretization.elements:", "pair"),
    ("too many elements", lambda d: d["discretization"].update(elements=[10000, 10000]), "discretization.elements",
     "exceeds"),
    ("osqp has no cone", lambda d: d.setdefault("solver", {}).update(method="qp-osqp"), "solver.method:",
     "second-order cone"),
    ("a 2D-only method", lambda d: d.setdefault("solver", {}).update(method="nt-newton"), "solver.method:",
     "solves 2D steps"),
    ("unknown method", lambda d: d.setdefault("solver", {}).update(method="socp-mosek"), "solver.method:",
     "must be one of"),
    ("dimension 4", lambda d: d["contact"].update(dimension=4), "contact.dimension:", "2, 3"),
    ("a friction law without its name", lambda d: d["contact"].update(friction={"kind": "falling"}),
     "contact.friction.law:", "must be one of"),
    ("a slip-velocity law's memory on a rolling start",
     lambda d: (d["contact"].update(friction={"law": "exponential", "static": 0.3, "kinetic": 0.2, "velocity": 1.0,
                                              "rolling_speed": 1000.0, "memory": 0.5}),
                d["load"].update(start="rolling")), "contact.friction.memory:", "load.start = 'braked'"),
    ("force and creepage along x", lambda d: d["load"].update(tangential=0.3), "load.creepage.longitudinal:",
     "at most one"),
    ("beyond the sliding limit", lambda d: (d["load"].update(tangential=0.8, lateral=0.7, start="braked"),
                                            d["load"].pop("creepage")), "load.tangential:", "< 1"),
    ("negative normal force", lambda d: d["load"].update(normal=-5.0), "load.normal:", "> 0"),
    ("step too long", lambda d: d["discretization"].update(step=20.0), "discretization.step:", "(0, 8]"),
    ("2D key in 3D", lambda d: d["discretization"].update(element="linear"), "discretization.element:",
     "a key of 2D scenes"),
    ("2D profile kind in 3D", lambda d: d["bodies"]["A"].update(profile={"kind": "dent"}), "bodies.A.profile.kind:",
     "in a 3D scene"),
]


@pytest.mark.parametrize("mod, key, allowed", [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_3d_input_is_one_line_naming_key_and_range(mod, key, allowed):
    msg = _error(mod)
    assert msg.startswith(key), msg
    assert allowed in msg, msg


def test_3d_key_in_a_2d_scene_names_the_dimension():
    base = load_scene("cattaneo-carter").to_dict()
    msg = _error(lambda d: d["bodies"]["A"].update(radius_y=30.0), base)
    assert msg.startswith("bodies.A.radius_y:") and "a key of 3D scenes" in msg and "dimension" in msg
    msg = _error(lambda d: d.setdefault("solver", {}).update(method="socp-clarabel"), base)
    assert msg.startswith("solver.method:") and "solves 3D steps" in msg


def test_dimension_2_is_the_default_and_may_be_written():
    d = load_scene("cattaneo-carter").to_dict()
    d["contact"]["dimension"] = 2
    assert scene_from_dict(d).dimension == 2


def test_a_cone_method_that_cannot_do_the_step_is_refused_by_its_record():
    """qp-osqp's 3D record solves the normal QP only; the refusal lists the methods whose records
    declare tangential steps on the friction disc, and every one of those is such a record."""
    caps = capabilities("qp-osqp", 3)
    assert caps.dimensions == {3} and "tangential" not in caps.solves
    names = cone_methods()
    assert "newton" in names and "socp-clarabel" in names and "qp-osqp" not in names
    for name in names:
        c = capabilities(name, 3)
        assert c.dimensions == {3} and c.traction_components == 2 and c.friction_set == "disc"
        assert {"normal", "tangential"} <= c.solves
    assert set(names) <= set(available_methods(3))


def test_the_registry_names_the_instances():
    m = get_method("socp-clarabel", 3, tolerance=1e-9)
    assert m.name == "socp-clarabel" and m.tolerance == 1e-9
    assert method_class("newton", 3) is not method_class("newton", 2)
    assert method_class("newton", 3).capabilities.dimensions == {3}


def _leaves(d, prefix=()):
    for k, v in d.items():
        if isinstance(v, dict) and v:
            yield from _leaves(v, prefix + (k,))
        else:
            yield prefix + (k,)


BAD_VALUES = [None, "x", -1, 0, [], {}, [1.0], 1e308, float("nan"), float("-inf"), True, [0, 0, 0]]


@pytest.mark.parametrize("name", BUILTIN_3D)
def test_every_key_of_a_3d_scene_set_to_nonsense_is_a_one_line_input_error(name):
    """Each leaf of a built-in 3D scene (and its removal) replaced by values of every wrong kind: the
    scene either validates or stops with a one-line InputError naming a key — never another exception."""
    base = load_scene(name).to_dict()
    for path in _leaves(base):
        for value in BAD_VALUES + ["<delete>"]:
            d = copy.deepcopy(base)
            node = d
            for k in path[:-1]:
                node = node[k]
            if value == "<delete>":
                del node[path[-1]]
            else:
                node[path[-1]] = value
            try:
                scene_from_dict(d)
            except InputError as err:
                msg = str(err)
                assert "\n" not in msg and ": " in msg, (path, value, msg)
