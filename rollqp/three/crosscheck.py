r"""The cross-check of a 3D run: a few of its steps solved again by the other route, step by step
(docs/validation3d.md §6).

A run keeps the records of the steps ``0``, ``K/2`` and ``K`` (:class:`SpotObserver`);
:func:`cross_check` poses each again — from the state before it, at its loads — and solves it with
the methods of :data:`rollqp.methods.CROSS_CHECK_METHODS_3D` other than the one that ran: Newton's
run is checked by Clarabel's QP and SOCP, a conic run by Newton. Differences are from the run's own
solution, in ``p0`` (pressure) and ``μp0`` (traction); the conic solver's raw answer (before its
active-set refinement, :mod:`rollqp.three.refine`) is compared too, and every residual is rollqp's.

**A steady state** (state 0 of a rolling start) is the fixed point of the march: one rolling step of
``Δq = dx`` from it, at its loads, must return it (docs/theory3d.md §6). That one step is a
transient SOCP — the honest cheap check of a steady state by the conic route, which reaches a
steady state itself only by marching (``solver.method = "qp-clarabel"`` on a rolling start does).

**A braked start** (phase ``"shift"``): its last static-shift step, from the state before it.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import RollqpError
from .march import coupled_step

__all__ = ["SpotObserver", "CrossCheck", "cross_check", "spot_steps", "SPOT_MAX_CONTACT", "AGREEMENT"]

#: Largest number of contact elements cross-checked by default: one Clarabel SOCP has twice as many
#: variables and a dense Hessian (measured here: 0.35 s at 300 contact elements, 5.3 s at 812, growing
#: like their cube); ``--cross-check`` forces it beyond.
SPOT_MAX_CONTACT = 1000
#: The refined answers of two routes that solve the same step to rollqp's residual 1e-10 agree to about
#: that times the conditioning of the stick block (measured ≤ 5e-11 μp0, docs/validation3d.md §6); a
#: different stick/slip partition would differ by 1e-3 or more. Differences above this are reported as
#: a disagreement.
AGREEMENT = 1e-7


def spot_steps(K: int) -> list[int]:
    """The steps a run of ``K`` rolling steps keeps for its cross-check: 0, K/2, K."""
    return sorted({0, K // 2, K})


class SpotObserver:
    """``observe(record, contact)`` for :func:`rollqp.three.run.run`: keeps the records of ``steps`` and
    the state before each (``kept[k] = (record, (p, t) before or None)``)."""

    def __init__(self, steps):
        self.steps, self.kept, self.contact, self._last = set(steps), {}, None, None

    def __len__(self) -> int:
        return len(self.kept)

    def __call__(self, rec, contact) -> None:
        self.contact = contact
        if rec.k in self.steps:
            before = rec.info.get("before") if rec.k == 0 else (self._last.p, self._last.t)
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

    def agrees(self) -> bool:
        return all("error" not in r and max(r["dp"], r["dt"]) <= AGREEMENT for r in self.rows.values())

    def __str__(self) -> str:
        head = f"{', '.join(self.rows)} on steps {', '.join(map(str, self.steps))}"
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
        return "\n".join(lines)


def _pose(scene, contact, rec, before):
    """``(kind, loads, previous, dq)`` of the step behind ``rec`` (module docstring)."""
    if rec.phase == "steady":
        return "rolling", scene.loads_at(0.0), (rec.p, rec.t), contact.grid.dx
    if rec.phase == "shift":
        return "shift", rec.info["loads"], before, None
    return "rolling", scene.loads_at(rec.q), before, scene.dq


def _compare(row, contact, rec, nsol, tsol):
    sc, mu = contact.scales, contact.mu
    d = {"dp": np.max(np.abs(nsol.p - rec.p)) / sc.stress, "dt": np.max(np.abs(tsol.t - rec.t)) / (mu * sc.stress),
         "dcreep": max(abs(tsol.xi - rec.xi), abs(tsol.eta - rec.eta)) / sc.slip,
         "residual": max(nsol.residual, tsol.residual)}
    rp, rt = nsol.info.get("raw"), tsol.info.get("raw")
    if rp is not None or rt is not None:
        row["raw"] = True
        d["dp_raw"] = np.max(np.abs((rp or {"p": nsol.p})["p"] - rec.p)) / sc.stress
        d["dt_raw"] = np.max(np.abs((rt or {"t": tsol.t})["t"] - rec.t)) / (mu * sc.stress)
    for k, v in d.items():
        row[k] = max(row.get(k, 0.0), float(v))


def cross_check(scene, observer: SpotObserver, ran: str, methods=None, tolerance: float = 1e-10) -> CrossCheck:
    """Solve the kept steps of a run (``observer``) again with ``methods`` (default: the registry's
    :data:`~rollqp.methods.CROSS_CHECK_METHODS_3D` without ``ran``) and compare (module docstring)."""
    from ..methods import CROSS_CHECK_METHODS_3D, get_method
    names = [m for m in (methods or CROSS_CHECK_METHODS_3D) if m != ran]
    contact, kept = observer.contact, observer.kept
    out = CrossCheck(sorted(kept), steady=any(rec.phase == "steady" for rec, _ in kept.values()))
    for name in names:
        row, k = {}, None
        t0 = time.perf_counter()
        try:
            method = get_method(name, 3, tolerance=tolerance)
            method.setup(contact)
            for k in sorted(kept):
                rec, before = kept[k]
                kind, loads, previous, dq = _pose(scene, contact, rec, before)
                nsol, tsol, _ = coupled_step(contact, method, scene.load.normal, kind, loads, previous, dq,
                                             scene.load.direction)
                _compare(row, contact, rec, nsol, tsol)
        except RollqpError as err:
            row = {"error": f"step {k}: {err}" if k is not None else str(err)}
        row["time"] = time.perf_counter() - t0
        out.rows[name] = row
    return out
