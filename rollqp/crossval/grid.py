r"""The cross-check of a 3D run: a few of its steps solved again by the other route, step by step
(docs/validation3d.md §6).

A run keeps the records of the steps ``0``, ``K/2`` and ``K`` (:class:`SpotObserver`);
:func:`cross_check` poses each again — from the state before it, at its loads — and solves it with
the methods of :data:`rollqp.methods.CROSS_CHECK_METHODS_3D` other than the one that ran: Newton's
run is checked by Clarabel's QP and SOCP, a conic run by Newton. Differences are from the run's own
solution, in ``p0`` (pressure) and ``μp0`` (traction); the conic solver's raw answer (before its
active-set refinement, :mod:`rollqp.methods.refine`) is compared too, and every residual is rollqp's.

**A steady state** (state 0 of a rolling start) is the fixed point of the march: one rolling step of
``Δq = dx`` from it, at its loads, must return it (docs/theory3d.md §6). That one step is a
transient SOCP — the honest cheap check of a steady state by the conic route, which reaches a
steady state itself only by marching (``solver.method = "qp-clarabel"`` on a rolling start does).

**A braked start** (phase ``"shift"``): its last static-shift step, from the state before it.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np

from ..advice.grid import conic_step_seconds, step_factor
from ..errors import InputError, RollqpError
from ..methods import (CROSS_CHECK_METHODS_3D, CROSSVAL_METHODS_3D, available_methods, capabilities, compose_3d,
                       get_method, method_class, require_3d)
from ..march.grid import _previous, coupled_step, posed_force, run

__all__ = ["SpotObserver", "CrossCheck", "cross_check", "crossval", "spot_steps", "SLACK", "AGREEMENT"]

#: The default cross-check of ``rollqp run`` may take the run's own wall time plus this many seconds: a
#: conic step whose estimated cost (:func:`rollqp.advice.grid.conic_step_seconds`) does not fit is not
#: started, and one still running at the end is stopped. ``--cross-check`` solves the three steps whatever
#: they cost.
SLACK = 3.0
#: The refined answers of two routes that solve the same step to rollqp's residual 1e-10 agree to about
#: that times the conditioning of the stick block (measured ≤ 5e-11 μp0, docs/validation3d.md §6); a
#: different stick/slip partition would differ by 1e-3 or more. Differences above this are reported as
#: a disagreement.
AGREEMENT = 1e-7


def spot_steps(K: int) -> list[int]:
    """The steps a run of ``K`` rolling steps keeps for its cross-check: 0, K/2, K (which of them are solved
    again within a time budget is :func:`cross_check`'s choice, the last first)."""
    return sorted({0, K // 2, K})


class SpotObserver:
    """``observe(record, contact)`` for :func:`rollqp.march.grid.run`: keeps the records of ``steps`` and
    the state before each (``kept[k] = (record, (p, t) before or None)``)."""

    def __init__(self, steps):
        self.steps, self.kept, self.contact, self._last = set(steps), {}, None, None

    def __len__(self) -> int:
        return len(self.kept)

    def __call__(self, rec, contact) -> None:
        self.contact = contact
        if rec.k in self.steps and rec.FN > 0:      # out of contact (FN = 0) nothing is solved
            before = rec.info.get("before") if rec.k == 0 else _previous(self._last)
            self.kept[rec.k] = (rec, before)
        self._last = rec


@dataclass
class CrossCheck:
    """The cross-check's rows: per method, the largest differences over the steps (``dp`` in p0, ``dt``
    in μp0, ``dcreep`` in p0/E*), the raw answer's (``dp_raw``, ``dt_raw``), the largest rollqp residual,
    and the time; or the error it raised. ``str()`` is the summary line of ``rollqp run``."""

    steps: list
    rows: dict = field(default_factory=dict)
    steady: bool = False
    #: ``(method, step) -> differences`` of each step (:meth:`table`).
    per_step: dict = field(default_factory=dict)
    ran: str = ""
    #: The time budget it ran under (seconds; None: none), and per method the steps it left out for it.
    budget: float | None = None
    skipped: dict = field(default_factory=dict)
    #: The estimated time of the step left out first (seconds).
    estimate: float | None = None
    #: ``(method, step) -> earlier step`` posed from the same data, whose solution it shares.
    same: dict = field(default_factory=dict)

    def table(self) -> str:
        """One line per step and method: the differences from the run's solution and rollqp's residual."""
        head = (f"{'step':>5}  {'method':<14} {'max|dp|/p0':>10} {'max|dt|/mu p0':>13} {'|d creep|':>9} "
                f"{'residual':>9} {'raw |dp|':>9} {'raw |dt|':>9}")
        lines = [f"reference: {self.ran} (its solution of each step); each step posed again from the state "
                 "before it, at its loads", head]
        for (m, k), d in sorted(self.per_step.items(), key=lambda kv: (kv[0][1], kv[0][0])):
            raw = (f"{d['dp_raw']:9.1e} {d['dt_raw']:9.1e}" if "dp_raw" in d else f"{'-':>9} {'-':>9}")
            same = f"  (the data of step {self.same[m, k]}: its solution)" if (m, k) in self.same else ""
            lines.append(f"{k:>5}  {m:<14} {d['dp']:10.1e} {d['dt']:13.1e} {d['dcreep']:9.1e} {d['residual']:9.1e} "
                         f"{raw}{same}")
        return "\n".join(lines)

    def agrees(self) -> bool:
        return all("error" not in r and max(r["dp"], r["dt"]) <= AGREEMENT for r in self.rows.values())

    def __str__(self) -> str:
        if not self.rows:
            return self._nothing()
        st = self.steps
        shown = f"{st[0]}–{st[-1]}" if len(st) > 3 and st == list(range(st[0], st[-1] + 1)) else ", ".join(map(str, st))
        head = f"{', '.join(self.rows)} on steps {shown}"
        same = {k for (_, k) in self.same}
        if same:
            head += f" ({len(same)} of them posed from the same data as an earlier step: solved once)"
        if self.steady:
            head += " (state 0 steady: one rolling step of dx from it must return it)"
        lines = [head]
        for m, r in self.rows.items():
            if "error" in r:
                lines.append(f"{m} failed: {r['error']}")
                continue
            verdict = "agree" if max(r["dp"], r["dt"]) <= AGREEMENT else f"DISAGREE (beyond {AGREEMENT:g})"
            raw = (f"; raw solver answer |dp| {r['dp_raw']:.1e}, |dt| {r['dt_raw']:.1e}"
                   if r.get("raw") else "")
            lines.append(f"{m}: {verdict}: max |dp| {r['dp']:.1e} p0, |dt| {r['dt']:.1e} mu p0, |d creepage| "
                         f"{r['dcreep']:.1e} p0/E*{raw}; residual {r['residual']:.1e}; {r['time']:.2f} s")
        for m, ks in self.skipped.items():
            lines.append(f"{m}: step{'s' if len(ks) > 1 else ''} {', '.join(map(str, sorted(ks)))} left out: beyond "
                         f"the budget of {self.budget:.1f} s (the run's own time plus {SLACK:g} s; --cross-check "
                         "solves every kept step)")
        return "\n".join(lines)

    def _nothing(self) -> str:
        if self.skipped:
            m, ks = next(iter(self.skipped.items()))
            took = (f"one {m} step takes about {self.estimate:.0f} s (estimate)" if self.estimate is not None
                    else f"a {m} step was stopped at the budget")   # a solve stopped mid-way: no estimate
            return (f"skipped: {took}, beyond the budget of "
                    f"{self.budget:.1f} s (the run's own time plus {SLACK:g} s); --cross-check solves steps {', '.join(map(str, sorted(ks)))} again, "
                    "rollqp crossval every step")
        return "nothing to check"


def _pose(scene, contact, rec, before):
    """``(kind, loads, previous, dq)`` of the step behind ``rec`` (module docstring)."""
    if "pose" in rec.info:          # a load path's step, posed as it was (rollqp.march.grid)
        kind, _, dq, _, loads = rec.info["pose"]
        return kind, loads, before, dq
    if rec.phase == "steady":
        return "rolling", scene.loads_at(0.0), (rec.p, rec.t), contact.grid.dx
    if rec.phase == "shift":
        return "shift", rec.info["loads"], before, None
    return "rolling", scene.loads_at(rec.q), before, scene.dq


def _compare(row, contact, rec, nsol, tsol) -> dict:
    sc, mu = contact.scales, contact.mu
    d = {"dp": np.max(np.abs(nsol.p - rec.p)) / sc.stress, "dt": np.max(np.abs(tsol.t - rec.t)) / ((mu or 1.0) * sc.stress),
         "dcreep": max(abs(tsol.xi - rec.xi), abs(tsol.eta - rec.eta)) / sc.slip,
         "residual": max(nsol.residual, tsol.residual)}
    rp, rt = nsol.info.get("raw"), tsol.info.get("raw")
    if rp is not None or rt is not None:
        row["raw"] = True
        d["dp_raw"] = np.max(np.abs((rp or {"p": nsol.p})["p"] - rec.p)) / sc.stress
        d["dt_raw"] = np.max(np.abs((rt or {"t": tsol.t})["t"] - rec.t)) / ((mu or 1.0) * sc.stress)
    for k, v in d.items():
        row[k] = max(row.get(k, 0.0), float(v))
    return {k: float(v) for k, v in d.items()}


def _key(kind, loads, previous, dq, constant_friction: bool = True) -> tuple:
    """The data a step is posed from, as bytes: two steps with equal keys are the same problem. The rolled
    distance ``loads.q`` is part of the data only where the friction law is read along the surface (a
    constant coefficient poses the same step at every ``q``)."""
    prev = b"" if previous is None else b"".join(np.asarray(v).tobytes() for v in previous)   # (p, t[, μ memory])
    if constant_friction:
        loads = replace(loads, q=0.0)
    return kind, repr(loads), None if dq is None else float(dq), prev


def cross_check(scene, observer: SpotObserver, ran: str, methods=None, tolerance: float = 1e-10,
                budget: float | None = None) -> CrossCheck:
    """Solve the kept steps of a run (``observer``) again with ``methods`` (default: the registry's
    :data:`~rollqp.methods.CROSS_CHECK_METHODS_3D` without ``ran``) and compare (module docstring).

    A step posed from exactly the same data as one solved before (the same state before it, bit for bit,
    the same loads and ``Δq``: the rolling steps that reproduce a steady state) is not solved again: its
    solution is that step's, compared with the run's own solution of it (``CrossCheck.same``).

    ``budget`` (seconds; None: none) bounds the wall time: the steps are taken the last first, a step
    whose estimated conic cost (:func:`rollqp.advice.grid.conic_step_seconds`) does not fit what is left
    is not started, and a conic solve still running at the end is stopped (``CrossCheck.skipped``)."""
    if methods is None:      # the other route: not the class that ran (socp-clarabel and qp-clarabel are one)
        methods = [m for m in CROSS_CHECK_METHODS_3D if method_class(m, 3) is not method_class(ran, 3)]
    names = [m for m in methods if m != ran]
    contact, kept = observer.contact, observer.kept
    t_start = time.perf_counter()
    deadline = None if budget is None else t_start + budget
    order = sorted(kept, reverse=budget is not None)
    out = CrossCheck(sorted(kept), steady=any(rec.phase == "steady" for rec, _ in kept.values()), ran=ran,
                     budget=budget)
    for name in names:
        row, k, done, measured = {}, None, {}, None
        t0 = time.perf_counter()
        try:
            method = get_method(name, 3, tolerance=tolerance)
            conic = not capabilities(name, 3).matrix_free
            if deadline is not None and conic:
                method.deadline = deadline
            method = compose_3d(method, friction=contact.law.kind)   # a slip-velocity law: as the run composes it
            method.setup(contact)
            for k in order:
                rec, before = kept[k]
                kind, loads, previous, dq = _pose(scene, contact, rec, before)
                key = _key(kind, loads, previous, dq, contact.law.kind == "constant")
                if key not in done:
                    m = max(int(np.sum(rec.p > 0)), 1)
                    # the estimate: the model's before the first conic step, then that step's own time
                    # (a step of dissimilar bodies: its N–T sweeps, rollqp.advice.grid.step_factor)
                    est = (conic_step_seconds(m) * step_factor(scene.materials.K, tolerance) if measured is None
                           else measured[0] * (m / measured[1]) ** 2)
                    if deadline is not None and conic and time.perf_counter() + est > deadline:
                        out.skipped.setdefault(name, []).append(k)
                        out.estimate = max(out.estimate or 0.0, est)
                        continue
                    t1 = time.perf_counter()
                    FN, direction = posed_force(scene, rec)
                    nsol, tsol, _ = coupled_step(contact, method, FN, kind, loads, previous, dq, direction)
                    measured = (time.perf_counter() - t1, m)
                    done[key] = (k, nsol, tsol)
                else:
                    out.same[name, k] = done[key][0]
                out.per_step[name, k] = _compare(row, contact, rec, *done[key][1:])
        except RollqpError as err:
            if getattr(err, "status", None) == "budget":
                out.skipped.setdefault(name, []).append(k)
            else:
                row = {"error": f"step {k}: {err}" if k is not None else str(err)}
        row["time"] = time.perf_counter() - t0
        if "dp" in row or "error" in row:
            out.rows[name] = row
    out.steps = sorted({k for (_, k) in out.per_step})
    return out


def crossval(scene, step: int | None = None, methods=None, tolerance: float = 1e-10) -> CrossCheck:
    """``rollqp crossval`` of a 3D scene: run it with its method (``solver.method``), then solve every
    stored step (or only ``step``) again with each of ``methods`` (default: the installed ones of
    :data:`rollqp.methods.CROSSVAL_METHODS_3D` other than the run's), each posed from the run's state
    before it and compared with the run's solution; every residual is rollqp's (module docstring).

    Raises
    ------
    InputError
        ``--step`` outside ``0 … K``, or a method that cannot solve the scene's steps.
    """
    K = scene.n_steps
    if step is not None and not (isinstance(step, int) and 0 <= step <= K):
        raise InputError("--step", f"must be an integer in [0, {K}] ({scene.name!r} has {K} rolling steps), got "
                                   f"{step!r}")
    if methods is None:
        installed = set(available_methods(3))
        methods = [m for m in CROSSVAL_METHODS_3D if m in installed]
    for name in methods:
        require_3d(name, "--methods")
    observer = SpotObserver(range(K + 1) if step is None else [step])
    run(scene, observe=observer)
    return cross_check(scene, observer, scene.solver.method, methods=methods, tolerance=tolerance)
