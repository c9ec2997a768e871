"""Speed of the 3D steps (docs/validation3d.md §10): wall times and ratios within one run.

    python benchmarks/three_speed.py            # about 10 minutes here (the 300 × 300 steady step dominates)
    python benchmarks/three_speed.py --quick    # without the 300 × 300 grid

1. A steady rolling step (the normal step, then the steady tangential step, Newton) on the 30 × 30
   grid of Kalker's circle and on CONTACT's 48 × 44 tractcurv grid — CONTACT's reference outputs
   print no times, so there is no CONTACT time to set it against (said in the table);
2. the same on 100 × 100 and 300 × 300 grids: the FFT path (no matrix is formed). The normal step
   starts from the Hertz pressure (``march.normal``), the steady step from zero traction;
3. Clarabel's SOCP against Newton on the same tangential step, both to rollqp's residual ≤ 1e-10
   (Clarabel polished; its unpolished residual beside it), on 16 × 16, 24 × 24 and 30 × 30 grids.

The machine is shared (2 cores, other jobs running): the load average is printed with the tables,
and only ratios within one run are meaningful.
"""
from __future__ import annotations

import argparse
import os
import time

import numpy as np
from harness import pin_threads, table

from rollqp.three.contact import Contact, Loads
from rollqp.three.grid import Grid
from rollqp.three.hertz import curvatures_for_ratio, hertz
from rollqp.three.march import normal, steady
from rollqp.three.materials import Materials
from rollqp.three.gnm import NewtonMethod
from rollqp.three.socp import ClarabelMethod

FN, MU = 1000.0, 0.3
STEEL = Materials.from_young(210e3, 0.28, 210e3, 0.28)


def best_of(fn, repeats):
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def steady_step(c, FN_, loads, path, repeats):
    """(normal time, steady tangential time, record) for one steady rolling step by Newton."""
    m = NewtonMethod(path=path)
    tn, p = best_of(lambda: normal(c, m, FN_), repeats)
    tt, rec = best_of(lambda: steady(c, m, FN_, loads, pressure=p), repeats)
    return tn, tt, rec


def section_steady(quick):
    rows = []
    cases = [("circle 30 × 30", Contact.hertzian(STEEL, (1 / 60, 1 / 60), FN, MU, elements=(30, 30), zone=(1.1, 1.1)),
              FN, "auto", 3)]
    m = Materials.from_shear(82000.0, 0.28, 82000.0, 0.28)
    B = curvatures_for_ratio(0.0008, 0.5)
    e = hertz(0.0008, B, m.Estar, 106700.0)
    g = Grid(48, 44, 2.2 * e.a / 48, 2.2 * e.b / 44, -1.1 * e.a, -1.1 * e.b)
    cases.append(("tractcurv 48 × 44", Contact(g, m, (0.0008, B), 106700.0, 0.33), 106700.0, "auto", 3))
    for n in (100,) if quick else (100, 300):
        cases.append((f"circle {n} × {n}", Contact.hertzian(STEEL, (1 / 60, 1 / 60), FN, MU, elements=(n, n),
                                                              zone=(1.1, 1.1)), FN, "krylov", 1))
    for label, c, F, path, rep in cases:
        loads = Loads(xi=-0.5 * c.scales.slip, eta=0.0)
        tn, tt, rec = steady_step(c, F, loads, path, rep)
        rows.append([label, c.grid.n, int(np.sum(rec.p > 0)), path, f"{tn:.3f}", f"{tt:.3f}",
                     f"{rec.residual:.1e}", "not printed in its ref_out" if "tractcurv" in label else "–"])
    return table(["grid", "elements", "in contact", "path", "normal [s]", "steady tangential [s]", "residual",
                  "CONTACT's time"], rows)


def section_socp(quick):
    rows = []
    for n in (16, 24) if quick else (16, 24, 30):
        c = Contact.hertzian(STEEL, (1 / 60, 1 / 60), FN, MU, elements=(n, n), zone=(1.15, 1.15))
        p = normal(c, NewtonMethod(), FN)
        prob = c.tangential_step("rolling", p.p, Loads(Fx=0.5 * MU * FN, eta=0.0), (p.p, 0.3 * MU * np.stack([p.p, 0 * p.p])),
                                 dq=c.grid.dx)
        tn, ref = best_of(lambda: NewtonMethod().solve(prob), 3)
        tk, refk = best_of(lambda: NewtonMethod(path="krylov").solve(prob), 3)
        clar = ClarabelMethod()
        tc, sol = best_of(lambda: clar.solve(prob), 2)
        d = np.max(np.abs(sol.t - ref.t)) / (MU * c.scales.stress)
        rows.append([f"{n} × {n}", int(np.sum(p.p > 0)), f"{tn:.3f}", f"{tk:.3f}", f"{tc:.3f}", f"{tc / min(tn, tk):.0f}",
                     f"{sol.residual:.0e} ({sol.info['unpolished']:.0e})", f"{max(ref.residual, refk.residual):.0e}",
                     f"{d:.1e}"])
    return table(["grid", "in contact", "Newton dense [s]", "Newton Krylov [s]", "Clarabel + polish [s]",
                  "Clarabel / best Newton", "Clarabel residual (unpolished)", "Newton residual",
                  "max\\|Δt\\|/μp0"], rows)


def main(argv=None):
    ap = argparse.ArgumentParser(description="Speed of the 3D steps (ratios within one run).")
    ap.add_argument("--quick", action="store_true", help="without the 300 × 300 grid and the 30 × 30 SOCP")
    args = ap.parse_args(argv)
    pin_threads()
    print(f"load average at start: {', '.join(f'{x:.2f}' for x in os.getloadavg())} (2 cores, shared)\n")
    for name, fn in (("steady rolling step, Newton", section_steady), ("SOCP against Newton", section_socp)):
        t0 = time.perf_counter()
        text = fn(args.quick)
        print(f"### {name} ({time.perf_counter() - t0:.0f} s)\n\n{text}\n", flush=True)
    print(f"load average at end: {', '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
