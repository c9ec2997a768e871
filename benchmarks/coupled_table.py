"""The paper's §6.3 table: coupled Newton against N–T alternation on Goodman → Bentall.

Usage::

    python benchmarks/coupled_table.py                 # the tables of docs/performance.md (~15 min)
    python benchmarks/coupled_table.py --quick         # one run each, no qp-clarabel (a smoke test)
    python benchmarks/coupled_table.py --repeats 5 --qp-repeats 1 --methods newton,nt-newton,qp-osqp

The problem is the paper's §6.2.1 coupled case (Fig. 7) as the built-in scene
``goodman-bentall`` (2β = 1, μ = 0.3, full coupling, 40 quadratic elements, Δq = Le/4,
material formulation, braked start with 40 normal-load steps at Q = 0, then free rolling
6 a_H). If that scene file is absent (older checkouts) an equivalent inline scene is used:
``cattaneo-carter`` with a compliant ν = 0 body A on a nearly rigid B (β ≈ 0.5).

Every step of the transient is solved by

* ``newton``: the coupled GNMls on all rows of Φ (paper §4, eq. 63–64);
* ``nt-newton``: the N–T alternation (paper §6.3, the PANA process) with GNMls halves;
* ``qp-clarabel``, ``qp-osqp``: the N–T alternation with convex-QP halves (what the driver
  does with a QP method on a fully coupled scene),

through ``rollqp.run(scene, method=m)``, and the result file's per-step counters are
averaged over the rolling steps k = 1…K: ``iterations`` (Newton iterations for ``newton``,
outer N–T iterations for the alternations), ``inner_normal``/``inner_tangential`` (the
halves' own iterations: Newton iterations for ``nt-newton``, interior-point or ADMM
iterations for the QP alternations), ``backtracks`` (Armijo reductions), ``step_time``.
The braked start (state 0: 40 normal-load increments) is reported separately.

Then, to explain the differences from the paper's numbers, variants are run through the
march (``rollqp.march``, with method objects the registry does not
name): the N–T stopping limit, the halves started cold instead of from the previous outer
iteration, and the augmentation r of the coupled Newton method.

Timings: medians over repeated runs in which the methods alternate (a change of the machine's
load then hits all of them alike); ratios compare runs of the same invocation. BLAS is pinned
to one thread (threadpoolctl) at import (``harness.py``, whose machine table is used).
"""
from __future__ import annotations

from harness import goodman_bentall_scene, interleaved, machine_table, ms, source_line, table  # (pins BLAS first)

import argparse
import sys
import time

import numpy as np

import rollqp
from rollqp.march.strip import new_result  # noqa: E402
from rollqp.operators import SceneOperators  # noqa: E402
from rollqp.errors import SolverError  # noqa: E402
from rollqp.methods.alternation import Alternation  # noqa: E402
from rollqp.methods.newton import NewtonMethod  # noqa: E402

SCENE = "goodman-bentall"
METHODS = ("newton", "nt-newton", "qp-clarabel", "qp-osqp")
#: Bands of the rolled distance q/a_H for the iteration counts along the transient (the paper:
#: the transient is gone after 1.8 contact widths, 3.6 a_H).
BANDS = ((0.0, 0.5), (0.5, 1.0), (1.0, 2.0), (2.0, 3.6), (3.6, None))


def scene_line(scene) -> str:
    d = scene.discretization
    return (f"β = {scene.beta:.4f} (2β = {2 * scene.beta:.3f}), μ = {scene.contact.friction:g}, coupling "
            f"`{scene.coupling_level}`, {d.elements} {d.element} elements on ±{d.zone:g} a_H "
            f"({2 * d.elements + 1 if d.element == 'quadratic' else d.elements} nodes), Δq = {d.step:g} Le "
            f"= {scene.dq / scene.a_H:.4f} a_H, {d.formulation} formulation, braked start with "
            f"{scene.load.start_steps} normal-load steps, {scene.n_steps} rolling steps to {d.distance:g} a_H, "
            f"tolerance {scene.solver.tolerance:g}")


