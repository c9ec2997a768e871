"""The benchmark suite: work–precision diagrams and scaling (``rollqp bench``, or ``python benchmarks/suite.py``).

Usage::

    rollqp bench --quick          # a smoke test: prints the tables (time: docs/performance.md)
    rollqp bench                  # the full study (about 16 minutes on 2 idle cores)
    rollqp bench --docs           # the full study, written into docs/performance.md
                                  # (between its <!-- bench:... --> markers) and
                                  # docs/figures/perf-*.png
    rollqp bench --parts scaling --methods newton,qp-osqp

Parts
-----
``tolerance``
    Work–precision over the solver tolerance (1e-4 … 1e-12) at a fixed discretization, for
    §6.1.1 (built-in ``cattaneo-carter``) and a dissimilar coupled scene (``goodman-bentall``
    shortened, :func:`coupled_scene`). Error: the largest distance over all states from the
    same discretization solved to round-off (``newton`` at tolerance 1e-14), i.e. the solver's
    own error, in p0 and μp0.
``discretization``
    Work–precision over the mesh (10 … 320 elements), the step (Δq = Le/2, Le/8), the three
    element types and both slip formulations, at the default tolerance 1e-10. Errors against
    closed forms (Cattaneo at q = 0, Carter at the end; :mod:`rollqp.closedforms`) and, for
    the intermediate state q = 1 a_H, against a fine reference run (``newton``, 640 quadratic
    elements, Δq = Le/4), interpolated to the coarse nodes.
``scaling``
    Rolling-step time against the number of nodes (41 … 2561) per method, with the fitted
    exponent, beside ``scipy.linalg.cho_factor`` of an SPD matrix of the same size (the dense
    floor). A method is not run at sizes where its previous size predicts a step above the
    budget (``--step-budget``); the table says so.

Timing: *stepping time* is Σ ``step_time`` of the result (the braked start included, the
influence matrices not), *step time* the median ``step_time`` over the rolling steps. BLAS
and OpenMP pools are pinned to one thread (threadpoolctl) for the whole study; medians are
taken over ``--repeats`` runs (fewer when a run is long, see :func:`timed_run`). Every run is
wrapped: a method that fails a case is recorded with its error, not a crash. Machine, package
versions, load average and the rollqp commit are printed first.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from harness import (Run, fit_exponent, cholesky_time, machine_table, table, fmt_err, timed_run, diff_to,  # noqa: F401
                     write_sections)
from rollqp.methods import METHOD_NAMES
from rollqp.scene import load_scene

#: Tolerances of the work–precision sweep.
TOLERANCES = (1e-4, 1e-6, 1e-8, 1e-10, 1e-12)
#: Meshes of the discretization sweep (elements) and of the scaling study.
MESHES = (10, 20, 40, 80, 160, 320)
SCALING_ELEMENTS = (20, 40, 80, 160, 320, 640, 1280)
#: Rolling steps timed per run of the scaling study (after the first, which is not timed).
SCALING_STEPS = 12
#: Intermediate state compared with the fine reference (q/a_H).
Q_MID = 1.0
#: Targets (docs/performance.md, "Targets").
TARGET_CHOL_RATIO = 3.0     # Newton step / cho_factor, n >= 321, at most
TARGET_CLARABEL_RATIO = 10.0  # Clarabel step / Newton step, n <= 321, at least
TARGET_EXPONENT = 3.0       # Newton step cost exponent up to n = 2561, at most
TARGET_RUN = 0.5            # s, §6.1.1 stepping time with Newton (40 QCE), at most

FIGURES = Path("docs") / "figures"
DOC = Path("docs") / "performance.md"



def mid_error(run: Run, ref: Run, mu: float, q_mid: float = Q_MID, key: str = "pt") -> float | None:
    """rms over ``|x| <= a_H`` of ``|t − t_ref|/(μp0)`` (``key="pn"``: ``|p − p_ref|/p0``) at q = q_mid a_H;
    the fine reference interpolated linearly to the run's nodes."""
    if not (run.ok and ref.ok):
        return None
    a, ra = run.arrays, ref.arrays
    aH, p0 = float(a["a_H"]), float(a["p0"])
    k = int(np.argmin(np.abs(a["q"] / aH - q_mid)))
    kr = int(np.argmin(np.abs(ra["q"] / aH - q_mid)))
    if abs(a["q"][k] / aH - q_mid) > 1e-9 or abs(ra["q"][kr] / aH - q_mid) > 1e-9:
        return None
    x = a["x"]
    m = np.abs(x) <= aH
    tr = np.interp(x[m], ra["x"], ra[key][kr])
    unit = p0 if key == "pn" else max(mu, 1e-300) * p0
    return float(np.sqrt(np.mean((a[key][k][m] - tr) ** 2))) / unit


