r"""The grid's march: a 3D scene's run over its grid — its contact built once, the starting state, the rolling
steps, the result (docs/scenes.md, "Three dimensions"; docs/theory3d.md §4, §6, §8). The strip's sibling is
:mod:`rollqp.march.strip`; :mod:`rollqp.march` runs either.

**The problems as sequences of steps:**

* :func:`static_shift` — Cattaneo–Mindlin: the bodies pressed together, then shifted by the
  tangential force ``(Fx, Fy)`` in ``steps`` increments (shift steps, eq. 3D.16 at ``Δq = c``);
* :func:`steady` — steady rolling with prescribed creepages ``(ξ, η, φ)`` or forces
  ``(Fx, Fy)`` and ``φ``: solved directly by a method that solves the steady operator
  (``"steady" in method.capabilities.solves``: Newton), marched to the steady state otherwise (each step an
  SOCP with ``Δq = dx``; docs/theory3d.md §6);
* :func:`transient` — rolling in x from a start (the braked state of :func:`static_shift`) with
  steps ``Δq``: a generator of :class:`StepRecord`\ s; :func:`rolling_steps` — the same along a load path.

Similar bodies (``K = 0``): the normal step is solved once and its pressure fixes every
tangential step. Dissimilar bodies: every step is the normal–tangential alternation
(:func:`coupled_step`, the 2D project's N–T process, paper §6.3): Gauss–Seidel over the normal
half (gap with ``A_nt t``) and the tangential half (bound ``μp``, history with ``A_tn p``) until
both halves' residuals at the common ``(p, t)`` are below the tolerance.

**Load paths** (the 3D counterpart of the 2D march's, :mod:`rollqp.kinematics`, with the same keys, meanings
and history objects, :mod:`rollqp.histories`):

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
:func:`rollqp.loads.check_load_path` holds the scene's checks of these keys.

**The run** (:func:`prepare`, :func:`march`, :func:`run`; the arguments and meaning of the strip's):

* **starting state** (record ``k = 0``): ``load.start = "braked"`` — the normal force, then the
  tangential forces in ``load.start_steps`` static shift steps (Cattaneo–Mindlin for similar bodies,
  :func:`static_shift`; phase ``"shift"``); ``"rolling"`` — the steady state at the loads of ``q = 0``
  (:func:`steady`: directly by a method whose record solves ``"steady"``, by the march to the fixed point
  otherwise; phase ``"steady"``);
* **rolling steps** ``k = 1 … K`` of ``Δq = step·dx`` at the loads of ``q_k`` (phase ``"rolling"``).
"""
from __future__ import annotations

import dataclasses
import os
import time
from dataclasses import dataclass, field
from typing import Iterator

import numpy as np

from ..advice.grid import MARCH_LENGTHS, START_STEPS
from ..atomic import stop_once
from ..errors import InputError, RollqpError, SolverError
from ..fields import fields_for
from ..friction import law_kind
from ..kinematics import plan
from ..methods import compose_3d, get_method, scene_method_3d
from ..operators.grid import Contact, Loads
from ..problem.grid import SEPARATION, SLIP, STICK, Residuals, StepSolution, disc_projection, element_states
from ..result import Layout, Result, ResumeSource, check_output, resume_source
from ..scene import load_scene
from ..scene.core import SceneBase
from ..loads import has_load_path, normal_force, start_force
from ..patch import moving_profile
from ..version import __version__
from .loop import RESUME_TOL, check_earlier, check_last, drive, last_index, stored_steps, versions
from .loop import keep_every as _keep_every

__all__ = ["StepRecord", "normal", "coupled_step", "static_shift", "steady", "transient", "out_of_contact",
           "rolling_steps", "posed_force", "prepare", "march", "run", "new_result", "resumed_record", "check_resumed",
           "check_states", "GRID", "SHIFTED_KEPT"]

#: N–T alternation sweeps before a :class:`SolverError`: it contracts about like ``|K|`` (measured,
#: docs/validation3d.md §7: 5–7 sweeps to 1e-15 for ``|K|`` = 0.045–0.075); 100 leaves room for ``|K|`` → 0.5.
MAX_SWEEPS = 100
#: Rolled distance (in units of ``c = √(ab)``) after which marching to the steady state gives up: the
#: march converges in 3–6 contact lengths (docs/validation3d.md §9: 70–98 steps of dx on 20 elements
#: across a circle ≈ 4 c); 60 c is ten times that.
MAX_MARCH_DISTANCE = 60.0
#: A Newton iterate on the march map is kept if its step changes the tractions by at most this fraction of
#: the change at the point it came from (else the march's own step is taken): a superlinear iteration
#: reduces it by orders of magnitude per step, a plain march by its contraction factor (about 0.9).
NEWTON_DECREASE = 0.5
#: Differences kept by the Anderson acceleration of the march to the steady state (the 2D
#: project's rolling start keeps 5): measured in docs/validation3d.md against the plain march.
ANDERSON_MEMORY = 6


