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
search as in :mod:`.uncoupled` (eq. 75–79).

**The degenerate iterate, and why it matters more here.** With ``Q`` prescribed the load row
``f̂ᵀt̂ = Q̂`` reaches ``ξ̂`` only through the rows of sticking nodes (``∂(r ŝ_i)/∂ξ̂ = r``). At an
iterate where no node sticks, a constant bound leaves the ``ξ̂`` column empty and the constant path
repairs it (the nearest node onto its kink, package docstring). With a falling law the column is
not empty but holds only ``σ_i ∂b_i/∂(r ŝ_i) r`` of the slipping nodes, small wherever ``μ`` is
flat: the Newton direction then moves ``ξ̂`` by ``(load residual)/(that small number)`` — it asks
the linearized law to carry the load below ``μ_k`` — and throws the iterate into gross sliding,
where ``μ' → 0``, ``J`` becomes singular and the merit ``θ`` has a valley at infinity
(``θ → ½(f̂ᵀμ_k p̂ − Q̂)²``). Measured on a ramped transient (rational law, ``v_h = 3 mm/s``,
``V = 10 m/s``): the warm start of step 21 had every node slipping, ``ξ̂`` went −1.2 → −12 → −607
→ −1.8e6 and the matrix became singular. So the repair is the constant path's, on the slip law's
bound: ``ξ̂`` shifted until the node nearest to sticking reaches its kink, and that node gets the
stick row (``info["shifts"]``).

**When the Newton iteration still fails** (a singular matrix, or an Armijo search that finds no
decrease: the direction of a non-monotone law need not descend on a kink), the step is not
given up: :func:`~.slip_step.solve_slip_step` runs the fixed point on the bound
(:class:`~rollqp.methods.fixedpoint.BoundFixedPoint`) with Newton's own constant-bound solves as
its inner method, trying this iteration from each fixed-point iterate that improved (a few
iterations from near a solution, quadratic), then a cold start, then the creepage search. A step
none of them solves is a :class:`~rollqp.errors.SolverError` naming the residual.

