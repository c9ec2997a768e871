"""The :class:`Scene`: a validated rolling-contact problem, its parts checked key by key and as a whole.

The composition of the package: the records of :mod:`.schema`, checked by :mod:`.checks` at
construction, with the derived quantities of :mod:`.derived`; built from a nested dict here
(:func:`scene_from_dict`), written by :mod:`.plain`, read from files by :mod:`.io`.
"""
from __future__ import annotations

import dataclasses
import functools
import os
from dataclasses import dataclass, field, fields
from typing import Any, ClassVar

from ..errors import InputError, MissingBackendError
from ..histories import parse_history
from ..validate import suggestion
from . import checks
from .derived import Derived
from .plain import plain, scene_to_dict
from .schema import Body, Contact, Discretization, Load, SolverSettings
from ..profiles import parse_profile

__all__ = ["Scene", "SceneBase", "TwoBodyScene", "scene_from_dict", "table_keys", "check_top"]


class SceneBase:
    """What every scene is, whatever its dimension: ``dimension`` (a scene file's ``[contact]
    dimension``: 2, this package's :class:`Scene`; 3, :class:`rollqp.scene.grid.Scene3D`), and the
    interface the command line and a run read — ``name``, ``source``, ``solver``, ``n_steps``,
    ``to_dict()``, ``to_toml()``, ``replace(**changes)``."""

    dimension: ClassVar[int] = 2


