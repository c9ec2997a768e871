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

import dataclasses
import functools
import os
from typing import Iterator

import numpy as np

from ..atomic import stop_once
from ..errors import InputError, SolverError
from ..fields import fields_for
from ..march import RESUME_TOL, _keep_every, _last_index, drive
from ..friction import law_kind
from ..methods import compose_3d, scene_method_3d
from ..result import Layout, Result, ResumeSource, check_output, resume_source
from ..scene import load_scene
from ..scene.core import SceneBase
from ..version import __version__
from ..operators.grid import Contact
from ..loadpath import out_of_contact, rolling_steps
from ..loads import start_force
from ..patch import moving_profile
from .march import StepRecord, _states, static_shift, steady

__all__ = ["prepare", "march", "run", "new_result", "resumed_record", "check_resumed", "check_states", "GRID"]


def prepare(scene, method=None):
    """``(scene, method, contact)``: the 3D scene validated, its method made and set up, its contact
    (grid, operators, Hertz ellipse) built once.

    ``method``: a name (overrides ``solver.method``) or a method object (checked by its record,
    :func:`rollqp.methods.compose_3d`).
    """
    scene = scene if isinstance(scene, SceneBase) else load_scene(scene)
    if scene.dimension != 3:
        raise InputError("contact.dimension", "rollqp.three.run runs 3D scenes; this one is "
                                              f"{scene.dimension}D (rollqp.run runs either)")
    if isinstance(method, str) and method != scene.solver.method:
        scene = scene.replace(**{"solver.method": method})
    kind = law_kind(scene.contact.friction)
    meth = (scene_method_3d(scene.solver, friction=kind) if method is None or isinstance(method, str)
            else compose_3d(method, friction=kind))
    contact = Contact(scene.grid, scene.materials, scene.curvatures, scene.load.normal, scene.contact.friction,
                      profile=None if scene.shape.hertzian else scene.shape.at(0.0), model=scene.contact.model,
                      layer=scene.contact.layer)
    if scene.shape.moves:      # a feature rolls through: the march moves the profile with the material
        contact.move = moving_profile(contact, scene.shape, scene.load.direction,
                                      "discretization.extent" if scene.discretization.extent is not None
                                      else "discretization.zone")
    meth.setup(contact)
    return scene, meth, contact


def _start(scene, meth, contact, tick=None) -> StepRecord:
    """State 0: the braked start's last static shift step, or the steady rolling state."""
    ld, FN = scene.load, start_force(scene)     # FN(0): load.normal without a normal history
    if FN <= 0.0:           # a normal history that starts at 0: out of contact
        return out_of_contact(contact, 0, ld.start, 0.0, scene.loads_at(0.0))
    if ld.start == "rolling":
        return steady(contact, meth, FN, scene.loads_at(0.0), direction=ld.direction, tick=tick)
    loads = scene.loads_at(0.0)
    if loads.xi is not None or loads.eta is not None:
        raise InputError("load.start", "a braked start shifts the bodies by the tangential forces: prescribe "
                                       "load.tangential and load.lateral (or start = \"rolling\")")
    last = static_shift(contact, meth, FN, loads.Fx, loads.Fy, loads.phi, steps=ld.start_steps, tick=tick)[-1]
    return dataclasses.replace(last, k=0)   # the shift steps are numbered within the start; it is state 0


