r"""Step files: one step of a scene, exported for any solver, and a checker for any solution.

:func:`export_step` marches a scene to step ``K`` and returns a :class:`StepFile`: the step's
data (influence matrices, weights, gap, friction, loads, history vector, scales), the state
before it, rollqp's solution, and the convex QP form of each half (docs/formulation.md §6) in the
arrays a generic QP solver takes. :meth:`StepFile.save` writes it as a ``.npz`` without
pickles, with solver-native files beside it (Clarabel's JSON, a cvxpy script); the keys are
documented in ``docs/stepfiles.md``. :func:`check_step` evaluates a candidate solution with
rollqp's own residuals (docs/formulation.md §5; paper eq. 51–60, 67), compares it with rollqp's
Newton and QP solutions, and says which condition fails at which nodes.

**Step numbering** follows the result file's ``q`` index (docs/results.md): step ``K >= 1`` is the
rolling step whose solution is state ``K`` (``q = K Δq``), solved from state ``K − 1``; step
``0`` is the starting state's last solve (the last static-shift increment of a braked start,
or the steady-rolling solve / last marching step of a rolling start).

**The step problem** is always stored in the coupled form of docs/formulation.md §4 (paper
eq. 63–64)::

    g = h − δ e + A_nn p + A_nt t,          s = ξ e + (c + A_tn p + A_tt t)/Δq,
    p >= 0, g >= 0, p·g = 0,                t = Proj_[−μp⁺, μp⁺](t − s),
    fᵀp = P (or δ given),                   fᵀt = Q (or ξ given).

``kind = "uncoupled"`` when ``A_nt = 0`` (similar materials, or the Goodman level): the normal
half does not see ``t``, and rollqp solves the normal half, then the tangential half at its
pressure. ``kind = "coupled"``: ``A_nt ≠ 0``, a quasi-variational inequality, not a QP.
"""
from __future__ import annotations

import json
import os
from dataclasses import dataclass, field

import numpy as np

from .errors import InputError, SolverError
from .npzfile import read_npz, real_array, real_scalar, text_value
from .problem import SEPARATION, SLIP, STICK, CoupledStep, Scales, StepSolution, classify, friction_residual

FORMAT = "rollqp-step/1"
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
#: Largest step file read (nodes): its four n × n matrices stay below 13 GB.
MAX_NODES = 20001


def export_step(scene, k: int, method: str | None = None) -> "StepFile":
    """March ``scene`` to step ``k`` with ``method`` (default Newton) and return its :class:`StepFile`.

    Parameters
    ----------
    scene : Scene, str or path
        A scene object, a TOML file or a built-in name.
    k : int
        Step number, ``0 <= k <= scene.n_steps`` (module docstring).
    method : str, optional
        Method that marches the scene to step ``k`` (default ``"newton"``, whatever the
        scene's ``[solver].method``); its solution of step ``k`` is stored as ``ref_*``.
    """
    from .march import march, prepare
    from .scene import Scene, load_scene
    scene = scene if isinstance(scene, Scene) else load_scene(scene)
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 0 <= k <= scene.n_steps:
        raise InputError("--step", f"must be an integer step in 0..{scene.n_steps} for scene "
                                   f"{scene.name!r}, got {k!r}")
    method = method or "newton"
    prepared = prepare(scene, method)
    for rec in march(scene, prepared=prepared):
        if rec.k == k:
            break
    if rec.problem is None:
        raise InputError("--step", f"step {k} of scene {scene.name!r} is out of contact (P = 0): nothing is solved there")
    return _from_record(prepared[0], prepared[2], int(k), method, rec)


def from_record(scene, ops, method, rec) -> "StepFile":
    """The :class:`StepFile` of a :class:`~rollqp.march.StepRecord` of ``scene`` (``ops`` its operators)."""
    return _from_record(scene, ops, rec.k, method, rec)


