"""Kinematics as a history: the rolled distance q(τ) of a time-like parameter τ, step by step (paper eq. 21, 32–40).

Without ``load.rolled`` a scene's steps are ``q_k = k·Δq`` and the time-like parameter is the
rolled distance itself, τ = q (the paper's eq. 21 with ``|V| = 1``). With ``load.rolled`` the steps
are ``τ_k = k·Δτ`` (``Δτ = step·Le``, the same grid) and the rolled distance is
``q(τ) = a_H·rolled(τ/a_H)``, any history (:mod:`rollqp.histories`): its increments
``Δq_k = q(τ_k) − q(τ_{k−1})`` may

* be positive: material flows in ``load.direction`` (d = ``load.direction``);
* be negative: a **reversal**, the material flows the other way (d = −``load.direction``), and
  the shift and upwind operators follow (``R`` of eq. 33 shifts by ``x_i − d·|Δq|``, ``D_up`` of
  eq. 38–40 looks the other way, :meth:`rollqp.strip.Strip.history_operator`);
* vanish: a **stop**, the step is a static shift under the loads of τ_k,
  ``s = ξ + (w^k − w^{k−1})/Δ`` with ``Δ = a_H`` and ``ξ·Δ`` the rigid shift (the braked start's
  form, §4.4; the record's ``shift``);
* vary from step to step (a prescribed variable Δq).

The loads are histories of τ (``P(τ)``, ``Q(τ)``, ``ξ(τ)``, ``δ(τ)``), so "roll, stop, cycle Q at
rest, roll back" is one scene. :class:`Plan` is the list of steps; :class:`HistoryCache` keeps
the history operators of the step sizes met (built once per distinct (Δq, d)). Post-processing:
:func:`hysteresis` (the Q–displacement loop of static steps and its dissipated energy per cycle).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Plan", "plan", "HistoryCache", "hysteresis", "STOP_TOL"]

#: ``|Δq|`` below this fraction of the element length is a stop (a table's flat segment gives exactly 0).
STOP_TOL = 1e-12


@dataclass(frozen=True)
class Plan:
    """The steps of a scene: ``tau`` (τ_k), ``q`` (q(τ_k)), and per step ``dq`` = ``|Δq_k|`` and ``d``.

    ``d[k]`` is the direction of the material in step k (±1), 0 for a stop; ``d[0] = load.direction``.
    ``rolled`` is False for a scene without ``load.rolled`` (then ``q`` is ``tau``, every
    ``dq`` the scene's Δq, every ``d`` its direction).
    """

    tau: np.ndarray
    q: np.ndarray
    dq: np.ndarray
    d: np.ndarray
    rolled: bool

    @property
    def final_direction(self) -> int:
        """The direction of the last step that rolled (``load.direction`` if none did)."""
        moving = self.d[1:][self.d[1:] != 0]
        return int(moving[-1]) if moving.size else int(self.d[0])

    def shift_range(self) -> tuple[float, float]:
        """``(min, max)`` of ``d·q`` over the run, ``d = load.direction``: where the material has moved."""
        s = self.d[0] * self.q
        return float(np.min(s)), float(np.max(s))


def plan(scene) -> Plan:
    """The :class:`Plan` of ``scene`` (module docstring)."""
    tau = scene.time_steps
    d0 = int(scene.load.direction)
    if scene.load.rolled is None:
        n = tau.size
        return Plan(tau, tau, np.full(n, scene.dq), np.full(n, d0), False)
    q = scene.rolled_distance(tau)
    dq = np.diff(q, prepend=q[0])
    stop = np.abs(dq) <= STOP_TOL * scene.element_length
    d = np.where(stop, 0, np.where(dq > 0, d0, -d0)).astype(int)
    d[0] = d0
    return Plan(tau, q, np.where(stop, 0.0, np.abs(dq)), d, True)


class HistoryCache:
    """The history operator ``M`` of each (Δq, d) met, from :meth:`SceneOperators.build_history
    <rollqp.operators.SceneOperators.build_history>` (sparse on either path).

    A table's Δq differs from step to step by round-off (``q(τ_k) − q(τ_{k−1})`` of interpolated
    values): steps within ``rtol`` (1e-12, far below the discretization error of the shift) reuse
    the operator of the first. At most ``size`` operators are kept (least recently used out).
    """

    def __init__(self, ops, rtol: float = 1e-12, size: int = 8):
        self.ops, self.rtol, self.size = ops, rtol, size
        self.items: list = []

    def get(self, dq: float, d: int):
        for i, (dq0, d0, M) in enumerate(self.items):
            if d0 == d and abs(dq - dq0) <= self.rtol * dq0:
                self.items.append(self.items.pop(i))
                return M
        M = self.ops.build_history(self.ops.scene.discretization.formulation, dq, d)
        self.items.append((dq, d, M))
        if len(self.items) > self.size:
            self.items.pop(0)
        return M


# =========================================================================== post-processing
def hysteresis(result, cycle: tuple[float, float] | None = None) -> dict:
    """The tangential load against the rigid displacement of a scene's static steps, and the energy lost.

    The displacement ``u`` is the one conjugate to ``Q``: minus the accumulated rigid static shift
    (the result's ``shift``, ξ·Δ of every static step, the braked start included). Q is the force
    of B on A's surface, so A's shaft carries −Q, and the work of the shaft loads is
    ``−Q·d(ξΔ) = Q·du`` (with ``contact.model = "bem"``: the displacement of shaft B against
    shaft A, along +x). On the half-space it holds an additive constant
    and a term linear in Q that depend on ``contact.reference_distance``; neither changes the
    area of a closed loop.

    Parameters
    ----------
    result : Result or dict
        A run's result (:class:`~rollqp.result.Result` or :func:`~rollqp.result.load_result`).
    cycle : (float, float), optional
        ``(τ_start, τ_end)`` in units of a_H of one closed cycle (Q and u return to their values):
        the energy is ``∮ Q du`` over it (trapezoidal rule on the states). Default: no energy.

    Returns
    -------
    dict
        ``tau`` (units of a_H), ``Q``, ``u`` (length), and ``energy`` (force, per unit axial length;
        ``nan`` without ``cycle``): the work of Q over the cycle, the energy dissipated by
        friction in it.
    """
    r = result.arrays() if hasattr(result, "arrays") else result
    a_H = float(r["a_H"])
    tau = np.asarray(r["time"] if "time" in r else r["q"], dtype=float) / a_H
    Q, u = np.asarray(r["Q"], dtype=float), -np.cumsum(np.asarray(r["shift"], dtype=float))
    energy = float("nan")
    if cycle is not None:
        m = (tau >= cycle[0] - 1e-9) & (tau <= cycle[1] + 1e-9)
        energy = float(np.sum(0.5 * (Q[m][1:] + Q[m][:-1]) * np.diff(u[m])))
    return {"tau": tau, "Q": Q, "u": u, "energy": energy}