def march(scene, method=None, *, prepared=None, resume=None, verify=True, state=None,
          start_progress=None) -> Iterator[StepRecord]:
    """The 3D run as a stream of :class:`~rollqp.three.march.StepRecord`: ``k = 0`` (the starting
    state), then the rolling steps (module docstring); with ``resume`` (the arrays of an earlier
    result file of this scene, or :meth:`ResumeSource.tail <rollqp.result.ResumeSource.tail>`) only the
    steps after its last state, once that state is checked to solve its own step (:func:`check_resumed`;
    ``verify=False`` with ``state``, the state it returned). ``start_progress(j, expected)``: called after each
    step of the start (a march to the steady state, or a static shift step; ``expected`` steps usually).

    Raises
    ------
    SolverError
        A step failed; ``err.step`` names it (0: the start).
    InputError
        ``--resume``: the stored states are another scene's, or the last one does not solve its step.
    """
    scene, meth, contact = prepared = prepared if prepared is not None else prepare(scene, method)
    if resume is not None:
        _resumable(scene)
        if state is None:
            state = check_resumed(scene, prepared, resume) if verify else resumed_record(scene, contact, resume)
        start, first = state, _last_index(resume) + 1
    else:
        try:
            start = _start(scene, meth, contact, start_progress)
        except SolverError as err:
            raise (err.with_step(0) if err.step is None else err) from err
        first = 1
    records = rolling_steps(scene, contact, meth, start, first)
    head = next(records)
    if resume is None:
        yield head
    yield from records


def resumed_record(scene, contact, arrays: dict, row: int = -1) -> StepRecord:
    """A stored state of a 3D result file of ``scene`` (the last one, ``row = -1``), as the run continues from
    it: the grid, the number of steps and the rolled distances checked to be the scene's.

    Raises
    ------
    InputError
        ``--resume``: the file belongs to another scene (another grid, other rolled distances).
    """
    g = scene.grid
    x, y, q = (np.asarray(arrays[k]) for k in ("x", "y", "q"))
    if (x.shape != (g.nx,) or y.shape != (g.ny,) or np.shape(arrays["pn"])[1:] != g.shape
            or not np.allclose(x, g.x, rtol=0, atol=1e-12 * g.dx * g.nx)
            or not np.allclose(y, g.y, rtol=0, atol=1e-12 * g.dy * g.ny)):
        raise InputError("--resume", f"the result file's grid ({y.size} x {x.size} elements) is not this scene's "
                                     f"({g.ny} x {g.nx}): another scene")
    steps = np.asarray(arrays["step"]) if "step" in arrays else np.arange(q.size)
    qs = scene.q_steps
    if (steps.shape != q.shape or q.size == 0 or steps[-1] >= qs.size
            or not np.allclose(q, qs[steps], rtol=1e-12, atol=1e-15 * scene.ellipse.a)):
        raise InputError("--resume", f"the result file's rolled distances are not this scene's (it has {q.size} "
                                     f"states, the scene {qs.size}): another scene")
    k = int(steps[row])
    p = np.array(arrays["pn"][row], dtype=float).ravel()
    t = np.stack([np.array(arrays[c][row], dtype=float).ravel() for c in ("px", "py")])
    s = np.stack([np.array(arrays[c][row], dtype=float).ravel() for c in ("sx", "sy")])
    xi, eta, phi = (float(v) for v in arrays["creepage"][row])
    return StepRecord(k, "resumed", float(q[row]), p, np.zeros_like(p), t, s,
                      np.array(arrays["state"][row]).ravel(), float(arrays["FN"][row]), float(arrays["Fx"][row]),
                      float(arrays["Fy"][row]), float(arrays["Mz"][row]), xi, eta, phi,
                      float(arrays["approach"][row]), 0, 0.0, float(arrays["residual"][row]))


