"""Validation of rollqp: closed forms (paper §6.1), CONTACT, convergence slopes.

One command regenerates every table of ``docs/validation.md``::

    python benchmarks/validation.py            # all tables (about 1.5 min on 2 cores)
    python benchmarks/validation.py --full     # also CONTACT's finest grid (880 elements, minutes)
    python benchmarks/validation.py --only contact-transient contact-steady

It prints Markdown. BLAS is pinned to one thread (threadpoolctl) so that timings mean the
same on every machine; the numbers themselves do not depend on it.

Sections (``--only`` names):

* ``paper``             §6.1.1 Cattaneo → Carter on the paper's mesh, per QP backend;
* ``ramp``              §6.1.2 ramp: its end state against Carter and against §6.1.1's;
* ``contact-transient`` CONTACT's Cattaneo → Carter transient on CONTACT's grid, step by step;
* ``contact-steady``    CONTACT's steady Carter cases (220 elements) at four load ratios;
* ``contact-grid``      CONTACT's grid study (μ = 0.3, Q/(μP) = 0.75), DX = 0.04 … 0.005 mm;
* ``convergence``       log–log slopes of the errors against Hertz, Cattaneo, Carter, creepage;
* ``splitting``         the symmetric–skew splitting's contraction factor ρ (rollqp.methods._qp).

Reference data: ``tests/data/contact`` in the repository (or ``$ROLLQP_CONTACT_REFDATA``);
see its README for CONTACT's conventions. CONTACT's FX < 0 with cksi > 0; rollqp's Q > 0 gives
ξ < 0 and t ≥ 0 with the same magnitudes, so |ξ| is compared with cksi and pt with −px.
"""
from __future__ import annotations

import argparse
import csv
import sys
import time

import numpy as np
from harness import table  # (pins BLAS first)

import rollqp
from rollqp import closedforms as cf
from rollqp.operators import SceneOperators


# CONTACT's inputs (refdata README) and its problem as a scene: benchmarks/refcases.py, one copy with
# the tests.
from refcases import (E_CONTACT, FN_CONTACT, G_CONTACT, MU_CONTACT, NU_CONTACT,  # noqa: E402,F401
                              RATIO_CONTACT as RATIO, REFDATA, contact_scene, convergence_errors)
from rollqp.report import rms_in_contact  # noqa: E402

QP_BACKENDS = ("qp-osqp", "qp-clarabel", "qp-cvxpy")
#: The generalized Newton method, run beside the QPs as a cross-check where present.
NEWTON = ("newton",) if "newton" in rollqp.available_methods() else ()


# =========================================================================== helpers
def read_csv(name):
    with open(REFDATA / name, newline="") as fh:
        return list(csv.DictReader(fh))


def read_table(name):
    return np.genfromtxt(REFDATA / name, delimiter=",", names=True)




def slope(n, err):
    """Fitted order p of err ~ Le^p: least squares on log err against log Le = log(2L/n)."""
    return float(np.polyfit(np.log(1.0 / np.asarray(n, float)), np.log(np.asarray(err, float)), 1)[0])


def settle_distance(q, rel, threshold):
    """First q from which |rel| stays ≤ threshold (q and rel over the rolling steps)."""
    bad = np.flatnonzero(np.abs(rel) > threshold)
    if bad.size == 0:
        return float(q[0])
    return float(q[bad[-1] + 1]) if bad[-1] + 1 < q.size else float("nan")


def timed_run(scene, method=None):
    t0 = time.perf_counter()
    res = rollqp.run(scene, method=method)
    return res, res.arrays(), time.perf_counter() - t0


def pct(v, digits=3):
    return f"{100 * v:.{digits}f} %"


# =========================================================================== §6.1.1 / §6.1.2
def paper_errors(r, scene):
    """Closed-form errors of a Cattaneo → Carter run (constant loads), in the §6.1.1 sense."""
    x, a, p0, R, mu = r["x"], scene.a_H, scene.p0, scene.R, scene.contact.friction
    ratio = float(r["Q"][-1]) / (mu * float(r["P"][-1]))
    xi, xi_c = float(r["creepage"][-1]), cf.carter_creepage(a, R, mu, ratio)
    return {
        "hertz": rms_in_contact(x, a, r["pn"][0] - cf.hertz_pressure(x, a, p0)) / p0,
        "cattaneo": rms_in_contact(x, a, r["pt"][0] - cf.cattaneo_traction(x, a, p0, mu, ratio)) / (mu * p0),
        "carter": rms_in_contact(x, a, r["pt"][-1] - cf.carter_traction(x, a, p0, mu, ratio, scene.load.direction))
        / (mu * p0),
        "creepage": xi / xi_c - 1.0,
        # the creep law read the other way: the load ratio Carter's law gives for rollqp's ξ
        "creep_law": cf.creep_force_ratio(xi, a, R, mu) / ratio - 1.0,
        "xi": xi, "xi_carter": xi_c,
    }


