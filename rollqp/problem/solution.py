"""Solutions of step problems and rollqp's own residuals of them; node states (docs/formulation.md §5)."""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from ..friction.projection import residual as projection_residual
from .scales import Scales

__all__ = ["SEPARATION", "STICK", "SLIP", "friction_residual", "Residuals", "StepSolution", "classify", "compare"]

# Node states in result files (docs/results.md): 0 separation, 1 stick, 2 slip.
SEPARATION, STICK, SLIP = 0, 1, 2


def friction_residual(t, s, bound, minus_bound=None, out=None):
    """``t − Proj_[−b, b](t − s)`` (eq. 60): zero iff ``|t| <= b`` and ``t`` opposes the slip ``s``.

    The one expression of the friction law's projection residual: rollqp's residuals use it with
    nondimensional ``t̂, ŝ, b̂``; the Newton method with ``r ŝ`` in place of ``ŝ`` (eq. 56, 63).
    ``minus_bound``: ``−b`` if the caller keeps it; ``out``: the array to write it into.
    """
    return projection_residual(t, s, bound, minus_bound, out)   # the ball of radius b, k = 1 (rollqp.friction.projection)


@dataclass
class Residuals:
    """rollqp's own nondimensional residuals of a step (max norms; see module docstring; on a
    grid, eq. 3D.29): ``load_tangential`` is the tangential load equation (along x on a grid), ``load_lateral`` the
    lateral one (along y; a grid's second traction component, zero on a strip)."""

    signorini: float = 0.0
    friction: float = 0.0
    load_normal: float = 0.0
    load_tangential: float = 0.0
    load_lateral: float = 0.0

    @property
    def max(self) -> float:
        """The largest residual; NaN if any is NaN (so that no limit check can pass it)."""
        a, b, c, d, e = self.signorini, self.friction, self.load_normal, self.load_tangential, self.load_lateral
        total = a + b + c + d + e  # NaN if any is (the residuals are >= 0: no inf − inf)
        # (builtin max on five floats: np.max costs 10× as much, and it is read for every solve)
        return float(max(a, b, c, d, e)) if total == total else float("nan")

    def __or__(self, other: "Residuals") -> "Residuals":
        a = np.asarray(dataclasses.astuple(self), dtype=float)
        b = np.asarray(dataclasses.astuple(other), dtype=float)
        return Residuals(*np.maximum(a, b).tolist())  # np.maximum propagates NaN


@dataclass
class StepSolution:
    """The unknowns of one step, how they were obtained, and rollqp's residuals.

    Absent parts are ``None`` (``g``/``delta`` for a tangential step, ``t``/``s``/``xi`` for
    a normal one). ``t`` and ``s`` have one row per traction component: shape ``(n,)`` on a strip,
    ``(2, n)`` (x and y) on a grid, whose lateral creepage is ``eta``. The statistics every method may report are typed fields (qpsolvers'
    ``Solution`` style): ``iterations`` counts the method's own iterations; ``time`` is the wall
    time of the solve in rollqp (``solver_time`` the external solver's own, if any);
    ``backtracks`` the Armijo step reductions (Newton); ``outer``, ``inner_normal`` and
    ``inner_tangential`` the outer iterations of the N–T alternation and the iterations of its
    halves; ``mu`` the friction coefficient at the nodes of a step with a friction law (the next
    step's memory); ``At`` the pair ``(t, A t)`` when the method computed the product (the march
    then needs no new one). What is particular to one method or solver (a residual history, the
    solver's status text, a QP multiplier) is in ``extras`` (``info`` is the same dict).

    Examples
    --------
    >>> from rollqp import StepSolution
    >>> sol = StepSolution(iterations=3, backtracks=1)
    >>> sol.iterations, sol.backtracks, sol.extras
    (3, 1, {})
    >>> sol.info is sol.extras
    True
    """

    p: np.ndarray | None = None
    t: np.ndarray | None = None
    g: np.ndarray | None = None
    s: np.ndarray | None = None
    delta: float | None = None
    xi: float | None = None
    residuals: Residuals = field(default_factory=Residuals)
    #: The lateral creepage of a grid's step (its second load unknown; ``xi`` the longitudinal one).
    eta: float | None = None
    method: str = ""
    status: str = "solved"
    iterations: int = 0
    time: float = 0.0
    solver_time: float = 0.0
    extras: dict = field(default_factory=dict)
    backtracks: int = 0
    outer: int = 0
    inner_normal: int = 0
    inner_tangential: int = 0
    mu: np.ndarray | None = field(default=None, repr=False)
    At: tuple | None = field(default=None, repr=False)

    @property
    def info(self) -> dict:
        """The method's own data (:attr:`extras`)."""
        return self.extras

    @property
    def residual(self) -> float:
        return self.residuals.max


def classify(p, t, s, mu, scales: Scales = Scales(), tol: float = 1e-7, bound=None, contact=None) -> np.ndarray:
    """Node states: 0 separation (``p̂ <= tol``), 2 slip (``|ŝ| > tol`` at the bound), 1 stick.

    ``t`` or ``s`` may be ``None`` (normal problem only): contact nodes are then stick. ``bound``:
    ``μ max(p, 0)`` if the caller has it (a step problem's :attr:`TangentialStep.bound`); ``contact``:
    ``p > tol·p0`` (boolean) likewise (a march whose pressure stays the same array from step to step).
    """
    p = np.asarray(p, dtype=float)
    if contact is None:
        contact = p > tol * scales.stress  # (thresholds scaled, not the arrays: 3 fewer array operations)
    if t is None or s is None:
        return contact.astype(np.int8)  # STICK where in contact, SEPARATION elsewhere
    at_bound = (mu * np.maximum(p, 0) if bound is None else bound) - np.abs(t) <= tol * scales.stress
    slipping = np.abs(s) > tol * scales.slip
    slipping &= at_bound
    slipping &= contact
    # STICK (1) in contact, SLIP (2) where slipping too (a subset of the contact): the two masks as 0/1 bytes, added
    return np.add(contact.view(np.int8), slipping.view(np.int8))


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
