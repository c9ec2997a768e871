"""Cost of the true-geometry (BEM) influence; prints markdown tables (docs/bem.md, "Cost").

Usage::

    python benchmarks/bench_bem.py              # the tables of docs/bem.md (~1 min)
    python benchmarks/bench_bem.py --repeats 3  # fewer repetitions

A. **Assembly and condensation** of the paper's meshes (§2.3): R_A = 150 mm on a 15 mm shaft,
   R_B = 300 mm on a 30 mm shaft, the strip of the built-in scene ``cattaneo-carter`` (40 QCE,
   81 nodes) plus 19 graded outer and 16 shaft elements per roller:
   :func:`rollqp.influence.bem.contact_compliance` per body (``H``, ``G`` assembly, LU of the
   body system, the 162 strip load cases), and the whole :func:`~rollqp.influence.bem.bem_influence`
   (both bodies, uncached). Target: both bodies within 2 s.
B. **Per-step cost of the transient**: ``rollqp.run`` of ``cattaneo-carter`` with
   ``contact.model = "halfspace"`` and ``"bem"`` (Newton and OSQP), median ``step_time`` of the
   rolling steps. The two models run alternately within each repetition and the ratio
   BEM/half-space is taken within the repetition, then the median. Target: the ratio is 1
   within the run-to-run noise (the step problems have the same size and structure; only the
   matrices' values differ).

BLAS is pinned to one thread (threadpoolctl) at import, before any matrix is built.
"""
from __future__ import annotations

import os

from harness import machine_table, table  # noqa: F401  (pins BLAS first)

import numpy as np  # noqa: E402
import rollqp  # noqa: E402

import argparse  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402


from rollqp import run  # noqa: E402
from rollqp.influence import bem  # noqa: E402


def assembly(scene, repeats):
    strip = rollqp.Strip(scene.half_width, scene.discretization.elements, scene.discretization.element)
    rows, totals = [], []
    for name, body in (("A", scene.A), ("B", scene.B)):
        t_all, t_asm, t_sol, info = [], [], [], None
        for _ in range(repeats):
            t0 = time.perf_counter()
            _, info = bem.contact_compliance(strip, body.radius, body.shaft_radius, body.E, body.nu)
            t_all.append(time.perf_counter() - t0)
            t_asm.append(info["assembly_seconds"])
            t_sol.append(info["solve_seconds"])
        rows.append([name, f"R = {body.radius:g}, shaft {body.shaft_radius:g}", info["nodes"], info["elements"],
                     f"{np.median(t_asm):.3f}", f"{np.median(t_sol):.4f}", f"{np.median(t_all):.3f}",
                     f"{info['memory_bytes'] / 2 ** 20:.1f}"])
    for _ in range(repeats):
        t0 = time.perf_counter()
        bem.bem_influence(strip, A=scene.A, B=scene.B, Estar=scene.Estar, beta=scene.beta)
        totals.append(time.perf_counter() - t0)
    return rows, float(np.median(totals))


def per_step(scene, methods, repeats):
    out = {}
    for m in methods:
        ratios, med = [], {"halfspace": [], "bem": []}
        for _ in range(repeats):
            times = {}
            for model in ("halfspace", "bem"):
                r = run(scene.replace(**{"contact.model": model, "solver.method": m}))
                times[model] = float(np.median(np.asarray(r.rows["step_time"])[1:]))
                med[model].append(times[model])
            ratios.append(times["bem"] / times["halfspace"])
        out[m] = (np.median(med["halfspace"]), np.median(med["bem"]), np.median(ratios),
                  np.min(ratios), np.max(ratios))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeats", type=int, default=7)
    args = ap.parse_args(argv)
    scene = rollqp.load_scene("cattaneo-carter")
    print(machine_table())
    print("\nA. BEM assembly + condensation, paper meshes (`python benchmarks/bench_bem.py`)\n")
    rows, total = assembly(scene, args.repeats)
    print(table(["body", "geometry", "nodes", "elements", "assembly s", "LU + 162 solves s", "total s",
                  "H, G, system MiB"], rows))
    print(f"\nBoth bodies and the combination (bem_influence, uncached): {total:.3f} s "
          f"(target <= 2 s: {'met' if total <= 2.0 else 'NOT met'})")
    print("\nB. Per-step cost of the §6.1.1 transient (median rolling step_time, ms)\n")
    res = per_step(scene, ["newton", "qp-osqp"], args.repeats)
    print(table(["method", "half-space ms", "BEM ms", "BEM / half-space (median)", "min", "max"],
                 [[m, f"{1e3 * h:.3f}", f"{1e3 * b:.3f}", f"{r:.3f}", f"{lo:.3f}", f"{hi:.3f}"]
                  for m, (h, b, r, lo, hi) in res.items()]))


if __name__ == "__main__":
    main()
