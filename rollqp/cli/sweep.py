"""``rollqp sweep SCENE --vary KEY=VALUES ... [--out STORE.zarr] [--scheduler ADDRESS] [--workers N]``: a
parameter study on dask, the product of the ``--vary`` values, its results in one labelled zarr store
(docs/sweeps.md; extra ``sweep``: dask, xarray, zarr, imported when the study starts)."""
from __future__ import annotations

from ..scene import load_scene
from .common import cluster_options
from .families import family, takes


def add_arguments(w) -> None:
    w.add_argument("scene", help="the base scene: a TOML file or a built-in scene")
    w.add_argument("--vary", action="append", required=True, metavar="KEY=VALUES",
                   help="a dotted scene key and its values: a,b,c | start:stop:count | start:stop:count:log "
                        "(repeat for more keys; the points are the product)")
    w.add_argument("--out", help="the zarr store (default <scene name>-sweep.zarr); run again to complete it")
    cluster_options(w)


def main(args) -> int:
    scene = load_scene(args.scene)
    takes(scene, "sweep")
    return family(scene).sweep(scene, args)
