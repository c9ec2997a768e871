"""Bentall–Johnson free rolling of dissimilar cylinders, and CONTACT's ``bentall`` case.

One command prints every table of the docs/validation.md section "Bentall–Johnson free rolling
and CONTACT's bentall case"::

    python benchmarks/bentall.py                 # all sections (about 80 s on 2 cores)
    python benchmarks/bentall.py --only contact mesh

It prints Markdown. BLAS is pinned to one thread (threadpoolctl), as in benchmarks/validation.py.

Sections (``--only`` names):

* ``contact``  CONTACT's bentall case on CONTACT's grid (216 constant elements, DX = 0.001 mm),
               μ = 1e-4 and 0.05, coupling ``goodman`` and ``full``, against CONTACT's creepages;
* ``mesh``     the same case on DX = 0.004 … 0.00025 mm (54 … 864 elements);
* ``limit``    the μ → 0 limit 0.457·κ·a/R: error against elements (constant, quadratic,
               20 … 320) at μ = 1e-4, and a dense sweep of constant meshes;
* ``friction`` |ξ|/ξ_BJ against μ = 1e-4 … 0.3, both couplings;
* ``signs``    A ↔ B and d = ±1: the signs of β, ξ and t;
* ``newton``   the Newton direct steady solve at μ = 1e-4 (free rolling), mesh by mesh;
* ``start``    the coupled rolling start with the QP methods: CONTACT's grid, μ = 0.05,
               full coupling; time against ``newton``'s direct steady solve, the answer against it,
               and the ways to reach the steady state that were measured (one N–T sweep per marching
               step, Anderson acceleration, the splitting of the steady operator).

The problem (CONTACT's examples/bentall.inp, Vollebregt & Kalker): R_A = R_B = 50 mm (R = 25 mm),
aluminium body 1 = rollqp's A (G = 23000, ν = 0.31), steel body 2 = B (G = 82000, ν = 0.28),
E = 2G(1 + ν); FN = 16201.9 N on a DY = 1000 mm strip, i.e. 16.2019 N/mm and a_H = 0.1 mm;
κ = 2β = 0.2877. Free rolling (Q = 0), steady state (``load.start = "rolling"``), Δq = Le.

Solver: ``newton`` (the direct steady solve); where it raises SolverError (free rolling at very
small μ, see ``newton``) the table says so and gives ``qp-osqp``'s steady state instead, which
the QP rolling start reaches by marching the transient at constant loads (the same discrete
steady state for constant elements with Δq = Le: tests/test_steady.py).
"""
from __future__ import annotations

import argparse
import dataclasses
import sys
import time

import numpy as np
from harness import table  # (pins BLAS first)

import rollqp
from rollqp import closedforms as cf
from rollqp.errors import SolverError
from rollqp.methods.alternation import Alternation

# CONTACT's bentall case (materials, load, grid), one copy with tests/test_bentall.py
from refcases import CONTACT_DX, CONTACT_XL, FN_BENTALL as FN, bentall_contact_grid  # noqa: E402,F401
from refcases import bentall_scene  # noqa: E402

CONTACT = {1e-4: ("5.260e-4", "goodman"), 0.05: ("4.29e-4", "full")}


# =========================================================================== helpers
def scene(mu, elements=80, element="constant", coupling="goodman", direction=-1, zone=1.1, swap=False,
          method="newton"):
    """Aluminium (A) on steel (B), free rolling, steady, Δq = Le (bentall_scene in benchmarks/refcases.py)."""
    return bentall_scene(mu, elements=elements, element=element, coupling=coupling, direction=direction,
                         zone=zone, swap=swap, method=method)


def contact_grid(mu, coupling, dx=CONTACT_DX, method="newton"):
    """CONTACT's strip ±0.108 mm with elements of ``dx`` mm, d = +1 (CHI = 180°)."""
    return bentall_contact_grid(mu, coupling, dx=dx, method=method)


def steady(s):
    """Steady state by ``newton``, else by ``qp-osqp``: (ξ, arrays, method, wall, newton's error)."""
    t0 = time.perf_counter()
    failure = None
    try:
        r = rollqp.run(s, method="newton")
        method = "newton"
    except SolverError as err:
        failure = err
        t0 = time.perf_counter()
        r = rollqp.run(s, method="qp-osqp")
        method = "qp-osqp (newton fails)"
    return float(r["creepage"][0]), r, method, time.perf_counter() - t0, failure


def bj(s):
    return cf.bentall_johnson_creepage(s.kappa, s.a_H, s.R)


