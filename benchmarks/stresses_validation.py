"""Validation of the subsurface stresses, the energy identities and the stress post-processing cost.

One command regenerates every table of ``docs/stresses.md``::

    python benchmarks/stresses_validation.py                 # all sections (a few minutes on 2 cores)
    python benchmarks/stresses_validation.py --only mcewen hertz

Sections (``--only`` names):

* ``mcewen``      the integrated field of Hertz p and t = μp on 20…160 elements against McEwen's
                  closed form, μ = 0, 0.1, 0.25, 0.5, with the slope as the mesh doubles;
* ``hertz``       frictionless: the maximum of τ1 from *computed* Hertz tractions (newton) against
                  0.300 p0 at 0.786 a;
* ``surface``     the friction coefficient at which the maximum of τ1 and of von Mises reaches the
                  surface (McEwen's field, ν = 0.3, and the integrated field on 160 elements);
* ``carter``      steady rolling of similar cylinders: dissipation D against −Qξ, slope;
* ``dissimilar``  steady free rolling (harmonic scene at P̄): D against the identity, newton vs
                  nt-newton on two meshes;
* ``balance``     the §6.1.1 transient: accumulated friction work against load work − ΔU;
* ``contact``     CONTACT's carter2d example (frictional power, FX·CKSI) against rollqp on its grid;
* ``bem``         the half-space field's error in a roller of a/R = 0.01 (solid disc, exact);
* ``cost``        stresses of all states of §6.1.1 (100 × 60 grid) against the transient itself.
"""
from __future__ import annotations

import argparse
import json
import time

import numpy as np
from harness import interleaved, table  # (pins BLAS first)

import rollqp
from rollqp import closedforms as cf
from rollqp.energy import balance, steady_identity
from rollqp.subsurface import invariants, stress_components, stress_history

MESHES = (20, 40, 80, 160)


def _slopes(errs):
    return ["–"] + [f"{np.log2(e0 / e1):.2f}" for e0, e1 in zip(errs, errs[1:])]


def _grid(nx=121, nz=80, width=1.5, depth=2.0, zmin=0.02):
    X, Z = np.meshgrid(np.linspace(-width, width, nx), np.linspace(zmin, depth, nz))
    return X.ravel(), Z.ravel()


def mcewen_errors(element, ne, mu, zmin=0.02):
    """max |σ − σ_McEwen|/p0 over the components on ±1.5 a, zmin a ≤ z ≤ 2 a (a = p0 = 1)."""
    strip = rollqp.Strip(1.25, ne, element)
    p = cf.hertz_pressure(strip.x, 1.0, 1.0)
    x, z = _grid(zmin=zmin)
    s = stress_components(strip, x, z, p, mu * p)
    ref = np.array(cf.mcewen_stresses(x, z, 1.0, 1.0, mu))
    return float(np.abs(s - ref).max())


def sec_mcewen():
    out = []
    for element in ("quadratic", "constant"):
        rows = []
        for mu in (0.0, 0.1, 0.25, 0.5):
            errs = [mcewen_errors(element, ne, mu) for ne in MESHES]
            rows.append([mu] + [f"{e:.2e}" for e in errs] + [" / ".join(_slopes(errs)[1:])])
        out.append(f"**{element} elements** on ±1.25 a (nodal Hertz p and t = μp; grid 121 × 80 on |x| ≤ 1.5 a, "
                   "0.02 a ≤ z ≤ 2 a; max over σxx, σzz, τxz of the error in p0)\n\n"
                   + table(["μ"] + [f"{n} el." for n in MESHES] + ["slopes"], rows))
    errs = [mcewen_errors("quadratic", ne, 0.25, zmin=0.2) for ne in MESHES]
    out.append("Away from the surface (z ≥ 0.2 a, quadratic, μ = 0.25): "
               + ", ".join(f"{e:.2e}" for e in errs) + f"; slopes {' / '.join(_slopes(errs)[1:])}.")
    return "\n\n".join(out)


