"""Registry of step methods: one module per method (the protocol: :mod:`rollqp.methods.base`).

========================  ==========================================================
``qp-clarabel``           convex QP, Clarabel native (interior point)
``qp-osqp``               convex QP, OSQP native (ADMM + polishing)
``qp-cvxpy``              convex QP, cvxpy textbook formulation (OSQP underneath)
``newton``                generalized Newton with line search (GNMls, paper §4)
``nt-newton``             normal–tangential alternation of Newton halves (paper §6.3)
``mf-newton``             matrix-free generalized Newton, Krylov reduced systems (FFT products)
``qps-daqp``, …           convex QP through qpsolvers (optional extra ``qpsolvers``:
                          DAQP, quadprog, ProxQP, PIQP, HiGHS; :mod:`.qp_qpsolvers`)
========================  ==========================================================

**Three dimensions** (a scene with ``[contact] dimension = 3``, :mod:`rollqp.march.grid`). A name keeps
its meaning across dimensions — ``newton`` is rollqp's generalized Newton method, a ``qp-*`` name the
convex programs on that external solver — and each dimension has its own table of classes:

========================  ==========================================================
``newton``                generalized Newton on the disc projection (:mod:`rollqp.methods.newton.disc`)
``qp-clarabel``           Clarabel: the normal QP and the tangential SOCP (one cone per element)
``socp-clarabel``         the same (the name says the cone)
``qp-cvxpy``              cvxpy's statement of the QP and the SOCP, solved by Clarabel
``socp-cvxpy``            the same
``socp-scs``              cvxpy's statement solved by SCS (first order, extra ``cvxpy``)
``qp-osqp``               OSQP: the normal QP only; no cones, so a 3D scene (tangential SOCPs)
                          refuses it up front, naming the methods that can
``fastsim``               Kalker's simplified theory (FASTSIM), steady rolling only: the fast
                          approximation (:mod:`rollqp.methods.fastsim`)
========================  ==========================================================

A name registered for one dimension only (``nt-newton``, ``mf-newton``, ``qps-*``; the ``socp-*``
names) resolves in the other to its own class, whose record (``Capabilities.dimension``) refuses
the scene up front (:func:`compose`, :func:`compose_3d`).

Optional backends are always registered by name; one whose package is not installed
raises :class:`~rollqp.errors.MissingBackendError` naming the pip extra, and
:func:`available_methods` leaves it out. Modules are imported on first use. :func:`register` adds a
method class under a new name (the one call a method written outside rollqp needs).

:func:`get_method` makes one method from its name and settings; :func:`scene_method` makes the
method a scene runs with, composed from what the named method declares
(:class:`~rollqp.methods.base.Capabilities`): on a coupled scene a method that does not solve
coupled steps runs inside the N–T alternation, and one that does not pose slip-dependent bounds
inside the fixed point on the bound. This module is the only place where method names are looked
at: the defaults and the reference methods below are named here.

Examples
--------
>>> from rollqp.methods import get_method, capabilities
>>> get_method("newton", tolerance=1e-9).tolerance
1e-09
>>> sorted(capabilities("qp-clarabel").solves)
['normal', 'tangential']
"""
from __future__ import annotations

import importlib
from dataclasses import dataclass

from ..errors import InputError, MissingBackendError
from .alternation import Alternation
from .base import (FRICTION_KINDS, KINDS, Capabilities, Method, check_kind,  # noqa: F401 - the protocol, re-exported
                   check_options)
from .continuation import SlipContinuation
from .fixedpoint import BoundFixedPoint


@dataclass(frozen=True)
class Optional:
    """A method class imported on first use, its ``dimensions`` declared here (so that the table is read
    without importing it): a module that needs an optional package (``extra``, the pip extra that brings
    it), or a core one that needs scipy or a solver package (``extra = None``: ``import rollqp`` loads
    neither; ``tests/test_layers.py`` checks each declaration against the class's capabilities)."""

    module: str
    attr: str
    extra: str | None
    dimensions: frozenset = frozenset({2})

    def load(self) -> type:
        """The class (its module's attribute: a missing solver package is its MissingBackendError)."""
        return getattr(importlib.import_module(self.module), self.attr)


#: The one method table: name -> the classes (or optional modules) under that name, at most one per
#: dimension; each class's ``capabilities.dimensions`` says which scenes it runs.
_TWO, _THREE = frozenset({2}), frozenset({3})


def _core(module: str, attr: str, dimensions: frozenset) -> Optional:
    return Optional(f"rollqp.methods.{module}", attr, None, dimensions)


