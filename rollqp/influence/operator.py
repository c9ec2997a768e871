r"""Influence operators: an ``n × n`` influence matrix, validated once, read-only, with a memo.

A step problem's influence (``A_nn``, ``A_tt``, ``A_nt``, ``A_tn``, or the steady slip operators
``Δ·d·D_up·A``; docs/formulation.md §3–4) is an :class:`Operator`. It is checked (square,
finite) when it is made and cannot change afterwards, so step problems built on it — every
step of a scene, every half of an N–T alternation — skip the ``O(n²)`` check, and what methods
derive from it (the symmetric–skew splitting of ``F·A``, scaled copies, Hessians) is computed
once and kept in the operator's :meth:`~Operator.memo`, which lives as long as the operator:
a scene's :class:`~rollqp.operators.SceneOperators`, or one user problem.

The interface is the part of a matrix that the methods use — ``A @ x``, ``x @ A``,
``A.shape``, ``A.diagonal()``, ``A.dense()`` — so that an operator without a stored matrix
(a Toeplitz product by FFT) can stand in for this dense one.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError

__all__ = ["Operator", "Split", "as_operator", "asymmetry", "split"]


class Operator:
    """A read-only ``n × n`` influence operator stored as a dense matrix.

    Parameters
    ----------
    matrix : array_like, shape (n, n)
        The influence coefficients. A writeable array is copied, so that the operator cannot
        change behind its memo; a read-only one (rollqp's own influence builders return
        read-only arrays) is kept as it is.
    name : str
        The argument or scene key named in errors (``"A"``, ``"Ann"``, ``"influence"``).

    Raises
    ------
    InputError
        ``name`` if the matrix is not square or not finite.
    """

    __slots__ = ("_m", "name", "_memo")

    def __init__(self, matrix, name: str = "A"):
        a = np.asarray(matrix, dtype=float)
        if a.ndim != 2 or a.shape[0] != a.shape[1]:
            raise InputError(name, f"must be a square matrix, got shape {a.shape}")
        if not np.all(np.isfinite(a)):
            raise InputError(name, "must be finite")
        if a.flags.writeable:
            a = a.copy()
            a.flags.writeable = False
        self._m = a
        self.name = name
        self._memo: dict = {}

    # ------------------------------------------------------------------ the matrix interface
    @property
    def shape(self) -> tuple[int, int]:
        return self._m.shape

    @property
    def n(self) -> int:
        return self._m.shape[0]

    def dense(self) -> np.ndarray:
        """The matrix (read-only)."""
        return self._m

    def diagonal(self) -> np.ndarray:
        return np.diagonal(self._m)

    def __matmul__(self, x):
        return self._m @ x

    def __rmatmul__(self, x):
        return x @ self._m

    def __array__(self, dtype=None, copy=None):
        if copy:
            return np.array(self._m, dtype=dtype)
        return self._m if dtype is None else self._m.astype(dtype, copy=False)

    def __repr__(self) -> str:
        return f"Operator({self.name!r}, n={self.n})"

    # ------------------------------------------------------------------ derived data
    def memo(self, key, build):
        """``build()`` computed once per ``key`` and kept with this operator.

        What a method derives from the operator alone (with the weights, scales and step
        length in ``key``) goes here; solver state that changes from step to step does not.
        """
        try:
            return self._memo[key]
        except KeyError:
            value = self._memo[key] = build()
            return value

    def split(self, f: np.ndarray) -> "Split":
        """The symmetric–skew splitting of ``F·A`` for the weights ``f`` (:func:`split`), kept."""
        f = np.asarray(f, dtype=float)
        return self.memo(("split", f.tobytes()), lambda: split(self, f))


def as_operator(A, name: str = "A", n: int | None = None) -> Operator:
    """``A`` if it is an :class:`Operator` of size ``n``, else a new, validated one."""
    op = A if isinstance(A, Operator) else Operator(A, name)
    if n is not None and op.shape != (n, n):
        raise InputError(name, f"must have shape ({n}, {n}), got {op.shape}")
    return op


@dataclass(frozen=True)
class Split:
    r"""``F A = F A_sym + F A_skew`` with ``F A_sym`` symmetric and ``F A_skew`` skew (docs/formulation.md §8).

    ``asymmetry = ‖FA − (FA)ᵀ‖_F / ‖FA‖_F``; ``sym = F⁻¹ sym(F A)`` (an :class:`Operator`: the
    operator whose weighted form is the QP Hessian) and ``skew = F⁻¹ skew(F A)``. For an exactly
    symmetric ``F A`` (constant elements on a uniform strip) ``sym`` is the operator itself.
    """

    asymmetry: float
    sym: Operator
    skew: np.ndarray


def asymmetry(A, f, sign: float = 1.0) -> float:
    """``‖FA − (FA)ᵀ‖_F / ‖FA‖_F`` with ``F = diag(f)``: how far the QP Hessian's source is from symmetric.

    ``A`` an operator or a matrix, ``f`` the weights (a vector, or ``diag(f)``). Zero for a zero ``A``.
    ``sign = -1`` measures the defect from antisymmetry, ``‖FA + (FA)ᵀ‖_F / ‖FA‖_F``. Above 512
    rows the norms are accumulated over row blocks (no ``n × n`` temporary).
    """
    f = np.asarray(f, dtype=float)
    f = np.diagonal(f) if f.ndim == 2 else f
    M = np.asarray(A, dtype=float)
    n = M.shape[0]
    if n <= 512:
        FA = f[:, None] * M
        norm = np.linalg.norm(FA)
        return float(np.linalg.norm(FA - sign * FA.T) / norm) if norm > 0 else 0.0
    num = den = 0.0
    b = 256
    for i0 in range(0, n, b):
        i1 = min(n, i0 + b)
        rows = f[i0:i1, None] * M[i0:i1]
        den += float(np.einsum("ij,ij->", rows, rows))
        for j0 in range(i0, n, b):   # the pair of blocks (i, j) and (j, i), each read along its rows
            j1 = min(n, j0 + b)
            d = rows[:, j0:j1] - sign * (f[j0:j1, None] * M[j0:j1, i0:i1]).T
            num += float(np.einsum("ij,ij->", d, d)) * (1.0 if j0 == i0 else 2.0)
    return float(np.sqrt(num / den)) if den > 0 else 0.0


def split(A, f: np.ndarray) -> Split:
    """The symmetric–skew splitting of ``F A`` (:class:`Split`); ``A`` an operator or a matrix."""
    op = as_operator(A)
    M = op.dense()
    f = np.asarray(f, dtype=float)
    FA = f[:, None] * M
    skew = 0.5 * (FA - FA.T)
    norm = np.linalg.norm(FA)
    asym = float(np.linalg.norm(skew) * 2 / norm) if norm > 0 else 0.0
    if asym > 0:
        sym = Operator((FA - skew) / f[:, None], f"sym({op.name})")
    else:
        sym = op
    skew_op = skew / f[:, None]
    skew_op.flags.writeable = False
    return Split(asym, sym, skew_op)
