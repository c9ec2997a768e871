"""The tables of docs/validation-wheel-rail.md from `rollqp wheelrail-table --out ROWS.json` and CONTACT's
reference outputs.

    rollqp wheelrail-table wheel-rail --element-size 0.2 --out rows.json
    python benchmarks/wheelrail_validation.py rows.json tests/data/wheelrail/mbench_a22_left.ref_out \
        tests/data/wheelrail/mbench_a22_right.ref_out
"""
from __future__ import annotations

import json
import sys

import numpy as np

from rollqp.wheelrail.benchmark import POSITIONS, read_reference

LOAD = 10000.0


def main(rows_path, *refs):
    rows = json.load(open(rows_path))
    ref = {}
    for path in refs:
        for c in read_reference(path):
            ref[c["wheel"], c["case"]] = c
    print("| case | y_ws | wheel | patches rollqp / CONTACT | y_rail (mm) | Δy_rail | Δx | Δδ (mrad) | ΔFN | ΔFx | ΔFs "
          "| Δ(Fx,Fs) wheel | ξ rollqp / CONTACT | s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    worst = {"dy": 0.0, "dx": 0.0, "dFN": 0.0, "dF": 0.0, "dFw": 0.0}
    times = []
    for side in ("left", "right"):
        for case in range(1, 22):
            mine = [r for r in rows if r["case"] == case and r["wheel"] == side]
            if not mine:
                continue
            c = ref[side, case]
            rp = c["patches"]
            times.append(mine[0]["time"])
            # the wheel's total creep forces: track frame FX(TR) and the lateral force in the plane of the patches
            Fw = np.array([mine[0]["FX_TR"], mine[0]["FY_TR"]])
            Fr = np.array([c["FX_TR"], c["FY_TR"]])
            dFw = float(np.max(np.abs(Fw - Fr))) / LOAD
            line = f"| {case} | {POSITIONS[case - 1][0]:g} | {side} | {len(mine)} / {len(rp)} |"
            if len(mine) == len(rp):
                m, r = mine[0], rp[0]
                d = {"dy": m["YCP_R"] - r["YCP_R"], "dx": m["XCP_TR"] - r["XCP_TR"], "da": m["DELTCP"] - r["DELTCP"],
                     "dFN": (m["FN"] - r["FN"]) / LOAD, "dFx": (m["FX"] - r["FX"]) / LOAD,
                     "dFs": (m["FS"] - r["FS"]) / LOAD}
                worst["dy"] = max(worst["dy"], abs(d["dy"]))
                worst["dx"] = max(worst["dx"], abs(d["dx"]))
                worst["dFN"] = max(worst["dFN"], abs(d["dFN"]))
                worst["dF"] = max(worst["dF"], abs(d["dFx"]), abs(d["dFs"]))
                line += (f" {m['YCP_R']:.3f} | {d['dy']:+.3f} | {d['dx']:+.3f} | {1e3 * d['da']:+.2f} | "
                         f"{d['dFN']:+.2%} | {d['dFx']:+.2%} | {d['dFs']:+.2%} |")
            else:
                line += " " + ", ".join(f"{m['YCP_R']:.2f}" for m in mine) + f" (CONTACT {rp[0]['YCP_R']:.2f}) | | | | | | |"
            worst["dFw"] = max(worst["dFw"], dFw)
            line += f" {dFw:.2%} | {mine[0]['CKSI']:.3e} / {rp[0]['CKSI']:.3e} | {mine[0]['time']:.1f} |"
            print(line)
    print()
    print(f"largest: |Δy_rail| {worst['dy']:.3f} mm, |Δx| {worst['dx']:.3f} mm, |ΔFN| {worst['dFN']:.2%}, "
          f"|ΔFx|, |ΔFs| {worst['dF']:.2%} of the wheel load (patches matched one to one); wheel totals "
          f"{worst['dFw']:.2%}; time per position and wheel: median {np.median(times):.1f} s, max {max(times):.1f} s")


if __name__ == "__main__":
    main(*sys.argv[1:])