# ----------------------------------------------------------------------------------- runs
def _summary(arr, scene, wall, cpu, calls=None):
    k = slice(1, None)
    st = arr["step_time"]
    out = dict(arr=arr, wall=wall, cpu=cpu, failed=None,
               it=float(arr["iterations"][k].mean()), n=float(arr["inner_normal"][k].mean()),
               t=float(arr["inner_tangential"][k].mean()), bt=float(arr["backtracks"][k].mean()),
               mean=float(st[k].mean()), median=float(np.median(st[k])), max=float(st[k].max()),
               total=float(st[k].sum()), start=float(st[0]), it0=int(arr["iterations"][0]),
               n0=int(arr["inner_normal"][0]), t0=int(arr["inner_tangential"][0]), bt0=int(arr["backtracks"][0]),
               residual=float(arr["residual"].max()))
    if calls is not None:
        out.update(calls)
    return out


def run_public(scene, name):
    """``rollqp.run(scene, method=name)``: the per-step counters and times of the result."""
    t0, c0 = time.perf_counter(), time.process_time()
    try:
        res = rollqp.run(scene, method=name)
    except SolverError as err:
        return dict(failed=str(err), wall=time.perf_counter() - t0, cpu=time.process_time() - c0)
    return _summary(res.arrays(), scene, time.perf_counter() - t0, time.process_time() - c0)


class _Recorder:
    """Wraps a method's ``solve`` (on the instance) to keep each coupled solution's residual history."""

    def __init__(self, method):
        self.histories = []
        solve = method.solve

        def recorded(problem, warm=None):
            sol = solve(problem, warm=warm)
            if problem.kind == "coupled" and "history" in sol.info:
                self.histories.append(list(sol.info["history"]))
            return sol

        method.solve = recorded

    def contraction(self, floor=1e-12):
        """Median ratio of successive coupled residuals of the outer iterations (above ``floor``)."""
        ratios = [h[i + 1] / h[i] for h in self.histories for i in range(len(h) - 1) if h[i + 1] > floor]
        return float(np.median(ratios)) if ratios else float("nan")


def run_variant(scene, model, method, label):
    """``rollqp.march`` with a method object the registry does not name."""
    rec = _Recorder(method)
    res = new_result(scene, model, label)
    t0, c0 = time.perf_counter(), time.process_time()
    try:
        for r in rollqp.march(scene, method=method):
            res.add(r)
    except SolverError as err:
        return dict(failed=f"step {len(res)}: {err}", wall=time.perf_counter() - t0, cpu=time.process_time() - c0)
    return _summary(res.arrays(), scene, time.perf_counter() - t0, time.process_time() - c0,
                    calls=dict(contraction=rec.contraction()))


def interleaved_jobs(jobs, repeats):
    """``{key: [runs]}``: each job ``key -> callable`` run ``repeats[key]`` times, the jobs alternating."""
    return interleaved(repeats, jobs, lambda job: job(),
                       log=lambda key, i, n: print(f"<!-- {key}: run {i}/{n} done -->", file=sys.stderr, flush=True))


def combine(runs):
    """Counts from the first successful run (they are deterministic), times as medians over the runs."""
    ok = [r for r in runs if r.get("failed") is None]
    if not ok:
        return dict(failed=runs[0]["failed"], runs=len(runs), ok=0)
    out = dict(ok[0])
    for key in ("wall", "cpu", "mean", "median", "max", "total", "start"):
        out[key] = float(np.median([r[key] for r in ok]))
    out["runs"], out["ok"] = len(runs), len(ok)
    out["failures"] = [r["failed"] for r in runs if r.get("failed") is not None]
    out["spread"] = (min(r["total"] for r in ok), max(r["total"] for r in ok))
    return out


def _diff(run, ref, scene):
    """max |p − p_ref|/p0 and max |t − t_ref|/(μ p0) over all states."""
    mu, p0 = scene.contact.friction, scene.p0
    a, b = run["arr"], ref["arr"]
    return (float(np.max(np.abs(a["pn"] - b["pn"]))) / p0, float(np.max(np.abs(a["pt"] - b["pt"]))) / (mu * p0))


# ----------------------------------------------------------------------------------- tables
def _f(v, fmt="{:.2f}"):
    return "–" if v is None or (isinstance(v, float) and np.isnan(v)) else fmt.format(v)


