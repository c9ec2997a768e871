r"""Matrix-free step method: generalized Newton (primal–dual active set) with Krylov reduced systems (docs/matrix-free.md).

The method of :mod:`rollqp.methods.newton` on the same equations (eq. 53, 61/62, 67; the
complementarity functions of eq. 74–90), without a stored matrix: on a piecewise-linear
branch of ``Φ`` the generalized Newton step is the solution of the *reduced system* of the
current node sets, so each iteration is

* **normal** (eq. 53): contact set ``I = {p̂ − r ĝ > 0}``, ``p̂ = 0`` off ``I`` and
  ``Â_II p̂_I = δ̂ e − ĥ_I`` with ``f̂ᵀp̂ = P̂`` (or ``δ̂`` given): ``p̂_I = δ̂ û + v̂`` with two
  reduced solves ``Â_II û = e``, ``Â_II v̂ = −ĥ_I`` and ``δ̂`` from the load row (eq. 67);
* **tangential** (eq. 61/62): stick set ``S = {|t̂ − r ŝ| < b̂}``, ``t̂ = b̂ sgn(t̂ − r ŝ)`` on the
  others, and ``ŝ_S = 0``: ``Â_SS t̂_S = −ĉ_S − Δq̂ ξ̂ e − (Â t̂_J)_S`` with ``f̂ᵀt̂ = Q̂`` (or
  ``ξ̂`` given), solved the same way;

until the sets repeat, when the iterate solves the step exactly (to the Krylov tolerance).
The reduced systems ``Â_II x = b`` are solved by GMRES on products with the full operator
(``Â (E_I x)`` restricted to ``I``: an FFT product for a
:class:`~rollqp.influence.toeplitz.ToeplitzOperator`, ``O(n log n)``), preconditioned by the
optimal (T. Chan) circulant of the operator's Toeplitz part on ``|I|`` nodes (an FFT of length
``|I|``), which clusters the spectrum of the log kernel (measured in docs/matrix-free.md).
Each step is warm-started from the previous step's sets and reduced solutions.

Hatted quantities are nondimensional as in :mod:`rollqp.problem`; the residuals and the
solution are rollqp's (``problem.solution``); short of the tolerance a :class:`SolverError`
names the residual. Coupled steps run inside the N–T alternation (``solves`` has no
``"coupled"``); the QP backends need the matrix and are not used on this path.
"""
from __future__ import annotations

import dataclasses
import time

import numpy as np
import scipy.fft
import scipy.sparse.linalg as spla

from ..errors import InputError, SolverError
from .base import Capabilities, check_kind, check_options
from ..problem import NormalStep

__all__ = ["KrylovNewton"]

PRECONDITIONERS = ("circulant", "none")
#: Relative GMRES tolerance of the reduced solves while the node sets still change: LOOSE, and
#: at most ``m^-LOOSE_EXPONENT`` on ``m`` nodes. The error of the solution can be the residual
#: times the condition number (``∝ m`` for the log kernel), and the set decisions at a contact
#: edge need it below the edge node's pressure (``∝ m^-1/2``): at 1e-6 the normal step at
#: 131,073 nodes took 14 set iterations and 36 s (loose solves moving 63 edge nodes the wrong
#: way), at m^-1.5 (2.9e-8) 5 and 12 s; below ~10,000 nodes the bound is above 1e-6 (no change).
LOOSE = 1e-6
LOOSE_EXPONENT = 1.5
#: The N–T alternation around ``mf-newton`` stops at this times the tolerance. It stops at a coupled
#: residual whose distance to the solution grows with its contraction rate: at the factor 1 the
#: states differed from the dense coupled ``newton`` by up to 2.2e-10 μp0 (harmonic, 1 a_H) and
#: 1.1e-10 (linear elements, dissimilar); at 0.1 and 0.01 by 4.0e-12 (harmonic), for 20 % more
#: outer iterations: 0.01 leaves a margin on both.
COUPLED_FACTOR = 1e-2
#: Loose set iterations without a smaller residual after which the reduced systems are solved
#: exactly: inexact solves can flip nodes that are at the bound with zero slip (after a stop)
#: at random, never repeating a set (measured: the built-in stop-reverse on a dense operator).
STALL = 3
#: Dead band of the stick/slip switches, relative to the tolerance (:func:`_next_friction_sets`).
DEADBAND = 1e-3
#: Nodes from which a cold normal step starts from a coarse solution, and the coarsening factor.
COARSE_MIN, COARSE_FACTOR = 2000, 4


