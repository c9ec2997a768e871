"""Benchmarks of the Newton step methods against the QP backends; prints markdown tables.

Usage::

    python benchmarks/bench_newton.py             # the tables of docs/performance.md (~5 min)
    python benchmarks/bench_newton.py --quick     # one repeat, OSQP only beside Newton (a smoke test)
    python benchmarks/bench_newton.py --repeats 9 --backends qp-osqp,qp-clarabel

A. **Tangential step, 81 nodes.** The rolling steps 0.5 < q/a_H <= 1.5 of the paper's §6.1.1
   (built-in scene ``cattaneo-carter``: similar cylinders, 40 quadratic elements, Δq = Le/2,
   μ = 0.1, Q/(μP) = 0.75). Every step problem is built from the previous state of one
   reference ``rollqp.run(scene, method="newton")`` exactly as the driver builds it (history
   vector ``c = −M w``, ``Model.tangential_step``), and every method solves *the same problem
   from the same warm start* (the reference's previous state, as a ``StepSolution``). Each
   method object solves the first step of the window once untimed, so that its solver objects
   and caches exist (as they do after the first step of a run). Timed: ``method.solve`` only.
B. **Coupled step, 81 nodes.** The same procedure on the dissimilar §6.2.1 problem
   (``goodman-bentall``, or an inline equivalent, see ``coupled_table.py``): β = 0.5, μ = 0.3,
   full coupling, Δq = Le/4; the rolling steps 0 < q/a_H <= 1.5 (every ``--stride``-th), where
   the transient is, solved by ``newton`` (coupled GNMls), ``nt-newton`` (N–T alternation of
   Newton halves) and the N–T alternations of the QP backends (``Alternation(qp)``, as the
   driver makes them).
C. **The whole §6.1.1 transient** ``rollqp.run("cattaneo-carter", method=m)``: stepping time
   Σ ``step_time`` (state 0, the braked start, included), its parts, and the whole call.

Targets checked at the end: A: Newton at least 10× faster than Clarabel per
tangential step at an equal or smaller residual; B: a coupled Newton step within 3 ms;
C: the §6.1.1 stepping time with Newton at most 0.5 s.

Timings are medians: over the steps, then over ``--repeats`` repetitions in which the methods
alternate (a change of the machine's load then hits all of them alike). Ratios are taken
within each repetition, then the median. BLAS is pinned to one thread (threadpoolctl) at
import, before any matrix is built (``harness.py``).
"""
from __future__ import annotations

from harness import goodman_bentall_scene, machine_table, ms, run_once, source_line, table  # (pins BLAS first)

import argparse
import sys
import time

import numpy as np

import rollqp
from rollqp.methods import QP_METHODS, scene_method  # noqa: E402
from rollqp.operators import SceneOperators  # noqa: E402
from rollqp.problem import StepSolution  # noqa: E402

SCENE = "cattaneo-carter"
#: Rolled-distance windows (q/a_H) of the timed steps.
WINDOW_A = (0.5, 1.5)
WINDOW_B = (0.0, 1.5)
#: Targets (docs/performance.md).
TARGET_RATIO_A = 10.0     # Clarabel time / Newton time per tangential step, at least
TARGET_STEP_B = 3e-3      # s, a coupled Newton step, at most
TARGET_RUN_C = 0.5        # s, Σ step_time of the §6.1.1 run with Newton, at most


def make_method(name, scene):
    """The method exactly as ``rollqp.run`` makes it for ``scene``."""
    return scene_method(scene.replace(**{"solver.method": name}).solver, coupled=scene.coupling_level == "full")


# ----------------------------------------------------------------------------------- steps
class Step:
    """One rolling step problem, its warm start and the reference solution (module docstring)."""

    __slots__ = ("k", "problem", "warm", "p_ref", "t_ref")

    def __init__(self, k, problem, warm, p_ref, t_ref):
        self.k, self.problem, self.warm, self.p_ref, self.t_ref = k, problem, warm, p_ref, t_ref


def reference_steps(scene, window, stride=1):
    """Step problems of the window built from a ``newton`` run's states, as the driver builds them."""
    res = rollqp.run(scene, method="newton")
    a = res.arrays()
    model = SceneOperators.build(scene)
    q = scene.q_steps / scene.a_H
    ks = np.flatnonzero((q > window[0] + 1e-12) & (q <= window[1] + 1e-12))[::stride]
    steps = []
    for k in ks:
        p, t = a["pn"][k - 1], a["pt"][k - 1]
        c = -(model.history() @ model.w(p, t))
        P, Q = float(scene.normal_load(scene.q_steps[k])), float(scene.tangential_load(scene.q_steps[k]))
        prob = (model.coupled_step(P, c, scene.dq, Q=Q) if model.coupled
                else model.tangential_step(p, c, scene.dq, Q=Q))
        warm = StepSolution(p=p.copy(), t=t.copy(), delta=float(a["approach"][k - 1]),
                            xi=float(a["creepage"][k - 1]))
        steps.append(Step(int(k), prob, warm, a["pn"][k], a["pt"][k]))
    return steps


