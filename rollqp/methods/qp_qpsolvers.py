r"""Backends through qpsolvers (Caron et al.): one class, parametrized by the solver's name.

Optional extra: ``pip install 'rollqp[qpsolvers]'`` installs qpsolvers and the solvers below
(all with Linux wheels for Python 3.11). A backend is registered as ``qps-<solver>``
(:mod:`rollqp.methods`) and is available when qpsolvers and that solver import.

==================  ===========  ===========================================================
method              solver       kind, settings rollqp passes
==================  ===========  ===========================================================
``qps-daqp``        DAQP         dual active set (dense); ``primal_tol = dual_tol = 1e-12``
``qps-quadprog``    quadprog     Goldfarb–Idnani dual active set (dense); no tolerances
``qps-proxqp``      ProxQP       proximal augmented Lagrangian (dense backend),
                                 ``eps_abs = min(tolerance, 1e-9)``, ``eps_rel = 0``
``qps-piqp``        PIQP         proximal interior point, ``eps_abs = eps_rel =``
                                 ``eps_duality_gap_* = 1e-4·tolerance`` (floored 1e-14)
``qps-highs``       HiGHS        active set QP (sparse input); feasibility tolerances
                                 ``1e-2·tolerance`` and no QP regularization (its default
                                 1e-7 left Signorini residuals of 5.6e-8 on the Hertz step)
==================  ===========  ===========================================================

The QP is passed as qpsolvers' ``Problem`` with ``G x <= h`` rows for the finite bounds and
equality rows for the load and for the nodes without a friction bound
(:func:`~rollqp.methods._qp.constraint_rows`: fixed variables as equalities, not as two
opposite bounds, which leave an interior point no interior). qpsolvers' Lagrangian is
``½xᵀPx + qᵀx + zᵀ(Gx − h) + yᵀ(Ax − b)``, the same sign as :class:`~rollqp.problem.QPForm`'s,
so ``y[0]`` is the load multiplier.

qpsolvers calls are stateless: there is no solver object to build once and update, so every
QP is set up anew (the cost is in ``time``; ``solver_time`` is the solver's own where
qpsolvers reports it). Everything else — the symmetric–skew splitting of the collocation
operator, rollqp's residual check, the N–T alternation on coupled scenes — is
:class:`~rollqp.methods._qp.QPMethod`'s. Active-set refinement
(:func:`~rollqp.methods._qp.active_set_refine`) is switched on only for the interior-point
and augmented-Lagrangian solvers (PIQP, ProxQP), whose complementarity stops short of the
active-set solvers'; it is kept only where it lowers rollqp's residual (``info["refined"]``
counts it).
"""
from __future__ import annotations

import functools
import importlib
import os
import time

import numpy as np

from ..errors import MissingBackendError
from ._qp import QPMethod, constraint_rows

#: Native settings rollqp lets through to each solver (qpsolvers passes keywords on unchecked,
#: so rollqp checks them: an unknown setting is an error, not silently ignored).
NATIVE_OPTIONS = {
    "daqp": ("primal_tol", "dual_tol", "zero_tol", "pivot_tol", "progress_tol", "cycle_tol", "iter_limit",
             "fval_bound", "eps_prox", "eta_prox", "rho_soft", "rel_subopt", "abs_subopt"),
    "quadprog": (),
    "proxqp": ("backend", "eps_abs", "eps_rel", "max_iter", "verbose", "rho", "mu_eq", "mu_in",
               "check_duality_gap", "eps_duality_gap_abs", "eps_duality_gap_rel", "compute_timings"),
    "piqp": ("backend", "eps_abs", "eps_rel", "eps_duality_gap_abs", "eps_duality_gap_rel", "max_iter", "verbose",
             "rho_init", "delta_init", "reg_lower_limit", "max_factor_retires", "preconditioner_scale_cost",
             "preconditioner_iter", "tau", "compute_timings"),
    "highs": ("primal_feasibility_tolerance", "dual_feasibility_tolerance", "qp_regularization_value",
              "time_limit", "output_flag", "log_to_console"),
}

