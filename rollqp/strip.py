"""Discretization of the contact strip (paper §3.1, eq. 31–48; docs/formulation.md §2).

The potential contact zone ``[-L, L]`` is divided into ``n_elements`` equal elements of
length ``Le``. Tractions are interpolated with element shape functions ``N_j``:

* ``"constant"``  – piecewise constant, one node at each element centre (Kalker's and
  CONTACT's choice; collocation at the centres);
* ``"linear"``    – piecewise linear, continuous, nodes at the element ends;
* ``"quadratic"`` – quadratic continuous elements (the paper's QCE, eq. 31), nodes at the
  element ends and midpoints.

The weights ``f_j = ∫ N_j dx`` give the loads ``P = fᵀp``, ``Q = fᵀt`` (eq. 65–67).

Relative tangential displacements ``w`` are interpolated with the same shape functions as
the tractions for linear and quadratic elements (eq. 31–32). Piecewise-constant elements
carry no displacement interpolation of their own: ``w`` is taken piecewise linear between
the element centres, which makes the material shift by one element (CONTACT's
``Δq = DX``) an exact index shift. Outside ``[x_1, x_n]`` the displacement is held at the
end node's value; only the leading-edge node ever looks there, and it must be out of
contact (the paper's treatment of its last equation, eq. 35).

Sign convention (docs/formulation.md §1): material moves through the contact with direction
``d = sgn(V)``; it enters at the leading edge ``x = -d·L``.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .discretization import Discretization
from .errors import InputError

ELEMENTS = ("constant", "linear", "quadratic")
FORMULATIONS = ("material", "convective-local")

# Shape functions on the reference element ξ ∈ [-1, 1]: N_a(ξ) = c0 + c1 ξ + c2 ξ².
_COEFFICIENTS = {
    "constant": np.array([[1.0, 0.0, 0.0]]),
    "linear": np.array([[0.5, -0.5, 0.0], [0.5, 0.5, 0.0]]),
    "quadratic": np.array([[0.0, -0.5, 0.5], [1.0, 0.0, -1.0], [0.0, 0.5, 0.5]]),
}


@dataclass(frozen=True)
class Strip:
    """Nodes, elements and weights on the potential contact zone ``[-L, L]``.

    Parameters
    ----------
    half_width : float
        ``L``, the half-width of the potential contact zone (scene length units).
    n_elements : int
        Number of elements on ``[-L, L]``.
    element : {"constant", "linear", "quadratic"}
        Traction interpolation.

    Attributes
    ----------
    x : ndarray, shape (n,)
        Node coordinates (collocation points).
    weights : ndarray, shape (n,)
        ``f_j = ∫ N_j dx`` (eq. 65–67).
    connectivity : ndarray, shape (n_elements, nen)
        Node indices of each element, in the order of :attr:`coefficients`.
    coefficients : ndarray, shape (nen, 3)
        Polynomial coefficients of the reference shape functions in ``ξ ∈ [-1, 1]``.
    edges : ndarray, shape (n_elements + 1,)
        Element end points.
    """

    half_width: float
    n_elements: int
    element: str = "quadratic"
    x: np.ndarray = field(init=False, repr=False)
    weights: np.ndarray = field(init=False, repr=False)
    connectivity: np.ndarray = field(init=False, repr=False)
    coefficients: np.ndarray = field(init=False, repr=False)
    edges: np.ndarray = field(init=False, repr=False)

    def __post_init__(self):
        if self.element not in ELEMENTS:
            raise InputError("element", f"must be one of {', '.join(ELEMENTS)}, got {self.element!r}")
        if not (isinstance(self.n_elements, (int, np.integer)) and self.n_elements >= 2):
            raise InputError("elements", f"must be an integer >= 2, got {self.n_elements!r}")
        if not (np.isfinite(self.half_width) and self.half_width > 0):
            raise InputError("half_width", f"must be a finite number > 0, got {self.half_width!r}")
        ne, L = int(self.n_elements), float(self.half_width)
        edges = np.linspace(-L, L, ne + 1)
        e = np.arange(ne)
        if self.element == "constant":
            x = 0.5 * (edges[:-1] + edges[1:])
            conn = e[:, None]
        elif self.element == "linear":
            x = edges.copy()
            conn = np.stack([e, e + 1], axis=1)
        else:
            x = np.linspace(-L, L, 2 * ne + 1)
            conn = np.stack([2 * e, 2 * e + 1, 2 * e + 2], axis=1)
        coef = _COEFFICIENTS[self.element]
        # ∫_{-1}^{1} (c0 + c1 ξ + c2 ξ²) dξ = 2 c0 + 2 c2 / 3, times the Jacobian Le/2
        w_local = (2 * coef[:, 0] + 2 * coef[:, 2] / 3) * (L / ne)
        weights = np.zeros(x.size)
        np.add.at(weights, conn, np.broadcast_to(w_local, conn.shape))
        for name, value in (("x", x), ("weights", weights), ("connectivity", conn),
                            ("coefficients", coef), ("edges", edges)):
            value = np.asarray(value)
            value.setflags(write=False)
            object.__setattr__(self, name, value)

    # ------------------------------------------------------------------ basic sizes
    @property
    def n(self) -> int:
        """Number of nodes."""
        return int(self.x.size)

    def record(self) -> Discretization:
        """The strip as a :class:`~rollqp.discretization.Discretization`: the nodes ``x`` (one coordinate),
        their weights, one traction component, fields of shape ``(n,)``."""
        return Discretization(self.x[None, :], self.weights, 1, (self.n,))

    @property
    def element_length(self) -> float:
        """``Le``, the element length."""
        return 2.0 * float(self.half_width) / int(self.n_elements)

    @property
    def spacing(self) -> float:
        """Distance between neighbouring nodes (``Le`` or ``Le/2`` for quadratic)."""
        return float(self.x[1] - self.x[0])

    def leading_index(self, direction: int) -> int:
        """Index of the leading-edge node, where material enters (``x = -d·L``)."""
        return self.n - 1 if _direction(direction) < 0 else 0

    def trailing_index(self, direction: int) -> int:
        """Index of the trailing-edge node, where material leaves (``x = +d·L``)."""
        return 0 if _direction(direction) < 0 else self.n - 1

    # ------------------------------------------------------------------ interpolation
    def traction_matrix(self, points) -> np.ndarray:
        """Matrix ``M`` with ``M @ p`` the interpolated traction at ``points``.

        Zero outside ``[-L, L]`` (no traction outside the potential contact zone).
        """
        pts = np.atleast_1d(np.asarray(points, dtype=float))
        ne, L, h = int(self.n_elements), float(self.half_width), 0.5 * self.element_length
        M = np.zeros((pts.size, self.n))
        inside = np.abs(pts) <= L * (1 + 1e-14)
        el = np.clip(np.floor((pts + L) / self.element_length).astype(int), 0, ne - 1)
        xi = (pts - 0.5 * (self.edges[el] + self.edges[el + 1])) / h
        vals = self.coefficients[None, :, 0] + self.coefficients[None, :, 1] * xi[:, None] \
            + self.coefficients[None, :, 2] * xi[:, None] ** 2
        rows = np.repeat(np.arange(pts.size), self.connectivity.shape[1])
        np.add.at(M, (rows, self.connectivity[el].ravel()), (vals * inside[:, None]).ravel())
        return M

    def displacement_matrix(self, points) -> np.ndarray:
        """Matrix ``M`` with ``M @ w`` the interpolated displacement at ``points`` (eq. 32).

        Shape functions of the element for linear and quadratic elements; piecewise linear
        between element centres for constant elements. Held at the end node's value
        outside ``[x_1, x_n]``.
        """
        pts = np.clip(np.atleast_1d(np.asarray(points, dtype=float)), self.x[0], self.x[-1])
        if self.element != "constant":
            return self.traction_matrix(pts)
        j = np.clip(np.searchsorted(self.x, pts, side="right") - 1, 0, self.n - 2)
        lam = (pts - self.x[j]) / (self.x[j + 1] - self.x[j])
        M = np.zeros((pts.size, self.n))
        r = np.arange(pts.size)
        M[r, j] += 1.0 - lam
        M[r, j + 1] += lam
        return M

    # ------------------------------------------------------------------ slip operators
    def shift_operator(self, dq: float, direction: int) -> np.ndarray:
        """``R`` of eq. 33: ``(R w)_i = w(x_i - d·Δq)``, the particle's previous position."""
        return self.displacement_matrix(self.x - _direction(direction) * float(dq))

    def upwind_difference(self, direction: int) -> np.ndarray:
        """``D_up`` (eq. 20, 38–40): one-sided difference towards the upstream neighbour.

        For ``d = -1`` (material from +x) row ``i`` is ``(w_{i+1} - w_i)/h_i`` and the last
        row repeats the one before (eq. 38); for ``d = +1`` row ``i`` is
        ``(w_i - w_{i-1})/h_{i-1}`` and the first row repeats the second (eq. 39).
        The paper's operator ``T`` of eq. 38–39 is ``d·D_up``.
        """
        n = self.n
        h = np.diff(self.x)
        D = np.zeros((n, n))
        if _direction(direction) < 0:
            i = np.arange(n - 1)
            D[i, i], D[i, i + 1] = -1.0 / h, 1.0 / h
            D[n - 1] = D[n - 2]
        else:
            i = np.arange(1, n)
            D[i, i - 1], D[i, i] = -1.0 / h, 1.0 / h
            D[0] = D[1]
        return D

    def history_operator(self, formulation: str, dq: float, direction: int) -> np.ndarray:
        """``M`` such that the history vector is ``c^{k-1} = -M w^{k-1}``.

        With it the slip of every transient form is ``s = ξ e + (c + w^k)/Δq``
        (eq. 36–37, 47–48; docs/formulation.md §2):

        * ``"material"``: ``M = R`` (eq. 37);
        * ``"convective-local"``: ``M = I - Δq·d·D_up`` (eq. 48);
        * ``"static"``: ``M = I`` (braked static shift: ``s = (w^k - w^{k-1})/Δ``,
          ``ξ`` the rigid shift over ``Δ``; §4.4).
        """
        if formulation == "material":
            return self.shift_operator(dq, direction)
        if formulation == "convective-local":
            return np.eye(self.n) - float(dq) * _direction(direction) * self.upwind_difference(direction)
        if formulation == "static":
            return np.eye(self.n)
        raise InputError("formulation", f"must be one of material, convective-local, static; got {formulation!r}")

    def steady_operator(self, direction: int, formulation: str = "convective-local",
                        dq: float | None = None) -> np.ndarray:
        """``T`` of the steady-rolling slip ``s = ξ e + T w``: the fixed point of the transient step of
        ``formulation`` (docs/formulation.md §9).

        A transient step's slip is ``ξ e + (w^k − M w^{k−1})/Δq`` (:meth:`history_operator`); at
        its fixed point ``w^k = w^{k−1} = w`` it is ``ξ e + (I − M) w/Δq``, so

        * ``"convective-local"``: ``T = d·D_up`` (eq. 14 without the local term, for every ``Δq``);
        * ``"material"``: ``T = (I − R)/Δq`` (eq. 33), the material shift's own difference. It is
          ``d·D_up`` except at the leading node when ``R`` moves nodal values by exactly one node
          spacing (constant and linear elements with ``Δq ≤ h``; quadratic with ``Δq = h = Le/2``);
          for other steps it is another consistent difference of ``w``, and the march of that
          formulation would leave the state of ``d·D_up`` (the difference is a discretization
          error: both converge to the continuous steady state as the mesh is refined).
        """
        d = _direction(direction)
        if formulation == "material":
            if dq is None or not float(dq) > 0.0:
                raise InputError("dq", f"the material steady operator needs the step Δq > 0, got {dq!r}")
            return (np.eye(self.n) - self.shift_operator(dq, d)) / float(dq)
        if formulation == "convective-local":
            return d * self.upwind_difference(d)
        raise InputError("formulation", f"must be material or convective-local; got {formulation!r}")


