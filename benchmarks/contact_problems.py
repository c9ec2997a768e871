"""CONTACT's problems timed on whichever rollqp is on the path (a worker of ``three_speed.py --only contact``).

    python benchmarks/contact_problems.py 10 20      # prints one JSON line per grid and creepage case

The circle of CONTACT's comparison (curvature 1/60 per body, FN = 1000 N, μ = 0.3, steel) on ``2·per + 2``
elements a side, ``per`` elements per semi-axis; ξ alone and ξ, η, φ together (partial slip). CPU seconds of
this process (``time.process_time``), so that the other jobs of a shared machine weigh less:

- ``steady``: the normal step and the steady tangential step on a fresh contact (influence coefficients
  built, not timed; everything a first solve derives from them — dense blocks, factors — timed), best of
  ``--repeats``;
- ``step`` / ``first`` / ``mean``: a transient march of 12 rolling steps of one element: the median of steps
  2–12, the first step (which sets up what the others reuse), and the mean over all 12, best of 3 marches.

It reads the modules from the layout of this checkout or from the older one (``rollqp.three.contact``,
``rollqp.three.gnm``), so that one run can time an older commit beside this one
(``three_speed.py --only contact --old DIR``).
"""
from __future__ import annotations

import argparse
import importlib
import json
import time

import numpy as np
from threadpoolctl import threadpool_limits

FN, MU = 1000.0, 0.3
A_HERTZ = 0.5857   # mm, the circle's Hertz radius (the spin's scale)


def _modules():
    """``(Contact, Loads, Materials, NewtonMethod, normal, steady, transient)`` of this layout or the older one."""
    try:
        og = importlib.import_module("rollqp.operators.grid")
        Contact, Loads = og.Contact, og.Loads
        Materials = importlib.import_module("rollqp.materials").Materials
        Newton = importlib.import_module("rollqp.methods.newton.disc").NewtonMethod
    except ImportError:
        oc = importlib.import_module("rollqp.three.contact")
        Contact, Loads = oc.Contact, oc.Loads
        Materials = importlib.import_module("rollqp.three.materials").Materials
        Newton = importlib.import_module("rollqp.three.gnm").NewtonMethod
    try:
        march = importlib.import_module("rollqp.march.grid")
    except ImportError:   # the older layout
        march = importlib.import_module("rollqp.three.march")
    return Contact, Loads, Materials, Newton, march.normal, march.steady, march.transient


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("per", nargs="+", type=int, help="elements per semi-axis")
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args(argv)
    Contact, Loads, Materials, Newton, normal, steady, transient = _modules()
    importlib.import_module("scipy.linalg")   # its BLAS loaded before the pools are limited

    def circle(per):
        zone = (per + 1) / per * (1 + 1e-9)
        return Contact.hertzian(Materials.from_young(210e3, 0.28, 210e3, 0.28), (1 / 60, 1 / 60), FN, MU,
                                elements=(2 * per + 2, 2 * per + 2), zone=(zone, zone))

    cases = (("ξ", Loads(xi=-1e-3, eta=0.0, phi=0.0)), ("ξ, η, φ", Loads(xi=-1e-3, eta=5e-4, phi=5e-4 / A_HERTZ)))
    with threadpool_limits(1):
        for per in args.per:
            for label, loads in cases:
                best, slip, on = np.inf, 0, 0
                for _ in range(args.repeats):
                    c, m = circle(per), Newton()
                    t0 = time.process_time()
                    p = normal(c, m, FN)
                    rec = steady(c, m, FN, loads, pressure=p)
                    best = min(best, time.process_time() - t0)
                    slip, on = int(np.sum(rec.state == 2)), int(np.sum(rec.state > 0))
                marches = []
                for _ in range(3):
                    c, m = circle(per), Newton()
                    gen, cpu = transient(c, m, FN, loads, c.grid.dx, 12), []
                    next(gen)                                   # the start (its normal step)
                    while True:
                        t0 = time.process_time()
                        try:
                            next(gen)
                        except StopIteration:
                            break
                        cpu.append(time.process_time() - t0)
                    marches.append((float(np.median(cpu[1:])), cpu[0], float(np.mean(cpu))))
                step, first, mean = min(marches)
                print(json.dumps({"per": per, "case": label, "grid": f"{c.grid.nx} × {c.grid.ny}", "slip": slip,
                                  "contact": on, "steady": best, "step": step, "first": first, "mean": mean}),
                      flush=True)


if __name__ == "__main__":
    main()