def time_steps(name, scene, steps):
    """Solve every step with a fresh method object (after one untimed solve); per-step numbers."""
    meth = make_method(name, scene)
    meth.solve(steps[0].problem, warm=steps[0].warm)  # solver objects and caches, as after step 1 of a run
    mu, p0 = scene.contact.friction, scene.p0
    rows = []
    for st in steps:
        t0, c0 = time.perf_counter(), time.process_time()
        sol = meth.solve(st.problem, warm=st.warm)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        info = sol.info
        dp = float(np.max(np.abs(sol.p - st.p_ref))) / p0 if sol.p is not None and st.problem.kind == "coupled" else 0.0
        rows.append(dict(wall=wall, cpu=cpu, it=sol.iterations, qps=info.get("qp_solves", np.nan),
                         n=sol.inner_normal if sol.outer else np.nan, t=sol.inner_tangential if sol.outer else np.nan,
                         bt=sol.backtracks, residual=sol.residual,
                         dt=float(np.max(np.abs(sol.t - st.t_ref))) / (mu * p0), dp=dp))
    return rows


def measure_steps(scene, steps, methods, repeats):
    """``{method: summary}``: per-step medians, then medians over repeats; ratios to ``newton`` per repeat."""
    per = {m: [] for m in methods}
    for _ in range(repeats):
        for m in methods:
            per[m].append(time_steps(m, scene, steps))
    out = {}
    for m, reps in per.items():
        med_wall = [float(np.median([r["wall"] for r in rows])) for rows in reps]
        med_cpu = [float(np.median([r["cpu"] for r in rows])) for rows in reps]
        first = reps[0]
        out[m] = dict(wall=float(np.median(med_wall)), cpu=float(np.median(med_cpu)),
                      max=float(np.median([max(r["wall"] for r in rows) for rows in reps])),
                      walls=med_wall,
                      it=float(np.mean([r["it"] for r in first])), qps=float(np.mean([r["qps"] for r in first])),
                      n=float(np.mean([r["n"] for r in first])), t=float(np.mean([r["t"] for r in first])),
                      bt=float(np.mean([r["bt"] for r in first])),
                      residual=max(r["residual"] for rows in reps for r in rows),
                      dt=max(r["dt"] for rows in reps for r in rows), dp=max(r["dp"] for rows in reps for r in rows))
    for m in methods:
        out[m]["ratio"] = float(np.median([w / wn for w, wn in zip(out[m]["walls"], out["newton"]["walls"])]))
    return out


def _ratio_to_clarabel(res):
    if res is None or "qp-clarabel" not in res:  # part A not run, or without Clarabel
        return None
    return float(np.median([wc / wn for wc, wn in zip(res["qp-clarabel"]["walls"], res["newton"]["walls"])]))


def section_a(repeats, backends):
    scene = rollqp.load_scene(SCENE)
    steps = reference_steps(scene, WINDOW_A)
    methods = ["newton"] + backends
    res = measure_steps(scene, steps, methods, repeats)
    rows = []
    for m in methods:
        r = res[m]
        newton = m == "newton"
        rows.append((f"`{m}`", ms(r["wall"]), ms(r["cpu"]), ms(r["max"]), f"{r['ratio']:.1f}",
                     f"{r['it']:.1f}", "–" if newton else f"{r['qps']:.1f}", f"{r['residual']:.1e}",
                     f"{r['dt']:.1e}"))
    k0, k1 = steps[0].k, steps[-1].k
    head = (f"### A. Tangential step, 81 nodes: Newton against the QP backends\n\n"
            f"`{SCENE}` (paper §6.1.1), rolling steps k = {k0}…{k1} (q/a_H = {scene.q_steps[k0] / scene.a_H:.3f}…"
            f"{scene.q_steps[k1] / scene.a_H:.3f}), {len(steps)} steps; each method solves the same step "
            f"problems from the same warm start (the previous state of a `newton` run); times of "
            f"`method.solve`, medians over the steps, then over {repeats} repeat(s), in ms. Iterations: Newton "
            f"iterations (`newton`), the solver's own iterations summed over the QPs of the symmetric–skew "
            f"splitting (QP backends). Δt: max over the steps of \\|t − t_ref\\|/(μp0), t_ref the `newton` run's "
            f"state k (for `newton` itself: how exactly the rebuilt step reproduces the run).\n")
    text = table(["method", "solve wall [ms]", "solve CPU [ms]", "slowest step [ms]", "time / `newton`",
                    "iterations per step", "QPs per step", "max residual", "max Δt/(μp0)"], rows)
    return head + "\n" + text + "\n", res


