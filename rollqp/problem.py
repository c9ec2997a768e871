r"""Step problems and their solutions (docs/formulation.md §4–6; paper eq. 49–71).

A *step problem* is the data of one discrete step — influence matrices, weights, gap,
friction bound, loads, history vector — and nothing about how it is solved. A
*solution* carries the unknowns, the method that produced them, and residuals computed
here, by rollqp, independently of any solver's self-reported accuracy (the split of
``qpsolvers.Problem`` / ``qpsolvers.Solution``).

Sign convention (the project's, docs/formulation.md §1): ``p >= 0`` is the pressure, ``t`` the
tangential traction on body A in +x, ``g >= 0`` the deformed gap, ``s`` the slip of A
relative to B per unit rolled distance, ``δ`` the rigid approach, ``ξ`` the creepage.

Normal step (eq. 53 with the load equation eq. 67)::

    g = h + o − δ e + A p,      p >= 0, g >= 0, p·g = 0,      fᵀp = P   (or δ given)

with ``o = A_nt t̄`` the gap change due to a fixed shear (zero for similar materials).

Tangential step (eq. 61/62 with eq. 67)::

    s = ξ e + (c + A t) / Δq,   |t| <= μ p̄,  t = Proj_[−μp̄, μp̄](t − r s),   fᵀt = Q   (or ξ given)

with ``c`` the history vector (eq. 37, 48) plus ``A_tn p̄``.

Nondimensional form: lengths by ``a_H``, stresses by ``p0``. The elastic operator turns
a stress into a displacement through ``1/E*``, so gaps are measured in
``u0 = a_H p0 / E*`` and slips in ``p0 / E*``; this is the augmentation ``r = E*/p0``
(the reciprocal of the scaled influence coefficients' size) applied to ``g`` and ``s``.
The residuals (:class:`Residuals`) are the max-norms of

* Signorini:      ``min(p̂, ĝ)``                              (eq. 51–52),
* friction law:   ``t̂ − Proj_[−μp̂⁺, μp̂⁺](t̂ − ŝ)``             (eq. 60),
* load equations: ``(fᵀp − P)/(a_H p0)``, ``(fᵀt − Q)/(a_H p0)``  (eq. 67).
"""
from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass, field

import numpy as np

from .errors import InputError
from .influence.operator import Operator, as_operator, asymmetry, split  # noqa: F401 - re-exported

# Node states in result files (docs/results.md): 0 separation, 1 stick, 2 slip.
SEPARATION, STICK, SLIP = 0, 1, 2


@dataclass(frozen=True)
class Scales:
    """Units of the nondimensional form: ``length`` (a_H), ``stress`` (p0), ``modulus`` (E*).

    The defaults (all 1) leave an array problem in the user's own units; pass the Hertz
    scales (:meth:`hertz`) for residuals that mean the same in every unit system.
    """

    length: float = 1.0
    stress: float = 1.0
    modulus: float = 1.0

    def __post_init__(self):
        for name in ("length", "stress", "modulus"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"scales.{name}", f"must be a finite number > 0, got {v!r}")

    @classmethod
    def hertz(cls, P: float, R: float, Estar: float) -> "Scales":
        """Hertz half-width ``a`` and peak pressure ``p0`` for load ``P`` (docs/formulation.md §12)."""
        from .closedforms import hertz_half_width, hertz_peak_pressure
        a = hertz_half_width(P, R, Estar)
        return cls(length=a, stress=hertz_peak_pressure(P, a), modulus=float(Estar))

    @property
    def displacement(self) -> float:
        """``u0 = a_H p0 / E*``: gaps, displacements, approach."""
        return self.length * self.stress / self.modulus

    @property
    def slip(self) -> float:
        """``p0 / E*``: slips and creepages."""
        return self.stress / self.modulus

    @property
    def force(self) -> float:
        """``a_H p0``: loads per unit axial length."""
        return self.length * self.stress


#: Largest magnitude of any number given to a step problem. rollqp forms products of up to four
#: of them (the QP objective pᵀ F A p, fᵀp, A·p): with every factor ≤ 1e60 these stay below
#: 1e240 · n, far from float64's 1.8e308, while any physical input in any units is far below
#: it (stresses ~1e11 Pa, compliances ~1e-12).
MAX_MAGNITUDE = 1e60


