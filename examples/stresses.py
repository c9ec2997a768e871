"""Subsurface stresses of the §6.1.1 transient through the Python API (docs/stresses.md).

Runs the built-in scene ``cattaneo-carter`` (similar steel cylinders braked at Q/(μP) = 0.75,
then rolling to Carter's steady state), and:

* checks the stresses of a frictionless Hertz state computed on the same mesh against McEwen's
  closed form (``closedforms.hertz_subsurface_stresses``): the largest error on the grid, and the
  maximum of τ1 against 0.300 p0 at 0.786 a;
* reports the peaks of von Mises and τ1 in state ``--step`` (default: the last, Carter), and the
  overall peak over every state of the transient (where and when the material is most loaded);
* with ``--figure``, draws the contour maps of von Mises and τ1 with the stick/slip zones above
  (docs/figures/stresses-carter.png).

Run it::

    python examples/stresses.py [--step K] [--figure FILE]

The same figure from a result file: ``rollqp stresses RESULT.npz --step K --plot FILE``.
"""
from __future__ import annotations

import argparse

import numpy as np

import rollqp
from rollqp import closedforms as cf
from rollqp.plot.stresses import plot_field
from rollqp.subsurface import stress_history


def hertz_check(scene):
    """Largest |σ − σ_Hertz|/p0 on ±1.5 a × (0.05 a, 2 a] and the computed max τ1 (value, depth) in p0, a."""
    s0 = scene.replace(**{"contact.friction": 0.0, "discretization.distance": 0.0,
                          "load.tangential": {"kind": "constant", "value": 0.0}})
    res = rollqp.run(s0)
    a, p0 = s0.a_H, s0.p0
    gx, gz = np.linspace(-1.5, 1.5, 61) * a, np.linspace(0.05, 2.0, 40) * a
    sf = rollqp.stresses(res, 0, (gx, gz))
    X, Z = np.meshgrid(gx, gz)
    ref = cf.hertz_subsurface_stresses(X, Z, a, p0)
    err = max(np.abs(sf[k] - r).max() for k, r in zip(("sxx", "szz", "txz"), ref)) / p0
    line = rollqp.stresses(res, 0, (np.array([0.0]), np.linspace(0.7, 0.88, 1801) * a))
    v, _, z = line.maxima["tau1"]
    return err, v / p0, z / a


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--step", type=int, default=-1, help="the state to map (default: the last)")
    ap.add_argument("--figure", help="PNG: von Mises and τ1 contours with the stick/slip zones")
    args = ap.parse_args(argv)
    scene = rollqp.load_scene("cattaneo-carter")
    err, tau, depth = hertz_check(scene)
    print(f"Hertz (computed, {scene.discretization.elements} QCE) against McEwen: max error {err:.2e} p0; "
          f"max tau1 {tau:.5f} p0 at z = {depth:.4f} a (closed form {cf.HERTZ_MAX_SHEAR[0]:.5f} at "
          f"{cf.HERTZ_MAX_SHEAR[1]:.5f})")
    res = rollqp.run(scene)
    arrays = res.arrays()
    arrays["meta"] = res.meta
    a, p0 = scene.a_H, scene.p0
    sf = rollqp.stresses(arrays, args.step)
    for key in ("von_mises", "tau1"):
        v, x, z = sf.maxima[key]
        print(f"state {sf.step} (q = {sf.q / a:.3f} a_H): peak {key} {v / p0:.4f} p0 at x = {x / a:+.3f} a_H, "
              f"z = {z / a:.3f} a_H")
    h = stress_history(arrays)
    for key in ("von_mises", "tau1"):
        v, x, z, k = h.overall[key]
        print(f"over all {len(arrays['q'])} states: peak {key} {v / p0:.4f} p0 at x = {x / a:+.3f} a_H, "
              f"z = {z / a:.3f} a_H in state {k} (q = {arrays['q'][k] / a:.3f} a_H)")
    if args.figure:
        plot_field(sf, arrays, args.figure, p0, a)
        print(f"figure {args.figure}")
    return dict(hertz_error=err, hertz_tau=tau, hertz_depth=depth, field=sf, history=h, scene=scene)


if __name__ == "__main__":
    main()
