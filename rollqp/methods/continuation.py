r"""Which solution of a slip-dependent step every method returns: the end of the path from the frozen bound.

A falling friction law can give one step several solutions (docs/friction.md, "Which solution of a step").
Which one a method finds would then depend on the method (docs/friction.md shows two methods' solutions of
the same step far apart, both to round-off). :class:`SlipContinuation` makes the choice once, for every method
that the registry composes with it (:func:`rollqp.methods.compose`): the solution returned is the end at
``λ = 1`` of the curve of solutions of the steps with the bound

.. math::
    \mu_\lambda(s) = (1 - \lambda)\,\mu_f + \lambda\,\mu(s), \qquad \mu_f = \mu(s_{\text{warm}}),

through the unique solution at ``λ = 0`` (the frozen bound: a convex QP), followed by arclength through its
folds and its changes of stick and slip (:mod:`.path`). It is the selection the rolling start makes at the
scale of the whole contact (the branch continuous with Coulomb at the static value, docs/friction.md), made
for every step: the solution that grows continuously out of the step with the previous state's friction
coefficients as the law's dependence on the new slip is switched on.

**What each method does.** The step at ``λ = 0`` is solved by the method itself (a convex QP for the QP
backends, Newton's constant-bound path for ``newton``); the path is followed by :func:`.path.follow` (rollqp's
own arithmetic on the step's NCP form, the same for every method); the step at its end is solved by the method
again, from the path's end, as a point of the path (:attr:`SlipBound.on_path
<rollqp.friction.bound.SlipBound.on_path>`: Newton's slip path from there, without its search for another
solution; the fixed point on the bound from there). So each method's answer is its own solution of the step,
with rollqp's residual, and all of them are the same solution.

**When.** On every step of a falling law (``μ_s > μ_k``): whether a step has more than one solution cannot be
told from its data at a cost below the path's. A second solution needs the bound map (the fixed point on the
bound, :mod:`.fixedpoint`) to expand somewhere, i.e. ``|∂μ/∂s|`` times the slip's response to a change of the
traction over the slip zone above one (docs/theory.md); the per-node estimate :func:`steepness`,
``κ = max_i |∂μ/∂s|_max p_i⁺ A_ii/Δq``, misses the response of the zone as a whole, so a threshold on it
that holds on one mesh need not hold on a finer one. On a mild law the path is short (docs/friction.md's
sweep table, column "path points"). A law that does not fall (``μ_s = μ_k``: a constant coefficient through
the law's path) and every other step take the method's own path unchanged. ``threshold`` sets another limit on κ (``inf``: never select, the
methods' own choice).

**Steady solves** are not selected: their operator is far from symmetric, the step at ``λ = 0`` is no convex
QP and need not have one solution; the branch of a direct steady solve is chosen by its braked start
(docs/friction.md, "Which steady state a rolling start returns").

**On a grid** (two traction components, :mod:`rollqp.problem.grid`) the path is followed in ``λ`` by
natural-parameter steps of Newton on the disc (:func:`follow_grid`), not by arclength: a path that turns back
(a fold) stops there, and the run says so (``info["path"]``, a ``RuntimeWarning``). Each selected step reports
:func:`uniqueness_factor` (``info["uniqueness"]``): below 1 the step with its creepages prescribed has one
solution (docs/friction.md, "When a step's solution is unique").

**Where the path stops.** A path that cannot be followed to ``λ = 1`` (it runs into gross sliding, or a
corrector does not converge) leaves the step to the method's own solution (or its ``SolverError``), and
says so: ``info["path"]`` is then ``{"stopped": message, "lam": λ reached}``.
"""
from __future__ import annotations

import time
import warnings

import numpy as np

from ..errors import SolverError
from .path import FrozenBoundPath, PathStop, follow

__all__ = ["SlipContinuation", "steepness", "frozen_coefficients", "uniqueness_factor", "follow_grid", "STEEP"]

#: :func:`steepness` from which a step's solution is selected by the path: every falling law (module docstring).
STEEP = 0.0


def _grid(problem) -> bool:
    """A grid's step (two traction components: the slip of shape ``(2, n)``), else a strip's."""
    return getattr(problem, "slip_shape", None) is not None


def steepness(problem) -> float:
    """``κ = max_i |∂μ/∂s|_max p_i⁺ |A_ii| / Δq`` of a slip-dependent step (module docstring): the largest factor by
    which a change of one node's coefficient can feed back on itself through its own slip, with the law at its
    steepest (:attr:`~rollqp.friction.bound.SlipBound.steepness`). On a grid ``A_ii`` is the larger diagonal entry of
    the element's 2 × 2 block of the slip operator ``B``."""
    if _grid(problem):
        d = np.abs(np.asarray(problem.B.diagonal(), dtype=float)).reshape(2, -1).max(axis=0)
    else:
        d = np.abs(np.asarray(problem.A.diagonal(), dtype=float))
    return problem.law.steepness * float(np.max(np.maximum(problem.p, 0.0) * d, initial=0.0)) / problem.dq


