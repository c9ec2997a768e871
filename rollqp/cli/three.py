"""The command line's parts of a 3D scene (a grid): the notes before a run, the cross-check of a few of its steps
and ``rollqp crossval`` (:data:`rollqp.cli.families.FAMILIES` names them). Its sweeps: :mod:`rollqp.cli.sweeps`."""
from __future__ import annotations

import sys

from ..advice.grid import notes
from ..crossval.grid import SLACK, SpotObserver, cross_check, spot_steps
from ..crossval.grid import crossval as crossval_steps


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
