"""The command line's parts of a 3D scene (a grid): the notes before a run, the cross-check of a few of its steps,
``rollqp crossval``, ``rollqp sweep`` and ``rollqp creep-curve`` (:data:`rollqp.cli.families.FAMILIES` names
them)."""
from __future__ import annotations

import sys

from ..advice.grid import notes
from ..crossval.grid import SLACK, SpotObserver, cross_check, spot_steps
from ..crossval.grid import crossval as crossval_steps
from ..errors import InputError
from ..sweep.three import creep_curve_3d, sweep_3d
from .common import check_plot, default_output, sweep_exit, sweep_signals


def advise(scene) -> None:
    """Before a 3D run: its estimated time and memory, and what runs faster (:mod:`rollqp.advice.grid`)."""
    for note in notes(scene):
        print(f"rollqp: {note}", file=sys.stderr, flush=True)


def spot(args, scene):
    """``(observer or {}, observer or None)``: the 3D run keeps steps 0, K/2, K for its cross-check (by default
    solved again as far as the run's own time plus :data:`~rollqp.crossval.grid.SLACK` allows, the last
    first; all three with ``--cross-check``)."""
    if args.quiet or args.cross_check is False:
        return {}, None
    observer = SpotObserver(spot_steps(scene.n_steps))
    return observer, observer


def check(observer, scene, budget=None) -> str:
    """The 3D cross-check (:func:`rollqp.crossval.grid.cross_check` of the observed steps); ``budget`` the run's own
    time in seconds, of which the check takes at most that plus :data:`~rollqp.crossval.grid.SLACK` (None: no
    limit)."""
    budget = None if budget is None else budget + SLACK   # at most the run's own time plus SLACK seconds
    return str(cross_check(scene, observer, scene.solver.method, tolerance=scene.solver.tolerance, budget=budget))


def crossval(scene, step, methods) -> int:
    """``rollqp crossval`` of a 3D scene: every step (or ``--step K``) of its run solved again by the SOCP
    backends and Newton (:func:`rollqp.crossval.grid.crossval`); exit 1 if they disagree."""
    check = crossval_steps(scene, step, methods, tolerance=scene.solver.tolerance)
    print(check.table())
    print(str(check))
    return 0 if check.agrees() else 1


def sweep(scene, args) -> int:
    out = args.out or default_output(scene.name, "-sweep.zarr")
    _, summary = sweep_signals(lambda: sweep_3d(scene, args.vary, out, scheduler=args.scheduler,
                                                  workers=args.workers, quiet=args.quiet))
    if not args.quiet:
        print(f"rollqp sweep of {scene.name} (3D): {out}")
        print(summary.table())
    return sweep_exit(summary)


def creep_curve(scene, args) -> int:
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
