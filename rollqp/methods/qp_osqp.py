"""OSQP, native interface (ADMM; Stellato et al. 2020).

Set up once per problem structure; each step ``update``\\ s ``q, l, u`` and warm-starts
from the previous step. ADMM alone does not reach cross-validation accuracy: solution
polishing (an active-set refinement) is switched on and its outcome is checked
(``info.status_polish``). OSQP calls a polish "unsuccessful" whenever the polished point
is not better than the ADMM iterate, which also happens when ADMM is already accurate;
so a failed polish is retried twice with ADMM tolerances two decades tighter each time,
and then rollqp's own residual decides (``info["status_polish"]`` records the outcome).
"""
from __future__ import annotations

import time

import numpy as np
import osqp
import scipy.sparse as sp

from ..errors import SolverError
from ._qp import QPMethod


class OsqpQP(QPMethod):
    """OSQP on the QPs of a step; ``**options`` are OSQP settings (``osqp`` ``setup`` keywords)."""

    name = "qp-osqp"
    native_options = tuple(a for a in dir(osqp.ext_builtin.OSQPSettings()) if not a.startswith("_"))

    def _settings(self, eps):
        s = dict(verbose=False, polishing=True, polish_refine_iter=20, eps_abs=eps, eps_rel=eps,
                 eps_prim_inf=1e-12, eps_dual_inf=1e-12, max_iter=int(self.max_iterations or 200000),
                 warm_starting=True, delta=1e-10, scaling=10, adaptive_rho=True)
        s.update(self.options)
        return s

    def structure_key(self, form):
        """Fixed variables (l = u) are data for OSQP, not structure: every variable has its
        identity row whatever its bounds. Keyed on them, the solver would be rebuilt at almost every
        tangential half of the N–T alternation, where pressures of ±1e-21 p0 at separated nodes
        make the zero-bound set change from half to half."""
        return form.structure[:-1]  # (kind, n, has_eq, finite lower, finite upper)

    def _bounds(self, form):
        l, u = form.lower.copy(), form.upper.copy()
        if form.a is not None:
            l = np.concatenate([[form.b], l])
            u = np.concatenate([[form.b], u])
        return l, u

    def _build(self, form):
        n = form.H.shape[0]
        rows = [sp.identity(n, format="csc")]
        if form.a is not None:
            rows.insert(0, sp.csc_matrix(form.a[None, :]))
        A = sp.vstack(rows, format="csc")
        l, u = self._bounds(form)
        m = osqp.OSQP()
        try:
            m.setup(P=sp.triu(sp.csc_matrix(form.H), format="csc"), q=form.q, A=A, l=l, u=u,
                    **self._settings(self._eps()))
        except (osqp.OSQPException, ValueError) as exc:  # reported as the QP's status, not leaked
            raise SolverError(f"OSQP's set-up failed ({type(exc).__name__}: {exc})", method=self.name,
                              status="setup failed") from None
        return m

    def _eps(self):
        # ADMM tolerance: polishing supplies the final digits; start loose, retry tighter.
        return max(self.tolerance, 1e-7)

    def _solve_form(self, form, x0, source=None):
        m, fresh = self._solver_for(form, source, self._build)
        if not fresh:
            if self._same_bounds(m, form):  # the splitting's next QP: only q changed
                m.update(q=form.q)
            else:
                l, u = self._bounds(form)
                m.update(q=form.q, l=l, u=u)
        self._bounds_of = (m, form)
        if x0 is not None:
            m.warm_start(x=x0)
        tc, cc = time.perf_counter(), time.process_time()
        res = m.solve(raise_error=False)  # statuses are checked here, not raised by OSQP
        tries = 1
        calls, cpu = time.perf_counter() - tc, time.process_time() - cc  # inside OSQP's solve() calls
        spent = res.info.solve_time + res.info.polish_time
        iters = res.info.iter
        while res.info.status_polish != 1 and tries < 3:
            eps = self._eps() * 10.0 ** (-2 * tries)
            m.update_settings(eps_abs=eps, eps_rel=eps)
            tc, cc = time.perf_counter(), time.process_time()  # the retry's solve call counts, its settings update not
            res = m.solve(raise_error=False)  # statuses are checked here, not raised by OSQP
            calls, cpu = calls + time.perf_counter() - tc, cpu + time.process_time() - cc
            tries += 1
            spent += res.info.solve_time + res.info.polish_time  # every try counts
            iters += res.info.iter
        if tries > 1:
            m.update_settings(eps_abs=self._eps(), eps_rel=self._eps())
        # A polish that still fails after the retries leaves the (tightly converged) ADMM
        # iterate: rollqp's residual check in QPMethod.solve decides whether it is enough.
        status = res.info.status
        y = res.y[0] if form.a is not None else 0.0
        return (np.asarray(res.x), y, status, iters, spent,
                {"solver_status": res.info.status, "status_polish": int(res.info.status_polish),
                 "tries": tries, "built": fresh, "solve_call_time": calls, "solve_call_cpu": cpu})