@dataclass(frozen=True)
class StepRecord:
    """The state after one step: fields on the grid (flattened: ``p``, ``g``, ``state`` of shape
    ``(n,)``, ``t``, ``s`` of ``(2, n)``), totals on body A, creepages, and the solve's counters."""

    k: int
    phase: str
    q: float
    p: np.ndarray
    g: np.ndarray
    t: np.ndarray
    s: np.ndarray
    state: np.ndarray
    FN: float
    Fx: float
    Fy: float
    Mz: float
    xi: float
    eta: float
    phi: float
    delta: float
    iterations: int
    time: float
    residual: float
    info: dict = field(default_factory=dict)
    #: The friction coefficient a slip-velocity law left at the elements (its memory, the next step's start), else None.
    mu: np.ndarray | None = None


def normal(contact, method, FN: float, t=None, warm=None):
    """The normal step (eq. 3D.14) solved by ``method``, from ``warm`` or the Hertz pressure
    (:meth:`~rollqp.operators.grid.Contact.hertz_start`)."""
    return method.solve(contact.normal_step(FN, t), warm if warm is not None else contact.hertz_start(FN))


def coupled_step(contact, method, FN, kind, loads, previous=None, dq=None, direction=-1, warm=None,
                 pressure=None):
    """One step: its normal and tangential halves (module docstring).

    ``pressure``: a normal solution to reuse (similar bodies: the pressure does not change);
    ``warm``: ``(normal, tangential)`` solutions to start from. Returns ``(normal, tangential,
    sweeps)``.
    """
    wn, wt = warm if warm is not None else (None, None)
    if contact.mu == 0:                 # frictionless: t = 0, the normal half alone (its shear is zero)
        nsol = pressure if pressure is not None else normal(contact, method, FN, warm=wn)
        return nsol, _frictionless(contact, kind, nsol, loads, previous, dq, direction), 1
    if not contact.ops.coupled:
        nsol = pressure if pressure is not None else normal(contact, method, FN, warm=wn)
        tsol = method.solve(contact.tangential_step(kind, nsol.p, loads, previous, dq, direction), wt)
        return nsol, tsol, 1
    t = wt.t if wt is not None else np.zeros((2, contact.grid.n))
    nsol = tsol = None
    for sweep in range(1, MAX_SWEEPS + 1):
        nsol = method.solve(contact.normal_step(FN, t), nsol or wn or contact.hertz_start(FN))
        tprob = contact.tangential_step(kind, nsol.p, loads, previous, dq, direction)
        tsol = method.solve(tprob, tsol or wt)
        t = tsol.t
        nres = contact.normal_step(FN, t).residuals(nsol.p, nsol.delta).max
        if max(nres, tsol.residual) <= method.tolerance:
            return nsol, tsol, sweep
    raise SolverError("the normal–tangential alternation did not converge", method=method.name,
                      iterations=MAX_SWEEPS, residual=max(nres, tsol.residual))


def _frictionless(contact, kind, nsol, loads, previous, dq, direction):
    """The tangential half at ``μ = 0``, as the 2D march's (:mod:`rollqp.march`): ``t = 0`` — the bound
    ``μp`` is zero on every element, so every element in contact slips freely and nothing is solved
    (a prescribed force is 0: ``load.tangential`` is then 0 by the scene's check). The creepages are
    not determined by the contact: the prescribed ones, else 0; the slip follows from them."""
    free = Loads(xi=0.0 if loads.xi is None else loads.xi, eta=0.0 if loads.eta is None else loads.eta,
                 phi=loads.phi)
    prob = contact.tangential_step(kind, nsol.p, free, previous, dq, direction)
    return prob.solution(np.zeros((2, contact.grid.n)), method="frictionless", extras={"status": "frictionless"})


def _warm_of(rec):
    """``(normal, tangential)``: the warm start of the step after a resumed state ``rec``, the numbers the
    step that computed it hands to the next (pressure and approach; tractions and creepages)."""
    return (StepSolution(residuals=Residuals(), p=rec.p, g=rec.g, delta=rec.delta),
            StepSolution(residuals=Residuals(), t=rec.t, s=rec.s, xi=rec.xi, eta=rec.eta))


