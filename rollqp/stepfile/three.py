r"""Step files of 3D scenes: one step on the grid, exported for any conic solver, and a checker for any
solution (docs/stepfiles.md, "Three dimensions").

:func:`export_step_3d` marches a 3D scene to step ``K`` and returns a :class:`StepFile3D`: the step's
data on the grid (the dense influence operators ``A_nn``, the slip operator ``B`` of the step, the
coupling operators ``A_nt``, ``A_tn``, the undeformed distance, the history vector, the loads and
creepages, the scales), the state before it, rollqp's solution, and both halves as conic programs in
rollqp's scaled variables (the QP of eq. 3D.22 and the SOCP of eq. 3D.20, each at rollqp's solution of
the other half, with the skew part of a steady operator frozen there). :meth:`StepFile3D.save` writes
the ``.npz`` without pickles and beside it Clarabel's JSON of both halves and a cvxpy script.
:func:`check_step_3d` evaluates a candidate ``(p, t[, δ, ξ, η])`` with rollqp's residuals (eq. 3D.29),
element by element, and names the elements where a condition fails.

The step problem (eq. 3D.14–3D.17) as stored::

    g = h − δ + A_nn p + A_nt t,       p ≥ 0, g ≥ 0, p·g = 0,        area·Σp = FN,
    Δq s = Δq w(ξ, η, φ) + c + A_tn p + B t,   t_i = Proj_{|·| ≤ μ p_i⁺}(t_i − s_i)   (ŝ, t̂ scaled),
    area·Σt_x = Fx (or ξ given),   area·Σt_y = Fy (or η given).

``step_type``: ``"rolling"`` (``B = A_tt``, ``c = −A_tt t' − A_tn p'`` at the previous state shifted by
``d·Δq``), ``"shift"`` (the last static-shift increment of a braked start, ``Δq = c``) or ``"steady"``
(the steady operators, eq. 3D.17, ``Δq = dx``). Step numbering is the result file's: ``K = 0`` is the
starting state.
"""
from __future__ import annotations

import json
import os
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..loads import start_force
from ..march.grid import StepRecord, march, prepare
from ..methods import REFERENCE_METHOD
from ..npzfile import read_npz, real_array, real_scalar, text_value
from ..problem.conic import normal_form, tangential_form
from ..problem.grid import NormalStep, Scales, TangentialStep, disc_projection
from ..result import META_LIMIT
from .file import write_step_files

__all__ = ["FORMAT_3D", "MAX_ELEMENTS_3D", "StepFile3D", "export_step_3d", "check_step_3d", "Check3D",
           "load_solution_3d", "DenseOperator"]

FORMAT_3D = "rollqp-step3d/1"
#: Largest grid a 3D step file holds: its dense ``B`` (2n × 2n) and couplings stay below 1 GB.
MAX_ELEMENTS_3D = 5000
_SCALARS = ("step", "q", "n_steps", "area", "dq", "mu", "phi", "FN", "length", "stress", "modulus", "prev_delta",
            "ref_delta", "ref_xi", "ref_eta", "ref_residual")
_OPTIONAL = ("Fx", "xi", "Fy", "eta")
_STEP_TYPES = ("rolling", "shift", "steady")
SOLUTION_KEYS_3D = ("p", "t", "delta", "xi", "eta")


