"""Energy and frictional dissipation of each state: result fields and the balance (docs/stresses.md §5).

Per unit axial length, in the scene's units, with rollqp's signs (docs/formulation.md §1: ``t`` on
A in +x, ``s`` the slip of A relative to B per unit rolled distance, friction opposing slip):

* ``friction_power`` (K+1, n): the dissipation density ``−t·s ≥ 0`` per unit rolled distance
  (force/length²; times the speed ``|V|`` it is the frictional power per unit area);
* ``dissipation`` (K+1,): ``D = −∫ t s dx = −fᵀ(t∘s)`` (force/length: energy per unit rolled
  distance and unit axial length);
* ``friction_work`` (K+1,): the step's frictional work ``D_k Δq`` (``D_k Δ``, ``Δ = a_H``, for a step at
  rest, a stop of ``load.rolled``: its slip is per a_H of shift; 0 for the starting state; the
  accumulated work is its cumulative sum, :func:`balance`);
* ``elastic_energy`` (K+1,): ``U = ½ pᵀF A_nn p + pᵀF A_nt t + ½ tᵀF A_tt t``, the work of the
  contact tractions on the two bodies, relative to the reference distance ``d_ref`` of the 2D
  half-space (docs/formulation.md §3: ``U`` changes by ``c(P² + Q²)/2`` with ``d_ref``);
* ``load_work`` (K+1,): the step's work of the applied loads through the rigid motions,
  ``−Q̄ ξ Δq + P̄ Δδ`` (``Q̄``, ``P̄`` the means of the step's two tangential and normal loads; ``Δ`` for ``Δq`` at rest, the rigid
  shift being ``ξ Δ``; 0 for the starting state).

The identities (derived in docs/stresses.md §5): from the slip ``s = ξ + d ∂w/∂x`` of steady
rolling and ``w = A_tn p + A_tt t``, with ``∫ t ∂(A_tt t)/∂x dx = 0`` (the log kernel's derivative is
odd) and ``∂(A_tn p)/∂x = −(2β/E*) p``::

    D = −Q ξ + d (2β/E*) ∫ p t dx        (steady rolling; similar bodies: D = −Q ξ)

and in a transient, step by step, ``friction_work = load_work − ΔU`` up to O(Δq²) and the
discretization error (similar bodies; with β ≠ 0 the term ``d (2β/E*) ∫ p t dx Δq`` is added).
"""
from __future__ import annotations

import numpy as np

from .fields import FORCE, STRESS, Field, register
from .friction import largest
from .errors import InputError

__all__ = ["friction_power", "dissipation", "friction_work", "step_length", "elastic_energy", "load_work", "balance",
           "steady_identity", "power", "grid_dissipation", "grid_frictional_power", "grid_elastic_energy",
           "grid_balance"]


def friction_power(rows) -> np.ndarray:
    """``−t·s`` at the nodes of a block of states (:class:`rollqp.fields.Rows`): dissipation per unit area
    and unit rolled distance (≥ 0 up to the solver tolerance; the starting state of a braked start: per
    a_H of static shift)."""
    return -rows["pt"] * rows["slip"]


def dissipation(rows) -> np.ndarray:
    """``D = −fᵀ(t∘s)`` of each state of a block: frictional dissipation per unit rolled distance (and
    axial length); one dot product a state (the same sums as state by state, to the last bit)."""
    f, power = rows.constants["f"], rows["friction_power"]
    return np.array([float(f @ row) for row in power])


def friction_work(rows) -> np.ndarray:
    """The step's frictional work ``D Δq`` (``D Δ`` at rest; 0 for the starting state): ``Δq`` is the
    length the step's slip is per, kept for each state by the run (:func:`step_length`)."""
    dq = rows["_dq"]
    D = rows["dissipation"]
    return np.where(dq != 0.0, D * dq, 0.0)


