r"""Φ and its pseudo-Jacobian node by node: the complementarity rows of paper eq. 74–90.

In the nondimensional unknowns of :mod:`rollqp.methods.newton` (``x`` the traction, ``y`` its
augmented partner, linear in the unknowns: ``y = r ĝ`` or ``r ŝ``):

* **normal** (eq. 51–53): ``Φ_i = min(p̂_i, r ĝ_i)``; the row is ``∂(r ĝ_i)`` where
  ``p̂_i > r ĝ_i`` (eq. 84, contact), ``∂p̂_i`` where ``p̂_i <= r ĝ_i`` (eq. 82 separated,
  eq. 83 the kink, the paper's "modified" choice);
* **tangential** (eq. 54–60): ``Φ_i = t̂_i − Proj_[−b_i, b_i](t̂_i − r ŝ_i)``, ``b = μ p̂⁺``; the row is
  ``∂(r ŝ_i)`` where ``|t̂_i − r ŝ_i| <= b_i`` (eq. 86 stick, eq. 87 its kink), ``∂t̂_i`` where
  ``|t̂_i − r ŝ_i| > b_i`` (eq. 88 slip, with ``b`` fixed) or ``b_i = 0`` (eq. 85);
* **coupled** (eq. 63): the bound is ``b = μ max(0, p̂ − y_N)``, defined at every iterate, so a
  slipping node's row also depends on ``p̂`` and ``ĝ``: ``e_t − σμ(e_p − ∂y_N)``, ``σ = sgn(t̂ − y_T)``
  (eq. 88); eq. 89/90 are the bound exactly zero.

Each function carries its equation numbers: a reader goes from the paper to the line here.
"""
from __future__ import annotations

import numpy as np

from ...errors import SolverError
from ...problem import friction_residual

__all__ = ["NormalNCP", "TangentialNCP", "coupled_cases", "coupled_phi", "slip_rows", "coupled_jacobian",
           "coupled_labels"]


class NormalNCP:
    """The normal rows ``min(p̂, r ĝ)`` (eq. 51–53, cases eq. 82–84)."""

    kind = "normal"
    #: Rows whose ``y`` enters ``Φ``: all (``None``).
    needs = None

    def phi(self, x, y, out=None):
        """``Φ_i = min(p̂_i, r ĝ_i)`` (eq. 52) (into ``out`` if given)."""
        return np.minimum(x, y, out=out)

    def mask(self, x, y, out=None):
        """Nodes with the ``∂(r ĝ_i)`` row: ``p̂_i > r ĝ_i`` (eq. 84); the others ``∂p̂_i`` (eq. 82/83)."""
        return np.greater(x, y, out=out)

    def nearest(self, x, y):
        """All ``p̂ <= r ĝ``: the node with the smallest ``r ĝ − p̂`` reaches contact when ``r ĝ`` drops by it."""
        j = int(np.argmin(y - x))
        return j, -(y[j] - x[j])

    def labels(self, x, y):
        """``"eq82"`` (separated), ``"eq83"`` (on the kink), ``"eq84"`` (contact) per node."""
        return np.where(x < y, "eq82", np.where(x == y, "eq83", "eq84"))


class TangentialNCP:
    """The friction rows ``t̂ − Proj_[−b, b](t̂ − r ŝ)`` with the bound ``b = μ p̄⁺`` fixed (eq. 54–60, 85–88)."""

    kind = "tangential"

    def __init__(self, b, minus_b=None):
        self.b = b
        self._minus_b = -b if minus_b is None else minus_b
        self.sep = b <= 0.0
        #: Rows whose ``y`` enters ``Φ``: a zero bound gives ``Φ_i = t̂_i`` whatever ``r ŝ_i`` (eq. 85).
        self.needs = ~self.sep
        self._b_stick = np.where(self.needs, b, -1.0)  # |u| <= this: stick where the bound is positive, never elsewhere

    def phi(self, x, y, out=None):
        """``Φ_i = t̂_i − Proj_[−b_i, b_i](t̂_i − r ŝ_i)`` (eq. 60): :func:`~rollqp.problem.friction_residual`
        with ``−b`` formed once per step (Newton evaluates ``Φ`` a few times an iteration; into ``out`` if given)."""
        return friction_residual(x, y, self.b, self._minus_b, out)

    def mask(self, x, y, out=None):
        """Nodes with the ``∂(r ŝ_i)`` row: ``|t̂_i − r ŝ_i| <= b_i`` (eq. 86/87, stick); the others
        ``∂t̂_i``: slip (eq. 88, ``b`` fixed) or a zero bound (eq. 85, separation) (into ``out`` if given)."""
        return np.less_equal(np.abs(x - y), self._b_stick, out=out)

    def nearest(self, x, y):
        """All ``|t̂ − r ŝ| > b``: the node with the smallest excess sticks when ``r ŝ`` moves by it."""
        u = x - y
        excess = np.abs(u) - self.b
        excess[self.sep] = np.inf
        j = int(np.argmin(excess))
        if not np.isfinite(excess[j]):
            raise SolverError("no node can stick: the friction bound is zero everywhere", status="degenerate")
        return j, float(np.sign(u[j]) * excess[j])

    def labels(self, x, y):
        """``"eq85"`` (zero bound), ``"eq86"`` (stick), ``"eq87"`` (its kink), ``"eq88"`` (slip) per node."""
        u = np.abs(x - y)
        b = self.b
        return np.where(self.sep, "eq85", np.where(u < b, "eq86", np.where(u == b, "eq87", "eq88")))


