"""Benchmarks of rollqp's QP step methods; prints markdown tables (parts D and E are in docs/performance.md).

Usage::

    python benchmarks/bench_qp.py            # parts A–E (a few minutes)
    python benchmarks/bench_qp.py --quick    # one repeat, fewer meshes (a smoke test)

What is measured (all on the built-in scene ``cattaneo-carter``, the paper's §6.1.1: similar
steel cylinders braked at Q/(μP) = 0.75, then rolling 6 a_H; half-space, μ = 0.1):

A. **Per-step cost** of a tangential step in the middle of the transient (rolled distance
   0.5 < q/a_H <= 1.5, where the stick zone is moving) for each QP backend, on 40 quadratic
   elements (81 nodes, the paper's mesh) and on 80 constant elements (80 nodes, exactly
   symmetric F·A: one QP per step). The step is marched here with the public
   :class:`rollqp.SceneOperators` (braked start, then rolling steps, as ``rollqp.run`` does),
   and each step's :class:`~rollqp.problem.StepSolution` gives rollqp's wall time
   (``time``), the external solver's own time (``solver_time``) and the number of QPs of the
   symmetric–skew splitting (``info["qp_solves"]``). The backend's native calls are timed
   separately by wrapping the method instance's ``_solve_form`` (benchmark-only
   instrumentation: nothing in the library is changed), and a "cold" step re-solves the same
   step with a fresh method object, i.e. without the solver set-up that rollqp reuses.
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

import numpy as np  # noqa: E402
import rollqp  # noqa: E402
from rollqp.bench import pin_threads  # noqa: E402

#: BLAS/OpenMP pools limited to one thread for the whole benchmark (kept alive here).
_THREAD_LIMIT = pin_threads()

import argparse  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

from rollqp import bench as _bench  # noqa: E402
from rollqp import closedforms as cf  # noqa: E402
from rollqp.operators import SceneOperators  # noqa: E402
from rollqp.methods import QP_METHODS, get_method  # noqa: E402
from rollqp.report import closed_form_errors  # noqa: E402

SCENE = "cattaneo-carter"
#: Window of the transient whose tangential steps are timed: 0.5 < q/a_H <= 1.5.
WINDOW = (0.5, 1.5)
#: Every this many steps of the window, the step is also solved "cold" (fresh method).
COLD_EVERY = 4


# ----------------------------------------------------------------------------------- machine
def machine_table() -> str:
    """The machine, packages, thread pools, load and command (``rollqp.bench.machine_table``)."""
    return _bench.machine_table()


_table = _bench.table


def _ms(seconds) -> str:
    return f"{1e3 * seconds:.2f}"


class Probe:
    """Times a method's native backend calls, counts its solver set-ups and polish retries.

    Wraps ``_solve_form`` and ``_build`` on the *instance* (the class is untouched):
    ``QPMethod.solve`` calls ``self._solve_form`` once per QP, and the backend builds its
    solver object through ``self._build`` only when no cached one fits.
    """

    def __init__(self, method):
        self.backend = 0.0
        self.builds = 0
        self.qps = 0
        self.retried = 0  # QPs the backend solved more than once (OSQP polish retries)
        self.iterates = []
        solve_form, build = method._solve_form, method._build

        def timed_solve_form(form, x0, source=None):
            t0 = time.perf_counter()
            out = solve_form(form, x0, source)
            self.backend += time.perf_counter() - t0
            self.iterates.append(np.array(out[0], dtype=float))
            self.qps += 1
            self.retried += int(out[5].get("tries", 1) > 1)
            return out

        def counted_build(form):
            self.builds += 1
            return build(form)

        method._solve_form = timed_solve_form
        method._build = counted_build


def new_method(name, scene, **kw):
    """The method as ``rollqp.run`` creates it (scene tolerance), plus ``kw``."""
    return get_method(name, tolerance=scene.solver.tolerance, **kw)


def march(scene, model, method, k_stop, on_step=None):
    """Braked start and rolling steps 1..k_stop, as ``rollqp.run`` does.

    Restricted to what the benchmark needs: β = 0 (or coupling off) and constant loads, so
    the normal step is solved once and each rolling step is one tangential step problem.
    ``on_step(k, problem, warm, solution, (wall, cpu))`` is called after rolling step ``k``; the
    wall-clock and process CPU times cover the history vector, the problem's construction, the
    solve and ``w``.

    Returns the normal solution and the wall time of the normal solve.
    """
    if model.Ant is not None or model.Atn is not None:
        raise ValueError("the benchmark march handles uncoupled scenes only")
    qs = scene.q_steps
    P = float(scene.normal_load(0.0))
    Q = float(scene.tangential_load(0.0))
    if np.ptp(scene.normal_load(qs)) != 0 or np.ptp(scene.tangential_load(qs)) != 0:
        raise ValueError("the benchmark march handles constant loads only")
    t0 = time.perf_counter()
    nsol = method.solve(model.normal_step(P))
    t_normal = time.perf_counter() - t0
    p = nsol.p
    w = np.zeros(model.strip.n)
    tsol = None
    N = scene.load.start_steps
    for j in range(1, N + 1):  # static shift, Δ = a_H (§4.4)
        tsol = method.solve(model.tangential_step(p, -w, model.scales.length, Q=Q * j / N), warm=tsol)
        w = model.w(p, tsol.t)
    for k in range(1, k_stop + 1):
        t0, c0 = time.perf_counter(), time.process_time()
        c = -(model.history() @ w)
        prob = model.tangential_step(p, c, scene.dq, Q=Q)
        warm = tsol
        tsol = method.solve(prob, warm=warm)
        w = model.w(p, tsol.t)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        if on_step is not None:
            on_step(k, prob, warm, tsol, (wall, cpu))
    return nsol, t_normal


def window_steps(scene):
    q = scene.q_steps / scene.a_H
    ks = np.flatnonzero((q > WINDOW[0] + 1e-12) & (q <= WINDOW[1] + 1e-12))
    return int(ks[0]), int(ks[-1])


def step_costs(scene, name, symmetric=False, operator="exact", cold=True):
    """Median per-step numbers of the tangential steps in the window, one march (module docstring)."""
    k0, k1 = window_steps(scene)
    model = SceneOperators.build(scene, symmetrized=symmetric)
    meth = new_method(name, scene, operator=operator)
    probe = Probe(meth)
    rows, keep = [], []
    residual = 0.0

    def on_step(k, prob, warm, sol, times):
        nonlocal residual
        if k >= k0:
            rows.append((times[0], times[1], sol.time, probe.backend, sol.solver_time, sol.info["qp_solves"],
                         sol.iterations))
            residual = max(residual, sol.residual)
            if cold and (k - k0) % COLD_EVERY == 0:
                keep.append((prob, warm))
        probe.backend = 0.0

    _, t_normal = march(scene, model, meth, k1, on_step)
    colds = []
    for prob, warm in keep:  # the same step, without the solver set-up rollqp reuses
        fresh = new_method(name, scene, operator=operator)
        t0 = time.perf_counter()
        fresh.solve(prob, warm=warm)
        colds.append(time.perf_counter() - t0)
    med = np.median(np.array(rows), axis=0)
    return dict(step=med[0], cpu=med[1], time=med[2], backend=med[3], solver=med[4], qps=med[5], iters=med[6],
                cold=float(np.median(colds)) if colds else float("nan"), residual=residual,
                builds=probe.builds, steps=(k0, k1), normal=t_normal, all_qps=probe.qps, retried=probe.retried)


def interleaved(repeats, backends, measure):
    """``{backend: {key: median over repeats}}``; the backends alternate within each repeat, so
    that a change in the machine's load hits all of them alike."""
    runs = {b: [] for b in backends}
    for _ in range(repeats):
        for b in backends:
            runs[b].append(measure(b))
    out = {}
    for b, rs in runs.items():
        out[b] = {}
        for key, v in rs[0].items():
            if isinstance(v, (int, float, np.floating, np.integer)) and not isinstance(v, bool):
                vals = [r[key] for r in rs if not np.isnan(r[key])]
                out[b][key] = float(np.median(vals)) if vals else float("nan")
            else:
                out[b][key] = v
        out[b]["residual"] = max(r["residual"] for r in rs)
    return out