class _Reduced:
    """``Â_II`` on a node set ``I`` as a GMRES operator, with its circulant preconditioner."""

    def __init__(self, A, scale, idx, symbol, stats):
        self.A, self.scale, self.idx, self.n, self.stats = A, scale, idx, A.shape[0], stats
        m = idx.size
        self.op = spla.LinearOperator((m, m), matvec=self.mv, dtype=float)
        self.M = None
        if symbol is not None and m > 1:
            mf = scipy.fft.next_fast_len(m, real=True)   # the circulant on a fast length ≥ m
            lam = symbol(mf)
            self.M = spla.LinearOperator((m, m), matvec=lambda r: scipy.fft.irfft(
                scipy.fft.rfft(np.ravel(r), n=mf) / lam, n=mf)[:m], dtype=float)

    def mv(self, x):
        full = np.zeros(self.n)
        full[self.idx] = np.ravel(x)
        self.stats["products"] += 1
        return self.scale * (self.A @ full)[self.idx]

    def target(self, b, atol, rtol=0.0) -> float:
        """The residual norm :meth:`solve` asks of GMRES: ``max(atol, rtol ‖b‖₂, 1e-15 ‖b‖₂)``, ``rtol`` at most
        ``m^-1.5`` (:data:`LOOSE_EXPONENT`)."""
        nb = float(np.linalg.norm(b))
        if rtol > 0.0:                                        # loose: at most m^-1.5 (LOOSE_EXPONENT)
            rtol = min(rtol, float(self.idx.size) ** -LOOSE_EXPONENT)
        return max(atol, rtol * nb, 1e-15 * nb)               # never below round-off of b

    def solve(self, b, x0, atol, rtol=0.0):
        """``Â_II x = b`` to ``‖r‖₂ <= max(atol, rtol ‖b‖₂)`` (GMRES, restarted every 60; :meth:`target`)."""
        if self.idx.size == 0:
            return np.zeros(0)
        nb = float(np.linalg.norm(b))
        atol = self.target(b, atol, rtol)
        x, info = spla.gmres(self.op, b, x0=x0, rtol=0.0, atol=atol, restart=min(60, self.idx.size),
                             maxiter=max(50, self.idx.size), M=self.M)
        self.stats["solves"] += 1
        if info != 0:
            r = float(np.linalg.norm(self.op @ x - b))
            if not r <= max(1e3 * atol, 1e-13 * nb):
                raise SolverError(f"GMRES did not converge on {self.idx.size} nodes "
                                  f"(residual {r:.3e}, wanted {atol:.1e})", method="mf-newton", residual=r)
        return x


def chan_symbol(A, scale):
    """``m ↦`` eigenvalues of the optimal circulant of the operator's Toeplitz part on ``m`` nodes.

    The Toeplitz part is read from an interior column (the average of two neighbouring columns,
    the two node families of quadratic elements): ``t_d = Â[j + d, j]``; T. Chan's circulant has
    the first column ``((m − k) t_k + k t_{k−m}) / m``.
    """
    n = A.shape[0]
    j = n // 2
    if not hasattr(A, "column"):
        return None
    col = 0.5 * (A.column(j) + np.roll(A.column(j + 1), -1)) * scale if n > 2 else A.column(j) * scale

    cache = {}

    def symbol(m):
        """The circulant's eigenvalues on ``m`` nodes (the last few sizes kept: a transient's sets repeat)."""
        if m in cache:
            return cache[m]
        if len(cache) >= 8:
            cache.clear()
        cache[m] = lam = _symbol(m)
        return lam

    def _symbol(m):
        k = np.arange(m)
        lo = np.clip(j - k, 0, n - 1)           # t_{-k} = Â[j - k, j]
        hi = np.clip(j + k, 0, n - 1)           # t_{k}
        t_pos, t_neg = col[hi], col[lo]
        c = ((m - k) * t_pos + k * np.roll(t_neg[::-1], 1)) / m
        lam = scipy.fft.rfft(c)
        if np.max(np.abs(lam.imag)) <= 1e-12 * np.max(np.abs(lam)):
            lam = lam.real                      # a symmetric Toeplitz part: a real spectrum
        # eigenvalues with a non-positive real part (the ω = 0 mode of the steady operator
        # d·D_up·A, whose symbol vanishes there) replaced by the largest real part
        return np.where(np.real(lam) > 0, lam, np.max(np.real(lam)))

    return symbol


