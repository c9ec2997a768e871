"""Scaling of the *coupled* step (dissimilar bodies, full coupling) against n.

    python benchmarks/coupled_scaling.py            # newton and nt-newton, 41 … 1281 nodes

The suite's scaling study (``rollqp bench --parts scaling``) times the uncoupled §6.1.1
transient, where Newton works on one n-sized reduced system per half and reuses its
factorization. The coupled step of ``goodman-bentall`` (β = 0.5, μ = 0.3) has 2n unknowns
(p and t, minus separated nodes), couples them through the friction bound μ·max(0, p − r g),
and (from N = 200 unknowns) reuses one LU across iterations and steps through a Woodbury
update of the rows whose node case changed. This script measures what that costs: median ``step_time``
of the rolling steps after the start, iterations per step, and the dense floors
``cho_factor`` of size n and of size 2n. Same harness as the suite (benchmarks/harness.py: BLAS pinned,
failures recorded, sizes skipped when the previous one predicts more than the budget).
"""
from __future__ import annotations

import argparse
import sys

import numpy as np

from harness import cholesky_time, fit_exponent, machine_table, table, timed_run  # (pins BLAS first)
from suite import coupled_scene


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--methods", default="newton,nt-newton")
    ap.add_argument("--elements", default="20,40,80,160,320,640")
    ap.add_argument("--budget", type=float, default=60.0, help="largest predicted run time (s) of a size")
    args = ap.parse_args(argv)
    methods = args.methods.split(",")
    elements = [int(e) for e in args.elements.split(",")]
    print(machine_table("python benchmarks/coupled_scaling.py"))
    rows, per = [], {m: {} for m in methods}
    chol = {}
    last = {}
    for E in elements:
        n = 2 * E + 1
        chol[n] = (cholesky_time(n), cholesky_time(2 * n))
        cells = [n, f"{1e3 * chol[n][0]:.3f}", f"{1e3 * chol[n][1]:.3f}"]
        for m in methods:
            prev = last.get(m)
            if prev is not None and (not prev.ok or prev.wall * (n / prev.n) ** 3 > args.budget):
                cells.append("skipped (budget)" if prev.ok else "skipped (smaller size failed)")
                continue
            # 1 a_H of rolling at Δq = Le/2, 10 normal-load steps in the start (coupled_scene)
            scene = coupled_scene(**{"discretization.elements": E, "solver.max_iterations": 2000})
            r = timed_run(scene, m, str(E), repeats=3 if n <= 400 else 1, budget=5.0, keep=False)
            last[m] = r
            if not r.ok:
                cells.append(f"failed: {r.failed}")
                continue
            per[m][n] = r.step
            cells.append(f"{1e3 * r.step:.3f} ({r.step / chol[n][0]:.1f}×)")
            print(f"  {m} n = {n}: {1e3 * r.step:.3f} ms/step", file=sys.stderr)
        rows.append(cells)
    expo = ["fitted exponent (n ≥ 161)", f"{fit_exponent(list(chol), [c[0] for c in chol.values()]):.2f}",
            f"{fit_exponent(list(chol), [c[1] for c in chol.values()]):.2f}"]
    for m in methods:
        ns = sorted(per[m])
        expo.append(f"{fit_exponent(ns, [per[m][k] for k in ns]):.2f}" if len(ns) >= 2 else "–")
    rows.append(expo)
    head = ["nodes n", "`cho_factor(n)` [ms]", "`cho_factor(2n)` [ms]"] + \
           [f"`{m}` step [ms] (× cho_factor(n))" for m in methods]
    print(table(head, rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
