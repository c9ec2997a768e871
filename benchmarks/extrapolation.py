"""The extrapolated creep forces against a grid-converged reference on several cases (docs/performance.md,
"Speed against error").

For each case: ``rollqp.extrapolate.extrapolate`` with the command's defaults (three grids ``n, 2n, 3n``
of the scene's ``n``, 8 positions each) — its value, its printed estimate and its CPU time — against a
reference extrapolated the same way from grids twice as fine (``2n, 3n, 4n``, 6 positions each), whose own
estimate is printed beside it; and, where given, one centred grid much finer still (``--fine N``) corrected by
the reference's fitted ``C h`` as an independent check of the reference.

    python benchmarks/extrapolation.py                        # every case (about an hour of CPU at load 10)
    python benchmarks/extrapolation.py --cases circle-1e-3 elliptic --json out.json
    python benchmarks/extrapolation.py --cases circle-1e-3 --fine 400
    python benchmarks/extrapolation.py --scan circle-1e-5 20 25 30 35 40    # centred grids: the force and the
                                                                            # computed contact area / (pi a b)

The machine is shared (2 cores, other jobs running): CPU seconds of this process are printed, and the load.
"""
from __future__ import annotations

import argparse
import json
import os
import time

import numpy as np
from harness import pin_threads, table

from rollqp import load_scene
from rollqp.extrapolate import extrapolate
from rollqp.march.grid import run

#: name -> (built-in scene, overrides, the quantity compared)
CASES = {
    "circle-1e-5": ("kalker-circular", {"load.creepage.longitudinal": 1e-5}, "Fx"),
    "circle-1e-4": ("kalker-circular", {"load.creepage.longitudinal": 1e-4}, "Fx"),
    "circle-1e-3": ("kalker-circular", {"load.creepage.longitudinal": 1e-3}, "Fx"),
    "circle-combined": ("kalker-circular", {"load.creepage.longitudinal": 5e-4, "load.creepage.lateral": 3e-4,
                                            "load.creepage.spin": 5e-4}, ("Fx", "Fy", "Mz")),
    "elliptic": ("kalker-elliptic", {}, ("Fx", "Fy", "Mz")),
    "dissimilar": ("kalker-circular", {"load.creepage.longitudinal": 1e-3, "bodies.B.E": 70000.0,
                                       "bodies.B.nu": 0.33}, "Fx"),
}


def _cpu_of(fn):
    c0 = time.process_time()
    out = fn()
    return out, time.process_time() - c0


def case(name, fine=None, reference=True):
    scene_name, over, qs = CASES[name]
    qs = (qs,) if isinstance(qs, str) else qs
    scene = load_scene(scene_name, over)
    n = min(scene.discretization.elements)
    test, cpu_test = _cpu_of(lambda: extrapolate(scene, shifts=8))
    ref, cpu_ref = (_cpu_of(lambda: extrapolate(scene, grids=(2 * n, 3 * n, 4 * n), shifts=6)) if reference
                    else (test, 0.0))
    rows = []
    for q in qs:
        t, r = test.forces[q], ref.forces[q]
        if t is None or r is None:
            continue
        row = {"case": name, "q": q, "value": t.value, "estimate": t.error, "cpu": cpu_test,
               "reference": r.value, "ref_estimate": r.error, "ref_cpu": cpu_ref,
               "true_error": abs(t.value - r.value), "grids": test.grids, "ref_grids": ref.grids,
               "order": t.order, "ref_order": r.order, "means": t.values, "errors": t.scatter,
               "ref_means": r.values, "ref_errors": r.scatter}
        if fine:
            s = scene.replace(**{"discretization.elements": [round(e * fine / n) for e in scene.discretization.elements],
                                 "discretization.distance": 0.0})
            got, cpu_fine = _cpu_of(lambda: float(run(s).arrays()[q][0]))
            # the reference's C h from its fit (F0 + C h through its finest average; h ∝ 1/elements)
            corr = (r.values[-1] - r.value) * ref.grids[-1] / fine
            row.update({"fine": fine, "fine_value": got, "fine_corrected": got - corr, "fine_cpu": cpu_fine})
        rows.append(row)
    return rows


def scan(name, grids):
    """The centred grids' force and computed contact area over ``πab``: the staircase's irregular part."""
    scene_name, over, qs = CASES[name]
    q = qs if isinstance(qs, str) else qs[0]
    scene = load_scene(scene_name, over)
    n = min(scene.discretization.elements)
    rows = []
    for g in grids:
        s = scene.replace(**{"discretization.elements": [round(e * g / n) for e in scene.discretization.elements],
                             "discretization.distance": 0.0})
        (a, cpu) = _cpu_of(lambda: run(s).arrays())
        e = s.ellipse
        area = float(np.sum(np.asarray(a["pn"])[0] > 0)) * s.grid.dx * s.grid.dy / (np.pi * e.a * e.b)
        rows.append([g, f"{float(a[q][0]):.6f}", f"{area:.5f}", f"{float(a[q][0]) / area:.6f}", f"{cpu:.2f}"])
    print(table(["grid", q, "contact area / (pi a b)", f"{q} / area ratio", "CPU [s]"], rows))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cases", nargs="*", default=list(CASES))
    ap.add_argument("--fine", type=int, default=None, help="one centred grid of this many elements as a check")
    ap.add_argument("--json", default=None)
    ap.add_argument("--no-reference", action="store_true", help="the command's extrapolation alone (no reference)")
    ap.add_argument("--scan", nargs="+", default=None, help="CASE N1 N2 ...: centred grids of one case")
    args = ap.parse_args(argv)
    pin_threads()
    if args.scan:
        return scan(args.scan[0], [int(v) for v in args.scan[1:]])
    rows = []
    for name in args.cases:
        rows += case(name, args.fine, not args.no_reference)
        if args.json:
            with open(args.json, "w", encoding="utf-8") as f:
                json.dump(rows, f, indent=1)
    print(f"load average {os.getloadavg()}")
    out = []
    for r in rows:
        rel = lambda v: f"{100 * v / abs(r['reference']):.3f} %"
        out.append([r["case"], r["q"], f"{r['value']:.6g}", rel(r["estimate"]), f"{r['cpu']:.1f}",
                    f"{r['reference']:.6g} ± {rel(r['ref_estimate'])}", rel(r["true_error"]),
                    "yes" if r["estimate"] >= r["true_error"] else "NO"])
    print(table(["case", "force", "extrapolated", "its estimate", "CPU [s]", "reference ± its estimate",
                 "true error", "estimate ≥ error"], out))


if __name__ == "__main__":
    main()