def sec_hertz():
    rows = []
    base = rollqp.load_scene("cattaneo-carter").replace(**{"contact.friction": 0.0, "discretization.distance": 0.0,
                                                           "load.tangential": {"kind": "constant", "value": 0.0}})
    zs = np.linspace(0.70, 0.88, 1801)
    for ne in MESHES:
        sc = base.replace(**{"discretization.elements": ne})
        res = rollqp.run(sc)
        a, p0 = sc.a_H, sc.p0
        sf = rollqp.stresses(res, 0, (np.linspace(-0.05, 0.05, 21) * a, zs * a))
        v, x, z = sf.maxima["tau1"]
        rows.append([ne, f"{v / p0:.5f}", f"{z / a:.4f}", f"{x / a:+.4f}",
                     f"{v / p0 - cf.HERTZ_MAX_SHEAR[0]:+.1e}", f"{z / a - cf.HERTZ_MAX_SHEAR[1]:+.1e}"])
    return ("Computed Hertz tractions (`cattaneo-carter` at μ = 0, newton, quadratic elements), τ1 on |x| ≤ 0.05 a, "
            "0.70 a ≤ z ≤ 0.88 a (depth step 1e-4 a); closed form "
            f"{cf.HERTZ_MAX_SHEAR[0]:.5f} p0 at {cf.HERTZ_MAX_SHEAR[1]:.5f} a\n\n"
            + table(["elements", "max τ1/p0", "z/a", "x/a", "Δ value", "Δ depth"], rows))


def surface_mu(field, name, lo=0.0, hi=0.6, tol=1e-3):
    """Smallest μ at which the maximum of ``name`` over the grid lies on the surface row (bisection)."""
    def at_surface(mu):
        v = field(mu)[name]
        return v[0].max() >= v[1:].max()
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if at_surface(mid) else (mid, hi)
    return 0.5 * (lo + hi)


def sec_surface():
    xs, zs = np.linspace(-1.2, 1.2, 481), np.concatenate([[0.0], np.linspace(0.0025, 1.0, 400)])
    X, Z = np.meshgrid(xs, zs)

    def closed(mu):
        return invariants(*cf.mcewen_stresses(X, Z, 1.0, 1.0, mu), 0.3)
    strip = rollqp.Strip(1.25, 80, "quadratic")
    p = cf.hertz_pressure(strip.x, 1.0, 1.0)
    Zi = np.where(Z == 0, 1e-4, Z)  # the integrated field is defined for z > 0: the first row at 1e-4 a

    def integrated(mu):
        s = stress_components(strip, X.ravel(), Zi.ravel(), p, mu * p)
        return {k: v.reshape(X.shape) for k, v in invariants(s[0], s[1], s[2], 0.3).items()}
    rows = [[name, f"{surface_mu(closed, key):.3f}", f"{surface_mu(integrated, key):.3f}"]
            for name, key in (("Tresca s1 − s3 (3D maximum shear, ν = 0.3)", "tresca"),
                              ("von Mises (ν = 0.3)", "von_mises"), ("τ1 (in-plane maximum shear)", "tau1"))]
    return ("Friction coefficient μ of a sliding Hertz contact (t = μp) above which the maximum lies on the "
            "surface (bisection to 1e-3; grid 481 × 401, |x| ≤ 1.2 a, z ≤ a, first subsurface row 0.0025 a)\n\n"
            + table(["quantity", "McEwen (closed form)", "integrated, 80 QCE"], rows))


def steady(name, ne, method="newton", element=None, **changes):
    sc = rollqp.load_scene(name)
    ch = {"discretization.elements": ne, "discretization.distance": 0.0, "load.start": "rolling",
          "solver.method": method}
    if element:
        ch["discretization.element"] = element
    ch.update(changes)
    sc = sc.replace(**ch)
    t0 = time.perf_counter()
    res = rollqp.run(sc).arrays()
    res["f"] = rollqp.Strip(sc.half_width, ne, sc.discretization.element).weights
    return sc, res, time.perf_counter() - t0


def sec_carter():
    out = []
    for element in ("quadratic", "constant"):
        rows, errs = [], []
        for ne in MESHES:
            sc, res, _ = steady("cattaneo-carter", ne, element=element)
            D, I = float(res["dissipation"][0]), -float(res["Q"][0] * res["creepage"][0])
            errs.append(abs(D / I - 1))
            rows.append([ne, f"{D:.6e}", f"{I:.6e}", f"{D / I - 1:+.2e}"])
        for r, s in zip(rows, _slopes(errs)):
            r.append(s)
        out.append(f"**{element}**\n\n" + table(["elements", "D = −∫ts dx (N/mm per mm)", "−Qξ", "D/(−Qξ) − 1",
                                                 "slope"], rows))
    return ("Steady rolling of `cattaneo-carter` (similar, Q/(μP) = 0.75, newton's direct steady solve)\n\n"
            + "\n\n".join(out))


