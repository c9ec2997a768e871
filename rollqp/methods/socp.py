r"""The 3D steps on external conic solvers: Clarabel natively, OSQP (normal step only), cvxpy
(docs/theory3d.md §5–6).

Each backend poses the normal step as the QP of eq. 3D.22 and the tangential step as the SOCP
of eq. 3D.20 (:mod:`rollqp.problem.conic`), maps the answer back (pressures, tractions, and the
load rows' multipliers as the approach and the creepages, eq. 3D.21) and evaluates it with
rollqp's own residuals on the step problem. On top of the solver:

* **tolerances** from the requested residual, never the solvers' defaults (Clarabel's defaults
  stop about 1e-4 short): gap and feasibility tolerances four decades below it, as in 2D;
* **symmetric–skew splitting** when ``âŜ`` is not symmetric: a sequence of conic programs with
  the skew part at the previous iterate (docs/formulation.md §8); a splitting that does not
  contract is a :class:`~rollqp.errors.SolverError` (the steady operator: its skew part dominates;
  the SOCP route reaches the steady state by marching, :func:`rollqp.march.grid.steady`);
* **active-set refinement** (:mod:`rollqp.methods.refine`): an interior point method ends with every
  complementary pair small but not zero, so elements at the edge of the contact or of the stick area
  are off by about ``√gap``. The answer is refined by the conic program's own KKT system on the
  active set the solver identified (eq. 3D.23: Newton iterations on smooth equations, the active set
  held fixed — OSQP's polish carried to the cone, as the 2D QPs' ``active_set_refine``) and kept only
  if rollqp's residual drops; ``info["raw"]`` keeps the solver's own answer and ``info["raw_residual"]``
  its residual, so that its distance from any other method stays visible;
* one solver object per structure (variables, cones, Hessian), afterwards only ``q`` and ``b``
  are updated (Clarabel ``update``).

OSQP has no cone: asking it for a tangential step is a one-line :class:`InputError` naming the
methods that can solve it.
"""
from __future__ import annotations

import time
import warnings

import numpy as np
import scipy.sparse as sp

from ..errors import InputError, MissingBackendError, SolverError
from .base import Capabilities, check_options
from ..threads import threads
from ..problem.conic import normal_form, tangential_form
from .refine import active_set_refine

__all__ = ["ConicMethod", "ClarabelMethod", "OsqpMethod", "CvxpyMethod", "ScsMethod", "raw_solution"]
#: Clarabel's linear solver for the KKT systems of these dense programs (:func:`_clarabel_settings`).
FACTORIZATION = "faer"
#: Largest splitting sequence; the contraction is measured and a growing change stops it earlier.
MAX_SPLITTING = 60


