r"""Active-set refinement of a conic solver's answer: its own KKT system on the active set it found
(docs/theory3d.md §5; the 3D counterpart of the 2D QPs' :func:`~rollqp.methods._qp.active_set_refine`).

An interior-point method stops with every complementary pair small but not zero: an element at the
edge of the contact (of the stick area) keeps both its slack and its multiplier near ``√gap``, so
Clarabel's pressures and tractions stop near 1e-8–1e-9 of ``p0`` (``μp0``) however tight its gap
tolerance. The KKT conditions of the convex programs, with the active set held at the one the solver
identified, are smooth equations; a few Newton iterations on them take the answer to round-off —
OSQP's *polishing* (Stellato et al., Math. Prog. Comp. 12 (2020) §5) carried to the cone. The
caller keeps the result only if rollqp's residual of it is smaller than that of the solver's own
answer, and keeps the raw answer beside it (``info["raw"]``), so the distance of the solver's own
answer from any other method stays visible.

**The active set** is read off the answer as the complementarity functions read it (eq. 3D.25 at
``r = 1``): element ``i`` is in contact where ``p̂_i > ĝ_i`` (else ``p_i = 0``); it slips where
``|t̂_i − ŝ_i| > b̂_i`` (the disc constraint active), else it sticks.

**Normal QP** (eq. 3D.22) on the contact set ``F``: ``Â_FF p̂_F − δ̂ = −ĥ_F`` and ``â Σ p̂_F = F̂_N`` —
one linear solve (Cholesky of ``Â_FF``, positive definite, and the Schur complement of the load row).

**Tangential SOCP** (eq. 3D.20) on the stick set ``S`` and slip set ``L``: the KKT conditions are
``ŝ_i = 0`` (``i ∈ S``: the gradient vanishes inside the cone) and ``ŝ_i = −λ_i t̂_i``, ``|t̂_i| = b̂_i``
(``i ∈ L``: on the cone's boundary, the gradient along the outward normal), with the load rows;
eliminating ``λ_i``:

.. math::
    \hat s_i = 0\ (i\in S),\qquad
    \hat t_{x,i}\hat s_{y,i} − \hat t_{y,i}\hat s_{x,i} = 0,\ \ \tfrac12(|\hat t_i|^2 − \hat b_i^2) = 0\ (i\in L),
    \qquad \hat a\textstyle\sum\hat t_j = \hat F_j                                      \qquad (3D.23)

smooth in ``(t̂, ξ̂, η̂)``; Newton's method on it from the solver's answer (the slip elements' tractions
put on their circles first). The sign ``λ_i ≥ 0`` (friction opposes the slip) is not imposed: a wrong
active set shows in rollqp's residual, and the refinement is then not kept.
"""
from __future__ import annotations

import warnings

import numpy as np
import scipy.linalg as sla

__all__ = ["active_set_refine", "REFINE_ITERATIONS"]

#: Newton iterations on eq. 3D.23: from an interior-point answer with the right active set they converge
#: quadratically from ~1e-8 to round-off in 2–3 (measured); more means the active set is wrong.
REFINE_ITERATIONS = 8
#: Stop once the scaled equations are this small (round-off of the dense products of order-one numbers).
REFINE_TARGET = 1e-14


def active_set_refine(problem, solution):
    """The solution of the conic program's KKT system on the active set of ``solution`` (module
    docstring), as a solution of ``problem`` with rollqp's residuals; ``None`` if the reduced system is
    singular or the active set is empty."""
    if problem.kind == "normal":
        return _refine_normal(problem, solution)
    return _refine_tangential(problem, solution)


def _refine_normal(problem, sol):
    sc = problem.scales
    s = sc.modulus / sc.length
    ph, gh = sol.p / sc.stress, sol.g / sc.displacement
    F = np.flatnonzero(ph > gh)
    if F.size == 0:
        return None
    hh = problem.h_total / sc.displacement
    try:
        chol = sla.cho_factor(s * problem.A.dense(F, F), lower=False, check_finite=False)
    except (np.linalg.LinAlgError, ValueError):
        return None
    v = sla.cho_solve(chol, -hh[F], check_finite=False)          # Â_FF p̂ = −ĥ_F + δ̂ 1
    u = sla.cho_solve(chol, np.ones(F.size), check_finite=False)
    if problem.delta is not None:
        dh = problem.delta / sc.displacement
    else:
        ah = problem.area / sc.length ** 2
        dh = (problem.FN / sc.force / ah - v.sum()) / u.sum()
    p = np.zeros(problem.n)
    p[F] = (v + dh * u) * sc.stress
    if not np.all(np.isfinite(p)):
        return None
    return problem.solution(p, dh * sc.displacement, method=sol.method, iterations=1)


