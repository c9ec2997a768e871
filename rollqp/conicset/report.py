r"""The conic test set's catalogue and its report in qpbenchmark's style (docs/conic-test-set.md).

Per settings, per solver: the **success rate** (the solver's own status says solved), the share of
answers **within** :data:`~rollqp.conicset.run.WITHIN` of the certified solution, the **shifted
geometric mean of the wall time** (in milliseconds, shift 10 ms, a failed solve charged
:data:`~rollqp.conicset.run.TIME_LIMIT`; divided by the best solver's, so 1.0 is the fastest), and
the shifted geometric means of ``max|x − x*|`` and of rollqp's residual (shift 1e-12, failures
charged 1). Then, at the high-accuracy settings, problem by problem: every answer's distance from the
certified solution and the solvers that are within it.
"""
from __future__ import annotations

import math

import numpy as np

from .run import TIME_LIMIT, WITHIN

__all__ = ["catalogue_table", "report", "shifted_geometric_mean"]


def shifted_geometric_mean(v, shift: float) -> float:
    """``exp(mean(log(v + shift))) − shift`` (qpbenchmark's ``shgeom``)."""
    v = np.asarray(v, dtype=float)
    return float(np.exp(np.mean(np.log(v + shift))) - shift)


def _e(v) -> str:
    return "—" if v is None or (isinstance(v, float) and not math.isfinite(v)) else f"{v:.0e}"


