r"""The matrix-free path of a scene: when it is taken, what it needs, and its operators (docs/matrix-free.md).

A uniform half-space strip is modelled without stored matrices when its method works with
products only (``mf-newton``) and it is large enough that FFT products beat dense ones
(:data:`THRESHOLD`, measured by ``python benchmarks/matrix_free.py --threshold``), or when the
scene asks for it (``solver.operator = "matrix-free"``). Then

* the influence operators are :class:`~rollqp.influence.toeplitz.ToeplitzOperator`\ s
  (``O(n)`` memory, ``O(n log n)`` products), checked positive definite without a matrix
  (:func:`~rollqp.influence.toeplitz.positive_definite_threshold`);
* the history and steady slip operators (eq. 37, 48; docs/formulation.md §9) are sparse
  (``scipy.sparse``, at most three non-zeros a row) instead of dense ``n × n`` arrays;
* the memory a run needs is ``O(n)`` per state (:func:`memory_estimate`), checked before any work.

A method that needs the matrix (``newton``, ``nt-newton``, the QP backends) on a scene the dense
path cannot hold is refused before any work, naming ``mf-newton`` (:func:`check_scene`).
"""
from __future__ import annotations

import time
from typing import TYPE_CHECKING

import numpy as np

from .errors import InputError
from .influence.operator import Operator
from .influence import get_model

if TYPE_CHECKING:  # annotations only: scipy.sparse is imported at first use (`import rollqp` stays free of it)
    from scipy import sparse

__all__ = ["MODES", "THRESHOLD", "mode", "memory_estimate", "check_scene", "sparse_history",
           "sparse_steady", "SteadyOperator", "steady_operators", "build"]

#: ``solver.operator``: ``"auto"`` (by :data:`THRESHOLD`), ``"dense"`` or ``"matrix-free"``.
MODES = ("auto", "dense", "matrix-free")

#: Nodes from which ``mf-newton`` on ``solver.operator = "auto"`` uses FFT products instead of
#: dense ones, by element type. Measured (normal Hertz step, quadratic elements, medians, shared
#: 2-core machine: ``python benchmarks/matrix_free.py --threshold``; docs/matrix-free.md): FFT
#: products win already at 321 nodes (3.5×, 19× at 641), because only the FFT operator carries the
#: circulant preconditioner; below 200 nodes the dense ``newton`` is the method to use anyway.
#: Constant and linear elements take one or two transforms a product instead of three: the same
#: threshold (not measured separately).
THRESHOLD = {"constant": 200, "linear": 200, "quadratic": 200}

#: Bytes per node of the matrix-free operators and solver work space (generators and their
#: transforms, GMRES basis of 60 vectors, sparse history operators), measured at 131,073 nodes.
BYTES_PER_NODE = 8 * 200


def mode(scene, capabilities=None) -> str:
    """``"dense"`` or ``"matrix-free"``: the scene's ``solver.operator`` with ``"auto"`` resolved.

    ``capabilities``: the :class:`~rollqp.methods.base.Capabilities` of the method that runs the scene
    (default: those its ``solver.method`` declares, :attr:`Scene.method_capabilities
    <rollqp.scene.Scene.method_capabilities>`)."""
    asked = scene.solver.operator or "auto"
    if asked != "auto":
        return asked
    caps = scene.method_capabilities if capabilities is None else capabilities
    if (caps.matrix_free and _model(scene).matrix_free
            and scene.n_nodes >= THRESHOLD[scene.discretization.element]):
        return "matrix-free"
    return "dense"


def _model(scene):
    """The scene's influence model (:class:`rollqp.influence.Model`)."""
    return get_model(scene.contact.model)


def memory_estimate(scene) -> float:
    """Bytes a matrix-free run needs at its peak: ``O(n)`` operators and work space, and the
    result's five per-state arrays (as :meth:`Scene.memory_estimate` counts them)."""
    n, states = scene.n_nodes, scene.n_steps + 1
    return float(BYTES_PER_NODE * n + 8.0 * 6 * states * n)


