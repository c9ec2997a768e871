"""Scenes: the validated description of one transient rolling-contact problem.

A scene is read from a TOML file (the contract is SPEC.md, "Scene file"), from the name of a
built-in scene (the files in ``rollqp/scenes/``) or from a plain dict of the same nesting::

    name, description
    [bodies.A] [bodies.B]   radius, E, nu, shaft_radius
    [contact]               friction, model, coupling, reference_distance, bem_outer_elements,
                            bem_inner_elements
    [load]                  normal, normal_history, tangential | creepage, start, direction,
                            start_steps, approach
    [discretization]        elements, element, zone, step, formulation, distance
    [solver]                method, tolerance, max_iterations, augmentation

Units are the user's, as long as they are consistent (the paper: N and mm). Loads are per unit
axial length. Load histories are functions of the rolled distance q in units of a_H
(:mod:`rollqp.histories`).

Every invalid input is an :class:`~rollqp.errors.InputError` naming the dotted key
(``bodies.A.nu``) and the allowed range or values; unknown keys get the closest valid name.
Besides the per-key ranges, a scene is checked as a whole (FORMULATION.md §1, §9):

* the normal load stays >= 0 over the rolled distance; where it is 0 the bodies are out of
  contact (the driver records an unloaded state, :func:`rollqp.run`) and Q must be 0;
* the largest Hertz half-width, a_H·sqrt(max P/P̄), stays clear of the zone's edges by at
  least three quarters of an element: a_H·sqrt(max P/P̄) < L·(1 − 1.5/elements), L = zone·a_H
  (the element length is 2L/elements);
* with ``formulation = "convective-local"``, Δq is at most the node spacing
  (``discretization.step`` <= 1 for constant and linear, <= 0.5 for quadratic elements):
  the upwind transport is unstable beyond it (docs/stability.md);
* where a tangential load is prescribed, a stick solution exists: ``|Q| < μP``, i.e.
  ``|Q/(μP̄)| / (P/P̄) < 1``, at every step (and at the histories' breakpoints and peaks).

Sign convention (FORMULATION.md §1): material moves through the contact with direction
d = ``load.direction`` (the paper's examples: d = −1) and enters at the leading edge x = −d·L.
"""
from __future__ import annotations

import dataclasses
import difflib
import math
import os
from dataclasses import dataclass, field, fields
from importlib import resources
from numbers import Real
from pathlib import Path
from typing import Any, Callable

import numpy as np

try:  # Python >= 3.11
    import tomllib
except ModuleNotFoundError:  # pragma: no cover - Python 3.10
    import tomli as tomllib  # type: ignore[no-redef]

from .errors import InputError
from .histories import Constant, History, parse_history
from .methods import METHOD_NAMES, check_name

__all__ = ["METHODS", "MODELS", "COUPLINGS", "STARTS", "ELEMENT_TYPES", "FORMULATION_TYPES",
           "Body", "Contact", "Load", "Discretization", "SolverSettings", "Scene",
           "load_scene", "scene_from_dict", "scene_from_toml", "builtin_scenes"]

METHODS = METHOD_NAMES  # the method registry (rollqp/methods/__init__.py), optional backends included
MODELS = ("halfspace", "bem")
COUPLINGS = ("auto", "full", "goodman", "off")
STARTS = ("braked", "rolling")
ELEMENT_TYPES = ("constant", "linear", "quadratic")
FORMULATION_TYPES = ("material", "convective-local")

#: ``|β|`` above which ``coupling = "auto"`` means full coupling
BETA_ZERO = 1e-12
#: free elements required between the largest contact and each end of the zone
EDGE_ELEMENTS = 1.5
#: largest ``discretization.step`` (Δq/Le) of the convective-local formulation: the node
#: spacing h/Le (:meth:`Scene._check_convective_step`)
CONVECTIVE_STEP_MAX = {"constant": 1.0, "linear": 1.0, "quadratic": 0.5}
#: allowed ``solver.augmentation`` (nondimensional r): the band in which newton converged on
#: every hard case (docs/stability.md, ``python benchmarks/hard_cases.py --only "r="``)
AUGMENTATION_MIN, AUGMENTATION_MAX = 1e-6, 10.0


# =========================================================================== parts
@dataclass(frozen=True)
class Body:
    """One elastic cylinder.

    Parameters
    ----------
    radius : float
        Outer radius R_A or R_B, ``> 0``.
    E : float
        Young's modulus, ``> 0``.
    nu : float
        Poisson's ratio, in (−1, 0.5).
    shaft_radius : float or None
        Inner (shaft) radius of the annular cylinder, in (0, radius); used by
        ``contact.model = "bem"`` only. None: not given.
    """

    radius: float
    E: float
    nu: float
    shaft_radius: float | None = None

    @property
    def G(self) -> float:
        """Shear modulus G = E / (2(1 + ν))."""
        return self.E / (2.0 * (1.0 + self.nu))


