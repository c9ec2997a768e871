r"""The convex programs of a 3D step in rollqp's scaled variables (docs/theory3d.md §5–6).

**Normal step: a QP** (eq. 3D.22). With ``F = â I`` (every element has the same area) and
``Â = A_nn E*/c`` symmetric (Betti on the uniform grid), the Signorini conditions of eq. 3D.14 are
the KKT conditions of

.. math::
    \min_{\hat p \ge 0}\ \tfrac12 \hat p^T(\hat a\hat A)\hat p + \hat a\,\hat h^T\hat p
    \quad\text{s.t.}\quad \hat a\textstyle\sum\hat p = \hat F_N,            \qquad (3D.22)

the approach being the load row's multiplier: ``δ̂ = −(obj/eq)·y``.

**Tangential step: an SOCP** (eq. 3D.20). The friction conditions of eq. 3D.15 — ``|t_i| ≤ b_i``,
``s_i = 0`` inside the disc, ``s_i = −λ t_i`` on its rim — are the KKT conditions of

.. math::
    \min_{\hat t}\ \tfrac12\hat t^T\,\mathrm{sym}(\hat a\hat S)\,\hat t + \hat a\,\hat s_0^T\hat t
    \quad\text{s.t.}\quad (\hat b_i, \hat t_{x,i}, \hat t_{y,i}) \in \mathcal{Q}^3,\quad
    \hat a\textstyle\sum\hat t_x = \hat F_x,\ \hat a\sum\hat t_y = \hat F_y,          \qquad (3D.20)

one second-order cone ``Q³ = {(u, v): |v| ≤ u}`` per element in contact, provided ``â Ŝ`` is
symmetric (shift and transient steps: ``Ŝ = E* A_tt/Δq``); the load rows' multipliers are the
creepages, ``ξ̂ = (obj/eq)·y_x`` (eq. 3D.21). A non-symmetric ``Ŝ`` (the steady operator) is
split, ``âŜ = H + K`` with ``K`` skew, and the skew part moved to the linear term at the previous
iterate (docs/theory3d.md §6; docs/formulation.md §8).

Both forms are normalized like the 2D :class:`~rollqp.problem.QPForm`: ``H``, ``q`` divided by
``obj`` (the largest diagonal entry of ``H``), the load rows by ``eq`` (their largest entry), so
that solver tolerances act on numbers of order one. Only the elements that can carry traction
are variables (``b_i > 0``; for the normal QP, every element).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["ConicForm", "normal_form", "tangential_form", "asymmetry"]


@dataclass(frozen=True)
class ConicForm:
    """``min ½xᵀHx + qᵀx`` s.t. ``a x = b`` (rows of ``a``) and ``x ∈ K`` (eq. 3D.22/3D.20).

    ``kind`` ``"normal"`` (``K``: ``x ≥ 0``) or ``"tangential"`` (``K``: a cone ``(bound_i, x_i,
    x_{nv+i})`` per element, ``x = [t̂_x(V), t̂_y(V)]``). ``elements`` are the grid elements of the
    variables; ``skew`` the skew part of ``â Ŝ``/obj (zero for a symmetric operator).
    """

    kind: str
    H: np.ndarray
    q: np.ndarray
    a: np.ndarray          # (k, m) load rows (k = 0: none)
    b: np.ndarray          # (k,)
    bound: np.ndarray | None
    elements: np.ndarray
    obj_scale: float
    eq_scale: float
    rows: tuple            # which load rows are present: ("FN",) or a subset of ("Fx", "Fy")
    skew: np.ndarray | None = None

    @property
    def m(self) -> int:
        return self.q.size

    def multipliers_to_unknowns(self, y) -> np.ndarray:
        """The load rows' multipliers as the unscaled unknowns: ``−δ̂`` (normal) or ``(ξ̂, η̂)``."""
        return np.asarray(y, dtype=float) * self.obj_scale / self.eq_scale


def asymmetry(M: np.ndarray) -> float:
    """``‖M − Mᵀ‖_F / ‖M‖_F``."""
    nrm = np.linalg.norm(M)
    return float(np.linalg.norm(M - M.T) / nrm) if nrm > 0 else 0.0


def _split(FA):
    """``(H/obj, K/obj, obj)``: the symmetric and skew parts of ``FA``, normalized, read-only (kept
    in the operator's memo: every step on the same elements reuses them and the solver object)."""
    H = 0.5 * (FA + FA.T)
    obj = float(np.max(np.abs(np.diag(H))))
    K = 0.5 * (FA - FA.T) / obj
    H = H / obj
    H.flags.writeable = K.flags.writeable = False
    return H, K, obj


def normal_form(problem, elements=None) -> ConicForm:
    """The QP of eq. 3D.22 for a :class:`~rollqp.problem.grid.NormalStep` (dense ``Â``), over
    ``elements`` (default: every element of the grid; the others are held at ``p = 0``)."""
    sc = problem.scales
    V = np.arange(problem.n) if elements is None else np.asarray(elements)
    ah = problem.area / sc.length ** 2
    f = ah * sc.modulus / sc.length
    if elements is None:
        H, skew, obj = problem.A.memo(("qp", f), lambda: _split(f * problem.A.dense()))
    else:
        H, skew, obj = problem.A.memo(("qp", V.tobytes(), f), lambda: _split(f * problem.A.dense(V, V)))
    q = ah * problem.h_total[V] / sc.displacement
    rows, a, b = (), np.zeros((0, V.size)), np.zeros(0)
    if problem.delta is not None:
        q = q - ah * problem.delta / sc.displacement
    else:
        rows, a, b = ("FN",), np.full((1, V.size), ah), np.array([problem.FN / sc.force])
    eq = float(np.max(a)) if a.size else 1.0
    return ConicForm("normal", H, q / obj, a / eq, b / eq, None, V, obj, eq, rows,
                     skew if np.any(skew != 0) else None)


def tangential_form(problem, elements=None) -> ConicForm:
    """The SOCP of eq. 3D.20 for a :class:`~rollqp.problem.grid.TangentialStep` (dense ``Ŝ``)
    on ``elements`` (default: those with a positive bound)."""
    sc = problem.scales
    V = np.flatnonzero(problem.bound > 0) if elements is None else np.asarray(elements)
    nv = V.size
    ah = problem.area / sc.length ** 2
    f = ah * sc.modulus / problem.dq
    H, skew, obj = problem.B.memo(("socp", V.tobytes(), f), lambda: _split(f * problem.B.dense(V, V)))
    xi0 = problem.xi if problem.xi is not None else 0.0
    eta0 = problem.eta if problem.eta is not None else 0.0
    w = np.stack([xi0 - problem.phi * problem.y, eta0 + problem.phi * problem.x])
    s0 = ((w + problem.c / problem.dq) / sc.slip)[:, V].ravel()
    rows, a_rows, b = [], [], []
    for j, (name, F) in enumerate((("Fx", problem.Fx), ("Fy", problem.Fy))):
        if F is not None:
            row = np.zeros(2 * nv)
            row[j * nv:(j + 1) * nv] = ah
            rows.append(name)
            a_rows.append(row)
            b.append(F / sc.force)
    a = np.array(a_rows).reshape(len(rows), 2 * nv)
    eq = float(np.max(a)) if a.size else 1.0
    return ConicForm("tangential", H, ah * s0 / obj, a / eq, np.array(b) / eq, problem.bound[V] / sc.stress,
                     V, obj, eq, tuple(rows), skew if np.any(skew != 0) else None)
