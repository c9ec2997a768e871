"""The dense path's speed with ``newton``: the three figures and the step/product ratio in one run.

Usage, from the repository root::

    python benchmarks/dense_speed.py                  # 81-node step ratio, whole CLI process, 641 nodes (~1 min)
    python benchmarks/dense_speed.py --full           # and cattaneo-carter at 2,561 nodes, 6,144 steps (minutes)
    python benchmarks/dense_speed.py --elements 1280 --distance 1.0   # a shorter window of the large case

Measured, each a median where it is repeated, BLAS pinned to one thread (``harness.py``):

1. **§6.1.1, 81 nodes**: the median Newton rolling step (``step_time`` of ``rollqp.run``) against three
   dense ``n × n`` products ``A @ x`` of the same size: the ratio "Newton step / three dense products"
   (:func:`speed.newton_step_ratio`).
2. **The whole process** ``rollqp run cattaneo-carter --method newton --out F`` in fresh processes
   (interpreter start, imports, the run, the summary with its cross-check, the result file;
   :func:`speed.cli_time`), and ``import rollqp`` alone.
3. **cattaneo-carter refined** (``--elements``, default 320: 641 nodes, 1,536 steps; ``--full``: 1,280,
   2,561 nodes, 6,144 steps): the whole ``rollqp.run`` call, its stepping time Σ ``step_time``, the
   Newton iterations, and the mean step against one dense product at that ``n`` (how many products
   a step costs).
"""
from __future__ import annotations

import argparse
import sys
import time
import timeit
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from harness import machine_table, pin_threads, table  # noqa: E402
from speed import cli_time, import_time, newton_step_ratio  # noqa: E402


def product_time(n: int) -> float:
    """Seconds of one dense ``n × n`` matrix–vector product (the best of 7 repeats)."""
    rng = np.random.default_rng(0)
    A, x = rng.standard_normal((n, n)), rng.standard_normal(n)
    number = max(5, int(2e7 / (n * n)))
    return min(timeit.repeat(lambda: A @ x, number=number, repeat=7)) / number


def refined(elements: int, distance: float | None) -> dict:
    """cattaneo-carter on ``elements`` quadratic elements with ``newton``: the whole ``rollqp.run`` call."""
    import rollqp
    over = {"discretization.elements": elements}
    if distance is not None:
        over["discretization.distance"] = distance
    scene = rollqp.load_scene("cattaneo-carter").replace(**over)
    t0, c0 = time.perf_counter(), time.process_time()
    a = rollqp.run(scene, method="newton").arrays()
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    n, K = int(a["x"].size), len(a["q"]) - 1
    st = a["step_time"]
    prod = product_time(n)
    return {"n": n, "K": K, "wall": wall, "cpu": cpu, "stepping": float(st.sum()),
            "step": float(st[1:].mean()), "iterations": float(a["iterations"][1:].mean()), "product": prod}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--full", action="store_true", help="the 2,561-node case (1,280 elements, 6,144 steps)")
    ap.add_argument("--elements", type=int, default=None, help="elements of the refined case (default 320)")
    ap.add_argument("--distance", type=float, default=None, help="rolled distance / a_H of the refined case "
                                                                 "(default the scene's 6)")
    ap.add_argument("--repeats", type=int, default=5, help="repeats of the 81-node and process figures")
    args = ap.parse_args(argv)
    pin_threads()
    elements = args.elements or (1280 if args.full else 320)
    print(machine_table() + "\n", flush=True)
    rows = []
    r = newton_step_ratio(args.repeats)
    rows.append((f"§6.1.1 Newton rolling step / three dense products (n = {r['n']})",
                 f"{r['ratio']:.1f} ({1e3 * r['step']:.3f} ms / 3 × {1e6 * r['product']:.2f} µs, step by step; "
                 f"against the best batch of products: {r['ratio_batch']:.1f})"))
    t = cli_time(args.repeats)
    rows.append(("`rollqp run cattaneo-carter --method newton`, whole process (with its cross-check)", f"{t:.2f} s"))
    t = import_time(args.repeats)
    rows.append(("`import rollqp` (fresh interpreter)", f"{t:.2f} s"))
    print(table(["figure", "measured"], rows) + "\n", flush=True)
    r = refined(elements, args.distance)
    rows = [(f"{r['n']}", f"{r['K']}", f"{r['wall']:.1f}", f"{r['cpu']:.1f}", f"{r['stepping']:.1f}",
             f"{1e3 * r['step']:.2f}", f"{r['iterations']:.2f}", f"{1e3 * r['product']:.2f}",
             f"{r['step'] / r['product']:.1f}")]
    print(f"cattaneo-carter, {elements} quadratic elements, `newton`:\n")
    print(table(["nodes", "steps", "run wall [s]", "run CPU [s]", "Σ step_time [s]", "mean step [ms]",
                 "iterations / step", "dense product [ms]", "step / product"], rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
