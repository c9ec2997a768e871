"""The numbers and figures of docs/stresses.md §9-10 and docs/validation3d.md §15-16: subsurface stresses,
energy and frictional power on the 3D grid.

    python benchmarks/stresses3d_validation.py                          # every table
    python benchmarks/stresses3d_validation.py --only hertz contact --figures docs/figures

Sections: ``kernels`` (the rectangle integrals against quadrature), ``hertz`` (Huber's axis, Hamilton's
field, the sliding traction, grids 11-81 across), ``contact`` (CONTACT's subsurf), ``energy`` (CONTACT's
tractcurv ELAST.EN and FRIC.POWER, the steady identity and the transient balance as the grid doubles).
``--figures DIR`` writes ``stresses-3d.png`` (a rolling contact's stresses) and
``stresses-3d-convergence.png``.
"""
from __future__ import annotations

import argparse
import re
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

import contact3d_cases  # noqa: E402
from rollqp import load_scene  # noqa: E402
from rollqp.closedforms.hertz3d import hamilton_normal, huber_axis, sliding_axis_shear  # noqa: E402
from rollqp.energy import elastic_energy_of, grid_balance  # noqa: E402
from rollqp.plot.stresses import plot_field3d  # noqa: E402
from rollqp.subsurface3d import invariants, point_load, stress_components, stresses3d  # noqa: E402
from rollqp.operators.grid import Contact, Loads  # noqa: E402
from rollqp.methods.newton.disc import NewtonMethod  # noqa: E402
from rollqp.discretization.grid import Grid  # noqa: E402
from rollqp.closedforms.hertz_ellipse import curvatures_for_ratio, hertz  # noqa: E402
from rollqp.march.grid import steady  # noqa: E402
from rollqp.materials import Materials  # noqa: E402
from rollqp.march.grid import run  # noqa: E402


def _gauss_disk(x, y, z, a, p0, nu, load, n=160):
    u, wu = np.polynomial.legendre.leggauss(n)
    u, wu = (u + 1) * np.pi / 4, wu * np.pi / 4
    t, wt = np.polynomial.legendre.leggauss(2 * n)
    t, wt = (t + 1) * np.pi, wt * np.pi
    U, T = np.meshgrid(u, t)
    W = np.outer(wt, wu) * a * a * np.sin(U) * np.cos(U) * p0 * np.cos(U)
    r = a * np.sin(U)
    return (point_load(x - r * np.cos(T), y - r * np.sin(T), z, nu)[load] * W.ravel()).sum(axis=1)


def kernels():
    print("## kernels: the 18 rectangle integrals against composite Gauss quadrature of the point loads")
    g = Grid(1, 1, 1.0, 0.6, -0.5, -0.3)
    for pt in [(0.1, 0.2, 0.3), (0.7, -0.4, 0.05), (-2.0, 1.5, 0.5), (0.5, 0.3, 0.2), (5.0, -3.0, 0.05)]:
        got = np.stack([stress_components(g, *pt, *(np.eye(3)[k].reshape(3, 1, 1)), 0.28)[:, 0] for k in range(3)])
        w = pt[2] / 6
        ks, ke = max(1, int(np.ceil(1.0 / w))), max(1, int(np.ceil(0.6 / w)))
        t, wt = np.polynomial.legendre.leggauss(12)

        def rule(lo, hi, k):
            e = np.linspace(lo, hi, k + 1)
            h = np.diff(e)[:, None] / 2
            return (e[:-1, None] + h * (t + 1)).ravel(), (h * wt).ravel()
        s, ws = rule(-0.5, 0.5, ks)
        e, we = rule(-0.3, 0.3, ke)
        S, E = np.meshgrid(s, e)
        ref = point_load(pt[0] - S, pt[1] - E, pt[2], 0.28) @ np.outer(we, ws).ravel()
        print(f"  point {pt}: largest difference {np.max(np.abs(got - ref)) / np.max(np.abs(ref)):.1e} of the largest")