class KrylovNewton:
    """Matrix-free generalized Newton (module docstring); registry name ``mf-newton``.

    Parameters
    ----------
    tolerance : float
        rollqp's nondimensional residual to reach.
    max_iterations : int
        Set iterations per step before :class:`SolverError`.
    preconditioner : {"circulant", "none"}
        Preconditioner of the reduced systems.
    """

    name = "mf-newton"
    #: Operator products only (``A @ x``, ``x @ A``, ``diagonal()``): no stored matrix. Coupled steps by the
    #: N–T alternation, which stops at :data:`COUPLED_FACTOR` times the tolerance (:attr:`capabilities`).
    capabilities = Capabilities(solves=frozenset({"normal", "tangential", "steady"}), matrix_free=True)

    def __init__(self, tolerance: float = 1e-10, max_iterations: int = 100, preconditioner: str = "circulant"):
        if preconditioner not in PRECONDITIONERS:
            raise InputError("preconditioner", f"must be one of {', '.join(PRECONDITIONERS)}, got {preconditioner!r}")
        self.tolerance = float(tolerance)
        self.max_iterations = int(max_iterations)
        self.preconditioner = preconditioner
        self.capabilities = dataclasses.replace(type(self).capabilities, coupled_limit=COUPLED_FACTOR * self.tolerance)
        self._warm = {"normal": {}, "tangential": {}}      # reduced solutions of the last step
        self.stats = {"products": 0, "solves": 0}

    @classmethod
    def from_settings(cls, settings, **options) -> "KrylovNewton":
        check_options(cls.name, options, ("preconditioner",))
        return cls(tolerance=settings.tolerance, max_iterations=settings.max_iterations or 100, **options)

    def setup(self, operators) -> None:
        self._warm = {"normal": {}, "tangential": {}}

    @staticmethod
    def _set_solve(state, key, red, A, b, atol, rtol):
        """``Â_II u = b`` for a right-hand side fixed by the node set alone (the load columns ``u`` of the
        normal and tangential steps, module docstring), kept in ``state`` with its set, operator and the
        residual it was solved to: a later iteration or step on the same set (the sets of a rolling
        transient settle and stay) takes it without a GMRES run if that residual is as small as it asks."""
        tol, ids = red.target(b, atol, rtol), red.idx.tobytes()
        hit = state.get(key + "_set")
        if hit is not None and hit[0] is A and hit[1] == ids and hit[2] <= tol and np.array_equal(hit[3], b):
            return hit[4]
        u = red.solve(b, _restrict(state, key, red.idx), atol, rtol)
        state[key + "_set"] = (A, ids, tol, b, u)
        return u

    def _reduced(self, A, scale, idx):
        symbol = None
        if self.preconditioner == "circulant":   # kept with the operator (derived from it alone)
            symbol = A.memo(("chan-circulant", float(scale)), lambda: chan_symbol(A, scale))
        return _Reduced(A, scale, idx, symbol, self.stats)

    # ------------------------------------------------------------------ one step
    def solve(self, problem, warm=None):
        check_kind(self, problem)
        t0 = time.perf_counter()
        before = dict(self.stats)
        sol = self._normal(problem, warm) if problem.kind == "normal" else self._tangential(problem, warm)
        sol.info.update({k: self.stats[k] - before[k] for k in self.stats})
        object.__setattr__(sol, "time", time.perf_counter() - t0)
        return sol

    def _loop(self, problem, active, iterate, what):
        """Iterate ``active → (solution, next sets)`` until the sets repeat and the residual is met.

        While the sets change the reduced systems are solved loosely (relative
        :data:`LOOSE`); once they repeat (or cycle, or :data:`STALL` iterations bring no smaller
        residual), to ``‖r‖₂ <= 10⁻² tol`` (tightened by 10⁻² until
        rollqp's residual is met): an inexact Newton method with exact final iterations.
        """
        seen, atol, rtol = set(), 1e-4 * self.tolerance, LOOSE
        best, stalled = np.inf, 0
        for it in range(1, self.max_iterations + 1):
            sol, nxt, key = iterate(active, atol, rtol)
            settled = np.array_equal(nxt, active)
            if rtol != 0.0:                       # loose phase: count iterations without progress
                stalled = 0 if sol.residual < best else stalled + 1
                best = min(best, sol.residual)
            if settled and rtol == 0.0:
                if sol.residual <= self.tolerance:
                    return sol, it
                if atol < 1e-6 * self.tolerance:
                    break
                atol *= 1e-2                      # the sets are right: solve them more exactly
            elif settled or (rtol != 0.0 and (key in seen or stalled >= STALL)):
                rtol, seen = 0.0, set()           # found (or cycling on inexact solves): solve exactly
            seen.add(key)
            active = nxt
        raise SolverError(f"the {what} step did not converge in {self.max_iterations} set "
                          f"iterations (rollqp residual {sol.residual:.3e} > {self.tolerance:.1e})",
                          method=self.name, residual=sol.residual)

    def _normal(self, pb, warm):
        sc = pb.scales
        scale = sc.modulus / sc.length                            # Â = A E*/a_H
        fh, hh = pb.f / sc.length, pb.h_total / sc.displacement
        r = 1.0 / float(np.mean(pb.A.diagonal()) * scale)
        state = self._warm["normal"] if len(self._warm["normal"].get("u", ())) == pb.n else {}
        self._warm["normal"] = state
        active = (warm.p > 0) if (warm is not None and warm.p is not None and np.any(warm.p > 0)) else \
            self._coarse_start(pb)

        def iterate(act, atol, rtol):
            idx = np.flatnonzero(act)
            if idx.size == 0:                                     # no contact: start at the closest node
                idx = np.array([int(np.argmin(hh))])
            red = self._reduced(pb.A, scale, idx)
            u = self._set_solve(state, "u", red, pb.A, np.ones(idx.size), atol, rtol)
            v = red.solve(-hh[idx], _restrict(state, "v", idx), atol, rtol)
            state.update(u=_expand(u, idx, pb.n), v=_expand(v, idx, pb.n))
            if pb.P is not None:
                d = (pb.P / sc.force - fh[idx] @ v) / (fh[idx] @ u)
            else:
                d = pb.delta / sc.displacement
            p = np.zeros(pb.n)
            p[idx] = d * u + v
            sol = pb.solution(p * sc.stress, d * sc.displacement, method=self.name)
            nxt = (p - r * sol.g / sc.displacement) > 0
            return sol, nxt, nxt.tobytes()

        sol, it = self._loop(pb, active, iterate, "normal")
        return _with(sol, it)

    def _coarse_start(self, pb) -> np.ndarray:
        """The contact set of a cold normal step: all nodes, or, from :data:`COARSE_MIN` nodes on an
        operator that has a coarse model (``A.coarsen``), the set of the same problem on
        :data:`COARSE_FACTOR` times fewer elements (solved the same way, recursively), interpolated:
        the fine iteration then starts next to its answer (nested iteration)."""
        make, strip = getattr(pb.A, "coarsen", None), getattr(pb.A, "strip", None)
        if make is None or strip is None or pb.n < COARSE_MIN or pb.offset is not None:
            return np.ones(pb.n, dtype=bool)
        coarse, Ac = make(max(2, int(strip.n_elements) // COARSE_FACTOR))
        hc = np.interp(coarse.x, strip.x, pb.h)
        sub = KrylovNewton(tolerance=max(self.tolerance, 1e-8), max_iterations=self.max_iterations,
                           preconditioner=self.preconditioner)
        try:
            sol = sub.solve(NormalStep(A=Ac, f=coarse.weights, h=hc, P=pb.P, delta=pb.delta, scales=pb.scales))
        except SolverError:
            return np.ones(pb.n, dtype=bool)
        for k in self.stats:
            self.stats[k] += sub.stats[k]
        return np.interp(strip.x, coarse.x, sol.p) > 0

    def _tangential(self, pb, warm):
        sc = pb.scales
        scale = sc.modulus / sc.length
        fh, ch, dqh = pb.f / sc.length, pb.c / sc.displacement, pb.dq / sc.length
        bh = pb.bound / sc.stress
        if not np.any(bh > 0):
            return _with(pb.solution(np.zeros(pb.n), _free_creepage(pb), method=self.name), 1)
        r = dqh / float(np.mean(pb.A.diagonal()) * scale)
        state = self._warm["tangential"] if len(self._warm["tangential"].get("v", ())) == pb.n else {}
        self._warm["tangential"] = state
        tw = warm.t if (warm is not None and warm.t is not None) else None
        if tw is not None:
            sign = np.sign(tw) * (np.abs(tw) / sc.stress >= bh * (1 - 1e-12))
            stick = (bh > 0) & (sign == 0)
        else:
            stick, sign = bh > 0, np.zeros(pb.n)
        active = np.where(stick, 2, sign).astype(np.int8)     # 2: stick, ±1: slip at ∓, 0: t = 0

        def iterate(act, atol, rtol):
            idx = np.flatnonzero(act == 2)
            tJ = np.where(act == 2, 0.0, bh * act)
            red = self._reduced(pb.A, scale, idx)
            w = scale * (pb.A @ tJ)
            xi0 = 0.0 if pb.Q is not None else pb.xi / sc.slip    # a prescribed creepage: Δq̂ ξ̂ e
            v = red.solve(-(ch[idx] + w[idx] + dqh * xi0), _restrict(state, "v", idx), atol, rtol)
            if pb.Q is not None:
                u = self._set_solve(state, "u", red, pb.A, np.full(idx.size, -dqh), atol, rtol)
                xi = (pb.Q / sc.force - fh @ tJ - fh[idx] @ v) / (fh[idx] @ u)
                state["u"] = _expand(u, idx, pb.n)
            else:
                xi, u = xi0, np.zeros(idx.size)
            state["v"] = _expand(v, idx, pb.n)
            t = tJ.copy()
            t[idx] = xi * u + v
            sol = pb.solution(t * sc.stress, xi * sc.slip, method=self.name)
            nxt = _next_friction_sets(act, t, sol.s / sc.slip, bh, DEADBAND * self.tolerance)
            if pb.Q is not None and not np.any(nxt == 2):    # a load row needs one sticking node
                y = np.abs(t - r * sol.s / sc.slip)
                nxt[np.argmin(np.where(bh > 0, y / np.where(bh > 0, bh, 1), np.inf))] = 2
            return sol, nxt, nxt.tobytes()

        sol, it = self._loop(pb, active, iterate, "tangential")
        return _with(sol, it)


def _next_friction_sets(act, t, s, b, eps=0.0):
    """The next stick/slip sets of the tangential iteration (eq. 57–60).

    A sticking node whose shear exceeds the bound by more than ``eps`` slips in the direction of
    its shear; a slipping node (``t = σ b``) whose slip does not oppose it (``σ s > eps``) sticks;
    the others keep their state. This is the ``r → 0⁺`` limit of ``Proj(t − r s)``: unlike a
    finite ``r`` it never moves a node from one bound straight to the other, which made the
    iteration oscillate and diverge after long steps (Δq = 8 Le at 2,001 nodes). The dead band
    ``eps`` (nondimensional, far below the tolerance: a node left in it adds at most ``eps`` to
    the friction residual of eq. 60) keeps round-off from flipping nodes that are both at the
    bound and at zero slip, as after a stop (static shift under constant loads: ``ŝ = 0`` up to
    round-off at every node), where it made 11–22 set iterations a step.
    """
    nxt = act.copy()
    stick = act == 2
    over = stick & (np.abs(t) > b + eps)
    nxt[over] = np.sign(t[over])
    slip = (act == 1) | (act == -1)
    nxt[slip & (act * s > eps)] = 2
    nxt[b <= 0] = 0
    return nxt.astype(np.int8)


def _free_creepage(pb):
    """``ξ`` of a tangential step without friction (``t = 0``): the prescribed one, or 0 for ``Q = 0``."""
    if pb.xi is not None:
        return pb.xi
    if pb.Q != 0:
        raise SolverError("a tangential load without any contact", method="mf-newton", residual=float("inf"))
    return 0.0


def _restrict(state, key, idx):
    v = state.get(key)
    return None if v is None else v[idx]


def _expand(x, idx, n):
    out = np.zeros(n)
    out[idx] = x
    return out


def _with(sol, iterations):
    object.__setattr__(sol, "iterations", iterations)
    return sol