_TABLE: dict[str, tuple] = {
    "qp-clarabel": (_core("qp_clarabel", "ClarabelQP", _TWO), _core("socp", "ClarabelMethod", _THREE)),
    "qp-osqp": (_core("qp_osqp", "OsqpQP", _TWO), _core("socp", "OsqpMethod", _THREE)),
    "qp-cvxpy": (Optional("rollqp.methods.qp_cvxpy", "CvxpyQP", "cvxpy"), _core("socp", "CvxpyMethod", _THREE)),
    "newton": (_core("newton", "NewtonMethod", _TWO), _core("newton.disc", "NewtonMethod", _THREE)),
    "nt-newton": (_core("nt_newton", "AlternationNewton", _TWO),),
    "mf-newton": (_core("krylov", "KrylovNewton", _TWO),),
    # qpsolvers backends: the module's attribute qps_<solver> checks that the solver is installed
    **{f"qps-{s}": (Optional("rollqp.methods.qp_qpsolvers", f"qps_{s}", "qpsolvers"),)
       for s in ("daqp", "quadprog", "proxqp", "piqp", "highs")},
    "socp-clarabel": (_core("socp", "ClarabelMethod", _THREE),),
    "socp-cvxpy": (_core("socp", "CvxpyMethod", _THREE),),
    "socp-scs": (_core("socp", "ScsMethod", _THREE),),
    "fastsim": (_core("fastsim", "FastsimMethod", _THREE),),
}


def _dimensions(entry) -> frozenset:
    return entry.dimensions if isinstance(entry, Optional) else entry.capabilities.dimensions


def _table(dimension: int) -> tuple:
    return tuple(name for name, entries in _TABLE.items() if any(dimension in _dimensions(e) for e in entries))


@dataclass(frozen=True)
class MethodRecord:
    """A method name resolved for scenes of one dimension: made once, when a scene is validated
    (:func:`resolve`), and carried from there (``scene.solver.method.record``) to :meth:`make`.

    ``entry`` is the class, or the :class:`Optional` module that holds it; :attr:`cls` imports an optional
    one (a missing package is a :class:`MissingBackendError` naming the pip extra).
    """

    name: str
    dimension: int
    entry: object

    @property
    def cls(self) -> type:
        entry = self.entry
        if isinstance(entry, Optional):
            try:
                return entry.load()
            except ModuleNotFoundError as exc:
                if entry.extra is None:
                    raise
                raise MissingBackendError(f"method {self.name!r} needs the package {exc.name!r} "
                                          f"(pip install 'rollqp[{entry.extra}]')") from exc
        return entry

    @property
    def capabilities(self) -> Capabilities:
        """What the class declares; for a method whose package is missing, a record that solves nothing."""
        try:
            return self.cls.capabilities
        except MissingBackendError:
            return Capabilities(dimensions=frozenset({self.dimension}))

    def make(self, settings, **options) -> Method:
        """The method configured from a scene's solver settings (``Cls.from_settings``), named by the registry."""
        method = self.cls.from_settings(settings, **options)
        if method.name != self.name:
            method.name = self.name
        return method


class MethodName(str):
    """A scene's ``solver.method`` once validated: the name (what the scene file holds, a ``str``) that
    carries its :class:`MethodRecord` (``.record``), so that nothing resolves it again."""

    def __new__(cls, record: MethodRecord):
        self = super().__new__(cls, record.name)
        self.record = record
        return self

    def __reduce__(self):
        return (MethodName, (self.record,))


