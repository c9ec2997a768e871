"""The QP paths' own overhead: the share of a step spent outside the solver's solve calls (issue 18).

Usage (from the repository root)::

    python benchmarks/qp_overhead.py                  # qp-osqp and qp-clarabel, 5 repeats
    python benchmarks/qp_overhead.py --repeats 1      # a smoke test

On the built-in scene ``cattaneo-carter`` (the paper's §6.1.1: 40 quadratic elements, 81 nodes,
193 rolling steps; each tangential step several QPs of the symmetric–skew splitting) every
rolling step of ``rollqp.march`` is timed as the march makes it (loads, history vector, the step
problem, the QPs, rollqp's residuals, ``w``; as :func:`harness.step_records` does), and beside it the wall
time spent inside the solver's own ``solve()`` calls during that step (``info["solve_call_time"]``
of the step's solution; a rollqp without that key is measured by timing ``osqp.OSQP.solve``, and
for Clarabel by its ``solver_time``, which there is the wall time of ``solve()``). The share
outside the solver is ``1 − solve calls / step``: median over the steps, then over the repeats, in
which the backends alternate (``harness.interleaved``). Prints a markdown table.
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
    """Wall time inside ``osqp.OSQP.solve`` while active (for a rollqp that does not report it)."""

    def __init__(self):
        import osqp
        self.cls, self.total = osqp.OSQP, 0.0
        self.original = self.cls.solve

    def __enter__(self):
        original = self.original

        def timed(obj, *args, **kw):
            t0 = time.perf_counter()
            try:
                return original(obj, *args, **kw)
            finally:
                self.total += time.perf_counter() - t0

        self.cls.solve = timed
        return self

    def __exit__(self, *exc):
        self.cls.solve = self.original


def call_time(sol, name, timer, before):
    """Wall time in the solver's solve calls during one step (module docstring)."""
    t = sol.info.get("solve_call_time")
    if t is not None:
        return float(t)
    return timer.total - before if name == "qp-osqp" else float(sol.solver_time)


def measure(name):
    """Per-step medians of one march of ``cattaneo-carter`` with method ``name``."""
    scene = rollqp.load_scene(SCENE)
    method = rollqp.methods.get_method(name, tolerance=scene.solver.tolerance)
    rows = []
    with OsqpCallTimer() as timer:
        records = rollqp.march(scene, method=method)
        next(records)  # the starting state
        while True:
            before = timer.total
            t0, c0 = time.perf_counter(), time.process_time()
            rec = next(records, None)
            wall, cpu = time.perf_counter() - t0, time.process_time() - c0
            if rec is None:
                break
            sol = rec.solution
            calls = call_time(sol, name, timer, before)
            rows.append((wall, cpu, calls, 1.0 - calls / wall, sol.info["qp_solves"], sol.residual))
    a = np.array(rows)
    return dict(step=float(np.median(a[:, 0])), cpu=float(np.median(a[:, 1])), calls=float(np.median(a[:, 2])),
                outside=float(np.median(a[:, 3])), total_outside=float(1.0 - a[:, 2].sum() / a[:, 0].sum()),
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
    for name in backends:
        rs = runs[name]
        med = {k: float(np.median([r[k] for r in rs])) for k in ("step", "cpu", "calls", "outside", "total_outside",
                                                                  "qps")}
        rows.append((f"`{name}`", ms(med["step"]), ms(med["cpu"]), ms(med["calls"]), f"{med['qps']:.0f}",
                     f"{100 * med['outside']:.1f} %", f"{100 * med['total_outside']:.1f} %",
                     f"{rs[0]['all_qps']}", f"{max(r['residual'] for r in rs):.1e}"))
    print(f"### The QP paths' overhead on `{SCENE}` (§6.1.1, 81 nodes)\n")
    print(f"{runs[backends[0]][0]['steps']} rolling steps per march; medians over the steps, then over "
          f"{args.repeats} repeat(s), the backends alternating. Times in ms. \"outside\": 1 − (time in the "
          f"solver's solve calls)/(step wall time), per step (median) and over the whole march (Σ/Σ).\n")
    print(table(["backend", "step wall", "step CPU", "in solve calls", "QPs per step", "outside, median step",
                 "outside, whole march", "QPs in the march", "max residual"], rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
