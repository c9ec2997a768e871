"""Check a step solution from a solver rollqp does not wrap: scipy's SLSQP on an exported step.

The workflow of ``docs/stepfiles.md`` in one script:

1. ``export_step``: march the paper's §6.1.1 scene (Cattaneo → Carter) with Newton to rolling
   step K and write the step file (what ``rollqp export-step cattaneo-carter --step K`` does);
2. solve both halves of the step from the ``.npz`` alone with ``scipy.optimize.minimize``
   (SLSQP), the collocation operator's skew part moved to the linear term at the previous
   iterate (the splitting of docs/formulation.md §8), the friction bound from the pressure found;
3. ``check_step``: rollqp's residuals of that candidate, its differences from rollqp's Newton
   and QP solutions, and the nodes whose stick/slip/separation state differs.

Run it::

    python examples/validate_external.py [K] [folder]

It exits non-zero if the external solution does not pass.
"""
from __future__ import annotations

import os
import sys
import tempfile

import numpy as np
from scipy.optimize import minimize

from rollqp.stepfile import check_step, export_step


def slsqp_half(z, half, lb, ub, q_extra, x0):
    """``min ½xᵀPx + (q + q_extra + skew x_prev)ᵀx`` s.t. ``lb <= x <= ub``, ``A x = b`` by SLSQP, iterated."""
    g = lambda k: z[f"{half}_qp_{k}"]  # noqa: E731
    P, skew, A, b = g("P"), g("skew"), g("A"), g("b")
    cons = [{"type": "eq", "fun": lambda x: A @ x - b, "jac": lambda x: A}] if A.shape[0] else []
    bounds = list(zip(lb, np.where(np.isfinite(ub), ub, None)))
    x = x0
    for _ in range(100):  # splitting: converges by ~0.05 per pass (docs/validation.md)
        q = g("q") + q_extra + skew @ x
        r = minimize(lambda v: 0.5 * v @ P @ v + q @ v, x, jac=lambda v: P @ v + q, method="SLSQP",
                     bounds=bounds, constraints=cons, options={"ftol": 1e-15, "maxiter": 2000})
        if not r.success:
            raise SystemExit(f"SLSQP failed on the {half} half: {r.message}")
        change, x = np.max(np.abs(r.x - x)), r.x
        if change < 1e-10:
            break
    # the load multiplier: stationarity P x + q + y a = λ on the free nodes (λ = 0 there)
    free = (x > lb + 1e-9) & (x < ub - 1e-9)
    y = 0.0
    if A.shape[0] and free.any():
        y = float(-np.mean(((P @ x + q)[free]) / A[0, free]))
    return x, y


def solve_external(path):
    """A candidate solution (p, t, δ, ξ) from the step file alone, by SLSQP."""
    z = dict(np.load(path, allow_pickle=False))
    n, mu = z["f"].size, float(z["mu"])
    N, T = "normal", "tangential"
    p, yn = slsqp_half(z, N, z[f"{N}_qp_lb"], z[f"{N}_qp_ub"], 0.0, np.zeros(n))
    p_phys = p * z[f"{N}_qp_x_scale"]
    bound = mu * np.maximum(p_phys, 0.0) / z[f"{T}_qp_x_scale"]
    # A_tn p enters through `coupling` (zero for similar materials), relative to rollqp's p
    q_extra = z[f"{T}_qp_coupling"] @ (p_phys - z["ref_p"]) / z[f"{N}_qp_x_scale"]
    t, yt = slsqp_half(z, T, -bound, bound, q_extra, np.zeros(n))
    out = {"p": p_phys, "t": t * z[f"{T}_qp_x_scale"]}
    if z[f"{N}_qp_A"].shape[0]:
        out["delta"] = yn * float(z[f"{N}_qp_y_scale"])
    if z[f"{T}_qp_A"].shape[0]:
        out["xi"] = yt * float(z[f"{T}_qp_y_scale"])
    return out


def main(K=4, folder=None):
    folder = folder or tempfile.mkdtemp(prefix="rollqp-")
    step = export_step("cattaneo-carter", K)
    path = os.path.join(folder, f"cattaneo-carter-step{K}.npz")
    step.save(path)
    candidate = solve_external(path)
    np.savez(os.path.join(folder, "slsqp-solution.npz"), **candidate)
    report = check_step(path, candidate)
    print(report)
    return report


if __name__ == "__main__":
    args = sys.argv[1:]
    report = main(int(args[0]) if args else 4, args[1] if len(args) > 1 else None)
    sys.exit(0 if report.passed else 1)