def _real(name, v) -> np.ndarray:
    """``v`` as a float array; an InputError naming ``name`` unless it holds real, finite numbers
    within ±:data:`MAX_MAGNITUDE` (booleans, complex numbers, strings, objects and ragged lists
    are refused, never cast)."""
    if type(v) is np.ndarray and v.dtype == np.float64:  # the common case: no copy, two numpy calls
        a = v
    else:
        try:
            a = np.asarray(v)
        except (ValueError, TypeError) as exc:
            raise InputError(name, f"must hold real numbers ({exc})") from None
        if a.dtype.kind not in "iuf":
            raise InputError(name, f"must hold real numbers, got {type(v).__name__} of dtype {a.dtype}")
        a = a.astype(float)
    if a.size:
        big = np.abs(a).max()  # (the method, not np.max: a third of the time on step-sized vectors)
        if not big <= MAX_MAGNITUDE:  # NaN compares false: one test for both
            if not np.all(np.isfinite(a)):
                raise InputError(name, "must be finite")
            raise InputError(name, f"values must be within ±{MAX_MAGNITUDE:g} (beyond, the products of the step "
                                   f"problem overflow; rescale, e.g. with Scales), got {big:.3g}")
    return a


def _scalar(name, v):
    """``v`` as a float, or ``None``; an InputError naming ``name`` unless it is one real number."""
    if v is None:
        return None
    if isinstance(v, (float, int)) and not isinstance(v, bool):  # the common case, without numpy
        x = float(v)
        if abs(x) <= MAX_MAGNITUDE:
            return x
    a = _real(name, v)
    if a.ndim != 0:
        raise InputError(name, f"must be a real number, got an array of shape {a.shape}")
    return float(a)


def _set_scalars(step, names) -> None:
    for name in names:
        object.__setattr__(step, name, _scalar(name, getattr(step, name)))


def _vec(name, v, n):
    a = _real(name, v)  # real and finite
    if a.shape != (n,):
        raise InputError(name, f"must have shape ({n},), got {a.shape}")
    return a


def _set_weights(step) -> int:
    """Validate a step's weights ``f`` (1-D, finite, all > 0) and its scales, store them, return ``n``."""
    if not isinstance(step.scales, Scales):
        raise InputError("scales", f"must be a rollqp.Scales (e.g. Scales.hertz(P, R, Estar), or Scales() for the "
                                   f"problem's own units), got {type(step.scales).__name__}")
    f = step.f
    n = np.shape(f)[0] if (f.ndim if type(f) is np.ndarray else np.ndim(f)) == 1 else -1
    if n < 1:
        raise InputError("f", "must be a 1-D array of weights")
    f = _vec("f", f, n)
    if (f <= 0).any():
        raise InputError("f", "weights must all be > 0")
    object.__setattr__(step, "f", f)
    return n


def _check_arrays(step, operators=(), vectors=(), optional=()) -> int:
    """Validate a step's weights, its operators (``n × n``) and vectors (``n``; ``optional`` may be
    ``None``) in place; return ``n``."""
    n = _set_weights(step)
    for name in operators:
        value = getattr(step, name)
        if value is not None or name in ("A", "Ann", "Att"):
            if not isinstance(value, Operator):
                value = _real(name, value)
            object.__setattr__(step, name, as_operator(value, name, n))
    for name in vectors + optional:
        if getattr(step, name) is not None or name in vectors:
            object.__setattr__(step, name, _vec(name, getattr(step, name), n))
    return n


def _per_node(mu) -> bool:
    """``mu`` is given per node (a sequence or an array of dimension >= 1), not one number."""
    return isinstance(mu, (list, tuple, np.ndarray)) and not (isinstance(mu, np.ndarray) and mu.ndim == 0)


