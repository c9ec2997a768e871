"""Load paths and profiles: stop and reverse, a fretting cycle at rest, a dent rolling through.

Three built-in scenes (docs/kinematics.md):

* ``stop-reverse``: Carter rolling for 3 a_H, a stop of 1 a_H under constant loads (static
  shift steps: nothing changes), then 6 a_H backwards: the stick zone moves to the new leading
  edge and the state converges to Carter's mirrored one;
* ``fretting``: Q cycles between ±0.6 μP at rest: the tractions at the turning points and in
  between against Mindlin–Deresiewicz, and (``contact.model = "bem"``, rigid shafts) the
  Q–displacement loop and its energy per cycle against the 2D closed form;
* ``dent``: a 3 µm cosine dent rolls through a braked Carter contact: the pressure peaks at the
  dent's rims, the zones and the creepage transient.

Run it::

    python examples/load_paths.py [METHOD] [--figures DIR]

prints the measured errors; ``--figures DIR`` draws ``fretting.png`` and ``dent.png`` into DIR:
the figures ``rollqp run SCENE --plot`` draws (:mod:`rollqp.plot`), the fretting loop with the
BEM rollers' beside the half-space's and the dent's creepage with the round rollers'.
"""
from __future__ import annotations

import argparse
import os

import numpy as np

import rollqp
from rollqp import closedforms as cf
from rollqp.kinematics import hysteresis
from rollqp.report import rms_in_contact


def stop_reverse(method):
    s = rollqp.load_scene("stop-reverse")
    a = rollqp.run(s, method).arrays()
    mu, x = s.contact.friction, a["x"]
    tau = a["time"] / s.a_H
    k3, k4 = (int(np.argmin(np.abs(tau - t))) for t in (3.0, 4.0))
    out = {"stop_change": float(np.max(np.abs(a["pt"][k4] - a["pt"][k3])) / (mu * s.p0)),
           "carter_mirrored": rms_in_contact(x, s.a_H, a["pt"][-1] - cf.carter_traction(x, s.a_H, s.p0, mu, 0.75, +1))
           / (mu * s.p0)}
    return s, a, out


def fretting(method):
    s = rollqp.load_scene("fretting")
    a = rollqp.run(s, method).arrays()
    mu, x = s.contact.friction, a["x"]
    tau = a["time"] / s.a_H
    TQ, TV = s.load.tangential.q, s.load.tangential.value
    errs = []
    for k in np.flatnonzero(tau <= 5.0):
        path = [v for q, v in zip(TQ, TV) if q < tau[k]] + [float(np.interp(tau[k], TQ, TV))]
        errs.append(rms_in_contact(x, s.a_H, a["pt"][k] - cf.mindlin_traction(x, s.a_H, s.p0, mu, path)) / (mu * s.p0))
    W = cf.mindlin_dissipation(0.6, mu, s.load.normal, s.Estar)
    loops = {}
    for model in ("halfspace", "bem"):
        sb = s.replace(**{"contact.model": model, "load.rolled": 0.0, "discretization.distance": 5.0,
                          "discretization.step": 1.0})
        loops[model] = hysteresis(rollqp.run(sb, method), (1.0, 5.0))
    out = {"turning": max(errs[int(np.argmin(np.abs(tau - t)))] for t in (1.0, 3.0, 5.0)), "worst": max(errs),
           "W_closed": W, "W_halfspace": loops["halfspace"]["energy"], "W_bem": loops["bem"]["energy"]}
    return s, a, out, loops


def dent(method):
    s = rollqp.load_scene("dent")
    a = rollqp.run(s, method).arrays()
    circle = rollqp.run(s.replace(**{"bodies.A.profile": None}), method).arrays()
    out = {"peak": float(a["pn"].max() / s.p0), "creepage_swing": float(np.ptp(a["creepage"][1:]) / abs(circle["creepage"][-1]))}
    return s, a, circle, out


def figures(folder, fr, dn):
    """The figures ``rollqp run SCENE --plot`` draws for fretting and the dent (rollqp.plot), with what this
    example adds: the BEM rollers' Q–u loop beside the half-space's, and the round rollers' creepage.
    (``rollqp run stop-reverse --plot F.png`` draws the stop and the reversal as they are.)"""
    from rollqp import plot
    s, a, _, loops = fr
    fig = plot.rest_figure(a, s)
    ax = fig.axes[1]                                   # the Q–u loop panel, in units of μP/(πE*)
    scale = np.pi * s.Estar / (0.1 * s.load.normal)
    h = loops["bem"]
    i, j = int(np.argmax(h["Q"])), int(np.argmin(h["Q"]))
    k = (h["u"][i] - h["u"][j]) / (h["Q"][i] - h["Q"][j])          # the secant compliance
    ax.plot((h["u"] - h["u"][i] - k * (h["Q"] - h["Q"][i])) * scale, h["Q"] / (0.1 * s.load.normal), "--",
            color="#8c564b", lw=1.2, label=f"BEM rollers on rigid shafts: $W$ = {h['energy']:.4g} N·mm/mm")
    plot.style.legend_below(ax, ncol=1)
    fig.savefig(os.path.join(folder, "fretting.png"), dpi=120)
    plot.pyplot().close(fig)

    s, a, circle, _ = dn
    fig = plot.profile_figure(a, s)
    ax = fig.axes[-1]                                  # the creepage panel
    xi = np.asarray(circle["creepage"], dtype=float) * s.R / s.a_H
    ax.plot(circle["q"][1:] / s.a_H, xi[1:], ":", color="0.3", lw=1.2, label="round rollers (no dent)")
    plot.style.legend_below(ax, ncol=3)
    fig.savefig(os.path.join(folder, "dent.png"), dpi=120)
    plot.pyplot().close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("method", nargs="?", default="newton")
    ap.add_argument("--figures", metavar="DIR")
    args = ap.parse_args(argv)
    sr, fr, dn = stop_reverse(args.method), fretting(args.method), dent(args.method)
    print(f"stop-reverse: change over the stop {sr[2]['stop_change']:.2e} mu p0; "
          f"rms(pt - mirrored Carter) {sr[2]['carter_mirrored']:.4f} mu p0")
    print(f"fretting: rms(pt - Mindlin) at the turning points {fr[2]['turning']:.4f}, worst state {fr[2]['worst']:.4f} mu p0; "
          f"energy per cycle {fr[2]['W_halfspace']:.5g} (half-space), {fr[2]['W_bem']:.5g} (BEM) vs {fr[2]['W_closed']:.5g} N")
    print(f"dent: peak pressure {dn[3]['peak']:.3f} p0; creepage swing {dn[3]['creepage_swing']:.3f} of the steady creepage")
    if args.figures:
        figures(args.figures, fr, dn)
    return sr, fr, dn


if __name__ == "__main__":
    main()
