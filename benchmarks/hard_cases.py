"""Hard cases for every method: the table of docs/stability.md.

Usage::

    python benchmarks/hard_cases.py                 # every case × method; prints the markdown table (~10 min)
    python benchmarks/hard_cases.py --fast          # only the cases the default test suite runs
    python benchmarks/hard_cases.py --only gross    # cases whose name contains "gross"
    python benchmarks/hard_cases.py --exclude mesh  # all but the fine meshes
    python benchmarks/hard_cases.py --convective-sweep   # the Δq sweep behind the convective-local bound
    python benchmarks/hard_cases.py --workers 2     # the same runs on a local dask cluster (extra 'sweep')

With ``--workers N`` the (case, method) runs go through rollqp's sweep executor
(:func:`harness.map_cases`): N single-threaded worker processes, one run per worker at a time, so
each timed run has a core to itself; the rows are printed in the same order, with the same
numbers (only the wall times differ), and the whole table takes less wall time.

Each case is a scene (:func:`cases`) run by ``rollqp.run`` with each method that applies to it
(``nt-newton`` only on coupled scenes). A case either **converges** — then every state's
tractions are compared with the case's reference — or **stops with a rollqp error**
(``InputError`` naming the key, ``SolverError`` naming the step and residual), never NaN.

References (column "reference"):

* ``newton 1e-12``: ``newton`` at ``solver.tolerance = 1e-12`` on the same discretization
  (no closed form applies, or the closed form would hide the solver error under the
  discretization error). "error" is then max over states of ``|Δp|/p0`` and ``|Δt|/(μ p0)``.
* a closed form (Carter's creepage, Cattaneo's traction, Hertz): "error" is then the
  discretization error plus the solver's, reported in a separate column ``closed form``; the
  ``newton 1e-12`` comparison is reported as well.

BLAS is pinned to one thread. The test suite (tests/test_hard_cases.py) imports
:func:`cases` and :func:`run_case` from here, so the table and the tests run the same scenes.
"""
from __future__ import annotations

import harness  # noqa: F401  (pins BLAS first)

import argparse  # noqa: E402
import math  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from dataclasses import dataclass, field  # noqa: E402
from typing import Callable  # noqa: E402

import numpy as np  # noqa: E402

import rollqp  # noqa: E402
from rollqp import closedforms as cf  # noqa: E402
from rollqp.errors import InputError, RollqpError, SolverError  # noqa: E402
from rollqp.scene import AUGMENTATION_MAX, AUGMENTATION_MIN, load_scene  # noqa: E402

QP = ("qp-clarabel", "qp-osqp", "qp-cvxpy")
#: methods of a "fast" case in the default test suite (the cheapest QP backend beside Newton);
#: the other backends run the same cases in the slow suite and in the table
CI = ("newton", "nt-newton", "qp-osqp")
#: methods of the long coupled cases: the N–T alternation of Clarabel and cvxpy halves is the
#: same iteration as OSQP's but 5–6× slower (120–150 s for 1 a_H of §6.2.1 on this shared
#: machine), so the table runs them on μ = 0.3 only
COUPLED_LONG = ("newton", "nt-newton", "qp-osqp")
ALL = ("newton", "nt-newton") + QP
#: Agreement of the QP methods' N–T alternation on coupled scenes: it stops once the coupled
#: residual is within the halves' accuracy (QP residual_limit 1e-8, "stalled at the accuracy of
#: the halves", alternation.py), and the coupled step amplifies a residual by ≤ 25 into the
#: tractions (measured 16–25 on §6.2.1): 25·1e-8 < 1e-6.
ALTERNATION_AGREE = 1e-6
#: Agreement of a QP rolling start (marched until a step changes t by < 1e-8 μp0) with Newton's
#: direct steady solve: STEADY_TOL/(1 − ρ) with per-step contraction ρ ≤ 0.99, as MARCH_TOL in
#: tests/test_steady.py (measured 9.9e-8 on the harmonic cases).
MARCH_AGREE = 1e-6
#: tolerance of the reference runs (newton, finite termination: stops at round-off)
REF_TOLERANCE = 1e-12