@dataclass(frozen=True)
class Contact:
    """Contact law and elastic model.

    Parameters
    ----------
    friction : float
        Coulomb coefficient μ, finite and ``>= 0``.
    model : {"halfspace", "bem"}
        Half-space influence (FORMULATION.md §3) or true geometry by BEM (§8).
    coupling : {"auto", "full", "goodman", "off"}
        Normal–tangential coupling level (§3); "auto" is "full" iff β ≠ 0, else "off".
    reference_distance : float or None
        d_ref of the 2D half-space kernel ``−ln(|x − s|/d_ref)``, ``> 0``; None: the relative
        radius R (see :attr:`Scene.reference_distance_value`).
    bem_outer_elements, bem_inner_elements : int or None
        ``model = "bem"``: elements on each roller's outer circle outside the strip and on its
        shaft, in [3, 2000]; None: the paper's 19 and 16 (docs/bem.md).
    """

    friction: float
    model: str = "halfspace"
    coupling: str = "auto"
    reference_distance: float | None = None
    bem_outer_elements: int | None = None
    bem_inner_elements: int | None = None


@dataclass(frozen=True)
class Load:
    """Loads and start, as histories of the rolled distance q/a_H.

    Parameters
    ----------
    normal : float
        Reference normal load P̄ per unit length, ``> 0``; defines a_H and p0.
    normal_history : History
        P(q) = P̄·normal_history(q/a_H); must stay >= 0 (0: out of contact).
    tangential : History or None
        Q(q) = μ·P̄·tangential(q/a_H) on body A (Q/(μP̄), P̄ the reference load).
    creepage : History or None
        Prescribed creepage ξ(q) = creepage(q/a_H) instead of Q. Exactly one of
        ``tangential`` and ``creepage`` is set in a validated scene (neither given:
        tangential constant 0).
    start : {"braked", "rolling"}
        Braked start (Hertz then Cattaneo, FORMULATION.md §9) or steady rolling.
    direction : {-1, +1}
        d = sgn(V), the direction of the material through the contact (paper: −1).
    start_steps : int
        Quasi-static steps applying the normal load of a braked start, ``>= 1``.
    approach : History or None
        Prescribed approach of the shaft centres δ(q) = approach(q/a_H) (length units) instead
        of the normal load (the normal-side analogue of ``creepage``); ``normal`` stays the
        reference load P̄ of a_H, p0 and the zone. Meaningful with ``contact.model = "bem"``
        (rigid shafts); on the half-space δ depends on ``reference_distance`` (docs/bem.md).
    """

    normal: float
    normal_history: History = Constant(1.0)
    tangential: History | None = None
    creepage: History | None = None
    start: str = "braked"
    direction: int = -1
    start_steps: int = 1
    approach: History | None = None


@dataclass(frozen=True)
class Discretization:
    """Discretization of the strip and of the rolled distance (FORMULATION.md §2, §4).

    Parameters
    ----------
    elements : int
        Elements on the potential contact zone [−L, L], in [2, 20000].
    element : {"constant", "linear", "quadratic"}
        Traction shape functions (the paper's QCE: "quadratic").
    zone : float
        L / a_H, ``> 1``.
    step : float
        Δq / Le, in (0, 8].
    formulation : {"material", "convective-local"}
        Time discretization of the slip (§4).
    distance : float
        Rolled distance / a_H, ``>= 0``.
    """

    elements: int = 40
    element: str = "quadratic"
    zone: float = 1.25
    step: float = 0.5
    formulation: str = "material"
    distance: float = 6.0


@dataclass(frozen=True)
class SolverSettings:
    """The step solver.

    Parameters
    ----------
    method : str
        One of :data:`METHODS`.
    tolerance : float
        Nondimensional residual tolerance, in [1e-15, 1e-2].
    max_iterations : int or None
        Iteration limit per step, ``>= 1``: Newton iterations (``newton``; each half of
        ``nt-newton``), outer N–T iterations (``nt-newton``, and the QP methods on a coupled
        scene), and the QP solver's own iterations per QP (the ``qp-*`` and ``qps-*`` methods).
        None (default): each method's own limit (Newton 200, N–T 200 outer iterations, the QP
        solvers' defaults).
    augmentation : float or None
        The Newton methods' nondimensional augmentation ``r`` of ``min(p, r g)`` and
        ``Proj(t − r s)`` (FORMULATION.md §5), the same for the normal and the tangential rows,
        in [:data:`AUGMENTATION_MIN`, :data:`AUGMENTATION_MAX`] (the band in which ``newton``
        converges on every hard case, docs/stability.md). None (default): automatic,
        ``1/mean(diag Â)`` (normal) and ``Δq̂/mean(diag Â)`` (tangential), see
        :mod:`rollqp.methods.newton`. Ignored by the QP methods. The solution does not depend
        on ``r``, only the Newton path does.
    """

    method: str = "newton"
    tolerance: float = 1e-10
    max_iterations: int | None = None
    augmentation: float | None = None