class TwoBodyScene(SceneBase):
    """The schema a strip's and a grid's scene share: two bodies pressed together and rolled, the tables
    ``name, description, units, [bodies.A], [bodies.B], [contact], [load], [discretization], [solver]``,
    checked key by key at construction in that order and then as a whole; written as a nested dict and
    TOML; changed by dotted keys (:meth:`replace`). A dimension gives its parts' checks
    (:attr:`_PARTS`), its check of the whole (:meth:`_check_whole`), its plain values (:meth:`_plain`),
    the keys that exclude each other (:attr:`_EXCLUSIVE`) and its reader (:meth:`from_dict`)."""

    #: ``(attribute, check)`` of each part, in the order they are checked (``check(value)``: the normalized
    #: value, or an :class:`InputError` naming the dotted key).
    _PARTS: ClassVar[tuple] = ()
    #: Dotted keys that exclude each other: setting one by :meth:`replace` removes the other unless it is set too.
    _EXCLUSIVE: ClassVar[dict] = {}

    def __post_init__(self):
        put = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731 - frozen dataclass
        put("name", checks.check_scene_name("name", self.name))
        put("description", checks.string("description", self.description))
        for attr, check in self._PARTS:
            put(attr, check(getattr(self, attr)))
        put("units", checks.check_units("units", self.units))
        put("source", str(self.source))
        self._check_whole()

    def _check_whole(self) -> None:
        """The scene as a whole (after every part is checked)."""

    @staticmethod
    def _plain(value: Any) -> Any:
        """The plain (TOML) form of a value handed to :meth:`replace`."""
        return plain(value)

    @classmethod
    def from_dict(cls, d: Any, source: str = "<dict>", default_name: str = "scene"):
        """The scene of this dimension from its nested dict."""
        raise NotImplementedError

    # ------------------------------------------------------------------ output
    def to_toml(self) -> str:
        """The scene as TOML text (tomli-w), defaults filled in; reading it back gives an equal scene."""
        try:
            import tomli_w
        except ImportError as exc:
            raise MissingBackendError("writing a scene as TOML needs tomli-w: pip install 'rollqp[toml]'") from exc
        return tomli_w.dumps(self.to_dict())

    def replace(self, **changes: Any):
        """A new, validated scene with some values changed.

        Parameters
        ----------
        **changes
            Dotted keys and values, e.g. ``scene.replace(**{"solver.method": "qp-osqp",
            "load.tangential": Ramp(0.0, 0.5, 2.0)})``. Values are what the TOML file would
            hold (histories may be :class:`~rollqp.histories.History` objects, whole tables
            dicts or part objects such as :class:`Body`); ``None`` removes an optional key.
            Setting one of two keys that exclude each other (a 2D scene's ``load.tangential`` and
            ``load.creepage``) removes the other unless it is set too.

        Returns
        -------
        A scene of the same dimension.

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
                    raise InputError(".".join(parts[:i + 1]), f"is not a table; cannot set {dotted}")
                node = nxt
            if value is None:
                node.pop(parts[-1], None)
            else:
                node[parts[-1]] = self._plain(value)
            other = self._EXCLUSIVE.get(dotted)
            if other is not None and value is not None and other not in changes:
                table, name = other.rsplit(".", 1)
                d[table].pop(name, None)
        return self.from_dict(d, source=self.source, default_name=self.name)


@dataclass(frozen=True)
class Scene(Derived, TwoBodyScene):
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

    _PARTS: ClassVar[tuple] = (("A", functools.partial(checks.check_body, "bodies.A")),
                               ("B", functools.partial(checks.check_body, "bodies.B")),
                               ("contact", checks.check_contact), ("load", checks.check_load),
                               ("discretization", checks.check_discretization), ("solver", checks.check_solver))
    _EXCLUSIVE: ClassVar[dict] = {"load.tangential": "load.creepage", "load.creepage": "load.tangential"}

    def _check_whole(self) -> None:
        checks.check_whole(self)

    @classmethod
    def from_dict(cls, d: Any, source: str = "<dict>", default_name: str = "scene") -> "Scene":
        """:func:`scene_from_dict`."""
        return scene_from_dict(d, source=source, default_name=default_name)

    def to_dict(self) -> dict:
        """The full scene as a nested plain dict, defaults filled in (:func:`.plain.scene_to_dict`)."""
        return scene_to_dict(self)


# =========================================================================== from a dict
_TOP_KEYS = ("name", "description", "units", "bodies", "contact", "load", "discretization", "solver")
_SECTIONS: dict[str, type] = {"contact": Contact, "load": Load,
                              "discretization": Discretization, "solver": SolverSettings}


def _unknown(key: str, word: str, allowed, where: str) -> InputError:
    hint = suggestion(word, allowed)
    return InputError(key, f"unknown key{hint} (allowed in {where}: {', '.join(allowed)})")


def table_keys(d: Any, key: str, cls: type, also=(), where: str | None = None, each_missing: bool = False) -> dict:
    """The keys of table ``key`` for the record ``cls`` (a dataclass), unknown and missing keys checked: an
    unknown key names itself and the allowed ones (``where``: how the message names the table, default
    ``[key]``); a missing required key (a field without a default, and ``also``) names itself, several
    missing ones name the table (``each_missing``: the first of them instead)."""
    where = where or f"[{key}]"
    if not isinstance(d, dict):
        raise InputError(key, f"must be a table [{key}], got {d!r}")
    names = [f.name for f in fields(cls)]
    for k in d:
        if k not in names:
            raise _unknown(f"{key}.{k}", k, names, where)
    required = [f.name for f in fields(cls)
                if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING] + list(also)
    missing = [k for k in required if k not in d]
    if len(missing) == 1 or missing and each_missing:
        raise InputError(f"{key}.{missing[0]}", f"missing required key ([{key}] needs {', '.join(required)})")
    if missing:
        raise InputError(key, "missing required keys " + ", ".join(f"{key}.{k}" for k in missing)
                              + f" ([{key}] needs {', '.join(required)})")
    return dict(d)


def check_top(d: Any) -> dict:
    """The top level of a scene's nested dict (either dimension): a table, no unknown key, the tables
    ``[bodies]``, ``[contact]`` and ``[load]`` present."""
    if not isinstance(d, dict):
        raise InputError("SCENE", f"must be a table of tables, got {type(d).__name__}")
    for k in d:
        if k not in _TOP_KEYS:
            raise _unknown(k, k, _TOP_KEYS, "the top level")
    for k in ("bodies", "contact", "load"):
        if k not in d:
            raise InputError(k, f"missing required table [{k}]")
    return d


def _body(d: Any, key: str, source: str) -> Body:
    """``[bodies.X]``, its ``profile`` read with the scene file's folder (:func:`rollqp.profiles.parse_profile`)."""
    t = table_keys(d, key, Body)
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
    check_top(d)
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
            parts[k] = table_keys(d[k], k, cls)
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
