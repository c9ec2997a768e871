r"""Three-dimensional scenes: Kalker's problem as a scene file (docs/scenes.md, "Three dimensions").

A scene with ``[contact] dimension = 3`` (:func:`rollqp.load_scene` reads the key and hands the
table here) describes two bodies with principal radii in x (rolling) and y (lateral), pressed by a
normal force and rolling in x with creepages or tangential forces::

    name, description, units
    [bodies.A] [bodies.B]   radius, radius_y (> 0 convex, < 0 concave, or inf), E, nu
    [contact]               dimension = 3, friction (Coulomb's μ, or a law: docs/friction.md), model ("halfspace"),
                            layer = { thickness = h, shear_modulus = G3 }
    [load]                  normal (FN), tangential (Fx/(μFN)), lateral (Fy/(μFN)),
                            creepage = { longitudinal = ξ, lateral = η, spin = φ },
                            start, direction, start_steps, normal_history, rolled
    [discretization]        elements = [nx, ny], zone = [zx, zy], step (Δq/Δx), distance (/a)
    [solver]                method, tolerance, max_iterations, augmentation

Along x exactly one of ``load.tangential`` and ``load.creepage.longitudinal`` is given (neither:
``Fx = 0``), along y one of ``load.lateral`` and ``load.creepage.lateral`` (neither: ``Fy = 0``);
the spin ``creepage.spin`` (1/length) defaults to 0. Each value is a number or a history of q/a
(:mod:`rollqp.histories`), ``a`` the Hertz semi-axis along x.

Checked before any work, each failure an :class:`~rollqp.errors.InputError` naming the key and the
allowed range: radii nonzero (``< 0`` concave, ``inf`` straight), a concentrated contact (the summed
curvature positive in both directions, eq. 3D.3), the grid covering the Hertz ellipse with a row of elements to spare on every side, the
element aspect ratio ``dx/dy`` in :data:`rollqp.discretization.grid.ASPECT_RANGE`, the forces below the sliding
limit ``|(Fx, Fy)| < μFN`` at every step (a law varying over the contact: ``∫ μ p dA``,
:func:`rollqp.loads.sliding_limits`), the work bounded (elements, steps, result size), and a
method whose record solves 3D tangential steps on the friction disc
(:func:`rollqp.methods.require_3d`).
"""
from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass, field, fields
from typing import Any, ClassVar

import numpy as np

from ..errors import InputError
from ..friction import parse_friction
from ..histories import Constant, History, parse_history
from ..influence import DEFAULT_MODEL, get_model
from ..influence.layer import check_relative, parse_layer
from ..methods import DEFAULT_METHOD, require_3d
from ..profiles3d import Shape, parse_body
from .core import TwoBodyScene, check_top, table_keys
from .plain import plain
from ..validate import choice, integer, number
from ..operators.grid import MU_REFERENCE, Loads
from ..profiles.surface import Body, curvatures
from ..discretization.grid import ASPECT_RANGE, MAX_ELEMENTS, Grid
from ..closedforms.hertz_ellipse import hertz
from ..loads import check_load_path, has_load_path, limit_message, sliding_limits
from ..friction.capacity import worst
from ..materials import Materials
from ..patch import check_patch, computed_patch, equivalent_curvatures, extent_grid, grid_extent
from ..methods import REFERENCE_METHOD
from ..methods import scene_method_3d

__all__ = ["Scene3D", "Body3D", "Contact3D", "Creepage3D", "Load3D", "Discretization3D", "Solver3D",
           "scene_from_dict", "MAX_STEPS", "MAX_RESULT_BYTES"]

#: Largest magnitude of a prescribed creepage ξ, η, and of the spin's rigid slip ``φ·max(a, b)`` at the
#: contact's edge. A creepage is a slip velocity over the rolling speed: at 1 the bodies slide as fast as
#: they roll, two decades beyond the onset of full sliding of any contact the half-space model holds
#: (about ``3μ a/R``, ``a/R`` small); a larger value is a typing error, not a rolling contact.
MAX_CREEPAGE = 1.0
#: Largest number of rolling steps of a 3D scene.
MAX_STEPS = 100_000
#: Largest result a 3D scene may ask for (bytes: six fields of 8 bytes per element and state).
MAX_RESULT_BYTES = 4 << 30
STARTS = ("braked", "rolling")


