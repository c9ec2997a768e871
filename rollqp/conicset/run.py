r"""Every installed conic solver on the conic test set, scored against the certified solutions.

Two routes per solver:

* **native** — the CBF file read back (:func:`rollqp.conicset.cbf.read`) and handed to the solver's
  own Python interface in the form ``Gz + s = h, s ∈ K; Aeq z = beq`` (:func:`~rollqp.conicset.cbf.standard_form`):
  what a user of CBLIB's files runs. The quadratic objective is the rotated-cone epigraph.
* **cvxpy** — the program stated from its arrays (``data/NAME.npz``) as cvxpy's textbook form
  (``quad_form`` objective, ``cp.SOC`` discs): cvxpy hands Clarabel and SCS the quadratic objective
  itself and builds its own epigraph for ECOS and CVXOPT.

Two settings: ``default`` (the solver's defaults, a time limit only) and ``high`` (every gap and
feasibility tolerance :data:`HIGH_ACCURACY`, qpbenchmark's high-accuracy value). Each answer is
scored by its distance from the certified solution, ``max|x − x*|`` in ``p0`` (the solver's
primal variables: pressures or tractions), by rollqp's residual of ``(x, y)`` (eq. 3D.29, from
the program's arrays, :func:`~rollqp.conicset.forms.residual`; ``y`` the load rows' multipliers
from the solver's duals), by its status and by its wall time.
"""
from __future__ import annotations

import json
import time
import warnings
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from . import cbf, fclib, fcsocp
from .forms import ProgramData, residual

__all__ = ["SOLVERS", "FC_SOLVERS", "SETTINGS", "Answer", "available", "solve", "run_set", "run_fclib",
           "HIGH_ACCURACY", "TIME_LIMIT", "WITHIN"]

#: qpbenchmark's high-accuracy tolerance, for every gap and feasibility tolerance of the ``high`` settings.
HIGH_ACCURACY = 1e-9
#: Wall seconds per solve: each solve runs in a forked process, ended at this limit (ECOS and CVXOPT have
#: no time limit of their own) and counted a failure; Clarabel and SCS are also given it as their own.
TIME_LIMIT = 40.0
#: The accuracy a cross-check needs: rollqp's ``check-step`` tolerance on ``max|x − x*|`` in ``p0``.
WITHIN = 1e-6
#: The solvers (``route-name``): native on the CBF file, cvxpy on the program's arrays.
SOLVERS = ("clarabel", "scs", "ecos", "cvxopt", "cvxpy-clarabel", "cvxpy-scs", "cvxpy-ecos", "cvxpy-cvxopt")
SETTINGS = ("default", "high")
#: The routes for the FCLib problems: the SOCP fixed point (:mod:`~rollqp.conicset.fcsocp`), each SOCP by
#: Clarabel or by SCS at high accuracy.
FC_SOLVERS = ("socp-fp-clarabel", "socp-fp-scs")


@dataclass
class Answer:
    """One solve: ``ok`` the solver's own status says solved; ``dx`` ``max|x − x*|``; ``residual``
    rollqp's; ``time`` wall seconds of the solver call (cvxpy: ``problem.solve``, its compilation included).
    FCLib routes: ``dx`` is ``max|r − r*|`` (in ``p0``), ``iterations`` the fixed-point iterations, ``inner``
    the conic solver's iterations summed over them and ``merit`` the natural-map residual
    (:func:`~rollqp.conicset.fcsocp.merit`)."""

    problem: str
    solver: str
    settings: str
    ok: bool
    status: str
    dx: float
    residual: float
    time: float
    iterations: int
    inner: int = 0
    merit: float = float("nan")


def available(solver: str) -> bool:
    """Whether the solver (and cvxpy, for a ``cvxpy-`` route; h5py, for a ``socp-fp-`` route) imports."""
    import importlib
    name = solver.removeprefix("cvxpy-").removeprefix("socp-fp-")
    mods = [name] + (["cvxpy"] if solver.startswith("cvxpy-") else []) \
        + (["h5py"] if solver.startswith("socp-fp-") else [])
    try:
        for m in mods:
            importlib.import_module(m)
    except ImportError:
        return False
    return True


