"""The step's sawtooth in the stick zone: §6.1.1 at Carter's state against the step Δq (docs/matrix-free.md).

With a long step (``discretization.step = 8``: Δq = 8 Le, the fast setting of the matrix-free path) the
material formulation carries the stick zone's history several elements a step, and the steady
traction there oscillates about Carter's with the period of one step. This script measures it:
``cattaneo-carter`` with ``mf-newton`` on ``--elements`` quadratic elements, rolled ``--distance`` a_H
at each ``--steps`` value, and for each the stick zone's oscillation (the traction less its moving
average over one step), its rms against Carter, the slip zone's rms and the creepage's error.

Run it::

    python benchmarks/step_sawtooth.py                            # 2,561 nodes, steps 8 4 2 1, 3 a_H
    python benchmarks/step_sawtooth.py --elements 5000 --steps 8 --distance 6   # the 10,001-node run
"""
from __future__ import annotations

import argparse
import time

import numpy as np

import rollqp
from rollqp import closedforms as cf


def measure(elements: int, step: float, distance: float) -> dict:
    """One run and its errors against Carter at the end (μp0; the creepage relative)."""
    s = rollqp.load_scene("cattaneo-carter").replace(**{
        "solver.method": "mf-newton", "discretization.elements": elements, "discretization.step": step,
        "discretization.distance": distance})
    t0 = time.process_time()
    a = rollqp.run(s).arrays()
    cpu = time.process_time() - t0
    x, aH, p0, mu = a["x"], float(a["a_H"]), float(a["p0"]), s.contact.mu
    ratio = float(a["Q"][-1]) / (mu * float(a["P"][-1]))
    r = (a["pt"][-1] - cf.carter_traction(x, aH, p0, mu, ratio, s.load.direction)) / (mu * p0)
    state = a["state"][-1]
    stick = r[state == 1]
    period = max(int(round(2 * step)), 2)  # one step in nodes (two nodes an element)
    smooth = np.convolve(stick, np.ones(period) / period, mode="same")
    osc = (stick - smooth)[period:-period]
    xi = float(a["creepage"][-1]) / cf.carter_creepage(aH, float(a["R"]), mu, ratio) - 1
    return {"nodes": x.size, "step": step, "steps": s.n_steps, "cpu": cpu, "oscillation": float(np.abs(osc).max()),
            "stick_rms": float(np.sqrt(np.mean(stick ** 2))), "slip_rms": float(np.sqrt(np.mean(r[state == 2] ** 2))),
            "creepage": xi}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elements", type=int, default=1280)
    ap.add_argument("--steps", type=float, nargs="+", default=[8, 4, 2, 1])
    ap.add_argument("--distance", type=float, default=3.0)
    args = ap.parse_args(argv)
    print("| nodes | `discretization.step` | steps | CPU | stick-zone oscillation | stick-zone rms | slip-zone rms "
          "| ξ/ξ_Carter − 1 |\n|---|---|---|---|---|---|---|---|")
    for step in args.steps:
        m = measure(args.elements, step, args.distance)
        print(f"| {m['nodes']} | {step:g} | {m['steps']} | {m['cpu']:.1f} s | {m['oscillation']:.4f} μp0 "
              f"| {m['stick_rms']:.4f} μp0 | {m['slip_rms']:.5f} μp0 | {100 * m['creepage']:+.2f} % |", flush=True)


if __name__ == "__main__":
    main()
