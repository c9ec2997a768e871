"""The unit names of a scene's numbers, for the summary and the figures (docs/scenes.md, ``units``).

rollqp computes in whatever consistent units a scene is written in (the paper: N and mm). A
scene may say which with the top-level key ``units``; the summary and the figures then print
a_H, p0, loads and energies with their names (``a_H = 1.050 mm, p0 = 606.0 MPa``). Without it
they say "scene units". Nothing is converted: the key names the units the numbers already are in.

Examples
--------
>>> unit_names("N-mm").stress
'MPa'
>>> unit_names("").length
'length units'
"""
from __future__ import annotations

from typing import NamedTuple


class UnitNames(NamedTuple):
    """Names of the derived units of one system (loads and energies per unit axial length, 2D)."""

    length: str
    stress: str
    load: str      # force per unit axial length (P, Q)
    energy: str    # energy per unit axial length (friction work)
    rate: str      # energy per unit axial length and rolled distance (dissipation)


#: The ``units`` a scene may declare (the key's allowed values); ``""``: not declared.
UNIT_SYSTEMS = {
    "N-mm": UnitNames("mm", "MPa", "N/mm", "N·mm/mm", "N/mm"),
    "N-m": UnitNames("m", "Pa", "N/m", "J/m", "N/m"),
    "lbf-in": UnitNames("in", "psi", "lbf/in", "lbf·in/in", "lbf/in"),
}
UNDECLARED = UnitNames("length units", "stress units", "force/length", "energy/length", "force/length")


def unit_names(units: str | None) -> UnitNames:
    """The :class:`UnitNames` of a declared system, or the generic names when none is declared."""
    return UNIT_SYSTEMS.get(units or "", UNDECLARED)

