"""rollqp's extension points, used from outside the package with public names only (docs/architecture.md,
"How to add …"): a friction law, a profile feature, an influence model and a step method, each written
here as a contributor would write it in their own file, registered with the one public call, and run
in a scene. Each case runs in a fresh interpreter (the registries are process-wide: a dummy registered
here must not reach the other tests), and each is held to what an equivalent built-in gives.
"""
from __future__ import annotations

import dataclasses
import math
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest

import rollqp
from rollqp.methods import Capabilities, check_kind, check_options
from rollqp.profiles import Feature, circle_height

HERE = Path(__file__).resolve().parent

#: The short run of the cases: the paper's §6.1.1 rollers, a braked start and 3 a_H of rolling.
SHORT = {"discretization.elements": 30, "discretization.distance": 3.0}


def _fresh(case: str) -> None:
    """Run ``case()`` of this module in a new interpreter; its failure (an AssertionError) fails the test."""
    code = f"import sys; sys.path[:0] = {[str(HERE), str(HERE.parent / 'benchmarks')]!r}; import test_extensions as t; t.{case}()"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, f"{case}:\n{out.stdout[-3000:]}\n{out.stderr[-5000:]}"


def _largest_difference(a, b) -> float:
    """The largest difference of the tractions, gaps and creepages of two results, in p0 and p0/E* (the
    nondimensional units of rollqp's residuals)."""
    a, b = a.arrays(), b.arrays()
    p0, slip = float(a["p0"]), float(a["p0"]) / float(a["Estar"])
    return max(float(np.max(np.abs(a["pn"] - b["pn"]))) / p0, float(np.max(np.abs(a["pt"] - b["pt"]))) / p0,
               float(np.max(np.abs(a["creepage"] - b["creepage"]))) / slip)


# ------------------------------------------------------------------------------ a friction law
@dataclass(frozen=True)
class LinearFriction:
    """``μ(x) = mu + slope·x`` along the contact frame (``a_H`` units) over ``|x| <= reach``: a spatial law
    (rollqp.friction.FrictionLaw); its reference (``load.tangential = Q/(μ P̄)``) is its largest value."""

    mu: float
    slope: float
    reach: float
    law: str = "linear-in-x"
    kind: ClassVar[str] = "spatial"

    @property
    def reference(self) -> float:
        return self.largest

    @property
    def largest(self) -> float:
        return self.mu + abs(self.slope) * self.reach

    def coefficient(self, points, q_hat, direction):
        return self.mu + self.slope * np.asarray(points, dtype=float)[0]

    def check_strip(self, half_width_hat, q_end_hat, direction):
        """It varies everywhere: it meets every strip."""


def case_friction_law():
    from rollqp.friction import register
    register("linear-in-x", LinearFriction)
    scene = rollqp.load_scene("cattaneo-carter").replace(**SHORT)
    L = scene.discretization.zone  # the strip is |x| <= L a_H: a two-point table over it is the same law
    mine = scene.replace(**{"contact.friction": {"law": "linear-in-x", "mu": 0.1, "slope": 0.01, "reach": L}})
    table = scene.replace(**{"contact.friction": {"law": "table", "x": [-L, L], "values": [0.1 - 0.01 * L,
                                                                                            0.1 + 0.01 * L]}})
    assert mine.contact.friction.kind == "spatial"
    a, b = rollqp.run(mine), rollqp.run(table)
    # the same μ at every node up to round-off of the interpolation (1e-16), so the same transient to the
    # solver's tolerance 1e-10 (each step converged to rollqp's residual 1e-10 from the same start)
    assert _largest_difference(a, b) <= 1e-9
    arr = a.arrays()
    assert np.allclose(arr["friction_coefficient"][-1], 0.1 + 0.01 * arr["x"] / float(arr["a_H"]), rtol=0, atol=1e-15)


def test_a_friction_law_from_outside():
    _fresh("case_friction_law")


#: A short 3D run: the braked circle of ``cattaneo-3d`` on a 16 × 16 grid, rolled 2 a.
SHORT_3D = {"discretization.elements": [16, 16], "discretization.distance": 2.0}