def stick_count(r):
    return int(np.sum(r["state"][0] == 1))


# =========================================================================== sections
def section_contact():
    s0 = contact_grid(1e-4, "goodman")
    print("#### CONTACT's bentall case on CONTACT's grid (216 constant elements, DX = 0.001 mm on ±0.108 mm, "
          "d = +1)\n")
    print(f"R = {s0.R:g} mm, E* = {s0.Estar:.6g} N/mm², β = {s0.beta:.6f}, κ = 2β = {s0.kappa:.4f}, "
          f"a_H = {s0.a_H:.7f} mm, p0 = {s0.p0:.4f} N/mm²; Bentall–Johnson ξ_BJ = 0.45739·κ·a/R = "
          f"{bj(s0):.5e}.\n")
    rows = []
    for mu in (1e-4, 0.05):
        ref, ref_coupling = CONTACT[mu]
        for coupling in ("goodman", "full"):
            s = contact_grid(mu, coupling)
            xi, r, method, wall, _ = steady(s)
            qp = ""
            if method == "newton":  # cross-check: the QP march reaches the same steady state
                rq = rollqp.run(s, method="qp-osqp")
                qp = f"{abs(float(rq['creepage'][0]) / xi - 1):.0e}"
            same = coupling == ref_coupling
            rows.append([f"{mu:g}", coupling, f"{xi:+.6e}", (ref + (" (its coupling)" if same else "")),
                         f"{xi / float(ref) - 1:+.2e}", f"{abs(xi) / bj(s):.5f}", stick_count(r), method, qp,
                         f"{wall:.2f} s"])
    print(table(["μ", "coupling", "rollqp ξ", "CONTACT |ξ|", "rollqp/CONTACT − 1", "|ξ|/ξ_BJ",
                 "stick elements", "method", "|ξ_qp-osqp/ξ − 1|", "wall"], rows))
    print()


def section_mesh():
    print("#### The same case on finer and coarser grids (zone ±0.108 mm, d = +1)\n")
    dxs = (0.004, 0.002, 0.001, 0.0005, 0.00025)
    cases = [(1e-4, "goodman"), (1e-4, "full"), (0.05, "goodman"), (0.05, "full")]
    cols = {c: [] for c in cases}
    notes = {c: [] for c in cases}
    for c in cases:
        for dx in dxs:
            s = contact_grid(*c, dx=dx)
            xi, r, method, wall, _ = steady(s)
            cols[c].append(xi)
            notes[c].append(("*" if method != "newton" else "") + f" ({wall:.1f} s)")
    s = contact_grid(1e-4, "goodman")
    rows = []
    for k, dx in enumerate(dxs):
        n = int(round(-2 * CONTACT_XL / dx))
        rows.append([f"{dx:g}", n, f"{dx / s.a_H:.4f}"] + [f"{cols[c][k]:.5e}{notes[c][k]}" for c in cases])
    print(table(["DX (mm)", "elements", "Le/a_H"] + [f"μ = {mu:g}, {cp}" for mu, cp in cases], rows))
    print("\n`*`: newton raised SolverError; qp-osqp's marched steady state. Relative changes between "
          "successive grids:\n")
    rows = []
    for k in range(1, len(dxs)):
        rows.append([f"{dxs[k - 1]:g} → {dxs[k]:g}"] + [f"{cols[c][k] / cols[c][k - 1] - 1:+.2e}" for c in cases])
    print(table(["DX"] + [f"μ = {mu:g}, {cp}" for mu, cp in cases], rows))
    # μ = 0.05: first-order convergence, Richardson from the two finest grids
    print()
    for c in cases[2:]:
        a, b = cols[c][-2], cols[c][-1]
        ext = 2 * b - a
        print(f"- μ = 0.05, {c[1]}: Richardson extrapolation (first order) from the two finest grids: "
              f"{ext:.5e}; the 216-element value is {cols[c][2] / ext - 1:+.1e} from it.")
    print()


