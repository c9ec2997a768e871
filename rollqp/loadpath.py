r"""Load paths of a 3D scene: the normal load as a history, the rolled distance as a history (docs/scenes.md,
"Three dimensions"; docs/theory3d.md §4).

The 3D counterpart of the 2D march's load paths (:mod:`rollqp.kinematics`), with the same keys and meanings
and the same history objects (:mod:`rollqp.histories`):

* ``load.normal_history``: the normal force at step k is ``FN_k = load.normal·normal_history(τ_k/a)``. Every
  step solves its own normal problem at ``FN_k`` (similar bodies: once per distinct load). ``FN_k = 0`` is out
  of contact: the step's fields are zero (every element separated), nothing is solved, and the tractions'
  memory is lost (the next loaded step starts from unloaded surfaces), as in 2D.
* ``load.rolled``: the steps are ``τ_k = k·Δτ`` (``Δτ = step·dx``) and the rolled distance is
  ``q_k = a·rolled(τ_k/a)`` (:func:`rollqp.kinematics.plan`, the same plan as in 2D). A step whose
  ``Δq_k = q_k − q_{k−1}`` is positive rolls by ``Δq_k`` in ``load.direction``; a negative one is a reversal
  (the material flows the other way, eq. 3D.16 with ``−d``); a zero one is a stop, a static shift step under
  the loads of ``τ_k`` (eq. 3D.16 at ``Δq = c``, the shift kind of :meth:`Contact.tangential_step
  <rollqp.operators.grid.Contact.tangential_step>`). The Δq may vary from step to step.

The loads (``tangential``, ``lateral``, the creepages and ``normal_history``) are histories of τ, so "roll,
stop, cycle Fx at rest, roll back" is one scene. ``load.tangential`` stays ``Fx/(μ·FN_ref)`` with
``FN_ref = load.normal``: a force proportional to the current load is the same history scaled.

:func:`rollqp.loads.check_load_path` holds the scene's checks of these keys (each a one-line
:class:`~rollqp.errors.InputError` naming the key); :func:`rolling_steps` is the stream of rolling steps
the run marches (:func:`rollqp.three.march.transient` itself for a scene without a load path).
"""
from __future__ import annotations

import dataclasses
import time

import numpy as np

from .errors import SolverError
from .kinematics import plan
from .loads import has_load_path, normal_force, start_force
from .three.march import StepRecord, _previous, _record, _states, _warm_of, coupled_step, normal, transient
from .problem.grid import SEPARATION

__all__ = ["out_of_contact", "rolling_steps", "posed_force", "SHIFTED_KEPT"]

#: Shifted influence operators kept for the distinct Δq of a load path (least recently used out): a table whose
#: slopes all differ would otherwise keep one per step.
SHIFTED_KEPT = 8


# =========================================================================== the steps
def out_of_contact(contact, k: int, phase: str, q: float, loads) -> StepRecord:
    """The state at ``FN = 0``: no pressure, no tractions, every element separated. Nothing is solved; the
    approach is not determined (any ``δ <= min h``) and is recorded as ``min h`` (the bodies just touch),
    the gap as ``h − min h``; the creepages are not determined either: the prescribed ones, else 0."""
    n = contact.grid.n
    delta = float(np.min(contact.h))
    zero2 = np.zeros((2, n))
    return StepRecord(k=k, phase=phase, q=float(q), p=np.zeros(n), g=np.asarray(contact.h, dtype=float) - delta,
                      t=zero2, s=zero2.copy(), state=np.full(n, SEPARATION, dtype=np.int8), FN=0.0, Fx=0.0, Fy=0.0,
                      Mz=0.0, xi=0.0 if loads.xi is None else float(loads.xi),
                      eta=0.0 if loads.eta is None else float(loads.eta), phi=float(loads.phi), delta=delta,
                      iterations=0, time=0.0, residual=0.0, info={"status": "out of contact"})


class _Shifted:
    """The shifted operators of the distinct step sizes met (:meth:`ContactOperators.shifted
    <rollqp.influence.grid.ContactOperators.shifted>` keeps one per offset): a Δq within 1e-12 of one met
    before (a table's Δq differ by round-off) reuses it, and at most :data:`SHIFTED_KEPT` are kept."""

    def __init__(self, contact):
        self.ops, self.keep, self.seen = contact.ops, {-contact.grid.dx, contact.grid.dx}, []

    def snap(self, dq: float) -> float:
        for i, v in enumerate(self.seen):
            if abs(v - dq) <= 1e-12 * v:
                self.seen.append(self.seen.pop(i))
                return v
        self.seen.append(dq)
        if len(self.seen) > SHIFTED_KEPT:
            old = self.seen.pop(0)
            for off in (old, -old):
                if off not in self.keep:
                    for which in ("tt", "tn"):
                        self.ops._cache.pop((which, float(off)), None)
        return dq


