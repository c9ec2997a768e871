"""The command line's parts of a 2D scene (a strip): the notes before a run, the cross-check of a few of its steps
and ``rollqp crossval`` (:data:`rollqp.cli.families.FAMILIES` names them), and how a dense run gives freed memory
back. Its sweeps: :mod:`rollqp.cli.sweeps`."""
from __future__ import annotations

import ctypes
import sys

from ..advice import alternation_note, estimate_note, fast_path
from ..crossval import SPOT_MAX_NODES, SPOT_METHODS, report, spot_check
from ..stepfile import from_record


def advise(scene) -> None:
    """Before a run: what rollqp chose for the user (the matrix-free path), or what the dense path or the N–T
    alternation will cost and what runs faster (:mod:`rollqp.advice`), one line each on stderr."""
    plan = fast_path(scene)
    lines = [plan.note] if plan.note else [estimate_note(scene)]
    lines.append(alternation_note(plan.scene))
    for note in filter(None, lines):
        print(f"rollqp: {note}", file=sys.stderr, flush=True)


def spot(args, scene):
    """``(kept steps, observer)``: the run keeps steps 0, K/2 and K as step files for the cross-check."""
    wanted = args.cross_check
    if wanted is None:
        n = scene.discretization.elements * {"constant": 1, "linear": 1, "quadratic": 2}[scene.discretization.element] + 1
        wanted = not args.quiet and n <= SPOT_MAX_NODES and scene.solver.method not in SPOT_METHODS
    if scene.contact.friction.kind != "constant":  # step files hold one constant μ (a law: docs/friction.md)
        wanted = False
    if not wanted or args.quiet:
        return {}, None
    K = scene.n_steps
    steps = sorted({0, K // 2, K})
    keep = {}

    def observe(rec, ops):
        if rec.k in steps and rec.problem is not None:
            keep[rec.k] = from_record(scene, ops, scene.solver.method, rec)

    return keep, observe


def check(keep, scene, budget=None) -> str:
    """The 2D cross-check (:func:`rollqp.crossval.spot_check` of the kept step files; strips of at most
    :data:`~rollqp.crossval.SPOT_MAX_NODES` nodes, no time budget)."""
    return str(spot_check(list(keep.values())))


def crossval(scene, step, methods) -> int:
    """``rollqp crossval`` of a 2D scene: every method on one step (:func:`rollqp.crossval.report`)."""
    print(report(scene, step=step, methods=methods))
    return 0


def give_back_freed_memory() -> None:
    """Linux (glibc): arrays of 1 MiB and more are mapped and returned to the system when freed. Without it glibc
    raises its threshold to 32 MiB after the first large array is freed, and the factorizations a long dense run
    makes and drops stay in the heap (measured on the 2,561-node cattaneo-carter run: 45 MB more peak memory)."""
    if not sys.platform.startswith("linux"):
        return
    try:
        ctypes.CDLL("libc.so.6").mallopt(-3, 1 << 20)  # M_MMAP_THRESHOLD
    except (OSError, AttributeError):  # not glibc
        pass