def _check_friction(step) -> None:
    """``μ`` finite and ``>= 0`` (a number, or one per node: :mod:`rollqp.friction`), ``Δq`` finite and ``> 0``."""
    if not _per_node(step.mu):
        if step.mu is None or not (np.isfinite(step.mu) and step.mu >= 0):
            raise InputError("mu", f"the coefficient of friction must be finite and >= 0, got {step.mu!r}")
    else:
        mu = _vec("mu", step.mu, step.f.size)
        if np.any(mu < 0):
            raise InputError("mu", f"the coefficients of friction must all be >= 0, got min {float(mu.min())!r}")
        object.__setattr__(step, "mu", mu)
    law = getattr(step, "law", None)
    if law is not None and not (callable(getattr(law, "mu", None)) and callable(getattr(law, "dmu", None))):
        raise InputError("law", f"must be a slip-dependent bound with mu(s) and dmu(s) (rollqp.friction.SlipBound), "
                                f"got {type(law).__name__}")
    if step.dq is None or not (np.isfinite(step.dq) and step.dq > 0):
        raise InputError("dq", f"the step must be a finite number > 0, got {step.dq!r}")


def _exactly_one(names, values):
    given = [n for n, v in zip(names, values) if v is not None]
    if len(given) != 1:
        raise InputError(" / ".join(names), f"give exactly one of {' or '.join(names)} (got {len(given)})")


def _check_sliding_limit(step, cap=None) -> float | None:
    """A tangential step with ``Q`` prescribed needs ``|Q| < μ fᵀp`` (a solution with stick), else an InputError.
    ``cap``: ``fᵀ(μ p⁺)`` if the caller has it. Returns the cap (None without ``Q``)."""
    if step.Q is not None:
        cap = float(step.f @ step.bound) if cap is None else cap
        if not abs(step.Q) < cap:
            raise InputError("Q", f"|Q| = {abs(step.Q):.6g} must be below the sliding limit "
                                  f"mu fᵀp = {cap:.6g} for a solution with stick")
    return cap


def _trusted(cls, **values):
    """A step problem of class ``cls`` from values that are already valid, without re-validation.

    For the halves of a checked :class:`CoupledStep`, the symmetrized or shifted copies of a
    checked step (each QP of the symmetric–skew splitting), and the steps rollqp.march builds from
    the scene's validated operators and the method's checked solutions
    (:meth:`~rollqp.operators.SceneOperators.tangential_step` with ``validate=False``): their
    operators are checked :class:`Operator`\\ s and their vectors are products of them with
    checked or solver-computed arrays, so the ``O(n)``–``O(n²)`` checks of ``__post_init__`` would
    only repeat (measured 3–14 % of a QP step on §6.1.1; a validated tangential step costs 16 µs
    there against 2.4 µs, a fifth of a Newton rolling step). The caller vouches for the values.
    """
    obj = object.__new__(cls)
    d = obj.__dict__
    plain, factories = _defaults(cls)
    d.update(plain)
    d.update(values)
    for name, make in factories:
        if name not in values:
            d[name] = make()
    return obj


@functools.cache
def _defaults(cls) -> tuple:
    """``(defaults, factories)`` of ``cls``'s fields: the plain default values, and the
    ``(name, default_factory)`` pairs (called for each object: a factory's value may be mutable)."""
    fields = dataclasses.fields(cls)
    return ({f.name: f.default for f in fields if f.default is not dataclasses.MISSING},
            tuple((f.name, f.default_factory) for f in fields if f.default_factory is not dataclasses.MISSING))


def _derived(step, **changes):
    """``step`` with ``changes`` (already valid: :func:`_trusted`), not re-validated."""
    obj = object.__new__(type(step))  # frozen: the fields set through __dict__, as dataclasses.replace would
    obj.__dict__.update(step.__dict__)
    obj.__dict__.update(changes)
    for name in _cached(type(step)):  # cached properties of the old values (TangentialStep.bound, …)
        obj.__dict__.pop(name, None)
    return obj


@functools.cache
def _cached(cls) -> tuple:
    """The names of ``cls``'s cached properties (computed from the fields, so not carried to a copy)."""
    return tuple(name for klass in cls.__mro__ for name, v in vars(klass).items()
                 if isinstance(v, functools.cached_property))


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