# ------------------------------------------------------------------------------------ native
def _clarabel(c, G, h, dims, Aeq, beq, high):
    import clarabel
    s = clarabel.DefaultSettings()
    s.verbose, s.time_limit = False, TIME_LIMIT
    if high:
        s.tol_gap_abs = s.tol_gap_rel = s.tol_feas = HIGH_ACCURACY
    cones = ([clarabel.ZeroConeT(Aeq.shape[0])] if Aeq.shape[0] else []) + \
        ([clarabel.NonnegativeConeT(dims["l"])] if dims["l"] else []) + [clarabel.SecondOrderConeT(q) for q in dims["q"]]
    A = sp.vstack([Aeq, G], format="csc")
    P = sp.csc_matrix((c.size, c.size))
    sol = clarabel.DefaultSolver(P, c, A, np.concatenate([beq, h]), cones, s).solve()
    status = str(sol.status)
    return np.asarray(sol.x), np.asarray(sol.z[:Aeq.shape[0]]), status, status == "Solved", int(sol.iterations)


def _scs(c, G, h, dims, Aeq, beq, high):
    import scs
    opts = dict(verbose=False, time_limit_secs=TIME_LIMIT)
    if high:
        opts.update(eps_abs=HIGH_ACCURACY, eps_rel=HIGH_ACCURACY, max_iters=1_000_000)
    data = {"A": sp.vstack([Aeq, G], format="csc"), "b": np.concatenate([beq, h]), "c": c}
    cone = {"z": Aeq.shape[0], "l": dims["l"], "q": dims["q"]}
    sol = scs.SCS(data, cone, **opts).solve()
    status = str(sol["info"]["status"])
    return sol["x"], sol["y"][:Aeq.shape[0]], status, status == "solved", int(sol["info"]["iter"])


def _ecos(c, G, h, dims, Aeq, beq, high):
    import ecos
    opts = dict(verbose=False)
    if high:
        opts.update(abstol=HIGH_ACCURACY, reltol=HIGH_ACCURACY, feastol=HIGH_ACCURACY)
    kw = dict(A=sp.csc_matrix(Aeq), b=beq) if Aeq.shape[0] else {}
    sol = ecos.solve(c, sp.csc_matrix(G), h, dims, **kw, **opts)
    info = sol["info"]
    y = np.asarray(sol["y"]) if Aeq.shape[0] else np.zeros(0)
    return np.asarray(sol["x"]), y, str(info["infostring"]), int(info["exitFlag"]) == 0, int(info["iter"])


def _cvxopt(c, G, h, dims, Aeq, beq, high):
    import cvxopt
    from cvxopt import solvers

    def spm(M):
        M = sp.coo_matrix(M)
        return cvxopt.spmatrix(M.data.tolist(), M.row.tolist(), M.col.tolist(), size=M.shape)
    opts = {"show_progress": False}
    if high:
        opts.update(abstol=HIGH_ACCURACY, reltol=HIGH_ACCURACY, feastol=HIGH_ACCURACY)
    args = dict(A=spm(Aeq), b=cvxopt.matrix(beq)) if Aeq.shape[0] else {}
    sol = solvers.conelp(cvxopt.matrix(c), spm(G), cvxopt.matrix(h), {"l": dims["l"], "q": dims["q"], "s": []},
                         options=opts, **args)
    x = np.array(sol["x"]).ravel() if sol["x"] is not None else np.full(c.size, np.nan)
    y = np.array(sol["y"]).ravel() if Aeq.shape[0] and sol["y"] is not None else np.zeros(Aeq.shape[0])
    return x, y, str(sol["status"]), sol["status"] == "optimal", int(sol.get("iterations", 0))


_NATIVE = {"clarabel": _clarabel, "scs": _scs, "ecos": _ecos, "cvxopt": _cvxopt}


