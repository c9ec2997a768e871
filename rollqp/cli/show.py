"""``rollqp show SCENE``: a scene's TOML with its defaults filled in."""
from __future__ import annotations

import sys

from ..scene import load_scene


def add_arguments(s) -> None:
    s.add_argument("scene")


def main(args) -> int:
    sys.stdout.write(load_scene(args.scene).to_toml())
    return 0