def frozen_coefficients(problem, warm) -> np.ndarray:
    """``μ_f``: the law's coefficients at the warm start's slip (the previous state's), or at rest without one; at
    rest also where those carry less than the prescribed load (the frozen step has no solution with stick)."""
    n, law = problem.n, problem.law
    shape = problem.slip_shape if _grid(problem) else (n,)
    s = warm.s if warm is not None and warm.s is not None and np.shape(warm.s) == shape else np.zeros(shape)
    mu = law.mu(np.asarray(s, dtype=float))
    if _grid(problem):
        F = np.hypot(problem.Fx or 0.0, problem.Fy or 0.0)
        if (problem.Fx is not None or problem.Fy is not None) and \
                not F < problem.area * float(np.sum(mu * np.maximum(problem.p, 0.0))):
            mu = law.mu(np.zeros(shape))
        return mu
    if problem.Q is not None and not abs(problem.Q) < float(problem.f @ (mu * np.maximum(problem.p, 0.0))):
        mu = law.mu(np.zeros(n))
    return mu


class SlipContinuation:
    """``inner`` with the solution of its slip-dependent steps selected by the path from the frozen bound (module
    docstring). Every other step, and a slip-dependent one whose :func:`steepness` is below ``threshold``, goes to
    ``inner`` unchanged (a law that does not fall has κ = 0). ``info`` of a selected solution: ``path`` (points, changes of piece, turns of ``λ``, the
    largest ``λ`` before the end) and ``steepness``."""

    def __init__(self, inner, threshold: float = STEEP, path_solver=None):
        self.inner = inner
        self.name, self.capabilities, self.tolerance = inner.name, inner.capabilities, inner.tolerance
        self.threshold = float(threshold)
        #: the Newton method on the grid's steps that follows the path in λ (docs/friction.md), for grids only
        self.path_solver = path_solver

    def __getattr__(self, name):
        """The inner method's settings (``max_iterations``, …): this wrapper only selects solutions."""
        if name == "inner":
            raise AttributeError(name)
        return getattr(self.inner, name)

    def carrier(self):
        """The inner method's (called only where the capabilities declare ``carries_state``)."""
        return self.inner.carrier()

    def setup(self, operators) -> None:
        self.inner.setup(operators)

    def predicting(self, on: bool):
        """The inner method's (called only where its capabilities declare it)."""
        return self.inner.predicting(on)

    def single_sweeps(self, on: bool):
        """The inner method's (called only where its capabilities declare it)."""
        return self.inner.single_sweeps(on)

    def solve(self, problem, warm=None):
        law = getattr(problem, "law", None)   # a grid's normal step has none
        if problem.kind != "tangential" or law is None or law.on_path or law.steady:
            # a steady solve's operator T·A is far from symmetric: its step at λ = 0 is no convex QP and need
            # not have one solution (module docstring, "Steady solves"; docs/friction.md)
            return self.inner.solve(problem, warm=warm)
        kappa = steepness(problem)
        if not (kappa > 0.0 and kappa >= self.threshold):
            return self.inner.solve(problem, warm=warm)
        if _grid(problem):
            return self._selected_grid(problem, warm, kappa)
        return self._selected(problem, warm, kappa)

    def _selected_grid(self, problem, warm, kappa):
        """A grid's step: the path from the frozen bound in ``λ`` by natural-parameter steps (module docstring,
        :func:`follow_grid`), its end solved by the method as a point of the path. ``info["uniqueness"]``: the
        factor :func:`uniqueness_factor` (below 1 the step with its creepages prescribed has one solution)."""
        t0 = time.perf_counter()
        unique = uniqueness_factor(problem)
        frozen = frozen_coefficients(problem, warm)
        start = self.inner.solve(problem.replace(mu=frozen, law=None), warm=warm)
        try:
            end, stats = follow_grid(self.path_solver, problem, frozen, start)
        except PathStop as err:  # the method's own solution, saying that it was not selected
            sol = self.inner.solve(problem, warm=warm)
            sol.info.update(path={"stopped": err.message, "lam": err.lam}, steepness=kappa, uniqueness=unique)
            _warn_unselected(err)
            return sol
        sol = self.inner.solve(problem.replace(law=problem.law.homotopy(frozen, 1.0)), warm=end)
        sol.info.update(path=stats, steepness=kappa, uniqueness=unique)
        sol.time = time.perf_counter() - t0
        return sol


    def _selected(self, problem, warm, kappa):
        t0 = time.perf_counter()
        frozen = frozen_coefficients(problem, warm)
        start = self.inner.solve(problem.replace(mu=frozen, law=None), warm=warm)
        sc = problem.scales
        x0 = start.t / sc.stress
        if problem.Q is not None:
            x0 = np.append(x0, start.xi / sc.slip)
        path = FrozenBoundPath(problem, frozen)
        try:
            u, stats = follow(path, x0)
        except PathStop as err:  # the method's own solution, saying that it was not selected
            sol = self.inner.solve(problem, warm=warm)
            sol.info.update(path={"stopped": err.message, "lam": err.lam}, steepness=kappa)
            return sol
        end = path.solution(u)
        sol = self.inner.solve(problem.derived(law=problem.law.homotopy(frozen, 1.0)), warm=end)
        sol.info.update(path=stats, steepness=kappa)
        sol.time = time.perf_counter() - t0
        return sol