def _record(contact, k, phase, q, nsol, tsol, loads, sweeps, elapsed, tprob_states):
    Fx, Fy, Mz = contact.moments(tsol.t)
    return StepRecord(k=k, phase=phase, q=q, p=nsol.p, g=nsol.g, t=tsol.t, s=tsol.s, state=tprob_states,
                      FN=contact.grid.area * float(nsol.p.sum()), Fx=Fx, Fy=Fy, Mz=Mz, xi=tsol.xi, eta=tsol.eta,
                      phi=loads.phi, delta=nsol.delta, iterations=sweeps * max(1, tsol.iterations), time=elapsed,
                      residual=max(nsol.residual, tsol.residual),
                      info={"sweeps": sweeps, "normal": nsol.info, "tangential": tsol.info}, mu=tsol.mu)


def _previous(rec):
    """What the step after the state ``rec`` takes as its ``previous``: ``(p, t)``, and the coefficient ``μ`` of a
    slip-velocity law's memory where the state carries one."""
    return (rec.p, rec.t) if rec.mu is None else (rec.p, rec.t, rec.mu)


def _states(contact, p, t, s, q=0.0, mu=None, direction=-1):
    """0 separation, 1 stick, 2 slip (:func:`~rollqp.problem.grid.element_states`). At ``μ = 0`` (bound
    zero) as in 2D (:func:`rollqp.problem.solution.classify`): an element in contact (``p > 0``) slips
    where its slip is not zero (``|ŝ| > 1e-7``, 2D's tolerance), else it sticks — nothing moves it. ``mu``: the
    coefficient of a slip-velocity law at the solution (its bound ``μ p⁺``)."""
    if contact.mu == 0:
        moving = np.hypot(*(np.asarray(s, dtype=float).reshape(2, -1) / contact.scales.slip)) > 1e-7
        return np.where(np.asarray(p) > 0, np.where(moving, SLIP, STICK), SEPARATION).astype(np.int8)
    if mu is None and contact.law.kind == "slip":   # a stored state: the law at its own slip (without memory)
        mu = contact.slip_bound("shift").mu(np.asarray(s, dtype=float).reshape(2, -1), contact=np.asarray(p) > 0)
    bound = contact.bound(p, q, direction) if mu is None else np.asarray(mu) * np.maximum(p, 0.0)
    return element_states(np.asarray(t), np.asarray(s), bound, contact.scales)


def static_shift(contact, method, FN: float, Fx: float = 0.0, Fy: float = 0.0, phi: float = 0.0, steps: int = 1,
                 tick=None):
    """Cattaneo–Mindlin: ``FN``, then ``(Fx, Fy)`` in ``steps`` equal increments (shift steps).

    Returns the list of :class:`StepRecord` (phase ``"shift"``), the last one the braked state;
    ``info["shift"]`` is the accumulated rigid shift ``(Σ ξ c, Σ η c)`` of A relative to B,
    ``info["loads"]`` the step's :class:`Loads` and ``info["before"]`` the ``(p, t)`` it started from
    (``None``: the unloaded surfaces), so that the step can be posed again.
    """
    if int(steps) != steps or steps < 1:
        raise InputError("load.start_steps", f"must be an integer >= 1, got {steps!r}")
    out, warm, previous, shift = [], None, None, np.zeros(2)
    nsol = None if contact.ops.coupled else normal(contact, method, FN)
    for j in range(1, int(steps) + 1):
        t0 = time.perf_counter()
        loads = Loads(Fx=Fx * j / steps, Fy=Fy * j / steps, phi=phi / steps)
        ns, ts, sw = coupled_step(contact, method, FN, "shift", loads, previous, warm=warm, pressure=nsol)
        shift = shift + contact.scales.length * np.array([ts.xi, ts.eta])
        rec = _record(contact, j - 1, "shift", 0.0, ns, ts, loads, sw, time.perf_counter() - t0,
                      _states(contact, ns.p, ts.t, ts.s, mu=ts.mu))
        rec.info.update(shift=tuple(shift), loads=loads, before=previous)
        out.append(rec)
        previous, warm = (ns.p, ts.t) if ts.mu is None else (ns.p, ts.t, ts.mu), (ns, ts)   # μ: a law's memory
        if tick is not None:
            tick(j, int(steps))
    return out


