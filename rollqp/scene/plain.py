"""Scenes out: the full scene as a nested plain dict (defaults filled in) and as TOML text (tomli-w).

Floats keep ``repr`` precision, so that reading the text back (:func:`rollqp.scene.io.scene_from_toml`)
gives an equal scene.
"""
from __future__ import annotations

import dataclasses
from dataclasses import fields
from typing import Any

import numpy as np

from ..errors import MissingBackendError
from ..histories import History
from ..profiles import Profile

__all__ = ["part_dict", "plain", "scene_to_dict", "scene_to_toml"]


def part_dict(obj) -> dict:
    """Plain dict of a part (Body, …, History), None values left out."""
    if isinstance(obj, History):
        return obj.to_dict()
    return {f.name: plain(getattr(obj, f.name)) for f in fields(obj) if getattr(obj, f.name) is not None}


def plain(v: Any) -> Any:
    """Plain (TOML/JSON) form of a value: histories and parts become dicts."""
    if isinstance(v, Profile):
        return v.to_dict()
    if isinstance(v, History) or dataclasses.is_dataclass(v) and not isinstance(v, type):
        return part_dict(v)
    if isinstance(v, np.generic):
        return v.item()
    return v


def scene_to_dict(scene) -> dict:
    """The full scene as a nested plain dict, defaults filled in.

    Histories are their inline-table dicts; absent optional values (``shaft_radius``,
    ``reference_distance``, the unused one of ``tangential``/``creepage``) are left out,
    since TOML has no null. JSON-serializable; :func:`scene_from_dict` reads it back.
    """
    return {"name": scene.name, "description": scene.description, **({"units": scene.units} if scene.units else {}),
            "bodies": {"A": part_dict(scene.A), "B": part_dict(scene.B)},
            "contact": part_dict(scene.contact), "load": part_dict(scene.load),
            "discretization": part_dict(scene.discretization), "solver": part_dict(scene.solver)}


def scene_to_toml(scene) -> str:
    """The scene as TOML text (docs/scenes.md's tables), defaults filled in; needs ``tomli-w``."""
    try:
        import tomli_w
    except ImportError as exc:
        raise MissingBackendError("writing a scene as TOML needs tomli-w: pip install 'rollqp[toml]'") from exc
    return tomli_w.dumps(scene_to_dict(scene))