#: Power iterations for the largest eigenvalue of a grid's slip operator (:func:`uniqueness_factor`): an upper
#: estimate is not needed to digits, 30 products give it to about 1 % on the circles measured.
POWER_ITERATIONS = 30


def uniqueness_factor(problem) -> float:
    r"""``κ_u = (1 − w) V max|dμ/dv| · max_i p̄_i⁺ · λ_max(B)/Δq`` of a grid's slip-dependent step (docs/friction.md,
    "When a step's solution is unique"): with the creepages prescribed, ``κ_u < 1`` makes the step's solution unique
    (two solutions would need ``(Δs, Δt) ≥ |Δs|²/λ_max(B/Δq)`` and ``(Δs, Δt) ≤ Σ_i k_i |Δs_i|²``, ``k_i`` the bound's
    Lipschitz constant ``(1 − w) V max|μ'| p̄_i``, at once). ``λ_max(B)`` of the symmetric slip operator by power
    iteration on its FFT products, kept with the operator."""
    B = problem.B

    def largest():
        v = np.ones(B.shape[1])
        lam = 0.0
        for _ in range(POWER_ITERATIONS):
            w = B @ v
            lam = float(np.linalg.norm(w))
            if not lam > 0.0:
                return 0.0
            v = w / lam
        return lam
    lam = B.memo(("largest eigenvalue",), largest) if hasattr(B, "memo") else largest()
    return problem.law.steepness * float(np.max(np.maximum(problem.p, 0.0), initial=0.0)) * lam / problem.dq


#: The smallest step in ``λ`` of the grid's path (:func:`follow_grid`): below it the path has met a fold.
MIN_LAMBDA_STEP = 1.0 / 1024
#: A step of the grid's path is halved when it changes the tractions by more than this many times the step before
#: it (scaled by the steps' lengths): a jump to another branch near a fold, not the smooth path.
JUMP = 4.0
#: A step of the grid's path that changes the tractions by less than this (in ``μ p0``) is never a jump: far below
#: any other branch, far above the solves' tolerance (measured: a path whose tractions did not move at all, rate 0,
#: then moved by 1e-10 from round-off, was taken for a fold before this floor).
SMOOTH = 1e-6


def follow_grid(newton, problem, frozen, start):
    """The solutions of the grid's step with the bound ``μ_λ(s) = (1 − λ) μ_f + λ μ(s)`` from ``λ = 0`` (``start``,
    the frozen step's solution) to ``λ = 1``, by natural-parameter continuation: each ``λ`` solved by ``newton`` from
    the last point, the step in ``λ`` halved where Newton fails or the tractions jump (:data:`JUMP`), doubled after
    a success. Returns ``(solution at λ = 1, stats)``; raises :class:`~.path.PathStop` where the step falls below
    :data:`MIN_LAMBDA_STEP`: the branch from the frozen bound turns back there (a fold of ``λ``), the step has
    another solution beyond it and the path is not followed around the fold on a grid."""
    lam, h, sol, points, halvings = 0.0, 0.25, start, 0, 0
    rate = None      # the last accepted step's change of the tractions per unit λ
    scale = float(np.max(np.abs(frozen) * np.maximum(problem.p, 0.0), initial=0.0)) or 1.0
    while lam < 1.0:
        step = min(h, 1.0 - lam)
        nxt = lam + step
        try:
            cand = newton.solve(problem.replace(law=problem.law.homotopy(frozen, nxt)), warm=sol)
            change = float(np.max(np.abs(cand.t - sol.t))) / scale / step
            ok = rate is None or change <= JUMP * rate or change * step <= SMOOTH
        except SolverError:
            ok = False
        if not ok:
            h = step / 2
            halvings += 1
            if h < MIN_LAMBDA_STEP:
                raise PathStop(f"the path from the frozen bound turns back near λ = {lam:.4g} (a fold: the step has "
                               "more than one solution, docs/friction.md)", lam=lam)
            continue
        lam, sol, rate, points = nxt, cand, change, points + 1
        h = min(2 * step, 0.5)
    return sol, {"points": points, "halvings": halvings, "lam_max": 1.0}


def _warn_unselected(err):
    """Say that a step's solution could not be selected: uniqueness fails there (docs/friction.md)."""
    warnings.warn(f"falling friction: {err.message}; the method's own solution is returned", RuntimeWarning,
                  stacklevel=3)