def check_resumed(scene, prepared, arrays: dict) -> StepRecord:
    """The state to continue from: the last stored state of ``arrays``, checked to solve its own step.

    The step is solved again from the state before it (from the start for state 0), with the warm start
    a run that never stopped gives it (the state before, for a rolling step after the first): the same
    computation, so it repeats the stored state bit for bit and the run continues from it. Otherwise it
    must agree to :data:`rollqp.march.RESUME_TOL` (pressures in p0, tractions in μp0; the forces, moment
    and creepages with them, the element states exactly) and the run continues from the stored state;
    else the file was changed or is corrupt: an :class:`InputError` on ``--resume``, one line, nothing run.
    """
    scene, meth, contact = prepared
    k = _last_index(arrays)
    if k > scene.n_steps:
        raise InputError("--resume", f"the result file has {k} rolling steps, the scene {scene.n_steps}")
    stored = resumed_record(scene, contact, arrays, -1)
    steps = np.asarray(arrays["step"]) if "step" in arrays else np.arange(len(arrays["q"]))
    try:
        if k == 0:
            again = _start(scene, meth, contact)
        elif steps.size >= 2 and int(steps[-2]) == k - 1:
            before = resumed_record(scene, contact, arrays, -2)
            again = list(rolling_steps(scene, contact, meth, before, k, last=k))[-1]
        else:
            raise InputError("--resume", f"the result file does not hold the state before its last one ({k}), "
                                         "which it needs to be continued")
    except SolverError as err:
        raise InputError("--resume", f"the last state ({k}) cannot be checked: its step, solved again, failed "
                                     f"({str(err)[:120]})") from None
    _compare(again, stored, contact, k)
    return again if _identical(again, stored) else stored


def _identical(a: StepRecord, b: StepRecord) -> bool:
    return all(np.array_equal(np.asarray(u, dtype=float), np.asarray(v, dtype=float)) for u, v in (
        (a.p, b.p), (a.t, b.t), (a.s, b.s), (a.delta, b.delta), ((a.xi, a.eta, a.phi), (b.xi, b.eta, b.phi)),
        ((a.FN, a.Fx, a.Fy, a.Mz), (b.FN, b.Fx, b.Fy, b.Mz)), (a.state, b.state)))


def _compare(again: StepRecord, stored: StepRecord, contact, k: int) -> None:
    """``stored`` is ``again`` (its step solved again) to :data:`RESUME_TOL`, else a one-line :class:`InputError`."""
    sc = contact.scales
    mu = min(float(contact.mu), 1.0)
    force = sc.stress * contact.grid.area * contact.grid.n
    checks = (("pressure", again.p, stored.p, sc.stress, "p0"),
              ("traction", again.t, stored.t, mu * sc.stress, "mu p0"),
              ("slip", again.s, stored.s, sc.slip, "p0/E*"),
              ("approach", again.delta, stored.delta, sc.displacement, "its scale"),
              ("creepage", (again.xi, again.eta), (stored.xi, stored.eta), sc.slip, "p0/E*"),
              ("spin creepage", again.phi, stored.phi, sc.slip / sc.length, "p0/(E* c)"),
              ("normal force", again.FN, stored.FN, force, "p0 times the grid's area"),
              ("tangential forces", (again.Fx, again.Fy), (stored.Fx, stored.Fy), mu * force,
               "mu p0 times the grid's area"),
              ("spin moment", again.Mz, stored.Mz, mu * force * sc.length, "mu p0 c times the grid's area"))
    for what, a, b, scale, unit in checks:
        d = np.abs(np.asarray(a, dtype=float) - np.asarray(b, dtype=float)) / scale
        worst = float(np.max(d)) if np.all(np.isfinite(d)) else np.inf
        if not worst <= RESUME_TOL:
            raise InputError("--resume", f"the last state ({k}) does not solve its own step: solved again from the "
                                         f"state before it, its {what} differs by {worst:.3g} {unit} (more than "
                                         f"{RESUME_TOL:g}): the file was changed or is corrupt")
    if not np.array_equal(_states(contact, stored.p, stored.t, stored.s), np.asarray(stored.state)):
        raise InputError("--resume", f"the last state ({k}): its element states are not those of its pressure, "
                                     "traction and slip: the file was changed or is corrupt")