def section_paper():
    scene = rollqp.load_scene("cattaneo-carter")
    rows, runs = [], {}
    for m in QP_BACKENDS + NEWTON:
        res, r, wall = timed_run(scene, m)
        runs[m] = r
        e = paper_errors(r, scene)
        rows.append([m, pct(e["hertz"]), pct(e["cattaneo"]), pct(e["carter"]), pct(e["creepage"]),
                     pct(e["creep_law"]), f"{e['xi']:.6e}", f"{r['residual'].max():.1e}", f"{wall:.1f} s"])
    ref = runs[QP_BACKENDS[0]]
    mup0 = scene.contact.friction * scene.p0
    others = [m for m in runs if m != QP_BACKENDS[0]]
    agree = max(float(np.abs(runs[m]["pt"] - ref["pt"]).max()) / mup0 for m in others)
    agree_xi = max(float(np.abs(runs[m]["creepage"][1:] / ref["creepage"][1:] - 1).max()) for m in others)
    print("### §6.1.1 Cattaneo → Carter on the paper's mesh (40 QCE, zone ±1.25 a_H, Δq = Le/2, 6 a_H)\n")
    print(table(["method", "Hertz rms/p0", "Cattaneo rms/μp0 (q = 0)", "Carter rms/μp0 (q = 6 a_H)",
                 "ξ/ξ_Carter − 1", "creep law: Q/μP(ξ)/0.75 − 1", "ξ (6 a_H)", "max residual", "wall"], rows))
    print(f"\n{', '.join(others)} against {QP_BACKENDS[0]}, all {len(ref['q'])} states: max |Δt| = {agree:.1e} μp0, "
          f"max |Δξ/ξ| = {agree_xi:.1e}.\n")
    return runs


def section_ramp(paper_runs=None):
    base = rollqp.load_scene("cattaneo-carter")
    scene = rollqp.load_scene("ramp")
    mup0 = scene.contact.friction * scene.p0
    rows = []
    for m in ("qp-osqp", "qp-clarabel") + NEWTON:
        _, r, wall = timed_run(scene, m)
        ref = paper_runs[m] if paper_runs and m in paper_runs else timed_run(base, m)[1]
        x, a, p0, mu = r["x"], scene.a_H, scene.p0, scene.contact.friction
        carter = rms_in_contact(x, a, r["pt"][-1] - cf.carter_traction(x, a, p0, mu, RATIO, -1)) / mup0
        xi_c = cf.carter_creepage(a, scene.R, mu, RATIO)
        d_t = float(np.abs(r["pt"][-1] - ref["pt"][-1]).max()) / mup0
        d_xi = float(r["creepage"][-1] / ref["creepage"][-1] - 1)
        stick = int(np.sum(r["state"][-1] == 1)), int(np.sum(ref["state"][-1] == 1))
        rows.append([m, pct(carter), pct(float(r["creepage"][-1]) / xi_c - 1), f"{d_t:.1e}", f"{d_xi:.1e}",
                     f"{stick[0]} / {stick[1]}", f"{wall:.1f} s"])
    print("### §6.1.2 ramp (built-in `ramp`: Q/(μP) 0 → 0.75 over 8/3 a_H, rolled to 6 a_H)\n")
    print(table(["method", "Carter rms/μp0 (6 a_H)", "ξ/ξ_Carter − 1", "max |t_ramp − t_6.1.1|/μp0",
                 "ξ_ramp/ξ_6.1.1 − 1", "stick nodes ramp / 6.1.1", "wall"], rows))
    print()