# =========================================================================== value checks
def _is_real(v: Any) -> bool:
    return isinstance(v, Real) and not isinstance(v, bool)


def _number(key: str, v: Any, allowed: str, ok: Callable[[float], bool]) -> float:
    """``float(v)`` if ``v`` is a finite real number with ``ok(v)``, else an InputError."""
    if not _is_real(v) or not math.isfinite(float(v)) or not ok(float(v)):
        raise InputError(key, f"must be a number {allowed}, got {v!r}")
    return float(v)


def _integer(key: str, v: Any, allowed: str, ok: Callable[[int], bool]) -> int:
    """``int(v)`` if ``v`` is an integer (not a bool, not a float) with ``ok(v)``."""
    if not isinstance(v, (int, np.integer)) or isinstance(v, bool) or not ok(int(v)):
        raise InputError(key, f"must be an integer {allowed}, got {v!r}")
    return int(v)


def _suggestion(word: Any, choices) -> str:
    """``"; did you mean 'x'?"`` for the closest of ``choices`` (case-insensitive), or ``""``."""
    if not isinstance(word, str):
        return ""
    lower = {c.lower(): c for c in choices}
    m = difflib.get_close_matches(word.lower(), list(lower), n=1, cutoff=0.6)
    return f"; did you mean {lower[m[0]]!r}?" if m else ""


def _choice(key: str, v: Any, choices: tuple[str, ...]) -> str:
    if not isinstance(v, str) or v not in choices:
        raise InputError(key, f"must be one of {', '.join(map(repr, choices))}, got {v!r}"
                              + _suggestion(v, choices))
    return v


def _string(key: str, v: Any) -> str:
    if not isinstance(v, str):
        raise InputError(key, f"must be a string, got {v!r}")
    return v


def _check_body(key: str, b: Any) -> Body:
    if not isinstance(b, Body):
        raise InputError(key, f"must be a Body, got {b!r}")
    radius = _number(f"{key}.radius", b.radius, "> 0", lambda x: x > 0)
    E = _number(f"{key}.E", b.E, "> 0", lambda x: x > 0)
    nu = _number(f"{key}.nu", b.nu, "in (-1, 0.5)", lambda x: -1.0 < x < 0.5)
    shaft = b.shaft_radius
    if shaft is not None:
        shaft = _number(f"{key}.shaft_radius", shaft, f"in (0, radius = {radius!r}) or absent",
                        lambda x: 0.0 < x < radius)
    return Body(radius, E, nu, shaft)


def _check_contact(c: Any) -> Contact:
    if not isinstance(c, Contact):
        raise InputError("contact", f"must be a Contact, got {c!r}")
    mu = _number("contact.friction", c.friction, ">= 0", lambda x: x >= 0)
    model = _choice("contact.model", c.model, MODELS)
    coupling = _choice("contact.coupling", c.coupling, COUPLINGS)
    d = c.reference_distance
    if d is not None:
        d = _number("contact.reference_distance", d, "> 0 or absent (then R)", lambda x: x > 0)
    mesh = [None if getattr(c, k) is None else
            _integer(f"contact.{k}", getattr(c, k), "in [3, 2000] or absent", lambda n: 3 <= n <= 2000)
            for k in ("bem_outer_elements", "bem_inner_elements")]
    return Contact(mu, model, coupling, d, *mesh)


def _check_load(ld: Any) -> Load:
    if not isinstance(ld, Load):
        raise InputError("load", f"must be a Load, got {ld!r}")
    normal = _number("load.normal", ld.normal, "> 0", lambda x: x > 0)
    nh = parse_history(ld.normal_history, "load.normal_history", constant_default=1.0)
    tang = None if ld.tangential is None else parse_history(ld.tangential, "load.tangential")
    creep = None if ld.creepage is None else parse_history(ld.creepage, "load.creepage")
    if tang is not None and creep is not None:
        raise InputError("load.creepage", "give exactly one of load.tangential and "
                                          "load.creepage, not both")
    if tang is None and creep is None:
        tang = Constant(0.0)
    start = _choice("load.start", ld.start, STARTS)
    direction = ld.direction
    if not isinstance(direction, (int, np.integer)) or isinstance(direction, bool) \
            or direction not in (-1, 1):
        raise InputError("load.direction", f"must be -1 or +1, got {direction!r}")
    steps = _integer("load.start_steps", ld.start_steps, ">= 1", lambda n: n >= 1)
    approach = None if ld.approach is None else parse_history(ld.approach, "load.approach")
    if approach is not None and nh != Constant(1.0):
        raise InputError("load.approach", "give at most one of load.normal_history and load.approach "
                                          "(with a prescribed approach the normal load is an unknown)")
    return Load(normal, nh, tang, creep, start, int(direction), steps, approach)