def sec_dissimilar():
    rows = []
    for ne in (84, 168):
        for method in ("newton", "nt-newton"):
            sc, res, wall = steady("harmonic", ne, method)
            D, I = float(res["dissipation"][0]), steady_identity(res, 0, sc.load.direction)
            meta = json.loads(str(res["meta"]))
            rows.append([ne, method, meta.get("rolling_start", ""),
                         f"{D:.6e}", f"{I:.6e}", f"{D / I - 1:+.2e}", f"{wall:.2f}"])
    trows = []
    for ne in (21, 42):
        for method in ("newton", "nt-newton"):
            sc = rollqp.load_scene("harmonic").replace(**{"discretization.elements": ne, "solver.method": method})
            res = rollqp.run(sc).arrays()
            trows.append([ne, method, f"{np.sum(res['friction_work']):.6e}", f"{res['dissipation'][-1]:.6e}"])
    return ("Steady free rolling of the `harmonic` scene's bodies (β = 0.144, μ = 0.1, Q = 0) at P̄; "
            "identity D = −Qξ + d(2β/E*)∫pt dx\n\n"
            + table(["elements", "method", "start", "D", "identity", "D/identity − 1", "wall s"], rows)
            + "\n\nThe `harmonic` transient itself (6 a_H, coupled steps), accumulated friction work and the last "
              "state's D, coupled newton against the N–T alternation:\n\n"
            + table(["elements", "method", "friction work", "D at the end"], trows))


def sec_balance():
    rows = []
    for ne in (20, 40, 80):
        sc = rollqp.load_scene("cattaneo-carter").replace(**{"discretization.elements": ne})
        res = rollqp.run(sc).arrays()
        b = balance(res)
        Wf, Wl, dU = b["friction_work"][-1], b["load_work"][-1], b["delta_U"][-1]
        rows.append([ne, f"{Wf:.5e}", f"{Wl:.5e}", f"{dU:.3e}", f"{(Wl - dU) / Wf - 1:+.2e}"])
    return ("The §6.1.1 transient (`cattaneo-carter`, 6 a_H from the braked state): accumulated work in N·mm/mm\n\n"
            + table(["elements", "friction work", "load work −Qξ Δq", "ΔU", "(load − ΔU)/friction − 1"], rows))


def contact_carter2d(element="constant", elements=None):
    """CONTACT's carter2d.inp on its grid: R = 500 mm on a plane (R_B = 1e9 mm here), G = 82000,
    ν = 0.28, FN = 35780 N over DY = 200 mm, CKSI = −2.4e-4 prescribed, μ = 0.3, steady;
    55 elements of 0.04 mm from x = −1.05 mm."""
    E = 2 * 82000.0 * 1.28
    P = 35780.0 / 200.0
    sc = rollqp.load_scene({
        "name": "carter2d", "bodies": {"A": {"radius": 500.0, "E": E, "nu": 0.28},
                                       "B": {"radius": 1e9, "E": E, "nu": 0.28}},
        "contact": {"friction": 0.3},
        "load": {"normal": P, "creepage": {"kind": "constant", "value": -2.4e-4}, "start": "rolling", "direction": -1},
        "discretization": {"elements": 55, "element": "constant", "zone": 1.1, "step": 1.0, "distance": 0.0},
        "solver": {"method": "newton"}})
    sc = sc.replace(**{"discretization.zone": 1.1 / sc.a_H})
    ne = elements or int(round(2.2 / 0.04))
    sc = sc.replace(**{"discretization.elements": ne, "discretization.element": element})
    res = rollqp.run(sc).arrays()
    return sc, res