def check_states(scene, contact, source) -> None:
    """Every state of an earlier part of the run (``source``: a :class:`~rollqp.result.ResumeSource` or a result
    file's arrays) consistent in itself, a block of states at a time: pressures >= 0, tractions in the friction
    disc and the element states those of p, t, s (to :data:`~rollqp.march.RESUME_TOL` of p0 and μp0), the forces
    and moment those of the pressures and tractions, the rolled distances the scene's (checked with the last
    state, :func:`resumed_record`). A state that is not is a changed or corrupt file: a one-line
    :class:`InputError` on ``--resume``, before anything is run or written. (The last state is moreover solved
    again: :func:`check_resumed`.)"""
    _resumable(scene)
    g, sc = contact.grid, contact.scales
    mu = float(contact.mu)
    tunit = (min(mu, 1.0) if mu > 0 else 1.0) * sc.stress
    force = sc.stress * g.area * g.n
    names = ("pn", "px", "py", "sx", "sy", "state", "FN", "Fx", "Fy", "Mz", "step")
    blocks = source.blocks(names) if isinstance(source, ResumeSource) else _array_blocks(source, names)
    seen = 0
    for b in blocks:
        m = len(b["pn"])
        p = np.asarray(b["pn"], dtype=float).reshape(m, -1)
        t = np.stack([np.asarray(b["px"], dtype=float).reshape(m, -1), np.asarray(b["py"], dtype=float).reshape(m, -1)], 1)
        sl = np.stack([np.asarray(b["sx"], dtype=float).reshape(m, -1), np.asarray(b["sy"], dtype=float).reshape(m, -1)], 1)
        k = np.asarray(b["step"]) if "step" in b else np.arange(seen, seen + m)
        bad = []
        if not (np.all(np.isfinite(p)) and np.all(np.isfinite(t)) and np.all(np.isfinite(sl))):
            bad = ["its fields are not finite"]
        elif np.min(p) < -RESUME_TOL * sc.stress:
            bad = [f"a pressure of {np.min(p) / sc.stress:.3g} p0 < 0"]
        elif np.max(np.hypot(t[:, 0], t[:, 1]) - mu * np.maximum(p, 0.0)) > RESUME_TOL * tunit:
            bad = ["a traction beyond the friction disc"]
        for i in range(m):
            if bad:
                break
            Fx, Fy, Mz = contact.moments(t[i])
            FN = g.area * float(p[i].sum())
            if not (abs(FN - float(b["FN"][i])) <= 1e-12 * force and abs(Fx - float(b["Fx"][i])) <= 1e-12 * force
                    and abs(Fy - float(b["Fy"][i])) <= 1e-12 * force
                    and abs(Mz - float(b["Mz"][i])) <= 1e-12 * force * sc.length):
                bad = [f"state {int(k[i])}: its forces are not those of its pressure and tractions"]
            elif not np.array_equal(_states(contact, p[i], t[i], sl[i]), np.asarray(b["state"][i]).ravel()):
                bad = [f"state {int(k[i])}: its element states are not those of its pressure, traction and slip"]
            else:
                bad = _law(contact, p[i], t[i], sl[i], np.asarray(b["state"][i]).ravel(), tunit, int(k[i]))
        if bad:
            where = bad[0] if bad[0].startswith("state") else f"a state of the file: {bad[0]}"
            raise InputError("--resume", f"{where}: the file was changed or is corrupt")
        seen += m


def _resumable(scene) -> None:
    """A run with a friction memory is not resumed: its result file does not hold the coefficient the material
    carries (a one-line :class:`InputError` on ``--resume``)."""
    law = scene.contact.friction
    if getattr(law, "kind", None) == "slip" and law.memory > 0:
        raise InputError("--resume", "a 3D run with a friction memory (contact.friction.memory > 0) cannot be "
                                     "resumed: its result file does not hold the coefficient the material carries; "
                                     "run it again")