# =========================================================================== parts
@dataclass(frozen=True)
class Body3D:
    """One body: principal radii ``radius`` (x–z plane) and ``radius_y`` (y–z plane), ``> 0`` (convex),
    ``< 0`` (concave: a groove) or ``inf`` (a straight generator; both ``inf``: a plane); Young's modulus ``E > 0``, Poisson's ratio
    ``nu`` in (−1, 0.5); a ``profile`` over (x, y) (:mod:`rollqp.profiles3d`: it replaces ``radius_y``
    or both radii)."""

    radius: float | None = None
    radius_y: float | None = None
    E: float = None
    nu: float = None
    profile: Any = None
    wear: float | None = None


@dataclass(frozen=True)
class Contact3D:
    """``dimension = 3``; Coulomb's coefficient ``friction`` (a number > 0); ``model``: the half-space; ``layer``: an
    interface layer ``{ thickness, shear_modulus }`` (:mod:`rollqp.influence.layer`), None: none."""

    friction: float
    dimension: int = 3
    model: str = DEFAULT_MODEL
    layer: Any = None

    @property
    def mu(self) -> float:
        """Coulomb's coefficient, or a law's reference ``μ`` (``load.tangential = Fx/(μ FN)``)."""
        return float(self.friction.reference)


@dataclass(frozen=True)
class Creepage3D:
    """Prescribed creepages as histories of q/a: ``longitudinal`` ξ, ``lateral`` η (None: the force
    along that axis is prescribed instead), ``spin`` φ (1/length; default 0)."""

    longitudinal: History | None = None
    lateral: History | None = None
    spin: History = Constant(0.0)


@dataclass(frozen=True)
class Load3D:
    """The normal force ``normal`` (FN, a force), the tangential forces as histories of q/a —
    ``tangential`` = Fx/(μFN), ``lateral`` = Fy/(μFN) — or the creepages (:class:`Creepage3D`), the
    ``start`` (``"braked"``: static shift to the initial forces, then rolling; ``"rolling"``: the
    steady state), the material's ``direction`` d = ±1 and the braked start's ``start_steps``; the load path
    (:mod:`rollqp.loads`): ``normal_history`` (FN(τ)/``normal``) and ``rolled`` (q(τ)/a, None: τ = q)."""

    normal: float
    tangential: History | None = None
    lateral: History | None = None
    creepage: Creepage3D = field(default_factory=Creepage3D)
    start: str = "braked"
    direction: int = -1
    start_steps: int = 1
    normal_history: History = Constant(1.0)
    rolled: History | None = None


@dataclass(frozen=True)
class Discretization3D:
    """``elements = (nx, ny)`` on the half-widths ``zone = (zx, zy)``·(a, b), or on ``extent = ((x0, x1),
    (y0, y1))`` in length units (with ``elements`` or ``element_size = (dx, dy)``); rolling steps of
    ``step``·dx up to ``distance``·a."""

    elements: tuple | None = None
    zone: tuple | None = None
    step: float = 1.0
    distance: float = 4.0
    extent: tuple | None = None
    element_size: tuple | None = None


@dataclass(frozen=True)
class Solver3D:
    """``method`` (a 3D method of the registry), ``tolerance`` (rollqp's nondimensional residual),
    ``max_iterations`` (per step; None: the method's own), ``augmentation`` (Newton's ``r``)."""

    method: str = DEFAULT_METHOD
    tolerance: float = 1e-10
    max_iterations: int | None = None
    augmentation: float | None = None


# =========================================================================== part checks
def _body(key, b: Body3D) -> Body3D:
    for k in ("E", "nu"):
        if getattr(b, k) is None:
            raise InputError(f"{key}.{k}", "missing required key")
    shape = parse_body({k: getattr(b, k) for k in ("radius", "radius_y", "profile") if getattr(b, k) is not None}, key)
    wear = None if b.wear is None else number(f"{key}.wear", b.wear, ">= 0 (Archard's k/H in 1/stress) or absent",
                                              lambda x: x >= 0)
    return Body3D(shape.rx, shape.ry, number(f"{key}.E", b.E, "> 0", lambda x: x > 0),
                  number(f"{key}.nu", b.nu, "in (-1, 0.5)", lambda x: -1.0 < x < 0.5), shape.profile_dict(), wear)


def _contact(c: Contact3D) -> Contact3D:
    law = parse_friction(c.friction)   # a number is Coulomb's coefficient; a table a law: checked once, here
    if c.dimension != 3 or isinstance(c.dimension, bool):
        raise InputError("contact.dimension", f"must be 3 in a 3D scene, got {c.dimension!r}")
    return Contact3D(law, 3, get_model(c.model, "contact.model", dimension=3).name, parse_layer(c.layer))


def _history(v, key):
    return None if v is None else parse_history(v, key)