#: The methods of two-dimensional scenes.
METHOD_NAMES = _table(2)
#: The methods of three-dimensional scenes (``[contact] dimension = 3``).
METHOD_NAMES_3D = _table(3)
#: Every name a scene's ``solver.method`` (or ``--method``) may hold, of either dimension.
SCENE_METHOD_NAMES = METHOD_NAMES + tuple(k for k in METHOD_NAMES_3D if k not in METHOD_NAMES)
#: The methods that pose convex QPs (each half of a step one QP; coupled steps by the N–T
#: alternation): for listings and benchmarks. What a method can do is its ``capabilities``.
QP_METHODS = tuple(k for k in METHOD_NAMES if k.startswith(("qp-", "qps-")))
#: The method of a scene without ``solver.method``.
DEFAULT_METHOD = "newton"
#: The reference method: step files are marched with it, and the cross-validation and the step checker
#: report differences from its solution (the residual of every method is rollqp's own all the same).
REFERENCE_METHOD = "newton"
#: The methods a candidate solution of a stored step is compared with (:func:`rollqp.stepfile.check_step`).
COMPARE_METHODS = ("newton", "qp-clarabel")
#: The QP backends a run is cross-checked against (core dependencies only: :func:`rollqp.crossval.spot_check`).
CROSS_CHECK_METHODS = ("qp-clarabel", "qp-osqp")
#: The method :func:`rollqp.solve_step` poses one step with by default (a convex QP, interior point).
STEP_METHOD = "qp-clarabel"
#: The methods a 3D run is cross-checked with (:func:`rollqp.crossval.grid.cross_check`): the conic
#: route (Clarabel, core dependency) and Newton; the one that ran the scene is left out.
CROSS_CHECK_METHODS_3D = ("socp-clarabel", "newton")
#: The methods ``rollqp crossval`` solves every step of a 3D scene with (those installed): rollqp's Newton
#: method and the SOCP backends (Clarabel natively, cvxpy's statement solved by Clarabel).
CROSSVAL_METHODS_3D = ("newton", "socp-clarabel", "socp-cvxpy")


def register(name: str, cls: type, extra: str | None = None) -> None:
    """Register a method class under ``name`` (a scene's ``solver.method``, :func:`get_method`).

    ``cls`` follows the protocol of :mod:`rollqp.methods.base`: ``name``, a class attribute
    ``capabilities`` (:class:`Capabilities`), ``from_settings``, ``setup`` and ``solve``. It runs the
    scenes of the dimensions its record declares (``capabilities.dimensions``); a name may hold one class
    per dimension. ``extra``: the pip extra that installs what it needs (named in the listings).

    Raises
    ------
    InputError
        ``name`` is already registered for one of those dimensions, or ``cls`` declares no :class:`Capabilities`.
    """
    declared = next((vars(k)["capabilities"] for k in cls.__mro__ if "capabilities" in vars(k)), None)
    if not isinstance(declared, Capabilities):
        raise InputError("cls", f"a method class declares its Capabilities as the class attribute "
                                f"'capabilities' ({cls!r} does not)")
    taken = _TABLE.get(name, ())
    if not isinstance(name, str) or not name or any(_dimensions(e) & declared.dimensions for e in taken):
        names = ", ".join(n for d in sorted(declared.dimensions) for n in _table(d))
        raise InputError("name", f"must be a new method name (registered: {names}), got {name!r}")
    _TABLE[name] = taken + (cls,)
    _refresh_names()


def _refresh_names() -> None:
    global METHOD_NAMES, METHOD_NAMES_3D, SCENE_METHOD_NAMES
    METHOD_NAMES, METHOD_NAMES_3D = _table(2), _table(3)
    SCENE_METHOD_NAMES = METHOD_NAMES + tuple(k for k in METHOD_NAMES_3D if k not in METHOD_NAMES)


def _unknown(name, key: str):
    names = SCENE_METHOD_NAMES
    import difflib
    close = difflib.get_close_matches(name, list(names), n=1) if isinstance(name, str) else []
    hint = f"; did you mean {close[0]!r}?" if close else ""
    return InputError(key, f"must be one of {', '.join(map(repr, names))}, got {name!r}{hint}")


def record(name, dimension: int = 2, key: str = "solver.method") -> MethodRecord:
    """The record of method ``name`` for scenes of ``dimension``, without making it or importing an
    optional package. A name registered for the other dimension only gives that dimension's record (its
    :class:`Capabilities` then refuse the scene: :func:`resolve`, :func:`compose`); a validated scene's
    ``solver.method`` carries its record already (:class:`MethodName`).

    Raises
    ------
    InputError
        ``key`` for an unknown name, or a ``dimension`` that is neither 2 nor 3.
    """
    if isinstance(name, MethodName) and name.record.dimension == dimension:
        return name.record
    if not isinstance(name, str) or name not in _TABLE:
        raise _unknown(name, key)
    if dimension not in (2, 3):
        raise InputError("contact.dimension", f"must be one of [2, 3], got {dimension!r}")
    entries = _TABLE[name]
    entry = next((e for e in entries if dimension in _dimensions(e)), entries[0])
    own = dimension if dimension in _dimensions(entry) else min(_dimensions(entry))
    return MethodRecord(str(name), own, entry)


