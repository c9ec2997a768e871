"""The normal step problem (paper eq. 53 with the load equation eq. 67): :class:`NormalStep`."""
from __future__ import annotations

import dataclasses
from dataclasses import InitVar, dataclass, field

import numpy as np

from ..errors import InputError
from .validation import _check_arrays, _copy, _exactly_one, _set_scalars
from .qp import QPForm, qp_hessian, symmetrized
from .scales import Scales
from .solution import Residuals, StepSolution

__all__ = ["NormalStep"]


@dataclass
class NormalStep:
    """The normal (Signorini) step problem (paper eq. 53, 67; docs/formulation.md §4).

    Parameters
    ----------
    A : (n, n) array
        ``A_nn``: gap change at node i due to unit nodal pressure j.
    f : (n,) array
        Weights ``f_j = ∫ N_j`` (eq. 65–67), all > 0.
    h : (n,) array
        Undeformed gap ``h`` (eq. 10).
    P, delta : float
        The normal load ``P = fᵀp`` or the prescribed approach ``δ``: exactly one.
    offset : (n,) array, optional
        Fixed gap change ``A_nt t̄`` from a known shear (zero if absent).
    scales : Scales
        Units of the nondimensional residuals.
    trusted : bool, optional
        The values are valid already (the scene's validated operators and a method's checked solutions, as
        rollqp.march passes them): the checks below are skipped. Default False: every argument is checked
        and stored as rollqp works with it (float arrays, an :class:`~rollqp.influence.operator.Operator`,
        floats), an :class:`~rollqp.errors.InputError` naming the first that is not valid.

    Examples
    --------
    >>> import numpy as np
    >>> from rollqp import NormalStep
    >>> step = NormalStep(A=np.eye(3), f=np.ones(3), h=np.zeros(3), P=1.0)
    >>> step.n, step.P
    (3, 1.0)
    >>> NormalStep(A=np.eye(3), f=np.ones(3), h=np.zeros(3), P=-1.0)
    Traceback (most recent call last):
    rollqp.errors.InputError: P: the normal load must be a finite number > 0, got -1.0
    """

    A: np.ndarray
    f: np.ndarray
    h: np.ndarray
    P: float | None = None
    delta: float | None = None
    offset: np.ndarray | None = None
    scales: Scales = field(default_factory=Scales)
    trusted: InitVar[bool] = False
    kind = "normal"
    law = None  # no friction bound (the tangential and coupled steps' slip-dependent ``law``)

    def __post_init__(self, trusted):
        if trusted:
            return
        _check_arrays(self, ("A",), ("h",), ("offset",))
        _set_scalars(self, ("P", "delta"))
        _exactly_one(("P", "delta"), (self.P, self.delta))
        if self.delta is not None and not np.isfinite(self.delta):
            raise InputError("delta", f"the prescribed approach must be finite, got {self.delta!r}")
        if self.P is not None and not (np.isfinite(self.P) and self.P > 0):
            raise InputError("P", f"the normal load must be a finite number > 0, got {self.P!r}")

    @property
    def n(self) -> int:
        return self.f.size

    def replace(self, **kw) -> "NormalStep":
        """The same step with the values ``kw``, checked."""
        return dataclasses.replace(self, **kw)

    def derived(self, **kw) -> "NormalStep":
        """:meth:`replace` made with ``trusted=True``, for values the caller guarantees valid."""
        return _copy(self, **kw)

    @property
    def h_total(self) -> np.ndarray:
        return self.h if self.offset is None else self.h + self.offset

    def gap(self, p, delta, Ap=None) -> np.ndarray:
        """``g = h + o − δ e + A p`` (eq. 25, 30); ``Ap``: the product ``A p`` if already computed."""
        return self.h_total - delta + (self.A @ p if Ap is None else Ap)

    def symmetrized(self) -> "NormalStep":
        """The same problem with ``A`` replaced by ``F⁻¹ sym(F A)`` (what a QP solves)."""
        return self.replace(A=symmetrized(self.A, self.f))

    def traction(self, sol: "StepSolution"):
        """The unknown traction of this problem in a solution: the pressure ``p``."""
        return sol.p

    def shifted(self, extra: np.ndarray) -> "NormalStep":
        """The same problem with ``extra`` (displacement units) added to the gap: ``o + extra``."""
        return _copy(self, offset=extra if self.offset is None else self.offset + extra)

    def evaluate(self, sol: "StepSolution") -> "StepSolution":
        """``sol``'s pressure and approach re-evaluated on this problem (rollqp's residuals)."""
        return self.solution(sol.p, sol.delta)

    def residuals(self, p, delta, g=None) -> "Residuals":
        """rollqp's residuals of ``(p, δ)``: ``‖min(p̂, ĝ)‖∞`` (eq. 51–52), load row (eq. 67); ``g``: its gap
        if already computed."""
        sc = self.scales
        g = self.gap(p, delta) if g is None else g
        sig = np.minimum(p / sc.stress, g / sc.displacement)
        load = 0.0 if self.P is None else (self.f @ p - self.P) / sc.force
        return Residuals(signorini=float(np.max(np.abs(sig))), load_normal=abs(float(load)))

    def qp_form(self) -> QPForm:
        r"""``min ½ p̂ᵀ sym(F̂Â) p̂ + (F̂ ĥ)ᵀ p̂`` s.t. ``p̂ >= 0``, ``f̂ᵀp̂ = P̂``; ``δ̂ = −y``.

        Hatted quantities are nondimensional (:class:`Scales`); KKT gives ``F̂ ĝ ⟂ p̂``.
        """
        sc = self.scales
        fh = self.f / sc.length
        H, obj = qp_hessian(self.A, fh, (sc.modulus, sc.length))  # once per operator (its memo)
        q = fh * self.h_total / sc.displacement
        if self.delta is not None:
            q = q - fh * (self.delta / sc.displacement)
        eq = float(np.max(fh))
        a = b = None
        if self.P is not None:
            a, b = fh / eq, self.P / sc.force / eq
        return QPForm(H=H, q=q / obj, lower=np.zeros(self.n), upper=np.full(self.n, np.inf),
                      a=a, b=b, obj_scale=obj, eq_scale=eq, kind="normal", dual_scale=obj / fh,
                      shift_scale=fh / (sc.displacement * obj))

    def solution_from_qp(self, form: QPForm, x, y, **meta) -> "StepSolution":
        """Map a QP solution back (pressure, approach) and evaluate it on this problem."""
        sc = self.scales
        p = np.asarray(x, dtype=float) * sc.stress
        delta = self.delta if self.delta is not None else -form.unscaled_multiplier(y) * sc.displacement
        return self.solution(p, delta, **meta)

    def solution(self, p, delta, Ap=None, **meta) -> "StepSolution":
        """``(p, δ)`` with its gap and residuals (``Ap``: the product ``A p`` if the caller has it)."""
        p = np.asarray(p, dtype=float)
        g = self.gap(p, delta, Ap)
        return StepSolution(p=p, g=g, delta=float(delta), residuals=self.residuals(p, delta, g), **meta)
