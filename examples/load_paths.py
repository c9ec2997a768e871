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

prints the measured errors; ``--figures DIR`` draws ``stop-reverse.png``, ``fretting.png`` and
``dent.png`` into DIR.
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


def _zones(ax, a, yscale, ylabel):
    ax.pcolormesh(a["x"] / float(a["a_H"]), yscale, a["state"], cmap="viridis", shading="nearest", vmin=0, vmax=2)
    ax.set_xlabel("x / a_H")
    ax.set_ylabel(ylabel)
    ax.set_title("zones (0 separation, 1 stick, 2 slip)")


def figures(folder, sr, fr, dn):
    from rollqp.plot import pyplot
    plt = pyplot()
    s, a, _ = sr
    fig, ax = plt.subplots(1, 2, figsize=(11, 4))
    tau = a["time"] / s.a_H
    for t in (0.0, 3.0, 4.0, 5.0, 10.0):
        k = int(np.argmin(np.abs(tau - t)))
        ax[0].plot(a["x"] / s.a_H, a["pt"][k] / (0.1 * s.p0), label=f"tau = {t:g} a_H, q = {a['q'][k] / s.a_H:.2g} a_H")
    ax[0].plot(a["x"] / s.a_H, cf.carter_traction(a["x"], s.a_H, s.p0, 0.1, 0.75, +1) / (0.1 * s.p0), "k:", label="Carter, reversed")
    ax[0].set_xlabel("x / a_H"), ax[0].set_ylabel("t / (mu p0)"), ax[0].legend(fontsize=7)
    _zones(ax[1], a, tau, "tau / a_H")
    fig.tight_layout(), fig.savefig(os.path.join(folder, "stop-reverse.png"), dpi=110), plt.close(fig)

    s, a, _, loops = fr
    fig, ax = plt.subplots(1, 2, figsize=(11, 4))
    tau = a["time"] / s.a_H
    TQ, TV = s.load.tangential.q, s.load.tangential.value
    for t in (0.0, 0.5, 1.0, 2.0, 3.0):
        k = int(np.argmin(np.abs(tau - t)))
        path = [v for q, v in zip(TQ, TV) if q < tau[k]] + [float(np.interp(tau[k], TQ, TV))]
        line, = ax[0].plot(a["x"] / s.a_H, a["pt"][k] / (0.1 * s.p0), "o", ms=3, label=f"tau = {t:g}, Q/(mu P) = {path[-1]:+.2f}")
        ax[0].plot(a["x"] / s.a_H, cf.mindlin_traction(a["x"], s.a_H, s.p0, 0.1, path) / (0.1 * s.p0), "-", color=line.get_color(), lw=0.8)
    ax[0].set_xlabel("x / a_H"), ax[0].set_ylabel("t / (mu p0)"), ax[0].legend(fontsize=7)
    ax[0].set_title("rollqp (dots), Mindlin-Deresiewicz (lines)")
    for model, h in loops.items():
        i, j = int(np.argmax(h["Q"])), int(np.argmin(h["Q"]))
        k = (h["u"][i] - h["u"][j]) / (h["Q"][i] - h["Q"][j])          # the secant compliance
        ax[1].plot((h["u"] - k * h["Q"]) * 1e3, h["Q"] / (0.1 * s.load.normal), label=f"{model}: W = {h['energy']:.4g} N")
    ax[1].set_xlabel("u - (secant compliance) Q  (um)"), ax[1].set_ylabel("Q / (mu P)")
    ax[1].legend(fontsize=7), ax[1].set_title(f"hysteresis; Mindlin 2D: W = {fr[2]['W_closed']:.4g} N per mm")
    fig.tight_layout(), fig.savefig(os.path.join(folder, "fretting.png"), dpi=110), plt.close(fig)

    s, a, circle, _ = dn
    fig, ax = plt.subplots(1, 3, figsize=(14, 4))
    q = a["q"] / s.a_H
    for qq in (0.0, 2.5, 3.3, 4.0):
        k = int(np.argmin(np.abs(q - qq)))
        ax[0].plot(a["x"] / s.a_H, a["pn"][k] / s.p0, label=f"q = {qq:g} a_H")
    ax[0].set_xlabel("x / a_H"), ax[0].set_ylabel("p / p0"), ax[0].legend(fontsize=7)
    _zones(ax[1], a, q, "q / a_H")
    ax[2].plot(q[1:], a["creepage"][1:] / abs(circle["creepage"][-1]), label="dent")
    ax[2].plot(q[1:], circle["creepage"][1:] / abs(circle["creepage"][-1]), "k:", label="circle")
    ax[2].set_xlabel("q / a_H"), ax[2].set_ylabel("xi / |xi_steady|"), ax[2].legend(fontsize=7)
    fig.tight_layout(), fig.savefig(os.path.join(folder, "dent.png"), dpi=110), plt.close(fig)


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
        figures(args.figures, sr, fr, dn)
    return sr, fr, dn


if __name__ == "__main__":
    main()
