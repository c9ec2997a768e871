"""Shared machinery of the QP backends (docs/formulation.md §6–8).

Each backend translates a :class:`~rollqp.problem.QPForm` into its solver's native form
once per *structure* (problem kind, size, which bounds are finite, load or multiplier
prescribed) and per Hessian, and afterwards only updates vectors and warm-starts.
The solution is mapped back and evaluated with rollqp's own residuals on the problem the
QP actually solves: the one with the symmetrized operator ``F⁻¹ sym(F A)``. The measured
asymmetry ``‖FA − (FA)ᵀ‖/‖FA‖`` travels with the solution (``info["asymmetry"]``).
"""
from __future__ import annotations

import dataclasses
import time

import numpy as np

from ..errors import InputError, SolverError
from ..problem import StepSolution
from .base import Capabilities, check_kind, check_options


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
    solutions, so the error contracts by ``ρ = ‖H^{-1/2} S H^{-1/2}‖₂`` per QP, independent
    of the mesh (its values: docs/validation.md). The single symmetrized QP is *not* a small
    perturbation: it puts a vertex/midnode checkerboard on the Hertz pressure, because ``S``
    feeds the log kernel's weakest mode (docs/formulation.md §8).

    ``info`` of a solution: ``qp_solves`` (QPs of the splitting), ``backend_time`` (wall time of
    the backend's calls: data update, solve, retries), ``setups`` (solver objects built),
    ``retried`` (QPs solved again after a failed polish), ``splitting_changes`` (max change of
    ``x/p0`` from QP to QP: its ratios are the splitting's contraction), ``asymmetry``, ``operator``,
    ``solve_call_time`` and ``solve_call_cpu`` (wall and CPU time inside the solver's own solve calls,
    summed over the QPs; NaN for a backend that does not report them: what rollqp adds to a step is
    the rest).

    One solver object is kept per constraint structure (:meth:`structure_key`) with the Hessian
    it was built for, recognized by its source (the Hessian array of the operator's memo,
    :func:`~rollqp.problem.qp_hessian`);
    :meth:`setup` drops them at the start of a scene. The splitting itself is the operator's own (:meth:`Operator.split
    <rollqp.influence.operator.Operator.split>`), computed once per scene.
    """

    name = "qp"
    #: Each half a convex QP; on request the QPs are solved on their predicted active sets first
    #: (:meth:`predicting`), and the accelerated rolling start takes it (:mod:`.steady_start`).
    capabilities = Capabilities(solves=frozenset({"normal", "tangential"}), predicting=True,
                                accelerated_start=True, quasi_newton=True)
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
        self.capabilities = dataclasses.replace(type(self).capabilities, operator=operator,
                                                residual_limit=self.residual_limit)
        self.options = options
        self._solvers = {}
        self._kkt = KKTCache()
        self._exact = KKTCache(_kkt_lu)  # the collocation operator's reduced systems (_exact_prediction)
        self._bounds_of = None  # (solver object, QPForm) of the last QP (_same_bounds)
        self._predict = False  # predicting

    @classmethod
    def from_settings(cls, settings, **options) -> "QPMethod":
        """From a scene's solver settings: ``tolerance``, and ``max_iterations`` as the solver's
        iteration limit per QP (absent: the backend's own); ``augmentation`` is Newton's only."""
        return cls(tolerance=settings.tolerance, max_iterations=settings.max_iterations, **options)

    def setup(self, operators) -> None:
        """A new scene: drop the solver objects of the previous one (they are rebuilt on first use)."""
        self._solvers = {}
        self._kkt = KKTCache()
        self._exact = KKTCache(_kkt_lu)
        self._bounds_of = None
        self._predict = False

    def predicting(self, on: bool) -> bool:
        """Switch the active-set prediction on or off; return whether it was on.

        With it on, a QP is first solved on the active set read off its warm start (the previous
        answer with the new data, :func:`active_set_refine`; then again from that candidate, at most
        :attr:`PREDICT_STEPS` candidates), and the backend is called only if no candidate's rollqp
        residual (:meth:`QPForm.residual <rollqp.problem.QPForm.residual>`) and distance outside its
        bounds are within :attr:`tolerance`. Such a candidate *is* the QP's solution to the accuracy the
        backend is asked for (a strictly convex QP has one KKT point; the residual measures the
        distance from it), found with the factors :class:`KKTCache` keeps per free set. For a
        sequence of QPs whose active set rarely changes: rollqp.march's rolling start (its accelerated
        phase, :mod:`rollqp.methods.steady_start`, and its march to the steady state), which approaches
        a steady state; the steps that give the state it keeps are solved with the prediction off.
        """
        was, self._predict = self._predict, bool(on)
        return was

    def kkt_caches(self) -> tuple:
        """``(Cholesky, LU)``: the :class:`KKTCache` objects of the active-set prediction (of the QP Hessians and of the
        collocation operators), whose factors the QP sensitivities of the rolling start reuse."""
        return self._kkt, self._exact

    # --------------------------------------------------------------- public
    def solve(self, problem, warm: StepSolution | None = None) -> StepSolution:
        """Solve a normal or tangential step; raise :class:`SolverError` short of solved.

        The step's QP data are formed once (:meth:`~rollqp.problem.NormalStep.qp_form`: the Hessian
        comes from the operator's memo); each QP of the splitting changes only ``q``
        (``q + ∂q/∂e · F⁻¹S x_{k−1}``), and rollqp's residual is evaluated once, on the answer.
        """
        check_kind(self, problem)
        if problem.law is not None:
            raise InputError("problem", f"method {self.name!r} solves steps with a fixed friction bound; this one depends on "
                                        "the slip: use rollqp.methods.fixedpoint.BoundFixedPoint around it (scenes do) "
                                        "or method 'newton'")
        t0 = time.perf_counter()
        sp = problem.A.split(problem.f)
        check_convex(sp.sym, problem.f)
        sym_problem = problem.derived(A=sp.sym) if sp.asymmetry > 0 else problem  # checked step: not re-validated
        exact = self.operator == "exact" and sp.asymmetry > 0
        x_prev, y_prev = None, None
        if warm is not None:
            w = problem.traction(warm)
            if w is not None and np.shape(w) == (problem.n,):
                x_prev, y_prev = np.asarray(w, dtype=float), warm.info.get("qp_multiplier")
        scratch = self._predict and (x_prev is None or y_prev is None)
        if scratch:  # predicting from scratch: from zero tractions, every node free (zero multipliers)
            x_prev, y_prev = (np.zeros(problem.n) if x_prev is None else x_prev), 0.0
        target = problem if exact or sp.asymmetry == 0 else sym_problem
        form, x, y, status, stats, info = self._splitting(target, sym_problem.qp_form(), sp.skew if exact else None,
                                                           x_prev, y_prev, scratch)
        final = target.solution_from_qp(form, x, y)  # rollqp's residuals, once
        final.method, final.status, final.iterations = self.name, "solved", stats["iterations"]
        final.solver_time = stats["solver_time"]
        final.time = time.perf_counter() - t0
        final.info.update(info)
        final.info.update(asymmetry=sp.asymmetry, operator="exact" if (exact or sp.asymmetry == 0) else "symmetrized",
                          qp_solves=stats["outer"], backend_time=stats["backend"], setups=stats["setups"],
                          retried=stats["retried"], splitting_changes=stats["changes"], solve_call_time=stats["calls"],
                          solve_call_cpu=stats["calls_cpu"], predicted=stats["predicted"], qp_multiplier=float(y))
        if not final.residual <= self.residual_limit:
            raise SolverError(f"the {problem.kind} QP solution's residual is above {self.residual_limit:.1e}",
                              method=self.name, status=status, residual=final.residual, iterations=stats["iterations"])
        return final

    def _splitting(self, problem, form, skew, x_prev, y_prev=None, scratch=False):
        """The QPs of one step: one, or (``skew`` given) the symmetric–skew splitting's sequence.

        Returns ``(form, x, y, status, stats, info)`` of the last QP. QP ``k`` has the linear term
        ``q + shift_scale · (F⁻¹S x_{k−1})`` (the gap offset or history shifted by ``F⁻¹S x``,
        docs/formulation.md §8) and stops when ``max|x_k − x_{k−1}|/p0`` is below the tolerance, or
        stalls at the QP solver's own accuracy. ``y_prev``: the QP multiplier of the warm start, if known
        (:meth:`predicting`); ``scratch``: the prediction starts with every node free (no warm start).
        """
        stress = problem.scales.stress
        q0, source = form.q, form.H  # the Hessian (from the operator's memo) identifies the solver object
        stats = dict(iterations=0, solver_time=0.0, outer=0, backend=0.0, setups=0, retried=0, changes=[], calls=0.0,
                     calls_cpu=0.0, predicted=0)
        change = np.inf
        if skew is not None and self._predict and x_prev is not None and y_prev is not None:
            hit = self._exact_prediction(problem, form, x_prev / stress, y_prev, scratch)
            if hit is not None:  # the splitting's fixed point on the predicted active set, in one solve
                stats.update(outer=1, predicted=1)
                return (*hit, "solved", stats, {"predicted": True, "solve_call_time": 0.0, "solve_call_cpu": 0.0})
        x_phys = x_prev if x_prev is not None else np.zeros(problem.n)
        while True:
            stats["outer"] += 1
            if skew is not None:
                form = form.with_q(q0 + form.shift_scale * (skew @ x_phys))  # F⁻¹ S x_{k−1}
            x0 = None if x_prev is None else x_prev / stress
            tb = time.perf_counter()
            x, y, status, it, st, info = self._answer(form, x0, y_prev, source, scratch and stats["outer"] == 1)
            stats["backend"] += time.perf_counter() - tb
            stats["calls"] += float(info.get("solve_call_time", np.nan))
            stats["calls_cpu"] += float(info.get("solve_call_cpu", np.nan))
            stats["setups"] += int(bool(info.get("built", False)))
            stats["retried"] += int(info.get("tries", 1) > 1)
            stats["iterations"] += int(it)
            stats["solver_time"] += float(st)
            stats["predicted"] += int(info.get("predicted", False))
            if status == "solved" and self.refine and not info.get("predicted", False):
                x, y = self._refined(form, x, y, info)
            if status != "solved":
                raise SolverError(f"the {problem.kind} QP was not solved", method=self.name, status=status,
                                  residual=form.residual(x, y), iterations=stats["iterations"])
            if skew is None:
                return form, x, y, status, stats, info
            x_new = form.traction(x) * stress
            last, change = change, float(np.abs(x_new - x_phys).max()) / stress
            stats["changes"].append(change)
            x_phys = x_prev = x_new
            y_prev = y
            if change <= self.tolerance or (change >= 0.5 * last and change <= self.residual_limit):
                return form, x, y, status, stats, info  # converged, or stalled at the QP solver's own accuracy
            if stats["outer"] >= self.max_splitting:
                raise SolverError("the symmetric-skew splitting did not converge", method=self.name,
                                  status=f"change {change:.2e} after {stats['outer']} QPs",
                                  iterations=stats["iterations"],
                                  residual=problem.solution_from_qp(form, x, y).residual)

    # --------------------------------------------------------------- helpers
    #: Candidates of the active-set prediction (:meth:`predicting`) before the backend is called: enough
    #: that the backend solves none of the coupled rolling start's QPs (docs/performance.md, "Measured
    #: settings of the methods").
    PREDICT_STEPS = 10

    def _answer(self, form, x0, y0, source, scratch=False):
        """``(x, y, status, iterations, solver_time, info)`` of a QP: the predicted answer
        (:meth:`predicting`) if it is within the tolerance, else the backend's (:meth:`_solve_form`)."""
        if self._predict and x0 is not None and y0 is not None:
            x, y, lam = x0, y0, (np.zeros(form.q.size) if scratch else None)
            for _ in range(self.PREDICT_STEPS):
                cand = active_set_refine(form, x, y, self._kkt, lam=lam)
                if cand is None:
                    break
                x, y = cand
                lam = form.multipliers(x, y)  # for both uses
                outside = float(np.abs(form.traction(x) - x).max(initial=0.0))  # QPForm.residual reads x clipped
                if max(form.residual(x, y, lam), outside) <= self.tolerance:
                    return x, y, "solved", 0, 0.0, {"predicted": True, "solve_call_time": 0.0, "solve_call_cpu": 0.0}
        return self._solve_form(form, x0, source)

    def _exact_prediction(self, problem, form, x0, y0, scratch=False):
        """``(form, x, y)``: the answer of the splitting's last QP, found without the splitting, or None.

        The splitting's QPs converge to the KKT point of the collocation operator itself, ``E = H +
        ∂q/∂e · F⁻¹S·p0`` in the form's variables (its linear term at ``x`` is ``q + ∂q/∂e · F⁻¹S x``,
        docs/formulation.md §8): on the active set read off the warm start that point is one solve of
        ``E``'s reduced KKT system (:func:`active_set_refine` with ``E``, factored by LU and kept per
        free set; every node free with ``scratch``), repeated from each candidate's own active set (at most
        :attr:`PREDICT_STEPS`). A
        candidate is accepted when it is within :attr:`tolerance` of solving the QP whose linear term it
        fixes itself (``form`` is that QP), i.e. when it is what the splitting would return; else the
        splitting runs as usual. For the QP rolling start, where the active set rarely changes
        (:meth:`predicting`): one LU solve a half instead of ~5 QPs of the splitting.
        """
        E, stress = collocation(problem, form), problem.scales.stress
        skew = problem.A.split(problem.f).skew
        x, y = x0, y0
        lam = np.zeros(x.size) if scratch else E @ x + form.q + (0.0 if form.a is None else float(y) * form.a)
        for _ in range(self.PREDICT_STEPS):
            cand = active_set_refine(form, x, y, self._exact, lam=lam, H=E)
            if cand is None:
                return None
            x, y = cand
            fx = form.with_q(form.q + form.shift_scale * (skew @ (form.traction(x) * stress)))
            lam = fx.multipliers(x, y)
            outside = float(np.abs(form.traction(x) - x).max(initial=0.0))
            if max(fx.residual(x, y, lam), outside) <= self.tolerance:
                return fx, x, y
            lam = E @ x + form.q + (0.0 if form.a is None else float(y) * form.a)
        return None

    def _refined(self, form, x, y, info):
        """The refined ``(x, y)`` if rollqp's residual of it (:meth:`QPForm.residual
        <rollqp.problem.QPForm.residual>`) is smaller, else the solver's own."""
        x = np.asarray(x, dtype=float)
        lam = form.multipliers(x, y)  # once for both
        cand = active_set_refine(form, x, y, self._kkt, lam=lam)
        base = form.residual(x, y, lam)
        info["unrefined_residual"] = max(base, info.get("unrefined_residual", 0.0))
        if cand is not None:
            res = form.residual(*cand)
            if res < base:
                info["refined"] = info.get("refined", 0) + 1
                return cand
        return x, y

    def _same_bounds(self, obj, form) -> bool:
        """Whether ``form`` has the bounds and load row of the last QP given to the solver object ``obj``
        (the same arrays: the splitting's QPs of one step share them), so that only ``q`` needs an update."""
        last = self._bounds_of
        return (last is not None and last[0] is obj and last[1].lower is form.lower and last[1].upper is form.upper
                and last[1].b == form.b)

    def structure_key(self, form):
        """What the backend's solver object depends on besides the Hessian (default: :attr:`QPForm.structure`)."""
        return form.structure

    def _solver_for(self, form, source, build):
        """``(solver object, fresh)`` for this constraint structure and Hessian, built on first use.

        One solver object is kept per structure (:meth:`structure_key`) with the Hessian it was
        built for. ``source`` is the Hessian array of the step problem's operator memo
        (:func:`~rollqp.problem.qp_hessian`), the same object for every step of a scene and costs
        nothing to recognize; another one (a user's new problem on the same matrix) is compared
        entry by entry (``O(n²)``).
        """
        key = self.structure_key(form)
        hit = self._solvers.get(key)
        if hit is not None and hit[2].shape == form.H.shape:
            src, obj, H = hit
            same = src is not None and src is source
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


def collocation(problem, form):
    """:func:`collocation_operator` of ``problem``'s QP ``form`` (a step whose ``F·A`` is asymmetric), kept in
    the operator's memo per weights, ``∂q/∂e`` and ``p0`` (one for every step of a march at one Δq)."""
    sp, stress = problem.A.split(problem.f), float(problem.scales.stress)
    key = ("collocation-operator", problem.f.tobytes(), form.shift_scale.tobytes(), stress)
    return problem.A.memo(key, lambda: collocation_operator(form, sp.skew, stress))


def collocation_operator(form, skew, stress):
    """``E = H + ∂q/∂e · F⁻¹S · p0``: the QP form's Hessian with the skew part of ``F·A`` put back, the
    operator of the collocation problem in the form's variables (docs/formulation.md §8: the splitting's
    QP at ``x`` has the linear term ``q + ∂q/∂e · F⁻¹S x``, so its fixed point solves ``E x + q + y a = λ``).
    ``skew``: :attr:`Split.skew <rollqp.influence.operator.Split.skew>` (``F⁻¹ skew(F A)``, physical),
    ``stress``: ``p0``. Non-symmetric, with ``H`` its symmetric part."""
    return form.H + (form.shift_scale * stress)[:, None] * skew


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


def active_set_refine(form, x, y, cache: "KKTCache | None" = None, lam=None, H=None):
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

    with ``x_A`` at its bounds, solved with the Cholesky factor of ``H_FF`` (positive definite: a
    principal block of the convex QP's Hessian) and the Schur complement ``a_Fᵀ H_FF⁻¹ a_F`` of the
    load row; ``cache`` (:class:`KKTCache`) keeps both per free set, so a step whose active set did
    not change since an earlier QP (the splitting's QPs, the next step) solves with them only.
    This is OSQP's *polishing* (Stellato et al., Math. Prog. Comp. 12 (2020) §5) applied to
    another solver's answer. The caller keeps the result only if rollqp's residual of it is
    smaller than that of the solver's own answer, so a wrong guess of the active set cannot make
    things worse. Returns ``None`` if the reduced system is singular. ``lam``: ``H x + q + y a``, if known.

    ``H``: another operator of the reduced system (default ``form.H``): the collocation operator of the
    splitting's fixed point (:meth:`QPMethod._exact_prediction`), non-symmetric, with ``cache`` a
    :class:`KKTCache` of LU factors (:func:`_kkt_lu`).
    """
    q, l, u, a = form.q, form.lower, form.upper, form.a
    exact = H is not None
    H = form.H if H is None else H
    x = np.asarray(x, dtype=float)
    if lam is None:
        lam = H @ x + q + (0.0 if a is None else float(y) * a)
    fixed = form.fixed.copy()
    at_lo = np.isfinite(l) & (x - l < lam) & ~fixed
    at_up = np.isfinite(u) & (u - x < -lam) & ~fixed
    xa = np.zeros_like(x)
    xa[fixed] = l[fixed]
    xa[at_lo] = l[at_lo]
    xa[at_up] = u[at_up]
    free = ~(fixed | at_lo | at_up)
    if a is not None and not free.any():
        return None
    fac = (cache or KKTCache(_kkt_lu if exact else _kkt_factor)).get(H, free, a)
    if fac is None:
        return None
    chol, z2, schur = fac
    solve = _lu_solve if exact else _chol_solve
    F = np.flatnonzero(free)
    rhs = -(q[F] + (H @ xa)[F])  # xa is zero on the free set: H_FA x_A
    if F.size == 0:
        xF, yr = np.empty(0), 0.0
    else:
        xF = solve(chol, rhs)  # (finiteness checked below)
        yr = 0.0
        if a is not None:
            yr = float((a[F] @ xF - (form.b - a @ xa)) / schur)
            xF = xF - yr * z2
    if not np.all(np.isfinite(xF)):
        return None
    xa[F] = xF
    return xa, yr


class KKTCache:
    """The factorizations of :func:`active_set_refine`'s reduced KKT systems, per Hessian and free set.

    An entry is ``(Cholesky factor of H_FF, H_FF⁻¹ a_F, a_Fᵀ H_FF⁻¹ a_F)``, kept for the Hessian
    array it was computed from (compared by identity: the step problems' Hessians come from their
    operator's memo, :func:`~rollqp.problem.qp_hessian`) and the load row's values; at most
    :attr:`MAX` entries, the oldest dropped first. ``None`` records a singular ``H_FF``.
    """

    MAX = 64

    def __init__(self, factor=None):
        self._entries = {}
        self._factor = _kkt_factor if factor is None else factor

    def get(self, H, free, a):
        key = (free.tobytes(), None if a is None else a.tobytes())
        hit = self._entries.get(key)
        if hit is not None and hit[0] is H:
            return hit[1]
        value = self._factor(H, free, a)
        if len(self._entries) >= self.MAX:
            self._entries.pop(next(iter(self._entries)))
        self._entries[key] = (H, value)
        return value


def _kkt_factor(H, free, a):
    """``(chol, H_FF⁻¹ a_F, a_Fᵀ H_FF⁻¹ a_F)`` for the free set, or ``None`` if ``H_FF`` is not positive definite.

    ``chol``: the upper Cholesky factor from LAPACK's ``dpotrf`` (what ``scipy.linalg.cho_factor``
    calls, without its wrappers: a step of the accelerated rolling start factors and solves with
    matrices of a few hundred rows, where the wrappers cost as much as the work).
    """
    from scipy.linalg import lapack
    F = np.flatnonzero(free)
    if F.size == 0:
        return (None, None, None)
    chol, info = lapack.dpotrf(H[np.ix_(F, F)], lower=0, clean=0)
    if info != 0:  # a pivot not positive (or NaN: LAPACK tests it): H_FF not positive definite
        return None
    if a is None:
        return chol, None, None
    z2 = _chol_solve(chol, a[F])
    schur = float(a[F] @ z2)
    return (chol, z2, schur) if np.isfinite(schur) and schur > 0 else None


def _chol_solve(chol, b):
    """``H_FF⁻¹ b`` with the factor of :func:`_kkt_factor` (LAPACK's ``dpotrs``)."""
    from scipy.linalg import lapack
    return lapack.dpotrs(chol, b, lower=0)[0]


def _kkt_lu(E, free, a):
    """``(LU, E_FF⁻¹ a_F, a_Fᵀ E_FF⁻¹ a_F)`` of a non-symmetric ``E`` on the free set (LAPACK's ``dgetrf``), as
    :func:`_kkt_factor` for a symmetric one; ``None`` if ``E_FF`` is singular or the Schur complement is not
    positive (the collocation operator's is: ``E_FF`` is a principal block of a matrix with a positive definite
    symmetric part)."""
    from scipy.linalg import lapack
    F = np.flatnonzero(free)
    if F.size == 0:
        return (None, None, None)
    lu, piv, info = lapack.dgetrf(E[np.ix_(F, F)])
    if info != 0:
        return None
    if a is None:
        return (lu, piv), None, None
    z2 = _lu_solve((lu, piv), a[F])
    schur = float(a[F] @ z2)
    return ((lu, piv), z2, schur) if np.isfinite(schur) and schur > 0 else None


def _lu_solve(factor, b):
    """``E_FF⁻¹ b`` with the factor of :func:`_kkt_lu` (LAPACK's ``dgetrs``)."""
    from scipy.linalg import lapack
    lu, piv = factor
    return lapack.dgetrs(lu, piv, b)[0]
