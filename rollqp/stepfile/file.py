"""The step file: :class:`StepFile` (its arrays, the ``.npz`` written without pickles, read back with checks) and
Clarabel's JSON of one half (docs/stepfiles.md)."""
from __future__ import annotations

import json
import os
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError, RollqpError
from ..npzfile import read_npz, real_array, real_scalar, text_value
from ..problem import CoupledStep, QPForm, Scales, StepSolution
from ..result import META_LIMIT, save_npz
from ..scene import load_scene
from .script import cvxpy_script

__all__ = ["FORMAT", "MAX_NODES", "STEP_TYPES", "StepFile", "clarabel_json"]

FORMAT = "rollqp-step/1"
#: Largest step file read (nodes): its four n × n matrices stay below 13 GB.
MAX_NODES = 20001

_ARRAYS_N = ("x", "f", "h", "c", "prev_p", "prev_t", "ref_p", "ref_t")
_ARRAYS_NN = ("A_nn", "A_tt", "A_nt", "A_tn")
_SCALARS = ("step", "q", "n_steps", "mu", "dq", "a_H", "p0", "Estar", "prev_delta", "prev_xi", "ref_delta",
            "ref_xi", "ref_residual")
_OPTIONAL = ("P", "Q", "delta", "xi")  # NaN in the file when not prescribed
_STRINGS = ("format", "kind", "step_type", "ref_method", "scene")
STEP_TYPES = ("rolling", "static-shift", "steady")



def write_step_files(path, arrays: dict, native: bool, clarabel_json, cvxpy_script) -> list[str]:
    """Write a step file's ``.npz`` and (``native``) ``STEM.normal.clarabel.json``,
    ``STEM.tangential.clarabel.json`` and ``STEM.cvxpy.py`` beside it, from the dimension's writers
    ``clarabel_json(arrays, half)`` and ``cvxpy_script(npz_name)``; return the paths (both dimensions)."""
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
        return write_step_files(path, self.arrays(), native, clarabel_json, cvxpy_script)

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
        try:  # a scene file's size (its profile tables inline): the limit of a result file's meta
            scene = json.loads(text_value(z, "scene", arg, limit=META_LIMIT))
        except (json.JSONDecodeError, RecursionError) as exc:
            raise InputError(arg, f"key 'scene' must be a JSON string ({type(exc).__name__})") from exc
        _check_scales(kw, scene, arg)
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
    # scipy.sparse and clarabel behind it (heavy): loaded for a step file's Clarabel JSON only
    from ..methods.qp_clarabel import clarabel_rows, clarabel_settings
    import scipy.sparse as sp

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


def _check_scales(kw: dict, scene, arg: str) -> None:
    """A step file's scales (``a_H``, ``p0``, ``Estar``) are its scene's, and its previous state's approach and
    creepage (a warm start) are within reach of them: every form, residual and solve divides by them, so an
    edited one is an error naming the key, not an overflow or a NaN."""
    try:
        sc = load_scene(scene)
    except RollqpError as err:
        raise InputError(arg, f"key 'scene' is not a valid scene ({str(err)[:200]})") from None
    for key, value in (("a_H", sc.a_H), ("p0", sc.p0), ("Estar", sc.Estar)):
        if not abs(kw[key] - value) <= 1e-9 * value:
            raise InputError(arg, f"key {key!r} = {kw[key]!r} is not the {key} of the file's scene ({value:.6g}): "
                                  "a corrupt or edited file")
    for key, limit in (("prev_delta", 1e6 * sc.a_H), ("prev_xi", 1e3)):  # (NaN: not known, allowed)
        if abs(kw[key]) > limit:
            raise InputError(arg, f"key {key!r} = {kw[key]!r} is beyond any previous state (|{key}| <= {limit:.3g})")