class RowSparse:
    """A matrix with at most ``k`` non-zeros a row, stored as ``cols``, ``vals`` of shape ``(n, k)``.

    The slip operators of a strip (the history operator ``M`` of eq. 37, 48, the upwind
    difference of eq. 38–40) have two or three non-zeros a row: stored so, their product costs
    ``O(n k)`` instead of a dense ``O(n²)`` one, with the same non-zero values (a padded entry
    has the value 0 and adds nothing). Only ``@`` (with a vector or an ``n × m`` matrix),
    ``shape``, :meth:`dense` and ``np.asarray`` are provided. Up to :data:`DENSE_MAX` entries the
    product with a vector is the dense one (one BLAS call; both products' costs by size:
    docs/performance.md, ``python benchmarks/row_sparse.py``).
    """

    __slots__ = ("cols", "vals", "shape", "_small")

    #: Largest matrix (entries) whose vector product goes through its dense copy.
    DENSE_MAX = 128 * 128

    def __init__(self, cols: np.ndarray, vals: np.ndarray, shape: tuple[int, int]):
        self.cols, self.vals, self.shape = cols, vals, (int(shape[0]), int(shape[1]))
        for a in (self.cols, self.vals):
            a.setflags(write=False)
        self._small = None
        if self.shape[0] * self.shape[1] <= self.DENSE_MAX:
            self._small = self.dense()
            self._small.setflags(write=False)

    @classmethod
    def from_dense(cls, M) -> "RowSparse":
        """The non-zeros of the dense matrix ``M``, row by row in column order."""
        M = np.asarray(M, dtype=float)
        rows, cols = np.nonzero(M)
        counts = np.bincount(rows, minlength=M.shape[0])
        k = max(int(counts.max(initial=0)), 1)
        start = np.concatenate(([0], np.cumsum(counts)[:-1]))
        slot = np.arange(rows.size) - start[rows]
        C = np.zeros((M.shape[0], k), dtype=np.intp)
        V = np.zeros((M.shape[0], k))
        C[rows, slot], V[rows, slot] = cols, M[rows, cols]
        return cls(C, V, M.shape)

    def __matmul__(self, w):
        w = np.asarray(w, dtype=float)
        if self._small is not None and w.ndim == 1:
            return self._small @ w
        cols, vals = self.cols, self.vals
        if w.ndim == 1:
            out = vals[:, 0] * w[cols[:, 0]]
            for j in range(1, cols.shape[1]):
                out += vals[:, j] * w[cols[:, j]]
            return out
        out = vals[:, 0, None] * w[cols[:, 0]]
        for j in range(1, cols.shape[1]):
            out += vals[:, j, None] * w[cols[:, j]]
        return out

    def dense(self) -> np.ndarray:
        """The ``n × m`` matrix."""
        M = np.zeros(self.shape)
        r = np.repeat(np.arange(self.shape[0]), self.cols.shape[1])
        np.add.at(M, (r, self.cols.ravel()), self.vals.ravel())
        return M

    def __array__(self, dtype=None, copy=None):
        M = self.dense()
        return M if dtype is None else M.astype(dtype, copy=False)

    def __repr__(self) -> str:
        return f"RowSparse(shape={self.shape}, per_row={self.cols.shape[1]})"


def _direction(d) -> int:
    if d not in (-1, 1):
        raise InputError("direction", f"must be -1 or +1, got {d!r}")
    return int(d)