# ------------------------------------------------------------------------------- scenes
def cattaneo_carter(**changes):
    return load_scene("cattaneo-carter").replace(**changes)


def coupled_scene(quick=False, **changes):
    """``goodman-bentall`` shortened: 20 quadratic elements, Δq = Le/2, 1 a_H of rolling,
    10 normal-load steps in the braked start (the QP alternations take ~0.1 s per step); with
    ``quick`` (a smoke test) 10 elements, 0.5 a_H and 4 start steps."""
    base = {"discretization.elements": 20, "discretization.step": 0.5, "discretization.distance": 1.0,
            "load.start_steps": 10}
    if quick:
        base.update({"discretization.elements": 10, "discretization.distance": 0.5, "load.start_steps": 4})
    base.update(changes)
    return load_scene("goodman-bentall").replace(**base)


# ------------------------------------------------------------------------------- part: tolerance
def part_tolerance(methods, tolerances, repeats, quick, log):
    """Work–precision over the tolerance: {scene label: {method: [Run per tolerance]}}."""
    out = {}
    scenes = [("§6.1.1 `cattaneo-carter` (40 QCE, 81 nodes, Δq = Le/2, 6 a_H)", cattaneo_carter(), 0.1),
              ("coupled `goodman-bentall`, shortened (20 QCE, 41 nodes, Δq = Le/2, 1 a_H, 10 start steps)",
               coupled_scene(quick), 0.3)]
    if quick:
        scenes[0] = ("§6.1.1 `cattaneo-carter` (20 QCE, 41 nodes, Δq = Le/2, 2 a_H)",
                     cattaneo_carter(**{"discretization.elements": 20, "discretization.distance": 2.0}), 0.1)
        scenes[1] = ("coupled `goodman-bentall`, shortened (10 QCE, 21 nodes, Δq = Le/2, 0.5 a_H, 4 start steps)",
                     scenes[1][1], 0.3)
    for label, scene, mu in scenes:
        ref = timed_run(scene.replace(**{"solver.tolerance": 1e-14}), "newton", "reference", repeats=1)
        if not ref.ok:  # round-off floor of this problem above 1e-14: the next best
            ref = timed_run(scene.replace(**{"solver.tolerance": 1e-13}), "newton", "reference", repeats=1)
        per = {}
        for m in methods:
            rows = []
            for tol in tolerances:
                r = timed_run(scene.replace(**{"solver.tolerance": tol}), m, f"{tol:g}", repeats=repeats,
                              budget=2.0 if not quick else 0.5)
                r.errors["solver"] = diff_to(r, ref, mu)
                r.arrays = None
                rows.append(r)
                log(f"  tolerance {label[:24]} {m} {tol:g}: "
                    + (f"{r.stepping:.3f} s, error {fmt_err(r.errors['solver'])}" if r.ok else r.failed))
            per[m] = rows
        out[label] = dict(runs=per, reference=ref, scene=scene)
    return out


def tolerance_tables(res, tolerances) -> str:
    parts = []
    for label, d in res.items():
        per = d["runs"]
        head = ["method"] + [f"tol {t:g}" for t in tolerances]
        rows = []
        for m, runs in per.items():
            cells = [f"`{m}`"]
            for r in runs:
                cells.append(f"{r.stepping:.3f} s / {fmt_err(r.errors.get('solver'))} / {r.residual:.0e}" if r.ok
                             else f"failed ({r.failed[:60]})")
            rows.append(cells)
        ref = d["reference"]
        parts.append(f"**{label}** — stepping time Σ`step_time` / largest distance from the reference over all "
                     f"states (max of \\|Δp\\|/p0 and \\|Δt\\|/(μp0)) / max rollqp residual. Reference: `newton` at "
                     f"tolerance 1e-14 on the same discretization (max residual {ref.residual:.0e}).\n\n"
                     + table(head, rows))
    return "\n\n".join(parts)


# ------------------------------------------------------------------------------- part: discretization
@dataclass
class Family:
    element: str = "quadratic"
    formulation: str = "material"
    step: float = 0.5

    @property
    def label(self):
        return f"{self.element}, {self.formulation}, Δq = Le/{round(1 / self.step)}"

    def scene(self, elements, **kw):
        return cattaneo_carter(**{"discretization.elements": elements, "discretization.element": self.element,
                                  "discretization.formulation": self.formulation,
                                  "discretization.step": self.step, **kw})