@dataclass
class Case:
    """One hard case: a scene, the methods that run it, and what it is held to.

    ``expect``: ``"converge"`` or the class name of the rollqp error it must stop with
    (``"InputError"``, ``"SolverError"``). ``closed``: optional ``f(result, scene) -> error``
    against a closed form, held to ``closed_tol`` (the discretization bound, with its reason).
    ``agree``: bound on the distance from the ``newton 1e-12`` reference, in p0 and μp0.
    """

    name: str
    group: str
    scene: Callable[[], object]
    methods: tuple = ALL
    expect: str = "converge"
    fast: bool = False
    closed: Callable | None = None
    closed_name: str = ""
    closed_tol: float = 0.0
    agree: float = 1e-7
    note: str = ""
    expect_by_method: dict = field(default_factory=dict)
    augmentation: float | None = None
    ref_scene: Callable | None = None
    #: bound for the QP methods if it differs from ``agree`` (coupled scenes, marched starts)
    agree_qp: float | None = None

    def agreement(self, method) -> float:
        return self.agree_qp if (self.agree_qp is not None and method in QP) else self.agree

    def runs_fast(self, method) -> bool:
        """In the default test suite: ``fast`` is True (every method) or a tuple of methods."""
        return method in self.fast if isinstance(self.fast, tuple) else bool(self.fast)

    def expected(self, method):
        return self.expect_by_method.get(method, self.expect)


# ------------------------------------------------------------------------------------ scenes
def _similar(**over):
    """§6.1.1 (cattaneo-carter): similar steel rollers, μ = 0.1, 40 QCE, Δq = Le/2."""
    return load_scene("cattaneo-carter").replace(**over)


def _coupled(**over):
    """§6.2.1 (goodman-bentall): 2β = 1, full coupling, 40 QCE, Δq = Le/4; shortened to 1 a_H."""
    base = {"discretization.distance": 1.0}
    base.update(over)
    return load_scene("goodman-bentall").replace(**base)


def _carter_creepage_error(result, scene):
    """|ξ/ξ_Carter − 1| at the last state (steady rolling after ≥ 4 a_H)."""
    mu, P = scene.contact.friction, scene.load.normal
    ref = cf.carter_creepage(scene.a_H, scene.R, mu, float(result["Q"][-1]) / (mu * P))
    return abs(float(result["creepage"][-1]) / ref - 1.0)


def _rms_in_contact(x, e):
    """rms of ``e`` over the nodes with |x| <= a_H (``x`` in a_H), as docs/validation.md."""
    inside = np.abs(x) <= 1.0 + 1e-12
    return float(np.sqrt(np.mean(e[..., inside] ** 2)))


def _cattaneo_error(result, scene):
    """rms over |x| <= a_H of (t − t_Cattaneo)/(μ p0) and (p − p_Hertz)/p0 at state 0 (braked start)."""
    x = result["x"] / scene.a_H
    mu, p0 = scene.contact.friction, scene.p0
    qr = float(result["Q"][0]) / (mu * scene.load.normal)
    ph = np.sqrt(np.clip(1.0 - x ** 2, 0.0, None))
    t = cf.cattaneo_traction(x, 1.0, 1.0, 1.0, qr)
    return max(_rms_in_contact(x, result["pt"][0] / (mu * p0) - t), _rms_in_contact(x, result["pn"][0] / p0 - ph))


def _hertz_error(result, scene):
    """rms over |x| <= a_H of (p − p_Hertz)/p0, largest over the states."""
    x = result["x"] / scene.a_H
    ph = np.sqrt(np.clip(1.0 - x ** 2, 0.0, None))
    return max(_rms_in_contact(x, p / scene.p0 - ph) for p in result["pn"])


