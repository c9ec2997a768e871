"""``rollqp extrapolate SCENE [--grids N1,N2,... ] [--shifts K]``: a 3D steady state's creep forces on a few
grids, each averaged over K grid positions, extrapolated with an error estimate
(:func:`rollqp.extrapolate.extrapolate`; docs/performance.md)."""
from __future__ import annotations

from ..errors import InputError
from ..extrapolate import SHIFTS, extrapolate
from ..scene import load_scene
from .families import takes


def add_arguments(xp) -> None:
    xp.add_argument("scene", help="a TOML scene file or a built-in 3D scene with a rolling start")
    xp.add_argument("--grids", help="two or more increasing element counts along the shorter axis, e.g. "
                    "40,80,120 (default: once, twice and three times the scene's)")
    xp.add_argument("--shifts", help=f"grid positions per grid, 2 to 64 (default {SHIFTS}): the forces are averaged "
                    "over them and their scatter is part of the error estimate")


def main(args) -> int:
    scene = load_scene(args.scene)
    takes(scene, "extrapolate")
    grids = None
    if args.grids:
        try:
            grids = tuple(int(v) for v in args.grids.split(","))
        except ValueError:
            raise InputError("--grids", f"must be integers N1,N2,..., got {args.grids!r}") from None
        if any(g < 1 or g > 2000 for g in grids):
            raise InputError("--grids", f"each count must be in [1, 2000], got {args.grids!r}")
    shifts = SHIFTS
    if args.shifts is not None:
        try:
            shifts = int(args.shifts)
        except ValueError:
            raise InputError("--shifts", f"must be an integer in [2, 64], got {args.shifts!r}") from None
    print(extrapolate(scene, grids, shifts=shifts))
    return 0
