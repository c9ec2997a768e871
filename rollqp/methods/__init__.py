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

METHOD_NAMES = tuple(_REGISTRY)
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


def register(name: str, cls: type, extra: str | None = None) -> None:
    """Register a method class under ``name`` (a scene's ``solver.method``, :func:`get_method`).

    ``cls`` follows the protocol of :mod:`rollqp.methods.base`: ``name``, a class attribute
    ``capabilities`` (:class:`Capabilities`), ``from_settings``, ``setup`` and ``solve``. ``extra``: the
    pip extra that installs what it needs, named when its import fails.

    Raises
    ------
    InputError
        ``name`` is already registered, or ``cls`` declares no :class:`Capabilities`.
    """
    if not isinstance(name, str) or not name or name in _REGISTRY:
        raise InputError("name", f"must be a new method name (registered: {', '.join(_REGISTRY)}), got {name!r}")
    declared = next((vars(k)["capabilities"] for k in cls.__mro__ if "capabilities" in vars(k)), None)
    if not isinstance(declared, Capabilities):
        raise InputError("cls", f"a method class declares its Capabilities as the class attribute "
                                f"'capabilities' ({cls!r} does not)")
    _REGISTRY[name] = (cls, None, extra)


def capabilities(name: str) -> Capabilities:
    """What the method ``name`` declares (its class's ``capabilities``), without making it; the
    declaration of a method that needs the matrix and solves nothing if its package is not installed.

    Raises
    ------
    InputError
        ``solver.method`` for an unknown name.
    """
    try:
        return method_class(name).capabilities
    except MissingBackendError:
        return Capabilities()


def available_methods() -> list[str]:
    """Names of the methods whose modules import on this installation."""
    out = []
    for name in _REGISTRY:
        try:
            method_class(name)
        except (MissingBackendError, InputError):
            continue
        out.append(name)
    return out


def check_name(name, key: str = "solver.method") -> str:
    """``name`` if it is a registered method, else an :class:`InputError` on ``key`` listing them."""
    if not isinstance(name, str) or name not in _REGISTRY:
        import difflib
        close = difflib.get_close_matches(name, list(_REGISTRY), n=1) if isinstance(name, str) else []
        hint = f"; did you mean {close[0]!r}?" if close else ""
        raise InputError(key, f"must be one of {', '.join(map(repr, _REGISTRY))}, got {name!r}{hint}")
    return name


def method_class(name: str) -> type:
    """The class of method ``name``, importing its module on first use.

    Raises
    ------
    InputError
        ``solver.method`` for an unknown name.
    MissingBackendError
        The method's package is not installed (the message names the pip extra).
    """
    check_name(name)
    module, cls, extra = _REGISTRY[name]
    if isinstance(module, type):  # registered as a class (register)
        return module
    try:
        mod = importlib.import_module(module)
    except ModuleNotFoundError as exc:
        hint = f" (pip install 'rollqp[{extra}]')" if extra else ""
        raise MissingBackendError(f"method {name!r} needs the package {exc.name!r}{hint}") from exc
    return getattr(mod, cls)


def get_method(name: str, **settings) -> Method:
    """A fresh instance of method ``name`` with ``settings`` (tolerance, max_iterations, …).

    An unknown setting is an :class:`InputError` naming it.
    """
    cls = method_class(name)
    try:
        return cls(**settings)
    except TypeError as exc:  # a keyword the constructor does not take
        raise InputError(name, f"invalid settings {sorted(settings)}: {exc}") from None


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
    (:class:`~rollqp.methods.fixedpoint.BoundFixedPoint`: each iteration one of its QPs). A method
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
    if friction == "slip" and not caps.slip_dependent:
        from .fixedpoint import BoundFixedPoint
        method = BoundFixedPoint(method)
    if coupled and "coupled" not in caps.solves:
        if not {"normal", "tangential"} <= caps.solves:
            raise InputError("solver.method", f"method {method.name!r} solves neither coupled steps nor both "
                                              "halves of them")
        from .alternation import Alternation
        return Alternation(method, max_outer=max_outer, limit=caps.coupled_limit)
    return method


def matrix_free(name: str) -> bool:
    """Whether method ``name`` works with operator products only (:attr:`Capabilities.matrix_free`),
    so that a scene may give it FFT operators (:mod:`rollqp.matrixfree`); False for a method whose
    package is not installed."""
    return capabilities(name).matrix_free