class _Kkt:
    """Eq. 3D.23 on the elements ``V`` of positive bound, stick set ``S``/slip set ``L`` fixed."""

    def __init__(self, problem, sol):
        sc = problem.scales
        self.problem, self.sc = problem, sc
        self.k = sc.modulus / problem.dq
        xi0 = problem.xi if problem.xi is not None else 0.0
        eta0 = problem.eta if problem.eta is not None else 0.0
        w = np.stack([xi0 - problem.phi * problem.y, eta0 + problem.phi * problem.x])
        self.V = V = np.flatnonzero(problem.bound > 0)
        self.nv = V.size
        self.s0 = ((w + problem.c / problem.dq) / sc.slip)[:, V]
        self.bh = problem.bound[V] / sc.stress
        self.ah = problem.area / sc.length ** 2
        self.free = [j for j, F in enumerate((problem.Fx, problem.Fy)) if F is not None]
        self.targets = [(problem.Fx, problem.Fy)[j] / sc.force for j in self.free]
        self.S = self.k * problem.B.memo(("dense", V.tobytes()), lambda: problem.B.dense(V, V))
        z = sol.t[:, V] / sc.stress - sol.s[:, V] / sc.slip
        self.slip = np.hypot(z[0], z[1]) > self.bh

    def start(self, sol):
        t = sol.t[:, self.V] / self.sc.stress
        norm = np.hypot(t[0], t[1])
        on = self.slip & (norm > 0)
        t[:, on] *= self.bh[on] / norm[on]
        zeta = np.array([(sol.xi, sol.eta)[j] / self.sc.slip for j in self.free])
        return np.concatenate([t.ravel(), zeta])

    def slips(self, x):
        nv = self.nv
        t = x[:2 * nv].reshape(2, nv)
        s = self.s0 + (self.S @ x[:2 * nv]).reshape(2, nv)
        for i, j in enumerate(self.free):
            s[j] += x[2 * nv + i]
        return t, s

    def equations(self, x):
        t, s = self.slips(x)
        L = self.slip
        ex = np.where(L, t[0] * s[1] - t[1] * s[0], s[0])
        ey = np.where(L, 0.5 * (t[0] ** 2 + t[1] ** 2 - self.bh ** 2), s[1])
        loads = [self.ah * t[j].sum() - F for j, F in zip(self.free, self.targets)]
        return np.concatenate([ex, ey, loads])

    def jacobian(self, x):
        nv, nf = self.nv, len(self.free)
        t, s = self.slips(x)
        ds = np.hstack([self.S, np.zeros((2 * nv, nf))])     # ∂ŝ/∂(t̂, ζ)
        for i, j in enumerate(self.free):
            ds[j * nv:(j + 1) * nv, 2 * nv + i] = 1.0
        dsx, dsy = ds[:nv], ds[nv:]
        L = self.slip[:, None]
        i = np.arange(nv)
        cross = t[0][:, None] * dsy - t[1][:, None] * dsx      # t_x ∂s_y − t_y ∂s_x …
        cross[i, i] += s[1]                                     # … + s_y ∂t_x
        cross[i, nv + i] -= s[0]                                # … − s_x ∂t_y
        circle = np.zeros_like(dsx)
        circle[i, i], circle[i, nv + i] = t[0], t[1]
        Jx = np.where(L, cross, dsx)
        Jy = np.where(L, circle, dsy)
        rows = [Jx, Jy]
        for j in self.free:
            row = np.zeros(2 * nv + nf)
            row[j * nv:(j + 1) * nv] = self.ah
            rows.append(row[None, :])
        return np.vstack(rows)


def _refine_tangential(problem, sol):
    sys = _Kkt(problem, sol)
    if sys.nv == 0:
        return None
    x = sys.start(sol)
    f = sys.equations(x)
    it = 0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", sla.LinAlgWarning)
        while it < REFINE_ITERATIONS and np.max(np.abs(f)) > REFINE_TARGET:
            try:
                d = sla.lu_solve(sla.lu_factor(sys.jacobian(x), check_finite=False), -f, check_finite=False)
            except (np.linalg.LinAlgError, ValueError):
                return None
            if not np.all(np.isfinite(d)):
                return None
            x, it = x + d, it + 1
            f = sys.equations(x)
    sc, nv, V = sys.sc, sys.nv, sys.V
    t = np.zeros((2, problem.n))
    t[:, V] = x[:2 * nv].reshape(2, nv) * sc.stress
    crp = {j: x[2 * nv + i] * sc.slip for i, j in enumerate(sys.free)}
    return problem.solution(t, crp.get(0), crp.get(1), method=sol.method, iterations=it)
