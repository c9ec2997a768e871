r"""Generalized Newton method with line search for the 3D steps (docs/theory3d.md §7).

The 2D project's GNMls (González & Abascal 2002 §4; Pang 1990) carried to the disc. In the
nondimensional variables of :mod:`rollqp.problem.grid` the steps are the nonsmooth equations

.. math::
    \Phi_N = \begin{bmatrix} \min(\hat p,\ r\hat g) \\ \hat a\sum\hat p − \hat F_N\end{bmatrix},
    \qquad
    \Phi_T = \begin{bmatrix} \hat t_i − \mathrm{Proj}_{|\cdot|\le \hat b_i}(\hat t_i − r\hat s_i) \\
             \hat a\sum\hat t_x − \hat F_x \\ \hat a\sum\hat t_y − \hat F_y\end{bmatrix}   \qquad (3D.25)

(``ĝ = ĥ − δ̂ + Â p̂``, ``ŝ = ŝ₀ + ξ̂ e_x + η̂ e_y + Ŝ t̂``; a load row is dropped where the
creepage — or the approach — is prescribed). The projection onto the disc of radius ``b``,
``P(z) = z`` for ``|z| ≤ b`` and ``b z/|z|`` otherwise, has the generalized derivative

.. math::
    \partial P(z) = I \ (|z| \le b),\qquad
    \partial P(z) = \kappa\,(I − \hat z\hat z^T),\ \kappa = b/|z|,\ \hat z = z/|z| \ (|z| > b)  \qquad (3D.26)

so the Newton matrix has, per element, the stick rows ``r ∂ŝ_i`` (the slip vanishes) and the
slip rows ``(I − M_i) e_i + r M_i ∂ŝ_i`` (``M_i = ∂P``: along ``ẑ_i`` the traction is fixed at
the bound, across it the slip rotates). The 2D method is the special case: a disc of one
dimension is the interval, ``I − ẑẑᵀ = 0`` and the rows are eq. 86–88 of the paper.

A slip-dependent bound ``b_i = μ(V|s_i|) p̂_i`` (a falling friction law, :class:`~rollqp.friction.bound.SlipBound`)
adds ``∂P/∂b = ẑ_i`` times the bound's gradient ``g_i = ∂b_i/∂ŝ_i`` to the slip rows: ``(I − M_i) e_i +
(r M_i − ẑ_i g_iᵀ) ∂ŝ_i`` (eq. 3D.26s, docs/theory3d.md §7), solved by LU (the rows are not symmetric) or GMRES;
where the line search cannot bring the merit down, the fixed point on the bound around the fixed-bound steps,
polished by Newton, as on a strip (:func:`_solve_slip_safeguarded`).

Each iteration solves ``J d = −Φ`` and takes ``α = ρ^m``, the first with
``θ(x + αd) ≤ (1 − 2σα) θ(x)``, ``θ = ½‖Φ‖²`` (eq. 75–79 of the paper; the full step where the
search fails, counted in ``info["nonmonotone"]``). The linear part ``Ŝ t̂`` (``Â p̂``) is carried
along the line (``K(x + αd) = Kx + α Kd``): one operator product per iteration. Stopping:
``‖Φ‖∞ ≤ tolerance·min(1, r)``, which bounds rollqp's residual (``r = 1``) by ``tolerance``.

Linear algebra (``path``): ``"dense"`` gathers the operator's block on the contact elements
and solves through its inverse, kept with the operator, by a capacitance matrix on the slipping
elements (:mod:`.capacitance`; by LU where most elements slip; normal: Cholesky of ``Â_FF``); ``"krylov"`` never forms it: CG (normal) or
GMRES (tangential) on FFT products, preconditioned by the elements' own 2 × 2 blocks.
``"auto"`` takes the dense path up to :data:`DENSE_UNKNOWNS` unknowns.
"""
from __future__ import annotations

import time
import warnings

import numpy as np
import scipy.linalg as sla

from ... import progress
from ...errors import InputError, SolverError
from ..base import Capabilities, check_options
from ..fixedpoint import BoundFixedPoint
from ...problem.grid import disc_projection
from . import capacitance
from .gmres import gmres

__all__ = ["NewtonMethod", "DENSE_UNKNOWNS", "tangential_rows"]

