"""The paper's §6.2.2 example through the Python API: a harmonic normal load.

Dissimilar cylinders (2β = 0.288, aluminium on steel, μ = 0.1; the built-in scene
``harmonic`` documents the materials) roll freely (Q = 0) in the steady state of the
constant load P̄; then the normal load varies as P = P̄(1 + 0.2 sin(2π q/λ)). The paper's
frequency is garbled in its text, so the wavelength λ (in a_H) is a parameter; the scene's
default is λ = 2 a_H. Paper's mesh: 21 QCE, Δq = 0.637·Le/2, convective-local formulation,
full coupling.

What the paper reports, and what this example measures:

* the contact width varies in phase with the load (here: the discrete contact half-width
  against the Hertz half-width a_H·√(P/P̄));
* one and two stick zones alternate ("two–one–two adhesion zones");
* the first cycle is transient, then the response is periodic: the states one wavelength
  apart are compared cycle by cycle (exactly one wavelength apart when λ is a whole number
  of steps, e.g. ``--wavelength`` 49·Δq/a_H; else the nearest step, and the phase mismatch
  is printed).

Run it::

    python examples/harmonic.py [METHOD] [--wavelength LAMBDA] [--cycles N] [--figures DIR]

METHOD defaults to the scene's (newton). ``--figures DIR`` writes harmonic-first-cycle.png
(Fig. 8), harmonic-periodic.png (Fig. 9, the last cycle) and harmonic-zones.png there.
"""
from __future__ import annotations

import argparse
import itertools
import os
import time

import numpy as np

import rollqp
from rollqp import closedforms as cf


def stick_zones(state):
    """Number of separate stick zones (runs of stick nodes) in one state."""
    return sum(1 for code, _ in itertools.groupby(state.tolist()) if code == 1)


def contact_half_width(x, state):
    """Half the length of the discrete contact: (last − first contact node + one spacing)/2."""
    on = np.nonzero(state > 0)[0]
    return 0.5 * (x[on[-1]] - x[on[0]] + (x[1] - x[0]))


