r"""The 3D tangential Newton direction through the inverse of the operator's contact block
(Sherman–Morrison–Woodbury; docs/theory3d.md §7).

On the traction rows the Newton matrix of eq. 3D.26 is ``J = (I − M) + M A`` with ``A = r Ŝ_VV``
and ``M`` block diagonal (``M_i = ∂P(z_i)``, the identity on a sticking element). ``J`` differs
from ``A`` only in the rows of the slipping elements ``Q``:

.. math::
    J = A + E_Q\,W,\qquad W = (M_Q − I)\,E_Q^T A + (I − M_Q)\,E_Q^T

so that, with ``A⁻¹`` once per contact set (:func:`inverse`, kept with the operator for a march's steps;
for a single solve :class:`Columns`: the LU, and the columns of ``A⁻¹`` on the slipping elements as they
are needed),

.. math::
    J^{-1} b = y − (A^{-1})_{:,Q}\,C^{-1} (I − M_Q)(y_Q − b_Q),\qquad y = A^{-1} b,\qquad
    C = M_Q + (I − M_Q)\,(A^{-1})_{QQ}                                     \qquad (3D.28a)

(``C`` is the capacitance matrix, of order ``2|Q|``; ``det J = det A · det C``). An iteration
then costs an LU of order ``2|Q|`` and products with ``A⁻¹`` instead of an LU of order ``2|V|``:
on a small grid in partial slip (a fifth of the elements slipping) a few hundredths of it. The direction
is the LU path's to round-off (not bit for bit: another order of operations).
"""
from __future__ import annotations

import warnings

import numpy as np
import scipy.linalg as sla

__all__ = ["Inverse", "Columns", "inverse", "factor", "solve", "MAX_FRACTION"]

#: Slipping rows ``2|Q|`` above this fraction of the traction rows: the LU of ``J`` itself (an LU
#: of order ``2|Q|`` then costs an eighth of it or more, and the products with ``A⁻¹`` are not free).
MAX_FRACTION = 0.5


class Inverse:
    """``S⁻¹`` of the operator's dense contact block ``S`` (LAPACK ``getrf``/``getri``), formed whole, for a
    march's steps on one contact set to share: every column then comes from the same computation whatever
    the history of the march (columns solved in batches as elements start to slip differ in the last bits
    with the batch, which would make a resumed march differ from the uninterrupted one)."""

    def __init__(self, S: np.ndarray):
        self.inv = sla.inv(S, check_finite=False)
        self.inv.flags.writeable = False

    def solve(self, b: np.ndarray) -> np.ndarray:
        """``S⁻¹ b``."""
        return self.inv @ b

    def columns(self, Q: np.ndarray) -> np.ndarray:
        """``S⁻¹[:, Q]``."""
        return self.inv[:, Q]


class Columns:
    """``S⁻¹`` for one solve: ``S``'s LU (``getrf``; it may be shared) and the columns of ``S⁻¹`` on the
    slipping elements, each solved (``getrs``) the first time its element slips in this solve. Cheaper than
    :class:`Inverse` for a single solve (a steady state), and as repeatable: the batches follow the solve's
    own iterates, not what was solved before."""

    def __init__(self, lu):
        self.lu = lu
        self.m = lu[0].shape[0]
        self._cols = np.empty((self.m, 0))
        self._where = np.full(self.m, -1, dtype=np.intp)

    def solve(self, b: np.ndarray) -> np.ndarray:
        """``S⁻¹ b``."""
        return sla.lu_solve(self.lu, b, check_finite=False)

    def columns(self, Q: np.ndarray) -> np.ndarray:
        """``S⁻¹[:, Q]``."""
        new = np.unique(Q[self._where[Q] < 0])
        if new.size:
            E = np.zeros((self.m, new.size))
            E[new, np.arange(new.size)] = 1.0
            self._where[new] = self._cols.shape[1] + np.arange(new.size)
            self._cols = np.hstack([self._cols, self.solve(E)])
        return self._cols[:, self._where[Q]]


def factor(S: np.ndarray):
    """``S``'s LU factors (for :class:`Columns`)."""
    return sla.lu_factor(S, check_finite=False)


def inverse(S: np.ndarray) -> Inverse:
    """:class:`Inverse` of ``S``."""
    return Inverse(S)


def solve(Sinv, scale: float, slip: np.ndarray, mxx, mxy, myy, b: np.ndarray):
    """``J⁻¹ b`` by eq. 3D.28a, ``A⁻¹ = S⁻¹/scale`` (``Sinv`` an :class:`Inverse` or :class:`Columns`); ``b``:
    ``(2 nv,)`` or ``(2 nv, k)``.

    ``slip``: the slipping elements (indices into the ``nv`` contact elements); ``mxx, mxy, myy``:
    ``M_i``'s entries on every contact element. ``None`` where ``C`` is singular (the caller takes
    the LU of ``J`` and its least-squares fallback).

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> nv = 6
    >>> S = np.eye(2 * nv) * 3 + 0.1 * rng.random((2 * nv, 2 * nv))
    >>> mxx, mxy, myy = np.ones(nv), np.zeros(nv), np.ones(nv)
    >>> mxx[[1, 4]], mxy[[1, 4]], myy[[1, 4]] = 0.3, -0.2, 0.6
    >>> J = np.block([[np.diag(1 - mxx), -np.diag(mxy)], [-np.diag(mxy), np.diag(1 - myy)]])
    >>> J += np.vstack([mxx[:, None] * S[:nv] + mxy[:, None] * S[nv:], mxy[:, None] * S[:nv] + myy[:, None] * S[nv:]])
    >>> b = rng.random(2 * nv)
    >>> d = solve(inverse(S), 1.0, np.array([1, 4]), mxx, mxy, myy, b)
    >>> bool(np.allclose(J @ d, b, rtol=0, atol=1e-13))
    True
    """
    y = Sinv.solve(b) / scale
    nv = mxx.size
    if slip.size == 0:
        return y
    Q = np.concatenate([slip, nv + slip])
    ns = slip.size
    SQ = Sinv.columns(Q)
    G = SQ[Q] / scale                                           # (A⁻¹)_QQ
    ax, axy, ay = mxx[slip], mxy[slip], myy[slip]
    zx, zxy, zy = 1 - ax, -axy, 1 - ay                          # I − M_Q
    C = np.empty((2 * ns, 2 * ns), order="F")
    np.multiply(zx[:, None], G[:ns], out=C[:ns])
    C[:ns] += zxy[:, None] * G[ns:]
    np.multiply(zxy[:, None], G[:ns], out=C[ns:])
    C[ns:] += zy[:, None] * G[ns:]
    i = np.arange(ns)
    C[i, i] += ax
    C[i, ns + i] += axy
    C[ns + i, i] += axy
    C[ns + i, ns + i] += ay
    e = y[Q] - b[Q]
    if e.ndim == 1:
        rhs = np.concatenate([zx * e[:ns] + zxy * e[ns:], zxy * e[:ns] + zy * e[ns:]])
    else:
        rhs = np.concatenate([zx[:, None] * e[:ns] + zxy[:, None] * e[ns:],
                              zxy[:, None] * e[:ns] + zy[:, None] * e[ns:]])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", sla.LinAlgWarning)
        c = sla.lu_solve(sla.lu_factor(C, overwrite_a=True, check_finite=False), rhs, check_finite=False)
    if not np.all(np.isfinite(c)):
        return None
    return y - (SQ @ c) / scale