def _from_record(scene, ops, k, method, rec):
    n = ops.n
    problem, sol = rec.problem, rec.solution
    if getattr(problem, "law", None) is not None or np.ndim(problem.mu) != 0:
        raise InputError("contact.friction", "a step file holds one constant coefficient of friction; this scene's "
                                             "friction law (docs/friction.md) cannot be exported")
    if problem.kind == "coupled":
        pb = problem
        ref = sol
    else:  # uncoupled: the normal half in effect and this tangential half, as one CoupledStep
        npb, nsol = rec.normal
        Atn = ops.steady()[0] if rec.phase == "steady" else ops.Atn
        c = problem.c if Atn is None else problem.c - Atn @ problem.p
        pb = CoupledStep(Ann=npb.A, Att=problem.A, Ant=None, Atn=Atn, f=problem.f, h=npb.h_total, mu=problem.mu,
                         c=c, dq=problem.dq, P=npb.P, delta=npb.delta, Q=problem.Q, xi=problem.xi,
                         scales=problem.scales)
        ref = pb.solution(nsol.p, sol.t, nsol.delta, sol.xi)
    zero = np.zeros((n, n))
    prev = rec.previous
    pd = None if prev.nsol is None else prev.nsol.delta
    px = None if prev.tsol is None else prev.tsol.xi
    dense = lambda M: zero if M is None else np.asarray(M)  # noqa: E731
    return StepFile(
        step=k, q=float(scene.q_steps[k]), n_steps=scene.n_steps, kind="coupled" if pb.Ant is not None else "uncoupled",
        x=ops.strip.x.copy(), f=pb.f, h=pb.h, mu=pb.mu, dq=pb.dq, c=pb.c, A_nn=dense(pb.Ann), A_tt=dense(pb.Att),
        A_nt=dense(pb.Ant), A_tn=dense(pb.Atn),
        P=pb.P, Q=pb.Q, delta=pb.delta, xi=pb.xi, a_H=pb.scales.length, p0=pb.scales.stress,
        Estar=pb.scales.modulus,
        prev_p=np.zeros(n) if prev.p is None else np.asarray(prev.p, float), prev_t=np.asarray(prev.t, float),
        prev_delta=np.nan if pd is None else float(pd), prev_xi=np.nan if px is None else float(px),
        ref_p=ref.p, ref_t=ref.t, ref_delta=float(ref.delta), ref_xi=float(ref.xi), ref_method=method,
        ref_residual=float(ref.residual), step_type=rec.phase, scene=scene.to_dict())


# ------------------------------------------------------------------------------ the file
_ARRAYS_N = ("x", "f", "h", "c", "prev_p", "prev_t", "ref_p", "ref_t")
_ARRAYS_NN = ("A_nn", "A_tt", "A_nt", "A_tn")
_SCALARS = ("step", "q", "n_steps", "mu", "dq", "a_H", "p0", "Estar", "prev_delta", "prev_xi", "ref_delta",
            "ref_xi", "ref_residual")
_OPTIONAL = ("P", "Q", "delta", "xi")  # NaN in the file when not prescribed
_STRINGS = ("format", "kind", "step_type", "ref_method", "scene")
STEP_TYPES = ("rolling", "static-shift", "steady")