def section_limit():
    print("#### The μ → 0 limit: |ξ|/ξ_BJ − 1 at μ = 1e-4 against the mesh (goodman, zone ±1.1 a_H, d = −1)\n")
    print("Bound: 0.24·Le/a_H (the stick point rounded to an element edge, see the text), plus the shear "
          "part of μ = 1e-4 (the last column: the same mesh at μ = 1e-6).\n")
    rows = []
    for n in (20, 40, 80, 160, 320):
        row = [n]
        for element in ("constant", "quadratic"):
            s = scene(1e-4, elements=n, element=element)
            xi, r, method, wall, _ = steady(s)
            row += [f"{abs(xi) / bj(s) - 1:+.3%}" + ("" if method == "newton" else "*"), f"{wall:.2f} s"]
        s = scene(1e-4, elements=n)
        s6 = scene(1e-6, elements=n)
        xi6 = steady(s6)[0]
        row.insert(1, f"{s.element_length / s.a_H:.4f}")
        row.insert(2, f"{0.24 * s.element_length / s.a_H:.3%}")
        row.append(f"{abs(xi6) / bj(s6) - 1:+.3%}")
        rows.append(row)
    print(table(["elements", "Le/a_H", "bound 0.24·Le/a_H", "constant", "wall", "quadratic", "wall",
                 "constant, μ = 1e-6"], rows))
    print("\n`*`: newton raised SolverError; qp-osqp's marched steady state.\n")
    # dense sweep
    for element, sizes in (("constant", range(20, 201, 2)), ("quadratic", range(20, 121, 2))):
        errs = []
        for n in sizes:
            s = scene(1e-4, elements=n, element=element, method="qp-osqp")
            r = rollqp.run(s)
            errs.append((n, abs(float(r["creepage"][0])) / bj(s) - 1, s.element_length / s.a_H))
        bad = [n for n, e, _ in errs if abs(e) > 0.01]
        worst = max(errs, key=lambda t: abs(t[1]) / t[2])
        print(f"- {element}, every even N from {sizes.start} to {sizes.stop - 1} (qp-osqp): "
              f"beyond 1 % at N = {bad if bad else 'none'}; all within 1 % from N = "
              f"{(max(bad) + 2) if bad else sizes.start}; max |ξ/ξ_BJ − 1|/(Le/a_H) = "
              f"{abs(worst[1]) / worst[2]:.3f} (N = {worst[0]}: {worst[1]:+.3%}).")
    print()


def section_friction():
    print("#### |ξ|/ξ_BJ against μ (zone ±1.1 a_H, d = −1)\n")
    mus = (1e-4, 1e-3, 1e-2, 0.05, 0.1, 0.3)
    rows = []
    for n in (160, 320):
        for coupling in ("goodman", "full"):
            row = [n, coupling]
            for mu in mus:
                s = scene(mu, elements=n, coupling=coupling)
                xi, r, method, wall, _ = steady(s)
                row.append(f"{abs(xi) / bj(s):.4f}" + ("" if method == "newton" else "*"))
            rows.append(row)
    print(table(["constant elements", "coupling"] + [f"μ = {mu:g}" for mu in mus], rows))
    print("\n`*`: newton raised SolverError; qp-osqp's marched steady state.\n")


def section_signs():
    print("#### Signs: swapping A and B, reversing the direction (μ = 0.05, 80 constant elements, newton)\n")
    rows = []
    ref = {}
    for coupling in ("goodman", "full"):
        for d in (-1, 1):
            for swap in (False, True):
                s = scene(0.05, coupling=coupling, direction=d, swap=swap)
                xi, r, method, wall, _ = steady(s)
                t = r["pt"][0]
                key = (coupling, d)
                if not swap:
                    ref[key] = (xi, t)
                    flip = "—"
                else:
                    xi0, t0 = ref[key]
                    flip = f"{np.max(np.abs(t + t0)) / (0.05 * s.p0):.1e}, {abs(xi + xi0) / abs(xi0):.1e}"
                rows.append([coupling, f"{d:+d}", "steel" if swap else "aluminium", f"{s.beta:+.5f}",
                             f"{s.kappa:+.4f}", f"{xi:+.6e}",
                             "yes" if np.sign(xi) == d * np.sign(s.kappa) else "NO",
                             f"{t[np.argmax(np.abs(t))] / (0.05 * s.p0):+.3f}", flip])
    print(table(["coupling", "d", "body A", "β", "κ", "ξ", "sgn ξ = d·sgn κ", "t at max |t| (μp0)",
                 "swapped: max |t + t_A|/μp0, |ξ + ξ_A|/|ξ_A|"], rows))
    print()


def section_newton():
    print("#### The Newton direct steady solve at μ = 1e-4 (free rolling, zone ±1.1 a_H, d = −1)\n")
    rows = []
    last = None
    for element in ("constant", "quadratic"):
        fails, ok = [], []
        for n in (20, 40, 60, 80, 100, 120, 160, 240, 320):
            try:
                rollqp.run(scene(1e-4, elements=n, element=element))
                ok.append(n)
            except SolverError as err:
                fails.append(n)
                last = err
        rows.append([element, ", ".join(map(str, fails)) or "—", ", ".join(map(str, ok)) or "—"])
    print(table(["element", "newton fails (SolverError) on N =", "converges on N ="], rows))
    if last is not None:
        print(f"\nTypical message: `{str(last)[:160]}…`\n")


