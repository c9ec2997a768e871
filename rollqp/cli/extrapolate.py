"""``rollqp extrapolate SCENE [--grids N1,N2,...] [--target PERCENT] [--budget SECONDS] [--workers N] [--shifts K]``:
a 3D steady state's creep forces on a few grids, each averaged over grid positions — as many as the target
error needs — extrapolated with an error estimate (:func:`rollqp.extrapolate.extrapolate`; docs/performance.md)."""
from __future__ import annotations

import math
import os
import sys

from ..errors import InputError
from ..extrapolate import BUDGET, MAX_SHIFTS, TARGET, extrapolate
from ..scene import load_scene
from .families import takes


def add_arguments(xp) -> None:
    xp.add_argument("scene", help="a TOML scene file or a built-in 3D scene with a rolling start")
    xp.add_argument("--grids", help="two or more increasing element counts along the shorter axis, e.g. "
                    "40,80,120 (default: once, twice and three times the scene's)")
    xp.add_argument("--target", help=f"the creep forces' error estimate to reach, in per cent (0.1 or 0.1%%), in (0, 100) "
                    f"(default {100 * TARGET:g}): positions are added to the grids until it is reached")
    xp.add_argument("--budget", help=f"seconds (wall clock) the positions may take, in (0, 1e6] (default {BUDGET:g}): "
                    "the rounds stop there with the estimate they reached")
    xp.add_argument("--workers", help="processes solving the positions side by side, 1 to 256 (default: one per "
                              "core, at most 8)")
    xp.add_argument("--shifts", help=f"a fixed number of grid positions per grid, 2 to {MAX_SHIFTS}, instead of the "
                    "target's (the target is then only reported)")


def _number(text, key, kind, allowed):
    try:
        v = kind(text)
    except ValueError:
        raise InputError(key, f"must be {allowed}, got {text!r}") from None
    if isinstance(v, float) and not math.isfinite(v):
        raise InputError(key, f"must be {allowed}, got {text!r}")
    return v


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
    shifts = None
    if args.shifts is not None:
        shifts = _number(args.shifts, "--shifts", int, f"an integer in [2, {MAX_SHIFTS}]")
    target = TARGET
    if args.target is not None:
        text = args.target.strip()
        pct = _number(text[:-1] if text.endswith("%") else text, "--target", float, "a percentage in (0, 100)")
        if not 0 < pct < 100:
            raise InputError("--target", f"must be a percentage in (0, 100), got {args.target!r}")
        target = pct / 100.0
    budget = BUDGET if args.budget is None else _number(args.budget, "--budget", float, "seconds in (0, 1e6]")
    workers = (min(os.cpu_count() or 1, 8) if args.workers is None
               else _number(args.workers, "--workers", int, "an integer in [1, 256]"))
    print(extrapolate(scene, grids, shifts=shifts, target=target, budget=budget, workers=workers,
                      progress=lambda text: print(f"extrapolate: {text}", file=sys.stderr, flush=True)))
    return 0
