"""Traction ramps on the BEM: why its creepage differs from the half-space's (docs/bem.md §7).

Usage::

    python benchmarks/bem_ramp_question.py                                   # tables (~1 min)
    python benchmarks/bem_ramp_question.py --figure docs/figures/bem-ramp.png

The built-in ``ramp`` scene (Q/(μP) 0 → 0.75 over 8/3 a_H from the braked state, the paper's
rollers R_A = 150, R_B = 300 mm, μ = 0.1, 40 QCE, Newton), with body A or B aluminium
(E = 2·23000·1.31, ν = 0.31, as ``tests/test_steady.py``) or both steel, and shafts of radius
0.1 R_α (the scene's) or 0.5 R_α; 20 a_H rolled. Each case runs with ``contact.model =
"halfspace"`` and ``"bem"`` and with two hybrids that isolate the causes:

* **HS + wind-up**: the half-space with the rank-one term ``(c_BEM − c_HS) e fᵀ`` added to
  ``A_tt``, i.e. the BEM's larger rigid tangential displacement of the rims per unit Q
  (``c``: :func:`windup_compliance`);
* **BEM, HS coupling**: the BEM with its ``A_tn, A_nt`` replaced by the half-space's ``±(β/E*)S``.

The wind-up term of a model is ``c·dQ/dq`` on the creepage: a constant ``c·Q`` in ``w`` enters
the slip ``s = ξe + (w^k − R w^{k−1})/Δq`` as ``c·(Q^k − Q^{k−1})/Δq``, and ``fᵀt = Q`` fixes
the tractions, so ξ absorbs it: ``ξ = ξ_tractions − c·dQ/dq``.
"""
from __future__ import annotations

from harness import machine_table, pyplot, table  # noqa: F401  (pins BLAS first)

import argparse  # noqa: E402
import dataclasses  # noqa: E402
import math  # noqa: E402
import sys  # noqa: E402

import numpy as np  # noqa: E402

import rollqp  # noqa: E402
from rollqp.influence import get_model, register_model  # noqa: E402

ALUMINIUM = {"E": 2 * 23000.0 * 1.31, "nu": 0.31}   # tests/test_steady.py
RAMP_END = 8.0 / 3.0                                 # q/a_H where the built-in ramp ends


def ramp_scene(model="halfspace", aluminium=None, shaft=0.1, distance=20.0, coupling="auto", **changes):
    """The built-in ``ramp`` with body ``aluminium`` ("A", "B" or None) aluminium and shafts
    ``shaft·R_α``; further scene changes as keyword arguments (dotted keys with ``__``)."""
    base = rollqp.load_scene("ramp")
    ch = {"contact.model": model, "contact.coupling": coupling, "discretization.distance": distance,
          "bodies.A.shaft_radius": shaft * base.A.radius, "bodies.B.shaft_radius": shaft * base.B.radius}
    if aluminium is not None:
        for k, v in ALUMINIUM.items():
            ch[f"bodies.{aluminium}.{k}"] = v
    ch.update({k.replace("__", "."): v for k, v in changes.items()})
    return base.replace(**ch)


def windup_compliance(scene) -> float:
    """``c``: the mean tangential displacement ``w`` over the contact per unit Q of a uniform
    tangential traction on |x| ≤ a_H (mm per N/mm), from the scene's own ``A_tt``.

    On the BEM this is the rigid rotation of both rims on their shafts plus the local
    deformation; on the half-space the constant of its log kernel, set by ``d_ref``.
    """
    ops = rollqp.SceneOperators.build(scene)
    x, f = ops.strip.x, ops.f
    t = (np.abs(x) <= scene.a_H).astype(float)
    w = ops.Att @ t
    inside = np.abs(x) <= scene.a_H
    return float(np.sum((f * w)[inside]) / np.sum(f[inside]) / (f @ t))


def torsion_compliance(scene) -> float:
    """Closed form of the rims' wind-up per unit Q: a plane-strain annulus (outer R, inner r
    welded to a rigid shaft) under the torque Q·R turns its rim by
    ``u_θ(R) = Q (R²/r² − 1)/(4πG)`` (τ = QR/(2πρ²)); the two rollers in series."""
    return sum((b.radius ** 2 / b.shaft_radius ** 2 - 1.0) / (4.0 * math.pi * b.G) for b in (scene.A, scene.B))