def measure(res, scene, wall, wavelength):
    a, p0, mu, R = float(res["a_H"]), float(res["p0"]), scene.contact.friction, float(res["R"])
    x, q = res["x"] / a, res["q"] / a
    K = len(q) - 1
    P = res["P"] / scene.load.normal
    half = np.array([contact_half_width(x, s) for s in res["state"]])
    hertz = np.sqrt(P)
    zones = np.array([stick_zones(s) for s in res["state"]])
    dq = float(q[1] - q[0])
    m = int(round(wavelength / dq))                     # steps per cycle
    mismatch = m * dq - wavelength                      # in a_H
    cycles = []
    for c in range(K // m):
        ks = np.arange(c * m, (c + 1) * m)
        if ks[-1] + m > K:                              # whole cycles only
            break
        cycles.append({
            "cycle": f"{c + 1}->{c + 2}",
            "dt": float(np.abs(res["pt"][ks + m] - res["pt"][ks]).max() / (mu * p0)),
            "dt_rms": float(np.sqrt(np.mean((res["pt"][ks + m] - res["pt"][ks]) ** 2)) / (mu * p0)),
            "dp": float(np.abs(res["pn"][ks + m] - res["pn"][ks]).max() / p0),
            "flips": int((res["state"][ks + m] != res["state"][ks]).sum()),
        })
    xi = res["creepage"]
    return {
        "steps": K,
        "steps_per_cycle": m,
        "phase_mismatch": mismatch,
        "iterations_start": int(res["iterations"][0]),
        "iterations_per_step": float(res["iterations"][1:].mean()),
        "wall": wall,
        "residual": float(res["residual"].max()),
        "xi_start": float(xi[0]),
        "xi_start_ratio": float(xi[0]) / cf.bentall_johnson_creepage(scene.kappa, a, R),
        "xi_end": float(xi[-1]),
        "xi_range": (float(xi.min()), float(xi.max())),
        "half_width_error": float(np.abs(half - hertz).max()),
        "node_spacing": float(x[1] - x[0]),
        "width_load_correlation": float(np.corrcoef(half, P)[0, 1]),
        "stick_zone_counts": {int(k): int((zones == k).sum()) for k in np.unique(zones)},
        "cycles": cycles,
        "friction_excess": float(np.max(np.abs(res["pt"]) - mu * res["pn"]) / (mu * p0)),
        "Q_max": float(np.abs(res["Q"]).max() / (mu * scene.load.normal)),
    }


def main(method=None, figures=None, wavelength=None, cycles=None):
    scene = rollqp.load_scene("harmonic")
    hist = scene.load.normal_history
    lam = float(wavelength) if wavelength is not None else hist.wavelength
    changes = {"load.normal_history": {"kind": "harmonic", "mean": hist.mean, "amplitude": hist.amplitude,
                                       "wavelength": lam, "phase": hist.phase}}
    if cycles is not None:
        changes["discretization.distance"] = float(cycles) * lam
    scene = scene.replace(**changes)
    t0 = time.perf_counter()
    result = rollqp.run(scene, method=method)
    wall = time.perf_counter() - t0
    res = result.arrays()
    st = measure(res, scene, wall, lam)
    name = method or scene.solver.method

    print(f"{scene.name}: {scene.description}")
    print(f"  beta = {scene.beta:.10f} (2beta = {scene.kappa:.6g}), mu = {scene.contact.friction}, "
          f"a_H = {scene.a_H:.4f}, a_H/R = {scene.a_H / scene.R:.4f}, p0 = {scene.p0:.2f}; method {name}")
    print(f"  P = P̄(1 + {hist.amplitude} sin(2 pi q/lambda)), lambda = {lam:.6g} a_H = {st['steps_per_cycle']} steps "
          f"of {scene.dq / scene.a_H:.5g} a_H (phase mismatch {st['phase_mismatch']:+.2e} a_H)")
    print(f"  {st['steps']} rolling steps + steady rolling start in {st['wall']:.2f} s; iterations: start "
          f"{st['iterations_start']}, {st['iterations_per_step']:.2f} per step; max residual {st['residual']:.1e}")
    print(f"  steady start: xi = {st['xi_start']:.5e} = {st['xi_start_ratio']:.4f} x Bentall-Johnson (mu -> 0)")
    print(f"  creepage over the run: [{st['xi_range'][0]:.5e}, {st['xi_range'][1]:.5e}], end {st['xi_end']:.5e}; "
          f"max |Q|/(mu P̄) {st['Q_max']:.1e}")
    print(f"  contact half-width vs Hertz sqrt(P/P̄): max difference {st['half_width_error']:.4f} a_H "
          f"(node spacing {st['node_spacing']:.4f} a_H), correlation with P {st['width_load_correlation']:.4f}")
    counts = ", ".join(f"{v} states with {k}" for k, v in st["stick_zone_counts"].items())
    print(f"  stick zones: {counts}")
    print(f"  max (|t| - mu p)/(mu p0) over all states: {st['friction_excess']:.1e}")
    print("  cycle-to-cycle change at the same phase (t in mu p0, p in p0):")
    for c in st["cycles"]:
        print(f"    cycle {c['cycle']}: max|dt| {c['dt']:.2e}, rms dt {c['dt_rms']:.2e}, max|dp| {c['dp']:.2e}, "
              f"node-state changes {c['flips']}")

    written = []
    if figures:
        from rollqp import plot
        os.makedirs(figures, exist_ok=True)
        q_end = res["q"][-1] / scene.a_H
        first = list(np.linspace(0.0, lam, 5))
        last = list(np.linspace(q_end - lam, q_end, 5))
        for fname, at, what in (("harmonic-first-cycle.png", first, "first load cycle, transient (Fig. 8)"),
                                ("harmonic-periodic.png", last, "last load cycle, periodic (Fig. 9)")):
            path = os.path.join(figures, fname)
            plot.snapshot_figure(res, scene, path, at=at,
                                 title=f"§6.2.2 harmonic normal load, lambda = {lam:.4g} a_H: {what}, "
                                       f"2beta = 0.288, mu = 0.1, {name}")
            written.append(path)
        path = os.path.join(figures, "harmonic-zones.png")
        plot.zone_map_figure(res, scene, path, title=f"§6.2.2: stick/slip zones, creepage and load, "
                                                     f"lambda = {lam:.4g} a_H, {name}")
        written.append(path)
        for path in written:
            print(f"  figure {path}")
    return {"result": res, "scene": scene, "stats": st, "figures": written, "method": name, "wavelength": lam}


def _args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("method", nargs="?", default=None, help="step method (default: the scene's, newton)")
    ap.add_argument("--wavelength", type=float, help="load wavelength lambda / a_H (default: the scene's, 2)")
    ap.add_argument("--cycles", type=float, help="rolled distance in wavelengths (default: the scene's 6 a_H)")
    ap.add_argument("--figures", metavar="DIR", help="write the figures to this folder")
    return ap.parse_args(argv)


if __name__ == "__main__":
    _a = _args()
    results = main(_a.method, figures=_a.figures, wavelength=_a.wavelength, cycles=_a.cycles)