class DenseOperator:
    """A dense matrix on ``n`` grid elements with the interface the 3D step problems and conic forms use
    (``@``, ``dense(rows, cols)`` with element indices applied to every component, ``memo``, ``shape``)."""

    def __init__(self, M, n: int):
        self.M = np.asarray(M, dtype=float)
        self.shape, self.n = self.M.shape, int(n)
        self._memo = {}

    def __matmul__(self, x):
        return self.M @ np.asarray(x, dtype=float)

    def dense(self, rows=None, cols=None):
        def widen(idx, size):
            if idx is None:
                return np.arange(size)
            idx = np.asarray(idx, dtype=np.intp)
            return np.concatenate([idx + j * self.n for j in range(size // self.n)])
        if rows is None and cols is None:
            return self.M
        return self.M[np.ix_(widen(rows, self.shape[0]), widen(cols, self.shape[1]))]

    def memo(self, key, build):
        if key not in self._memo:
            self._memo[key] = build()
        return self._memo[key]


@dataclass
class StepFile3D:
    """One step of a 3D scene with rollqp's solution of it (module docstring; docs/stepfiles.md)."""

    step: int
    q: float
    n_steps: int
    step_type: str
    x: np.ndarray          # (n,) element centres, flattened (row j = y_j, C order)
    y: np.ndarray
    nx: int
    ny: int
    area: float
    A_nn: np.ndarray       # (n, n)
    B: np.ndarray          # (2n, 2n)
    A_nt: np.ndarray       # (n, 2n)
    A_tn: np.ndarray       # (2n, n)
    h: np.ndarray          # (n,)
    c: np.ndarray          # (2, n): the history, without A_tn p
    dq: float
    mu: float
    phi: float
    FN: float
    Fx: float | None
    xi: float | None
    Fy: float | None
    eta: float | None
    length: float
    stress: float
    modulus: float
    prev_p: np.ndarray
    prev_t: np.ndarray
    prev_delta: float
    ref_p: np.ndarray
    ref_t: np.ndarray
    ref_delta: float
    ref_xi: float
    ref_eta: float
    ref_residual: float
    ref_method: str = ""
    scene: dict = field(default_factory=dict)

    @property
    def n(self) -> int:
        return self.h.size

    @property
    def coupled(self) -> bool:
        return bool(np.any(self.A_nt) or np.any(self.A_tn))

    def scales(self):
        return Scales(self.length, self.stress, self.modulus, dimension=3)

    def normal(self, t):
        """The normal step (eq. 3D.14) at the traction ``t`` (its gap ``A_nt t``)."""
        off = self.A_nt @ np.asarray(t, dtype=float).ravel() if self.coupled else None
        return NormalStep(DenseOperator(self.A_nn, self.n), self.area, self.h, FN=self.FN, offset=off, scales=self.scales())

    def tangential(self, p):
        """The tangential step (eq. 3D.15) at the pressure ``p`` (bound ``μp⁺``, history ``c + A_tn p``)."""
        p = np.asarray(p, dtype=float)
        c = self.c + (self.A_tn @ p).reshape(2, -1) if self.coupled else self.c
        return TangentialStep(DenseOperator(self.B, self.n), self.area, self.mu * np.maximum(p, 0.0), self.x, self.y, c,
                              self.dq, Fx=self.Fx, xi=self.xi, Fy=self.Fy, eta=self.eta, phi=self.phi,
                              scales=self.scales())

    def forms(self) -> dict:
        """Both halves as conic programs (:mod:`rollqp.problem.conic`) at rollqp's solution of the other half."""
        return {"normal": normal_form(self.normal(self.ref_t)), "tangential": tangential_form(self.tangential(self.ref_p))}

    def form_arrays(self) -> dict:
        """``{half}_socp_{H, q, q_frozen, a, b, bound, elements, obj_scale, eq_scale}``: ``q_frozen = q +
        skew·x_ref`` (the one program whose solution is rollqp's if that is right)."""
        sc = self.scales()
        out = {}
        for half, f in self.forms().items():
            V = f.elements
            x_ref = (self.ref_p[V] if half == "normal" else self.ref_t[:, V].ravel()) / sc.stress
            qf = f.q + (f.skew @ x_ref if f.skew is not None else 0.0)
            for k, v in (("H", f.H), ("q", f.q), ("q_frozen", qf), ("a", f.a), ("b", f.b),
                         ("bound", np.zeros(0) if f.bound is None else f.bound), ("elements", V),
                         ("obj_scale", f.obj_scale), ("eq_scale", f.eq_scale)):
                out[f"{half}_socp_{k}"] = np.asarray(v, dtype=float)
        return out

    # ---------------------------------------------------------------- I/O
    def arrays(self) -> dict:
        out = {"format": np.asarray(FORMAT_3D), "step_type": np.asarray(self.step_type),
               "ref_method": np.asarray(self.ref_method), "scene": np.asarray(json.dumps(self.scene, sort_keys=True)),
               "nx": np.asarray(self.nx), "ny": np.asarray(self.ny)}
        for k in ("x", "y", "A_nn", "B", "A_nt", "A_tn", "h", "c", "prev_p", "prev_t", "ref_p", "ref_t"):
            out[k] = np.asarray(getattr(self, k), dtype=float)
        for k in _SCALARS:
            out[k] = np.asarray(float(getattr(self, k)))
        for k in _OPTIONAL:
            v = getattr(self, k)
            out[k] = np.asarray(np.nan if v is None else float(v))
        out.update(self.form_arrays())
        return out

    def save(self, path, native: bool = True) -> list[str]:
        """Write the ``.npz`` and (``native``) ``STEM.normal.clarabel.json``, ``STEM.tangential.clarabel.json``
        (``clarabel.load_from_file``'s format) and ``STEM.cvxpy.py``; return the paths."""
        return write_step_files(path, self.arrays(), native, clarabel_json_3d, cvxpy_script_3d)

    @classmethod
    def load(cls, path, arg: str = "STEP.npz", z: dict | None = None) -> "StepFile3D":
        """Read a 3D step file, every key checked (shape, finiteness, ranges); the stored conic programs must
        be those of its data. A missing, corrupt or foreign file or a bad key is a one-line :class:`InputError`."""
        z = read_npz(path, arg) if z is None else z
        if "format" not in z or np.asarray(z["format"]).dtype.kind not in "US" or str(z["format"]) != FORMAT_3D:
            raise InputError(arg, f"{os.fspath(path)!r} is not a rollqp 3D step file (key 'format' must be "
                                  f"{FORMAT_3D!r})")
        nx, ny = (real_scalar(z, k, arg) for k in ("nx", "ny"))
        if not all(v == int(v) and 1 <= v <= MAX_ELEMENTS_3D for v in (nx, ny)) or nx * ny > MAX_ELEMENTS_3D:
            raise InputError(arg, f"keys 'nx', 'ny' must be whole numbers with nx·ny in 1..{MAX_ELEMENTS_3D}, got "
                                  f"{nx!r}, {ny!r}")
        nx, ny = int(nx), int(ny)
        n = nx * ny
        kw = {k: real_array(z, k, s, arg) for k, s in (
            ("x", (n,)), ("y", (n,)), ("A_nn", (n, n)), ("B", (2 * n, 2 * n)), ("A_nt", (n, 2 * n)),
            ("A_tn", (2 * n, n)), ("h", (n,)), ("c", (2, n)), ("prev_p", (n,)), ("prev_t", (2, n)), ("ref_p", (n,)),
            ("ref_t", (2, n)))}
        kw.update({k: real_scalar(z, k, arg, finite=k != "prev_delta") for k in _SCALARS})
        for k in _OPTIONAL:
            v = real_scalar(z, k, arg, finite=False)
            if np.isinf(v):
                raise InputError(arg, f"key {k!r} must be finite, or NaN when not prescribed; got {v!r}")
            kw[k] = None if np.isnan(v) else v
        for k in ("step", "n_steps"):
            if kw[k] != int(kw[k]) or not 0 <= kw[k] <= 1e9:
                raise InputError(arg, f"key {k!r} must be a whole number >= 0, got {kw[k]!r}")
            kw[k] = int(kw[k])
        for k in ("area", "dq", "length", "stress", "modulus", "FN"):
            if not kw[k] > 0:
                raise InputError(arg, f"key {k!r} must be > 0, got {kw[k]!r}")
        if not 0 <= kw["mu"] <= 10:
            raise InputError(arg, f"key 'mu' must be in [0, 10], got {kw['mu']!r}")
        try:
            scene = json.loads(text_value(z, "scene", arg, limit=META_LIMIT))
        except (json.JSONDecodeError, RecursionError) as exc:
            raise InputError(arg, f"key 'scene' must be a JSON string ({type(exc).__name__})") from exc
        step = cls(nx=nx, ny=ny, step_type=text_value(z, "step_type", arg, _STEP_TYPES),
                   ref_method=text_value(z, "ref_method", arg)[:100], scene=scene if isinstance(scene, dict) else {},
                   **kw)
        try:
            step.normal(step.ref_t)
            step.tangential(step.ref_p)       # validates the data (bounds, loads below the sliding limit, …)
        except InputError as err:
            raise InputError(arg, f"the step's data are not a step problem ({err})") from None
        step._check_forms(z, arg)
        return step

    def _check_forms(self, z, arg):
        for name, value in self.form_arrays().items():
            stored = real_array(z, name, value.shape, arg)
            scale = max(1.0, float(np.max(np.abs(value), initial=0.0)))
            if np.any(np.abs(value - stored) > 1e-10 * scale):
                raise InputError(arg, f"key {name!r} does not match the step's own data (a corrupt or edited file)")


# =========================================================================== export
def export_step_3d(scene, k: int, method: str | None = None) -> StepFile3D:
    """March the 3D ``scene`` to step ``k`` with ``method`` (default the reference method) and return its
    :class:`StepFile3D`."""
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 0 <= k <= scene.n_steps:
        raise InputError("--step", f"must be an integer step in 0..{scene.n_steps} for scene {scene.name!r}, got {k!r}")
    if scene.grid.n > MAX_ELEMENTS_3D:
        raise InputError("discretization.elements", f"a 3D step file holds dense operators of at most "
                                                     f"{MAX_ELEMENTS_3D} elements; this grid has {scene.grid.n}")
    method = method or REFERENCE_METHOD
    prepared = prepare(scene, method)
    scene, meth, contact = prepared
    if contact.law.kind != "constant":   # a law along the surface: μ differs from element to element
        raise InputError("contact.friction", "a 3D step file holds one constant coefficient of friction; this "
                                             "scene's friction law cannot be exported")
    prev: StepRecord | None = None
    rec = None
    for rec in march(scene, prepared=prepared):
        if rec.k == k:
            break
        prev = rec
    ops, g, ld = contact.ops, contact.grid, scene.load
    direction = ld.direction
    if k == 0 and ld.start == "rolling":
        kind, loads, previous, dq = "steady", scene.loads_at(0.0), None, None
        B, Atn = ops.steady("tt", direction), (ops.steady("tn", direction) if ops.coupled else None)
    elif k == 0:
        kind, loads, previous, dq = "shift", rec.info["loads"], rec.info["before"], None
        B, Atn = ops.Att, (ops.Atn if ops.coupled else None)
    else:
        kind, loads, previous, dq = "rolling", scene.loads_at(rec.q), (prev.p, prev.t), scene.dq
        B, Atn = ops.Att, (ops.Atn if ops.coupled else None)
    FN = start_force(scene) if k == 0 else ld.normal
    if "pose" in rec.info:          # a load path's step (rollqp.march.grid): its load, Δq, direction, loads
        kind, FN, dq, direction, loads = rec.info["pose"]
    if rec.FN == 0:
        raise InputError("--step", f"step {k} of {scene.name!r} is out of contact (load.normal_history is 0 there): "
                                   "nothing is solved, there is no step to export")
    tp = contact.tangential_step(kind, rec.p, loads, previous, dq, direction)
    c = tp.c - (Atn @ rec.p).reshape(2, -1) if Atn is not None else tp.c
    n = g.n
    sc = contact.scales
    pp = np.zeros(n) if previous is None else np.asarray(previous[0], float)
    pt = np.zeros((2, n)) if previous is None else np.asarray(previous[1], float).reshape(2, n)
    step = StepFile3D(
        step=int(k), q=float(rec.q), n_steps=scene.n_steps, step_type="shift" if kind == "shift" else kind,
        x=contact.x.copy(), y=contact.y.copy(), nx=g.nx, ny=g.ny, area=g.area, A_nn=ops.Ann.dense(),
        B=B.dense(), A_nt=ops.Ant.dense() if ops.coupled else np.zeros((n, 2 * n)),
        A_tn=Atn.dense() if Atn is not None else np.zeros((2 * n, n)), h=contact.h.copy(), c=c, dq=tp.dq,
        mu=contact.mu, phi=tp.phi, FN=FN, Fx=tp.Fx, xi=tp.xi, Fy=tp.Fy, eta=tp.eta, length=sc.length,
        stress=sc.stress, modulus=sc.modulus, prev_p=pp, prev_t=pt,
        prev_delta=float("nan") if prev is None else float(prev.delta), ref_p=np.asarray(rec.p, float),
        ref_t=np.asarray(rec.t, float).reshape(2, n), ref_delta=float(rec.delta), ref_xi=float(rec.xi),
        ref_eta=float(rec.eta), ref_residual=0.0, ref_method=meth.name, scene=scene.to_dict())
    step.ref_residual = check_step_3d(step, {"p": step.ref_p, "t": step.ref_t, "delta": step.ref_delta,
                                             "xi": step.ref_xi, "eta": step.ref_eta}).worst
    return step


# =========================================================================== check
@dataclass
class Check3D:
    """The verdict on a candidate: rollqp's residuals (max over the elements), the elements where each
    condition fails (flattened indices, with their ``(x, y)``), the fitted unknowns, and the distance from
    rollqp's stored solution."""

    step: int
    step_type: str
    tol: float
    residuals: dict
    failed: dict
    fitted: tuple
    delta: float
    xi: float
    eta: float
    dp: float
    dt: float
    where: dict = field(default_factory=dict)

    @property
    def passed(self) -> bool:
        return not self.failed

    @property
    def worst(self) -> float:
        return max(self.residuals.values())

    def diagnosis(self) -> list[str]:
        out = []
        for cond, idx in self.failed.items():
            if cond.startswith("load"):
                out.append(f"{cond}: residual {self.residuals[cond]:.3g} > {self.tol:g}")
                continue
            xs = ", ".join(f"({x:.4g}, {y:.4g})" for x, y in self.where[cond][:5])
            out.append(f"{cond}: {len(idx)} element(s) above {self.tol:g} (worst {self.residuals[cond]:.3g}) at (x, y) = "
                       f"{xs}{' …' if len(idx) > 5 else ''}")
        return out

    def __str__(self) -> str:
        L = [f"rollqp check-step: 3D step {self.step} ({self.step_type}), tolerance {self.tol:g}",
             "  rollqp residuals (nondimensional, docs/theory3d.md §10):"]
        L += [f"    {k:<14} {v:.3e}  {'FAIL' if k in self.failed else 'ok'}" for k, v in self.residuals.items()]
        fit = f" (fitted: {', '.join(self.fitted)})" if self.fitted else ""
        L.append(f"  unknowns: delta = {self.delta:.10g}, xi = {self.xi:.6g}, eta = {self.eta:.6g}{fit}")
        L.append(f"  against rollqp's stored solution: max |dp| {self.dp:.2e} p0, |dt| {self.dt:.2e} mu p0")
        L.append("  verdict: " + ("PASS" if self.passed else "FAIL: " + "; ".join(self.diagnosis())))
        return "\n".join(L)


def load_solution_3d(path, n: int, arg: str = "SOLUTION.npz") -> dict:
    """A candidate from a ``.npz``: ``p`` (n,) and ``t`` (2, n) in the scene's units (flattened in the grid's C
    order), optionally ``delta``, ``xi``, ``eta``."""
    return validate_solution_3d(read_npz(path, arg), n, arg)


def validate_solution_3d(sol: dict, n: int, arg: str = "solution") -> dict:
    if "format" in sol:
        raise InputError(arg, "this is a step file, not a solution (keys p, t, delta, xi, eta)")
    unknown = sorted(set(sol) - set(SOLUTION_KEYS_3D))
    if unknown:
        raise InputError(arg, f"unknown key(s) {', '.join(map(repr, unknown[:5]))}; allowed: {', '.join(SOLUTION_KEYS_3D)}")
    for k in ("p", "t"):
        if k not in sol:
            raise InputError(arg, f"missing key {k!r}: a 3D candidate gives the pressure p (n,) and the traction t (2, n)")
    out = {"p": real_array(sol, "p", (n,), arg), "t": real_array(sol, "t", (2, n), arg)}
    out.update({k: real_scalar(sol, k, arg) for k in ("delta", "xi", "eta") if k in sol})
    return out


def _fit_delta(pb, p):
    on = p > 1e-6 * float(np.max(p, initial=0.0))     # an interior point's separated elements: p ~ 1e-12 p0
    g0 = pb.h_total + pb.A @ p
    return float(np.mean(g0[on])) if on.any() else float(np.min(g0))


def _fit_creep(tp, t, which):
    """The creepage that makes the slip vanish on average over the stick elements (``|t| < bound``), least
    squares; with none, over the elements in contact."""
    Bt = (tp.B @ t.ravel()).reshape(2, -1)
    w = (tp.c + Bt) / tp.dq
    rig = np.stack([-tp.phi * tp.y, tp.phi * tp.x])
    stick = (np.hypot(t[0], t[1]) < (1 - 1e-4) * tp.bound) & (tp.bound > 0)   # off the rim by more than round-off
    sel = stick if stick.any() else tp.bound > 0
    j = 0 if which == "xi" else 1
    return float(-np.mean((w[j] + rig[j])[sel])) if sel.any() else 0.0


def check_step_3d(step, solution, tol: float = 1e-8) -> Check3D:
    """Evaluate a candidate solution of a stored 3D step with rollqp's residuals, element by element.

    ``solution``: a dict or a ``.npz`` path with ``p`` (n,), ``t`` (2, n) and optionally ``delta``, ``xi``,
    ``eta``; a missing unknown is fitted (``δ``: the mean of ``h + A_nt t + A_nn p`` over the contact; a
    creepage: the one that makes the mean slip over the stick elements vanish) and named in the report.
    """
    if isinstance(tol, bool) or not (isinstance(tol, (int, float)) and np.isfinite(tol) and tol > 0):
        raise InputError("--tol", f"must be a finite number > 0, got {tol!r}")
    step = step if isinstance(step, StepFile3D) else StepFile3D.load(step)
    sol = (validate_solution_3d(dict(solution), step.n) if isinstance(solution, dict)
           else load_solution_3d(solution, step.n))
    p, t = sol["p"], sol["t"]
    npb, tpb = step.normal(t), step.tangential(p)
    fitted = []
    delta = sol.get("delta")
    if delta is None:
        delta, _ = _fit_delta(npb, p), fitted.append("delta")
    xi, eta = tpb.xi, tpb.eta
    if xi is None:
        xi = sol.get("xi")
        if xi is None:
            xi, _ = _fit_creep(tpb, t, "xi"), fitted.append("xi")
    if eta is None:
        eta = sol.get("eta")
        if eta is None:
            eta, _ = _fit_creep(tpb, t, "eta"), fitted.append("eta")
    sc = step.scales()
    g = npb.gap(p, delta)
    sig = np.abs(np.minimum(p / sc.stress, g / sc.displacement))
    s = tpb.slip(t, xi, eta)
    th, sh, bh = t / sc.stress, s / sc.slip, tpb.bound / sc.stress
    r = th - disc_projection(th - sh, bh)
    fric = np.hypot(r[0], r[1])
    nres, tres = npb.residuals(p, delta, g), tpb.residuals(t, xi, eta, s)
    residuals = {"signorini": float(sig.max()), "friction": float(fric.max()), "load_normal": nres.load_normal,
                 "load_x": tres.load_tangential, "load_y": tres.load_lateral}
    failed, where = {}, {}
    for cond, per in (("signorini", sig), ("friction", fric)):
        idx = np.flatnonzero(per > tol)
        if idx.size:
            idx = idx[np.argsort(-per[idx])]
            failed[cond], where[cond] = idx, list(zip(step.x[idx], step.y[idx]))
    for cond in ("load_normal", "load_x", "load_y"):
        if residuals[cond] > tol:
            failed[cond] = np.zeros(0, int)
    dp = float(np.max(np.abs(p - step.ref_p))) / sc.stress
    dt = float(np.max(np.abs(t - step.ref_t))) / (max(step.mu, 1e-300) * sc.stress)
    return Check3D(step.step, step.step_type, float(tol), residuals, failed, tuple(fitted), float(delta), float(xi),
                   float(eta), dp, dt, where)


# =========================================================================== native files
def clarabel_json_3d(arrays: dict, half: str) -> dict:
    """One half's program (``q_frozen``) in the JSON that ``clarabel.load_from_file`` reads: the load rows
    (zero cone), then ``x ≥ 0`` (normal, nonnegative cone) or one ``(b̂_i, t̂_x,i, t̂_y,i) ∈ Q³`` per element
    (tangential), the rows of :mod:`rollqp.methods.socp`; rollqp's tolerances for 1e-10."""
    import scipy.sparse as sp
    g = lambda k: arrays[f"{half}_socp_{k}"]  # noqa: E731
    H, q, a, b = g("H"), g("q_frozen"), g("a"), g("b")
    m, k = q.size, a.shape[0]
    if half == "normal":
        A = sp.vstack([sp.csr_matrix(a), -sp.identity(m)], format="csc")
        rhs = np.concatenate([b, np.zeros(m)])
        cones = ([{"ZeroConeT": int(k)}] if k else []) + [{"NonnegativeConeT": int(m)}]
    else:
        nv = m // 2
        i = np.arange(nv)
        soc = sp.csr_matrix((-np.ones(2 * nv), (np.concatenate([3 * i + 1, 3 * i + 2]), np.concatenate([i, nv + i]))),
                            shape=(3 * nv, m))
        r = np.zeros(3 * nv)
        r[3 * i] = g("bound")
        A = sp.vstack([sp.csr_matrix(a.reshape(k, m)), soc], format="csc")
        rhs = np.concatenate([b, r])
        cones = ([{"ZeroConeT": int(k)}] if k else []) + [{"SecondOrderConeT": 3}] * nv

    def csc(M):
        M = sp.csc_matrix(M)
        M.sort_indices()
        return {"m": int(M.shape[0]), "n": int(M.shape[1]), "colptr": M.indptr.tolist(), "rowval": M.indices.tolist(),
                "nzval": M.data.tolist()}
    gap = 1e-13      # as rollqp's Clarabel (rollqp.methods.socp): at 1e-14 it stops "AlmostSolved"
    settings = {"max_iter": 200, "tol_gap_abs": gap, "tol_gap_rel": gap, "tol_feas": gap, "tol_ktratio": gap,
                "presolve_enable": False, "verbose": False}
    return {"P": csc(sp.triu(sp.csc_matrix(H))), "q": q.tolist(), "A": csc(A), "b": rhs.tolist(), "cones": cones,
            "settings": settings}


def cvxpy_script_3d(step_name: str) -> str:
    """The cvxpy script for the 3D step file ``step_name``: the name enters only as a string literal (``repr``)
    and, outside ``[A-Za-z0-9._-]`` replaced, in the docstring (no name can inject code)."""
    import re
    shown = re.sub(r"[^A-Za-z0-9._-]", "_", step_name)
    stem = shown[:-4] if shown.endswith(".npz") else shown
    return (_SCRIPT.replace("@LITERAL@", repr(step_name)).replace("@STEM@", stem).replace("@SHOWN@", shown))


_SCRIPT = r'''"""Rebuild and solve the 3D step in @SHOWN@ with cvxpy (written by rollqp export-step).

Needs numpy and cvxpy. The normal half is the QP of eq. 3D.22, the tangential half the SOCP of
eq. 3D.20 with one second-order cone per element, each at rollqp's solution of the other half and
with the skew part of a steady operator frozen there (q_frozen). The pressure and traction are
written to the .npz that `rollqp check-step` reads (it fits the approach and the creepages):

    python @STEM@.cvxpy.py            # -> @STEM@.cvxpy-solution.npz
    rollqp check-step @SHOWN@ @STEM@.cvxpy-solution.npz
"""
import os
import sys

import cvxpy as cp
import numpy as np

here = os.path.dirname(os.path.abspath(__file__))
path = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, @LITERAL@)
z = dict(np.load(path, allow_pickle=False))
n = z["h"].size


def half(name):
    d = {k[len(name) + 6:]: v for k, v in z.items() if k.startswith(name + "_socp_")}
    m = d["q_frozen"].size
    x = cp.Variable(m)
    cons = [d["a"] @ x == d["b"]] if d["a"].shape[0] else []
    if name == "normal":
        cons.append(x >= 0)
    else:
        nv = m // 2
        cons.append(cp.SOC(d["bound"], cp.vstack([x[:nv], x[nv:]]), axis=0))
    obj = 0.5 * cp.quad_form(x, cp.psd_wrap(d["H"])) + d["q_frozen"] @ x
    cp.Problem(cp.Minimize(obj), cons).solve(solver=cp.CLARABEL, tol_gap_abs=1e-12, tol_gap_rel=1e-12,
                                             tol_feas=1e-12)
    # the load rows' multipliers are the unknowns (eq. 3D.21): -delta and the creepages, in rollqp's scales
    y = cons[0].dual_value * d["obj_scale"] / d["eq_scale"] if d["a"].shape[0] else np.zeros(0)
    return x.value, d["elements"].astype(int), np.atleast_1d(y)


xp, Vn, yn = half("normal")
xt, Vt, yt = half("tangential")
u0 = float(z["length"]) * float(z["stress"]) / float(z["modulus"])
extra = {"delta": -float(yn[0]) * u0}
rows = [k for k, f in (("xi", "Fx"), ("eta", "Fy")) if np.isfinite(z[f])]   # the creepages of the force rows
extra.update({k: float(v) * float(z["stress"]) / float(z["modulus"]) for k, v in zip(rows, yt)})
p = np.zeros(n)
p[Vn] = xp * float(z["stress"])
t = np.zeros((2, n))
nv = Vt.size
t[0, Vt], t[1, Vt] = xt[:nv] * float(z["stress"]), xt[nv:] * float(z["stress"])
out = os.path.splitext(path)[0] + ".cvxpy-solution.npz"
np.savez(out, p=p, t=t, **extra)
print("wrote", out)
'''