def step_length(rec) -> float:
    """The length the step's slip is per: ``|Δq_k|`` of a rolling step (its own under ``load.rolled``),
    ``Δ = a_H`` of a static-shift step at rest (a stop of ``load.rolled``: the slip ``s = (w^k − w^{k−1})/Δ
    + ξ`` is per ``a_H`` of shift, §4.4, so ``s Δ`` is the slip displacement and ``ξ Δ`` the rigid shift);
    0 for the starting state (``k = 0``: the braked start's increments are not recorded one by one).
    :class:`~rollqp.result.Result` keeps it with each state (``_dq``) for the derived works."""
    if rec.k == 0 or rec.problem is None or rec.phase not in ("rolling", "static-shift"):
        return 0.0
    return float(rec.problem.dq)


def elastic_energy(rec, ops) -> float:
    """``U = ½ pᵀF A_nn p + pᵀF A_nt t + ½ tᵀF A_tt t`` (relative to ``d_ref``).

    From the displacements the step already has, not from new ``n × n`` products: ``A_nn p + A_nt t
    = g − h + δ`` (eq. 25, 30: the gap of the state) and, without ``A_tn``, ``A_tt t = w`` (eq. 28);
    with coupling the terms ``A_nt t`` and ``A_tt t`` are multiplied out.
    """
    st = rec.state
    p, t, f = st.p, st.t, ops.f
    if p is None or (not np.any(p) and not np.any(t)):
        return 0.0
    G, coupled = _normal_displacement(rec)
    if G is None:  # no gap of the state to read it from
        U = 0.5 * float((f * p) @ (ops.Ann @ p)) + 0.5 * float((f * t) @ (ops.Att @ t))
        if ops.Ant is not None:
            U += float((f * p) @ (ops.Ant @ t))
        return U
    U = 0.5 * float((f * p) @ G)  # ½ pᵀF A_nn p, or ½ pᵀF (A_nn p + A_nt t) (coupled)
    if ops.Ant is not None and np.any(t):
        U += (0.5 if coupled else 1.0) * float((f * p) @ (ops.Ant @ t))
    if np.any(t):
        At = st.w if ops.Atn is None else ops.Att @ t
        U += 0.5 * float((f * t) @ At)
    return U


def _normal_displacement(rec):
    """``(G, coupled)`` from the state's gap ``g``, approach ``δ`` and the undeformed gap of its problem:
    ``G = A_nn p = g − h − o + δ`` of a normal half (``coupled`` False; eq. 53, ``o`` its fixed offset),
    ``G = A_nn p + A_nt t = g − h + δ`` of a coupled step (eq. 25, 30); ``(None, False)`` where the
    record does not hold them."""
    st = rec.state
    nsol = st.nsol
    if nsol is None or nsol.g is None or nsol.delta is None or st.w is None:
        return None, False
    if st.normal is not None:
        return nsol.g - st.normal.h_total + nsol.delta, False
    if rec.problem is not None and rec.problem.kind == "coupled":
        return nsol.g - rec.problem.h + nsol.delta, True
    return None, False


def load_work(rows) -> np.ndarray:
    """``−½(Q_k + Q_{k−1}) ξ Δq + ½(P_k + P_{k−1})(δ_k − δ_{k−1})`` of each rolling step or step at rest of a
    block (``Δ`` for ``Δq``, :func:`step_length`; 0 for the starting state), ``P_{k−1} = fᵀp^{k−1}``.

    Both loads by the trapezoidal rule over the step: the elastic energy is a function of the state, and
    the work of a force that changes through the step is its mean times the displacement (with ``Q_k``
    alone a fretting cycle at rest, ``|ΔQ| = 0.0375 μ P̄`` a step, left 2e-4 N per step unbalanced, the
    size of the step's frictional work)."""
    f, dq = rows.constants["f"], rows["_dq"]
    Q, Q0, xi = rows["Q"], rows.before("Q"), rows["creepage"]
    P, pn0 = rows["P"], rows.before("pn")
    delta, delta0 = rows["approach"], rows.before("approach")
    out = np.zeros(rows.m)
    for i in np.flatnonzero(dq != 0.0).tolist():  # the starting state (dq = 0) has no predecessor
        W = -0.5 * (float(Q[i]) + float(Q0[i])) * float(xi[i]) * float(dq[i])
        out[i] = W + 0.5 * (float(P[i]) + float(f @ pn0[i])) * (float(delta[i]) - float(delta0[i]))
    return out


