"""The cvxpy script written beside a step file: it rebuilds the step's QPs and solves them (docs/stepfiles.md)."""
from __future__ import annotations

__all__ = ["cvxpy_script", "CVXPY_SCRIPT"]


def cvxpy_script(step_name: str) -> str:
    """The cvxpy script for the step file ``step_name`` (a file name, no folder).

    The name is data, never code: it enters the script as a Python string literal
    (``repr``), and in the docstring only with its characters outside ``[A-Za-z0-9._-]``
    replaced, so no file name can end the docstring or the literal and inject code.
    """
    import re
    shown = re.sub(r"[^A-Za-z0-9._-]", "_", step_name)
    return (CVXPY_SCRIPT.replace("@STEPFILE_LITERAL@", repr(step_name))
            .replace("@STEPFILE_STEM@", shown[:-4] if shown.endswith(".npz") else shown)
            .replace("@STEPFILE@", shown))



CVXPY_SCRIPT = r'''"""Rebuild and solve the step in @STEPFILE@ with cvxpy (written by rollqp export-step).

Self-contained: needs numpy and cvxpy only. Each half of the step is the variational
inequality with operator P + skew (the collocation step; P the symmetric part of the scaled
F·A, docs/formulation.md §8), solved as a sequence of convex QPs with Hessian P and the skew part
moved to the linear term at the previous iterate (q_k = q + skew x_{k-1}); the two halves
alternate (paper §6.3), the other half entering through `coupling` (zero for an uncoupled
step) and the friction bound mu·max(p, 0). Each sweep is one QP per half, from zero. The result is written to the .npz that `rollqp check-step` reads:

    python @STEPFILE_STEM@.cvxpy.py            # -> @STEPFILE_STEM@.cvxpy-solution.npz
    rollqp check-step @STEPFILE@ @STEPFILE_STEM@.cvxpy-solution.npz
"""
import os
import sys
import warnings

import cvxpy as cp
import numpy as np

here = os.path.dirname(os.path.abspath(__file__))
path = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, @STEPFILE_LITERAL@)
z = dict(np.load(path, allow_pickle=False))
TOL = 1e-11  # change of x (p/p0, t/p0) per sweep at which the iteration stops
INACCURATE = [0]  # QPs cvxpy reported "optimal_inaccurate" (Clarabel close to, not at, its 1e-12 tolerances)


def half(name):
    return {k[len(name) + 4:]: v for k, v in z.items() if k.startswith(name + "_qp_")}


def build(d):
    """One cvxpy problem per half, compiled once: q, lb, ub are parameters."""
    n = d["q"].size
    x, q = cp.Variable(n), cp.Parameter(n)
    lb, ub = cp.Parameter(n), cp.Parameter(n)
    eq = [d["A"] @ x == d["b"]] if d["A"].shape[0] else []
    big = 1e6  # finite stand-in for the open upper bound of the pressure (p <= 1e6 p0)
    prob = cp.Problem(cp.Minimize(0.5 * cp.quad_form(x, cp.psd_wrap(d["P"])) + q @ x), eq + [x >= lb, x <= ub])

    def solve(q_value, lo, up):
        q.value, lb.value, ub.value = q_value, lo, np.minimum(up, big)
        for tol in (1e-12, 1e-10, 1e-8):  # tight first (never the defaults); looser if Clarabel stalls
            try:
                with warnings.catch_warnings():  # "optimal_inaccurate" is counted below, not warned per QP
                    warnings.simplefilter("ignore", UserWarning)
                    prob.solve(solver=cp.CLARABEL, tol_gap_abs=tol, tol_gap_rel=tol, tol_feas=tol, tol_ktratio=1e-6)
                break
            except cp.error.SolverError:
                continue
        if prob.status not in ("optimal", "optimal_inaccurate"):
            raise SystemExit(f"cvxpy: {prob.status}")
        # Clarabel stopped short of 1e-12 but close ("almost solved"): kept, and rollqp check-step judges the result
        INACCURATE[0] += prob.status == "optimal_inaccurate"
        return x.value.copy(), (float(eq[0].dual_value[0]) if eq else 0.0)

    return solve


N, T = half("normal"), half("tangential")
solve_n, solve_t = build(N), build(T)
p, t = np.zeros(z["ref_p"].size), np.zeros(z["ref_t"].size)
p_ref, t_ref = z["ref_p"] / N["x_scale"], z["ref_t"] / T["x_scale"]
mu = float(z["mu"])
for it in range(500):
    # normal half: skew part and shear (coupling; zero if uncoupled) at the previous iterate
    p_new, yn = solve_n(N["q"] + N["skew"] @ p + N["coupling"] @ (t - t_ref), N["lb"], N["ub"])
    # tangential half at the new pressure: bound mu·max(p, 0), A_tn p through coupling
    bound = mu * np.maximum(p_new, 0.0) * N["x_scale"] / T["x_scale"]
    t_new, yt = solve_t(T["q"] + T["skew"] @ t + T["coupling"] @ (p_new - p_ref), -bound, bound)
    change = max(np.max(np.abs(p_new - p)), np.max(np.abs(t_new - t)))
    p, t = p_new, t_new
    if change < TOL:
        break
print(f"{it + 1} sweeps, last change {change:.1e}"
      + (f"; {INACCURATE[0]} of {2 * (it + 1)} QPs near, not at, Clarabel's 1e-12 tolerances" if INACCURATE[0] else ""))
out = {"p": p * N["x_scale"], "t": t * T["x_scale"]}
if N["A"].shape[0]:
    out["delta"] = yn * float(N["y_scale"])
if T["A"].shape[0]:
    out["xi"] = yt * float(T["y_scale"])
target = path[:-4] + ".cvxpy-solution.npz"
np.savez(target, **out)
print(f"wrote {target}")
'''
