"""Checking a candidate solution of a stored step with rollqp's residuals (:func:`check_step`), and solving a stored
step with any rollqp method (:func:`solve_stored`)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError, SolverError
from ..methods import COMPARE_METHODS, compose, get_method
from ..npzfile import read_npz, real_array, real_scalar
from ..problem import SEPARATION, SLIP, STICK, StepSolution, classify, friction_residual
from .file import FORMAT, StepFile

__all__ = ["DEFAULT_TOL", "CONDITIONS", "SOLUTION_KEYS", "solve_stored", "Failure", "CheckReport", "load_solution", "validate_solution",
           "check_step"]

#: Default pass/fail limit of :func:`check_step` on each nondimensional residual.
#: Three decades below the discretization error of the paper's meshes (≈1e-3 p0, docs/validation.md),
#: so a pass means "solves this discrete step", not "close to the physics"; two decades above the
#: QP backends' residual limit (1e-8), and above what an interior point without refinement
#: (the cvxpy script: 8.6e-8 to 1.6e-7) or scipy's SLSQP (1.0e-7) reach on the exported QPs
#: (docs/stepfiles.md), so any converged solver passes.
DEFAULT_TOL = 1e-6
CONDITIONS = ("signorini", "friction", "load_normal", "load_tangential")
_LABEL = {"signorini": "Signorini (p >= 0, g >= 0, p·g = 0; eq. 51-52)",
          "friction": "friction law (|t| <= mu p, t opposes slip; eq. 57-60)",
          "load_normal": "normal load f'p = P (eq. 67)",
          "load_tangential": "tangential load f't = Q (eq. 67)"}
_STATE = {SEPARATION: "separation", STICK: "stick", SLIP: "slip"}
SOLUTION_KEYS = ("p", "t", "delta", "xi")


# ------------------------------------------------------------------------------ solving stored steps
def solve_stored(step: StepFile, method: str, tolerance: float = 1e-10) -> StepSolution:
    """Solve a stored step with any rollqp method, warm-started from the previous state.

    Uncoupled steps: the normal half, then the tangential half at its pressure (as the march
    does). Coupled steps: Newton on the coupled problem; ``nt-newton`` and the QP backends by
    the N–T alternation (paper §6.3). ``inner_normal`` and ``inner_tangential`` count the iterations of
    the halves.
    """
    pb = step.problem()
    meth = compose(get_method(method, tolerance=tolerance), pb.Ant is not None)
    warm = step.previous() if np.any(step.prev_p) else None  # none before the first load increment
    if pb.Ant is not None:
        return meth.solve(pb, warm=warm)
    nsol = meth.solve(pb.normal_half(np.zeros(pb.n)), warm=warm)
    tsol = meth.solve(pb.tangential_half(nsol.p), warm=warm)
    sol = pb.solution(nsol.p, tsol.t, nsol.delta, tsol.xi, method=method, iterations=nsol.iterations + tsol.iterations,
                      time=nsol.time + tsol.time, solver_time=nsol.solver_time + tsol.solver_time,
                      inner_normal=nsol.iterations, inner_tangential=tsol.iterations)
    sol.extras.update(iterations_reported=nsol.extras.get("iterations_reported", True)
                      and tsol.extras.get("iterations_reported", True))
    return sol


# ------------------------------------------------------------------------------ checking
@dataclass
class Failure:
    """One violated condition: its residual, and the nodes where it is violated (worst first, with why)."""

    condition: str
    value: float
    nodes: np.ndarray
    reasons: list
    x: np.ndarray
    detail: str = ""

    def line(self, tol) -> str:
        head = f"{self.condition}: residual {self.value:.3e} > {tol:.1e}"
        if self.detail:
            head += f" ({self.detail})"
        if self.nodes.size:
            shown = ", ".join(f"node {i} x={xi:+.4g} {r}" for i, xi, r in
                              zip(self.nodes[:6], self.x[:6], self.reasons[:6]))
            more = f", … {self.nodes.size - 6} more" if self.nodes.size > 6 else ""
            head += f" at {self.nodes.size} node(s): {shown}{more}"
        return head


@dataclass
class CheckReport:
    """What :func:`check_step` found; ``str()`` is the readable report, ``passed`` the verdict."""

    step: int
    kind: str
    step_type: str
    given: tuple
    tol: float
    residuals: dict
    failures: list
    delta: float | None
    xi: float | None
    fitted: tuple
    comparisons: dict
    state_differs: np.ndarray
    states: tuple
    x: np.ndarray
    notes: list = field(default_factory=list)

    @property
    def passed(self) -> bool:
        return not self.failures

    def diagnosis(self) -> list[str]:
        """One line per failed condition."""
        return [f.line(self.tol) for f in self.failures]

    def __str__(self) -> str:
        L = [f"step {self.step} ({self.kind}, {self.step_type}); candidate gives {', '.join(self.given)}; tolerance {self.tol:.1e}"]
        if self.delta is not None:
            L.append(f"  approach δ = {self.delta:.10g}" + (" (fitted: mean gap closure at the contact nodes)"
                                                              if "delta" in self.fitted else ""))
        if self.xi is not None:
            L.append(f"  creepage ξ = {self.xi:.10g}" + (" (fitted: zero mean slip at the stick nodes)"
                                                          if "xi" in self.fitted else ""))
        L.append("  rollqp residuals (nondimensional, docs/formulation.md §5):")
        for c in CONDITIONS:
            if c in self.residuals:
                v = self.residuals[c]
                L.append(f"    {c:<16} {v:10.3e}  {'ok' if v <= self.tol else 'FAIL'}   {_LABEL[c]}")
        for name, d in self.comparisons.items():
            parts = [f"max|Δp| = {d['p']:.2e} p0" if "p" in d else None,
                     f"max|Δt| = {d['t']:.2e} μp0" if "t" in d else None,
                     f"residual of {name} {d['residual']:.1e}"]
            L.append(f"  vs {name:<12} " + ", ".join(p for p in parts if p))
        if self.state_differs.size:
            cand, ref = self.states
            L.append(f"  node states differing from newton ({self.state_differs.size}):")
            for i in self.state_differs[:20]:
                L.append(f"    node {i:3d} x = {self.x[i]:+.5g}: {_STATE[int(cand[i])]} (newton: {_STATE[int(ref[i])]})")
            if self.state_differs.size > 20:
                L.append(f"    … {self.state_differs.size - 20} more")
        else:
            L.append("  node states (separation/stick/slip): all as newton's")
        L += [f"  note: {n}" for n in self.notes]
        L.append("PASS" if self.passed else "FAIL\n" + "\n".join("  " + d for d in self.diagnosis()))
        return "\n".join(L)


def load_solution(path, n: int, arg: str = "SOLUTION.npz") -> dict:
    """Read a candidate solution: keys ``p``, ``t`` ((n,), scene units), ``delta``, ``xi`` (scalars)."""
    z = read_npz(path, arg)
    return validate_solution(z, n, arg)


def validate_solution(sol: dict, n: int, arg: str = "solution") -> dict:
    unknown = sorted(set(sol) - set(SOLUTION_KEYS))
    if "format" in sol and np.asarray(sol["format"]).dtype.kind in "US" and str(sol["format"]) == FORMAT:
        raise InputError(arg, "this is a step file, not a solution (keys p, t, delta, xi)")
    if unknown:
        more = f", … ({len(unknown)} in all)" if len(unknown) > 5 else ""
        raise InputError(arg, f"unknown key(s) {', '.join(map(repr, unknown[:5]))}{more}; "
                              f"allowed: {', '.join(SOLUTION_KEYS)}")
    if "p" not in sol and "t" not in sol:
        raise InputError(arg, "give the pressure 'p' and/or the traction 't'")
    out = {k: real_array(sol, k, (n,), arg) for k in ("p", "t") if k in sol}
    out.update({k: real_scalar(sol, k, arg) for k in ("delta", "xi") if k in sol})
    return out


def check_step(step, solution, tol: float = DEFAULT_TOL, compare_with=COMPARE_METHODS) -> CheckReport:
    """Evaluate a candidate solution of a stored step with rollqp's residuals.

    Parameters
    ----------
    step : StepFile or path
    solution : dict or path
        ``p`` and/or ``t`` ((n,), the scene's units: pressure >= 0 in compression, traction on
        body A in +x), optionally ``delta`` (approach) and ``xi`` (creepage). Missing ``δ``
        (``ξ``) is fitted: the mean of ``h + A_nn p + A_nt t`` over the contact nodes (``−`` the
        mean of ``(c + A_tn p + A_tt t)/Δq`` over the stick nodes). With only ``p`` the
        tangential half is not checked and ``t`` is rollqp's; with only ``t`` the normal half is
        not checked and ``p`` is rollqp's (the friction bound and ``A_tn p`` use it).
    tol : float
        Pass/fail limit on each residual (:data:`DEFAULT_TOL`).
    compare_with : methods
        rollqp methods whose solution of the step the candidate is compared with (default
        :data:`rollqp.methods.COMPARE_METHODS`).
    """
    if not (np.isfinite(tol) and tol > 0):
        raise InputError("--tol", f"must be a finite number > 0, got {tol!r}")
    step = step if isinstance(step, StepFile) else StepFile.load(step)
    sol = (validate_solution(dict(solution), step.n) if isinstance(solution, dict)
           else load_solution(solution, step.n))
    pb, sc = step.problem(), step.scales
    p = sol.get("p", step.ref_p)
    t = sol.get("t", step.ref_t)
    given = tuple(k for k in SOLUTION_KEYS if k in sol)
    notes, fitted = [], []
    delta, xi = _fitted_multipliers(step, pb, sol, p, t, tol, notes, fitted)
    s = pb.slip(p, t, xi)
    res = pb.residuals(p, t, delta, xi)
    checked = []
    if "p" in sol:
        checked += ["signorini", "load_normal"] if pb.P is not None else ["signorini"]
    if "t" in sol:
        checked += ["friction", "load_tangential"] if pb.Q is not None else ["friction"]
    residuals = {c: getattr(res, c) for c in checked}
    failures = [_failure(c, residuals[c], step, pb, p, t, delta, xi, tol) for c in checked if residuals[c] > tol]
    cand_state = classify(p, t, s, step.mu, sc, tol=max(tol, 1e-7))
    comparisons, ref_state = _compare(step, sol, p, t, tol, compare_with, notes)
    differs = np.flatnonzero(cand_state != ref_state)
    return CheckReport(step=step.step, kind=step.kind, step_type=step.step_type, given=given, tol=tol,
                       residuals=residuals, failures=failures,
                       delta=float(delta) if ("p" in sol) else None, xi=float(xi) if ("t" in sol) else None,
                       fitted=tuple(f for f in fitted if (f == "delta" and "p" in sol) or (f == "xi" and "t" in sol)),
                       comparisons=comparisons, state_differs=differs, states=(cand_state, ref_state), x=step.x,
                       notes=notes)


def _fitted_multipliers(step, pb, sol, p, t, tol, notes, fitted):
    """``(δ, ξ)``: prescribed, the candidate's, or fitted (:func:`check_step`); notes and fits appended."""
    sc = step.scales
    ph = p / sc.stress
    delta = pb.delta if pb.delta is not None else sol.get("delta")
    if "delta" in sol and pb.delta is not None:
        notes.append("the step prescribes δ; the candidate's δ is ignored")
    if delta is None:
        closure = pb.h + pb.Ann @ p + (0.0 if pb.Ant is None else pb.Ant @ t)
        contact = ph > tol
        delta = float(np.mean(closure[contact])) if contact.any() else float(np.min(closure))
        fitted.append("delta")
    xi = pb.xi if pb.xi is not None else sol.get("xi")
    if "xi" in sol and pb.xi is not None:
        notes.append("the step prescribes ξ; the candidate's ξ is ignored")
    if xi is None:
        bh = step.mu * np.maximum(p, 0.0) / sc.stress
        w = (pb.c + pb.Att @ t + (0.0 if pb.Atn is None else pb.Atn @ p)) / pb.dq
        stick = (bh - np.abs(t) / sc.stress > tol) & (ph > tol)
        if stick.any():
            xi = float(-np.mean(w[stick]))
            fitted.append("xi")
        else:
            xi = step.ref_xi
            notes.append("no stick node to fit ξ on: rollqp's ξ used")
    return delta, xi


