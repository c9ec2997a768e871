"""Scenes in and out: TOML files, dicts and the built-in scenes; TOML written by tomli-w.

Reading (:func:`load_scene`, :func:`scene_from_toml`, :func:`scene_from_dict`) checks the
structure — unknown and missing keys, named with their dotted path and the closest valid name —
and hands the values to :class:`~rollqp.scene.Scene`, which checks them. Nothing read is ever
executed or used as a path (a scene's name is restricted, docs/scenes.md). Writing
(:func:`scene_to_dict`, :func:`scene_to_toml`) gives the full scene with its defaults; the TOML
goes through the ``tomli-w`` library (optional extra ``toml``), floats with ``repr`` precision so
that reading the text back gives an equal scene.
"""
from __future__ import annotations

import dataclasses
import os
from dataclasses import fields
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

try:  # Python >= 3.11
    import tomllib
except ModuleNotFoundError:  # pragma: no cover - Python 3.10
    import tomli as tomllib  # type: ignore[no-redef]

from ..errors import InputError, MissingBackendError
from ..histories import History, parse_history
from .checks import safe_name
from .core import Scene
from .schema import Body, Contact, Discretization, Load, SolverSettings
from .validate import suggestion

__all__ = ["load_scene", "scene_from_dict", "scene_from_toml", "builtin_scenes", "scene_to_dict", "scene_to_toml"]

#: Largest scene file read (bytes): scenes are a few hundred bytes; tables of 10^5 points fit.
MAX_FILE_BYTES = 16 << 20


# =========================================================================== output
def part_dict(obj) -> dict:
    """Plain dict of a part (Body, …, History), None values left out."""
    if isinstance(obj, History):
        return obj.to_dict()
    return {f.name: plain(getattr(obj, f.name)) for f in fields(obj) if getattr(obj, f.name) is not None}


def plain(v: Any) -> Any:
    """Plain (TOML/JSON) form of a value: histories and parts become dicts."""
    from ..profiles import Profile
    if isinstance(v, Profile):
        return v.to_dict()
    if isinstance(v, History) or dataclasses.is_dataclass(v) and not isinstance(v, type):
        return part_dict(v)
    if isinstance(v, np.generic):
        return v.item()
    return v


def scene_to_dict(scene: Scene) -> dict:
    """The full scene as a nested plain dict, defaults filled in.

    Histories are their inline-table dicts; absent optional values (``shaft_radius``,
    ``reference_distance``, the unused one of ``tangential``/``creepage``) are left out,
    since TOML has no null. JSON-serializable; :func:`scene_from_dict` reads it back.
    """
    return {"name": scene.name, "description": scene.description, **({"units": scene.units} if scene.units else {}),
            "bodies": {"A": part_dict(scene.A), "B": part_dict(scene.B)},
            "contact": part_dict(scene.contact), "load": part_dict(scene.load),
            "discretization": part_dict(scene.discretization), "solver": part_dict(scene.solver)}


def scene_to_toml(scene: Scene) -> str:
    """The scene as TOML text (docs/scenes.md's tables), defaults filled in; needs ``tomli-w``."""
    try:
        import tomli_w
    except ImportError as exc:
        raise MissingBackendError("writing a scene as TOML needs tomli-w: pip install 'rollqp[toml]'") from exc
    return tomli_w.dumps(scene_to_dict(scene))


# =========================================================================== input
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
    from ..profiles import parse_profile
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


def scene_from_toml(text: str, source: str = "<string>", default_name: str = "scene") -> Scene:
    """Build and validate a scene from TOML text.

    Raises
    ------
    InputError
        On a TOML syntax error (naming ``source`` and tomllib's message) or invalid input.
    """
    if text.startswith("\ufeff"):  # a UTF-8 byte-order mark, as some editors write
        text = text[1:]
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(source, f"invalid TOML: {exc}") from exc
    except RecursionError:
        raise InputError(source, "invalid TOML: nested too deeply") from None
    return scene_from_dict(data, source=source, default_name=default_name)


def _builtin_dir():
    return resources.files("rollqp").joinpath("scenes")


def _builtin_files() -> dict[str, Any]:
    out = {}
    for entry in _builtin_dir().iterdir():
        if entry.name.endswith(".toml") and entry.is_file():
            out[entry.name[:-len(".toml")]] = entry
    return dict(sorted(out.items()))


def builtin_scenes() -> dict[str, str]:
    """The built-in scenes: name → one-line description."""
    out = {}
    for name, entry in _builtin_files().items():
        try:
            desc = tomllib.loads(entry.read_text(encoding="utf-8")).get("description", "")
        except tomllib.TOMLDecodeError:  # pragma: no cover - the built-ins are tested
            desc = "(unreadable)"
        out[name] = str(desc)
    return out


def load_scene(source: Any) -> Scene:
    """Read and validate a scene.

    Parameters
    ----------
    source : str, os.PathLike, dict or Scene
        A path to a TOML file; the name of a built-in scene (:func:`builtin_scenes`; a file
        of that name takes precedence); a nested dict as :meth:`Scene.to_dict` gives; or a
        scene, returned as is.

    Returns
    -------
    Scene
        A scene without ``name`` is named after its file.

    Raises
    ------
    InputError
        ``SCENE`` if no such file or built-in scene exists; the file's path on a TOML syntax
        error; the dotted key on invalid input.
    """
    if isinstance(source, Scene):
        return source
    if isinstance(source, dict):
        return scene_from_dict(source)
    if not isinstance(source, (str, os.PathLike)):
        raise InputError("SCENE", "must be a path to a TOML file, the name of a built-in scene "
                                  f"or a dict, got {type(source).__name__}")
    path = Path(source)
    if path.is_file():
        if path.stat().st_size > MAX_FILE_BYTES:
            raise InputError(str(path), f"a scene file is at most {MAX_FILE_BYTES >> 20} MiB")
        try:
            text = path.read_bytes().decode("utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise InputError(str(path), f"cannot read the scene file: {exc}") from exc
        return scene_from_toml(text, source=str(path), default_name=safe_name(path.stem))
    builtins = _builtin_files()
    name = os.fspath(source)
    if isinstance(source, str) and name in builtins:
        text = builtins[name].read_text(encoding="utf-8")
        return scene_from_toml(text, source=f"builtin:{name}", default_name=name)
    raise InputError("SCENE", f"no such file or built-in scene {name!r}"
                              f"{suggestion(name, builtins)}; built-in scenes: "
                              f"{', '.join(builtins)}")