def _nodes(element, elements):
    return 2 * elements + 1 if element == "quadratic" else elements + (element == "linear")


def mesh_sweep(methods, meshes, make_scene, nodes, errors, repeats, run_budget, tag, log):
    """``{method: [Run per mesh]}``: ``make_scene(E)`` by each method, coarse to fine.

    A mesh is skipped when the previous one's stepping time × (steps ratio) × (n ratio)^1.5
    predicts more than ``run_budget`` seconds, or when a coarser mesh failed or was skipped;
    ``errors(run)`` adds the run's errors against a reference.
    """
    per = {}
    for m in methods:
        rows = []
        prev = prev_E = None
        for E in meshes:
            n = nodes(E)
            if prev is not None and not prev.ok:
                rows.append(Run(method=m, label=str(E), n=n, skipped="a coarser mesh failed or was skipped"))
                continue
            if prev is not None:
                pred = prev.stepping * (E / prev_E) * (n / prev.n) ** 1.5
                if pred > run_budget:
                    rows.append(Run(method=m, label=str(E), n=n,
                                    skipped=f"predicted {pred:.0f} s > {run_budget:g} s budget"))
                    prev = rows[-1]
                    continue
            r = timed_run(make_scene(E), m, str(E), repeats=repeats, budget=1.0)
            r.errors.update(errors(r))
            r.arrays = None
            rows.append(r)
            prev, prev_E = r, E
            log(f"  {tag} {m} {E}: " + (f"{r.stepping:.3f} s, " + ", ".join(
                f"{k} {fmt_err(v)}" for k, v in r.errors.items()) if r.ok else r.failed))
        per[m] = rows
    return per


def part_discretization(methods, families, meshes, repeats, run_budget, quick, log):
    """{family label: {method: [Run per mesh]}} and the fine reference."""
    ref_elements = 160 if quick else 640
    ref_scene = cattaneo_carter(**{"discretization.elements": ref_elements, "discretization.step": 0.25,
                                   "discretization.distance": Q_MID, "solver.max_iterations": 2000})
    log(f"  fine reference: newton, {ref_elements} QCE, Δq = Le/4, to q = {Q_MID} a_H")
    ref = timed_run(ref_scene, "newton", "fine reference", repeats=1)
    if not ref.ok:
        log(f"  fine reference failed: {ref.failed}")
    out = {}
    for fam in families:
        out[fam.label] = mesh_sweep(
            methods, meshes, lambda E, fam=fam: fam.scene(E, **{"solver.max_iterations": 2000}),
            lambda E, fam=fam: _nodes(fam.element, E), lambda r: {"mid": mid_error(r, ref, 0.1)},
            repeats, run_budget, fam.label, log)
    return out, ref


def part_coupled(methods, meshes, repeats, run_budget, quick, log):
    """The coupled scene over the mesh: {label: {method: [Run]}}, the fine reference."""
    ref_elements = 80 if quick else 160
    ref = timed_run(coupled_scene(**{"discretization.elements": ref_elements}), "newton", "fine reference",
                    repeats=1)
    log(f"  coupled fine reference: newton, {ref_elements} QCE: " + (f"{ref.stepping:.1f} s" if ref.ok else ref.failed))
    mu = 0.3
    dist = coupled_scene().discretization.distance

    def errors(r):
        return {"start": mid_error(r, ref, mu, 0.0), "end": mid_error(r, ref, mu, dist),
                "end_p": mid_error(r, ref, mu, dist, key="pn")}

    label = "coupled `goodman-bentall`, shortened (QCE, Δq = Le/2, 1 a_H, 10 start steps)"
    per = mesh_sweep(methods, meshes, lambda E: coupled_scene(**{"discretization.elements": E}),
                     lambda E: 2 * E + 1, errors, repeats, run_budget, "coupled", log)
    return {label: per}, ref


#: Error columns of the mesh tables: (key, header).
CC_COLUMNS = (("cattaneo", "Cattaneo (q = 0)"), ("mid", f"fine ref. (q = {Q_MID:g} a_H)"), ("carter", "Carter (end)"))
COUPLED_COLUMNS = (("start", "t, Goodman state (q = 0)"), ("end", "t, q = 1 a_H"), ("end_p", "p, q = 1 a_H"))