def resolve(name, dimension: int, key: str = "solver.method") -> MethodName:
    """``name`` validated for a scene of ``dimension``: the :class:`MethodName` carrying its record (the
    scene's check, before any work; the one place a scene's method name becomes a class).

    The record must declare ``dimension`` (a 2D-only method on a 3D scene and the reverse are refused
    here, naming the methods of that dimension), and a 3D method must solve tangential steps on the
    friction disc (:func:`compose_3d`); a method whose package is missing passes (running it names the
    pip extra).
    """
    if isinstance(name, MethodName) and name.record.dimension == dimension:
        return name
    rec = record(name, dimension, key)
    try:
        caps = rec.cls.capabilities
    except MissingBackendError:
        return MethodName(rec)
    if dimension not in caps.dimensions:
        own = ", ".join(_RUNNABLE[dimension]())
        raise InputError(key, f"method {rec.name!r} solves {_dims(caps)}D steps (its capabilities); a {dimension}D "
                              f"scene needs one of {own}")
    if dimension == 3:
        _require_cones(rec.name, caps, key)
    return MethodName(rec)


def _dims(caps) -> str:
    return "/".join(str(d) for d in sorted(caps.dimensions))


def capabilities(name: str, dimension: int = 2) -> Capabilities:
    """What the method ``name`` declares for scenes of ``dimension`` (its class's ``capabilities``),
    without making it; the declaration of a method that needs the matrix and solves nothing if its
    package is not installed.

    Raises
    ------
    InputError
        ``solver.method`` for an unknown name.
    """
    return record(name, dimension).capabilities


def available_methods(dimension: int = 2) -> list[str]:
    """Names of the methods of ``dimension`` whose modules import on this installation."""
    out = []
    for name in _table(dimension):
        try:
            record(name, dimension).cls
        except (MissingBackendError, InputError):
            continue
        out.append(name)
    return out


def check_name(name, key: str = "solver.method", dimension: int | None = None) -> str:
    """``name`` if it is a registered method, else an :class:`InputError` on ``key`` listing them; with
    ``dimension``, :func:`resolve` (the name with its record)."""
    if dimension is not None:
        return resolve(name, dimension, key)
    if not isinstance(name, str) or name not in _TABLE:
        raise _unknown(name, key)
    return name


def method_class(name: str, dimension: int = 2) -> type:
    """The class of method ``name`` for scenes of ``dimension`` (:func:`record`'s ``cls``).

    Raises
    ------
    InputError
        ``solver.method`` for an unknown name.
    MissingBackendError
        The method's package is not installed (the message names the pip extra).
    """
    return record(name, dimension).cls


def get_method(name: str, dimension: int = 2, **settings) -> Method:
    """A fresh instance of method ``name`` (for scenes of ``dimension``) with ``settings`` (tolerance,
    max_iterations, …); its ``name`` is the registry's.

    An unknown setting is an :class:`InputError` naming it.
    """
    cls = method_class(name, dimension)
    try:
        method = cls(**settings)
    except TypeError as exc:  # a keyword the constructor does not take
        raise InputError(name, f"invalid settings {sorted(settings)}: {exc}") from None
    if method.name != name:
        method.name = name
    return method


def scene_method(settings, coupled: bool = False, friction: str = "constant", **options) -> Method:
    """The method a scene runs with: ``settings.method`` (its record: :func:`record`) built from the
    scene's solver settings.

    Parameters
    ----------
    settings : rollqp.scene.SolverSettings
        ``method``, ``tolerance``, ``max_iterations``, ``augmentation``.
    coupled : bool
        The scene's steps are coupled (full coupling): a method that does not declare
        ``"coupled"`` is wrapped in the N–T alternation (paper §6.3), with
        ``settings.max_iterations`` outer iterations.
    friction : {"constant", "spatial", "slip"}
        The kind of the scene's friction law (:func:`rollqp.friction.law_kind`); see :func:`compose`.
    **options
        Method-specific settings (an unknown one is an :class:`InputError`).
    """
    method = record(settings.method, 2).make(settings, **options)
    return compose(method, coupled, max_outer=settings.max_iterations, friction=friction)