def _mu(scene) -> bool:
    """Friction somewhere (a Coulomb μ > 0 or a law of :mod:`rollqp.friction` that is not zero)."""
    return largest(scene.contact.friction) > 0


for _f in (
    Field("friction_power", "state", STRESS, "frictional dissipation density -t s >= 0 per unit rolled distance "
          "(times |V|: power per unit area); written when mu > 0", derive=friction_power, needed=_mu),
    Field("dissipation", "step", FORCE, "frictional dissipation D = -integral(t s dx) per unit rolled distance "
          "(and axial length); written when mu > 0", derive=dissipation, needed=_mu),
    Field("friction_work", "step", "force", "frictional work of the step per unit axial length, D dq (0 for the starting "
          "state); its cumulative sum is the accumulated work", derive=friction_work, needed=_mu, reduce="sum"),
    Field("elastic_energy", "step", "force", "elastic energy of the contact tractions per unit axial length, "
          "1/2 p.F.Ann.p + p.F.Ant.t + 1/2 t.F.Att.t (relative to d_ref)", compute=elastic_energy),
    Field("load_work", "step", "force", "work of the applied loads in the step, -mean(Q) xi dq + "
          "mean(P) d(delta) (0 for the starting state)", derive=load_work, reduce="sum"),
):
    register(_f)


def balance(res: dict) -> dict:
    """Accumulated frictional work, load work and elastic energy change of a result (arrays).

    Returns ``friction_work``, ``load_work`` (cumulative sums), ``delta_U`` (``U_k − U_0``) and
    ``residual = load_work − delta_U − friction_work`` (all shape (K+1,)).
    """
    Wf = np.cumsum(res["friction_work"]) if "friction_work" in res else np.zeros(len(res["q"]))
    Wl = np.cumsum(res["load_work"])
    dU = np.asarray(res["elastic_energy"]) - float(res["elastic_energy"][0])
    return dict(friction_work=Wf, load_work=Wl, delta_U=dU, residual=Wl - dU - Wf)


def steady_identity(res: dict, k: int, direction: int) -> float:
    """Right-hand side of the steady identity ``D = −Q ξ + d (2β/E*) ∫ p t dx`` at state ``k``
    (nodal quadrature with the strip's weights reconstructed from ``x``: pass ``f`` in ``res``)."""
    f = res["f"]
    return float(-res["Q"][k] * res["creepage"][k]
                 + direction * 2 * float(res["beta"]) / float(res["Estar"]) * f @ (res["pn"][k] * res["pt"][k]))


def power(res: dict, speed: float) -> np.ndarray:
    """Frictional power per unit axial length of each state at the rolling speed ``|V|`` (length/time):
    ``D·|V|`` (force·length/time per length); the density is ``friction_power·|V|``."""
    if not (isinstance(speed, (int, float, np.floating)) and np.isfinite(speed) and speed >= 0):
        raise InputError("speed", f"must be a finite number >= 0 (|V|, length/time), got {speed!r}")
    if "dissipation" not in res:
        raise InputError("result", "holds no 'dissipation' (a frictionless scene, or written before rollqp had it)")
    return np.asarray(res["dissipation"], dtype=float) * float(speed)


# =========================================================================== the grid (3D)
# The same quantities on Kalker's grid of rectangles (docs/stresses.md §10), CONTACT's definitions (its
# user guide, "ELEN" and "FRIC"): element tractions times element areas. Signs as in 2D: (px, py) on A,
# (sx, sy) the slip of A relative to B per unit rolled distance, so the dissipation density
# −(px sx + py sy) is >= 0; CONTACT prints FRIC = (V/1000) dx dy Σ p·s <= 0 (its units: W with N, mm, mm/s).
def grid_dissipation(rows) -> np.ndarray:
    """``−(p_x s_x + p_y s_y)`` on the grid of a block of states: the frictional power density per unit rolled
    distance (times ``|V|``: per unit time), ``(m, ny, nx)``."""
    return -(rows["px"] * rows["sx"] + rows["py"] * rows["sy"])