#: Largest reduced system solved densely by ``path="auto"``. Measured (benchmarks/three_speed.py):
#: on CONTACT's 48 × 44 steady case (2768 unknowns) a dense LU step takes 1.3 s, the GMRES step
#: 0.07 s; at 500 unknowns (a 20 × 20 grid) they are even. Above this, FFT products and GMRES.
DENSE_UNKNOWNS = 1200
#: The same for a transient or shift step (the operator ``A_tt`` itself). The dense path solves through the
#: inverse of the contact block, computed once per contact set and shared by the march's steps
#: (:mod:`.capacitance`); measured on circles (ξ, η, φ, 12 steps), CPU of a transient step dense / Krylov,
#: median (the first step, which inverts the block): 1.9 (8.5) / 13.0 ms at 5 per semi-axis, 3.0 (26) /
#: 17.8 ms at 10 (632 unknowns), 6.5 (59) / 20.8 ms at 12, 14.5 (163) / 25.1 ms at 15 (about 1420
#: unknowns: the 12 steps even), 49 (634) / 50 ms at 20 (2544 unknowns).
TRANSIENT_DENSE_UNKNOWNS = 1200
#: Relative tolerance of the Krylov solves, against ‖Φ‖: an inexact Newton step of this
#: accuracy keeps the local convergence superlinear (Eisenstat–Walker forcing ≤ 1e-2 ‖Φ‖).
KRYLOV_FORCING = 1e-3


def _sparse_linalg():
    """``scipy.sparse.linalg``, imported on the first Krylov solve: a small grid's run on the dense path does
    without it (about 20 ms of CPU at start-up)."""
    import scipy.sparse.linalg
    return scipy.sparse.linalg


def _line_search(theta0, phi_at, rho, sigma, max_backtracks=30):
    """``(α, Φ(α), accepted)``: the first ``α = ρ^m`` with ``θ(α) ≤ (1 − 2σα)θ(0)`` (eq. 75–79 of the
    paper). If none is accepted (a direction from a kink that is no descent direction there): the
    tried ``α`` with the smallest ``θ`` if it decreases ``θ`` at all, else the full step (the 2D
    method's escape from a kink), and ``accepted = False``."""
    alpha, best = 1.0, (np.inf, 1.0, None)
    for _ in range(max_backtracks):
        phi = phi_at(alpha)
        theta = 0.5 * float(phi @ phi)
        if theta <= (1 - 2 * sigma * alpha) * theta0:
            return alpha, phi, True
        if theta < best[0]:
            best = (theta, alpha, phi)
        alpha *= rho
    if best[0] < theta0:
        return best[1], best[2], False
    return 1.0, phi_at(1.0), False


class NewtonMethod:
    r"""GNMls on the 3D normal and tangential steps (eq. 3D.25–3D.28).

    Parameters
    ----------
    tolerance : float
        Target of ``‖Φ‖∞`` (nondimensional, in (0, 1)).
    max_iterations : int
        Newton iterations per step before a :class:`~rollqp.errors.SolverError`.
    r : float, optional
        The augmentation; default ``1/mean(diag Â)`` (normal) and ``1/mean(diag Ŝ)`` on the
        contact (tangential): both arguments of the ``min``/``Proj`` then respond alike to the
        element's own traction (docs/theory3d.md §7).
    rho, sigma : float
        Armijo parameters.
    path : {"auto", "dense", "krylov"}
        Linear algebra of the Newton steps (module docstring).

    Examples
    --------
    >>> m = NewtonMethod(tolerance=1e-10)
    >>> m.name, sorted(m.capabilities.solves), m.capabilities.friction_set
    ('newton-3d', ['normal', 'steady', 'tangential'], 'disc')
    """

    #: The registry names the instance (rollqp.methods); this is the class's default label.
    name = "newton-3d"
    capabilities = Capabilities(solves=frozenset({"normal", "tangential", "steady"}), matrix_free=True,
                                dimensions=frozenset({3}), traction_components=2, friction_set="disc",
                                slip_dependent=True)

    def __init__(self, tolerance: float = 1e-10, max_iterations: int = 100, r: float | None = None,
                 rho: float = 0.5, sigma: float = 1e-4, path: str = "auto"):
        if not (np.isfinite(tolerance) and 0 < tolerance < 1):
            raise InputError("solver.tolerance", f"must be in (0, 1), got {tolerance!r}")
        if int(max_iterations) != max_iterations or max_iterations < 1:
            raise InputError("solver.max_iterations", f"must be an integer >= 1, got {max_iterations!r}")
        if r is not None and not (np.isfinite(r) and 1e-6 <= r <= 10):
            raise InputError("solver.augmentation", f"must be in [1e-6, 10], got {r!r}")
        if path not in ("auto", "dense", "krylov"):
            raise InputError("path", f"must be 'auto', 'dense' or 'krylov', got {path!r}")
        self.tolerance, self.max_iterations, self.r = float(tolerance), int(max_iterations), r
        self.rho, self.sigma, self.path = float(rho), float(sigma), path

    @classmethod
    def from_settings(cls, settings, **options):
        """From a scene's solver settings: ``tolerance``, ``max_iterations`` (default 100),
        ``augmentation`` (``r``); options ``path``, ``rho``, ``sigma``."""
        check_options(cls.name, options, ("path", "rho", "sigma"))
        return cls(tolerance=settings.tolerance, max_iterations=settings.max_iterations or 100,
                   r=settings.augmentation, **options)

    def setup(self, operators=None) -> None:
        """Nothing to build: the dense blocks are memoized by the operators themselves."""

    def solve(self, problem, warm=None):
        """Solve a :class:`~rollqp.problem.grid.NormalStep` or
        :class:`~rollqp.problem.grid.TangentialStep`; ``warm``: a previous solution."""
        t0 = time.perf_counter()
        if problem.kind == "normal":
            sol = _solve_normal(self, problem, warm)
        elif problem.kind == "tangential" and problem.law is not None and not problem.law.on_path:
            sol = _solve_slip_safeguarded(self, problem, warm)
        elif problem.kind == "tangential":
            sol = _solve_tangential(self, problem, warm)
        else:
            raise InputError("problem", f"cannot solve a {problem.kind!r} step")
        sol.info["time"] = time.perf_counter() - t0
        return sol

    def _use_dense(self, unknowns: int, limit: int = DENSE_UNKNOWNS) -> bool:
        return self.path == "dense" or (self.path == "auto" and unknowns <= limit)

    def _iterate(self, x, Kx, phi_fn, step_fn, r, what):
        """The GNMls loop: ``phi_fn(x, Kx) → Φ``, ``step_fn(x, Kx, Φ) → (d, Kd)``."""
        t0 = time.perf_counter()
        phi = phi_fn(x, Kx)
        info = {"r": r, "nonmonotone": 0, "directions": 0}
        target = self.tolerance * min(1.0, r)
        for it in range(self.max_iterations + 1):
            res = float(np.max(np.abs(phi), initial=0.0))
            if it:  # the progress lines of a long solve (rollqp.progress: the command line listens)
                progress.iteration(what, it, res, time.perf_counter() - t0, target)
            if res <= target:
                info["directions"] = it
                return x, Kx, info
            if it == self.max_iterations:
                break
            d, Kd = step_fn(x, Kx, phi)
            alpha, phi, ok = _line_search(0.5 * float(phi @ phi), lambda a: phi_fn(x + a * d, Kx + a * Kd),
                                          self.rho, self.sigma)
            info["nonmonotone"] += not ok
            x, Kx = x + alpha * d, Kx + alpha * Kd
        raise SolverError(f"{what} Newton did not converge", method=self.name, iterations=self.max_iterations,
                          residual=float(np.max(np.abs(phi))))