def _check_discretization(d: Any) -> Discretization:
    if not isinstance(d, Discretization):
        raise InputError("discretization", f"must be a Discretization, got {d!r}")
    return Discretization(
        elements=_integer("discretization.elements", d.elements, ">= 2 (and <= 20000)",
                          lambda n: 2 <= n <= 20000),
        element=_choice("discretization.element", d.element, ELEMENT_TYPES),
        zone=_number("discretization.zone", d.zone, "> 1", lambda x: x > 1),
        step=_number("discretization.step", d.step, "in (0, 8]", lambda x: 0 < x <= 8),
        formulation=_choice("discretization.formulation", d.formulation, FORMULATION_TYPES),
        distance=_number("discretization.distance", d.distance, ">= 0", lambda x: x >= 0))


def _check_solver(s: Any) -> SolverSettings:
    if not isinstance(s, SolverSettings):
        raise InputError("solver", f"must be a SolverSettings, got {s!r}")
    return SolverSettings(
        method=check_name(s.method, "solver.method"),
        tolerance=_number("solver.tolerance", s.tolerance, "in [1e-15, 1e-2]",
                          lambda x: 1e-15 <= x <= 1e-2),
        max_iterations=None if s.max_iterations is None else _integer(
            "solver.max_iterations", s.max_iterations, ">= 1 or absent (each method's default)", lambda n: n >= 1),
        augmentation=None if s.augmentation is None else _number(
            "solver.augmentation", s.augmentation,
            f"in [{AUGMENTATION_MIN:g}, {AUGMENTATION_MAX:g}] or absent (automatic)",
            lambda x: AUGMENTATION_MIN <= x <= AUGMENTATION_MAX))


