r"""An interface layer between the bodies: a thin elastic third body sheared by the tangential tractions
(docs/theory3d.md, "Interface layer"; both dimensions).

A layer of thickness ``h`` and shear modulus ``G₃`` between the two bodies (oxides, wear debris, friction
modifiers) is sheared elastically by the tangential traction ``t`` that it transmits; the displacement jump
across it is local,

.. math::
    u^{(3)}(x) = \frac{h}{G_3}\,t(x) \qquad (\text{L.1})

(CONTACT's material model ``M = 4`` with no plasticity, ``TAU_C0 = 0``; Vollebregt 2014). It adds the
compliance ``c = h/G₃`` (length per stress) to the tangential influence wherever the tangential
displacement difference of the bodies is read:

.. math::
    w = A_{tn}\,p + (A_{tt} + c\,I)\,t \qquad (\text{L.2})

— nothing else: the layer carries the pressure across unchanged (it is thin against the contact, its normal
compliance is not part of the model), so the normal problem, the Hertz scales and the normal–tangential
coupling are the bodies' own. ``h`` and ``G₃`` enter through ``h/G₃`` only. Where the bodies are far stiffer
than the layer the contact becomes a *brush* of independent springs of stiffness ``G₃/h`` per area (the
closed form the layer is validated against, :mod:`rollqp.closedforms.brush`).

On a strip (2D) tractions are collocated at the nodes, so (L.2) adds ``c`` to the diagonal of ``A_tt``
(:func:`strip_tangential`); ``F·(A_tt + cI)`` stays as symmetric as ``F·A_tt``. On a grid (3D) the traction
is constant on each rectangle, so the layer's kernel is ``c`` times the indicator of the element holding the
collocation point (:func:`grid_kernel`): at no offset the identity, at the rolling step's offset ``−d·Δq`` the
element the particle came from, and in the steady slip operator ``A − A(· − d·dx)`` the upwind difference
``c (t_i − t_{i−d})`` (:class:`LayeredOperators`).

Examples
--------
>>> layer = parse_layer({"thickness": 1.25, "shear_modulus": 8200.0})
>>> f"{layer.compliance:.4e}"
'1.5244e-04'
>>> parse_layer({"thickness": 1.25, "shear_modulus": 0.0})
Traceback (most recent call last):
...
rollqp.errors.InputError: contact.layer.shear_modulus: must be a number > 0 (G3 of the layer, stress units), got 0.0
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import InputError
from ..validate import number, suggestion
from .blocktoeplitz import BlockToeplitz
from .operator import Operator

__all__ = ["Layer", "parse_layer", "compliance_of", "summary_rows", "strip_tangential", "LayeredDiagonal", "grid_kernel",
           "LayeredOperators", "with_layer", "KEYS"]

#: The keys of ``[contact.layer]``.
KEYS = ("thickness", "shear_modulus")

#: Largest layer compliance ``h/G₃`` relative to the bodies' ``c/E*`` (``c = √(ab)`` on a grid, ``a_H`` on a
#: strip). Beyond it the bodies' elasticity is below 1e-5 of the layer's, the layer's diagonal swamps the
#: influence to round-off and Newton's tangential target ``tolerance·r`` (``r ≈ 1/diagonal``) falls below
#: round-off (measured on the circle, 3D: converged at 1.3e5, not at 1.3e6): the contact is a brush
#: (:mod:`rollqp.closedforms.brush`), or the units are wrong.
MAX_RELATIVE_COMPLIANCE = 1e5


@dataclass(frozen=True)
class Layer:
    """A thin elastic interface layer (module docstring): ``thickness`` ``h >= 0`` (length units; 0: no layer)
    and ``shear_modulus`` ``G₃ > 0`` (stress units)."""

    thickness: float
    shear_modulus: float

    @property
    def compliance(self) -> float:
        """``h/G₃``: the tangential displacement jump per unit traction (length per stress, eq. L.1)."""
        return self.thickness / self.shear_modulus


def parse_layer(value: Any, key: str = "contact.layer") -> Layer | None:
    """``[contact.layer]`` checked: ``None`` (no layer), a :class:`Layer` or a table ``{thickness, shear_modulus}``.

    Raises
    ------
    InputError
        Naming ``key`` or ``key.<sub-key>`` and the allowed range.
    """
    if value is None:
        return None
    if isinstance(value, Layer):
        value = {"thickness": value.thickness, "shear_modulus": value.shear_modulus}
    if not isinstance(value, dict):
        raise InputError(key, f"must be a table {{ thickness = h, shear_modulus = G3 }} (a layer of thickness h >= 0 "
                              f"and shear modulus G3 > 0 between the bodies), got {value!r}")
    for k in value:
        if k not in KEYS:
            raise InputError(f"{key}.{k}", f"unknown key{suggestion(k, KEYS)} (allowed in [{key}]: {', '.join(KEYS)})")
    for k in KEYS:
        if k not in value:
            raise InputError(f"{key}.{k}", f"missing required key ([{key}] needs {', '.join(KEYS)})")
    h = number(f"{key}.thickness", value["thickness"], ">= 0 (the layer's thickness, length units; 0: no layer)",
               lambda x: x >= 0)
    G = number(f"{key}.shear_modulus", value["shear_modulus"], "> 0 (G3 of the layer, stress units)", lambda x: x > 0)
    if not math.isfinite(h / G):
        raise InputError(f"{key}.thickness", f"thickness/shear_modulus = {h!r}/{G!r} must be a finite compliance")
    return Layer(h, G)


def summary_rows(layer: Layer | None, length: str = "length units", stress: str = "stress units") -> list:
    """A run summary's row of the layer (both dimensions): ``[("interface layer", text)]``, none without one."""
    if compliance_of(layer) == 0.0:
        return []
    return [("interface layer", f"h = {layer.thickness:.5g} {length}, G3 = {layer.shear_modulus:.5g} {stress}: "
                                f"h/G3 = {layer.compliance:.4g} {length}/{stress} in the tangential influence "
                                "(docs/theory3d.md §13)")]


