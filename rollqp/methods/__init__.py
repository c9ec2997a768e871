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

**Three dimensions** (a scene with ``[contact] dimension = 3``, :mod:`rollqp.three`). A name keeps
its meaning across dimensions — ``newton`` is rollqp's generalized Newton method, a ``qp-*`` name the
convex programs on that external solver — and each dimension has its own table of classes:

========================  ==========================================================
``newton``                generalized Newton on the disc projection (:mod:`rollqp.three.gnm`)
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

from ..errors import InputError, MissingBackendError
from .base import (FRICTION_KINDS, KINDS, Capabilities, Method, check_kind,  # noqa: F401 - the protocol, re-exported
                   check_options)

# name -> (module, class, pip extra that provides it or None)
_REGISTRY = {
    "qp-clarabel": ("rollqp.methods.qp_clarabel", "ClarabelQP", None),
    "qp-osqp": ("rollqp.methods.qp_osqp", "OsqpQP", None),
    "qp-cvxpy": ("rollqp.methods.qp_cvxpy", "CvxpyQP", "cvxpy"),
    "newton": ("rollqp.methods.newton", "NewtonMethod", None),
    "nt-newton": ("rollqp.methods.nt_newton", "AlternationNewton", None),
    "mf-newton": ("rollqp.methods.krylov", "KrylovNewton", None),
    # qpsolvers backends: the module's attribute qps_<solver> checks that the solver is installed
    **{f"qps-{s}": ("rollqp.methods.qp_qpsolvers", f"qps_{s}", "qpsolvers")
       for s in ("daqp", "quadprog", "proxqp", "piqp", "highs")},
}

# name -> (module, class, extra) of the methods of three-dimensional scenes (rollqp.three)
_REGISTRY_3D = {
    "newton": ("rollqp.three.gnm", "NewtonMethod", None),
    "qp-clarabel": ("rollqp.three.socp", "ClarabelMethod", None),
    "socp-clarabel": ("rollqp.three.socp", "ClarabelMethod", None),
    "qp-cvxpy": ("rollqp.three.socp", "CvxpyMethod", "cvxpy"),
    "socp-cvxpy": ("rollqp.three.socp", "CvxpyMethod", "cvxpy"),
    "socp-scs": ("rollqp.three.socp", "ScsMethod", "cvxpy"),
    "qp-osqp": ("rollqp.three.socp", "OsqpMethod", None),
    "fastsim": ("rollqp.methods.fastsim", "FastsimMethod", None),
}
_TABLES = {2: _REGISTRY, 3: _REGISTRY_3D}

#: The methods of two-dimensional scenes.
METHOD_NAMES = tuple(_REGISTRY)
#: The methods of three-dimensional scenes (``[contact] dimension = 3``).
METHOD_NAMES_3D = tuple(_REGISTRY_3D)
#: Every name a scene's ``solver.method`` (or ``--method``) may hold, of either dimension.
SCENE_METHOD_NAMES = METHOD_NAMES + tuple(k for k in _REGISTRY_3D if k not in _REGISTRY)
#: The methods that pose convex QPs (each half of a step one QP; coupled steps by the N–T
#: alternation): for listings and benchmarks. What a method can do is its ``capabilities``.
QP_METHODS = tuple(k for k in _REGISTRY if k.startswith(("qp-", "qps-")))
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
#: The methods a 3D run is cross-checked with (:func:`rollqp.three.crosscheck.cross_check`): the conic
#: route (Clarabel, core dependency) and Newton; the one that ran the scene is left out.
CROSS_CHECK_METHODS_3D = ("socp-clarabel", "newton")
#: The methods ``rollqp crossval`` solves every step of a 3D scene with (those installed): rollqp's Newton
#: method and the SOCP backends (Clarabel natively, cvxpy's statement solved by Clarabel).
CROSSVAL_METHODS_3D = ("newton", "socp-clarabel", "socp-cvxpy")


