"""``rollqp export-step SCENE --step K [--out STEP.npz] [--method METHOD]``: one step's data and its QP
(3D: SOCP) forms, written by the scene's dimension (docs/stepfiles.md)."""
from __future__ import annotations

from ..methods import SCENE_METHOD_NAMES
from ..result import check_output
from ..scene import load_scene
from .common import default_output
from .families import family, takes


def add_arguments(e) -> None:
    e.add_argument("scene", help="a TOML scene file or the name of a built-in scene")
    e.add_argument("--step", type=int, required=True, help="step K: 0 = the starting state's last solve, "
                   "K >= 1 the rolling step whose solution is state K of the result file")
    e.add_argument("--out", help="step file (.npz); default <scene name>-step<K>.npz")
    e.add_argument("--method", choices=SCENE_METHOD_NAMES, help="method that marches to step K (default newton)")


def main(args) -> int:
    scene = load_scene(args.scene)
    takes(scene, "export-step")
    out = check_output(args.out or default_output(scene.name, f"-step{args.step}.npz"), "step file")
    step = family(scene).export_step(scene, args.step, method=args.method)
    for path in step.save(out):
        print(f"wrote {path}")
    return 0