def cases() -> list[Case]:
    """Every hard case, in table order."""
    out = []
    # ---------------------------------------------------------------- near gross sliding
    for qr, fast in ((0.99, CI), (0.999, CI)):
        out.append(Case(f"gross {qr}", "gross sliding",
                        lambda qr=qr: _similar(**{"load.tangential": {"kind": "constant", "value": qr}}),
                        methods=("newton",) + QP, fast=fast, closed=_carter_creepage_error,
                        closed_name="Carter ξ", closed_tol=1e-2,
                        note="Q/(μP) near 1: stick zone c/a = √(1 − Q/(μP)) below one element"))
    for qr in (1.0, 1.2):
        out.append(Case(f"gross {qr}", "gross sliding",
                        lambda qr=qr: _similar(**{"load.tangential": {"kind": "constant", "value": qr}}),
                        methods=("newton",) + QP, expect="InputError", fast=True,
                        note="no stick solution: rejected by the scene, naming load.tangential"))
    # gross sliding under a prescribed creepage: |ξ| beyond μa/R, every contact node slips
    out.append(Case("gross creepage 1.5", "gross sliding",
                    lambda: _similar(**{"load.creepage": {"kind": "constant",
                                                          "value": -1.5 * 0.1 * _similar().a_H / _similar().R},
                                        "load.start": "rolling", "discretization.distance": 2.0}),
                    methods=("newton",) + QP, fast=CI,
                    note="prescribed |ξ| = 1.5 μa/R: full sliding, Q = μP (reported by state = 2 at every contact node)"))
    # ---------------------------------------------------------------- strong coupling
    for mu, fast in ((0.3, ("newton", "nt-newton")), (0.6, ("newton",)), (1.0, ("newton",))):
        out.append(Case(f"coupling mu={mu}", "strong coupling",
                        lambda mu=mu: _coupled(**{"contact.friction": mu}), fast=fast,
                        methods=ALL if mu == 0.3 else COUPLED_LONG, agree_qp=ALTERNATION_AGREE,
                        note="β = 0.5, full coupling, Goodman start (40 normal load steps), 1 a_H of free rolling"))
    out.append(Case("coupling mu=5", "strong coupling", lambda: _coupled(**{"contact.friction": 5.0}),
                    methods=COUPLED_LONG,
                    expect="SolverError", expect_by_method={"newton": "converge"}, fast=("newton", "nt-newton"),
                    note="β = 0.5, μ = 5: the N–T alternation cycles (1.5e-3 ↔ 1.9e-3) and stops as stalled; "
                         "coupled Newton converges"))
    # ---------------------------------------------------------------- step size
    for form in ("material", "convective-local"):
        for step in (1 / 16, 1 / 8, 1 / 4, 1 / 2, 1.0, 2.0):
            fast = CI if (step in (1 / 4, 1.0) and form == "convective-local" or step == 2.0) else False
            unstable = form == "convective-local" and step > 1.0
            over = {"discretization.step": step, "discretization.formulation": form,
                    "discretization.element": "linear", "discretization.distance": 4.0}
            out.append(Case(f"dq {form} Le*{step:g}", "step size",
                            lambda over=over: _similar(**over), methods=("newton",) + QP,
                            fast=True if unstable else fast, expect="InputError" if unstable else "converge",
                            closed=_carter_creepage_error, closed_name="Carter ξ", closed_tol=3e-2,
                            note="convective-local beyond the node spacing: rejected (discretization.step)"
                            if unstable else "linear elements (the two formulations coincide at Δq ≤ Le)"))
    for form, step in (("convective-local", 0.75), ("material", 2.0)):
        out.append(Case(f"dq quadratic {form} Le*{step:g}", "step size",
                        lambda form=form, step=step: _similar(**{"discretization.step": step,
                                                                 "discretization.formulation": form,
                                                                 "discretization.distance": 4.0}),
                        methods=("newton",) + QP, fast=True if form == "convective-local" else CI,
                        expect="InputError" if form == "convective-local" else "converge",
                        closed=_carter_creepage_error, closed_name="Carter ξ", closed_tol=5e-2,
                        note="40 QCE: node spacing Le/2, so convective-local is rejected above step 0.5; "
                             "material at 2 Le: Carter ξ first order in Δq (measured −3.7 %)"))
    # ---------------------------------------------------------------- augmentation r
    for r in (1e-8, 1e-7, 1e-6, 1e-4, 1e-2, 1.0, 10.0, 1e2, 1e3, 1e4, 1e6, 1e8):
        inside = AUGMENTATION_MIN <= r <= AUGMENTATION_MAX
        out.append(Case(f"r={r:g} similar", "augmentation r",
                        lambda r=r: _similar(**{"discretization.distance": 3.0}), methods=("newton",),
                        augmentation=r, fast=r in (1e-6, 10.0), expect="converge" if inside else "any",
                        note="§6.1.1, 3 a_H; r the same for the normal and the tangential rows"))
        out.append(Case(f"r={r:g} coupled", "augmentation r",
                        lambda r=r: _coupled(**{"discretization.distance": 1.0}), methods=("newton", "nt-newton"),
                        augmentation=r, fast=False, expect="converge" if inside else "any",
                        note="§6.2.1, 1 a_H"))
    # ---------------------------------------------------------------- units
    out.append(Case("units N, m", "units", lambda: _similar(**{
        "bodies.A.radius": 0.15, "bodies.B.radius": 0.3, "bodies.A.E": 2.1e11, "bodies.B.E": 2.1e11,
        "bodies.A.shaft_radius": 0.015, "bodies.B.shaft_radius": 0.03, "load.normal": 1e6}),
        methods=("newton",) + QP, ref_scene=_similar, fast=CI, agree=1e-9,
        note="§6.1.1 in N and m against N and mm: the same nondimensional problem"))
    out.append(Case("units loads 1e-6", "units", lambda: _similar(**{"load.normal": 1e-3}),
                    methods=("newton",) + QP, ref_scene=_similar, fast=CI, agree=2e-4,
                    note="P̄ = 1e-3 N/mm: a_H/R 1000× smaller. Not the same nondimensional problem: the gap "
                         "of the true circles, h = x²/(R(1 + √(1 − x²/R²))), departs from the parabola by "
                         "O((a_H/R)²) = 1.1e-4 at P̄ = 1000 N/mm, 1e-10 here; bound 2e-4"))
    out.append(Case("units loads and E 1e6", "units", lambda: _similar(**{
        "load.normal": 1e9, "bodies.A.E": 2.1e11, "bodies.B.E": 2.1e11}),
        methods=("newton",) + QP, ref_scene=_similar, fast=CI, agree=1e-9,
        note="N and mm against MN-scaled loads and moduli: the same a_H, p0 1e6× larger"))
    out.append(Case("units loads 1e6", "units", lambda: _similar(**{"load.normal": 1e9}),
                    methods=("newton",) + QP, expect="InputError", fast=True,
                    note="a_H = 23 R: beyond the half-space model; rejected naming the radius"))
    # ---------------------------------------------------------------- fine meshes
    for n, fast in ((160, False), (320, False), (640, False), (1280, False)):
        le = 2 * 1.25 / n
        out.append(Case(f"mesh {2 * n + 1} nodes", "fine mesh",
                        lambda n=n, le=le: _similar(**{"discretization.elements": n,
                                                       "discretization.distance": 2 * 0.5 * le}),
                        methods=("newton",) + QP, fast=fast, closed=_cattaneo_error, closed_name="Cattaneo t, Hertz p",
                        closed_tol=0.1 * le, note=f"{n} QCE: braked start (Cattaneo) and 2 rolling steps; closed form "
                        "rms bound 0.1·Le/a_H (first order; measured 0.093–0.097·Le/a_H on these meshes, 0.081 on 40–80 QCE "
                        "in docs/validation.md's slightly different measure)"))
    # ---------------------------------------------------------------- loss and regain of contact
    drop = {"kind": "table", "q": [0.0, 1.0, 2.0, 2.5, 3.5, 4.5], "value": [1.0, 1.0, 0.0, 0.0, 1.0, 1.0]}
    out.append(Case("contact lost and regained", "loss of contact", lambda: _similar(**{
        "load.normal_history": drop, "load.tangential": dict(drop, value=[0.5, 0.5, 0.0, 0.0, 0.5, 0.5])}),
        methods=("newton",) + QP, fast=CI, closed=_carter_creepage_error, closed_name="Carter ξ",
        closed_tol=1e-2, note="P(q) and Q(q) fall to 0 (q = 2…2.5 a_H) and come back; 6 a_H"))
    out.append(Case("contact lost, coupled", "loss of contact", lambda: _coupled(**{
        "load.normal_history": drop, "discretization.distance": 5.0}), fast=False, methods=COUPLED_LONG,
        agree_qp=ALTERNATION_AGREE,
        note="§6.2.1 (β = 0.5, free rolling) with the same P(q)"))
    for amp, fast in ((0.9, False), (1.0, False)):
        out.append(Case(f"harmonic amplitude {amp}", "loss of contact", lambda amp=amp: load_scene("harmonic").replace(**{
            "load.normal_history": {"kind": "harmonic", "mean": 1.0, "amplitude": amp, "wavelength": 2.0},
            "discretization.zone": 1.6, "discretization.distance": 2.0}), fast=fast, methods=COUPLED_LONG,
            agree_qp=MARCH_AGREE,
            note="§6.2.2 with P/P̄ = 1 + A sin(πq/a_H): contact width changes every step; one cycle"))
    # ---------------------------------------------------------------- degenerate complementarity
    out.append(Case("degenerate edges on nodes", "degenerate", lambda: _similar(**{
        "discretization.element": "linear", "discretization.distance": 4.0}),
        methods=("newton",) + QP, fast=CI, closed=_carter_creepage_error, closed_name="Carter ξ", closed_tol=3e-2,
        note="linear, 40 elements on ±1.25 a_H: nodes at x = ±a (p = g = 0), at Cattaneo's c = a/2 and "
             "Carter's stick/slip boundary x = 0"))
    out.append(Case("degenerate mu=0", "degenerate", lambda: _similar(**{
        "contact.friction": 0.0, "load.tangential": {"kind": "constant", "value": 0.0},
        "discretization.distance": 1.0}), methods=("newton",) + QP, fast=CI, closed=_hertz_error,
        closed_name="Hertz p", closed_tol=6e-3, note="frictionless: every node on the kink |t| = μp = 0; "
        "Hertz rms bound 0.1·Le/a_H (measured 3.6e-3 on 40 QCE, docs/validation.md)"))
    out.append(Case("degenerate mu=0 coupled", "degenerate", lambda: _coupled(**{
        "contact.friction": 0.0, "discretization.distance": 0.5}), fast=CI, closed=_hertz_error, agree_qp=ALTERNATION_AGREE,
        closed_name="Hertz p", closed_tol=6e-3, note="β = 0.5 frictionless: t = 0, Hertz (bound as above)"))
    return out