#: rollqp method name -> (qpsolvers solver name, package that provides it, refine)
SOLVERS = {
    "qps-daqp": ("daqp", "daqp", False),
    "qps-quadprog": ("quadprog", "quadprog", False),
    "qps-proxqp": ("proxqp", "proxsuite", True),
    "qps-piqp": ("piqp", "piqp", True),
    "qps-highs": ("highs", "highspy", False),
}


def _settings(solver: str, tolerance: float, max_iterations) -> dict:
    """Tight tolerances per solver (never the defaults: see module docstring)."""
    ip = max(1e-4 * tolerance, 1e-14)
    if solver == "daqp":
        s = dict(primal_tol=1e-12, dual_tol=1e-12)
        if max_iterations:
            s["iter_limit"] = int(max_iterations)
        return s
    if solver == "proxqp":
        s = dict(backend="dense", eps_abs=min(tolerance, 1e-9), eps_rel=0.0)
        if max_iterations:
            s["max_iter"] = int(max_iterations)
        return s
    if solver == "piqp":
        s = dict(backend="dense", eps_abs=ip, eps_rel=ip, eps_duality_gap_abs=ip, eps_duality_gap_rel=ip)
        if max_iterations:
            s["max_iter"] = int(max_iterations)
        return s
    if solver == "highs":
        # output_flag/log_to_console off: HiGHS otherwise prints its banner and log to stdout,
        # into rollqp's summary (rollqp's own SolverError says what went wrong)
        return dict(primal_feasibility_tolerance=1e-2 * tolerance, dual_feasibility_tolerance=1e-2 * tolerance,
                    qp_regularization_value=0.0, output_flag=False, log_to_console=False)
    return {}  # quadprog: a direct dual active-set method without tolerances


def _iterations(extras) -> int:
    """The solver's iteration count from qpsolvers' ``extras`` (0 if it does not say: DAQP and
    HiGHS through qpsolvers 4.13 report none)."""
    if not isinstance(extras, dict):
        return 0
    for key in ("iterations", "iter"):
        v = extras.get(key)
        if v is not None:
            v = np.ravel(v)
            return int(v[0]) if v.size else 0
    info = extras.get("info")
    for attr in ("iter", "iterations", "iter_ext"):
        v = info.get(attr) if isinstance(info, dict) else getattr(info, attr, None)
        if v is not None:
            return int(v)
    return 0


