"""Speed of the 3D steps (docs/validation3d.md §10): wall times and ratios within one run.

    python benchmarks/three_speed.py            # about 10 minutes here (the 300 × 300 steady step dominates)
    python benchmarks/three_speed.py --quick    # without the 300 × 300 grid

1. A steady rolling step (the normal step, then the steady tangential step, Newton) on the 30 × 30
   grid of Kalker's circle and on CONTACT's 48 × 44 tractcurv grid — CONTACT's reference outputs
   print no times, so there is no CONTACT time to set it against (said in the table);
2. the same on 100 × 100 and 300 × 300 grids: the FFT path (no matrix is formed). The normal step
   starts from the Hertz pressure (``march.normal``), the steady step from zero traction;
3. Clarabel's SOCP against Newton on the same tangential step, both to rollqp's residual ≤ 1e-10
   (Clarabel refined on its active set; its raw residual beside it), on 16 × 16, 24 × 24 and 30 × 30 grids;
4. the built-in 3D scenes run as ``rollqp run`` runs them (``rollqp.three.run.run``, Newton, without the
   cross-check), and one conic step of each (Clarabel, the cost of the cross-check per step);
5. the conic route to a steady state on 24 × 24: Newton's method on the march map (``accelerate="chord"``)
   against the Anderson-accelerated march, at a small creepage (all stick) and a large one (partial slip).

    python benchmarks/three_speed.py --only builtins chord     # sections 4 and 5 alone (about 5 minutes)

The machine is shared (2 cores, other jobs running): the load average is printed with the tables,
and only ratios within one run are meaningful.
"""
from __future__ import annotations

import argparse
import os
import time

import numpy as np
from harness import pin_threads, table

from rollqp.operators.grid import Contact, Loads
from rollqp.discretization.grid import Grid
from rollqp.three.hertz import curvatures_for_ratio, hertz
from rollqp.three.march import normal, steady
from rollqp.materials import Materials
from rollqp.methods.newton.disc import NewtonMethod
from rollqp.methods.socp import ClarabelMethod

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
                     f"{sol.residual:.0e} ({sol.info['raw_residual']:.0e})", f"{max(ref.residual, refk.residual):.0e}",
                     f"{d:.1e}"])
    return table(["grid", "in contact", "Newton dense [s]", "Newton Krylov [s]", "Clarabel + refinement [s]",
                  "Clarabel / best Newton", "Clarabel residual (raw)", "Newton residual",
                  "max\\|Δt\\|/μp0"], rows)


def section_builtins(quick):
    """The built-in scenes: the run as ``rollqp run`` makes it (Newton), and one Clarabel step of its end."""
    from rollqp import load_scene
    from rollqp.methods import get_method
    from rollqp.three.march import coupled_step
    from rollqp.three.run import prepare, run
    rows = []
    for name in ("kalker-circular", "kalker-elliptic", "cattaneo-3d"):
        scene = load_scene(name)
        t0 = time.perf_counter()
        res = run(scene).arrays()
        wall = time.perf_counter() - t0
        _, _, contact = prepare(scene)
        clar = get_method("socp-clarabel", 3)
        clar.setup(contact)
        k = len(res["q"]) - 1
        prev = (res["pn"][k - 1].ravel(), np.stack([res["px"][k - 1].ravel(), res["py"][k - 1].ravel()])) if k else \
            (res["pn"][0].ravel(), np.stack([res["px"][0].ravel(), res["py"][0].ravel()]))
        t1 = time.perf_counter()
        coupled_step(contact, clar, scene.load.normal, "rolling", scene.loads_at(float(res["q"][k])), prev,
                     scene.dq if k else contact.grid.dx, scene.load.direction)
        tc = time.perf_counter() - t1
        n = int(np.sum(res["state"][-1] > 0))
        rows.append([name, f"{scene.grid.nx} × {scene.grid.ny}", n, k, f"{wall:.2f}", f"{float(np.sum(res['step_time'])):.2f}",
                     f"{float(np.median(res['step_time'][1:])) * 1e3:.0f}" if k else "–", f"{tc:.2f}"])
    return table(["scene", "grid", "in contact", "rolling steps", "run [s]", "stepping [s]", "median step [ms]",
                  "one Clarabel step [s]"], rows)


def section_chord(quick):
    """The conic route to a steady state: Newton on the march map against Anderson's march (Clarabel)."""
    c = Contact.hertzian(Materials.from_young(210e3, 0.25, 210e3, 0.25), (1 / 60, 1 / 60), FN, MU,
                         elements=(16, 16) if quick else (24, 24), zone=(1.25, 1.25))
    rows = []
    for xi in (1e-5, 1e-3):
        out = {}
        for acc in ("chord", "anderson"):
            m = ClarabelMethod()
            t0 = time.perf_counter()
            rec = steady(c, m, FN, Loads(xi=-xi, eta=0.0, phi=0.0), accelerate=acc)
            out[acc] = (rec, time.perf_counter() - t0)
        (a, ta), (b, tb) = out["chord"], out["anderson"]
        slip = int(np.sum(a.state == 2))
        rows.append([f"{c.grid.nx} × {c.grid.ny}", f"{xi:g}", f"{slip}/{int(np.sum(a.state > 0))}", a.info["marched"],
                     f"{ta:.1f}", b.info["marched"], f"{tb:.1f}", f"{tb / ta:.1f}",
                     f"{np.max(np.abs(a.t - b.t)) / (MU * c.scales.stress):.0e}"])
    return table(["grid", "ξ", "slip/contact", "chord steps", "chord [s]", "Anderson steps", "Anderson [s]",
                  "Anderson / chord", "max\\|Δt\\|/μp0"], rows)


SECTIONS = {"steady": ("steady rolling step, Newton", section_steady), "socp": ("SOCP against Newton", section_socp),
            "builtins": ("the built-in 3D scenes", section_builtins),
            "chord": ("the conic route to a steady state", section_chord)}


def main(argv=None):
    ap = argparse.ArgumentParser(description="Speed of the 3D steps (ratios within one run).")
    ap.add_argument("--quick", action="store_true", help="without the 300 × 300 grid and the 30 × 30 SOCP")
    ap.add_argument("--only", nargs="+", choices=sorted(SECTIONS), help="these sections only")
    args = ap.parse_args(argv)
    pin_threads()
    print(f"load average at start: {', '.join(f'{x:.2f}' for x in os.getloadavg())} (2 cores, shared)\n")
    for key in args.only or SECTIONS:
        name, fn = SECTIONS[key]
        t0 = time.perf_counter()
        text = fn(args.quick)
        print(f"### {name} ({time.perf_counter() - t0:.0f} s)\n\n{text}\n", flush=True)
    print(f"load average at end: {', '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
