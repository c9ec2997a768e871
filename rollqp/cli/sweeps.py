"""The command line's sweeps of each dimension, ``rollqp sweep`` and ``rollqp creep-curve`` on dask
(:data:`rollqp.cli.families.FAMILIES` names them; docs/sweeps.md): in a module of their own, so that a run loads
no part of a parameter study."""
from __future__ import annotations

from ..errors import InputError
from ..sweep import sweep as sweep_points
from ..sweep.creep import creep_curve as creep_points
from ..sweep.three import creep_curve_3d, sweep_3d as sweep_grid
from .common import check_plot, default_output, sweep_exit, sweep_signals


def sweep_2d(scene, args) -> int:
    out = args.out or default_output(scene.name, "-sweep.zarr")
    summary = sweep_signals(lambda: sweep_points(scene, args.vary, out, scheduler=args.scheduler, workers=args.workers,
                                          quiet=args.quiet))
    if not args.quiet:
        print(f"rollqp sweep of {scene.name}: {out}")
        print(summary.table())
    return sweep_exit(summary)


def sweep_3d(scene, args) -> int:
    out = args.out or default_output(scene.name, "-sweep.zarr")
    _, summary = sweep_signals(lambda: sweep_grid(scene, args.vary, out, scheduler=args.scheduler,
                                                  workers=args.workers, quiet=args.quiet))
    if not args.quiet:
        print(f"rollqp sweep of {scene.name} (3D): {out}")
        print(summary.table())
    return sweep_exit(summary)


def creep_2d(scene, args) -> int:
    if args.creepage is not None or args.values is not None:
        raise InputError("--creepage" if args.creepage is not None else "--values",
                         "a 2D creep curve prescribes the load ratios: --ratios (and --friction)")
    args.ratios = "0.05:0.95:19" if args.ratios is None else args.ratios
    out = args.out or default_output(scene.name, "-creep.zarr")
    check_plot(args.plot)
    curve = sweep_signals(lambda: creep_points(scene, args.ratios, args.friction, out, scheduler=args.scheduler,
                                              workers=args.workers, quiet=args.quiet))
    return _report_curve(curve, args, out, plot=not curve.summary.interrupted)


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
    return _report_curve(curve, args, out, plot=True)


def _report_curve(curve, args, out, plot: bool) -> int:
    """A creep curve's figure (``--plot``, when ``plot``), its table and summary, and the exit code (either
    dimension's curve)."""
    if args.plot and plot:
        curve.plot(args.plot)
    if not args.quiet:
        print(curve.table())
        print(curve.summary.table())
        print(f"  store         {out}" + (f"\n  figure        {args.plot}" if args.plot else ""))
    return sweep_exit(curve.summary)