def maintable(scene, res, methods):
    ref = res.get("newton")
    rows = [("paper, coupled GNMls", "≈ 6", "–", "–", "–", "–", "–", "–", "–", "1", "–", "–", "–"),
            ("paper, N–T with GNMls halves", "≈ 90 (derived: 6 × (3 + 12))", "≈ 6", "≈ 18 (≈ 3)", "≈ 72 (≈ 12)",
             "–", "–", "–", "–", "≈ 3", "“exactly the same results”", "", "")]
    notes = []
    for name in methods:
        r = res[name]
        label = f"`{name}`" + (" (alternation, QP halves)" if name.startswith("qp-") else "")
        if r.get("ok", 0) == 0:
            rows.append((label, "failed", *["–"] * 11))
            notes.append(f"`{name}` failed: {r['failed']}")
            continue
        coupled = name == "newton"
        alt = not coupled
        newton_its = r["it"] if coupled else (r["n"] + r["t"] if name == "nt-newton" else None)
        inner = (lambda v: f"{v:.2f} ({v / r['it']:.2f})") if alt else (lambda v: "–")
        ratio = r["total"] / ref["total"] if ref and ref.get("ok") else float("nan")
        dp, dt = _diff(r, ref, scene) if ref and ref.get("ok") and not coupled else (0.0, 0.0)
        rows.append((label, _f(newton_its), _f(r["it"]) if alt else "–", inner(r["n"]), inner(r["t"]), _f(r["bt"]),
                     ms(r["mean"]), ms(r["median"]), f"{r['total']:.3f}", _f(ratio, "{:.1f}"),
                     "0 (reference)" if coupled else f"{dp:.1e}", "0 (reference)" if coupled else f"{dt:.1e}",
                     f"{r['residual']:.1e}"))
        if r.get("failures"):
            notes.append(f"`{name}`: {len(r['failures'])} of {r['runs']} runs failed: " + "; ".join(r["failures"]))
        notes.append(f"`{name}`: {r['ok']} run(s), stepping total from {r['spread'][0]:.3f} to {r['spread'][1]:.3f} s, "
                     f"whole run {r['wall']:.2f} s wall / {r['cpu']:.2f} s CPU (median)")
    notes.insert(0, "paper (§6.3): “an average of 6 N–T iterations to obtain the solution for one time step. Inside "
                    "one of these iterations, the GNMls algorithm employs 3 and 12 iterations to solve the Normal and "
                    "Tangential parts, respectively, compared with the 6 GNMls iterations needed by the Coupled "
                    "scheme”; its per-step inner counts here are 6 × those")
    head = ["method", "Newton iterations per step", "outer N–T iterations per step",
            "inner normal per step (per outer)", "inner tangential per step (per outer)", "backtracks per step",
            "time per step, mean [ms]", "median [ms]", "stepping total Σ`step_time` [s]", "time / coupled Newton",
            "max |p − p_newton|/p0", "max |t − t_newton|/(μp0)", "max residual"]
    return table(head, rows) + "\n\n" + "".join(f"- {n}.\n" for n in notes)


def starttable(scene, res, methods):
    N = scene.load.start_steps
    ref = res.get("newton")
    rows = []
    for name in methods:
        r = res[name]
        if r.get("ok", 0) == 0:
            continue
        coupled = name == "newton"
        rows.append((f"`{name}`", _f(r["it0"] / N) if coupled else "–", "–" if coupled else _f(r["it0"] / N),
                     "–" if coupled else _f(r["n0"] / N), "–" if coupled else _f(r["t0"] / N), _f(r["bt0"] / N),
                     ms(r["start"] / N), f"{r['start']:.3f}",
                     _f(r["start"] / ref["start"], "{:.1f}") if ref and ref.get("ok") else "–"))
    head = ["method", "Newton iterations per load step", "outer iterations per load step", "inner normal per load step",
            "inner tangential per load step", "backtracks per load step", "time per load step [ms]",
            "start total [s]", "time / coupled Newton"]
    return table(head, rows)


def bandstable(scene, res, methods):
    rows = []
    for name in methods:
        r = res[name]
        if r.get("ok", 0) == 0:
            continue
        a = r["arr"]
        q = a["q"] / scene.a_H
        cells = []
        for lo, hi in BANDS:
            sel = (q > lo) & (q <= (hi if hi is not None else np.inf))
            it = a["iterations"][sel].mean()
            if name == "newton":
                cells.append(f"{it:.2f}")
            else:
                cells.append(f"{it:.2f} ({a['inner_normal'][sel].mean():.1f} + {a['inner_tangential'][sel].mean():.1f})")
        rows.append((f"`{name}`", *cells))
    head = ["method"] + [f"{lo:g} < q/a_H ≤ {hi:g}" if hi is not None else f"q/a_H > {lo:g}" for lo, hi in BANDS]
    return table(head, rows)