def friction_residual(t, s, bound, minus_bound=None):
    """``t − Proj_[−b, b](t − s)`` (eq. 60): zero iff ``|t| <= b`` and ``t`` opposes the slip ``s``.

    The one expression of the friction law's projection residual: rollqp's residuals use it with
    nondimensional ``t̂, ŝ, b̂``; the Newton method with ``r ŝ`` in place of ``ŝ`` (eq. 56, 63).
    ``minus_bound``: ``−b`` if the caller keeps it.
    """
    if minus_bound is None:
        minus_bound = -bound
    # np.maximum/np.minimum rather than np.clip: the same numbers (``b >= 0``), without np.clip's
    # Python-level dispatch (half the time on a step's vectors, and Newton evaluates it a few times an iteration)
    return t - np.maximum(np.minimum(t - s, bound), minus_bound)


def symmetrized(A, f: np.ndarray) -> Operator:
    """``F⁻¹ sym(F A)``: the operator whose weighted form is the QP Hessian (docs/formulation.md §7)."""
    return as_operator(A).split(f).sym


@dataclass(frozen=True)
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
    Infinite bounds are ``±inf``.
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

    def with_q(self, q: np.ndarray) -> "QPForm":
        """The same QP with the linear term ``q`` (the splitting's next QP); the cached :attr:`structure` kept."""
        new = object.__new__(QPForm)  # frozen: the fields set through __dict__, as dataclasses.replace would
        new.__dict__.update(self.__dict__)
        new.__dict__["q"] = q
        return new

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
        return (self.kind, self.H.shape[0], self.a is not None,
                np.isfinite(self.lower).tobytes(), np.isfinite(self.upper).tobytes(), self.fixed.tobytes())

    @property
    def fixed(self) -> np.ndarray:
        """Mask of variables with ``lower == upper`` (no friction bound: ``x_i = 0``)."""
        return self.lower == self.upper