def mesh_tables(res, columns) -> str:
    parts = []
    for fam, per in res.items():
        rows = []
        blank = ["–"] * (len(columns) + 2)
        for m, runs in per.items():
            for r in runs:
                if r.skipped:
                    rows.append((f"`{m}`", r.label, r.n, *blank, f"skipped: {r.skipped}"))
                elif r.failed:
                    rows.append((f"`{m}`", r.label, r.n or "–", *blank, f"failed: {r.failed[:80]}"))
                else:
                    rows.append((f"`{m}`", r.label, r.n, r.steps, f"{r.stepping:.3f}",
                                 *(fmt_err(r.errors.get(k)) for k, _ in columns), f"{r.residual:.0e}"))
        parts.append(f"**{fam}**\n\n" + table(["method", "elements", "nodes", "steps", "stepping [s]",
                                               *(h for _, h in columns), "max residual / note"], rows))
    return "\n\n".join(parts)


def discretization_tables(res, ref) -> str:
    note = (f"Errors: rms over the contact of \\|t − t_closed form\\|/(μp0) (`rollqp.report.closed_form_errors`), and "
            f"rms over \\|x\\| ≤ a_H of \\|t − t_ref\\|/(μp0) at q = {Q_MID:g} a_H against the fine reference "
            f"(`newton`, {ref.n} nodes, Δq = Le/4, interpolated linearly to the coarse nodes; "
            + (f"{ref.stepping:.1f} s" if ref.ok else f"failed: {ref.failed}") + ").")
    return note + "\n\n" + mesh_tables(res, CC_COLUMNS)


def coupled_tables(res, ref) -> str:
    note = ("Errors against the fine reference (`newton`, " + (f"{ref.n} nodes" if ref.ok else f"failed: {ref.failed}")
            + ", the same scene), interpolated linearly to the coarse nodes: rms over \\|x\\| ≤ a_H of "
              "\\|t − t_ref\\|/(μp0) in the Goodman state (q = 0, after the 10 normal-load steps) and at the end, "
              "and of \\|p − p_ref\\|/p0 at the end.")
    return note + "\n\n" + mesh_tables(res, COUPLED_COLUMNS)


def equal_accuracy(res, key, levels) -> str:
    """For each method: the least stepping time among its runs whose error ``key`` is <= each level."""
    fam = next(iter(res))
    per = res[fam]
    rows = []
    for m, runs in per.items():
        cells = [f"`{m}`"]
        for lv in levels:
            ts = [r.stepping for r in runs if r.ok and r.errors.get(key) is not None and r.errors[key] <= lv]
            cells.append(f"{min(ts):.3f}" if ts else "not reached")
        rows.append(cells)
    return table(["method"] + [f"{key} error ≤ {lv:g}" for lv in levels], rows)


# ------------------------------------------------------------------------------- part: scaling
def part_scaling(methods, elements, repeats, step_budget, log):
    """{method: [Run per size]}, {n: cho_factor seconds}."""
    chol = {}
    per = {m: [] for m in methods}
    last = {}
    for E in elements:
        n = 2 * E + 1
        chol[n] = cholesky_time(n, repeats=7 if n <= 700 else 3)
        for m in methods:
            prev = last.get(m)
            if prev is not None and not prev.ok:
                per[m].append(Run(method=m, label=str(E), n=n, skipped="a smaller size failed or was skipped"))
                last[m] = per[m][-1]
                continue
            if prev is not None:
                pred = prev.step * (n / prev.n) ** 3
                if pred > step_budget:
                    per[m].append(Run(method=m, label=str(E), n=n,
                                      skipped=f"predicted step {pred:.2g} s > {step_budget:g} s budget"))
                    last[m] = per[m][-1]
                    continue
            dq = 0.5 * 2.5 / E  # a_H
            scene = cattaneo_carter(**{"discretization.elements": E, "discretization.distance": (SCALING_STEPS + 1) * dq,
                                       "solver.max_iterations": 2000})
            r = timed_run(scene, m, str(E), repeats=repeats if n <= 700 else 1, budget=3.0, keep=False)
            per[m].append(r)
            last[m] = r
            log(f"  scaling {m} n = {n}: " + (f"{1e3 * r.step:.3f} ms/step (cho {1e3 * chol[n]:.3f} ms)"
                                              if r.ok else r.failed))
    return per, chol