@dataclass
class StepFile:
    """One step of a scene with rollqp's solution of it (module docstring; ``docs/stepfiles.md``).

    Attributes hold the step's data in the scene's units; :meth:`problem` gives it as a
    :class:`~rollqp.problem.CoupledStep`, :meth:`qp_forms` as QPs, :meth:`save`/:meth:`load`
    read and write the ``.npz``.
    """

    step: int
    q: float
    n_steps: int
    kind: str
    x: np.ndarray
    f: np.ndarray
    h: np.ndarray
    mu: float
    dq: float
    c: np.ndarray
    A_nn: np.ndarray
    A_tt: np.ndarray
    A_nt: np.ndarray
    A_tn: np.ndarray
    P: float | None
    Q: float | None
    delta: float | None
    xi: float | None
    a_H: float
    p0: float
    Estar: float
    prev_p: np.ndarray
    prev_t: np.ndarray
    prev_delta: float
    prev_xi: float
    ref_p: np.ndarray
    ref_t: np.ndarray
    ref_delta: float
    ref_xi: float
    ref_method: str
    ref_residual: float
    step_type: str = "rolling"
    scene: dict = field(default_factory=dict)

    @property
    def n(self) -> int:
        return self.f.size

    @property
    def scales(self) -> Scales:
        return Scales(self.a_H, self.p0, self.Estar)

    def problem(self) -> CoupledStep:
        """The step problem (zero coupling matrices are absent ones: ``None``)."""
        return CoupledStep(Ann=self.A_nn, Att=self.A_tt, Ant=self.A_nt if np.any(self.A_nt) else None,
                           Atn=self.A_tn if np.any(self.A_tn) else None, f=self.f, h=self.h, mu=self.mu, c=self.c,
                           dq=self.dq, P=self.P, delta=self.delta, Q=self.Q, xi=self.xi, scales=self.scales)

    def reference(self) -> StepSolution:
        """rollqp's stored solution, evaluated on :meth:`problem`."""
        sol = self.problem().solution(self.ref_p, self.ref_t, self.ref_delta, self.ref_xi)
        sol.method = self.ref_method
        return sol

    def previous(self) -> StepSolution:
        """The state before the step (a warm start)."""
        d = None if not np.isfinite(self.prev_delta) else self.prev_delta
        x = None if not np.isfinite(self.prev_xi) else self.prev_xi
        return StepSolution(p=self.prev_p, t=self.prev_t, delta=d, xi=x)

    def qp_forms(self) -> dict:
        r"""Each half's QP in scaled variables, at rollqp's solution of the other half.

        Keys ``normal`` and ``tangential``, each a dict: ``P`` (Hessian, the symmetric part of
        the scaled ``F A``), ``skew`` (its skew part: the collocation step is the variational
        inequality with operator ``P + skew``), ``q`` (linear term), ``q_frozen`` (``q + skew
        x_ref``: the one QP whose solution is rollqp's if that is right), ``lb``, ``ub``,
        ``A`` (``(m, n)``, ``m`` = 1 with a load row, else 0), ``b``, ``coupling`` (``∂q/∂x̂``
        of the other half: ``A_nt`` resp. ``A_tn`` scaled), ``x_scale`` (``p = x·x_scale``),
        ``y_scale`` (``δ`` resp. ``ξ`` ``= y·y_scale``, with the Lagrangian
        ``½xᵀPx + qᵀx + y(Ax − b) + …``).
        """
        pb, sc = self.problem(), self.scales
        out = {}
        fh = self.f / sc.length
        for half in ("normal", "tangential"):
            hp = pb.normal_half(self.ref_t) if half == "normal" else pb.tangential_half(self.ref_p)
            form = hp.symmetrized().qp_form()
            den = form.obj_scale * (1.0 if half == "normal" else hp.dq / sc.length)
            M = fh[:, None] * hp.A.dense() * (sc.modulus / sc.length) / den
            skew = 0.5 * (M - M.T)
            other = self.A_nt if half == "normal" else self.A_tn
            coupling = fh[:, None] * other * (sc.stress / sc.displacement) / den
            x_ref = (self.ref_p if half == "normal" else self.ref_t) / sc.stress
            y_unit = sc.displacement if half == "normal" else sc.slip
            sign = -1.0 if half == "normal" else 1.0
            out[half] = dict(P=form.H, skew=skew, q=form.q, q_frozen=form.q + skew @ x_ref, lb=form.lower,
                             ub=form.upper, A=np.zeros((0, self.n)) if form.a is None else form.a[None, :],
                             b=np.zeros(0) if form.a is None else np.array([form.b]), coupling=coupling,
                             x_scale=sc.stress, y_scale=sign * form.obj_scale / form.eq_scale * y_unit)
        return out

    # ---------------------------------------------------------------- I/O
    def arrays(self) -> dict:
        out = {"format": np.asarray(FORMAT), "kind": np.asarray(self.kind), "step_type": np.asarray(self.step_type),
               "ref_method": np.asarray(self.ref_method),
               "scene": np.asarray(json.dumps(self.scene, sort_keys=True))}
        for k in _ARRAYS_N + _ARRAYS_NN:
            out[k] = np.asarray(getattr(self, k), dtype=float)
        for k in _SCALARS:
            out[k] = np.asarray(getattr(self, k))
        for k in _OPTIONAL:
            v = getattr(self, k)
            out[k] = np.asarray(np.nan if v is None else float(v))
        for half, form in self.qp_forms().items():
            for key, v in form.items():
                out[f"{half}_qp_{key}"] = np.asarray(v, dtype=float)
        return out

    def save(self, path, native: bool = True) -> list[str]:
        """Write the ``.npz`` and (``native``) the solver-native files beside it; return the paths.

        ``STEP.npz`` → ``STEP.normal.clarabel.json``, ``STEP.tangential.clarabel.json`` (Clarabel's
        ``load_from_file`` format, the ``q_frozen`` QPs) and ``STEP.cvxpy.py`` (rebuilds both
        halves from the ``.npz`` and solves them; writes ``STEP.cvxpy-solution.npz``).
        """
        from .result import save_npz
        arrays = self.arrays()
        path = save_npz(path, arrays, "step file")
        written = [path]
        if native:
            stem = path[:-4]
            for half in ("normal", "tangential"):
                name = f"{stem}.{half}.clarabel.json"
                with open(name, "w", encoding="utf-8") as fh:
                    json.dump(clarabel_json(arrays, half), fh)
                written.append(name)
            name = f"{stem}.cvxpy.py"
            with open(name, "w", encoding="utf-8") as fh:
                fh.write(cvxpy_script(os.path.basename(path)))
            written.append(name)
        return written

    @classmethod
    def load(cls, path, arg: str = "STEP.npz") -> "StepFile":
        """Read a step file, every key checked (kind, shape, finiteness); its stored QP forms must
        agree with its data. A missing, corrupt or foreign file or a bad key is an :class:`InputError`."""
        z = read_npz(path, arg)
        if "format" not in z or np.asarray(z["format"]).dtype.kind not in "US" or str(z["format"]) != FORMAT:
            raise InputError(arg, f"{os.fspath(path)!r} is not a rollqp step file (key 'format' must be {FORMAT!r})")
        missing = [k for k in _ARRAYS_N + _ARRAYS_NN + _SCALARS + _OPTIONAL + _STRINGS if k not in z]
        if missing:
            raise InputError(arg, f"missing key(s) {', '.join(missing)} in {os.fspath(path)!r}")
        f = np.asarray(z["f"])
        n = f.shape[0] if f.ndim == 1 else 0
        if not 1 <= n <= MAX_NODES:
            raise InputError(arg, f"key 'f' must be a 1-D array of 1 to {MAX_NODES} weights, got shape {f.shape}")
        kw = {k: real_array(z, k, (n,), arg) for k in _ARRAYS_N}
        kw.update({k: real_array(z, k, (n, n), arg) for k in _ARRAYS_NN})
        kw.update({k: real_scalar(z, k, arg, finite=k not in ("prev_delta", "prev_xi")) for k in _SCALARS})
        for k in _OPTIONAL:
            v = real_scalar(z, k, arg, finite=False)
            if np.isinf(v):
                raise InputError(arg, f"key {k!r} must be finite, or NaN when not prescribed; got {v!r}")
            kw[k] = None if np.isnan(v) else v
        for k in ("step", "n_steps"):
            if kw[k] != int(kw[k]) or not 0 <= kw[k] <= 1e9:
                raise InputError(arg, f"key {k!r} must be a whole number >= 0, got {kw[k]!r}")
            kw[k] = int(kw[k])
        kind = text_value(z, "kind", arg, ("coupled", "uncoupled"))
        step_type = text_value(z, "step_type", arg, STEP_TYPES)
        try:
            scene = json.loads(text_value(z, "scene", arg))
        except (json.JSONDecodeError, RecursionError) as exc:
            raise InputError(arg, f"key 'scene' must be a JSON string ({type(exc).__name__})") from exc
        step = cls(kind=kind, step_type=step_type, ref_method=text_value(z, "ref_method", arg)[:100], scene=scene, **kw)
        step.problem()  # validates the data (weights > 0, loads, friction, …)
        step.check_forms(z, arg)
        return step

    def check_forms(self, z: dict, arg: str = "STEP.npz") -> None:
        """The stored QP forms (``normal_qp_*``, ``tangential_qp_*`` in ``z``) are those of this step's data.

        Recomputed from the same data they agree up to the round-off of another BLAS (1e-10 of
        the largest entry); anything else is a corrupt or edited file, an :class:`InputError`.
        """
        for half, form in self.qp_forms().items():
            for key, value in form.items():
                name = f"{half}_qp_{key}"
                value = np.asarray(value, dtype=float)
                stored = real_array(z, name, value.shape, arg, finite=False)
                fin = np.isfinite(value)
                scale = max(1.0, float(np.max(np.abs(value[fin]), initial=0.0)))
                if (not np.array_equal(fin, np.isfinite(stored)) or not np.array_equal(value[~fin], stored[~fin])
                        or np.any(np.abs(value[fin] - stored[fin]) > 1e-10 * scale)):
                    raise InputError(arg, f"key {name!r} does not match the step's own data (a corrupt or edited file)")