# ------------------------------------------------------------------------------------- cvxpy
def _cvxpy(d: ProgramData, solver: str, high: bool):
    import cvxpy as cp
    x = cp.Variable(d.m)
    cons = [d.a @ x == d.b] if d.k else []
    if d.kind == "normal":
        cons.append(x >= 0)
    else:
        nv = d.m // 2
        cons.append(cp.SOC(d.bound, cp.vstack([x[:nv], x[nv:]]), axis=0))
    prob = cp.Problem(cp.Minimize(0.5 * cp.quad_form(x, cp.psd_wrap(d.H)) + d.q @ x), cons)
    name = solver.upper()
    opts = {"CLARABEL": dict(time_limit=TIME_LIMIT), "SCS": dict(time_limit_secs=TIME_LIMIT), "ECOS": {},
            "CVXOPT": {}}[name]
    if high:
        opts.update({"CLARABEL": dict(tol_gap_abs=HIGH_ACCURACY, tol_gap_rel=HIGH_ACCURACY, tol_feas=HIGH_ACCURACY),
                     "SCS": dict(eps_abs=HIGH_ACCURACY, eps_rel=HIGH_ACCURACY, max_iters=1_000_000),
                     "ECOS": dict(abstol=HIGH_ACCURACY, reltol=HIGH_ACCURACY, feastol=HIGH_ACCURACY),
                     "CVXOPT": dict(abstol=HIGH_ACCURACY, reltol=HIGH_ACCURACY, feastol=HIGH_ACCURACY)}[name])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            prob.solve(solver=name, **opts)
        except cp.error.SolverError as err:
            return np.full(d.m, np.nan), np.zeros(d.k), f"error: {str(err)[:60]}", False, 0
    xv = np.asarray(x.value) if x.value is not None else np.full(d.m, np.nan)
    y = np.asarray(cons[0].dual_value, dtype=float).ravel() if d.k and cons[0].dual_value is not None \
        else np.zeros(d.k)
    iters = prob.solver_stats.num_iters if prob.solver_stats is not None else 0
    return xv, y, str(prob.status), prob.status == "optimal", int(iters or 0)


def _child(pipe, solver, settings, d, conic):
    try:
        pipe.send(_solve_here(solver, settings, d, conic))
    except Exception as err:   # anything a solver raises is its answer: a failed solve, with its message
        pipe.send((np.full(d.m, np.nan), np.zeros(d.k), f"error: {type(err).__name__}: {str(err)[:80]}", False, 0,
                   float("nan")))
    finally:
        pipe.close()


def solve(solver: str, settings: str, d: ProgramData, conic=None, limit: float = TIME_LIMIT):
    """``(x, y, status, ok, iterations, seconds)`` of one solve in a forked process, ended after ``limit``
    seconds (status ``"time limit"``); ``conic`` the CBF problem (native routes)."""
    import multiprocessing
    ctx = multiprocessing.get_context("fork")
    recv, send = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_child, args=(send, solver, settings, d, conic), daemon=True)
    t0 = time.perf_counter()
    proc.start()
    send.close()
    out = recv.recv() if recv.poll(limit + 5.0) else None
    if proc.is_alive():
        proc.kill()
    proc.join()
    if out is None:
        return np.full(d.m, np.nan), np.zeros(d.k), "time limit", False, 0, time.perf_counter() - t0
    x, y, status, ok, it, sec = out
    sec = sec if np.isfinite(sec) else time.perf_counter() - t0
    if not sec <= limit:
        ok, status = False, f"time limit ({status})"
    return x, y, status, ok, it, sec