def compliance_of(layer: Layer | None) -> float:
    """``h/G₃`` of ``layer``, 0 without one."""
    return 0.0 if layer is None else layer.compliance


def check_relative(layer: Layer | None, length: float, Estar: float, key: str = "contact.layer") -> None:
    """The layer's compliance at most :data:`MAX_RELATIVE_COMPLIANCE` times the bodies' ``length/E*``."""
    c = compliance_of(layer)
    bodies = length / Estar
    if c > MAX_RELATIVE_COMPLIANCE * bodies:
        raise InputError(f"{key}.thickness", f"the layer's compliance thickness/shear_modulus = {c:.3g} is more than "
                                             f"{MAX_RELATIVE_COMPLIANCE:g} times the bodies' c/E* = {bodies:.3g}: "
                                             "every creepage would be full sliding; check the units")


# ============================================================================ the strip (2D)
class LayeredDiagonal(Operator):
    """``A + c·I`` of an operator without a stored matrix (a Toeplitz product by FFT), never a matrix: the
    interface of :class:`~rollqp.influence.operator.Operator` (``@``, ``x @ A``, ``diagonal()``, ``column(j)``,
    ``entries(i, j)``, ``dense()``, ``memo``)."""

    __array_ufunc__ = None      # ``x @ op`` goes to __rmatmul__

    def __init__(self, A, c: float, name: str = "influence"):
        self.A, self.c, self.name = A, float(c), name
        self._memo = {}

    @property
    def shape(self) -> tuple[int, int]:
        return self.A.shape

    @property
    def n(self) -> int:
        return self.A.shape[0]

    def __matmul__(self, x):
        x = np.asarray(x, dtype=float)
        return self.A @ x + self.c * x

    def __rmatmul__(self, y):
        y = np.asarray(y, dtype=float)
        return y @ self.A + self.c * y

    def diagonal(self) -> np.ndarray:
        return self.A.diagonal() + self.c

    def column(self, j: int) -> np.ndarray:
        col = np.array(self.A.column(j), dtype=float)
        col[j] += self.c
        return col

    def entries(self, i, j) -> np.ndarray:
        i, j = np.asarray(i), np.asarray(j)
        return self.A.entries(i, j) + np.where(i == j, self.c, 0.0)

    def dense(self) -> np.ndarray:
        m = np.array(self.A.dense(), dtype=float)
        m[np.diag_indices_from(m)] += self.c
        return m

    def __array__(self, dtype=None, copy=None):
        m = self.dense()
        return m if dtype is None else m.astype(dtype, copy=False)

    def __repr__(self) -> str:
        return f"LayeredDiagonal({self.name!r}, n={self.n}, c={self.c:g})"


def strip_tangential(Att, layer: Layer | None, name: str = "influence"):
    """``A_tt + c·I`` on a strip (eq. L.2; ``c = h/G₃``): a new :class:`Operator` of a stored matrix, a
    :class:`LayeredDiagonal` of an FFT operator; ``Att`` itself without a layer (or ``h = 0``)."""
    c = compliance_of(layer)
    if c == 0.0:
        return Att
    if isinstance(Att, Operator) and type(Att) is Operator:
        m = np.array(Att.dense(), dtype=float)
        m[np.diag_indices_from(m)] += c
        return Operator(m, name)
    if isinstance(Att, np.ndarray):
        m = np.array(Att, dtype=float)
        m[np.diag_indices_from(m)] += c
        return m
    return LayeredDiagonal(Att, c, name)