def case_friction_law_both_dimensions():
    """The same law object, registered once, runs a 2D and a 3D scene: on the grid it is read at the element
    centres (``points[0]`` = x/a), equal to the built-in table over x, and the 3D tractions sit in its discs."""
    from rollqp.friction import register
    register("linear-in-x", LinearFriction)
    law = {"law": "linear-in-x", "mu": 0.3, "slope": 0.02, "reach": 1.25}
    two = rollqp.run(rollqp.load_scene("cattaneo-carter").replace(**SHORT, **{"contact.friction": law}))
    assert two.arrays()["residual"].max() <= 1e-9
    scene = rollqp.load_scene("cattaneo-3d").replace(**SHORT_3D)
    mine = scene.replace(**{"contact.friction": law})
    table = scene.replace(**{"contact.friction": {"law": "table", "x": [-1.25, 1.25], "values": [0.275, 0.325],
                                                  "frame": "fixed"}})
    assert mine.contact.friction.kind == "spatial" and mine.mu == 0.325   # its reference: the largest value
    a, b = rollqp.run(mine).arrays(), rollqp.run(table).arrays()
    # the same μ at every element up to the table's interpolation round-off (1e-16): the same transient to
    # the solver's tolerance 1e-10 (each step converged to rollqp's residual 1e-10 from the same start)
    for k in ("pn", "px", "py"):
        assert np.max(np.abs(a[k] - b[k])) / float(a["p0"]) <= 1e-9, k
    # on the grid: |t_i| <= μ(x_i) p_i, with equality where an element slips (state 2), to 1e-8 p0
    # (the residual tolerance 1e-10 on the nondimensional projection, with margin)
    mu = 0.3 + 0.02 * a["x"][None, :] / float(a["a"]) + 0.0 * a["y"][:, None]
    t, p, state = np.hypot(a["px"][-1], a["py"][-1]), a["pn"][-1], a["state"][-1]
    assert t.shape == mu.shape == p.shape, (t.shape, mu.shape, p.shape)
    assert np.all(t <= mu * np.maximum(p, 0) + 1e-8 * float(a["p0"]))
    slip = state == 2
    assert slip.any() and np.max(np.abs(t[slip] - mu[slip] * p[slip])) <= 1e-8 * float(a["p0"])


def test_a_friction_law_in_both_dimensions():
    _fresh("case_friction_law_both_dimensions")


# ------------------------------------------------------------------------------ a profile feature
@dataclass(frozen=True)
class Ripple(Feature):
    """``waves`` cosine dents of ``depth`` side by side, each ``wavelength`` wide, centred at material
    coordinate ``position``: zero outside its extent."""

    depth: float
    wavelength: float
    position: float
    waves: int = 1
    kind: ClassVar[str] = "ripple"

    def height(self, s):
        u = (np.asarray(s, dtype=float) - self.position) / self.wavelength
        inside = np.abs(u) < 0.5 * self.waves
        return np.where(inside, self.depth * 0.5 * (1.0 + np.cos(2.0 * math.pi * u)), 0.0)

    def extent(self):
        half = 0.5 * self.waves * self.wavelength
        return self.position - half, self.position + half

    def to_dict(self):
        return {"kind": "ripple", "depth": self.depth, "wavelength": self.wavelength, "position": self.position,
                "waves": self.waves}


def parse_ripple(key, values, radius, folder):
    return Ripple(float(values["depth"]), float(values["wavelength"]), float(values["position"]),
                  int(values.get("waves", 1)))


def case_profile_feature():
    from rollqp.errors import InputError
    from rollqp.profiles import register
    register("ripple", Ripple, ("depth", "wavelength", "position", "waves"), parse_ripple)
    dent = rollqp.load_scene("dent").replace(**SHORT)
    defect = dent.A.profile.features[0]
    one = dent.replace(**{"bodies.A.profile": {"kind": "ripple", "depth": defect.depth, "wavelength": defect.width,
                                               "position": defect.position}})
    a, b = rollqp.run(one), rollqp.run(dent)
    # one wave is the cosine dent (its height to round-off, 1e-19 mm): the same transient to the solver's tolerance
    assert _largest_difference(a, b) <= 1e-9
    three = dent.replace(**{"bodies.A.profile": {"kind": "ripple", "depth": 0.001, "wavelength": 0.3,
                                                 "position": 1.0, "waves": 3}})
    r = rollqp.run(three)
    assert r.arrays()["pn"].shape[0] == three.n_steps + 1
    ops = rollqp.SceneOperators.build(three)
    x, d = ops.strip.x, three.load.direction
    q = 1.0 * three.a_H
    circle = circle_height(x, three.A.radius) + circle_height(x, three.B.radius)
    assert np.allclose(ops.gap(q), circle + three.A.profile.features[0].height(x - d * q), rtol=0, atol=1e-15)
    with pytest.raises(InputError, match=r"bodies\.A\.profile\.width"):  # wider than the zone: refused by extent()
        dent.replace(**{"bodies.A.profile": {"kind": "ripple", "depth": 0.001, "wavelength": 0.3, "position": 1.0,
                                             "waves": 40}})


