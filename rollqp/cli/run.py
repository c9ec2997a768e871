"""``rollqp run SCENE [--out RESULT.npz] [--plot FIGURE.png] [--method METHOD] [--keep-every K] [--quiet]`` and
``rollqp run --resume RESULT.npz``: run a scene and write its result file (docs/scenes.md, docs/results.md).

The run itself, its summary, figure and cross-check are its dimension's (:class:`~rollqp.cli.common.Family`).
"""
from __future__ import annotations

import argparse
import ctypes
import signal
import sys
import time
from contextlib import nullcontext

from ..errors import InputError
from ..journal import Journal, journal_path
from ..methods import SCENE_METHOD_NAMES, method_class
from ..progress import listening
from ..result import OutputLock, check_output, resume_source
from ..scene import load_scene, scene_from_dict
from .common import EXIT_INTERRUPTED, EXIT_TERMINATED, EXIT_WRITE, Terminated, check_plot, default_output, on_sigterm
from .families import family
from .reporting import estimate_progress, iteration_lines, progress, start_progress


def keep_count(text):
    """``--keep-every K``: a whole number >= 1 of a few digits."""
    t = str(text).strip()
    if not t.isdigit() or len(t) > 9 or int(t) < 1:
        shown = t if len(t) <= 20 else f"{t[:20]}… ({len(t)} characters)"
        raise argparse.ArgumentTypeError(f"must be a whole number >= 1 (keep every K-th state), got {shown!r}")
    return int(t)


def add_arguments(r) -> None:
    r.add_argument("scene", nargs="?", help="a TOML scene file or the name of a built-in scene "
                   "(with --resume: optional, the scene stored in the result file)")
    r.add_argument("--out", help="result file (.npz); default: <scene name>.npz in the current folder "
                   "(with --resume: the resumed file)")
    r.add_argument("--resume", metavar="RESULT.npz", help="continue an interrupted, failed or killed run from its "
                   "result file (or the journal RESULT.npz.journal a killed run leaves)")
    r.add_argument("--keep-every", dest="keep_every", type=keep_count, metavar="K",
                   help="keep every K-th state in the result file (and the last two); works, times and iteration "
                        "counts are summed over the steps in between (default 1: every state)")
    r.add_argument("--plot", help="draw tractions, slip and creepage to this PNG file")
    r.add_argument("--method", choices=SCENE_METHOD_NAMES, help="overrides [solver].method")
    r.add_argument("--quiet", action="store_true", help="print nothing but errors")
    r.add_argument("--stresses", action="store_true", help="report the peak subsurface von Mises and tau1 over "
                   "the run, with place and state (docs/stresses.md)")
    r.add_argument("--cross-check", dest="cross_check", action=argparse.BooleanOptionalAction, default=None,
                   help="solve three steps again with qp-clarabel and qp-osqp (3D: socp-clarabel, or newton for a "
                        "conic run) and show the differences (default: on for strips of at most 400 nodes run by "
                        "a method other than those; 3D: the steps that fit the run's own time plus 3 s)")
    r.add_argument("--allow-long", dest="allow_long", action="store_true",
                   help="start a 3D conic run even when its estimate is above an hour (refused otherwise)")


def run_scene(args):
    """``(scene, resume source or None, out)`` of ``rollqp run``'s arguments, checked before any work."""
    source = None
    if args.resume:
        source = resume_source(args.resume, "--resume")
        try:
            scene = scene_from_dict(source.meta["scene"], source=args.resume)
        except (KeyError, TypeError) as exc:
            source.close()
            raise InputError("--resume", "the result file holds no scene (meta['scene'])") from exc
        if args.scene is not None and load_scene(args.scene).to_dict() != scene.to_dict():
            source.close()
            raise InputError("--resume", f"the result file was computed for another scene than {args.scene!r}")
        if args.method and args.method != scene.solver.method:
            source.close()
            raise InputError("--method", f"the run was made with {scene.solver.method!r}; resume it with that method")
    elif args.scene is None:
        raise InputError("SCENE", "give a scene file or a built-in scene (or --resume RESULT.npz)")
    else:  # --method is the scene's method before it is validated (solver.operator = "matrix-free" with mf-newton)
        scene = load_scene(args.scene, {"solver.method": args.method} if args.method else None)
    method_class(scene.solver.method, scene.dimension)  # installed? (a missing backend names its pip extra)
    out = check_output(args.out or (source.path if source is not None else None) or default_output(scene.name))
    check_plot(args.plot)
    return scene, source, out


def _saved(err, out, what):
    """The one-line message of a failed or interrupted run: where its completed states are."""
    partial = getattr(err, "partial", None)
    if partial is None or not len(partial):
        return f"{what}; nothing was completed"
    return f"{what} — the {len(partial)} completed states are in {out} (continue: rollqp run --resume {out})"


