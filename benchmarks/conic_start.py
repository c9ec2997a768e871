"""The conic route's start of a steady state: conic steps and CPU time from zero tractions and from FASTSIM's
steady state (docs/performance.md, "The conic route and the cross-check").

    python benchmarks/conic_start.py 24 1e-3 zero fastsim     # the 24 x 24 circle at xi = 1e-3, both starts
    python benchmarks/conic_start.py 40 1e-3 fastsim          # the 40 x 40 partial-slip steady state

Each line: grid, creepage, start, conic steps of the march, CPU and wall seconds of the whole start (normal
step, FASTSIM where used, the march), Fx. The machine is shared: CPU seconds of this process and the load.
"""
from __future__ import annotations

import os
import sys
import time

from harness import pin_threads

from rollqp import load_scene
from rollqp.march.grid import normal, steady
from rollqp.march.grid import prepare


def start(n: int, xi: float, how: str, method: str = "socp-clarabel"):
    scene = load_scene("kalker-circular", {"load.creepage.longitudinal": xi, "discretization.elements": [n, n],
                                           "discretization.distance": 0.0, "solver.method": method})
    scene, meth, contact = prepare(scene)
    c0, w0 = time.process_time(), time.perf_counter()
    ns = normal(contact, meth, scene.load.normal)
    rec = steady(contact, meth, scene.load.normal, scene.loads_at(0.0), pressure=ns,
                 approximate_start=(how == "fastsim"))
    return rec.info.get("marched"), time.process_time() - c0, time.perf_counter() - w0, rec.Fx


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    n, xi, hows = int(argv[0]), float(argv[1]), argv[2:] or ["zero", "fastsim"]
    pin_threads()
    for how in hows:
        steps, cpu, wall, Fx = start(n, xi, how)
        print(f"{n} x {n}  xi = {xi:g}  from {how}: {steps} conic steps, CPU {cpu:.1f} s, wall {wall:.1f} s, "
              f"Fx = {Fx:.6f}  (load {os.getloadavg()[0]:.1f})", flush=True)


if __name__ == "__main__":
    main()