# =========================================================================== CONTACT
def contact_reference_transient():
    hist = read_csv("a_catt2carter_mu0.1_history.csv")
    allsteps = read_table("a_catt2carter_mu0.1_tractions_all_steps.csv")
    steady = read_table("a_catt2carter_mu0.1_steady_reference.csv")
    n = int(allsteps["i"].max())
    steps = int(allsteps["step"].max()) + 1
    ref = {
        "q": np.array([float(h["rolled_over_a"]) for h in hist]),
        "cksi": np.array([float(h["cksi"]) for h in hist]),
        "rel": np.array([float(h["creepage_rel_diff_vs_steady"] or "nan") for h in hist]),
        "x": allsteps["x_mm"][allsteps["step"] == 0],
        "px": allsteps["px"].reshape(steps, n),
        "pn": allsteps["pn"].reshape(steps, n),
        "px_steady": steady["px"],
    }
    # CONTACT's steady creepage, as its history's relative differences define it
    ref["cksi_steady"] = float(np.nanmedian(ref["cksi"][1:] / (1.0 + ref["rel"][1:])))
    return ref


def transient_metrics(q, xi_abs, pt, pt_steady, xi_steady):
    """Overshoot peak and settling, as CONTACT's README states them (rolling steps only)."""
    rel = xi_abs[1:] / xi_steady - 1.0
    k = int(np.argmax(xi_abs[1:]))
    l2 = np.linalg.norm(pt[1:] - pt_steady, axis=1) / np.linalg.norm(pt_steady)
    return {"peak": float(rel[k]), "peak_q": float(q[1 + k]),
            "settle1": settle_distance(q[1:], rel, 0.01), "settle01": settle_distance(q[1:], rel, 0.001),
            "l2_1": settle_distance(q[1:], l2, 0.01)}


def section_contact_transient():
    ref = contact_reference_transient()
    rows, cmp_rows = [], []
    mc = transient_metrics(ref["q"], np.r_[0.0, ref["cksi"][1:]], -ref["px"], -ref["px_steady"], ref["cksi_steady"])
    for m in ("qp-osqp", "qp-clarabel") + NEWTON:
        scene = contact_scene(method=m)
        res, r, wall = timed_run(scene)
        _, rs, _ = timed_run(contact_scene(method=m, start="rolling", distance=0.0))
        a, p0, mup0 = scene.a_H, scene.p0, MU_CONTACT * scene.p0
        dx = float(np.abs(r["x"] - ref["x"]).max())
        dq = float(np.abs(r["q"] / a - ref["q"]).max())
        xi = np.abs(r["creepage"])
        d_xi = np.abs(xi[1:] - ref["cksi"][1:]) / ref["cksi_steady"]
        d_t = np.abs(r["pt"] + ref["px"]) / mup0
        d_p = float(np.abs(r["pn"] - ref["pn"]).max()) / p0
        kx = int(np.argmax(d_xi))
        kt = np.unravel_index(int(np.argmax(d_t[1:])), d_t[1:].shape)
        rows.append([m, f"{dx:.1e}", f"{dq:.1e}", f"{d_xi.max():.2e} (q = {ref['q'][1 + kx]:.3f})",
                     f"{d_t[0].max():.2e}",
                     f"{d_t[1:].max():.2e} (q = {ref['q'][1 + kt[0]]:.3f}, x = {ref['x'][kt[1]]:.4f})",
                     f"{d_p:.2e}", f"{wall:.2f} s ({1e3 * wall / (len(r['q'])):.1f} ms/step)"])
        xs = float(abs(rs["creepage"][0]))
        mr = transient_metrics(r["q"] / a, xi, r["pt"], rs["pt"][0], xs)
        kp = int(np.argmin(np.abs(ref["q"] - mc["peak_q"])))  # CONTACT's peak step
        cmp_rows.append([f"rollqp {m}", f"{xs:.6e}", pct(mr["peak"], 2),
                         f"{(xi[kp] - ref['cksi'][kp]) / ref['cksi_steady']:.1e}",
                         f"{mr['peak_q']:.3f}",
                         f"{mr['settle1']:.3f}", f"{mr['settle01']:.3f}", f"{mr['l2_1']:.3f}",
                         f"{float(np.abs(rs['pt'][0] + ref['px_steady']).max()) / mup0:.1e}"])
    cmp_rows.insert(0, ["CONTACT", f"{ref['cksi_steady']:.6e}", pct(mc["peak"], 2), "—", f"{mc['peak_q']:.3f}",
                        f"{mc['settle1']:.3f}", f"{mc['settle01']:.3f}", f"{mc['l2_1']:.3f}", "—"])
    print("### CONTACT: Cattaneo → Carter transient on CONTACT's grid "
          "(88 constant elements on ±1.1 a_H, Δq = DX = a/40, material form, 160 steps to 4 a_H)\n")
    print("Step by step (CONTACT step k ↔ rollqp state k); creepage relative to CONTACT's steady "
          f"creepage {ref['cksi_steady']:.6e}, tractions relative to μp0:\n")
    print(table(["method", "max |x − x_CONTACT| (mm)", "max |q/a − q_CONTACT/a|",
                 "max_k ||ξ_k| − cksi_k| / cksi_steady", "max_i |pt + px|/μp0, step 0 (Cattaneo)",
                 "max_k,i |pt + px|/μp0, steps 1–160", "max |pn − pn_CONTACT|/p0", "wall (161 states)"], rows))
    # where the pressures differ (the last method's run; pn is the same for every method)
    dp = (r["pn"][0] - ref["pn"][0]) / p0
    edge = int(np.argmax(np.abs(dp)))
    nxt = edge + (1 if ref["x"][edge] < 0 else -1)
    inner = np.abs(ref["x"]) < 0.9 * a
    print(f"\nPressure: the largest difference is at the outermost contact element, x = {ref['x'][edge]:+.4f} mm "
          f"(rollqp {r['pn'][0][edge]:.4f}, CONTACT {ref['pn'][0][edge]:.4f} N/mm², {dp[edge]:+.1e} p0); "
          f"{dp[nxt]:+.1e} p0 one element in; at most {np.abs(dp[inner]).max():.1e} p0 for |x| < 0.9 a. "
          f"Step 0's rigid shift and approach (d_ref-dependent, not compared): rollqp "
          f"{float(r['shift'][0]):+.3e} mm and {float(r['approach'][0]):.3e} mm; CONTACT shift "
          f"{float(ref['cksi'][0]):+.3e} mm.")
    print("\nThe transient's shape (q in a_H; each code against its own steady state on this grid):\n")
    print(table(["", "steady |ξ|", "overshoot peak", "peak: (|ξ| − cksi)/cksi_steady", "at q",
                 "|ξ| within 1 % of steady from q",
                 "within 0.1 % from q", "t within 1 % (L2) of steady from q", "steady max |pt + px|/μp0"],
                cmp_rows))
    print()