def _load(ld: Load3D) -> Load3D:
    cr = ld.creepage
    if not isinstance(cr, Creepage3D):
        raise InputError("load.creepage", "must be a table { longitudinal = ξ, lateral = η, spin = φ } (numbers or "
                                          f"histories), got {cr!r}")
    cr = Creepage3D(_history(cr.longitudinal, "load.creepage.longitudinal"),
                    _history(cr.lateral, "load.creepage.lateral"), parse_history(cr.spin, "load.creepage.spin"))
    fx, fy = _history(ld.tangential, "load.tangential"), _history(ld.lateral, "load.lateral")
    for force, creep, name in ((fx, cr.longitudinal, "tangential"), (fy, cr.lateral, "lateral")):
        if force is not None and creep is not None:
            raise InputError(f"load.creepage.{'longitudinal' if name == 'tangential' else 'lateral'}",
                             f"give at most one of load.{name} (a force) and this creepage")
    fx = fx if fx is not None or cr.longitudinal is not None else Constant(0.0)
    fy = fy if fy is not None or cr.lateral is not None else Constant(0.0)
    direction = ld.direction
    if not isinstance(direction, (int, np.integer)) or isinstance(direction, bool) or direction not in (-1, 1):
        raise InputError("load.direction", f"must be -1 or +1, got {direction!r}")
    return Load3D(number("load.normal", ld.normal, "> 0 (the normal force FN)", lambda x: x > 0), fx, fy, cr,
                  choice("load.start", ld.start, STARTS), int(direction),
                  integer("load.start_steps", ld.start_steps, ">= 1 (and <= 10000)", lambda n: 1 <= n <= 10_000),
                  parse_history(ld.normal_history, "load.normal_history", constant_default=1.0),
                  _history(ld.rolled, "load.rolled"))


def _pair(key, v, what, check) -> tuple:
    if isinstance(v, (str, bytes, dict)) or not hasattr(v, "__len__") or len(v) != 2:
        raise InputError(key, f"must be a pair [along x, along y] of {what}, got {v!r}")
    return tuple(check(f"{key}[{i}]", x) for i, x in enumerate(v))


def _discretization(d: Discretization3D) -> Discretization3D:
    extent, size = grid_extent(d.extent, d.zone, d.element_size, d.elements)
    elements = None
    if size is None:
        elements = _pair("discretization.elements", (40, 40) if d.elements is None else d.elements, "integers >= 4",
                         lambda k, v: integer(k, v, ">= 4 (and <= 10000)", lambda n: 4 <= n <= 10_000))
        if elements[0] * elements[1] > MAX_ELEMENTS:
            raise InputError("discretization.elements", f"nx·ny = {elements[0] * elements[1]} exceeds {MAX_ELEMENTS} "
                                                        "elements")
    zone = None
    if extent is None:
        zone = _pair("discretization.zone", (1.25, 1.25) if d.zone is None else d.zone, "half-widths / (a, b) > 1",
                     lambda k, v: number(k, v, "> 1 (and <= 100): the grid covers the Hertz ellipse",
                                         lambda x: 1 < x <= 100))
    return Discretization3D(elements, zone,
                            number("discretization.step", d.step, "in (0, 8] (Δq/Δx)", lambda x: 0 < x <= 8),
                            number("discretization.distance", d.distance, "in [0, 1e6] (rolled distance / a)",
                                   lambda x: 0 <= x <= 1e6), extent, size)


def _solver(s: Solver3D) -> Solver3D:
    return Solver3D(
        require_3d(s.method, "solver.method"),
        number("solver.tolerance", s.tolerance, "in [1e-15, 1e-2]", lambda x: 1e-15 <= x <= 1e-2),
        None if s.max_iterations is None else integer("solver.max_iterations", s.max_iterations,
                                                      ">= 1 (and <= 100000) or absent", lambda n: 1 <= n <= 100_000),
        None if s.augmentation is None else number("solver.augmentation", s.augmentation,
                                                   "in [1e-6, 10] or absent (automatic)", lambda x: 1e-6 <= x <= 10))


