r"""GNMls on the coupled step: all rows of ``Φ`` at once (eq. 63–64, 80–90), unknowns ``z = (p̂, t̂, δ̂?, ξ̂?)``.

``y_N = r_N ĝ`` and ``y_T = r_T ŝ`` are linear in ``z`` (:class:`~.linear.CoupledSystem`); the friction
bound is ``b = μ max(0, p̂ − y_N)`` (eq. 63), so a slipping node's row depends on ``p̂`` and ``ĝ``
(eq. 88, :mod:`.ncp`). Start: the previous step (warm), else one N–T sweep of the two halves
(:func:`rollqp.methods.alternation.sweep`). Directions: :class:`~.linear.CoupledFactors` (one LU
reused across iterations and steps through a Woodbury update of the rows whose node case changed),
or with ``coupled_reuse`` false :func:`~.linear.direct_coupled_direction` (a new reduced system per
iteration, the reference). When the Armijo search fails (a node on a kink where the modified row
is not the directional derivative), one N–T sweep from the iterate replaces the step.
"""
from __future__ import annotations

import numpy as np

from ...errors import SolverError
from ...problem import StepSolution
from . import linear
from .common import ALPHA_MIN, not_converged
from .linear import coupled_vectors
from .ncp import coupled_cases, coupled_phi
from ..alternation import sweep


__all__ = ["solve_coupled"]


class _Coupled:
    """The state of the coupled iteration: ``z``, ``y_N``, ``y_T``, ``Φ`` and the counts."""

    def __init__(self, meth, pb, warm):
        self.meth, self.pb = meth, pb
        self.S, self.factors = meth.coupled_system(pb)
        self.kN, self.kT = coupled_vectors(self.S, pb)
        self.n, self.mu = pb.n, pb.mu
        sc = pb.scales
        self.Phat = pb.P / sc.force if self.S.iP is not None else None
        self.Qhat = pb.Q / sc.force if self.S.iQ is not None else None
        self.start = self._start(warm)
        self.history, self.merits, self.steps = [], [], []
        self.backtracks = self.sweeps = self.shifts = 0

    def _start(self, warm):
        """Step 1: the previous step's state, else one N–T sweep of the halves (normal with ``t = 0``)."""
        pb, S, n, sc = self.pb, self.S, self.n, self.pb.scales
        start = "warm"
        if (warm is not None and warm.p is not None and warm.t is not None and np.shape(warm.p) == (n,)
                and np.shape(warm.t) == (n,)):
            p0, t0_, d0, x0 = warm.p, warm.t, warm.delta, warm.xi
        else:
            start = "cold"
            nsol, tsol = sweep(self.meth, pb, np.zeros(n))
            p0, t0_, d0, x0 = nsol.p, tsol.t, nsol.delta, tsol.xi
        z = np.zeros(S.N)
        z[:n], z[n:2 * n] = p0 / sc.stress, t0_ / sc.stress
        if S.iP is not None:
            z[S.iP] = (d0 if d0 is not None else 0.0) / sc.displacement
        if S.iQ is not None:
            z[S.iQ] = (x0 if x0 is not None else 0.0) / sc.slip
        self.set(z)
        return start

    def set(self, z):
        """Take the iterate ``z``: the linear parts and ``Φ`` evaluated anew."""
        n = self.n
        self.z = z
        self.p, self.t = z[:n], z[n:2 * n]
        self.refresh()

    def refresh(self):
        self.yN, self.yT = self.S.KN @ self.z + self.kN, self.S.KT @ self.z + self.kT
        self.phi = self.residual(self.p, self.t, self.yN, self.yT)

    def residual(self, p, t, yN, yT):
        return coupled_phi(self.S, p, t, yN, yT, self.mu, self.Phat, self.Qhat)

    def solution(self):
        sc, S, z = self.pb.scales, self.S, self.z
        return self.pb.solution(self.p * sc.stress, self.t * sc.stress,
                                z[S.iP] * sc.displacement if S.iP is not None else None,
                                z[S.iQ] * sc.slip if S.iQ is not None else None)

    def cases(self, it, nrm):
        """The node cases (eq. 82–90), a degenerate iterate repaired first: without a contact node
        (no ``δ̂`` column) or a stick node (no ``ξ̂`` column) the nearest node is moved onto its kink."""
        S, mu, p, t = self.S, self.mu, self.p, self.t
        contact, stick, slip_sign, _ = coupled_cases(p, t, self.yN, self.yT, mu)
        if S.iP is not None and not contact.any():
            j = int(np.argmin(self.yN - p))
            self.z[S.iP] += (p[j] - self.yN[j]) / S.KN[j, S.iP]
            self.refresh()
            contact, stick, slip_sign, _ = coupled_cases(p, t, self.yN, self.yT, mu)
            contact[j] = True
            self.shifts += 1
        if S.iQ is not None and not stick.any():
            b = mu * np.maximum(0.0, p - self.yN)
            u = t - self.yT
            excess = np.where(b > 0, np.abs(u) - b, np.inf)
            j = int(np.argmin(excess))
            if not np.isfinite(excess[j]):
                raise SolverError("the coupled Newton iteration reached an iterate where no node can "
                                  f"stick (friction bound zero everywhere; merit θ = {self.merits[-1]:.3e})",
                                  method=self.meth.name, status="degenerate", iterations=it, residual=nrm)
            self.z[S.iQ] += np.sign(u[j]) * excess[j] / S.KT[j, S.iQ]
            self.refresh()
            contact, stick, slip_sign, _ = coupled_cases(p, t, self.yN, self.yT, mu)
            stick[j] = True
            slip_sign[j] = 0.0
            self.shifts += 1
        return contact, stick, slip_sign

    def direction(self, cases, it, nrm):
        """``(d, K_N d, K_T d)`` with ``J d = −Φ`` (eq. 80), on the reused factors or directly."""
        S = self.S
        if self.meth.coupled_reuse:  # reduced system, LU reused across iterations and steps
            out = self.factors.direction(*cases, self.mu, self.phi)
            d, dN, dT = out if out is not None else (None, None, None)
        else:  # the direct path (reference): a new reduced system every iteration
            d = linear.direct_coupled_direction(S, *cases, self.mu, self.phi)
            dN = dT = None
            if d is not None:
                dN, dT = S.KN @ d, S.KT @ d
        if d is None or not np.all(np.isfinite(d)):
            raise SolverError("the coupled Newton matrix is singular",
                              method=self.meth.name, status="singular", iterations=it, residual=nrm)
        return d, dN, dT

    def line_search(self, d, dN, dT):
        """Armijo (eq. 75–78, ``s = 1``); ``0`` when it fails below :data:`ALPHA_MIN`."""
        n = self.n
        rho, two_sigma = self.meth.rho, 2.0 * self.meth.sigma
        dp, dt = d[:n], d[n:2 * n]
        theta = self.merits[-1]
        alpha = 1.0
        while True:
            pa = self.residual(self.p + alpha * dp, self.t + alpha * dt, self.yN + alpha * dN, self.yT + alpha * dT)
            if 0.5 * float(pa @ pa) <= (1.0 - two_sigma * alpha) * theta:
                return alpha
            alpha *= rho
            self.backtracks += 1
            if alpha < ALPHA_MIN:
                return 0.0

    def sweep(self):
        """One N–T sweep from ``z`` (the fallback when Armijo fails); returns the new ``z``."""
        pb, S, n, sc, z = self.pb, self.S, self.n, self.pb.scales, self.z
        warm = StepSolution(p=z[:n] * sc.stress, t=z[n:2 * n] * sc.stress,
                            delta=z[S.iP] * sc.displacement if S.iP is not None else pb.delta,
                            xi=z[S.iQ] * sc.slip if S.iQ is not None else pb.xi)
        nsol, tsol = sweep(self.meth, pb, warm.t, warm, warm)
        out = z.copy()
        out[:n], out[n:2 * n] = nsol.p / sc.stress, tsol.t / sc.stress
        if S.iP is not None:
            out[S.iP] = nsol.delta / sc.displacement
        if S.iQ is not None:
            out[S.iQ] = tsol.xi / sc.slip
        return out


