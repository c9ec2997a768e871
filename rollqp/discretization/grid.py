r"""The uniform rectangular grid of the potential contact area (docs/theory3d.md §3).

Kalker's discretization: the potential contact area, a rectangle in the plane ``z = 0``, is
divided into ``nx × ny`` equal elements of size ``dx × dy``; tractions are constant on each
element and the contact conditions are collocated at the element centres

.. math::
    x_i = x_l + (i + \tfrac12)\,dx,\quad i = 0 … n_x − 1, \qquad
    y_j = y_l + (j + \tfrac12)\,dy,\quad j = 0 … n_y − 1          \qquad (3D.9)

(CONTACT's definition with its ``XL, YL, DX, DY``). Fields live on the grid as arrays of shape
``(ny, nx)`` (row ``j`` is ``y_j``, column ``i`` is ``x_i``, the layout of the result file) and
are flattened in C order, element ``k = j·nx + i``, for the linear algebra.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import Discretization
from ..errors import InputError
from ..validate import positive, scalar

__all__ = ["Grid", "ASPECT_RANGE", "MAX_ELEMENTS"]

#: Allowed element aspect ratios ``dx/dy``. The influence coefficients are exact for any
#: rectangle, but centre collocation resolves the traction only to ``O(max(dx, dy))``: beyond
#: this range the long side decides the error and the short side is wasted (docs/validation3d.md,
#: "element aspect ratio", measures the Hertz error against the aspect ratio).
ASPECT_RANGE = (0.2, 5.0)
#: Largest grid (elements). The FFT path needs ``O(n)`` memory (about 100 bytes an element per
#: kernel), the Newton method's Krylov solves a few dozen vectors of ``2n``: 10⁶ elements are a
#: few GB, beyond what this machine (and most laptops) has to spare.
MAX_ELEMENTS = 1_000_000


def _positive_int(name, v) -> int:
    if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 1:
        raise InputError(name, f"must be an integer >= 1, got {v!r}")
    return int(v)


@dataclass(frozen=True)
class Grid:
    """A uniform grid of ``nx × ny`` rectangular elements (eq. 3D.9).

    Parameters
    ----------
    nx, ny : int
        Elements along x (rolling direction) and y (lateral).
    dx, dy : float
        Element sizes (> 0).
    xl, yl : float
        Lower-left corner of the potential contact area (element centres at
        ``xl + (i + 1/2) dx``).

    Raises
    ------
    InputError
        Naming the argument, for a non-positive count or size, an aspect ratio ``dx/dy``
        outside :data:`ASPECT_RANGE`, or more than :data:`MAX_ELEMENTS` elements.

    Examples
    --------
    >>> g = Grid.centred(4, 2, 1.0, 0.5)
    >>> g.x, g.y
    (array([-0.75, -0.25,  0.25,  0.75]), array([-0.25,  0.25]))
    >>> g.n, g.area
    (8, 0.25)
    """

    nx: int
    ny: int
    dx: float
    dy: float
    xl: float
    yl: float

    def __post_init__(self):
        object.__setattr__(self, "nx", _positive_int("nx", self.nx))
        object.__setattr__(self, "ny", _positive_int("ny", self.ny))
        for name in ("dx", "dy"):
            object.__setattr__(self, name, positive(name, getattr(self, name)))
        for name in ("xl", "yl"):
            object.__setattr__(self, name, scalar(name, getattr(self, name)))
        if self.nx * self.ny > MAX_ELEMENTS:
            raise InputError("elements", f"nx·ny = {self.nx * self.ny} exceeds {MAX_ELEMENTS} elements")
        lo, hi = ASPECT_RANGE
        if not lo <= self.dx / self.dy <= hi:
            raise InputError("elements", f"element aspect ratio dx/dy = {self.dx / self.dy:.4g} must be in "
                                         f"[{lo:g}, {hi:g}] (centre collocation loses accuracy beyond)")

    @classmethod
    def centred(cls, nx: int, ny: int, half_x: float, half_y: float) -> "Grid":
        """The grid of ``nx × ny`` elements on ``[−half_x, half_x] × [−half_y, half_y]``."""
        half_x = positive("half_x", half_x)
        half_y = positive("half_y", half_y)
        nx, ny = _positive_int("nx", nx), _positive_int("ny", ny)
        return cls(nx, ny, 2 * half_x / nx, 2 * half_y / ny, -half_x, -half_y)

    @classmethod
    def for_ellipse(cls, a: float, b: float, elements, zone=(1.25, 1.25)) -> "Grid":
        """The centred grid of ``elements = (nx, ny)`` on ``zone[0]·a × zone[1]·b`` half-widths.

        The scene keys ``discretization.elements`` and ``discretization.zone`` (SPEC): a zone
        below 1 would cut the Hertz ellipse, an :class:`InputError` naming ``zone``.
        """
        nx, ny = elements
        zx, zy = (positive("zone", z) for z in zone)
        if zx <= 1 or zy <= 1:
            raise InputError("zone", f"half-widths / (a, b) must be > 1 so that the grid covers the Hertz "
                                     f"ellipse, got {tuple(zone)}")
        return cls.centred(nx, ny, zx * a, zy * b)

    # ------------------------------------------------------------------ geometry
    @property
    def n(self) -> int:
        """Number of elements ``nx·ny``."""
        return self.nx * self.ny

    @property
    def area(self) -> float:
        """Element area ``dx·dy``: the weight of every element in a force (eq. 3D.14)."""
        return self.dx * self.dy

    @property
    def shape(self) -> tuple[int, int]:
        """``(ny, nx)``: the shape of a field on the grid."""
        return self.ny, self.nx

    @property
    def x(self) -> np.ndarray:
        """Element centres along x, ``(nx,)``."""
        return self.xl + (np.arange(self.nx) + 0.5) * self.dx

    @property
    def y(self) -> np.ndarray:
        """Element centres along y, ``(ny,)``."""
        return self.yl + (np.arange(self.ny) + 0.5) * self.dy

    def centres(self) -> tuple[np.ndarray, np.ndarray]:
        """``(X, Y)``: the centre coordinates of every element, flattened (``(n,)`` each)."""
        X, Y = np.meshgrid(self.x, self.y)
        return X.ravel(), Y.ravel()

    def record(self) -> Discretization:
        """The grid as a :class:`~rollqp.discretization.Discretization`: the element centres ``(x, y)``, the
        element area as every weight, two traction components, fields of shape ``(ny, nx)``."""
        return Discretization(np.stack(self.centres()), np.full(self.n, self.area), 2, self.shape)

    def field(self, v) -> np.ndarray:
        """A flattened field ``(n,)`` (or ``(k, n)``) as ``(ny, nx)`` (or ``(k, ny, nx)``)."""
        v = np.asarray(v)
        return v.reshape(v.shape[:-1] + self.shape)

    def covers(self, a: float, b: float) -> bool:
        """Whether the ellipse of semi-axes ``a, b`` centred at 0 lies inside the grid without its
        outermost rows and columns of elements (which then carry no pressure)."""
        xl, xh = self.xl + self.dx, self.xl + (self.nx - 1) * self.dx
        yl, yh = self.yl + self.dy, self.yl + (self.ny - 1) * self.dy
        return xl <= -a and xh >= a and yl <= -b and yh >= b
