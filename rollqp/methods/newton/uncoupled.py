r"""GNMls on the uncoupled step problems: the normal step (eq. 53) and the tangential step (eq. 61/62).

Steps 1–7 of the paper's §4 on ``Φ(z) = [φ(x, y); f̂ᵀx − load]`` with ``y = K z + k0`` linear in
``z`` (the "halved system": ``g`` and ``s`` eliminated): the start (Step 1: the previous step, else
a Hertz-like profile or zero shear), the direction on the reduced system (eq. 80,
:class:`~.linear.ReducedSystem`), the Armijo line search (eq. 75–79), the repair of degenerate
iterates. The creepage search that rescues a tangential step with ``Q`` prescribed is :mod:`.creepage`. The node
rows ``φ`` and their cases (eq. 82–88) are :mod:`.ncp`'s.
"""
from __future__ import annotations

import math

import numpy as np

from ...errors import SolverError
from .common import ALPHA_MIN, Stalled, not_converged  # noqa: F401 - re-exported
from .linear import partial_product
from .ncp import NormalNCP, TangentialNCP

__all__ = ["ALPHA_MIN", "Stalled", "not_converged", "solve_uncoupled", "solve_normal", "solve_tangential"]

def solve_uncoupled(meth, problem, warm, t0):
    """A normal or tangential step; a warm start that stalls is restarted once cold."""
    solve = solve_normal if problem.kind == "normal" else solve_tangential
    try:
        return solve(meth, problem, warm, t0)
    except Stalled:
        # the warm start led to a Newton fixed point that is not a solution (a wrong
        # active set that the Newton step reproduces): restart once from the cold start
        sol = solve(meth, problem, None, t0)
        sol.info["restarts"] = 1
        return sol


# ------------------------------------------------------------------------------ the two kinds
def _normal_start(pb, sys_, warm):
    """Step 1 of the normal step: ``(z, start)`` from the previous pressure and approach, else a
    Hertz-like profile scaled to the load (or to close the gap at a prescribed approach)."""
    sc = pb.scales
    u0 = sc.displacement
    n = pb.n
    hhat = pb.h_total / u0
    with_load = pb.P is not None
    Phat = pb.P / sc.force if with_load else None
    dhat_fixed = None if with_load else pb.delta / u0
    start = "cold"
    p0 = None
    if warm is not None and warm.p is not None and np.shape(warm.p) == (n,):
        p0, start = np.asarray(warm.p, dtype=float) / sc.stress, "warm"
    if p0 is None:
        # ĥ = x̂² for two cylinders in Hertz units: p̂ = √(1 − x̂²) is the Hertz solution
        p0 = np.sqrt(np.maximum(0.0, 1.0 - (hhat - hhat.min())))
    guess = p0 > 0
    if not guess.any():
        guess = hhat == hhat.min()
    if with_load:
        if start == "cold" and sys_.fhat @ p0 > 0:
            p0 = p0 * (Phat / (sys_.fhat @ p0))
        if start == "warm" and warm.delta is not None:
            d0 = warm.delta / u0
        else:  # the approach that closes the gap on average over the guessed contact
            d0 = float(np.mean((hhat + sys_.ahat_product(p0))[guess]))
        return np.append(p0, d0), start
    if start == "cold":  # scale the profile to close the gap on average over it
        Ap = sys_.ahat_product(p0)[guess].mean()
        c = (dhat_fixed - hhat[guess].mean()) / Ap if Ap > 0 else 0.0
        p0 = p0 * max(c, 0.0)
    return p0.copy(), start


def solve_normal(meth, pb, warm, t0):
    """GNMls on the normal step ``min(p̂, r ĝ) = 0``, ``f̂ᵀp̂ = P̂`` (eq. 52–53, 67)."""
    sc = pb.scales
    u0 = sc.displacement
    sys_ = meth.system(pb, None)
    n, r = pb.n, sys_.r
    hhat = pb.h_total / u0
    with_load = pb.P is not None
    Phat = pb.P / sc.force if with_load else None
    dhat_fixed = None if with_load else pb.delta / u0
    z, start = _normal_start(pb, sys_, warm)
    k0 = r * (hhat - (dhat_fixed if dhat_fixed is not None else 0.0))
    known = _last_product(sys_, warm.p if start == "warm" else None)
    z, it, info, (p, Ap, *_), _, _ = iterate(meth, pb, sys_, z, k0, Phat, NormalNCP(), start == "warm", known)
    delta = z[n] * u0 if with_load else pb.delta
    info["start"] = start
    sol = pb.solution(p, delta, Ap=Ap)
    sys_.last = (sol.p, Ap)
    return meth.finish(sol, it, info, t0)


