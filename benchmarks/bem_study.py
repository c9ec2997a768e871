"""Where the half-space model departs from true geometry (docs/bem.md, "Study"); figure + table.

Usage::

    python benchmarks/bem_study.py                      # table + docs/figures/bem-study.png (~1 min)
    python benchmarks/bem_study.py --figure out.png
    python benchmarks/bem_study.py --grading            # the mesh-grading trade-off table only
    python benchmarks/bem_study.py --mesh docs/figures/bem-mesh.png   # the default mesh of body A

The paper's rollers (R_A = 150 mm, R_B = 300 mm, relative radius R = 100 mm, steel on steel,
μ = 0.1) in steady rolling at Q/(μP) = 0.75 (``start = "rolling"``, Newton's direct steady
solve), with the normal load P chosen so that the Hertz half-width is a_H/R = 0.01 … 0.3, and
shafts of radius ``ratio·R_α`` on both rollers (0.1: the paper's thick rims; 0.5; 0.8: thin
rims, a rim of 0.2 R_α). For every case the same scene is run with ``contact.model =
"halfspace"`` and ``"bem"`` (coupling ``auto`` = off for similar materials, and the BEM again
with ``full`` to keep its geometric A_nt/A_tn), and the table gives BEM/half-space ratios of

* the peak pressure ``max p``;
* the contact half-width, measured by the second moment of the pressure,
  ``a_eq = 2 sqrt(∫p x² / ∫p)`` (exact for any elliptic pressure; a smooth measure, unlike the
  last loaded node);
* Carter's creepage ``ξ`` (the steady creepage at Q/(μP) = 0.75).

The half-space run reproduces Hertz and Carter to the discretization error (its own ratios to
the closed forms are printed as a check). Strip: 60 QCE on ±1.6 a_H (the BEM contacts of thin
rims are wider than a_H).
"""
from __future__ import annotations

from harness import machine_table, table  # noqa: F401  (pins BLAS first)

import numpy as np  # noqa: E402
import rollqp  # noqa: E402

import argparse  # noqa: E402
import math  # noqa: E402
import sys  # noqa: E402
from pathlib import Path  # noqa: E402


from rollqp import closedforms as cf  # noqa: E402
from rollqp import run  # noqa: E402

A_OVER_R = (0.01, 0.02, 0.05, 0.1, 0.2, 0.3)
SHAFT_RATIOS = (0.1, 0.5, 0.8)
RATIO = 0.75


def scene_for(a_over_R, shaft_ratio, model, coupling="auto"):
    base = rollqp.load_scene("cattaneo-carter")
    R, Es = base.R, base.Estar
    P = math.pi * Es * (a_over_R * R) ** 2 / (4.0 * R)           # a_H = a_over_R · R
    return base.replace(**{
        "load.normal": P, "load.start": "rolling", "load.tangential": {"kind": "constant", "value": RATIO},
        "bodies.A.shaft_radius": shaft_ratio * base.A.radius, "bodies.B.shaft_radius": shaft_ratio * base.B.radius,
        "contact.model": model, "contact.coupling": coupling, "solver.method": "newton",
        "discretization.elements": 60, "discretization.zone": 1.6, "discretization.distance": 0.0})


def measures(res, scene):
    p = np.asarray(res.rows["pn"][0])
    x = res.x
    f = rollqp.Strip(scene.half_width, scene.discretization.elements, scene.discretization.element).weights
    a_eq = 2.0 * math.sqrt(float(f @ (p * x * x)) / float(f @ p))
    return float(p.max()), a_eq, float(res.rows["creepage"][0])


def study():
    rows = []
    for ratio in SHAFT_RATIOS:
        for aR in A_OVER_R:
            hs = scene_for(aR, ratio, "halfspace")
            mh = measures(run(hs), hs)
            bs = scene_for(aR, ratio, "bem")
            rb = run(bs)
            mb = measures(rb, bs)
            bf = scene_for(aR, ratio, "bem", "full")
            mf = measures(run(bf), bf)
            xi_carter = cf.carter_creepage(hs.a_H, hs.R, hs.contact.friction, RATIO)
            rows.append(dict(shaft=ratio, aR=aR, p=mb[0] / mh[0], a=mb[1] / mh[1], xi=mb[2] / mh[2],
                             xi_full=mf[2] / mh[2], p_full=mf[0] / mh[0],
                             hs_p=mh[0] / hs.p0, hs_a=mh[1] / hs.a_H, hs_xi=mh[2] / xi_carter,
                             coupling=rb.meta["model"]["coupling_size"]))
    return rows


