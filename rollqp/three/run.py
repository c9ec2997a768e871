r"""A 3D scene's run: its contact built once, the starting state, the rolling steps, the result
(docs/scenes.md, "Three dimensions"; docs/theory3d.md §4, §6).

The 3D counterpart of :func:`rollqp.march.march` and :func:`rollqp.march.run`, with the same
arguments and the same meaning:

* **starting state** (record ``k = 0``): ``load.start = "braked"`` — the normal force, then the
  tangential forces in ``load.start_steps`` static shift steps (Cattaneo–Mindlin for similar bodies,
  :func:`rollqp.three.march.static_shift`; phase ``"shift"``); ``"rolling"`` — the steady state at
  the loads of ``q = 0`` (:func:`rollqp.three.march.steady`: directly by a method whose record
  solves ``"steady"``, by the march to the fixed point otherwise; phase ``"steady"``);
* **rolling steps** ``k = 1 … K`` of ``Δq = step·dx`` at the loads of ``q_k`` (phase ``"rolling"``).

Dissimilar bodies (``K ≠ 0``) run every step as the normal–tangential alternation of the method's
own halves (:func:`rollqp.three.march.coupled_step`).
"""
from __future__ import annotations

import functools
import json
from typing import Iterator

import numpy as np

from ..errors import InputError, SolverError
from ..scene import load_scene
from ..scene.core import SceneBase
from .contact import Contact
from .patch import moving_profile
from .march import StepRecord, static_shift, steady, transient
from .result import Result3D

__all__ = ["prepare", "march", "run", "new_result", "resumed_record", "resume_arrays"]


def prepare(scene, method=None):
    """``(scene, method, contact)``: the 3D scene validated, its method made and set up, its contact
    (grid, operators, Hertz ellipse) built once.

    ``method``: a name (overrides ``solver.method``) or a method object (checked by its record,
    :func:`rollqp.methods.compose_3d`).
    """
    from ..methods import compose_3d, scene_method_3d
    scene = scene if isinstance(scene, SceneBase) else load_scene(scene)
    if scene.dimension != 3:
        raise InputError("contact.dimension", "rollqp.three.run runs 3D scenes; this one is "
                                              f"{scene.dimension}D (rollqp.run runs either)")
    if isinstance(method, str) and method != scene.solver.method:
        scene = scene.replace(**{"solver.method": method})
    meth = scene_method_3d(scene.solver) if method is None or isinstance(method, str) else compose_3d(method)
    contact = Contact(scene.grid, scene.materials, scene.curvatures, scene.load.normal, scene.mu,
                      profile=None if scene.shape.hertzian else scene.shape.at(0.0))
    if scene.shape.moves:      # a feature rolls through: the march moves the profile with the material
        contact.move = moving_profile(contact, scene.shape, scene.load.direction)
    meth.setup(contact)
    return scene, meth, contact


def _start(scene, meth, contact) -> StepRecord:
    ld = scene.load
    if ld.start == "rolling":
        return steady(contact, meth, ld.normal, scene.loads_at(0.0), direction=ld.direction)
    loads = scene.loads_at(0.0)
    if loads.xi is not None or loads.eta is not None:
        raise InputError("load.start", "a braked start shifts the bodies by the tangential forces: prescribe "
                                       "load.tangential and load.lateral (or start = \"rolling\")")
    return static_shift(contact, meth, ld.normal, loads.Fx, loads.Fy, loads.phi, steps=ld.start_steps)[-1]