def compose(method: Method, coupled: bool, max_outer: int | None = None, friction: str = "constant") -> Method:
    """``method``, or the N–T alternation around it when ``coupled`` and it does not solve coupled steps.

    With a slip-dependent friction law (``friction = "slip"``) a method that does not declare
    ``slip_dependent`` runs inside the fixed point on the bound
    (:class:`~rollqp.methods.fixedpoint.BoundFixedPoint`: each iteration one of its QPs), and every method
    inside :class:`~rollqp.methods.continuation.SlipContinuation`, which selects the solution of a step that a
    steep law makes non-unique (the end of the path from the frozen bound, docs/friction.md "Which solution of a step"). A method
    whose coupled step takes a constant coefficient only (``newton``) refuses a law on a coupled
    scene up front, naming the alternatives.
    """
    caps = method.capabilities
    if 2 not in caps.dimensions:
        raise InputError("solver.method", f"method {method.name!r} solves {_dims(caps)}D steps (its capabilities); "
                                          "a scene is a two-dimensional rolling contact")
    if coupled and "coupled" in caps.solves and friction not in caps.coupled_friction:
        raise InputError("solver.method", f"method {method.name!r} solves coupled steps with "
                                          f"{' or '.join(sorted(caps.coupled_friction))} friction only; with a "
                                          f"{friction} friction law on a coupled scene use "
                                          "'nt-newton' (Newton halves in the N–T alternation) or a qp-* method")
    if friction == "slip":
        if not caps.slip_dependent:
            method = BoundFixedPoint(method)
        method = SlipContinuation(method)
    if coupled and "coupled" not in caps.solves:
        if not {"normal", "tangential"} <= caps.solves:
            raise InputError("solver.method", f"method {method.name!r} solves neither coupled steps nor both "
                                              "halves of them")
        return Alternation(method, max_outer=max_outer, limit=caps.coupled_limit)
    return method


def scene_method_3d(settings, friction: str = "constant", **options) -> Method:
    """The method a three-dimensional scene runs with: ``settings.method``'s record for dimension 3, built
    from the scene's solver settings and checked by :func:`compose_3d` (``friction``: the kind of the scene's
    law, :func:`rollqp.friction.law_kind`)."""
    return compose_3d(record(settings.method, 3).make(settings, **options), friction=friction)


def compose_3d(method: Method, friction: str = "constant") -> Method:
    """``method`` if its record can run a 3D scene: dimension 3, and tangential steps on the friction
    disc (a second-order cone per element); else an :class:`InputError` naming the methods that can.

    (Dissimilar bodies run the normal–tangential alternation of :mod:`rollqp.march.grid` with the
    method's own halves: every 3D method is composed so.) With a slip-dependent law (``friction = "slip"``)
    as in 2D (:func:`compose`): a method that does not declare ``slip_dependent`` runs inside the fixed point
    on the bound, and every method inside :class:`~rollqp.methods.continuation.SlipContinuation`.
    """
    caps = method.capabilities
    if 3 not in caps.dimensions:
        raise InputError("solver.method", f"method {method.name!r} solves {_dims(caps)}D steps (its capabilities); "
                                          f"a 3D scene needs one of {', '.join(cone_methods())}")
    _require_cones(method.name, caps)
    if friction == "slip" and not isinstance(method, SlipContinuation):
        if not caps.slip_dependent:
            method = BoundFixedPoint(method)
        # the path in λ is followed by Newton on the disc (rollqp's own arithmetic, the same for every method)
        path = record("newton", 3).cls(tolerance=method.tolerance)
        method = SlipContinuation(method, path_solver=path)
    return method


def _require_cones(name: str, caps: Capabilities, key: str = "solver.method") -> None:
    if not {"normal", "tangential"} <= caps.solves or caps.friction_set != "disc" or caps.traction_components != 2:
        raise InputError(key, f"method {name!r} cannot solve a 3D tangential step (the friction disc |t| <= mu p "
                              f"of each element is a second-order cone, which it cannot pose); methods that can: "
                              f"{', '.join(cone_methods())}")


def require_3d(name, key: str = "solver.method") -> str:
    """:func:`resolve` for dimension 3 (the 3D scene's check of ``solver.method``, before any work)."""
    return resolve(name, 3, key)


def cone_methods() -> tuple:
    """The installed 3D methods that solve tangential steps on the friction disc (their records say so)."""
    out = []
    for name in _table(3):
        try:
            caps = record(name, 3).cls.capabilities
        except MissingBackendError:
            continue
        if {"normal", "tangential"} <= caps.solves and caps.friction_set == "disc":
            out.append(name)
    return tuple(out)


#: The methods that run a scene of each dimension (named in the refusals).
_RUNNABLE = {2: lambda: _table(2), 3: cone_methods}


def matrix_free(name: str) -> bool:
    """Whether method ``name`` works with operator products only (:attr:`Capabilities.matrix_free`),
    so that a scene may give it FFT operators (:mod:`rollqp.matrixfree`); False for a method whose
    package is not installed."""
    return capabilities(name).matrix_free
