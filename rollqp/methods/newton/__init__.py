r"""Generalized Newton method with line search (GNMls; Pang 1990; paper §4, eq. 74–90).

Solves the *uncoupled* normal and tangential step problems (:class:`~rollqp.problem.NormalStep`,
:class:`~rollqp.problem.TangentialStep`) as the nonsmooth equations of docs/formulation.md §4,
with the problem's own collocation operator ``A`` (no symmetrization), so that its solution is
the one the QP backends reach by symmetric–skew splitting (``operator="exact"``).

Nondimensional unknowns (:class:`~rollqp.problem.Scales`: ``p0``, ``a_H``, ``E*``;
``u0 = a_H p0/E*``) with the linear rows eliminated — the "halved system" of docs/formulation.md §10:

.. math::
    \hat g = \hat h - \hat\delta\, e + \hat A \hat p, \qquad
    \hat s = \hat\xi\, e + (\hat c + \hat A \hat t)/\Delta\hat q,

    \Phi_N(\hat p, \hat\delta) = \begin{bmatrix} \min(\hat p,\; r \hat g) \\
        \hat f^T \hat p - \hat P \end{bmatrix}, \qquad
    \Phi_T(\hat t, \hat\xi) = \begin{bmatrix} \hat t - \mathrm{Proj}_{[-b, b]}(\hat t - r \hat s) \\
        \hat f^T \hat t - \hat Q \end{bmatrix},\quad b = \mu \hat p^+ ,

with ``Â = A E*/a_H``, ``f̂ = f/a_H``, ``ĥ = (h + o)/u0``, ``ĉ = c/u0``, ``Δq̂ = Δq/a_H``. With
``δ`` (``ξ``) prescribed the load row and ``δ̂`` (``ξ̂``) are dropped.

Newton direction (eq. 74, 80): ``J d = −Φ`` with ``J`` the Jacobian of the linear part plus the
pseudo-Jacobian of the ``min``/``Proj`` rows chosen node by node (eq. 82–90, the paper's
"modified" linear choice on the kinks). ``J`` is never formed: the identity rows (separated
and slipping nodes) are eliminated and the rest is solved on the free nodes
(:meth:`~.linear.ReducedSystem.direction`, LAPACK ``getrf``/``getrs``), reusing the last factorization
through a small Schur complement while the active set moves by a few nodes; the coupled step
reuses its LU likewise, by a Woodbury update of the rows whose node case changed
(:class:`~.linear.CoupledFactors`). Step length (eq. 75–79): ``α = ρ^m`` (``s = 1``), the first
``m`` with ``θ(z + αd) <= (1 − 2σα) θ(z)``, ``θ = ½‖Φ‖²``. Along the search line only the
``min``/``Proj`` are re-evaluated: the linear parts ``r ĝ``, ``r ŝ`` move by ``α K d`` with
``K d`` computed once per iteration. The linear part is carried from iterate to iterate this way
(on large strips ``K d`` is ``−Φ`` on the free rows and block products on the rows ``Φ`` reads:
:func:`~.linear.partial_product`), and evaluated anew from one product ``A x`` of the traction
wherever the stopping test is passed; the step's solution reuses that product (slip, residuals,
``w``) and the next step starts from it.

**The augmentation r.** The paper's ``r = 0.1 N/mm`` is dimensional. Here ``r`` is
nondimensional and chosen so that the two arguments of ``min``/``Proj`` respond alike to a
change of the traction at the node itself: ``∂p̂_i/∂p̂_i = 1`` against ``r ∂ĝ_i/∂p̂_i = r Â_ii``
(normal) and ``∂t̂_i/∂t̂_i = 1`` against ``r ∂ŝ_i/∂t̂_i = r Â_ii/Δq̂`` (tangential), on average::

    r_N = 1 / mean(diag Â),        r_T = Δq̂ / mean(diag Â)

(``r_N ≈ 5.3``, ``r_T ≈ 0.17`` on 40 quadratic elements with ``Δq = Le/2``). Any ``r > 0`` has
the same solutions (``min(p, r g) = 0`` and the friction projection are independent of
``r``); only the path of the iteration changes. Pass ``r=`` to override.

**Stopping.** ``‖Φ‖_∞ <= tolerance·min(1, r)``: rollqp's residuals (:class:`Residuals`) are the
same functions with ``r = 1``, and ``|min(a, b)| <= |min(a, r b)|/min(1, r)`` (likewise for the
projection residual), so the returned solution's ``residual`` is ``<= tolerance``. ``Φ`` is
piecewise linear: once the active sets are right the next full step is exact, and the
iteration ends at round-off (quadratic, indeed finite, termination).

Deviations from the paper, both on degenerate iterates only:

* if no node is in contact (normal) or in stick (tangential) while the load row is present,
  the ``δ̂`` (``ξ̂``) column of ``J`` vanishes. ``δ̂`` (``ξ̂``) is then shifted until the node
  nearest to switching lies on its kink — the shift moves every ``y_i`` alike, so no other node
  changes case and ``Φ`` (and ``θ``) does not change — and that node gets the contact/stick row,
  the one-sided derivative into contact/stick (counted in ``info["shifts"]``);
* if the Armijo search fails (``α < 1e-10``; possible only on a kink, where the modified row is
  not the directional derivative), the full step is taken (counted in ``info["nonmonotone"]``);
* if a tangential step with ``Q`` prescribed still fails (one stick node: the repair above can
  cycle, e.g. free rolling at μ ≲ 3e-4), it is solved with ``ξ`` prescribed and ``ξ`` is searched
  for ``fᵀt = Q`` (:func:`~.creepage.tangential_by_creepage`; counted in ``info["creepage_search"]``).

Robustness (docs/stability.md): the nondimensional ``r`` may be set (``[solver] augmentation``,
the same for both rows) within [1e-6, 10], where every hard case converges; failures are
:class:`~rollqp.errors.SolverError` with the merit, iterations and ``‖Φ‖∞``.

References: J.-S. Pang, Newton's method for B-differentiable equations, Math. Oper. Res. 15
(1990) 311–341; González & Abascal, IJNME 53 (2002) 843–874, §4.

The package, along the paper: :mod:`.ncp` (Φ, the node cases and pseudo-Jacobian rows,
eq. 74–90), :mod:`.linear` (the reduced and bordered systems, the coupled system, the reused
factorizations), :mod:`.uncoupled` (GNMls on the normal and tangential steps), :mod:`.coupled`
(GNMls on the coupled step); :class:`NewtonMethod` here is the method of the registry.
"""
from __future__ import annotations

