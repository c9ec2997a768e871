"""The figure of docs/theory3d.md §11: traction vectors, stick and slip areas and the pressure of a
steady rolling 3D contact (Kalker's problem, an a/b = 0.5 ellipse with ξ, η and spin), from a real run.

    python benchmarks/three_figure.py --figure docs/figures/three_traction.png
"""
from __future__ import annotations

import argparse
import time

import numpy as np
from harness import pin_threads, pyplot

from rollqp.operators.grid import Contact, Loads
from rollqp.three.hertz import curvatures_for_ratio
from rollqp.three.march import steady
from rollqp.materials import Materials
from rollqp.methods.newton.disc import NewtonMethod


def run(elements):
    m = Materials.from_young(210e3, 0.28, 210e3, 0.28)
    A = 1 / 60
    c = Contact.hertzian(m, (A, curvatures_for_ratio(A, 0.5)), 1000.0, 0.3, elements=elements, zone=(1.15, 1.15))
    su = c.scales.slip
    loads = Loads(xi=-0.12 * su, eta=0.05 * su, phi=0.06 * su / c.scales.length)
    t0 = time.perf_counter()
    rec = steady(c, NewtonMethod(), 1000.0, loads, direction=-1)
    return c, rec, time.perf_counter() - t0


def draw(c, rec, path):
    plt = pyplot()
    g, e = c.grid, c.ellipse
    X, Y = g.field(c.x), g.field(c.y)
    fig, ax = plt.subplots(figsize=(6.4, 7.2))
    state = g.field(rec.state).astype(float)
    ax.pcolormesh(g.x / e.a, g.y / e.a, np.where(state == 1, 1.0, np.nan), cmap="Greys", vmin=0, vmax=2.5,
                  shading="nearest")
    cs = ax.contour(X / e.a, Y / e.a, g.field(rec.p) / e.p0, levels=[0.2, 0.4, 0.6, 0.8], colors="tab:blue",
                    linewidths=0.6)
    ax.clabel(cs, fontsize=7, fmt="%.1f")
    th = np.linspace(0, 2 * np.pi, 200)
    ax.plot(np.cos(th), e.b / e.a * np.sin(th), "k-", lw=0.8)
    k = 2                                   # every second element, for legibility
    tx, ty = g.field(rec.t[0]), g.field(rec.t[1])
    sl = (slice(None, None, k), slice(None, None, k))
    st = g.field(rec.state)[sl]
    slip, stick = st == 2, st == 1
    q = c.mu * e.p0
    ax.quiver((X / e.a)[sl][slip], (Y / e.a)[sl][slip], (tx / q)[sl][slip], (ty / q)[sl][slip], color="tab:red",
              scale=18, width=0.004, label="slip: t = −μp s/|s|")
    ax.quiver((X / e.a)[sl][stick], (Y / e.a)[sl][stick], (tx / q)[sl][stick], (ty / q)[sl][stick],
              color="k", scale=18, width=0.004, label="stick (grey area)")
    ax.set_aspect("equal")
    ax.set_xlabel("x / a   (material enters at x = +a)")
    ax.set_ylabel("y / a")
    ax.set_title(f"steady rolling, a/b = 0.5: ξ, η, φ = {rec.xi / c.scales.slip:.2f}, {rec.eta / c.scales.slip:.2f}, "
                 f"{rec.phi * c.scales.length / c.scales.slip:.2f} (p0/E*)\n"
                 f"Fx, Fy = {rec.Fx / (c.mu * 1000):.3f}, {rec.Fy / (c.mu * 1000):.3f} μFN; pressure contours p/p0",
                 fontsize=9)
    ax.legend(loc="lower left", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main(argv=None):
    ap = argparse.ArgumentParser(description="Draw docs/theory3d.md's traction figure from a steady rolling run.")
    ap.add_argument("--figure", default="docs/figures/three_traction.png", help="output PNG")
    ap.add_argument("--elements", type=int, nargs=2, default=(40, 80), metavar=("NX", "NY"))
    args = ap.parse_args(argv)
    pin_threads()
    c, rec, secs = run(tuple(args.elements))
    draw(c, rec, args.figure)
    print(f"{args.figure}: grid {c.grid.nx}x{c.grid.ny}, residual {rec.residual:.1e}, {secs:.1f} s, "
          f"stick {int(np.sum(rec.state == 1))}, slip {int(np.sum(rec.state == 2))} elements")


if __name__ == "__main__":
    main()
