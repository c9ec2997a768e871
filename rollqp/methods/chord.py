r"""Newton's method on the march map: the conic route to a steady state in a few steps
(docs/theory3d.md §6, docs/validation3d.md §9).

A method without a steady solve (the conic ones: the steady operator's skew part defeats the
splitting) reaches the steady state as the fixed point ``x = G(x)`` of one rolling step of
``Δq = dx``: ``G`` maps the previous tractions ``x`` to the step's tractions, each evaluation a
conic program. Marching (``x ← G(x)``, Anderson-accelerated) takes a contact length or more of
steps. Instead, Newton's method on ``F(x) = G(x) − x``: with ``z = (t̂, ξ̂, η̂)`` the step's unknowns,
``Φ(z; x) = 0`` its equations (eq. 3D.25, the rolling step: ``ŝ = ŝ₀ + Ŝ t̂ − Ŝ_sh x + E ζ``) and
``P`` the tractions of ``z``, a Newton step for ``z + dz = G(x + dx)``, ``P(z + dz) = x + dx`` is

.. math::
    J_{ss}\,dz = −J_x\,F(x),\qquad x_{new} = P(z + dz),\qquad
    J_x = ∂Φ/∂x = −r M Ŝ_{sh},\quad J_{ss} = ∂Φ/∂z + J_x P          \qquad (3D.24)

— ``J_ss`` is the steady problem's Jacobian (eq. 3D.28 with ``Ŝ − Ŝ_sh``), both at the partition
``M = ∂Proj`` of the conic answer ``z``. Only the path uses Newton's algebra: every iterate is
evaluated by the conic method (``z = G(x)``), and the answer is certified by it, ``|G(x) − x| ≤ tol``
— the same fixed point the march stops at. A Newton iterate that does not reduce ``|F|`` is
replaced by the march's own step ``x ← G(x)``, which cannot go wrong far from the solution.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla

__all__ = ["chord_step"]


def _derivative(z, b):
    """``(m_xx, m_xy, m_yy)`` of ``∂Proj`` onto the discs of radii ``b`` at ``z`` (eq. 3D.26)."""
    norm = np.hypot(z[0], z[1])
    slip = norm > b
    with np.errstate(divide="ignore", invalid="ignore"):
        kap = np.where(slip, b / norm, 1.0)
        ux, uy = np.where(slip, z[0] / norm, 0.0), np.where(slip, z[1] / norm, 0.0)
    return kap * (1 - ux * ux), -kap * ux * uy, kap * (1 - uy * uy)


def _rows(m, R):
    """``M R`` for the 2 × 2 blocks ``m`` of the elements and ``R`` of shape ``(2 nv, cols)``."""
    mxx, mxy, myy = m
    nv = mxx.size
    Rx, Ry = R[:nv], R[nv:]
    return np.vstack([mxx[:, None] * Rx + mxy[:, None] * Ry, mxy[:, None] * Rx + myy[:, None] * Ry])


def chord_step(problem, solution, shifted, x):
    """The Newton iterate ``x_new`` of eq. 3D.24 (tractions ``(2, n)``, scene units), or None if the
    system is singular.

    ``problem``: the rolling step ``G`` solved at ``x`` (:class:`~rollqp.problem.grid.TangentialStep`,
    ``B = A_tt``, ``Δq = dx``); ``solution`` its conic answer ``z = G(x)``; ``shifted``: the operator
    ``A_tt(· − d dx)`` of its history vector; ``x``: the previous tractions ``(2, n)``.
    """
    sc = problem.scales
    V = np.flatnonzero(problem.bound > 0)
    nv = V.size
    if nv == 0:
        return None
    k = sc.modulus / problem.dq
    S = k * problem.B.memo(("dense", V.tobytes()), lambda: problem.B.dense(V, V))
    Ssh = k * shifted.memo(("dense", V.tobytes()), lambda: shifted.dense(V, V))
    r = 1.0 / float(np.mean(np.diag(S)))
    free = [j for j, F in enumerate((problem.Fx, problem.Fy)) if F is not None]
    E = np.zeros((2 * nv, len(free)))
    for i, j in enumerate(free):
        E[j * nv:(j + 1) * nv, i] = 1.0
    ah = problem.area / sc.length ** 2
    t, s = solution.t[:, V] / sc.stress, solution.s[:, V] / sc.slip
    m = _derivative(t - r * s, problem.bound[V] / sc.stress)
    Jz = _rows(m, r * np.hstack([S, E]))
    Jz[:, :2 * nv] += np.eye(2 * nv) - _rows(m, np.eye(2 * nv))
    Jx = -_rows(m, r * Ssh)
    Jss = Jz.copy()
    Jss[:, :2 * nv] += Jx
    loads = np.zeros((len(free), 2 * nv + len(free)))
    for i, j in enumerate(free):
        loads[i, j * nv:(j + 1) * nv] = ah
    F = (t - x[:, V] / sc.stress).ravel()
    rhs = np.concatenate([-(Jx @ F), np.zeros(len(free))])
    try:
        dz = sla.solve(np.vstack([Jss, loads]), rhs, check_finite=False)
    except (np.linalg.LinAlgError, ValueError):
        return None
    if not np.all(np.isfinite(dz)):
        return None
    out = np.zeros_like(solution.t)
    out[:, V] = (t.ravel() + dz[:2 * nv]).reshape(2, nv) * sc.stress
    return out
