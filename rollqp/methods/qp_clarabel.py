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
    slip zone — the other is left at about gap/factor. Measured maximum residual over the
    193 steps of ``rollqp run cattaneo-carter --method qp-clarabel``: gap tolerance 1e-12
    → 5.5e-8, 1e-13 → 3.1e-9, 1e-14 → 4.9e-10. Four decades below the requested
    tolerance (floored at 1e-15) therefore reaches it; Clarabel then often reports
    ``AlmostSolved`` (its reduced tolerances met), and rollqp's own residual decides.
    """
    t = max(1e-4 * tolerance, 1e-15)
    return t, t


class ClarabelQP(QPMethod):
    name = "qp-clarabel"
    refine = True  # interior point: complementarity stops at sqrt(gap); see active_set_refine

    def _settings(self):
        s = clarabel.DefaultSettings()
        s.verbose = False
        s.presolve_enable = False
        gap, feas = clarabel_tolerances(self.tolerance)
        s.tol_gap_abs = gap
        s.tol_gap_rel = gap
        s.tol_feas = feas
        s.tol_ktratio = min(1e-6, gap)
        s.iterative_refinement_reltol = 1e-14
        s.iterative_refinement_abstol = 1e-14
        s.iterative_refinement_max_iter = 20
        s.max_iter = int(self.max_iterations or 200)
        for k, v in self.options.items():
            setattr(s, k, v)
        return s

    def _rhs(self, form):
        n, up, lo, fx = constraint_rows(form)
        parts = []
        if form.a is not None:
            parts.append([form.b])
        parts += [form.lower[fx], form.upper[up], -form.lower[lo]]
        return np.concatenate([np.atleast_1d(np.asarray(p, dtype=float)) for p in parts])

    def _build(self, form):
        n, up, lo, fx = constraint_rows(form)
        blocks = []
        I = sp.identity(n, format="csr")
        if form.a is not None:
            blocks.append(sp.csr_matrix(form.a[None, :]))
        blocks += [I[fx], I[up], -I[lo]]
        cones = []
        if form.a is not None or fx.size:
            cones.append(clarabel.ZeroConeT(int(form.a is not None) + fx.size))
        cones.append(clarabel.NonnegativeConeT(up.size + lo.size))
        A = sp.vstack(blocks, format="csc")
        P = sp.triu(sp.csc_matrix(form.H), format="csc")
        return clarabel.DefaultSolver(P, form.q, A, self._rhs(form), cones, self._settings())

    def _solve_form(self, form, x0):
        t0 = time.perf_counter()
        solver, fresh = self._solver_for(form, self._build)
        setup = time.perf_counter() - t0 if fresh else 0.0
        if not fresh:
            solver.update(q=form.q, b=self._rhs(form))
        t1 = time.perf_counter()
        sol = solver.solve()
        solve_wall = time.perf_counter() - t1
        status = str(sol.status)
        y = sol.z[0] if form.a is not None else 0.0
        # Clarabel's own ``solve_time`` includes the solver object's one-time set-up, and a
        # reused object reports it again on every solve; rollqp reports the wall time of the
        # ``solve()`` call instead, and the set-up (when built here) separately.
        info = {"solver_status": status, "clarabel_solve_time": float(sol.solve_time)}
        if fresh:
            info["setup_time"] = setup
        return (np.asarray(sol.x), y, "solved" if status in _SOLVED else status, sol.iterations,
                solve_wall, info)