import time

import numpy as np

from ...errors import InputError, SolverError
from ...problem import StepSolution
from ..base import Capabilities, check_options
from . import linear
from .coupled import solve_coupled
from .creepage import tangential_by_creepage
from .linear import CoupledFactors, ReducedSystem, coupled_system, coupled_vectors
from .ncp import NormalNCP, TangentialNCP, coupled_cases, coupled_jacobian, coupled_labels, coupled_phi
from .slip_step import solve_slip_step
from .uncoupled import solve_uncoupled

__all__ = ["NewtonMethod"]


class NewtonMethod:
    r"""GNMls for one uncoupled step (paper §4, eq. 74–90); see the module docstring.

    Parameters
    ----------
    tolerance : float
        Target of ``‖Φ‖_∞`` (nondimensional; scaled by ``min(1, r)`` so that rollqp's own
        residual of the result is below it).
    max_iterations : int
        Newton iterations (directions) per step before :class:`~rollqp.errors.SolverError`.
    r : float, optional
        Nondimensional augmentation; default ``1/mean(diag Â)`` for the normal and
        ``Δq̂/mean(diag Â)`` for the tangential problem (module docstring).
    rho, sigma : float
        Armijo parameters (eq. 75–78): ``α = ρ^m``, accept when
        ``θ(z + αd) <= (1 − 2σα) θ(z)``. Paper: ``ρ = 0.9``, ``σ = 0.1``.

    Notes
    -----
    ``solve`` returns the :class:`~rollqp.problem.StepSolution` built by the problem itself
    (``problem.solution``), so its residuals are rollqp's. ``info`` holds ``r``,
    ``backtracks`` (Armijo reductions, all iterations), ``merit`` (final ``θ``),
    ``history`` (``‖Φ‖_∞`` before each iteration and at the end), ``merits`` (``θ``, likewise),
    ``steps`` (the accepted
    ``α`` of each iteration), ``nonmonotone`` (full steps taken after a failed search),
    ``shifts`` (degenerate iterates repaired) and
    ``start`` (``"warm"`` or ``"cold"``).
    """

    name = "newton"
    #: Every kind of step, the steady one included, on the collocation operator itself (not
    #: F⁻¹ sym(F A)); steps whose friction bound depends on the slip too (:mod:`.slip`), but coupled
    #: steps with a constant coefficient only.
    capabilities = Capabilities(solves=frozenset({"normal", "tangential", "coupled", "steady"}), slip_dependent=True,
                                coupled_friction=frozenset({"constant"}), carries_state=True)
    #: Coupled steps: reuse the LU of the coupled Jacobian across iterations and steps
    #: (:class:`~.linear.CoupledFactors`); ``False`` solves a new reduced system every iteration
    #: (:func:`~.linear.direct_coupled_direction`, the reference the tests compare with).
    coupled_reuse = True
    #: Record the factorizations of the uncoupled systems (:attr:`ReducedSystem.events
    #: <.linear.ReducedSystem.events>`), for a march that journals its states (:mod:`rollqp.solverstate`)
    record = False

    def __init__(self, tolerance: float = 1e-10, max_iterations: int = 200, r: float | None = None,
                 rho: float = 0.9, sigma: float = 0.1):
        if not (np.isfinite(tolerance) and 0 < tolerance < 1):
            raise InputError("solver.tolerance", f"must be in (0, 1), got {tolerance!r}")
        if max_iterations is None:
            max_iterations = 200
        if int(max_iterations) != max_iterations or max_iterations < 1:
            raise InputError("solver.max_iterations", f"must be an integer >= 1, got {max_iterations!r}")
        if r is not None and not (np.isfinite(r) and r > 0):
            raise InputError("r", f"the augmentation must be a finite number > 0, got {r!r}")
        if not (0 < rho < 1):
            raise InputError("rho", f"must be in (0, 1), got {rho!r}")
        if not (0 < sigma < 0.5):
            raise InputError("sigma", f"must be in (0, 1/2), got {sigma!r}")
        self.tolerance = float(tolerance)
        self.max_iterations = int(max_iterations)
        self.r = None if r is None else float(r)
        self.rho = float(rho)
        self.sigma = float(sigma)
        self._systems = {}
        self._coupled = {}
        self._last = None  # (A, f, kind, Δq̂, scales, system) of the last uncoupled step
        self._large, self._dropped = 1, set()  # large systems kept at once; keys of those dropped

    @classmethod
    def from_settings(cls, settings, **options) -> "NewtonMethod":
        """From a scene's solver settings: ``tolerance``, ``max_iterations`` (Newton iterations per
        step, default 200) and ``augmentation`` (``r``, default automatic)."""
        check_options(cls.name, options, ("rho", "sigma"))
        return cls(tolerance=settings.tolerance, max_iterations=settings.max_iterations,
                   r=settings.augmentation, **options)

    def carrier(self):
        """Itself: it keeps the reduced systems' factors across steps (``capabilities.carries_state``)."""
        return self

    def setup(self, operators) -> None:
        """A new scene: drop the scaled systems and factorizations of the previous one."""
        self._systems = {}
        self._coupled = {}
        self._cache = {}
        self._last = None
        self._large, self._dropped = 1, set()


    # ------------------------------------------------------------------ public
    def solve(self, problem, warm: StepSolution | None = None) -> StepSolution:
        """Solve a normal, tangential or coupled step; raise :class:`SolverError` short of the tolerance."""
        t0 = time.perf_counter()
        if problem.kind == "coupled":
            if problem.law is not None or np.ndim(problem.mu) != 0:
                raise InputError("solver.method", "newton's coupled step takes a constant friction coefficient "
                                                  "only; for a friction law on a coupled scene use 'nt-newton' "
                                                  "(Newton halves in the N–T alternation) or a qp-* method")
            return solve_coupled(self, problem, warm, t0)
        if problem.kind == "tangential" and problem.law is not None:
            return self._solve_slip(problem, warm, t0)
        if problem.kind not in ("normal", "tangential"):
            raise InputError("problem", f"the Newton method solves normal, tangential or coupled steps, "
                                        f"not {problem.kind!r}")
        try:
            sol = solve_uncoupled(self, problem, warm, t0)
        except SolverError as err:
            if problem.kind != "tangential" or problem.Q is None:
                raise
            sol = tangential_by_creepage(self, problem, warm, t0, err)
        return self.checked(sol)

    def _solve_slip(self, problem, warm, t0):
        """A slip-dependent tangential step (:func:`.slip_step.solve_slip_step`: Newton from the warm start, safeguarded
        by the fixed point on the bound, a cold start and, with ``Q`` prescribed, the creepage search)."""
        return solve_slip_step(self, problem, warm, t0)

    def augmentation(self, problem) -> float:
        """The nondimensional ``r`` used for ``problem`` (package docstring)."""
        dqh = problem.dq / problem.scales.length if problem.kind == "tangential" else None
        return self.system(problem, dqh).r

    # ------------------------------------------------------------------ the workspace
    #: Scaled systems kept per method (with their LU factors) before the oldest is dropped: a
    #: scene has a few (normal, tangential at Δq and at the braked start's Δ, steady).
    MAX_SYSTEMS = 16
    #: Large systems (``K`` of :data:`LARGE_BYTES` or more: at 2,561 nodes 50 MB, with its factors up to 100 MB)
    #: kept at once: one to begin with, so that the start's systems (a normal half that stays fixed, the
    #: braked start's Δ) make way for the rolling steps' instead of staying beside them; one more each time
    #: a dropped system is asked for again (a scene whose steps alternate between two: one rebuild, n²
    #: operations and a factorization), up to :data:`MAX_LARGE_SYSTEMS`.
    MAX_LARGE_SYSTEMS = 3
    LARGE_BYTES = 8 << 20

    def system(self, pb, dqh) -> ReducedSystem:
        """The :class:`~.linear.ReducedSystem` of an uncoupled step, built once per operator, weights,
        scales, ``Δq̂`` and ``r`` and kept in the method's workspace (:meth:`setup` clears it).

        Keyed by the :class:`~rollqp.influence.operator.Operator` object itself (it lives as long as
        the entry, and is validated and read-only), not by its address: the workspace holds state
        that changes from step to step (the LU factors), so it belongs to the method, not to the
        operator's memo.
        """
        sc = pb.scales
        last = self._last
        if (last is not None and last[0] is pb.A and last[1] is pb.f and last[2] == pb.kind and last[3] == dqh
                and last[4] is sc):  # the same operator, weights and scales as the last step (no O(n) key)
            return last[5]
        key = (pb.kind, pb.A, pb.f.tobytes(), sc, dqh, self.r)
        hit = self._systems.get(key)
        if hit is not None:
            self._systems[key] = self._systems.pop(key)  # most recently used last
            self._last = (pb.A, pb.f, pb.kind, dqh, sc, hit)
            return hit
        n, last = pb.n, None  # (not holding the last step's system while a new one is built)
        self._make_room(key, 8 * n * (n + 1))
        K = np.empty((n, n + 1))  # Â in its first n columns, scaled into K in place (ReducedSystem)
        Ahat = np.multiply(pb.A.dense(), sc.modulus / sc.length, out=K[:, :n])
        fhat = pb.f / sc.length
        scale = float(np.mean(np.diag(Ahat)))
        if not scale > 0:
            raise InputError("A", "the influence matrix must have a positive mean diagonal")
        if pb.kind == "normal":
            r = self.r if self.r is not None else 1.0 / scale
            last, t_scale = -np.ones(pb.n), 1.0  # ∂(r ĝ)/∂δ̂ = −r, ∂(r ĝ)/∂p̂ = r Â
        else:
            r = self.r if self.r is not None else dqh / scale
            last, t_scale = np.ones(pb.n), dqh  # ∂(r ŝ)/∂ξ̂ = r, ∂(r ŝ)/∂t̂ = r Â/Δq̂
        sys_ = ReducedSystem(pb.A, pb.f, Ahat, fhat, r, last, t_scale, unit=sc.modulus / sc.length / sc.stress,
                             workspace=K, a_scale=sc.modulus / sc.length)
        if self.record:  # a march that journals its states records the factorizations (rollqp.solverstate)
            sys_.events = []
        self._keep(self._systems, key, sys_)
        self._last = (pb.A, pb.f, pb.kind, dqh, sc, sys_)
        return sys_

    def coupled_system(self, pb):
        """``(CoupledSystem, CoupledFactors)`` of a coupled step, built once per operator set, weights,
        scales, ``Δq``, ``r`` and which loads are prescribed (:meth:`system` says why per method)."""
        sc = pb.scales
        key = (pb.Ann, pb.Att, pb.Ant, pb.Atn, pb.f.tobytes(), sc, pb.dq, self.r, pb.P is None, pb.Q is None)
        hit = self._coupled.get(key)
        if hit is None:
            S = coupled_system(pb, self.r)
            hit = (S, CoupledFactors(S))
            if self.record:  # (rollqp.solverstate)
                hit[1].events = []
            self._keep(self._coupled, key, hit)
        return hit

    def _make_room(self, key, nbytes: int) -> None:
        """Before the large system ``key`` is built: drop the least recently used large ones beyond the
        number kept (:data:`MAX_LARGE_SYSTEMS` says how it grows)."""
        if nbytes < self.LARGE_BYTES:
            return
        if key in self._dropped:  # asked for again: the scene alternates between more systems
            self._large = min(self._large + 1, self.MAX_LARGE_SYSTEMS)
        large = [k for k, v in self._systems.items() if v.K.nbytes >= self.LARGE_BYTES]
        for k in large[:max(0, len(large) - self._large + 1)]:
            if self._last is not None and self._last[5] is self._systems[k]:
                self._last = None
            del self._systems[k]
            self._dropped.add(k)

    def _keep(self, store, key, value):
        if len(store) >= self.MAX_SYSTEMS:
            store.pop(next(iter(store)))
        store[key] = value

    # ------------------------------------------------------------------ results
    def checked(self, sol):
        """Never hand back a step whose rollqp residual misses the tolerance.

        The iteration stops on ``‖Φ‖∞ <= tolerance·min(1, r)``, which bounds rollqp's own
        residual (r = 1) by ``tolerance`` in exact arithmetic. With an extreme ``r`` (outside the
        accepted band: docs/stability.md, "The augmentation r") round-off in the r-scaled rows breaks
        that implication; the step is then a failure, not a solution.
        """
        if not sol.residual <= self.tolerance:
            raise SolverError(f"the Newton iteration stopped on its scaled test but rollqp's residual {sol.residual:.3e} exceeds the "
                              f"tolerance {self.tolerance:.1e} (augmentation r = {sol.info.get('r', float('nan')):.3g})",
                              method=self.name, status="residual above tolerance",
                              iterations=sol.iterations, residual=sol.residual)
        return sol

    def finish(self, sol, it, info, t0):
        """Label a solution with the method, its iterations, ``info`` and the wall time since ``t0``."""
        sol.method, sol.status, sol.iterations = self.name, "solved", it
        sol.backtracks = int(info.pop("backtracks", 0))
        if sol.extras:
            sol.extras.update(info)
        else:  # a new solution's empty dict: the method's own (the same items, no copy)
            sol.extras = info
        sol.time = time.perf_counter() - t0
        return sol

    # ------------------------------------------------------------------ for tests and diagnostics
    def residual_and_jacobian(self, problem, z):
        """``(Φ(z), J(z), cases)`` in the nondimensional unknowns ``z`` (package docstring).

        ``z = (p̂, δ̂)`` or ``(t̂, ξ̂)`` (without the last entry if ``δ``/``ξ`` is prescribed).
        ``cases[i]`` names the pseudo-Jacobian row chosen for node ``i``: ``"eq82"``/``"eq83"``/
        ``"eq84"`` (normal) or ``"eq85"``/``"eq86"``/``"eq87"``/``"eq88"`` (tangential).

        For a :class:`~rollqp.problem.CoupledStep`, ``z = (p̂, t̂, δ̂?, ξ̂?)`` and ``cases`` is a
        pair ``(normal, tangential)`` of per-node labels; the tangential ones add ``"eq89"``
        (bound exactly zero, ``t̂ ≠ y_T``) and ``"eq90"`` (bound zero and ``t̂ = y_T``).
        """
        z = np.asarray(z, dtype=float)
        if problem.kind == "coupled":
            return self._coupled_residual_and_jacobian(problem, z)
        sc, n = problem.scales, problem.n
        if problem.kind == "normal":
            sys_ = self.system(problem, None)
            with_load = problem.P is not None
            k0 = sys_.r * (problem.h_total / sc.displacement - (0.0 if with_load else problem.delta / sc.displacement))
            load = problem.P / sc.force if with_load else None
            ncp = NormalNCP()
        else:
            dqh = problem.dq / sc.length
            sys_ = self.system(problem, dqh)
            with_load = problem.Q is not None
            k0 = sys_.r * (problem.c / sc.displacement / dqh + (0.0 if with_load else problem.xi / sc.slip))
            load = problem.Q / sc.force if with_load else None
            ncp = TangentialNCP(problem.bound / sc.stress)
        K = sys_.matrices(with_load)
        x, y = z[:n], K @ z + k0
        mask = np.append(ncp.mask(x, y), True) if with_load else ncp.mask(x, y)
        J = sys_.jacobian(mask, with_load)
        ph = ncp.phi(x, y)
        phi = np.append(ph, sys_.fhat @ x - load) if with_load else ph
        return phi, J, ncp.labels(x, y)

    def _coupled_residual_and_jacobian(self, pb, z):
        S, _ = self.coupled_system(pb)
        kN, kT = coupled_vectors(S, pb)
        n, mu, sc = pb.n, pb.mu, pb.scales
        p, t = z[:n], z[n:2 * n]
        yN, yT = S.KN @ z + kN, S.KT @ z + kT
        contact, stick, slip_sign, _ = coupled_cases(p, t, yN, yT, mu)
        J = coupled_jacobian(S, contact, stick, slip_sign, mu)
        phi = coupled_phi(S, p, t, yN, yT, mu, pb.P / sc.force if S.iP is not None else None,
                          pb.Q / sc.force if S.iQ is not None else None)
        return phi, np.asarray(J), coupled_labels(p, t, yN, yT, mu)


__all__ += ["linear"]