def register(name: str, cls: type, extra: str | None = None) -> None:
    """Register a method class under ``name`` (a scene's ``solver.method``, :func:`get_method`).

    ``cls`` follows the protocol of :mod:`rollqp.methods.base`: ``name``, a class attribute
    ``capabilities`` (:class:`Capabilities`), ``from_settings``, ``setup`` and ``solve``. It goes into
    the table of the dimension its record declares (``capabilities.dimension``). ``extra``: the pip
    extra that installs what it needs, named when its import fails.

    Raises
    ------
    InputError
        ``name`` is already registered for that dimension, or ``cls`` declares no :class:`Capabilities`.
    """
    declared = next((vars(k)["capabilities"] for k in cls.__mro__ if "capabilities" in vars(k)), None)
    if not isinstance(declared, Capabilities):
        raise InputError("cls", f"a method class declares its Capabilities as the class attribute "
                                f"'capabilities' ({cls!r} does not)")
    table = _TABLES.get(declared.dimension)
    if table is None:
        raise InputError("cls", f"capabilities.dimension must be one of {sorted(_TABLES)}, got {declared.dimension!r}")
    if not isinstance(name, str) or not name or name in table:
        raise InputError("name", f"must be a new method name (registered: {', '.join(table)}), got {name!r}")
    table[name] = (cls, None, extra)
    _refresh_names()


def _refresh_names() -> None:
    global METHOD_NAMES, METHOD_NAMES_3D, SCENE_METHOD_NAMES
    METHOD_NAMES, METHOD_NAMES_3D = tuple(_REGISTRY), tuple(_REGISTRY_3D)
    SCENE_METHOD_NAMES = METHOD_NAMES + tuple(k for k in _REGISTRY_3D if k not in _REGISTRY)


def capabilities(name: str, dimension: int = 2) -> Capabilities:
    """What the method ``name`` declares for scenes of ``dimension`` (its class's ``capabilities``),
    without making it; the declaration of a method that needs the matrix and solves nothing if its
    package is not installed.

    Raises
    ------
    InputError
        ``solver.method`` for an unknown name.
    """
    try:
        return method_class(name, dimension).capabilities
    except MissingBackendError:
        return Capabilities(dimension=dimension)


def available_methods(dimension: int = 2) -> list[str]:
    """Names of the methods of ``dimension`` whose modules import on this installation."""
    out = []
    for name in _TABLES[dimension]:
        try:
            method_class(name, dimension)
        except (MissingBackendError, InputError):
            continue
        out.append(name)
    return out


def check_name(name, key: str = "solver.method", dimension: int | None = None) -> str:
    """``name`` if it is a registered method, else an :class:`InputError` on ``key`` listing them.

    With ``dimension``, the method's record must declare that dimension (a 2D-only method on a 3D
    scene and the reverse are refused here, through :class:`Capabilities`, naming the methods of
    that dimension); a method whose package is missing passes (running it names the pip extra).
    """
    names = SCENE_METHOD_NAMES
    if not isinstance(name, str) or name not in names:
        import difflib
        close = difflib.get_close_matches(name, list(names), n=1) if isinstance(name, str) else []
        hint = f"; did you mean {close[0]!r}?" if close else ""
        raise InputError(key, f"must be one of {', '.join(map(repr, names))}, got {name!r}{hint}")
    if dimension is not None:
        try:
            declared = method_class(name, dimension).capabilities.dimension
        except MissingBackendError:
            return name
        if declared != dimension:
            own = ", ".join(_RUNNABLE[dimension]())
            raise InputError(key, f"method {name!r} solves {declared}D steps (its capabilities); a {dimension}D "
                                  f"scene needs one of {own}")
    return name