def section_b(repeats, methods, stride):
    scene, label = goodman_bentall_scene()
    steps = reference_steps(scene, WINDOW_B, stride=stride)
    res = measure_steps(scene, steps, methods, repeats)
    rows = []
    for m in methods:
        r = res[m]
        newton = m == "newton"
        alt = not newton
        qp = m in QP_METHODS
        rows.append((f"`{m}`" + (" (alternation)" if qp else ""), ms(r["wall"]), ms(r["cpu"]), ms(r["max"]),
                     f"{r['ratio']:.1f}", f"{r['it']:.2f}" + (" outer" if alt else ""),
                     f"{r['n']:.1f} + {r['t']:.1f}" if alt else "–", f"{r['bt']:.2f}", f"{r['residual']:.1e}",
                     f"{r['dp']:.1e} / {r['dt']:.1e}"))
    k0, k1 = steps[0].k, steps[-1].k
    head = (f"### B. Coupled step, 81 nodes: {label}\n\n"
            f"β = {scene.beta:.4f}, μ = {scene.contact.friction:g}, full coupling, Δq = Le/4: rolling steps "
            f"k = {k0}…{k1} (q/a_H = {scene.q_steps[k0] / scene.a_H:.3f}…{scene.q_steps[k1] / scene.a_H:.3f}), every "
            f"{stride}{'nd' if stride == 2 else 'th' if stride > 2 else 'st'} step, {len(steps)} steps, the same "
            f"problems from the same warm starts for every method (the previous state of a `newton` run); "
            f"times of `method.solve`, medians over the steps, then over {repeats} repeat(s), in ms. Iterations: "
            f"Newton iterations (`newton`), outer N–T iterations (alternations), with the halves' inner "
            f"iterations (Newton for `nt-newton`, interior-point/ADMM for the QP halves). Δp/Δt: max over the "
            f"steps of \\|p − p_ref\\|/p0 and \\|t − t_ref\\|/(μp0), p_ref and t_ref the `newton` run's state k.\n")
    text = table(["method", "step wall [ms]", "step CPU [ms]", "slowest step [ms]", "time / `newton`",
                    "iterations per step", "inner normal + tangential", "backtracks per step", "max residual",
                    "max Δp/p0 / Δt/(μp0)"], rows)
    return head + "\n" + text + "\n", res


def section_c(repeats, qp_repeats, backends):
    methods = ["newton"] + backends
    runs = {m: [] for m in methods}
    for rep in range(max(repeats, qp_repeats)):
        for m in methods:
            if rep < (repeats if m == "newton" else qp_repeats):
                runs[m].append(run_once(rollqp.load_scene(SCENE), m))
    med = {m: {k: float(np.median([r[k] for r in rs])) for k in rs[0]} for m, rs in runs.items()}
    rows = []
    for m in methods:
        r = med[m]
        rows.append((f"`{m}`", f"{r['stepping']:.3f}", f"{r['start']:.3f}", f"{r['rolling']:.3f}", ms(r["median"]),
                     ms(r["max"]), f"{r['stepping'] / med['newton']['stepping']:.1f}", f"{r['wall']:.3f}",
                     f"{r['cpu']:.3f}", f"{r['influence']:.3f}", f"{r['iters']:.0f}", f"{r['residual']:.1e}",
                     f"{r['carter']:.4f}"))
    head = (f"### C. The whole §6.1.1 transient: `rollqp.run(\"{SCENE}\", method=m)`\n\n"
            f"State 0 (the braked start: Hertz, then Cattaneo in {rollqp.load_scene(SCENE).load.start_steps} "
            f"static-shift step(s)) and {med['newton']['K']:.0f} rolling steps of Δq = Le/2 (40 quadratic elements, 81 nodes); "
            f"medians over {repeats} run(s) of `newton` and {qp_repeats} of each QP backend. *Stepping*: "
            f"Σ `step_time` of the result, state 0 included; *call*: the whole `rollqp.run`, with the influence "
            f"matrices and the result's assembly.\n")
    text = table(["method", "stepping Σ`step_time` [s]", "state 0 [s]", "rolling steps [s]", "median step [ms]",
                    "slowest step [ms]", "stepping / `newton`", "call wall [s]", "call CPU [s]",
                    "influence matrices [s]", "iterations", "max residual", "Carter error (rms/μp0)"], rows)
    return head + "\n" + text + "\n", med