def solve_tangential(meth, pb, warm, t0):
    """GNMls on the tangential step ``t̂ = Proj_[−b, b](t̂ − r ŝ)``, ``f̂ᵀt̂ = Q̂`` (eq. 60–62, 67)."""
    sc = pb.scales
    dqh = pb.dq / sc.length
    sys_ = meth.system(pb, dqh)
    n, r = pb.n, sys_.r
    with_load = pb.Q is not None
    Qhat = pb.Q / sc.force if with_load else None
    xi_fixed = None if with_load else pb.xi / sc.slip
    z = np.zeros(n + 1 if with_load else n)  # (t̂, ξ̂) or t̂: the start, Step 1
    start = "cold"
    if warm is not None and warm.t is not None and _has_shape(warm.t, n):
        np.divide(warm.t, sc.stress, out=z[:n])
        start = "warm"
        if warm.xi is not None and with_load:
            z[n] = warm.xi / sc.slip
    k0 = pb.c * (r / (sc.displacement * dqh))  # r ĉ/Δq̂ (+ r ξ̂ prescribed)
    if xi_fixed is not None:
        k0 += r * xi_fixed
    known = _last_product(sys_, warm.t if start == "warm" else None)
    z, it, info, product, y, phi = iterate(meth, pb, sys_, z, k0, Qhat, _friction_rows(sys_, pb), start == "warm", known)
    tt, At = product[0], product[1]
    xi = z[n] * sc.slip if with_load else pb.xi
    info["start"] = start
    # the slip and rollqp's residuals from the last iterate's own y = r ŝ and load row (TangentialStep.solution)
    sol = pb.solution(tt, xi, At, (z[:n], y / r, phi[n] if with_load else 0.0))  # (At, hat)
    sys_.last = (sol.t,) + product[1:]  # (t, A t[, unit·A t]): the next step's start needs no product
    sol.At = (sol.t, At)  # w = A_tt t (+ A_tn p) of the state needs no new product (rollqp.march)
    return meth.finish(sol, it, info, t0)


def _has_shape(a, n) -> bool:
    """``np.shape(a) == (n,)`` (an array's own shape read first: np.shape's dispatch costs more)."""
    return (a.shape if type(a) is np.ndarray else np.shape(a)) == (n,)


def _friction_rows(sys_, pb):
    """The friction rows of ``pb`` (:class:`~.ncp.TangentialNCP` of ``b̂ = μp̄⁺/p0``), kept on the system
    while the steps share their read-only bound array (a fixed normal half: the same pressure every step)."""
    bound = pb.bound
    last = sys_.ncp
    if last is None or last[0] is not bound:
        last = sys_.ncp = (bound, TangentialNCP(*pb.bound_hat))
    return last[1]


def _last_product(sys_, x):
    """``(x, A x[, unit·A x])`` if the system's last solution was the traction ``x`` (the warm start), else None."""
    last = sys_.last
    if x is None or last is None or not (last[0] is x or np.array_equal(last[0], x)):
        return None
    return last


# ------------------------------------------------------------------------------ the iteration
#: Iterations between two products ``A x`` of the iterate: in between ``y`` is carried along
#: (``y ← y + α K d``), which bounds the drift of its round-off.
REFRESH_EVERY = 16