# ------------------------------------------------------------------------------------ running
@dataclass
class Row:
    case: str
    method: str
    outcome: str          # "converged" or the error class name
    message: str = ""
    iterations: int = 0   # max per state
    residual: float = float("nan")
    error: float = float("nan")      # against newton 1e-12
    closed: float = float("nan")     # against the closed form
    seconds: float = 0.0
    states: int = 0
    ok: bool = False

    @property
    def converged(self):
        return self.outcome == "converged"


_REF = {}


def reference(case: Case):
    """``newton`` at ``REF_TOLERANCE`` on the case's scene (cached per case)."""
    if case.name not in _REF:
        scene = (case.ref_scene or case.scene)()
        _REF[case.name] = rollqp.run(scene.replace(**{"solver.tolerance": REF_TOLERANCE}), method="newton")
    return _REF[case.name]


def traction_error(a, b, scene, ref_scene=None) -> float:
    """max over common states of |Δp|/p0, |Δt|/(μ p0) and |Δξ|/(a_H/R), each run in its own scales.

    The creepage of state 0 is left out: after a braked start it is the static shift per a_H, a
    rigid displacement that depends on ``ln(d_ref/a_H)`` (the 2D half-space's undetermined
    constant, FORMULATION.md §3), so it legitimately differs when only the loads are scaled.
    """
    rs = ref_scene or scene
    k = min(len(a["q"]), len(b["q"]))
    mu = scene.contact.friction if scene.contact.friction > 0 else 1.0
    xi = np.abs(a["creepage"][1:k] * scene.R / scene.a_H - b["creepage"][1:k] * rs.R / rs.a_H)
    return max(float(np.max(np.abs(a["pn"][:k] / scene.p0 - b["pn"][:k] / rs.p0))),
               float(np.max(np.abs(a["pt"][:k] / (mu * scene.p0) - b["pt"][:k] / (mu * rs.p0)))),
               float(np.max(xi, initial=0.0)))


