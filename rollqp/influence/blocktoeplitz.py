r"""Block-Toeplitz influence operators on the grid: products by 2D FFT, dense blocks on demand
(docs/theory3d.md §3).

On the uniform grid the influence coefficient between elements ``I`` and ``J`` depends only on
``(i_I − i_J, j_I − j_J)``, so a product ``u = A t`` is a 2D discrete convolution of the traction
field with the kernel array of :func:`rollqp.influence.cerruti.kernels`:

.. math::
    u_{j,i} = \sum_{j',i'} K[j − j' + n_y − 1,\ i − i' + n_x − 1]\; t_{j',i'}          \qquad (3D.13)

computed exactly (no periodic wrap-around) by real FFTs of size ``L_y × L_x ≥ (2n_y − 1) ×
(2n_x − 1)`` (``_fft().next_fast_len``), the kernel's transform computed once per operator:
``O(n log n)`` time and ``O(n)`` memory, so the matrix is never needed. A
:class:`BlockToeplitz` maps ``m_in`` traction components to ``m_out`` displacement components
(``A_nn``: 1 × 1; ``A_tt``: 2 × 2 with blocks ``xx, xy; yx, yy``; couplings 1 × 2 and 2 × 1);
vectors are the components' flattened fields one after the other (``[t_x, t_y]``, ``2n``).
:meth:`BlockToeplitz.dense` gathers the matrix, or a block of it between subsets of elements
(the contact area), for the dense path of the QP/SOCP backends and of Newton's method, up to
:data:`DENSE_MAX` entries.
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError


def _fft():
    """``scipy.fft``, imported on a grid's first product: ``import rollqp`` loads no scipy (a 2D half-space
    scene never needs it)."""
    import scipy.fft
    return scipy.fft


__all__ = ["BlockToeplitz", "DENSE_MAX"]

#: Largest dense block gathered (entries): 5·10⁷ doubles are 400 MB. Above it the matrix-free
#: path is the only one (a 100 × 100 grid's tangential block has 4·10⁸ entries).
DENSE_MAX = 50_000_000


class BlockToeplitz:
    """A read-only block-Toeplitz operator ``(m_out·n) × (m_in·n)`` on a grid (eq. 3D.13).

    Parameters
    ----------
    grid : rollqp.discretization.grid.Grid
    blocks : list of list of ndarray or None
        ``blocks[a][b]``: the kernel (shape ``(2ny − 1, 2nx − 1)``) from input component ``b`` to
        output component ``a``; ``None`` for a zero block.
    name : str
        Named in errors.

    Examples
    --------
    >>> from rollqp.discretization.grid import Grid
    >>> from rollqp.materials import Materials
    >>> from rollqp.influence.cerruti import kernels
    >>> g = Grid.centred(6, 5, 1.0, 1.0)
    >>> k = kernels(g, Materials.from_shear(1.0, 0.3, 1.0, 0.3))
    >>> A = BlockToeplitz(g, [[k["nn"]]], "Ann")
    >>> p = np.random.default_rng(0).random(g.n)
    >>> bool(np.allclose(A @ p, A.dense() @ p, rtol=1e-13, atol=0))
    True
    """

    def __init__(self, grid, blocks, name: str = "A"):
        self.grid = grid
        self.name = name
        shape = (2 * grid.ny - 1, 2 * grid.nx - 1)
        self.blocks = [[None if k is None else np.array(k, dtype=float) for k in row] for row in blocks]
        for row in self.blocks:
            if len(row) != len(self.blocks[0]):
                raise InputError(name, "every row of blocks needs the same number of kernels")
            for k in row:
                if k is not None and (k.shape != shape or not np.all(np.isfinite(k))):
                    raise InputError(name, f"kernels must be finite arrays of shape {shape}")
                if k is not None:
                    k.flags.writeable = False
        self.m_out, self.m_in = len(self.blocks), len(self.blocks[0])
        self._fft_shape = (_fft().next_fast_len(shape[0], real=True),
                           _fft().next_fast_len(shape[1], real=True))
        self._hat = None
        self._memo = {}

    # ------------------------------------------------------------------ interface
    @property
    def shape(self) -> tuple[int, int]:
        return self.m_out * self.grid.n, self.m_in * self.grid.n

    def __repr__(self) -> str:
        return f"BlockToeplitz({self.name!r}, {self.m_out}x{self.m_in} blocks, grid {self.grid.nx}x{self.grid.ny})"

    #: Derived objects kept per operator (dense blocks of contact sets are large: the oldest go first).
    MEMO_SIZE = 4

    def memo(self, key, build):
        """``build()`` once per ``key``, kept with the operator (what methods derive from it; the
        last :attr:`MEMO_SIZE` keys)."""
        if key not in self._memo:
            if len(self._memo) >= self.MEMO_SIZE:
                self._memo.pop(next(iter(self._memo)))
            self._memo[key] = build()
        return self._memo[key]

    def _transforms(self):
        if self._hat is None:
            L = self._fft_shape
            self._hat = [[None if k is None else _fft().rfft2(k, s=L) for k in row] for row in self.blocks]
        return self._hat

    def __matmul__(self, x) -> np.ndarray:
        """``A x`` by FFT (eq. 3D.13); ``x`` of length ``m_in·n`` (or ``(m_in·n, k)``: column by column)."""
        x = np.asarray(x, dtype=float)
        if x.ndim == 2:
            return np.column_stack([self @ x[:, j] for j in range(x.shape[1])])
        g = self.grid
        if x.shape != (self.m_in * g.n,):
            raise InputError(self.name, f"product with a vector of shape {x.shape}, expected ({self.m_in * g.n},)")
        L = self._fft_shape
        hats = _fft().rfft2(x.reshape(self.m_in, g.ny, g.nx), s=L)     # every component in one call
        rows = [a for a, row in enumerate(self._transforms()) if any(kh is not None for kh in row)]
        out = np.zeros((self.m_out, g.ny, g.nx))
        if rows:
            acc = np.empty((len(rows),) + hats.shape[1:], dtype=hats.dtype)
            for i, a in enumerate(rows):
                first = True
                for b, kh in enumerate(self._transforms()[a]):
                    if kh is not None:
                        if first:
                            np.multiply(kh, hats[b], out=acc[i])
                            first = False
                        else:
                            acc[i] += kh * hats[b]
            full = _fft().irfft2(acc, s=L)                                # every output in one call
            out[rows] = full[:, g.ny - 1:2 * g.ny - 1, g.nx - 1:2 * g.nx - 1]
        return out.ravel()

    def diagonal(self) -> np.ndarray:
        """The diagonal (``m·n``, square operators): each block's kernel at zero offset."""
        if self.m_in != self.m_out:
            raise InputError(self.name, "the diagonal of a non-square operator")
        g = self.grid
        return np.concatenate([np.full(g.n, 0.0 if self.blocks[a][a] is None else self.blocks[a][a][g.ny - 1, g.nx - 1])
                               for a in range(self.m_out)])

    def dense(self, rows=None, cols=None) -> np.ndarray:
        """The matrix, or its block between element subsets ``rows`` and ``cols`` (index arrays
        into the ``n`` elements, applied to every component): shape ``(m_out·|rows|, m_in·|cols|)``.

        Raises
        ------
        InputError
            If the block would have more than :data:`DENSE_MAX` entries (use the FFT product).
        """
        g = self.grid
        rows = np.arange(g.n) if rows is None else np.asarray(rows, dtype=np.intp)
        cols = np.arange(g.n) if cols is None else np.asarray(cols, dtype=np.intp)
        size = self.m_out * rows.size * self.m_in * cols.size
        if size > DENSE_MAX:
            raise InputError("solver.method", f"the influence matrix as a dense matrix ({self.name}): {size:,} entries "
                                              f"({size * 8 / 1e9:.1f} GB), above the limit of {DENSE_MAX:,}; use "
                                              "--method newton (FFT products, no matrix) or a coarser grid "
                                              "(discretization.elements)")
        bi = (rows // g.nx)[:, None] - (cols // g.nx)[None, :] + g.ny - 1
        ai = (rows % g.nx)[:, None] - (cols % g.nx)[None, :] + g.nx - 1
        out = np.zeros((self.m_out * rows.size, self.m_in * cols.size))
        r, c = rows.size, cols.size
        for a, row in enumerate(self.blocks):
            for b, k in enumerate(row):
                if k is not None:
                    out[a * r:(a + 1) * r, b * c:(b + 1) * c] = k[bi, ai]
        return out

    # ------------------------------------------------------------------ algebra
    def combine(self, other: "BlockToeplitz", alpha: float = 1.0, beta: float = 1.0, name=None) -> "BlockToeplitz":
        """``alpha·self + beta·other`` (same grid and block layout), e.g. the steady slip operator
        ``(A − A_shifted)/dx`` of eq. 3D.17."""
        if other.grid != self.grid or (other.m_out, other.m_in) != (self.m_out, self.m_in):
            raise InputError("other", "operators on different grids or block layouts")

        def add(k1, k2):
            if k1 is None and k2 is None:
                return None
            return (0.0 if k1 is None else alpha * k1) + (0.0 if k2 is None else beta * k2)

        blocks = [[add(k1, k2) for k1, k2 in zip(r1, r2)] for r1, r2 in zip(self.blocks, other.blocks)]
        return BlockToeplitz(self.grid, blocks, name or f"{self.name}+{other.name}")

    def scaled(self, factor: float, name=None) -> "BlockToeplitz":
        """``factor·self``."""
        blocks = [[None if k is None else factor * k for k in row] for row in self.blocks]
        return BlockToeplitz(self.grid, blocks, name or f"{factor:g}*{self.name}")