class _Iterate:
    """The state of one GNMls iteration (Steps 2–7): the iterate, ``y = K z + k0``, ``Φ`` and the counts.

    ``y`` is linear in ``z``: it is evaluated from a product ``A x`` of the traction (``x`` in the
    problem's units, ``Ax`` its product; the last step's, if the iteration starts from it), then
    carried along each step by ``α K d`` (:meth:`Kd`). The stopping test is passed only on a
    ``y`` evaluated from a product of the iterate itself (:meth:`refresh`), whose ``A x`` the
    step's solution then reuses.
    """

    def __init__(self, meth, pb, sys_, z, k0, load, ncp, start=None):
        self.meth, self.pb, self.sys, self.ncp = meth, pb, sys_, ncp
        self.n = pb.n
        self.load = load
        self.with_load = load is not None
        self.K = sys_.matrices(self.with_load)
        self.k0 = k0
        self.needs = getattr(ncp, "needs", None)
        self.z = z
        self.x = z[:self.n]
        #: full products from here on (:meth:`exact_products`): the carried ``y`` reached its round-off floor
        self.exact = False
        if start is None:
            self.refresh()
        else:  # the traction of the last step and its product A x
            self.xphys, self.Ax = start[0], start[1]
            self._y_from_product()
        self.history, self.merits, self.steps = [], [], []
        self.backtracks = self.nonmono = self.shifts = 0

    def exact_products(self):
        """Carry ``y`` no more and multiply by the whole matrix: each iterate gets its own full product
        ``A x`` and ``K d`` is a full product. Taken when the carried ``y`` met the tolerance but the
        iterate's own product did not. Near a tight tolerance (1e-12 at 2,561 nodes) two things are at
        the residual's own size: the free rows' ``K_F d = −Φ_F`` holds only to the solve's round-off,
        and a product over the contact columns rounds differently as the set of columns changes
        (7e-16 relative, times ``|r A x|``): Newton then cannot settle below that noise (measured: a
        floor of 1.25e-12 over 200 iterations), while one fixed full product per iterate is a
        deterministic function it converges on (7.5e-15)."""
        self.exact = True

    def residual(self, x, y):
        """``Φ = [φ(x, y); f̂ᵀx − load]`` (eq. 74; the load row eq. 67 only with the load prescribed)."""
        if not self.with_load:
            return self.ncp.phi(x, y)
        out = np.empty(self.n + 1)
        out[:self.n] = self.ncp.phi(x, y)
        out[self.n] = self.sys.fhat @ x - self.load
        return out

    def refresh(self):
        """``y`` and ``Φ`` from a new product ``A x`` of the iterate."""
        self.xphys, self.Ax, _ = self.product(self.z, with_y=False)
        self._y_from_product()

    def product(self, z, with_y=True):
        """``(x, A x, y)`` at the unknowns ``z`` (``x`` the traction in the problem's units)."""
        x = z[:self.n] * self.pb.scales.stress
        if not self.exact:  # the columns where x ≠ 0 (the contact: zero traction outside)
            Ax = partial_product(self.pb.A.dense(), np.arange(self.n), x, np.flatnonzero(x))
        else:
            Ax = self.pb.A @ x
        return x, Ax, (self._y(Ax, z) if with_y else None)

    def _y(self, Ax, z):
        """``y = K z + k0`` from the product ``A x`` of ``z``'s traction: ``unit·(A x) + k0 (+ K_load z_n)``."""
        y = self.sys.unit * Ax + self.k0
        if self.with_load:
            y += self.sys.load_column * z[self.n]
        return y

    def take(self, z, trial, phi, merit):
        """The iterate ``z`` with its product ``(x, A x, y)`` (:meth:`product`), its ``Φ`` and merit ``θ``
        (the line search's)."""
        self.z = z
        self.x = z[:self.n]
        self.xphys, self.Ax, self.y = trial
        self.fresh, self.since = True, 0
        self.phi, self.merit = phi, merit

    def _y_from_product(self):
        self.y = self._y(self.Ax, self.z)
        self.fresh, self.since = True, 0
        self.phi, self.merit = self.residual(self.x, self.y), None

    def update(self, z, alpha, Kd):
        """The iterate ``z`` reached by the step ``α d``, with ``K d`` (:meth:`Kd`)."""
        self.z = z
        self.x = z[:self.n]
        self.since += 1
        if self.since >= REFRESH_EVERY or self.exact:
            self.refresh()
            return
        self.y = self.y + alpha * Kd
        self.fresh = False
        self.phi, self.merit = self.residual(self.x, self.y), None

    def Kd(self, d, mask):
        """``K d`` on the rows ``Φ`` reads. On the free rows (``mask``) the Newton equations give it,
        ``K_F d = −Φ_F``; the others are multiplied by the blocks of ``K`` they need (the columns
        where ``d ≠ 0``); rows whose ``y`` does not enter ``Φ`` (a zero friction bound) are left 0."""
        if self.exact:
            return self.K @ d
        n = self.n
        F = mask[:n]
        Kd = np.zeros(n)
        Kd[F] = -self.phi[:n][F]
        rows = ~F if self.needs is None else ~F & self.needs
        rows = np.flatnonzero(rows)
        Kd[rows] = partial_product(self.K, rows, d, np.flatnonzero(d))
        return Kd

    def rows(self, mask):
        """The node rows of the pseudo-Jacobian (eq. 80–90) in ``mask``; a degenerate iterate (no
        ``δ̂``/``ξ̂`` column) is repaired by moving the nearest node onto its kink first."""
        n, ncp = self.n, self.ncp
        m = ncp.mask(self.x, self.y)
        if self.with_load and not m.any():
            try:
                j, dy = ncp.nearest(self.x, self.y)
            except SolverError as err:
                raise SolverError(err.message, method=self.meth.name, status=err.status) from None
            self.z[n] += dy / self.K[j, n]
            if self.fresh:  # only δ̂/ξ̂ moved: y from the same product
                self._y_from_product()
            else:
                self.y = self.y + self.K[:, n] * (dy / self.K[j, n])
                self.phi, self.merit = self.residual(self.x, self.y), None
            m = ncp.mask(self.x, self.y)
            m[j] = True
            self.shifts += 1
        mask[:n] = m

    def line_search(self, d, Kd, warm, full=None):
        """Armijo (eq. 75–78, ``s = 1``): ``α = ρ^m``, the first with ``θ(z + αd) <= (1 − 2σα) θ(z)``;
        below :data:`ALPHA_MIN` the full step (cold start) or :class:`Stalled` (warm start).

        ``full = (z + d, its product)`` (:meth:`product`): ``α = 1`` is tried on the full step's own
        ``y`` (``Kd`` may then be None: ``y(z + d) − y``, formed only if the full step is refused). Returns ``(α, (Φ, θ) at z + αd)``, the latter ``None`` unless ``α = 1`` was taken on ``full``."""
        meth = self.meth
        rho, two_sigma = meth.rho, 2.0 * meth.sigma
        dx = d[:self.n]
        theta = self.merits[-1]
        alpha = 1.0
        if full is not None:
            pa = self.residual(full[0][:self.n], full[1][2])
            merit = 0.5 * float(pa @ pa)
            if merit <= (1.0 - two_sigma) * theta:
                return 1.0, (pa, merit)
            alpha = rho
            self.backtracks += 1
            Kd = full[1][2] - self.y
        counts = [self.backtracks, self.nonmono]
        alpha = _backtrack(meth, self.x, self.y, dx, Kd, theta, self.load, self.ncp, self.sys, warm, counts, alpha)
        self.backtracks, self.nonmono = counts
        return alpha, None


