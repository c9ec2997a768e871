"""Shared machinery of the QP backends (docs/formulation.md §6–8).

Each backend translates a :class:`~rollqp.problem.QPForm` into its solver's native form
once per *structure* (problem kind, size, which bounds are finite, load or multiplier
prescribed) and per Hessian, and afterwards only updates vectors and warm-starts.
The solution is mapped back and evaluated with rollqp's own residuals on the problem the
QP actually solves: the one with the symmetrized operator ``F⁻¹ sym(F A)``. The measured
asymmetry ``‖FA − (FA)ᵀ‖/‖FA‖`` travels with the solution (``info["asymmetry"]``).
"""
from __future__ import annotations

import time

import numpy as np

from ..errors import InputError, SolverError
from ..problem import StepSolution
from .base import check_kind, check_options


class QPMethod:
    """Base class of the QP backends: built once per scene, one solver object per problem structure.

    Parameters
    ----------
    tolerance : float
        Target accuracy of the solver (its own convergence tolerances are set from it).
    residual_limit : float, optional
        Largest acceptable rollqp residual (nondimensional max norm); a solve whose
        residual exceeds it is a :class:`~rollqp.errors.SolverError`. Default
        ``max(100·tolerance, 1e-12)``: the solvers' stopping tests are on their scaled
        KKT conditions, which bound rollqp's residuals up to the conditioning of the
        scaling (measured factor below 100 on the paper's meshes).
    max_iterations : int, optional
        The solver's own iteration limit per QP (None: the backend's default).
    operator : {"exact", "symmetrized"}
        ``"exact"`` (default): solve the collocation problem itself by symmetric–skew
        splitting (below). ``"symmetrized"``: one QP with ``F⁻¹ sym(F A)`` in place of
        ``A``; the solution then belongs to that other discrete problem, and its residuals
        are computed on it.
    **options
        Native settings of the backend's solver (:attr:`native_options`); an unknown one is
        an :class:`~rollqp.errors.InputError` naming it.

    Notes
    -----
    A QP needs a symmetric Hessian, and the weighted collocation operator ``F A`` is
    symmetric only for piecewise-constant elements on a uniform grid. Writing
    ``F A = H + S`` (``H`` symmetric, ``S`` skew), the step is solved as a sequence of
    convex QPs with Hessian ``H`` and the skew part moved to the linear term at the
    previous iterate, ``q_k = q + S x_{k−1}``. Its fixed point satisfies the KKT
    conditions of the collocation problem exactly. The solution map of a strongly
    monotone variational inequality is 1-Lipschitz from ``H⁻¹``-norm data to ``H``-norm
    solutions, so the error contracts by ``ρ = ‖H^{-1/2} S H^{-1/2}‖₂`` per QP; measured
    ρ ≈ 0.05 for quadratic and 0.065 for linear elements, independent of the mesh
    (``docs/validation.md``). The single symmetrized QP is *not* a small perturbation:
    on 40 quadratic elements it puts a vertex/midnode checkerboard of 13 % of p0 on the
    Hertz pressure, because ``S`` feeds the log kernel's weakest mode.

    ``info`` of a solution: ``qp_solves`` (QPs of the splitting), ``backend_time`` (wall time of
    the backend's calls: data update, solve, retries), ``setups`` (solver objects built),
    ``retried`` (QPs solved again after a failed polish), ``splitting_changes`` (max change of
    ``x/p0`` from QP to QP: its ratios are the splitting's contraction), ``asymmetry``, ``operator``.

    One solver object is kept per constraint structure (:meth:`structure_key`) with the Hessian
    it was built for, recognized by its source (the symmetrized operator, the weights and the
    scales: the Hessian is normalized by its largest diagonal entry, so ``Δq`` drops out);
    :meth:`setup` drops them at the start of a scene. The splitting itself is the operator's own (:meth:`Operator.split
    <rollqp.influence.operator.Operator.split>`), computed once per scene.
    """

    name = "qp"
    solves = frozenset({"normal", "tangential"})
    extra = None  # pip extra that installs the backend, if optional
    #: Active-set refinement of the solver's answer (:func:`active_set_refine`); on for the
    #: interior-point backends, whose complementarity stops at ``sqrt(gap tolerance)``.
    refine = False
    max_splitting = 60
    #: Native solver settings a backend accepts as ``**options`` (see each backend).
    native_options: tuple = ()
    #: Solver objects kept before the oldest are dropped: structures can churn (tiny pressures
    #: of ±1e-21 p0 at separated nodes change the finite-bound pattern).
    MAX_SOLVERS = 32

    def __init__(self, tolerance: float = 1e-10, residual_limit: float | None = None,
                 max_iterations: int | None = None, operator: str = "exact", **options):
        if not (np.isfinite(tolerance) and 0 < tolerance < 1):
            raise InputError("solver.tolerance", f"must be in (0, 1), got {tolerance!r}")
        if operator not in ("exact", "symmetrized"):
            raise InputError("operator", f"must be 'exact' or 'symmetrized', got {operator!r}")
        if max_iterations is not None and (int(max_iterations) != max_iterations or max_iterations < 1):
            raise InputError("solver.max_iterations", f"must be an integer >= 1, got {max_iterations!r}")
        check_options(self.name, options, self.native_options)
        self.tolerance = float(tolerance)
        self.residual_limit = float(residual_limit) if residual_limit is not None else max(100 * tolerance, 1e-12)
        self.max_iterations = max_iterations
        self.operator = operator
        self.options = options
        self._solvers = {}

    @classmethod
    def from_settings(cls, settings, **options) -> "QPMethod":
        """From a scene's solver settings: ``tolerance``, and ``max_iterations`` as the solver's
        iteration limit per QP (absent: the backend's own); ``augmentation`` is Newton's only."""
        return cls(tolerance=settings.tolerance, max_iterations=settings.max_iterations, **options)

    def setup(self, operators) -> None:
        """A new scene: drop the solver objects of the previous one (they are rebuilt on first use)."""
        self._solvers = {}

    # --------------------------------------------------------------- public
    def solve(self, problem, warm: StepSolution | None = None) -> StepSolution:
        """Solve a normal or tangential step; raise :class:`SolverError` short of solved."""
        check_kind(self, problem)
        if getattr(problem, "law", None) is not None:
            raise InputError("problem", f"method {self.name!r} solves steps with a fixed friction bound; this one depends on "
                                        "the slip: use rollqp.friction.fixedpoint.BoundFixedPoint around it (scenes do) "
                                        "or method 'newton'")
        t0 = time.perf_counter()
        sp = problem.A.split(problem.f)
        check_convex(sp.sym, problem.f)
        sym_problem = problem.replace(A=sp.sym) if sp.asymmetry > 0 else problem
        x_prev = None
        if warm is not None:
            w = problem.traction(warm)
            if w is not None and np.shape(w) == (problem.n,):
                x_prev = np.asarray(w, dtype=float)
        exact = self.operator == "exact" and sp.asymmetry > 0
        # what the QP Hessian is a function of (the solver objects are kept per source, _solver_for)
        source = (sym_problem.A, sym_problem.f.tobytes(), sym_problem.scales)
        iters, solver_time, outer, change = 0, 0.0, 0, np.inf
        backend, setups, retried, changes = 0.0, 0, 0, []
        x_phys = x_prev if x_prev is not None else np.zeros(problem.n)
        while True:
            outer += 1
            prob = sym_problem.shifted(sp.skew @ x_phys) if exact else sym_problem  # F⁻¹ S x_{k−1}
            form = prob.qp_form()
            x0 = None if x_prev is None else x_prev / problem.scales.stress
            tb = time.perf_counter()
            x, y, status, it, st, info = self._solve_form(form, x0, source)
            backend += time.perf_counter() - tb
            setups += int(bool(info.get("built", False)))
            retried += int(info.get("tries", 1) > 1)
            iters += int(it)
            solver_time += float(st)
            if status == "solved" and self.refine:
                x, y = self._refined(prob, form, x, y, info)
            sol = prob.solution_from_qp(form, x, y)
            if status != "solved":
                raise SolverError(f"the {problem.kind} QP was not solved", method=self.name, status=status,
                                  residual=sol.residual, iterations=iters)
            if not exact:
                break
            x_new = problem.traction(sol)
            last, change = change, float(np.max(np.abs(x_new - x_phys))) / problem.scales.stress
            changes.append(change)
            x_phys = x_prev = x_new
            if change <= self.tolerance or (change >= 0.5 * last and change <= self.residual_limit):
                break  # converged, or stalled at the QP solver's own accuracy
            if outer >= self.max_splitting:
                raise SolverError("the symmetric-skew splitting did not converge", method=self.name,
                                  status=f"change {change:.2e} after {outer} QPs", iterations=iters,
                                  residual=problem.evaluate(sol).residual)
        final = (problem if exact or sp.asymmetry == 0 else sym_problem).evaluate(sol)
        final.method, final.status, final.iterations = self.name, "solved", iters
        final.solver_time = solver_time
        final.time = time.perf_counter() - t0
        final.info.update(info)
        final.info.update(asymmetry=sp.asymmetry, operator="exact" if (exact or sp.asymmetry == 0) else "symmetrized",
                          qp_solves=outer, backend_time=backend, setups=setups, retried=retried,
                          splitting_changes=changes)
        if not final.residual <= self.residual_limit:
            raise SolverError(f"the {problem.kind} QP solution's residual is above {self.residual_limit:.1e}",
                              method=self.name, status=status, residual=final.residual, iterations=iters)
        return final

    # --------------------------------------------------------------- helpers
    @staticmethod
    def _refined(prob, form, x, y, info):
        """The refined ``(x, y)`` if rollqp's residual of it is smaller, else the solver's own."""
        cand = active_set_refine(form, x, y)
        base = prob.solution_from_qp(form, x, y).residual
        info["unrefined_residual"] = max(base, info.get("unrefined_residual", 0.0))
        if cand is not None:
            res = prob.solution_from_qp(form, *cand).residual
            if res < base:
                info["refined"] = info.get("refined", 0) + 1
                return cand
        return x, y

    def structure_key(self, form):
        """What the backend's solver object depends on besides the Hessian (default: :attr:`QPForm.structure`)."""
        return form.structure

    def _solver_for(self, form, source, build):
        """``(solver object, fresh)`` for this constraint structure and Hessian, built on first use.

        One solver object is kept per structure (:meth:`structure_key`) with the Hessian it was
        built for. ``source`` is what the Hessian is a function of — the (symmetrized) operator,
        the weights and the scales; the same source costs nothing to recognize, another one (a
        user's new problem on the same matrix) is compared entry by entry (``O(n²)``).
        """
        key = self.structure_key(form)
        hit = self._solvers.get(key)
        if hit is not None and hit[2].shape == form.H.shape:
            src, obj, H = hit
            same = src is not None and source is not None and src[0] is source[0] and src[1:] == source[1:]
            if same or np.array_equal(H, form.H):
                if not same:
                    self._solvers[key] = (source, obj, H)
                return obj, False
        obj = build(form)
        if len(self._solvers) >= self.MAX_SOLVERS:
            self._solvers.pop(next(iter(self._solvers)))
        self._solvers[key] = (source, obj, form.H.copy())
        return obj, True

    def _solve_form(self, form, x0, source=None):  # pragma: no cover - abstract
        """Return ``(x, y, status, iterations, solver_time, info)``; status 'solved' or the solver's."""
        raise NotImplementedError


