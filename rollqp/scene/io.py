"""Scenes in and out: TOML files, dicts and the built-in scenes; TOML written by tomli-w.

Reading (:func:`load_scene`, :func:`scene_from_toml`, :func:`scene_from_dict`) checks the
structure — unknown and missing keys, named with their dotted path and the closest valid name —
and hands the values to :class:`~rollqp.scene.Scene`, which checks them. Nothing read is ever
executed or used as a path (a scene's name is restricted, docs/scenes.md). Writing
(:func:`scene_to_dict`, :func:`scene_to_toml`) gives the full scene with its defaults; the TOML
goes through the ``tomli-w`` library (a core dependency), floats with ``repr`` precision so
that reading the text back gives an equal scene.
"""
from __future__ import annotations

import dataclasses
import os
from importlib import resources
from pathlib import Path
from typing import Any

try:  # Python >= 3.11
    import tomllib
except ModuleNotFoundError:  # pragma: no cover - Python 3.10
    import tomli as tomllib  # type: ignore[no-redef]

from ..errors import InputError
from ..validate import suggestion
from .checks import safe_name
from .core import Scene, SceneBase
from .core import scene_from_dict as scene_from_dict_2d
from .grid import Body3D
from .grid import Contact3D
from .grid import Discretization3D
from .grid import Load3D
from .grid import Solver3D
from .grid import scene_from_dict as scene_from_dict_3d
from .plain import part_dict, plain, scene_to_dict, scene_to_toml  # noqa: F401 - re-exported
from .schema import Body
from .schema import Contact
from .schema import Discretization
from .schema import Load
from .schema import SolverSettings

__all__ = ["load_scene", "scene_from_dict", "scene_from_toml", "builtin_scenes", "scene_to_dict", "scene_to_toml"]

#: Largest scene file read (bytes): scenes are a few hundred bytes; tables of 10^5 points fit.
MAX_FILE_BYTES = 16 << 20


def _parse_3d(d: dict, source: str, default_name: str):
    if isinstance(d.get("contact"), dict) and d["contact"].get("kind") == "wheel-rail":
        # a real cycle, the contract's one arrow back up: the wheel-rail scene is built on SceneBase (this package)
        # and read here; imported on its first scene (docs/wheel-rail.md)
        from ..wheelrail.scene import scene_from_dict as wheel_rail
        return wheel_rail(d, source=source, default_name=default_name)
    return scene_from_dict_3d(d, source=source, default_name=default_name)


#: The parser of each scene dimension (``[contact] dimension``).
_PARSERS = {2: scene_from_dict_2d, 3: _parse_3d}


def scene_from_dict(d: Any, source: str = "<dict>", default_name: str = "scene"):
    """Build and validate a scene from its nested dict, of the dimension its ``[contact] dimension``
    names (default 2: :class:`~rollqp.scene.Scene`; 3: :class:`~rollqp.scene.grid.Scene3D`).

    Raises
    ------
    InputError
        ``contact.dimension`` if it is not 2 or 3; else as the scene of that dimension.
    """
    contact = d.get("contact") if isinstance(d, dict) else None
    dimension = contact.get("dimension", 2) if isinstance(contact, dict) else 2
    if isinstance(dimension, bool) or not isinstance(dimension, int) or dimension not in _PARSERS:
        raise InputError("contact.dimension", f"must be one of {', '.join(map(str, _PARSERS))} (default 2), got "
                                              f"{dimension!r}")
    if dimension == 2 and isinstance(contact, dict) and "dimension" in contact:  # the 2D schema has no such key: 2 is its default
        d = {**d, "contact": {k: v for k, v in contact.items() if k != "dimension"}}
    try:
        return _PARSERS[dimension](d, source=source, default_name=default_name)
    except InputError as err:
        other = _other_dimension_key(err.key, dimension)
        if other is None:
            raise
        raise InputError(err.key, f"{str(err).split(': ', 1)[-1]}; it is a key of {other}D scenes and this scene is "
                                  f"{dimension}D ([contact] dimension = {dimension}{' by default' if dimension == 2 else ''}"
                                  f"; docs/scenes.md)") from None