def _solve_here(solver: str, settings: str, d: ProgramData, conic=None):
    """``(x, y, status, ok, iterations, seconds)`` of one solve in this process."""
    high = settings == "high"
    t0 = time.perf_counter()
    if solver.startswith("cvxpy-"):
        x, y, status, ok, it = _cvxpy(d, solver.removeprefix("cvxpy-"), high)
    else:
        c, G, h, dims, Aeq, beq = cbf.standard_form(conic)
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                z, y, status, ok, it = _NATIVE[solver](c, G, h, dims, Aeq, beq, high)
            except (ValueError, ArithmeticError) as err:   # CVXOPT's "singular KKT matrix", ECOS' errors
                z, y, status, ok, it = np.full(c.size, np.nan), np.zeros(Aeq.shape[0]), f"error: {err}", False, 0
        x = np.asarray(z, dtype=float)[:d.m]
    return np.asarray(x, dtype=float), np.asarray(y, dtype=float), status, bool(ok), it, time.perf_counter() - t0


def run_set(folder, solvers=None, settings=SETTINGS, only=None, progress=None) -> list[Answer]:
    """Every conic program of the set under ``folder`` on ``solvers`` (default: every available one);
    answers appended to ``folder/results/answers.jsonl`` as they come."""
    folder = Path(folder)
    solvers = [s for s in (solvers or SOLVERS) if available(s)]
    names = sorted(p.stem for p in (folder / "cbf").glob("*.cbf"))
    if only:
        names = [n for n in names if n in only]
    (folder / "results").mkdir(exist_ok=True)
    out = []
    with open(folder / "results" / "answers.jsonl", "w", encoding="utf-8") as log:
        for name in names:
            with np.load(folder / "data" / f"{name}.npz") as z:
                d = ProgramData.from_arrays(z)
            with np.load(folder / "solutions" / f"{name}.npz") as z:
                x_star = z["x"]
            conic = cbf.read(folder / "cbf" / f"{name}.cbf")
            for solver in solvers:
                for st in settings:
                    x, y, status, ok, it, sec = solve(solver, st, d, conic)
                    dx = float(np.max(np.abs(x - x_star))) if np.all(np.isfinite(x)) else float("inf")
                    ans = Answer(name, solver, st, ok, status, dx, residual(d, x, y), sec, it)
                    out.append(ans)
                    log.write(json.dumps(asdict(ans)) + "\n")
                    log.flush()
                    if progress:
                        progress(ans)
    return out


def run_fclib(folder, solvers=None, only=None, progress=None, limit: float = 4 * TIME_LIMIT) -> list[Answer]:
    """Every FCLib problem under ``folder/fclib`` on the SOCP fixed point (``solvers``: :data:`FC_SOLVERS`,
    default every available one), each read from its file alone, then scored against the file's certified
    ``/solution`` and by the natural-map merit; answers written to ``folder/results/answers-fclib.jsonl``.
    ``limit`` wall seconds per fixed point."""
    folder = Path(folder)
    solvers = [s for s in (solvers or FC_SOLVERS) if s in FC_SOLVERS and available(s)]
    names = sorted(p.stem for p in (folder / "fclib").glob("*.hdf5"))
    if only:
        names = [n for n in names if n in only]
    (folder / "results").mkdir(exist_ok=True)
    out = []
    with open(folder / "results" / "answers-fclib.jsonl", "w", encoding="utf-8") as log:
        for name in names:
            path = folder / "fclib" / f"{name}.hdf5"
            d = fclib.read(path)
            for solver in solvers:
                a = fcsocp.solve_file(path, solver.removeprefix("socp-fp-"), limit=limit)
                fin = bool(np.all(np.isfinite(a.r)))
                ans = Answer(name, solver, "high", a.converged, a.status if a.converged else
                             f"not converged: {a.status}, |ds| {a.ds:.1e}",
                             float(np.max(np.abs(a.r - d["r"]))) if fin else float("inf"),
                             fclib.residual(d["W"], d["q"], d["mu"], a.r) if fin else float("inf"), a.time,
                             a.iterations, a.inner, fcsocp.merit(d["W"], d["q"], d["mu"], a.r) if fin else float("inf"))
                out.append(ans)
                log.write(json.dumps(asdict(ans)) + "\n")
                log.flush()
                if progress:
                    progress(ans)
    return out
