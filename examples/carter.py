"""Carter's problem: steady rolling of similar cylinders, and the creep-force law.

The rollers of the paper's §6.1 (built-in scene ``cattaneo-carter``: steel on steel, μ = 0.1,
40 quadratic elements on ±1.25 a_H, material moving in −x so that it enters at x = +a) roll
steadily under a tangential load Q. The steady state is solved directly
(``load.start = "rolling"``, rolled distance 0: with ``newton`` the steady problem
s = ξ + d·∂w/∂x is one nonsmooth system, docs/formulation.md §2) and held against Carter's closed
forms (``rollqp.closedforms``):

* traction: a stick zone of half-width c = a√(1 − Q/(μP)) touching the leading edge, where
  t = μp0[√(1 − x²/a²) − (c/a)√(1 − (x − x_c)²/c²)], x_c = −d(a − c); t = μp elsewhere;
* creepage: ξ = −sgn(Q)(μa/R)(1 − √(1 − |Q|/(μP))), i.e. the creep-force law
  |Q|/(μP) = 1 − (1 − |ξ|R/(μa))².

Run it::

    python examples/carter.py [METHOD] [--elements N] [--figure PATH]

METHOD defaults to newton (``nt-newton`` also solves the steady problem directly; the QP methods
reach it by marching the transient, which takes longer). ``--figure PATH`` draws the tractions
and the creep curve against Carter's.
"""
from __future__ import annotations

import argparse

import numpy as np

import rollqp
from rollqp import closedforms as cf
from rollqp.report import rms_in_contact
from rollqp.problem import STICK

#: Load ratios Q/(μP) whose tractions are drawn and checked.
RATIOS = (0.25, 0.5, 0.75, 0.95)
#: Load ratios of the creep curve (RATIOS included).
CURVE = (0.05, 0.1, 0.2, 0.25, 0.3, 0.4, 0.5, 0.6, 0.7, 0.75, 0.8, 0.9, 0.95)




def steady(ratio, method="newton", elements=None):
    """The steady rolling state of ``cattaneo-carter`` at Q/(μP) = ``ratio``: (scene, arrays)."""
    changes = {"load.tangential": {"kind": "constant", "value": float(ratio)},
               "load.start": "rolling", "discretization.distance": 0.0}
    if elements:
        changes["discretization.elements"] = int(elements)
    scene = rollqp.load_scene("cattaneo-carter").replace(**changes)
    return scene, rollqp.run(scene, method=method).arrays()


def measure(scene, res):
    """Traction and creepage against Carter's closed forms; the discrete stick zone."""
    x, a, p0, R = res["x"], float(res["a_H"]), float(res["p0"]), float(res["R"])
    mu, d = scene.contact.friction, scene.load.direction
    ratio = float(res["Q"][0]) / (mu * float(res["P"][0]))
    xi, xi_c = float(res["creepage"][0]), cf.carter_creepage(a, R, mu, ratio)
    stick = x[res["state"][0] == STICK] / a
    return {
        "ratio": ratio,
        "carter": rms_in_contact(x, a, res["pt"][0] - cf.carter_traction(x, a, p0, mu, ratio, d)) / (mu * p0),
        "xi": xi,
        "xi_carter": xi_c,
        "xi_error": xi / xi_c - 1.0,
        "law_ratio": float(cf.creep_force_ratio(xi, a, R, mu)),
        "stick": (float(stick.min()), float(stick.max())) if stick.size else (np.nan, np.nan),
        "stick_carter": tuple(v / a for v in cf.carter_stick_zone(a, ratio, d)),
        "spacing": float(x[1] - x[0]) / a,
        "residual": float(res["residual"].max()),
    }


