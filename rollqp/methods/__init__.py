"""Registry of step methods: one module per method (STYLE.md).

========================  ==========================================================
``qp-clarabel``           convex QP, Clarabel native (interior point)
``qp-osqp``               convex QP, OSQP native (ADMM + polishing)
``qp-cvxpy``              convex QP, cvxpy textbook formulation (OSQP underneath)
``newton``                generalized Newton with line search (GNMls, paper §4)
``nt-newton``             normal–tangential alternation of Newton halves (paper §6.3)
``qps-daqp``, …           convex QP through qpsolvers (optional extra ``qpsolvers``:
                          DAQP, quadprog, ProxQP, PIQP, HiGHS; :mod:`.qp_qpsolvers`)
========================  ==========================================================

Optional backends are always registered by name; one whose package is not installed
raises :class:`~rollqp.errors.MissingBackendError` naming the pip extra, and
:func:`available_methods` leaves it out.

A method is created once per scene with :func:`get_method` and reused for every step,
so that solver objects are built once and only updated afterwards.
"""
from __future__ import annotations

import importlib

from ..errors import InputError, MissingBackendError

# name -> (module, class, pip extra that provides it or None, what it solves)
_REGISTRY = {
    "qp-clarabel": ("rollqp.methods.qp_clarabel", "ClarabelQP", None, "qp"),
    "qp-osqp": ("rollqp.methods.qp_osqp", "OsqpQP", None, "qp"),
    "qp-cvxpy": ("rollqp.methods.qp_cvxpy", "CvxpyQP", None, "qp"),
    "newton": ("rollqp.methods.newton", "NewtonMethod", None, "newton"),
    "nt-newton": ("rollqp.methods.alternation", "AlternationNewton", None, "newton"),
    # qpsolvers backends: the module's attribute qps_<solver> checks that the solver is installed
    **{f"qps-{s}": ("rollqp.methods.qp_qpsolvers", f"qps_{s}", "qpsolvers", "qp")
       for s in ("daqp", "quadprog", "proxqp", "piqp", "highs")},
}

QP_METHODS = tuple(k for k, v in _REGISTRY.items() if v[3] == "qp")
METHOD_NAMES = tuple(_REGISTRY)


def available_methods() -> list[str]:
    """Names of the methods whose modules import on this installation."""
    out = []
    for name in _REGISTRY:
        try:
            _load(name)
        except (MissingBackendError, InputError, AttributeError):
            continue
        out.append(name)
    return out


def _load(name: str):
    if name not in _REGISTRY:
        raise InputError("solver.method", f"unknown method {name!r}; choose one of {', '.join(_REGISTRY)}")
    module, cls, extra, _ = _REGISTRY[name]
    try:
        mod = importlib.import_module(module)
    except ModuleNotFoundError as exc:
        if exc.name == module:
            raise InputError("solver.method", f"method {name!r} is not available in this version of rollqp; "
                             f"available: {', '.join(QP_METHODS)}") from exc
        hint = f" (pip install 'rollqp[{extra}]')" if extra else ""
        raise MissingBackendError(f"method {name!r} needs the package {exc.name!r}{hint}") from exc
    try:
        return getattr(mod, cls)
    except AttributeError as exc:
        raise InputError("solver.method", f"method {name!r} is not available in this version of rollqp; "
                         f"available: {', '.join(available_methods())}") from exc


def get_method(name: str, **settings):
    """A fresh instance of method ``name`` with ``settings`` (tolerance, max_iterations, …)."""
    return _load(name)(**settings)