def _table_keys(dimension: int) -> dict:
    """``{table: key names}`` of the scene tables of ``dimension`` (their dataclass fields)."""
    if dimension == 2:
        classes = {"bodies": Body, "contact": Contact, "load": Load, "discretization": Discretization,
                   "solver": SolverSettings}
    else:
        classes = {"bodies": Body3D, "contact": Contact3D, "load": Load3D, "discretization": Discretization3D,
                   "solver": Solver3D}
    return {t: {f.name for f in dataclasses.fields(c)} for t, c in classes.items()}


def _other_dimension_key(key, dimension: int):
    """The other dimension if ``key`` (``table.name`` or ``bodies.X.name``) is a key of its scenes
    and not of ``dimension``'s, else None: the hint of an unknown key from the wrong dimension."""
    parts = str(key).split(".")
    if len(parts) not in (2, 3) or (len(parts) == 3 and parts[0] != "bodies"):
        return None
    table, name = parts[0], parts[-1]
    other = 5 - dimension
    if name in _table_keys(dimension).get(table, ()) or name not in _table_keys(other).get(table, ()):
        return None
    return other


def scene_from_toml(text: str, source: str = "<string>", default_name: str = "scene", overrides=None) -> Scene:
    """Build and validate a scene from TOML text (``overrides``: dotted keys set before it is validated).

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
    return scene_from_dict(_overridden(data, overrides), source=source, default_name=default_name)


def _overridden(data, overrides):
    """``data`` with the dotted ``overrides`` set (a command line's ``--method``: the scene is validated with it)."""
    for key, value in (overrides or {}).items():
        *tables, last = key.split(".")
        d = data
        for t in tables:
            d = d.setdefault(t, {}) if isinstance(d, dict) else d
        if isinstance(d, dict):
            d[last] = value
    return data


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


def load_scene(source: Any, overrides: dict | None = None) -> Scene:
    """Read and validate a scene.

    Parameters
    ----------
    source : str, os.PathLike, dict or Scene
        A path to a TOML file; the name of a built-in scene (:func:`builtin_scenes`; a file
        of that name takes precedence); a nested dict as :meth:`Scene.to_dict` gives; or a
        scene, returned as is.
    overrides : dict, optional
        Dotted keys (``{"solver.method": "mf-newton"}``) set in a file's or built-in scene's table
        before it is validated, so that the scene is checked as it will run (a command line's
        ``--method``).

    Returns
    -------
    Scene
        A scene without ``name`` is named after its file.

    Raises
    ------
    InputError
        ``SCENE`` if no such file or built-in scene exists; the file's path on a TOML syntax
        error; the dotted key on invalid input.

    Examples
    --------
    >>> from rollqp import load_scene
    >>> scene = load_scene("cattaneo-carter")
    >>> scene.n_nodes, scene.solver.method, scene.contact.friction
    (81, 'newton', 0.1)
    >>> scene.replace(**{"discretization.elements": 20}).n_nodes
    41
    >>> load_scene("catano-carter")
    Traceback (most recent call last):
    ...
    rollqp.errors.InputError: SCENE: no such file or built-in scene 'catano-carter'; did you mean 'cattaneo-carter'?...
    """
    if isinstance(source, SceneBase):
        return source.replace(**overrides) if overrides else source
    if isinstance(source, dict):
        import copy
        return scene_from_dict(_overridden(copy.deepcopy(source), overrides) if overrides else source)
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
        return scene_from_toml(text, source=str(path), default_name=safe_name(path.stem), overrides=overrides)
    builtins = _builtin_files()
    name = os.fspath(source)
    if isinstance(source, str) and name in builtins:
        text = builtins[name].read_text(encoding="utf-8")
        return scene_from_toml(text, source=f"builtin:{name}", default_name=name, overrides=overrides)
    raise InputError("SCENE", f"no such file or built-in scene {name!r}"
                              f"{suggestion(name, builtins)}; built-in scenes: "
                              f"{', '.join(builtins)}")
