"""cvxpy: the textbook formulation, for readability and as a third opinion.

.. code-block:: text

    minimize    ½ xᵀ H x + qᵀ x
    subject to  aᵀ x == b,   l <= x <= u

``q``, ``b``, ``l`` and ``u`` are :class:`cvxpy.Parameter`\\ s, so the problem is
DPP-compliant and compiled once per scene; each step only sets parameter values.
The default solver is OSQP, with polishing passed explicitly (cvxpy turns it off on
re-solves otherwise) and ``status_polish`` checked; ``solver="CLARABEL"`` is accepted.
"""
from __future__ import annotations

import importlib.util

import numpy as np

from ._qp import QPMethod, constraint_rows
from .qp_clarabel import ClarabelQP, clarabel_settings
from .qp_osqp import OsqpQP
from ..errors import InputError

if importlib.util.find_spec("cvxpy") is None:  # not installed: the registry names the extra to install
    raise ModuleNotFoundError("No module named 'cvxpy'", name="cvxpy")


def _cvxpy():
    """cvxpy, imported when a problem is first built: reading the method's capabilities (the registry, the
    advice before a run) does not import it (90 MB of memory)."""
    import cvxpy
    return cvxpy


try:
    import osqp as _osqp
    _POLISH_KEY = "polish" if int(_osqp.__version__.split(".")[0]) < 1 else "polishing"
except ImportError:  # pragma: no cover - osqp is a core dependency
    _POLISH_KEY = "polishing"


class CvxpyQP(QPMethod):
    """cvxpy on the QPs of a step; ``solver`` is ``"OSQP"`` (default) or ``"CLARABEL"``, and
    ``**options`` are that solver's settings (cvxpy passes them on)."""

    name = "qp-cvxpy"
    # OSQP's own polish fails inside cvxpy on most of these QPs (the status_polish check
    # retries), and Clarabel stops at sqrt(gap): refine on the found active set (_qp.py).
    refine = True
    native_options = tuple(sorted(set(OsqpQP.native_options) | set(ClarabelQP.native_options)))

    def __init__(self, tolerance=1e-10, residual_limit=None, max_iterations=None, operator="exact",
                 solver="OSQP", **options):
        if solver not in ("OSQP", "CLARABEL"):
            raise InputError("solver", f"cvxpy backend solver must be 'OSQP' or 'CLARABEL', got {solver!r}")
        self.native_options = OsqpQP.native_options if solver == "OSQP" else ClarabelQP.native_options
        super().__init__(tolerance, residual_limit, max_iterations, operator, **options)
        self.solver = solver

    def _build(self, form):
        cp = _cvxpy()
        n, up, lo, fx = constraint_rows(form)
        x = cp.Variable(n, name="x")
        q = cp.Parameter(n, name="q")
        objective = cp.Minimize(0.5 * cp.quad_form(x, cp.psd_wrap(form.H)) + q @ x)
        cons, params = [], {"q": q}
        if form.a is not None:
            b = cp.Parameter(name="b")
            cons.append(form.a @ x == b)
            params["b"] = b
        if fx.size:
            cons.append(x[fx] == 0.0)  # nodes without friction bound carry no shear
        if up.size:
            u = cp.Parameter(up.size, name="u")
            cons.append(x[up] <= u)
            params["u"] = (u, up)
        if lo.size:
            l = cp.Parameter(lo.size, name="l")
            cons.append(x[lo] >= l)
            params["l"] = (l, lo)
        prob = cp.Problem(objective, cons)
        if not prob.is_dpp():  # pragma: no cover - a bug in this module, not bad input
            raise RuntimeError("the cvxpy step problem is not DPP-compliant")
        return prob, x, params, cons

    def _solver_kwargs(self):
        if self.solver == "OSQP":
            eps = max(self.tolerance, 1e-7)
            # cvxpy forwards this dict to OSQP; OSQP >= 1 calls the switch "polishing", and cvxpy
            # defaults it to off on every re-solve that does not refactorize.
            kw = dict(**{_POLISH_KEY: True}, polish_refine_iter=20, eps_abs=eps, eps_rel=eps, delta=1e-10,
                      max_iter=int(self.max_iterations or 200000), warm_start=True)
        else:
            kw = clarabel_settings(self.tolerance)
            for k in ("verbose", "presolve_enable", "iterative_refinement_max_iter"):
                kw.pop(k)  # left to cvxpy's own defaults
            kw["max_iter"] = int(self.max_iterations or 200)
        kw.update(self.options)
        return kw

    def _solve_form(self, form, x0, source=None):
        cp = _cvxpy()
        (prob, x, params, cons), fresh = self._solver_for(form, source, self._build)
        params["q"].value = form.q
        if "b" in params:
            params["b"].value = float(form.b)
        if "u" in params:
            params["u"][0].value = form.upper[params["u"][1]]
        if "l" in params:
            params["l"][0].value = form.lower[params["l"][1]]
        if x0 is not None:
            x.value = x0
        kwargs = self._solver_kwargs()
        try:
            prob.solve(solver=getattr(cp, self.solver), **kwargs)
        except cp.error.SolverError as exc:
            return (np.zeros(form.H.shape[0]), 0.0, f"solver error: {exc}", 0, 0.0, {})
        status = prob.status
        info = {"solver_status": status, "built": fresh}
        if self.solver == "OSQP":
            # OSQP's polish is passed on, but inside cvxpy it is refused on most of these QPs
            # (its active-set guess is not better than the ADMM iterate). Retrying with tighter
            # ADMM tolerances tripled the cost; the active-set refinement in QPMethod.solve
            # (refine = True) finishes the job instead, and rollqp's residual decides.
            extra = prob.solver_stats.extra_stats
            info["status_polish"] = getattr(getattr(extra, "info", None), "status_polish", None)
        ok = status == cp.OPTIMAL
        y = float(cons[0].dual_value) if (form.a is not None and ok) else 0.0
        xv = np.asarray(x.value) if x.value is not None else np.zeros(form.H.shape[0])
        st = prob.solver_stats
        return (xv, y, "solved" if ok else str(status), st.num_iters or 0, st.solve_time or 0.0, info)