#: (model name, edit) → the name of the model registered for them (:func:`edited`)
_EDITED: dict = {}


def edited(scene, edit):
    """``scene`` with its influence model's matrices passed through ``edit(infl, strip, scene)``: a model registered
    once per (model, edit) through the public extension point (rollqp.influence.register_model)."""
    base = get_model(scene.contact.model)
    if (base.name, edit) not in _EDITED:
        name = f"{base.name}-edited-{len(_EDITED)}"
        register_model(dataclasses.replace(base, name=name, operators=None,
                                           build=lambda sc, strip, **kw: edit(base.build(sc, strip, **kw), strip, sc)))
        _EDITED[base.name, edit] = name
    return scene.replace(**{"contact.model": _EDITED[base.name, edit]})


def add_windup(dc):
    """Edit: ``A_tt + dc·e fᵀ`` (a rigid tangential shift of the rims of dc per unit Q)."""
    def edit(infl, strip, scene):
        Att = np.array(infl.Att) + dc * np.outer(np.ones(strip.n), strip.weights)
        return dataclasses.replace(infl, Att=Att)
    return edit


def halfspace_coupling(infl, strip, scene):
    """Edit: the BEM's A_tn, A_nt replaced by the half-space's (same coupling level)."""
    hs = get_model("halfspace").build(scene, strip)
    return dataclasses.replace(infl, Atn=hs.Atn, Ant=hs.Ant)


def creepage(scene, edit=None):
    """``(q/a_H, Q, ξ)`` of a Newton run of ``scene`` (influence edited by ``edit``)."""
    s = edited(scene, edit) if edit else scene
    a = rollqp.run(s.replace(**{"solver.method": "newton"}), method="newton").arrays()
    return a["q"] / scene.a_H, a["Q"], a["creepage"]


def steady_creepage(scene, ratio=0.75) -> float:
    """Newton's direct steady solve (``load.start = "rolling"``) at Q/(μP) = ratio."""
    s = scene.replace(**{"load.start": "rolling", "discretization.distance": 0.0,
                         "load.tangential": {"kind": "constant", "value": ratio}})
    return float(rollqp.run(s, method="newton").arrays()["creepage"][0])


def at(q, xi, where):
    return float(xi[int(np.argmin(np.abs(q - where)))])


CASES = [(None, 0.1), (None, 0.5), ("A", 0.1), ("A", 0.5), ("B", 0.1), ("B", 0.5)]
LABEL = {None: "steel/steel", "A": "Al A / steel B", "B": "steel A / Al B"}
MID, AFTER = 1.5, RAMP_END + 4.0     # mid-ramp; two contact widths (4 a_H) after the ramp


def study(aluminium, shaft, distance):
    """Every measured quantity of one case (module docstring)."""
    sH, sB = (ramp_scene(m, aluminium, shaft, distance) for m in ("halfspace", "bem"))
    cH, cB = windup_compliance(sH), windup_compliance(sB)
    dQdq = 0.75 * sH.contact.friction * sH.load.normal / (RAMP_END * sH.a_H)
    q, _, xH = creepage(sH)
    _, _, xB = creepage(sB)
    _, _, xHw = creepage(sH, add_windup(cB - cH))
    _, _, xBc = creepage(sB, halfspace_coupling)
    steady = {m: steady_creepage(s) for m, s in (("H", sH), ("B", sB))}
    steady["Bc"] = steady_creepage_edited(sB, halfspace_coupling)
    free = {m: steady_creepage(s, 0.0) for m, s in (("H", sH), ("B", sB))}
    scale = abs(steady["H"]) if abs(steady["H"]) > 1e-12 else abs(steady["B"])
    return dict(
        case=LABEL[aluminium], shaft=shaft, beta=sH.beta, cH=cH, cB=cB, torsion=torsion_compliance(sB), dQdq=dQdq,
        mid_H=at(q, xH, MID), mid_B=at(q, xB, MID), mid_Bc=at(q, xBc, MID), predicted=-(cB - cH) * dQdq,
        full_resid=float(np.max(np.abs(xBc - xHw)[1:])) / scale,
        after_H=at(q, xH, AFTER), after_B=at(q, xB, AFTER), end_H=float(xH[-1]), end_B=float(xB[-1]),
        steady_H=steady["H"], steady_B=steady["B"], steady_Bc=steady["Bc"], free_H=free["H"], free_B=free["B"],
        curves=(q, xH, xB, xHw, xBc))


