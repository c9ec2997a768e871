"""Clarabel, native interface (interior point; Goulart & Chen 2024).

Built once per problem structure; each step only ``update``\\ s ``q`` and ``b``
(presolve off, or Clarabel refuses data updates). Clarabel's defaults stop about 1e-4
short of what cross-validation needs on these problems: its gap and feasibility
tolerances are set from the scene's tolerance, the data are rescaled to order one by
:class:`~rollqp.problem.QPForm`, and iterative refinement is tightened.
"""
from __future__ import annotations

import time

import clarabel
import numpy as np
import scipy.sparse as sp

from ._qp import QPMethod, constraint_rows

# "AlmostSolved" (Clarabel's reduced tolerances met) is accepted here because the residual
# check in QPMethod.solve, not Clarabel's status, is what decides (see clarabel_tolerances).
_SOLVED = {"Solved", "AlmostSolved"}


def clarabel_tolerances(tolerance: float) -> tuple[float, float]:
    """Clarabel's (gap, feasibility) tolerances for a requested rollqp residual.

    The duality-gap test bounds the sum of the products of each bound's slack and
    multiplier (``p_i·ĝ_i f_i``, ``(μp_i − |t_i|)·|ŝ_i| f_i``), not each ``min(·,·)``. Where
    one factor is small but not zero — gap just outside the contact, slip at the edge of a
    slip zone — the other is left at about gap/factor. Four decades below the requested
    tolerance (floored at 1e-15) reaches it (the measured residuals by gap tolerance:
    docs/performance.md, "Measured settings of the methods"); Clarabel then often reports
    ``AlmostSolved`` (its reduced tolerances met), and rollqp's own residual decides.
    """
    t = max(1e-4 * tolerance, 1e-15)
    return t, t


def clarabel_rows(form):
    """Clarabel's constraint rows ``A x + s = b``, ``s`` in the cones, for a :class:`~rollqp.problem.QPForm`.

    The zero cone holds the load row (if any) and the nodes without a friction bound
    (``lower == upper``: equalities, not two opposite bounds, :func:`~rollqp.methods._qp.constraint_rows`);
    the nonnegative cone ``x <= upper`` (finite) and ``−x <= −lower`` (finite).

    Returns
    -------
    A : scipy.sparse.csc_matrix
    b : ndarray
    cones : tuple of (str, int)
        ``("ZeroConeT", m0)``, ``("NonnegativeConeT", m1)``.
    """
    n, up, lo, fx = constraint_rows(form)
    I = sp.identity(n, format="csr")
    blocks = [sp.csr_matrix(form.a[None, :])] if form.a is not None else []
    blocks += [I[fx], I[up], -I[lo]]
    cones = (("ZeroConeT", int(form.a is not None) + fx.size), ("NonnegativeConeT", up.size + lo.size))
    return sp.vstack(blocks, format="csc"), clarabel_rhs(form, (up, lo, fx)), cones


def clarabel_rhs(form, rows=None) -> np.ndarray:
    """The right-hand side ``b`` of :func:`clarabel_rows` alone (what a re-solve updates: the
    sparse rows stay those of the solver object's structure). ``rows``: ``(up, lo, fx)`` if known."""
    up, lo, fx = constraint_rows(form)[1:] if rows is None else rows
    b = [[form.b]] if form.a is not None else []
    b += [form.lower[fx], form.upper[up], -form.lower[lo]]
    return np.concatenate([np.atleast_1d(np.asarray(v, dtype=float)) for v in b])


def clarabel_settings(tolerance: float) -> dict:
    """rollqp's Clarabel settings for a requested residual (never the defaults: module docstring)."""
    gap, feas = clarabel_tolerances(tolerance)
    return dict(verbose=False, presolve_enable=False, tol_gap_abs=gap, tol_gap_rel=gap, tol_feas=feas,
                tol_ktratio=min(1e-6, gap), iterative_refinement_reltol=1e-14,
                iterative_refinement_abstol=1e-14, iterative_refinement_max_iter=20)


class ClarabelQP(QPMethod):
    """Clarabel on the QPs of a step; ``**options`` are ``clarabel.DefaultSettings`` attributes."""

    name = "qp-clarabel"
    refine = True  # interior point: complementarity stops at sqrt(gap); see active_set_refine
    native_options = tuple(a for a in dir(clarabel.DefaultSettings()) if not a.startswith("_"))

    def _settings(self):
        s = clarabel.DefaultSettings()
        values = clarabel_settings(self.tolerance)
        values["max_iter"] = int(self.max_iterations or 200)
        values.update(self.options)
        for k, v in values.items():
            setattr(s, k, v)
        return s

    def _build(self, form):
        A, b, cones = clarabel_rows(form)
        cones = [getattr(clarabel, name)(m) for name, m in cones if m or name == "NonnegativeConeT"]
        P = sp.triu(sp.csc_matrix(form.H), format="csc")
        return clarabel.DefaultSolver(P, form.q, A, b, cones, self._settings())

    def _solve_form(self, form, x0, source=None):
        t0 = time.perf_counter()
        solver, fresh = self._solver_for(form, source, self._build)
        setup = time.perf_counter() - t0 if fresh else 0.0
        if not fresh:
            if self._same_bounds(solver, form):  # the splitting's next QP: only q changed
                solver.update(q=form.q)
            else:
                solver.update(q=form.q, b=clarabel_rhs(form))
        self._bounds_of = (solver, form)
        t1, c1 = time.perf_counter(), time.process_time()
        sol = solver.solve()
        solve_wall, solve_cpu = time.perf_counter() - t1, time.process_time() - c1
        status = str(sol.status)
        y = sol.z[0] if form.a is not None else 0.0
        # Clarabel's own ``solve_time`` includes the solver object's one-time set-up, and a
        # reused object reports it again on every solve; rollqp reports the wall time of the
        # ``solve()`` call instead, and the set-up (when built here) separately.
        info = {"solver_status": status, "clarabel_solve_time": float(sol.solve_time), "built": fresh,
                "solve_call_time": solve_wall, "solve_call_cpu": solve_cpu}
        if fresh:
            info["setup_time"] = setup
        return (np.asarray(sol.x), y, "solved" if status in _SOLVED else status, sol.iterations,
                solve_wall, info)
