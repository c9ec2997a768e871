"""The tables of docs/validation3d.md: the 3D solutions against closed forms, Kalker's table and CONTACT.

Every section prints a markdown table (``--section NAME``, or all of them); ``--quick`` runs
smaller grids (a smoke run). Run from the repository root::

    python benchmarks/three_validation.py --section hertz
    python benchmarks/three_validation.py --section kalker
    python benchmarks/three_validation.py                       # everything (about an hour here)

Sections: ``hertz`` (semi-axes, p0, approach, pressure, as the grid doubles), ``cattaneo``
(Cattaneo–Mindlin on a circle, ν = 0 and 0.3), ``kalker`` (creep coefficients, extrapolated),
``sliding`` (full sliding), ``contact`` (CONTACT's cattaneo, catt_to_cart, tractcurv on CONTACT's
grids), ``agree`` (the conic solvers against Newton, step by step), ``coupling`` (the N–T
alternation for dissimilar bodies), ``aspect`` (element aspect ratio), ``march`` (the SOCP route
to the steady state), ``layer`` (the interface layer against the brush), ``tractcurv`` (CONTACT's tractcurv
series 2 and 3: falling friction with the interface layer, FASTSIM).
"""
from __future__ import annotations

import argparse
import time

import numpy as np
import contact3d_cases
import layer_cases
from harness import pin_threads, table

from rollqp.closedforms.cattaneo3d import cattaneo_shift, cattaneo_traction
from rollqp.closedforms.kalker import kalker_linear
from rollqp.operators.grid import Contact, Loads
from rollqp.discretization.grid import Grid
from rollqp.closedforms.hertz_ellipse import curvatures_for_ratio, hertz
from rollqp.march.grid import coupled_step, static_shift, steady, transient
from rollqp.materials import Materials
from rollqp.methods.newton.disc import NewtonMethod
from rollqp.report.grid import cattaneo_errors, creep_matrix, hertz_errors
from rollqp.methods.socp import ClarabelMethod, CvxpyMethod, OsqpMethod

FN, MU = 1000.0, 0.3
A_CURV = 1 / 60


def slope(hs, errs):
    """The exponent of ``err ∝ h^k`` between consecutive grids."""
    return [f"{np.log(abs(e1 / e2)) / np.log(h1 / h2):.2f}" for h1, h2, e1, e2 in zip(hs, hs[1:], errs, errs[1:])]


def contact_for(ratio, n, nu=0.25, zone=1.25, mu=MU):
    """A Hertz contact of semi-axis ratio ``a/b`` on ``n`` elements along the shorter axis (square elements)."""
    m = Materials.from_young(210e3, nu, 210e3, nu)
    B = curvatures_for_ratio(A_CURV, ratio)
    nx, ny = (n, max(3, round(n / ratio))) if ratio <= 1 else (max(3, round(n * ratio)), n)
    zone = max(zone, 1 + 2.5 / min(nx, ny))     # the outer rows of elements stay outside the ellipse
    return Contact.hertzian(m, (A_CURV, B), FN, mu, elements=(nx, ny), zone=(zone, zone))


def section_hertz(quick):
    rows = []
    for ratio in (1.0, 0.5, 0.2):
        ns = (11, 21, 41) if quick else (21, 41, 81, 161)
        hs, errs = [], {k: [] for k in ("a", "b", "p0", "delta", "rms")}
        for n in ns:
            c = contact_for(ratio, n)
            sol = NewtonMethod().solve(c.normal_step(FN))
            e = hertz_errors(c, sol)
            hs.append(c.grid.dx / min(c.ellipse.a, c.ellipse.b))
            for k in errs:
                errs[k].append(e[k])
            rows.append([ratio, f"{c.grid.nx}×{c.grid.ny}", f"{hs[-1]:.4f}"] + [f"{e[k]:+.2e}" for k in errs])
        rows.append([ratio, "slope", ""] + [", ".join(slope(hs, errs[k])) for k in errs])
    return table(["a/b", "grid", "dx/min(a,b)", "a", "b", "p0", "δ", "rms(p − p_H)/p0"], rows)


