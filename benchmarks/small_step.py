"""Where the §6.1.1 Newton rolling step at 81 nodes goes: its parts re-run on one captured step.

``speed.newton_step_ratio()`` compares the rolling step of ``cattaneo-carter`` (40 quadratic elements, 81
nodes, ``newton``) with three dense 81 × 81 products, each step against three products timed right after
it in the march (docs/performance.md, "Speed targets"). This script takes the median ``step_time`` of ``rollqp.run`` and then times the parts of
one step that took one Newton iteration (the common case), each alone and warm (timeit, best of 7):
the step problem's construction, the whole ``method.solve`` (in it: the solution with its slip and
rollqp's own residuals, ``problem.solution``, as Newton calls it: on its last iterate's nondimensional
traction, slip and load row), the node states of the record (``rollqp.classify``) and a dense
product. What the parts leave of the median step is the march's own logic around them and the
memory traffic between steps (a part repeated alone runs on warm caches). The mean step (the first
rolling steps take more iterations, and a new free set a new factorization) is printed too::

    python benchmarks/small_step.py [--runs 5] [--source /other/checkout [--rounds 3]]

``--source`` measures ``speed.newton_step_ratio()`` (the speed table's figure) instead, in fresh processes on
this source tree and on another one (another checkout's rollqp, measured by this checkout's benchmarks), the
two alternating
``--rounds`` times: the two trees' ratios under the same load.

The solve is timed from the previous state's solution without its kept product ``A t`` (the march
hands it over), so it does one product more than in the march (about 1.5 µs).
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import timeit
from pathlib import Path

import numpy as np

from harness import pin_threads

pin_threads()

import rollqp  # noqa: E402
from rollqp.march import prepare  # noqa: E402


def best(f, number=4000) -> float:
    """Microseconds a call, the best of 7 repetitions of ``number`` calls."""
    return min(timeit.repeat(f, number=number, repeat=7)) / number * 1e6


def measure(runs=5) -> dict:
    times = [rollqp.run("cattaneo-carter", method="newton").arrays()["step_time"][1:] for _ in range(runs)]
    steps = [np.median(t) for t in times]
    scene, method, ops = prepare("cattaneo-carter", "newton")
    records = list(rollqp.march(scene, prepared=(scene, method, ops)))
    k = next(i for i in range(len(records) // 2, len(records)) if records[i].counters.iterations == 1)
    rec, warm = records[k], records[k - 1].state.tsol
    pb, sol = rec.problem, rec.solution
    n = pb.n
    rng = np.random.default_rng(0)
    A, x = rng.standard_normal((n, n)), rng.standard_normal(n)
    mu = float(pb.mu)
    sc = pb.scales
    load = 0.0 if pb.Q is None else float(pb.f @ sol.t - pb.Q) / sc.force
    hat = (sol.t / sc.stress, sol.s / sc.slip, load)  # what Newton hands over: t̂, ŝ = y/r, the load row
    return {
        "median step (rollqp.run)": float(np.median(steps)) * 1e6,
        "mean step (rollqp.run)": float(np.median([np.mean(t) for t in times])) * 1e6,
        "step problem (ops.tangential_step)": best(lambda: ops.tangential_step(pb.p, pb.c, pb.dq, Q=pb.Q, xi=pb.xi,
                                                                               validate=False)),
        "method.solve, one Newton iteration": best(lambda: method.solve(pb, warm=warm)),
        "  in it: slip and rollqp's residuals (problem.solution)": best(lambda: pb.solution(sol.t, sol.xi, hat=hat)),
        "node states (rollqp.classify)": best(lambda: rollqp.classify(rec.state.p, rec.state.t, sol.s, mu, pb.scales,
                                                                      bound=pb.bound)),
        "one dense n × n product": best(lambda: A @ x, 20000),
    }


#: The child of ``--source``: ``speed.newton_step_ratio()`` of this checkout's benchmarks (its second argument) on
#: the rollqp of the source tree given as its first argument: the same measurement of both trees.
CHILD = """import os, sys
sys.path[:0] = [sys.argv[1], sys.argv[2]]
import harness, speed
harness.pin_threads()
r = speed.newton_step_ratio()
print(r["step"], r["product"], r["ratio"], os.getloadavg()[0])
"""


def compare(source, rounds=3) -> list:
    """``(tree, step s, product s, ratio, load)`` of ``speed.newton_step_ratio()`` on this tree and ``source``,
    alternating, each in a fresh process."""
    trees = [str(Path(__file__).resolve().parent.parent), str(Path(source).resolve())]
    env = dict(os.environ, PYTHONPATH="")
    out = []
    for _ in range(rounds):
        for tree in trees:
            got = subprocess.run([sys.executable, "-c", CHILD, tree, str(Path(__file__).resolve().parent)],
                                 capture_output=True, text=True, env=env,
                                 check=True, cwd=tree).stdout.split()
            out.append((tree, *map(float, got)))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=5, help="runs of rollqp.run for the median step (default 5)")
    ap.add_argument("--source", help="another source tree: speed.newton_step_ratio() on both, alternating")
    ap.add_argument("--rounds", type=int, default=3, help="--source: rounds of the two trees (default 3)")
    args = ap.parse_args(argv)
    if args.source:
        print("| source tree | median step µs | product in the march µs | step / 3 products, step by step | load (1 min, after) |\n|---|---|---|---|---|")
        for tree, step, product, ratio, load in compare(args.source, args.rounds):
            print(f"| {tree} | {1e6 * step:.1f} | {1e6 * product:.2f} | {ratio:.1f} | {load:.1f} |")
        return
    r = measure(args.runs)
    step = r["median step (rollqp.run)"]
    print("| part (81 nodes, cattaneo-carter, newton) | µs | share of the median step |\n|---|---|---|")
    for name, us in r.items():
        print(f"| {name} | {us:.1f} | {us / step:.0%} |")


if __name__ == "__main__":
    main()
