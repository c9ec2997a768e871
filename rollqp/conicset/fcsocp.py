r"""An external route for the FCLib problems: the SOCP fixed point of Coulomb friction contact.

FCLib's local problem ``FC(W, q, μ)`` (:mod:`~rollqp.conicset.fclib`) is not a convex program: De
Saxcé's term ``s = μ‖u_T‖`` in ``û = u + (s, 0, 0)`` depends on the answer. With ``s`` held fixed it
is one — the cone complementarity problem ``C*_μ ∋ W r + q + s ⊥ r ∈ C_μ`` is the optimality system of
the convex SOCP (Acary, Cadoux, Lemaréchal, Malick 2011, *A formulation of the linear discrete
Coulomb friction problem via convex optimization*, ZAMM 91(2), eq. 3.3 and algorithm 1)

.. math::
    \min_r\ \tfrac12 r^\top W r + (q + s)^\top r \quad\text{s.t.}\quad \|r_{T,i}\| \le \mu_i r_{N,i},

so the classic route solves that SOCP, updates ``s_i = μ_i ‖u_{T,i}‖`` from the new ``u = W r + q``
and repeats until ``s`` stops moving; a fixed point is a solution of ``FC(W, q, μ)``. Each SOCP is
solved by an external conic solver — Clarabel (interior point, the quadratic objective handed over
as ``P = W``) or SCS (operator splitting, factored once, warm-started and only ``c`` updated per
iteration) — at high accuracy; nothing of rollqp's Newton method is used, and the problem is read
from the FCLib file alone (``/fclib_local``; the file's ``/solution`` is not opened by the route).

The answer is scored by :func:`merit`, the FCLib-style natural-map residual of the Coulomb cone
complementarity from ``(W, q, μ)`` alone (Siconos' ``fc3d_compute_error`` without its division by
``‖q‖``): ``‖r − Proj_{C_μ}(r − û)‖₂`` over every contact.

>>> import numpy as np
>>> W, q, mu = np.diag([2.0, 1.0, 1.0]), np.array([-1.0, 0.5, 0.0]), np.array([0.3])
>>> a = solve(W, q, mu, "clarabel")
>>> a.converged, bool(merit(W, q, mu, a.r) < 1e-8)
(True, True)
>>> np.round(a.r, 6)   # r_N = 1/2 from the normal row; the slip saturates |r_T| = μ r_N = 0.15
array([ 0.5 , -0.15,  0.  ])
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..errors import InputError
from . import fclib

__all__ = ["BACKENDS", "FixedPointAnswer", "coulomb_projection", "merit", "solve", "solve_file", "TOL_S",
           "TOL_SOCP", "MAX_ITERATIONS"]

#: The external conic solvers the route drives.
BACKENDS = ("clarabel", "scs")
#: Every gap and feasibility tolerance of each SOCP (Clarabel's and SCS's ``eps_abs``/``eps_rel``): high
#: accuracy, below the 1e-9 of the conic runner because the fixed point carries each solve's error on.
TOL_SOCP = 1e-10
#: The fixed point stops when ``max|s_{k+1} − s_k|`` (in the problem's units) is at most this.
TOL_S = 1e-10
#: Fixed-point iterations before the route says it did not converge.
MAX_ITERATIONS = 100


@dataclass
class FixedPointAnswer:
    """``r`` the reactions; ``converged`` whether ``s`` stopped moving within :data:`MAX_ITERATIONS`;
    ``iterations`` fixed-point iterations (SOCP solves); ``inner`` the conic solver's iterations, summed;
    ``ds`` the last ``max|s_{k+1} − s_k|``; ``status`` the last SOCP's status; ``time`` wall seconds."""

    r: np.ndarray
    converged: bool
    iterations: int
    inner: int
    ds: float
    status: str
    time: float


def coulomb_projection(z, mu):
    """The Euclidean projection of ``z`` (``(N, T1, T2)`` per contact, flat) on the Coulomb cones
    ``‖r_T‖ ≤ μ r_N``."""
    z = np.asarray(z, dtype=float).reshape(-1, 3)
    mu = np.asarray(mu, dtype=float)
    zn, zt = z[:, 0], z[:, 1:]
    nt = np.hypot(zt[:, 0], zt[:, 1])
    out = np.zeros_like(z)
    inside = nt <= mu * zn
    polar = mu * nt <= -zn
    side = ~inside & ~polar
    out[inside] = z[inside]
    a = (zn[side] + mu[side] * nt[side]) / (1.0 + mu[side] ** 2)
    out[side, 0] = a
    out[side, 1:] = (mu[side] * a / nt[side])[:, None] * zt[side]
    return out.ravel()


def _de_saxce(u, mu):
    """``s = (μ‖u_T‖, 0, 0)`` per contact, flat."""
    u = np.asarray(u, dtype=float).reshape(-1, 3)
    s = np.zeros_like(u)
    s[:, 0] = np.asarray(mu) * np.hypot(u[:, 1], u[:, 2])
    return s.ravel()