def section_cattaneo(quick):
    rows = []
    for nu in (0.0, 0.3):
        ns = (12, 24, 48) if quick else (16, 32, 64, 128)
        hs, rms, shift = [], [], []
        for n in ns:
            c = contact_for(1.0, n, nu=nu, zone=1.15)
            ratio = 0.6
            rec = static_shift(c, NewtonMethod(), FN, Fx=ratio * MU * FN)[-1]
            e, m = c.ellipse, c.materials
            err = cattaneo_errors(c, rec, ratio, lambda r: cattaneo_traction(r, e.a, e.p0, MU, ratio))
            ref = cattaneo_shift(FN, e.a, MU, ratio, m.G, m.nu)
            hs.append(c.grid.dx / e.a)
            rms.append(err["rms"])
            shift.append(abs(rec.info["shift"][0]) / ref - 1)
            rows.append([nu, f"{n}×{n}", f"{hs[-1]:.4f}", f"{err['rms']:.2e}", f"{err['max']:.2e}", f"{err['ty']:.2e}",
                         f"{shift[-1]:+.2e}"])
        rows.append([nu, "slope", "", ", ".join(slope(hs, rms)), "", "", ", ".join(slope(hs, shift))])
    return table(["ν", "grid", "dx/a", "rms(t − t_C)/μp0", "max/μp0", "max|t_y|/μp0", "shift/δ_C − 1"], rows)


def kalker_series(ratio, nu, ns):
    """Area-normalized creep coefficients on a series of grids and their least-squares extrapolation
    ``C(h) = C₀ + C₁ h``."""
    hs, vals = [], []
    for n in ns:
        c = contact_for(ratio, n, nu=nu, zone=1.1, mu=1e3)     # μ large: the linear theory (no slip)
        C, info = creep_matrix(c, NewtonMethod(), FN, area_normalized=True)
        assert info["slipping"] == 0
        hs.append(c.grid.dx / c.ellipse.c)
        vals.append([C[0, 0], C[1, 1], C[1, 2], C[2, 2]])
    hs, vals = np.array(hs), np.array(vals)
    M = np.column_stack([np.ones_like(hs), hs])
    coef, res, *_ = np.linalg.lstsq(M, vals, rcond=None)
    scatter = np.sqrt(np.mean((vals - M @ coef) ** 2, axis=0))
    return hs, vals, coef[0], scatter


def section_kalker(quick):
    rows = []
    cases = [(1.0, 0.25), (0.5, 0.25), (2.0, 0.25), (1.0, 0.28), (0.5, 0.28), (2.0, 0.28)]
    for ratio, nu in cases:
        base = (12, 16, 20) if quick else tuple(range(24, 65, 4))
        ns = [max(6, round(b * min(1.0, ratio))) for b in base]
        hs, vals, C0, scatter = kalker_series(ratio, nu, ns)
        ref = kalker_linear(ratio, nu) + (None,)     # Table E.3 (ν = 0.25: the table itself); C33: none
        cells = []
        for j, name in enumerate(("C11", "C22", "C23", "C33")):
            r = ref[j]
            dev = "" if r is None else f" ({C0[j] / r - 1:+.2%})"
            cells.append(f"{C0[j]:.3f} ± {scatter[j]:.3f}{dev}" + ("" if r is None else f" vs {r:.3g}"))
        rows.append([ratio, nu, f"{len(ns)} grids, h = {hs.min():.3f}…{hs.max():.3f}"] + cells)
    return table(["a/b", "ν", "grids", "C11", "C22", "C23", "C33"], rows)


def section_sliding(quick):
    rows = []
    n = 16 if quick else 32
    for nu in (0.0, 0.3):
        c = contact_for(1.0, n, nu=nu, zone=1.2)
        for scale in (4, 16, 64):
            xi, eta = -0.004 * scale, 0.003 * scale
            rec = steady(c, NewtonMethod(), FN, Loads(xi=xi, eta=eta, phi=0.0))
            on = rec.p > 0
            w = np.array([xi, eta]) / np.hypot(xi, eta)
            tmag = np.hypot(rec.t[0], rec.t[1])
            dot = -(rec.t[0, on] * w[0] + rec.t[1, on] * w[1])
            cross = rec.t[0, on] * w[1] - rec.t[1, on] * w[0]
            ang = np.abs(np.arctan2(cross, dot))
            bound = np.max(np.abs(tmag[on] - MU * rec.p[on])) / (MU * c.scales.stress)
            total = np.sum(tmag) * c.grid.area / (MU * FN) - 1
            rows.append([nu, f"{np.hypot(xi, eta):.3g}", int(np.sum(rec.state == 2)), int(on.sum()),
                         f"{bound:.1e}", f"{np.max(ang):.2e}", f"{total:+.1e}"])
    return table(["ν", "|creepage|", "slipping", "in contact", "max\\||t| − μp\\|/μp0", "max angle(−t, w) [rad]",
                  "Σ|t|·area/(μFN) − 1"], rows)