class ConicMethod:
    """Shared machinery of the conic backends (module docstring).

    Parameters
    ----------
    tolerance : float
        Requested rollqp residual; a solution above ``residual_limit`` (default
        ``max(100·tolerance, 1e-12)``) is a :class:`SolverError`.
    refine : bool
        Refine the solver's answer on its active set (module docstring); the raw answer stays in
        ``info["raw"]``.
    max_iterations : int, optional
        The solver's own iteration limit.
    residual_limit : float, optional
        The largest rollqp residual accepted.
    """

    #: The registry names the instance (rollqp.methods); this is the class's default label.
    name = "conic"
    #: ``time.perf_counter()`` at which Clarabel stops its iterations (a cross-check's time budget); None: none.
    deadline = None
    capabilities = Capabilities(solves=frozenset({"normal", "tangential"}), dimensions=frozenset({3}), traction_components=2,
                                friction_set="disc")

    def __init__(self, tolerance: float = 1e-10, refine: bool = True, max_iterations: int | None = None,
                 residual_limit: float | None = None):
        if not (np.isfinite(tolerance) and 0 < tolerance < 1):
            raise InputError("solver.tolerance", f"must be in (0, 1), got {tolerance!r}")
        self.tolerance = float(tolerance)
        self.refine = bool(refine)
        self.max_iterations = max_iterations
        self.residual_limit = residual_limit if residual_limit is not None else max(100 * tolerance, 1e-12)
        self._solvers = {}

    @classmethod
    def from_settings(cls, settings, **options):
        """From a scene's solver settings: ``tolerance``, ``max_iterations`` (the solver's own limit);
        options ``refine``, ``residual_limit``."""
        check_options(cls.name, options, ("refine", "residual_limit"))
        return cls(tolerance=settings.tolerance, max_iterations=settings.max_iterations, **options)

    def setup(self, operators=None) -> None:
        """A new contact: drop the solver objects of the previous one."""
        self._solvers = {}

    def solve(self, problem, warm=None):
        """Solve a normal or tangential step (eq. 3D.22/3D.20); rollqp's residuals decide."""
        if problem.kind not in self.capabilities.solves:   # a scene is refused up front by the registry, naming the methods that can
            raise InputError("solver.method", f"{self.name} cannot solve a {problem.kind} step (it solves: "
                                              f"{', '.join(sorted(self.capabilities.solves))}; its capabilities)")
        t0 = time.perf_counter()
        elements = predicted_contact(problem, warm) if problem.kind == "normal" else None
        sol, info = self._solve_on(problem, elements)
        if elements is not None and not sol.residual <= self.residual_limit:   # the prediction missed
            sol, info = self._solve_on(problem, None)
            sol.info["predicted"] = "missed: solved on every element"
        sol.info["time"] = time.perf_counter() - t0
        if not sol.residual <= self.residual_limit:
            raise SolverError(f"rollqp's residual above the limit {self.residual_limit:.1e}", method=self.name,
                              status=info.get("status"), residual=sol.residual)
        return sol

    def _solve_on(self, problem, elements):
        """The conic program over ``elements`` (normal step; None: all), refined; rollqp's residual is over
        every element."""
        form = normal_form(problem, elements) if problem.kind == "normal" else tangential_form(problem)
        x, y, info = self._splitting(form)
        sol = _solution(problem, form, x, y, self.name, info)
        if self.refine:
            sol = self._refined(problem, sol)
        else:
            sol.info.update(raw_residual=sol.residual, raw=_unknowns(sol), refined=False)
        if elements is not None:
            sol.info["predicted"] = int(elements.size)
        return sol, info

    def _splitting(self, form):
        """Solve the form; with a skew part, the splitting's sequence (docs/formulation.md §8)."""
        x, y, info = self._solve_form(form, form.q)
        if form.skew is None:
            return x, y, info
        changes = []
        for k in range(1, MAX_SPLITTING):
            x_new, y, info = self._solve_form(form, form.q + form.skew @ x)
            changes.append(float(np.max(np.abs(x_new - x))))
            x = x_new
            if changes[-1] <= self.tolerance:
                break
            if k >= 3 and changes[-1] > changes[-2] > changes[-3]:
                raise SolverError("the symmetric–skew splitting does not contract on this operator "
                                  "(steady rolling: march to the steady state instead)", method=self.name,
                                  residual=changes[-1])
        info["splitting_changes"] = changes
        return x, y, info

    def _refined(self, problem, sol):
        """:func:`~rollqp.methods.refine.active_set_refine` of the solver's answer, kept if rollqp's
        residual drops; the raw answer and its residual in ``info``."""
        raw = {"raw_residual": sol.residual, "raw": _unknowns(sol)}
        ref = active_set_refine(problem, sol)
        if ref is not None and ref.residual < sol.residual:
            info = {**sol.info, **raw, "refined": True, "refine_iterations": ref.iterations}
            return type(sol)(**{**ref.__dict__, "method": self.name, "iterations": sol.iterations, "extras": info})
        sol.info.update(raw, refined=False)
        return sol

    def _solve_form(self, form, q):   # pragma: no cover - abstract
        raise NotImplementedError


#: Rows of elements added around a warm start's contact set for the normal QP's variables.
CONTACT_MARGIN = 2


