r"""One step's friction coefficient from the scene's law: a number, one value per node, or a slip-dependent bound.

:func:`step_coefficient` is what :class:`~rollqp.operators.SceneOperators` calls for each step;
:class:`SlipBound` is the bound of a slip-velocity law at one step (docs/theory.md,
"Slip-dependent friction"):

.. math::
    \mu_i(s_i) = (1 - w)\,\mu_\infty(V |s_i|) + w\,\bar\mu_i,\qquad
    \frac{\partial \mu_i}{\partial s_i} = (1 - w)\,\mu_\infty'(V|s_i|)\,V\,\mathrm{sgn}(s_i),

with ``μ∞`` the law's steady curve (:meth:`~.laws.SlipVelocity.steady`), ``V`` the rolling
speed, ``w = L/(L + Δq)`` the memory weight (implicit Euler of ``L dμ/dq = μ∞ − μ`` along the
material) and ``μ̄`` the coefficient the material at node ``i`` carried at the previous step
(transported by ``d Δq`` and interpolated; material entering the strip brings the static value).
Without memory ``w = 0``.

**Outside the contact** (``p_i <= 0``) there is no sliding interface: the slip ``s_i`` there is only
the kinematic relative motion of two surfaces apart. The coefficient a step hands on as the memory
(:meth:`~rollqp.problem.TangentialStep.coefficient`) therefore takes ``v = 0`` there, as CONTACT
does: separated material relaxes towards ``μ∞(0) = μ_s`` over the memory length and enters the
contact at (nearly) the static value. The bound itself is ``μ p⁺ = 0`` there either way.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError

__all__ = ["SlipBound", "step_coefficient", "grid_coefficient", "steady_branches"]


@dataclass(frozen=True)
class SlipBound:
    """The slip-dependent coefficient ``μ(s)`` of one step (module docstring). ``s`` is the slip per unit
    rolled distance (the step problems' ``s``, a pure number).

    With ``frozen`` (coefficients at the nodes, those of the previous state) the bound is a point of the path
    from the frozen bound to the law, ``μ_λ(s) = (1 − λ) μ_f + λ μ(s)`` with ``λ = blend`` (docs/friction.md,
    "Which solution of a step"): a step with such a bound asks for the solution near its warm start
    (:attr:`on_path`). ``frozen = None``: the law itself.
    """

    law: object                      # rollqp.friction.laws.SlipVelocity
    weight: float = 0.0              # memory weight w
    previous: np.ndarray | None = None  # μ̄ at the nodes (memory); None: w = 0
    frozen: np.ndarray | None = None    # μ_f of the path from the frozen bound (None: the law itself)
    blend: float = 1.0                  # λ on that path
    steady: bool = False                # the bound of a direct steady solve (its operator is not symmetric)

    def mu(self, s, contact=None) -> np.ndarray:
        """``μ_i(s_i)``; ``s`` of shape ``(n,)`` (a strip) or ``(2, n)`` (a grid: ``|s_i|`` the length of the
        element's slip vector); ``contact`` (a mask, optional): outside it the slip velocity is taken as 0, CONTACT's
        semantics (module docstring), so that the memory of separated material relaxes towards the static value."""
        v = self.law.rolling_speed * _magnitude(s)
        if contact is not None:
            v = np.where(contact, v, 0.0)
        m, _ = self.law.steady(v)
        m = m if self.previous is None else (1.0 - self.weight) * m + self.weight * self.previous
        return m if self.frozen is None else (1.0 - self.blend) * self.frozen + self.blend * m

    def dmu(self, s) -> np.ndarray:
        """``∂μ_i/∂s_i`` (zero at ``s_i = 0``: the one-sided derivative into slip is taken by the Newton
        method from the sign of the slip it moves to). On a grid (``s`` of shape ``(2, n)``) the gradient
        ``(1 − w) μ'(V|s_i|) V s_i/|s_i|``, shape ``(2, n)``, zero where ``s_i = 0``."""
        V = self.law.rolling_speed
        s = np.asarray(s)
        if s.ndim == 2:
            norm = np.hypot(s[0], s[1])
            _, d = self.law.steady(V * norm)
            unit = np.divide(s, norm, out=np.zeros(s.shape), where=norm > 0)
            d = (1.0 - self.weight) * d * V * unit
        else:
            _, d = self.law.steady(V * np.abs(s))
            d = (1.0 - self.weight) * d * V * np.sign(s)
        return d if self.frozen is None else self.blend * d

    def take(self, idx) -> "SlipBound":
        """This bound on the nodes ``idx`` only (the memory and the frozen coefficients taken there)."""
        pick = lambda a: None if a is None else np.asarray(a)[idx]  # noqa: E731
        return SlipBound(self.law, self.weight, pick(self.previous), pick(self.frozen), self.blend, self.steady)

    @property
    def on_path(self) -> bool:
        """A point of the path from the frozen bound (``frozen`` given): its step is solved near the warm start."""
        return self.frozen is not None

    def homotopy(self, frozen, blend) -> "SlipBound":
        """This bound as the point ``λ = blend`` of the path from the frozen coefficients ``frozen``."""
        return SlipBound(self.law, self.weight, self.previous, np.asarray(frozen, dtype=float), float(blend),
                         self.steady)

    @property
    def steepness(self) -> float:
        """The largest ``|∂μ/∂s|`` the law takes: ``(1 − w) V max|dμ/dv|``."""
        return (1.0 - self.weight) * self.law.rolling_speed * float(self.law.steepest)

    def segment(self, v) -> np.ndarray:
        """The smooth piece of ``μ(v)`` each slip velocity ``v >= 0`` lies on (:attr:`~.laws.SlipVelocity.kinks`)."""
        return np.searchsorted(np.asarray(self.law.kinks, dtype=float), v, side="right")

    def branch(self, v, k) -> tuple:
        """``(μ, ∂μ/∂v)`` of this step's coefficient (the memory included, the path's blend not) at the slip
        velocities ``v`` on the smooth pieces ``k`` of the law, each piece's formula continued beyond it
        (:meth:`~.laws.SlipVelocity.branch`)."""
        m, d = self.law.branch(v, k)
        if self.previous is None:
            return m, d
        return (1.0 - self.weight) * m + self.weight * self.previous, (1.0 - self.weight) * d

    def slip_velocity(self, s) -> np.ndarray:
        """``v = V |s|`` (length/time); ``s`` of shape ``(n,)`` or ``(2, n)``."""
        return self.law.rolling_speed * _magnitude(np.asarray(s, dtype=float))


def _magnitude(s):
    """``|s_i|``: the absolute value on a strip (``(n,)``), the length of the slip vector on a grid (``(2, n)``)."""
    s = np.asarray(s)
    return np.hypot(s[0], s[1]) if s.ndim == 2 else np.abs(s)


def _at_nodes(points, x_hat):
    """``points`` with those within round-off (1e-9 of a node spacing) of the strip's end nodes put on them:
    material that was at an end node keeps its memory instead of being taken for material entering
    the strip (a step of exactly a node spacing lands there up to the last bit of ``Δq``)."""
    tol = 1e-9 * float(np.min(np.diff(x_hat))) if x_hat.size > 1 else 0.0
    points = np.where(np.abs(points - x_hat[0]) <= tol, x_hat[0], points)
    return np.where(np.abs(points - x_hat[-1]) <= tol, x_hat[-1], points)


def step_coefficient(law, x_hat, q_hat, direction, *, dq_hat=None, previous=None, steady=False):
    """What one step problem takes as ``mu`` (and ``law``): ``(mu, law)``.

    Parameters
    ----------
    law : FrictionLaw
        ``scene.contact.friction`` (:class:`rollqp.friction.FrictionLaw`).
    x_hat : (n,) array
        The nodes in ``a_H`` units.
    q_hat : float
        Rolled distance of the step in ``a_H`` units.
    direction : int
        ``d = load.direction``.
    dq_hat : float or None
        The step's signed rolled distance ``q_k − q_{k−1}`` in ``a_H`` units (negative when a load
        path rolls back; rolling steps; ``None``: no transport of the memory, a static shift or a
        steady state).
    previous : (n,) array or None
        The coefficient at the nodes after the previous step (memory).
    steady : bool
        A direct steady solve: a law with memory cannot be posed there (InputError).
    """
    kind = law.kind
    if kind == "constant":
        return law.mu, None  # the number itself (a plain float): the constant-coefficient code path
    if kind == "spatial":
        return law.coefficient(x_hat[None, :], q_hat, direction), None   # the strip's points, (1, n)
    return _slip_bound(law, x_hat, x_hat.shape, dq_hat, direction, previous, steady)


def grid_coefficient(law, x_hat, shape, *, dq_hat=None, direction=-1, previous=None, steady=False):
    """:func:`step_coefficient` of a slip-velocity ``law`` on a grid: ``(μ_s, SlipBound)``.

    ``x_hat`` (``(nx,)``) are the element centres along the rolling direction in the contact's length unit,
    ``shape = (ny, nx)`` the grid's; ``previous`` (``(ny·nx,)``, row after row) the coefficient after the last
    step. The memory is carried with the material along x on each row of elements (the material now at ``(x, y)``
    was at ``(x − d Δq, y)``), as on a strip; entering material brings the static value."""
    return _slip_bound(law, np.asarray(x_hat, dtype=float), tuple(shape), dq_hat, direction, previous, steady)


def _slip_bound(law, x_hat, shape, dq_hat, direction, previous, steady):
    """The slip-velocity branch of :func:`step_coefficient` on nodes of ``shape`` (``(n,)`` a strip, ``(ny, nx)`` a
    grid, ``x_hat`` the positions along the last axis)."""
    static = law.steady(0.0)[0]
    if law.memory == 0.0:
        return float(static), SlipBound(law, steady=bool(steady))
    if steady:
        raise InputError("contact.friction.memory", "a direct steady solve cannot carry the friction memory "
                                                    "along the material; use load.start = 'braked' (marching) or "
                                                    "memory = 0")
    size = int(np.prod(shape))
    if previous is None:
        previous = np.full(size, float(static))
    if dq_hat is not None:  # the material now at x was at x − d Δq (Δq signed: a reversal brings it back)
        at = _at_nodes(x_hat - direction * dq_hat, x_hat)
        rows = np.asarray(previous, dtype=float).reshape(-1, x_hat.size)
        previous = np.concatenate([np.interp(at, x_hat, row, left=float(static), right=float(static))
                                   for row in rows]).reshape(size) if len(shape) > 1 else \
            np.interp(at, x_hat, previous, left=float(static), right=float(static))
    w = law.weight(dq_hat if dq_hat is not None else 1.0)
    return float(static), SlipBound(law, w, np.asarray(previous, dtype=float))


def steady_branches(law, Q, P, gross) -> str | None:
    """What a direct steady solve with the force ``Q`` prescribed should tell about the other steady states of a
    falling ``law`` (docs/friction.md, "Which steady state"), or None.

    At large slip ``μ → μ_k``: with ``μ_k P < |Q| < μ_s P`` a *gross-sliding* steady state exists besides the
    branch that grows continuously from Coulomb at ``μ_s`` (every node slipping, at the creepage where the mean
    of ``μ(V|s|)`` carries ``|Q|``); the Newton start from the braked state returns the latter. ``gross``: the
    state returned is gross sliding."""
    lo, hi = law.kinetic * P, law.static * P
    if gross:
        return (f"gross sliding: every contact node slips (|Q| = {abs(Q) / P:.4g} P between mu_k P = {lo / P:.4g} P "
                f"and mu_s P = {hi / P:.4g} P); a state with stick may exist too (docs/friction.md)")
    if lo < abs(Q) < hi and law.static > law.kinetic:
        return (f"a gross-sliding steady state exists too (|Q| = {abs(Q) / P:.4g} P > mu_k P = {lo / P:.4g} P); "
                "this one has stick, the branch continuous with Coulomb at mu_s (docs/friction.md)")
    return None