def march(scene, method=None, *, prepared=None, resume=None) -> Iterator[StepRecord]:
    """The 3D run as a stream of :class:`~rollqp.three.march.StepRecord`: ``k = 0`` (the starting
    state), then the rolling steps (module docstring); with ``resume`` (the arrays of an earlier
    result file of this scene) only the steps after its last state.

    Raises
    ------
    SolverError
        A step failed; ``err.step`` names it (0: the start).
    """
    scene, meth, contact = prepared if prepared is not None else prepare(scene, method)
    if resume is not None:
        start, first = resumed_record(scene, contact, resume), len(resume["q"])
    else:
        try:
            start = _start(scene, meth, contact)
        except SolverError as err:
            raise (err.with_step(0) if err.step is None else err) from err
        first = 1
    records = transient(contact, meth, scene.load.normal, scene.loads_at, scene.dq, scene.n_steps,
                        scene.load.direction, start=start, first=first)
    head = next(records)
    if resume is None:
        yield head
    yield from records


def resumed_record(scene, contact, arrays: dict) -> StepRecord:
    """The last state of a 3D result file of ``scene``, as the run continues from it."""
    g = scene.grid
    if arrays["pn"].shape[1:] != g.shape or not np.allclose(arrays["x"], g.x, rtol=0, atol=1e-12 * g.dx * g.nx):
        raise InputError("--resume", "the result file's grid is not this scene's: another scene")
    k = len(arrays["q"]) - 1
    if k > scene.n_steps:
        raise InputError("--resume", f"the result file has {k} rolling steps, the scene {scene.n_steps}")
    p = np.asarray(arrays["pn"][-1], dtype=float).ravel()
    t = np.stack([np.asarray(arrays[c][-1], dtype=float).ravel() for c in ("px", "py")])
    s = np.stack([np.asarray(arrays[c][-1], dtype=float).ravel() for c in ("sx", "sy")])
    xi, eta, phi = (float(v) for v in arrays["creepage"][-1])
    return StepRecord(k, "resumed", float(arrays["q"][-1]), p, np.zeros_like(p), t, s,
                      np.asarray(arrays["state"][-1]).ravel(), float(arrays["FN"][-1]), float(arrays["Fx"][-1]),
                      float(arrays["Fy"][-1]), float(arrays["Mz"][-1]), xi, eta, phi, float(arrays["approach"][-1]),
                      0, 0.0, float(arrays["residual"][-1]))


def new_result(scene, contact, method_name: str, out=None) -> Result3D:
    """An empty :class:`~rollqp.three.result.Result3D` with the scene's scalars and metadata (``out``: its
    result file, journaled as the run goes)."""
    from ..version import __version__
    e = scene.ellipse
    meta = {"scene": scene.to_dict(), "method": method_name, "rollqp": __version__, "versions": dict(_versions()),
            "dimension": 3, "dq": scene.dq, "elements": int(contact.grid.n), "coupled": bool(contact.ops.coupled),
            "slip_note": ("state 0 of a braked start: static-shift slip per c = sqrt(ab) of shift"
                          if scene.load.start == "braked" else "state 0: the steady state")}
    return Result3D(contact.grid, {"a": e.a, "b": e.b, "p0": e.p0, "Estar": e.Estar}, meta, out=out)


@functools.lru_cache(maxsize=1)
def _versions() -> tuple:
    """The package versions recorded in a result's meta (read once per process)."""
    import importlib.metadata as md
    out = []
    for pkg in ("numpy", "scipy", "clarabel", "osqp", "cvxpy"):
        try:
            out.append((pkg, md.version(pkg)))
        except md.PackageNotFoundError:
            out.append((pkg, None))
    return tuple(out)


def _raw_distance(meta: dict, rec: StepRecord, contact) -> None:
    """A conic method's raw answers (the solver's own, before the active-set refinement,
    :mod:`rollqp.three.refine`) against the refined ones the run keeps: the largest distance over the
    run in ``meta["raw_distance"]`` (``dp`` in p0, ``dt`` in μp0, ``steps`` compared); nothing for a
    method without a raw answer (Newton)."""
    sc = contact.scales
    rp, rt = (rec.info.get(part, {}).get("raw") for part in ("normal", "tangential"))
    if rp is None and rt is None:
        return
    row = meta.setdefault("raw_distance", {"dp": 0.0, "dt": 0.0, "steps": 0})
    if rp is not None:
        row["dp"] = max(row["dp"], float(np.max(np.abs(rp["p"] - rec.p))) / sc.stress)
    if rt is not None:
        row["dt"] = max(row["dt"], float(np.max(np.abs(rt["t"] - rec.t))) / ((contact.mu or 1.0) * sc.stress))
    row["steps"] += 1


