"""Benchmarks of rollqp's QP step methods; prints markdown tables (parts D and E are in docs/performance.md).

Usage::

    python benchmarks/bench_qp.py            # parts A–E (a few minutes)
    python benchmarks/bench_qp.py --quick    # one repeat, fewer meshes (a smoke test)

What is measured (all on the built-in scene ``cattaneo-carter``, the paper's §6.1.1: similar
steel cylinders braked at Q/(μP) = 0.75, then rolling 6 a_H; half-space, μ = 0.1):

A. **Per-step cost** of a tangential step in the middle of the transient (rolled distance
   0.5 < q/a_H <= 1.5, where the stick zone is moving) for each QP backend, on 40 quadratic
   elements (81 nodes, the paper's mesh) and on 80 constant elements (80 nodes, exactly
   symmetric F·A: one QP per step). The steps are those of ``rollqp.march`` (the step's wall and
   CPU time cover the loads, the history vector, the problem's construction, the solve and
   ``w``), and each step's :class:`~rollqp.problem.StepSolution` gives rollqp's wall time
   (``time``), the external solver's own time (``solver_time``), the wall time of the backend's
   calls (``info["backend_time"]``: data update, solve, retries), the solver objects built
   (``info["setups"]``) and the number of QPs of the symmetric–skew splitting
   (``info["qp_solves"]``); a "cold" step re-solves the same step with a fresh method object,
   i.e. without the solver set-up that rollqp reuses.
B. **The whole run** ``rollqp.run("cattaneo-carter", method=m)`` for each backend: wall time,
   stepping time (sum of ``Result.step_time``), median step time, max residual, and the error
   against Carter's steady state at the end.
C. **The cost of the splitting**: ``operator="exact"`` (the collocation problem, several QPs)
   against ``operator="symmetrized"`` (one QP with F⁻¹sym(F·A)) on 40 quadratic elements:
   step times and the error of the starting pressure against Hertz.
D. **The splitting by mesh** (quadratic, linear, constant elements): the asymmetry of A and
   of F·A, the bound ρ = ‖H^{-1/2} S H^{-1/2}‖₂ (F·A = H + S, symmetric + skew), the
   contraction per QP observed in the normal step, and the Hertz error of the exact and of
   the symmetrized operator.
E. **The equality multipliers** read as δ (normal QP) and ξ (tangential QP): the gap they
   give vanishes on the contact nodes and the slip on the stick nodes.

Timings are medians: over the steps of the window, then over ``--repeats`` repetitions, in
which the backends alternate (a change of the machine's load then hits all of them alike).
Ratios compare numbers of the same run only. BLAS is pinned to one thread (threadpoolctl)
at import, before any heavy work.
"""
from __future__ import annotations

from harness import interleaved, machine_table, medians, ms, run_once, step_records, table  # (pins BLAS first)

import argparse
import sys
import time

import numpy as np

import rollqp
from rollqp import closedforms as cf
from rollqp.methods import QP_METHODS, get_method
from rollqp.operators import SceneOperators

SCENE = "cattaneo-carter"
#: Window of the transient whose tangential steps are timed: 0.5 < q/a_H <= 1.5.
WINDOW = (0.5, 1.5)
#: Every this many steps of the window, the step is also solved "cold" (fresh method).
COLD_EVERY = 4


def new_method(name, scene, **kw):
    """The method as ``rollqp.run`` creates it (scene tolerance), plus ``kw``."""
    return get_method(name, tolerance=scene.solver.tolerance, **kw)


def window_steps(scene):
    q = scene.q_steps / scene.a_H
    ks = np.flatnonzero((q > WINDOW[0] + 1e-12) & (q <= WINDOW[1] + 1e-12))
    return int(ks[0]), int(ks[-1])


