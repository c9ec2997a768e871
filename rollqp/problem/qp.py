"""The convex QP of a step in rollqp's scaled variables, shared by every QP backend: :class:`QPForm`
(docs/formulation.md §6–7)."""
from __future__ import annotations

import functools
from dataclasses import InitVar, dataclass

import numpy as np

from ..influence.operator import Operator, as_operator

__all__ = ["QPForm", "qp_hessian", "symmetrized"]


def qp_hessian(A, fh, scale):
    """``(H / obj, obj)``: the QP Hessian ``sym(F̂ Â)`` normalized by its largest diagonal entry.

    Computed once per operator, weights and ``scale = (E*, a_H)`` (``Â = A·E*/a_H``) and kept in
    the operator's memo (read-only): every step of a scene, every QP of the splitting, reuses it,
    and the backends recognize it as the Hessian their solver object was built for. The
    tangential QP's ``sym(F̂Â)/Δq̂`` has the same normalized Hessian and ``obj/Δq̂``
    (:meth:`TangentialStep.qp_form`): one array for every Δq of a load path.
    """
    def build():
        Ah = A.dense() * scale[0] / scale[1]
        FA = fh[:, None] * Ah
        H = 0.5 * (FA + FA.T)
        obj = float(np.max(np.abs(np.diag(H))))
        Hn = H / obj
        Hn.flags.writeable = False
        return Hn, obj

    return A.memo(("qp-hessian", fh.tobytes(), tuple(scale)), build)


def symmetrized(A, f: np.ndarray) -> Operator:
    """``F⁻¹ sym(F A)``: the operator whose weighted form is the QP Hessian (docs/formulation.md §7)."""
    return as_operator(A).split(f).sym


@dataclass
class QPForm:
    r"""A convex QP in rollqp's scaled variables, shared by all QP backends.

    .. math::
        \min_x \tfrac12 x^T H x + q^T x \quad\text{s.t.}\quad a^T x = b,\;
        \ell \le x \le u

    ``x`` is the nondimensional traction (``p/p0`` or ``t/p0``). ``H`` and ``q`` are
    divided by ``obj_scale`` and the equality row by ``eq_scale`` so that their entries
    are of order one (solver tolerances then mean what they say). The equality multiplier
    ``y`` is defined by the Lagrangian ``½xᵀHx + qᵀx + y(aᵀx − b) − …`` (so ``∇ = −y a``
    at an interior solution); :meth:`unscaled_multiplier` maps the solver's ``y`` back.
    Infinite bounds are ``±inf``. ``known_structure``: the :attr:`structure` of a QP with the same
    constraints (:meth:`with_q`), not computed again.
    """

    H: np.ndarray
    q: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    a: np.ndarray | None
    b: float | None
    obj_scale: float
    eq_scale: float
    kind: str
    #: ``obj/f̂``: maps the bound multipliers ``λ = Hx + q + y a`` to the nondimensional gap ``ĝ``
    #: (normal) or slip ``ŝ`` (tangential), so that :meth:`residual` is rollqp's residual (None: unknown).
    dual_scale: np.ndarray | None = None
    #: ``∂q/∂e``: the change of ``q`` per unit (displacement) added to the gap offset (normal) or the
    #: history vector (tangential), the shift of the splitting's QPs (None: unknown).
    shift_scale: np.ndarray | None = None
    known_structure: InitVar[tuple | None] = None

    def __post_init__(self, known_structure):
        self._known_structure = known_structure

    def with_q(self, q: np.ndarray) -> "QPForm":
        """The same QP with the linear term ``q`` (the splitting's next QP); its :attr:`structure` kept."""
        return QPForm(H=self.H, q=q, lower=self.lower, upper=self.upper, a=self.a, b=self.b, obj_scale=self.obj_scale,
                      eq_scale=self.eq_scale, kind=self.kind, dual_scale=self.dual_scale, shift_scale=self.shift_scale,
                      known_structure=self.structure)

    def traction(self, x) -> np.ndarray:
        """The nondimensional traction of a QP solution: ``x`` (normal) or ``x`` clipped to its bounds (tangential)."""
        x = np.asarray(x, dtype=float)
        return x if self.kind == "normal" else np.clip(x, self.lower, self.upper)

    def multipliers(self, x, y) -> np.ndarray:
        """The bound multipliers ``λ = H x + q + y a`` of the Lagrangian (class docstring): ``λ_i > 0`` at a
        lower bound, ``< 0`` at an upper one, zero where ``x_i`` is free."""
        lam = self.H @ np.asarray(x, dtype=float) + self.q
        return lam + float(y) * self.a if self.a is not None else lam

    def residual(self, x, y, lam=None) -> float:
        """rollqp's residual of ``(x, y)`` on the problem this QP poses, from the QP data alone.

        ``max |x̂ − Proj_[ℓ, u](x̂ − λ·obj/f̂)|`` (Signorini ``min(p̂, ĝ)`` for ``ℓ = 0, u = ∞``; the friction
        law eq. 60 for ``±μp̂``) and the load row ``|f̂ᵀx̂ − P̂|`` (eq. 67), with ``x̂`` :meth:`traction`: the
        same numbers as the step problem's :meth:`~NormalStep.residuals` up to rounding (``H`` is
        ``sym(F̂Â)/obj``). Needs :attr:`dual_scale`; ``lam``: ``Hx + q + y a`` if known.
        """
        xh = self.traction(x)
        if lam is None:
            lam = self.multipliers(x, y)
        r = float(np.max(np.abs(xh - np.clip(xh - lam * self.dual_scale, self.lower, self.upper))))
        if self.a is not None:
            r = max(r, abs(float(self.a @ xh - self.b)) * self.eq_scale)
        return r

    def unscaled_multiplier(self, y: float) -> float:
        """The multiplier of the unscaled problem (``−δ̂`` normal, ``ξ̂`` tangential)."""
        return float(y) * self.obj_scale / self.eq_scale

    @functools.cached_property
    def structure(self) -> tuple:
        """What fixes the constraint matrix: the solver object can be reused while it holds."""
        if self._known_structure is not None:
            return self._known_structure
        return (self.kind, self.H.shape[0], self.a is not None,
                np.isfinite(self.lower).tobytes(), np.isfinite(self.upper).tobytes(), self.fixed.tobytes())

    @property
    def fixed(self) -> np.ndarray:
        """Mask of variables with ``lower == upper`` (no friction bound: ``x_i = 0``)."""
        return self.lower == self.upper