def section_contact_steady():
    summ = read_csv("b_carter_steady_mu0.1_summary.csv")
    tr = read_table("b_carter_steady_mu0.1_tractions.csv")
    rows = []
    for row in summ:
        ratio = -float(row["fx_over_mu_fn"])
        scene = contact_scene(elements=220, ratio=ratio, start="rolling", distance=0.0)
        res, r, wall = timed_run(scene)
        xi = float(r["creepage"][0])
        xi_c = cf.carter_creepage(scene.a_H, scene.R, MU_CONTACT, ratio)
        m = tr["fx_over_mu_fn"] == float(row["fx_over_mu_fn"])
        d_t = float(np.abs(r["pt"][0] + tr["px"][m]).max()) / (MU_CONTACT * scene.p0)
        stick = r["x"][r["state"][0] == 1]
        half = 0.5 * scene.element_length
        rows.append([f"{ratio:.2f}", pct(xi / xi_c - 1, 3), pct(float(row["creepage_rel_diff"]), 3),
                     f"{abs(xi) / float(row['creepage']) - 1:.1e}",
                     f"[{stick.min() - half:.2f}, {stick.max() + half:.2f}]",
                     f"[{float(row['adhesion_x_from']):.2f}, {float(row['adhesion_x_to']):.2f}]",
                     f"{d_t:.1e}", f"{wall:.1f} s"] + newton_check(scene, xi))
    print("### CONTACT: steady Carter rolling (220 constant elements on ±1.1 a_H, DX = 0.01 mm = a/100; "
          "rollqp: `start = \"rolling\"`, the transient marched to steady with Δq = DX)\n")
    print(table(["Q/(μP)", "rollqp ξ/ξ_Carter − 1", "CONTACT ξ/ξ_Carter − 1", "|ξ_rollqp|/ξ_CONTACT − 1",
                 "rollqp stick zone (mm)", "CONTACT adhesion (mm)", "max |pt + px|/μp0", "wall (qp-osqp)"]
                + NEWTON_COLUMNS, rows))
    print()


NEWTON_COLUMNS = ["wall (newton)", "|ξ_newton/ξ_qp-osqp − 1|"] if NEWTON else []


def newton_check(scene, xi_qp):
    """The same steady state by the Newton method: its wall time and its creepage against the QP's."""
    if not NEWTON:
        return []
    _, r, wall = timed_run(scene, NEWTON[0])
    return [f"{wall:.1f} s", f"{abs(float(r['creepage'][0]) / xi_qp - 1):.0e}"]


