r"""Half-space influence on a uniform strip as a (block-)Toeplitz product by FFT, never a matrix (docs/matrix-free.md).

On the uniform strip of :class:`rollqp.strip.Strip` every collocation matrix of
:mod:`rollqp.influence.halfspace` (eq. 25–30) has the form

.. math::

    M[i, j] = \sum_{a} \sum_{e:\ \mathrm{conn}[e, a] = j} P_a[i - r e - k_{min}],
    \qquad \mathrm{conn}[e, a] = r e + a

with ``r = 1`` (constant, linear) or ``2`` (quadratic), ``a`` the local node of an element and
``P_a`` a generating vector of ``n - k_min = n + r(n_e - 1)`` values: the reference moments of
the kernel at the ``O(n)`` distinct offsets times the half-length
(:func:`~rollqp.influence.kernels.element_offsets`). Constant elements give a Toeplitz
matrix, linear ones a Toeplitz matrix with two boundary columns, quadratic ones a 1×2 block
Toeplitz matrix (even and odd columns). Hence

* ``M x = Σ_a P_a ∗ u_a`` with ``u_a[r e] = x[conn[e, a]]``: one real FFT of length
  ``≈ 2n`` per local node and one inverse FFT (a non-periodic, exact linear convolution: the
  circular wrap-around falls on indices that are not kept), ``O(n log n)`` time and ``O(n)``
  memory; ``xᵀ M`` is the correlation, by the same transforms;
* the dense matrix (:func:`assemble`) is built row block by row block from strided views of the
  ``P_a``: the same products, added in the same order, as the general assembly, so the
  matrices are bitwise those of the element-by-element path, at ``O(n)`` kernel evaluations.

:class:`ToeplitzOperator` is an :class:`~rollqp.influence.operator.Operator` without a stored
matrix (``@``, ``x @ A``, ``diagonal()``, ``dense()``, ``memo``); :func:`halfspace_operators`
builds ``A_nn = A_tt`` and the coupling ``A_nt``, ``A_tn`` (eq. 26, 29) of a scene with it.
"""
from __future__ import annotations

import numpy as np
from numpy.lib.stride_tricks import as_strided

from ..errors import InputError
from .kernels import assemble_elements, element_offsets, lattice_offsets, log_moments, sgn_moments
from .operator import Operator
from ..strip import Strip

__all__ = ["kernel_moments", "elementwise", "generators", "assemble", "ToeplitzOperator", "log_operator", "sgn_operator",
           "halfspace_operators", "positive_definite_threshold"]

#: Rows per block of the dense assembly (bounds its temporaries to a few MB).
_ROWS = 256


def kernel_moments(kernel: str):
    """The reference moments of ``kernel`` (``"log"``: eq. 26's ``ln|ξ − ξ_i|``, ``"sgn"``: eq. 29's
    ``sgn(ξ_i − ξ)``), the ``moments`` argument of :func:`generators` and :func:`elementwise`."""
    try:
        return {"log": log_moments, "sgn": sgn_moments}[kernel]
    except KeyError:
        raise InputError("kernel", f"must be 'log' or 'sgn', got {kernel!r}") from None


def elementwise(strip, moments) -> np.ndarray:
    """The matrix of the general (node, element) gather on the lattice offsets: the reference
    that :func:`assemble` reproduces bitwise (tests)."""
    return assemble_elements(strip, moments, element_offsets(strip, True))


def generators(strip, moments, lattice=None):
    """``(P, r)``: the generating vectors ``P[a] = hl · (moments(values) @ coef.T)[:, a]`` of a lattice strip.

    ``moments`` is ``kernels.log_moments`` or ``sgn_moments``, ``lattice`` the result of
    :func:`~rollqp.influence.kernels.lattice_offsets` (computed if ``None``); ``P`` has shape
    ``(nen, n - k_min)`` with ``k_min = -r (n_e - 1)``. A strip that is not a uniform lattice is
    an :class:`InputError` on ``strip``.
    """
    lattice = lattice_offsets(strip) if lattice is None else lattice
    if lattice is None:
        raise InputError("strip", "nodes are not a uniform lattice (the FFT operator needs one)")
    values, _, hl = lattice
    conn = np.asarray(strip.connectivity)
    ne, nen = conn.shape
    r = int(conn[1, 0] - conn[0, 0]) if ne > 1 else 1
    if not np.array_equal(conn, r * np.arange(ne)[:, None] + np.arange(nen)[None, :]):
        raise InputError("strip", "the connectivity is not that of a uniform lattice")
    coef = np.asarray(strip.coefficients, dtype=float)
    local = moments(values) @ coef.T                          # (n_values, nen)
    P = np.ascontiguousarray((local * hl).T)                   # products as in _assemble
    return P, r