def steady(contact, method, FN: float, loads: Loads, direction: int = -1, start=None, memory: int = None,
           pressure=None, accelerate: str = "chord", tick=None, approximate_start: bool = True):
    """Steady rolling (eq. 3D.17): directly if ``"steady" in method.capabilities.solves``, else as the fixed
    point of rolling steps of ``Δq = dx`` from ``start`` (a :class:`StepRecord`, or zero tractions), reached
    when a step changes the tractions by less than the method's tolerance (``info["marched"]`` steps).

    ``accelerate``: ``"chord"`` (similar bodies; default) Newton's method on the march map
    (:mod:`rollqp.methods.chord`, eq. 3D.24), every iterate evaluated by the method; ``"anderson"`` the
    march accelerated by Anderson's method with ``memory`` differences (default :data:`ANDERSON_MEMORY`;
    0: the plain march; dissimilar bodies always). ``pressure``: the normal solution to use (similar
    bodies; solved here if ``None``). ``tick(j, expected)``: called after each step of the march (``expected``: the
    steps a march usually takes, ``MARCH_LENGTHS`` contact lengths of ``dx``; it may take more or fewer).
    ``approximate_start``: a march of similar bodies with no ``start`` starts from
    :func:`approximate_steady` (Kalker's simplified theory: 5 conic steps instead of 88 on the 24 × 24 circle at
    ξ = 1e-3, the same steady state; docs/performance.md). """
    t0 = time.perf_counter()
    if "steady" in method.capabilities.solves or contact.mu == 0:
        warm = (start, start) if start is not None else None
        nsol, tsol, sw = coupled_step(contact, method, FN, "steady", loads, direction=direction, warm=warm,
                                      pressure=pressure)
        return _record(contact, 0, "steady", 0.0, nsol, tsol, loads, sw, time.perf_counter() - t0,
                       _states(contact, nsol.p, tsol.t, tsol.s, mu=tsol.mu))
    if accelerate not in ("chord", "anderson"):
        raise InputError("accelerate", f"must be 'chord' or 'anderson', got {accelerate!r}")
    if accelerate == "chord" and not contact.ops.coupled:
        if start is None and approximate_start:
            pressure = pressure or normal(contact, method, FN)
            start = approximate_steady(contact, FN, loads, direction, pressure)
        return _newton_to_steady(contact, method, FN, loads, direction, start, t0, pressure, tick)
    return _march_to_steady(contact, method, FN, loads, direction, start, t0,
                            ANDERSON_MEMORY if memory is None else int(memory), pressure, tick)


def approximate_steady(contact, FN: float, loads: Loads, direction: int, pressure):
    """The start of a march to the steady state: FASTSIM's steady state (:mod:`rollqp.methods.fastsim`, Kalker's
    simplified theory on the same grid and pressure: tractions inside the discs ``|t| ≤ μp``, a few per cent off
    the exact ones), or None where FASTSIM does not apply (the march then starts from zero tractions). The
    march's fixed point does not depend on its start: the steady state it reaches is the method's own."""
    try:
        approx = get_method("fastsim", 3)
        approx.setup(contact)
        return steady(contact, approx, FN, loads, direction=direction, pressure=pressure)
    except RollqpError:
        return None


def _expected_march(contact, started: bool = False) -> int:
    """The steps a march to the steady state usually takes, for its progress: from a start near it
    (``started``: FASTSIM's) :data:`rollqp.advice.grid.START_STEPS`, from zero :data:`rollqp.advice.grid.MARCH_LENGTHS`
    contact lengths of ``dx``."""
    if started:
        return START_STEPS
    return int(MARCH_LENGTHS * 2 * contact.ellipse.a / contact.grid.dx) + 1