def resume_arrays(resume):
    """The arrays to continue from: ``resume`` is the arrays of a result file (a dict,
    :func:`rollqp.load_result`) or what ``rollqp run --resume`` read (:func:`rollqp.result.resume_source`:
    a 3D run writes its result file, no journal), or None."""
    if resume is None or isinstance(resume, dict):
        return resume
    if resume.journal is not None:      # a killed run's journal (it holds more than the result file)
        from .result import journal_arrays
        return journal_arrays(resume.journal)
    return resume.arrays


def _started(result, resume) -> None:
    """A resumed run's result: the earlier states, and what state 0 and the earlier steps noted. With a
    result file, the earlier states are written to it first, so that they are on disk while the new
    journal is filled (a run killed then resumes from the file)."""
    if result.out is not None:
        earlier = Result3D(result.grid, result.scalars, dict(result.meta))
        earlier.extend(resume)
        earlier.save(result.out)
    result.extend(resume)
    result.meta["resumed_from"] = len(result) - 1
    earlier = resume.get("meta", {})
    earlier = earlier if isinstance(earlier, dict) else json.loads(str(earlier))
    for key in ("static_shift", "rolling_start", "raw_distance"):
        if key in earlier:
            result.meta[key] = earlier[key]


def _noted(result, rec, contact) -> None:
    """What a record adds to the result's notes (``meta``)."""
    if rec.k == 0 and "marched" in rec.info:
        result.meta["rolling_start"] = f"marched to the steady state in {rec.info['marched']} steps"
    if rec.k == 0 and "shift" in rec.info:
        result.meta["static_shift"] = [float(v) for v in rec.info["shift"]]
    _raw_distance(result.meta, rec, contact)


def run(scene, method=None, progress=None, resume=None, observe=None, out=None, keep_every=None) -> Result3D:
    """Run a 3D scene and return its :class:`~rollqp.three.result.Result3D` (arguments as
    :func:`rollqp.march.run`: ``progress(k, K)`` after each rolling step, ``observe(record, contact)``
    with every record, ``resume`` an earlier result file's arrays or :func:`resume_arrays`' source,
    ``out`` the result file: every state journaled as it is completed (``out.journal``: a run killed
    even by SIGKILL loses at most the state in flight), the file written at the end — and, with the
    completed states and the reason in ``meta["failed"]`` or ``meta["interrupted"]``, when the run
    fails or is interrupted).
    ``keep_every``: a 3D run keeps every state (None or 1).

    Raises
    ------
    SolverError, InputError, KeyboardInterrupt
        ``err.partial`` holds the result of the completed states.
    """
    if keep_every not in (None, 1):
        raise InputError("--keep-every", f"a 3D run keeps every state (1), got {keep_every!r}")
    resume = resume_arrays(resume)
    asked = scene if isinstance(scene, SceneBase) else load_scene(scene)
    scene, meth, contact = prepared = prepare(asked, method)
    result = new_result(scene, contact, meth.name, out)
    if resume is not None:
        _started(result, resume)
    K = scene.n_steps
    try:
        for rec in march(scene, prepared=prepared, resume=resume):
            result.add(rec)
            _noted(result, rec, contact)
            if observe is not None:
                observe(rec, contact)
            if progress is not None and rec.k > 0:
                progress(rec.k, K)
    except (SolverError, InputError, KeyboardInterrupt) as err:
        err.partial = result
        if out is not None and len(result):
            result.finish({"interrupted" if isinstance(err, KeyboardInterrupt) else "failed": str(err) or "interrupted"})
        raise
    result.finish()
    return result
