r"""Generalized Newton method with line search (GNMls; Pang 1990; paper §4, eq. 74–90).

Solves the *uncoupled* normal and tangential step problems (:class:`~rollqp.problem.NormalStep`,
:class:`~rollqp.problem.TangentialStep`) as the nonsmooth equations of docs/formulation.md §4,
with the problem's own collocation operator ``A`` (no symmetrization), so that its solution is
the one the QP backends reach by symmetric–skew splitting (``operator="exact"``).

Nondimensional unknowns (:class:`~rollqp.problem.Scales`: ``p0``, ``a_H``, ``E*``;
``u0 = a_H p0/E*``) with the linear rows eliminated — the "halved system" of docs/formulation.md §10:

.. math::
    \hat g = \hat h - \hat\delta\, e + \hat A \hat p, \qquad
    \hat s = \hat\xi\, e + (\hat c + \hat A \hat t)/\Delta\hat q,

    \Phi_N(\hat p, \hat\delta) = \begin{bmatrix} \min(\hat p,\; r \hat g) \\
        \hat f^T \hat p - \hat P \end{bmatrix}, \qquad
    \Phi_T(\hat t, \hat\xi) = \begin{bmatrix} \hat t - \mathrm{Proj}_{[-b, b]}(\hat t - r \hat s) \\
        \hat f^T \hat t - \hat Q \end{bmatrix},\quad b = \mu \hat p^+ ,

with ``Â = A E*/a_H``, ``f̂ = f/a_H``, ``ĥ = (h + o)/u0``, ``ĉ = c/u0``, ``Δq̂ = Δq/a_H``. With
``δ`` (``ξ``) prescribed the load row and ``δ̂`` (``ξ̂``) are dropped.

Newton direction (eq. 74, 80): ``J d = −Φ`` with ``J`` the Jacobian of the linear part plus the
pseudo-Jacobian of the ``min``/``Proj`` rows chosen node by node (eq. 82–90, the paper's
"modified" linear choice on the kinks). ``J`` is never formed: the identity rows (separated
and slipping nodes) are eliminated and the rest is solved on the free nodes
(:meth:`_System.direction`, LAPACK ``getrf``/``getrs``), reusing the last factorization
through a small Schur complement while the active set moves by a few nodes; the coupled step
reuses its LU likewise, by a Woodbury update of the rows whose node case changed
(:class:`_CoupledFactors`). Step length (eq. 75–79): ``α = ρ^m`` (``s = 1``), the first
``m`` with ``θ(z + αd) <= (1 − 2σα) θ(z)``, ``θ = ½‖Φ‖²``. Along the search line only the
``min``/``Proj`` are re-evaluated: the linear parts ``r ĝ``, ``r ŝ`` move by ``α K d`` with
``K d`` computed once per iteration.

**The augmentation r.** The paper's ``r = 0.1 N/mm`` is dimensional. Here ``r`` is
nondimensional and chosen so that the two arguments of ``min``/``Proj`` respond alike to a
change of the traction at the node itself: ``∂p̂_i/∂p̂_i = 1`` against ``r ∂ĝ_i/∂p̂_i = r Â_ii``
(normal) and ``∂t̂_i/∂t̂_i = 1`` against ``r ∂ŝ_i/∂t̂_i = r Â_ii/Δq̂`` (tangential), on average::

    r_N = 1 / mean(diag Â),        r_T = Δq̂ / mean(diag Â)

(``r_N ≈ 5.3``, ``r_T ≈ 0.17`` on 40 quadratic elements with ``Δq = Le/2``). Any ``r > 0`` has
the same solutions (``min(p, r g) = 0`` and the friction projection are independent of
``r``); only the path of the iteration changes. Pass ``r=`` to override.

**Stopping.** ``‖Φ‖_∞ <= tolerance·min(1, r)``: rollqp's residuals (:class:`Residuals`) are the
same functions with ``r = 1``, and ``|min(a, b)| <= |min(a, r b)|/min(1, r)`` (likewise for the
projection residual), so the returned solution's ``residual`` is ``<= tolerance``. ``Φ`` is
piecewise linear: once the active sets are right the next full step is exact, and the
iteration ends at round-off (quadratic, indeed finite, termination).

Deviations from the paper, both on degenerate iterates only:

* if no node is in contact (normal) or in stick (tangential) while the load row is present,
  the ``δ̂`` (``ξ̂``) column of ``J`` vanishes. ``δ̂`` (``ξ̂``) is then shifted until the node
  nearest to switching lies on its kink — the shift moves every ``y_i`` alike, so no other node
  changes case and ``Φ`` (and ``θ``) does not change — and that node gets the contact/stick row,
  the one-sided derivative into contact/stick (counted in ``info["shifts"]``);
* if the Armijo search fails (``α < 1e-10``; possible only on a kink, where the modified row is
  not the directional derivative), the full step is taken (counted in ``info["nonmonotone"]``);
* if a tangential step with ``Q`` prescribed still fails (one stick node: the repair above can
  cycle, e.g. free rolling at μ ≲ 3e-4), it is solved with ``ξ`` prescribed and ``ξ`` is searched
  for ``fᵀt = Q`` (``_tangential_by_creepage``; counted in ``info["creepage_search"]``).

Robustness (docs/stability.md): the nondimensional ``r`` may be set (``[solver] augmentation``,
the same for both rows) within [1e-6, 10], where every hard case converges; failures are
:class:`~rollqp.errors.SolverError` with the merit, iterations and ``‖Φ‖∞``.

References: J.-S. Pang, Newton's method for B-differentiable equations, Math. Oper. Res. 15
(1990) 311–341; González & Abascal, IJNME 53 (2002) 843–874, §4.
"""
from __future__ import annotations

import time

import numpy as np
from scipy.linalg.lapack import dgesv, dgetrf, dgetrs

from ..errors import InputError, SolverError
from ..problem import StepSolution
from .base import check_options

#: Smallest Armijo step tried before the full step is taken anyway (see module docstring).
ALPHA_MIN = 1e-10


class _Stalled(Exception):
    """The Armijo search failed from a warm start (``solve`` then restarts cold)."""


