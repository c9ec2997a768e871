"""Why the coupled step is not one QP: the joint QP over (p, t) gives a dilatant friction law.

docs/theory.md §6 argues that the contact step with the friction bound μp depending on the
unknown pressure is a quasi-variational inequality, and that it is *not* the KKT system of the
obvious convex QP over both tractions,

    minimize E(p, t)   subject to   p >= 0,  |t| <= μ p,  fᵀp = P,  fᵀt = Q,

although the set {|t| <= μp} is convex and E (the elastic energy plus the load terms) is a
convex quadratic. The KKT conditions of that QP give, at every node where the shear is at its
bound and slips, an open gap g = μ·Δq·|s| under a positive pressure: the friction law of
plasticity with an associated flow rule (dilatancy), not Coulomb's. This script measures it on
the braked start of the paper's §6.1.1 (Cattaneo's problem: steel rollers, μ = 0.1, P then
Q = 0.75 μP by a static shift with Δ = a_H), on 80 piecewise-constant elements, where F·A is
exactly symmetric so that every QP here is exact:

* the right answer: the normal step, then the tangential step with the bound μp fixed — two
  QPs, here solved by Newton and by Clarabel;
* the joint QP, solved by cvxpy (Clarabel underneath): its Signorini residual, its distance from
  the right answer, and the relation g = μ·Δq·|s| at its slipping nodes;
* the control: with Q = 0 nothing slips and the joint QP gives the right answer.

Run it::

    python examples/one_qp.py
"""
from __future__ import annotations

import cvxpy as cp
import numpy as np

import rollqp
from rollqp.operators import SceneOperators

#: Clarabel's tolerances for the joint QP (cvxpy's defaults are 1e-8: never trust them for a comparison).
TOL = 1e-12


def model(elements=80):
    scene = rollqp.load_scene("cattaneo-carter").replace(**{
        "discretization.element": "constant", "discretization.elements": elements,
        "discretization.distance": 0.0})
    return scene, SceneOperators.build(scene)


def two_qps(m, P, Q, dq, method):
    """The step as rollqp solves it: normal QP, then the tangential QP with the bound μp fixed."""
    ns = rollqp.solve_step(m.normal_step(P), method)
    ts = rollqp.solve_step(m.tangential_step(ns.p, np.zeros(m.f.size), dq, Q=Q), method)
    return ns, ts


def joint_qp(m, mu, P, Q, dq):
    """One QP over (p̂, t̂) on {p̂ >= 0, |t̂| <= μp̂}; returns p̂, t̂, δ̂ and Δq̂·ξ̂ (its multipliers)."""
    sc = m.scales
    u0, fh, dqh = sc.displacement, m.f / sc.length, dq / sc.length
    Ah = m.Ann.dense() * (sc.modulus / sc.length)
    H = fh[:, None] * Ah                      # F̂Â: exactly symmetric for constant elements (tested)
    p, t = cp.Variable(fh.size), cp.Variable(fh.size)
    # E = ½p̂ᵀF̂Âp̂ + (F̂ĥ)ᵀp̂ + ½t̂ᵀF̂Ât̂ (c = 0: unloaded bodies before the shift; β = 0)
    energy = 0.5 * cp.quad_form(p, cp.psd_wrap(H)) + (fh * m.h / u0) @ p + 0.5 * cp.quad_form(t, cp.psd_wrap(H))
    load_p, load_t = fh @ p == P / sc.force, fh @ t == Q / sc.force
    cons = [p >= 0, t <= mu * p, -t <= mu * p, load_p, load_t]
    cp.Problem(cp.Minimize(energy), cons).solve(solver="CLARABEL", tol_gap_abs=TOL, tol_gap_rel=TOL, tol_feas=TOL)
    # cvxpy's Lagrangian adds ν·(fᵀx − load): stationarity F̂(ĥ + Âp̂) + ν_p f̂ = λ, so δ̂ = −ν_p;
    # F̂Ât̂ + ν_t f̂ = λ_ℓ − λ_u with Δq̂·ŝ = Δq̂·ξ̂ + Ât̂, so Δq̂·ξ̂ = ν_t
    return p.value, t.value, -float(load_p.dual_value), float(load_t.dual_value), Ah, dqh


def measure(ratio, elements=80):
    scene, m = model(elements)
    sc, mu, P = m.scales, scene.contact.friction, scene.load.normal
    Q, dq = ratio * mu * P, sc.length
    ns, ts = two_qps(m, P, Q, dq, "newton")
    nc, tc = two_qps(m, P, Q, dq, "qp-clarabel")
    ph, th, dh, dqxi, Ah, dqh = joint_qp(m, mu, P, Q, dq)
    gh = m.h / sc.displacement - dh + Ah @ ph          # ĝ of the joint QP
    sh = dqxi / dqh + (Ah @ th) / dqh                  # ŝ of the joint QP
    contact = ph > 1e-6
    FA = m.f[:, None] * m.Ann.dense()
    slipping = contact & (np.abs(sh) > 1e-6)
    return {
        "ratio": ratio,
        "symmetric": bool(np.array_equal(FA, FA.T)),
        "newton_residual": max(ns.residual, ts.residual),
        "clarabel_vs_newton": max(np.abs(nc.p - ns.p).max() / sc.stress, np.abs(tc.t - ts.t).max() / (mu * sc.stress)),
        "slipping": int(slipping.sum()),
        "contact": int(contact.sum()),
        "dilatancy": float(np.abs(gh[slipping] - mu * dqh * np.abs(sh[slipping])).max()) if slipping.any() else 0.0,
        "max_gap_slip": float(gh[slipping].max()) if slipping.any() else 0.0,
        "joint_signorini": float(np.abs(np.minimum(ph, gh)).max()),
        "joint_dp": float(np.abs(ph * sc.stress - ns.p).max() / sc.stress),
        "joint_dt": float(np.abs(th * sc.stress - ts.t).max() / (mu * sc.stress)),
    }


def main(elements=80):
    rows = [measure(r, elements) for r in (0.75, 0.0)]
    print(f"Cattaneo's braked start, {elements} constant elements (F·A exactly symmetric), mu = 0.1")
    for m in rows:
        print(f"  Q/(mu P) = {m['ratio']:.2f}")
        print(f"    two QPs (normal, then tangential with mu p fixed): residual {m['newton_residual']:.1e} (newton), "
              f"qp-clarabel within {m['clarabel_vs_newton']:.1e} of it")
        print(f"    one joint QP: {m['slipping']} of {m['contact']} contact nodes slip; there "
              f"max |g - mu dq |s||/u0 = {m['dilatancy']:.1e}, gap g/u0 up to {m['max_gap_slip']:.4f}")
        print(f"    one joint QP: Signorini residual max|min(p, g)| = {m['joint_signorini']:.1e}; "
              f"off the right answer by {m['joint_dp']:.1e} p0 (pressure), {m['joint_dt']:.1e} mu p0 (shear)")
    return {"rows": rows}


if __name__ == "__main__":
    results = main()