# =========================================================================== scene
@dataclass(frozen=True)
class Scene:
    """A validated rolling-contact problem (SPEC.md, "Scene file").

    Construction validates every field and the scene as a whole and normalizes the values
    (numbers to float, history tables to :class:`~rollqp.histories.History`); the parts
    (:class:`Body`, …) are plain records checked here, with their dotted scene keys.

    Parameters
    ----------
    name, description : str
        Identification; the description is one line.
    A, B : Body
        The two cylinders (``[bodies.A]``, ``[bodies.B]``); tangential traction and creepage
        are reported for body A.
    contact : Contact
    load : Load
    discretization : Discretization
    solver : SolverSettings
    source : str
        Where the scene came from (a path, ``builtin:<name>`` or ``<dict>``); not compared.

    Raises
    ------
    InputError
        Naming the dotted key and the allowed range.
    """

    name: str
    description: str
    A: Body
    B: Body
    contact: Contact
    load: Load
    discretization: Discretization = Discretization()
    solver: SolverSettings = SolverSettings()
    source: str = field(default="<dict>", compare=False)

    def __post_init__(self):
        put = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731 - frozen dataclass
        put("name", _string("name", self.name))
        put("description", _string("description", self.description))
        put("A", _check_body("bodies.A", self.A))
        put("B", _check_body("bodies.B", self.B))
        put("contact", _check_contact(self.contact))
        put("load", _check_load(self.load))
        put("discretization", _check_discretization(self.discretization))
        put("solver", _check_solver(self.solver))
        put("source", str(self.source))
        self._check_whole()

    # ------------------------------------------------------------------ whole-scene checks
    @property
    def q_end(self) -> float:
        """Last rolled distance the loads are evaluated at, in units of a_H.

        ``max(distance, n_steps·Δq/a_H)``: the last step may overshoot ``distance`` by less
        than one step when ``distance`` is not a whole number of steps.
        """
        return max(self.discretization.distance, self.n_steps * self.dq / self.a_H)

    def _check_whole(self) -> None:
        disc, load = self.discretization, self.load
        q_end = self.q_end
        nmin, nmax = load.normal_history.extremes(q_end)
        if not nmin >= 0:
            raise InputError("load.normal_history",
                             f"must stay >= 0 over the rolled distance [0, {q_end:.6g}] a_H (a "
                             f"pull, P < 0, is not a contact problem), but its minimum is {nmin:.6g}")
        self._check_convective_step()
        self._check_bem()
        free = 1.0 - EDGE_ELEMENTS / disc.elements
        if not math.sqrt(nmax) < disc.zone * free:
            raise InputError(
                "discretization.zone",
                f"the contact reaches the edge of the zone (needs zone > "
                f"{math.sqrt(nmax) / free:.6g} for the largest normal load {nmax:.6g}·P̄ with "
                f"{disc.elements} elements, leaving {EDGE_ELEMENTS / 2} of an element free at each end;"
                f" got {disc.zone!r})")
        tang = load.tangential
        if tang is None:
            return
        if self.contact.friction == 0.0:
            tmin, tmax = tang.extremes(q_end)
            if tmin != 0.0 or tmax != 0.0:
                raise InputError("load.tangential",
                                 "must be 0 when contact.friction = 0 (it is Q/(mu P̄) and "
                                 f"|Q| <= mu P = 0), got values in [{tmin:.6g}, {tmax:.6g}]")
            return
        tmin, tmax = tang.extremes(q_end)
        if nmin > 0 and max(abs(tmin), abs(tmax)) / nmin < 1.0:  # a sufficient bound
            return
        q = np.unique(np.concatenate((self.q_steps / self.a_H,
                                      load.normal_history.critical_points(q_end),
                                      tang.critical_points(q_end))))
        Qr, Pr = np.abs(np.asarray(tang(q), dtype=float)), np.asarray(load.normal_history(q), dtype=float)
        with np.errstate(divide="ignore", invalid="ignore"):  # P = 0 (contact lost): Q must be 0 too
            ratio = np.where(Pr > 0, Qr / np.where(Pr > 0, Pr, 1.0), np.where(Qr > 0, np.inf, 0.0))
        i = int(np.argmax(ratio))
        if np.isinf(ratio[i]):
            raise InputError("load.tangential",
                             f"must be 0 where the normal load is 0 (contact lost), but Q/(mu P̄) = "
                             f"{float(tang(q[i])):.6g} at q = {q[i]:.6g} a_H where P = 0")
        if not ratio[i] < 1.0:
            raise InputError("load.tangential",
                             f"|Q|/(mu P) must stay below 1 for a stick solution (gross sliding"
                             f" is not supported), but it reaches {ratio[i]:.6g} at q = "
                             f"{q[i]:.6g} a_H")

    def _check_bem(self) -> None:
        """``model = "bem"``: both shafts given, and the strip shorter than half a circumference."""
        if self.contact.model != "bem":
            return
        for key, body in (("bodies.A", self.A), ("bodies.B", self.B)):
            if body.shaft_radius is None:
                raise InputError(f"{key}.shaft_radius", "is required when contact.model = 'bem' (the "
                                                        f"rigid shaft's radius, in (0, {body.radius!r}))")
            if not 2.0 * self.half_width < math.pi * body.radius:
                raise InputError("discretization.zone",
                                 f"the strip (2L = {2 * self.half_width:.6g}) must be shorter than half the "
                                 f"circumference of {key} (radius {body.radius!r}) for model = 'bem'")

    @property
    def bem_mesh(self) -> tuple[int, int]:
        """``(outer, inner)`` BEM element counts per roller (defaults 19, 16; docs/bem.md)."""
        from .influence.bem import DEFAULT_INNER, DEFAULT_OUTER  # one place for the paper's counts
        c = self.contact
        return (DEFAULT_OUTER if c.bem_outer_elements is None else c.bem_outer_elements,
                DEFAULT_INNER if c.bem_inner_elements is None else c.bem_inner_elements)

    def _check_convective_step(self) -> None:
        """Convective-local slip is stable only for Δq up to the node spacing h.

        Its upwind term ``d·D_up w^{k−1}`` is explicit transport of ``w`` by Δq per step: a
        CFL condition, Δq ≤ h, with h = Le for constant and linear elements and Le/2 for
        quadratic ones (a midnode). Beyond it the transient does not settle: measured on
        §6.1.1 (``docs/stability.md``) the creepage oscillates by 3–17 % of Carter's from
        step to step and ends 4–34 % off, against ≤ 1.7 % (material, same Δq) and exactly
        the steady limit for Δq ≤ h. Rejected, naming ``discretization.step``.
        """
        disc = self.discretization
        if disc.formulation != "convective-local":
            return
        limit = CONVECTIVE_STEP_MAX[disc.element]
        if disc.step > limit:
            raise InputError("discretization.step",
                             f"must be in (0, {limit:g}] with formulation = 'convective-local' and "
                             f"{disc.element} elements (Δq at most the node spacing: the upwind "
                             f"transport is unstable beyond it, docs/stability.md), got {disc.step!r}; "
                             f"use a smaller step or formulation = 'material'")

    # ------------------------------------------------------------------ derived quantities
    @property
    def Estar(self) -> float:
        """Contact modulus E*, 1/E* = (1 − ν_A²)/E_A + (1 − ν_B²)/E_B (plane strain)."""
        A, B = self.A, self.B
        return 1.0 / ((1.0 - A.nu ** 2) / A.E + (1.0 - B.nu ** 2) / B.E)

    @property
    def R(self) -> float:
        """Relative radius R, 1/R = 1/R_A + 1/R_B."""
        return 1.0 / (1.0 / self.A.radius + 1.0 / self.B.radius)

    @property
    def beta(self) -> float:
        """Dundurs' parameter (FORMULATION.md §3).

        β = ½[(1 − 2ν_A)/G_A − (1 − 2ν_B)/G_B] / [(1 − ν_A)/G_A + (1 − ν_B)/G_B];
        zero for similar materials, and it changes sign when A and B are swapped.
        """
        A, B = self.A, self.B
        num = (1.0 - 2.0 * A.nu) / A.G - (1.0 - 2.0 * B.nu) / B.G
        den = (1.0 - A.nu) / A.G + (1.0 - B.nu) / B.G
        return 0.5 * num / den

    @property
    def kappa(self) -> float:
        """κ = 2β: the paper's "constant" (eq. 92), Bentall–Johnson's κ."""
        return 2.0 * self.beta

    @property
    def a_H(self) -> float:
        """Hertz half-width for the reference load P̄: a_H = sqrt(4 P̄ R / (π E*))."""
        return math.sqrt(4.0 * self.load.normal * self.R / (math.pi * self.Estar))

    @property
    def p0(self) -> float:
        """Hertz peak pressure for P̄: p0 = 2 P̄ / (π a_H) = a_H E* / (2R)."""
        return 2.0 * self.load.normal / (math.pi * self.a_H)

    @property
    def coupling_level(self) -> str:
        """Coupling level used: "full", "goodman" or "off" ("auto": "full" iff ``|β| > 1e-12``)."""
        c = self.contact.coupling
        if c == "auto":
            return "full" if abs(self.beta) > BETA_ZERO else "off"
        return c

    @property
    def leading_edge(self) -> int:
        """Sign of x where material enters the contact, −d (FORMULATION.md §1)."""
        return -self.load.direction

    @property
    def half_width(self) -> float:
        """Half-width of the potential contact zone, L = zone·a_H."""
        return self.discretization.zone * self.a_H

    @property
    def element_length(self) -> float:
        """Element length Le = 2L / elements."""
        return 2.0 * self.half_width / self.discretization.elements

    @property
    def dq(self) -> float:
        """Rolled distance per step, Δq = step·Le (length units)."""
        return self.discretization.step * self.element_length

    @property
    def n_steps(self) -> int:
        """Number of rolling steps K: distance·a_H/Δq, rounded if within 1e-9 of an integer
        (relative), else rounded up."""
        ratio = self.discretization.distance * self.a_H / self.dq
        r = round(ratio)
        return int(r) if abs(r - ratio) <= 1e-9 * ratio else int(math.ceil(ratio))

    @property
    def q_steps(self) -> np.ndarray:
        """Rolled distances q_k = k·Δq, k = 0 … K, shape (K + 1,), length units."""
        return np.arange(self.n_steps + 1) * self.dq

    @property
    def reference_distance_value(self) -> float:
        """d_ref of the half-space kernel: ``contact.reference_distance``, or R if absent."""
        d = self.contact.reference_distance
        return self.R if d is None else d

    def normal_load(self, q):
        """Normal load P(q) = P̄·normal_history(q/a_H).

        Parameters
        ----------
        q : float or ndarray
            Rolled distance, length units.
        """
        return self.load.normal * self.load.normal_history(np.asarray(q, dtype=float) / self.a_H)

    def tangential_load(self, q):
        """Tangential load on body A, Q(q) = μ·P̄·tangential(q/a_H).

        Parameters
        ----------
        q : float or ndarray
            Rolled distance, length units.

        Raises
        ------
        InputError
            If the scene prescribes the creepage instead.
        """
        if self.load.tangential is None:
            raise InputError("load.tangential", "not prescribed: this scene prescribes "
                                                "load.creepage instead")
        return (self.contact.friction * self.load.normal
                * self.load.tangential(np.asarray(q, dtype=float) / self.a_H))

    def prescribed_creepage(self, q):
        """Prescribed creepage ξ(q) = creepage(q/a_H).

        Parameters
        ----------
        q : float or ndarray
            Rolled distance, length units.

        Raises
        ------
        InputError
            If the scene prescribes the tangential load instead.
        """
        if self.load.creepage is None:
            raise InputError("load.creepage", "not prescribed: this scene prescribes "
                                              "load.tangential instead")
        return self.load.creepage(np.asarray(q, dtype=float) / self.a_H)

    def prescribed_approach(self, q):
        """Prescribed approach δ(q) = approach(q/a_H) of the shaft centres, or None if P is given.

        Parameters
        ----------
        q : float or ndarray
            Rolled distance, length units.
        """
        if self.load.approach is None:
            return None
        return self.load.approach(np.asarray(q, dtype=float) / self.a_H)

    # ------------------------------------------------------------------ output
    def to_dict(self) -> dict:
        """The full scene as a nested plain dict, defaults filled in.

        Histories are their inline-table dicts; absent optional values (``shaft_radius``,
        ``reference_distance``, the unused one of ``tangential``/``creepage``) are left out,
        since TOML has no null. JSON-serializable; :func:`scene_from_dict` reads it back.
        """
        return {"name": self.name, "description": self.description,
                "bodies": {"A": _part_dict(self.A), "B": _part_dict(self.B)},
                "contact": _part_dict(self.contact), "load": _part_dict(self.load),
                "discretization": _part_dict(self.discretization),
                "solver": _part_dict(self.solver)}

    def to_toml(self) -> str:
        """The scene as TOML text in SPEC.md's layout, defaults filled in.

        Floats are written with ``repr`` precision, so :func:`load_scene` of the text gives
        back an equal scene.
        """
        d = self.to_dict()
        lines = [f"name = {_toml_value(d['name'])}",
                 f"description = {_toml_value(d['description'])}"]
        for table in _TABLES:
            sub = d
            for part in table.split("."):
                sub = sub[part]
            lines += ["", f"[{table}]"]
            lines += [f"{_toml_key(k)} = {_toml_value(v)}" for k, v in sub.items()]
        return "\n".join(lines) + "\n"

    def replace(self, **changes: Any) -> "Scene":
        """A new, validated scene with some values changed.

        Parameters
        ----------
        **changes
            Dotted keys and values, e.g. ``scene.replace(**{"solver.method": "qp-osqp",
            "load.tangential": Ramp(0.0, 0.5, 2.0)})``. Values are what the TOML file would
            hold (histories may be :class:`~rollqp.histories.History` objects, whole tables
            dicts or part objects such as :class:`Body`); ``None`` removes an optional key.
            Setting one of ``load.tangential``/``load.creepage`` removes the other unless it
            is set too.

        Returns
        -------
        Scene

        Raises
        ------
        InputError
            As for a scene file, naming the dotted key.
        """
        d = self.to_dict()
        for dotted, value in changes.items():
            parts = dotted.split(".")
            node = d
            for i, part in enumerate(parts[:-1]):
                nxt = node.setdefault(part, {})
                if not isinstance(nxt, dict):
                    raise InputError(".".join(parts[:i + 1]), f"is not a table; cannot set "
                                                              f"{dotted}")
                node = nxt
            if value is None:
                node.pop(parts[-1], None)
            else:
                node[parts[-1]] = _plain(value)
            pair = {"load.tangential": "creepage", "load.creepage": "tangential"}
            if dotted in pair and value is not None and f"load.{pair[dotted]}" not in changes:
                d["load"].pop(pair[dotted], None)
        return scene_from_dict(d, source=self.source, default_name=self.name)