# =========================================================================== the coupled rolling start
class PlainMarch(Alternation):
    """The rolling start without Anderson acceleration: one N–T sweep per marching step, then converged steps."""

    def __init__(self, *args, **kw):
        super().__init__(*args, **kw)
        self.capabilities = dataclasses.replace(self.capabilities, accelerated_start=False)


def unpredicted(name, tolerance):
    """``name``'s QP backend with the active-set prediction kept off (QPMethod.predicting): every QP of
    the accelerated start solved by the backend itself, without the prediction."""
    meth = rollqp.methods.get_method(name, tolerance=tolerance)
    meth.predicting = lambda on: False  # the accelerated start switches it on through this call
    return meth


class AndersonOnly(Alternation):
    """The accelerated start without its Newton phase: plain steps, then Anderson."""

    def __init__(self, *args, **kw):
        super().__init__(*args, **kw)
        self.capabilities = dataclasses.replace(self.capabilities, quasi_newton=False)


class FullAlternation(PlainMarch):
    """The plain march with the alternation converged at every step."""

    def __init__(self, *args, **kw):
        super().__init__(*args, **kw)  # rollqp.march then never switches to one sweep per step
        self.capabilities = dataclasses.replace(self.capabilities, single_sweeps=False)


def timed_cpu_run(s, method):
    c0, t0 = time.process_time(), time.perf_counter()
    r = rollqp.run(s, method=method)
    return r, time.process_time() - c0, time.perf_counter() - t0


def start_distance(r, ref, s):
    a, b = r.arrays(), ref.arrays()
    dp = np.max(np.abs(a["pn"][0] - b["pn"][0])) / s.p0
    dt = np.max(np.abs(a["pt"][0] - b["pt"][0])) / (s.contact.friction * s.p0)
    return max(dp, dt), abs(float(a["creepage"][0]) / float(b["creepage"][0]) - 1)


def start_map(s, name):
    """The marching map ``G`` of the QP rolling start (rollqp.methods.steady_start.sweep_map) from the braked
    state of ``s``, with ``name``'s QP backend; ``(G, braked shear, operators, QP counter)``."""
    from rollqp.march import prepare
    from rollqp.methods.steady_start import sweep_map
    braked = s.replace(**{"load.start": "braked", "discretization.distance": 0.0})
    _, meth, ops = prepare(braked, name)
    state = next(rollqp.march(braked, name)).state
    meth.inner.predicting(True)  # as in the accelerated start: the QPs near steady state on their active sets
    G0 = sweep_map(meth, ops, state, P=float(s.normal_load(0.0)), Q=0.0, xi=None, dq=s.dq, M=ops.history())
    count = [0]

    def G(t):
        count[0] += 2
        return G0(t)

    return G, state.t, ops, count