def predicted_contact(problem, warm):
    """The elements a normal step's QP is posed over: the warm start's contact set (``p > 0``) and
    :data:`CONTACT_MARGIN` rows of elements around it, or None (every element) without a warm start.

    The other elements are held at ``p = 0``; the answer is kept only if rollqp's residual over the whole
    grid passes, and then it solves the full QP too (its KKT conditions hold: the left-out elements'
    gaps are ``>= 0`` at zero pressure). A miss is solved again on every element. The QP shrinks from the
    whole grid to about the contact (the 40 × 40 kalker-circular grid: 1600 to about 900 variables, a
    dense factorization about 6 times cheaper).
    """
    if warm is None or warm.p is None or np.shape(warm.p) != (problem.n,):
        return None
    grid = problem.A.grid
    mask = (np.asarray(warm.p) > 0).reshape(grid.shape)
    if not mask.any():
        return None
    r = CONTACT_MARGIN
    padded = np.pad(mask, r)
    out = np.zeros_like(mask)
    for di in range(2 * r + 1):
        for dj in range(2 * r + 1):
            out |= padded[di:di + grid.ny, dj:dj + grid.nx]
    V = np.flatnonzero(out.ravel())
    return None if V.size == problem.n else V


def _unknowns(sol) -> dict:
    """The unknowns of a solution (copies): ``p, delta`` or ``t, xi, eta``."""
    if sol.p is not None:
        return {"p": np.array(sol.p), "delta": sol.delta}
    return {"t": np.array(sol.t), "xi": sol.xi, "eta": sol.eta}


def raw_solution(problem, solution):
    """The conic solver's own answer behind ``solution`` (``info["raw"]``, before the active-set
    refinement), evaluated on ``problem`` with rollqp's residuals; ``solution`` itself if it has none."""
    raw = solution.info.get("raw")
    if raw is None:
        return solution
    if "p" in raw:
        return problem.solution(raw["p"], raw["delta"], method=solution.method)
    return problem.solution(raw["t"], raw["xi"], raw["eta"], method=solution.method)


def _solution(problem, form, x, y, name, info):
    """Map a solver's ``(x, y)`` back to the step's unknowns (eq. 3D.21) and evaluate it."""
    sc = problem.scales
    unknowns = form.multipliers_to_unknowns(y)
    if form.kind == "normal":
        p = np.zeros(problem.n)
        p[form.elements] = np.maximum(np.asarray(x), 0.0) * sc.stress
        delta = problem.delta if problem.delta is not None else -float(unknowns[0]) * sc.displacement
        return problem.solution(p, delta, method=name, iterations=info.get("iterations", 0), extras=info)
    nv = form.elements.size
    t = np.zeros((2, problem.n))
    t[:, form.elements] = np.asarray(x).reshape(2, nv) * sc.stress
    crp = dict(zip(form.rows, unknowns * sc.slip))
    return problem.solution(t, crp.get("Fx"), crp.get("Fy"), method=name,
                            iterations=info.get("iterations", 0), extras=info)


def _clarabel_settings(tolerance, max_iterations):
    import clarabel
    s = clarabel.DefaultSettings()
    # four decades below the residual asked for (2D: qp_clarabel), floored at 1e-13: at 1e-14 Clarabel
    # stops "AlmostSolved" at a residual of 3e-4 on a 30 × 30 rolling step (540 cones), at 1e-13 it
    # reaches 9e-9 "Solved" (measured; the active-set refinement takes either to round-off)
    gap = max(1e-4 * tolerance, 1e-13)
    # max_threads: faer's own pool (0 = every core) at rollqp's BLAS threads (rollqp.threads)
    values = dict(max_threads=threads(), verbose=False, presolve_enable=False, tol_gap_abs=gap, tol_gap_rel=gap, tol_feas=gap,
                  tol_ktratio=min(1e-6, gap), iterative_refinement_reltol=1e-14,
                  iterative_refinement_abstol=1e-14, iterative_refinement_max_iter=20,
                  max_iter=int(max_iterations or 200))
    for k, v in values.items():
        setattr(s, k, v)
    try:  # the supernodal factorization: the Hessian of the contact is dense (measured: 3x less CPU than QDLDL's
        s.direct_solve_method = FACTORIZATION   # on the 40 x 40 grid, equal answers)
    except (AttributeError, ValueError, TypeError):  # pragma: no cover - an older Clarabel: its default
        pass
    return s


