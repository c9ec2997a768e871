"""One step of a scene as a :class:`~.file.StepFile`: marched to it (:func:`export_step`) or taken from a record (:func:`from_record`)."""
from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..march import march, prepare
from ..methods import REFERENCE_METHOD
from ..problem import CoupledStep
from ..scene import Scene, load_scene
from .file import StepFile

__all__ = ["export_step", "from_record"]


def export_step(scene, k: int, method: str | None = None) -> "StepFile":
    """March ``scene`` to step ``k`` with ``method`` (default Newton) and return its :class:`StepFile`.

    Parameters
    ----------
    scene : Scene, str or path
        A scene object, a TOML file or a built-in name.
    k : int
        Step number, ``0 <= k <= scene.n_steps`` (module docstring).
    method : str, optional
        Method that marches the scene to step ``k`` (default the reference method,
        :data:`rollqp.methods.REFERENCE_METHOD`, whatever the scene's ``[solver].method``); its solution of
        step ``k`` is stored as ``ref_*``.
    """
    scene = scene if isinstance(scene, Scene) else load_scene(scene)
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 0 <= k <= scene.n_steps:
        raise InputError("--step", f"must be an integer step in 0..{scene.n_steps} for scene "
                                   f"{scene.name!r}, got {k!r}")
    method = method or REFERENCE_METHOD
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
    if problem.law is not None or np.ndim(problem.mu) != 0:
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