def check_scene(scene, dense_max_nodes: int, capabilities=None) -> str:
    """The scene's operator mode, after refusing what cannot run (before any work); ``capabilities`` as
    for :func:`mode`.

    Raises
    ------
    InputError
        ``solver.operator`` = ``"matrix-free"`` with a method that needs the matrix or a model
        other than the half-space; ``discretization.elements`` when a method that needs the matrix
        is asked for more than ``dense_max_nodes`` nodes (naming ``mf-newton``).
    """
    caps = scene.method_capabilities if capabilities is None else capabilities
    m = mode(scene, caps)
    method = scene.solver.method
    if m == "matrix-free":
        if not caps.matrix_free:
            raise InputError("solver.operator", f"'matrix-free' needs a method that works with products only "
                                                f"(mf-newton); {method!r} needs the "
                                                f"n × n matrix: use solver.method = 'mf-newton' or "
                                                f"solver.operator = 'dense'")
        if not _model(scene).matrix_free:
            raise InputError("solver.operator", f"'matrix-free' needs a contact.model with FFT operators (a uniform "
                                                f"strip's Toeplitz kernels), got {scene.contact.model!r}")
    elif scene.n_nodes > dense_max_nodes:
        gb = 8.0 * 6 * scene.n_nodes ** 2 / 2 ** 30
        alt = ("solver.method = 'mf-newton' (matrix-free, O(n) memory)" if _model(scene).matrix_free
               else "fewer elements")
        raise InputError("discretization.elements",
                         f"{scene.discretization.elements} {scene.discretization.element} elements make "
                         f"{scene.n_nodes} nodes; the dense path ({method!r} needs the n × n matrices, about "
                         f"{gb:.3g} GiB) takes at most {dense_max_nodes} (20000 elements): use {alt}")
    return m


# ------------------------------------------------------------------------------ slip operators
def _displacement(strip, points) -> sparse.csr_matrix:
    """Sparse :meth:`~rollqp.strip.Strip.displacement_matrix` (same values, at most three per row)."""
    from scipy import sparse  # at first use: `import rollqp` stays free of scipy.sparse
    pts = np.clip(np.atleast_1d(np.asarray(points, dtype=float)), strip.x[0], strip.x[-1])
    n, m = strip.n, pts.size
    rows = np.arange(m)
    if strip.element == "constant":
        j = np.clip(np.searchsorted(strip.x, pts, side="right") - 1, 0, n - 2)
        lam = (pts - strip.x[j]) / (strip.x[j + 1] - strip.x[j])
        return sparse.csr_matrix((np.concatenate([1.0 - lam, lam]), (np.concatenate([rows, rows]),
                                  np.concatenate([j, j + 1]))), shape=(m, n))
    ne, L, h = int(strip.n_elements), float(strip.half_width), 0.5 * strip.element_length
    el = np.clip(np.floor((pts + L) / strip.element_length).astype(int), 0, ne - 1)
    xi = (pts - 0.5 * (strip.edges[el] + strip.edges[el + 1])) / h
    c = strip.coefficients
    vals = c[None, :, 0] + c[None, :, 1] * xi[:, None] + c[None, :, 2] * xi[:, None] ** 2
    nen = c.shape[0]
    return sparse.csr_matrix((vals.ravel(), (np.repeat(rows, nen), strip.connectivity[el].ravel())),
                             shape=(m, n))


def _upwind(strip, direction: int) -> sparse.csr_matrix:
    """Sparse :meth:`~rollqp.strip.Strip.upwind_difference` (eq. 20, 38–40)."""
    from scipy import sparse  # at first use: `import rollqp` stays free of scipy.sparse
    n, hx = strip.n, np.diff(strip.x)
    if direction < 0:
        i = np.arange(n - 1)
        r = np.concatenate([i, i, [n - 1, n - 1]])
        c = np.concatenate([i, i + 1, [n - 2, n - 1]])
        v = np.concatenate([-1.0 / hx, 1.0 / hx, [-1.0 / hx[-1], 1.0 / hx[-1]]])
    else:
        i = np.arange(1, n)
        r = np.concatenate([i, i, [0, 0]])
        c = np.concatenate([i - 1, i, [0, 1]])
        v = np.concatenate([-1.0 / hx, 1.0 / hx, [-1.0 / hx[0], 1.0 / hx[0]]])
    return sparse.csr_matrix((v, (r, c)), shape=(n, n))


def sparse_history(strip, formulation: str, dq: float, direction: int) -> sparse.csr_matrix:
    """Sparse :meth:`~rollqp.strip.Strip.history_operator`: ``c^{k-1} = -M w^{k-1}`` (eq. 37, 48)."""
    from scipy import sparse  # at first use: `import rollqp` stays free of scipy.sparse
    if direction not in (-1, 1):
        raise InputError("direction", f"must be -1 or +1, got {direction!r}")
    if formulation == "material":
        return _displacement(strip, strip.x - direction * float(dq))
    eye = sparse.identity(strip.n, format="csr")
    if formulation == "convective-local":
        return (eye - float(dq) * direction * _upwind(strip, direction)).tocsr()
    if formulation == "static":
        return eye
    raise InputError("formulation", f"must be one of material, convective-local, static; got {formulation!r}")