# ----------------------------------------------------------------------------------- sections
def clarabel_setup_in_solve_time(scene, samples=21):
    """Median of Clarabel's ``solve_time`` minus the wall time of ``solver.solve()`` (seconds).

    Clarabel reports as ``solve_time`` its timers' total, which includes the one-time set-up of
    the solver object (``DefaultInfo::finalize``, "includes setup"), so on every re-solve of a
    reused object it exceeds the solve's own wall time by that set-up time.
    """
    model = SceneOperators.build(scene)
    form = model.normal_step(float(scene.normal_load(0.0))).qp_form()
    solver = new_method("qp-clarabel", scene)._build(form)
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
        costs = interleaved(repeats, backends, lambda b: step_costs(scene, b))
        rows, notes = [], []
        for name in backends:
            c = costs[name]
            own = c["time"] - c["backend"]
            rows.append((f"`{name}`", _ms(c["step"]), _ms(c["cpu"]), _ms(c["time"]), _ms(c["backend"]),
                         _ms(c["solver"]), f"{c['time'] / c['solver']:.2f}", f"{100 * own / c['time']:.0f} %",
                         f"{c['qps']:.0f}", f"{c['iters']:.0f}", _ms(c["cold"]), f"{c['cold'] / c['time']:.1f}"))
            notes.append(f"`{name}`: {c['builds']:.0f} solver set-ups in the whole march, "
                         f"{c['retried']:.0f} of its {c['all_qps']:.0f} QPs solved again after a failed polish, "
                         f"max residual {c['residual']:.1e}")
        k0, k1 = c["steps"]
        q0, q1 = scene.q_steps[k0] / scene.a_H, scene.q_steps[k1] / scene.a_H
        out.append(f"### A. Per-step cost: {label}\n\n"
                   f"Tangential rolling steps k = {k0}…{k1} (q/a_H = {q0:.3f}…{q1:.3f}) of `{SCENE}`; "
                   f"medians over the steps, then over {repeats} repeat(s). Times in ms.\n")
        out.append(_table(["backend", "step wall", "step CPU", "rollqp `time`", "backend calls", "`solver_time`",
                           "`time`/`solver_time`", "share of `time` outside the backend calls",
                           "QPs per step (`qp_solves`)", "solver iterations per step", "cold step (fresh method)",
                           "cold / warm"], rows))
        out.append("\n" + "; ".join(notes) + ".\n")
        if "qp-clarabel" in backends:
            off = clarabel_setup_in_solve_time(scene)
            out.append(f"Clarabel's `solve_time` exceeds the wall time of its own `solve()` call by "
                       f"{_ms(off)} ms per QP on this problem (median of 21 re-solves of one solver object): "
                       f"it includes the object's one-time set-up, which rollqp reuses.\n")
    return "\n".join(out)