def iterate(meth, pb, sys_, z, k0, load, ncp, warm=False, start=None):
    """GNMls Steps 2–7 on ``Φ(z) = [φ(x, y); f̂ᵀx − load]`` with ``y = K z + k0``.

    ``x = z[:n]`` is the traction, ``y`` the augmented gap/slip ``r ĝ``/``r ŝ`` (linear in z);
    ``ncp`` gives ``φ`` and its node cases (:class:`~.ncp.NormalNCP`, :class:`~.ncp.TangentialNCP`);
    ``start``: ``(x, A x)`` of the start in the problem's units, if the product is known.
    Returns ``(z, iterations, info, product, y, Φ)``: ``product`` is ``(x, A x)`` or ``(x, A x, unit·A x)``,
    ``x`` the solution's traction in the problem's units; ``y``, ``Φ`` at ``z`` (evaluated from its own product).
    """
    if not sys_.partial:
        return _iterate_dense(meth, pb, sys_, z, k0, load, ncp, warm, start)
    r = sys_.r
    st = _Iterate(meth, pb, sys_, z, k0, load, ncp, start)
    stop = meth.tolerance * min(1.0, r)
    mask = sys_.mask(st.with_load)  # last entry: load row (always the JK row)
    it = 0
    while True:
        nrm = float(np.abs(st.phi).max())
        if nrm <= stop and not st.fresh:  # converged on the carried y: test on the iterate's own product
            st.refresh()
            nrm = float(np.abs(st.phi).max())
            if nrm > stop:
                st.exact_products()
        st.history.append(nrm)
        st.merits.append(0.5 * float(st.phi @ st.phi) if st.merit is None else st.merit)
        if nrm <= stop:
            break
        if it >= meth.max_iterations:
            raise not_converged(meth, pb.kind, st.merits, it, nrm, stop)
        it += 1
        st.rows(mask)
        d = sys_.direction(mask, st.phi, st.with_load)  # reduced system on the free nodes
        if d is None or not math.isfinite(float(np.add.reduce(d))):  # a NaN or an infinity anywhere (one sum)
            raise _singular(meth, pb, it, nrm)
        if it == 1 and sys_.settled:
            # the last step took one iteration (so this one likely does too): the product at the full step
            # gives K d (all rows) and, if the step is taken, the iterate's own y and Φ
            zf = st.z + d
            full, Kd = (zf, st.product(zf)), None  # K d = y(z + d) − y, if the full step is refused
        else:
            full, Kd = None, st.Kd(d, mask)
        alpha, at_full = st.line_search(d, Kd, warm, full)
        st.steps.append(alpha)
        if at_full is not None:
            st.take(full[0], full[1], *at_full)  # eq. 79, α = 1
        else:
            st.update(st.z + alpha * d, alpha, full[1][2] - st.y if Kd is None else Kd)  # eq. 79
    sys_.settled = it == 1
    if it or start is None:  # a product of this iteration's (else the start's): how it was taken
        sys_.exact = st.exact
    info = {"r": r, "backtracks": st.backtracks, "merit": st.merits[-1], "history": st.history,
            "merits": st.merits, "steps": st.steps, "nonmonotone": st.nonmono, "shifts": st.shifts,
            "tolerance_phi": stop}
    return st.z, it, info, (st.xphys, st.Ax), st.y, st.phi