def method_class(name: str, dimension: int = 2) -> type:
    """The class of method ``name`` for scenes of ``dimension``, importing its module on first use.

    A name registered for the other dimension only resolves to that class: its
    :class:`Capabilities` then refuse the scene (:func:`compose`, :func:`compose_3d`).

    Raises
    ------
    InputError
        ``solver.method`` for an unknown name.
    MissingBackendError
        The method's package is not installed (the message names the pip extra).
    """
    check_name(name)
    if dimension not in _TABLES:
        raise InputError("contact.dimension", f"must be one of {sorted(_TABLES)}, got {dimension!r}")
    table = _TABLES[dimension]
    if name not in table:
        table = next(t for t in _TABLES.values() if name in t)
    module, cls, extra = table[name]
    if isinstance(module, type):  # registered as a class (register)
        return module
    try:
        mod = importlib.import_module(module)
    except ModuleNotFoundError as exc:
        hint = f" (pip install 'rollqp[{extra}]')" if extra else ""
        raise MissingBackendError(f"method {name!r} needs the package {exc.name!r}{hint}") from exc
    return getattr(mod, cls)


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
    """The method a scene runs with: ``settings.method`` built from the scene's solver settings.

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
    method = method_class(settings.method).from_settings(settings, **options)
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
    if caps.dimension != 2:
        raise InputError("solver.method", f"method {method.name!r} solves {caps.dimension}D steps (its capabilities); "
                                          "a scene is a two-dimensional rolling contact")
    if coupled and "coupled" in caps.solves and friction not in caps.coupled_friction:
        raise InputError("solver.method", f"method {method.name!r} solves coupled steps with "
                                          f"{' or '.join(sorted(caps.coupled_friction))} friction only; with a "
                                          f"{friction} friction law on a coupled scene use "
                                          "'nt-newton' (Newton halves in the N–T alternation) or a qp-* method")
    if friction == "slip":
        from .continuation import SlipContinuation
        if not caps.slip_dependent:
            from .fixedpoint import BoundFixedPoint
            method = BoundFixedPoint(method)
        method = SlipContinuation(method)
    if coupled and "coupled" not in caps.solves:
        if not {"normal", "tangential"} <= caps.solves:
            raise InputError("solver.method", f"method {method.name!r} solves neither coupled steps nor both "
                                              "halves of them")
        from .alternation import Alternation
        return Alternation(method, max_outer=max_outer, limit=caps.coupled_limit)
    return method


def scene_method_3d(settings, **options) -> Method:
    """The method a three-dimensional scene runs with: ``settings.method`` from the 3D table, built from
    the scene's solver settings and checked by :func:`compose_3d`."""
    method = method_class(settings.method, 3).from_settings(settings, **options)
    if method.name != settings.method:
        method.name = settings.method
    return compose_3d(method)


def compose_3d(method: Method) -> Method:
    """``method`` if its record can run a 3D scene: dimension 3, and tangential steps on the friction
    disc (a second-order cone per element); else an :class:`InputError` naming the methods that can.

    (Dissimilar bodies run the normal–tangential alternation of :mod:`rollqp.three.march` with the
    method's own halves: every 3D method is composed so.)
    """
    caps = method.capabilities
    if caps.dimension != 3:
        raise InputError("solver.method", f"method {method.name!r} solves {caps.dimension}D steps (its capabilities); "
                                          f"a 3D scene needs one of {', '.join(cone_methods())}")
    _require_cones(method.name, caps)
    return method


def _require_cones(name: str, caps: Capabilities, key: str = "solver.method") -> None:
    if not {"normal", "tangential"} <= caps.solves or caps.friction_set != "disc" or caps.traction_components != 2:
        raise InputError(key, f"method {name!r} cannot solve a 3D tangential step (the friction disc |t| <= mu p "
                              f"of each element is a second-order cone, which it cannot pose); methods that can: "
                              f"{', '.join(cone_methods())}")


def require_3d(name, key: str = "solver.method") -> str:
    """Check, through its record, that method ``name`` runs a 3D scene (the scene's check, before any work):
    :func:`check_name` for dimension 3, then the cones of :func:`compose_3d`."""
    check_name(name, key, dimension=3)
    try:
        caps = method_class(name, 3).capabilities
    except MissingBackendError:
        return name
    _require_cones(name, caps, key)
    return name


def cone_methods() -> tuple:
    """The installed 3D methods that solve tangential steps on the friction disc (their records say so)."""
    out = []
    for name in _REGISTRY_3D:
        try:
            caps = method_class(name, 3).capabilities
        except MissingBackendError:
            continue
        if {"normal", "tangential"} <= caps.solves and caps.friction_set == "disc":
            out.append(name)
    return tuple(out)


#: The methods that run a scene of each dimension (named in the refusals).
_RUNNABLE = {2: lambda: tuple(_REGISTRY), 3: cone_methods}


def matrix_free(name: str) -> bool:
    """Whether method ``name`` works with operator products only (:attr:`Capabilities.matrix_free`),
    so that a scene may give it FFT operators (:mod:`rollqp.matrixfree`); False for a method whose
    package is not installed."""
    return capabilities(name).matrix_free