_TABLES = ("bodies.A", "bodies.B", "contact", "load", "discretization", "solver")


def _part_dict(obj) -> dict:
    """Plain dict of a part (Body, …, History), None values left out."""
    if isinstance(obj, History):
        return obj.to_dict()
    return {f.name: _plain(getattr(obj, f.name)) for f in fields(obj)
            if getattr(obj, f.name) is not None}


def _plain(v: Any) -> Any:
    """Plain (TOML/JSON) form of a value: histories and parts become dicts."""
    if isinstance(v, History) or dataclasses.is_dataclass(v) and not isinstance(v, type):
        return _part_dict(v)
    if isinstance(v, np.generic):
        return v.item()
    return v


# =========================================================================== TOML output
def _toml_key(k: str) -> str:
    if k and all(c.isascii() and (c.isalnum() or c in "_-") for c in k):
        return k
    return _toml_string(k)


def _toml_string(s: str) -> str:
    out = ['"']
    for ch in s:
        if ch == '"':
            out.append('\\"')
        elif ch == "\\":
            out.append("\\\\")
        elif ch == "\n":
            out.append("\\n")
        elif ch == "\t":
            out.append("\\t")
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04X}")
        else:
            out.append(ch)
    out.append('"')
    return "".join(out)


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return repr(v)  # 'inf', '-inf', 'nan' are TOML too
    if isinstance(v, str):
        return _toml_string(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_toml_key(k)} = {_toml_value(x)}" for k, x in v.items()) + " }"
    raise TypeError(f"cannot write {v!r} as TOML")