def variants(scene, repeats):
    """Explanatory variants (module docstring); ``{label: combined run}`` in table order."""
    model = SceneOperators.build(scene)
    tol, its = scene.solver.tolerance, scene.solver.max_iterations

    class ColdHalves:
        """Benchmark-only wrapper: the inner method ignores the warm start of each half."""

        def __init__(self, inner):
            self.inner, self.tolerance, self.name = inner, inner.tolerance, "cold halves"
            self.capabilities = inner.capabilities

        def setup(self, operators):
            self.inner.setup(operators)

        def carrier(self):
            return self.inner.carrier()

        def solve(self, problem, warm=None):
            return self.inner.solve(problem, warm=None)

    def nt(tolerance=tol, r=None, cold=False):
        inner = NewtonMethod(tolerance=tolerance, max_iterations=its, r=r)
        return Alternation(ColdHalves(inner) if cold else inner, max_outer=its, limit=tolerance)

    makers = {"coupled Newton, default r": lambda: NewtonMethod(tolerance=tol, max_iterations=its)}
    for r in (0.01, 0.1, 1.0, 10.0):
        makers[f"coupled Newton, r = {r:g}"] = (lambda r=r: NewtonMethod(tolerance=tol, max_iterations=its, r=r))
    for tl in (1e-6, 1e-12):
        makers[f"coupled Newton, tolerance {tl:.0e}"] = (lambda tl=tl: NewtonMethod(tolerance=tl, max_iterations=its))
    makers[f"N–T, tolerance {tol:.0e} (default)"] = lambda: nt()
    for tl in (1e-6, 1e-8, 1e-12):
        makers[f"N–T, tolerance {tl:.0e}"] = (lambda tl=tl: nt(tolerance=tl))
    makers["N–T, halves started cold"] = lambda: nt(cold=True)
    for r in (0.01, 1.0):
        makers[f"N–T, r = {r:g} in the halves"] = (lambda r=r: nt(r=r))
    jobs = {k: (lambda mk=mk, k=k: run_variant(scene, model, mk(), k)) for k, mk in makers.items()}
    raw = interleaved_jobs(jobs, {k: repeats for k in jobs})
    return {k: combine(v) for k, v in raw.items()}, model


def variantstable(scene, var, ref, model):
    rows = []
    base = var["coupled Newton, default r"]
    for label, r in var.items():
        if r.get("ok", 0) == 0:
            rows.append((label, "failed: " + r["failed"].split(": ", 2)[-1], *["–"] * 8))
            continue
        coupled = label.startswith("coupled")
        dp, dt = _diff(r, ref, scene)
        rows.append((label, _f(r["it"]) if coupled else _f(r["it"]) + " outer",
                     "–" if coupled else f"{r['n'] / r['it']:.2f} + {r['t'] / r['it']:.2f}",
                     _f(r["bt"]), _f(r["contraction"], "{:.3f}") if not coupled else "–",
                     ms(r["mean"]), _f(r["total"] / base["total"], "{:.1f}") if base.get("ok") else "–",
                     _f(r["it0"] / scene.load.start_steps) + ("" if coupled else " outer"),
                     f"{dp:.1e} / {dt:.1e}", f"{r['residual']:.1e}"))
    head = ["variant", "iterations per rolling step", "inner normal + tangential per outer iteration",
            "backtracks per step", "residual ratio per outer iteration (median)", "time per step [ms]",
            "time / coupled Newton (default r)", "iterations per start load step",
            "max |Δp|/p0 / max |Δt|/(μp0) vs `newton`", "max residual"]
    return table(head, rows)