def merit(W, q, mu, r) -> float:
    """The natural-map residual ``‖r − Proj_{C_μ}(r − û)‖₂``, ``û = W r + q + (μ‖u_T‖, 0, 0)``: zero
    exactly at a solution of ``FC(W, q, μ)``; from the file's ``(W, q, μ)`` alone."""
    r = np.asarray(r, dtype=float)
    u = W @ r + q
    return float(np.linalg.norm(r - coulomb_projection(r - u - _de_saxce(u, mu), mu)))


def _cone_rows(mu):
    """``A``, ``b`` with ``b − A r = (μ r_N, r_T1, r_T2)`` per contact: ``A r + s = b, s ∈ SOC(3)``."""
    nc = mu.size
    i = np.arange(nc)
    rows = np.r_[3 * i, 3 * i + 1, 3 * i + 2]
    return sp.csc_matrix((np.r_[-mu, -np.ones(2 * nc)], (rows, rows)), shape=(3 * nc, 3 * nc)), np.zeros(3 * nc)


class _Clarabel:
    def __init__(self, W, c, mu, tol, limit):
        import clarabel
        self.clarabel = clarabel
        st = clarabel.DefaultSettings()
        st.verbose, st.time_limit = False, limit
        st.tol_gap_abs = st.tol_gap_rel = st.tol_feas = tol
        st.presolve_enable = False   # the data update of each iteration needs the same structure
        A, b = _cone_rows(mu)
        self.solver = clarabel.DefaultSolver(sp.triu(W, format="csc"), c, A, b,
                                             [clarabel.SecondOrderConeT(3)] * mu.size, st)
        self.first = True

    def __call__(self, c):
        if not self.first:
            self.solver.update(q=c)
        self.first = False
        sol = self.solver.solve()
        status = str(sol.status)
        return np.asarray(sol.x), status, status == "Solved", int(sol.iterations)


class _SCS:
    def __init__(self, W, c, mu, tol, limit):
        import scs
        A, b = _cone_rows(mu)
        self.solver = scs.SCS({"P": sp.triu(W, format="csc"), "A": A, "b": b, "c": c}, {"q": [3] * mu.size},
                              verbose=False, eps_abs=tol, eps_rel=tol, max_iters=1_000_000, time_limit_secs=limit)
        self.first = True

    def __call__(self, c):
        if not self.first:
            self.solver.update(c=c)
        sol = self.solver.solve(warm_start=not self.first)
        self.first = False
        status = str(sol["info"]["status"])
        return np.asarray(sol["x"]), status, status == "solved", int(sol["info"]["iter"])


def solve(W, q, mu, backend: str = "clarabel", tol: float = TOL_SOCP, tol_s: float = TOL_S,
          max_iterations: int = MAX_ITERATIONS, limit: float = 40.0) -> FixedPointAnswer:
    """The SOCP fixed point (module docstring) of ``FC(W, q, μ)`` by ``backend`` (:data:`BACKENDS`);
    ``limit`` wall seconds for the whole fixed point (each SOCP gets what is left)."""
    if backend not in BACKENDS:
        raise InputError("backend", f"unknown backend {backend!r}; allowed: {', '.join(BACKENDS)}")
    W = sp.csc_matrix(W)
    q, mu = np.asarray(q, dtype=float), np.asarray(mu, dtype=float)
    if W.shape != (q.size, q.size) or q.size != 3 * mu.size:
        raise InputError("W, q, mu", f"need W (m, m), q (m,) and mu (m/3,); got {W.shape}, {q.shape}, {mu.shape}")
    t0 = time.perf_counter()
    s = np.zeros_like(q)
    make = {"clarabel": _Clarabel, "scs": _SCS}[backend]
    socp = make(W, q + s, mu, tol, limit)
    r, inner, ds, status, converged = np.zeros_like(q), 0, np.inf, "", False
    for k in range(1, max_iterations + 1):
        x, status, ok, it = socp(q + s)
        inner += it
        if not ok or not np.all(np.isfinite(x)):
            return FixedPointAnswer(r, False, k, inner, ds, status, time.perf_counter() - t0)
        r = x
        s_new = _de_saxce(W @ r + q, mu)
        ds = float(np.max(np.abs(s_new - s)))
        s = s_new
        if ds <= tol_s:
            converged = True
            break
        if time.perf_counter() - t0 > limit:
            status = f"time limit ({status})"
            break
    return FixedPointAnswer(r, converged, k, inner, ds, status, time.perf_counter() - t0)


def solve_file(path, backend: str = "clarabel", **kw) -> FixedPointAnswer:
    """:func:`solve` on an FCLib local problem read from ``path`` (``W``, ``q``, ``μ`` only)."""
    d = fclib.read(path, solution=False)
    return solve(d["W"], d["q"], d["mu"], backend, **kw)
