"""The tangential (friction) step problem (paper eq. 61/62 with eq. 67): :class:`TangentialStep`."""
from __future__ import annotations

import dataclasses
from dataclasses import InitVar, dataclass, field

import numpy as np

from ..errors import InputError
from .validation import _check_arrays, _check_friction, _check_sliding_limit, _copy, _exactly_one, _per_node, _set_scalars
from .qp import QPForm, qp_hessian, symmetrized
from .scales import Scales
from .solution import Residuals, StepSolution, friction_residual

__all__ = ["TangentialStep", "FrictionBound"]


@dataclass(frozen=True)
class FrictionBound:
    """A tangential step's friction bound ``μ·max(p̄, 0)`` (eq. 60) and its nondimensional ``(b̂, −b̂)``,
    read-only arrays: :attr:`TangentialStep.bound` and :attr:`TangentialStep.bound_hat` of one pressure
    ``p̄`` and one ``μ``, handed to the next step of the same two (:class:`TangentialStep`'s ``known_bound``)."""

    values: np.ndarray
    hat: tuple


@dataclass
class TangentialStep:
    """The tangential (friction) step problem (paper eq. 61/62, 67; docs/formulation.md §4).

    Parameters
    ----------
    A : (n, n) array
        ``A_tt``: relative tangential displacement ``w`` at node i due to unit shear at j.
    f : (n,) array
        Weights (eq. 65–67).
    p : (n,) array
        The fixed pressure ``p̄``; the friction bound is ``μ·max(p̄, 0)``.
    mu : float
        Coefficient of friction, >= 0.
    c : (n,) array
        History vector plus ``A_tn p̄``: ``Δq·s = Δq ξ e + c + A t``.
    dq : float
        Rolled distance of the step ``Δq`` (for a static shift: the shift's length unit).
    Q, xi : float
        Tangential load ``Q = fᵀt`` or prescribed creepage ``ξ``: exactly one.
    scales : Scales
    law : SlipBound, optional
        A slip-dependent bound ``μ(s)`` (:mod:`rollqp.friction`); None: ``μ`` fixed.
    trusted : bool, optional
        The values are valid already: the checks are skipped (as for :class:`NormalStep`).
    known_bound : FrictionBound, optional
        With ``trusted``: the bound of this step's very ``p`` and ``mu`` objects, computed for an earlier
        step (the march's fixed normal half), used instead of computing it again.

    Examples
    --------
    >>> import numpy as np
    >>> from rollqp import TangentialStep
    >>> step = TangentialStep(A=np.eye(3), f=np.ones(3), p=np.array([0.0, 2.0, 1.0]), mu=0.5, c=np.zeros(3),
    ...                       dq=1.0, Q=0.5)
    >>> step.bound
    array([0. , 1. , 0.5])
    """

    A: np.ndarray                 # A_tt (eq. 28, 29): an Operator once validated
    f: np.ndarray                 # weights, eq. 65–67
    p: np.ndarray                 # the fixed pressure: bound μ p̄⁺ (eq. 60)
    mu: float
    c: np.ndarray                 # history vector + A_tn p̄ (eq. 37, 48)
    dq: float                     # Δq, or the static shift's length unit
    Q: float | None = None        # load row (eq. 67) …
    xi: float | None = None       # … or the creepage prescribed
    scales: Scales = field(default_factory=Scales)
    law: object = None            # slip-dependent bound μ(s) (rollqp.friction.SlipBound); None: μ fixed
    trusted: InitVar[bool] = False
    known_bound: InitVar[FrictionBound | None] = None
    kind = "tangential"

    def __post_init__(self, trusted, known_bound):
        known = known_bound if trusted else None
        # the bound and its nondimensional pair, computed on first use (properties below) or given
        self._bound, self._bound_hat = (None, None) if known is None else (known.values, known.hat)
        if trusted:
            return
        _check_arrays(self, ("A",), ("p", "c"))
        _set_scalars(self, ("dq", "Q", "xi") + (() if _per_node(self.mu) else ("mu",)))  # μ per node: _check_friction
        _check_friction(self)
        _exactly_one(("Q", "xi"), (self.Q, self.xi))
        if self.xi is not None and not np.isfinite(self.xi):
            raise InputError("xi", f"the prescribed creepage must be finite, got {self.xi!r}")
        if self.Q is not None and not np.isfinite(self.Q):
            raise InputError("Q", f"the tangential load must be finite, got {self.Q!r}")
        _check_sliding_limit(self)

    @property
    def n(self) -> int:
        return self.f.size

    @property
    def bound(self) -> np.ndarray:
        """``μ·max(p̄, 0)`` (with a slip-dependent ``law``: at zero slip, the static bound); computed once
        per step problem (read-only: the march, the solver and rollqp's residual each read it), or given
        (``known_bound``)."""
        b = self._bound
        if b is None:
            if self.law is not None:
                b = self.law.mu(np.zeros(self.n)) * np.maximum(self.p, 0.0)
            else:
                b = self.mu * np.maximum(self.p, 0.0)
            b.flags.writeable = False
            self._bound = b
        return b

    @property
    def bound_hat(self) -> tuple:
        """``(b̂, −b̂)``, ``b̂ = μp̄⁺/p0`` of :attr:`bound` (read-only): rollqp's friction residual and
        Newton's friction rows read them; computed once per step problem, or given (``known_bound``)."""
        if self._bound_hat is None:
            bh = self.bound / self.scales.stress
            nb = -bh
            bh.flags.writeable = nb.flags.writeable = False
            self._bound_hat = (bh, nb)
        return self._bound_hat

    def bound_at(self, s) -> np.ndarray:
        """The bound at the slip ``s``: ``μ(s)·max(p̄, 0)`` (``law``), else :attr:`bound`."""
        return self.bound if self.law is None else self.law.mu(s) * np.maximum(self.p, 0.0)

    def coefficient(self, s=None, p=None):
        """``μ`` of this step: the number or per-node array, or ``law.mu(s)`` at the slip ``s``; ``p`` (default the
        step's pressure): outside the contact (``p <= 0``) a law takes the slip velocity as 0 (docs/friction.md)."""
        if self.law is None or s is None:
            return self.mu
        return self.law.mu(s, contact=(self.p if p is None else p) > 0.0)

    def frozen(self, s) -> "TangentialStep":
        """The same step with the bound frozen at the slip ``s`` (``μ = law.mu(s)`` per node): a convex QP."""
        return self.replace(mu=self.law.mu(s), law=None)

    def replace(self, **kw) -> "TangentialStep":
        """The same step with the values ``kw``, checked."""
        return dataclasses.replace(self, **kw)

    def derived(self, **kw) -> "TangentialStep":
        """:meth:`replace` made with ``trusted=True``, for values the caller guarantees valid."""
        return _copy(self, **kw)

    def slip(self, t, xi, At=None) -> np.ndarray:
        """``s = ξ e + (c + A t)/Δq`` (eq. 36, 47); ``At``: the product ``A t`` if already computed."""
        return xi + (self.c + (self.A @ t if At is None else At)) / self.dq

    def symmetrized(self) -> "TangentialStep":
        """The same problem with ``A`` replaced by ``F⁻¹ sym(F A)`` (what a QP solves)."""
        return self.replace(A=symmetrized(self.A, self.f))

    def traction(self, sol: "StepSolution"):
        """The unknown traction of this problem in a solution: the shear ``t``."""
        return sol.t

    def shifted(self, extra: np.ndarray) -> "TangentialStep":
        """The same problem with ``extra`` (displacement units) added to the history: ``c + extra``."""
        return _copy(self, c=self.c + extra)

    def evaluate(self, sol: "StepSolution") -> "StepSolution":
        """``sol``'s traction and creepage re-evaluated on this problem (rollqp's residuals)."""
        return self.solution(sol.t, sol.xi)

    def residuals(self, t, xi, s=None) -> "Residuals":
        """rollqp's residuals of ``(t, ξ)``: ``‖t̂ − Proj_[−μp̂⁺, μp̂⁺](t̂ − ŝ)‖∞`` (eq. 60), load row (eq. 67);
        ``s``: its slip if already computed."""
        sc = self.scales
        s = self.slip(t, xi) if s is None else s
        bh, nb = self.bound_hat if self.law is None else (self.bound_at(s) / sc.stress, None)
        fr = friction_residual(t / sc.stress, s / sc.slip, bh, nb)
        load = 0.0 if self.Q is None else (self.f @ t - self.Q) / sc.force
        return Residuals(friction=float(np.abs(fr).max()), load_tangential=abs(float(load)))

    def qp_form(self) -> QPForm:
        r"""``min ½ t̂ᵀ sym(F̂Â) t̂/Δq̂ + (F̂ĉ/Δq̂)ᵀ t̂`` s.t. ``|t̂| <= μp̂``, ``f̂ᵀt̂ = Q̂``; ``ξ̂ = y``.

        KKT gives ``F̂ ŝ`` equal to the bound multipliers: ``ŝ = 0`` where ``|t| < μp̄``, and
        ``ŝ`` opposite to ``t`` where the bound is active (eq. 57–60).
        """
        sc = self.scales
        fh = self.f / sc.length
        dqh = self.dq / sc.length
        # sym(F̂Â)/Δq̂ normalized by its largest diagonal entry is the normal Hessian whatever Δq̂:
        # one array per operator (its memo), so a solver object serves every Δq of a load path
        H, obj = qp_hessian(self.A, fh, (sc.modulus, sc.length))
        obj = obj / dqh
        q = fh * (self.c / sc.displacement) / dqh
        if self.xi is not None:
            q = q + fh * (self.xi / sc.slip)
        eq = float(np.max(fh))
        bh = self.bound / sc.stress
        a = b = None
        if self.Q is not None:
            a, b = fh / eq, self.Q / sc.force / eq
        return QPForm(H=H, q=q / obj, lower=-bh, upper=bh, a=a, b=b, obj_scale=obj,
                      eq_scale=eq, kind="tangential", dual_scale=obj / fh,
                      shift_scale=fh / (sc.displacement * dqh * obj))

    def solution_from_qp(self, form: QPForm, x, y, **meta) -> "StepSolution":
        """Map a QP solution back (traction, creepage) and evaluate it on this problem."""
        sc = self.scales
        t = np.clip(np.asarray(x, dtype=float) * sc.stress, -self.bound, self.bound)
        xi = self.xi if self.xi is not None else form.unscaled_multiplier(y) * sc.slip
        return self.solution(t, xi, **meta)

    def solution(self, t, xi, At=None, hat=None, **meta) -> "StepSolution":
        """``(t, ξ)`` with its slip and residuals (``At``: the product ``A t`` if the caller has it).

        ``hat``: ``(t̂, ŝ, f̂ᵀt̂ − Q̂)``, the nondimensional traction, slip and load row of ``(t, ξ)`` if the caller
        has them (Newton's last iterate: ``ŝ = y/r``): the slip is then ``ŝ·p0/E*`` and the residuals are
        evaluated on them, without the product, the slip formula and the rescaling (the same numbers to
        round-off: tests/test_newton.py compares the two).
        """
        t = np.asarray(t, dtype=float)
        if hat is not None and self.law is None:
            t_hat, s_hat, load_hat = hat
            bh, nb = self.bound_hat
            fr = friction_residual(t_hat, s_hat, bh, nb)
            res = Residuals(0.0, float(np.maximum.reduce(np.abs(fr))), 0.0, 0.0 if self.Q is None else abs(float(load_hat)))
            # (the fields p, t, g, s, δ, ξ, residuals in their order: keywords cost as much as the construction)
            return StepSolution(self.p, t, None, s_hat * self.scales.slip, None, float(xi), res, **meta)
        s = self.slip(t, xi, At)
        return StepSolution(t=t, s=s, xi=float(xi), p=self.p, residuals=self.residuals(t, xi, s), **meta)