def hertz_rows(ns=(11, 21, 41, 81), nu=0.3, mu=0.3):
    rows = []
    m = Materials.from_young(210e3, nu, 210e3, nu)
    for n in ns:
        c = Contact.hertzian(m, (1 / 60, 1 / 60), 1000.0, mu, elements=(n, n), zone=(1.3, 1.3))
        p = c.grid.field(NewtonMethod().solve(c.normal_step(1000.0)).p)
        e = c.ellipse
        t0 = time.process_time()
        z = np.linspace(0.1, 2, 20) * e.a
        s = stress_components(c.grid, 0 * z, 0 * z, z, p, mu * p, 0 * p, nu)
        sxx, szz = huber_axis(z, e.a, e.p0, nu)
        huber = max(np.abs(s[0] - sxx).max(), np.abs(s[1] - sxx).max(), np.abs(s[2] - szz).max()) / e.p0
        shear = np.abs(s[4] - sliding_axis_shear(z, e.a, e.p0, mu)).max() / e.p0
        X, Y, Z = np.array([0.5, 0.3, -0.7]) * e.a, np.array([0.2, -0.6, 0.1]) * e.a, np.array([0.4, 0.5, 0.3]) * e.a
        off = stress_components(c.grid, X, Y, Z, p, mu * p, 0 * p, nu)
        cpu = time.process_time() - t0
        ref = hamilton_normal(X, Y, Z, e.a, e.p0, nu) + mu * np.stack(
            [_gauss_disk(X[i], Y[i], Z[i], e.a, e.p0, nu, 1) for i in range(3)], axis=1)
        rows.append((n, c.grid.dx / e.a, huber, shear, np.abs(off - ref).max() / e.p0, cpu))
    return rows


def hertz_section(figures=None):
    print("## hertz: the stresses of the computed Hertz pressure (and q_x = 0.3 p) against the closed forms")
    rows = hertz_rows()
    print("| elements across | dx/a | Huber, axis (p0) | sliding σxz, axis (μ = 0.3, p0) | off the axis (p0) | CPU s |")
    print("|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r[0]} | {r[1]:.4f} | {r[2]:.2e} | {r[3]:.2e} | {r[4]:.2e} | {r[5]:.2f} |")
    for col, name in ((2, "Huber"), (3, "sliding"), (4, "off axis")):
        sl = [np.log(rows[i][col] / rows[i + 1][col]) / np.log(rows[i][1] / rows[i + 1][1]) for i in range(len(rows) - 1)]
        print(f"  slopes {name}: " + ", ".join(f"{v:.2f}" for v in sl))
    if figures:
        from rollqp.plot import pyplot
        plt = pyplot()
        fig, ax = plt.subplots(figsize=(6, 4.5), constrained_layout=True)
        h = np.array([r[1] for r in rows])
        for col, label, mk in ((2, "Huber (axis: σxx, σyy, σzz)", "o-"), (3, "sliding traction μp: σxz on the axis", "s-"),
                               (4, "Hamilton + quadrature, off the axis", "^-")):
            ax.loglog(h, [r[col] for r in rows], mk, label=label)
        ax.loglog(h, rows[0][2] * (h / h[0]) ** 2, "k:", label="slope 2")
        ax.set_xlabel("dx / a")
        ax.set_ylabel("largest error / p0")
        ax.set_title("3D subsurface stresses below a computed Hertz contact", fontsize=9)
        ax.legend(fontsize=8)
        path = Path(figures) / "stresses-3d-convergence.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        print(f"  figure {path}")


def contact_section():
    print("## contact: CONTACT's subsurf case 2 (one element, pn = 1, px = 0.999), every point below the surface")
    rows = [line.split() for line in open(contact3d_cases.DATA / "subsurf.ref_subs") if not line.startswith("%")]
    d = np.array([[float(v) for v in r] for r in rows if len(r) == 14])
    d = d[np.any(d[:, 3:] != 0, axis=1) & (d[:, 2] > 0)]
    g = Grid(1, 1, 1.0, 1.0, -0.4999, -0.4998)
    inv = invariants(stress_components(g, d[:, 0], d[:, 1], d[:, 2], [[1.0]], [[0.999]], [[0.0]], 0.28))
    cols = dict(hydrostatic=6, von_mises=7, sxx=8, sxy=9, sxz=10, syy=11, syz=12, szz=13)
    print(f"  {len(d)} points")
    for name, c in cols.items():
        diff = np.abs(inv[name] - d[:, c])
        print(f"  {name:12s} largest difference {diff.max():.2e}, largest over the printing precision "
              f"(5e-6 |ref| + 5e-7): {np.max(diff / (5e-6 * np.abs(d[:, c]) + 5e-7)):.2f}")