def grid_frictional_power(rows) -> np.ndarray:
    """``dx dy Σ −(p·s)``: the frictional power per unit rolled distance of each state (a force; times ``|V|``
    the power, CONTACT's −1000·FRIC)."""
    d = rows["dissipation"]
    return float(rows.constants["area"]) * d.reshape(d.shape[0], -1).sum(axis=1)


def grid_elastic_energy(rec, contact) -> float:
    """``U = ½ dx dy (pᵀ u_n + tᵀ u_t)``, ``u = A·(p, t)`` the displacement differences of the two bodies
    (docs/theory3d.md §3; CONTACT's ELEN times 1000): two products by the grid's operators."""
    return elastic_energy_of(contact.ops, rec.p, rec.t)


def elastic_energy_of(ops, p, t) -> float:
    """:func:`grid_elastic_energy` of tractions ``p`` (n,) and ``t`` (2, n) with the operators ``ops``
    (:class:`~rollqp.influence.grid.ContactOperators`)."""
    p = np.asarray(p, dtype=float).ravel()
    t = np.asarray(t, dtype=float).ravel()
    if not np.any(p) and not np.any(t):
        return 0.0
    un, ut = ops.Ann @ p, ops.Att @ t
    if ops.coupled:
        un, ut = un + ops.Ant @ t, ut + ops.Atn @ p
    return 0.5 * ops.grid.area * float(p @ un + t @ ut)


def grid_balance(res: dict) -> dict:
    """The energy balance of a 3D run (arrays of a result): accumulated frictional work ``Σ P_f Δq``, the work of
    the loads through the rigid motions ``Σ [−(F̄x ξ + F̄y η + M̄z φ) Δq + F̄N Δδ]`` (means of the step's two
    states, as in 2D), ``delta_U = U_k − U_0`` and ``residual = load_work − delta_U − friction_work``, each
    (K+1,). Rolling steps only: the starting state's static shift is not a rolled distance."""
    q = np.asarray(res["q"], dtype=float)
    dq = np.abs(np.diff(q, prepend=q[0]))
    c = np.asarray(res["creepage"], dtype=float)
    P = np.asarray(res["frictional_power"], dtype=float)
    mean = {k: 0.5 * (np.asarray(res[k], dtype=float) + np.roll(np.asarray(res[k], dtype=float), 1))
            for k in ("Fx", "Fy", "Mz", "FN")}
    dd = np.diff(np.asarray(res["approach"], dtype=float), prepend=float(res["approach"][0]))
    W = -(mean["Fx"] * c[:, 0] + mean["Fy"] * c[:, 1] + mean["Mz"] * c[:, 2]) * dq + mean["FN"] * dd
    W[0] = 0.0
    Wf = np.cumsum(np.where(np.arange(q.size) > 0, P * dq, 0.0))
    U = np.asarray(res["elastic_energy"], dtype=float)
    return dict(friction_work=Wf, load_work=np.cumsum(W), delta_U=U - U[0], residual=np.cumsum(W) - (U - U[0]) - Wf)


def _mu3(scene) -> bool:
    return float(getattr(scene, "mu", 0.0) or 0.0) > 0


for _f in (
    Field("dissipation", "state", STRESS, "frictional power density -(px sx + py sy) >= 0 per unit rolled distance "
          "(times |V|: power per unit area; CONTACT's fricdens)", derive=grid_dissipation, needed=_mu3),
    Field("frictional_power", "step", "force", "frictional power dx dy sum(-(p.s)) per unit rolled distance (times "
          "|V|: the power; CONTACT's FRIC.POWER = -|V| times this / 1000 in its units)", derive=grid_frictional_power,
          needed=_mu3),
    Field("elastic_energy", "step", "force*length", "elastic energy 1/2 dx dy (p.u_n + t.u_t) of the two bodies "
          "(CONTACT's ELAST.EN times 1000 in its units)", compute=grid_elastic_energy),
):
    register(_f, 3)