def clarabel_json(arrays: dict, half: str) -> dict:
    """One half's ``q_frozen`` QP in the JSON that ``clarabel.load_from_file`` reads.

    Rows as in :mod:`rollqp.methods.qp_clarabel`: the zero cone holds the load row (if any)
    and the nodes without a friction bound (``lb == ub``), the nonnegative cone
    ``x <= ub`` (finite ``ub``) and ``−x <= −lb`` (finite ``lb``). Solver settings are rollqp's
    (:func:`~rollqp.methods.qp_clarabel.clarabel_tolerances` for tolerance 1e-10).
    """
    import scipy.sparse as sp

    from .methods.qp_clarabel import clarabel_rows, clarabel_settings
    from .problem import QPForm
    g = lambda k: arrays[f"{half}_qp_{k}"]  # noqa: E731
    Aeq, beq = g("A"), g("b")
    form = QPForm(H=g("P"), q=g("q_frozen"), lower=g("lb"), upper=g("ub"), a=Aeq[0] if Aeq.shape[0] else None,
                  b=float(beq[0]) if Aeq.shape[0] else None, obj_scale=1.0, eq_scale=1.0, kind=half)
    A, b, cones = clarabel_rows(form)

    def csc(M):
        M = sp.csc_matrix(M)
        M.sort_indices()
        return {"m": int(M.shape[0]), "n": int(M.shape[1]), "colptr": M.indptr.tolist(),
                "rowval": M.indices.tolist(), "nzval": M.data.tolist()}

    settings = clarabel_settings(1e-10)
    settings.pop("iterative_refinement_max_iter")
    return {"P": csc(sp.triu(form.H)), "q": form.q.tolist(), "A": csc(A), "b": b.tolist(),
            "cones": [{name: int(m)} for name, m in cones], "settings": settings}