def _constraint_rows(form):
    """Clarabel's ``A x + s = b``: the load rows (zero cone), then ``x ≥ 0`` (normal) or one
    ``(b̂_i, t̂_x,i, t̂_y,i) ∈ Q³`` per element (tangential)."""
    import clarabel
    m, k = form.m, form.a.shape[0]
    top = sp.csr_matrix(form.a)
    cones = [clarabel.ZeroConeT(k)] if k else []
    if form.kind == "normal":
        return sp.vstack([top, -sp.identity(m)], format="csc"), np.concatenate([form.b, np.zeros(m)]), \
            cones + [clarabel.NonnegativeConeT(m)]
    nv = m // 2
    i = np.arange(nv)
    rows = np.concatenate([3 * i + 1, 3 * i + 2])
    cols = np.concatenate([i, nv + i])
    soc = sp.csr_matrix((-np.ones(2 * nv), (rows, cols)), shape=(3 * nv, m))
    rhs = np.zeros(3 * nv)
    rhs[3 * i] = form.bound
    return sp.vstack([top, soc], format="csc"), np.concatenate([form.b, rhs]), \
        cones + [clarabel.SecondOrderConeT(3)] * nv


class ClarabelMethod(ConicMethod):
    """Clarabel (interior point, native cones): the QP of eq. 3D.22 and the SOCP of eq. 3D.20."""

    name = "clarabel"

    def _solve_form(self, form, q):
        import clarabel
        key = (form.kind, form.elements.tobytes(), form.rows, float(form.obj_scale))
        entry = self._solvers.get(key)
        A, b, cones = _constraint_rows(form)
        if entry is None or entry[0] is not form.H:
            P = sp.triu(sp.csc_matrix(form.H), format="csc")
            # built without the step's q and b, then given them: Clarabel scales its data once, when it is built
            # (its cost scaling reads q), so that a solver object built at another step would steer the last bits
            # of every later answer; built from (P, A) alone, the answer to a step is the same whichever step
            # built it (a resumed run repeats the uninterrupted one bit for bit)
            solver = clarabel.DefaultSolver(P, np.zeros_like(q), A, np.zeros_like(b), cones,
                                            _clarabel_settings(self.tolerance, self.max_iterations))
            self._solvers = {key: (form.H, solver)}
        else:
            solver = entry[1]
        solver.update(q=q, b=b)
        deadline = self.deadline
        if deadline is not None:  # a time budget (the run's cross-check): stop at its end
            solver.set_termination_callback(lambda info: time.perf_counter() > deadline)
        else:
            solver.unset_termination_callback()
        sol = solver.solve()
        status = str(sol.status)
        if deadline is not None and time.perf_counter() > deadline and status not in ("Solved", "AlmostSolved"):
            raise SolverError("stopped at the end of its time budget", method=self.name, status="budget")
        if status not in ("Solved", "AlmostSolved"):
            raise SolverError("Clarabel did not solve the step", method=self.name, status=status)
        k = form.a.shape[0]
        return np.asarray(sol.x), np.asarray(sol.z[:k]), {"status": status, "iterations": int(sol.iterations)}


class OsqpMethod(ConicMethod):
    """OSQP (ADMM, polished) on the normal QP of eq. 3D.22; a tangential step is an InputError."""

    name = "osqp"
    #: No cones: the friction disc cannot be posed, so it solves the normal QP only.
    capabilities = Capabilities(solves=frozenset({"normal"}), dimensions=frozenset({3}), traction_components=2,
                                friction_set="interval")

    def _solve_form(self, form, q):
        import osqp
        m, k = form.m, form.a.shape[0]
        lo = np.concatenate([form.b, np.zeros(m)])
        hi = np.concatenate([form.b, np.full(m, np.inf)])
        key = (form.kind, form.elements.tobytes(), form.rows, float(form.obj_scale))
        entry = self._solvers.get(key)
        if entry is None or entry[0] is not form.H:
            P = sp.triu(sp.csc_matrix(form.H), format="csc")
            A = sp.vstack([sp.csr_matrix(form.a), sp.identity(m)], format="csc")
            solver = osqp.OSQP()
            # ADMM's stopping test is on its scaled KKT residuals; the polish (an active-set KKT solve)
            # then gives the exact answer: three decades below the residual asked for, as the 2D backend
            eps = max(1e-3 * self.tolerance, 1e-15)
            solver.setup(P, q, A, lo, hi, verbose=False, eps_abs=eps, eps_rel=eps, polishing=True,
                         max_iter=int(self.max_iterations or 200000), polish_refine_iter=10)
            self._solvers = {key: (form.H, solver)}
        else:
            solver = entry[1]
            solver.update(q=q, l=lo, u=hi)
        res = solver.solve(raise_error=False)
        status = str(res.info.status)
        if "solved" not in status.lower():
            raise SolverError("OSQP did not solve the step", method=self.name, status=status)
        return np.asarray(res.x), np.asarray(res.y[:k]), {"status": status, "iterations": int(res.info.iter),
                                                           "polish": int(res.info.status_polish)}


