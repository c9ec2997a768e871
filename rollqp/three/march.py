r"""The 3D problems as sequences of steps (docs/theory3d.md §4, §6, §8).

* :func:`static_shift` — Cattaneo–Mindlin: the bodies pressed together, then shifted by the
  tangential force ``(Fx, Fy)`` in ``steps`` increments (shift steps, eq. 3D.16 at ``Δq = c``);
* :func:`steady` — steady rolling with prescribed creepages ``(ξ, η, φ)`` or forces
  ``(Fx, Fy)`` and ``φ``: solved directly by a method that solves the steady operator
  (``"steady" in method.capabilities.solves``: Newton), marched to the steady state otherwise (each step an
  SOCP with ``Δq = dx``; docs/theory3d.md §6);
* :func:`transient` — rolling in x from a start (the braked state of :func:`static_shift`) with
  steps ``Δq``: a generator of :class:`StepRecord`\ s.

Similar bodies (``K = 0``): the normal step is solved once and its pressure fixes every
tangential step. Dissimilar bodies: every step is the normal–tangential alternation
(:func:`coupled_step`, the 2D project's N–T process, paper §6.3): Gauss–Seidel over the normal
half (gap with ``A_nt t``) and the tangential half (bound ``μp``, history with ``A_tn p``) until
both halves' residuals at the common ``(p, t)`` are below the tolerance.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..advice.grid import MARCH_LENGTHS
from ..errors import InputError, SolverError
from ..methods.chord import chord_step
from ..operators.grid import Loads
from ..problem.grid import Residuals, SEPARATION, SLIP, STICK, StepSolution, disc_projection, element_states

__all__ = ["StepRecord", "normal", "coupled_step", "static_shift", "steady", "transient"]

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
           pressure=None, accelerate: str = "chord", tick=None):
    """Steady rolling (eq. 3D.17): directly if ``"steady" in method.capabilities.solves``, else as the fixed
    point of rolling steps of ``Δq = dx`` from ``start`` (a :class:`StepRecord`, or zero tractions), reached
    when a step changes the tractions by less than the method's tolerance (``info["marched"]`` steps).

    ``accelerate``: ``"chord"`` (similar bodies; default) Newton's method on the march map
    (:mod:`rollqp.methods.chord`, eq. 3D.24), every iterate evaluated by the method; ``"anderson"`` the
    march accelerated by Anderson's method with ``memory`` differences (default :data:`ANDERSON_MEMORY`;
    0: the plain march; dissimilar bodies always). ``pressure``: the normal solution to use (similar
    bodies; solved here if ``None``). ``tick(j, expected)``: called after each step of the march (``expected``: the
    steps a march usually takes, ``MARCH_LENGTHS`` contact lengths of ``dx``; it may take more or fewer)."""
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
        return _newton_to_steady(contact, method, FN, loads, direction, start, t0, pressure, tick)
    return _march_to_steady(contact, method, FN, loads, direction, start, t0,
                            ANDERSON_MEMORY if memory is None else int(memory), pressure, tick)


def _expected_march(contact) -> int:
    """The steps a march to the steady state usually takes (:data:`rollqp.advice.grid.MARCH_LENGTHS` contact
    lengths of ``dx``), for its progress."""
    return int(MARCH_LENGTHS * 2 * contact.ellipse.a / contact.grid.dx) + 1


def _newton_to_steady(contact, method, FN, loads, direction, start, t0, pressure=None, tick=None):
    """The fixed point of the march by Newton's method on the march map (:func:`rollqp.methods.chord.chord_step`),
    a march step wherever a Newton iterate does not reduce the change by :data:`NEWTON_DECREASE`."""
    nsol = pressure or normal(contact, method, FN)
    dx, n = contact.grid.dx, contact.grid.n
    shifted = contact.ops.shifted("tt", -direction * dx)
    unit = contact.mu * contact.scales.stress
    base = np.zeros((2, n)) if start is None else np.asarray(start.t, dtype=float)
    x, best, warm = base, None, None       # best: (change, x, G(x)) of the last accepted base point
    limit = int(np.ceil(MAX_MARCH_DISTANCE * contact.scales.length / dx))
    bound = contact.bound(nsol.p)
    expected = _expected_march(contact)
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
