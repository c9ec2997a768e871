"""``rollqp crossval SCENE [--step K] [--methods M1,M2]``: every available method on one step, side by side
(a 3D scene: every step of its run); and the cross-check after ``rollqp run``, which solves a few of the run's
steps again by other methods (docs/stepfiles.md)."""
from __future__ import annotations

from ..crossval import SPOT_MAX_NODES, SPOT_METHODS, report, spot_check
from ..crossval.grid import SpotObserver, cross_check, spot_steps
from ..crossval.grid import crossval as crossval_steps
from ..errors import InputError
from ..methods import SCENE_METHOD_NAMES
from ..scene import load_scene
from ..stepfile import StepFile, from_record
from .common import family, takes


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


def crossval_2d(scene, step, methods) -> int:
    """``rollqp crossval`` of a 2D scene: every method on one step (:func:`rollqp.crossval.report`)."""
    print(report(scene, step=step, methods=methods))
    return 0


def crossval_3d(scene, step, methods) -> int:
    """``rollqp crossval`` of a 3D scene: every step (or ``--step K``) of its run solved again by the SOCP
    backends and Newton (:func:`rollqp.crossval.grid.crossval`); exit 1 if they disagree."""
    check = crossval_steps(scene, step, methods, tolerance=scene.solver.tolerance)
    print(check.table())
    print(str(check))
    return 0 if check.agrees() else 1


# --------------------------------------------------------------------------- the cross-check of rollqp run
def spot_2d(args, scene):
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


def check_2d(keep, scene, budget=None) -> str:
    """The 2D cross-check (:func:`rollqp.crossval.spot_check` of the kept step files; strips of at most
    :data:`~rollqp.crossval.SPOT_MAX_NODES` nodes, no time budget)."""
    return str(spot_check(list(keep.values())))


def spot_3d(args, scene):
    """``(observer or {}, observer or None)``: the 3D run keeps steps 0, K/2, K for its cross-check (by default
    solved again as far as the run's own time plus :data:`~rollqp.crossval.grid.SLACK` allows, the last
    first; all three with ``--cross-check``)."""
    if args.quiet or args.cross_check is False:
        return {}, None
    observer = SpotObserver(spot_steps(scene.n_steps))
    return observer, observer


def check_3d(observer, scene, budget=None) -> str:
    """The 3D cross-check (:func:`rollqp.crossval.grid.cross_check` of the observed steps, within ``budget``
    seconds)."""
    return str(cross_check(scene, observer, scene.solver.method, tolerance=scene.solver.tolerance, budget=budget))