def step_costs(scene, name, operator="exact", cold=True):
    """Median per-step numbers of the tangential steps in the window, one march (module docstring)."""
    k0, k1 = window_steps(scene)
    meth = new_method(name, scene, operator=operator)
    recs = step_records(scene, meth, stop=k1)
    start = recs[0][0]
    rows, keep = [], []
    residual = 0.0
    setups = start.state.nsol.info.get("setups", 0) + start.solution.info.get("setups", 0)
    qps = retried = 0
    for rec, wall, cpu in recs[1:]:
        sol = rec.solution
        setups += sol.info["setups"]
        qps += sol.info["qp_solves"]
        retried += sol.info["retried"]
        if rec.k >= k0:
            rows.append((wall, cpu, sol.time, sol.info["backend_time"], sol.solver_time, sol.info["qp_solves"],
                         sol.iterations))
            residual = max(residual, sol.residual)
            if cold and (rec.k - k0) % COLD_EVERY == 0:
                keep.append((rec.problem, rec.previous.tsol))
    colds = []
    for prob, warm in keep:  # the same step, without the solver set-up rollqp reuses
        fresh = new_method(name, scene, operator=operator)
        t0 = time.perf_counter()
        fresh.solve(prob, warm=warm)
        colds.append(time.perf_counter() - t0)
    med = np.median(np.array(rows), axis=0)
    return dict(step=med[0], cpu=med[1], time=med[2], backend=med[3], solver=med[4], qps=med[5], iters=med[6],
                cold=float(np.median(colds)) if colds else float("nan"), residual=residual,
                builds=setups, steps=(k0, k1), normal=start.state.nsol.time, all_qps=qps, retried=retried)


def interleaved_medians(repeats, cases, measure):
    """``{case: medians of measure(case)}`` over ``repeats`` repetitions, the cases alternating
    (``harness.interleaved``); the residual is the largest, not the median."""
    runs = interleaved(repeats, {c: c for c in cases}, measure)
    out = {}
    for c, rs in runs.items():
        out[c] = medians(rs)
        out[c]["residual"] = max(r["residual"] for r in rs)
    return out


# ----------------------------------------------------------------------------------- sections
def clarabel_setup_in_solve_time(scene, samples=21):
    """Median of Clarabel's ``solve_time`` minus the wall time of ``solver.solve()`` (seconds).

    Clarabel reports as ``solve_time`` its timers' total, which includes the one-time set-up of
    the solver object (``DefaultInfo::finalize``, "includes setup"), so on every re-solve of a
    reused object it exceeds the solve's own wall time by that set-up time.
    """
    import clarabel
    import scipy.sparse as sp
    from rollqp.methods.qp_clarabel import clarabel_rows, clarabel_settings
    model = SceneOperators.build(scene)
    form = model.normal_step(float(scene.normal_load(0.0))).qp_form()
    A, b, cones = clarabel_rows(form)
    settings = clarabel.DefaultSettings()
    for k, v in clarabel_settings(scene.solver.tolerance).items():
        setattr(settings, k, v)
    solver = clarabel.DefaultSolver(sp.triu(sp.csc_matrix(form.H), format="csc"), form.q, A, b,
                                    [getattr(clarabel, c)(m) for c, m in cones if m or c == "NonnegativeConeT"],
                                    settings)
    diffs = []
    for _ in range(samples):
        t0 = time.perf_counter()
        sol = solver.solve()
        diffs.append(sol.solve_time - (time.perf_counter() - t0))
    return float(np.median(diffs))


def section_step_costs(repeats, backends):
    base = rollqp.load_scene(SCENE)
    variants = [("40 quadratic elements (81 nodes)", base),
                ("80 constant elements (80 nodes)",
                 base.replace(**{"discretization.element": "constant", "discretization.elements": 80}))]
    out = []
    for label, scene in variants:
        costs = interleaved_medians(repeats, backends, lambda b: step_costs(scene, b))
        rows, notes = [], []
        for name in backends:
            c = costs[name]
            own = c["time"] - c["backend"]
            rows.append((f"`{name}`", ms(c["step"]), ms(c["cpu"]), ms(c["time"]), ms(c["backend"]),
                         ms(c["solver"]), f"{c['time'] / c['solver']:.2f}", f"{100 * own / c['time']:.0f} %",
                         f"{c['qps']:.0f}", f"{c['iters']:.0f}", ms(c["cold"]), f"{c['cold'] / c['time']:.1f}"))
            notes.append(f"`{name}`: {c['builds']:.0f} solver set-ups in the whole march, "
                         f"{c['retried']:.0f} of its {c['all_qps']:.0f} QPs solved again after a failed polish, "
                         f"max residual {c['residual']:.1e}")
        k0, k1 = c["steps"]
        q0, q1 = scene.q_steps[k0] / scene.a_H, scene.q_steps[k1] / scene.a_H
        out.append(f"### A. Per-step cost: {label}\n\n"
                   f"Tangential rolling steps k = {k0}…{k1} (q/a_H = {q0:.3f}…{q1:.3f}) of `{SCENE}`; "
                   f"medians over the steps, then over {repeats} repeat(s). Times in ms.\n")
        out.append(table(["backend", "step wall", "step CPU", "rollqp `time`", "backend calls", "`solver_time`",
                           "`time`/`solver_time`", "share of `time` outside the backend calls",
                           "QPs per step (`qp_solves`)", "solver iterations per step", "cold step (fresh method)",
                           "cold / warm"], rows))
        out.append("\n" + "; ".join(notes) + ".\n")
        if "qp-clarabel" in backends:
            off = clarabel_setup_in_solve_time(scene)
            out.append(f"Clarabel's `solve_time` exceeds the wall time of its own `solve()` call by "
                       f"{ms(off)} ms per QP on this problem (median of 21 re-solves of one solver object): "
                       f"it includes the object's one-time set-up, which rollqp reuses.\n")
    return "\n".join(out)