def scaling_table(per, chol) -> tuple[str, dict]:
    ns = sorted(chol)
    head = ["nodes", "`cho_factor` [ms]"] + [f"`{m}` [ms]" for m in per] + ["`newton` / `cho_factor`"]
    rows = []
    for n in ns:
        cells = [n, f"{1e3 * chol[n]:.3f}"]
        for m, runs in per.items():
            r = next((r for r in runs if r.n == n), None)
            if r is None:
                cells.append("–")
            elif r.skipped:
                cells.append(f"skipped ({r.skipped})")
            elif r.failed:
                cells.append(f"failed ({r.failed[:50]})")
            else:
                cells.append(f"{1e3 * r.step:.3f}")
        nr = next((r for r in per.get("newton", []) if r.n == n and r.ok), None)
        cells.append(f"{nr.step / chol[n]:.2f}" if nr else "–")
        rows.append(cells)
    expo = {}
    erow = ["fitted exponent (n ≥ 161)", f"{fit_exponent(ns, [chol[n] for n in ns]):.2f}"]
    for m, runs in per.items():
        ok = [r for r in runs if r.ok]
        expo[m] = fit_exponent([r.n for r in ok], [r.step for r in ok])
        erow.append(f"{expo[m]:.2f}" if np.isfinite(expo[m]) else "–")
    erow.append("")
    rows.append(erow)
    expo["cho_factor"] = fit_exponent(ns, [chol[n] for n in ns])
    return table(head, rows), expo


# ------------------------------------------------------------------------------- targets
def targets(tol_res, scal, chol, expo) -> tuple[str, dict]:
    rows, status = [], {}
    newton = {r.n: r for r in scal.get("newton", []) if r.ok}
    clar = {r.n: r for r in scal.get("qp-clarabel", []) if r.ok}
    big = [n for n in sorted(newton) if n >= 321]
    if big:
        worst = max(newton[n].step / chol[n] for n in big)
        ok = worst <= TARGET_CHOL_RATIO
        rows.append(("Newton step / dense Cholesky, n ≥ 321", f"≤ {TARGET_CHOL_RATIO:g}",
                     ", ".join(f"{newton[n].step / chol[n]:.2f} (n = {n})" for n in big), "met" if ok else "**missed**"))
        status["chol"] = ok
    small = [n for n in sorted(newton) if n <= 321 and n in clar]
    if small:
        ratios = [clar[n].step / newton[n].step for n in small]
        resid_ok = all(newton[n].residual <= clar[n].residual for n in small)
        ok = min(ratios) >= TARGET_CLARABEL_RATIO and resid_ok
        rows.append(("Clarabel step / Newton step, n ≤ 321, at ≤ residual", f"≥ {TARGET_CLARABEL_RATIO:g}",
                     ", ".join(f"{r:.0f} (n = {n}; residual {newton[n].residual:.0e} vs {clar[n].residual:.0e})"
                               for n, r in zip(small, ratios)), "met" if ok else "**missed**"))
        status["clarabel"] = ok
    if "newton" in expo and np.isfinite(expo["newton"]):
        top = max(newton) if newton else 0
        ok = expo["newton"] <= TARGET_EXPONENT
        rows.append(("Newton step cost exponent, 161 ≤ n ≤ " + str(top), f"≤ {TARGET_EXPONENT:g}",
                     f"{expo['newton']:.2f}" + ("" if top >= 2561 else f" (largest n measured: {top})"),
                     "met" if ok and top >= 2561 else ("**missed**" if not ok else "not measured to 2561")))
        status["exponent"] = ok
    for label, d in (tol_res or {}).items():
        if not label.startswith("§6.1.1") or "(40 QCE" not in label:
            continue
        r = next((r for m, runs in d["runs"].items() if m == "newton" for r in runs if r.label == "1e-10"), None)
        if r is not None and r.ok:
            ok = r.stepping <= TARGET_RUN
            rows.append(("§6.1.1 transient at 40 QCE with Newton (tolerance 1e-10), Σ`step_time`",
                         f"≤ {TARGET_RUN:g} s", f"{r.stepping:.3f} s (whole call {r.wall:.3f} s)",
                         "met" if ok else "**missed**"))
            status["run"] = ok
    return table(["target", "required", "measured", ""], rows), status


# ------------------------------------------------------------------------------- figures
def _plt():
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        return plt
    except ImportError:
        return None


MARKERS = {"newton": "o", "nt-newton": "s", "qp-clarabel": "^", "qp-osqp": "v", "qp-cvxpy": "D"}
FLOOR = 1e-16  # errors of exactly 0 are drawn here