def accounting(scene, model, repeats):
    """Where the rolling steps' time goes, coupled Newton against N–T with Newton halves.

    One march each (``rollqp.march``) with the method's ``solve``
    (and, for N–T, the inner Newton method's ``solve``) wrapped on the instance to sum their wall
    time over the rolling steps; medians over ``repeats`` marches.
    """
    tol, its = scene.solver.tolerance, scene.solver.max_iterations

    def one(kind):
        inner = NewtonMethod(tolerance=tol, max_iterations=its)
        meth = inner if kind == "coupled" else Alternation(inner, max_outer=its)
        res = new_result(scene, model, kind)
        acc = dict(solve=0.0, halves=0.0, half_calls=0, half_its=0, its=0)
        outer_solve, inner_solve = meth.solve, inner.solve

        def timed_outer(problem, warm=None):
            t0 = time.perf_counter()
            sol = outer_solve(problem, warm=warm)
            if len(res) >= 1:  # rolling steps only (state 0 is recorded before them)
                acc["solve"] += time.perf_counter() - t0
                acc["its"] += sol.iterations
            return sol

        def timed_inner(problem, warm=None):
            t0 = time.perf_counter()
            sol = inner_solve(problem, warm=warm)
            if len(res) >= 1:
                acc["halves"] += time.perf_counter() - t0
                acc["half_calls"] += 1
                acc["half_its"] += sol.iterations
            return sol

        if kind == "coupled":
            meth.solve = timed_outer
        else:
            inner.solve = timed_inner
            meth.solve = timed_outer
        for r in rollqp.march(scene, method=meth):
            res.add(r)
        acc["step"] = float(res.arrays()["step_time"][1:].sum())
        return acc

    runs = {"coupled": [], "nt": []}
    for _ in range(repeats):
        for kind in runs:
            runs[kind].append(one(kind))
    med = {k: {key: float(np.median([r[key] for r in v])) for key in v[0]} for k, v in runs.items()}
    K = scene.n_steps
    rows = []
    for kind, label in (("coupled", "`newton` (coupled GNMls)"), ("nt", "`nt-newton` (N–T, Newton halves)")):
        m = med[kind]
        halves = m["halves"] if kind == "nt" else float("nan")
        per = "Newton iteration" if kind == "coupled" else "outer iteration"
        rows.append((label, ms(m["step"] / K), ms(m["solve"] / K),
                     "–" if kind == "coupled" else ms(halves / K),
                     "–" if kind == "coupled" else ms((m["solve"] - halves) / K),
                     ms((m["step"] - m["solve"]) / K), f"{m['its'] / K:.2f}",
                     f"{1e6 * m['solve'] / m['its']:.0f} µs per {per}",
                     "–" if kind == "coupled" else
                     f"{1e6 * halves / m['half_calls']:.0f} µs per half, "
                     f"{m['half_its'] / m['half_calls']:.2f} Newton iterations per half"))
    head = ["method", "step [ms]", "solve [ms]", "in the halves' Newton solves [ms]",
            "rest of the alternation [ms]", "driver outside the solve [ms]", "iterations per step",
            "solve time per iteration", "halves"]
    note = ("Means per rolling step over the march, medians over "
            f"{repeats} march(es). *Rest of the alternation*: `normal_half`/`tangential_half` (A_nt t, A_tn p, "
            "the half problems' construction and validation) and the coupled residual of each outer iterate "
            "(`CoupledStep.solution`). *Driver*: history vector, problem construction, w, the result record.\n\n")
    return note + table(head, rows)


def microtable(model, number=200, repeat=7):
    """LAPACK solves of the coupled and the half systems, and ``Residuals.max``; medians, µs."""
    import timeit

    from scipy.linalg.lapack import dgesv

    from rollqp.problem import Residuals

    rng = np.random.default_rng(0)
    n = model.strip.n
    N = 2 * n + 2
    Jc = np.asfortranarray(rng.random((N, N)) + N * np.eye(N))
    Jh = np.asfortranarray(rng.random((n + 1, n + 1)) + n * np.eye(n + 1))
    bc, bh = rng.random(N), rng.random(n + 1)
    res = Residuals(1e-11, 2e-11, 3e-12, 4e-12)

    def us(fn):
        return 1e6 * float(np.median(timeit.repeat(fn, number=number, repeat=repeat))) / number

    rows = [(f"LAPACK `dgesv` (copy + LU + solve), {N}×{N}: one coupled Newton iteration",
             f"{us(lambda: dgesv(Jc.copy(order='F'), bc)):.0f}"),
            (f"LAPACK `dgesv` (copy + LU + solve), {n + 1}×{n + 1}: one Newton iteration of a half",
             f"{us(lambda: dgesv(Jh.copy(order='F'), bh)):.0f}"),
            ("`Residuals.max` (every `StepSolution.residual`; `dataclasses.astuple`)", f"{us(lambda: res.max):.1f}")]
    return f"Medians of {repeat} × {number} calls.\n\n" + table(["piece", "µs"], rows)