# ----------------------------------------------------------------------------- CONTACT's examples
def section_contact(quick):
    out = []
    ref, ours = contact3d_cases.cattaneo()
    rows = [[k, f"{ref[k]:.4g}", f"{ours[k]:.6g}",
             f"{ours[k] / ref[k] - 1:+.1e}" if isinstance(ref[k], float) else str(ours[k] == ref[k])] for k in ref]
    out.append("cattaneo (case 2)\n\n" + table(["quantity", "CONTACT", "rollqp", "rollqp/CONTACT − 1 or equal"], rows))
    steps = 8 if quick else 56
    ref, ours = contact3d_cases.catt_to_cart(steps)
    worst = max(abs(o[0] / r[0] - 1) for r, o in zip(ref, ours))
    same = sum(o[1:] == r[1:] for r, o in zip(ref, ours))
    rows = [[k, f"{r[0]:.4g}", f"{o[0]:.6g}", f"{o[0] / r[0] - 1:+.1e}", f"{o[1]}/{o[2]} ({r[1]}/{r[2]})"]
            for k, (r, o) in enumerate(zip(ref, ours)) if k < 6 or k == len(ref) - 1]
    out.append(f"catt_to_cart (cases 1–{steps + 1}): max |creepage/CONTACT − 1| = {worst:.1e}; adhesion/slip "
               f"counts equal in {same} of {len(ref)} cases\n\n"
               + table(["case − 1", "CONTACT shift/CKSI", "rollqp", "ratio − 1", "adh/slip (CONTACT)"], rows))
    cases = 6 if quick else 30
    ref, ours = contact3d_cases.tractcurv(cases)
    worst = max(abs(o[0] / r[1] - 1) for r, o in zip(ref, ours))
    same = sum(o[1:] == r[2:] for r, o in zip(ref, ours))
    rows = [[f"{r[0]:.3g}", f"{r[1]:.4g}", f"{o[0]:.6g}", f"{o[0] / r[1] - 1:+.1e}", f"{o[1]}/{o[2]} ({r[2]}/{r[3]})"]
            for r, o in zip(ref, ours)]
    out.append(f"tractcurv series 1 (cases 1–{cases}): max |FX/CONTACT − 1| = {worst:.1e}; adhesion/slip counts "
               f"equal in {same} of {len(ref)} cases\n\n"
               + table(["CKSI", "CONTACT FX", "rollqp Fx", "ratio − 1", "adh/slip (CONTACT)"], rows))
    return "\n\n".join(out)


# ----------------------------------------------------------------------------- two routes
def _diff(a, b, c):
    pu, tu, su = c.scales.stress, MU * c.scales.stress, c.scales.slip
    out = {}
    if a.p is not None:
        out["p"] = np.max(np.abs(a.p - b.p)) / pu
    if getattr(a, "t", None) is not None:
        out["t"] = np.max(np.abs(a.t - b.t)) / tu
        out["xi"] = max(abs(a.xi - b.xi), abs(a.eta - b.eta)) / su
    return out


def section_agree(quick):
    n = 12 if quick else 20
    c = contact_for(0.7, n, nu=0.3)
    newton = NewtonMethod()
    methods = {"socp-clarabel": ClarabelMethod(), "socp-cvxpy (Clarabel)": CvxpyMethod(solver="CLARABEL"),
               "socp-cvxpy (SCS)": CvxpyMethod(solver="SCS"), "qp-osqp": OsqpMethod()}
    rows = []
    pn = newton.solve(c.normal_step(FN))
    for name, m in methods.items():
        s = m.solve(c.normal_step(FN))
        rows.append(["normal", name, f"{_diff(s, pn, c)['p']:.1e}", "", "", f"{s.residual:.1e}", "–"])
    steps = {"shift (Fx, Fy)": ("shift", Loads(Fx=0.5 * MU * FN, Fy=-0.3 * MU * FN), None),
             "rolling, spin": ("rolling", Loads(Fx=0.4 * MU * FN, eta=1e-4, phi=0.3e-3 / c.scales.length),
                               (pn.p, 0.2 * MU * pn.p * np.array([[1.0], [0.0]])))}
    for label, (kind, loads, prev) in steps.items():
        prob = c.tangential_step(kind, pn.p, loads, prev, dq=c.grid.dx)
        ref = newton.solve(prob)
        for name, m in methods.items():
            if name == "qp-osqp":
                continue
            s = m.solve(prob)
            d = _diff(s, ref, c)
            rows.append([label, name, "", f"{d['t']:.1e}", f"{d['xi']:.1e}", f"{s.residual:.1e}",
                         f"{s.info.get('raw_residual', float('nan')):.1e}"])
    rows += _agree_transient(c, quick)
    return table(["step", "method", "max\\|Δp\\|/p0", "max\\|Δt\\|/μp0", "\\|Δ(ξ, η)\\|/(p0/E*)", "residual",
                  "raw residual"], rows)