# ----------------------------------------------------------------------------- normal step
def _normal_scaled(problem):
    sc = problem.scales
    s = sc.modulus / sc.length                       # Â = A E*/c
    hh = problem.h_total / sc.displacement
    ah = problem.area / sc.length ** 2
    Fh = None if problem.FN is None else problem.FN / sc.force
    dh = None if problem.delta is None else problem.delta / sc.displacement
    return s, hh, ah, Fh, dh


def _solve_normal(method, problem, warm):
    sc = problem.scales
    s, hh, ah, Fh, dh = _normal_scaled(problem)
    A = problem.A
    diag = s * float(A.diagonal()[0])
    r = method.r if method.r is not None else 1.0 / diag
    n = problem.n
    if warm is not None and warm.p is not None and warm.p.shape == (n,):
        p0, d0 = warm.p / sc.stress, warm.delta / sc.displacement
    else:   # rigid interpenetration of a few elements as the first contact set
        p0, d0 = np.zeros(n), float(np.sort(hh)[min(n - 1, max(1, n // 50))])
    free_delta = dh is None
    x = np.append(p0, d0 if free_delta else dh)
    Kx = s * (A @ x[:n])

    def phi_fn(x, Kx):
        g = hh - x[n] + Kx
        out = np.minimum(x[:n], r * g)
        return np.append(out, ah * x[:n].sum() - Fh) if free_delta else out

    def step_fn(x, Kx, phi):
        return _normal_direction(method, A, s, x, Kx, phi, r, hh, ah, free_delta)

    x, Kx, info = method._iterate(x, Kx, phi_fn, step_fn, r, "normal")
    p = np.maximum(x[:n], 0.0) * sc.stress
    Ap = (A @ p)
    return problem.solution(p, x[n] * sc.displacement, Ap=Ap, method=method.name,
                            iterations=info["directions"], extras=info)


def _normal_direction(method, A, s, x, Kx, phi, r, hh, ah, free_delta):
    """The reduced Newton system of the normal step (eq. 3D.27): identity rows off the contact
    set ``F = {p̂ > r ĝ}``, ``Â_FF d_F − dδ e = −ĝ_F − Â_FN d_N`` on it, and the load row."""
    n = hh.size
    p, g = x[:n], hh - x[n] + Kx
    F = np.flatnonzero(p > r * g)
    dN = np.where(p > r * g, 0.0, -p)
    if F.size == 0:   # no element in contact: raise the approach until the nearest touches
        d = np.append(dN, np.min(g) + 1e-12 if free_delta else 0.0)   # the nearest element just inside (ĝ units)
        return d, s * (A @ d[:n])
    KdN = s * (A @ dN)
    rhs = -g[F] - KdN[F]
    solve = _spd_solver(method, A, s, F)
    v = solve(rhs)
    dF, dd = v, 0.0
    if free_delta:
        u = solve(np.ones(F.size))
        target = -phi[n] / ah - dN.sum()
        dd = (target - v.sum()) / u.sum()
        dF = v + dd * u
    d = dN.copy()
    d[F] = dF
    return np.append(d, dd), s * (A @ d)


def _spd_solver(method, A, s, F):
    """``b ↦ Â_FF⁻¹ b``: Cholesky of the gathered block, or CG on FFT products."""
    if method._use_dense(F.size):
        chol = sla.cho_factor(s * A.dense(F, F), lower=False, check_finite=False)   # F changes: not kept
        return lambda b: sla.cho_solve(chol, b, check_finite=False)
    n = A.shape[0]
    spla = _sparse_linalg()

    def mv(v):
        full = np.zeros(n)
        full[F] = v
        return s * (A @ full)[F]

    op = spla.LinearOperator((F.size, F.size), matvec=mv, dtype=float)

    def solve(b):
        # to round-off of the block's condition (~n_F): the step must be exact on its contact set for
        # Newton's finite termination on the piecewise-linear Φ_N
        x, info = spla.cg(op, b, rtol=1e-13, atol=0.0, maxiter=20 * F.size)
        if info != 0:
            raise SolverError("normal Newton: CG on the contact set did not converge", method=method.name)
        return x
    return solve


# ------------------------------------------------------------------------- tangential step
def _tangential_scaled(problem):
    """``(Ŝ factor, ŝ₀, b̂, â, free creepage columns, load targets)`` of eq. 3D.25."""
    sc = problem.scales
    k = sc.modulus / problem.dq                      # Ŝ = E* B/Δq
    xi0 = problem.xi if problem.xi is not None else 0.0
    eta0 = problem.eta if problem.eta is not None else 0.0
    w = np.stack([xi0 - problem.phi * problem.y, eta0 + problem.phi * problem.x])
    s0 = (w + problem.c / problem.dq) / sc.slip
    free = [j for j, F in enumerate((problem.Fx, problem.Fy)) if F is not None]
    targets = [(problem.Fx, problem.Fy)[j] / sc.force for j in free]
    return k, s0, problem.bound / sc.stress, problem.area / sc.length ** 2, free, targets


def _solve_tangential(method, problem, warm):
    sc = problem.scales
    k, s0, bh, ah, free, targets = _tangential_scaled(problem)
    n, B = problem.n, problem.B
    V = np.flatnonzero(bh > 0)
    if V.size == 0:   # no contact: no traction (the sliding limit check rejects a nonzero force)
        return problem.solution(np.zeros((2, n)), 0.0, 0.0, method=method.name, extras={"contact": 0})
    diag = k * B.diagonal()
    r = method.r if method.r is not None else 1.0 / float(np.mean(np.concatenate([diag[V], diag[n + V]])))
    if warm is not None and warm.t is not None and np.shape(warm.t) == (2, n):
        t0 = np.asarray(warm.t, dtype=float) / sc.stress * (bh > 0)
        z0 = np.array([(warm.xi, warm.eta)[j] for j in free], dtype=float) / sc.slip
        Kx = k * (B @ t0.ravel()).reshape(2, n)[:, V].ravel()
    else:
        t0, z0, Kx = _cold_start(k, B, s0, bh, ah, free, targets, V)
    x = np.append(t0[:, V].ravel(), z0)
    sys = _TangentialSystem(method, problem, V, k, s0[:, V].ravel(), bh[V], ah, free, targets, r)
    if problem.law is not None:   # a slip-dependent bound b_i(s_i) = μ(V|s_i|) p̄_i⁺ (eq. 3D.26s)
        sys.slip_law(problem.law.take(V), np.maximum(problem.p[V], 0.0) / sc.stress, sc.slip)
    x, Kx, info = method._iterate(x, Kx, sys.phi, sys.step, r, "tangential")
    t = np.zeros((2, n))
    t[:, V] = x[:2 * V.size].reshape(2, V.size) * sc.stress
    crp = {j: x[2 * V.size + i] * sc.slip for i, j in enumerate(free)}
    sol = problem.solution(t, crp.get(0), crp.get(1), method=method.name, iterations=info["directions"],
                           extras={**info, "contact": int(V.size)})
    # ‖Φ‖∞ ≤ tol·min(1, r) bounds the residual on the same products; the fresh FFT product of
    # problem.solution can differ by round-off times the condition: 100× is the 2D QPs' residual_limit
    if not sol.residual <= 100 * method.tolerance:
        raise SolverError("tangential Newton: rollqp's residual above 100·tolerance", method=method.name,
                          residual=sol.residual, iterations=sol.iterations)
    return sol


def tangential_rows(problem, t, creepages=(), method=None):
    """``(Φ, x, J)`` of a grid's tangential step at the traction ``t`` (``(2, n)``) and its free creepages
    ``creepages`` (``ξ``, then ``η``: those the step does not prescribe), for checks of the Newton matrix: ``Φ``
    the function ``x ↦ Φ_T(x)`` (eq. 3D.25), ``x`` the point (the scaled tractions on the contact elements, x then
    y, then the scaled creepages) and ``J`` the dense Newton matrix there (eq. 3D.26–3D.28, with eq. 3D.26s for a
    slip-dependent bound)."""
    method = method if method is not None else NewtonMethod(path="dense")
    sc = problem.scales
    k, s0, bh, ah, free, targets = _tangential_scaled(problem)
    n, V = problem.n, np.flatnonzero(bh > 0)
    diag = k * problem.B.diagonal()
    r = method.r if method.r is not None else 1.0 / float(np.mean(np.concatenate([diag[V], diag[n + V]])))
    sys = _TangentialSystem(method, problem, V, k, s0[:, V].ravel(), bh[V], ah, free, targets, r)
    if problem.law is not None:
        sys.slip_law(problem.law.take(V), np.maximum(problem.p[V], 0.0) / sc.stress, sc.slip)
    x = np.append((np.asarray(t, dtype=float) / sc.stress)[:, V].ravel(), np.asarray(creepages, float) / sc.slip)
    (mxx, mxy, myy), extra = sys.projection_derivative(x, sys.product(x[:2 * V.size]))
    c = (mxx, mxy, mxy, myy)
    if extra is not None:
        ux, uy, g = extra
        c = (mxx - ux * g[0] / r, mxy - ux * g[1] / r, mxy - uy * g[0] / r, myy - uy * g[1] / r)
    return (lambda y: sys.phi(y, sys.product(y[:2 * V.size]))), x, np.array(sys.matrix(c, mxx, mxy, myy))


#: Newton iterations allowed when polishing an iterate of the fixed point on the bound (quadratic convergence from
#: near a solution takes a handful), as on a strip (:data:`rollqp.methods.newton.slip.POLISH_ITERATIONS`).
POLISH_ITERATIONS = 25


def _solve_slip_safeguarded(method, problem, warm):
    """A step with a slip-dependent bound (eq. 3D.26s), safeguarded as on a strip
    (:func:`rollqp.methods.newton.slip_step.solve_slip_step`): Newton from ``warm``; where its line search cannot
    bring the merit down (a falling law's Newton direction need not descend; measured on a ramped transient:
    stuck at ‖Φ‖ = 1.5e-2 where the fixed point converged in 11 iterations), the fixed point on the bound around
    Newton's fixed-bound solves, each iterate that improved polished by Newton (``info["fixed_point"]``: its
    iterations). The first error is raised if both fail."""
    try:
        return _solve_tangential(method, problem, warm)
    except SolverError as first:
        fixed = BoundFixedPoint(_FixedBound(method), polish=lambda sol: _polish(method, problem, sol))
        try:
            sol = fixed.solve(problem, warm)
        except SolverError as second:
            raise SolverError(f"{first.message}; the fixed point on the bound failed too ({second.message})",
                              method=method.name, status=first.status, iterations=first.iterations,
                              residual=min(r for r in (first.residual, second.residual, np.inf) if r is not None))
        sol.info["fixed_point"] = sol.info.get("bound_iterations", 0)
        return sol


def _polish(method, problem, sol):
    """Newton on the slip-dependent step from ``sol`` with at most :data:`POLISH_ITERATIONS` iterations, else None."""
    quick = NewtonMethod(method.tolerance, POLISH_ITERATIONS, method.r, method.rho, method.sigma, method.path)
    try:
        return _solve_tangential(quick, problem, sol)
    except SolverError:
        return None


class _FixedBound:
    """Newton on the fixed-bound steps of the fixed point on the bound (``law`` None there)."""

    def __init__(self, method):
        self.method, self.name, self.capabilities, self.tolerance = method, method.name, method.capabilities, \
            method.tolerance

    def solve(self, problem, warm=None):
        return self.method.solve(problem, warm=warm)


def _cold_start(k, B, s0, bh, ah, free, targets, V):
    """A start for a step without a warm one: each prescribed force spread in proportion to the bound
    (the traction of a uniform slip, inside the discs since |F| < μFN), and the free creepages that
    leave the mean slip of the contact zero. From t = 0 the first iterations only shorten the step
    (measured: 37 iterations on a 64 × 64 Cattaneo shift against 9 from here)."""
    n = bh.size
    t0 = np.zeros((2, n))
    for j, F in zip(free, targets):
        t0[j] = F / (ah * bh.sum()) * bh
    Kx = k * (B @ t0.ravel()).reshape(2, n)[:, V].ravel()
    sV = s0[:, V] + Kx.reshape(2, V.size)
    z0 = np.array([-float(np.mean(sV[j])) for j in free])
    return t0, z0, Kx


class _TangentialSystem:
    """Φ_T of eq. 3D.25 on the contact elements ``V`` and its Newton directions (eq. 3D.26–3D.28)."""

    def __init__(self, method, problem, V, k, s0, bh, ah, free, targets, r):
        self.method, self.problem, self.V, self.k = method, problem, V, k
        self.s0, self.bh, self.ah, self.free, self.targets, self.r = s0, bh, ah, free, targets, r
        self.nv = V.size
        self.E = np.zeros((2 * self.nv, len(free)))     # ∂ŝ/∂(ξ̂, η̂): ones on the x (y) rows
        for i, j in enumerate(free):
            self.E[j * self.nv:(j + 1) * self.nv, i] = 1.0
        steady = str(getattr(problem.B, "name", "")).startswith("steady")   # the steady operator (eq. 3D.17)
        self.steady, self._columns = steady, None
        self.dense = method._use_dense(2 * self.nv + len(free), DENSE_UNKNOWNS if steady else TRANSIENT_DENSE_UNKNOWNS)
        self.S = k * self._block() if self.dense else None
        self._rS = None
        self.law = None

    def slip_law(self, law, phat, slip_unit):
        """Make the bound slip-dependent: ``b̂_i = μ_i(ŝ_i·slip_unit) p̂_i`` (``law`` on the contact elements)."""
        self.law, self.phat, self.slip_unit = law, phat, slip_unit

    def bound(self, sh):
        """``b̂`` at the scaled slip ``sh`` (``(2 nv,)``): the fixed bound, or the law's at the slip."""
        if self.law is None:
            return self.bh
        return self.law.mu(sh.reshape(2, self.nv) * self.slip_unit) * self.phat

    def _block(self):
        """The operator's dense block on the contact elements (kept with the operator)."""
        B, V = self.problem.B, self.V
        return B.memo(("dense", V.tobytes()), lambda: B.dense(V, V))

    def _inverse(self):
        """The inverse of :meth:`_block`: whole and kept with the operator for the steps of a march (they share
        it), as an LU kept with the operator and this solve's own columns for a steady state (one solve)."""
        B, key = self.problem.B, self.V.tobytes()
        if not self.steady:
            return B.memo(("inverse", key), lambda: capacitance.inverse(self._block()))
        if self._columns is None:
            self._columns = capacitance.Columns(B.memo(("lu", key), lambda: capacitance.factor(self._block())))
        return self._columns

    def split(self, x, Kx):
        m = 2 * self.nv
        t, z = x[:m], x[m:]
        sh = self.s0 + Kx + self.E @ z
        return t, z, sh

    def phi(self, x, Kx):
        t, _, sh = self.split(x, Kx)
        nv = self.nv
        zt = (t - self.r * sh).reshape(2, nv)
        res = t - disc_projection(zt, self.bound(sh)).ravel()
        loads = [self.ah * t[j * nv:(j + 1) * nv].sum() - F for j, F in zip(self.free, self.targets)]
        return np.concatenate([res, loads])

    def projection_derivative(self, x, Kx):
        """``(m_xx, m_xy, m_yy)`` of ``M_i = ∂P(z_i)`` (eq. 3D.26), per element; with a slip-dependent bound also
        ``(u_x, u_y)`` (``ẑ_i`` on slipping elements, else 0) and the bound's gradient ``g_i = ∂b̂_i/∂ŝ_i``."""
        t, _, sh = self.split(x, Kx)
        z = (t - self.r * sh).reshape(2, self.nv)
        bh = self.bound(sh)
        norm = np.hypot(z[0], z[1])
        slip = norm > bh
        with np.errstate(divide="ignore", invalid="ignore"):
            kap = np.where(slip, bh / norm, 1.0)
            ux, uy = np.where(slip, z[0] / norm, 0.0), np.where(slip, z[1] / norm, 0.0)
        m = kap * (1 - ux * ux), -kap * ux * uy, kap * (1 - uy * uy)
        if self.law is None:
            return m, None
        g = self.law.dmu(sh.reshape(2, self.nv) * self.slip_unit) * (self.phat * self.slip_unit)
        return m, (ux, uy, g)

    def step(self, x, Kx, phi):
        (mxx, mxy, myy), extra = self.projection_derivative(x, Kx)
        # the coefficients of r ∂ŝ in the rows (eq. 3D.26: M_i; with a slip-dependent bound M_i − ẑ_i g_iᵀ/r,
        # eq. 3D.26s: along ẑ_i the traction follows the bound as the slip changes it)
        c = (mxx, mxy, mxy, myy)
        if extra is not None:
            ux, uy, g = extra
            r = self.r
            c = (mxx - ux * g[0] / r, mxy - ux * g[1] / r, mxy - uy * g[0] / r, myy - uy * g[1] / r)
        d = (self._dense_step(c, mxx, mxy, myy, phi) if self.dense
             else self._krylov_step(c, mxx, mxy, myy, phi))
        return d, self.product(d[:2 * self.nv])

    def product(self, dt):
        """``Ŝ_VV dt`` (dense block or FFT)."""
        if self.S is not None:
            return self.S @ dt
        n, V = self.problem.n, self.V
        full = np.zeros((2, n))
        full[:, V] = dt.reshape(2, self.nv)
        return self.k * (self.problem.B @ full.ravel()).reshape(2, n)[:, V].ravel()

    def _dense_step(self, c, mxx, mxy, myy, phi):
        if self.law is not None:   # a slip-dependent bound: the rows M_i − ẑ_i g_iᵀ/r (eq. 3D.26s), by LU
            return self._lu_step(c, mxx, mxy, myy, phi)
        slip = np.flatnonzero((mxx != 1.0) | (mxy != 0.0) | (myy != 1.0))   # M_i = I: a sticking element
        if 2 * slip.size <= capacitance.MAX_FRACTION * 2 * self.nv:
            d = self._capacitance_step(slip, mxx, mxy, myy, phi)
            if d is not None:
                return d
        return self._lu_step(c, mxx, mxy, myy, phi)

    def _capacitance_step(self, slip, mxx, mxy, myy, phi):
        """``J d = −Φ`` by eq. 3D.28a (the load rows bordered: ``d_t = X_0 + X_ζ dζ``); ``None`` where it is
        singular (the LU step decides)."""
        nv, r, nf = self.nv, self.r, len(self.free)
        m = 2 * nv
        rhs = -phi[:m]
        if nf:
            cols = [-r * np.concatenate([(mxx, mxy)[j], (mxy, myy)[j]]) for j in self.free]   # −J_tζ
            rhs = np.column_stack([rhs] + cols)
        X = capacitance.solve(self._inverse(), r * self.k, slip, mxx, mxy, myy, rhs)
        if X is None or not np.all(np.isfinite(X)):
            return None
        if not nf:
            return X
        LX = self.ah * np.stack([X[j * nv:(j + 1) * nv].sum(axis=0) for j in self.free])   # (nf, 1 + nf)
        if not np.linalg.cond(LX[:, 1:]) < 1e12:   # every element slipping: the load rows are singular
            return None
        dz = np.linalg.solve(LX[:, 1:], -phi[m:] - LX[:, 0])
        return np.concatenate([X[:, 0] + X[:, 1:] @ dz, dz])

    def matrix(self, c, mxx, mxy, myy) -> np.ndarray:
        """The dense Newton matrix ``J`` (eq. 3D.26–3D.28; ``c`` the coefficients of ``r ∂ŝ``, eq. 3D.26s)."""
        nv, r, nf = self.nv, self.r, len(self.free)
        m = 2 * nv
        cxx, cxy, cyx, cyy = c
        if self._rS is None:   # r·[Ŝ E] once per solve (the same numbers as forming it each iteration)
            self._rS = r * np.hstack([self.S, self.E])
        R = self._rS
        Rx, Ry = R[:nv], R[nv:]
        # J of eq. 3D.26 filled in place, row blocks and load rows (no stacking copies)
        J = np.empty((m + nf, m + nf), order="F")
        Jx, Jy = J[:nv], J[nv:m]
        np.multiply(cxx[:, None], Rx, out=Jx)
        Jx += cxy[:, None] * Ry
        np.multiply(cyx[:, None], Rx, out=Jy)
        Jy += cyy[:, None] * Ry
        i = np.arange(nv)
        Jx[i, i] += 1 - mxx
        Jx[i, nv + i] -= mxy
        Jy[i, i] -= mxy
        Jy[i, nv + i] += 1 - myy
        for row, j in enumerate(self.free):
            J[m + row] = 0.0
            J[m + row, j * nv:(j + 1) * nv] = self.ah
        return J

    def _lu_step(self, c, mxx, mxy, myy, phi):
        J = self.matrix(c, mxx, mxy, myy)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", sla.LinAlgWarning)
            d = sla.lu_solve(sla.lu_factor(J, overwrite_a=True, check_finite=False), -phi, check_finite=False)
        if not np.all(np.isfinite(d)):   # singular (e.g. every element slipping): least squares
            d = self._dense_step_lstsq(c, mxx, mxy, myy, phi)
        return d

    def _dense_step_lstsq(self, c, mxx, mxy, myy, phi):
        """The least-squares Newton direction where ``J`` is singular (built again: the LU overwrote it)."""
        nv, R, nf = self.nv, self._rS, len(self.free)
        m = 2 * nv
        cxx, cxy, cyx, cyy = c
        Rx, Ry = R[:nv], R[nv:]
        Jx = cxx[:, None] * Rx + cxy[:, None] * Ry
        Jy = cyx[:, None] * Rx + cyy[:, None] * Ry
        i = np.arange(nv)
        Jx[i, i] += 1 - mxx
        Jx[i, nv + i] -= mxy
        Jy[i, i] -= mxy
        Jy[i, nv + i] += 1 - myy
        L = np.zeros((nf, m + nf))
        for row, j in enumerate(self.free):
            L[row, j * nv:(j + 1) * nv] = self.ah
        return np.linalg.lstsq(np.vstack([Jx, Jy, L]), -phi, rcond=None)[0]

    def _krylov_step(self, c, mxx, mxy, myy, phi):
        """``J d = −Φ`` without the matrix: the load rows eliminated (``d_t = J_tt⁻¹(−Φ_t − J_tζ dζ)``,
        then the ``k × k`` system of the load rows for ``dζ``), each ``J_tt`` solve by GMRES on FFT
        products, preconditioned by the elements' 2 × 2 blocks ``M_i r Ŝ_ii + (I − M_i)``."""
        nv, r, nf = self.nv, self.r, len(self.free)
        m = 2 * nv
        cxx, cxy, cyx, cyy = c

        def apply_J(dt):   # the rows of eq. 3D.28 on d_t (dζ = 0)
            Rd = r * self.product(dt)
            tx, ty = dt[:nv], dt[nv:]
            return np.concatenate([cxx * Rd[:nv] + cxy * Rd[nv:] + tx - (mxx * tx + mxy * ty),
                                   cyx * Rd[:nv] + cyy * Rd[nv:] + ty - (mxy * tx + myy * ty)])

        P = self._block_preconditioner(c, mxx, mxy, myy)

        def solve(b):
            # 80 × 50 iterations at most: measured ≤ 150 on the 300 × 300 grid; beyond, the inexact step
            # still goes to the line search (info > 0 is not an error)
            x, info = gmres(apply_J, b, P, rtol=KRYLOV_FORCING, restart=80, maxiter=50)
            if info < 0 or not np.all(np.isfinite(x)):
                raise SolverError("tangential Newton: GMRES failed", method=self.method.name)
            return x

        dt0 = solve(-phi[:m])
        if nf == 0:
            return dt0
        cols = r * np.column_stack([np.concatenate([cxx * e[:nv] + cxy * e[nv:], cyx * e[:nv] + cyy * e[nv:]])
                                    for e in self.E.T])                       # J_tζ: the creepage columns
        W = np.column_stack([solve(-c) for c in cols.T])                     # J_tt⁻¹ (−J_tζ)
        L = np.zeros((nf, m))
        for i, j in enumerate(self.free):
            L[i, j * nv:(j + 1) * nv] = self.ah
        dz = np.linalg.lstsq(L @ W, -phi[m:] - L @ dt0, rcond=1e-12)[0]   # singular: every element slipping
        return np.concatenate([dt0 + W @ dz, dz])

    def _block_preconditioner(self, c, mxx, mxy, myy):
        """``v ↦`` the elements' 2 × 2 blocks of ``J_tt`` (with ``Ŝ``'s own diagonal), inverted."""
        nv, r = self.nv, self.r
        cxx, cxy, cyx, cyy = c
        dg = self.k * self.problem.B.diagonal()
        n, V = self.problem.n, self.V
        sxx, syy = r * dg[V], r * dg[n + V]
        a11 = cxx * sxx + 1 - mxx
        a12, a21 = cxy * syy - mxy, cyx * sxx - mxy
        a22 = cyy * syy + 1 - myy
        det = a11 * a22 - a12 * a21

        def pc(v):
            vx, vy = v[:nv], v[nv:]
            return np.concatenate([(a22 * vx - a12 * vy) / det, (a11 * vy - a21 * vx) / det])
        return pc