def keep_freed_memory() -> None:
    """Linux (glibc): freed arrays below 32 MiB stay in the heap for the next allocation (the mapping threshold at
    its largest, the heap trimmed only above 256 MiB free, grown 64 MiB at a time). Measured on a 150 × 150 steady
    step in one process (load 14): 1.0 s of system time and 5.3 s of user time with glibc's defaults, 0.0 s and
    4.8 s so; the 300 × 300 step with the 2D runs' setting spent 44 s of system time against 35 s of user time."""
    if not sys.platform.startswith("linux"):
        return
    try:
        libc = ctypes.CDLL("libc.so.6")
        libc.mallopt(-3, 32 << 20)   # M_MMAP_THRESHOLD
        libc.mallopt(-1, 256 << 20)  # M_TRIM_THRESHOLD
        libc.mallopt(-2, 64 << 20)   # M_TOP_PAD
    except (OSError, AttributeError):  # not glibc
        pass


def _unwritten(err: OSError, out) -> str:
    """The one line of a run whose journal or result file could not be written: what, why, and what is kept."""
    what = f"cannot write {err.filename or out} ({err.strerror or err})"
    try:
        j = Journal.open(journal_path(out), "journal")
    except (InputError, OSError):
        return f"{what}; no state was kept"
    try:
        n = len(j)
    finally:
        j.close()
    return (f"{what}: the {n} completed states are in {journal_path(out)} (continue once there is room: "
            f"rollqp run --resume {out})")


def main(args) -> int:
    """``rollqp run``: 0, or an exit code of :mod:`rollqp.cli.common` (a failed run raises its error)."""
    scene, source, out = run_scene(args)
    fam = family(scene)
    if getattr(args, "stresses", False) and fam.stresses is None:
        raise InputError("--stresses", f"the subsurface stresses are computed for 2D scenes only; {scene.name!r} is "
                                       f"{scene.dimension}D")
    if fam.refuse is not None:
        fam.refuse(scene, getattr(args, "allow_long", False))
    (fam.memory_policy or keep_freed_memory)()
    if source is not None and source.journal is None and source.last == scene.n_steps:
        print(f"rollqp: {args.resume} is complete ({scene.n_steps} rolling steps): nothing to resume",
              file=sys.stderr)
        return 0
    cb, close = progress(args.quiet)
    if not args.quiet:
        fam.advise(scene)
        cb = estimate_progress(cb, scene.n_steps - (0 if source is None else max(source.last, 0)))
    keep, observe = fam.spot(args, scene)
    t0 = time.perf_counter()
    previous = signal.signal(signal.SIGTERM, on_sigterm)
    try:
        with OutputLock(out), (nullcontext() if args.quiet else listening(iteration_lines())):
            try:
                result = fam.run(scene, progress=cb, resume=source, observe=observe, out=out, keep_every=args.keep_every,
                                 start_progress=None if args.quiet or source is not None else start_progress())
            except KeyboardInterrupt as err:
                # the run is over and its states are written: a later Ctrl-C or SIGTERM must not cut the exit short
                signal.signal(signal.SIGINT, signal.SIG_IGN)
                previous = signal.SIG_IGN  # (SIGTERM's, set below)
                close()
                print(f"rollqp: {_saved(err, out, 'interrupted')}", file=sys.stderr)
                return EXIT_TERMINATED if isinstance(err, Terminated) else EXIT_INTERRUPTED
            except OSError as err:  # the journal or the result file could not be written (a full disk)
                close()
                print(f"rollqp: error: {_unwritten(err, out)}", file=sys.stderr)
                return EXIT_WRITE
            except Exception as err:
                if getattr(err, "partial", None) is not None:
                    err.args = (_saved(err, out, str(err)),)
                raise
            finally:
                close()
                if source is not None:
                    source.close()
            wall = time.perf_counter() - t0
    finally:
        signal.signal(signal.SIGTERM, previous)
    res = result.arrays()
    if args.plot:
        fam.plot(res, scene, args.plot)
    if not args.quiet:
        peaks = fam.stresses(result) if getattr(args, "stresses", False) else None
        print(fam.summary(res, scene, scene.solver.method, wall, peaks))  # the method that ran: from res's meta
        if keep:
            t1 = time.perf_counter()
            # by default within the run's own time (the 3D check adds its SLACK), all of it with --cross-check
            head, *failures = fam.check(keep, scene, None if args.cross_check else wall).splitlines()
            print(f"  cross-check   {head} ({time.perf_counter() - t1:.2f} s)")
            for line in failures:  # each in full, on a line of its own
                print(f"                {line}")
        print(f"  result        {out}" + (f"\n  figure        {args.plot}" if args.plot else ""))
    return 0