# =========================================================================== the scene
@dataclass(frozen=True)
class Scene3D(TwoBodyScene):
    """A validated three-dimensional rolling-contact problem (module docstring; docs/scenes.md).

    The parts are checked key by key and the scene as a whole at construction; the derived
    quantities (:attr:`materials`, :attr:`ellipse`, :attr:`grid`, :attr:`dq`, :attr:`n_steps`) are
    what the run (:mod:`rollqp.march.grid`) builds its contact from.

    Examples
    --------
    >>> from rollqp import load_scene
    >>> s = load_scene("kalker-circular")
    >>> s.dimension, s.grid.nx, s.grid.ny, round(s.ellipse.a, 4), s.n_steps
    (3, 40, 40, 0.5857, 64)
    >>> s.replace(**{"bodies.A.radius": 0.0})
    Traceback (most recent call last):
    ...
    rollqp.errors.InputError: bodies.A.radius: must be a nonzero number (> 0 convex, < 0 concave, inf for a straight generator), got 0.0
    """

    name: str
    description: str
    A: Body3D
    B: Body3D
    contact: Contact3D
    load: Load3D
    discretization: Discretization3D = field(default_factory=Discretization3D)
    solver: Solver3D = field(default_factory=Solver3D)
    units: str = ""
    source: str = field(default="<dict>", compare=False)

    dimension: ClassVar[int] = 3
    _PARTS: ClassVar[tuple] = (("A", functools.partial(_body, "bodies.A")), ("B", functools.partial(_body, "bodies.B")),
                               ("contact", _contact), ("load", _load), ("discretization", _discretization),
                               ("solver", _solver))

    def _check_whole(self) -> None:
        _check_whole(self)

    @staticmethod
    def _plain(value: Any) -> Any:
        return _plain(value)

    @classmethod
    def from_dict(cls, d: Any, source: str = "<dict>", default_name: str = "scene") -> "Scene3D":
        """:func:`scene_from_dict`."""
        return scene_from_dict(d, source=source, default_name=default_name)

    # ------------------------------------------------------------------ derived
    @functools.cached_property
    def materials(self) -> Materials:
        """Kalker's combined constants G, ν, K (eq. 3D.10)."""
        return Materials.from_young(self.A.E, self.A.nu, self.B.E, self.B.nu)

    @functools.cached_property
    def shape(self) -> Shape:
        """The undeformed distance ``h(x, y, shift)`` of the two bodies (:mod:`rollqp.profiles3d`)."""
        return Shape(*(parse_body({k: v for k, v in (("radius", b.radius), ("radius_y", b.radius_y),
                                                      ("profile", b.profile)) if v is not None}, f"bodies.{name}")
                       for name, b in (("A", self.A), ("B", self.B))))

    @functools.cached_property
    def curvatures(self) -> tuple[float, float]:
        """``(A, B)`` of ``h = A x² + B y²`` (eq. 3D.3); with a profile, its curvatures at the origin where
        both are positive, else the equivalent curvatures of the computed contact
        (:func:`rollqp.patch.equivalent_curvatures`)."""
        if self.shape.hertzian:
            return curvatures(Body(self.A.radius, self.A.radius_y, "A"), Body(self.B.radius, self.B.radius_y, "B"))
        A, B = self.shape.curvatures()
        if A > 0 and B > 0:
            return A, B
        pt = self.patch
        return equivalent_curvatures(pt.a, pt.b, self.materials.Estar, self.load.normal)

    @functools.cached_property
    def patch(self):
        """The contact the normal step finds for the profile at the reference load (:mod:`rollqp.patch`),
        None for two paraboloids."""
        if self.shape.hertzian:
            return None
        A, B = self.shape.curvatures()
        guess = (A, B) if A > 0 and B > 0 else None
        return computed_patch(self.shape.at(0.0), self.grid, self.materials, self.load.normal,
                              scene_method_3d(Solver3D(REFERENCE_METHOD, 1e-12)), guess)

    @functools.cached_property
    def ellipse(self):
        """The Hertz ellipse of ``load.normal`` (a, b, p0, δ, E*: :class:`~rollqp.closedforms.hertz_ellipse.HertzEllipse`)."""
        A, B = self.curvatures
        return hertz(A, B, self.materials.Estar, self.load.normal)

    @functools.cached_property
    def grid(self) -> Grid:
        """The ``elements`` on ``zone·(a, b)`` (:meth:`Grid.for_ellipse <rollqp.discretization.grid.Grid.for_ellipse>`),
        or on ``extent`` (:func:`rollqp.patch.extent_grid`)."""
        d = self.discretization
        if d.extent is not None:
            return extent_grid(d.extent, d.elements, d.element_size)
        e = self.ellipse
        return Grid.for_ellipse(e.a, e.b, d.elements, d.zone)

    @property
    def mu(self) -> float:
        return self.contact.mu

    @property
    def dq(self) -> float:
        """Rolled distance per step, ``step·dx``."""
        return self.discretization.step * self.grid.dx

    @property
    def n_steps(self) -> int:
        """Rolling steps K: ``distance·a/Δq``, rounded if within 1e-9 of an integer, else up."""
        ratio = self.discretization.distance * self.ellipse.a / self.dq
        r = round(ratio)
        return int(r) if abs(r - ratio) <= 1e-9 * max(ratio, 1.0) else int(math.ceil(ratio))

    @property
    def time_steps(self) -> np.ndarray:
        """The time-like parameter ``τ_k = k·Δq``, ``k = 0 … K`` (length units): the argument of the load
        histories (the rolled distance itself without ``load.rolled``)."""
        return np.arange(self.n_steps + 1) * self.dq

    @property
    def q_steps(self) -> np.ndarray:
        """Rolled distances ``q_k``, ``k = 0 … K``: ``k·Δq``, or ``q(τ_k)`` with ``load.rolled``
        (:mod:`rollqp.kinematics`)."""
        return self.rolled_distance(self.time_steps)

    def rolled_distance(self, tau):
        """``q(τ) = a·rolled(τ/a)`` (length units); ``τ`` itself without ``load.rolled``."""
        if self.load.rolled is None:
            return np.asarray(tau, dtype=float)
        return self.ellipse.a * np.asarray(self.load.rolled(np.asarray(tau, dtype=float) / self.ellipse.a), dtype=float)

    @property
    def element_length(self) -> float:
        """The element length along the rolling direction, ``dx`` (:func:`rollqp.kinematics.plan`'s unit)."""
        return self.grid.dx

    def contact_elements(self) -> int:
        """The elements whose centres lie inside the Hertz ellipse: about those in contact (the size of
        a step's conic program, which :mod:`rollqp.advice.grid` estimates from)."""
        e, g = self.ellipse, self.grid
        X, Y = np.meshgrid(g.x / e.a, g.y / e.b)
        return int(np.sum(X * X + Y * Y < 1))

    def loads_at(self, q: float) -> Loads:
        """The tangential loading at the rolled distance ``q`` (length units): forces on A from the
        ratios (``Fx = tangential·μFN``), creepages as given, the spin."""
        ld, s = self.load, float(q) / self.ellipse.a
        cap = self.mu * ld.normal
        cr = ld.creepage
        val = lambda h: None if h is None else float(h(s))  # noqa: E731
        Fx, Fy = val(ld.tangential), val(ld.lateral)
        return Loads(Fx=None if Fx is None else Fx * cap, xi=val(cr.longitudinal),
                     Fy=None if Fy is None else Fy * cap, eta=val(cr.lateral), phi=float(cr.spin(s)), q=float(q))

    # ------------------------------------------------------------------ output
    def to_dict(self) -> dict:
        """The full scene as a nested plain dict, defaults filled in (constant histories as numbers)."""
        ld, d = self.load, self.discretization
        loads = {"normal": ld.normal, **_opt("tangential", ld.tangential), **_opt("lateral", ld.lateral),
                 "creepage": {**_opt("longitudinal", ld.creepage.longitudinal),
                              **_opt("lateral", ld.creepage.lateral), "spin": _plain(ld.creepage.spin)},
                 "start": ld.start, "direction": ld.direction, "start_steps": ld.start_steps,
                 **({} if ld.normal_history == Constant(1.0) else {"normal_history": _plain(ld.normal_history)}),
                 **_opt("rolled", ld.rolled)}
        solver = {k.name: getattr(self.solver, k.name) for k in fields(self.solver)
                  if getattr(self.solver, k.name) is not None}
        disc = {"elements": d.elements, "zone": d.zone, "extent": d.extent, "element_size": d.element_size}
        disc = {k: [list(v) if isinstance(v, tuple) else v for v in val] for k, val in disc.items() if val is not None}
        return {"name": self.name, "description": self.description, **({"units": self.units} if self.units else {}),
                "bodies": {k: {f: v for f, v in dataclasses.asdict(b).items() if v is not None}
                           for k, b in (("A", self.A), ("B", self.B))},
                "contact": {"dimension": 3, "friction": plain(self.contact.friction), "model": self.contact.model,
                            **({} if self.contact.layer is None else {"layer": plain(self.contact.layer)})},
                "load": loads,
                "discretization": {**disc, "step": d.step, "distance": d.distance},
                "solver": solver}