# ------------------------------------------------------------------------------ solving stored steps
def solve_stored(step: StepFile, method: str, tolerance: float = 1e-10) -> StepSolution:
    """Solve a stored step with any rollqp method, warm-started from the previous state.

    Uncoupled steps: the normal half, then the tangential half at its pressure (as the march
    does). Coupled steps: Newton on the coupled problem; ``nt-newton`` and the QP backends by
    the N–T alternation (paper §6.3). ``info`` holds ``iterations_normal`` and
    ``iterations_tangential`` (inner iterations) besides the method's own.
    """
    from .methods import compose, get_method
    pb = step.problem()
    meth = compose(get_method(method, tolerance=tolerance), pb.Ant is not None)
    warm = step.previous() if np.any(step.prev_p) else None  # none before the first load increment
    if pb.Ant is not None:
        sol = meth.solve(pb, warm=warm)
        sol.info.setdefault("inner_normal", 0)
        sol.info.setdefault("inner_tangential", 0)
        return sol
    nsol = meth.solve(pb.normal_half(np.zeros(pb.n)), warm=warm)
    tsol = meth.solve(pb.tangential_half(nsol.p), warm=warm)
    sol = pb.solution(nsol.p, tsol.t, nsol.delta, tsol.xi, method=method, iterations=nsol.iterations + tsol.iterations,
                      time=nsol.time + tsol.time, solver_time=nsol.solver_time + tsol.solver_time)
    sol.info.update(inner_normal=nsol.iterations, inner_tangential=tsol.iterations,
                    iterations_reported=nsol.info.get("iterations_reported", True)
                    and tsol.info.get("iterations_reported", True))
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


def check_step(step, solution, tol: float = DEFAULT_TOL, compare_with=("newton", "qp-clarabel")) -> CheckReport:
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
        rollqp methods whose solution of the step the candidate is compared with.
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


# ------------------------------------------------------------------------------ the cvxpy script
def cvxpy_script(step_name: str) -> str:
    """The cvxpy script for the step file ``step_name`` (a file name, no folder).

    The name is data, never code: it enters the script as a Python string literal
    (``repr``), and in the docstring only with its characters outside ``[A-Za-z0-9._-]``
    replaced, so no file name can end the docstring or the literal and inject code.
    """
    import re
    shown = re.sub(r"[^A-Za-z0-9._-]", "_", step_name)
    return (CVXPY_SCRIPT.replace("@STEPFILE_LITERAL@", repr(step_name))
            .replace("@STEPFILE_STEM@", shown[:-4] if shown.endswith(".npz") else shown)
            .replace("@STEPFILE@", shown))