def rolling_steps(scene, contact, method, start, first: int = 1, last: int | None = None):
    r"""The rolling steps ``k = first … last`` (default: the scene's ``n_steps``) from ``start`` (the
    :class:`~rollqp.three.march.StepRecord` before step ``first``, yielded first): :func:`~rollqp.three.march.transient`
    for a scene without a load path, the load path's steps otherwise (module docstring). A
    :class:`SolverError` carries the step."""
    last = scene.n_steps if last is None else int(last)
    if not has_load_path(scene):
        yield from transient(contact, method, scene.load.normal, scene.loads_at, scene.dq, last,
                             scene.load.direction, start=start, first=first)
        return
    pl = plan(scene)
    fn = normal_force(scene, pl.tau)
    yield start
    prev, warm = start, (_warm_of(start) if start.k >= 1 and start.FN > 0 else None)
    move = getattr(contact, "move", None)
    shifted = _Shifted(contact)
    fixed = None                          # (FN, normal solution) of similar bodies, reused while FN holds
    for k in range(int(first), last + 1):
        t0 = time.perf_counter()
        q, d0 = float(pl.q[k]), scene.load.direction
        d = int(pl.d[k]) or d0              # a stop (Δq = 0) is a shift step: its direction only places μ
        # the loads of τ_k, with the rolled distance q_k where a friction law is read (its material frame puts
        # a point s at x = s + d0·q_k, the law reads d·q: q·d0·d, so that a reversal's d = −d0 reads the same)
        ld = dataclasses.replace(scene.loads_at(float(pl.tau[k])), q=q * d0 * d)
        FN = float(fn[k])
        if move is not None:
            move(q)
        if FN <= 0.0:
            rec = out_of_contact(contact, k, "unloaded", q, ld)
            yield rec
            prev, warm = rec, None
            continue
        pressure = None
        if not contact.ops.coupled:
            if fixed is None or fixed[0] != FN or move is not None:
                fixed = (FN, normal(contact, method, FN))
            pressure = fixed[1]
        previous = _previous(prev)
        if prev.FN != FN:       # the last step's tractions may lie outside this load's discs: a cold start
            warm = None
        stop = pl.d[k] == 0
        phase = "shift" if stop else "rolling"       # a stop: a static shift step under the loads of τ_k
        dq = None if stop else shifted.snap(float(pl.dq[k]))
        try:
            ns, ts, sw = coupled_step(contact, method, FN, phase, ld, previous, dq, d, warm=warm, pressure=pressure)
        except SolverError as exc:
            if warm is None:
                raise exc.with_step(k) from None
            try:                # a warm start can mislead Newton's active set: once more from cold
                ns, ts, sw = coupled_step(contact, method, FN, phase, ld, previous, dq, d, pressure=pressure)
            except SolverError as again:
                raise again.with_step(k) from None
        rec = _record(contact, k, phase, q, ns, ts, ld, sw, time.perf_counter() - t0,
                      _states(contact, ns.p, ts.t, ts.s, mu=_step_mu(contact, ts, ld.q, d)))
        rec.info["pose"] = (phase, FN, dq, d, ld)       # how the step was posed: rollqp.crossval.grid
        yield rec
        prev, warm = rec, (ns, ts)


def _step_mu(contact, ts, q: float, direction: int):
    """The coefficient the step's bound had: a slip-velocity law's own (``ts.mu``), else the law at the rolled
    distance and direction the step read it at (a material frame's patch or table moves with the material)."""
    if ts.mu is not None or contact.law.kind == "slip":
        return ts.mu
    return contact.coefficient(q, direction)


def posed_force(scene, rec) -> tuple[float, int]:
    """``(FN, direction)`` of the step behind the record ``rec`` of a run of ``scene``: a load path's own
    (``rec.info["pose"]``), else the starting state's ``FN(0)`` or ``load.normal``, and ``load.direction``."""
    pose = rec.info.get("pose")
    if pose is not None:
        return pose[1], pose[3]
    return (start_force(scene) if rec.k == 0 else float(scene.load.normal)), scene.load.direction