def run_case(case: Case, method: str, with_reference: bool = True) -> Row:
    """Run ``case`` with ``method``; judge it against the case's expectation and reference."""
    row = Row(case.name, method, "converged")
    t0 = time.perf_counter()
    try:
        scene = case.scene()
        if case.augmentation is not None:
            scene = _with_augmentation(scene.replace(**{"solver.method": method}), case.augmentation)
        res = rollqp.run(scene, method=method)
    except RollqpError as err:
        row.seconds = time.perf_counter() - t0
        row.outcome, row.message = type(err).__name__, str(err)
        partial = getattr(err, "partial", None)
        row.states = 0 if partial is None else len(partial)
        if isinstance(err, SolverError) and err.residual is not None:
            row.residual = err.residual
        row.ok = case.expected(method) in (row.outcome, "any") and _clear(err)
        return row
    row.seconds = time.perf_counter() - t0
    arr = res.arrays()
    row.states = len(res)
    row.iterations = int(np.max(arr["iterations"]))
    row.residual = float(np.max(arr["residual"]))
    finite = all(np.all(np.isfinite(arr[k])) for k in ("pn", "pt", "creepage", "residual"))
    if case.closed is not None:
        row.closed = case.closed(arr, scene)
    if with_reference:
        ref = reference(case)
        row.error = traction_error(arr, ref.arrays(), scene, case.ref_scene() if case.ref_scene else None)
    row.ok = case.expected(method) in ("converge", "any") and finite \
        and (not with_reference or row.error <= case.agreement(method)) \
        and (case.closed is None or row.closed <= case.closed_tol)
    return row