def _newton_to_steady(contact, method, FN, loads, direction, start, t0, pressure=None, tick=None):
    """The fixed point of the march by Newton's method on the march map (:func:`rollqp.methods.chord.chord_step`),
    a march step wherever a Newton iterate does not reduce the change by :data:`NEWTON_DECREASE`."""
    from ..methods.chord import chord_step   # (scipy: on first use, import rollqp stays light)
    nsol = pressure or normal(contact, method, FN)
    dx, n = contact.grid.dx, contact.grid.n
    shifted = contact.ops.shifted("tt", -direction * dx)
    unit = contact.mu * contact.scales.stress
    base = np.zeros((2, n)) if start is None else np.asarray(start.t, dtype=float)
    x, best, warm = base, None, None       # best: (change, x, G(x)) of the last accepted base point
    limit = int(np.ceil(MAX_MARCH_DISTANCE * contact.scales.length / dx))
    bound = contact.bound(nsol.p)
    expected = _expected_march(contact, started=start is not None)
    for k in range(1, limit + 1):
        if tick is not None and k > 1:
            tick(k - 1, expected)
        prob = contact.tangential_step("rolling", nsol.p, loads, (nsol.p, x), dx, direction)
        try:
            ts = method.solve(prob, warm)
        except SolverError:
            if best is None:           # a march step itself failed: nothing to fall back on
                raise
            x, warm, best = best[2], None, None       # the Newton iterate's step failed: the march's instead
            continue
        change = float(np.max(np.abs(ts.t - x))) / unit
        if change <= method.tolerance:
            rec = _record(contact, 0, "steady", 0.0, nsol, ts, loads, 1, time.perf_counter() - t0,
                          _states(contact, nsol.p, ts.t, ts.s, mu=ts.mu))
            rec.info.update({"marched": k, "change": change, "accelerate": "chord"})
            return rec
        if best is not None and not change <= NEWTON_DECREASE * best[0]:
            x, warm, best = best[2], None, None        # the Newton iterate failed: the march's own step instead
            continue
        best, warm = (change, x, ts.t), ts
        cand = chord_step(prob, ts, shifted, x)
        x = ts.t if cand is None else disc_projection(cand, bound)   # the fixed point is inside the discs
    raise SolverError(f"no steady state after {limit} steps (rolling {MAX_MARCH_DISTANCE:g} c)", method=method.name)


def _pack(p, t):
    return np.concatenate([np.asarray(p, dtype=float), np.asarray(t, dtype=float).ravel()])


def _march_to_steady(contact, method, FN, loads, direction, start, t0, memory=ANDERSON_MEMORY, pressure=None,
                     tick=None):
    """The fixed point ``x = G(x)`` of a rolling step of ``Δq = dx`` (``x = (p, t)``: the state whose
    displacements the step shifts), by Anderson's acceleration (type II, ``memory`` last
    differences; 0: the plain march). Every iterate is a solution of its own step; the answer
    is ``G(x_k)`` once it changes ``x_k`` by less than the tolerance (in ``p0`` and ``μp0``)."""
    n = contact.grid.n
    nsol = None if contact.ops.coupled else (pressure or normal(contact, method, FN))
    if start is None:
        p0 = nsol.p if nsol is not None else normal(contact, method, FN).p
        start = (p0, np.zeros((2, n)))
    else:
        start = (start.p, start.t)
    x = _pack(*start)
    scale = np.concatenate([np.full(n, contact.scales.stress), np.full(2 * n, contact.mu * contact.scales.stress)])
    X, Gs, warm = [], [], None
    limit = int(np.ceil(MAX_MARCH_DISTANCE * contact.scales.length / contact.grid.dx))
    expected = _expected_march(contact)
    for k in range(1, limit + 1):
        if tick is not None and k > 1:
            tick(k - 1, expected)
        ns, ts, sw = coupled_step(contact, method, FN, "rolling", loads, (x[:n], x[n:].reshape(2, n)),
                                  contact.grid.dx, direction, warm=warm, pressure=nsol)
        gx = _pack(ns.p, ts.t)
        change = float(np.max(np.abs(gx - x) / scale))
        if change <= method.tolerance:
            rec = _record(contact, 0, "steady", 0.0, ns, ts, loads, sw, time.perf_counter() - t0,
                          _states(contact, ns.p, ts.t, ts.s, mu=ts.mu))
            rec.info.update({"marched": k, "change": change})
            return rec
        X.append(x)
        Gs.append(gx)
        x, warm = _anderson(X[-memory - 1:], Gs[-memory - 1:], scale) if memory else gx, (ns, ts)
    raise SolverError(f"no steady state after rolling {MAX_MARCH_DISTANCE:g} c", method=method.name)


def _anderson(X, Gs, scale):
    """Anderson's type-II extrapolation from the iterates ``X`` and their images ``Gs``: the
    affine combination of the images whose residuals ``G(x) − x`` (scaled) combine to the least."""
    if len(X) < 2:
        return Gs[-1]
    F = np.array([(g - x) / scale for x, g in zip(X, Gs)]).T
    dF = np.diff(F, axis=1)
    dG = np.diff(np.array(Gs).T, axis=1)
    gamma = np.linalg.lstsq(dF, F[:, -1], rcond=1e-12)[0]   # drop dependent differences (a repeated iterate)
    return Gs[-1] - dG @ gamma


