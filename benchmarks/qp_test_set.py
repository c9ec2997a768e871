#!/usr/bin/env python3
r"""rollqp's step QPs as a qpbenchmark test set, each with a certified solution (docs/qp-test-set.md).

::

    python benchmarks/qp_test_set.py [--out DIR] [--small] [--only NAMES] [--run [--settings S] [--solver S]]
    python benchmarks/qp_test_set.py --out DIR --summarize

writes the test set to ``DIR`` (default ``qp-test-set``)::

    DIR/rolling_contact.py      the qpbenchmark TestSet (needs numpy and qpbenchmark only, not rollqp)
    DIR/data/NAME.npz           each QP in qpsolvers' ``Problem.save`` format (P, q, G, h, A, b, lb, ub)
    DIR/solutions/NAME.npz      its certified solution (x, y, z), the map back to rollqp's tractions
    DIR/problems.md             the catalogue: what each QP is, its size, conditioning, degeneracy, certificates

and with ``--run`` runs qpbenchmark on it with every solver qpsolvers finds and qpbenchmark's four
settings: ``DIR/results/rolling_contact.md`` is qpbenchmark's standard report, and
``DIR/results/certified.md`` adds what that report cannot see, each answer's distance from the
certified solution. ``python DIR/rolling_contact.py run --author NAME`` is the same run by
qpbenchmark's own command line.

**The QPs** are the convex QPs rollqp poses for the normal (Signorini) and tangential (friction)
halves of a step (docs/formulation.md §6), exactly as rollqp hands them to qpsolvers
(``rollqp.methods.qp_qpsolvers``): rollqp's scaled variables ``x = p/p0`` or ``t/p0``, the Hessian
``sym(F̂Â)`` divided by its largest diagonal entry, the load row ``f̂ᵀx = P̂`` as an equality scaled
by ``max f̂``, ``G x <= h`` rows for the finite bounds (``x >= 0``; ``|x| <= μp̂``) and equality rows
``x_i = 0`` for the nodes without a friction bound (never two opposite bounds). Where ``F·A`` is not
symmetric (linear and quadratic elements) a step is solved by the symmetric–skew splitting
(docs/formulation.md §8), a sequence of QPs with the skew part in the linear term: the set holds
the *last* QP of that sequence (the skew part frozen at the step's solution: its optimum is the
collocation step's solution, NAME without suffix) and for some steps the *first* (frozen at the
warm start, the previous state: suffix ``-split1``).

**The certificates.** Each reference solution is rollqp's Newton method (tolerance 1e-12, cold
start) on the step problem whose KKT system the QP is — the shifted symmetrized step
``sym.shifted(F⁻¹S x̄)`` — checked three ways: rollqp's own residuals of that step
(docs/formulation.md §5) and, for the last QP, of the collocation step itself, both ≤ 1e-12
(:data:`CERTIFIED`); and the QP's own KKT conditions from its exported arrays (qpbenchmark's
primal and dual residuals and duality gap, and the projection residual ``x − Proj(x − ∇L)``).
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

from harness import machine_rows, pin_threads, table

pin_threads()

import numpy as np  # noqa: E402  (after the thread limit)

import rollqp  # noqa: E402
from refcases import bentall_scene  # noqa: E402  (benchmarks/refcases.py, beside this file)
from rollqp.scene import load_scene  # noqa: E402

#: rollqp's residual (nondimensional, docs/formulation.md §5) every reference solution must meet:
#: Newton terminates finitely on these piecewise-linear equations, so it reaches round-off
#: (measured ≤ 4.3e-14 on the 40–81-node steps, ≤ 6.7e-13 on 2561 nodes).
CERTIFIED = 1e-12
#: qpbenchmark's high-accuracy tolerance (primal, dual, gap): every reference solution must pass it
#: on the exported arrays (TestSet.define_tolerances).
HIGH_ACCURACY = 1e-9
#: Name of the test set: the file DIR/rolling_contact.py and its class RollingContact (qpbenchmark
#: loads ``NAME.py`` and the class ``NAME.title()`` without underscores).
SET_NAME = "rolling_contact"
#: Time limit per QP solve (qpbenchmark's ``runtime`` tolerance, and the limit of the solvers that take
#: one): the largest QPs (2561 nodes, dense) take Clarabel and OSQP tens of seconds on this machine.
RUNTIME = 100.0


# ------------------------------------------------------------------------------------ catalogue
@dataclass(frozen=True)
class Case:
    """One QP of the set: state ``k`` of ``scene()`` marched with Newton, one half, one stage.

    ``stage``: ``"step"`` — the QP whose optimum is the step's solution (the last QP of the
    splitting, or the only one where ``F·A`` is symmetric); ``"split1"`` — the splitting's first QP,
    the skew part frozen at the warm start (the previous state).
    """

    name: str
    scene: object = field(repr=False, compare=False)
    k: int
    half: str
    stage: str = "step"
    what: str = ""
    group: str = ""


def _cc(**over):
    """§6.1.1 (cattaneo-carter): similar steel rollers, μ = 0.1, 40 QCE on ±1.25 a_H, Δq = Le/2."""
    return load_scene("cattaneo-carter").replace(**over)


def _gb(**over):
    """§6.2.1 (goodman-bentall): 2β = 1, μ = 0.3, full coupling, Goodman start, 1 a_H of free rolling."""
    return load_scene("goodman-bentall").replace(**{"discretization.distance": 1.0, **over})


def _fine(elements):
    """§6.1.1 on ``elements`` QCE (2 elements + 1 nodes): braked start and two rolling steps."""
    return _cc(**{"discretization.elements": elements, "discretization.distance": 2.5 / elements})


def _xi(ratio):
    """§6.1.1 with the creepage prescribed (ratio of Carter's sliding creepage μa/R), rolling start."""
    sc = _cc()
    return _cc(**{"load.creepage": {"kind": "constant", "value": -ratio * 0.1 * sc.a_H / sc.R},
                  "load.start": "rolling", "discretization.distance": 0.0625})


def _paper_cases():
    cc, gb = "paper §6.1.1 (cattaneo-carter, 40 QCE)", "paper §6.2.1 (goodman-bentall, 2β = 1, full coupling)"
    return [
        Case("cc-qce40-s0-normal", _cc, 0, "normal", what="Hertz: the normal step of the braked start", group=cc),
        Case("cc-qce40-s0-normal-split1", _cc, 0, "normal", "split1",
             what="Hertz, the splitting's first QP from p = 0: the plain symmetrized step", group=cc),
        Case("cc-qce40-s0-tangential", _cc, 0, "tangential", what="Cattaneo: static shift to Q = 0.75 μP", group=cc),
        Case("cc-qce40-k48-tangential", _cc, 48, "tangential",
             what="rolling step 48 (q = 1.5 a_H): Cattaneo → Carter transient", group=cc),
        Case("cc-qce40-k48-tangential-split1", _cc, 48, "tangential", "split1",
             what="rolling step 48, the splitting's first QP (skew part at state 47)", group=cc),
        Case("cc-qce40-k192-tangential", _cc, 192, "tangential", what="rolling step 192: Carter's steady state",
             group=cc),
        Case("ramp-qce40-k40-tangential", lambda: load_scene("ramp"), 40, "tangential",
             what="§6.1.2: Q/(μP) ramped while rolling, step 40 (Q/(μP) = 0.35)", group="paper §6.1.2 (ramp)"),
        Case("gb-qce40-s0-normal", _gb, 0, "normal",
             what="Goodman state: normal half at the coupled solution (offset A_nt t)", group=gb),
        Case("gb-qce40-s0-tangential", _gb, 0, "tangential",
             what="Goodman state: tangential half at the coupled solution (bound μp)", group=gb),
        Case("gb-qce40-k64-normal", _gb, 64, "normal", what="free rolling step 64 (1 a_H): normal half", group=gb),
        Case("gb-qce40-k64-normal-split1", _gb, 64, "normal", "split1",
             what="free rolling step 64: normal half, the splitting's first QP", group=gb),
        Case("gb-qce40-k64-tangential", _gb, 64, "tangential", what="free rolling step 64: tangential half",
             group=gb),
        Case("harmonic-qce21-k12-normal", lambda: load_scene("harmonic"), 12, "normal",
             what="§6.2.2: harmonic load near its peak (q = 0.49 a_H), normal half", group="paper §6.2.2 (harmonic)"),
        Case("harmonic-qce21-k12-tangential", lambda: load_scene("harmonic"), 12, "tangential",
             what="§6.2.2: harmonic load near its peak, tangential half (convective-local)",
             group="paper §6.2.2 (harmonic)"),
    ]


def _hard_cases():
    el, slip, fr, cp = ("element types", "near full slip", "near-zero friction", "strong coupling")
    const = lambda: _cc(**{"discretization.element": "constant"})  # noqa: E731
    lin = lambda: _cc(**{"discretization.element": "linear"})  # noqa: E731
    qr = lambda r: (lambda: _cc(**{"load.tangential": {"kind": "constant", "value": r}}))  # noqa: E731
    tiny = lambda: bentall_scene(1e-4, elements=80).replace(**{"discretization.distance": 0.055})  # noqa: E731
    return [
        Case("cc-const40-s0-normal", const, 0, "normal", what="40 constant elements: F·A exactly symmetric", group=el),
        Case("cc-const40-k48-tangential", const, 48, "tangential", what="constant elements, rolling step 48", group=el),
        Case("cc-lin40-s0-normal", lin, 0, "normal",
             what="40 linear elements: the continuum's contact edges (p = g = 0) exactly on nodes", group=el),
        Case("cc-lin40-k96-tangential", lin, 96, "tangential",
             what="linear elements, rolling step 96: Carter's stick/slip boundary (x = 0) on a node", group=el),
        Case("cc-qr0.99-s0-tangential", qr(0.99), 0, "tangential",
             what="Q/(μP) = 0.99: Cattaneo stick zone c/a = 0.1 (one element)", group=slip),
        Case("cc-qr0.999-s0-tangential", qr(0.999), 0, "tangential",
             what="Q/(μP) = 0.999: stick zone c/a = 0.03, below one element", group=slip),
        Case("cc-qr0.999-k192-tangential", qr(0.999), 192, "tangential",
             what="Q/(μP) = 0.999, rolling step 192: Carter at 0.999", group=slip),
        Case("cc-xi0.5-k1-tangential", lambda: _xi(0.5), 1, "tangential",
             what="creepage prescribed (ξ = 0.5 μa/R): partial slip, no load row", group=slip),
        Case("cc-xi1.5-k1-tangential", lambda: _xi(1.5), 1, "tangential",
             what="creepage prescribed beyond sliding (1.5 μa/R): every contact node slips", group=slip),
        Case("bentall-mu1e-4-const80-k1-tangential", tiny, 1, "tangential",
             what="aluminium on steel, μ = 1e-4, free rolling: one stick node, bounds 1e-4", group=fr),
        Case("gb-mu1-qce40-k64-normal", lambda: _gb(**{"contact.friction": 1.0}), 64, "normal",
             what="2β = 1 with μ = 1: normal half (strong shear feedback)", group=cp),
        Case("gb-mu1-qce40-k64-tangential", lambda: _gb(**{"contact.friction": 1.0}), 64, "tangential",
             what="2β = 1 with μ = 1: tangential half", group=cp),
        Case("cc-bem-qce40-s0-normal", lambda: _cc(**{"contact.model": "bem"}), 0, "normal",
             what="true geometry (BEM, rollers on shafts): Hertz-like step", group="BEM influence"),
        Case("cc-bem-qce40-k48-tangential", lambda: _cc(**{"contact.model": "bem"}), 48, "tangential",
             what="true geometry (BEM): rolling step 48", group="BEM influence"),
    ]


def _mesh_cases():
    out = []
    for elements in (160, 320, 640, 1280):
        n = 2 * elements + 1
        out.append(Case(f"cc-qce{elements}-s0-normal", lambda e=elements: _fine(e), 0, "normal",
                        what=f"Hertz on {elements} QCE ({n} nodes)", group="fine meshes"))
        out.append(Case(f"cc-qce{elements}-k2-tangential", lambda e=elements: _fine(e), 2, "tangential",
                        what=f"rolling step 2 after Cattaneo, {elements} QCE ({n} nodes)", group="fine meshes"))
    return out


def cases(small: bool = False) -> list[Case]:
    """Every QP of the set, in catalogue order; ``small``: the few the tests generate (n ≤ 81, seconds)."""
    everything = _paper_cases() + _hard_cases() + _mesh_cases()
    if small:
        keep = ("cc-const40-s0-normal", "cc-qce40-k48-tangential", "cc-qce40-k48-tangential-split1",
                "gb-qce40-s0-normal")
        return [c for c in everything if c.name in keep]
    return everything


# ------------------------------------------------------------------------------------ the QPs
def march_states(scene, ks) -> dict:
    """``{k: StepRecord}`` of ``scene`` marched with Newton at tolerance 1e-12 (:data:`CERTIFIED`)."""
    scene = scene.replace(**{"solver.tolerance": 1e-12, "solver.method": "newton"})
    want, out = set(ks), {}
    for rec in rollqp.march(scene, "newton"):
        if rec.k in want:
            out[rec.k] = rec
        if len(out) == len(want):
            break
    missing = want - set(out)
    if missing:
        raise ValueError(f"scene {scene.name!r} has no state {sorted(missing)}")
    return out


def halves(rec) -> dict:
    """``{"normal": (problem, solution, previous traction), "tangential": …}`` of a record.

    Uncoupled steps: the normal half in effect and the tangential step. Coupled steps: the two halves
    of the N–T alternation at the coupled solution (``CoupledStep.normal_half(t)``, ``tangential_half(p)``),
    each a convex QP whose solution is the coupled one. The previous traction is the state before the
    step (the warm start rollqp's QP methods begin the splitting from; zero before the first load).
    """
    prev = rec.previous
    n = rec.problem.n
    prev_p = np.zeros(n) if prev is None or prev.p is None else np.asarray(prev.p, dtype=float)
    prev_t = np.zeros(n) if prev is None or prev.t is None else np.asarray(prev.t, dtype=float)
    if rec.problem.kind == "coupled":
        sol = rec.solution
        return {"normal": (rec.problem.normal_half(sol.t), sol, prev_p),
                "tangential": (rec.problem.tangential_half(sol.p), sol, prev_t)}
    npb, nsol = rec.normal
    return {"normal": (npb, nsol, prev_p), "tangential": (rec.problem, rec.solution, prev_t)}


def traction(problem, sol):
    """The half's unknown traction in a solution: ``p`` (normal) or ``t`` (tangential)."""
    return np.asarray(sol.p if problem.kind == "normal" else sol.t, dtype=float)


def multiplier(problem, sol) -> float:
    """The half's load multiplier in a solution: ``δ`` (normal) or ``ξ`` (tangential)."""
    return float(sol.delta if problem.kind == "normal" else sol.xi)


def qp_problem(half, x_frozen):
    """``(problem, skew)``: the step problem whose KKT system is the QP, and ``‖F⁻¹S‖/‖A‖``.

    ``F·A = sym + skew`` (docs/formulation.md §7–8): the QP is the symmetrized step (``A`` replaced
    by ``F⁻¹ sym(F A)``, its :meth:`symmetrized`) with the skew part's displacement ``F⁻¹S x̄`` at the
    frozen traction ``x̄`` added to the gap offset (normal) or the history vector (tangential), its
    :meth:`shifted`: the QP rollqp's splitting solves with ``x̄`` its previous iterate. A symmetric
    ``F·A`` (constant elements on a uniform grid) gives the step itself.
    """
    A = np.asarray(half.A, dtype=float)
    sym = half.symmetrized()
    skew = A - np.asarray(sym.A, dtype=float)  # F⁻¹ skew(F A)
    size = float(np.abs(skew).max() / np.abs(A).max())
    if size == 0.0:
        return half, 0.0
    return sym.shifted(skew @ x_frozen), size


def newton_reference(problem, fallback):
    """Newton's solution of ``problem`` at tolerance 1e-12: cold, or warm from ``fallback`` if the cold
    start does not converge (the creepage search of a near-degenerate tangential step can need it)."""
    newton = rollqp.get_method("newton", tolerance=1e-12)
    try:
        return newton.solve(problem), "cold"
    except rollqp.SolverError:
        return newton.solve(problem, warm=fallback), "warm"


def qpsolvers_arrays(form) -> dict:
    """The QP as rollqp's qpsolvers backends pose it (``rollqp.methods.qp_qpsolvers``), dense.

    ``P = H``, ``q``; ``G x <= h``: ``x_i <= u_i`` for the finite upper bounds (indices ``up``), then
    ``−x_i <= −ℓ_i`` for the finite lower ones (``lo``); ``A x = b``: the load row ``a`` (if the load is
    prescribed), then ``x_i = ℓ_i`` for the nodes with ``ℓ_i = u_i`` (``fixed``: no friction bound).
    """
    n = form.H.shape[0]
    fixed = form.lower == form.upper
    up = np.flatnonzero(np.isfinite(form.upper) & ~fixed)
    lo = np.flatnonzero(np.isfinite(form.lower) & ~fixed)
    fx = np.flatnonzero(fixed)
    eye = np.eye(n)
    G = np.vstack([eye[up], -eye[lo]])
    h = np.concatenate([form.upper[up], -form.lower[lo]])
    rows, b = [], []
    if form.a is not None:
        rows.append(form.a[None, :])
        b.append(float(form.b))
    if fx.size:
        rows.append(eye[fx])
        b.extend(form.lower[fx])
    return dict(P=np.array(form.H, dtype=float), q=np.array(form.q, dtype=float),
                G=G if G.shape[0] else None, h=h if h.size else None,
                A=np.vstack(rows) if rows else None, b=np.asarray(b, dtype=float) if rows else None,
                up=up, lo=lo, fixed=fx, load_row=form.a is not None)


def bounds(arrays) -> tuple:
    """``(L, U, fixed mask)``: the lower and upper bound of every variable (±inf where none)."""
    n = arrays["q"].size
    L, U = np.full(n, -np.inf), np.full(n, np.inf)
    m = arrays["up"].size
    if arrays["G"] is not None:
        U[arrays["up"]] = arrays["h"][:m]
        L[arrays["lo"]] = -arrays["h"][m:]
    fixed = np.zeros(n, dtype=bool)
    fixed[arrays["fixed"]] = True
    return L, U, fixed


def gradient(arrays, x, y_load) -> np.ndarray:
    """``P x + q + a y_load``: the Lagrangian's gradient without the bound and fixed-node terms."""
    r = arrays["P"] @ x + arrays["q"]
    if arrays["load_row"]:
        r = r + y_load * arrays["A"][0]
    return r


def duals(arrays, x, y_load) -> tuple:
    """``(y, z)`` of qpsolvers' Lagrangian ``½xᵀPx + qᵀx + yᵀ(Ax − b) + zᵀ(Gx − h)`` at ``x``.

    ``y``: the load multiplier, then ``−∇_i`` for each fixed node (their rows are ``e_iᵀ``); ``z``:
    ``max(−∇_i, 0)`` on the upper-bound rows and ``max(∇_i, 0)`` on the lower-bound rows, ``∇ = P x + q + a y``.
    At an exact optimum this is the dual solution; what is left of stationarity shows in the dual
    residual, and a multiplier on a slack constraint in the duality gap.
    """
    r = gradient(arrays, x, y_load)
    y = ([y_load] if arrays["load_row"] else []) + list(-r[arrays["fixed"]])
    z = np.concatenate([np.maximum(-r[arrays["up"]], 0.0), np.maximum(r[arrays["lo"]], 0.0)])
    return (np.asarray(y, dtype=float) if y else None), (z if arrays["G"] is not None else None)


def projection_residual(arrays, x, y_load) -> float:
    """``max |x − Proj_[L, U](x − ∇)|`` over the free and bounded variables, ``|x_i − ℓ_i|`` over the fixed
    ones and ``|aᵀx − b|``: zero exactly at the QP's KKT point (rollqp's NCP form, docs/formulation.md §4)."""
    L, U, fixed = bounds(arrays)
    r = gradient(arrays, x, y_load)
    proj = np.abs(x - np.clip(x - r, L, U))[~fixed]
    out = float(proj.max(initial=0.0))
    if fixed.any():
        out = max(out, float(np.abs(x[fixed] - arrays["b"][int(arrays["load_row"]):]).max()))
    if arrays["load_row"]:
        out = max(out, abs(float(arrays["A"][0] @ x - arrays["b"][0])))
    return out


#: A bound constraint is *weakly active* when both its slack and its multiplier are at most this
#: (on the QP's order-one scale): a solver stopping at a tolerance above it cannot tell on which side
#: of the complementarity the variable lies (the contact and stick/slip edges).
WEAK = 1e-6


def active_set(arrays, x, y_load) -> dict:
    """The optimum's active set read as rollqp reads it (``x_i − ℓ_i < ∇_i``: at the lower bound, …),
    with the strict-complementarity margin ``min_i max(slack_i, |∇_i|)`` over the bounded variables and the
    narrowest box ``min (u_i − ℓ_i)`` (a friction bound ``±μp̂_i`` closing at the edge of the contact)."""
    L, U, fixed = bounds(arrays)
    r = gradient(arrays, x, y_load)
    at_lo = np.isfinite(L) & (x - L < r) & ~fixed
    at_up = np.isfinite(U) & (U - x < -r) & ~fixed
    bounded = (np.isfinite(L) | np.isfinite(U)) & ~fixed
    slack = np.minimum(x - L, U - x)
    both = np.maximum(slack, np.abs(r))[bounded]
    width = (U - L)[bounded & np.isfinite(U - L)]
    return dict(at_lo=at_lo, at_up=at_up, free=~(at_lo | at_up | fixed), fixed=fixed,
                margin=float(both.min(initial=np.inf)), weak=int(np.sum(both <= WEAK)),
                narrowest=float(width.min(initial=np.inf)))


def condition(arrays, act) -> dict:
    """``κ(P)``, ``κ(P_FF)`` (the Hessian on the free variables: what an active-set method factors) and
    qpsolvers' ``Problem.cond`` of the KKT matrix on the optimum's active set (2-norm condition numbers)."""
    import qpsolvers
    P = arrays["P"]
    ev = np.linalg.eigvalsh(P)
    F = np.flatnonzero(act["free"])
    evf = np.linalg.eigvalsh(P[np.ix_(F, F)]) if F.size else np.array([1.0])
    up_rows = np.flatnonzero(act["at_up"][arrays["up"]])
    lo_rows = arrays["up"].size + np.flatnonzero(act["at_lo"][arrays["lo"]])
    prob = qpsolvers.Problem(P, arrays["q"], arrays["G"], arrays["h"], arrays["A"], arrays["b"])
    kkt = prob.cond(qpsolvers.ActiveSet(G_indices=np.concatenate([up_rows, lo_rows]).tolist()))
    return dict(kappa=float(ev[-1] / ev[0]), kappa_free=float(evf[-1] / evf[0]), kappa_kkt=float(kkt),
                lambda_min=float(ev[0]))


def kkt_metrics(arrays, x, y_load) -> dict:
    """qpbenchmark's three metrics of the solution ``(x, y, z)`` (qpsolvers' ``Solution``: primal residual,
    dual residual, duality gap) on the exported arrays, and the projection residual."""
    import qpsolvers
    y, z = duals(arrays, x, y_load)
    prob = qpsolvers.Problem(arrays["P"], arrays["q"], arrays["G"], arrays["h"], arrays["A"], arrays["b"])
    sol = qpsolvers.Solution(prob, found=True, x=x, y=y, z=z)
    return dict(primal=float(sol.primal_residual()), dual=float(sol.dual_residual()), gap=float(sol.duality_gap()),
                projection=projection_residual(arrays, x, y_load))


# ------------------------------------------------------------------------------------ one case
@dataclass
class Exported:
    """One QP of the set: its arrays (:func:`qpsolvers_arrays`), the certified ``x`` and load multiplier
    ``y_load``, and what is known about it (``meta``: certificates, map back to rollqp, measurements)."""

    case: Case
    arrays: dict = field(repr=False)
    x: np.ndarray = field(repr=False)
    y_load: float
    meta: dict = field(default_factory=dict)

    def duals(self) -> tuple:
        return duals(self.arrays, self.x, self.y_load)

    def problem(self):
        """The QP as a ``qpbenchmark.Problem`` named after the case."""
        import qpbenchmark
        a = self.arrays
        return qpbenchmark.Problem(a["P"], a["q"], a["G"], a["h"], a["A"], a["b"], None, None, name=self.case.name)


def export(case: Case, rec, measure: bool = True) -> Exported:
    """The QP of ``case`` at the record ``rec`` (state ``case.k``), with its certified solution.

    The reference is Newton's solution of the QP's own step problem (:func:`qp_problem`), checked by
    rollqp's residuals (≤ :data:`CERTIFIED`) on that problem and — for the last QP of a step — on the
    collocation step itself, and by the QP's KKT conditions on the exported arrays (``meta``).
    """
    half, sol, prev = halves(rec)[case.half]
    x_step = traction(half, sol)
    target, skew = qp_problem(half, x_step if case.stage == "step" else prev)
    t0 = time.perf_counter()
    ref, start = newton_reference(target, sol)
    newton_time = time.perf_counter() - t0
    form, sc = target.qp_form(), half.scales
    unit = sc.displacement if half.kind == "normal" else sc.slip  # δ in u0, ξ in p0/E* (docs/formulation.md §5)
    y_scale = (-1.0 if half.kind == "normal" else 1.0) * form.obj_scale / form.eq_scale * unit
    x = traction(target, ref) / sc.stress
    y_load = multiplier(target, ref) / y_scale if form.a is not None else 0.0
    arrays = qpsolvers_arrays(form)
    meta = dict(name=case.name, what=case.what, group=case.group, half=half.kind, stage=case.stage, k=rec.k,
                phase=rec.phase, n=int(x.size), m_eq=0 if arrays["A"] is None else int(arrays["A"].shape[0]),
                m_in=0 if arrays["G"] is None else int(arrays["G"].shape[0]), skew=skew, newton_start=start,
                newton_iterations=int(ref.iterations), newton_time=newton_time,
                residual_qp_step=float(ref.residual),
                residual_collocation=float(half.evaluate(ref).residual) if case.stage == "step" else float("nan"),
                agreement=float(np.abs(x - x_step / sc.stress).max()) if case.stage == "step" else float("nan"),
                x_scale=float(sc.stress), y_scale=float(y_scale), multiplier_unit=float(unit),
                dual_scale=np.asarray(form.dual_scale, dtype=float))
    meta.update(kkt_metrics(arrays, x, y_load))
    if measure:
        act = active_set(arrays, x, y_load)
        meta.update(condition(arrays, act), margin=act["margin"], weak=act["weak"], narrowest=act["narrowest"],
                    at_lower=int(act["at_lo"].sum()),
                    at_upper=int(act["at_up"].sum()), free=int(act["free"].sum()), fixed=int(act["fixed"].sum()))
    return Exported(case, arrays, x, y_load, meta)


def certified(e: Exported) -> list[str]:
    """What fails the certificate (empty: certified): rollqp's residuals ≤ :data:`CERTIFIED` and the QP's
    KKT metrics below qpbenchmark's high-accuracy tolerance :data:`HIGH_ACCURACY`."""
    m, bad = e.meta, []
    for key in ("residual_qp_step", "residual_collocation"):
        if np.isfinite(m[key]) and not m[key] <= CERTIFIED:
            bad.append(f"{key} = {m[key]:.2e} > {CERTIFIED:g}")
    for key in ("primal", "dual", "gap", "projection"):
        if not m[key] < HIGH_ACCURACY:
            bad.append(f"KKT {key} = {m[key]:.2e} >= {HIGH_ACCURACY:g}")
    return bad


def generate(selected: list[Case], measure: bool = True, log=None) -> list[Exported]:
    """Every case's :class:`Exported`, each scene marched once (the cases that share it grouped)."""
    groups = {}
    for case in selected:
        scene = case.scene()
        key = json.dumps(scene.to_dict(), sort_keys=True, default=str)
        groups.setdefault(key, (scene, []))[1].append(case)
    out = {}
    for scene, group in groups.values():
        t0 = time.perf_counter()
        states = march_states(scene, {c.k for c in group})
        for case in group:
            out[case.name] = export(case, states[case.k], measure=measure)
        if log:
            log(f"{scene.name}: {', '.join(c.name for c in group)} ({time.perf_counter() - t0:.1f} s)")
    return [out[c.name] for c in selected]


# ------------------------------------------------------------------------------------ files
TEST_SET_SOURCE = '''#!/usr/bin/env python3
"""Rolling contact test set: the step QPs of rollqp (2D transient rolling contact of elastic cylinders).

Generated by rollqp's ``benchmarks/qp_test_set.py`` (documented in rollqp's docs/qp-test-set.md);
needs numpy and qpbenchmark only. ``data/NAME.npz``: each QP in qpsolvers' ``Problem.save``
format; ``solutions/NAME.npz``: its certified solution ``(x, y, z)`` (:meth:`RollingContact.reference`).

    python rolling_contact.py run --author NAME      # results/rolling_contact.md: qpbenchmark's report
"""

import os
from typing import Iterator

import numpy as np
import qpbenchmark
import qpsolvers
from qpbenchmark import Problem
from qpbenchmark.benchmark import main

#: Time limit per solve [s] (qpbenchmark's ``runtime`` tolerance; the largest QPs have 2561 dense variables).
RUNTIME = {runtime!r}

DESCRIPTION = {description!r}


class RollingContact(qpbenchmark.TestSet):
    """rollqp's normal (Signorini) and tangential (friction) step QPs, each with a certified solution."""

    @property
    def description(self) -> str:
        return DESCRIPTION

    @property
    def title(self) -> str:
        return "Rolling contact test set (rollqp step QPs)"

    @property
    def sparse_only(self) -> bool:
        return False

    def __init__(self):
        here = os.path.dirname(os.path.abspath(__file__))
        self.data_dir = os.path.join(here, "data")
        self.solution_dir = os.path.join(here, "solutions")
        super().__init__()

    def define_tolerances(self, runtime: float = RUNTIME) -> None:
        super().define_tolerances(runtime=runtime)

    def __iter__(self) -> Iterator[Problem]:
        for fname in sorted(os.listdir(self.data_dir)):
            if fname.endswith(".npz"):
                yield Problem.load(os.path.join(self.data_dir, fname))

    def reference(self, problem: Problem) -> qpsolvers.Solution:
        """The certified solution of ``problem`` (``x``, ``y``, ``z`` of qpsolvers' Lagrangian)."""
        with np.load(os.path.join(self.solution_dir, problem.name + ".npz"), allow_pickle=False) as z:
            y = z["y"] if z["y"].size else None
            dual = z["z"] if z["z"].size else None
            return qpsolvers.Solution(problem, found=True, x=z["x"].copy(), y=y, z=dual)


if __name__ == "__main__":
    path = os.path.abspath(__file__)
    main(test_set_path=path, results_path=os.path.join(os.path.dirname(path), "results", "qpbenchmark_results.csv"))
'''

DESCRIPTION = (
    "Convex QPs of rollqp's time steps for 2D transient rolling contact of elastic cylinders "
    "(González & Abascal 2002): the normal (Signorini: x = p/p0 >= 0, load row f'x = P) and tangential "
    "(Coulomb friction: |x| <= mu p/p0, load row f'x = Q) halves of steps of the paper's examples and of "
    "rollqp's hard cases, n = 40 to 2561. Dense Hessians from boundary influence matrices (a discretized "
    "log kernel: condition number growing like n), box-type bounds whose active set changes at the contact "
    "and stick/slip edges. Each problem's certified solution (solutions/NAME.npz) is rollqp's Newton "
    "solution of the same discrete step, with rollqp's residuals below 1e-12.")


def save_problem(path: Path, arrays: dict) -> None:
    """One QP in qpsolvers' ``Problem.save`` keys (``None`` as a 0-d object array, which ``Problem.load``
    reads back as None), compressed: the ``G`` rows are ±unit vectors."""
    none = np.array(None, dtype=object)
    data = {k: (none if arrays.get(k) is None else np.asarray(arrays[k], dtype=float))
            for k in ("P", "q", "G", "h", "A", "b", "lb", "ub")}
    np.savez_compressed(path, **data)


def save_solution(path: Path, e: Exported, scene_json: str) -> None:
    """The certified solution and the map back to rollqp (docs/qp-test-set.md, "Files")."""
    y, z = e.duals()
    m = e.meta
    scalars = {k: m[k] for k in ("k", "n", "m_eq", "m_in", "skew", "residual_qp_step", "residual_collocation",
                                 "agreement", "primal", "dual", "gap", "projection", "x_scale", "y_scale",
                                 "multiplier_unit") if k in m}
    texts = {k: m[k] for k in ("name", "what", "group", "half", "stage", "phase", "newton_start")}
    np.savez_compressed(path, x=e.x, y=np.zeros(0) if y is None else y, z=np.zeros(0) if z is None else z,
                        up=e.arrays["up"], lo=e.arrays["lo"], fixed=e.arrays["fixed"],
                        load_row=np.asarray(e.arrays["load_row"]), dual_scale=m["dual_scale"],
                        scene=np.asarray(scene_json), **{k: np.asarray(v) for k, v in {**scalars, **texts}.items()})


def write_set(out: Path, exported: list[Exported], scenes: dict) -> list[str]:
    """Write the test set to ``out`` (module docstring); returns the catalogue's lines."""
    for sub in ("data", "solutions", "results"):
        (out / sub).mkdir(parents=True, exist_ok=True)
    for e in exported:
        save_problem(out / "data" / f"{e.case.name}.npz", e.arrays)
        save_solution(out / "solutions" / f"{e.case.name}.npz", e, scenes[e.case.name])
    (out / f"{SET_NAME}.py").write_text(TEST_SET_SOURCE.format(runtime=RUNTIME, description=DESCRIPTION),
                                        encoding="utf-8")
    lines = catalogue(exported)
    (out / "problems.md").write_text("\n".join(lines) + "\n", encoding="utf-8")
    return lines


def _g(v) -> str:
    return "–" if v is None or not np.isfinite(v) else f"{v:.1e}"


def catalogue(exported: list[Exported]) -> list[str]:
    """The markdown catalogue: one row per QP with its size, conditioning, active set and certificates."""
    rows = []
    for e in exported:
        m = e.meta
        rows.append((f"`{m['name']}`", m["n"], m["m_eq"], m["m_in"], _g(m.get("kappa")), _g(m.get("kappa_free")),
                     _g(m.get("kappa_kkt")), f"{m.get('at_lower', '–')}/{m.get('at_upper', '–')}/{m.get('fixed', '–')}",
                     _g(m.get("margin")), _g(m.get("narrowest")),
                     _g(max(m["residual_qp_step"], np.nan_to_num(m["residual_collocation"]))),
                     _g(max(m["primal"], m["dual"], m["gap"], m["projection"])), m["what"]))
    head = ["problem", "n", "eq rows", "ineq rows", "κ(P)", "κ(P_FF)", "κ(KKT)", "at lower/upper/fixed",
            "margin", "narrowest box", "rollqp residual", "KKT residual", "what"]
    return [table(head, rows)]


# ------------------------------------------------------------------------------------ running qpbenchmark
def load_test_set(out: Path):
    """The generated ``RollingContact`` test set of ``out`` (imported from its file, as qpbenchmark does)."""
    import importlib.util
    spec = importlib.util.spec_from_file_location(f"{SET_NAME}_{abs(hash(str(out)))}", out / f"{SET_NAME}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.RollingContact()


#: An answer is "within reach" of the certified solution when max|x − x*| is at most this (x = p/p0, t/p0):
#: check-step's default tolerance (rollqp.stepfile.DEFAULT_TOL), three decades below the
#: discretization error of the paper's meshes (≈1e-3 p0, docs/validation.md).
CLOSE = 1e-6


def run_benchmark(out: Path, settings=None, solver=None, log=print, author="rollqp"):
    """Run qpbenchmark on the set in ``out`` (every solver and settings, or the ones named) and write its
    report (``results/rolling_contact.md``), keeping each answer's distance from the certified solution."""
    import qpbenchmark

    test_set = load_test_set(out)
    if settings:  # qpbenchmark's report covers every settings of its test set: keep only the one run
        if settings not in test_set.solver_settings:
            raise SystemExit(f"--settings must be one of {', '.join(test_set.solver_settings)}, got {settings!r}")
        test_set.solver_settings = {settings: test_set.solver_settings[settings]}
        test_set.tolerances = {settings: test_set.tolerances[settings]}
    if solver:
        if solver not in test_set.solvers:
            raise SystemExit(f"--solver must be one of {', '.join(sorted(test_set.solvers))}, got {solver!r}")
        test_set.solvers = {solver}
    refs = {p.name: test_set.reference(p).x for p in test_set}
    distances = {}

    class CertifiedResults(qpbenchmark.Results):
        """qpbenchmark's results, plus ``max|x − x*|`` of every answer (its report shows KKT residuals only)."""

        def update(self, problem, solver, settings, solution, runtime):
            super().update(problem, solver, settings, solution, runtime)
            x = solution.x if solution.found else None
            ok = x is not None and np.shape(x) == refs[problem.name].shape and np.all(np.isfinite(x))
            distances[(problem.name, solver, settings)] = float(np.abs(x - refs[problem.name]).max()) if ok else np.inf

    csv = out / "results" / "qpbenchmark_results.csv"
    csv.parent.mkdir(parents=True, exist_ok=True)
    if csv.exists():
        csv.unlink()  # a clean measurement: every (problem, solver, settings) solved in this run
    results = CertifiedResults(str(csv), test_set)
    t0 = time.perf_counter()
    qpbenchmark.run(test_set, results, only_settings=settings, only_solver=solver)
    log(f"qpbenchmark ran the set in {time.perf_counter() - t0:.0f} s")
    qpbenchmark.Report(author, results).write(str(out / "results" / f"{SET_NAME}.md"))
    with open(out / "results" / "certified.csv", "w", encoding="utf-8") as fh:
        fh.write("problem,solver,settings,distance\n")
        fh.writelines(f"{p},{s},{st},{d!r}\n" for (p, s, st), d in sorted(distances.items()))
    return test_set, results.df, distances


def passed(df, test_set) -> dict:
    """``{(problem, solver, settings): bool}``: qpbenchmark's success criterion (found, and primal and dual
    residuals and duality gap below the settings' tolerances)."""
    out = {}
    for row in df.itertuples():
        tol = test_set.tolerances[row.settings]
        out[(row.problem, row.solver, row.settings)] = bool(
            row.found and row.primal_residual < tol.primal and row.dual_residual < tol.dual
            and row.duality_gap < tol.gap)
    return out


#: The order of qpbenchmark's settings in the tables here: the one that decides first.
SETTINGS_ORDER = ("high_accuracy", "mid_accuracy", "low_accuracy", "default")


def certified_report(test_set, df, distances, settings_order=SETTINGS_ORDER) -> list[str]:
    """What qpbenchmark's report cannot show: each answer against the certified solution (markdown lines)."""
    ok = passed(df, test_set)
    sizes = {p.name: p.q.size for p in test_set}
    problems = sorted({p for p, _, _ in distances}, key=lambda p: (sizes[p], p))
    solvers = sorted({s for _, s, _ in distances})
    settings = [s for s in settings_order if any(k[2] == s for k in distances)]
    lines = [f"Problems: {len(problems)}; solvers: {', '.join(solvers)}.", "",
             "Each cell: problems whose answer passes qpbenchmark's check (found; primal, dual residuals and "
             f"duality gap below the settings' tolerance) · problems whose answer is within {CLOSE:g} of the "
             "certified solution (max|x − x*|, x = p/p0 or t/p0), out of "
             f"{len(problems)}.", ""]
    rows = []
    for s in solvers:
        rows.append([s] + [f"{sum(ok.get((p, s, st), False) for p in problems)} · "
                           f"{sum(distances.get((p, s, st), np.inf) <= CLOSE for p in problems)}" for st in settings])
    lines += [table(["solver"] + settings, rows), ""]
    for st in settings:
        lines += [f"Settings *{st}*, max|x − x*| of each answer (✗: fails qpbenchmark's check; — : no answer); "
                  "last column: solvers that pass the check and are within "
                  f"{CLOSE:g}:", ""]
        rows = []
        for p in problems:
            cells = []
            for s in solvers:
                d = distances.get((p, s, st))
                if d is None:
                    cells.append("")
                    continue
                cells.append("—" if not np.isfinite(d) else ("" if ok[(p, s, st)] else "✗ ") + f"{d:.0e}")
            good = sum(ok.get((p, s, st), False) and distances.get((p, s, st), np.inf) <= CLOSE for s in solvers)
            rows.append([f"`{p}`", sizes[p]] + cells + [good])
        lines += [table(["problem", "n"] + solvers + ["good"], rows), ""]
    lines += runtime_table(df, sizes, solvers)
    return lines


def runtime_table(df, sizes, solvers) -> list[str]:
    """Median runtime [s] per solver at high accuracy, by problem size."""
    classes = [(0, 100), (100, 1000), (1000, 2000), (2000, 10 ** 9)]
    sub = df[df.settings == "high_accuracy"]
    if sub.empty:
        return []
    classes = [(lo, hi) for lo, hi in classes if any(lo <= n < hi for n in sizes.values())]
    rows = []
    for s in solvers:
        cells = []
        for lo, hi in classes:
            r = sub[(sub.solver == s) & sub.problem.map(lambda p: lo <= sizes[p] < hi)].runtime
            cells.append("–" if r.empty else f"{float(np.median(r)):.3g}")
        rows.append([s] + cells)
    names = {}
    for lo, hi in classes:
        ns = sorted({n for n in sizes.values() if lo <= n < hi})
        names[(lo, hi)] = f"n = {ns[0]}–{ns[-1]}" if len(ns) > 1 else f"n = {ns[0]}"
    return ["Median wall time of one solve [s], settings *high_accuracy*, by size (qpbenchmark's `runtime`: "
            "the qpsolvers call; for the solvers that take sparse matrices only, the dense ones are converted "
            "before the clock starts):", "",
            table(["solver"] + [names[c] for c in classes], rows), ""]


def summarize(out: Path, header=()) -> list[str]:
    """The tables of the last run in ``out``: qpbenchmark's results by settings and solver versions (from its
    report), and each answer against the certified solution (also written to ``results/certified.md``)."""
    import qpbenchmark
    test_set = load_test_set(out)
    df = qpbenchmark.Results(str(out / "results" / "qpbenchmark_results.csv"), test_set).df
    distances = {}
    with open(out / "results" / "certified.csv", encoding="utf-8") as fh:
        for line in fh.readlines()[1:]:
            p, s, st, d = line.strip().split(",")
            distances[(p, s, st)] = float(d)
    rep = certified_report(test_set, df, distances)
    (out / "results" / "certified.md").write_text("\n".join(list(header) + rep) + "\n", encoding="utf-8")
    load = " / ".join(f"{v:.2f}" for v in os.getloadavg())
    return (["## qpbenchmark's report: results by settings", ""] + report_summary(out / "results" / f"{SET_NAME}.md")
            + ["", "## Against the certified solutions", ""] + rep
            + [f"Load average when these tables were written: {load} (1, 5, 15 min)."])


def report_summary(path: Path) -> list[str]:
    """The "Results by settings" tables of qpbenchmark's report at ``path``, its links made plain text."""
    import re
    text = path.read_text(encoding="utf-8")
    versions = text.split("## Solvers\n", 1)[1].split("\n## ", 1)[0].strip()
    part = text.split("## Results by settings\n", 1)[1].split("\n## ", 1)[0]
    part = re.sub(r"\[([^\]]+)\]\(#[^)]*\)", r"\1", part)
    part = re.sub(r"\[shifted geometric mean\]\(([^)]*)\)", r"shifted geometric mean (\1)", part)
    return ["Solver versions (qpbenchmark's table):", ""] + versions.splitlines() + [""] + \
        part.strip().replace("### ", "#### ").splitlines()


def conditioning(exported: list[Exported]) -> list[str]:
    """``κ`` against ``n`` over the §6.1.1 normal steps on refined meshes, with the fitted power of ``n``."""
    import re
    rows = sorted((e.meta["n"], e.meta["name"], e.meta["kappa"], e.meta["kappa_free"], e.meta["kappa_kkt"],
                   e.meta["lambda_min"]) for e in exported
                  if re.fullmatch(r"cc-qce\d+-s0-normal", e.case.name) and "kappa" in e.meta)
    if len(rows) < 2:
        return []
    n, kappa = np.array([r[0] for r in rows], float), np.array([r[2] for r in rows])
    slope = float(np.polyfit(np.log(n), np.log(kappa), 1)[0])
    lines = [table(["n", "problem", "κ(P)", "κ(P_FF)", "κ(KKT)", "λ_min(P)", "λ_max(P)", "κ(P)/n"],
                   [(r[0], f"`{r[1]}`", _g(r[2]), _g(r[3]), _g(r[4]), _g(r[5]), _g(r[2] * r[5]), f"{r[2] / r[0]:.1f}")
                    for r in rows])]
    return lines + ["", f"Least-squares fit: κ(P) ∝ n^{slope:.2f} (P scaled to a unit largest diagonal entry)."]


# ------------------------------------------------------------------------------------ command line
def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default="qp-test-set", help="folder to write the test set to (default qp-test-set)")
    ap.add_argument("--small", action="store_true", help="only the few small QPs the tests generate")
    ap.add_argument("--only", default=None, help="comma-separated substrings of the problem names to keep")
    ap.add_argument("--run", action="store_true", help="run qpbenchmark on the set and write its report")
    ap.add_argument("--settings", default=None, help="with --run: only these qpbenchmark settings")
    ap.add_argument("--solver", default=None, help="with --run: only this solver")
    ap.add_argument("--author", default="rollqp", help="with --run: the author field of qpbenchmark's report")
    ap.add_argument("--summarize", action="store_true",
                    help="only print the tables of the last --run in --out again (nothing generated or solved)")
    args = ap.parse_args(argv)
    out = Path(args.out)
    if args.summarize:
        print("\n".join(summarize(out)))
        return 0
    selected = cases(small=args.small)
    if args.only:
        keys = [k.strip() for k in args.only.split(",") if k.strip()]
        selected = [c for c in selected if any(k in c.name for k in keys)]
        if not selected:
            ap.error(f"--only {args.only!r} matches no problem name")
    log = lambda msg: print(msg, file=sys.stderr, flush=True)  # noqa: E731
    t0 = time.perf_counter()
    exported = generate(selected, log=log)
    bad = {e.case.name: certified(e) for e in exported if certified(e)}
    if bad:
        print(f"not certified: {bad}", file=sys.stderr)
        return 1
    scenes = {c.name: json.dumps(c.scene().to_dict(), sort_keys=True, default=str) for c in selected}
    lines = write_set(out, exported, scenes)
    log(f"wrote {len(exported)} QPs to {out}/ in {time.perf_counter() - t0:.0f} s (all certified)")
    header = ["## Machine", "", table(["", ""], machine_rows()), ""]
    print("\n".join(header + ["## The problems", ""] + lines + ["", "## Conditioning against n", ""]
                    + conditioning(exported)))
    if args.run:
        run_benchmark(out, settings=args.settings, solver=args.solver, log=log, author=args.author)
        print("\n".join([""] + summarize(out, header)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