def section_runs(repeats, backends):
    runs = interleaved_medians(repeats, backends, lambda name: run_once(rollqp.load_scene(SCENE), name))
    rows = []
    for name in backends:
        r = runs[name]
        rows.append((f"`{name}`", f"{r['wall']:.2f}", f"{r['cpu']:.2f}", f"{r['stepping']:.2f}", ms(r["median"]),
                     f"{r['iters']:.0f}", f"{r['residual']:.1e}", f"{r['carter']:.4f}"))
    # QPs of the splitting along the transient (one march; OSQP when available, it is the fastest)
    scene = rollqp.load_scene(SCENE)
    probe_backend = "qp-osqp" if "qp-osqp" in backends else backends[0]
    qps = np.array([(rec.q / scene.a_H, rec.solution.info["qp_solves"])
                    for rec, _, _ in step_records(scene, new_method(probe_backend, scene))[1:]])
    bands = [(0.0, 0.5), (0.5, 1.5), (1.5, 3.0), (3.0, scene.q_steps[-1] / scene.a_H)]
    along = ", ".join(f"{np.median(qps[(qps[:, 0] > lo) & (qps[:, 0] <= hi), 1]):.0f} for {lo:g} < q/a_H ≤ {hi:g}"
                      for lo, hi in bands)
    note = (f"\nQPs of the splitting per tangential step along the transient (`{probe_backend}`, medians): "
            f"{along}.\n")
    head = (f"### B. The whole §6.1.1 run: `rollqp.run(\"{SCENE}\", method=m)`\n\n"
            f"{r['K']:.0f} rolling steps of Δq = Le/2 after the braked start (40 quadratic elements, 81 nodes); "
            f"medians over {repeats} run(s).\n")
    return head + "\n" + table(["backend", "wall [s]", "CPU [s]", "stepping Σ`step_time` [s]", "median step [ms]",
                                  "solver iterations", "max residual", "Carter error (rms/μp0)"], rows) + "\n" + note


def section_splitting(repeats, backends):
    scene = rollqp.load_scene(SCENE)
    x, a, p0 = None, scene.a_H, scene.p0
    pairs = [(b, op) for b in backends for op in ("exact", "symmetrized")]
    costs = interleaved_medians(repeats, pairs, lambda bo: step_costs(scene, bo[0], operator=bo[1], cold=False))
    rows = []
    for name in backends:
        for op in ("exact", "symmetrized"):
            sym = op == "symmetrized"
            c = costs[(name, op)]
            model = SceneOperators.build(scene, symmetrized=sym)
            sol = new_method(name, scene, operator=op).solve(model.normal_step(float(scene.normal_load(0.0))))
            x = model.strip.x
            err = (sol.p - cf.hertz_pressure(x, a, p0)) / p0
            inside = np.abs(x) <= a
            rows.append((f"`{name}`", f"`{op}`", ms(c["normal"]), f"{sol.info['qp_solves']}", ms(c["time"]),
                         f"{c['qps']:.0f}", f"{np.max(np.abs(err)):.4f}",
                         f"{np.sqrt(np.mean(err[inside] ** 2)):.4f}", f"{err[x.size // 2]:+.4f}",
                         f"{err[x.size // 2 + 1]:+.4f}"))
    head = (f"### C. The cost of the splitting (40 quadratic elements, `{SCENE}`)\n\n"
            f"`exact`: the collocation problem by symmetric–skew splitting; `symmetrized`: one QP with "
            f"F⁻¹sym(F·A) (the driver then uses that operator for the whole transient). Normal step: the "
            f"one normal solve of the run (fresh method, set-up included); tangential step: median over "
            f"the window of part A; medians over {repeats} repeat(s). Errors: starting pressure against "
            f"Hertz, divided by p0 (node {x.size // 2} is x = 0, an element end; node {x.size // 2 + 1} "
            f"the next mid-node).\n")
    return head + "\n" + table(["backend", "operator", "normal step [ms]", "normal QPs", "tangential step [ms]",
                                  "QPs per tangential step", "max |p − p_Hertz|/p0",
                                  "rms in contact", "error at x = 0", "error at next node"], rows) + "\n"