def _run_once(name):
    """One ``rollqp.run`` of the scene: wall and CPU time, stepping time and its parts, iterations,
    largest residual, Carter's error (also used by bench_newton.py)."""
    scene = rollqp.load_scene(SCENE)
    t0, c0 = time.perf_counter(), time.process_time()
    res = rollqp.run(scene, method=name)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    arr = res.arrays()
    errs = {n: v for n, v, _ in closed_form_errors(arr, scene)}
    st = arr["step_time"]
    return dict(wall=wall, cpu=cpu, influence=float(res.meta["model"].get("influence_seconds", np.nan)),
                stepping=float(st.sum()), start=float(st[0]), rolling=float(st[1:].sum()),
                median=float(np.median(st[1:])), max=float(st[1:].max()), residual=float(arr["residual"].max()),
                iters=int(arr["iterations"].sum()), carter=errs.get("carter", float("nan")), K=len(st) - 1)


def section_runs(repeats, backends):
    runs = interleaved(repeats, backends, _run_once)
    rows = []
    for name in backends:
        r = runs[name]
        rows.append((f"`{name}`", f"{r['wall']:.2f}", f"{r['cpu']:.2f}", f"{r['stepping']:.2f}", _ms(r["median"]),
                     f"{r['iters']:.0f}", f"{r['residual']:.1e}", f"{r['carter']:.4f}"))
    # QPs of the splitting along the transient (one march; OSQP when available, it is the fastest)
    scene = rollqp.load_scene(SCENE)
    probe_backend = "qp-osqp" if "qp-osqp" in backends else backends[0]
    qps = []
    march(scene, SceneOperators.build(scene), new_method(probe_backend, scene), scene.n_steps,
          lambda k, prob, warm, sol, times: qps.append((scene.q_steps[k] / scene.a_H, sol.info["qp_solves"])))
    qps = np.array(qps)
    bands = [(0.0, 0.5), (0.5, 1.5), (1.5, 3.0), (3.0, scene.q_steps[-1] / scene.a_H)]
    along = ", ".join(f"{np.median(qps[(qps[:, 0] > lo) & (qps[:, 0] <= hi), 1]):.0f} for {lo:g} < q/a_H ≤ {hi:g}"
                      for lo, hi in bands)
    note = (f"\nQPs of the splitting per tangential step along the transient (`{probe_backend}`, medians): "
            f"{along}.\n")
    head = (f"### B. The whole §6.1.1 run: `rollqp.run(\"{SCENE}\", method=m)`\n\n"
            f"{r['K']:.0f} rolling steps of Δq = Le/2 after the braked start (40 quadratic elements, 81 nodes); "
            f"medians over {repeats} run(s).\n")
    return head + "\n" + _table(["backend", "wall [s]", "CPU [s]", "stepping Σ`step_time` [s]", "median step [ms]",
                                  "solver iterations", "max residual", "Carter error (rms/μp0)"], rows) + "\n" + note


