"""``rollqp scenes``: the built-in scenes, each with its dimension and description."""
from __future__ import annotations

from ..scene import builtin_scenes, load_scene


def add_arguments(p) -> None:
    """No options."""


def main(args) -> int:
    names = builtin_scenes()
    w = max(map(len, names))
    for k, v in names.items():      # every scene tagged by its dimension, the same way
        print(f"{k:<{w}}  {load_scene(k).dimension}D  {v}")
    return 0
