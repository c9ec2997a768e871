"""``rollqp extrapolate SCENE [--grids N1,N2,N3]``: a 3D steady state's creep forces on three grids,
extrapolated with an error estimate (:func:`rollqp.extrapolate.extrapolate`; docs/performance.md)."""
from __future__ import annotations

from ..errors import InputError
from ..extrapolate import extrapolate
from ..scene import load_scene
from .families import takes


def add_arguments(xp) -> None:
    xp.add_argument("scene", help="a TOML scene file or a built-in 3D scene with a rolling start")
    xp.add_argument("--grids", help="three element counts along the shorter axis in a constant ratio, e.g. "
                    "20,40,80 (default: half, once and twice the scene's)")


def main(args) -> int:
    scene = load_scene(args.scene)
    takes(scene, "extrapolate")
    grids = None
    if args.grids:
        try:
            grids = tuple(int(v) for v in args.grids.split(","))
        except ValueError:
            raise InputError("--grids", f"must be three integers N1,N2,N3, got {args.grids!r}") from None
        if any(g < 1 or g > 2000 for g in grids):
            raise InputError("--grids", f"each count must be in [1, 2000], got {args.grids!r}")
    print(extrapolate(scene, grids))
    return 0