def targets(res_a, res_b, med_c):
    rows = []
    ratio = _ratio_to_clarabel(res_a)
    if ratio is not None:
        n, c = res_a["newton"], res_a["qp-clarabel"]
        ok = ratio >= TARGET_RATIO_A and n["residual"] <= c["residual"]
        rows.append(("A: tangential step, Clarabel time / Newton time (same steps, same warm starts)",
                     f"≥ {TARGET_RATIO_A:g} at ≤ residual",
                     f"{ratio:.0f} ({ms(c['wall'])} / {ms(n['wall'])} ms); residual {n['residual']:.1e} "
                     f"(Newton) vs {c['residual']:.1e} (Clarabel)", "met" if ok else "**missed**"))
    if res_b is not None:
        n = res_b["newton"]
        ok = n["wall"] <= TARGET_STEP_B and n["max"] <= TARGET_STEP_B
        rows.append(("B: coupled Newton step, 81 nodes", f"≤ {1e3 * TARGET_STEP_B:g} ms",
                     f"median {ms(n['wall'])} ms, slowest {ms(n['max'])} ms", "met" if ok else "**missed**"))
    if med_c is not None:
        s = med_c["newton"]["stepping"]
        rows.append(("C: §6.1.1 transient with Newton, Σ `step_time`", f"≤ {TARGET_RUN_C:g} s",
                     f"{s:.3f} s (whole call {med_c['newton']['wall']:.3f} s)",
                     "met" if s <= TARGET_RUN_C else "**missed**"))
    return "### Targets\n\n" + table(["target", "required", "measured", ""], rows) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="one repeat, qp-osqp only beside Newton (smoke test)")
    ap.add_argument("--repeats", type=int, default=None, help="repetitions (default 5, or 1 with --quick)")
    ap.add_argument("--qp-repeats", type=int, default=None,
                    help="whole runs of the QP backends in part C (default 3, or 1 with --quick)")
    ap.add_argument("--backends", default=None,
                    help=f"comma-separated QP methods for A and C (default {','.join(QP_METHODS)})")
    ap.add_argument("--coupled", default=None,
                    help="comma-separated methods for B (default newton,nt-newton,qp-clarabel,qp-osqp)")
    ap.add_argument("--stride", type=int, default=2, help="every stride-th step of B's window (default 2)")
    ap.add_argument("--parts", default="A,B,C", help="parts to run (default A,B,C)")
    args = ap.parse_args(argv)
    quick = args.quick
    repeats = args.repeats or (1 if quick else 5)
    qp_repeats = args.qp_repeats or (1 if quick else 3)
    backends = [b.strip() for b in (args.backends or ("qp-osqp" if quick else ",".join(QP_METHODS))).split(",")
                if b.strip()]
    coupled = [m.strip() for m in (args.coupled or ("newton,nt-newton,qp-osqp" if quick else
                                                    "newton,nt-newton,qp-clarabel,qp-osqp")).split(",") if m.strip()]
    if "newton" not in coupled:
        coupled.insert(0, "newton")
    parts = {p.strip().upper() for p in args.parts.split(",")}
    print("## Machine\n")
    print(machine_table())
    print("\nrollqp source: " + source_line() + "\n")
    res_a = res_b = med_c = None
    t_all = time.perf_counter()
    if "A" in parts:
        t0 = time.perf_counter()
        text, res_a = section_a(repeats, backends)
        print(text)
        print(f"<!-- part A measured in {time.perf_counter() - t0:.1f} s -->\n", flush=True)
    if "B" in parts:
        t0 = time.perf_counter()
        text, res_b = section_b(max(1, (repeats + 1) // 2) if not quick else 1, coupled, args.stride)
        print(text)
        print(f"<!-- part B measured in {time.perf_counter() - t0:.1f} s -->\n", flush=True)
    if "C" in parts:
        t0 = time.perf_counter()
        text, med_c = section_c(repeats, qp_repeats, backends)
        print(text)
        print(f"<!-- part C measured in {time.perf_counter() - t0:.1f} s -->\n", flush=True)
    print(targets(res_a, res_b, med_c))
    print(f"<!-- measured in {time.perf_counter() - t_all:.0f} s -->")
    return 0


if __name__ == "__main__":
    sys.exit(main())