def _curves(ax, curves, xlabel, ylabel, title, legend=8):
    """Log–log curves ``{label: [(x, y), ...]}`` on ``ax`` (work–precision style)."""
    import matplotlib

    cmap = matplotlib.colormaps["tab20"]
    for i, (label, pts) in enumerate(curves.items()):
        if pts:  # a fixed colour per label, also when another label has no points
            x, y = zip(*pts)
            color = f"C{list(MARKERS).index(label)}" if label in MARKERS else cmap(i % 20)
            ax.loglog(x, y, marker=MARKERS.get(label, "."), label=label, color=color)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    if legend:
        ax.legend(fontsize=legend)


def _save(fig, plt, path):
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def figure_tolerance(res, path):
    plt = _plt()
    if plt is None:
        return None
    fig, axes = plt.subplots(1, len(res), figsize=(5.2 * len(res), 4.2), squeeze=False)
    for ax, (label, d) in zip(axes[0], res.items()):
        curves = {m: [(r.stepping, max(r.errors.get("solver") or 0.0, FLOOR)) for r in runs
                      if r.ok and r.errors.get("solver") is not None] for m, runs in d["runs"].items()}
        _curves(ax, curves, "stepping time Σ step_time [s]", "max distance from reference (p0, μp0)",
                label.split(" (")[0].replace("`", "") + "\n(one point per tolerance 1e-4 … 1e-12)")
    return _save(fig, plt, path)


def figure_discretization(res, path, columns=CC_COLUMNS):
    plt = _plt()
    if plt is None:
        return None
    fam = next(iter(res))
    per = res[fam]
    fig, axes = plt.subplots(1, len(columns), figsize=(5 * len(columns), 4.2))
    for ax, (k, title) in zip(axes, columns):
        curves = {m: [(r.stepping, r.errors[k]) for r in runs if r.ok and r.errors.get(k)] for m, runs in per.items()}
        _curves(ax, curves, "stepping time Σ step_time [s]", "rms error / (μp0), p: / p0",
                f"{title}\n{fam.split(' (')[0].replace('`', '')}; one point per mesh")
    return _save(fig, plt, path)


def figure_families(res, path):
    plt = _plt()
    if plt is None or len(res) < 2:
        return None
    methods = list(next(iter(res.values())))
    fig, axes = plt.subplots(1, len(methods), figsize=(4.6 * len(methods), 4.2), squeeze=False)
    for i, (ax, m) in enumerate(zip(axes[0], methods)):
        curves = {fam: [(r.stepping, r.errors["carter"]) for r in per.get(m, []) if r.ok and r.errors.get("carter")]
                  for fam, per in res.items()}
        _curves(ax, curves, "stepping time [s]", "rms error / (μp0) at the end",
                f"{m}: Carter error vs time, by discretization family", legend=6 if i == 0 else 0)
    return _save(fig, plt, path)


def figure_scaling(per, chol, expo, path):
    plt = _plt()
    if plt is None:
        return None
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    ns = sorted(chol)
    ax.loglog(ns, [chol[n] * 1e3 for n in ns], "k--", label=f"cho_factor (exp. {expo.get('cho_factor', np.nan):.2f})")
    curves = {m: [(r.n, 1e3 * r.step) for r in runs if r.ok] for m, runs in per.items()}
    for m, pts in curves.items():
        if pts:
            x, y = zip(*pts)
            e = expo.get(m, np.nan)
            ax.loglog(x, y, marker=MARKERS.get(m, "o"), color=f"C{list(MARKERS).index(m)}" if m in MARKERS else None,
                      label=f"{m} (exp. {e:.2f})" if np.isfinite(e) else m)
    _curves(ax, {}, "nodes n", "median rolling step [ms]",
            "cattaneo-carter, Δq = Le/2, first rolling steps; one BLAS thread")
    return _save(fig, plt, path)