def check_convex(sym, f) -> None:
    """The QP of a step is convex: ``sym(F·A)`` positive definite, checked once per operator.

    An attempted Cholesky factorization of ``F·A_sym`` (scaled by its largest diagonal entry),
    kept in the operator's memo. A matrix that fails it — indefinite, singular, zero — has no
    convex QP: an :class:`InputError` on ``A`` before any solver sees it (a solver handed a
    non-convex QP fails in its own words, or worse, returns something).
    """
    def test():
        M = f[:, None] * sym.dense()
        d = float(np.max(np.abs(np.diagonal(M)))) if M.size else 0.0
        if not d > 0:
            return "its diagonal is zero"
        try:
            np.linalg.cholesky(0.5 * (M + M.T) / d)
        except np.linalg.LinAlgError:
            lam = float(np.linalg.eigvalsh(0.5 * (M + M.T) / d)[0])
            return f"its smallest eigenvalue is {lam:.3e} (relative to the largest diagonal entry)"
        return None

    why = sym.memo(("convex", np.asarray(f, dtype=float).tobytes()), test)
    if why is not None:
        raise InputError("A", f"the QP methods need sym(F·A) positive definite (a convex QP), but {why}; "
                              "check the influence matrix (or its reference distance), or use method 'newton'")


def constraint_rows(form):
    """Indices of the rows ``x_i <= u_i`` (finite ``u``), ``-x_i <= -l_i`` (finite ``l``) and
    ``x_i = l_i`` (``l_i == u_i``: a node with a zero friction bound).

    Fixed variables are equalities, not two opposite active inequalities: the latter make
    an interior point's interior empty and an active-set polish's KKT system singular.
    """
    n = form.H.shape[0]
    fixed = form.fixed
    up = np.flatnonzero(np.isfinite(form.upper) & ~fixed)
    lo = np.flatnonzero(np.isfinite(form.lower) & ~fixed)
    return n, up, lo, np.flatnonzero(fixed)