def steady_creepage_edited(scene, edit, ratio=0.75):
    return steady_creepage(edited(scene, edit), ratio)


def tables(results, distance) -> str:
    e = "{:.3e}".format
    r1 = [(r["case"], r["shaft"], f"{r['beta']:+.3f}", e(r["cH"]), e(r["cB"]), e(r["torsion"]), f"{r['dQdq']:.2f}",
           e(r["mid_H"]), e(r["mid_B"]), f"{r['mid_B'] / r['mid_H']:.2f}", e(r["mid_Bc"] - r["mid_H"]),
           e(r["predicted"]), f"{(r['mid_Bc'] - r['mid_H']) / r['predicted']:.4f}", e(r["mid_B"] - r["mid_Bc"]))
          for r in results]
    h1 = ["bodies", "shaft/R_α", "β", "c_HS", "c_BEM", "torsion (R²/r²−1)/4πG", "dQ/dq (N/mm²)",
          f"ξ_HS (q = {MID} a_H)", "ξ_BEM", "BEM/HS", "wind-up: ξ_BEM,HS coupling − ξ_HS",
          "predicted −(c_BEM − c_HS)·dQ/dq", "measured/predicted", "coupling: ξ_BEM − ξ_BEM,HS coupling"]
    r2 = [(r["case"], r["shaft"], e(r["after_H"]), e(r["after_B"]), f"{r['after_B'] / r['after_H']:.3f}",
           e(r["end_H"]), e(r["end_B"]), e(r["steady_H"]), e(r["steady_B"]), f"{r['steady_B'] / r['steady_H']:.3f}",
           f"{r['steady_Bc'] / r['steady_H']:.4f}", e(r["free_H"]), e(r["free_B"]), f"{r['full_resid']:.4f}")
          for r in results]
    h2 = ["bodies", "shaft/R_α", f"ξ_HS (q = {AFTER:.2f} a_H)", "ξ_BEM", "BEM/HS", f"ξ_HS (q = {distance:g} a_H)",
          "ξ_BEM", "steady ξ_HS", "steady ξ_BEM", "BEM/HS", "BEM, HS coupling / HS",
          "free rolling ξ_HS", "free rolling ξ_BEM", "max |ξ_BEM,HS coupling − ξ_HS+wind-up| / |steady ξ_HS|"]
    return ("During the ramp (Q/(μP) 0 → 0.75 over 8/3 a_H):\n\n" + table(h1, r1)
            + "\n\nAfter the ramp, the steady state (direct solve, Q/(μP) = 0.75) and free rolling (Q = 0):\n\n"
            + table(h2, r2))


SCALES = (1.0, 4.0, 16.0)


def scaling_table() -> str:
    """Steady creepage BEM/HS (Q = 0 and Q/(μP) = 0.75) as a_H/R shrinks (radii and shafts × k,
    same load) and with the outer BEM mesh refined: the coupling difference is a finite-size effect."""
    rows = []
    for al in ("A", "B"):
        for k in SCALES:
            geo = {f"bodies__{b}__{key}": v * k for b, R in (("A", 150.0), ("B", 300.0))
                   for key, v in (("radius", R), ("shaft_radius", 0.1 * R))}
            for outer in ((19, 38, 76) if k == 1.0 else (19,)):
                sH = ramp_scene("halfspace", al, **geo)
                sB = ramp_scene("bem", al, contact__bem_outer_elements=outer, **geo)
                fH, fB = steady_creepage(sH, 0.0), steady_creepage(sB, 0.0)
                tH, tB = steady_creepage(sH), steady_creepage(sB)
                rows.append((LABEL[al], f"{sH.a_H / sH.R:.4f}", outer, f"{fH:.4e}", f"{fB:.4e}", f"{fB / fH:.3f}",
                             f"{fB - fH:+.3e}", f"{tH:.4e}", f"{tB:.4e}", f"{tB / tH:.3f}"))
    return table(["bodies", "a_H/R", "BEM outer elements", "free ξ_HS", "free ξ_BEM", "BEM/HS", "ξ_BEM − ξ_HS",
                  "ξ_HS (Q/μP = 0.75)", "ξ_BEM", "BEM/HS"], rows)


