r"""3D step problems and their solutions, with rollqp's own residuals (docs/theory3d.md §4–5, §10).

A step problem is the data of one discrete step — operator, element area, gap or slip data,
friction bound, loads — and nothing about how it is solved; a solution carries the unknowns,
the method and residuals computed here, never taken from a solver's report.

Sign convention (docs/theory3d.md §1; CONTACT's, body A = its body 1): z points into the upper
body A; ``p ≥ 0`` is the pressure, ``t = (t_x, t_y)`` the tangential traction on A; ``g ≥ 0`` the
deformed gap; ``s`` the slip of A relative to B per unit rolled distance; ``ξ, η, φ`` the
creepages (rigid slip of A relative to B over ``|V|``); ``Fx, Fy, Mz`` act on A.

Normal step (eq. 3D.14), the shear ``t̄`` fixed::

    g = h + A_nt t̄ − δ + A_nn p,     p ≥ 0, g ≥ 0, p·g = 0,     area·Σp = FN   (or δ given)

Tangential step (eq. 3D.15), the pressure ``p̄`` fixed, bound ``b = μ p̄⁺``::

    s = w(ξ, η, φ) + (c + B t)/Δq,   w = (ξ − φy, η + φx),   t_i = Proj_{|t|≤b_i}(t_i − r s_i),
    area·Σt_x = Fx (or ξ given),      area·Σt_y = Fy (or η given)

with ``B`` and ``c`` from the kind of step (shift, transient, steady: eq. 3D.16–3D.17) and the
projection onto the disc of radius ``b_i`` (eq. 3D.19): ``|t_i| ≤ b_i``, ``s_i = 0`` where
``|t_i| < b_i``, ``t_i = −b_i s_i/|s_i|`` where ``s_i ≠ 0``.

Nondimensional form (:class:`Scales`): stresses by ``p0``, lengths by ``c = √(ab)``, gaps by
``u0 = c p0/E*``, slips and creepages by ``p0/E*``, forces by ``p0 c²``. The residuals are the
max-norms of ``min(p̂, ĝ)`` (Signorini), ``|t̂_i − Proj_{b̂_i}(t̂_i − ŝ_i)|`` (friction) and the
load rows (eq. 3D.29).
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..friction.projection import project
from .scales import Scales
from .solution import Residuals, StepSolution
from ..validate import positive as _positive, scalar

__all__ = ["Scales", "Residuals", "StepSolution", "NormalStep", "TangentialStep", "disc_projection",
           "rigid_slip", "element_states", "SEPARATION", "STICK", "SLIP"]

#: Element states (result files): 0 separation, 1 stick, 2 slip.
SEPARATION, STICK, SLIP = 0, 1, 2


def disc_projection(z: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``Proj_{|·| ≤ b_i}(z_i)`` element by element (eq. 3D.19: Coulomb's law on the disc, the variational
    inequality 3D.18, as a projection); ``z`` of shape ``(2, n)``, ``b ≥ 0``: the ball of radius ``b`` for
    ``k = 2`` (:func:`rollqp.friction.projection.project`)."""
    return project(z, b)