def _failure(c, value, step, pb, p, t, delta, xi, tol) -> Failure:
    """The :class:`Failure` of condition ``c``: the violating nodes, worst first, with why."""
    sc = step.scales
    nodes, reasons, detail = np.array([], dtype=int), [], ""
    if c == "signorini":
        ph, gh = p / sc.stress, pb.gap(p, t, delta) / sc.displacement
        r = np.minimum(ph, gh)
        nodes = np.flatnonzero(np.abs(r) > tol)
        reasons = ["negative pressure" if ph[i] < -tol else "penetration (g < 0)" if gh[i] < -tol
                   else "pressure with the gap open" for i in nodes]
    elif c == "friction":
        th, sh = t / sc.stress, pb.slip(p, t, xi) / sc.slip
        bh = step.mu * np.maximum(p, 0.0) / sc.stress
        r = friction_residual(th, sh, bh)
        nodes = np.flatnonzero(np.abs(r) > tol)
        reasons = ["|t| above the bound mu p" if abs(th[i]) > bh[i] + tol
                   else "slips below the bound (should stick)" if abs(th[i]) < bh[i] - tol
                   else "slip not opposed by t" for i in nodes]
    else:
        load = "P" if c == "load_normal" else "Q"
        got = float(step.f @ (p if c == "load_normal" else t))
        detail = f"f'{'p' if load == 'P' else 't'} = {got:.8g}, {load} = {getattr(pb, load):.8g}"
    if nodes.size:  # worst first
        order = np.argsort(-np.abs(r[nodes]), kind="stable")
        nodes, reasons = nodes[order], [reasons[j] for j in order]
    return Failure(c, value, nodes, reasons, step.x[nodes], detail)


def _compare(step, sol, p, t, tol, compare_with, notes):
    """``(comparisons, reference node states)``: the candidate against rollqp's methods on the step."""
    sc = step.scales
    comparisons, ref_state = {}, None
    for name in compare_with:
        try:
            other = solve_stored(step, name)
        except SolverError as err:
            notes.append(f"{name} failed on this step: {err}")
            continue
        d = {"residual": other.residual}
        if "p" in sol:
            d["p"] = float(np.max(np.abs(p - other.p)) / sc.stress)
        if "t" in sol:
            d["t"] = float(np.max(np.abs(t - other.t)) / (sc.stress * (step.mu or 1.0)))
        comparisons[name] = d
        if ref_state is None:
            ref_state = classify(other.p, other.t, other.s, step.mu, sc, tol=max(tol, 1e-7))
    if ref_state is None:
        ref = step.reference()
        ref_state = classify(ref.p, ref.t, ref.s, step.mu, sc, tol=max(tol, 1e-7))
    return comparisons, ref_state