def _with_augmentation(scene, r):
    """``scene`` with ``solver.augmentation = r``, the validated range lifted so that the band's
    outside can be measured too (a user gets an InputError there)."""
    import rollqp.scene.checks as sc
    lo, hi = sc.AUGMENTATION_MIN, sc.AUGMENTATION_MAX
    sc.AUGMENTATION_MIN, sc.AUGMENTATION_MAX = 0.0, math.inf
    try:
        return scene.replace(**{"solver.augmentation": r})
    finally:
        sc.AUGMENTATION_MIN, sc.AUGMENTATION_MAX = lo, hi


def _clear(err) -> bool:
    """A clear error: InputError names a key; SolverError names the step and a finite residual."""
    if isinstance(err, InputError):
        return bool(err.key) and "nan" not in str(err).lower()
    if isinstance(err, SolverError):
        return err.step is not None and err.residual is not None and math.isfinite(err.residual)
    return False


def run_named(name: str, methods: tuple, with_reference: bool) -> list:
    """:func:`run_case` of the case called ``name`` with each of ``methods`` (a job of
    :func:`harness.map_cases`: cases hold functions, so a worker rebuilds the case from its name;
    one job per case, so that its ``newton 1e-12`` reference is computed once)."""
    case = {c.name: c for c in cases()}[name]
    return [run_case(case, m, with_reference=with_reference) for m in methods]


def run_all(selected, stream=sys.stdout, workers=None):
    rows = []
    by = {c.name: c for c in selected}
    print(_HEADER, file=stream, flush=True)
    jobs = [(c.name, tuple(c.methods), c.expect in ("converge", "any")) for c in selected]
    if workers and workers > 1:
        import hard_cases  # the workers import the function from this module, not from __main__
        fn = hard_cases.run_named
    else:
        fn = run_named
    for row in (r for case_rows in harness.map_cases(fn, jobs, workers=workers) for r in case_rows):
        rows.append(row)
        print(_line(row, by[row.case]), file=stream, flush=True)
        print(f"{row.case:28s} {row.method:12s} {row.outcome:11s} it {row.iterations:4d} "
              f"res {row.residual:9.2e} err {row.error:9.2e} cf {row.closed:9.2e} "
              f"{row.seconds:7.2f}s {'ok' if row.ok else 'FAIL'} {row.message}",
              file=sys.stderr, flush=True)
    return rows