def transient(contact, method, FN: float, loads, dq: float, steps: int, direction: int = -1, start=None,
              first: int = 1):
    r"""Rolling steps ``k = first … steps`` of ``Δq`` (at ``q = k Δq``) from ``start`` (a
    :class:`StepRecord`, the state before step ``first``; zero tractions if ``None``), which is
    yielded first. ``loads``: a :class:`Loads` or a function ``q ↦ Loads``. Yields
    :class:`StepRecord`\ s; a :class:`SolverError` carries the step."""
    load_at = loads if callable(loads) else (lambda q: loads)
    if start is None:
        nsol = normal(contact, method, FN)
        zero = np.zeros((2, contact.grid.n))
        start = StepRecord(0, "start", 0.0, nsol.p, nsol.g, zero, zero.copy(), _states(contact, nsol.p, zero, zero),
                           FN, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, nsol.delta, nsol.iterations, 0.0, nsol.residual,
                           {"normal": nsol.info})
    yield start
    # the step after a rolling step sets out from it; the first rolling step from nothing (as a run that never
    # stopped does, whatever the start: a resumed run repeats the same computations)
    prev, warm = start, (_warm_of(start) if start.k >= 1 else None)
    fixed = None
    move = getattr(contact, "move", None)       # a profile feature rolls through: a normal step every step
    if not contact.ops.coupled and move is None:
        fixed = normal(contact, method, FN, warm=None)
    for k in range(int(first), int(steps) + 1):
        t0 = time.perf_counter()
        q = k * dq
        ld = load_at(q)
        if move is not None:
            move(q)
        try:
            ns, ts, sw = coupled_step(contact, method, FN, "rolling", ld, _previous(prev), dq, direction,
                                      warm=warm, pressure=fixed)
        except SolverError as exc:
            raise exc.with_step(k) from None
        rec = _record(contact, k, "rolling", q, ns, ts, ld, sw, time.perf_counter() - t0, _states(contact, ns.p, ts.t, ts.s, q, ts.mu, direction))
        rec.info["direction"] = direction       # where a friction law in the material frame was read (the mu field)
        if move is not None and hasattr(move, "check"):
            move.check(ns.p, k)
        yield rec
        prev, warm = rec, (ns, ts)


# =========================================================================== load paths
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
    :class:`StepRecord` before step ``first``, yielded first): :func:`transient`
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


