r"""GNMls on the tangential step with a slip-dependent bound ``b_i = μ_i(s_i) p̂_i⁺`` (docs/theory.md, "Slip-dependent friction").

The rows are those of eq. 60 with the bound now a function of the unknowns through the slip:

.. math::
    \Phi_i = \hat t_i - \mathrm{Proj}_{[-b_i(\hat s), b_i(\hat s)]}(\hat t_i - r \hat s_i),\qquad
    b_i = \mu_i(s_i)\,\hat p_i^+ ,

and the pseudo-Jacobian keeps the node cases of eq. 85–88 with one change, at slipping nodes
(eq. 88 with ``b`` no longer fixed; docs/formulation.md §13, "eq. 88s")::

    stick (eq. 86/87):  ∂(r ŝ_i)
    zero bound (eq. 85): e_{t,i}
    slip (eq. 88s):     e_{t,i} − σ_i (∂b_i/∂(r ŝ_i)) ∂(r ŝ_i),   σ_i = sgn(t̂_i − r ŝ_i),
                        ∂b_i/∂(r ŝ_i) = p̂_i⁺ μ_i'(s_i) (p0/E*) / r

(``μ'`` from :meth:`~rollqp.friction.bound.SlipBound.dmu`). With ``μ' = 0`` the slip row is the
identity row of eq. 88 and the iteration is the constant-bound one. The slip rows are no longer
identity rows, so the reduced system of :mod:`.linear` does not apply: ``J`` is formed and solved
densely (``n`` is at most a few hundred nodes on the meshes this law is used with). Armijo line
search as in :mod:`.uncoupled` (eq. 75–79); a failed search takes the full step
(``info["nonmonotone"]``). Falling friction can make the step non-unique (docs/theory.md): the
iteration finds the solution its start leads to — the previous step's, else zero shear.
"""
from __future__ import annotations

import numpy as np

from ...errors import SolverError
from ...problem import friction_residual
from .common import ALPHA_MIN, not_converged

__all__ = ["solve_slip"]


class _SlipRows:
    """``Φ`` and the pseudo-Jacobian of the slip-dependent tangential step at one iterate."""

    def __init__(self, pb, sys_, with_load, load, k0):
        sc = pb.scales
        self.pb, self.sys, self.n, self.r = pb, sys_, pb.n, sys_.r
        self.K = sys_.matrices(with_load)
        self.k0, self.load, self.with_load = k0, load, with_load
        self.phat = np.maximum(pb.p, 0.0) / sc.stress
        self.slip_unit = sc.slip

    def at(self, z):
        """``(x, y, s, b, Φ)`` at ``z``: traction, ``r ŝ``, physical slip, bound, residual."""
        n = self.n
        x, y = z[:n], self.K @ z + self.k0
        s = y / self.r * self.slip_unit
        b = self.pb.law.mu(s) * self.phat
        phi = friction_residual(x, y, b)
        if self.with_load:
            phi = np.append(phi, self.sys.fhat @ x - self.load)
        return x, y, s, b, phi

    def jacobian(self, x, y, s, b):
        """The pseudo-Jacobian (module docstring: eq. 85, 86/87, 88s)."""
        n, K = self.n, self.K
        N = K.shape[1]
        u = x - y
        zero = b <= 0.0
        stick = (np.abs(u) <= b) & ~zero
        slip = ~stick & ~zero
        J = np.zeros((N, N))
        J[:n] = np.eye(n, N)
        ist = np.flatnonzero(stick)
        J[ist] = K[ist]
        db = self.phat * self.pb.law.dmu(s) * self.slip_unit / self.r  # ∂b/∂(r ŝ)
        isl = np.flatnonzero(slip)
        J[isl] -= (np.sign(u[isl]) * db[isl])[:, None] * K[isl]
        if self.with_load:
            J[n, :n] = self.sys.fhat
        return J, stick


def solve_slip(meth, pb, warm, t0):
    """GNMls on the slip-dependent tangential step (module docstring); ``meth`` is the Newton method."""
    sc = pb.scales
    dqh = pb.dq / sc.length
    sys_ = meth.system(pb, dqh)
    n, r = pb.n, sys_.r
    with_load = pb.Q is not None
    xi_fixed = None if with_load else pb.xi / sc.slip
    k0 = r * (pb.c / sc.displacement / dqh + (xi_fixed if xi_fixed is not None else 0.0))
    rows = _SlipRows(pb, sys_, with_load, pb.Q / sc.force if with_load else None, k0)
    t, xi0, start = np.zeros(n), 0.0, "cold"
    if warm is not None and warm.t is not None and np.shape(warm.t) == (n,):
        t, start = np.asarray(warm.t, dtype=float) / sc.stress, "warm"
        xi0 = warm.xi / sc.slip if warm.xi is not None else 0.0
    z = np.append(t, xi0) if with_load else t.copy()
    z, it, info = _iterate(meth, pb, rows, z)
    info["start"] = start
    tt = z[:n] * sc.stress
    xi = z[n] * sc.slip if with_load else pb.xi
    return meth.finish(pb.solution(tt, xi), it, info, t0)


def _iterate(meth, pb, rows, z):
    """Newton directions on the dense pseudo-Jacobian with the Armijo search (eq. 74–79)."""
    stop = meth.tolerance * min(1.0, rows.r)
    x, y, s, b, phi = rows.at(z)
    history, merits, steps = [], [], []
    backtracks = nonmono = it = 0
    while True:
        nrm = float(np.max(np.abs(phi)))
        history.append(nrm)
        merits.append(0.5 * float(phi @ phi))
        if nrm <= stop:
            break
        if it >= meth.max_iterations:
            raise not_converged(meth, "slip-dependent tangential", merits, it, nrm, stop)
        it += 1
        J, _ = rows.jacobian(x, y, s, b)
        try:
            d = np.linalg.solve(J, -phi)
        except np.linalg.LinAlgError:
            d = None
        if d is None or not np.all(np.isfinite(d)):
            raise SolverError("the slip-dependent tangential Newton matrix is singular", method=meth.name,
                              status="singular", iterations=it, residual=nrm)
        alpha = 1.0
        while True:
            cand = rows.at(z + alpha * d)
            if 0.5 * float(cand[4] @ cand[4]) <= (1.0 - 2.0 * meth.sigma * alpha) * merits[-1]:
                break
            alpha *= meth.rho
            backtracks += 1
            if alpha < ALPHA_MIN:
                alpha, nonmono = 1.0, nonmono + 1
                cand = rows.at(z + d)
                break
        steps.append(alpha)
        z = z + alpha * d
        x, y, s, b, phi = cand
    info = {"r": rows.r, "backtracks": backtracks, "merit": merits[-1], "history": history, "merits": merits,
            "steps": steps, "nonmonotone": nonmono, "shifts": 0, "tolerance_phi": stop, "dense": True}
    return z, it, info