def figure(runs, curve, path):
    """Tractions against Carter's, and the creep curve against Carter's law."""
    from rollqp.plot import LABELS, pyplot
    from rollqp.plot.style import legend_below, reference
    plt = pyplot()
    fig, ax = plt.subplots(1, 2, figsize=(12, 5.0), constrained_layout=True)
    scene = runs[0][0]
    d = scene.load.direction
    xs = np.linspace(-1.25, 1.25, 1001)
    colors = plt.cm.viridis(np.linspace(0.78, 0.0, len(runs)))
    for color, (_, res, m) in zip(colors, runs):
        a, p0, mu = float(res["a_H"]), float(res["p0"]), scene.contact.friction
        ax[0].plot(xs, cf.carter_traction(xs, 1.0, 1.0, 1.0, m["ratio"], d), "-", color=color, lw=0.9)
        ax[0].plot(res["x"] / a, res["pt"][0] / (mu * p0), "o", ms=3, color=color,
                   label=f"$Q/(\\mu P) = {m['ratio']:.2f}$")
    ax[0].plot(xs, cf.hertz_pressure(xs, 1.0, 1.0), ":", color="0.5", lw=0.8, label=r"bound $\mu p$")
    ax[0].annotate("leading edge", xy=(-d * 1.0, 0.0), xytext=(-d * 0.7, 0.1), ha="center", fontsize=8,
                   arrowprops={"arrowstyle": "->", "lw": 0.6})
    ax[0].set(xlabel=LABELS["x"], ylabel=LABELS["t"],
              title=f"steady traction: rollqp (dots), Carter (lines); material moves in {'+' if d > 0 else '-'}x")
    k = np.linspace(0, 1, 400)
    reference(ax[1], k, 1 - (1 - k) ** 2, "carter", ls="-", label=r"Carter: $Q/(\mu P) = 1 - (1 - |\xi| R/(\mu a))^2$")
    xi_n = [abs(m["xi"]) * m["R"] / (m["mu"] * m["a"]) for m in curve]
    ax[1].plot(xi_n, [m["ratio"] for m in curve], "o", ms=4, color="C0", label="rollqp, direct steady solve")
    ax[1].set(xlabel=r"$|\xi|\,R/(\mu a_H)$", ylabel=LABELS["Q"], title="creep-force law")
    for axis in ax:
        axis.grid(alpha=0.3)
        legend_below(axis)
    fig.suptitle("Carter: steady rolling of similar rollers, 40 QCE (paper §6.1.1, the end state)")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main(method="newton", elements=None, figure_path=None, ratios=RATIOS, curve=CURVE):
    runs, points = [], []
    for ratio in sorted(set(ratios) | set(curve)):
        scene, res = steady(ratio, method, elements)
        m = measure(scene, res)
        m.update(nominal=ratio, a=float(res["a_H"]), R=float(res["R"]), mu=scene.contact.friction)
        points.append(m)
        if ratio in ratios:
            runs.append((scene, res, m))
    scene = runs[0][0]
    print(f"Carter: steady rolling, {scene.discretization.elements} {scene.discretization.element} elements "
          f"on ±{scene.discretization.zone} a_H, d = {scene.load.direction}, method {method}")
    print(f"  {'Q/(mu P)':>8} {'rms(t-Carter)/(mu p0)':>22} {'xi':>12} {'xi/xi_Carter-1':>15} "
          f"{'law: Q/(mu P)(xi)':>18} {'stick x/a_H':>17} {'Carter':>17} {'residual':>9}")
    for m in points:
        carter = f"{m['carter']:22.4f}" if m["nominal"] in ratios else f"{'':>22}"
        print(f"  {m['ratio']:8.2f} {carter} {m['xi']:12.5e} {m['xi_error']:+15.4%} {m['law_ratio']:18.4f} "
              f"{m['stick'][0]:+8.4f}..{m['stick'][1]:+.4f} {m['stick_carter'][0]:+8.4f}..{m['stick_carter'][1]:+.4f} "
              f"{m['residual']:9.1e}")
    if figure_path:
        print(f"  figure {figure(runs, points, figure_path)}")
    return {"runs": runs, "curve": points, "method": method}


def _args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("method", nargs="?", default="newton", help="step method (default newton)")
    ap.add_argument("--elements", type=int, help="elements on the zone (default: the scene's, 40)")
    ap.add_argument("--figure", metavar="PATH", help="write the figure (PNG) here")
    return ap.parse_args(argv)


if __name__ == "__main__":
    _a = _args()
    results = main(_a.method, elements=_a.elements, figure_path=_a.figure)