def _agree_transient(c, quick):
    """Two independent marches (braked start, rolling steps): Clarabel against Newton, step by step."""
    steps = 4 if quick else 12
    loads = Loads(Fx=0.6 * MU * FN, eta=0.0)
    runs = []
    for m in (NewtonMethod(), ClarabelMethod()):
        start = static_shift(c, m, FN, Fx=loads.Fx)[-1]
        runs.append(list(transient(c, m, FN, loads, c.grid.dx, steps, -1, start=start)))
    dt = max(np.max(np.abs(a.t - b.t)) for a, b in zip(*runs)) / (MU * c.scales.stress)
    dxi = max(abs(a.xi - b.xi) for a, b in zip(*runs)) / c.scales.slip
    return [[f"transient, {steps} steps", "socp-clarabel", "", f"{dt:.1e}", f"{dxi:.1e}",
             f"{max(r.residual for r in runs[1]):.1e}", "–"]]


def section_coupling(quick):
    rows = []
    n = 12 if quick else 24
    for EA, nuA, EB, nuB in [(70e3, 0.33, 210e3, 0.28), (210e3, 0.28, 70e3, 0.33), (5e3, 0.45, 210e3, 0.3)]:
        m = Materials.from_young(EA, nuA, EB, nuB)
        c = Contact.hertzian(m, (A_CURV, A_CURV), FN, MU, elements=(n, n), zone=(1.25, 1.25))
        for label, kind, loads in (("shift Fx = 0.5 μFN", "shift", Loads(Fx=0.5 * MU * FN, eta=0.0)),
                                   ("steady ξ = −1e-3", "steady", Loads(xi=-1e-3, eta=0.0))):
            t0 = time.perf_counter()
            ns, ts, sw = coupled_step(c, NewtonMethod(), FN, kind, loads)
            ns2, ts2, sw2 = coupled_step(c, ClarabelMethod(), FN, kind, loads) if kind == "shift" else (ns, ts, sw)
            d = np.max(np.abs(ts.t - ts2.t)) / (MU * c.scales.stress)
            rows.append([f"{EA / 1e3:g}/{nuA} on {EB / 1e3:g}/{nuB}", f"{m.K:+.4f}", label, sw,
                         f"{max(ns.residual, ts.residual):.1e}", f"{d:.1e}" if kind == "shift" else "–",
                         f"{time.perf_counter() - t0:.1f}"])
    return table(["E_A [GPa]/ν_A on E_B/ν_B", "K", "step", "N–T sweeps (Newton)", "residual",
                  "Clarabel − Newton, t/μp0", "time [s]"], rows)


def section_aspect(quick):
    rows = []
    total = 400 if quick else 1600
    for asp in (0.2, 0.5, 1.0, 2.0, 5.0):
        nx = int(round(np.sqrt(total * asp)))    # dx/dy = asp on a square zone: nx/ny = 1/asp·… (square contact)
        ny = int(round(total / nx))
        m = Materials.from_young(210e3, 0.25, 210e3, 0.25)
        e = hertz(A_CURV, A_CURV, m.Estar, FN)
        g = Grid.centred(ny, nx, 1.25 * e.a, 1.25 * e.b)
        c = Contact(g, m, (A_CURV, A_CURV), FN, MU)
        er = hertz_errors(c, NewtonMethod().solve(c.normal_step(FN)))
        rows.append([f"{g.dx / g.dy:.2f}", f"{g.nx}×{g.ny}", f"{er['rms']:.2e}", f"{er['a']:+.2e}", f"{er['b']:+.2e}"])
    return table(["dx/dy", "grid", "rms(p − p_H)/p0", "a_h/a − 1", "b_h/b − 1"], rows)