def rigid_slip(xi: float, eta: float, phi: float, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """The rigid slip of A relative to B over ``|V|`` (eq. 3D.1): ``(ξ − φ y, η + φ x)``, ``(2, n)``."""
    return np.stack([xi - phi * y, eta + phi * x])


def _vector(name, v, n) -> np.ndarray:
    a = np.asarray(v, dtype=float) if v is not None else None
    if a is None or a.shape != (n,) or not np.all(np.isfinite(a)):
        raise InputError(name, f"must be a finite array of shape ({n},)")
    return a


def _number(name, v, positive=False, allow_none=False):
    """:func:`rollqp.validate.positive` or :func:`~rollqp.validate.scalar` of ``v``; ``None`` kept where allowed."""
    if v is None and allow_none:
        return None
    return _positive(name, v) if positive else scalar(name, v)


def _one_of(names, values):
    given = [n for n, v in zip(names, values) if v is not None]
    if len(given) != 1:
        raise InputError(" / ".join(names), f"give exactly one of {' or '.join(names)} (got {len(given)})")


@dataclass(frozen=True)
class NormalStep:
    """The normal (Signorini) step problem (eq. 3D.14).

    Parameters
    ----------
    A : rollqp.influence.blocktoeplitz.BlockToeplitz
        ``A_nn`` (1 × 1 blocks) on the grid of ``n`` elements.
    area : float
        Element area ``dx·dy``.
    h : (n,) array
        Undeformed distance at the element centres (eq. 3D.3).
    FN, delta : float
        The normal force (``> 0``) or the prescribed approach: exactly one.
    offset : (n,) array, optional
        ``A_nt t̄``: the gap change of a fixed shear (dissimilar bodies).
    scales : Scales
    """

    A: object
    area: float
    h: np.ndarray
    FN: float | None = None
    delta: float | None = None
    offset: np.ndarray | None = None
    scales: Scales = field(default_factory=lambda: Scales(dimension=3))
    kind = "normal"

    def __post_init__(self):
        n = self.A.shape[1]
        if self.A.shape != (n, n):
            raise InputError("A", f"the normal operator must be square (1 × 1 blocks), got {self.A.shape}")
        if not isinstance(self.scales, Scales) or self.scales.dimension != 3:
            raise InputError("scales", "a grid's step takes Scales(..., dimension=3) (forces in p0 c²), got "
                                       f"{self.scales!r}")
        object.__setattr__(self, "area", _number("area", self.area, positive=True))
        object.__setattr__(self, "h", _vector("h", self.h, n))
        if self.offset is not None:
            object.__setattr__(self, "offset", _vector("offset", self.offset, n))
        _one_of(("FN", "delta"), (self.FN, self.delta))
        object.__setattr__(self, "FN", _number("FN", self.FN, positive=True, allow_none=True))
        object.__setattr__(self, "delta", _number("delta", self.delta, allow_none=True))

    @property
    def n(self) -> int:
        return self.h.size

    @property
    def h_total(self) -> np.ndarray:
        """``h + A_nt t̄``."""
        return self.h if self.offset is None else self.h + self.offset

    def gap(self, p, delta, Ap=None) -> np.ndarray:
        """``g = h + A_nt t̄ − δ + A_nn p`` (eq. 3D.14); ``Ap``: the product if known."""
        return self.h_total - delta + (self.A @ p if Ap is None else Ap)

    def residuals(self, p, delta, g=None) -> Residuals:
        """``‖min(p̂, ĝ)‖∞`` and the load row ``|area·Σp − FN|/(p0 c²)`` (eq. 3D.29)."""
        sc = self.scales
        g = self.gap(p, delta) if g is None else g
        sig = float(np.max(np.abs(np.minimum(p / sc.stress, g / sc.displacement))))
        load = 0.0 if self.FN is None else abs(self.area * float(np.sum(p)) - self.FN) / sc.force
        return Residuals(signorini=sig, load_normal=load)

    def solution(self, p, delta, Ap=None, **meta) -> StepSolution:
        """``(p, δ)`` with its gap and rollqp's residuals."""
        p = np.asarray(p, dtype=float)
        g = self.gap(p, float(delta), Ap)
        return StepSolution(residuals=self.residuals(p, delta, g), p=p, g=g, delta=float(delta), **meta)


@dataclass(frozen=True)
class TangentialStep:
    """The tangential (friction) step problem with the pressure fixed (eq. 3D.15).

    Parameters
    ----------
    B : rollqp.influence.blocktoeplitz.BlockToeplitz
        The 2 × 2 slip operator: ``A_tt`` (shift, transient) or ``A_tt − A_tt(· − d Δx)``
        (steady rolling, eq. 3D.17).
    area : float
        Element area.
    bound : (n,) array
        The traction bound ``μ p̄⁺`` (``>= 0``; zero outside the contact).
    x, y : (n,) arrays
        Element centres (the spin's lever arms, eq. 3D.1).
    c : (2, n) array
        The history and coupling vector: ``Δq s = Δq w + c + B t``.
    dq : float
        Rolled distance of the step (for a shift: its length unit; steady: ``dx``).
    Fx, xi : float
        Force on A along x or the creepage ξ: exactly one.
    Fy, eta : float
        Force along y or the creepage η: exactly one.
    phi : float
        The spin creepage φ (1/length), always given.
    scales : Scales
    p : (n,) array, optional
        The pressure ``p̄`` (required with ``law``): a slip-dependent bound is ``μ(s) p̄⁺``.
    law : SlipBound, optional
        A slip-dependent coefficient ``μ_i(V|s_i|)`` (:class:`rollqp.friction.bound.SlipBound`, docs/friction.md):
        the step is then a quasi-variational inequality whose bound ``μ_i(s_i) p̄_i⁺`` moves with the slip;
        ``bound`` is the bound at zero slip (the sliding limit's). ``None``: the bound is ``bound``.
    """

    B: object
    area: float
    bound: np.ndarray
    x: np.ndarray
    y: np.ndarray
    c: np.ndarray
    dq: float
    Fx: float | None = None
    xi: float | None = None
    Fy: float | None = None
    eta: float | None = None
    phi: float = 0.0
    scales: Scales = field(default_factory=lambda: Scales(dimension=3))
    p: np.ndarray | None = None
    law: object = None
    kind = "tangential"

    def __post_init__(self):
        n = self.B.shape[1] // 2
        if self.B.shape != (2 * n, 2 * n):
            raise InputError("B", f"the slip operator must be 2 × 2 blocks, got shape {self.B.shape}")
        if not isinstance(self.scales, Scales) or self.scales.dimension != 3:
            raise InputError("scales", "a grid's step takes Scales(..., dimension=3) (forces in p0 c²), got "
                                       f"{self.scales!r}")
        object.__setattr__(self, "area", _number("area", self.area, positive=True))
        bound = _vector("bound", self.bound, n)
        if np.any(bound < 0):
            raise InputError("bound", "the traction bound μp must be >= 0")
        object.__setattr__(self, "bound", bound)
        for name in ("x", "y"):
            object.__setattr__(self, name, _vector(name, getattr(self, name), n))
        c = np.asarray(self.c, dtype=float)
        if c.shape != (2, n) or not np.all(np.isfinite(c)):
            raise InputError("c", f"must be a finite array of shape (2, {n})")
        object.__setattr__(self, "c", c)
        object.__setattr__(self, "dq", _number("dq", self.dq, positive=True))
        object.__setattr__(self, "phi", _number("phi", self.phi))
        _one_of(("Fx", "xi"), (self.Fx, self.xi))
        _one_of(("Fy", "eta"), (self.Fy, self.eta))
        for name in ("Fx", "xi", "Fy", "eta"):
            object.__setattr__(self, name, _number(name, getattr(self, name), allow_none=True))
        if self.p is not None:
            object.__setattr__(self, "p", _vector("p", self.p, n))
        if self.law is not None and self.p is None:
            raise InputError("p", "a slip-dependent bound (law) needs the pressure p of the step")
        self._check_sliding_limit()

    def _check_sliding_limit(self):
        cap = self.area * float(np.sum(self.bound))
        F = math.hypot(self.Fx or 0.0, self.Fy or 0.0)
        if (self.Fx is not None or self.Fy is not None) and not F < cap:
            key = "Fx" if self.Fx is not None else "Fy"
            raise InputError(key, f"|(Fx, Fy)| = {F:.6g} must be below the sliding limit Σ μp·area "
                                  f"= {cap:.6g} (μ·FN where μ is uniform) for a solution with stick")

    @property
    def n(self) -> int:
        return self.bound.size

    @property
    def slip_shape(self) -> tuple[int, int]:
        """The shape of a slip on this grid, ``(2, n)``."""
        return (2, self.bound.size)

    def bound_at(self, s) -> np.ndarray:
        """The bound at the slip ``s`` (``(2, n)``): ``μ(s) p̄⁺`` with a slip-dependent ``law``, else :attr:`bound`."""
        return self.bound if self.law is None else self.law.mu(s) * np.maximum(self.p, 0.0)

    def coefficient(self, s=None, p=None):
        """``μ`` at the elements: ``law.mu(s)`` at the slip ``s`` (outside the contact, ``p <= 0``, at zero slip
        velocity: docs/friction.md), else None (the bound is data)."""
        if self.law is None or s is None:
            return None
        return self.law.mu(s, contact=(self.p if p is None else p) > 0.0)

    def replace(self, **kw) -> "TangentialStep":
        """The same step with the values ``kw``, checked; ``mu`` (a number or ``(n,)`` array) sets the bound
        ``mu p̄⁺`` (with ``law=None``: the step with its coefficient frozen, a convex SOCP)."""
        if "mu" in kw:
            mu = kw.pop("mu")
            kw["bound"] = np.asarray(mu, dtype=float) * np.maximum(self.p, 0.0)
        return dataclasses.replace(self, **kw)

    derived = replace

    def evaluate(self, sol: StepSolution) -> StepSolution:
        """``sol``'s traction and creepages re-evaluated on this problem (rollqp's residuals)."""
        return self.solution(sol.t, sol.xi, sol.eta)

    def creepages(self, xi=None, eta=None) -> tuple[float, float]:
        """``(ξ, η)``: the prescribed ones, else the given unknowns."""
        return (self.xi if self.xi is not None else float(xi),
                self.eta if self.eta is not None else float(eta))

    def slip(self, t, xi=None, eta=None, Bt=None) -> np.ndarray:
        """``s = w(ξ, η, φ) + (c + B t)/Δq`` (eq. 3D.15), shape ``(2, n)``; ``Bt``: ``B t`` if known."""
        xi, eta = self.creepages(xi, eta)
        t = np.asarray(t, dtype=float)
        Bt = (self.B @ t.ravel()).reshape(2, -1) if Bt is None else np.asarray(Bt).reshape(2, -1)
        return rigid_slip(xi, eta, self.phi, self.x, self.y) + (self.c + Bt) / self.dq

    def residuals(self, t, xi=None, eta=None, s=None) -> Residuals:
        """``max_i |t̂_i − Proj_{b̂_i}(t̂_i − ŝ_i)|`` and the load rows (eq. 3D.29)."""
        sc = self.scales
        t = np.asarray(t, dtype=float).reshape(2, -1)
        s = self.slip(t, xi, eta) if s is None else s
        th, sh, bh = t / sc.stress, s / sc.slip, self.bound_at(s) / sc.stress
        r = th - disc_projection(th - sh, bh)
        fric = float(np.max(np.hypot(r[0], r[1])))
        lx = 0.0 if self.Fx is None else abs(self.area * float(np.sum(t[0])) - self.Fx) / sc.force
        ly = 0.0 if self.Fy is None else abs(self.area * float(np.sum(t[1])) - self.Fy) / sc.force
        return Residuals(friction=fric, load_tangential=lx, load_lateral=ly)

    def solution(self, t, xi=None, eta=None, Bt=None, **meta) -> StepSolution:
        """``(t, ξ, η)`` with its slip and rollqp's residuals."""
        t = np.asarray(t, dtype=float).reshape(2, -1)
        xi, eta = self.creepages(xi, eta)
        s = self.slip(t, xi, eta, Bt)
        if self.law is not None:   # the coefficient at the elements: the next step's memory
            meta.setdefault("mu", self.coefficient(s))
        return StepSolution(residuals=self.residuals(t, xi, eta, s), t=t, s=s, xi=xi, eta=eta, **meta)

    def states(self, t, s=None) -> np.ndarray:
        """0 separation (``b = 0``), 1 stick, 2 slip, ``(n,)``: slip where the projection of eq. 3D.19 is
        active, ``|t̂_i − ŝ_i| > b̂_i`` (the partition of the solution; ``s``: its slip if known)."""
        t = np.asarray(t, dtype=float).reshape(2, -1)
        s = self.slip(t) if s is None else np.asarray(s).reshape(2, -1)
        return element_states(t, s, self.bound_at(s), self.scales)


def element_states(t, s, bound, scales) -> np.ndarray:
    """The states of :meth:`TangentialStep.states` from tractions, slips and bounds."""
    z = t / scales.stress - s / scales.slip
    slip = np.hypot(z[0], z[1]) > bound / scales.stress
    return np.where(bound <= 0, SEPARATION, np.where(slip, SLIP, STICK)).astype(np.int8)