def _plain(v):
    if isinstance(v, Constant):
        return v.value
    if isinstance(v, History):
        return v.to_dict()
    if isinstance(v, np.generic):
        return v.item()
    return v


def _opt(key, v) -> dict:
    return {} if v is None else {key: _plain(v)}


# =========================================================================== the scene as a whole
def _check_whole(scene) -> None:
    """The derived quantities, the grid against the ellipse (with a profile: against the computed contact),
    the work, the sliding limit (module docstring)."""
    if scene.discretization.extent is None and not scene.shape.hertzian:
        A, B = scene.shape.curvatures()
        if not (A > 0 and B > 0):
            raise InputError("discretization.extent", f"required: the profile's curvature at the origin is not "
                                                      f"positive (A = {A:.4g}, B = {B:.4g}), so there is no Hertz "
                                                      "ellipse to scale discretization.zone by; give the grid in length "
                                                      "units, extent = [[x0, x1], [y0, y1]]")
    _check_ellipse(scene)
    check_relative(scene.contact.layer, math.sqrt(scene.ellipse.a * scene.ellipse.b), scene.materials.Estar)
    for key, body in (("bodies.A", scene.A), ("bodies.B", scene.B)):  # Archard's k·p0/H <= 1, as in 2D
        if body.wear is not None and not body.wear * scene.ellipse.p0 <= 1.0:
            raise InputError(f"{key}.wear", f"must be a number in [0, 1/p0 = {1.0 / scene.ellipse.p0:.6g}] (k/H in "
                                            f"1/stress: Archard's k·p0/H is at most 1), got {body.wear!r}")
    if scene.discretization.extent is None:
        _check_grid(scene)
    elif scene.shape.hertzian and not scene.grid.covers(scene.ellipse.a, scene.ellipse.b):
        raise InputError("discretization.extent", f"the grid must cover the Hertz ellipse (a = {scene.ellipse.a:.4g}, "
                                                  f"b = {scene.ellipse.b:.4g}) with a row of elements to spare on each "
                                                  "side; widen it")
    if not scene.shape.hertzian:
        scene.shape.check_cover(scene.grid, lambda k: f"bodies.{k}.profile")
        check_patch(scene.patch, "discretization.extent" if scene.discretization.extent is not None
                    else "discretization.zone")
    _check_work(scene)
    _check_memory(scene)
    if has_load_path(scene):
        check_load_path(scene)      # the sliding limit of the current load among them
    else:
        _check_sliding_limit(scene)
    _check_creepages(scene)