class CvxpyMethod(ConicMethod):
    """cvxpy's textbook statement of eq. 3D.22/3D.20 (DPP parameters), on ``solver`` (``"CLARABEL"``
    or ``"SCS"``)."""

    name = "cvxpy"
    #: The solver cvxpy hands the program to.
    default_solver = "CLARABEL"

    def __init__(self, tolerance: float = 1e-10, refine: bool = True, max_iterations=None, residual_limit=None,
                 solver: str | None = None):
        super().__init__(tolerance, refine, max_iterations, residual_limit)
        try:
            import cvxpy
        except ImportError:
            raise MissingBackendError("the cvxpy methods need cvxpy: pip install 'rollqp[cvxpy]'") from None
        solver = self.default_solver if solver is None else solver
        if solver not in cvxpy.installed_solvers() or solver not in ("CLARABEL", "SCS"):
            raise InputError("solver", f"must be an installed one of CLARABEL, SCS, got {solver!r}")
        self.solver = solver

    def _options(self):
        if self.solver == "SCS":   # first order: its accuracy, not the residual asked for, decides
            return dict(eps_abs=1e-12, eps_rel=1e-12, max_iters=int(self.max_iterations or 200000))
        gap = max(1e-4 * self.tolerance, 1e-13)   # as _clarabel_settings
        return dict(tol_gap_abs=gap, tol_gap_rel=gap, tol_feas=gap, tol_ktratio=min(1e-6, gap),
                    max_iter=int(self.max_iterations or 200), direct_solve_method=FACTORIZATION)

    def _build(self, form):
        import cvxpy as cp
        m, k = form.m, form.a.shape[0]
        x = cp.Variable(m)
        qp = cp.Parameter(m)
        cons = []
        if k:
            bp = cp.Parameter(k)
            cons.append(form.a @ x == bp)
        else:
            bp = None
        if form.kind == "normal":
            cons.append(x >= 0)
            bnd = None
        else:
            nv = m // 2
            bnd = cp.Parameter(nv, nonneg=True)
            cons.append(cp.SOC(bnd, cp.vstack([x[:nv], x[nv:]]), axis=0))
        obj = cp.Minimize(0.5 * cp.quad_form(x, cp.psd_wrap(form.H)) + qp @ x)
        return cp.Problem(obj, cons), x, qp, bp, bnd, cons

    def _solve_form(self, form, q):
        key = (form.kind, form.elements.tobytes(), form.rows)
        entry = self._solvers.get(key)
        if entry is None or entry[0] is not form.H:
            entry = (form.H, self._build(form))
            self._solvers = {key: entry}
        prob, x, qp, bp, bnd, cons = entry[1]
        qp.value = q
        if bp is not None:
            bp.value = form.b
        if bnd is not None:
            bnd.value = form.bound
        with warnings.catch_warnings():   # "may be inaccurate": rollqp's residual decides, not the status
            warnings.simplefilter("ignore", UserWarning)
            # warm_start=False: cvxpy would otherwise keep Clarabel's solver object from step to step, whose
            # scaling (made from the first step's data) steers the last bits of every later answer
            prob.solve(solver=self.solver, warm_start=False, **self._options())
        if prob.status not in ("optimal", "optimal_inaccurate") or x.value is None:
            raise SolverError(f"cvxpy/{self.solver} did not solve the step", method=self.name, status=prob.status)
        y = np.asarray(cons[0].dual_value, dtype=float).ravel() if bp is not None else np.zeros(0)
        return np.asarray(x.value), y, {"status": prob.status, "solver": self.solver,
                                        "iterations": int(prob.solver_stats.num_iters or 0)}


class ScsMethod(CvxpyMethod):
    """cvxpy's statement (:class:`CvxpyMethod`) solved by SCS (a first-order conic solver, asked for
    1e-12: its own accuracy, not the residual asked for, decides)."""

    name = "scs"
    default_solver = "SCS"