def test_a_profile_feature_from_outside():
    _fresh("case_profile_feature")


# ------------------------------------------------------------------------------ an influence model
def case_influence_model():
    from rollqp.errors import InputError
    from rollqp.influence import Model, halfspace_influence, register_model

    def build(scene, strip):
        return halfspace_influence(strip, Estar=scene.Estar, beta=scene.beta, R_A=scene.A.radius, R_B=scene.B.radius,
                                   coupling=scene.coupling_level, d_ref=scene.reference_distance_value)

    def check(scene):
        if scene.coupling_level == "full":
            raise InputError("contact.coupling", "the copied half-space takes uncoupled scenes only")

    register_model(Model("halfspace-copy", build, "the half-space, built by a contributor", check=check,
                         profiles=False))
    scene = rollqp.load_scene("cattaneo-carter").replace(**SHORT)
    mine = scene.replace(**{"contact.model": "halfspace-copy"})
    a, b = rollqp.run(mine), rollqp.run(scene)
    assert _largest_difference(a, b) == 0.0, "the same matrices: the same numbers"
    assert a.meta["model"]["operator"] == "collocation"
    with pytest.raises(InputError, match="contact.coupling"):  # its own check runs with the scene's
        rollqp.load_scene("goodman-bentall").replace(**{"contact.model": "halfspace-copy"})
    with pytest.raises(InputError, match=r"bodies\.A\.profile"):  # it declares no profiles
        rollqp.load_scene("dent").replace(**{"contact.model": "halfspace-copy"})


def test_an_influence_model_from_outside():
    _fresh("case_influence_model")


def case_influence_model_3d():
    """A 3D influence model registered from outside: ``build(grid, materials)`` gives the contact's operators
    (here the Boussinesq–Cerruti ones, built by a contributor from the public kernels), and a 3D scene's
    ``contact.model`` runs it; the other dimension's scenes do not accept it."""
    from rollqp.errors import InputError
    from rollqp.influence import Model, register_model
    from rollqp.influence.grid import ContactOperators
    built = []

    def build(grid, materials):
        built.append(grid.n)
        return ContactOperators(grid, materials)

    register_model(Model("cerruti-copy", build, "the 3D half-space, built by a contributor",
                         dimensions=frozenset({3})))
    scene = rollqp.load_scene("cattaneo-3d").replace(**SHORT_3D)
    a = rollqp.run(scene.replace(**{"contact.model": "cerruti-copy"})).arrays()
    b = rollqp.run(scene).arrays()
    assert built == [256], "the scene's contact is built by the registered model, once"
    for k in ("pn", "px", "py", "Fx", "approach"):
        assert np.array_equal(a[k], b[k]), f"the same operators: the same numbers ({k})"
    with pytest.raises(InputError, match="contact.model"):   # a 3D model is no 2D scene's
        rollqp.load_scene("cattaneo-carter").replace(**{"contact.model": "cerruti-copy"})


def test_a_3d_influence_model_from_outside():
    _fresh("case_influence_model_3d")


@dataclass(frozen=True)
class Bell:
    """A contributor's feature over (x, y): a cosine bell of ``depth`` on a circle of ``diameter`` at
    ``(x0, y0)``, fixed in the contact (it does not roll through)."""

    depth: float
    diameter: float
    x0: float = 0.0
    y0: float = 0.0
    kind: ClassVar[str] = "bell"
    material: ClassVar[bool] = False

    def height(self, x, y):
        r = 2.0 * np.hypot(np.asarray(x, dtype=float) - self.x0, np.asarray(y, dtype=float) - self.y0) / self.diameter
        return np.where(r < 1.0, self.depth * 0.5 * (1.0 + np.cos(np.pi * np.minimum(r, 1.0))), 0.0)

    def to_dict(self):
        return {"kind": "bell", "depth": self.depth, "diameter": self.diameter, "x0": self.x0, "y0": self.y0}