def section_contact_grid(full=False):
    study = read_csv("b_carter_steady_mu0.3_q0.75_grid_study.csv")
    rows_in = [r for r in study if float(r["dy_mm"]) == 200.0]
    rows, ns, er, ec, xi220, rel220 = [], [], [], [], None, None
    for row in rows_in:
        n = int(row["mx"])
        if n > 440 and not full:
            rows.append([row["dx_mm"], n, "(--full)", pct(float(row["creepage_rel_diff"]), 4), "", ""]
                        + ["" for _ in NEWTON_COLUMNS] + [row["wall_time_s"] + " s"])
            continue
        scene = contact_scene(elements=n, ratio=0.75, start="rolling", distance=0.0, mu=0.3)
        res, r, wall = timed_run(scene)
        xi = float(r["creepage"][0])
        rel = xi / cf.carter_creepage(scene.a_H, scene.R, 0.3, 0.75) - 1
        xi220, rel220 = (xi, rel) if n == 220 else (xi220, rel220)
        ns.append(n), er.append(abs(rel)), ec.append(abs(float(row["creepage_rel_diff"])))
        rows.append([row["dx_mm"], n, pct(rel, 4), pct(float(row["creepage_rel_diff"]), 4),
                     f"{abs(xi) / float(row['creepage']) - 1:.1e}", f"{wall:.1f} s"] + newton_check(scene, xi)
                    + [row["wall_time_s"] + " s"])
    print("### CONTACT's grid study (μ = 0.3, Q/(μP) = 0.75, steady; zone ±1.1 a_H, DY = 200 mm in CONTACT)\n")
    print(table(["DX (mm)", "elements", "rollqp ξ/ξ_Carter − 1", "CONTACT ξ/ξ_Carter − 1",
                 "|ξ_rollqp|/ξ_CONTACT − 1", "rollqp wall (qp-osqp)"] + NEWTON_COLUMNS + ["CONTACT wall"], rows))
    if len(ns) >= 3:
        print(f"\nFitted order over the rows run (excluding DX = 0.04, where a_H is not on an element edge): "
              f"rollqp {slope(ns[1:], er[1:]):.3f}, CONTACT {slope(ns[1:], ec[1:]):.3f}.")
    if xi220 is not None:
        # CONTACT's 2D mode is one row of elements of width DY: its strip-width sensitivity at DX = 0.01
        dy = [r for r in study if int(r["mx"]) == 220]
        print("\nCONTACT's strip width DY at DX = 0.01 mm against rollqp's plane-strain value "
              f"(ξ = {xi220:.10e}, ξ/ξ_Carter − 1 = {pct(rel220, 5)}):\n")
        print(table(["DY (mm)", "CONTACT ξ/ξ_Carter − 1", "|ξ_rollqp|/ξ_CONTACT − 1"],
                    [[r["dy_mm"], pct(float(r["creepage_rel_diff"]), 5), f"{abs(xi220) / float(r['creepage']) - 1:.1e}"]
                     for r in sorted(dy, key=lambda r: float(r["dy_mm"]))]))
    print()


# =========================================================================== convergence
CONV_ELEMENTS = (10, 20, 40, 80)


def section_convergence():
    keys = ("hertz", "cattaneo", "carter", "creepage")
    print("### Convergence under refinement (paper's problem: zone ±1.25 a_H, so a_H is an element edge on "
          "every mesh; Δq = Le/2; qp-osqp)\n")
    print("Errors: rms over the nodes in |x| ≤ a_H of (pn − Hertz)/p0 and (pt − Cattaneo)/μp0 at q = 0, "
          "(pt − Carter)/μp0 in steady rolling (`start = \"rolling\"`), and |ξ/ξ_Carter − 1|. "
          "Order p: least-squares slope of log(error) against log(Le).\n")
    slopes = []
    for el in ("constant", "linear", "quadratic"):
        t0 = time.perf_counter()
        errs = [convergence_errors(el, n) for n in CONV_ELEMENTS]
        wall = time.perf_counter() - t0
        rows = [[el, n] + [f"{e[k]:.3e}" for k in keys] for n, e in zip(CONV_ELEMENTS, errs)]
        sl = [slope(CONV_ELEMENTS, [e[k] for e in errs]) for k in keys]
        rows.append([el, "**order p**"] + [f"**{v:.2f}**" for v in sl])
        slopes.append([el] + [f"{v:.2f}" for v in sl] + [f"{wall:.1f} s"])
        print(table(["element", "elements", "Hertz", "Cattaneo", "Carter", "creepage"], rows))
        print()
    print(table(["element", "Hertz p", "Cattaneo p", "Carter p", "creepage p", "wall (4 meshes)"], slopes))
    print()