# =========================================================================== input
_TOP_KEYS = ("name", "description", "bodies", "contact", "load", "discretization", "solver")
_SECTIONS: dict[str, type] = {"contact": Contact, "load": Load,
                              "discretization": Discretization, "solver": SolverSettings}


def _unknown(key: str, word: str, allowed, where: str) -> InputError:
    hint = _suggestion(word, allowed)
    return InputError(key, f"unknown key{hint} (allowed in {where}: {', '.join(allowed)})")


def _table(d: dict, key: str, cls: type) -> dict:
    """The keys of table ``key`` for dataclass ``cls``: unknown and missing keys checked."""
    where = f"[{key}]"
    if not isinstance(d, dict):
        raise InputError(key, f"must be a table {where}, got {d!r}")
    names = [f.name for f in fields(cls)]
    for k in d:
        if k not in names:
            raise _unknown(f"{key}.{k}", k, names, where)
    required = [f.name for f in fields(cls)
                if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING]
    missing = [k for k in required if k not in d]
    if len(missing) == 1:
        raise InputError(f"{key}.{missing[0]}",
                         f"missing required key ({where} needs {', '.join(required)})")
    if missing:
        raise InputError(key, "missing required keys " + ", ".join(f"{key}.{k}" for k in missing)
                              + f" ({where} needs {', '.join(required)})")
    return dict(d)


