r"""The influence operators of one contact, built once per grid and materials (docs/theory3d.md §3–4).

:class:`ContactOperators` holds ``A_nn`` (1 × 1), ``A_tt`` (2 × 2), and for dissimilar bodies the
couplings ``A_nt`` (1 × 2: gap due to shear) and ``A_tn`` (2 × 1: tangential displacement due
to pressure), as :class:`~rollqp.influence.blocktoeplitz.BlockToeplitz` operators, and derives on first
use (kept) the operators of a rolling step:

* the displacements at the previous position of the particles, ``x − d·Δq`` (eq. 3D.16): the
  same kernels evaluated with the offset ``−d·Δq`` along x (:meth:`shifted`);
* the steady slip operator ``A_tt − A_tt(· − d·dx)`` (eq. 3D.17, with ``Δq = dx``): the exact
  difference of the two kernels, so no row of it is truncated at the edge of the grid
  (:meth:`steady`).

``d`` is the direction in which material moves through the contact (docs/formulation.md §1):
``d = −1`` is CONTACT's rolling in +x (``CHI = 0``), material entering at ``x = +a``.
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError
from .cerruti import kernels
from .blocktoeplitz import BlockToeplitz

__all__ = ["ContactOperators"]


def _blocks(k, layout):
    return [[k.get(c) if c is not None else None for c in row] for row in layout]


_LAYOUTS = {
    "nn": [["nn"]],
    "tt": [["xx", "xy"], ["yx", "yy"]],
    "nt": [["nx", "ny"]],
    "tn": [["xn"], ["yn"]],
}


class ContactOperators:
    """The influence operators of a grid and a pair of materials (module docstring).

    Parameters
    ----------
    grid : rollqp.discretization.grid.Grid
    materials : rollqp.materials.Materials

    Examples
    --------
    >>> from rollqp.discretization.grid import Grid
    >>> from rollqp.materials import Materials
    >>> ops = ContactOperators(Grid.centred(8, 8, 1.0, 1.0), Materials.from_young(210e3, 0.3, 210e3, 0.3))
    >>> ops.Ann.shape, ops.Att.shape, ops.coupled
    ((64, 64), (128, 128), False)
    """

    def __init__(self, grid, materials):
        self.grid, self.materials = grid, materials
        self._cache = {}
        k = kernels(grid, materials)
        self.Ann = BlockToeplitz(grid, _blocks(k, _LAYOUTS["nn"]), "Ann")
        self.Att = BlockToeplitz(grid, _blocks(k, _LAYOUTS["tt"]), "Att")
        self.coupled = materials.K != 0.0
        self.Ant = BlockToeplitz(grid, _blocks(k, _LAYOUTS["nt"]), "Ant") if self.coupled else None
        self.Atn = BlockToeplitz(grid, _blocks(k, _LAYOUTS["tn"]), "Atn") if self.coupled else None

    def shifted(self, which: str, offset: float) -> BlockToeplitz:
        """``A_tt`` (``which="tt"``) or ``A_tn`` (``"tn"``) evaluated at ``x + offset``: the
        displacements, due to tractions on the grid, of the points one step upstream
        (``offset = −d·Δq``, eq. 3D.16). Kept per ``(which, offset)``."""
        if which not in ("tt", "tn"):
            raise InputError("which", f"must be 'tt' or 'tn', got {which!r}")
        if which == "tn" and not self.coupled:
            return None
        key = (which, float(offset))
        if key not in self._cache:
            comps = [c for row in _LAYOUTS[which] for c in row]
            k = kernels(self.grid, self.materials, offset=(float(offset), 0.0), components=comps)
            self._cache[key] = BlockToeplitz(self.grid, _blocks(k, _LAYOUTS[which]), f"{which}(x{offset:+g})")
        return self._cache[key]

    def steady(self, which: str, direction: int) -> BlockToeplitz:
        """The steady slip operator ``A − A(· − d·dx)`` of eq. 3D.17 (``which`` ``"tt"`` or ``"tn"``;
        divide by ``dx`` for the slip): ``s = w + (A t − A(· − d dx) t)/dx``."""
        if direction not in (-1, 1):
            raise InputError("direction", f"must be -1 or +1, got {direction!r}")
        key = ("steady", which, direction)
        if key not in self._cache:
            base = self.Att if which == "tt" else self.Atn
            if base is None:
                return None
            self._cache[key] = base.combine(self.shifted(which, -direction * self.grid.dx), 1.0, -1.0,
                                            f"steady_{which}")
        return self._cache[key]

    def coordinates(self) -> tuple[np.ndarray, np.ndarray]:
        """The element centres ``(x, y)``, flattened."""
        return self.grid.centres()