def default_r(scene, model):
    """The coupled Newton method's default (r_N, r_T) for this scene (``info['r']`` of one step)."""
    P, Q = float(scene.normal_load(0.0)), float(scene.tangential_load(0.0))
    sol = NewtonMethod(tolerance=scene.solver.tolerance).solve(
        model.coupled_step(P, np.zeros(model.strip.n), scene.dq, Q=Q))
    return sol.info["r"]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="one run each, without qp-clarabel (smoke test)")
    ap.add_argument("--repeats", type=int, default=None, help="runs of the Newton methods (default 5)")
    ap.add_argument("--qp-repeats", type=int, default=None, help="runs of the QP alternations (default 3)")
    ap.add_argument("--variant-repeats", type=int, default=None, help="runs of each variant (default 3)")
    ap.add_argument("--methods", default=None, help=f"comma-separated (default {','.join(METHODS)})")
    args = ap.parse_args(argv)
    quick = args.quick
    reps = args.repeats or (1 if quick else 5)
    qreps = args.qp_repeats or (1 if quick else 3)
    vreps = args.variant_repeats or (1 if quick else 3)
    methods = [m.strip() for m in (args.methods or ("newton,nt-newton,qp-osqp" if quick else ",".join(METHODS)))
               .split(",") if m.strip()]
    if "newton" not in methods:
        methods.insert(0, "newton")  # the reference of the ratios and differences
    scene, label = goodman_bentall_scene()

    print("## Machine\n")
    print(machine_table())
    print("\nrollqp source: " + source_line() + "\n")
    t_all = time.perf_counter()
    jobs = {m: (lambda m=m: run_public(scene, m)) for m in methods}
    res = {m: combine(v) for m, v in interleaved_jobs(jobs, {m: (qreps if m.startswith("qp-") else reps)
                                                        for m in methods}).items()}
    model = SceneOperators.build(scene)
    rN, rT = default_r(scene, model)
    print(f"### Goodman → Bentall: {label}\n")
    print(scene_line(scene) + f"; `rollqp.run(scene, method=m)`; means over the {scene.n_steps} rolling steps "
          f"(state 0, the braked start, in the next table); times are medians over {reps} run(s) of the Newton "
          f"methods and {qreps} of the QP alternations. Inner iterations: Newton iterations for `nt-newton`, "
          f"interior-point (Clarabel) or ADMM (OSQP) iterations for the QP alternations. The default "
          f"augmentation of the coupled Newton method here is r_N = {rN:.3g}, r_T = {rT:.3g} (nondimensional).\n")
    print(maintable(scene, res, methods))
    print(f"#### The braked start: {scene.load.start_steps} normal-load steps at Q = 0 (state 0)\n")
    print(starttable(scene, res, methods))
    print("\n#### Iterations per step along the rolled distance\n")
    print("`newton`: Newton iterations; alternations: outer iterations (inner normal + inner tangential).\n")
    print(bandstable(scene, res, methods))
    print()
    var, model = variants(scene, vreps)
    print(f"#### What the counts depend on (variants through the driver's march; medians over {vreps} run(s))\n")
    print("Coupled Newton with a fixed augmentation r (both rows; default: the scene-derived r_N, r_T above); "
          "N–T alternation (Newton halves) with another tolerance (the halves' and the limit on the coupled "
          "residual), with each half "
          "started cold (pressure from a Hertz-like profile, traction from zero) instead of from the previous "
          "outer iteration, or with a fixed r in the halves. Residual ratio: median of successive coupled "
          "residuals over the outer iterations (above 1e-12).\n")
    print(variantstable(scene, var, res["newton"], model))
    print("\n#### Where the time of a step goes\n")
    print(accounting(scene, model, vreps))
    print()
    print(microtable(model))
    print(f"\n<!-- measured in {time.perf_counter() - t_all:.0f} s -->")
    return 0


if __name__ == "__main__":
    sys.exit(main())
