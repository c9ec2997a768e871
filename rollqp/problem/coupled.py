"""The coupled step problem (full normal–tangential coupling, docs/formulation.md §10): :class:`CoupledStep`."""
from __future__ import annotations

import dataclasses
from dataclasses import InitVar, dataclass, field

import numpy as np

from ..errors import InputError
from .validation import _check_arrays, _check_friction, _check_sliding_limit, _exactly_one, _per_node, _set_scalars
from .normal import NormalStep
from .scales import Scales
from .solution import Residuals, StepSolution, friction_residual
from .tangential import TangentialStep

__all__ = ["CoupledStep"]


@dataclass
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
    law : SlipBound, optional
        A slip-dependent bound ``μ(s)`` (:mod:`rollqp.friction`); None: ``μ`` fixed.
    trusted : bool, optional
        The values are valid already: the checks are skipped (as for :class:`NormalStep`).

    Notes
    -----
    ``Atn`` and ``Att`` are the *slip* operators: for transient steps the influence matrices
    themselves; for steady rolling (``s = ξ e + T w``, :meth:`SceneOperators.steady
    <rollqp.operators.SceneOperators.steady>`) rollqp.march passes ``Δ·T·A_tn`` and ``Δ·T·A_tt`` with
    ``dq = Δ`` and ``c = 0``.
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
    trusted: InitVar[bool] = False
    kind = "coupled"

    def __post_init__(self, trusted):
        if trusted:
            return
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
        # not re-validated: the coupled step's checked data
        return NormalStep(A=self.Ann, f=self.f, h=self.h, P=self.P, delta=self.delta, offset=off, scales=self.scales,
                          trusted=True)

    def tangential_half(self, p) -> TangentialStep:
        """The tangential step with the pressure ``p`` fixed (eq. 61/62): bound ``μ p⁺``."""
        p = np.asarray(p, dtype=float)
        if not np.all(np.isfinite(p)):
            raise InputError("p", "the fixed pressure must be finite")
        c = self.c if self.Atn is None else self.c + self.Atn @ p
        # not re-validated (trusted) but for the sliding limit, which depends on this pressure
        half = TangentialStep(A=self.Att, f=self.f, p=p, mu=self.mu, c=c, dq=self.dq, Q=self.Q, xi=self.xi,
                              scales=self.scales, law=self.law, trusted=True)
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
