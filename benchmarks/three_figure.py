"""The figure of docs/theory3d.md §11: traction vectors, stick and slip areas and the pressure of a
steady rolling 3D contact (Kalker's problem, the a/b = 0.5 ellipse of the built-in scene
``kalker-elliptic`` with ξ, η and spin), from a real run on a finer grid than the scene's.

    python benchmarks/three_figure.py --figure docs/figures/three_traction.png
"""
from __future__ import annotations

import argparse
import time

import numpy as np
from harness import pin_threads

from rollqp import load_scene
from rollqp.plot.three import field_figure
from rollqp.march.grid import run


def main(argv=None):
    ap = argparse.ArgumentParser(description="Draw docs/theory3d.md's traction figure from a steady rolling run.")
    ap.add_argument("--figure", default="docs/figures/three_traction.png", help="output PNG")
    ap.add_argument("--elements", type=int, nargs=2, default=(40, 80), metavar=("NX", "NY"))
    args = ap.parse_args(argv)
    pin_threads()
    scene = load_scene("kalker-elliptic").replace(**{"discretization.elements": list(args.elements)})
    t0 = time.perf_counter()
    res = run(scene).arrays()
    secs = time.perf_counter() - t0
    xi, eta, phi = res["creepage"][0]
    cap = scene.mu * scene.load.normal
    title = (f"steady rolling, $a/b = 0.5$, $\\xi, \\eta, \\phi = {xi:.3g}, {eta:.3g}, {phi:.3g}$/mm:\n"
             f"$F_x, F_y = {res['Fx'][0] / cap:+.3f}, {res['Fy'][0] / cap:+.3f}\\,\\mu F_N$ "
             f"(material enters at $x = +a$)")
    field_figure(res, scene, args.figure, title=title)
    st = res["state"][0]
    print(f"{args.figure}: grid {res['x'].size}x{res['y'].size}, residual {float(res['residual'][0]):.1e}, "
          f"{secs:.1f} s, stick {int(np.sum(st == 1))}, slip {int(np.sum(st == 2))} elements")


if __name__ == "__main__":
    main()