# ------------------------------------------------------------------------------ small n
#: ``a.max()``, ``a.any()`` without their Python-level wrappers (the same reductions)
_max, _any = np.maximum.reduce, np.logical_or.reduce

def _point(ev, z, k0, load, start=None):
    """``(x, A x, y, Φ)`` at the unknowns ``z`` from a new product ``A x`` of its traction (``start``: the
    known ``(x, A x)``): :meth:`_Iterate.product` and :meth:`_Iterate.residual` in one call, the same numbers.
    ``ev``: the step's constants (:func:`_iterate_dense`)."""
    n, stress, A, unit, lc, fhat, phi_rows = ev
    x = z[:n]
    if start is None:
        xphys = x * stress
        Ax = A.dot(xphys)  # (ndarray.dot: the same BLAS call and numbers as @, without matmul's ufunc dispatch)
        uAx = unit * Ax
    else:  # the last step's (x, A x) and, if it kept it, unit·(A x): the same numbers as formed here
        xphys, Ax = start[0], start[1]
        uAx = start[2] if len(start) > 2 else unit * Ax
    y = uAx + k0
    if load is None:
        return xphys, Ax, y, phi_rows(x, y), uAx
    y += lc * z[n]
    phi = np.empty(n + 1)
    phi_rows(x, y, phi[:n])
    phi[n] = fhat.dot(x) - load
    return xphys, Ax, y, phi, uAx