class _System:
    """Cached, r-scaled matrices of one problem operator (per ``A``, ``f``, scales, ``Δq``, ``r``).

    ``K`` (``n × (n+1)``) maps ``z = (x, δ̂|ξ̂)`` to the linear part of ``y = r ĝ`` or ``r ŝ``;
    ``K_nl`` is its first ``n`` columns (``δ``/``ξ`` prescribed, no load row). The
    pseudo-Jacobian has a ``K`` row at the contact/stick nodes (``mask``), an identity row at
    the separated/slipping nodes, and the load row ``[f̂ᵀ, 0]`` last; :meth:`direction` solves
    with it on the free nodes only (the reduced system) and keeps the LU factors of the last
    few active sets.
    """

    __slots__ = ("A", "f", "Ahat", "fhat", "r", "K", "K_nl", "_base", "factorizations", "updates")

    #: Largest change of the active set, against the factored one, solved by a Schur complement
    #: (as a fraction of the factored size; at least :attr:`UPDATE_MIN` nodes); beyond, refactor.
    UPDATE_FRACTION = 0.125
    UPDATE_MIN = 4
    #: Below this many free nodes a new factorization is cheaper than the bordered solve.
    UPDATE_MIN_SIZE = 64

    def __init__(self, A, f, Ahat, fhat, r, last_column, t_scale):
        n = fhat.size
        self.A, self.f, self.Ahat, self.fhat, self.r = A, f, Ahat, fhat, r
        K = np.empty((n, n + 1))
        K[:, :n] = (r / t_scale) * Ahat
        K[:, n] = r * last_column
        self.K = K
        self.K_nl = np.ascontiguousarray(K[:, :n])
        self._base = {}  # with_load -> (mask, free, position of each node in free or -1, lu, piv)
        self.factorizations = 0  # LU factorizations of a reduced matrix (diagnostics)
        self.updates = 0  # directions solved by a Schur complement on an older factorization

    def matrices(self, with_load):
        """``K`` with or without the load column."""
        return self.K if with_load else self.K_nl

    def jacobian(self, mask, with_load):
        """The full pseudo-Jacobian ``J`` (for tests and diagnostics; the iteration never forms it)."""
        n = self.fhat.size
        K = self.matrices(with_load)
        N = K.shape[1]
        J = np.zeros((N, N))
        J[:n] = np.where(mask[:n, None], K, np.eye(n, N))
        if with_load:
            J[n, :n] = self.fhat
        return J

    def _factor(self, m, with_load):
        """LU of the reduced matrix on the free set ``m`` (below); ``None`` if singular."""
        n = self.fhat.size
        K = self.K
        free = np.flatnonzero(m)
        nf = free.size
        M = np.empty((nf + with_load, nf + with_load), order="F")
        M[:nf, :nf] = K[np.ix_(free, free)]
        if with_load:
            M[:nf, nf] = K[free, n]
            M[nf, :nf] = self.fhat[free]
            M[nf, nf] = 0.0
        if M.size:
            lu, piv, info = dgetrf(M, overwrite_a=True)
            if info != 0 or not np.all(np.isfinite(np.diag(lu))):
                return None
        else:
            lu, piv = M, np.empty(0, dtype=np.int32)
        pos = np.full(n, -1)
        pos[free] = np.arange(nf)
        self.factorizations += 1
        return m.copy(), free, pos, lu, piv, {}

    def direction(self, mask, phi, with_load):
        r"""The Newton direction ``d``: ``J d = −Φ`` solved on the free nodes (eq. 80).

        A node without a ``K`` row (``mask`` false: separated, slipping) has the identity row,
        so ``d_i = −Φ_i`` there. Eliminating those nodes leaves, on the free set ``F``,

        .. math::
            \begin{bmatrix} K_{FF} & k_F \\ \hat f_F^T & 0 \end{bmatrix}
            \begin{bmatrix} d_F \\ d_\lambda \end{bmatrix} =
            -\begin{bmatrix} \Phi_F + K_{F,P} d_P \\ \Phi_\lambda + \hat f_P^T d_P \end{bmatrix}

        (``k_F`` the ``δ̂``/``ξ̂`` column; without the load row and column if prescribed), whose
        determinant is that of ``J``. Its LU factors are kept. When the free set ``F`` differs
        from the factored one ``F₀`` by a few nodes (``R = F₀∖F`` released, ``A = F∖F₀`` added:
        the stick/slip boundary moving by a node or two between iterations and steps), the
        system is solved on the old factors, bordered:

        .. math::
            \begin{bmatrix} M_0 & B & E_R \\ C & D & 0 \\ E_R^T & 0 & 0 \end{bmatrix}
            \begin{bmatrix} u \\ v \\ w \end{bmatrix} =
            \begin{bmatrix} r_0 \\ r_A \\ -\Phi_R \end{bmatrix},

        (``B``, ``C``, ``D`` the rows and columns of ``K`` for ``A``; ``E_R`` unit columns: the
        slack ``w`` frees the old rows of ``R`` and the last block pins ``d_R``), through its
        Schur complement of size ``|A| + |R|`` (two triangular solves per bordering column, no
        new factorization). A larger change refactors. Returns ``None`` if singular.
        """
        n = self.fhat.size
        K = self.K if with_load else self.K_nl
        m = mask[:n]
        base = self._base.get(with_load)
        if base is not None:
            m0, free0, pos0, lu, piv, cols = base
            released = np.flatnonzero(m0 & ~m)
            added = np.flatnonzero(m & ~m0)
            k = released.size + added.size
            if k and (k > max(self.UPDATE_MIN, self.UPDATE_FRACTION * free0.size)
                      or free0.size < self.UPDATE_MIN_SIZE):
                base = None
        if base is None:
            base = self._factor(m, with_load)
            if base is None:
                return None
            self._base[with_load] = base
            m0, free0, pos0, lu, piv, cols = base
            released = added = np.empty(0, dtype=int)
            k = 0
        d = np.empty(K.shape[1])
        pinned = np.flatnonzero(~m)
        d[pinned] = -phi[pinned]
        known = np.flatnonzero(~m & ~m0)  # pinned now and not in the factored set
        if known.size:
            e = np.zeros(K.shape[1])
            e[known] = d[known]
            Ke = K @ e
        else:
            Ke = np.zeros(n)
        nf0 = free0.size
        r0 = np.empty(nf0 + with_load)
        r0[:nf0] = -phi[free0] - Ke[free0]
        if with_load:
            r0[nf0] = -phi[n] - self.fhat[known] @ d[known]
        if r0.size == 0 and k == 0:
            return d
        u0, info = dgetrs(lu, piv, r0)
        if info != 0:
            return None
        if k == 0:
            d[free0] = u0[:nf0]
            if with_load:
                d[n] = u0[nf0]
            return d
        # bordered solve on the old factors: Z = M0⁻¹ [B, E_R], S = [[D, 0], [0, 0]] − [C; E_Rᵀ] Z.
        # The columns of Z are kept per node (``cols``): as the set drifts away from the factored
        # one, each step adds a node or two, and only their columns cost triangular solves.
        na = added.size
        keys = added.tolist() + [-1 - i for i in released.tolist()]
        missing = [c for c in keys if c not in cols]
        if missing:
            order = [c for c in missing if c >= 0] + [c for c in missing if c < 0]  # W's columns
            W = np.zeros((nf0 + with_load, len(missing)), order="F")
            ma = np.array([c for c in order if c >= 0], dtype=int)
            mr = np.array([-1 - c for c in order if c < 0], dtype=int)
            W[:nf0, :ma.size] = K[np.ix_(free0, ma)]
            if with_load:
                W[nf0, :ma.size] = self.fhat[ma]
            W[pos0[mr], ma.size + np.arange(mr.size)] = 1.0
            Zm, info = dgetrs(lu, piv, W)
            if info != 0:
                return None
            for j, c in enumerate(order):
                cols[c] = Zm[:, j]
        Z = np.column_stack([cols[c] for c in keys])
        S = np.empty((k, k))
        Ca = K[np.ix_(added, free0)]
        S[:na] = -(Ca @ Z[:nf0])
        if with_load:
            S[:na] -= np.outer(K[added, n], Z[nf0])
        S[na:] = -Z[pos0[released]]
        S[:na, :na] += K[np.ix_(added, added)]
        Cu0 = np.empty(k)
        Cu0[:na] = Ca @ u0[:nf0] + (K[added, n] * u0[nf0] if with_load else 0.0)
        Cu0[na:] = u0[pos0[released]]
        rhs = np.concatenate([-phi[added] - Ke[added], d[released]]) - Cu0
        try:
            vw = np.linalg.solve(S, rhs)
        except np.linalg.LinAlgError:
            return None
        u = u0 - Z @ vw
        d[free0] = u[:nf0]
        d[released] = -phi[released]  # what the last block pins them to, without round-off
        d[added] = vw[:na]
        if with_load:
            d[n] = u[nf0]
        self.updates += 1
        return d


def _slip_rows(KN, i, sm):
    """Rows ``e_{t,i} − σμ (e_{p,i} − K_N[i])`` of the coupled pseudo-Jacobian at slipping nodes
    ``i`` (eq. 88), with ``sm = σμ`` per node (``n`` = the number of nodes, ``KN.shape[0]``)."""
    n = KN.shape[0]
    rows = sm[:, None] * KN[i]
    rows[np.arange(i.size), i] -= sm
    rows[np.arange(i.size), n + i] += 1.0
    return rows