def solve_coupled(meth, pb, warm, t0):
    """GNMls on the coupled step (module docstring); the :class:`~rollqp.problem.StepSolution`."""
    st = _Coupled(meth, pb, warm)
    S, factors = st.S, st.factors
    counts = (factors.factorizations, factors.updates)
    stop = meth.tolerance * min(1.0, S.rN, S.rT)
    it = tightened = 0
    while True:
        nrm = float(np.max(np.abs(st.phi)))
        st.history.append(nrm)
        st.merits.append(0.5 * float(st.phi @ st.phi))
        if nrm <= stop:
            sol = st.solution()
            if sol.residual <= meth.tolerance or tightened >= 3:
                break
            stop *= 0.1  # the bound μ max(0, p − r g) differs from μ p⁺ off the solution
            tightened += 1
            st.history.pop()
            st.merits.pop()
            continue
        if it >= meth.max_iterations:
            raise not_converged(meth, "coupled", st.merits, it, nrm, stop)
        it += 1
        d, dN, dT = st.direction(st.cases(it, nrm), it, nrm)
        alpha = st.line_search(d, dN, dT)
        if alpha == 0.0:
            # Armijo failed: the direction is not a descent direction (a node on a kink where the
            # modified row is not the directional derivative). Taking the full step anyway can
            # cycle (measured: μ = 0.03, Goodman loading). Instead take one N–T sweep of the
            # halves from here — each half is a monotone problem solved by its own GNMls — and
            # resume the coupled iteration from its result.
            st.sweeps += 1
            st.steps.append(0.0)
            st.set(st.sweep())
        else:
            st.steps.append(alpha)
            st.set(st.z + alpha * d)  # eq. 79
    info = {"r": (S.rN, S.rT), "backtracks": st.backtracks, "merit": st.merits[-1], "history": st.history,
            "merits": st.merits, "steps": st.steps, "nonmonotone": st.sweeps, "sweeps": st.sweeps,
            "shifts": st.shifts, "tolerance_phi": stop, "start": st.start}
    if meth.coupled_reuse:
        info["factorizations"] = factors.factorizations - counts[0]
        info["updates"] = factors.updates - counts[1]
    return meth.finish(sol, it, info, t0)