def _iterate_dense(meth, pb, sys_, z, k0, load, ncp, warm, start):
    """:func:`iterate` below :data:`~.linear.PARTIAL_MIN` nodes: the same iterates and numbers as :class:`_Iterate`
    there (every iterate its own product ``A x``, ``α = 1`` tried on the full step's product), written out in
    one loop. At 81 nodes a rolling step takes one iteration, whose arithmetic (a few dozen operations on
    81-vectors) costs about what the object's method calls around it would."""
    n, r = pb.n, sys_.r
    ev = (n, pb.scales.stress, pb.A.dense(), sys_.unit, sys_.load_column, sys_.fhat, ncp.phi)
    with_load = load is not None
    stop = meth.tolerance * min(1.0, r)
    mask = sys_.mask(with_load)
    two_sigma = 2.0 * meth.sigma
    xphys, Ax, y, phi, uAx = _point(ev, z, k0, load, start)
    merit, history, merits, steps, counts = None, [], [], [], [0, 0, 0]  # backtracks, nonmonotone, shifts
    it = 0
    while True:
        nrm = float(_max(np.abs(phi)))
        history.append(nrm)
        merits.append(0.5 * float(phi.dot(phi)) if merit is None else merit)
        if nrm <= stop:
            break
        if it >= meth.max_iterations:
            raise not_converged(meth, pb.kind, merits, it, nrm, stop)
        it += 1
        m = ncp.mask(z[:n], y, mask[:n])  # the node rows, straight into the mask
        if with_load and not _any(m):  # degenerate: _Iterate.rows
            m, y, phi = _repair(meth, ev, sys_, z, k0, load, ncp, xphys, Ax, y)
            mask[:n] = m
            merit = None
            counts[2] += 1
        d = sys_.direction(mask, phi, with_load)  # reduced system on the free nodes
        if d is None:
            raise _singular(meth, pb, it, nrm)
        zf = z + d
        full = _point(ev, zf, k0, load)
        pa = full[3]
        merit = 0.5 * float(pa.dot(pa))
        # d has a NaN or an infinity iff z + d has (z is finite): in x̂, Φ's own row of that node is not finite
        # (x̂ − Proj(…), with the load row f̂ᵀx̂ too), so the merit is not; in ξ̂, the number itself
        if not (math.isfinite(merit) and (not with_load or math.isfinite(zf[n]))):
            raise _singular(meth, pb, it, nrm)
        if merit <= (1.0 - two_sigma) * merits[-1]:  # eq. 75–78 at α = 1
            steps.append(1.0)
            z, (xphys, Ax, y, phi, uAx) = zf, full
            continue
        counts[0] += 1  # the full step refused: α = ρ next
        alpha = _backtrack(meth, z[:n], y, d[:n], full[2] - y, merits[-1], load, ncp, sys_, warm, counts, meth.rho)
        steps.append(alpha)
        z = z + alpha * d  # eq. 79
        xphys, Ax, y, phi, uAx = _point(ev, z, k0, load)
        merit = None
    sys_.settled = False
    info = {"r": r, "backtracks": counts[0], "merit": merits[-1], "history": history, "merits": merits,
            "steps": steps, "nonmonotone": counts[1], "shifts": counts[2], "tolerance_phi": stop}
    return z, it, info, (xphys, Ax, uAx), y, phi


def _singular(meth, pb, it, nrm):
    return SolverError(f"the {pb.kind} Newton matrix is singular", method=meth.name, status="singular",
                       iterations=it, residual=nrm)


def _repair(meth, ev, sys_, z, k0, load, ncp, xphys, Ax, y):
    """:meth:`_Iterate.rows` on a degenerate iterate (no node in stick/contact): ``δ̂``/``ξ̂`` moved so that the
    nearest node lies on its kink (in place in ``z``); ``(mask, y, Φ)`` there, that node with the ``K`` row."""
    n = ev[0]
    try:
        j, dy = ncp.nearest(z[:n], y)
    except SolverError as err:
        raise SolverError(err.message, method=meth.name, status=err.status) from None
    z[n] += dy / sys_.K[j, n]
    _, _, y, phi, _ = _point(ev, z, k0, load, (xphys, Ax))  # only δ̂/ξ̂ moved: y from the same product
    m = ncp.mask(z[:n], y)
    m[j] = True
    return m, y, phi


def _backtrack(meth, x, y, dx, Kd, theta, load, ncp, sys_, warm, counts, alpha):
    """The Armijo line search (eq. 75–78, ``s = 1``) on ``(x, y) + α (d, K d)`` from ``α = alpha`` (1, or ``ρ``
    once the full step was refused): the first ``α = alpha·ρ^m`` with ``θ <= (1 − 2σα) θ(z)``; below
    :data:`ALPHA_MIN` the full step (cold start) or :class:`Stalled` (warm start). ``counts[0]``, ``counts[1]``:
    the backtracks and the non-monotone steps, counted on."""
    rho, two_sigma = meth.rho, 2.0 * meth.sigma
    n = x.size
    while True:
        xa, ya = x + alpha * dx, y + alpha * Kd
        if load is None:
            pa = ncp.phi(xa, ya)
        else:
            pa = np.empty(n + 1)
            pa[:n] = ncp.phi(xa, ya)
            pa[n] = sys_.fhat @ xa - load
        if 0.5 * float(pa @ pa) <= (1.0 - two_sigma * alpha) * theta:
            return alpha
        alpha *= rho
        counts[0] += 1
        if alpha < ALPHA_MIN:
            if warm:
                raise Stalled()
            counts[1] += 1
            return 1.0