class _CoupledFactors:
    r"""LU factors of one coupled pseudo-Jacobian ``J_f``, reused for nearby ones (Woodbury).

    The rows of the coupled ``J`` (:meth:`NewtonMethod._coupled_jacobian`) take one of a few
    kinds per node: the ``p̂_i`` row is ``K_N`` (contact) or ``e_i`` (separated); the ``t̂_i``
    row is ``K_T`` (stick), ``e_{n+i} − σμ(e_i − K_N)`` (slip, ``σ = ±1``) or ``e_{n+i}`` (zero
    bound); the load rows never change. ``J_f`` is factored on its free rows only (the reduced
    system of :meth:`NewtonMethod._coupled_direction`, identity rows eliminated), which is a
    factorization of the whole ``J_f``:

    .. math::
        J_f^{-1} b:\quad x_P = b_P, \qquad M x_F = b_F - R_{F,P}\, b_P .

    A later ``J`` differs from ``J_f`` in the rows ``C`` of the nodes whose case changed,
    ``J = J_f + E_C\,\Delta R`` (``E_C`` unit columns), and is solved on the old factors by the
    Sherman–Morrison–Woodbury formula

    .. math::
        J^{-1} b = y - Z\,(I + \Delta R\, Z)^{-1} \Delta R\, y, \qquad y = J_f^{-1} b,\;
        Z = J_f^{-1} E_C ,

    whose columns ``J_f⁻¹ e_c`` are kept per row ``c`` until the next factorization (a drifting
    case pattern costs triangular solves only for rows new to it). ``J`` is refactored when
    ``|C|`` exceeds :attr:`UPDATE_FRACTION` of the factored size (at least :attr:`UPDATE_MIN`
    rows), when the factored system is small (:attr:`UPDATE_MIN_SIZE`), when the capacitance
    matrix ``I + ΔR Z`` is ill-conditioned (:attr:`MAX_CONDITION`), or when the updated
    direction's residual ``‖J d + Φ‖`` is not at round-off; a fresh factorization gives the
    direct path's direction exactly (same matrix, same LAPACK calls).
    """

    __slots__ = ("S", "n", "N", "kind", "mu", "free", "pinned", "posF", "posP", "lu", "piv", "Rp", "cols",
                 "factorizations", "updates", "rejected", "scale")

    #: Largest number of changed rows solved by the Woodbury update, as a fraction of the factored
    #: (free) size, at least :attr:`UPDATE_MIN`; beyond, refactor. Measured (median rolling step of
    #: benchmarks/coupled_scaling.py's scene, 321 / 641 nodes): 0.03 → 7.1 / 44.7 ms (refactors
    #: nearly every step), 0.0625 → 2.07 / 12.1 ms, 0.125 → 2.34 / 13.0 ms, 0.25 → 3.5 ms,
    #: 0.5 → 4.2 ms (321 nodes; the k × k capacitance and k new columns grow); the rolling
    #: pattern drifts by ~30 rows (median; 90 % ≤ 50) from the factored one at 321 nodes.
    UPDATE_FRACTION = 0.0625
    UPDATE_MIN = 8
    #: Below this many free unknowns a new factorization is as cheap as the update.
    UPDATE_MIN_SIZE = 48
    #: Below this many unknowns (``N``) every direction is solved directly
    #: (:meth:`NewtonMethod._coupled_direction`): the bookkeeping costs more than the LU.
    #: Measured (same scene, direct / updated): 41 nodes 0.28 / 0.44 ms, 81 nodes 0.54 /
    #: 0.60 ms, 101 nodes 0.72 / 0.70 ms, 121 nodes 0.94 / 0.78 ms.
    DIRECT_BELOW = 200
    #: Largest condition number of the capacitance matrix accepted.
    MAX_CONDITION = 1e8
    #: Largest accepted ‖J d + Φ‖∞ / (‖Φ‖∞ + ‖J‖∞‖d‖∞) of an updated direction (round-off is ~1e-15).
    MAX_RESIDUAL = 1e-10

    def __init__(self, S):
        self.S, self.n, self.N = S, S["KN"].shape[0], S["N"]
        self.kind = None
        self.mu = None
        self.factorizations = self.updates = self.rejected = 0
        self.scale = 1.0 + max(float(np.max(np.sum(np.abs(S["KN"]), axis=1))),
                               float(np.max(np.sum(np.abs(S["KT"]), axis=1))))

    @staticmethod
    def kinds(S, contact, stick, slip_sign):
        """Row kind codes (length ``N``): p rows 0 identity / 1 ``K_N``; t rows 0 identity /
        2 ``K_T`` / 3 slip σ = +1 / 4 slip σ = −1; load rows 5."""
        n = contact.size
        k = np.full(S["N"], 5, dtype=np.int8)
        k[:n] = contact
        k[n:2 * n] = np.where(stick, 2, np.where(slip_sign > 0, 3, np.where(slip_sign < 0, 4, 0)))
        return k

    def rows(self, idx, kind):
        """The rows ``idx`` of ``J`` with the kinds ``kind`` (dense, ``len(idx) × N``)."""
        S, n, mu = self.S, self.n, self.mu
        out = np.zeros((idx.size, self.N))
        for code in np.unique(kind).tolist():
            w = np.flatnonzero(kind == code)
            r = idx[w]
            if code == 0:
                out[w, r] = 1.0
            elif code == 1:
                out[w] = S["KN"][r]
            elif code == 2:
                out[w] = S["KT"][r - n]
            elif code == 5:
                out[w] = S["J0"][r]
            else:  # slip, σ = +1 (3) or −1 (4)
                i = r - n
                out[w] = _slip_rows(S["KN"], i, np.full(i.size, (1.0 if code == 3 else -1.0) * mu))
        return out

    def _factor(self, kind, mu):
        """Factor ``J`` of the row kinds ``kind`` on its free rows; ``False`` if singular."""
        self.mu = mu
        free = np.flatnonzero(kind != 0)
        pinned = np.flatnonzero(kind == 0)
        R = self.rows(free, kind[free])
        self.kind, self.free, self.pinned = kind, free, pinned
        self.posF = np.full(self.N, -1)
        self.posF[free] = np.arange(free.size)
        self.posP = np.full(self.N, -1)
        self.posP[pinned] = np.arange(pinned.size)
        self.Rp = R[:, pinned]
        self.cols = {}
        self.lu = None
        self.factorizations += 1
        if free.size:
            lu, piv, info = dgetrf(np.asfortranarray(R[:, free]), overwrite_a=True)
            if info != 0:
                self.kind = None
                return False
            self.lu, self.piv = lu, piv
        return True

    def _solve(self, b):
        """``J_f⁻¹ b`` (``b`` of length ``N``)."""
        x = np.empty(self.N)
        x[self.pinned] = b[self.pinned]
        if self.free.size:
            rhs = b[self.free] - self.Rp @ x[self.pinned]
            sol, info = dgetrs(self.lu, self.piv, rhs)
            if info != 0:
                return None
            x[self.free] = sol
        return x

    def _columns(self, C):
        """``Z = J_f⁻¹ E_C``, from the kept columns, computing the missing ones together."""
        miss = [c for c in C.tolist() if c not in self.cols]
        if miss:
            miss = np.array(miss)
            m = miss.size
            X = np.zeros((self.N, m))
            B = np.zeros((self.free.size, m), order="F")
            inF = self.posF[miss] >= 0
            jF, jP = np.flatnonzero(inF), np.flatnonzero(~inF)
            B[self.posF[miss[jF]], jF] = 1.0
            X[miss[jP], jP] = 1.0
            if jP.size and self.free.size:
                B[:, jP] = -self.Rp[:, self.posP[miss[jP]]]
            if self.free.size:
                sol, info = dgetrs(self.lu, self.piv, B)
                if info != 0:
                    return None
                X[self.free] = sol
            for j, c in enumerate(miss.tolist()):
                self.cols[c] = X[:, j]
        return np.column_stack([self.cols[c] for c in C.tolist()])

    def direction(self, contact, stick, slip_sign, mu, phi):
        """``(d, K_N d, K_T d)`` with ``J d = −Φ``; ``None`` if ``J`` is singular (see the class)."""
        S = self.S
        if self.N < self.DIRECT_BELOW:
            d = NewtonMethod._coupled_direction(S, contact, stick, slip_sign, mu, phi)
            return None if d is None else (d, S["KN"] @ d, S["KT"] @ d)
        kind = self.kinds(S, contact, stick, slip_sign)
        C = None
        if self.kind is not None and mu == self.mu:
            C = np.flatnonzero(kind != self.kind)
            if C.size and (C.size > max(self.UPDATE_MIN, self.UPDATE_FRACTION * self.free.size)
                           or self.free.size < self.UPDATE_MIN_SIZE):
                C = None
        if C is None or C.size == 0:
            if C is None and not self._factor(kind, mu):
                return None
            d = self._solve(-phi)
            return None if d is None else (d, S["KN"] @ d, S["KT"] @ d)
        y = self._solve(-phi)
        Z = self._columns(C)
        if y is None or Z is None:
            return None
        dR = self.rows(C, kind[C]) - self.rows(C, self.kind[C])
        cap = dR @ Z
        cap[np.diag_indices_from(cap)] += 1.0
        d = None
        if np.all(np.isfinite(cap)) and np.linalg.cond(cap) <= self.MAX_CONDITION:
            d = y - Z @ np.linalg.solve(cap, dR @ y)
            dN, dT = S["KN"] @ d, S["KT"] @ d
            if self._residual(kind, d, dN, dT, phi) <= self.MAX_RESIDUAL * (
                    np.max(np.abs(phi)) + self.scale * np.max(np.abs(d))):
                self.updates += 1
                return d, dN, dT
        self.rejected += 1  # refactor at this J: the direct path's direction
        if not self._factor(kind, mu):
            return None
        d = self._solve(-phi)
        return None if d is None else (d, S["KN"] @ d, S["KT"] @ d)

    def _residual(self, kind, d, dN, dT, phi):
        """``‖J d + Φ‖∞`` from ``K_N d`` and ``K_T d``."""
        n, S = self.n, self.S
        kp, kt = kind[:n], kind[n:2 * n]
        dp, dt = d[:n], d[n:2 * n]
        sig = np.where(kt == 3, 1.0, -1.0) * self.mu
        Jd = np.empty(self.N)
        Jd[:n] = np.where(kp == 1, dN, dp)
        Jd[n:2 * n] = np.where(kt == 2, dT, np.where(kt == 0, dt, dt - sig * (dp - dN)))
        loads = np.arange(2 * n, self.N)
        if loads.size:
            Jd[loads] = S["J0"][loads] @ d
        r = Jd + phi
        return float(np.max(np.abs(r))) if np.all(np.isfinite(r)) else np.inf


