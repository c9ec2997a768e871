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
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError

__all__ = ["SlipBound", "step_coefficient"]


@dataclass(frozen=True)
class SlipBound:
    """The slip-dependent coefficient ``μ(s)`` of one step (module docstring). ``s`` is the slip per unit
    rolled distance (the step problems' ``s``, a pure number)."""

    law: object                      # rollqp.friction.laws.SlipVelocity
    weight: float = 0.0              # memory weight w
    previous: np.ndarray | None = None  # μ̄ at the nodes (memory); None: w = 0

    def mu(self, s) -> np.ndarray:
        """``μ_i(s_i)``."""
        m, _ = self.law.steady(self.law.rolling_speed * np.abs(s))
        return m if self.previous is None else (1.0 - self.weight) * m + self.weight * self.previous

    def dmu(self, s) -> np.ndarray:
        """``∂μ_i/∂s_i`` (zero at ``s_i = 0``: the one-sided derivative into slip is taken by the Newton
        method from the sign of the slip it moves to)."""
        V = self.law.rolling_speed
        _, d = self.law.steady(V * np.abs(s))
        return (1.0 - self.weight) * d * V * np.sign(s)

    def slip_velocity(self, s) -> np.ndarray:
        """``v = V |s|`` (length/time)."""
        return self.law.rolling_speed * np.abs(np.asarray(s, dtype=float))


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
        return law.mu, None  # the number itself (a plain float): the old code path
    if kind == "spatial":
        return law.coefficient(x_hat, q_hat, direction), None
    static = law.steady(0.0)[0]
    if law.memory == 0.0:
        return float(static), SlipBound(law)
    if steady:
        raise InputError("contact.friction.memory", "a direct steady solve cannot carry the friction memory "
                                                    "along the material; use load.start = 'braked' (marching) or "
                                                    "memory = 0")
    if previous is None:
        previous = np.full(x_hat.shape, float(static))
    if dq_hat is not None:  # the material now at x was at x − d Δq (Δq signed: a reversal brings it back)
        previous = np.interp(_at_nodes(x_hat - direction * dq_hat, x_hat), x_hat, previous,
                             left=float(static), right=float(static))
    w = law.weight(dq_hat if dq_hat is not None else 1.0)
    return float(static), SlipBound(law, w, np.asarray(previous, dtype=float))