def catalogue_table(catalogue: dict) -> str:
    """The problems: size, cones, load rows, conditioning, contact/stick/slip, certificates."""
    rows = ["| problem | kind | grid | n | cones | load rows | κ | contact el. | stick / slip | rollqp residual | "
            "from the file | what |", "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for name, m in catalogue.items():
        kind = m["kind"]
        kappa = m.get("cond_H", m.get("cond_W"))
        cones = m.get("cones", m.get("contacts", 0)) if kind != "normal" else 0
        ss = f"{m['stick']:.2f} / {m['slip']:.2f}" if "stick" in m else f"{m.get('contact', 0):.2f} in contact"
        nel = m.get("contact_elements", round(m.get("contact", 0) * m["n"]))
        kindname = {"normal": "QP", "tangential": "SOCP", "fc": "FCLib"}[kind]
        rows.append(f"| `{name}` | {kindname} | {m['grid'][0]}×{m['grid'][1]} | {m['n']} | {cones} | "
                    f"{m.get('load_rows', '–')} | {kappa:.1e} | {nel} | {ss} | {m['residual']:.1e} | "
                    f"{m['residual_from_arrays']:.1e} | {m['what']} |")
    return "\n".join(rows)


def _summary(answers, settings, solvers):
    rows = ["| solver | success rate (%) | within 1e-6 (%) | runtime (shm) | max\\|x − x*\\| (shm) | "
            "rollqp residual (shm) |", "|---|---|---|---|---|---|"]
    stats = {}
    for s in solvers:
        a = [x for x in answers if x.solver == s and x.settings == settings]
        if not a:
            continue
        t = [1e3 * (x.time if x.ok else max(x.time, TIME_LIMIT)) for x in a]
        dx = [x.dx if x.ok and math.isfinite(x.dx) else 1.0 for x in a]
        rs = [x.residual if x.ok and math.isfinite(x.residual) else 1.0 for x in a]
        stats[s] = (100 * np.mean([x.ok for x in a]), 100 * np.mean([x.ok and x.dx <= WITHIN for x in a]),
                    shifted_geometric_mean(t, 10.0), shifted_geometric_mean(dx, 1e-12),
                    shifted_geometric_mean(rs, 1e-12))
    best = min(v[2] for v in stats.values()) if stats else 1.0
    for s, (ok, within, t, dx, rs) in stats.items():
        rows.append(f"| {s} | {ok:.1f} | {within:.1f} | {t / best:.1f} | {dx:.1e} | {rs:.1e} |")
    return "\n".join(rows)


def _per_problem(answers, settings, solvers, catalogue):
    head = "| problem | n | " + " | ".join(solvers) + " | within 1e-6 |"
    rows = [head, "|" + "---|" * (len(solvers) + 3)]
    names = sorted({a.problem for a in answers}, key=lambda n: (catalogue.get(n, {}).get("n", 0), n))
    for name in names:
        cells, good = [], []
        for s in solvers:
            a = next((x for x in answers if x.problem == name and x.solver == s and x.settings == settings), None)
            if a is None:
                cells.append("")
                continue
            mark = "" if a.ok else "✗ "
            cells.append(mark + (_e(a.dx) if math.isfinite(a.dx) else "—"))
            if a.ok and a.dx <= WITHIN:
                good.append(s)
        rows.append(f"| `{name}` | {catalogue.get(name, {}).get('n', '')} | " + " | ".join(cells) + f" | {len(good)} |")
    return "\n".join(rows)


def _times(answers, settings, solvers, catalogue):
    bins = [(0, 200), (200, 700), (700, 10 ** 9)]
    label = {0: "n < 200", 1: "200 ≤ n < 700", 2: "n ≥ 700"}
    rows = ["| solver | " + " | ".join(label[i] for i in range(len(bins))) + " |", "|---" * (len(bins) + 1) + "|"]
    for s in solvers:
        cells = []
        for lo, hi in bins:
            t = [a.time for a in answers if a.solver == s and a.settings == settings
                 and lo <= catalogue.get(a.problem, {}).get("n", 0) < hi]
            cells.append(f"{np.median(t):.3g}" if t else "–")
        rows.append(f"| {s} | " + " | ".join(cells) + " |")
    return "\n".join(rows)


def _fclib(answers, catalogue):
    rows = ["| problem | contacts | route | converged | fixed-point it. | solver it. | time [s] | max\\|r − r*\\| | "
            "merit | rollqp residual | within 1e-6 |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for a in sorted(answers, key=lambda a: (catalogue.get(a.problem, {}).get("n", 0), a.problem, a.solver)):
        good = a.ok and a.dx <= WITHIN and a.merit <= WITHIN
        rows.append(f"| `{a.problem}` | {catalogue.get(a.problem, {}).get('contacts', '')} | {a.solver} | "
                    f"{'yes' if a.ok else 'no: ' + a.status} | {a.iterations} | {a.inner} | {a.time:.2f} | "
                    f"{a.dx:.1e} | {a.merit:.1e} | {a.residual:.1e} | {'yes' if good else 'no'} |")
    return "\n".join(rows)


def report(answers, catalogue, machine: str = "") -> str:
    """The Markdown report of a run (module docstring); the FCLib problems' answers (the SOCP fixed
    point) in their own table."""
    fc = [a for a in answers if catalogue.get(a.problem, {}).get("kind") == "fc"]
    answers = [a for a in answers if catalogue.get(a.problem, {}).get("kind") != "fc"]
    solvers = list(dict.fromkeys(a.solver for a in answers))
    settings = list(dict.fromkeys(a.settings for a in answers))
    n = len({a.problem for a in answers})
    out = [f"# Conic test set: {n} conic programs, {len(solvers)} solver routes", ""]
    if machine:
        out += [machine, ""]
    for st in settings:
        out += [f"## Settings: {st}", "", _summary(answers, st, solvers), ""]
    for st in settings:
        out += [f"## Distance from the certified solution, {st} settings (max|x − x*| in p0; ✗: the solver's "
                f"status is not solved)", "", _per_problem(answers, st, solvers, catalogue), ""]
        out += [f"Median wall time [s], {st} settings:", "", _times(answers, st, solvers, catalogue), ""]
    if fc:
        out += ["## FCLib problems: the SOCP fixed point (each SOCP by Clarabel or SCS, tolerances 1e-10)", "",
                "max|r − r*| in p0 from the certified solution; merit: the natural-map residual "
                "‖r − Proj_C(r − û)‖₂ from W, q, μ; within 1e-6: converged, and distance and merit at "
                "most 1e-6.",
                "", _fclib(fc, catalogue), ""]
    return "\n".join(out)