class NewtonMethod:
    r"""GNMls for one uncoupled step (paper §4, eq. 74–90); see the module docstring.

    Parameters
    ----------
    tolerance : float
        Target of ``‖Φ‖_∞`` (nondimensional; scaled by ``min(1, r)`` so that rollqp's own
        residual of the result is below it).
    max_iterations : int
        Newton iterations (directions) per step before :class:`~rollqp.errors.SolverError`.
    r : float, optional
        Nondimensional augmentation; default ``1/mean(diag Â)`` for the normal and
        ``Δq̂/mean(diag Â)`` for the tangential problem (module docstring).
    rho, sigma : float
        Armijo parameters (eq. 75–78): ``α = ρ^m``, accept when
        ``θ(z + αd) <= (1 − 2σα) θ(z)``. Paper: ``ρ = 0.9``, ``σ = 0.1``.

    Notes
    -----
    ``solve`` returns the :class:`~rollqp.problem.StepSolution` built by the problem itself
    (``problem.solution``), so its residuals are rollqp's. ``info`` holds ``r``,
    ``backtracks`` (Armijo reductions, all iterations), ``merit`` (final ``θ``),
    ``history`` (``‖Φ‖_∞`` before each iteration and at the end), ``merits`` (``θ``, likewise),
    ``steps`` (the accepted
    ``α`` of each iteration), ``nonmonotone`` (full steps taken after a failed search),
    ``shifts`` (degenerate iterates repaired) and
    ``start`` (``"warm"`` or ``"cold"``).
    """

    name = "newton"
    solves = frozenset({"normal", "tangential", "coupled", "steady"})
    operator = "exact"  # the collocation operator itself, not F⁻¹ sym(F A)
    #: Coupled steps: reuse the LU of the coupled Jacobian across iterations and steps
    #: (:class:`_CoupledFactors`); ``False`` solves a new reduced system every iteration
    #: (:meth:`_coupled_direction`, the reference the tests compare with).
    coupled_reuse = True

    def __init__(self, tolerance: float = 1e-10, max_iterations: int = 200, r: float | None = None,
                 rho: float = 0.9, sigma: float = 0.1):
        if not (np.isfinite(tolerance) and 0 < tolerance < 1):
            raise InputError("solver.tolerance", f"must be in (0, 1), got {tolerance!r}")
        if max_iterations is None:
            max_iterations = 200
        if int(max_iterations) != max_iterations or max_iterations < 1:
            raise InputError("solver.max_iterations", f"must be an integer >= 1, got {max_iterations!r}")
        if r is not None and not (np.isfinite(r) and r > 0):
            raise InputError("r", f"the augmentation must be a finite number > 0, got {r!r}")
        if not (0 < rho < 1):
            raise InputError("rho", f"must be in (0, 1), got {rho!r}")
        if not (0 < sigma < 0.5):
            raise InputError("sigma", f"must be in (0, 1/2), got {sigma!r}")
        self.tolerance = float(tolerance)
        self.max_iterations = int(max_iterations)
        self.r = None if r is None else float(r)
        self.rho = float(rho)
        self.sigma = float(sigma)
        self._cache = {}

    @classmethod
    def from_settings(cls, settings, **options) -> "NewtonMethod":
        """From a scene's solver settings: ``tolerance``, ``max_iterations`` (Newton iterations per
        step, default 200) and ``augmentation`` (``r``, default automatic)."""
        check_options(cls.name, options, ("rho", "sigma"))
        return cls(tolerance=settings.tolerance, max_iterations=settings.max_iterations,
                   r=settings.augmentation, **options)

    def setup(self, operators) -> None:
        """A new scene: drop the scaled systems and factorizations of the previous one."""
        self._cache = {}

    # ------------------------------------------------------------------ public
    def solve(self, problem, warm: StepSolution | None = None) -> StepSolution:
        """Solve a :class:`NormalStep` or :class:`TangentialStep`; raise :class:`SolverError` if short."""
        t0 = time.perf_counter()
        if problem.kind in ("normal", "tangential"):
            try:
                sol = self._solve_uncoupled(problem, warm, t0)
            except SolverError as err:
                if problem.kind != "tangential" or problem.Q is None:
                    raise
                sol = self._tangential_by_creepage(problem, warm, t0, err)
            return self._checked(sol)
        if problem.kind == "coupled":
            return self._solve_coupled(problem, warm, t0)
        raise InputError("problem", f"the Newton method solves normal, tangential or coupled steps, "
                                    f"not {problem.kind!r}")

    def _solve_uncoupled(self, problem, warm, t0):
        solve = self._solve_normal if problem.kind == "normal" else self._solve_tangential
        try:
            return solve(problem, warm, t0)
        except _Stalled:
            # the warm start led to a Newton fixed point that is not a solution (a wrong
            # active set that the Newton step reproduces): restart once from the cold start
            sol = solve(problem, None, t0)
            sol.info["restarts"] = 1
            return sol

    def _tangential_by_creepage(self, pb, warm, t0, err):
        r"""Fallback when GNMls fails on a tangential step with ``Q`` prescribed: solve for ``ξ``.

        The failure this repairs: with a single stick node (free rolling at μ ≲ 3e-4) the load
        row's only ``ξ̂`` entry is that node's, and the "nearest node onto its kink" repair (module
        docstring) makes Newton cycle between active sets. With ``ξ`` prescribed instead the load
        row is gone and GNMls converges (CONTACT's workaround: solve with ξ given first). The
        load is then met by a root search on ``F(ξ̂) = f̂ᵀt̂(ξ̂) − Q̂``, continuous, piecewise
        linear and monotone (friction opposes slip), each evaluation a ξ-prescribed solve warm
        started from the previous one: bracketing by doubling steps from the warm ``ξ``, then
        Brent's method. The root's traction then warm-starts the Q-prescribed GNMls (one or two
        iterations on the right active set); if that fails too, the ξ-prescribed solution at the
        root is kept when rollqp's residual of the original problem is within tolerance.
        Counted in ``info["creepage_search"]`` (evaluations). Otherwise ``err`` is raised.
        """
        from scipy.optimize import brentq

        sc = pb.scales
        Qhat = pb.Q / sc.force
        fhat = pb.f / sc.length
        last = {"sol": warm, "evals": 0, "its": int(err.iterations or 0)}

        def F(xh):
            last["evals"] += 1
            sol = self._solve_uncoupled(pb.replace(Q=None, xi=xh * sc.slip), last["sol"], t0)
            last["sol"] = sol
            last["its"] += sol.iterations
            return float(fhat @ (sol.t / sc.stress)) - Qhat

        try:
            x0 = warm.xi / sc.slip if warm is not None and warm.xi is not None else 0.0
            f0 = F(x0)
            h = 2.0 * pb.mu * max(float(np.max(pb.p)) / sc.stress, 1e-12) + 1e-6
            lo = hi = x0
            flo = fhi = f0
            for _ in range(80):  # widen both ways until F changes sign
                if flo * fhi <= 0.0:
                    break
                lo, hi = lo - h, hi + h
                flo, fhi = F(lo), F(hi)
                h *= 2.0
            else:
                raise err
            root = brentq(F, lo, hi, xtol=1e-15, rtol=1e-15, maxiter=200) if flo * fhi < 0 else (lo if flo == 0 else hi)
            at_root = self._solve_uncoupled(pb.replace(Q=None, xi=root * sc.slip), last["sol"], t0)
        except (SolverError, ValueError, RuntimeError):  # a ξ-prescribed solve failed, or Brent did not converge
            raise err from None
        try:
            sol = self._solve_tangential(pb, at_root, t0)
        except (SolverError, _Stalled):
            sol = pb.solution(at_root.t, at_root.xi)
            if not sol.residual <= self.tolerance:
                raise err from None
            sol = self._finish(sol, at_root.iterations, dict(at_root.info), t0)
        sol.info["creepage_search"] = last["evals"] + 1
        sol.iterations += last["its"] + at_root.iterations  # all Newton iterations of the step
        return sol

    # ------------------------------------------------------------ the two kinds
    def _solve_normal(self, pb, warm, t0):
        sc = pb.scales
        u0 = sc.displacement
        sys_ = self._system(pb, None)
        n, r = pb.n, sys_.r
        hhat = pb.h_total / u0
        with_load = pb.P is not None
        Phat = pb.P / sc.force if with_load else None
        dhat_fixed = None if with_load else pb.delta / u0

        # start (Step 1): previous step's pressure and approach, else a Hertz-like profile
        start = "cold"
        p0 = None
        if warm is not None and warm.p is not None and np.shape(warm.p) == (n,):
            p0, start = np.asarray(warm.p, dtype=float) / sc.stress, "warm"
        if p0 is None:
            # ĥ = x̂² for two cylinders in Hertz units: p̂ = √(1 − x̂²) is the Hertz solution
            p0 = np.sqrt(np.maximum(0.0, 1.0 - (hhat - hhat.min())))
        guess = p0 > 0
        if not guess.any():
            guess = hhat == hhat.min()
        if with_load:
            if start == "cold" and sys_.fhat @ p0 > 0:
                p0 = p0 * (Phat / (sys_.fhat @ p0))
            if start == "warm" and warm.delta is not None:
                d0 = warm.delta / u0
            else:  # the approach that closes the gap on average over the guessed contact
                d0 = float(np.mean((hhat + sys_.Ahat @ p0)[guess]))
            z = np.append(p0, d0)
        else:
            if start == "cold":  # scale the profile to close the gap on average over it
                Ap = (sys_.Ahat @ p0)[guess].mean()
                c = (dhat_fixed - hhat[guess].mean()) / Ap if Ap > 0 else 0.0
                p0 = p0 * max(c, 0.0)
            z = p0.copy()
        k0 = r * (hhat - (dhat_fixed if dhat_fixed is not None else 0.0))

        def phi_nodes(x, y):
            return np.minimum(x, y)

        def mask_of(x, y):
            # eq. 84 (p̂_i > r ĝ_i: Φ_i = r ĝ_i, row r ∂ĝ_i); eq. 82/83 (p̂_i <= r ĝ_i: row ∂p̂_i)
            return x > y

        def nearest(x, y):
            # all p̂ <= r ĝ: the node with the smallest r ĝ − p̂ reaches contact when r ĝ drops by it
            j = int(np.argmin(y - x))
            return j, -(y[j] - x[j])

        z, it, info = self._iterate(pb, sys_, z, k0, Phat, phi_nodes, mask_of, nearest, start == "warm")
        p = z[:n] * sc.stress
        delta = z[n] * u0 if with_load else pb.delta
        info["start"] = start
        return self._finish(pb.solution(p, delta), it, info, t0)

    def _solve_tangential(self, pb, warm, t0):
        sc = pb.scales
        sys_ = self._system(pb, pb.dq / sc.length)
        n, r = pb.n, sys_.r
        dqh = pb.dq / sc.length
        b = pb.bound / sc.stress
        with_load = pb.Q is not None
        Qhat = pb.Q / sc.force if with_load else None
        xi_fixed = None if with_load else pb.xi / sc.slip

        start = "cold"
        t = np.zeros(n)
        xi0 = 0.0
        if warm is not None and warm.t is not None and np.shape(warm.t) == (n,):
            t, start = np.asarray(warm.t, dtype=float) / sc.stress, "warm"
            if warm.xi is not None:
                xi0 = warm.xi / sc.slip
        z = np.append(t, xi0) if with_load else t.copy()
        k0 = r * (pb.c / sc.displacement / dqh + (xi_fixed if xi_fixed is not None else 0.0))
        sep = b <= 0.0

        def phi_nodes(x, y):
            return x - np.clip(x - y, -b, b)

        def mask_of(x, y):
            # eq. 86/87 (|t̂_i − r ŝ_i| <= b_i, stick: Φ_i = r ŝ_i, row r ∂ŝ_i);
            # eq. 88 (> b_i, slip: Φ_i = t̂_i ∓ b_i with b fixed, row ∂t̂_i);
            # eq. 85 (b_i = 0, separation: Φ_i = t̂_i, row ∂t̂_i).
            return (np.abs(x - y) <= b) & ~sep

        def nearest(x, y):
            # all |t̂ − r ŝ| > b: the node with the smallest excess sticks when r ŝ moves by it
            u = x - y
            excess = np.abs(u) - b
            excess[sep] = np.inf
            j = int(np.argmin(excess))
            if not np.isfinite(excess[j]):
                raise SolverError("no node can stick: the friction bound is zero everywhere",
                                  method=self.name, status="degenerate")
            return j, float(np.sign(u[j]) * excess[j])

        z, it, info = self._iterate(pb, sys_, z, k0, Qhat, phi_nodes, mask_of, nearest, start == "warm")
        tt = z[:n] * sc.stress
        xi = z[n] * sc.slip if with_load else pb.xi
        info["start"] = start
        return self._finish(pb.solution(tt, xi), it, info, t0)

    # ------------------------------------------------------------ the iteration
    def _iterate(self, pb, sys_, z, k0, load, phi_nodes, mask_of, nearest, warm=False):
        """GNMls Steps 2–7 on ``Φ(z) = [φ(x, y); f̂ᵀx − load]`` with ``y = K z + k0``.

        ``x = z[:n]`` is the traction, ``y`` the augmented gap/slip ``r ĝ``/``r ŝ`` (linear in z).
        """
        n = pb.n
        r = sys_.r
        with_load = load is not None
        K = sys_.matrices(with_load)
        fhat = sys_.fhat
        stop = self.tolerance * min(1.0, r)
        rho, two_sigma = self.rho, 2.0 * self.sigma
        mask = np.ones(n + 1 if with_load else n, dtype=bool)  # last entry: load row (always the JK row)
        history, merits, steps = [], [], []
        backtracks = nonmono = shifts = 0
        it = 0

        def residual(x, y):
            ph = phi_nodes(x, y)
            return np.append(ph, fhat @ x - load) if with_load else ph

        x = z[:n]
        y = K @ z + k0
        phi = residual(x, y)
        while True:
            nrm = float(np.max(np.abs(phi)))
            history.append(nrm)
            merits.append(0.5 * float(phi @ phi))
            if nrm <= stop:
                break
            if it >= self.max_iterations:
                theta = merits[-1]
                raise SolverError(f"the {pb.kind} Newton iteration did not converge: merit θ = {theta:.3e} "
                                  f"after {it} iterations (‖Φ‖∞ = {nrm:.3e} > {stop:.1e})",
                                  method=self.name, status=f"merit {theta:.3e}", iterations=it,
                                  residual=nrm)
            it += 1
            # pseudo-Jacobian (eq. 80–90), assembled by rows
            m = mask_of(x, y)
            if with_load and not m.any():
                # no δ̂/ξ̂ column: move the nearest node onto its kink (module docstring)
                j, dy = nearest(x, y)
                z[n] += dy / K[j, n]
                y = K @ z + k0
                phi = residual(x, y)
                m = mask_of(x, y)
                m[j] = True
                shifts += 1
            mask[:n] = m
            d = sys_.direction(mask, phi, with_load)  # reduced system on the free nodes
            if d is None or not np.all(np.isfinite(d)):
                raise SolverError(f"the {pb.kind} Newton matrix is singular",
                                  method=self.name, status="singular", iterations=it, residual=nrm)
            # Armijo (eq. 75–78), s = 1
            dx = d[:n]
            Kd = K @ d
            theta = merits[-1]
            alpha = 1.0
            while True:
                xa, ya = x + alpha * dx, y + alpha * Kd
                pa = residual(xa, ya)
                if 0.5 * float(pa @ pa) <= (1.0 - two_sigma * alpha) * theta:
                    break
                alpha *= rho
                backtracks += 1
                if alpha < ALPHA_MIN:
                    if warm:
                        raise _Stalled()
                    nonmono += 1
                    alpha = 1.0
                    xa, ya = x + dx, y + Kd
                    break
            steps.append(alpha)
            z = z + alpha * d  # eq. 79
            x = z[:n]
            y = K @ z + k0  # fresh, not accumulated: no drift of the linear part
            phi = residual(x, y)
        info = {"r": r, "backtracks": backtracks, "merit": merits[-1], "history": history, "merits": merits,
                "steps": steps, "nonmonotone": nonmono, "shifts": shifts, "tolerance_phi": stop}
        return z, it, info

    # ------------------------------------------------------------ the coupled step
    def _solve_coupled(self, pb, warm, t0):
        r"""GNMls on all rows of ``Φ`` (eq. 63–64, 80–90): unknowns ``z = (p̂, t̂, δ̂?, ξ̂?)``.

        ``y_N = r_N ĝ`` and ``y_T = r_T ŝ`` are linear in ``z``; the friction bound is
        ``b = μ max(0, p̂ − y_N)`` (eq. 63), so a slipping node's row depends on ``p̂`` and ``ĝ``
        (eq. 88). Start: the previous step (warm), else one N–T sweep of the two halves.
        Directions: :class:`_CoupledFactors` (one LU reused across iterations and steps through
        a Woodbury update of the rows whose node case changed), or with ``coupled_reuse``
        false :meth:`_coupled_direction` (a new reduced system per iteration, the reference).
        """
        sc = pb.scales
        n = pb.n
        S = self._coupled_system(pb)
        N, iP, iQ = S["N"], S["iP"], S["iQ"]
        KN, KT, kN, kT = S["KN"], S["KT"], S["kN"], S["kT"]
        mu = pb.mu
        Phat = pb.P / sc.force if iP is not None else None
        Qhat = pb.Q / sc.force if iQ is not None else None

        start = "warm"
        if (warm is not None and warm.p is not None and warm.t is not None and np.shape(warm.p) == (n,)
                and np.shape(warm.t) == (n,)):
            p0, t0_, d0, x0 = warm.p, warm.t, warm.delta, warm.xi
        else:  # cold: one N–T sweep of the halves (normal with t = 0, then tangential)
            start = "cold"
            nsol = self.solve(pb.normal_half(np.zeros(n)))
            tsol = self.solve(pb.tangential_half(nsol.p))
            p0, t0_, d0, x0 = nsol.p, tsol.t, nsol.delta, tsol.xi
        z = np.zeros(N)
        z[:n], z[n:2 * n] = p0 / sc.stress, t0_ / sc.stress
        if iP is not None:
            z[iP] = (d0 if d0 is not None else 0.0) / sc.displacement
        if iQ is not None:
            z[iQ] = (x0 if x0 is not None else 0.0) / sc.slip
        fhat = S["fhat"]
        factors = S["factors"].get("lu")
        if factors is None:
            factors = S["factors"]["lu"] = _CoupledFactors(S)
        counts = (factors.factorizations, factors.updates)

        def residual(p, t, yN, yT):
            b = mu * np.maximum(0.0, p - yN)
            out = np.empty(N)
            out[:n] = np.minimum(p, yN)
            out[n:2 * n] = t - np.clip(t - yT, -b, b)
            if iP is not None:
                out[iP] = fhat @ p - Phat
            if iQ is not None:
                out[iQ] = fhat @ t - Qhat
            return out

        stop = self.tolerance * min(1.0, S["rN"], S["rT"])
        rho, two_sigma = self.rho, 2.0 * self.sigma
        history, merits, steps = [], [], []
        backtracks = sweeps = shifts = it = tightened = 0
        p, t = z[:n], z[n:2 * n]
        yN, yT = KN @ z + kN, KT @ z + kT
        phi = residual(p, t, yN, yT)
        while True:
            nrm = float(np.max(np.abs(phi)))
            history.append(nrm)
            merits.append(0.5 * float(phi @ phi))
            if nrm <= stop:
                sol = pb.solution(p * sc.stress, t * sc.stress,
                                  z[iP] * sc.displacement if iP is not None else None,
                                  z[iQ] * sc.slip if iQ is not None else None)
                if sol.residual <= self.tolerance or tightened >= 3:
                    break
                stop *= 0.1  # the bound μ max(0, p − r g) differs from μ p⁺ off the solution
                tightened += 1
                history.pop()
                merits.pop()
                continue
            if it >= self.max_iterations:
                theta = merits[-1]
                raise SolverError(f"the coupled Newton iteration did not converge: merit θ = {theta:.3e} "
                                  f"after {it} iterations (‖Φ‖∞ = {nrm:.3e} > {stop:.1e})",
                                  method=self.name, status=f"merit {theta:.3e}", iterations=it, residual=nrm)
            it += 1
            contact, stick, slip_sign, _ = self._coupled_cases(p, t, yN, yT, mu)
            if iP is not None and not contact.any():  # no δ̂ column: see module docstring
                j = int(np.argmin(yN - p))
                z[iP] += (p[j] - yN[j]) / KN[j, iP]
                yN, yT = KN @ z + kN, KT @ z + kT
                phi = residual(p, t, yN, yT)
                contact, stick, slip_sign, _ = self._coupled_cases(p, t, yN, yT, mu)
                contact[j] = True
                shifts += 1
            if iQ is not None and not stick.any():  # no ξ̂ column
                b = mu * np.maximum(0.0, p - yN)
                u = t - yT
                excess = np.where(b > 0, np.abs(u) - b, np.inf)
                j = int(np.argmin(excess))
                if not np.isfinite(excess[j]):
                    raise SolverError("the coupled Newton iteration reached an iterate where no node can "
                                      f"stick (friction bound zero everywhere; merit θ = {merits[-1]:.3e})",
                                      method=self.name, status="degenerate", iterations=it, residual=nrm)
                z[iQ] += np.sign(u[j]) * excess[j] / KT[j, iQ]
                yN, yT = KN @ z + kN, KT @ z + kT
                phi = residual(p, t, yN, yT)
                contact, stick, slip_sign, _ = self._coupled_cases(p, t, yN, yT, mu)
                stick[j] = True
                slip_sign[j] = 0.0
                shifts += 1
            if self.coupled_reuse:  # reduced system, LU reused across iterations and steps
                out = factors.direction(contact, stick, slip_sign, mu, phi)
                d, dN, dT = out if out is not None else (None, None, None)
            else:  # the direct path (reference): a new reduced system every iteration
                d = self._coupled_direction(S, contact, stick, slip_sign, mu, phi)
                if d is not None:
                    dN, dT = KN @ d, KT @ d
            if d is None or not np.all(np.isfinite(d)):
                raise SolverError("the coupled Newton matrix is singular",
                                  method=self.name, status="singular", iterations=it, residual=nrm)
            dp, dt = d[:n], d[n:2 * n]
            theta = merits[-1]
            alpha = 1.0
            while True:
                pa = residual(p + alpha * dp, t + alpha * dt, yN + alpha * dN, yT + alpha * dT)
                if 0.5 * float(pa @ pa) <= (1.0 - two_sigma * alpha) * theta:
                    break
                alpha *= rho
                backtracks += 1
                if alpha < ALPHA_MIN:
                    alpha = 0.0
                    break
            if alpha == 0.0:
                # Armijo failed: the direction is not a descent direction (a node on a kink
                # where the modified row is not the directional derivative). Taking the full
                # step anyway can cycle (measured: μ = 0.03, Goodman loading). Instead take one
                # N–T sweep of the halves from here — each half is a monotone problem solved by
                # its own GNMls — and resume the coupled iteration from its result.
                sweeps += 1
                z = self._sweep(pb, z, S)
                steps.append(0.0)
            else:
                steps.append(alpha)
                z = z + alpha * d  # eq. 79
            p, t = z[:n], z[n:2 * n]
            yN, yT = KN @ z + kN, KT @ z + kT
            phi = residual(p, t, yN, yT)
        info = {"r": (S["rN"], S["rT"]), "backtracks": backtracks, "merit": merits[-1], "history": history,
                "merits": merits, "steps": steps, "nonmonotone": sweeps, "sweeps": sweeps, "shifts": shifts,
                "tolerance_phi": stop, "start": start}
        if self.coupled_reuse:
            info["factorizations"] = factors.factorizations - counts[0]
            info["updates"] = factors.updates - counts[1]
        return self._finish(sol, it, info, t0)

    def _sweep(self, pb, z, S):
        """One N–T sweep from ``z`` (the coupled iteration's fallback); returns the new ``z``."""
        sc, n = pb.scales, pb.n
        iP, iQ = S["iP"], S["iQ"]
        warm = StepSolution(p=z[:n] * sc.stress, t=z[n:2 * n] * sc.stress,
                            delta=z[iP] * sc.displacement if iP is not None else pb.delta,
                            xi=z[iQ] * sc.slip if iQ is not None else pb.xi)
        nsol = self.solve(pb.normal_half(warm.t), warm=warm)
        tsol = self.solve(pb.tangential_half(nsol.p), warm=warm)
        out = z.copy()
        out[:n], out[n:2 * n] = nsol.p / sc.stress, tsol.t / sc.stress
        if iP is not None:
            out[iP] = nsol.delta / sc.displacement
        if iQ is not None:
            out[iQ] = tsol.xi / sc.slip
        return out

    @staticmethod
    def _coupled_cases(p, t, yN, yT, mu):
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

    @staticmethod
    def _coupled_direction(S, contact, stick, slip_sign, mu, phi):
        """The coupled Newton direction, ``J d = −Φ`` on the free unknowns only (eq. 80).

        The rows of :meth:`_coupled_jacobian` for ``p̂_i`` of a separated node and for ``t̂_i`` of
        a node with a zero bound are identity rows, so ``d = −Φ`` there; the rest (contact
        pressures, tractions under a positive bound, ``δ̂``, ``ξ̂``) is assembled directly,
        row by row, and solved (LAPACK ``gesv``). Returns ``None`` if it is singular. The
        reference path (``coupled_reuse = False``) and :class:`_CoupledFactors`' solve on small
        systems; otherwise the iteration reuses factorizations (:class:`_CoupledFactors`).
        """
        n = contact.size
        KN, KT = S["KN"], S["KT"]
        ic = np.flatnonzero(contact)
        it_ = np.flatnonzero(stick | (slip_sign != 0))  # t rows that are not identity rows
        loads = np.array([k for k in (S["iP"], S["iQ"]) if k is not None], dtype=int)
        free = np.concatenate([ic, n + it_, loads])
        pinned = np.concatenate([np.flatnonzero(~contact), n + np.flatnonzero(~stick & (slip_sign == 0))])
        R = np.empty((free.size, S["N"]))
        R[:ic.size] = KN[ic]
        st = stick[it_]
        rows = np.empty((it_.size, S["N"]))
        rows[st] = KT[it_[st]]
        isl = it_[~st]
        if isl.size:
            rows[~st] = _slip_rows(KN, isl, slip_sign[isl] * mu)
        R[ic.size:ic.size + it_.size] = rows
        R[ic.size + it_.size:] = S["J0"][loads]
        d = np.empty(S["N"])
        d[pinned] = -phi[pinned]
        rhs = -phi[free] - R[:, pinned] @ d[pinned]
        if free.size:
            _, _, x, fail = dgesv(np.asfortranarray(R[:, free]), rhs, overwrite_a=True, overwrite_b=True)
            if fail != 0:
                return None
            d[free] = x
        return d

    @staticmethod
    def _coupled_jacobian(S, contact, stick, slip_sign, mu):
        """The pseudo-Jacobian ``BΦ`` (eq. 80–90), Fortran-ordered for LAPACK."""
        n = contact.size
        J = np.array(S["J0"], order="F")  # identity rows and load rows
        ic = np.flatnonzero(contact)
        J[ic] = S["KN"][ic]
        ist = np.flatnonzero(stick)
        J[n + ist] = S["KT"][ist]
        isl = np.flatnonzero(slip_sign)
        if isl.size:
            J[n + isl] = _slip_rows(S["KN"], isl, slip_sign[isl] * mu)
        return J

    def _coupled_system(self, pb):
        """Scaled, r-weighted linear parts ``y_N = K_N z + k_N``, ``y_T = K_T z + k_T``."""
        sc = pb.scales
        key = ("coupled", id(pb.Ann), id(pb.Att), id(pb.Ant), id(pb.Atn), id(pb.f), sc, pb.dq, self.r,
               pb.P is None, pb.Q is None)
        hit = self._cache.get(key)
        if hit is None or not all(a is b for a, b in zip(hit["src"], (pb.Ann, pb.Att, pb.Ant, pb.Atn, pb.f))):
            n = pb.n
            m = sc.modulus / sc.length
            dqh = pb.dq / sc.length
            Ann, Att = pb.Ann.dense() * m, pb.Att.dense() * m
            sN, sT = float(np.mean(np.diag(Ann))), float(np.mean(np.diag(Att)))
            if not (sN > 0 and sT > 0):
                raise InputError("A", "the influence matrices must have a positive mean diagonal")
            rN = self.r if self.r is not None else 1.0 / sN
            rT = self.r if self.r is not None else dqh / sT
            iP = 2 * n if pb.P is not None else None
            iQ = (2 * n + (iP is not None)) if pb.Q is not None else None
            N = 2 * n + (iP is not None) + (iQ is not None)
            KN = np.zeros((n, N))
            KT = np.zeros((n, N))
            KN[:, :n] = rN * Ann
            KT[:, n:2 * n] = (rT / dqh) * Att
            if pb.Ant is not None:
                KN[:, n:2 * n] = rN * m * pb.Ant.dense()
            if pb.Atn is not None:
                KT[:, :n] = (rT / dqh) * m * pb.Atn.dense()
            if iP is not None:
                KN[:, iP] = -rN
            if iQ is not None:
                KT[:, iQ] = rT
            fhat = pb.f / sc.length
            J0 = np.zeros((N, N))
            J0[:2 * n, :2 * n] = np.eye(2 * n)
            if iP is not None:
                J0[iP, :n] = fhat
            if iQ is not None:
                J0[iQ, n:2 * n] = fhat
            hit = {"src": (pb.Ann, pb.Att, pb.Ant, pb.Atn, pb.f), "N": N, "iP": iP, "iQ": iQ, "KN": KN,
                   "KT": KT, "J0": J0, "fhat": fhat, "rN": rN, "rT": rT, "dqh": dqh,
                   "factors": {}}  # the _CoupledFactors of this operator, made by _solve_coupled
            if len(self._cache) >= 16:
                self._cache.clear()
            self._cache[key] = hit
        # the vectors change every step
        u0 = sc.displacement
        dqh = hit["dqh"]
        kN = hit["rN"] * (pb.h / u0 - (pb.delta / u0 if pb.delta is not None else 0.0))
        kT = hit["rT"] * (pb.c / u0 / dqh + (pb.xi / sc.slip if pb.xi is not None else 0.0))
        return dict(hit, kN=kN, kT=kT)

    # ------------------------------------------------------------ helpers
    def _checked(self, sol):
        """Never hand back a step whose rollqp residual misses the tolerance.

        The iteration stops on ``‖Φ‖∞ <= tolerance·min(1, r)``, which bounds rollqp's own
        residual (r = 1) by ``tolerance`` in exact arithmetic. With an extreme ``r`` (measured:
        r = 1e-8, outside the accepted band) round-off in the r-scaled rows breaks that
        implication; the step is then a failure, not a solution.
        """
        if not sol.residual <= self.tolerance:
            raise SolverError(f"the Newton iteration stopped on its scaled test but rollqp's residual {sol.residual:.3e} exceeds the "
                              f"tolerance {self.tolerance:.1e} (augmentation r = {sol.info.get('r', float('nan')):.3g})",
                              method=self.name, status="residual above tolerance",
                              iterations=sol.iterations, residual=sol.residual)
        return sol

    def _finish(self, sol, it, info, t0):
        sol.method, sol.status, sol.iterations = self.name, "solved", it
        sol.info.update(info)
        sol.time = time.perf_counter() - t0
        return sol

    def augmentation(self, problem) -> float:
        """The nondimensional ``r`` used for ``problem`` (module docstring)."""
        dqh = problem.dq / problem.scales.length if problem.kind == "tangential" else None
        return self._system(problem, dqh).r

    def _system(self, pb, dqh):
        """Scaled matrices of ``pb``, cached by the identity of ``A``/``f`` (as QPMethod._split)."""
        sc = pb.scales
        key = (pb.kind, id(pb.A), id(pb.f), sc, dqh, self.r)
        hit = self._cache.get(key)
        if hit is not None and hit.A is pb.A and hit.f is pb.f:
            return hit
        Ahat = pb.A.dense() * (sc.modulus / sc.length)
        fhat = pb.f / sc.length
        scale = float(np.mean(np.diag(Ahat)))
        if not scale > 0:
            raise InputError("A", "the influence matrix must have a positive mean diagonal")
        if pb.kind == "normal":
            r = self.r if self.r is not None else 1.0 / scale
            last, t_scale = -np.ones(pb.n), 1.0  # ∂(r ĝ)/∂δ̂ = −r, ∂(r ĝ)/∂p̂ = r Â
        else:
            r = self.r if self.r is not None else dqh / scale
            last, t_scale = np.ones(pb.n), dqh  # ∂(r ŝ)/∂ξ̂ = r, ∂(r ŝ)/∂t̂ = r Â/Δq̂
        sys_ = _System(pb.A, pb.f, Ahat, fhat, r, last, t_scale)
        if len(self._cache) >= 16:
            self._cache.clear()
        self._cache[key] = sys_
        return sys_

    # ------------------------------------------------------------ for tests and diagnostics
    def residual_and_jacobian(self, problem, z):
        """``(Φ(z), J(z), cases)`` in the nondimensional unknowns ``z`` (module docstring).

        ``z = (p̂, δ̂)`` or ``(t̂, ξ̂)`` (without the last entry if ``δ``/``ξ`` is prescribed).
        ``cases[i]`` names the pseudo-Jacobian row chosen for node ``i``: ``"eq82"``/``"eq83"``/
        ``"eq84"`` (normal) or ``"eq85"``/``"eq86"``/``"eq87"``/``"eq88"`` (tangential).

        For a :class:`~rollqp.problem.CoupledStep`, ``z = (p̂, t̂, δ̂?, ξ̂?)`` and ``cases`` is a
        pair ``(normal, tangential)`` of per-node labels; the tangential ones add ``"eq89"``
        (bound exactly zero, ``t̂ ≠ y_T``) and ``"eq90"`` (bound zero and ``t̂ = y_T``).
        """
        z = np.asarray(z, dtype=float)
        sc = problem.scales
        n = problem.n
        if problem.kind == "coupled":
            return self._coupled_residual_and_jacobian(problem, z)
        if problem.kind == "normal":
            sys_ = self._system(problem, None)
            with_load = problem.P is not None
            k0 = sys_.r * (problem.h_total / sc.displacement - (0.0 if with_load else problem.delta / sc.displacement))
            load = problem.P / sc.force if with_load else None
            K = sys_.matrices(with_load)
            x, y = z[:n], K @ z + k0
            ph = np.minimum(x, y)
            m = x > y
            cases = np.where(x < y, "eq82", np.where(x == y, "eq83", "eq84"))
        else:
            dqh = problem.dq / sc.length
            sys_ = self._system(problem, dqh)
            with_load = problem.Q is not None
            b = problem.bound / sc.stress
            k0 = sys_.r * (problem.c / sc.displacement / dqh + (0.0 if with_load else problem.xi / sc.slip))
            load = problem.Q / sc.force if with_load else None
            K = sys_.matrices(with_load)
            x, y = z[:n], K @ z + k0
            ph = x - np.clip(x - y, -b, b)
            u = np.abs(x - y)
            sep = b <= 0
            m = (u <= b) & ~sep
            cases = np.where(sep, "eq85", np.where(u < b, "eq86", np.where(u == b, "eq87", "eq88")))
        mask = np.append(m, True) if with_load else m
        J = sys_.jacobian(mask, with_load)
        phi = np.append(ph, sys_.fhat @ x - load) if with_load else ph
        return phi, J, cases

    def _coupled_residual_and_jacobian(self, pb, z):
        S = self._coupled_system(pb)
        n, mu, sc = pb.n, pb.mu, pb.scales
        p, t = z[:n], z[n:2 * n]
        yN, yT = S["KN"] @ z + S["kN"], S["KT"] @ z + S["kT"]
        contact, stick, slip_sign, zero_bound = self._coupled_cases(p, t, yN, yT, mu)
        J = self._coupled_jacobian(S, contact, stick, slip_sign, mu)
        b = mu * np.maximum(0.0, p - yN)
        phi = [np.minimum(p, yN), t - np.clip(t - yT, -b, b)]
        if S["iP"] is not None:
            phi.append([S["fhat"] @ p - pb.P / sc.force])
        if S["iQ"] is not None:
            phi.append([S["fhat"] @ t - pb.Q / sc.force])
        u = np.abs(t - yT)
        ncase = np.where(p < yN, "eq82", np.where(p == yN, "eq83", "eq84"))
        exact_zero = (p - yN) == 0.0  # eq. 85 is p̂ − y_N < 0 (the bound's argument negative)
        tcase = np.where(zero_bound & ~exact_zero, "eq85", "")
        tcase = np.where(zero_bound & exact_zero & (u > 0), "eq89", tcase)
        tcase = np.where(zero_bound & exact_zero & (u == 0), "eq90", tcase)
        tcase = np.where(~zero_bound, np.where(u < b, "eq86", np.where(u == b, "eq87", "eq88")), tcase)
        return np.concatenate(phi), np.asarray(J), (ncase, tcase)
