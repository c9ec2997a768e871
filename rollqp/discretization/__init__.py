"""Discretizations of the potential contact area, as one record: :class:`Discretization`.

A step problem sees its discretization through four things — the points where the unknowns sit
(``points``, shape ``(d, n)``: ``x`` on a strip, ``(x, y)`` on a grid), their weights in a force
(``weights``, ``(n,)``: ``P = weightsᵀ p``), the number of tangential traction components ``k`` (1 on a
strip, 2 on a grid) and the shape a field of it is stored in. The strip of nodes along x
(:class:`rollqp.strip.Strip`, two dimensions) and the uniform grid of rectangles
(:class:`rollqp.discretization.grid.Grid`, three) are its two leaves: each gives its record
(``record()``), and what is written once for both — the friction laws read at the ``points``
(:class:`rollqp.friction.FrictionLaw`), the projection onto the ball of ``k`` components
(:mod:`rollqp.friction.projection`) — reads the record, not the leaf.

Examples
--------
>>> from rollqp.discretization.grid import Grid
>>> r = Grid.centred(4, 3, 1.0, 1.0).record()
>>> r.dimension, r.components, r.points.shape, r.field_shape
(3, 2, (2, 12), (3, 4))
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError

__all__ = ["Discretization"]


@dataclass(frozen=True)
class Discretization:
    """The record of a discretization (module docstring): ``points`` ``(d, n)``, ``weights`` ``(n,)``,
    ``components`` ``k`` and ``field_shape`` (the shape a field of one value per point is stored in)."""

    points: np.ndarray
    weights: np.ndarray
    components: int
    field_shape: tuple

    def __post_init__(self):
        pts, w = np.asarray(self.points, dtype=float), np.asarray(self.weights, dtype=float)
        if pts.ndim != 2 or pts.shape[0] not in (1, 2):
            raise InputError("points", f"must have shape (d, n) with d = 1 or 2, got {pts.shape}")
        if w.shape != (pts.shape[1],):
            raise InputError("weights", f"must have shape ({pts.shape[1]},), got {w.shape}")
        if self.components not in (1, 2):
            raise InputError("components", f"must be 1 or 2, got {self.components!r}")
        if int(np.prod(self.field_shape)) != pts.shape[1]:
            raise InputError("field_shape", f"must hold {pts.shape[1]} values, got {self.field_shape}")

    @property
    def n(self) -> int:
        """The number of points."""
        return self.points.shape[1]

    @property
    def dimension(self) -> int:
        """The problem's dimension: 2 for points along a line, 3 for points on a surface."""
        return self.points.shape[0] + 1