def sec_contact():
    # CONTACT's numbers (tests/data/contact/examples/carter2d.ref_out): FX = 6955 N, CKSI = −2.4e-4,
    # FRIC.POWER = −47.62 W at VELOC = 30000 mm/s over DY = 200 mm, i.e. D = 47.62e3/30000/200 N/mm per mm.
    D_contact, Q_contact = 47.62e3 / 30000 / 200, 6955.0 / 200
    rows = [["CONTACT (50 of 55 constant el. in contact)", f"{Q_contact:.4f}", f"{D_contact:.5e}",
             f"{Q_contact * 2.4e-4:.5e}", f"{D_contact / (Q_contact * 2.4e-4) - 1:+.2e}"]]
    for element, ne in (("constant", None), ("constant", 220), ("quadratic", 110)):
        sc, res = contact_carter2d(element, ne)
        D, Q = float(res["dissipation"][0]), float(res["Q"][0])
        rows.append([f"rollqp, {res['x'].size} nodes {element}", f"{abs(Q):.4f}", f"{D:.5e}",
                     f"{abs(Q) * 2.4e-4:.5e}", f"{D / (abs(Q) * 2.4e-4) - 1:+.2e}"])
    return ("CONTACT's `carter2d` example (steady, creepage −2.4e-4 prescribed, μ = 0.3), per mm of axial length\n\n"
            + table(["", "|Q| N/mm", "D = ∫|t s| dx", "|Q ξ|", "D/|Qξ| − 1"], rows))


def disc_field(x, z, a, p0, R):
    """Exact σ in a solid disc of radius R compressed by two opposite Hertz pressures (Hertz 1883;
    Timoshenko & Goodier §41): the Flamant field of each load plus the uniform tension P/(πR)."""
    P = np.pi * a * p0 / 2
    top = np.array(cf.mcewen_stresses(x, z, a, p0))
    bot = np.array(cf.mcewen_stresses(-x, 2 * R - z, a, p0))  # the opposite load: its frame turned by π
    uniform = P / (np.pi * R)
    return top[0] + bot[0] + uniform, top[1] + bot[1] + uniform, top[2] + bot[2]


def sec_bem():
    rows = []
    x, z = _grid(121, 80, 1.5, 2.0)
    for aR in (0.1, 0.01):
        hs = invariants(*cf.mcewen_stresses(x, z, 1.0, 1.0), 0.3)
        dk = invariants(*disc_field(x, z, 1.0, 1.0, 1.0 / aR), 0.3)
        rows.append([aR, f"{np.abs(hs['von_mises'] - dk['von_mises']).max():.2e}",
                     f"{np.abs(hs['tau1'] - dk['tau1']).max():.2e}",
                     f"{abs(hs['von_mises'].max() - dk['von_mises'].max()):.2e}", f"{aR / 2:.3f}"])
    return ("Half-space field against the exact field of a solid disc (radius R) under opposite Hertz loads, "
            "|x| ≤ 1.5 a, z ≤ 2 a, errors in p0 (ν = 0.3)\n\n"
            + table(["a/R", "max |Δ von Mises|", "max |Δ τ1|", "Δ peak von Mises", "P/(πR p0) = a/(2R)"], rows))


def sec_cost():
    sc = rollqp.load_scene("cattaneo-carter")
    res = rollqp.run(sc)
    arrays = res.arrays()
    arrays["meta"] = res.meta
    cases = {"transient": lambda: rollqp.run(sc), "stresses": lambda: stress_history(arrays)}

    def measure(f):
        t0, c0 = time.perf_counter(), time.process_time()
        f()
        return time.perf_counter() - t0, time.process_time() - c0
    cases["one state 200 x 200"] = lambda: rollqp.stresses(arrays, 0)
    t = interleaved(5, cases, measure)
    med = {k: np.median(np.array(v), axis=0) for k, v in t.items()}
    rows = [[k, f"{w:.3f}", f"{c:.3f}", f"{w / med['transient'][0]:.2f}", f"{c / med['transient'][1]:.2f}"]
            for k, (w, c) in med.items()]
    return (f"§6.1.1 (`cattaneo-carter`, {len(arrays['q'])} states, {arrays['x'].size} nodes; stresses of every "
            "state on the 100 × 60 default grid of stress_history), medians of 5 interleaved runs on a shared "
            "2-core machine\n\n" + table(["", "wall s", "CPU s", "wall / transient", "CPU / transient"], rows))


SECTIONS = {"mcewen": sec_mcewen, "hertz": sec_hertz, "surface": sec_surface, "carter": sec_carter,
            "dissimilar": sec_dissimilar, "balance": sec_balance, "contact": sec_contact, "bem": sec_bem,
            "cost": sec_cost}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--only", nargs="+", choices=list(SECTIONS), help="run only these sections")
    args = ap.parse_args(argv)
    for name in args.only or SECTIONS:
        t0 = time.perf_counter()
        print(f"### {name}\n\n{SECTIONS[name]()}\n\n({time.perf_counter() - t0:.1f} s)\n", flush=True)


if __name__ == "__main__":
    main()
