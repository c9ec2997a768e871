r"""The linear algebra of the Newton directions: reduced systems, and factorizations reused across iterations.

The pseudo-Jacobian of ``Φ`` (eq. 80–90, :mod:`.ncp`) has an identity row at every separated
or slipping node, so the direction is known there (``d_i = −Φ_i``) and the rest is solved on the
free nodes only — the *reduced system*. Its LU factors are kept while the free set drifts by a
few nodes: :class:`ReducedSystem` (uncoupled steps) solves the bordered system through a Schur
complement on the old factors; :class:`CoupledFactors` (the coupled step, whose rows are one of
a few kinds per node) updates by Sherman–Morrison–Woodbury. Both refactor when the change is
large or the update ill-conditioned, and a fresh factorization gives the direct path's direction
exactly (same matrix, same LAPACK calls). :class:`CoupledSystem` is the coupled step's r-scaled
linear part, a typed record built once per operator set (:func:`coupled_system`).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.linalg.lapack import dgesv, dgetrf, dgetrs

from ...errors import InputError
from ..blocks import MAX_BLOCKS, RUN_GAP, partial_product, runs  # noqa: F401 - re-exported
from .ncp import slip_rows

__all__ = ["ReducedSystem", "CoupledSystem", "coupled_system", "coupled_vectors", "CoupledFactors",
           "direct_coupled_direction", "runs", "partial_product", "PARTIAL_MIN"]

#: From this many nodes the iteration multiplies only the blocks of ``K`` it needs
#: (:func:`partial_product`); below, one dense product is cheaper than the bookkeeping.
PARTIAL_MIN = 320
#: Columns of the reduced matrix gathered at a time into its factorization's array.
FACTOR_COLUMNS = 256
_NONE = np.empty(0, dtype=np.intp)  # no nodes (read-only)
_NONE.flags.writeable = False


class ReducedSystem:
    """The r-scaled linear part of one uncoupled step's ``Φ`` and its reduced solves (per ``A``, ``f``, scales, ``Δq``, ``r``).

    ``K`` (``n × (n+1)``) maps ``z = (x, δ̂|ξ̂)`` to the linear part of ``y = r ĝ`` or ``r ŝ``;
    ``K_nl`` is its first ``n`` columns (``δ``/``ξ`` prescribed, no load row). The
    pseudo-Jacobian has a ``K`` row at the contact/stick nodes (``mask``), an identity row at
    the separated/slipping nodes, and the load row ``[f̂ᵀ, 0]`` last; :meth:`direction` solves
    with it on the free nodes only (the reduced system) and keeps the LU factors of the last
    few active sets.
    """

    __slots__ = ("A", "f", "a_scale", "fhat", "r", "K", "_K_nl", "load_column", "unit", "partial", "last", "settled", "_base",
                 "factorizations", "updates", "_factors", "_masks", "ncp", "exact", "events", "_serial", "tag")

    #: Largest change of the active set, against the factored one, solved by a Schur complement
    #: (as a fraction of the factored size; at least :attr:`UPDATE_MIN` nodes); beyond, refactor.
    UPDATE_FRACTION = 0.125
    UPDATE_MIN = 4
    #: Below this many free nodes a new factorization is cheaper than the bordered solve.
    UPDATE_MIN_SIZE = 64
    #: Factorizations kept per system (the oldest dropped first; together at most the size of ``K``).
    MAX_FACTORS = 4

    def __init__(self, A, f, Ahat, fhat, r, last_column, t_scale, unit=1.0, workspace=None, a_scale=None):
        n = fhat.size
        self.A, self.f, self.fhat, self.r = A, f, fhat, r
        #: ``Â = a_scale · A`` (:meth:`ahat_product`); ``Â`` itself is not kept (n² doubles less per system)
        self.a_scale = a_scale
        if workspace is not None:  # ``Ahat`` is ``workspace[:, :n]``: scaled in place into K (no second n × n array)
            K = workspace
            K[:, :n] *= r / t_scale
        else:
            K = np.empty((n, n + 1))
            K[:, :n] = (r / t_scale) * Ahat
        K[:, n] = r * last_column
        self.K = K
        col = K[:, n].copy()  # contiguous: y's load term (a strided column costs twice as much)
        #: ``K``'s load column, or the one number it holds (``±r``: the normal and tangential steps'
        #: ``∂y/∂δ̂``, ``∂y/∂ξ̂``), which ``y`` then adds as a number: the same values, one operation less
        self.load_column = float(col[0]) if n and np.all(col == col[0]) else col
        self._K_nl = None  # made on first use: a scene with the load row never needs it
        #: ``K_nl x̂ = unit · (A x)`` for a traction ``x`` in the problem's units (``x̂ = x/p0``)
        self.unit = (r / t_scale) * unit
        self.partial = n >= PARTIAL_MIN
        #: ``(x, A x)`` of the last solution (and ``unit·A x``, if kept): the next step, warm-started from ``x``, needs no new product
        self.last = None
        #: The last step converged in one iteration (the iteration then multiplies at the full step
        #: instead of carrying y: :func:`~.uncoupled.iterate`)
        self.settled = False
        self._base = {}  # with_load -> (mask, free, position of each node in free or -1, lu, piv, store, key)
        self._masks = {}
        #: ``(bound, rows)``: the friction rows of the last tangential step (:func:`~.uncoupled._friction_rows`)
        self.ncp = None
        self._factors = {}  # (with_load, mask bytes) -> the same, for the last few free sets (:meth:`_keep`)
        self.factorizations = 0  # LU factorizations of a reduced matrix (diagnostics)
        self.updates = 0  # directions solved by a Schur complement on an older factorization
        #: ``last``'s product was the whole ``A x`` (``True``), not the product over the columns where ``x ≠ 0``
        self.exact = not self.partial
        #: ``None``, or the list the factorizations made and the bordered solves on them are recorded in
        #: (:meth:`state`, :meth:`restore`: a resumed march rebuilds them as they were)
        self.events = None
        self._serial = 0  # the number of the next factorization (its ``_Store.id``)
        self.tag = None  # the recorder's name for the system (:mod:`rollqp.solverstate`)

    def ahat_product(self, x) -> np.ndarray:
        """``Â x``, ``Â = A·E*/L`` the nondimensional influence matrix (the normal step's starting guesses)."""
        return (self.A @ x) * self.a_scale

    @property
    def nbytes(self) -> int:
        """Bytes of the system's arrays: ``K`` (``K_nl`` is a view of it) and the kept factorizations."""
        return self.K.nbytes + sum(b[3].nbytes for b in self._factors.values())

    def mask(self, with_load):
        """The row-choice mask of an iteration (``n`` nodes, and the load row last, always true), one
        array per system reused by every iteration (:func:`~.uncoupled.iterate` sets the node rows)."""
        m = self._masks.get(with_load)
        if m is None:
            m = self._masks[with_load] = np.ones(self.fhat.size + with_load, dtype=bool)
        return m

    def matrices(self, with_load):
        """``K`` with or without the load column."""
        return self.K if with_load else self.K_nl

    @property
    def K_nl(self) -> np.ndarray:
        """``K`` without the load column: a view (its rows are ``K``'s with a stride of n + 1, which BLAS
        takes as it is: the products of a prescribed δ/ξ cost the same as on a contiguous copy, measured,
        and give the same numbers, without a second n × n array)."""
        if self._K_nl is None:
            self._K_nl = self.K[:, :-1]
        return self._K_nl

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
        """LU of the reduced matrix on the free set ``m`` (below), kept (:meth:`_keep`); ``None`` if singular."""
        self._make_room(8 * (np.count_nonzero(m) + with_load) ** 2)  # within the size of K also while it is built
        base = self._build(m, with_load)
        if base is not None:
            self._keep(base[6], base)
            if self.events is not None:
                self.events.append(("f", base[5].id, with_load, base[1]))
        return base

    def _build(self, m, with_load):
        """The factorization of :meth:`_factor`, not kept: ``(mask, free, pos, lu, piv, store, key)``."""
        n = self.fhat.size
        K = self.K
        free = np.flatnonzero(m)
        nf = free.size
        M = np.empty((nf + with_load, nf + with_load), order="F")
        # small n: two takes (np.ix_ costs 2.4× as much at 81 nodes); large n: np.ix_, without the
        # intermediate nf × n rows of the takes, a block of columns at a time (no second nf × nf array)
        if self.partial:
            for j in range(0, nf, FACTOR_COLUMNS):
                cols = free[j:j + FACTOR_COLUMNS]
                M[:nf, j:j + cols.size] = K[np.ix_(free, cols)]
        else:
            M[:nf, :nf] = K.take(free, 0).take(free, 1)
        if with_load:
            M[:nf, nf] = K[free, n]
            M[nf, :nf] = self.fhat[free]
            M[nf, nf] = 0.0
        if M.size:
            lu, piv, info = dgetrf(M, overwrite_a=True)
            if info != 0 or not np.isfinite(lu.diagonal()).all():
                return None
        else:
            lu, piv = M, np.empty(0, dtype=np.int32)
        pos = np.full(n, -1)
        pos[free] = np.arange(nf)
        self.factorizations += 1
        store = _Store(nf + with_load)
        store.id, self._serial = self._serial, self._serial + 1
        return (m.copy(), free, pos, lu, piv, store, (with_load, m.tobytes()))

    def _make_room(self, nbytes) -> None:
        """Drop the oldest kept factorizations until one more of ``nbytes`` fits (:meth:`_keep`'s limits): the
        same ones :meth:`_keep` would drop once it is kept, dropped before it is built, so that the matrix
        being factored and the kept factors never hold more than ``K`` does (at 2,561 nodes, 52 MB less peak)."""
        store = self._factors
        while store and (len(store) >= self.MAX_FACTORS or
                         sum(b[3].nbytes for b in store.values()) + nbytes > self.K.nbytes):
            store.pop(next(iter(store)))

    def _keep(self, key, base):
        """Keep the factorization ``base`` of the free set ``key`` (:data:`MAX_FACTORS`, within the size of ``K``):
        a free set that oscillates between a few sets from step to step (a stick/slip boundary node
        changing sides) then finds its factors again instead of refactoring."""
        store = self._factors
        store[key] = base
        while len(store) > self.MAX_FACTORS or (len(store) > 1 and sum(b[3].nbytes for b in store.values())
                                                 > self.K.nbytes):
            store.pop(next(iter(store)))

    def state(self) -> dict:
        """What identifies the kept factorizations (the numbers of :meth:`_factor`'s records, in :meth:`_keep`'s
        order; the last one used per ``with_load``) and the flags the next iteration reads."""
        base = {int(w): b[5].id for w, b in self._base.items() if b is not None}
        return {"kept": [b[5].id for b in self._factors.values()], "base": base, "settled": bool(self.settled),
                "exact": bool(self.exact), "serial": self._serial}

    def restore(self, state: dict, made: dict) -> None:
        """Rebuild the kept factorizations of :meth:`state`: ``made[id] = (with_load, free, borders)``, each the
        same LU of the same matrix, its store grown by the same bordered solves in the same order (so a
        resumed march solves its directions as the uninterrupted one did, bit for bit)."""
        n = self.fhat.size
        built = {}
        for fid in dict.fromkeys(state["kept"] + list(state["base"].values())):
            with_load, free, borders = made[fid]
            m = np.zeros(n, dtype=bool)
            m[free] = True
            base = self._build(m, with_load)
            if base is None:
                raise ValueError(f"the kept factorization {fid} is singular")
            base[5].id = fid
            K = self.K if with_load else self.K_nl
            for added, released in borders:
                added, released = np.asarray(added, dtype=np.intp), np.asarray(released, dtype=np.intp)
                if (np.any(m[added]) or not np.all(m[released]) or added.min(initial=0) < 0
                        or released.min(initial=0) < 0):  # (read from a file: nodes of this set's border)
                    raise ValueError(f"a recorded bordered solve on the kept factorization {fid} is not its border")
                grown = self._grow(K, base, added, released, np.zeros(base[1].size + with_load), with_load)
                if grown is None:
                    raise ValueError(f"a bordered solve on the kept factorization {fid} failed")
                store = base[5]
                store.products([store.rslot[a] for a in added.tolist()], [store.cslot[c] for c in grown[1]])
            built[fid] = base
        self._factors = {built[i][6]: built[i] for i in state["kept"]}
        self._base = {bool(int(w)): built[i] for w, i in state["base"].items()}
        self.settled, self.exact, self._serial = bool(state["settled"]), bool(state["exact"]), int(state["serial"])

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
        base, k = self._base.get(with_load), 0
        released = added = _NONE
        key = (with_load, m.tobytes())  # (comparing the bytes: a third of the time of m ^ m0 and .any())
        if base is not None:
            if key != base[6]:
                base = self._factors.get(key)  # this very set factored before: exact
                if base is None:
                    base = self._base[with_load]
                    changed = m ^ base[0]
                    released, added = np.flatnonzero(changed & base[0]), np.flatnonzero(changed & m)
                    k = released.size + added.size
                    if not self._borders(base, k):  # far from the last one: the nearest kept factorization?
                        base, released, added = self._nearest(m, with_load)
                        k = released.size + added.size
                        if not self._borders(base, k):
                            base, k = None, 0
                self._base[with_load] = base
        if base is None:
            base = self._factor(m, with_load)
            if base is None:
                return None
            self._base[with_load] = base
        if k == 0 and not self.partial:
            return self._on_factors(base, phi, with_load)
        m0, free0, pos0, lu, piv, store, _ = base
        notm = ~m
        d = np.empty(K.shape[1])
        pinned = notm.nonzero()[0]  # (the method: np.flatnonzero's wrapper costs as much again)
        d[pinned] = -phi[pinned]
        known = pinned if k == 0 else (notm & ~m0).nonzero()[0]  # pinned now and not in the factored set
        Ke = self._known_product(K, d, known, free0, added)
        nf0 = free0.size
        r0 = np.empty(nf0 + with_load)
        r0[:nf0] = -phi[free0] - Ke[free0]
        if with_load:
            r0[nf0] = -phi[n] - self.fhat[known] @ d[known]
        if nf0 + with_load == 0 and k == 0:
            return d
        if k:
            return self._bordered(K, phi, d, r0, Ke, base, added, released, with_load)
        u0, info = dgetrs(lu, piv, r0)
        if info != 0:
            return None
        d[free0] = u0[:nf0]
        if with_load:
            d[n] = u0[nf0]
        return d

    def _borders(self, base, k) -> bool:
        """Whether a free set ``k`` nodes away from the factorization ``base`` is solved on it, bordered
        (:data:`UPDATE_FRACTION`, :data:`UPDATE_MIN`, :data:`UPDATE_MIN_SIZE`), rather than factored anew."""
        return k <= max(self.UPDATE_MIN, self.UPDATE_FRACTION * base[1].size) and base[1].size >= self.UPDATE_MIN_SIZE

    def _nearest(self, m, with_load):
        """``(factorization, released, added)``: of the kept factorizations (:meth:`_keep`), the one whose free
        set differs least from ``m``, and the nodes it must release and add.

        A Newton iterate's free set can swing by hundreds of nodes and back within a step, so it is far
        from the set factored last but within a few nodes of the one factored at the same iterate of the
        previous step: bordered on that one instead of refactoring twice a step (measured in
        docs/performance.md, "Measured settings of the methods"). :meth:`direction` asks for it only
        where the last factorization is too far to border on (the iterates near it keep bordering on it)."""
        best, best_k = self._base[with_load], None
        for b in self._factors.values():
            if b[6][0] != with_load:
                continue
            k = int(np.count_nonzero(m ^ b[0]))
            if best_k is None or k < best_k:
                best, best_k = b, k
        changed = m ^ best[0]
        return best, np.flatnonzero(changed & best[0]), np.flatnonzero(changed & m)

    def _on_factors(self, base, phi, with_load):
        r"""The direction on the factored free set itself, below :data:`PARTIAL_MIN` nodes: the
        right-hand side of :meth:`direction`'s reduced system is

        .. math:: r = \begin{bmatrix} K_{FP} \\ \hat f_P^T \end{bmatrix} \Phi_P
                      - \begin{bmatrix} \Phi_F \\ \Phi_\lambda \end{bmatrix}

        (``d_P = −Φ_P`` on the pinned nodes ``P``), with the block ``[K_FP; f̂_Pᵀ]`` taken once per
        factorization: one product of ``|F| × |P|`` instead of the ``n × n`` one and a dozen
        indexing operations (at 81 nodes the step's direction in 6 instead of 9 µs)."""
        m0, free0, pos0, lu, piv, store, _ = base
        if store.block is None:
            pinned = np.flatnonzero(~m0)
            rows = np.append(free0, self.fhat.size) if with_load else free0  # the unknowns solved for
            B = np.empty((rows.size, pinned.size))
            B[:free0.size] = self.K.take(free0, 0).take(pinned, 1)
            if with_load:
                B[free0.size] = self.fhat[pinned]
            store.block = (pinned, rows, B)
        pinned, rows, B = store.block
        d = np.negative(phi)  # d_P = −Φ_P; the rows solved for are written below
        if rows.size == 0:
            return d
        phi_p = phi[pinned]
        r0 = B.dot(phi_p)  # (ndarray.dot: @'s numbers, a quarter of a microsecond less)
        r0 -= phi[rows]
        u0, info = dgetrs(lu, piv, r0, 0, 1)  # (trans = 0, overwrite_b: r0 is this solve's own; positional: cheaper)
        if info != 0:
            return None
        d[rows] = u0
        return d

    def _known_product(self, K, d, known, free0, added):
        """``K e`` with ``e = d`` on the ``known`` nodes and 0 elsewhere, on the rows the solve reads
        (``free0`` and ``added``; the others are left 0)."""
        n = self.fhat.size
        if known.size == 0:
            return np.zeros(n)
        e = np.zeros(K.shape[1])
        e[known] = d[known]
        if not self.partial:
            return K @ e
        Ke = np.zeros(n)
        rows = np.sort(np.concatenate((free0, added)))  # disjoint: added is outside the factored set
        Ke[rows] = partial_product(K, rows, e, known[e[known] != 0.0])
        return Ke

    def _bordered(self, K, phi, d, r0, Ke, base, added, released, with_load):
        """The direction on the factors of another free set, bordered by the rows and columns of
        the ``added`` and ``released`` nodes (:meth:`direction`; ``r0`` its right-hand side on the
        factored set); ``None`` if singular."""
        n = self.fhat.size
        m0, free0, pos0, lu, piv, store, _ = base
        nf0 = free0.size
        k = released.size + added.size
        grown = self._grow(K, base, added, released, r0, with_load)
        if grown is None:
            return None
        u0, keys = grown
        if self.events is not None:
            self.events.append(("b", store.id, added, released))
        na = added.size
        cs = [store.cslot[c] for c in keys]
        rs = [store.rslot[a] for a in added.tolist()]
        Z = store.Z[:, cs]
        S = np.empty((k, k))
        S[:na] = -store.products(rs, cs)
        S[na:] = -Z[pos0[released]]
        S[:na, :na] += K[np.ix_(added, added)]
        Cu0 = np.empty(k)
        Cu0[:na] = store.R[rs] @ u0
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

    def _grow(self, K, base, added, released, r0, with_load):
        """``(u0, keys)`` of :meth:`_bordered`: ``u0 = M0⁻¹ r0``, and the store of ``base`` grown by what this
        border needs (``keys``: its columns' keys); ``None`` if the solve fails."""
        n = self.fhat.size
        m0, free0, pos0, lu, piv, store, _ = base
        nf0 = free0.size
        # bordered solve on the old factors: Z = M0⁻¹ [B, E_R], S = [[D, 0], [0, 0]] − [C; E_Rᵀ] Z.
        # The columns of Z, the rows C of the added nodes and their products C Z are kept per node
        # (``store``): as the set drifts away from the factored one, each step adds a node or two,
        # and only theirs cost triangular solves and products. The solve for u0 = M0⁻¹ r0 takes the
        # new columns along (one pass over the factors).
        na = added.size
        keys = added.tolist() + [-1 - i for i in released.tolist()]
        missing = [c for c in keys if c not in store.cslot]
        W = np.zeros((nf0 + with_load, 1 + len(missing)), order="F")
        W[:, 0] = r0
        if missing:
            ma = np.array([c for c in missing if c >= 0], dtype=int)
            mr = np.array([-1 - c for c in missing if c < 0], dtype=int)
            order = ma.tolist() + [-1 - i for i in mr.tolist()]  # W's columns
            W[:nf0, 1:1 + ma.size] = K[np.ix_(free0, ma)]
            if with_load:
                W[nf0, 1:1 + ma.size] = self.fhat[ma]
            W[pos0[mr], 1 + ma.size + np.arange(mr.size)] = 1.0
        X, info = dgetrs(lu, piv, W)
        if info != 0:
            return None
        u0 = X[:, 0]
        if missing:
            store.add_columns(order, X[:, 1:])
        new_rows = [a for a in added.tolist() if a not in store.rslot]
        if new_rows:
            rows = np.empty((len(new_rows), nf0 + with_load))
            rows[:, :nf0] = K[np.ix_(new_rows, free0)]
            if with_load:
                rows[:, nf0] = K[new_rows, n]
            store.add_rows(new_rows, rows)
        return u0, keys


class _Store:
    """What the bordered solves of one factorization keep (:meth:`ReducedSystem._bordered`): the columns
    ``Z_c = M0⁻¹ w_c`` per key (an added node ``a >= 0``, a released node ``−1 − i``), the rows
    ``C_a = [K_{a,F0}, k_a]`` of the added nodes, and their products ``G = C Z``, each computed once."""

    def __init__(self, m):
        self.m = m
        self.id = -1  # the factorization's number (:meth:`ReducedSystem.state`)
        #: ``(pinned, rows, [K_FP; f̂_Pᵀ])`` of :meth:`ReducedSystem._on_factors`, made on first use
        self.block = None
        self.cslot, self.rslot = {}, {}
        self.Z = np.empty((m, 16), order="F")
        self.R = np.empty((16, m))
        self.G = np.empty((16, 16))
        self.filled = np.zeros(16, dtype=int)  # per row slot: the column slots of G computed

    def add_columns(self, keys, X):
        c0 = len(self.cslot)
        if c0 + len(keys) > self.Z.shape[1]:
            cap = 2 * (c0 + len(keys))
            Z = np.empty((self.m, cap), order="F")
            Z[:, :c0] = self.Z[:, :c0]
            self.Z = Z
            G = np.empty((self.G.shape[0], cap))
            G[:, :c0] = self.G[:, :c0]
            self.G = G
        self.Z[:, c0:c0 + len(keys)] = X
        for j, c in enumerate(keys):
            self.cslot[c] = c0 + j

    def add_rows(self, nodes, rows):
        r0 = len(self.rslot)
        if r0 + len(nodes) > self.R.shape[0]:
            cap = 2 * (r0 + len(nodes))
            R = np.empty((cap, self.m))
            R[:r0] = self.R[:r0]
            self.R = R
            G = np.empty((cap, self.G.shape[1]))
            G[:r0] = self.G[:r0]
            self.G = G
            self.filled = np.concatenate([self.filled, np.zeros(cap - self.filled.size, dtype=int)])
        self.R[r0:r0 + len(nodes)] = rows
        self.filled[r0:r0 + len(nodes)] = 0
        for j, a in enumerate(nodes):
            self.rslot[a] = r0 + j

    def products(self, rs, cs):
        """``G[rs][:, cs] = C Z``, the missing entries computed first."""
        nc = len(self.cslot)
        rs = np.asarray(rs, dtype=int)
        lag = rs[self.filled[rs] < nc]
        if lag.size:
            c0 = int(self.filled[lag].min())
            self.G[np.ix_(lag, np.arange(c0, nc))] = self.R[lag] @ self.Z[:, c0:nc]
            self.filled[lag] = nc
        return self.G[np.ix_(rs, cs)]


@dataclass
class CoupledSystem:
    """The r-scaled linear parts of the coupled step, ``y_N = K_N z + k_N``, ``y_T = K_T z + k_T`` (eq. 63–64).

    ``z = (p̂, t̂, δ̂?, ξ̂?)`` of length ``N``; ``iP``/``iQ`` the indices of ``δ̂``/``ξ̂`` (``None``:
    prescribed); ``J0`` the identity and load rows of the pseudo-Jacobian; ``rN``, ``rT`` the
    augmentations; ``dqh = Δq/a_H``. Per step only the vectors change (:func:`coupled_vectors`).
    """

    N: int
    iP: int | None
    iQ: int | None
    KN: np.ndarray
    KT: np.ndarray
    J0: np.ndarray
    fhat: np.ndarray
    rN: float
    rT: float
    dqh: float
    factors: dict = field(default_factory=dict, repr=False)


def coupled_system(pb, r) -> CoupledSystem:
    """The :class:`CoupledSystem` of a :class:`~rollqp.problem.CoupledStep` (``r``: the method's
    augmentation, or ``None`` for the default ``1/mean(diag Â)``, ``Δq̂/mean(diag Â)``)."""
    sc = pb.scales
    n = pb.n
    m = sc.modulus / sc.length
    dqh = pb.dq / sc.length
    Ann, Att = pb.Ann.dense() * m, pb.Att.dense() * m
    sN, sT = float(np.mean(np.diag(Ann))), float(np.mean(np.diag(Att)))
    if not (sN > 0 and sT > 0):
        raise InputError("A", "the influence matrices must have a positive mean diagonal")
    rN = r if r is not None else 1.0 / sN
    rT = r if r is not None else dqh / sT
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
    return CoupledSystem(N=N, iP=iP, iQ=iQ, KN=KN, KT=KT, J0=J0, fhat=fhat, rN=rN, rT=rT, dqh=dqh)


def coupled_vectors(S: CoupledSystem, pb):
    """``(k_N, k_T)`` of one step: the gap and history terms, and the prescribed ``δ``/``ξ``."""
    sc = pb.scales
    u0 = sc.displacement
    kN = S.rN * (pb.h / u0 - (pb.delta / u0 if pb.delta is not None else 0.0))
    kT = S.rT * (pb.c / u0 / S.dqh + (pb.xi / sc.slip if pb.xi is not None else 0.0))
    return kN, kT


class CoupledFactors:
    r"""LU factors of one coupled pseudo-Jacobian ``J_f``, reused for nearby ones (Woodbury).

    The rows of the coupled ``J`` (:func:`~.ncp.coupled_jacobian`) take one of a few
    kinds per node: the ``p̂_i`` row is ``K_N`` (contact) or ``e_i`` (separated); the ``t̂_i``
    row is ``K_T`` (stick), ``e_{n+i} − σμ(e_i − K_N)`` (slip, ``σ = ±1``) or ``e_{n+i}`` (zero
    bound); the load rows never change. ``J_f`` is factored on its free rows only (the reduced
    system of :func:`direct_coupled_direction`, identity rows eliminated), which is a
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
                 "factorizations", "updates", "rejected", "scale", "events", "tag")

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
    #: (:func:`direct_coupled_direction`): the bookkeeping costs more than the LU.
    #: Measured (same scene, direct / updated): 41 nodes 0.28 / 0.44 ms, 81 nodes 0.54 /
    #: 0.60 ms, 101 nodes 0.72 / 0.70 ms, 121 nodes 0.94 / 0.78 ms.
    DIRECT_BELOW = 200
    #: Largest condition number of the capacitance matrix accepted.
    MAX_CONDITION = 1e8
    #: Largest accepted ‖J d + Φ‖∞ / (‖Φ‖∞ + ‖J‖∞‖d‖∞) of an updated direction (round-off is ~1e-15).
    MAX_RESIDUAL = 1e-10

    def __init__(self, S):
        self.S, self.n, self.N = S, S.KN.shape[0], S.N
        self.kind = None
        self.mu = None
        self.factorizations = self.updates = self.rejected = 0
        #: ``None``, or the list the factorizations and the batches of kept columns are recorded in
        #: (:meth:`state`, :meth:`restore`), and the recorder's name for them (:mod:`rollqp.solverstate`)
        self.events, self.tag = None, None
        self.scale = 1.0 + max(float(np.max(np.sum(np.abs(S.KN), axis=1))),
                               float(np.max(np.sum(np.abs(S.KT), axis=1))))

    @staticmethod
    def kinds(S, contact, stick, slip_sign):
        """Row kind codes (length ``N``): p rows 0 identity / 1 ``K_N``; t rows 0 identity /
        2 ``K_T`` / 3 slip σ = +1 / 4 slip σ = −1; load rows 5."""
        n = contact.size
        k = np.full(S.N, 5, dtype=np.int8)
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
                out[w] = S.KN[r]
            elif code == 2:
                out[w] = S.KT[r - n]
            elif code == 5:
                out[w] = S.J0[r]
            else:  # slip, σ = +1 (3) or −1 (4)
                i = r - n
                out[w] = slip_rows(S.KN, i, np.full(i.size, (1.0 if code == 3 else -1.0) * mu))
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
                if self.events is not None:
                    self.events.append(("F", None, None))
                return False
            self.lu, self.piv = lu, piv
        if self.events is not None:
            self.events.append(("F", kind, mu))
        return True

    def restore(self, factored) -> None:
        """Factor again as recorded: ``factored = (kind, mu, batches)``, the row kinds and ``μ`` of the last
        factorization (``kind`` ``None``: none) and the batches of columns kept on it since, in order (each
        batch solved together, as it was: the same columns, bit for bit)."""
        kind, mu, batches = factored
        events, self.events = self.events, None  # (not recorded again)
        try:
            if kind is None:
                self.kind = None
                return
            if not self._factor(np.asarray(kind, dtype=np.int8), mu):
                raise ValueError("the recorded coupled factorization is singular")
            for batch in batches:
                if self._columns(np.asarray(batch, dtype=np.intp)) is None:
                    raise ValueError("a recorded batch of coupled columns failed")
        finally:
            self.events = events

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
            if self.events is not None:
                self.events.append(("C", miss))
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
            d = direct_coupled_direction(S, contact, stick, slip_sign, mu, phi)
            return None if d is None else (d, S.KN @ d, S.KT @ d)
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
            return None if d is None else (d, S.KN @ d, S.KT @ d)
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
            dN, dT = S.KN @ d, S.KT @ d
            if self._residual(kind, d, dN, dT, phi) <= self.MAX_RESIDUAL * (
                    np.max(np.abs(phi)) + self.scale * np.max(np.abs(d))):
                self.updates += 1
                return d, dN, dT
        self.rejected += 1  # refactor at this J: the direct path's direction
        if not self._factor(kind, mu):
            return None
        d = self._solve(-phi)
        return None if d is None else (d, S.KN @ d, S.KT @ d)

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
            Jd[loads] = S.J0[loads] @ d
        r = Jd + phi
        return float(np.max(np.abs(r))) if np.all(np.isfinite(r)) else np.inf



def direct_coupled_direction(S, contact, stick, slip_sign, mu, phi):
    """The coupled Newton direction, ``J d = −Φ`` on the free unknowns only (eq. 80).

    The rows of :meth:`_coupled_jacobian` for ``p̂_i`` of a separated node and for ``t̂_i`` of
    a node with a zero bound are identity rows, so ``d = −Φ`` there; the rest (contact
    pressures, tractions under a positive bound, ``δ̂``, ``ξ̂``) is assembled directly,
    row by row, and solved (LAPACK ``gesv``). Returns ``None`` if it is singular. The
    reference path (``coupled_reuse = False``) and :class:`CoupledFactors`' solve on small
    systems; otherwise the iteration reuses factorizations (:class:`CoupledFactors`).
    """
    n = contact.size
    KN, KT = S.KN, S.KT
    ic = np.flatnonzero(contact)
    it_ = np.flatnonzero(stick | (slip_sign != 0))  # t rows that are not identity rows
    loads = np.array([k for k in (S.iP, S.iQ) if k is not None], dtype=int)
    free = np.concatenate([ic, n + it_, loads])
    pinned = np.concatenate([np.flatnonzero(~contact), n + np.flatnonzero(~stick & (slip_sign == 0))])
    R = np.empty((free.size, S.N))
    R[:ic.size] = KN[ic]
    st = stick[it_]
    rows = np.empty((it_.size, S.N))
    rows[st] = KT[it_[st]]
    isl = it_[~st]
    if isl.size:
        rows[~st] = slip_rows(KN, isl, slip_sign[isl] * mu)
    R[ic.size:ic.size + it_.size] = rows
    R[ic.size + it_.size:] = S.J0[loads]
    d = np.empty(S.N)
    d[pinned] = -phi[pinned]
    rhs = -phi[free] - R[:, pinned] @ d[pinned]
    if free.size:
        _, _, x, fail = dgesv(np.asfortranarray(R[:, free]), rhs, overwrite_a=True, overwrite_b=True)
        if fail != 0:
            return None
        d[free] = x
    return d

