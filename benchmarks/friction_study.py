"""Friction laws: convergence slopes, marching against the direct steady solve, Newton against the fixed point.

Prints the Markdown tables of docs/friction.md ("Convergence and cross-checks")::

    python benchmarks/friction_study.py                 # all sections (about 1–2 min on a shared 2-core machine)
    python benchmarks/friction_study.py --only slope    # one section: slope, falling, march, fixedpoint

Sections:

* ``slope``      static = kinetic (the slip-dependent Newton path) against Carter's closed-form creepage,
                 Q = 0.5 μP prescribed, direct steady solve, constant elements 23 … 368 on CONTACT's ±4.6 mm;
* ``falling``    the falling law's steady Q at ξ = −1e-3 as the mesh doubles (no closed form: successive
                 differences and their observed order);
* ``march``      a fine-mesh marching run (Q prescribed on the rising branch) against the direct steady solve;
* ``fixedpoint`` Newton against the fixed point on the bound around qp-clarabel, step by step (V = 450 mm/s);
* ``sweep``      a ramped falling-friction transient (tests/test_friction_falling.py's scene: V = 10 m/s, 80
                 constant elements, Q ramped to 0.5 μ_s P over 0.9 a_H, 4.5 a_H) for the exponential and
                 linear laws over v_h = 1 … 1e12 mm/s: each method's run (the registry's composition: the
                 solution of each step selected by the path from the frozen bound), the two runs against each
                 other, and every step of Newton's run re-solved from the same state by the bare methods
                 (the slip Newton alone, the fixed point on the bound alone), all at tolerance 1e-12: how
                 often each bare method returns another solution of the same step (about 40 min).
"""
from __future__ import annotations

import argparse
import time

import numpy as np
from harness import table  # (pins BLAS first)

from rollqp import closedforms as cf
from rollqp.methods.fixedpoint import BoundFixedPoint
from rollqp.march import march, prepare, run
from rollqp.methods import get_method
from friction_cases import FALLING_RAMP, VELDEP, veldep_scene

MESHES = (23, 46, 92, 184, 368)


def slope_section():
    """static = kinetic = 0.3: |ξ/ξ_Carter − 1| as the mesh doubles (the law's path against a closed form)."""
    rows, errs = [], []
    for n in MESHES:
        sc = veldep_scene(elements=n, static=0.3, kinetic=0.3, tangential=0.5, grid="symmetric")
        t0 = time.perf_counter()
        xi = float(run(sc, "newton").arrays()["creepage"][-1])
        ref = cf.carter_creepage(sc.a_H, sc.R, 0.3, 0.5)
        errs.append(abs(xi / ref - 1))
        order = "" if len(errs) < 2 else f"{np.log2(errs[-2] / errs[-1]):.2f}"
        rows.append([n, f"{xi:.8e}", f"{ref:.8e}", f"{errs[-1]:.2e}", order, f"{time.perf_counter() - t0:.2f}"])
    return table(["elements", "ξ (law path)", "ξ Carter", "|ξ/ξ_C − 1|", "order", "s"], rows)


def falling_section():
    rows, vals = [], []
    for n in MESHES:
        r = run(veldep_scene(elements=n, grid="symmetric"), "newton").arrays()
        vals.append(r["Q"][-1] / (0.3 * VELDEP["FN"]))
        d = "" if len(vals) < 2 else f"{abs(vals[-1] - vals[-2]):.2e}"
        order = "" if len(vals) < 3 else f"{np.log2(abs(vals[-2] - vals[-3]) / abs(vals[-1] - vals[-2])):.2f}"
        rows.append([n, f"{vals[-1]:.6f}", d, order])
    return table(["elements", "Q/(μ_s P), ξ = −0.9999e-3", "|change|", "order"], rows)


def march_section():
    """Marched to the end against the direct steady solve: V = 45 m/s with the creepage prescribed (2D: the
    transient at prescribed ξ relaxes over tens of a_H, the uniform part of w changing with Q) and
    V = 4.5 m/s with the force prescribed on a fine mesh."""
    cases = [dict(elements=92, speed=45000.0, distance=40.0, creepage=VELDEP["CKSI"], tangential=None),
             dict(elements=92, speed=4500.0, distance=10.0, creepage=None, tangential=0.5)]
    rows = []
    for c in cases:
        sc = veldep_scene(elements=c["elements"], tangential=c["tangential"],
                          **({} if c["creepage"] is None else {"creepage": c["creepage"]})).replace(
            **{"contact.friction.rolling_speed": c["speed"]})
        key = "creepage" if c["tangential"] is not None else "Q"
        steady = float(run(sc, "newton").arrays()[key][-1])
        t0 = time.perf_counter()
        r = run(sc.replace(**{"load.start": "braked", "discretization.distance": c["distance"]}), "newton").arrays()
        v = r[key]
        rows.append([f"{c['speed']:g}", "ξ" if key == "Q" else "Q", c["elements"], f"{c['distance']:g}", key,
                     f"{v[-1]:.8e}", f"{steady:.8e}", f"{abs(v[-1] / steady - 1):.2e}", f"{abs(v[-1] / v[-2] - 1):.1e}",
                     f"{time.perf_counter() - t0:.1f}"])
    return table(["V [mm/s]", "prescribed", "elements", "distance [a_H]", "compared", "marched", "direct steady",
                  "relative difference", "last step's change", "s"], rows)


