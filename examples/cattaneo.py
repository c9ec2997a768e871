"""Cattaneo's problem: the braked start of the paper's §6.1 (Hertz, then a tangential load).

Similar steel rollers (the built-in scene ``cattaneo-carter``: R_A = 150 mm, R_B = 300 mm,
P = 1000 N/mm, μ = 0.1, 40 quadratic elements on ±1.25 a_H) are pressed together and then,
without rolling, loaded tangentially from Q = 0 up to Q/(μP) = 0.25, 0.5, 0.75 and 0.95 (one
static-shift step each, ``rolled distance = 0``). Each starting state is held against the
closed forms (``rollqp.closedforms``):

* Hertz: p(x) = p0·√(1 − x²/a²);
* Cattaneo–Mindlin: a central stick zone |x| < c, c/a = √(1 − Q/(μP)), where the traction is
  μp0·[√(1 − x²/a²) − (c/a)√(1 − x²/c²)], and slip at t = μp(x) outside it.

Run it::

    python examples/cattaneo.py [METHOD] [--elements N] [--figure PATH]

METHOD defaults to newton (any of ``rollqp.available_methods()``); ``--figure PATH`` draws the
pressure, the tractions and the stick zones against the closed forms.
"""
from __future__ import annotations

import argparse

import numpy as np

import rollqp
from rollqp import closedforms as cf
from rollqp.report import rms_in_contact
from rollqp.problem import STICK

#: Load ratios Q/(μP) of the braked starts.
RATIOS = (0.25, 0.5, 0.75, 0.95)




def braked_start(ratio, method="newton", elements=None):
    """State 0 of ``cattaneo-carter`` braked at Q/(μP) = ``ratio``; returns (scene, arrays)."""
    changes = {"load.tangential": {"kind": "constant", "value": float(ratio)},
               "discretization.distance": 0.0}
    if elements:
        changes["discretization.elements"] = int(elements)
    scene = rollqp.load_scene("cattaneo-carter").replace(**changes)
    return scene, rollqp.run(scene, method=method).arrays()


def measure(scene, res):
    """Errors against Hertz and Cattaneo, and the discrete stick zone, at q = 0."""
    x, a, p0, mu = res["x"], float(res["a_H"]), float(res["p0"]), scene.contact.friction
    ratio = float(res["Q"][0]) / (mu * float(res["P"][0]))
    stick = x[res["state"][0] == STICK] / a
    c = cf.cattaneo_stick_half_width(1.0, ratio)
    return {
        "ratio": ratio,
        "hertz": rms_in_contact(x, a, res["pn"][0] - cf.hertz_pressure(x, a, p0)) / p0,
        "cattaneo": rms_in_contact(x, a, res["pt"][0] - cf.cattaneo_traction(x, a, p0, mu, ratio)) / (mu * p0),
        "stick": (float(stick.min()), float(stick.max())) if stick.size else (np.nan, np.nan),
        "c": c,
        "spacing": float(x[1] - x[0]) / a,
        "residual": float(res["residual"].max()),
    }


def figure(runs, path):
    """Pressure against Hertz, tractions against Cattaneo, stick zones against c/a = √(1 − r)."""
    from rollqp.plot import LABELS, pyplot
    from rollqp.plot.style import legend_below, reference
    plt = pyplot()
    fig, ax = plt.subplots(1, 3, figsize=(15, 5.0), constrained_layout=True)
    scene, res, _ = runs[0]
    a, p0, mu = float(res["a_H"]), float(res["p0"]), scene.contact.friction
    xs = np.linspace(-1.25, 1.25, 1001)
    reference(ax[0], xs, cf.hertz_pressure(xs, 1.0, 1.0), "hertz", ls="-")
    ax[0].plot(res["x"] / a, res["pn"][0] / p0, "o", ms=3, color="C0", label="rollqp")
    ax[0].set(xlabel=LABELS["x"], ylabel=LABELS["p"], title="pressure (every braked start)")
    colors = plt.cm.viridis(np.linspace(0.78, 0.0, len(runs)))
    for color, (_, res, m) in zip(colors, runs):
        ax[1].plot(xs, cf.cattaneo_traction(xs, 1.0, 1.0, 1.0, m["ratio"]), "-", color=color, lw=0.9)
        ax[1].plot(res["x"] / a, res["pt"][0] / (mu * p0), "o", ms=3, color=color,
                   label=f"$Q/(\\mu P) = {m['ratio']:.2f}$")
    ax[1].plot(xs, cf.hertz_pressure(xs, 1.0, 1.0), ":", color="0.5", lw=0.8, label=r"bound $\mu p$")
    ax[1].set(xlabel=LABELS["x"], ylabel=LABELS["t"], title="traction: rollqp (dots), Cattaneo (lines)")
    rs = np.linspace(0, 0.999, 400)
    reference(ax[2], rs, np.sqrt(1 - rs), "cattaneo", ls="-", label=r"Cattaneo: $c/a = \sqrt{1 - Q/(\mu P)}$")
    for color, (_, _, m) in zip(colors, runs):
        ax[2].plot([m["ratio"]] * 2, m["stick"], "s", color=color, ms=4)
    reference(ax[2], rs, -np.sqrt(1 - rs), "cattaneo", ls="-", label=None)
    ax[2].set(xlabel=LABELS["Q"], ylabel=LABELS["x"], title="stick zone: outermost stick nodes (squares)")
    for axis in ax:
        axis.grid(alpha=0.3)
        legend_below(axis)
    fig.suptitle("Cattaneo: braked start of similar rollers, 40 QCE (paper §6.1.1, q = 0)")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main(method="newton", elements=None, figure_path=None, ratios=RATIOS):
    runs = []
    for ratio in ratios:
        scene, res = braked_start(ratio, method, elements)
        runs.append((scene, res, measure(scene, res)))
    scene = runs[0][0]
    print(f"Cattaneo: braked start, {scene.discretization.elements} {scene.discretization.element} "
          f"elements on ±{scene.discretization.zone} a_H, method {method}")
    print(f"  {'Q/(mu P)':>8} {'rms(p-Hertz)/p0':>16} {'rms(t-Cattaneo)/(mu p0)':>24} "
          f"{'stick nodes x/a_H':>20} {'c/a':>7} {'max residual':>13}")
    for _, _, m in runs:
        print(f"  {m['ratio']:8.2f} {m['hertz']:16.4f} {m['cattaneo']:24.4f} "
              f"{m['stick'][0]:+9.4f}..{m['stick'][1]:+.4f} {m['c']:7.4f} {m['residual']:13.1e}")
    if figure_path:
        print(f"  figure {figure(runs, figure_path)}")
    return {"runs": runs, "method": method}


def _args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("method", nargs="?", default="newton", help="step method (default newton)")
    ap.add_argument("--elements", type=int, help="elements on the zone (default: the scene's, 40)")
    ap.add_argument("--figure", metavar="PATH", help="write the figure (PNG) here")
    return ap.parse_args(argv)


if __name__ == "__main__":
    _a = _args()
    results = main(_a.method, elements=_a.elements, figure_path=_a.figure)