def _law(contact, p, t, s, states, tunit, k) -> list:
    """Coulomb's law at a stored state (to :data:`RESUME_TOL`): a sticking element does not slip (``|s|`` in the
    tangential steps' slip unit), a slipping one's traction is ``−μp s/|s|`` (in μp0): ``[]``, or what is wrong."""
    slip_unit = tunit / contact.materials.Estar
    sn = np.hypot(s[0], s[1])
    stick, slipping = states == 1, (states == 2) & (sn > 0)
    if np.any(sn[stick] > RESUME_TOL * slip_unit):
        return [f"state {k}: a sticking element slips"]
    mu = contact.mu
    if contact.law.kind == "slip":   # a slip-velocity law (without memory: a run with one is not resumed) at the slip
        mu = contact.slip_bound("shift").mu(np.asarray(s, dtype=float), contact=np.asarray(p) > 0)
    b = mu * np.maximum(p, 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        r = np.hypot(t[0] + b * s[0] / sn, t[1] + b * s[1] / sn)
    if np.any(r[slipping] > RESUME_TOL * tunit):
        return [f"state {k}: a slipping element's traction is not opposite its slip"]
    return []


def _array_blocks(arrays, names, rows: int = 256):
    K1 = len(arrays["q"])
    for i in range(0, K1, rows):
        yield {k: np.asarray(arrays[k][i:i + rows]) for k in names if k in arrays}


def _read_grid(rec: StepRecord, contact) -> tuple[dict, dict]:
    """The core fields and notes of a 3D :class:`~rollqp.three.march.StepRecord` (:data:`GRID`)."""
    g = contact.grid
    t, s = np.asarray(rec.t).reshape(2, -1), np.asarray(rec.s).reshape(2, -1)
    values = dict(q=rec.q, pn=g.field(rec.p), px=g.field(t[0]), py=g.field(t[1]), sx=g.field(s[0]),
                  sy=g.field(s[1]), state=g.field(rec.state), FN=rec.FN, Fx=rec.Fx, Fy=rec.Fy, Mz=rec.Mz,
                  creepage=(rec.xi, rec.eta, rec.phi), approach=rec.delta, step=rec.k,
                  iterations=rec.iterations, step_time=rec.time, residual=rec.residual)
    return values, dict(rec.info.get("notes", {}))


#: The grid's result (a 3D scene): :data:`rollqp.fields.FIELDS_3D`, one :class:`~rollqp.result.Result`.
GRID = Layout(3, ("q", "pn", "px", "py", "sx", "sy", "state", "FN", "Fx", "Fy", "Mz", "creepage", "approach",
                  "step", "iterations", "step_time", "residual"), _read_grid)


def new_result(scene, contact, method_name: str, out=None, keep_every: int = 1) -> Result:
    """An empty :class:`~rollqp.result.Result` of the grid (:data:`GRID`) with the scene's scalars and metadata
    (``out``: its result file, journaled as the run goes)."""
    e, g = scene.ellipse, contact.grid
    meta = {"scene": scene.to_dict(), "method": method_name, "rollqp": __version__, "versions": dict(_versions()),
            "dimension": 3, "dq": scene.dq, "elements": int(g.n), "coupled": bool(contact.ops.coupled),
            "slip_note": ("state 0 of a braked start: static-shift slip per c = sqrt(ab) of shift"
                          if scene.load.start == "braked" else "state 0: the steady state")}
    constants = {"area": g.area, "wear_A": scene.A.wear or 0.0, "wear_B": scene.B.wear or 0.0,
                 "braked": float(scene.load.start == "braked")}
    return Result(g.x, {"a": e.a, "b": e.b, "p0": e.p0, "Estar": e.Estar}, meta, fields_for(scene), keep_every=keep_every,
                  out=out, operators=contact, layout=GRID, coords={"x": g.x, "y": g.y}, constants=constants)


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


def _raw_distance(meta: dict, rec: StepRecord, contact) -> bool:
    """A conic method's raw answers (the solver's own, before the active-set refinement,
    :mod:`rollqp.methods.refine`) against the refined ones the run keeps: the largest distance over the
    run in ``meta["raw_distance"]`` (``dp`` in p0, ``dt`` in μp0, ``steps`` compared); nothing for a
    method without a raw answer (Newton). True if it was updated."""
    sc = contact.scales
    rp, rt = (rec.info.get(part, {}).get("raw") for part in ("normal", "tangential"))
    if rp is None and rt is None:
        return False
    row = meta.setdefault("raw_distance", {"dp": 0.0, "dt": 0.0, "steps": 0})
    if rp is not None:
        row["dp"] = max(row["dp"], float(np.max(np.abs(rp["p"] - rec.p))) / sc.stress)
    if rt is not None:
        row["dt"] = max(row["dt"], float(np.max(np.abs(rt["t"] - rec.t))) / ((contact.mu or 1.0) * sc.stress))
    row["steps"] += 1
    return True


def _noted(meta: dict, records, contact):
    """The records, each with the notes it adds to the result's ``meta`` (``rec.info["notes"]``: journaled with
    the state, so that a resumed run has them)."""
    for rec in records:
        notes = {}
        if rec.k == 0 and "marched" in rec.info:
            notes["rolling_start"] = f"marched to the steady state in {rec.info['marched']} steps"
        if rec.k == 0 and "shift" in rec.info:
            notes["static_shift"] = [float(v) for v in rec.info["shift"]]
        if _raw_distance(meta, rec, contact):
            notes["raw_distance"] = dict(meta["raw_distance"])
        rec.info["notes"] = notes
        yield rec


def run(scene, method=None, progress=None, resume=None, observe=None, out=None, keep_every=None,
        start_progress=None) -> Result:
    """Run a 3D scene and return its :class:`~rollqp.result.Result` — :func:`rollqp.march.run` for the grid, with
    the same arguments and guarantees (docs/results.md): ``progress(k, K)`` after each rolling step,
    ``observe(record, contact)`` with every record, ``resume`` an earlier part of the run (the path of its
    result file or journal, a :class:`~rollqp.result.ResumeSource`, or a result file's arrays), whose last
    state is checked to solve its own step first (:func:`check_resumed`); ``out`` the result file: every
    state journaled as it is completed (``out.journal``: a run killed even by SIGKILL loses at most the
    state in flight; no state is kept in memory), the file written at the end — and, with the completed
    states and the reason in ``meta["failed"]`` or ``meta["interrupted"]``, when the run fails or is
    interrupted; ``keep_every``: keep every k-th state (and the last two); ``start_progress(j, expected)`` after
    each step of the start (:func:`march`: a conic method's march to a steady state can take minutes).

    Raises
    ------
    SolverError, InputError, KeyboardInterrupt
        ``err.partial`` holds the result of the completed states.
    """
    asked = scene if isinstance(scene, SceneBase) else load_scene(scene)
    if out is not None:
        out = check_output(out, key="out")
    source = resume_source(resume) if isinstance(resume, (str, os.PathLike)) else resume
    keep = _keep_every(keep_every, source)
    scene, meth, contact = prepared = prepare(asked, method)
    tail = state = None
    if source is not None:
        tail = source.tail() if isinstance(source, ResumeSource) else source
        resumed_record(scene, contact, tail)            # the grid and the rolled distances: this scene's
        check_states(scene, contact, source)            # every state consistent, before any is solved from
        state = check_resumed(scene, prepared, tail)
    result = new_result(scene, contact, meth.name, out=out, keep_every=keep)
    records = _noted(result.meta, march(scene, prepared=prepared, resume=tail, verify=False, state=state,
                                        start_progress=start_progress), contact)
    with stop_once():  # a second Ctrl-C never interrupts the writing of what the first one saves
        return drive(result, records, source=source, resumed_from=None if tail is None else _last_index(tail),
                     operators=contact, observe=observe, progress=progress, steps=scene.n_steps)