def scene_from_dict(d: Any, source: str = "<dict>", default_name: str = "scene") -> Scene:
    """Build and validate a scene from its nested dict (the parsed TOML).

    Parameters
    ----------
    d : dict
        ``{"name": ..., "bodies": {"A": {...}, "B": {...}}, "contact": {...}, ...}``;
        ``[discretization]`` and ``[solver]`` may be absent (defaults).
    source : str
        Recorded in :attr:`Scene.source`.
    default_name : str
        Name of a scene without ``name``.

    Returns
    -------
    Scene

    Raises
    ------
    InputError
        Naming the dotted key.
    """
    if not isinstance(d, dict):
        raise InputError("SCENE", f"must be a table of tables, got {type(d).__name__}")
    for k in d:
        if k not in _TOP_KEYS:
            raise _unknown(k, k, _TOP_KEYS, "the top level")
    for k in ("bodies", "contact", "load"):
        if k not in d:
            raise InputError(k, f"missing required table [{k}]")
    bodies = d["bodies"]
    if not isinstance(bodies, dict):
        raise InputError("bodies", f"must be a table with [bodies.A] and [bodies.B], got "
                                   f"{bodies!r}")
    for k in bodies:
        if k not in ("A", "B"):
            raise _unknown(f"bodies.{k}", k, ("A", "B"), "[bodies]")
    for k in ("A", "B"):
        if k not in bodies:
            raise InputError(f"bodies.{k}", f"missing required table [bodies.{k}] "
                                            "(needs radius, E, nu)")
    A = Body(**_table(bodies["A"], "bodies.A", Body))
    B = Body(**_table(bodies["B"], "bodies.B", Body))
    parts = {}
    for k, cls in _SECTIONS.items():
        if k in d or k in ("contact", "load"):
            parts[k] = _table(d[k], k, cls)
        else:
            parts[k] = {}
    ld = parts["load"]
    if "normal_history" in ld:
        ld["normal_history"] = parse_history(ld["normal_history"], "load.normal_history",
                                             constant_default=1.0)
    for k in ("tangential", "creepage", "approach"):
        if k in ld:
            ld[k] = parse_history(ld[k], f"load.{k}")
    return Scene(name=d.get("name", default_name), description=d.get("description", ""),
                 A=A, B=B, contact=Contact(**parts["contact"]), load=Load(**ld),
                 discretization=Discretization(**parts["discretization"]),
                 solver=SolverSettings(**parts["solver"]), source=source)


def scene_from_toml(text: str, source: str = "<string>", default_name: str = "scene") -> Scene:
    """Build and validate a scene from TOML text.

    Raises
    ------
    InputError
        On a TOML syntax error (naming ``source`` and tomllib's message) or invalid input.
    """
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(source, f"invalid TOML: {exc}") from exc
    return scene_from_dict(data, source=source, default_name=default_name)


def _builtin_dir():
    return resources.files(__package__).joinpath("scenes")


def _builtin_files() -> dict[str, Any]:
    out = {}
    for entry in _builtin_dir().iterdir():
        if entry.name.endswith(".toml") and entry.is_file():
            out[entry.name[:-len(".toml")]] = entry
    return dict(sorted(out.items()))


def builtin_scenes() -> dict[str, str]:
    """The built-in scenes: name → one-line description."""
    out = {}
    for name, entry in _builtin_files().items():
        try:
            desc = tomllib.loads(entry.read_text(encoding="utf-8")).get("description", "")
        except tomllib.TOMLDecodeError:  # pragma: no cover - the built-ins are tested
            desc = "(unreadable)"
        out[name] = str(desc)
    return out


def load_scene(source: Any) -> Scene:
    """Read and validate a scene.

    Parameters
    ----------
    source : str, os.PathLike, dict or Scene
        A path to a TOML file; the name of a built-in scene (:func:`builtin_scenes`; a file
        of that name takes precedence); a nested dict as :meth:`Scene.to_dict` gives; or a
        scene, returned as is.

    Returns
    -------
    Scene
        A scene without ``name`` is named after its file.

    Raises
    ------
    InputError
        ``SCENE`` if no such file or built-in scene exists; the file's path on a TOML syntax
        error; the dotted key on invalid input.
    """
    if isinstance(source, Scene):
        return source
    if isinstance(source, dict):
        return scene_from_dict(source)
    if not isinstance(source, (str, os.PathLike)):
        raise InputError("SCENE", "must be a path to a TOML file, the name of a built-in scene "
                                  f"or a dict, got {type(source).__name__}")
    path = Path(source)
    if path.is_file():
        try:
            text = path.read_bytes().decode("utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise InputError(str(path), f"cannot read the scene file: {exc}") from exc
        return scene_from_toml(text, source=str(path), default_name=path.stem)
    builtins = _builtin_files()
    name = os.fspath(source)
    if isinstance(source, str) and name in builtins:
        text = builtins[name].read_text(encoding="utf-8")
        return scene_from_toml(text, source=f"builtin:{name}", default_name=name)
    raise InputError("SCENE", f"no such file or built-in scene {name!r}"
                              f"{_suggestion(name, builtins)}; built-in scenes: "
                              f"{', '.join(builtins)}")
