"""``rollqp creep-curve SCENE [--ratios ...] [--friction ...] [--plot F.png]`` (2D) and ``rollqp creep-curve
SCENE3D --creepage longitudinal|lateral|spin --values V [--plot F.png]``: the steady creep curve on dask, with
Carter's law or the Bentall–Johnson limit (2D) or Kalker's linear theory (3D) beside it (docs/sweeps.md)."""
from __future__ import annotations

from ..errors import InputError
from ..scene import load_scene
from ..sweep.creep import creep_curve
from ..sweep.three import creep_curve_3d
from .common import check_plot, cluster_options, default_output, family, sweep_exit, sweep_signals, takes


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


def creep_2d(scene, args) -> int:
    if args.creepage is not None or args.values is not None:
        raise InputError("--creepage" if args.creepage is not None else "--values",
                         "a 2D creep curve prescribes the load ratios: --ratios (and --friction)")
    args.ratios = "0.05:0.95:19" if args.ratios is None else args.ratios
    out = args.out or default_output(scene.name, "-creep.zarr")
    check_plot(args.plot)
    curve = sweep_signals(lambda: creep_curve(scene, args.ratios, args.friction, out, scheduler=args.scheduler,
                                              workers=args.workers, quiet=args.quiet))
    if args.plot and not curve.summary.interrupted:
        curve.plot(args.plot)
    if not args.quiet:
        print(curve.table())
        print(curve.summary.table())
        print(f"  store         {out}" + (f"\n  figure        {args.plot}" if args.plot else ""))
    return sweep_exit(curve.summary)


def creep_3d(scene, args) -> int:
    if args.ratios is not None or args.friction is not None:
        raise InputError("--ratios" if args.ratios is not None else "--friction",
                         "a 3D creep curve prescribes the creepage: --creepage longitudinal|lateral|spin --values V")
    out = args.out or default_output(scene.name, "-creep.zarr")
    check_plot(args.plot)
    curve = sweep_signals(lambda: creep_curve_3d(scene, args.creepage or "longitudinal",
                                                 args.values or "1e-4:2e-3:12", out, scheduler=args.scheduler,
                                                 workers=args.workers, quiet=args.quiet))
    if curve.FN is None:       # interrupted: the points done are saved in the store
        print(curve.summary.table())
        return sweep_exit(curve.summary)
    if args.plot:
        curve.plot(args.plot)
    if not args.quiet:
        print(curve.table())
        print(curve.summary.table())
        print(f"  store         {out}" + (f"\n  figure        {args.plot}" if args.plot else ""))
    return sweep_exit(curve.summary)