def section_march(quick):
    rows = []
    n = 12 if quick else 20
    c = contact_for(1.0, n, nu=0.25, zone=1.2)
    loads = Loads(Fx=0.5 * MU * FN, eta=0.0)
    direct = steady(c, NewtonMethod(), FN, loads)

    class Stepper(NewtonMethod):   # Newton on the rolling steps only: counts the march's steps cheaply
        solves = frozenset({"normal", "tangential"})

    for label, m, mem in [("Newton steps", Stepper(), 0), ("Newton steps", Stepper(), 6),
                          ("socp-clarabel", ClarabelMethod(), 6)]:
        t0 = time.perf_counter()
        rec = steady(c, m, FN, loads, memory=mem)
        d = np.max(np.abs(rec.t - direct.t)) / (MU * c.scales.stress)
        rows.append([label, mem, rec.info["marched"], f"{d:.1e}", f"{time.perf_counter() - t0:.1f}"])
    return table(["stepper", "Anderson memory", "steps (Δq = dx)", "max\\|t − t_direct\\|/μp0", "time [s]"], rows)


def section_layer(quick):
    """The interface layer against the brush (eq. B.1) as the grid doubles: 3D (a circle, n × n over 1.1·(a, b)) and
    the strip (constant elements over ±1.1 a_H), a layer 1e4 times as compliant as the bodies' a/G or a_H/E*."""
    rows = []
    ns3 = (11, 22) if quick else (11, 22, 44, 88)
    errs = [layer_cases.brush_3d(n) for n in ns3]
    for (e, h), n in zip(errs, ns3):
        rows.append(["3D grid", f"{n} × {n}", *(f"{v:+.2e}" for v in e)])
    ns2 = (22, 44) if quick else (22, 44, 88, 176)
    errs2 = [layer_cases.brush_strip(n) for n in ns2]
    for (e, h), n in zip(errs2, ns2):
        rows.append(["strip", n, *(f"{v:+.2e}" for v in e)])
    orders = [[f"order ({what}, first grid to last)", "",
               *(f"{layer_cases.order([e[0][j] for e in es], [e[1] for e in es]):.2f}" for j in range(2))]
              for what, es in (("3D", errs), ("strip", errs2))]
    return table(["discretization", "elements", "F/(μN)/brush − 1 at κ = 0.3", "at κ = 1"], rows + orders)


def section_tractcurv(quick):
    """CONTACT's tractcurv series 2 (falling friction with memory, interface layer) and series 3 (FASTSIM) on its
    48 × 44 grid; series 1 is in section ``contact``."""
    cases = 4 if quick else 30
    ref, ours = contact3d_cases.tractcurv_falling(cases)
    _, bare = contact3d_cases.tractcurv_falling(cases, memory=False)
    rows = [[f"{r[0]:.4g}", f"{r[1]:.4g}", f"{o[0]:.6g}", f"{o[0] / r[1] - 1:+.1e}", f"{b[0] / r[1] - 1:+.1e}",
             f"{o[1]}/{o[2]} ({r[2]}/{r[3]})", o[3]] for r, o, b in zip(ref, ours, bare)]
    worst = max(abs(o[0] / r[1] - 1) for r, o in zip(ref, ours))
    worst_bare = max(abs(b[0] / r[1] - 1) for r, b in zip(ref, bare))
    out = (f"series 2 (cases 31–{30 + cases}): max |FX/CONTACT − 1| = {worst:.1e} with CONTACT's memory, {worst_bare:.1e} "
           "without (MEMDST = 0)\n\n" +
           table(["CKSI", "CONTACT FX", "rollqp Fx", "ratio − 1", "no memory: ratio − 1", "adh/slip (CONTACT)",
                  "outer iterations"], rows))
    rows3 = [[f"{x:.4g}", f"{r:.4g}", f"{o:.6g}", f"{o / r - 1:+.1e}"] for x, r, o in layer_cases.tractcurv_fastsim()[:cases]]
    return out + "\n\nseries 3 (FASTSIM) against rollqp's fastsim\n\n" + table(["CKSI", "CONTACT FX", "rollqp fastsim Fx",
                                                                                  "ratio − 1"], rows3)


SECTIONS = {"hertz": section_hertz, "cattaneo": section_cattaneo, "kalker": section_kalker, "sliding": section_sliding,
            "contact": section_contact, "agree": section_agree, "coupling": section_coupling, "aspect": section_aspect,
            "march": section_march, "layer": section_layer, "tractcurv": section_tractcurv}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--section", choices=sorted(SECTIONS), action="append", help="a section (repeatable; default all)")
    ap.add_argument("--quick", action="store_true", help="small grids: a smoke run, not the published numbers")
    args = ap.parse_args(argv)
    pin_threads()
    for name in args.section or list(SECTIONS):
        t0 = time.perf_counter()
        text = SECTIONS[name](args.quick)
        print(f"### {name} ({time.perf_counter() - t0:.0f} s)\n\n{text}\n", flush=True)


if __name__ == "__main__":
    main()