# ------------------------------------------------------------------------------ the coupled step
def coupled_cases(p, t, yN, yT, mu):
    """Node cases of the coupled ``Φ`` (eq. 82–90).

    Returns ``contact`` (eq. 84: row ``∂y_N``), ``stick`` (eq. 86/87: row ``∂y_T``),
    ``slip_sign`` (eq. 88: ``σ = sgn(t̂ − y_T)``, row ``e_t − σμ(e_p − ∂y_N)``; 0 elsewhere)
    and ``zero_bound`` (eq. 85/89/90: ``b = 0``, row ``e_t``).
    """
    contact = p > yN
    b = mu * np.maximum(0.0, p - yN)
    u = t - yT
    zero_bound = b <= 0.0
    stick = (np.abs(u) <= b) & ~zero_bound
    slip_sign = np.where(stick | zero_bound, 0.0, np.sign(u))
    return contact, stick, slip_sign, zero_bound


def coupled_phi(S, p, t, yN, yT, mu, Phat, Qhat):
    """``Φ`` of the coupled step (eq. 63–64, 70–71): ``min(p̂, y_N)``, the friction rows with the
    bound ``μ max(0, p̂ − y_N)`` (eq. 63), and the load rows (eq. 67)."""
    n = p.size
    b = mu * np.maximum(0.0, p - yN)
    out = np.empty(S.N)
    out[:n] = np.minimum(p, yN)
    out[n:2 * n] = friction_residual(t, yT, b)
    if S.iP is not None:
        out[S.iP] = S.fhat @ p - Phat
    if S.iQ is not None:
        out[S.iQ] = S.fhat @ t - Qhat
    return out


def slip_rows(KN, i, sm):
    """Rows ``e_{t,i} − σμ (e_{p,i} − K_N[i])`` of the coupled pseudo-Jacobian at slipping nodes
    ``i`` (eq. 88), with ``sm = σμ`` per node (``n`` = the number of nodes, ``KN.shape[0]``)."""
    n = KN.shape[0]
    rows = sm[:, None] * KN[i]
    rows[np.arange(i.size), i] -= sm
    rows[np.arange(i.size), n + i] += 1.0
    return rows


def coupled_jacobian(S, contact, stick, slip_sign, mu):
    """The pseudo-Jacobian ``BΦ`` (eq. 80–90), Fortran-ordered for LAPACK."""
    n = contact.size
    J = np.array(S.J0, order="F")  # identity rows and load rows
    ic = np.flatnonzero(contact)
    J[ic] = S.KN[ic]
    ist = np.flatnonzero(stick)
    J[n + ist] = S.KT[ist]
    isl = np.flatnonzero(slip_sign)
    if isl.size:
        J[n + isl] = slip_rows(S.KN, isl, slip_sign[isl] * mu)
    return J


def coupled_labels(p, t, yN, yT, mu):
    """Per-node labels ``(normal, tangential)``: ``"eq82"``–``"eq84"`` and ``"eq85"``–``"eq90"``."""
    b = mu * np.maximum(0.0, p - yN)
    zero_bound = b <= 0.0
    u = np.abs(t - yT)
    ncase = np.where(p < yN, "eq82", np.where(p == yN, "eq83", "eq84"))
    exact_zero = (p - yN) == 0.0  # eq. 85 is p̂ − y_N < 0 (the bound's argument negative)
    tcase = np.where(zero_bound & ~exact_zero, "eq85", "")
    tcase = np.where(zero_bound & exact_zero & (u > 0), "eq89", tcase)
    tcase = np.where(zero_bound & exact_zero & (u == 0), "eq90", tcase)
    tcase = np.where(~zero_bound, np.where(u < b, "eq86", np.where(u == b, "eq87", "eq88")), tcase)
    return ncase, tcase