#: The range of a contact's compliance c/E* (length per stress) whose influence coefficients, and their sums over
#: up to a million elements, are finite normal floating-point numbers (1e±308), with 1e58 to spare.
COMPLIANCE_RANGE = (1e-250, 1e250)


def _check_ellipse(scene) -> None:
    try:
        e = scene.ellipse
    except InputError as err:
        if err.key.startswith("bodies."):
            raise
        key = "bodies.A.radius" if err.key == "A" else "bodies.A.radius_y"
        raise InputError(key, str(err).split(": ", 1)[-1]) from None
    except ArithmeticError:   # the ellipse's lengths under- or overflow (a load of 1e-300 on moduli of 1e300)
        raise InputError("load.normal", f"the Hertz ellipse of FN = {scene.load.normal!r} with these radii and moduli "
                                        "is not a finite, nonzero size: extreme input; use other units") from None
    if not all(math.isfinite(v) and v > 0 for v in (e.a, e.b, e.p0, e.delta)):
        raise InputError("load.normal", f"the Hertz ellipse of FN = {scene.load.normal!r} with these radii and moduli "
                                        f"is not finite (a = {e.a:.3g}, b = {e.b:.3g}, p0 = {e.p0:.3g}): extreme input")
    # the influence coefficients are about c/E* (a displacement per unit pressure on an element of size c): beyond
    # this range their sums over the grid overflow or underflow in floating point, whatever the units
    flex = math.sqrt(e.a * e.b) / scene.materials.Estar
    if not COMPLIANCE_RANGE[0] <= flex <= COMPLIANCE_RANGE[1]:
        soft = min("AB", key=lambda k: getattr(scene, k).E / (1 - getattr(scene, k).nu ** 2))
        key = f"bodies.{soft if flex > 1 else 'AB'[soft == 'A']}.E"
        raise InputError(key, f"the contact's compliance c/E* = {flex:.3g} (c = sqrt(ab) = {math.sqrt(e.a * e.b):.3g}, "
                              f"E* = {scene.materials.Estar:.3g}) must be in [{COMPLIANCE_RANGE[0]:g}, "
                              f"{COMPLIANCE_RANGE[1]:g}]: the influence coefficients would not be finite numbers; "
                              "use other units")


