"""Solve one step from your own arrays, with every QP backend, and compare them.

You have influence coefficients from your own FEM/BEM code — a matrix ``A`` with
``A[i, j]`` the displacement at node i due to a unit traction at node j, integration
weights ``f`` with ``P = fᵀp`` — and want rollqp's step solvers and its independent
residuals. Here :func:`rollqp.halfspace_influence` stands in for "my FEM/BEM code": after
the first block only plain numpy arrays are used.

The problem: the paper's steel rollers (R_A = 150 mm, R_B = 300 mm, E = 210 GPa, ν = 0.3,
P = 1000 N/mm, μ = 0.1), pressed together (normal step), then shifted without rolling until
Q = 0.6 μP (one tangential static-shift step: Cattaneo's problem). Sign convention
(docs/formulation.md §1): p ≥ 0 in compression, t on body A in +x, g ≥ 0 the gap,
s = ξ + (c + A t)/Δq the slip of A relative to B.

Run it::

    python examples/own_arrays.py
"""
from __future__ import annotations

import numpy as np

import rollqp

METHODS = ("qp-clarabel", "qp-osqp", "qp-cvxpy")
STATE_NAMES = {0: "separation", 1: "stick", 2: "slip"}


def my_fem_arrays():
    """Stand-in for the user's own code: nodes, weights, gap, influence matrices (N, mm)."""
    E, nu, R_A, R_B = 210000.0, 0.3, 150.0, 300.0
    Estar = 1.0 / (2 * (1 - nu ** 2) / E)
    R = 1.0 / (1 / R_A + 1 / R_B)
    a = np.sqrt(4 * 1000.0 * R / (np.pi * Estar))
    strip = rollqp.Strip(1.25 * a, 40, "constant")       # 40 elements on ±1.25 a_H
    infl = rollqp.halfspace_influence(strip, Estar=Estar, beta=0.0, R_A=R_A, R_B=R_B)
    return dict(x=np.array(strip.x), f=np.array(strip.weights), h=np.array(infl.h),
                A_nn=np.array(infl.Ann), A_tt=np.array(infl.Att), Estar=Estar, R=R)


def zones(x, state):
    """Runs of equal node states from left to right: ``[(name, x_first, x_last, count), ...]``."""
    out = []
    start = 0
    for i in range(1, x.size + 1):
        if i == x.size or state[i] != state[start]:
            out.append((STATE_NAMES[int(state[start])], float(x[start]), float(x[i - 1]), i - start))
            start = i
    return out


def main(P=1000.0, mu=0.1, ratio=0.6, methods=METHODS):
    arr = my_fem_arrays()
    x, f = arr["x"], arr["f"]
    scales = rollqp.Scales.hertz(P, arr["R"], arr["Estar"])     # residuals in a_H, p0, E*
    print(f"{x.size} nodes; a_H = {scales.length:.4f} mm, p0 = {scales.stress:.2f} MPa")
    FA = f[:, None] * arr["A_nn"]        # a QP needs F·A symmetric; rollqp splits off any skew part
    print(f"weighted asymmetry |FA - (FA)^T|/|FA| = {np.linalg.norm(FA - FA.T) / np.linalg.norm(FA):.1e}")

    # ---- normal step: g = h − δ + A p, p ≥ 0, g ≥ 0, p·g = 0, fᵀp = P
    normal = rollqp.NormalStep(A=arr["A_nn"], f=f, h=arr["h"], P=P, scales=scales)
    nsol = {m: rollqp.solve_step(normal, m) for m in methods}

    # ---- tangential step: static shift from unloaded bodies (c = 0, Δq = a_H), fᵀt = Q
    ref = nsol[methods[0]]
    tangential = rollqp.TangentialStep(A=arr["A_tt"], f=f, p=ref.p, mu=mu, c=np.zeros(x.size),
                                       dq=scales.length, Q=ratio * mu * P, scales=scales)
    tsol = {m: rollqp.solve_step(tangential, m) for m in methods}

    print("\nrollqp's residuals (nondimensional, max norm)")
    print(f"  {'method':<12} {'signorini':>10} {'load P':>10} {'friction':>10} {'load Q':>10} "
          f"{'delta [mm]':>12} {'xi':>12}")
    for m in methods:
        n, t = nsol[m].residuals, tsol[m].residuals
        print(f"  {m:<12} {n.signorini:10.1e} {n.load_normal:10.1e} {t.friction:10.1e} "
              f"{t.load_tangential:10.1e} {nsol[m].delta:12.6e} {tsol[m].xi:12.5e}")

    print("\ndifferences against", methods[0], "(p in p0, t in mu p0, delta in u0, xi in p0/E*)")
    differences = {}
    for m in methods[1:]:
        dn = rollqp.compare(nsol[m], nsol[methods[0]], scales=scales)
        dt = rollqp.compare(tsol[m], tsol[methods[0]], mu=mu, scales=scales)
        differences[m] = {"p": dn["p"], "delta": dn["delta"], "t": dt["t"], "xi": dt["xi"],
                          "state_differs": dt["state_differs"]}
        d = differences[m]
        print(f"  {m:<12} p {d['p']:.1e}  delta {d['delta']:.1e}  t {d['t']:.1e}  xi {d['xi']:.1e}  "
              f"nodes in another state: {d['state_differs'].size}")

    states = {m: rollqp.classify(s.p, s.t, s.s, mu, scales) for m, s in tsol.items()}
    print("\nstick / slip / separation (x / a_H)")
    for m in methods:
        z = zones(x / scales.length, states[m])
        print(f"  {m:<12} " + " | ".join(f"{k} {x0:+.3f}..{x1:+.3f}" for k, x0, x1, _ in z))
    print(f"  Cattaneo: stick |x| < c, c/a = sqrt(1 - Q/(mu P)) = {np.sqrt(1 - ratio):.4f}")
    return {"normal": nsol, "tangential": tsol, "differences": differences, "states": states,
            "x": x, "scales": scales, "problems": (normal, tangential)}


if __name__ == "__main__":
    results = main()