def section_start():
    s = contact_grid(0.05, "full")
    print("#### The coupled rolling start with the QP methods (CONTACT's grid, 216 constant elements, μ = 0.05, "
          "full coupling)\n")
    print("`newton` solves the steady problem directly; the QP methods reach it by marching (rollqp.march's "
          "rolling start), both from the normal half at zero shear: the march map (one N–T sweep of a step of "
          "Δq = Le as a function of the shear) solved by Newton's method with the map's Jacobian from the QPs' "
          "active sets, full steps with a Jacobian at every iterate (damped steps, then Anderson acceleration, if "
          "those cycle; rollqp.methods.steady_start), each QP of the map solved first on the active set of its warm "
          "start (QPMethod.predicting; the backend when that is not within the tolerance), then marching steps "
          "with the alternation converged, solved by the backend, until max|Δt| per step < 1e-8 μp0. `without the "
          "Newton phase`: plain steps, then Anderson; `without the active-set prediction`: every QP by the backend; "
          "`plain march`: neither Newton nor Anderson (one sweep per step, then converged steps); `full "
          "alternation`: the alternation converged at every step. "
          "Distance: max of |Δp|/p0 and |Δt|/(μp0) from `newton`'s steady state (the same discrete state: constant "
          "elements, Δq = Le). N–T sweeps: `iterations` of state 0 (two QPs each). CPU seconds, one process.\n")
    ref, cpu_ref, wall_ref = timed_cpu_run(s, "newton")
    rows = [["`newton` (direct steady solve)", f"{cpu_ref:.2f}", f"{wall_ref:.2f}", "1", "–", "0", "0"]]
    qp = lambda cls, name="qp-osqp": cls(rollqp.methods.get_method(name, tolerance=s.solver.tolerance))  # noqa: E731
    tol = s.solver.tolerance
    cases = [("`qp-osqp`", "qp-osqp"), ("`qp-osqp`, without the Newton phase", qp(AndersonOnly)),
             ("`qp-osqp`, without the active-set prediction", unpredicted("qp-osqp", tol)),
             ("`qp-osqp`, plain march", qp(PlainMarch)), ("`qp-osqp`, full alternation", qp(FullAlternation)),
             ("`qp-clarabel`", "qp-clarabel"), ("`qp-clarabel`, without the active-set prediction",
                                                unpredicted("qp-clarabel", tol))]
    for label, method in cases:
        r, cpu, wall = timed_cpu_run(s, method)
        dist, dxi = start_distance(r, ref, s)
        rows.append([label, f"{cpu:.2f}", f"{wall:.2f}", f"{cpu / cpu_ref:.0f}", int(r.arrays()["iterations"][0]),
                     f"{dist:.1e}", f"{dxi:.1e}"])
    print(table(["method", "CPU [s]", "wall [s]", "CPU / newton", "N–T sweeps (state 0)", "distance from newton",
                 "|ξ/ξ_newton − 1|"], rows))
    print()
    from rollqp.methods.steady_start import MapJacobian, fixed_point
    G, t0, ops, count = start_map(s, "qp-osqp")
    jac = MapJacobian(ops, P=float(s.normal_load(0.0)), Q=0.0, xi=None, dq=s.dq, M=ops.history(), delta=None)
    rows = []
    for newton, memory, start in ((None, 0, None), (None, 10, 0.1), (None, 60, 1.0), (None, 150, 1.0),
                                  (None, 150, 0.1), (None, 150, 0.01), (None, 300, 0.1), (np.inf, 150, 0.1),
                                  (0.3, 150, 0.1), (0.1, 150, 0.1), (0.05, 150, 0.1)):
        count[0] = 0
        _, evals, best = fixed_point(G, t0.copy(), s.contact.friction * s.p0, target=1e-10, memory=memory,
                                     anderson_from=start if start is not None else 1.0, patience=800,
                                     max_evaluations=800, jacobian=None if newton is None else jac,
                                     newton_from=newton or 0.0)
        rows.append(["–" if newton is None else ("at once" if newton == np.inf else f"{newton:g}"), memory or "0 (plain)",
                     "–" if start is None else f"{start:g}", evals, count[0], f"{best:.1e}"])
    print("The march map, `qp-osqp` (with the active-set prediction), from the braked state: residual max|G(t) − t|/"
          "(μp0) below which the Newton phase starts (– : none), Anderson's memory (differences kept) and the "
          "residual below which it extrapolates, map evaluations to 1e-10 (at most 800; the Newton phase's Jacobians "
          "not counted), and the smallest residual reached:\n")
    print(table(["Newton from", "memory", "Anderson from", "evaluations", "QPs", "smallest residual"], rows))
    Atn, Att = ops.steady()
    FA = ops.f[:, None] * Att.dense()
    lam = np.linalg.eigvalsh(0.5 * (FA + FA.T))
    print(f"\nThe steady slip operator's weighted symmetric part sym(F·d·D_up·A_tt) has eigenvalues from "
          f"{lam[0] / lam[-1]:+.2f}·λ_max to λ_max: indefinite, so no convex QP has it as Hessian and the "
          f"symmetric–skew splitting cannot be applied to the steady problem.\n")


SECTIONS = {"contact": section_contact, "mesh": section_mesh, "limit": section_limit,
            "friction": section_friction, "signs": section_signs, "newton": section_newton,
            "start": section_start}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--only", nargs="+", choices=list(SECTIONS), help="run only these sections")
    args = ap.parse_args(argv)
    import importlib.metadata as md
    print(f"<!-- generated by `python benchmarks/bentall.py`: rollqp {rollqp.__version__}, numpy "
          f"{np.__version__}, osqp {md.version('osqp')}; BLAS pinned to 1 thread -->\n")
    t0 = time.perf_counter()
    if True:  # BLAS pinned by harness at import
        for name in args.only or list(SECTIONS):
            SECTIONS[name]()
            sys.stdout.flush()
    print(f"<!-- total wall time {time.perf_counter() - t0:.0f} s -->")


if __name__ == "__main__":
    main()