def _check_grid(scene) -> None:
    e, d = scene.ellipse, scene.discretization
    (nx, ny), (zx, zy) = d.elements, d.zone
    dx, dy = 2 * zx * e.a / nx, 2 * zy * e.b / ny
    lo, hi = ASPECT_RANGE
    if not lo <= dx / dy <= hi:
        square = max(4, round(nx * zy * e.b / (zx * e.a)))
        raise InputError("discretization.elements", f"element aspect ratio dx/dy = {dx / dy:.4g} must be in [{lo:g}, "
                                                    f"{hi:g}]: the influence coefficients are exact, but the tractions "
                                                    f"are resolved only to O(max(dx, dy)) (docs/validation3d.md §8); "
                                                    f"square elements: [{nx}, {square}]")
    for n, z, axis in ((nx, zx, "x"), (ny, zy, "y")):
        if z * (1 - 2 / n) < 1:
            need = math.ceil(2 / (1 - 1 / z)) + 1 if z > 1 else None
            raise InputError("discretization.zone", f"the grid must cover the Hertz ellipse with a row of elements to "
                                                    f"spare on each side: zone·(1 − 2/elements) >= 1 along {axis}, got "
                                                    f"{z:g}·(1 − 2/{n}) = {z * (1 - 2 / n):.4g}; raise the zone or the "
                                                    f"elements (at least {need} elements along {axis} with zone {z:g})")


def _check_work(scene) -> None:
    K = scene.n_steps
    if K > MAX_STEPS:
        raise InputError("discretization.distance", f"asks for {K} rolling steps, more than {MAX_STEPS}: a shorter "
                                                    "distance or a longer discretization.step")
    size = 48.0 * (K + 1) * scene.grid.n
    if size > MAX_RESULT_BYTES:
        raise InputError("discretization.distance", f"the result of {K + 1} states of {scene.grid.n} elements would be "
                                                    f"{size / 2 ** 30:.3g} GiB, more than {MAX_RESULT_BYTES >> 30} GiB: "
                                                    "fewer steps or elements")


def _check_memory(scene) -> None:
    """A slip-velocity law's memory is carried with the material from step to step: the steady state of a rolling
    start has no previous step to carry it from (as in 2D: docs/friction.md)."""
    law = scene.contact.friction
    if getattr(law, "kind", None) == "slip" and law.memory > 0 and scene.load.start == "rolling":
        raise InputError("contact.friction.memory", f"= {law.memory!r} needs load.start = 'braked': a steady rolling "
                                                    "start cannot carry the friction memory along the material "
                                                    "(or set memory = 0)")


def _check_sliding_limit(scene) -> None:
    """Prescribed forces: ``|(Fx, Fy)|/(μFN) < 1`` at every step (and the histories' breakpoints); with a friction
    law varying over the contact, below its own sliding limit ``∫ μ p dA/(μ FN)`` (:func:`rollqp.loads.sliding_limits`)."""
    ld = scene.load
    if ld.tangential is None and ld.lateral is None:
        return
    s_end = float(scene.time_steps[-1]) / scene.ellipse.a
    s = scene.time_steps / scene.ellipse.a
    for h in (ld.tangential, ld.lateral):
        if h is not None:
            s = np.union1d(s, h.critical_points(s_end))
    fx = ld.tangential(s) if ld.tangential is not None else 0.0
    fy = ld.lateral(s) if ld.lateral is not None else 0.0
    r = np.hypot(fx, fy) * np.ones_like(s)
    k = int(np.argmax(r))
    if scene.mu == 0 and r[k] != 0:   # as in 2D (rollqp.scene.checks.check_tangential)
        key = "load.tangential" if ld.tangential is not None else "load.lateral"
        raise InputError(key, f"must be 0 when contact.friction = 0 (a force over mu FN, and |(Fx, Fy)| <= mu FN = 0), "
                              f"got |(Fx, Fy)|/(mu FN) = {r[k]:.6g} at q = {s[k]:.6g} a; prescribe creepages instead")
    lim = sliding_limits(scene, s, 1.0, r)    # a law varying over the contact: its own limit (rollqp.loads)
    if lim is not None:
        c, limit = lim
        k = worst(r, limit)
        if not r[k] < limit[k]:
            key = "load.tangential" if ld.tangential is not None else "load.lateral"
            raise InputError(key, f"|(Fx, Fy)|/(mu FN) = {r[k]:.6g} at q = {s[k]:.6g} a "
                                  + limit_message(scene, c[k], limit[k]))
        return
    if not r[k] < 1:
        key = "load.tangential" if ld.tangential is not None else "load.lateral"
        raise InputError(key, f"|(Fx, Fy)|/(mu FN) = {r[k]:.6g} at q = {s[k]:.6g} a must be < 1: a stick solution "
                              "exists only below the sliding limit (prescribe creepages for gross sliding)")