def _f(x):
    return "–" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.1e}"


_HEADER = ("| case | method | outcome | max it/state | max residual | error vs reference | "
           "closed form | held to | time (s) | as expected |\n|---|---|---|---:|---:|---:|---:|---|---:|---|")


def _line(r, c) -> str:
    a = c.agreement(r.method)
    held = {"converge": f"≤ {a:.0e}", "any": f"≤ {a:.0e} or a clear error"}.get(
        c.expected(r.method), c.expected(r.method))
    if c.closed is not None and c.expected(r.method) == "converge":
        held += f"; {c.closed_name} ≤ {c.closed_tol:.0e}"
    outcome = r.outcome if r.converged else f"{r.outcome}: {r.message}".replace("|", "\\|")
    return (f"| {r.case} | {r.method} | {outcome} | {r.iterations} | {_f(r.residual)} | "
            f"{_f(r.error)} | {_f(r.closed)} | {held} | {r.seconds:.2f} | {'yes' if r.ok else 'NO'} |")


def results_table(rows, selected) -> str:
    by = {c.name: c for c in selected}
    return "\n".join([_HEADER] + [_line(r, by[r.case]) for r in rows])


def convective_sweep(stream=sys.stdout):
    """Material against convective-local over Δq/Le (newton, §6.1.1, 8 a_H): Carter's creepage
    error at the end and its step-to-step spread (std of the last 5 creepages / Carter's), the
    scene's convective-local bound lifted to measure beyond it."""
    import rollqp.scene as sc
    saved = dict(sc.CONVECTIVE_STEP_MAX)
    sc.CONVECTIVE_STEP_MAX.update({k: math.inf for k in saved})
    print("| element | Δq/Le | material: ξ/ξ_Carter − 1 | spread | convective-local: ξ/ξ_Carter − 1 | spread |\n"
          "|---|---:|---:|---:|---:|---:|", file=stream)
    try:
        for el in ("constant", "linear", "quadratic"):
            for step in (0.5, 0.75, 1.0, 1.1, 1.25, 1.5, 2.0, 3.0):
                cells = []
                for form in ("material", "convective-local"):
                    scene = _similar(**{"discretization.element": el, "discretization.step": step,
                                        "discretization.formulation": form, "discretization.distance": 8.0})
                    r = rollqp.run(scene, method="newton")
                    ref = cf.carter_creepage(scene.a_H, scene.R, 0.1, 0.75)
                    xi = r["creepage"]
                    cells += [f"{xi[-1] / ref - 1:+.2%}", f"{np.std(xi[-5:]) / abs(ref):.1e}"]
                print(f"| {el} | {step:g} | " + " | ".join(cells) + " |", file=stream, flush=True)
    finally:
        sc.CONVECTIVE_STEP_MAX.update(saved)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fast", action="store_true", help="only the cases the default test suite runs")
    ap.add_argument("--only", default="", help="cases whose name contains one of these (comma-separated)")
    ap.add_argument("--exclude", default=None, help="leave out cases whose name contains this")
    ap.add_argument("--workers", type=int, default=None,
                    help="run the cases on a local dask cluster of N single-threaded worker processes")
    ap.add_argument("--convective-sweep", action="store_true",
                    help="only the material/convective-local sweep over Δq (docs/stability.md)")
    args = ap.parse_args(argv)
    if True:  # BLAS pinned by harness at import
        if args.convective_sweep:
            return convective_sweep()
        only = args.only.split(",")
        selected = [c for c in cases() if (c.fast or not args.fast) and any(o in c.name for o in only)
                    and not (args.exclude and args.exclude in c.name)]
        if args.fast:
            for c in selected:
                c.methods = tuple(m for m in c.methods if c.runs_fast(m))
        t0 = time.perf_counter()
        rows = run_all(selected, workers=args.workers)  # prints the table row by row
        print(f"\n{len(rows)} runs, {sum(r.ok for r in rows)} as expected, {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