def _views(P, r, n, ne):
    """``V[a][i, e] = P[a][i - r e - k_min]`` as strided views (no copy)."""
    kmin = -r * (ne - 1)
    out = []
    for a in range(P.shape[0]):
        base = P[a, -kmin:]                                    # element i - k_min at e = 0
        out.append(as_strided(base, shape=(n, ne), strides=(base.strides[0], -r * base.strides[0]),
                              writeable=False))
    return out


def assemble(P, r, n, ne) -> np.ndarray:
    """The dense ``M`` (C order) from the generating vectors: ``M[:, a + r e] += P_a[i - r e - k_min]``.

    Row blocks of :data:`_ROWS`; for each local node ``a`` in order, the strided columns
    ``a, a + r, …`` receive the strided view of ``P_a``: the operations of the general
    assembly, so the result is bitwise the same (``O(n²)`` writes, no ``n × n`` temporary).
    """
    M = np.zeros((n, n))
    views = _views(P, r, n, ne)
    for i0 in range(0, n, _ROWS):
        i1 = min(n, i0 + _ROWS)
        for a, V in enumerate(views):
            M[i0:i1, a:a + r * (ne - 1) + 1:r] += V[i0:i1]
    return M


class ToeplitzOperator(Operator):
    """A read-only ``n × n`` (block-)Toeplitz influence operator applied by FFT (module docstring).

    Parameters
    ----------
    P : ndarray, shape (nen, n - k_min)
        Generating vectors (:func:`generators`), times ``scale``.
    r : int
        Node stride of the elements (1 or 2).
    n, ne : int
        Nodes and elements.
    name : str
        The scene key named in errors.
    """

    #: numpy defers ``x @ op`` to :meth:`__rmatmul__` (instead of converting the operator to an array)
    __array_ufunc__ = None

    def __init__(self, P, r: int, n: int, ne: int, name: str = "influence"):
        P = np.array(P, dtype=float)
        if not np.all(np.isfinite(P)):
            raise InputError(name, "must be finite")
        P.flags.writeable = False
        self._P, self._r, self._n, self._ne = P, int(r), int(n), int(ne)
        self._spectra()
        self.name = name
        self._memo = {}
        self._m = None

    # ------------------------------------------------------------------ the matrix interface
    @property
    def shape(self) -> tuple[int, int]:
        return (self._n, self._n)

    @property
    def n(self) -> int:
        return self._n

    @property
    def kmin(self) -> int:
        return -self._r * (self._ne - 1)

    def scaled(self, c: float, name: str | None = None) -> "ToeplitzOperator":
        """``c`` times this operator (a new operator)."""
        return ToeplitzOperator(c * self._P, self._r, self._n, self._ne, name or self.name)

    def _spectra(self):
        r"""The transforms of one product (:meth:`matvec`): one forward and one inverse FFT of length ``L``.

        With ``j = r e + a`` the product is ``y[i] = Σ_a Σ_{j ∈ J_a} P_a[i − k_min − j + a] x[j]``,
        ``J_a = {a, a + r, …, a + r(n_e − 1)}``. Extended to every node ``j ≡ a`` (mod ``r``) it is, per
        residue ``ρ``, a convolution of ``x`` restricted to the nodes ``j ≡ ρ`` with the kernel ``K_ρ[m] =
        Σ_{a ≡ ρ} P_a[m + a]``, ``K̂_ρ(ω) = Σ_{a ≡ ρ} e^{iωa} P̂_a(ω)``; the nodes the extension adds (the
        one or two end nodes that an element's local node ``a`` never reaches) are subtracted again,
        ``O(n)`` each (:attr:`_ends`). For ``r = 2`` the two residues come from one transform of ``x``:
        ``X_ρ(ω) = (X(ω) ± X(ω + π))/2`` and ``X(ω + π)`` is the half-spectrum reversed and conjugated (``L``
        even), so ``Ŷ = A X + B conj(X reversed)`` with ``A = (K̂_0 + K̂_1)/2``, ``B = (K̂_0 − K̂_1)/2``. ``L``
        is a fast length (``scipy.fft.next_fast_len``) of at least ``2n − 1`` and ``n − k_min + r``: the
        circular wrap-around of the shifted kernels then falls on indices that are not kept, and the
        product is the exact linear convolution (docs/matrix-free.md, "The operator").
        """
        import scipy.fft  # here: the dense assembly (generators, assemble) needs no scipy.fft
        P, r, n, ne = self._P, self._r, self._n, self._ne
        nen, lp = P.shape
        L = scipy.fft.next_fast_len(max(2 * n - 1, lp + r), real=True)
        while L % 2:
            L = scipy.fft.next_fast_len(L + 1, real=True)
        self._L = L
        Phat = scipy.fft.rfft(P, n=L, axis=1)
        w = np.exp(2j * np.pi * np.arange(L // 2 + 1) / L)
        K = [sum(Phat[a] * w ** a for a in range(nen) if a % r == rho) for rho in range(r)]
        if r == 1:
            self._AB = (K[0], None)
        else:
            self._AB = (0.5 * (K[0] + K[1]), 0.5 * (K[0] - K[1]))
        kept = np.arange(n) - self.kmin                           # the kept indices of the convolution
        ends = []
        for a in range(nen):                                      # nodes j ≡ a (mod r) that J_a misses
            every = np.arange(a % r, n, r)
            for j in np.setdiff1d(every, a + r * np.arange(ne)):
                k = (kept - j) % L                                # the circular kernel index of Q_a = P_a[· + a]
                k = np.where(k > lp - 1 - a, k - L, k) + a
                ends.append((int(j), np.where((k >= 0) & (k < lp), P[a, np.clip(k, 0, lp - 1)], 0.0)))
        self._ends = ends

    def matvec(self, x):
        """``M x`` (eq. 25, 28) by one zero-padded forward FFT and one inverse (:meth:`_spectra`): exact linear
        convolution, ``O(n log n)``."""
        x = np.asarray(x, dtype=float)
        import scipy.fft  # here: the dense assembly (generators, assemble) needs no scipy.fft
        L, (A, B) = self._L, self._AB
        X = scipy.fft.rfft(x, n=L, axis=0)
        if x.ndim > 1:
            A, B = A[:, None], (None if B is None else B[:, None])
        Y = A * X if B is None else A * X + B * np.conj(X[::-1])
        y = scipy.fft.irfft(Y, n=L, axis=0)[-self.kmin:-self.kmin + self._n]
        for j, v in self._ends:
            y -= v * x[j] if x.ndim == 1 else np.outer(v, x[j])
        return y

    def rmatvec(self, y):
        """``yᵀ M`` (``Mᵀ y``): the correlation of ``y`` with the kernels of :meth:`_spectra`, by one forward and
        one inverse FFT (the residues of ``r = 2`` recombined as in :meth:`matvec`), less the end nodes."""
        y = np.asarray(y, dtype=float)
        import scipy.fft  # here: the dense assembly (generators, assemble) needs no scipy.fft
        L, (A, B), off = self._L, self._AB, -self.kmin
        pad = np.zeros((L,) + y.shape[1:])
        pad[off:off + self._n] = y
        Yh = scipy.fft.rfft(pad, axis=0)
        if y.ndim > 1:
            A, B = A[:, None], (None if B is None else B[:, None])
        W = np.conj(A) * Yh if B is None else np.conj(A) * Yh + (B * np.conj(Yh))[::-1]
        out = scipy.fft.irfft(W, n=L, axis=0)[:self._n]
        for j, v in self._ends:
            out[j] -= v @ y
        return out

    def dense(self) -> np.ndarray:
        """The matrix, assembled once from the generating vectors (``O(n²)`` memory; kept)."""
        if self._m is None:
            m = assemble(self._P, self._r, self._n, self._ne)
            m.flags.writeable = False
            self._m = m
        return self._m

    def diagonal(self) -> np.ndarray:
        """``M[i, i]`` (``O(n)``): :meth:`entries` on the diagonal."""
        i = np.arange(self._n)
        return self.entries(i, i)

    def column(self, j: int) -> np.ndarray:
        """Column ``j`` of the matrix (``O(n)``): for preconditioners."""
        return self.entries(np.arange(self._n), np.full(self._n, int(j)))

    def entries(self, i, j) -> np.ndarray:
        """``M[i, j]`` for index arrays ``i``, ``j`` (``O(len)``): ``Σ_a P_a[i − r e − k_min]`` over the local
        nodes ``a`` with ``j = r e + a`` (the diagonal, a column, the diagonal of a product)."""
        i, j = np.asarray(i, dtype=int), np.asarray(j, dtype=int)
        out = np.zeros(np.broadcast(i, j).shape)
        for a in range(self._P.shape[0]):
            e = (j - a) // self._r
            ok = ((j - a) % self._r == 0) & (e >= 0) & (e < self._ne)
            out += np.where(ok, self._P[a, np.where(ok, i - self._r * e - self.kmin, 0)], 0.0)
        return out

    def __matmul__(self, x):
        return self.matvec(x)

    def __rmatmul__(self, x):
        return self.rmatvec(x)

    def __array__(self, dtype=None, copy=None):
        m = self.dense()
        return m if dtype is None else m.astype(dtype, copy=False)

    def __repr__(self) -> str:
        return f"ToeplitzOperator({self.name!r}, n={self.n}, r={self._r})"

    @property
    def nbytes(self) -> int:
        """Bytes held (generators and their transforms; the dense matrix if it was asked for)."""
        spectra = sum(0 if v is None else v.nbytes for v in self._AB) + sum(v.nbytes for _, v in self._ends)
        return int(self._P.nbytes + spectra + (0 if self._m is None else self._m.nbytes))


def log_operator(strip, d_ref: float, scale: float = 1.0, name: str = "influence") -> ToeplitzOperator:
    """``scale · K`` of :func:`~rollqp.influence.halfspace.log_kernel_matrix` as an FFT operator.

    The rigid term ``ln(d_ref/hl) hl ∫N_a`` of every column (``K(d') = K(d) + ln(d'/d) e fᵀ``)
    is folded into the generating vectors: each ``P_a`` gets the constant
    ``hl ln(d_ref/hl) ∫_{-1}^{1} N_a dξ``.
    """
    P, r = generators(strip, log_moments)
    hl = 0.5 * strip.element_length
    coef = np.asarray(strip.coefficients, dtype=float)
    w_ref = 2.0 * coef[:, 0] + 2.0 * coef[:, 2] / 3.0
    G = -P + (hl * np.log(d_ref / hl) * w_ref)[:, None]
    conn = np.asarray(strip.connectivity)
    op = ToeplitzOperator(scale * G, r, strip.n, conn.shape[0], name)
    op.strip = strip
    op.coarsen = lambda ne: _coarse_log(strip, ne, d_ref, scale, name)
    return op


def _coarse_log(strip, ne: int, d_ref: float, scale: float, name: str):
    """``(coarse strip, its log operator)``: the same kernel on ``ne`` elements of the same zone
    (a coarse model of the same problem, for the cold start of :mod:`rollqp.methods.krylov`)."""
    coarse = Strip(float(strip.half_width), int(ne), strip.element)
    return coarse, log_operator(coarse, d_ref, scale, name)


def sgn_operator(strip, scale: float = 1.0, name: str = "influence") -> ToeplitzOperator:
    """``scale · S`` of :func:`~rollqp.influence.halfspace.sgn_kernel_matrix` as an FFT operator."""
    P, r = generators(strip, sgn_moments)
    return ToeplitzOperator(scale * P, r, strip.n, np.asarray(strip.connectivity).shape[0], name)


def positive_definite_threshold(strip, rtol: float = 1e-10, maxiter: int | None = None) -> float:
    """Smallest admissible ``d_ref`` of the discretization, matrix-free (cf. ``minimum_reference_distance``).

    ``sym(F K(d)) = B + τ f fᵀ`` with ``B = sym(F K(4L))`` positive definite and
    ``τ = ln(d/4L)``: positive definite exactly for ``d > 4L exp(-1/(fᵀB⁻¹f))``
    (``halfspace._threshold``). ``B⁻¹f`` by conjugate gradients on FFT products.
    """
    import scipy.sparse.linalg as spla
    L = float(strip.half_width)
    d0 = 4.0 * L
    K = log_operator(strip, d0)
    f = np.asarray(strip.weights, dtype=float)
    n = f.size

    def mv(x):
        return 0.5 * (f * K.matvec(x) + K.rmatvec(f * x))

    op = spla.LinearOperator((n, n), matvec=mv, dtype=float)
    y, info = spla.cg(op, f, rtol=rtol, atol=0.0, maxiter=maxiter or 20 * n)
    if info != 0:
        return float("nan")
    q = float(f @ y)
    return float(d0 * np.exp(-1.0 / q)) if q > 0 else float("nan")


def halfspace_operators(strip, *, Estar: float, beta: float, d_ref: float, coupling: str):
    """``(A_nn, A_tt, A_tn, A_nt)`` of :func:`~rollqp.influence.halfspace.halfspace_influence` as FFT operators.

    ``A_nn = A_tt = (2/(πE*)) K``, ``A_nt = (β/E*) S`` (full coupling), ``A_tn = −(β/E*) S``
    (full or Goodman); ``coupling`` already resolved (no ``"auto"``).
    """
    Ann = log_operator(strip, d_ref, 2.0 / (np.pi * Estar))
    Atn = Ant = None
    if coupling in ("full", "goodman"):
        S = sgn_operator(strip)
        Atn = S.scaled(-beta / Estar)
        if coupling == "full":
            Ant = S.scaled(beta / Estar)
    return Ann, Ann, Atn, Ant