CVXPY_SCRIPT = r'''"""Rebuild and solve the step in @STEPFILE@ with cvxpy (written by rollqp export-step).

Self-contained: needs numpy and cvxpy only. Each half of the step is the variational
inequality with operator P + skew (the collocation step; P the symmetric part of the scaled
F·A, docs/formulation.md §8), solved as a sequence of convex QPs with Hessian P and the skew part
moved to the linear term at the previous iterate (q_k = q + skew x_{k-1}); the two halves
alternate (paper §6.3), the other half entering through `coupling` (zero for an uncoupled
step) and the friction bound mu·max(p, 0). Each sweep is one QP per half, from zero. The result is written to the .npz that `rollqp check-step` reads:

    python @STEPFILE_STEM@.cvxpy.py            # -> @STEPFILE_STEM@.cvxpy-solution.npz
    rollqp check-step @STEPFILE@ @STEPFILE_STEM@.cvxpy-solution.npz
"""
import os
import sys
import warnings

import cvxpy as cp
import numpy as np

here = os.path.dirname(os.path.abspath(__file__))
path = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, @STEPFILE_LITERAL@)
z = dict(np.load(path, allow_pickle=False))
TOL = 1e-11  # change of x (p/p0, t/p0) per sweep at which the iteration stops
INACCURATE = [0]  # QPs cvxpy reported "optimal_inaccurate" (Clarabel close to, not at, its 1e-12 tolerances)


def half(name):
    return {k[len(name) + 4:]: v for k, v in z.items() if k.startswith(name + "_qp_")}


def build(d):
    """One cvxpy problem per half, compiled once: q, lb, ub are parameters."""
    n = d["q"].size
    x, q = cp.Variable(n), cp.Parameter(n)
    lb, ub = cp.Parameter(n), cp.Parameter(n)
    eq = [d["A"] @ x == d["b"]] if d["A"].shape[0] else []
    big = 1e6  # finite stand-in for the open upper bound of the pressure (p <= 1e6 p0)
    prob = cp.Problem(cp.Minimize(0.5 * cp.quad_form(x, cp.psd_wrap(d["P"])) + q @ x), eq + [x >= lb, x <= ub])

    def solve(q_value, lo, up):
        q.value, lb.value, ub.value = q_value, lo, np.minimum(up, big)
        for tol in (1e-12, 1e-10, 1e-8):  # tight first (never the defaults); looser if Clarabel stalls
            try:
                with warnings.catch_warnings():  # "optimal_inaccurate" is counted below, not warned per QP
                    warnings.simplefilter("ignore", UserWarning)
                    prob.solve(solver=cp.CLARABEL, tol_gap_abs=tol, tol_gap_rel=tol, tol_feas=tol, tol_ktratio=1e-6)
                break
            except cp.error.SolverError:
                continue
        if prob.status not in ("optimal", "optimal_inaccurate"):
            raise SystemExit(f"cvxpy: {prob.status}")
        # Clarabel stopped short of 1e-12 but close ("almost solved"): kept, and rollqp check-step judges the result
        INACCURATE[0] += prob.status == "optimal_inaccurate"
        return x.value.copy(), (float(eq[0].dual_value[0]) if eq else 0.0)

    return solve


N, T = half("normal"), half("tangential")
solve_n, solve_t = build(N), build(T)
p, t = np.zeros(z["ref_p"].size), np.zeros(z["ref_t"].size)
p_ref, t_ref = z["ref_p"] / N["x_scale"], z["ref_t"] / T["x_scale"]
mu = float(z["mu"])
for it in range(500):
    # normal half: skew part and shear (coupling; zero if uncoupled) at the previous iterate
    p_new, yn = solve_n(N["q"] + N["skew"] @ p + N["coupling"] @ (t - t_ref), N["lb"], N["ub"])
    # tangential half at the new pressure: bound mu·max(p, 0), A_tn p through coupling
    bound = mu * np.maximum(p_new, 0.0) * N["x_scale"] / T["x_scale"]
    t_new, yt = solve_t(T["q"] + T["skew"] @ t + T["coupling"] @ (p_new - p_ref), -bound, bound)
    change = max(np.max(np.abs(p_new - p)), np.max(np.abs(t_new - t)))
    p, t = p_new, t_new
    if change < TOL:
        break
print(f"{it + 1} sweeps, last change {change:.1e}"
      + (f"; {INACCURATE[0]} of {2 * (it + 1)} QPs near, not at, Clarabel's 1e-12 tolerances" if INACCURATE[0] else ""))
out = {"p": p * N["x_scale"], "t": t * T["x_scale"]}
if N["A"].shape[0]:
    out["delta"] = yn * float(N["y_scale"])
if T["A"].shape[0]:
    out["xi"] = yt * float(T["y_scale"])
target = path[:-4] + ".cvxpy-solution.npz"
np.savez(target, **out)
print(f"wrote {target}")
'''