def _observed_contraction(changes):
    """Geometric mean of successive ratios of max|x_k − x_{k−1}| (``info["splitting_changes"]``;
    the first change, from the start, left out), above the solvers' noise."""
    d = list(changes[1:])
    ratios = [d[i + 1] / d[i] for i in range(len(d) - 1) if d[i + 1] > 1e-9]
    return float(np.exp(np.mean(np.log(ratios)))) if ratios else float("nan"), (max(ratios) if ratios else float("nan"))


def _hertz_max_error(scene, model, sol):
    x = model.strip.x
    return float(np.max(np.abs(sol.p - cf.hertz_pressure(x, scene.a_H, scene.p0)))) / scene.p0


def section_contraction(meshes):
    base = rollqp.load_scene(SCENE)
    rows, note = [], ""
    for element in ("quadratic", "linear", "constant"):
        for ne in meshes:
            scene = base.replace(**{"discretization.element": element, "discretization.elements": ne})
            model = SceneOperators.build(scene)
            A, f = model.Ann.dense(), model.f
            FA = f[:, None] * A
            H, S = 0.5 * (FA + FA.T), 0.5 * (FA - FA.T)
            lam, V = np.linalg.eigh(H)
            Hm = (V / np.sqrt(lam)) @ V.T
            rho = float(np.linalg.norm(Hm @ S @ Hm, 2))
            nS = np.linalg.norm(S)
            inner = float(np.linalg.norm(S[1:-1, 1:-1]) / nS) if nS > 0 else 0.0
            P = float(scene.normal_load(0.0))
            sol = new_method("qp-osqp", scene).solve(model.normal_step(P))
            gm, worst = _observed_contraction(sol.info["splitting_changes"])
            sym_model = SceneOperators.build(scene, symmetrized=True)
            sym = new_method("qp-osqp", scene, operator="symmetrized").solve(sym_model.normal_step(P))
            rows.append((element, ne, model.strip.n, f"{np.linalg.norm(A - A.T) / np.linalg.norm(A):.3f}",
                         f"{np.linalg.norm(FA - FA.T) / np.linalg.norm(FA):.2e}", f"{inner:.2f}", f"{rho:.4f}",
                         "–" if np.isnan(gm) else f"{gm:.3f} ({worst:.3f})", sol.info["qp_solves"],
                         f"{_hertz_max_error(scene, model, sol):.4f}",
                         f"{_hertz_max_error(scene, sym_model, sym):.4f}"))
            if element == "quadratic" and ne == 40:
                dp = (sym.p - sol.p) / scene.p0
                rq = float(dp @ H @ dp / (dp @ dp))
                mid = model.strip.n // 2
                note = (f"40 quadratic elements: p_symmetrized − p_exact is load-neutral "
                        f"(fᵀΔp/(a_H p0) = {f @ dp / scene.a_H:.1e}) and alternates between element ends "
                        f"({dp[mid]:+.4f} p0 at x = 0) and mid-nodes ({dp[mid + 1]:+.4f} p0 next to it); its "
                        f"Rayleigh quotient ΔpᵀHΔp/ΔpᵀΔp is {rq / lam[-1]:.2e} λ_max of H "
                        f"(λ_min = {lam[0] / lam[-1]:.2e}, median {np.median(lam) / lam[-1]:.2e} λ_max).")
    head = ("### D. The splitting by mesh (zone ±1.25 a_H, d_ref = R)\n\n"
            "F·A = H + S (symmetric + skew) for A = A_nn; ρ = ‖H^{-1/2} S H^{-1/2}‖₂ bounds the error "
            "reduction per QP in the H-norm. \"skew off the end nodes\": ‖S‖ of the block without the first "
            "and last rows and columns, over ‖S‖. Observed: ratios of successive changes "
            "max|p_k − p_{k−1}| in the normal step of `qp-osqp` (tolerance 1e-10, from p = 0), geometric "
            "mean (largest), counting changes above 1e-9 p0 only. Hertz: max|p − p_Hertz|/p0 of the "
            "starting pressure, `exact` and `symmetrized` operator.\n")
    return head + "\n" + table(["element", "elements", "nodes", "‖A−Aᵀ‖/‖A‖", "‖FA−(FA)ᵀ‖/‖FA‖",
                                  "skew off the end nodes", "ρ", "observed per QP", "normal-step QPs",
                                  "Hertz error, exact", "Hertz error, symmetrized"], rows) + "\n\n" + note + "\n"