#: A prescribed nonzero creepage must set tractions of at least this many times the tangential steps' tolerance
#: (in their unit): the answer is then resolved to 1 % or better.
MEANINGFUL = 100.0


def _check_creepages(scene) -> None:
    """Prescribed creepages: ``|ξ|, |η| <= MAX_CREEPAGE`` and ``|φ|·max(a, b) <= MAX_CREEPAGE`` at every step
    (and the histories' breakpoints)."""
    cr, e = scene.load.creepage, scene.ellipse
    s_end = float(scene.time_steps[-1]) / e.a
    arm = max(e.a, e.b)
    for h, key, scale, what in ((cr.longitudinal, "longitudinal", 1.0, "|xi|"), (cr.lateral, "lateral", 1.0, "|eta|"),
                                (cr.spin, "spin", arm, "|phi|·max(a, b)")):
        if h is None:
            continue
        s = np.union1d(scene.time_steps / e.a, h.critical_points(s_end))
        v = np.abs(h(s) * np.ones_like(s)) * scale
        k = int(np.argmax(v))
        if not v[k] <= MAX_CREEPAGE:
            here = f" (here |phi| <= {MAX_CREEPAGE / arm:.4g} per length unit)" if key == "spin" else ""
            raise InputError(f"load.creepage.{key}", f"{what} = {v[k]:.4g} at q = {s[k]:.4g} a must be <= "
                                                     f"{MAX_CREEPAGE:g}{here}: a creepage is a slip velocity over the "
                                                     f"rolling speed, and full sliding sets in near 3 mu a/R (a few 1e-3 "
                                                     f"for steel wheels on rails): larger is a typing error")
        # the tractions a creepage sets are about E* |xi| (at most mu p0): where that is below the tangential steps'
        # tolerance a step stops at zero tractions, however wrong (a creepage of 1e-3 under FN = 1e30)
        mu = scene.mu
        if mu > 0:
            unit = e.p0 * min(1.0, mu / MU_REFERENCE)          # the tangential steps' stress unit (rollqp.operators.grid)
            lowest = float(np.min(v[v > 0], initial=np.inf)) * scene.materials.Estar / unit
            if lowest < MEANINGFUL * scene.solver.tolerance:
                raise InputError(f"load.creepage.{key}", f"{what} = {float(np.min(v[v > 0])):.4g} sets tractions of "
                                                         f"about {lowest:.3g} times the unit {unit:.3g} of the tangential "
                                                         f"steps, below {MEANINGFUL:g} times solver.tolerance: at this "
                                                         f"load (p0 = {e.p0:.4g}) the steps would stop at zero tractions; "
                                                         f"a larger creepage, a smaller load.normal, or a smaller "
                                                         f"solver.tolerance")


# =========================================================================== from a dict
_TABLES = {"contact": Contact3D, "load": Load3D, "discretization": Discretization3D, "solver": Solver3D}


def _table(d: Any, key: str, cls: type, also=()) -> dict:
    return table_keys(d, key, cls, also, where=f"[{key}] of a 3D scene", each_missing=True)


def scene_from_dict(d: Any, source: str = "<dict>", default_name: str = "scene") -> Scene3D:
    """Build and validate a 3D scene from its nested dict (the parsed TOML); every invalid input is an
    :class:`InputError` naming the dotted key."""
    check_top(d)
    bodies = d["bodies"]
    if not isinstance(bodies, dict) or set(bodies) != {"A", "B"}:
        raise InputError("bodies", "must hold exactly the tables [bodies.A] and [bodies.B] (radius, radius_y, E, nu)")
    A, B = (Body3D(**_table(bodies[k], f"bodies.{k}", Body3D, ("E", "nu"))) for k in ("A", "B"))
    parts = {k: _table(d.get(k, {}), k, cls) for k, cls in _TABLES.items()}
    if "creepage" in parts["load"]:
        cr = parts["load"]["creepage"]
        parts["load"]["creepage"] = Creepage3D(**_table(cr, "load.creepage", Creepage3D)) if isinstance(cr, dict) else cr
    return Scene3D(name=d.get("name", default_name), description=d.get("description", ""), units=d.get("units", ""),
                   A=A, B=B, contact=Contact3D(**parts["contact"]), load=Load3D(**parts["load"]),
                   discretization=Discretization3D(**parts["discretization"]), solver=Solver3D(**parts["solver"]),
                   source=source)