def section_splitting():
    base = rollqp.load_scene("cattaneo-carter")
    rows = []
    for el in ("linear", "quadratic"):
        for n in CONV_ELEMENTS:
            m = SceneOperators.build(base.replace(**{"discretization.elements": n, "discretization.element": el}),
                            symmetrized=False)
            Att = m.Att.dense()  # (an Operator: products only; its matrix for the eigenvalues)
            FA = m.f[:, None] * Att
            H, S = 0.5 * (FA + FA.T), 0.5 * (FA - FA.T)
            w, V = np.linalg.eigh(H)
            Hi = (V / np.sqrt(w)) @ V.T
            rho = float(np.abs(np.linalg.eigvals(Hi @ S @ Hi)).max())
            asym_A = float(np.linalg.norm(Att - Att.T) / np.linalg.norm(Att))
            hertz = []
            for op in ("exact", "symmetrized"):  # the splitting, or one QP with F⁻¹ sym(F A)
                sol = rollqp.get_method("qp-osqp", operator=op).solve(m.normal_step(m.scene.load.normal))
                e = sol.p - cf.hertz_pressure(m.strip.x, m.scene.a_H, m.scene.p0)
                hertz += [rms_in_contact(m.strip.x, m.scene.a_H, e) / m.scene.p0,
                          float(np.abs(e).max()) / m.scene.p0, sol.info.get("qp_solves", 1)]
            rows.append([el, n, f"{asym_A:.3f}", f"{m.info['asymmetry_Att']:.4f}", f"{rho:.4f}",
                         f"{hertz[0]:.2e} / {hertz[1]:.2e} ({hertz[2]} QPs)", f"{hertz[3]:.2e} / {hertz[4]:.2e}"])
    print("### Symmetric–skew splitting of the QP methods (zone ±1.25 a_H)\n")
    print("ρ = ‖H^(−1/2) S H^(−1/2)‖₂ with F·A = H + S, the error contraction per QP of "
          "`rollqp.methods._qp.QPMethod`; constant elements have S = 0 exactly. Last two columns: the "
          "normal step (Hertz) solved by the splitting (the default) and by one QP with the symmetrized "
          "operator (`operator=\"symmetrized\"`).\n")
    print(table(["element", "elements", "‖A − Aᵀ‖/‖A‖", "‖FA − (FA)ᵀ‖/‖FA‖", "ρ",
                 "Hertz rms / max error, splitting (p0)", "Hertz rms / max error, one symmetrized QP (p0)"], rows))
    print()


SECTIONS = {"paper": None, "ramp": None, "contact-transient": section_contact_transient,
            "contact-steady": section_contact_steady, "contact-grid": None,
            "convergence": section_convergence, "splitting": section_splitting}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--only", nargs="+", choices=list(SECTIONS), help="run only these sections")
    ap.add_argument("--full", action="store_true", help="include CONTACT's 880-element grid-study row")
    args = ap.parse_args(argv)
    todo = args.only or list(SECTIONS)
    needs_ref = {"contact-transient", "contact-steady", "contact-grid"} & set(todo)
    if needs_ref and not REFDATA.is_dir():
        sys.exit(f"CONTACT reference data not found at {REFDATA} (set ROLLQP_CONTACT_REFDATA)")
    import importlib.metadata as md
    print(f"<!-- generated by `python benchmarks/validation.py{' --full' if args.full else ''}`: rollqp "
          f"{rollqp.__version__}, numpy {np.__version__}, osqp {md.version('osqp')}, "
          f"clarabel {md.version('clarabel')}, cvxpy {md.version('cvxpy')}; BLAS pinned to 1 thread -->\n")
    t0 = time.perf_counter()
    if True:  # BLAS pinned by harness at import
        paper_runs = None
        for name in todo:
            if name == "paper":
                paper_runs = section_paper()
            elif name == "ramp":
                section_ramp(paper_runs)
            elif name == "contact-grid":
                section_contact_grid(args.full)
            else:
                SECTIONS[name]()
            sys.stdout.flush()
    print(f"<!-- total wall time {time.perf_counter() - t0:.0f} s -->")


if __name__ == "__main__":
    main()