def case_profile_feature_3d():
    """A profile feature with a height over (x, y), registered once: a 3D body's ``profile`` takes it, and it
    gives the built-in circular cosine defect's numbers (the same heights, written independently)."""
    from rollqp.profiles3d import register_feature

    def parse(key, item, radius):
        return Bell(**item)

    register_feature("bell", ("depth", "diameter", "x0", "y0"), parse)
    scene = rollqp.load_scene("cattaneo-3d").replace(**SHORT_3D)
    body = {"radius": 30.0, "radius_y": 30.0, "E": 210000.0, "nu": 0.25}
    mine = scene.replace(**{"bodies.A": {**body, "profile": {"kind": "bell", "depth": 2e-4, "diameter": 0.4,
                                                             "x0": 0.1}}})
    ref = scene.replace(**{"bodies.A": {**body, "profile": {"kind": "defect", "x": 0.1, "y": 0.0, "depth": 2e-4,
                                                            "length": 0.4, "width": 0.4, "frame": "contact"}}})
    a, b = rollqp.run(mine).arrays(), rollqp.run(ref).arrays()
    assert not np.array_equal(a["pn"][-1], rollqp.run(scene).arrays()["pn"][-1]), "the bell changes the pressure"
    # the same heights to round-off (1e-19 mm): the same steps to the solver's tolerance 1e-10
    for k in ("pn", "px", "py"):
        assert np.max(np.abs(a[k] - b[k])) / float(a["p0"]) <= 1e-9, k


def test_a_3d_profile_feature_from_outside():
    _fresh("case_profile_feature_3d")


# ------------------------------------------------------------------------------ a method
class Halves:
    """Newton on the normal and tangential halves only (no coupled, no steady problem): the registry
    composes it with the N–T alternation on a coupled scene and the march reaches a rolling start by
    marching. Counts its solves."""

    name = "halves"
    capabilities = Capabilities(solves=frozenset({"normal", "tangential"}))

    def __init__(self, tolerance=1e-10, max_iterations=200):
        self.tolerance = tolerance
        self.newton = rollqp.get_method("newton", tolerance=tolerance, max_iterations=max_iterations)
        self.solved = 0

    @classmethod
    def from_settings(cls, settings, **options):
        check_options(cls.name, options, ())
        return cls(settings.tolerance, settings.max_iterations or 200)

    def setup(self, operators):
        self.newton.setup(operators)

    def solve(self, problem, warm=None):
        check_kind(self, problem)
        self.solved += 1
        return self.newton.solve(problem, warm)


def case_method():
    from rollqp.march import prepare
    from rollqp.methods import register
    register("halves", Halves)
    scene = rollqp.load_scene("cattaneo-carter").replace(**SHORT)
    a, b = rollqp.run(scene, method="halves"), rollqp.run(scene, method="newton")
    assert a.meta["method"] == "halves"
    assert _largest_difference(a, b) == 0.0, "Newton's solves of the same step problems"
    coupled = rollqp.load_scene("goodman-bentall").replace(**SHORT)
    _, meth, _ = prepare(coupled, "halves")
    assert "coupled" in meth.capabilities.solves and meth.inner.capabilities == Halves.capabilities
    c, d = rollqp.run(coupled, method="halves"), rollqp.run(coupled, method="nt-newton")
    assert _largest_difference(c, d) == 0.0, "the N–T alternation of the same Newton halves"
    rolling = scene.replace(**{"load.start": "rolling", "discretization.distance": 0.0})
    assert rollqp.run(rolling, method="halves").meta["rolling_start"] == "marching to steady state"


def test_a_method_from_outside():
    _fresh("case_method")


def test_the_capabilities_are_checked():
    """A record that declares a problem kind rollqp does not have is refused, naming it; a method of
    another dimension is refused for a scene before any work (its record, not its name)."""
    from rollqp.methods import compose
    with pytest.raises(rollqp.InputError, match="capabilities.solves"):
        Capabilities(solves=frozenset({"normal", "sideways"}))
    three = Halves()
    three.capabilities = dataclasses.replace(Halves.capabilities, dimensions=frozenset({3}), traction_components=2,
                                             friction_set="disc")
    with pytest.raises(rollqp.InputError, match="solver.method.*3D steps"):
        compose(three, coupled=False)
    assert compose(Halves(), coupled=False).capabilities.dimensions == {2}