# ------------------------------------------------------------------------------- main
PARTS = ("tolerance", "discretization", "scaling")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="rollqp bench", description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="a smoke test: fewer cases, one repeat (about 30 s of CPU; 1-1.5 min on 2 cores)")
    ap.add_argument("--parts", default=",".join(PARTS), help=f"comma-separated parts (default {','.join(PARTS)})")
    ap.add_argument("--methods", default=",".join(METHOD_NAMES),
                    help=f"comma-separated methods (default {','.join(METHOD_NAMES)})")
    ap.add_argument("--repeats", type=int, default=None, help="runs per case, median taken (default 3; 1 with --quick)")
    ap.add_argument("--run-budget", type=float, default=None,
                    help="discretization sweep: skip a mesh whose predicted stepping time exceeds this [s] "
                         "(default 20; 2 with --quick)")
    ap.add_argument("--step-budget", type=float, default=None,
                    help="scaling: skip a size whose predicted step time exceeds this [s] (default 2; 0.05 with --quick)")
    ap.add_argument("--docs", action="store_true",
                    help="write the tables into docs/performance.md and the figures into docs/figures/perf-*.png")
    ap.add_argument("--figures", default=None, help="directory for the figures (default docs/figures with --docs, "
                                                     "else none)")
    ap.add_argument("--json", default=None, help="also write the raw numbers to this JSON file")
    args = ap.parse_args(argv)

    quick = args.quick
    parts = [p.strip() for p in args.parts.split(",") if p.strip()]
    bad = [p for p in parts if p not in PARTS]
    methods = [m.strip() for m in args.methods.split(",") if m.strip()]
    badm = [m for m in methods if m not in METHOD_NAMES]
    if bad or badm:
        print(f"rollqp bench: unknown {'part' if bad else 'method'} {', '.join(bad or badm)}; "
              f"choose from {', '.join(PARTS if bad else METHOD_NAMES)}", file=sys.stderr)
        return 2
    if args.docs and quick:
        print("rollqp bench: --docs writes the full study; drop --quick", file=sys.stderr)
        return 2
    repeats = args.repeats or (1 if quick else 3)
    run_budget = args.run_budget or (2.0 if quick else 20.0)
    step_budget = args.step_budget or (0.05 if quick else 2.0)
    fig_dir = Path(args.figures) if args.figures else (FIGURES if args.docs else None)
    if fig_dir is not None:
        fig_dir.mkdir(parents=True, exist_ok=True)

    def log(msg):
        print(msg, file=sys.stderr, flush=True)

    command = "rollqp bench " + " ".join(argv if argv is not None else sys.argv[1:])
    sections = {"machine": machine_table(command.strip())}
    print("## Machine\n\n" + sections["machine"] + "\n", flush=True)
    out = Outputs(fig_dir, log)
    t_all = time.perf_counter()
    try:
        run_parts(parts, methods, quick, repeats, run_budget, step_budget, sections, out, log)
    finally:  # what was computed is kept, also when a later part or figure fails
        total = time.perf_counter() - t_all
        print(f"<!-- measured in {total:.0f} s -->")
        if args.json:
            Path(args.json).write_text(json.dumps(out.raw, indent=1, default=float))
            log(f"raw numbers: {args.json}")
        if args.docs:
            written = write_sections(DOC, sections)
            log(f"wrote {', '.join(written) or 'no'} section(s) of {DOC}")
        if out.figures:
            log("figures: " + ", ".join(map(str, out.figures)))
    if out.failed:
        log(f"rollqp bench: {len(out.failed)} figure(s) failed (above); the tables and raw numbers are complete")
    return 1 if out.failed else 0


class Outputs:
    """The figures and raw numbers of a study as its parts finish; a figure that fails is logged and
    recorded (``failed``), never the end of the study: its tables are printed and written anyway."""

    def __init__(self, fig_dir, log):
        self.fig_dir, self.log = fig_dir, log
        self.figures, self.failed, self.raw = [], [], {}

    def figure(self, fn, *args, name):
        if self.fig_dir is None:
            return
        try:
            path = fn(*args, self.fig_dir / name)
        except Exception as err:  # noqa: BLE001 - any plotting error: the numbers stay
            self.failed.append((name, f"{type(err).__name__}: {err}"))
            self.log(f"rollqp bench: figure {name} failed: {type(err).__name__}: {err}")
            return
        if path:
            self.figures.append(path)