def fixedpoint_section(elements=92, distance=2.0, speed=450.0):
    sc = veldep_scene(elements=elements, start="braked", distance=distance).replace(
        **{"contact.friction.rolling_speed": speed})
    fp = BoundFixedPoint(get_method("qp-clarabel", tolerance=1e-10))
    fp.setup(prepare(sc, "qp-clarabel")[2])
    worst, its = 0.0, []
    for rec in march(sc, "newton"):
        if rec.k > 0:
            sol = fp.solve(rec.problem, warm=rec.previous.tsol)
            worst = max(worst, float(np.max(np.abs(sol.t - rec.solution.t))) / (0.3 * sc.p0))
            its.append(sol.info["bound_iterations"])
    return table(["V [mm/s]", "elements", "steps", "max |Δt| / (μ_s p0)", "QPs per step (median, max)"],
                 [[f"{speed:g}", elements, len(its), f"{worst:.1e}", f"{np.median(its):g}, {max(its)}"]])


SWEEP_SCENE = {**FALLING_RAMP, "name": "falling-sweep", "solver": {"method": "newton", "tolerance": 1e-12},
               "discretization": {**FALLING_RAMP["discretization"], "distance": 4.5}}
SWEEP = [("rational", 3.0, 0.75)] + [(law, v, 4.5) for law in ("exponential", "linear")
                                    for v in (1.0, 10.0, 100.0, 1e3, 1e4, 1e6, 1e8, 1e10, 1e12)]


def _marched(sc, method):
    """``(tractions of the states, records, message)`` of a run that may stop with a SolverError."""
    from rollqp.errors import SolverError
    ts, recs = [], []
    try:
        for rec in march(sc, method):
            ts.append(rec.state.t.copy())
            recs.append(rec)
        return ts, recs, "ran"
    except SolverError as err:
        return ts, recs, f"step {err.step}: {err.status}, residual {err.residual:.1e}"


def _unselected(sc, recs, mp0):
    """Every step of the selected run re-solved from the same previous state by each method *without* the
    selection (the bare slip Newton; the fixed point on the bound around qp-clarabel): per method the steps on
    which it returns another solution (``> 1e-8`` μ_s p0 away), the largest distance, the largest residual of
    those other solutions, and the steps it fails on."""
    out = []
    for name in ("newton", "qp-clarabel"):
        raw = get_method(name, tolerance=1e-12)
        raw = raw if name == "newton" else BoundFixedPoint(raw)
        raw.setup(prepare(sc, name)[2])
        other, worst, res, failed = 0, 0.0, 0.0, 0
        for rec in recs[1:]:
            try:
                sol = raw.solve(rec.problem, warm=rec.previous.tsol)
            except Exception:  # noqa: BLE001 - a SolverError of the bare method: counted
                failed += 1
                continue
            d = float(np.max(np.abs(sol.t - rec.solution.t))) / mp0
            if d > 1e-8:
                other, worst, res = other + 1, max(worst, d), max(res, float(sol.residual))
        out.append(f"{other}" + (f" ({worst:.2f}; {res:.0e})" if other else "") + (f", {failed} failed" if failed else ""))
    return out


def sweep_section():
    """Newton and the QP fixed point (both with the selection of the path from the frozen bound) on the ramped
    falling-friction transient over the velocity scale, and the bare methods on the same steps."""
    from rollqp.scene import scene_from_dict
    rows = []
    for law, vh, dist in SWEEP:
        sc = scene_from_dict(SWEEP_SCENE).replace(**{"contact.friction.law": law, "contact.friction.velocity": vh,
                                                     "discretization.distance": dist})
        mp0 = 0.32 * sc.p0
        t0 = time.perf_counter()
        tn, recs, msg_n = _marched(sc, "newton")
        t1 = time.perf_counter()
        tq, rq, msg_q = _marched(sc, "qp-clarabel")
        t2 = time.perf_counter()
        k = min(len(tn), len(tq))
        traj = max(float(np.max(np.abs(a - b))) for a, b in zip(tn[:k], tq[:k])) / mp0
        res = max(float(r.solution.residual) for r in recs[1:] + rq[1:])
        pts = max(r.solution.info.get("path", {}).get("points", 0) for r in recs[1:])
        rows.append([law, f"{vh:g}", f"{dist:g}", f"{len(tn) - 1} ({msg_n})", f"{len(tq) - 1} ({msg_q})",
                     f"{traj:.1e}", f"{res:.0e}", pts, f"{t1 - t0:.0f} / {t2 - t1:.0f}", *_unselected(sc, recs, mp0)])
    return table(["law", "v_h [mm/s]", "a_H", "newton steps", "qp-clarabel steps", "runs: max |Δt|/(μ_s p0)",
                  "largest residual", "path points (max a step)", "s (newton / qp-clarabel)",
                  "bare newton: other solutions (max |Δt|; residual)", "bare fixed point: other solutions"], rows)


SECTIONS = {"slope": slope_section, "falling": falling_section, "march": march_section,
            "fixedpoint": fixedpoint_section, "sweep": sweep_section}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="+", choices=list(SECTIONS), help="sections to run (default all)")
    args = ap.parse_args(argv)
    for name in args.only or SECTIONS:
        print(f"\n### {name}\n")
        print(SECTIONS[name]())


if __name__ == "__main__":
    main()
