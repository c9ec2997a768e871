"""The cross-validation report: every available method on one exported step, side by side.

:func:`report` exports step ``K`` of a scene (:func:`rollqp.stepfile.export_step`, marched by
Newton), solves that stored step with every method in :func:`rollqp.available_methods` — the
native QP backends (Clarabel, OSQP, cvxpy), each qpsolvers backend, Newton and the N–T
alternation — warm-started from the same previous state, and lists for each rollqp's
residuals per condition (docs/formulation.md §5), iterations, wall time, and the largest
difference from Newton's solution in ``p0`` (pressure) and ``μ p0`` (traction). On a coupled
step (``A_nt ≠ 0``, §6.2.1) the QP backends run the N–T alternation (paper §6.3). A steady
rolling step (the direct rolling start, docs/theory.md §5) is not a convex QP: a method that
does not solve it directly reaches it the way ``rollqp run`` does, by marching the scene at its
starting loads to the steady state (:func:`solve_step_file`), and its state is then evaluated
on the same stored steady step.

Times are one solve each, on whatever machine runs the report: read them as ratios within
one table, not as benchmarks (``benchmarks/`` has those).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import RollqpError
from ..methods import CROSS_CHECK_METHODS, REFERENCE_METHOD
from ..stepfile import StepFile, export_step, solve_stored
from ..methods import available_methods
from ..problem import classify
from ..methods import capabilities
from ..march import march
from ..scene import scene_from_dict


@dataclass
class Row:
    method: str
    ok: bool
    residuals: dict = field(default_factory=dict)
    iterations: str = ""
    time: float = float("nan")
    dp: float = float("nan")
    dt: float = float("nan")
    states: int = 0
    error: str = ""


@dataclass
class Report:
    """A cross-validation table; ``str()`` prints it (Markdown)."""

    scene: str
    step: int
    q: float
    kind: str
    rows: list
    kind_note: str = ""

    def __str__(self) -> str:
        head = (f"scene {self.scene}, step {self.step} (q = {self.q:.6g}), {self.kind} step; "
                f"residuals nondimensional (docs/formulation.md §5), differences from {REFERENCE_METHOD}\n\n"
                "| method | Signorini | friction | load P | load Q | iterations | time [ms] "
                "| max abs Δp [p0] | max abs Δt [μp0] | states ≠ |\n"
                "|---|---|---|---|---|---|---|---|---|---|")
        lines = [head]
        if self.kind_note:
            lines[0] = head.replace("\n\n|", f"\n{self.kind_note}\n\n|", 1)
        for r in self.rows:
            if not r.ok:
                lines.append(f"| {r.method} | failed: {r.error} |||||||||")
                continue
            rs = r.residuals
            lines.append(f"| {r.method} | {rs['signorini']:.1e} | {rs['friction']:.1e} | {rs['load_normal']:.1e} "
                         f"| {rs['load_tangential']:.1e} | {r.iterations} | {1e3 * r.time:.1f} | {r.dp:.1e} "
                         f"| {r.dt:.1e} | {r.states} |")
        return "\n".join(lines)


def report(scene, step: int | None = None, methods=None, tolerance: float = 1e-10) -> Report:
    """Cross-validate step ``step`` of ``scene`` (default: step 1) over ``methods`` (default: all available).

    ``scene`` may also be a :class:`~rollqp.stepfile.StepFile` (then ``step`` is ignored).
    Iterations: ``normal+tangential`` inner iterations for an uncoupled step; for a coupled
    one ``outer (normal+tangential)`` for the alternations and Newton's own count; ``—``
    where the solver does not report them (DAQP, HiGHS through qpsolvers).
    """
    sf = scene if isinstance(scene, StepFile) else export_step(scene, 1 if step is None else step)
    names = list(methods) if methods is not None else available_methods()
    if REFERENCE_METHOD in names:
        names.remove(REFERENCE_METHOD)
    names.insert(0, REFERENCE_METHOD)
    sc = sf.scales
    rows, ref, ref_state = [], None, None
    for name in names:
        t0 = time.perf_counter()
        try:
            sol = solve_step_file(sf, name, tolerance=tolerance)
        except RollqpError as err:
            rows.append(Row(name, False, error=str(err)))
            continue
        wall = time.perf_counter() - t0
        state = classify(sol.p, sol.t, sol.s, sf.mu, sc)
        if ref is None:
            ref, ref_state = sol, state
        inner = f"{sol.inner_normal}+{sol.inner_tangential}"
        if not sol.extras.get("iterations_reported", True):
            inner = "—"  # DAQP and HiGHS do not report iterations through qpsolvers
        its = f"{sol.iterations} ({inner})" if sol.outer else (inner if sf.kind == "uncoupled" else str(sol.iterations))
        if sol.extras.get("marched"):
            its = f"{sol.iterations} (march to steady)"
        rows.append(Row(name, True, residuals=dict(signorini=sol.residuals.signorini, friction=sol.residuals.friction,
                                                   load_normal=sol.residuals.load_normal,
                                                   load_tangential=sol.residuals.load_tangential),
                        iterations=its, time=wall, dp=float(np.max(np.abs(sol.p - ref.p)) / sc.stress),
                        dt=float(np.max(np.abs(sol.t - ref.t)) / (sc.stress * (sf.mu or 1.0))),
                        states=int(np.count_nonzero(state != ref_state))))
    name = sf.scene.get("name", "?") if isinstance(sf.scene, dict) else "?"
    note = STEADY_NOTE if sf.step_type == "steady" else ""
    return Report(scene=name, step=sf.step, q=sf.q, kind=sf.kind + (" steady" if sf.step_type == "steady" else ""), rows=rows, kind_note=note)


#: What the report says of a steady step (the rows marked "marched").
STEADY_NOTE = ("A steady rolling step is not a convex QP (its slip operator makes the symmetric part indefinite, "
               "docs/theory.md §5): methods that do not solve it directly reach it by marching the scene at its "
               "starting loads, as `rollqp run --method` does; their state is evaluated on this step.")


def solve_step_file(sf: StepFile, name: str, tolerance: float = 1e-10):
    """Solve a stored step with method ``name`` as a run with that method would.

    A rolling or static-shift step is solved as stored (:func:`rollqp.stepfile.solve_stored`).
    A steady rolling step (``step_type == "steady"``) is solved directly by a method that declares
    ``"steady"``; any other method (the QP backends: the steady problem is no convex QP) reaches it
    the way ``rollqp run`` does, by the scene's march at its starting loads to steady rolling
    (:meth:`rollqp.march` state 0), and its state is evaluated on the stored step: the residuals
    are rollqp's of that same discrete steady problem (``extras["marched"]`` is then True;
    ``iterations`` counts every solve of the march).
    """
    if sf.step_type != "steady" or "steady" in capabilities(name).solves:
        return solve_stored(sf, name, tolerance=tolerance)
    if not isinstance(sf.scene, dict) or not sf.scene:
        raise RollqpError(f"step {sf.step} is a steady rolling step, which {name} reaches by marching the "
                          "scene; the step file holds no scene to march")
    scene = scene_from_dict(sf.scene).replace(**{"solver.tolerance": tolerance})
    t0 = time.perf_counter()
    rec = next(iter(march(scene, name)))  # state 0: the rolling start, marched to steady
    sol = sf.problem().solution(rec.state.p, rec.state.t, rec.solution.delta, rec.solution.xi, method=name,
                                iterations=rec.counters.iterations, time=time.perf_counter() - t0)
    sol.extras["marched"] = True
    return sol


# ---------------------------------------------------------------------------- the run's cross-check
#: The QP backends a run is cross-checked against (core dependencies only).
SPOT_METHODS = CROSS_CHECK_METHODS
#: Largest strip (nodes) cross-checked by default: the QP backends take seconds per step beyond it.
SPOT_MAX_NODES = 400


@dataclass
class SpotCheck:
    """Chosen steps of a run solved again by other methods, against the run's own solutions.

    ``rows`` holds, per method, the largest differences over the steps (``p`` in p0, ``t`` in
    μp0) and the largest rollqp residual of its solutions, or the error it raised. ``str()`` is
    the summary line of ``rollqp run``, each failure on a line of its own, in full.
    """

    steps: list
    rows: dict
    steady: list = field(default_factory=list)

    def __str__(self) -> str:
        ok = {m: r for m, r in self.rows.items() if "error" not in r}
        head = f"{', '.join(self.rows)} on steps {', '.join(map(str, self.steps))}"
        if ok:
            dp = max(r["p"] for r in ok.values())
            dt = max(r["t"] for r in ok.values())
            head += f": max |dp| {dp:.1e} p0, |dt| {dt:.1e} mu p0 from the run's own solutions"
        if self.steady:
            head += f" (step {', '.join(map(str, self.steady))} steady: the QP methods march to it, as their runs do)"
        bad = [f"{m} failed: {r['error']}" for m, r in self.rows.items() if "error" in r]
        return "\n".join([head] + bad)


def spot_check(steps, methods=SPOT_METHODS, tolerance: float = 1e-10) -> SpotCheck:
    """Solve the stored steps (:class:`~rollqp.stepfile.StepFile`, from the run's records) with ``methods``.

    Each step is solved from the state before it (the run's), as :func:`report` does, and
    compared with the run's own solution of it (``ref_*``): the run's main job shows both routes
    of the project — the complementarity system and the convex QPs — agreeing on the same
    discrete steps.
    """
    rows = {}
    for name in methods:
        row = {"p": 0.0, "t": 0.0, "residual": 0.0}
        for sf in steps:
            try:
                sol = solve_step_file(sf, name, tolerance=tolerance)
            except RollqpError as err:
                row = {"error": f"step {sf.step}: {err}"}
                break
            sc = sf.scales
            row["p"] = max(row["p"], float(np.max(np.abs(sol.p - sf.ref_p)) / sc.stress))
            row["t"] = max(row["t"], float(np.max(np.abs(sol.t - sf.ref_t)) / (sc.stress * (sf.mu or 1.0))))
            row["residual"] = max(row["residual"], sol.residual)
        rows[name] = row
    return SpotCheck([sf.step for sf in steps], rows, [sf.step for sf in steps if sf.step_type == "steady"])
