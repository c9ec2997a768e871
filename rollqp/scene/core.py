"""The :class:`Scene`: a validated rolling-contact problem, its parts checked key by key and as a whole.

The composition of the package: the records of :mod:`.schema`, checked by :mod:`.checks` at
construction, with the derived quantities of :mod:`.derived`; read and written by :mod:`.io`.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from ..errors import InputError
from . import checks
from .derived import Derived
from .schema import Body, Contact, Discretization, Load, SolverSettings

__all__ = ["Scene"]


@dataclass(frozen=True)
class Scene(Derived):
    """A validated rolling-contact problem (docs/scenes.md).

    Construction validates every field and the scene as a whole and normalizes the values
    (numbers to float, history tables to :class:`~rollqp.histories.History`); the parts
    (:class:`Body`, …) are plain records checked here, with their dotted scene keys.

    Parameters
    ----------
    name, description : str
        Identification; the description is one line.
    A, B : Body
        The two cylinders (``[bodies.A]``, ``[bodies.B]``); tangential traction and creepage
        are reported for body A.
    contact : Contact
    load : Load
    discretization : Discretization
    solver : SolverSettings
    units : str
        The units the numbers are in, for the summary and figures only (:data:`rollqp.units.UNIT_SYSTEMS`:
        ``"N-mm"``, ``"N-m"``, ``"lbf-in"``; ``""``: not declared). Nothing is converted.
    source : str
        Where the scene came from (a path, ``builtin:<name>`` or ``<dict>``); not compared.

    Raises
    ------
    InputError
        Naming the dotted key and the allowed range.
    """

    name: str
    description: str
    A: Body
    B: Body
    contact: Contact
    load: Load
    discretization: Discretization = field(default_factory=Discretization)
    solver: SolverSettings = field(default_factory=SolverSettings)
    units: str = ""
    source: str = field(default="<dict>", compare=False)

    def __post_init__(self):
        put = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731 - frozen dataclass
        put("name", checks.check_scene_name("name", self.name))
        put("description", checks.string("description", self.description))
        put("A", checks.check_body("bodies.A", self.A))
        put("B", checks.check_body("bodies.B", self.B))
        put("contact", checks.check_contact(self.contact))
        put("load", checks.check_load(self.load))
        put("discretization", checks.check_discretization(self.discretization))
        put("solver", checks.check_solver(self.solver))
        put("units", checks.check_units("units", self.units))
        put("source", str(self.source))
        checks.check_whole(self)

    # ------------------------------------------------------------------ output
    def to_dict(self) -> dict:
        """The full scene as a nested plain dict, defaults filled in (:func:`.io.scene_to_dict`)."""
        from .io import scene_to_dict
        return scene_to_dict(self)

    def to_toml(self) -> str:
        """The scene as TOML text, defaults filled in (:func:`.io.scene_to_toml`); :func:`load_scene`
        of the text gives back an equal scene."""
        from .io import scene_to_toml
        return scene_to_toml(self)

    def replace(self, **changes: Any) -> "Scene":
        """A new, validated scene with some values changed.

        Parameters
        ----------
        **changes
            Dotted keys and values, e.g. ``scene.replace(**{"solver.method": "qp-osqp",
            "load.tangential": Ramp(0.0, 0.5, 2.0)})``. Values are what the TOML file would
            hold (histories may be :class:`~rollqp.histories.History` objects, whole tables
            dicts or part objects such as :class:`Body`); ``None`` removes an optional key.
            Setting one of ``load.tangential``/``load.creepage`` removes the other unless it
            is set too.

        Returns
        -------
        Scene

        Raises
        ------
        InputError
            As for a scene file, naming the dotted key.
        """
        from .io import plain, scene_from_dict
        d = self.to_dict()
        for dotted, value in changes.items():
            parts = dotted.split(".")
            node = d
            for i, part in enumerate(parts[:-1]):
                nxt = node.setdefault(part, {})
                if not isinstance(nxt, dict):
                    raise InputError(".".join(parts[:i + 1]), f"is not a table; cannot set "
                                                              f"{dotted}")
                node = nxt
            if value is None:
                node.pop(parts[-1], None)
            else:
                node[parts[-1]] = plain(value)
            pair = {"load.tangential": "creepage", "load.creepage": "tangential"}
            if dotted in pair and value is not None and f"load.{pair[dotted]}" not in changes:
                d["load"].pop(pair[dotted], None)
        return scene_from_dict(d, source=self.source, default_name=self.name)