**Which solution.** Falling friction can make the step non-unique (docs/theory.md). A solution is
taken as it is found only if the falling law makes none of its modes unstable
(:func:`unstable_modes`: no real eigenvalue ``<= 0`` of ``J_f⁻¹ J``, ``J_f`` the pseudo-Jacobian with the
bound frozen) — the solution lies on the branch that grows continuously from the frozen bound as the
law's slope is switched on, the only kind the fixed point on the bound can converge to (it contracts
only where the spectral radius of its map is below 1, and ``J_f⁻¹ J = I − (that map's derivative)`` on
the slipping nodes). Measured on a ramped transient (exponential law, ``v_h = 10`` mm/s, ``V = 10``
m/s, step 43): the warm Newton iteration converged to a solution with one unstable mode, 0.19 μ_s p0
from the previous state; the fixed point's, 0.15 away, has none, and is the one now returned. A
solution with unstable modes is returned only when no attempt finds another (``info["unstable"]``).
Steeper laws can have several stable solutions of one step; then the first attempt that finds one
decides (docs/friction.md, "Newton against the QP fixed point over the velocity scale").
"""
from __future__ import annotations

import numpy as np

from ...errors import SolverError
from ...problem import friction_residual
from .common import ALPHA_MIN, not_converged

__all__ = ["solve_slip", "unstable_modes", "POLISH_ITERATIONS", "FIXED_POINT_WINDOW"]

#: Newton iterations allowed when polishing a fixed-point iterate (quadratic convergence from near a
#: solution takes a handful; more means the iterate is not near enough yet).
POLISH_ITERATIONS = 25
#: An iteration whose merit fell by less than 10 % over its last ``STALL_ITERATIONS`` iterations stalls (short
#: steps on a kink of a non-monotone law, measured on CONTACT's problem at 45 m/s: θ 4.8e-4 → 4.3e-4 over
#: 150 iterations, 2.3 s, where the fixed point then solved the step in 0.02 s): the next attempt is taken.
STALL_ITERATIONS = 10
STALL_DECREASE = 0.9
#: The fixed point inside the step is given up when its best residual over this many iterations is not 10 %
#: below the best before them (the map does not contract there; a cold start and the creepage search remain).
FIXED_POINT_WINDOW = 20


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

    def stick(self, x, y, b):
        """Nodes in stick (eq. 86/87: ``|t̂ − r ŝ| <= b``, ``b > 0``)."""
        return (np.abs(x - y) <= b) & (b > 0.0)

    def jacobian(self, x, y, s, b, stick):
        """The pseudo-Jacobian (module docstring: eq. 85, 86/87, 88s) with the stick nodes ``stick``."""
        n, K = self.n, self.K
        N = K.shape[1]
        u = x - y
        slip = ~stick & (b > 0.0)
        J = np.zeros((N, N))
        J[:n] = np.eye(n, N)
        ist = np.flatnonzero(stick)
        J[ist] = K[ist]
        db = self.phat * self.pb.law.dmu(s) * self.slip_unit / self.r  # ∂b/∂(r ŝ)
        isl = np.flatnonzero(slip)
        J[isl] -= (np.sign(u[isl]) * db[isl])[:, None] * K[isl]
        if self.with_load:
            J[n, :n] = self.sys.fhat
        return J

    def repair(self, z, x, y, b):
        """No node sticks while the load row is there (module docstring): ``ξ̂`` shifted so that the node
        nearest to sticking reaches its kink ``|t̂ − r ŝ| = b``. Returns ``(z, j)``, or ``(z, None)`` if
        every bound is zero. The bound moves with the slip, so the kink is found by a few secant
        steps on ``|u_j| − b_j`` in the shift (exact for a constant bound: one step)."""
        n = self.n
        excess = np.abs(x - y) - b
        excess[b <= 0.0] = np.inf
        j = int(np.argmin(excess))
        if not np.isfinite(excess[j]):
            return z, None
        col = self.K[j, n]  # ∂(r ŝ_j)/∂ξ̂
        z = z.copy()
        for _ in range(8):
            u = x[j] - y[j]
            gap = abs(u) - b[j]
            if gap <= 0.0:
                break
            z[n] += np.sign(u) * gap / col  # y_j moves towards x_j by the excess at the current bound
            _, y, _, b, _ = self.at(z)
        return z, j


def solve_slip(meth, pb, warm, t0, max_iterations=None, stall=True):
    """GNMls on the slip-dependent tangential step (module docstring) from ``warm`` (else zero shear).

    ``meth`` is the Newton method; ``max_iterations`` (default the method's) bounds the iterations; ``stall``:
    give up an iteration that stalls (:data:`STALL_ITERATIONS`; the last attempt of a step runs to the limit).
    Raises :class:`~rollqp.errors.SolverError` on a singular matrix, a failed search or the limit."""
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
    z, it, info = _iterate(meth, pb, rows, z, meth.max_iterations if max_iterations is None else max_iterations, stall)
    info["start"] = start
    tt = z[:n] * sc.stress
    xi = z[n] * sc.slip if with_load else pb.xi
    return meth.finish(pb.solution(tt, xi), it, info, t0)


def _iterate(meth, pb, rows, z, max_iterations, stall=True):
    """Newton directions on the dense pseudo-Jacobian with the Armijo search (eq. 74–79)."""
    stop = meth.tolerance * min(1.0, rows.r)
    x, y, s, b, phi = rows.at(z)
    history, merits, steps = [], [], []
    backtracks = shifts = it = 0
    while True:
        nrm = float(np.max(np.abs(phi)))
        history.append(nrm)
        merits.append(0.5 * float(phi @ phi))
        if nrm <= stop:
            break
        if it >= max_iterations:
            raise not_converged(meth, "slip-dependent tangential", merits, it, nrm, stop)
        if stall and it >= STALL_ITERATIONS and merits[-1] > STALL_DECREASE * merits[-1 - STALL_ITERATIONS]:
            raise SolverError(f"the slip-dependent tangential Newton iteration stalls: merit θ = {merits[-1]:.3e}, "
                              f"{merits[-1 - STALL_ITERATIONS]:.3e} {STALL_ITERATIONS} iterations before",
                              method=meth.name, status="stalled", iterations=it, residual=nrm)
        it += 1
        stick = rows.stick(x, y, b)
        if rows.with_load and not stick.any():  # the degenerate iterate (module docstring)
            z, j = rows.repair(z, x, y, b)
            if j is not None:
                x, y, s, b, phi = rows.at(z)
                stick = rows.stick(x, y, b)
                stick[j] = True
                shifts += 1
        d = _direction(rows.jacobian(x, y, s, b, stick), phi)
        if d is None:
            raise SolverError("the slip-dependent tangential Newton matrix is singular", method=meth.name,
                              status="singular", iterations=it, residual=nrm)
        theta = 0.5 * float(phi @ phi)
        alpha = 1.0
        while True:
            cand = rows.at(z + alpha * d)
            if 0.5 * float(cand[4] @ cand[4]) <= (1.0 - 2.0 * meth.sigma * alpha) * theta:
                break
            alpha *= meth.rho
            backtracks += 1
            if alpha < ALPHA_MIN:  # no decrease along the direction: not a descent direction here
                raise SolverError(f"the slip-dependent tangential Newton line search found no decrease "
                                  f"(merit θ = {theta:.3e})", method=meth.name, status="line search",
                                  iterations=it, residual=nrm)
        steps.append(alpha)
        z = z + alpha * d
        x, y, s, b, phi = cand
    info = {"r": rows.r, "backtracks": backtracks, "merit": merits[-1], "history": history, "merits": merits,
            "steps": steps, "nonmonotone": 0, "shifts": shifts, "tolerance_phi": stop, "dense": True}
    return z, it, info


def _direction(J, phi):
    """``d = −J⁻¹Φ``, or None if ``J`` is singular or the direction not finite."""
    try:
        d = np.linalg.solve(J, -phi)
    except np.linalg.LinAlgError:
        return None
    return d if np.isfinite(d).all() else None


def _rows(meth, pb):
    """:class:`_SlipRows` of ``pb`` and the unknowns ``z`` of a solution of it (``z(sol)``)."""
    sc = pb.scales
    dqh = pb.dq / sc.length
    sys_ = meth.system(pb, dqh)
    with_load = pb.Q is not None
    xi_fixed = None if with_load else pb.xi / sc.slip
    k0 = sys_.r * (pb.c / sc.displacement / dqh + (xi_fixed if xi_fixed is not None else 0.0))
    rows = _SlipRows(pb, sys_, with_load, pb.Q / sc.force if with_load else None, k0)

    def z(sol):
        t = np.asarray(sol.t, dtype=float) / sc.stress
        return np.append(t, sol.xi / sc.slip) if with_load else t
    return rows, z


def unstable_modes(meth, pb, sol) -> int:
    r"""How many modes of the solution ``sol`` the falling law makes unstable: the real eigenvalues ``<= 0`` of
    ``J_f⁻¹ J`` (module docstring, "Which solution").

    ``J`` is the pseudo-Jacobian at ``sol`` (eq. 88s) and ``J_f`` the same with the bound frozen (``μ' = 0``:
    the slip rows identity rows). Along the homotopy ``J(λ) = J_f + λ (J − J_f)`` from the frozen bound
    (``λ = 0``) to the law (``λ = 1``), ``det J(λ) = det J_f ∏ (1 + λ(e_i − 1))`` vanishes for some
    ``λ ∈ (0, 1]`` exactly when an eigenvalue ``e_i`` of ``J_f⁻¹ J`` is real and ``<= 0``: the solution then
    lies past a fold of the branch that grows from the frozen bound as the law's slope is switched on.
    ``J − J_f`` is nonzero on the slipping rows only, so the nontrivial ``e_i`` are ``1 + eig(C J_f⁻¹ E)``
    (``C`` those rows of ``J − J_f``, ``E`` their unit columns): an ``m × m`` eigenproblem, ``m`` the
    slipping nodes. 0 when no node slips, the law is flat there, or ``J_f`` is singular (no node sticks with
    the load row: the frozen step is degenerate and tells nothing)."""
    rows, z = _rows(meth, pb)
    x, y, s, b, _ = rows.at(z(sol))
    stick = rows.stick(x, y, b)
    isl = np.flatnonzero(~stick & (b > 0.0))
    if isl.size == 0 or (rows.with_load and not stick.any()):
        return 0
    J = rows.jacobian(x, y, s, b, stick)
    N = J.shape[1]
    C = J[isl] - np.eye(rows.n, N)[isl]
    if not np.any(C):
        return 0
    Jf = J.copy()
    Jf[isl] = np.eye(rows.n, N)[isl]
    E = np.zeros((N, isl.size))
    E[isl, np.arange(isl.size)] = 1.0
    try:
        X = np.linalg.solve(Jf, E)
    except np.linalg.LinAlgError:
        return 0
    e = 1.0 + np.linalg.eigvals(C @ X)
    real = np.abs(e.imag) <= 1e-12 * np.maximum(1.0, np.abs(e.real))
    return int(np.count_nonzero(real & (e.real <= 0.0)))