def run_parts(parts, methods, quick, repeats, run_budget, step_budget, sections, out, log):
    """Run the chosen parts in order; each prints its tables and draws its figures as soon as it ends."""
    tol_res = scal = chol = expo = None
    if "tolerance" in parts:
        t0 = time.perf_counter()
        tols = (1e-4, 1e-8, 1e-12) if quick else TOLERANCES
        tol_res = part_tolerance(methods, tols, repeats, quick, log)
        out.raw["tolerance"] = {lb: {m: [_raw(r) for r in rs] for m, rs in d["runs"].items()}
                                for lb, d in tol_res.items()}
        sections["tolerance"] = tolerance_tables(tol_res, tols)
        print("## Work–precision: solver tolerance\n\n" + sections["tolerance"] + "\n", flush=True)
        out.figure(figure_tolerance, tol_res, name="perf-wp-tolerance.png")
        log(f"tolerance part: {time.perf_counter() - t0:.0f} s")
    if "discretization" in parts:
        run_discretization(methods, quick, repeats, run_budget, sections, out, log)
    if "scaling" in parts:
        t0 = time.perf_counter()
        elements = (20, 40, 80, 160) if quick else SCALING_ELEMENTS
        scal, chol = part_scaling(methods, elements, repeats, step_budget, log)
        out.raw["scaling"] = {"cho_factor": chol, **{m: [_raw(r) for r in rs] for m, rs in scal.items()}}
        text, expo = scaling_table(scal, chol)
        sections["scaling"] = (f"Median `step_time` of rolling steps 2…{SCALING_STEPS + 1} of `cattaneo-carter` "
                               f"(QCE, Δq = Le/2: the first steps of the transient, where the stick zone moves every "
                               f"step), beside `scipy.linalg.cho_factor` of an SPD matrix of the same n (median of "
                               f"repeats). Budget: a size is skipped when the previous size's step × (n ratio)³ "
                               f"exceeds {step_budget:g} s. `solver.max_iterations` = 2000: the braked start "
                               f"(Cattaneo from zero traction) takes Newton ~200 iterations at 2561 nodes.\n\n" + text)
        print("## Scaling\n\n" + sections["scaling"] + "\n", flush=True)
        out.figure(figure_scaling, scal, chol, expo, name="perf-scaling.png")
        log(f"scaling part: {time.perf_counter() - t0:.0f} s")
    if scal is not None or tol_res is not None:
        sections["targets"], _ = targets(tol_res, scal or {}, chol or {}, expo or {})
        print("## Targets\n\n" + sections["targets"] + "\n")


def run_discretization(methods, quick, repeats, run_budget, sections, out, log):
    """The discretization part: the main family, the other families (full study), the coupled scene."""
    t0 = time.perf_counter()
    meshes = (10, 20, 40) if quick else MESHES
    fams = [Family()]
    if not quick:
        fams += [Family(e, f, s) for e in ("quadratic", "linear", "constant")
                 for f in ("material", "convective-local") for s in (0.5, 0.125)
                 if (e, f, s) != ("quadratic", "material", 0.5)]
    fam_meshes = meshes if quick else (10, 20, 40, 80, 160)
    main_res, ref = part_discretization(methods, fams[:1], meshes, repeats, run_budget, quick, log)
    out.raw["discretization"] = {lb: {m: [_raw(r) for r in rs] for m, rs in per.items()} for lb, per in main_res.items()}
    sections["discretization"] = (discretization_tables(main_res, ref) + "\n\nLeast stepping time [s] at which "
                                  "each method reaches an error level (its runs above, any mesh):\n\n"
                                  + equal_accuracy(main_res, "carter", (3e-2, 1e-2, 3e-3, 1e-3)) + "\n\n"
                                  + equal_accuracy(main_res, "mid", (3e-2, 1e-2, 3e-3, 1e-3)))
    print("## Work–precision: discretization\n\n" + sections["discretization"] + "\n", flush=True)
    out.figure(figure_discretization, main_res, name="perf-wp-discretization.png")
    fam_res = {}
    if len(fams) > 1:
        fam_res, _ = part_discretization(methods, fams[1:], fam_meshes, 1, run_budget / 4, quick, log)
        out.raw["discretization"].update({lb: {m: [_raw(r) for r in rs] for m, rs in per.items()}
                                          for lb, per in fam_res.items()})
        sections["families"] = discretization_tables(fam_res, ref)
        print("## Work–precision: element types, formulations, steps\n\n" + sections["families"] + "\n", flush=True)
        out.figure(figure_families, {**main_res, **fam_res}, name="perf-wp-families.png")
    coupled_res, cref = part_coupled(methods, (10, 20) if quick else (10, 20, 40, 80), repeats, run_budget,
                                     quick, log)
    out.raw["discretization"].update({lb: {m: [_raw(r) for r in rs] for m, rs in per.items()}
                                      for lb, per in coupled_res.items()})
    sections["coupled"] = coupled_tables(coupled_res, cref)
    print("## Work–precision: discretization, coupled scene\n\n" + sections["coupled"] + "\n", flush=True)
    out.figure(lambda r, path: figure_discretization(r, path, COUPLED_COLUMNS), coupled_res, name="perf-wp-coupled.png")
    log(f"discretization part: {time.perf_counter() - t0:.0f} s")


def _raw(r: Run) -> dict:
    return {k: v for k, v in r.__dict__.items() if k != "arrays"}


if __name__ == "__main__":
    sys.exit(main())
