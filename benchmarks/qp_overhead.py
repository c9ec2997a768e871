"""The QP paths' own overhead: the share of a step spent outside the solver's solve calls.

Usage (from the repository root)::

    python benchmarks/qp_overhead.py                  # qp-osqp and qp-clarabel, 5 repeats
    python benchmarks/qp_overhead.py --repeats 1      # a smoke test

On the built-in scene ``cattaneo-carter`` (the paper's §6.1.1: 40 quadratic elements, 81 nodes,
193 rolling steps; each tangential step several QPs of the symmetric–skew splitting) every
rolling step of ``rollqp.march`` is timed as the march makes it (loads, history vector, the step
problem, the QPs, rollqp's residuals, ``w``; as :func:`harness.step_records` does), and beside it
the time spent inside the solver's own ``solve()`` calls during that step
(``info["solve_call_time"]`` and ``info["solve_call_cpu"]`` of the step's solution; a rollqp
without them is measured by timing ``osqp.OSQP.solve``, and for Clarabel by its ``solver_time``,
there the wall time of ``solve()``, with no CPU time). The share outside the solver is
``1 − solve calls / step``: median over the steps, then over the repeats, in which the backends
alternate (``harness.interleaved``), in CPU time (``time.process_time``; the solvers run on one
thread) and in wall time. Under a heavy load both grow (measured: ``qp-osqp`` 17 % CPU at a load
average of 4.9, 29 % at 5.9): compare runs of similar load only. Prints a markdown table.
"""
from __future__ import annotations

from harness import interleaved, machine_table, ms, table  # (pins BLAS first)

import argparse
import sys
import time

import numpy as np

import rollqp

SCENE = "cattaneo-carter"


class OsqpCallTimer:
    """Wall and CPU time inside ``osqp.OSQP.solve`` while active (for a rollqp that does not report them)."""

    def __init__(self):
        import osqp
        self.cls, self.wall, self.cpu = osqp.OSQP, 0.0, 0.0
        self.original = self.cls.solve

    def __enter__(self):
        original = self.original

        def timed(obj, *args, **kw):
            t0, c0 = time.perf_counter(), time.process_time()
            try:
                return original(obj, *args, **kw)
            finally:
                self.wall += time.perf_counter() - t0
                self.cpu += time.process_time() - c0

        self.cls.solve = timed
        return self

    def __exit__(self, *exc):
        self.cls.solve = self.original


def call_times(sol, name, timer, before):
    """(wall, CPU) time in the solver's solve calls during one step (module docstring)."""
    if "solve_call_time" in sol.info:
        return float(sol.info["solve_call_time"]), float(sol.info["solve_call_cpu"])
    if name == "qp-osqp":
        return timer.wall - before[0], timer.cpu - before[1]
    return float(sol.solver_time), float("nan")  # Clarabel's solver_time is the wall time of solve(); no CPU time


def measure(name):
    """Per-step medians of one march of ``cattaneo-carter`` with method ``name``."""
    scene = rollqp.load_scene(SCENE)
    method = rollqp.methods.get_method(name, tolerance=scene.solver.tolerance)
    rows = []
    with OsqpCallTimer() as timer:
        records = rollqp.march(scene, method=method)
        next(records)  # the starting state
        while True:
            before = (timer.wall, timer.cpu)
            t0, c0 = time.perf_counter(), time.process_time()
            rec = next(records, None)
            wall, cpu = time.perf_counter() - t0, time.process_time() - c0
            if rec is None:
                break
            sol = rec.solution
            calls, calls_cpu = call_times(sol, name, timer, before)
            rows.append((wall, cpu, calls, calls_cpu, sol.info["qp_solves"], sol.residual))
    a = np.array(rows)
    return dict(step=float(np.median(a[:, 0])), cpu=float(np.median(a[:, 1])), calls=float(np.median(a[:, 2])),
                calls_cpu=float(np.median(a[:, 3])), outside=float(np.median(1.0 - a[:, 2] / a[:, 0])),
                outside_cpu=float(np.median(1.0 - a[:, 3] / np.maximum(a[:, 1], 1e-300))),
                total_outside=float(1.0 - a[:, 2].sum() / a[:, 0].sum()),
                total_outside_cpu=float(1.0 - a[:, 3].sum() / a[:, 1].sum()),
                qps=float(np.median(a[:, 4])), all_qps=int(a[:, 4].sum()), steps=len(rows),
                residual=float(a[:, 5].max()))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5, help="repetitions, the backends alternating (default 5)")
    ap.add_argument("--backends", default="qp-osqp,qp-clarabel", help="comma-separated QP methods")
    args = ap.parse_args(argv)
    backends = [b.strip() for b in args.backends.split(",") if b.strip()]
    print("## Machine\n")
    print(machine_table())
    print()
    runs = interleaved(args.repeats, {b: b for b in backends}, measure)
    rows = []
    keys = ("step", "cpu", "calls", "calls_cpu", "outside", "outside_cpu", "total_outside", "total_outside_cpu", "qps")
    for name in backends:
        rs = runs[name]
        med = {k: float(np.median([r[k] for r in rs])) for k in keys}
        rows.append((f"`{name}`", ms(med["step"]), ms(med["cpu"]), ms(med["calls"]), ms(med["calls_cpu"]),
                     f"{med['qps']:.0f}", f"{100 * med['outside_cpu']:.1f} %", f"{100 * med['total_outside_cpu']:.1f} %",
                     f"{100 * med['outside']:.1f} %", f"{100 * med['total_outside']:.1f} %",
                     f"{rs[0]['all_qps']}", f"{max(r['residual'] for r in rs):.1e}"))
    print(f"### The QP paths' overhead on `{SCENE}` (§6.1.1, 81 nodes)\n")
    print(f"{runs[backends[0]][0]['steps']} rolling steps per march; medians over the steps, then over "
          f"{args.repeats} repeat(s), the backends alternating. Times in ms. \"outside\": 1 − (time in the "
          f"solver's solve calls)/(the step's time), per step (median) and over the whole march (Σ/Σ), in CPU "
          f"time (what a loaded machine does not inflate) and in wall time.\n")
    print(table(["backend", "step wall", "step CPU", "in solve calls (wall)", "in solve calls (CPU)", "QPs per step",
                 "outside, median step (CPU)", "outside, whole march (CPU)", "outside, median step (wall)",
                 "outside, whole march (wall)", "QPs in the march", "max residual"], rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