# ---------------------------------------------------------------------------- problems
@dataclass(frozen=True)
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
    """

    A: np.ndarray
    f: np.ndarray
    h: np.ndarray
    P: float | None = None
    delta: float | None = None
    offset: np.ndarray | None = None
    scales: Scales = field(default_factory=Scales)
    kind = "normal"

    def __post_init__(self):
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
        return dataclasses.replace(self, **kw)

    def derived(self, **kw) -> "NormalStep":
        """:meth:`replace` without re-validation, for values the caller guarantees valid (:func:`_trusted`)."""
        return _derived(self, **kw)

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
        return _derived(self, offset=extra if self.offset is None else self.offset + extra)

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


@dataclass(frozen=True)
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
    kind = "tangential"

    def __post_init__(self):
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

    @functools.cached_property
    def bound(self) -> np.ndarray:
        """``μ·max(p̄, 0)`` (with a slip-dependent ``law``: at zero slip, the static bound); computed once
        per step problem (read-only: the march, the solver and rollqp's residual each read it)."""
        if self.law is not None:
            b = self.law.mu(np.zeros(self.n)) * np.maximum(self.p, 0.0)
        else:
            b = self.mu * np.maximum(self.p, 0.0)
        b.flags.writeable = False
        return b

    @functools.cached_property
    def bound_hat(self) -> tuple:
        """``(b̂, −b̂)``, ``b̂ = μp̄⁺/p0`` of :attr:`bound` (read-only): rollqp's friction residual and
        Newton's friction rows read them."""
        bh = self.bound / self.scales.stress
        nb = -bh
        bh.flags.writeable = nb.flags.writeable = False
        return bh, nb

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
        return dataclasses.replace(self, **kw)

    def derived(self, **kw) -> "TangentialStep":
        """:meth:`replace` without re-validation, for values the caller guarantees valid (:func:`_trusted`)."""
        return _derived(self, **kw)

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
        return _derived(self, c=self.c + extra)

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

    def solution(self, t, xi, At=None, **meta) -> "StepSolution":
        """``(t, ξ)`` with its slip and residuals (``At``: the product ``A t`` if the caller has it)."""
        t = np.asarray(t, dtype=float)
        s = self.slip(t, xi, At)
        return StepSolution(t=t, s=s, xi=float(xi), p=self.p, residuals=self.residuals(t, xi, s), **meta)


@dataclass(frozen=True)
class CoupledStep:
    r"""The coupled step (paper eq. 63–64, 67; docs/formulation.md §4): all rows of ``Φ``.

    .. math::
        g = h - \delta e + A_{nn} p + A_{nt} t, \qquad
        s = \xi e + (c + A_{tn} p + A_{tt} t)/\Delta q,

        p \ge 0,\ g \ge 0,\ p g = 0, \qquad
        t = \mathrm{Proj}_{[-\mu p^+, \mu p^+]}(t - s), \qquad
        f^T p = P\ (\text{or } \delta), \qquad f^T t = Q\ (\text{or } \xi).

    The friction bound depends on the unknown pressure: a quasi-variational inequality, not
    a QP. It is solved by the coupled Newton method or by the N–T alternation of its two
    halves (:meth:`normal_half`, :meth:`tangential_half`), which are ordinary step problems.

    Parameters
    ----------
    Ann, Att : (n, n) arrays
        Normal and tangential influence (eq. 25, 28).
    Ant, Atn : (n, n) arrays or None
        Coupling: gap change per unit shear, tangential displacement per unit pressure
        (``None``: zero; ``Ant = None`` is the Goodman level of docs/formulation.md §10).
    f, h, mu : weights, undeformed gap, coefficient of friction.
    c : (n,) array
        History vector (eq. 37, 48): ``Δq·s = Δq ξ e + c + A_tn p + A_tt t``.
    dq : float
        Step length (for a static shift: its length unit; for steady rolling see below).
    P, delta : exactly one;  Q, xi : exactly one.
    scales : Scales

    Notes
    -----
    ``Atn`` and ``Att`` are the *slip* operators: for transient steps the influence matrices
    themselves; for steady rolling (``s = ξ e + d·D_up w``) rollqp.march passes
    ``Δ·d·D_up·A_tn`` and ``Δ·d·D_up·A_tt`` with ``dq = Δ`` and ``c = 0``.
    """

    Ann: np.ndarray               # eq. 25–26
    Att: np.ndarray               # eq. 28–29 (steady rolling: the steady slip operator)
    Ant: np.ndarray | None        # gap per unit shear (None: the Goodman level)
    Atn: np.ndarray | None        # tangential displacement per unit pressure
    f: np.ndarray                 # weights, eq. 65–67
    h: np.ndarray                 # undeformed gap, eq. 10
    mu: float
    c: np.ndarray                 # history vector, eq. 37, 48
    dq: float
    P: float | None = None        # normal load row …
    delta: float | None = None    # … or the approach prescribed
    Q: float | None = None        # tangential load row …
    xi: float | None = None       # … or the creepage prescribed
    scales: Scales = field(default_factory=Scales)
    law: object = None            # slip-dependent bound μ(s) (rollqp.friction.SlipBound); None: μ fixed
    kind = "coupled"

    def __post_init__(self):
        _check_arrays(self, ("Ann", "Att", "Ant", "Atn"), ("h", "c"))
        _set_scalars(self, ("dq", "P", "delta", "Q", "xi") + (() if _per_node(self.mu) else ("mu",)))
        _check_friction(self)
        _exactly_one(("P", "delta"), (self.P, self.delta))
        _exactly_one(("Q", "xi"), (self.Q, self.xi))
        if self.P is not None and not (np.isfinite(self.P) and self.P > 0):
            raise InputError("P", f"the normal load must be a finite number > 0, got {self.P!r}")
        for name in ("delta", "xi", "Q"):
            v = getattr(self, name)
            if v is not None and not np.isfinite(v):
                raise InputError(name, f"must be finite, got {v!r}")
        mu_max = self.mu if np.ndim(self.mu) == 0 and self.law is None else float(
            np.max(self.mu if self.law is None else self.law.mu(np.zeros(self.n))))
        if self.Q is not None and self.P is not None and not abs(self.Q) < mu_max * self.P:
            raise InputError("Q", f"|Q| = {abs(self.Q):.6g} must be below the sliding limit "
                                  f"mu P = {mu_max * self.P:.6g} for a solution with stick")

    @property
    def n(self) -> int:
        return self.f.size

    def replace(self, **kw) -> "CoupledStep":
        return dataclasses.replace(self, **kw)

    def gap(self, p, t, delta) -> np.ndarray:
        """``g = h − δ e + A_nn p + A_nt t`` (eq. 25, 30)."""
        g = self.h - delta + self.Ann @ p
        return g if self.Ant is None else g + self.Ant @ t

    def slip(self, p, t, xi) -> np.ndarray:
        """``s = ξ e + (c + A_tn p + A_tt t)/Δq`` (eq. 36, 47)."""
        w = self.c + self.Att @ t
        if self.Atn is not None:
            w = w + self.Atn @ p
        return xi + w / self.dq

    def normal_half(self, t) -> NormalStep:
        """The normal step with the shear ``t`` fixed (eq. 53): offset ``A_nt t``."""
        off = None if self.Ant is None else self.Ant @ np.asarray(t, dtype=float)
        if off is not None and not np.all(np.isfinite(off)):
            raise InputError("t", "the fixed shear must be finite")
        # not re-validated: the coupled step's checked data (_trusted)
        return _trusted(NormalStep, A=self.Ann, f=self.f, h=self.h, P=self.P, delta=self.delta, offset=off,
                        scales=self.scales)

    def tangential_half(self, p) -> TangentialStep:
        """The tangential step with the pressure ``p`` fixed (eq. 61/62): bound ``μ p⁺``."""
        p = np.asarray(p, dtype=float)
        if not np.all(np.isfinite(p)):
            raise InputError("p", "the fixed pressure must be finite")
        c = self.c if self.Atn is None else self.c + self.Atn @ p
        # not re-validated (_trusted) but for the sliding limit, which depends on this pressure
        half = _trusted(TangentialStep, A=self.Att, f=self.f, p=p, mu=self.mu, c=c, dq=self.dq, Q=self.Q,
                        xi=self.xi, scales=self.scales, law=self.law)
        _check_sliding_limit(half)
        return half

    def coefficient(self, s=None, p=None):
        """``μ`` of this step: the number or per-node array, or ``law.mu(s)`` at the slip ``s``; with the pressure
        ``p``, outside the contact (``p <= 0``) a law takes the slip velocity as 0 (docs/friction.md)."""
        if self.law is None or s is None:
            return self.mu
        return self.law.mu(s, contact=None if p is None else p > 0.0)

    def residuals(self, p, t, delta, xi, g=None, s=None) -> "Residuals":
        """rollqp's residuals of the coupled step: Signorini, friction (bound ``μp⁺``), loads (eq. 70–71);
        ``g``, ``s``: its gap and slip if already computed."""
        sc = self.scales
        g = self.gap(p, t, delta) if g is None else g
        s = self.slip(p, t, xi) if s is None else s
        sig = np.minimum(p / sc.stress, g / sc.displacement)
        th, sh = t / sc.stress, s / sc.slip
        bh = self.coefficient(s) * np.maximum(p, 0.0) / sc.stress
        fr = friction_residual(th, sh, bh)
        ln = 0.0 if self.P is None else (self.f @ p - self.P) / sc.force
        lt = 0.0 if self.Q is None else (self.f @ t - self.Q) / sc.force
        return Residuals(signorini=float(np.max(np.abs(sig))), friction=float(np.max(np.abs(fr))),
                         load_normal=abs(float(ln)), load_tangential=abs(float(lt)))

    def solution(self, p, t, delta, xi, **meta) -> "StepSolution":
        p, t = np.asarray(p, dtype=float), np.asarray(t, dtype=float)
        delta = self.delta if self.delta is not None else float(delta)
        xi = self.xi if self.xi is not None else float(xi)
        g, s = self.gap(p, t, delta), self.slip(p, t, xi)
        return StepSolution(p=p, t=t, g=g, s=s, delta=float(delta), xi=float(xi),
                            residuals=self.residuals(p, t, delta, xi, g, s), **meta)


# ---------------------------------------------------------------------------- solutions
@dataclass
class Residuals:
    """rollqp's own nondimensional residuals of a step (max norms; see module docstring)."""

    signorini: float = 0.0
    friction: float = 0.0
    load_normal: float = 0.0
    load_tangential: float = 0.0

    @property
    def max(self) -> float:
        """The largest residual; NaN if any is NaN (so that no limit check can pass it)."""
        a, b, c, d = self.signorini, self.friction, self.load_normal, self.load_tangential
        total = a + b + c + d  # NaN if any is (the residuals are >= 0: no inf − inf)
        # (builtin max on four floats: np.max costs 10× as much, and it is read for every solve)
        return float(max(a, b, c, d)) if total == total else float("nan")

    def __or__(self, other: "Residuals") -> "Residuals":
        a = np.asarray(dataclasses.astuple(self), dtype=float)
        b = np.asarray(dataclasses.astuple(other), dtype=float)
        return Residuals(*np.maximum(a, b).tolist())  # np.maximum propagates NaN


@dataclass
class StepSolution:
    """The unknowns of one step, how they were obtained, and rollqp's residuals.

    Absent parts are ``None`` (``g``/``delta`` for a tangential step, ``t``/``s``/``xi`` for
    a normal one). ``iterations`` counts the method's own iterations; ``time`` is the wall
    time of the solve in rollqp (``solver_time`` the external solver's own, if any).
    """

    p: np.ndarray | None = None
    t: np.ndarray | None = None
    g: np.ndarray | None = None
    s: np.ndarray | None = None
    delta: float | None = None
    xi: float | None = None
    residuals: Residuals = field(default_factory=Residuals)
    method: str = ""
    status: str = "solved"
    iterations: int = 0
    time: float = 0.0
    solver_time: float = 0.0
    info: dict = field(default_factory=dict)

    @property
    def residual(self) -> float:
        return self.residuals.max


def classify(p, t, s, mu, scales: Scales = Scales(), tol: float = 1e-7, bound=None) -> np.ndarray:
    """Node states: 0 separation (``p̂ <= tol``), 2 slip (``|ŝ| > tol`` at the bound), 1 stick.

    ``t`` or ``s`` may be ``None`` (normal problem only): contact nodes are then stick. ``bound``:
    ``μ max(p, 0)`` if the caller has it (a step problem's :attr:`TangentialStep.bound`).
    """
    p = np.asarray(p, dtype=float)
    contact = p > tol * scales.stress  # (thresholds scaled, not the arrays: 3 fewer array operations)
    state = contact.astype(np.int8)  # STICK where in contact, SEPARATION elsewhere
    if t is not None and s is not None:
        at_bound = (mu * np.maximum(p, 0) if bound is None else bound) - np.abs(t) <= tol * scales.stress
        slipping = (np.abs(s) > tol * scales.slip) & at_bound & contact
        state[slipping] = SLIP
    return state


def compare(a: StepSolution, b: StepSolution, mu: float | None = None, scales: Scales = Scales()) -> dict:
    """Differences between two solutions of the same step, nondimensional.

    Returns ``max |Δp|/p0``, ``max |Δt|/(μ p0)`` (or ``/p0`` if μ is not given), ``|Δδ|/u0``, ``|Δξ|/(p0/E*)``,
    and the indices of nodes whose stick/slip/separation state differs.
    """
    out = {}
    if a.p is not None and b.p is not None:
        out["p"] = float(np.max(np.abs(a.p - b.p)) / scales.stress)
    if a.t is not None and b.t is not None:
        tscale = scales.stress * (mu if mu else 1.0)
        out["t"] = float(np.max(np.abs(a.t - b.t)) / tscale)
    if a.delta is not None and b.delta is not None:
        out["delta"] = abs(a.delta - b.delta) / scales.displacement
    if a.xi is not None and b.xi is not None:
        out["xi"] = abs(a.xi - b.xi) / scales.slip
    if a.p is not None and b.p is not None:
        sa = classify(a.p, a.t, a.s, mu or 0.0, scales)
        sb = classify(b.p, b.t, b.s, mu or 0.0, scales)
        out["state_differs"] = np.flatnonzero(sa != sb)
    return out