# =========================================================================== the run
def prepare(scene, method=None):
    """``(scene, method, contact)``: the 3D scene validated, its method made and set up, its contact
    (grid, operators, Hertz ellipse) built once.

    ``method``: a name (overrides ``solver.method``) or a method object (checked by its record,
    :func:`rollqp.methods.compose_3d`).
    """
    scene = scene if isinstance(scene, SceneBase) else load_scene(scene)
    if scene.dimension != 3:
        raise InputError("contact.dimension", "rollqp.march.grid runs 3D scenes; this one is "
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
    """The 3D run as a stream of :class:`StepRecord`: ``k = 0`` (the starting
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
        _resumable(scene, resume if isinstance(resume, dict) else {})
        if state is None:
            state = check_resumed(scene, prepared, resume) if verify else resumed_record(scene, contact, resume)
        start, first = state, last_index(resume) + 1
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
    steps = stored_steps(arrays)
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
    # a slip-velocity law's coefficient at the elements (field "mu"): the memory the next step starts from
    mu = np.array(arrays["mu"][row], dtype=float).ravel() if "mu" in arrays and contact.law.kind == "slip" else None
    return StepRecord(k, "resumed", float(q[row]), p, np.zeros_like(p), t, s,
                      np.array(arrays["state"][row]).ravel(), float(arrays["FN"][row]), float(arrays["Fx"][row]),
                      float(arrays["Fy"][row]), float(arrays["Mz"][row]), xi, eta, phi,
                      float(arrays["approach"][row]), 0, 0.0, float(arrays["residual"][row]), mu=mu)


def check_resumed(scene, prepared, arrays: dict) -> StepRecord:
    """The state to continue from: the last stored state of ``arrays``, checked to solve its own step
    (:func:`rollqp.march.loop.check_last`, as the strip's).

    The step is solved again from the state before it (from the start for state 0), with the warm start
    a run that never stopped gives it (the state before, for a rolling step after the first): the same
    computation, so it repeats the stored state bit for bit and the run continues from it. Otherwise it
    must agree to :data:`rollqp.march.loop.RESUME_TOL` (pressures in p0, tractions in μp0; the forces, moment
    and creepages with them, the element states exactly) and the run continues from the stored state;
    else the file was changed or is corrupt: an :class:`InputError` on ``--resume``, one line, nothing run.
    """
    scene, meth, contact = prepared

    def step(k):
        before = resumed_record(scene, contact, arrays, -2)
        return list(rolling_steps(scene, contact, meth, before, k, last=k))[-1]

    def consistent(stored):
        if not np.array_equal(_states(contact, stored.p, stored.t, stored.s, mu=stored.mu), np.asarray(stored.state)):
            return "its element states are not those of its pressure, traction and slip"
        return None

    return check_last(arrays, stored=lambda row: resumed_record(scene, contact, arrays, row),
                      start=lambda: _start(scene, meth, contact), step=step, identical=_identical,
                      differences=lambda again, stored: _differences(again, stored, contact), consistent=consistent,
                      n_steps=scene.n_steps)


def _identical(a: StepRecord, b: StepRecord) -> bool:
    return all(np.array_equal(np.asarray(u, dtype=float), np.asarray(v, dtype=float)) for u, v in (
        (a.p, b.p), (a.t, b.t), (a.s, b.s), (a.delta, b.delta), ((a.xi, a.eta, a.phi), (b.xi, b.eta, b.phi)),
        ((a.FN, a.Fx, a.Fy, a.Mz), (b.FN, b.Fx, b.Fy, b.Mz)), (a.state, b.state)))


def _differences(again: StepRecord, stored: StepRecord, contact) -> tuple:
    """``(what, again, stored, scale, unit)`` of every field and total a resumed state is checked by."""
    sc = contact.scales
    mu = min(float(contact.mu), 1.0)
    force = sc.stress * contact.grid.area * contact.grid.n
    return (("pressure", again.p, stored.p, sc.stress, "p0"),
            ("traction", again.t, stored.t, mu * sc.stress, "mu p0"),
            ("slip", again.s, stored.s, sc.slip, "p0/E*"),
            ("approach", again.delta, stored.delta, sc.displacement, "its scale"),
            ("creepage", (again.xi, again.eta), (stored.xi, stored.eta), sc.slip, "p0/E*"),
            ("spin creepage", again.phi, stored.phi, sc.slip / sc.length, "p0/(E* c)"),
            ("normal force", again.FN, stored.FN, force, "p0 times the grid's area"),
            ("tangential forces", (again.Fx, again.Fy), (stored.Fx, stored.Fy), mu * force,
             "mu p0 times the grid's area"),
            ("spin moment", again.Mz, stored.Mz, mu * force * sc.length, "mu p0 c times the grid's area"))


def check_states(scene, contact, source) -> None:
    """Every state of an earlier part of the run (``source``: a :class:`~rollqp.result.ResumeSource` or a result
    file's arrays) consistent in itself (:func:`rollqp.march.loop.check_earlier`): pressures >= 0, tractions in
    the friction disc and the element states those of p, t, s (to :data:`~rollqp.march.loop.RESUME_TOL` of p0 and
    μp0), the forces and moment those of the pressures and tractions, the rolled distances the scene's (checked
    with the last state, :func:`resumed_record`). (The last state is moreover solved again: :func:`check_resumed`.)
    A slip-velocity law's states are checked with their stored coefficient (field ``mu``)."""
    g, sc = contact.grid, contact.scales
    mu = float(contact.mu)
    tunit = (min(mu, 1.0) if mu > 0 else 1.0) * sc.stress
    force = sc.stress * g.area * g.n

    def inconsistent(b, k):
        m = len(b["pn"])
        _resumable(scene, b)
        # each element's own coefficient, as stored (field mu: any law's); without it the law's, at q = 0
        law_mu = np.asarray(b["mu"], dtype=float).reshape(m, -1) if "mu" in b else None
        p = np.asarray(b["pn"], dtype=float).reshape(m, -1)
        t = np.stack([np.asarray(b["px"], dtype=float).reshape(m, -1), np.asarray(b["py"], dtype=float).reshape(m, -1)], 1)
        sl = np.stack([np.asarray(b["sx"], dtype=float).reshape(m, -1), np.asarray(b["sy"], dtype=float).reshape(m, -1)], 1)
        if not (np.all(np.isfinite(p)) and np.all(np.isfinite(t)) and np.all(np.isfinite(sl))):
            return "its fields are not finite"
        if np.min(p) < -RESUME_TOL * sc.stress:
            return f"a pressure of {np.min(p) / sc.stress:.3g} p0 < 0"
        bound_mu = law_mu if law_mu is not None else float(contact.law.largest)   # the disc of each element's μ
        if np.max(np.hypot(t[:, 0], t[:, 1]) - bound_mu * np.maximum(p, 0.0)) > RESUME_TOL * tunit:
            return "a traction beyond the friction disc"
        for i in range(m):
            Fx, Fy, Mz = contact.moments(t[i])
            FN = g.area * float(p[i].sum())
            if not (abs(FN - float(b["FN"][i])) <= 1e-12 * force and abs(Fx - float(b["Fx"][i])) <= 1e-12 * force
                    and abs(Fy - float(b["Fy"][i])) <= 1e-12 * force
                    and abs(Mz - float(b["Mz"][i])) <= 1e-12 * force * sc.length):
                return f"state {int(k[i])}: its forces are not those of its pressure and tractions"
            mu_i = None if law_mu is None else law_mu[i]
            if not np.array_equal(_states(contact, p[i], t[i], sl[i], mu=mu_i), np.asarray(b["state"][i]).ravel()):
                return f"state {int(k[i])}: its element states are not those of its pressure, traction and slip"
            bad = _law(contact, p[i], t[i], sl[i], np.asarray(b["state"][i]).ravel(), tunit, int(k[i]), mu_i)
            if bad:
                return bad
        return None

    check_earlier(source, ("pn", "px", "py", "sx", "sy", "state", "FN", "Fx", "Fy", "Mz", "step", "mu"), inconsistent)


def _resumable(scene, arrays) -> None:
    """A run with a friction memory is resumed from the coefficient the material carries, the stored field ``mu``
    of ``arrays``; without it, a one-line :class:`InputError` on ``--resume``."""
    law = scene.contact.friction
    if getattr(law, "kind", None) == "slip" and law.memory > 0 and "mu" not in arrays:
        raise InputError("--resume", "a 3D run with a friction memory (contact.friction.memory > 0) resumes from the "
                                     "stored friction coefficient, field 'mu', which the result file does not hold; "
                                     "run it again")


def _law(contact, p, t, s, states, tunit, k, mu=None) -> str | None:
    """Coulomb's law at a stored state (to :data:`RESUME_TOL`): a sticking element does not slip (``|s|`` in the
    tangential steps' slip unit), a slipping one's traction is ``−μp s/|s|`` (in μp0): ``None``, or what is wrong.
    ``mu``: a slip-velocity law's stored coefficient at the elements (else the law at the slip, or the number)."""
    slip_unit = tunit / contact.materials.Estar
    sn = np.hypot(s[0], s[1])
    stick, slipping = states == 1, (states == 2) & (sn > 0)
    if np.any(sn[stick] > RESUME_TOL * slip_unit):
        return f"state {k}: a sticking element slips"
    if mu is None:
        mu = contact.mu
        if contact.law.kind == "slip":   # a slip-velocity law without its stored coefficient: the law at the slip
            mu = contact.slip_bound("shift").mu(np.asarray(s, dtype=float), contact=np.asarray(p) > 0)
    b = mu * np.maximum(p, 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        r = np.hypot(t[0] + b * s[0] / sn, t[1] + b * s[1] / sn)
    if np.any(r[slipping] > RESUME_TOL * tunit):
        return f"state {k}: a slipping element's traction is not opposite its slip"
    return None


def _read_grid(rec: StepRecord, contact) -> tuple[dict, dict]:
    """The core fields and notes of a 3D :class:`StepRecord` (:data:`GRID`)."""
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
    meta = {"scene": scene.to_dict(), "method": method_name, "rollqp": __version__, "versions": versions(),
            "dimension": 3, "dq": scene.dq, "elements": int(g.n), "coupled": bool(contact.ops.coupled),
            "slip_note": ("state 0 of a braked start: static-shift slip per c = sqrt(ab) of shift"
                          if scene.load.start == "braked" else "state 0: the steady state")}
    constants = {"area": g.area, "wear_A": scene.A.wear or 0.0, "wear_B": scene.B.wear or 0.0,
                 "braked": float(scene.load.start == "braked")}
    return Result(g.x, {"a": e.a, "b": e.b, "p0": e.p0, "Estar": e.Estar}, meta, fields_for(scene), keep_every=keep_every,
                  out=out, operators=contact, layout=GRID, coords={"x": g.x, "y": g.y}, constants=constants)


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
        return drive(result, records, source=source, resumed_from=None if tail is None else last_index(tail),
                     operators=contact, observe=observe, progress=progress, steps=scene.n_steps)
