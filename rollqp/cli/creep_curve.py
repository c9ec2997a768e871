"""``rollqp creep-curve SCENE [--ratios ...] [--friction ...] [--plot F.png]`` (2D) and ``rollqp creep-curve
SCENE3D --creepage longitudinal|lateral|spin --values V [--plot F.png]``: the steady creep curve on dask, with
Carter's law or the Bentall–Johnson limit (2D) or Kalker's linear theory (3D) beside it (docs/sweeps.md)."""
from __future__ import annotations

from ..scene import load_scene
from .common import cluster_options
from .families import family, takes


def add_arguments(c) -> None:
    c.add_argument("scene", help="the base scene: a TOML file or a built-in scene")
    c.add_argument("--ratios", default=None, help="2D: load ratios Q/(mu P): a,b,c or start:stop:count "
                   "(default 0.05:0.95:19)")
    c.add_argument("--friction", help="2D: friction coefficients mu (default: the scene's)")
    c.add_argument("--creepage", help="3D: the creepage swept: longitudinal | lateral | spin (default longitudinal)")
    c.add_argument("--values", help="3D: its values, a,b,c or start:stop:count (default 1e-4:2e-3:12; spin in "
                   "1/length)")
    c.add_argument("--plot", help="draw the creep-force figure to this file")
    c.add_argument("--out", help="the zarr store (default <scene name>-creep.zarr)")
    cluster_options(c)


def main(args) -> int:
    scene = load_scene(args.scene)
    takes(scene, "creep-curve")
    return family(scene).creep_curve(scene, args)
