"""The numbers of docs/validation3d.md's section on 3D load paths: a varying normal load against Hertz and the
steady state at the current load, a stop, a reversal against the 2D code, fretting at rest, and Newton against
Clarabel on a path with variable steps.

    python benchmarks/three_loads.py            # 16² and 24² (about a minute)
    python benchmarks/three_loads.py --fine     # adds 32² (a few minutes)
"""
from __future__ import annotations

import sys

import numpy as np

import rollqp
from rollqp.kinematics import plan
from rollqp.closedforms.hertz_ellipse import hertz
from rollqp.march.grid import static_shift, steady
from rollqp.march.grid import prepare, run

REVERSE = {"kind": "table", "q": [0, 3, 4, 10], "value": [0, 3, 3, -3]}


def circle(n=16, **changes):
    return rollqp.load_scene("kalker-circular").replace(**{"discretization.elements": [n, n],
                                                           "discretization.zone": [1.4, 1.4], **changes})


def braked(n=16, **changes):
    return circle(n, **{"load.start": "braked", "load.creepage": None, "load.tangential": 0.75, **changes})


def varying_load(n, lam=16.0, xi=1e-4):
    """Max over the steps of ‖p − p_Hertz(FN_k)‖/‖p_Hertz‖ and of |Fx − Fx_steady(FN_k)|/(μFN_k)."""
    s = circle(n, **{"load.creepage": {"longitudinal": xi}, "discretization.distance": lam / 4,
                     "load.normal_history": {"kind": "harmonic", "mean": 1.0, "amplitude": 0.3, "wavelength": lam}})
    a = run(s).arrays()
    _, meth, contact = prepare(s)
    A, B = s.curvatures
    ep, dF = [], []
    for k in range(a["FN"].size):
        FN = float(a["FN"][k])
        ph = hertz(A, B, s.materials.Estar, FN).pressure(contact.x, contact.y)
        ep.append(np.linalg.norm(a["pn"][k].ravel() - ph) / np.linalg.norm(ph))
        st = steady(contact, meth, FN, s.loads_at(float(s.time_steps[k])), direction=-1)
        dF.append(abs(a["Fx"][k] - st.Fx) / (s.mu * FN))
    grows = np.flatnonzero(np.diff((a["pn"] > 0).sum(axis=(1, 2))) > 0) + 1
    lag = max(dF[1:grows[0]]) if grows.size and grows[0] > 1 else float("nan")
    swing = (a["Fx"].max() - a["Fx"].min()) / abs(a["Fx"][0])
    return max(ep), max(dF), lag, swing


def stop_and_reversal():
    s = braked(**{"load.rolled": REVERSE, "discretization.distance": 10.0})
    a = run(s).arrays()
    pl = plan(s)
    stops = np.flatnonzero(pl.d[1:] == 0) + 1
    k0 = stops[0] - 1
    mu_p0 = s.mu * s.ellipse.p0
    stop = max(float(np.max(np.abs(a["px"][k] - a["px"][k0]))) / mu_p0 for k in stops)
    fwd = run(braked(**{"discretization.distance": 6.0})).arrays()
    mirror = float(np.max(np.abs(a["px"][-2][:, ::-1] - fwd["px"][-1]))) / mu_p0
    first_back = int(np.flatnonzero(pl.d == 1)[0])
    m = a["state"][first_back] == 1
    centroid = float(np.broadcast_to(a["x"], m.shape)[m].mean()) / s.ellipse.a
    return stop, mirror, float(pl.q[first_back] - pl.q[first_back - 1]) / s.ellipse.a, centroid


def fretting():
    L = 8 * braked().grid.dx / braked().ellipse.a
    s = braked(**{"load.rolled": {"kind": "constant", "value": 0.0}, "discretization.distance": 4 * L,
                  "load.tangential": {"kind": "table", "q": [0, L, 2 * L, 3 * L, 4 * L],
                                      "value": [0.6, 0.0, -0.6, 0.0, 0.6]}})
    a = run(s).arrays()
    mu_p0 = s.mu * s.ellipse.p0
    _, meth, contact = prepare(s)
    cat = {F: static_shift(contact, meth, s.load.normal, F * s.mu * s.load.normal)[-1].t[0] for F in (0.6, 0.3)}
    md = contact.grid.field(cat[0.6] - 2 * cat[0.3])
    return (float(np.max(np.abs(a["px"][16] + a["px"][0]))) / mu_p0,
            float(np.max(np.abs(a["px"][32] - a["px"][0]))) / mu_p0,
            float(np.max(np.abs(a["px"][8] - md))) / mu_p0)


def methods():
    s = braked(12, **{"load.rolled": {"kind": "table", "q": [0, 1, 1.5, 2.5, 4], "value": [0, 0.5, 0.5, 1.5, 0.75]},
                      "load.normal_history": {"kind": "table", "q": [0, 1.2, 4], "value": [1.0, 1.2, 0.9]},
                      "load.tangential": {"kind": "table", "q": [0, 1.2, 1.4], "value": [0.5, -0.3, 0.4]},
                      "discretization.distance": 4.0})
    a, b = run(s).arrays(), run(s, method="socp-clarabel").arrays()
    return (float(np.max(np.abs(a["px"] - b["px"]))) / (s.mu * s.ellipse.p0),
            float(np.max(np.abs(a["pn"] - b["pn"]))) / s.ellipse.p0)


def main(argv):
    grids = (16, 24, 32) if "--fine" in argv else (16, 24)
    print("varying load (harmonic 1 ± 0.3, λ = 16 a, ξ = 1e-4, a quarter wavelength):")
    for n in grids:
        ep, dF, lag, swing = varying_load(n)
        print(f"  {n}²: pressure vs Hertz(FN_k) {ep:.4f}; |Fx − steady(FN_k)|/(μFN) {dF:.3g} (before the contact "
              f"first grows {lag:.2g}); Fx changes by {100 * swing:.1f} %")
    stop, mirror, dq, c = stop_and_reversal()
    print(f"stop under held Fx: tractions change {stop:.2g} μp0; reversal: the end state vs the forward run "
          f"mirrored {mirror:.2g} μp0; the first step back (Δq = {dq:.3f} a) has its stick zone at x̄ = {c:+.3f} a")
    print("fretting at rest (0.6 → −0.6 → 0.6): state at −0.6 vs −state(0.6) {:.2g}, back at 0.6 vs state(0.6) "
          "{:.2g}, at 0 vs t(0.6) − 2t(0.3) {:.2g} μp0".format(*fretting()))
    print("Newton vs socp-clarabel on variable steps, a stop, a reversal, a varying load: tractions {:.2g} μp0, "
          "pressure {:.2g} p0".format(*methods()))


if __name__ == "__main__":
    main(sys.argv[1:])