# ============================================================================ the grid (3D)
def grid_kernel(grid, c: float, offset=(0.0, 0.0)) -> np.ndarray:
    """The layer's kernel on ``grid`` (shape ``(2ny − 1, 2nx − 1)``, the layout of
    :func:`rollqp.influence.cerruti.kernels`): the displacement jump at ``x_I + offset`` due to a unit traction
    on element ``J`` is ``c`` if the point lies in ``J`` (``c/2`` on an edge shared by two, ``c/4`` at a corner),
    else 0 (eq. L.1 with tractions constant on the rectangles).

    >>> from rollqp.discretization.grid import Grid
    >>> k = grid_kernel(Grid.centred(3, 2, 1.0, 1.0), 2.0, (-1.0, 0.0))
    >>> k.shape, float(k.sum()), [int(v) for v in np.argwhere(k)[0]]   # i − i' = 1: the element on the −x side
    ((3, 5), 2.0, [1, 3])
    """
    ox, oy = (float(v) for v in offset)

    def weights(n, d, o):
        rel = np.arange(-(n - 1), n) + o / d       # (i − i') + offset / d: where the point lies, in elements
        a = np.abs(rel)
        tol = 1e-9
        return np.where(a < 0.5 - tol, 1.0, np.where(a <= 0.5 + tol, 0.5, 0.0))

    return c * np.outer(weights(grid.ny, grid.dy, oy), weights(grid.nx, grid.dx, ox))


def _layered_tt(grid, base: BlockToeplitz, c: float, offset, name: str) -> BlockToeplitz:
    k = grid_kernel(grid, c, offset)
    zero = None
    return base.combine(BlockToeplitz(grid, [[k, zero], [zero, k]], "layer"), 1.0, 1.0, name)


class LayeredOperators:
    """A 3D contact's operators (:class:`~rollqp.influence.grid.ContactOperators` or any model's with its
    interface) with the layer's compliance ``c`` in the tangential blocks (eq. L.2): ``A_tt``, its
    :meth:`shifted` copies and the :meth:`steady` slip operator; ``A_nn`` and the couplings are the bodies'.

    Examples
    --------
    >>> from rollqp.discretization.grid import Grid
    >>> from rollqp.materials import Materials
    >>> from rollqp.influence.grid import ContactOperators
    >>> base = ContactOperators(Grid.centred(6, 6, 1.0, 1.0), Materials.from_shear(1.0, 0.3, 1.0, 0.3))
    >>> ops = LayeredOperators(base, Layer(0.5, 1.0))
    >>> t = np.random.default_rng(1).random(72)
    >>> bool(np.allclose(ops.Att @ t, base.Att @ t + 0.5 * t, rtol=1e-13, atol=1e-15))
    True
    """

    def __init__(self, base, layer: Layer):
        self.base, self.layer = base, layer
        self.c = layer.compliance
        self.grid, self.materials, self.coupled = base.grid, base.materials, base.coupled
        self.Ann, self.Ant, self.Atn = base.Ann, base.Ant, base.Atn
        self.Att = _layered_tt(self.grid, base.Att, self.c, (0.0, 0.0), "Att+layer")
        self._cache = {}

    def shifted(self, which: str, offset: float):
        """As the bodies' :meth:`~rollqp.influence.grid.ContactOperators.shifted`, with the layer's jump at
        ``x + offset`` in ``"tt"``."""
        if which != "tt":
            return self.base.shifted(which, offset)
        key = ("tt", float(offset))
        if key not in self._cache:
            self._cache[key] = _layered_tt(self.grid, self.base.shifted("tt", offset), self.c, (float(offset), 0.0),
                                           f"tt(x{float(offset):+g})+layer")
        return self._cache[key]

    def steady(self, which: str, direction: int):
        """The steady slip operator ``A − A(· − d·dx)`` (eq. 3D.17) with the layer: in ``"tt"`` the bodies' plus
        ``c`` times the upwind difference."""
        if which != "tt":
            return self.base.steady(which, direction)
        key = ("steady", direction)
        if key not in self._cache:
            if direction not in (-1, 1):
                raise InputError("direction", f"must be -1 or +1, got {direction!r}")
            self._cache[key] = self.Att.combine(self.shifted("tt", -direction * self.grid.dx), 1.0, -1.0,
                                                "steady_tt+layer")
        return self._cache[key]

    def coordinates(self):
        """The element centres ``(x, y)``, flattened."""
        return self.base.coordinates()


def with_layer(ops, layer: Layer | None):
    """``ops`` with the layer's compliance (:class:`LayeredOperators`); ``ops`` itself without a layer or with
    ``h = 0``."""
    return ops if compliance_of(layer) == 0.0 else LayeredOperators(ops, layer)