def section_multipliers(backends):
    """The equality multipliers as δ and ξ: the gap closes and the slip vanishes where they should."""
    scene = rollqp.load_scene(SCENE)
    model = SceneOperators.build(scene)
    sc = model.scales
    k_probe = window_steps(scene)[1]
    rows = []
    for name in backends:
        rec = step_records(scene, new_method(name, scene), stop=k_probe, keep=lambda k: k == k_probe)[-1][0]
        nsol, prob, sol = rec.state.nsol, rec.problem, rec.solution
        contact = nsol.p > 1e-8 * sc.stress
        bound = prob.bound
        stick = (nsol.p > 1e-8 * sc.stress) & (bound - np.abs(sol.t) > 1e-6 * sc.stress)
        rows.append((f"`{name}`", f"{nsol.delta / sc.displacement:.6f}",
                     f"{np.max(np.abs(nsol.g[contact])) / sc.displacement:.1e}", f"{int(contact.sum())}",
                     f"{sol.xi / sc.slip:+.6f}", f"{np.max(np.abs(sol.s[stick])) / sc.slip:.1e}",
                     f"{int(stick.sum())}"))
    q = scene.q_steps[k_probe] / scene.a_H
    head = (f"### E. The equality multipliers (δ̂ = −y normal, ξ̂ = y tangential)\n\n"
            f"`{SCENE}`, the normal step and rolling step k = {k_probe} (q = {q:.3f} a_H). δ and ξ are "
            f"read from the solvers' equality multipliers (`QPForm.unscaled_multiplier`); the gap g "
            f"(in u0 = a_H p0/E\\*) must vanish on the contact nodes (p > 1e-8 p0) and the slip s "
            f"(in p0/E\\*) on the stick nodes (μp − |t| > 1e-6 p0).\n")
    return head + "\n" + table(["backend", "δ/u0", "max |g|/u0 in contact", "contact nodes", "ξ/(p0/E*)",
                                  "max |s|/(p0/E*) in stick", "stick nodes"], rows) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="one repeat and fewer meshes (smoke test)")
    ap.add_argument("--repeats", type=int, default=None, help="repetitions (default 5, or 1 with --quick)")
    ap.add_argument("--backends", default=",".join(QP_METHODS),
                    help=f"comma-separated QP methods (default {','.join(QP_METHODS)})")
    args = ap.parse_args(argv)
    repeats = args.repeats or (1 if args.quick else 5)
    backends = [b.strip() for b in args.backends.split(",") if b.strip()]
    meshes = (10, 40) if args.quick else (10, 20, 40, 80, 160)
    print("## Machine\n")
    print(machine_table())
    print()
    for section in (lambda: section_step_costs(repeats, backends),
                    lambda: section_runs(max(1, (repeats + 1) // 2), backends),
                    lambda: section_splitting(repeats, backends),
                    lambda: section_contraction(meshes),
                    lambda: section_multipliers(backends)):
        t0 = time.perf_counter()
        text = section()
        print(text)
        print(f"<!-- section measured in {time.perf_counter() - t0:.1f} s -->\n", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