def figure(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.8), constrained_layout=True)
    keys = (("p", "peak pressure  max p"), ("a", "contact half-width  a_eq"), ("xi", "Carter creepage  ξ"))
    for ax, (key, title) in zip(axes, keys):
        for ratio, marker in zip(SHAFT_RATIOS, "osd"):
            sel = [r for r in rows if r["shaft"] == ratio]
            ax.plot([r["aR"] for r in sel], [r[key] for r in sel], marker=marker,
                    label=f"shaft/R = {ratio:g}")
            if key == "xi":
                ax.plot([r["aR"] for r in sel], [r["xi_full"] for r in sel], marker=marker, ls=":",
                        color=ax.lines[-1].get_color(), alpha=0.7)
        ax.axhline(1.0, color="k", lw=0.8)
        ax.set_xscale("log")
        ax.set_xlabel("a_H / R")
        ax.set_title(title + ": BEM / half-space", fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=8)
    axes[2].text(0.02, 0.02, "dotted: BEM with its geometric A_nt/A_tn (coupling full)",
                 transform=axes[2].transAxes, fontsize=7)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def gradingtable():
    """The default mesh's grading cap: Lamé error against the §6.1.1 transient's departure.

    For caps of ``f·2πR/n_outer`` (``f = MAX_ANGLE_FACTOR``): the Lamé error on the contact mesh
    of body A (``lame_ring``, uniform outer pressure), the max difference of the §6.1.1
    transient (``cattaneo-carter``, Newton) from the half-space run over all nodes and steps,
    and the asymmetry of F·A_nn.
    """
    from rollqp.influence import bem
    base = rollqp.load_scene("cattaneo-carter").replace(**{"solver.method": "newton"})
    rh = run(base)
    strip = rollqp.Strip(base.half_width, 40, "quadratic")
    exact = cf.lame_ring_displacement(150.0, 15.0, 150.0, 1.0, base.A.E, base.A.nu)
    keep = bem.MAX_ANGLE_FACTOR
    rows = []
    try:
        for factor in (1.0, 1.15, 1.36, 2.0, 4.0):
            bem.MAX_ANGLE_FACTOR = factor
            mesh = bem.annulus_mesh(150.0, 15.0, strip.edges)
            lame = np.max(np.abs(bem.lame_ring(mesh, base.A.nu, 1.0, base.A.E) / exact - 1))
            rb = run(base.replace(**{"contact.model": "bem"}))
            dt = np.max(np.abs(np.asarray(rb.rows["pt"]) - np.asarray(rh.rows["pt"]))) / (0.1 * base.p0)
            dp = np.max(np.abs(np.asarray(rb.rows["pn"]) - np.asarray(rh.rows["pn"]))) / base.p0
            free = mesh.lengths[40:mesh.n_outer_elements]
            rows.append([f"{factor:g}", f"{free[0]:.3g}", f"{free.max():.3g}", f"{lame:.2e}", f"{dt:.4f}",
                         f"{dp:.4f}", f"{rb.meta['model']['asymmetry_FA']:.2e}"])
    finally:
        bem.MAX_ANGLE_FACTOR = keep
    return table(["cap factor", "first free element (mm)", "largest (mm)", "Lamé error", "§6.1.1 max|Δt|/(μp0)",
                   "max|Δp|/p0", "asymmetry F·A_nn"], rows)


def mesh_figure(path):
    """The default BEM mesh of body A of ``cattaneo-carter``: whole roller and the strip's neighbourhood."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from rollqp.influence import bem
    sc = rollqp.load_scene("cattaneo-carter")
    strip = rollqp.Strip(sc.half_width, 40, "quadratic")
    m = bem.annulus_mesh(sc.A.radius, sc.A.shaft_radius, strip.edges)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.6), constrained_layout=True)
    for ax, zoom in zip(axes, (None, 12.0 * sc.half_width)):
        for e in range(m.n_elements):
            x, _, _ = m.points(e, np.linspace(-1, 1, 60))
            ax.plot(x[:, 0], x[:, 1], color="C0" if e >= m.n_strip else "C3", lw=1.2 if e >= m.n_strip else 3,
                    zorder=1 if e >= m.n_strip else 3)
        ends, _, _ = m.points(np.arange(m.n_elements)[:, None], np.array([-1.0, 1.0]))
        ax.plot(ends[m.n_strip:, :, 0].ravel(), ends[m.n_strip:, :, 1].ravel(), "k|" if zoom else "k.", ms=6, zorder=2)
        ax.set_aspect("equal")
        if zoom:
            ax.set_xlim(-zoom, zoom)
            ax.set_ylim(-sc.A.radius - 0.3 * zoom, -sc.A.radius + 0.5 * zoom)
            ax.set_title(f"near the contact (strip: 40 QCE on ±{sc.half_width:.3g} mm, red)", fontsize=9)
        else:
            ax.set_title(f"body A: R = {sc.A.radius:g}, shaft {sc.A.shaft_radius:g} mm; strip (red) + "
                         f"{m.n_outer_elements - m.n_strip} graded + "
                         f"{m.n_elements - m.n_outer_elements} shaft elements",
                         fontsize=9)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--figure", default=str(Path(__file__).resolve().parents[1] / "docs/figures/bem-study.png"))
    ap.add_argument("--grading", action="store_true", help="print the mesh-grading trade-off table only")
    ap.add_argument("--mesh", metavar="PNG", help="draw the default mesh of body A to PNG and stop")
    args = ap.parse_args(argv)
    if args.mesh:
        mesh_figure(args.mesh)
        return
    if args.grading:
        print(gradingtable())
        return
    rows = study()
    print(table(["shaft/R", "a_H/R", "max p (BEM/HS)", "a_eq (BEM/HS)", "ξ (BEM/HS)", "ξ full (BEM/HS)",
                  "|F A_nt|/|F A_nn|", "HS: max p/p0", "HS: a_eq/a_H", "HS: ξ/ξ_Carter"],
                 [[f"{r['shaft']:g}", f"{r['aR']:g}", f"{r['p']:.4f}", f"{r['a']:.4f}", f"{r['xi']:.4f}",
                   f"{r['xi_full']:.4f}", f"{r['coupling']:.2e}", f"{r['hs_p']:.4f}", f"{r['hs_a']:.4f}",
                   f"{r['hs_xi']:.4f}"] for r in rows]))
    figure(rows, args.figure)
    print(f"\nfigure: {args.figure}")


if __name__ == "__main__":
    main()