def energy_section():
    print("## energy: CONTACT's tractcurv series 1 (48 x 44, V = 1e4 mm/s)")
    blocks = contact3d_cases.blocks("tractcurv")
    m = Materials.from_shear(82000.0, 0.28, 82000.0, 0.28)
    A = 0.0008
    B = curvatures_for_ratio(A, 0.5)
    e = hertz(A, B, m.Estar, 106700.0)
    c = Contact(Grid(48, 44, 2.2 * e.a / 48, 2.2 * e.b / 44, -1.1 * e.a, -1.1 * e.b), m, (A, B), 106700.0, 0.33)
    newton = NewtonMethod()
    p = newton.solve(c.normal_step(106700.0))
    dU, dP = [], []
    for blk in blocks[:30]:
        xi = float(re.search(r"CKSI\s+CETA\s+CPHI\n\s*\S+\s+\S+\s+\S+\s+(\S+)", blk).group(1))
        U_ref, P_ref = (float(v) for v in re.search(r"FRIC.POWER\n\s*\S+\s+\S+\s+\S+\s+\S+\s+(\S+)\s+(\S+)", blk).groups())
        rec = steady(c, newton, 106700.0, Loads(xi=xi, eta=0.0), -1, pressure=p)
        U = elastic_energy_of(c.ops, rec.p, rec.t) / 1000
        P = 1e4 / 1000 * c.grid.area * float(np.sum(np.asarray(rec.t).reshape(2, -1) * np.asarray(rec.s).reshape(2, -1)))
        dU.append(abs(U / U_ref - 1))
        dP.append(abs(P / P_ref - 1))
    print(f"  ELAST.EN: largest relative difference {max(dU):.1e}; FRIC.POWER: {max(dP):.1e} (case "
          f"{int(np.argmax(dP)) + 1}), {sorted(dP)[-2]:.1e} the next")
    print("## energy: steady identity and transient balance on a circle (cattaneo-3d) as the grid doubles")
    print("| elements across | 1 − P_f/(−Fx ξ), steady | balance residual / frictional work, transient |")
    print("|---|---|---|")
    for n in (12, 24, 48):
        base = {"discretization.elements": [n, n], "discretization.zone": [1.3, 1.3], "name": f"c{n}"}
        s = load_scene("cattaneo-3d").replace(**base, **{"load.start": "rolling", "discretization.distance": 0.0})
        a = run(s).arrays()
        ident = 1 - a["frictional_power"][0] / -(a["Fx"][0] * a["creepage"][0, 0])
        t = run(load_scene("cattaneo-3d").replace(**base, **{"discretization.distance": 1.5})).arrays()
        b = grid_balance(t)
        print(f"| {n} | {ident:.3f} | {b['residual'][-1] / b['friction_work'][-1]:.3f} |")


def figure(folder):
    scene = load_scene("cattaneo-3d").replace(**{"discretization.elements": [32, 32], "discretization.distance": 1.0})
    res = run(scene)
    a = res.arrays()
    sf = stresses3d(a, -1, plane=("y", 0.0), depths=np.linspace(0.02, 1.6, 60) * float(a["a"]),
                    along=np.linspace(-1.25, 1.25, 161) * float(a["a"]))
    path = plot_field3d(sf, a, Path(folder) / "stresses-3d.png", float(a["p0"]))
    print(f"  figure {path}: peak von Mises {sf.maxima['von_mises'][0] / float(a['p0']):.3f} p0 at depth "
          f"{sf.maxima['von_mises'][3] / float(a['a']):.3f} a")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--only", nargs="+", choices=("kernels", "hertz", "contact", "energy"), default=None)
    ap.add_argument("--figures", help="folder for stresses-3d.png and stresses-3d-convergence.png")
    args = ap.parse_args(argv)
    only = args.only or ("kernels", "hertz", "contact", "energy")
    if "kernels" in only:
        kernels()
    if "hertz" in only:
        hertz_section(args.figures)
    if "contact" in only:
        contact_section()
    if "energy" in only:
        energy_section()
    if args.figures:
        figure(args.figures)


if __name__ == "__main__":
    main()