class QpsolversQP(QPMethod):
    """A QP backend through qpsolvers; subclasses (:func:`backend`) fix the solver.

    Parameters
    ----------
    tolerance, residual_limit, max_iterations, operator
        As :class:`~rollqp.methods._qp.QPMethod`.
    **options
        The solver's settings (:data:`NATIVE_OPTIONS`), passed through qpsolvers over rollqp's.
    """

    solver = ""  # qpsolvers' name of the solver, set by each subclass

    def __init__(self, tolerance: float = 1e-10, residual_limit=None, max_iterations=None,
                 operator: str = "exact", **options):
        super().__init__(tolerance, residual_limit, max_iterations, operator, **options)
        import qpsolvers
        self._qpsolvers = qpsolvers
        if self.solver == "highs":
            _discard_highs_banner()

    def _problem(self, form):
        n, up, lo, fx = constraint_rows(form)
        I = np.eye(n)
        G = np.vstack([I[up], -I[lo]])
        h = np.concatenate([form.upper[up], -form.lower[lo]])
        A_rows, b = [], []
        if form.a is not None:
            A_rows.append(form.a[None, :])
            b.append(float(form.b))
        if fx.size:
            A_rows.append(I[fx])
            b.extend(form.lower[fx])
        A = np.vstack(A_rows) if A_rows else None
        P, G = np.array(form.H), (G if G.shape[0] else None)  # a copy: the Hessian is read-only (a memo), DAQP writes
        if self.solver == "highs":  # HiGHS takes sparse matrices only (qpsolvers would convert and warn)
            import scipy.sparse as sp
            P, G, A = (None if M is None else sp.csc_matrix(M) for M in (P, G, A))
        return self._qpsolvers.Problem(P, form.q, G, h if h.size else None,
                                       A, np.asarray(b, dtype=float) if A_rows else None)

    def _solve_form(self, form, x0, source=None):
        problem = self._problem(form)
        kwargs = _settings(self.solver, self.tolerance, self.max_iterations)
        kwargs.update(self.options)
        t0 = time.perf_counter()
        try:
            sol = self._qpsolvers.solve_problem(problem, solver=self.solver,
                                                initvals=x0 if self.solver in ("proxqp", "piqp") else None,
                                                **kwargs)
        except Exception as exc:  # qpsolvers raises its own errors for solver failures
            n = form.H.shape[0]
            return np.zeros(n), 0.0, f"{type(exc).__name__}: {exc}", 0, time.perf_counter() - t0, {}
        spent = time.perf_counter() - t0
        ok = bool(sol.found) and sol.x is not None and np.all(np.isfinite(sol.x))
        x = np.asarray(sol.x, dtype=float) if sol.x is not None else np.zeros(form.H.shape[0])
        y = float(sol.y[0]) if (form.a is not None and sol.y is not None and len(sol.y)) else 0.0
        iters = _iterations(sol.extras)
        return x, y, "solved" if ok else "not found", iters, spent, {"solver": self.solver, "built": True,
                                                                      "iterations_reported": iters > 0}


@functools.lru_cache(maxsize=None)
def _discard_highs_banner() -> None:
    """Build the process's first HiGHS object with the C-level stdout pointed at the null device.

    HiGHS prints its banner (version and licence) on stdout when the first ``Highs`` object of
    a process is built, before any option can silence it; it would land in rollqp's summary,
    in anything piped from it, and on the terminal of ``rollqp crossval`` and ``rollqp bench``.
    The banner is discarded, once per process (``highspy.__version__`` names the version);
    later objects print nothing (their log is off by ``output_flag``).
    """
    import ctypes
    import sys
    import highspy
    sys.stdout.flush()
    saved = os.dup(1)
    null = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(null, 1)
        highspy.Highs()
        try:
            ctypes.CDLL(None).fflush(None)  # the banner sits in C's stdout buffer until flushed
        except (OSError, AttributeError):  # pragma: no cover - no C library to flush (non-POSIX)
            pass
    finally:
        os.dup2(saved, 1)
        os.close(saved)
        os.close(null)


def _available(solver: str, package: str) -> bool:
    try:
        importlib.import_module(package)
        import qpsolvers
    except ImportError:
        return False
    return solver in qpsolvers.available_solvers


@functools.lru_cache(maxsize=None)
def backend(name: str) -> type:
    """The method class of the qpsolvers backend ``name`` (``"qps-daqp"``, …)."""
    solver, _, refine = SOLVERS[name]
    return type(f"Qps{solver.capitalize()}", (QpsolversQP,),
                {"name": name, "solver": solver, "refine": refine, "native_options": NATIVE_OPTIONS[solver],
                 "__doc__": f"``{name}``: {solver} through qpsolvers (:class:`QpsolversQP`)."})


def __getattr__(attr):
    """``qps_<solver>``: the class of that backend, if qpsolvers and the solver are installed."""
    name = attr.replace("_", "-")
    if name not in SOLVERS:
        raise AttributeError(attr)
    solver, package, _ = SOLVERS[name]
    if not _available(solver, package):
        raise MissingBackendError(f"method {name!r} needs the solver package {package!r} "
                                  f"(pip install 'rollqp[qpsolvers]')")
    return backend(name)