def active_set_refine(form, x, y):
    r"""One equality-constrained KKT solve on the active set the solver found.

    An interior-point method stops with every complementary pair ``(slack, multiplier)``
    small but not zero: where both are small (a node at the edge of the contact or of a
    slip zone) each is about ``sqrt(gap)``, so Clarabel's tractions stop near 1e-8 of p0
    even at gap tolerances of 1e-15. With the Lagrangian of :class:`~rollqp.problem.QPForm`
    the bound multipliers are ``λ = H x + q + y a`` (``λ_i > 0`` at a lower, ``< 0`` at an
    upper bound), and the active set is read off as the NCP form reads it:
    ``x_i − l_i < λ_i`` (at the lower bound), ``u_i − x_i < −λ_i`` (at the upper). Then

    .. math::
        \begin{bmatrix} H_{FF} & a_F \\ a_F^T & 0 \end{bmatrix}
        \begin{bmatrix} x_F \\ y \end{bmatrix} =
        \begin{bmatrix} -q_F - H_{FA} x_A \\ b - a_A^T x_A \end{bmatrix}

    with ``x_A`` at its bounds. This is OSQP's *polishing* (Stellato et al., Math. Prog. Comp.
    12 (2020) §5) applied to another solver's answer. The caller keeps the result only if
    rollqp's residual of it is smaller than that of the solver's own answer, so a wrong
    guess of the active set cannot make things worse. Returns ``None`` if the reduced
    system is singular.
    """
    H, q, l, u, a = form.H, form.q, form.lower, form.upper, form.a
    x = np.asarray(x, dtype=float)
    lam = H @ x + q + (float(y) * a if a is not None else 0.0)
    fixed = form.fixed.copy()
    at_lo = np.isfinite(l) & (x - l < lam) & ~fixed
    at_up = np.isfinite(u) & (u - x < -lam) & ~fixed
    xa = x.copy()
    xa[fixed] = l[fixed]
    xa[at_lo] = l[at_lo]
    xa[at_up] = u[at_up]
    act = fixed | at_lo | at_up
    F = np.flatnonzero(~act)
    A_ = np.flatnonzero(act)
    rhs = -(q[F] + H[np.ix_(F, A_)] @ xa[A_])
    try:
        if a is None:
            xF = np.linalg.solve(H[np.ix_(F, F)], rhs) if F.size else np.empty(0)
            yr = 0.0
        else:
            if F.size == 0:
                return None
            m = F.size
            K = np.zeros((m + 1, m + 1))
            K[:m, :m] = H[np.ix_(F, F)]
            K[:m, m] = K[m, :m] = a[F]
            sol = np.linalg.solve(K, np.append(rhs, form.b - a[A_] @ xa[A_]))
            xF, yr = sol[:m], float(sol[m])
    except np.linalg.LinAlgError:
        return None
    if not np.all(np.isfinite(xF)):
        return None
    xa[F] = xF
    return xa, yr