def section_splitting(repeats, backends):
    scene = rollqp.load_scene(SCENE)
    x, a, p0 = None, scene.a_H, scene.p0
    pairs = [(b, op) for b in backends for op in ("exact", "symmetrized")]
    costs = interleaved(repeats, pairs, lambda bo: step_costs(scene, bo[0], symmetric=bo[1] == "symmetrized",
                                                              operator=bo[1], cold=False))
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
            rows.append((f"`{name}`", f"`{op}`", _ms(c["normal"]), f"{sol.info['qp_solves']}", _ms(c["time"]),
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
    return head + "\n" + _table(["backend", "operator", "normal step [ms]", "normal QPs", "tangential step [ms]",
                                  "QPs per tangential step", "max |p − p_Hertz|/p0",
                                  "rms in contact", "error at x = 0", "error at next node"], rows) + "\n"


def _observed_contraction(iterates):
    """Geometric mean of successive ratios of max|x_k − x_{k−1}|, above the solvers' noise."""
    d = [float(np.max(np.abs(iterates[i + 1] - iterates[i]))) for i in range(len(iterates) - 1)]
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
            A, f = model.Ann, model.f
            FA = f[:, None] * A
            H, S = 0.5 * (FA + FA.T), 0.5 * (FA - FA.T)
            lam, V = np.linalg.eigh(H)
            Hm = (V / np.sqrt(lam)) @ V.T
            rho = float(np.linalg.norm(Hm @ S @ Hm, 2))
            nS = np.linalg.norm(S)
            inner = float(np.linalg.norm(S[1:-1, 1:-1]) / nS) if nS > 0 else 0.0
            P = float(scene.normal_load(0.0))
            meth = new_method("qp-osqp", scene)
            probe = Probe(meth)
            sol = meth.solve(model.normal_step(P))
            gm, worst = _observed_contraction(probe.iterates)
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
    return head + "\n" + _table(["element", "elements", "nodes", "‖A−Aᵀ‖/‖A‖", "‖FA−(FA)ᵀ‖/‖FA‖",
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
        meth = new_method(name, scene)
        got = {}
        nsol, _ = march(scene, model, meth, k_probe,
                        lambda k, prob, warm, sol, times: got.update(prob=prob, sol=sol) if k == k_probe else None)
        contact = nsol.p > 1e-8 * sc.stress
        prob, sol = got["prob"], got["sol"]
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
    return head + "\n" + _table(["backend", "δ/u0", "max |g|/u0 in contact", "contact nodes", "ξ/(p0/E*)",
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
