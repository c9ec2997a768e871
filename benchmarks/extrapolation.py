"""The extrapolated creep forces against grid-converged references (docs/performance.md, "Speed against error").

For each case: ``rollqp.extrapolate.extrapolate`` with the command's defaults (three grids ``n, 2n, 3n`` of
the scene's ``n``, positions added until the creep forces' estimate is within 0.1 %, 2 worker processes) —
its value, its printed estimate, the positions it took, its wall-clock and CPU time (with its workers') —
against the reference recorded in tests/data/extrapolation/references.json (the same method on grids twice as
fine, 6 positions each; ``--reference compute`` computes it again), and where given one centred grid much
finer still (``--fine N``).

    python benchmarks/extrapolation.py                        # every case against the recorded references
    python benchmarks/extrapolation.py --cases circle-1e-3 elliptic --json out.json
    python benchmarks/extrapolation.py --cases circle-1e-3 --reference compute
    python benchmarks/extrapolation.py --scan circle-1e-5 20 25 30 35 40    # centred grids: the force and the
                                                                            # computed contact area / (pi a b)
    python benchmarks/extrapolation.py --sources circle-1e-5 40 24          # where a position's scatter comes from
    python benchmarks/extrapolation.py --averages circle-1e-5 16 40 50 60 70 80 100 120   # is F0 + C h enough?

The machine is shared (2 cores): the load average is printed with the table.
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import time
from pathlib import Path

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


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


REFERENCES = Path(__file__).resolve().parent.parent / "tests" / "data" / "extrapolation" / "references.json"


def case(name, fine=None, reference="recorded", workers=2):
    """The command's defaults (its target, ``workers`` processes) on one case against its reference: the recorded
    one (tests/data/extrapolation/references.json), one computed now (the same method on grids twice as fine,
    6 positions each), or none."""
    scene_name, over, qs = CASES[name]
    qs = (qs,) if isinstance(qs, str) else qs
    scene = load_scene(scene_name, over)
    n = min(scene.discretization.elements)
    c0, k0, w0 = time.process_time(), _children_cpu(), time.perf_counter()
    test = extrapolate(scene, workers=workers)
    wall, cpu_test = time.perf_counter() - w0, time.process_time() - c0 + _children_cpu() - k0
    recorded = {c["q"]: c for c in json.loads(REFERENCES.read_text(encoding="utf-8"))["cases"] if c["case"] == name}
    if reference == "compute":
        ref, cpu_ref = _cpu_of(lambda: extrapolate(scene, grids=(2 * n, 3 * n, 4 * n), shifts=6))
    rows = []
    for q in qs:
        t = test.forces[q]
        if t is None:
            continue
        row = {"case": name, "q": q, "value": t.value, "estimate": t.error, "cpu": cpu_test, "wall": wall,
               "workers": workers, "positions": test.shifts, "reached": test.reached, "grids": test.grids,
               "order": t.order, "means": t.values, "errors": t.scatter}
        if reference == "compute" and ref.forces[q] is not None:
            r = ref.forces[q]
            row.update({"reference": r.value, "ref_estimate": r.error, "ref_cpu": cpu_ref, "ref_grids": ref.grids,
                        "established": r.error <= 0.02 * abs(r.value)})
        elif reference == "recorded" and q in recorded:
            r = recorded[q]
            row.update({"reference": r["reference"], "ref_estimate": r["reference_estimate"],
                        "established": r["established"]})
        if "reference" in row:
            row["true_error"] = abs(t.value - row["reference"])
        if fine and "reference" in row:
            s = scene.replace(**{"discretization.elements": [round(e * fine / n) for e in scene.discretization.elements],
                                 "discretization.distance": 0.0})
            got, cpu_fine = _cpu_of(lambda: float(run(s).arrays()[q][0]))
            row.update({"fine": fine, "fine_value": got, "fine_cpu": cpu_fine})
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


def sources(name, n, count):
    """Where a position's irregular part comes from: the scatter of ``Fx`` over ``count`` random positions of
    grid ``n`` with the grid's own normal solution, with the cell-averaged Hertz pressure in its place (the
    contact edge cut smoothly), and with no slip (μ = 100)."""
    import dataclasses

    from rollqp.extrapolate import PositionedGrid
    from rollqp.march.grid import normal, prepare, steady
    scene_name, over, _ = CASES[name]
    scene = load_scene(scene_name, over)
    base = min(scene.discretization.elements)
    rng = np.random.default_rng(3)
    got = {"own pressure": [], "cell-averaged Hertz pressure": [], "no slip (mu = 100)": []}
    grid, stuck = PositionedGrid(scene, n, base), PositionedGrid(scene.replace(**{"contact.friction": 100.0}), n, base)
    for _ in range(count):
        j = int(rng.integers(1, 10 ** 6))
        for g, keys in ((grid, ("own pressure", "cell-averaged Hertz pressure")), (stuck, ("no slip (mu = 100)",))):
            sc, meth, contact = prepare(g.at(j))
            FN, loads = sc.load.normal, sc.loads_at(0.0)
            ns = normal(contact, meth, FN)
            got[keys[0]].append(contact.moments(steady(contact, meth, FN, loads, direction=sc.load.direction,
                                                       pressure=ns).t)[0])
            if len(keys) > 1:
                e, m = contact.ellipse, 12
                off = (np.arange(m) + 0.5) / m - 0.5
                X = contact.x[:, None, None] + off[None, :, None] * contact.grid.dx
                Y = contact.y[:, None, None] + off[None, None, :] * contact.grid.dy
                p = np.sqrt(np.clip(1 - (X / e.a) ** 2 - (Y / e.b) ** 2, 0, None)).mean(axis=(1, 2))
                p *= FN / (p.sum() * contact.grid.area)
                cell = dataclasses.replace(ns, p=p)
                got[keys[1]].append(contact.moments(steady(contact, meth, FN, loads, direction=sc.load.direction,
                                                           pressure=cell).t)[0])
    rows = [[k, f"{np.mean(v):.6g}", f"{100 * np.std(v, ddof=1) / abs(np.mean(v)):.3f} %"] for k, v in got.items()]
    print(f"{name}, grid {n}, {count} random positions")
    print(table(["normal solution", "mean Fx", "scatter of one position"], rows))


def averages(name, count, grids):
    """The positions' averages of ``Fx`` on each grid (``count`` positions each, the command's sequence), the
    first-order fit through them and its reduced chi-square: is ``F0 + C h`` the whole smooth part?"""
    from rollqp.extrapolate import PositionedGrid, fit_first_order, scatter, solve_position
    scene_name, over, _ = CASES[name]
    scene = load_scene(scene_name, over)
    base = min(scene.discretization.elements)
    parts = [PositionedGrid(scene, n, base) for n in grids]
    vals = []
    for g in parts:
        (v, cpu) = _cpu_of(lambda: [solve_position(g.at(j))[0] for j in range(count)])
        vals.append(np.array(v))
        print(f"grid {g.n}: {np.mean(v):.7g} ± {np.std(v, ddof=1) / np.sqrt(count):.2g}, "
              f"one position's scatter {100 * np.std(v, ddof=1) / abs(np.mean(v)):.3f} %, {cpu:.1f} s CPU", flush=True)
    h = np.array([g.h for g in parts])
    means, se = np.array([v.mean() for v in vals]), np.array([v.std(ddof=1) for v in vals]) / np.sqrt(count)
    e = fit_first_order(h, means, se)
    w = 1 / se ** 2
    M = np.column_stack([np.ones_like(h), h])
    coef = np.linalg.solve(M.T @ (w[:, None] * M), M.T @ (w * means))
    chi2 = float(np.sum(w * (means - M @ coef) ** 2)) / max(len(h) - 2, 1)
    print(f"F0 + C h through {len(h)} grids: F0 = {e.value:.7g} ± {100 * e.error / abs(e.value):.3f} % (the estimate), "
          f"reduced chi-square {chi2:.2f}; scatter floors {np.round(scatter(h, vals) / abs(e.value) * 100, 3)} %")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cases", nargs="*", default=list(CASES))
    ap.add_argument("--fine", type=int, default=None, help="one centred grid of this many elements as a check")
    ap.add_argument("--json", default=None)
    ap.add_argument("--reference", choices=("recorded", "compute", "none"), default="recorded",
                    help="the references: recorded in tests/data/extrapolation (default), computed now, or none")
    ap.add_argument("--workers", type=int, default=2, help="the command's worker processes (default 2)")
    ap.add_argument("--scan", nargs="+", default=None, help="CASE N1 N2 ...: centred grids of one case")
    ap.add_argument("--sources", nargs=3, default=None, metavar=("CASE", "N", "COUNT"),
                    help="the scatter of one position with the own pressure, the cell-averaged Hertz pressure, no slip")
    ap.add_argument("--averages", nargs="+", default=None, metavar="CASE K N1 N2",
                    help="CASE K N1 N2 ...: K positions' averages on each grid and the first-order fit's chi-square")
    args = ap.parse_args(argv)
    pin_threads()
    if args.scan:
        return scan(args.scan[0], [int(v) for v in args.scan[1:]])
    if args.sources:
        return sources(args.sources[0], int(args.sources[1]), int(args.sources[2]))
    if args.averages:
        return averages(args.averages[0], int(args.averages[1]), [int(v) for v in args.averages[2:]])
    rows = []
    for name in args.cases:
        rows += case(name, args.fine, args.reference, args.workers)
        if args.json:
            with open(args.json, "w", encoding="utf-8") as f:
                json.dump(rows, f, indent=1)
    print(f"load average {os.getloadavg()}")
    out = []
    for r in rows:
        ref = r.get("reference")
        rel = lambda v: f"{100 * v / abs(ref if ref else r['value']):.3f} %"
        checked = ref is not None and r.get("established", True)
        out.append([r["case"], r["q"], f"{r['value']:.6g}", rel(r["estimate"]), "/".join(map(str, r["positions"])),
                    f"{r['wall']:.1f}", f"{r['cpu']:.1f}",
                    f"{ref:.6g} ± {rel(r['ref_estimate'])}" if ref is not None else "-",
                    rel(r["true_error"]) if checked else "-",
                    ("yes" if r["estimate"] >= r["true_error"] else "NO") if checked else "-"])
    print(table(["case", "force", "extrapolated", "its estimate", "positions", "wall [s]", "CPU [s]",
                 "reference ± its estimate", "error", "estimate ≥ error"], out))


if __name__ == "__main__":
    main()
