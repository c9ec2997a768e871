"""``rollqp crossval SCENE [--step K] [--methods M1,M2]``: every available method on one step, side by side
(a 3D scene: every step of its run; docs/stepfiles.md)."""
from __future__ import annotations

from ..crossval import report
from ..errors import InputError
from ..methods import SCENE_METHOD_NAMES
from ..scene import load_scene
from ..stepfile import StepFile
from .families import family, takes


def add_arguments(x) -> None:
    x.add_argument("scene", help="a TOML scene file, a built-in scene, or an exported STEP.npz")
    x.add_argument("--step", type=int, default=None, help="step K (default 1; a 3D scene: every step of its run)")
    x.add_argument("--methods", help="comma-separated methods (default: every available one)")


def main(args) -> int:
    methods = None
    if args.methods:
        methods = [m.strip() for m in args.methods.split(",") if m.strip()]
        bad = [m for m in methods if m not in SCENE_METHOD_NAMES]
        if bad or not methods:
            raise InputError("--methods", f"unknown method(s) {', '.join(bad) or '(none given)'}; "
                                          f"choose from {', '.join(SCENE_METHOD_NAMES)}")
    if args.scene.endswith(".npz"):
        print(report(StepFile.load(args.scene, arg="SCENE"), methods=methods))
        return 0
    scene = load_scene(args.scene)
    takes(scene, "crossval")
    return family(scene).crossval(scene, args.step, methods)
