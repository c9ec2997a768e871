"""Closed-form solutions of 2D (plane-strain) contact of cylinders, for checking the solvers.

docs/formulation.md §12 restated as functions. Every function uses the project's sign convention
(docs/formulation.md §1):

* ``p ≥ 0`` is the contact pressure (compression positive);
* ``t`` is the tangential traction acting on body A in ``+x`` (B receives ``-t``),
  ``Q = ∫ t dx`` is the tangential load on A;
* ``ξ = (V_A − V_B)/|V|`` is the creepage (rigid slip of A relative to B);
* material moves through the contact with direction ``d = sgn(V)``: it enters at the
  leading edge ``x = −d·a`` and leaves at the trailing edge ``x = +d·a``;
* ``ratio = Q/(μP)`` is the signed tangential load ratio.

Symbols: ``P`` normal load per unit length, ``R`` relative radius (``1/R = 1/R_A + 1/R_B``),
``E*`` contact modulus (``1/E* = (1−ν_A²)/E_A + (1−ν_B²)/E_B``), ``a`` contact half-width,
``p0`` peak Hertz pressure, ``μ`` Coulomb friction coefficient. Any consistent units.

All traction and pressure functions are vectorized over ``x``: they accept a scalar or an
array and return a float or an ndarray of the same shape; they are zero outside
``|x| ≤ a``.

The 2D Hertz approach (rigid-body approach of the axes) is deliberately *not* given: in
plane strain it depends on how the bodies are supported far from the contact (the
logarithmic rigid constant ``d_ref`` of docs/formulation.md §3), so there is no definite
half-space formula to check against.

One module per closed form, each citing its source (its ``SOURCE``) and defining its symbols:
:mod:`.hertz`, :mod:`.cattaneo`, :mod:`.carter`, :mod:`.bentall_johnson`, :mod:`.mindlin`,
:mod:`.rounded_punch`, :mod:`.lame`, :mod:`.mcewen`, :mod:`.brush`. Every function is importable from here as
``rollqp.closedforms.<name>``; :data:`SOURCES` maps each function's name to its citation.

The 3D closed forms are modules of their own here, not imported with the package (``import rollqp`` stays
light): :mod:`.hertz_ellipse` (the Hertz ellipse), :mod:`.kalker` (Kalker's linear theory, Table E.3),
:mod:`.cattaneo3d` (Cattaneo–Mindlin on the circle) and :mod:`.hertz3d` (stresses below a circular contact).
"""
from __future__ import annotations
from __future__ import annotations

from . import bentall_johnson, brush, carter, cattaneo, hertz, lame, mcewen, mindlin, rounded_punch
from .bentall_johnson import BENTALL_JOHNSON_COEFFICIENT, bentall_johnson_creepage
from .brush import brush_creep_ratio, brush_kappa
from .carter import (carter_creepage, carter_slip, carter_stick_zone, carter_traction,
                     creep_force_ratio)
from .cattaneo import cattaneo_stick_half_width, cattaneo_traction
from .hertz import hertz_half_width, hertz_peak_pressure, hertz_pressure
from .lame import lame_ring_displacement
from .mcewen import HERTZ_MAX_SHEAR, hertz_subsurface_stresses, mcewen_stresses
from .mindlin import mindlin_displacement, mindlin_dissipation, mindlin_traction, mindlin_turning_points
from .rounded_punch import rounded_punch_half_width, rounded_punch_load, rounded_punch_pressure

__all__ = [
    "hertz_half_width",
    "hertz_peak_pressure",
    "hertz_pressure",
    "cattaneo_stick_half_width",
    "cattaneo_traction",
    "carter_stick_zone",
    "carter_traction",
    "carter_creepage",
    "carter_slip",
    "creep_force_ratio",
    "bentall_johnson_creepage",
    "brush_creep_ratio",
    "brush_kappa",
    "BENTALL_JOHNSON_COEFFICIENT",
    "lame_ring_displacement",
    "SOURCES",
    "mindlin_turning_points",
    "mindlin_traction",
    "mindlin_dissipation",
    "mindlin_displacement",
    "rounded_punch_load",
    "rounded_punch_half_width",
    "rounded_punch_pressure",
    "mcewen_stresses",
    "hertz_subsurface_stresses",
    "HERTZ_MAX_SHEAR",
]

#: Citation of each function's closed form (each module's ``SOURCE``).
SOURCES: dict[str, str] = {
    **dict.fromkeys(("hertz_half_width", "hertz_peak_pressure", "hertz_pressure"), hertz.SOURCE),
    **dict.fromkeys(("cattaneo_stick_half_width", "cattaneo_traction"), cattaneo.SOURCE),
    **dict.fromkeys(("carter_stick_zone", "carter_traction", "carter_creepage", "carter_slip"), carter.SOURCE),
    "creep_force_ratio": carter.SOURCE + "; " + carter.KALKER,
    "bentall_johnson_creepage": bentall_johnson.SOURCE,
    **dict.fromkeys(("brush_creep_ratio", "brush_kappa"), brush.SOURCE),
    "lame_ring_displacement": lame.SOURCE,
    **dict.fromkeys(("mindlin_turning_points", "mindlin_traction", "mindlin_dissipation", "mindlin_displacement"),
                    mindlin.SOURCE),
    **dict.fromkeys(("rounded_punch_load", "rounded_punch_half_width", "rounded_punch_pressure"), rounded_punch.SOURCE),
    **dict.fromkeys(("hertz_subsurface_stresses", "mcewen_stresses"), mcewen.SOURCE),
}