def sparse_steady(strip, direction: int, formulation: str = "convective-local",
                  dq: float | None = None) -> sparse.csr_matrix:
    """Sparse :meth:`~rollqp.strip.Strip.steady_operator`: ``T`` of the steady slip ``s = ξ e + T w``,
    the fixed point of the transient step of ``formulation`` (docs/formulation.md §9): ``d·D_up``
    (convective-local), ``(I − R)/Δq`` (material)."""
    from scipy import sparse  # at first use: `import rollqp` stays free of scipy.sparse
    if direction not in (-1, 1):
        raise InputError("direction", f"must be -1 or +1, got {direction!r}")
    if formulation == "material":
        if dq is None or not float(dq) > 0.0:
            raise InputError("dq", f"the material steady operator needs the step Δq > 0, got {dq!r}")
        eye = sparse.identity(strip.n, format="csr")
        return ((eye - sparse_history(strip, "material", dq, direction)) / float(dq)).tocsr()
    if formulation == "convective-local":
        return direction * _upwind(strip, direction)
    raise InputError("formulation", f"must be material or convective-local; got {formulation!r}")


class SteadyOperator(Operator):
    """``c·T·A``: a sparse slip operator ``T`` times an FFT influence operator ``A``, never a matrix.

    The steady slip operators ``Δ·T·A_tt`` and ``Δ·T·A_tn`` (:func:`sparse_steady`; docs/formulation.md
    §9) of a matrix-free scene: products ``O(n log n)``, memory ``O(n)``; the operator interface
    of :class:`~rollqp.influence.operator.Operator` (``@``, ``x @ A``, ``diagonal()``,
    ``column(j)``, ``dense()``, ``memo``) so that step problems and ``mf-newton`` take it unchanged
    (the column gives ``mf-newton`` its circulant preconditioner).
    """

    __array_ufunc__ = None      # ``x @ op`` goes to __rmatmul__

    def __init__(self, T, A, c: float = 1.0, name: str = "steady"):
        self.T, self.A, self.c, self.name = T.tocsr(), A, float(c), name
        self._memo = {}

    @property
    def shape(self) -> tuple[int, int]:
        return self.A.shape

    @property
    def n(self) -> int:
        return self.A.shape[0]

    def __matmul__(self, x):
        return self.c * (self.T @ (self.A @ x))

    def __rmatmul__(self, y):
        return (self.c * (self.T.T @ y)) @ self.A

    def diagonal(self) -> np.ndarray:
        """``c Σ_k T[i, k] A[k, i]`` from ``T``'s non-zeros and ``A.entries`` (``O(n)``)."""
        coo = self.T.tocoo()
        vals = coo.data * self.A.entries(coo.col, coo.row)
        return self.c * np.bincount(coo.row, weights=vals, minlength=self.n)

    def column(self, j: int) -> np.ndarray:
        return self.c * (self.T @ self.A.column(j))

    def dense(self) -> np.ndarray:
        return self.c * (self.T @ self.A.dense())

    def __array__(self, dtype=None, copy=None):
        m = self.dense()
        return m if dtype is None else m.astype(dtype, copy=False)

    def __repr__(self) -> str:
        return f"SteadyOperator({self.name!r}, n={self.n})"


def steady_operators(ops):
    """``(Δ·T·A_tn or None, Δ·T·A_tt)`` (``T`` the scene's :func:`sparse_steady`) of a matrix-free scene as :class:`SteadyOperator` objects
    (``Δ = a_H``; the dense path's :meth:`SceneOperators.steady <rollqp.operators.SceneOperators.steady>`)."""
    sc = ops.scene
    T = sparse_steady(ops.strip, sc.load.direction, sc.discretization.formulation, sc.dq)
    delta = ops.scales.length
    Atn = None if ops.Atn is None else SteadyOperator(T, ops.Atn, delta, "steady A_tn")
    return Atn, SteadyOperator(T, ops.Att, delta, "steady A_tt")


# ------------------------------------------------------------------------------ operators
def build(scene, strip):
    """``(A_nn, A_tt, A_tn, A_nt, h, info)`` of a matrix-free scene: its influence model's FFT operators
    (:attr:`Model.operators <rollqp.influence.Model.operators>`; the half-space's: eq. 25–30)."""
    return get_model(scene.contact.model).operators(scene, strip)
