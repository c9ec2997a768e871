"""The :class:`Scene`: a validated rolling-contact problem, its parts checked key by key and as a whole.

The composition of the package: the records of :mod:`.schema`, checked by :mod:`.checks` at
construction, with the derived quantities of :mod:`.derived`; built from a nested dict here
(:func:`scene_from_dict`), written by :mod:`.plain`, read from files by :mod:`.io`.
"""
from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass, field, fields
from typing import Any, ClassVar

from ..errors import InputError
from ..histories import parse_history
from ..validate import suggestion
from . import checks
from .derived import Derived
from .plain import plain, scene_to_dict, scene_to_toml
from .schema import Body, Contact, Discretization, Load, SolverSettings
from ..profiles import parse_profile

__all__ = ["Scene", "SceneBase", "scene_from_dict"]


class SceneBase:
    """What every scene is, whatever its dimension: ``dimension`` (a scene file's ``[contact]
    dimension``: 2, this package's :class:`Scene`; 3, :class:`rollqp.scene.grid.Scene3D`), and the
    interface the command line and a run read — ``name``, ``source``, ``solver``, ``n_steps``,
    ``to_dict()``, ``to_toml()``, ``replace(**changes)``."""

    dimension: ClassVar[int] = 2


@dataclass(frozen=True)
class Scene(Derived, SceneBase):
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
        """The full scene as a nested plain dict, defaults filled in (:func:`.plain.scene_to_dict`)."""
        return scene_to_dict(self)

    def to_toml(self) -> str:
        """The scene as TOML text, defaults filled in (:func:`.plain.scene_to_toml`); :func:`load_scene`
        of the text gives back an equal scene."""
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


# =========================================================================== from a dict
_TOP_KEYS = ("name", "description", "units", "bodies", "contact", "load", "discretization", "solver")
_SECTIONS: dict[str, type] = {"contact": Contact, "load": Load,
                              "discretization": Discretization, "solver": SolverSettings}


def _unknown(key: str, word: str, allowed, where: str) -> InputError:
    hint = suggestion(word, allowed)
    return InputError(key, f"unknown key{hint} (allowed in {where}: {', '.join(allowed)})")


def _table(d: dict, key: str, cls: type) -> dict:
    """The keys of table ``key`` for dataclass ``cls``: unknown and missing keys checked."""
    where = f"[{key}]"
    if not isinstance(d, dict):
        raise InputError(key, f"must be a table {where}, got {d!r}")
    names = [f.name for f in fields(cls)]
    for k in d:
        if k not in names:
            raise _unknown(f"{key}.{k}", k, names, where)
    required = [f.name for f in fields(cls)
                if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING]
    missing = [k for k in required if k not in d]
    if len(missing) == 1:
        raise InputError(f"{key}.{missing[0]}",
                         f"missing required key ({where} needs {', '.join(required)})")
    if missing:
        raise InputError(key, "missing required keys " + ", ".join(f"{key}.{k}" for k in missing)
                              + f" ({where} needs {', '.join(required)})")
    return dict(d)


def _body(d: Any, key: str, source: str) -> Body:
    """``[bodies.X]``, its ``profile`` read with the scene file's folder (:func:`rollqp.profiles.parse_profile`)."""
    t = _table(d, key, Body)
    if "profile" in t:
        folder = os.path.dirname(os.path.abspath(source)) if os.path.isfile(source) else None
        radius = t.get("radius")
        if not (isinstance(radius, (int, float)) and not isinstance(radius, bool) and radius > 0):
            raise InputError(f"{key}.radius", f"must be a number > 0, got {radius!r}")
        t["profile"] = parse_profile(t["profile"], f"{key}.profile", float(radius), folder)
    return Body(**t)


def scene_from_dict(d: Any, source: str = "<dict>", default_name: str = "scene") -> Scene:
    """Build and validate a scene from its nested dict (the parsed TOML).

    Parameters
    ----------
    d : dict
        ``{"name": ..., "bodies": {"A": {...}, "B": {...}}, "contact": {...}, ...}``;
        ``[discretization]`` and ``[solver]`` may be absent (defaults).
    source : str
        Recorded in :attr:`Scene.source`.
    default_name : str
        Name of a scene without ``name``.

    Returns the validated :class:`Scene`; every invalid input is an :class:`InputError` naming
    the dotted key.
    """
    if not isinstance(d, dict):
        raise InputError("SCENE", f"must be a table of tables, got {type(d).__name__}")
    for k in d:
        if k not in _TOP_KEYS:
            raise _unknown(k, k, _TOP_KEYS, "the top level")
    for k in ("bodies", "contact", "load"):
        if k not in d:
            raise InputError(k, f"missing required table [{k}]")
    bodies = d["bodies"]
    if not isinstance(bodies, dict):
        raise InputError("bodies", f"must be a table with [bodies.A] and [bodies.B], got "
                                   f"{bodies!r}")
    for k in bodies:
        if k not in ("A", "B"):
            raise _unknown(f"bodies.{k}", k, ("A", "B"), "[bodies]")
    for k in ("A", "B"):
        if k not in bodies:
            raise InputError(f"bodies.{k}", f"missing required table [bodies.{k}] "
                                            "(needs radius, E, nu)")
    A, B = (_body(bodies[k], f"bodies.{k}", source) for k in ("A", "B"))
    parts = {}
    for k, cls in _SECTIONS.items():
        if k in d or k in ("contact", "load"):
            parts[k] = _table(d[k], k, cls)
        else:
            parts[k] = {}
    ld = parts["load"]
    if "normal_history" in ld:
        ld["normal_history"] = parse_history(ld["normal_history"], "load.normal_history",
                                             constant_default=1.0)
    for k in ("tangential", "creepage", "approach", "rolled"):
        if k in ld:
            ld[k] = parse_history(ld[k], f"load.{k}")
    return Scene(name=d.get("name", default_name), description=d.get("description", ""), units=d.get("units", ""),
                 A=A, B=B, contact=Contact(**parts["contact"]), load=Load(**ld),
                 discretization=Discretization(**parts["discretization"]),
                 solver=SolverSettings(**parts["solver"]), source=source)