def figure(results, path):
    plt = pyplot()
    picks = [r for r in results if r["shaft"] == 0.1 and r["case"] in (LABEL[None], LABEL["A"])]
    fig, axes = plt.subplots(1, len(picks), figsize=(5.2 * len(picks), 3.8), squeeze=False)
    for ax, r in zip(axes[0], picks):
        q, xH, xB, xHw, xBc = r["curves"]
        ax.plot(q, xH * 1e3, "k-", lw=1.5, label="half-space")
        ax.plot(q, xB * 1e3, "C3-", lw=1.5, label="BEM")
        ax.plot(q, xHw * 1e3, "C0--", lw=1.2, label="half-space + BEM wind-up")
        ax.plot(q, xBc * 1e3, "C2:", lw=1.8, label="BEM with half-space coupling")
        ax.axvline(RAMP_END, color="0.6", lw=0.8)
        ax.set_xlabel("q / a_H")
        ax.set_ylabel("creepage ξ × 10³")
        ax.set_title(f"{r['case']}, shafts {r['shaft']} R_α", fontsize=10)
        ax.set_xlim(0, min(q[-1], 10))
        ax.grid(alpha=0.3)
    axes[0][0].legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def checks() -> list[str]:
    """Steel/steel, shafts 0.1 R_α: (1) the half-space's c is its kernel constant,
    c(d_ref) = c(R) + 2 ln(d_ref/R)/(πE*); the d_ref that gives the BEM's c makes the half-space
    reproduce the BEM's ramp; (2) a prescribed steady creepage returns the load it came from."""
    sH, sB = ramp_scene("halfspace", None, 0.1, 8.0), ramp_scene("bem", None, 0.1, 8.0)
    cH, cB = windup_compliance(sH), windup_compliance(sB)
    c10 = windup_compliance(sH.replace(**{"contact.reference_distance": 10.0 * sH.R}))
    out = [f"c_HS(10 R) − c_HS(R) = {c10 - cH:.6e}, 2 ln(10)/(πE*) = {2 * math.log(10) / (math.pi * sH.Estar):.6e}"]
    d = sH.R * math.exp((cB - cH) * math.pi * sH.Estar / 2.0)
    q, _, xH = creepage(sH.replace(**{"contact.reference_distance": d}))
    _, _, xB = creepage(sB)
    out.append(f"half-space with d_ref = {d:.3g} mm (c_HS = c_BEM): max |ξ_HS − ξ_BEM|/|ξ_BEM| = "
               f"{np.max(np.abs(xH - xB)[1:] / np.abs(xB[1:])):.2e} over 8 a_H")
    for name, s in (("half-space", sH), ("BEM", sB)):
        xi = steady_creepage(s)
        sp = s.replace(**{"load.start": "rolling", "discretization.distance": 0.0,
                          "load.creepage": {"kind": "constant", "value": xi}})
        Q = float(rollqp.run(sp, method="newton").arrays()["Q"][0])
        out.append(f"{name}: steady ξ = {xi:.6e} at Q/(μP) = 0.75; prescribed back: Q/(μP) = "
                   f"{Q / (s.contact.friction * s.load.normal):.10f}")
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--figure", metavar="PNG", help="also draw ξ(q) of the shaft-0.1 cases to PNG")
    ap.add_argument("--distance", type=float, default=20.0, help="rolled distance / a_H (default 20)")
    args = ap.parse_args(argv)
    results = []
    for al, sh in CASES:
        results.append(study(al, sh, args.distance))
        print(f"  {LABEL[al]}, shaft {sh}: done", file=sys.stderr, flush=True)
    print(machine_table(" ".join(["python benchmarks/bem_ramp_question.py"] + (argv or sys.argv[1:]))))
    print()
    print(tables(results, args.distance))
    print("\nThe coupling difference against a_H/R (radii and shafts scaled, same load; steady solves):\n")
    print(scaling_table())
    print("\nChecks (steel/steel, shafts 0.1 R_α):\n")
    print("\n".join("* " + line for line in checks()))
    if args.figure:
        figure(results, args.figure)
        print(f"\nfigure: {args.figure}")


if __name__ == "__main__":
    main()
