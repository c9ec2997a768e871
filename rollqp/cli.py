"""The ``rollqp`` command (docs/scenes.md and docs/results.md: the command line, scene and result files).

    rollqp run SCENE [--out RESULT.npz] [--plot FIGURE.png] [--method METHOD] [--keep-every K] [--quiet]
    rollqp run --resume RESULT.npz
    rollqp scenes
    rollqp show SCENE
    rollqp export-step SCENE --step K [--out STEP.npz] [--method METHOD]
    rollqp check-step STEP.npz SOLUTION.npz [--tol T]
    rollqp crossval SCENE [--step K] [--methods M1,M2]
    rollqp extrapolate SCENE [--grids N1,N2,N3]   (3D: creep forces from three grids, with an error estimate)
    rollqp bench [--quick] [--docs] [...]   (benchmarks/suite.py: work–precision and scaling)
    rollqp sweep SCENE --vary KEY=VALUES ... [--out STORE.zarr] [--scheduler ADDRESS] [--workers N]
    rollqp creep-curve SCENE [--ratios ...] [--friction ...] [--plot F.png]   (docs/sweeps.md)
    rollqp creep-curve SCENE3D --creepage longitudinal|lateral|spin --values V [--plot F.png]
    rollqp stresses RESULT.npz --step K [--plot F.png] [--out S.npz] [--body A|B] [--grid NX,NZ] (3D: --plane, --line, --depths)

Errors are one line on stderr and a non-zero exit: 2 for invalid input, 3 for a solver
that did not converge (the completed steps are written to the result file first), 4 for a
result that could not be written (a full disk: the completed steps stay in the journal, and
``run --resume`` continues once there is room).
``check-step`` exits 1 when the candidate fails, with one line per failed condition.
BLAS threads are pinned to ``$ROLLQP_THREADS`` (default one) before numpy and scipy load
(:mod:`rollqp.threads`): their wheels each bundle OpenBLAS, and two pools competing for 2 cores
made a 3D run 3× slower.
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from dataclasses import dataclass
from typing import Callable

EXIT_INPUT, EXIT_SOLVER = 2, 3
#: The journal or the result file could not be written (a full disk, a file size limit).
EXIT_WRITE = 4
#: Interrupted by Ctrl-C (SIGINT) or SIGTERM: the shell's 128 + signal number.
EXIT_INTERRUPTED, EXIT_TERMINATED = 130, 143


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, no usage dump
        self.exit(EXIT_INPUT, f"rollqp: error: {message} (see 'rollqp --help')\n")


def version_text() -> str:
    """``rollqp X (Python …, numpy …, scipy …, clarabel …, osqp …)``: what a bug report needs."""
    import platform
    from importlib import metadata
    from .version import __version__
    deps = []
    for name in ("numpy", "scipy", "clarabel", "osqp"):
        try:
            deps.append(f"{name} {metadata.version(name)}")
        except metadata.PackageNotFoundError:  # pragma: no cover - core dependencies
            deps.append(f"{name} missing")
    return f"rollqp {__version__} (Python {platform.python_version()}, {', '.join(deps)})"


class _Version(argparse.Action):
    """``--version``: print :func:`version_text` and exit 0 (computed only when asked)."""

    def __init__(self, option_strings, dest, **kw):
        super().__init__(option_strings, dest, nargs=0, help="print rollqp's version (and its solvers') and exit")

    def __call__(self, parser, namespace, values, option_string=None):
        parser.exit(0, version_text() + "\n")


def _parser():
    from .methods import SCENE_METHOD_NAMES as METHOD_NAMES  # either dimension's (docs/scenes.md)
    p = _Parser(prog="rollqp", description="Transient rolling contact in 2D and 3D: convex QP/SOCP steps and "
                                           "generalized Newton.")
    p.add_argument("--version", action=_Version)
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)
    r = sub.add_parser("run", help="run a scene and write its result file")
    r.add_argument("scene", nargs="?", help="a TOML scene file or the name of a built-in scene "
                   "(with --resume: optional, the scene stored in the result file)")
    r.add_argument("--out", help="result file (.npz); default: <scene name>.npz in the current folder "
                   "(with --resume: the resumed file)")
    r.add_argument("--resume", metavar="RESULT.npz", help="continue an interrupted, failed or killed run from its "
                   "result file (or the journal RESULT.npz.journal a killed run leaves)")
    r.add_argument("--keep-every", dest="keep_every", type=_keep_count, metavar="K",
                   help="keep every K-th state in the result file (and the last two); works, times and iteration "
                        "counts are summed over the steps in between (default 1: every state)")
    r.add_argument("--plot", help="draw tractions, slip and creepage to this PNG file")
    r.add_argument("--method", choices=METHOD_NAMES, help="overrides [solver].method")
    r.add_argument("--quiet", action="store_true", help="print nothing but errors")
    r.add_argument("--stresses", action="store_true", help="report the peak subsurface von Mises and tau1 over "
                   "the run, with place and state (docs/stresses.md)")
    r.add_argument("--cross-check", dest="cross_check", action=argparse.BooleanOptionalAction, default=None,
                   help="solve three steps again with qp-clarabel and qp-osqp (3D: socp-clarabel, or newton for a "
                        "conic run) and show the differences (default: on for strips of at most 400 nodes run by "
                        "a method other than those; 3D: the steps that fit the run's own time plus 3 s)")
    r.add_argument("--allow-long", dest="allow_long", action="store_true",
                   help="start a 3D conic run even when its estimate is above an hour (refused otherwise)")
    sub.add_parser("scenes", help="list the built-in scenes")
    s = sub.add_parser("show", help="print a scene's TOML with defaults filled in")
    s.add_argument("scene")
    e = sub.add_parser("export-step", help="write one step's data and QP forms (docs/stepfiles.md)")
    e.add_argument("scene", help="a TOML scene file or the name of a built-in scene")
    e.add_argument("--step", type=int, required=True, help="step K: 0 = the starting state's last solve, "
                   "K >= 1 the rolling step whose solution is state K of the result file")
    e.add_argument("--out", help="step file (.npz); default <scene name>-step<K>.npz")
    e.add_argument("--method", choices=METHOD_NAMES, help="method that marches to step K (default newton)")
    c = sub.add_parser("check-step", help="check a candidate solution of an exported step")
    c.add_argument("step_file", metavar="STEP.npz")
    c.add_argument("solution", metavar="SOLUTION.npz", help="keys p and/or t (scene units), optional delta, xi "
                   "(3D: p (n,) and t (2, n) on the grid, optional delta, xi, eta)")
    c.add_argument("--tol", type=float, default=None, help="pass/fail limit on each nondimensional residual "
                   "(default 1e-6: see docs/stepfiles.md)")
    x = sub.add_parser("crossval", help="every available method on one step, side by side")
    x.add_argument("scene", help="a TOML scene file, a built-in scene, or an exported STEP.npz")
    x.add_argument("--step", type=int, default=None, help="step K (default 1; a 3D scene: every step of its run)")
    x.add_argument("--methods", help="comma-separated methods (default: every available one)")
    xp = sub.add_parser("extrapolate", help="3D: the steady state's creep forces on three grids, extrapolated "
                        "(Richardson, the order measured) with an error estimate (docs/performance.md)")
    xp.add_argument("scene", help="a TOML scene file or a built-in 3D scene with a rolling start")
    xp.add_argument("--grids", help="three element counts along the shorter axis in a constant ratio, e.g. "
                    "20,40,80 (default: half, once and twice the scene's)")
    _stresses_parser(sub)
    _wheelrail_parser(sub)
    b = sub.add_parser("bench", add_help=False, help="benchmarks: work–precision and scaling "
                       "(docs/performance.md; 'rollqp bench --help' for the options)")
    b.add_argument("bench_args", nargs=argparse.REMAINDER)
    _sweep_parsers(sub)
    return p


#: Seconds between progress lines when stderr is not a terminal (a log file, a batch job);
#: ``$ROLLQP_PROGRESS_SECONDS`` overrides it.
LOG_EVERY = 5.0


def _log_every() -> float:
    """Seconds between progress lines: ``$ROLLQP_PROGRESS_SECONDS``, or :data:`LOG_EVERY` when unset or
    not a number."""
    try:
        return float(os.environ.get("ROLLQP_PROGRESS_SECONDS", LOG_EVERY))
    except ValueError:
        return LOG_EVERY


def _progress(quiet):
    """A progress callback and its closer: a tqdm bar on a terminal (after 2 s, if tqdm is
    installed), a line every :data:`LOG_EVERY` seconds otherwise (logs and batch jobs)."""
    if quiet:
        return None, lambda: None
    if sys.stderr.isatty():
        try:
            from tqdm import tqdm
        except ImportError:
            tqdm = None
        if tqdm is not None:
            bar = {}

            def cb(k, K):
                if "b" not in bar:
                    bar["b"] = tqdm(total=K, delay=2.0, unit="step", leave=False, file=sys.stderr)
                bar["b"].update(1)

            return cb, lambda: bar.get("b") and bar["b"].close()
    t0 = time.perf_counter()
    last = [t0]
    every = _log_every()

    def line(k, K):
        now = time.perf_counter()
        if now - last[0] >= every or k == K and now - t0 >= every:
            last[0] = now
            print(f"rollqp: step {k}/{K} ({100.0 * k / max(K, 1):.0f} %), {now - t0:.1f} s", file=sys.stderr,
                  flush=True)

    return line, lambda: None


def _iteration_lines():
    """A :mod:`rollqp.progress` listener: a line every :data:`LOG_EVERY` seconds of a long solve inside one
    step (the Newton iterations of a large grid's steady step, with the residual), and from a minute on
    the remaining time estimated from the residual's last decrease."""
    from .progress import remaining_iterations
    every = _log_every()
    state = {"last": 0.0, "res": []}

    def listen(what, it, res, seconds, target):
        if it == 1:  # a new solve
            state["last"], state["res"] = 0.0, []
        state["res"].append(res)
        if seconds - state["last"] < every:
            return
        state["last"] = seconds
        line = f"rollqp: {what} step: Newton iteration {it}, residual {res:.1e} (to reach {target:.0e}), {seconds:.0f} s"
        left = remaining_iterations(state["res"], target) if seconds >= 60 else None
        if left:
            line += (f"; at most about {_minutes(left * seconds / it)} to go ({left} more iterations of "
                     f"{seconds / it:.0f} s at the residual's last rate of decrease; Newton's only speeds up)")
        print(line, file=sys.stderr, flush=True)

    return listen


class Terminated(KeyboardInterrupt):
    """SIGTERM, handled as Ctrl-C: the completed states are written before rollqp exits."""


def _on_sigterm(signum, frame):
    raise Terminated()


def default_output(name: str, suffix: str = ".npz") -> str:
    """``<name><suffix>`` in the current folder, the scene name reduced to a safe file name.

    A scene's name never steers the path: every character outside ``[A-Za-z0-9._-]`` becomes
    ``_`` and leading dots are dropped (``"../x"`` → ``"_x"``), so the default output stays in
    the working folder.
    """
    import re
    safe = re.sub(r"[^A-Za-z0-9._-]", "_", name).lstrip(".")[:100] or "result"
    return safe + suffix


def _check_plot(path):
    """Check ``--plot`` before the run: a known image format and a writable folder."""
    if path is None:
        return
    from .errors import InputError
    from .plot import pyplot
    ext = os.path.splitext(path)[1].lstrip(".").lower()
    formats = pyplot().figure().canvas.get_supported_filetypes()
    pyplot().close("all")
    if ext not in formats:
        raise InputError("--plot", f"unknown figure format {ext or '(none)'!r}; use one of "
                                   f"{', '.join(sorted(formats))}")
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder) or not os.access(folder, os.W_OK):
        raise InputError("--plot", f"cannot write in folder {folder!r}")


def _run_scene(args):
    """``(scene, resume source or None, out)`` of ``rollqp run``'s arguments, checked before any work."""
    from .errors import InputError
    from .result import check_output, resume_source
    from .scene import load_scene, scene_from_dict
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
    from .methods import method_class
    method_class(scene.solver.method, scene.dimension)  # installed? (a missing backend names its pip extra)
    out = check_output(args.out or (source.path if source is not None else None) or default_output(scene.name))
    _check_plot(args.plot)
    return scene, source, out


def _saved(err, out, what):
    """The one-line message of a failed or interrupted run: where its completed states are."""
    partial = getattr(err, "partial", None)
    if partial is None or not len(partial):
        return f"{what}; nothing was completed"
    return f"{what} — the {len(partial)} completed states are in {out} (continue: rollqp run --resume {out})"


def _give_back_freed_memory() -> None:
    """Linux (glibc): arrays of 1 MiB and more are mapped and returned to the system when freed. Without it glibc
    raises its threshold to 32 MiB after the first large array is freed, and the factorizations a long dense run
    makes and drops stay in the heap (measured on the 2,561-node cattaneo-carter run: 45 MB more peak memory)."""
    if not sys.platform.startswith("linux"):
        return
    try:
        import ctypes
        ctypes.CDLL("libc.so.6").mallopt(-3, 1 << 20)  # M_MMAP_THRESHOLD
    except (OSError, AttributeError):  # not glibc
        pass


def _keep_freed_memory() -> None:
    """Linux (glibc): freed arrays below 32 MiB stay in the heap for the next allocation (the mapping threshold at
    its largest, the heap trimmed only above 256 MiB free, grown 64 MiB at a time). Measured on a 150 × 150 steady
    step in one process (load 14): 1.0 s of system time and 5.3 s of user time with glibc's defaults, 0.0 s and
    4.8 s so; the 300 × 300 step with the 2D runs' setting spent 44 s of system time against 35 s of user time."""
    if not sys.platform.startswith("linux"):
        return
    try:
        import ctypes
        libc = ctypes.CDLL("libc.so.6")
        libc.mallopt(-3, 32 << 20)   # M_MMAP_THRESHOLD
        libc.mallopt(-1, 256 << 20)  # M_TRIM_THRESHOLD
        libc.mallopt(-2, 64 << 20)   # M_TOP_PAD
    except (OSError, AttributeError):  # not glibc
        pass


@dataclass(frozen=True)
class Family:
    """What the command line does with the scenes of one dimension (``scene.dimension``): one record per
    dimension, so that the commands dispatch through it and never test the dimension themselves.

    ``run(scene, progress=, resume=, observe=)`` the run (a result with ``arrays()``, ``save()``);
    ``summary(arrays, scene, method, wall, stresses)``; ``plot(arrays, scene, path)``; ``advise(scene)``
    the notes before a run; ``spot(args, scene)`` → ``(kept, observe)`` of the cross-check and ``check(kept,
    scene)`` its lines; ``stresses(result)`` the peak subsurface stresses (None: not for these scenes);
    ``commands``: the other subcommands that take its scenes; ``crossval(scene, step, methods)`` prints
    ``rollqp crossval``'s report and returns the exit code; ``check(kept, scene, budget)`` takes a time budget
    in seconds (None: none); ``export_step(scene, k, method)`` the step file of step ``k``; ``sweep(scene, args)``
    and ``creep_curve(scene, args)`` run those commands and return the exit code.
    """

    run: Callable
    summary: Callable
    plot: Callable
    advise: Callable
    spot: Callable
    check: Callable
    stresses: Callable | None
    commands: frozenset
    crossval: Callable
    export_step: Callable | None = None
    sweep: Callable | None = None
    creep_curve: Callable | None = None
    #: ``refuse(scene, allow_long)``: raise an InputError, before any work, for a run that cannot finish in
    #: reasonable time or memory (3D conic runs: :func:`rollqp.advice.grid.refusal`).
    refuse: Callable = lambda scene, allow_long: None
    #: How freed memory goes back to the system (glibc): the dense 2D runs give arrays of 1 MiB and more back at
    #: once (:func:`_give_back_freed_memory`, their peak memory); by default (None) the runs keep them for the
    #: next FFT product (:func:`_keep_freed_memory`: a 3D step's products allocate and free arrays of a few MiB
    #: thousands of times, and mapping each afresh cost more system time than the step's own work).
    memory_policy: Callable | None = None


def _family_2d() -> Family:
    from .march import run
    from .plot import plot_result
    from .report import summary
    from .subsurface import stress_history
    from .stepfile import export_step
    return Family(run, summary, plot_result, _advise, _spot_steps, _spot_lines, stress_history,
                  frozenset({"export-step", "crossval", "sweep", "creep-curve"}), _crossval_2d,
                  export_step=export_step, sweep=_sweep_2d, creep_curve=_creep_2d,
                  memory_policy=_give_back_freed_memory)


def _family_3d() -> Family:
    from .plot.three import three_figure
    from .advice.grid import notes, refusal
    from .report.grid import summary
    from .march.grid import run

    def advise(scene):
        for note in notes(scene):
            print(f"rollqp: {note}", file=sys.stderr, flush=True)

    from .stepfile.three import export_step_3d
    return Family(run, summary, three_figure, advise, _spot_3d, _check_3d, None, frozenset({"crossval", "export-step", "sweep",
                                                                                       "creep-curve", "extrapolate"}),
                  _crossval_3d, refuse=refusal, export_step=export_step_3d, sweep=_sweep_3d, creep_curve=_creep_3d)


def _family_wheel_rail() -> Family:
    from .wheelrail.cli import family_record
    return family_record(Family)


#: The record of each dimension (made on first use: ``rollqp --help`` imports nothing heavy); a scene whose
#: ``family`` names another record (a wheel on its rail) uses that one.
FAMILIES = {2: _family_2d, 3: _family_3d, "wheel-rail": _family_wheel_rail}


def family(scene) -> Family:
    """The :class:`Family` of ``scene``'s dimension (or of its ``family``)."""
    return FAMILIES[getattr(scene, "family", scene.dimension)]()


def _takes(scene, command: str) -> None:
    """Refuse a scene whose dimension's record does not list ``command``."""
    if command not in family(scene).commands:
        from .errors import InputError
        name = lambda d: f"{d}D" if isinstance(d, int) else d   # noqa: E731 - a dimension or a family's name
        dims = " and ".join(name(d) for d, f in FAMILIES.items() if command in f().commands)
        takes = ", ".join(["run", "show", "scenes", *sorted(family(scene).commands)])
        what = name(getattr(scene, "family", scene.dimension))
        raise InputError("SCENE", f"{scene.name!r} is a {what} scene; rollqp {command} works on {dims} "
                                  f"scenes (a {what} scene: rollqp {takes})")


def _unwritten(err: OSError, out) -> str:
    """The one line of a run whose journal or result file could not be written: what, why, and what is kept."""
    from .errors import InputError
    from .journal import Journal, journal_path
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


def cmd_run(args) -> int:
    import signal

    from .result import OutputLock
    scene, source, out = _run_scene(args)
    fam = family(scene)
    if getattr(args, "stresses", False) and fam.stresses is None:
        from .errors import InputError
        raise InputError("--stresses", f"the subsurface stresses are computed for 2D scenes only; {scene.name!r} is "
                                       f"{scene.dimension}D")
    fam.refuse(scene, getattr(args, "allow_long", False))
    (fam.memory_policy or _keep_freed_memory)()
    if source is not None and source.journal is None and source.last == scene.n_steps:
        print(f"rollqp: {args.resume} is complete ({scene.n_steps} rolling steps): nothing to resume",
              file=sys.stderr)
        return 0
    cb, close = _progress(args.quiet)
    if not args.quiet:
        fam.advise(scene)
        cb = estimate_progress(cb, scene.n_steps - (0 if source is None else max(source.last, 0)))
    keep, observe = fam.spot(args, scene)
    t0 = time.perf_counter()
    previous = signal.signal(signal.SIGTERM, _on_sigterm)
    from contextlib import nullcontext

    from .progress import listening
    try:
        with OutputLock(out), (nullcontext() if args.quiet else listening(_iteration_lines())):
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
            from .crossval.grid import SLACK  # the default: at most the run's own time plus SLACK seconds
            head, *failures = fam.check(keep, scene, None if args.cross_check else wall + SLACK).splitlines()
            print(f"  cross-check   {head} ({time.perf_counter() - t1:.2f} s)")
            for line in failures:  # each in full, on a line of its own
                print(f"                {line}")
        print(f"  result        {out}" + (f"\n  figure        {args.plot}" if args.plot else ""))
    return 0


def _spot_lines(keep, scene, budget=None) -> str:
    """The 2D cross-check (:func:`rollqp.crossval.spot_check` of the kept step files; strips of at most
    :data:`~rollqp.crossval.SPOT_MAX_NODES` nodes, no time budget)."""
    from .crossval import spot_check
    return str(spot_check(list(keep.values())))


def _spot_3d(args, scene):
    """``(observer or {}, observer or None)``: the 3D run keeps steps 0, K/2, K for its cross-check (by default
    solved again as far as the run's own time plus :data:`~rollqp.crossval.grid.SLACK` allows, the last
    first; all three with ``--cross-check``)."""
    from .crossval.grid import SpotObserver, spot_steps
    if args.quiet or args.cross_check is False:
        return {}, None
    observer = SpotObserver(spot_steps(scene.n_steps))
    return observer, observer


def _crossval_2d(scene, step, methods) -> int:
    """``rollqp crossval`` of a 2D scene: every method on one step (:func:`rollqp.crossval.report`)."""
    from .crossval import report
    print(report(scene, step=step, methods=methods))
    return 0


def _crossval_3d(scene, step, methods) -> int:
    """``rollqp crossval`` of a 3D scene: every step (or ``--step K``) of its run solved again by the SOCP
    backends and Newton (:func:`rollqp.crossval.grid.crossval`); exit 1 if they disagree."""
    from .crossval.grid import crossval
    check = crossval(scene, step, methods, tolerance=scene.solver.tolerance)
    print(check.table())
    print(str(check))
    return 0 if check.agrees() else 1


def _check_3d(observer, scene, budget=None) -> str:
    from .crossval.grid import cross_check
    return str(cross_check(scene, observer, scene.solver.method, tolerance=scene.solver.tolerance, budget=budget))


#: A run's remaining time above which ``rollqp run`` prints its estimate after the first steps (seconds).
ANNOUNCE_SECONDS = 60.0


def _advise(scene) -> None:
    """Before a run: what rollqp chose for the user (the matrix-free path), or what the dense path or the N–T
    alternation will cost and what runs faster (:mod:`rollqp.advice`), one line each on stderr."""
    from .advice import alternation_note, estimate_note, fast_path
    plan = fast_path(scene)
    notes = [plan.note] if plan.note else [estimate_note(scene)]
    notes.append(alternation_note(plan.scene))
    for note in filter(None, notes):
        print(f"rollqp: {note}", file=sys.stderr, flush=True)


def start_progress():
    """The report of a start's steps (a march to the steady state, the static shift steps): after the first
    :data:`START_ESTIMATE_SECONDS`, once, the estimated time of the whole start if it exceeds
    :data:`ANNOUNCE_SECONDS`; then a line every ``ROLLQP_PROGRESS_SECONDS`` (default :data:`LOG_EVERY`)."""
    t0 = time.perf_counter()
    state = {"last": t0, "said": False}
    every = _log_every()

    def tick(j, expected):
        now = time.perf_counter()
        if not state["said"] and now - t0 >= START_ESTIMATE_SECONDS:
            state["said"] = True
            total = (now - t0) / j * max(expected, j)
            if total > ANNOUNCE_SECONDS:
                print(f"rollqp: the starting state: about {_minutes(total)} ({expected} steps usually, "
                      f"{(now - t0) / j:.3g} s a step measured on the first {j})", file=sys.stderr, flush=True)
        if now - state["last"] >= every:
            state["last"] = now
            print(f"rollqp: the starting state: step {j} (about {expected} usually), {now - t0:.1f} s",
                  file=sys.stderr, flush=True)
    return tick


#: Seconds of a start's steps after which its total time is estimated (:func:`start_progress`).
START_ESTIMATE_SECONDS = 3.0


def estimate_progress(cb, steps: int):
    """``cb`` that also prints, once, the estimated remaining time when it exceeds :data:`ANNOUNCE_SECONDS`:
    measured on the first rolling steps (after at least 10 s of them, or 5 steps), the start excluded."""
    state = {"t": None, "k": 0, "said": False}

    def progress(k, K):
        now = time.perf_counter()
        if state["t"] is None:  # the first rolling step is done: the clock starts here
            state["t"], state["k"] = now, k
        elif not state["said"] and (now - state["t"] >= 10.0 or k - state["k"] >= 5):
            per = (now - state["t"]) / (k - state["k"])
            left = per * (K - k)
            state["said"] = True
            if left > ANNOUNCE_SECONDS:
                print(f"rollqp: about {_minutes(left)} to go: {K - k} of {steps} steps left at {per:.3g} s a step "
                      f"(measured on steps {state['k'] + 1}..{k})", file=sys.stderr, flush=True)
        if cb is not None:
            cb(k, K)

    return progress


def _minutes(seconds: float) -> str:
    return f"{seconds:.0f} s" if seconds < 120 else f"{seconds / 60:.0f} min" if seconds < 7200 else f"{seconds / 3600:.1f} h"


def _spot_steps(args, scene):
    """``(kept steps, observer)``: the run keeps steps 0, K/2 and K as step files for the cross-check."""
    from .crossval import SPOT_MAX_NODES, SPOT_METHODS
    wanted = args.cross_check
    if wanted is None:
        n = scene.discretization.elements * {"constant": 1, "linear": 1, "quadratic": 2}[scene.discretization.element] + 1
        wanted = not args.quiet and n <= SPOT_MAX_NODES and scene.solver.method not in SPOT_METHODS
    if scene.contact.friction.kind != "constant":  # step files hold one constant μ (a law: docs/friction.md)
        wanted = False
    if not wanted or args.quiet:
        return {}, None
    from .stepfile import from_record
    K = scene.n_steps
    steps = sorted({0, K // 2, K})
    keep = {}

    def observe(rec, ops):
        if rec.k in steps and rec.problem is not None:
            keep[rec.k] = from_record(scene, ops, scene.solver.method, rec)

    return keep, observe


def cmd_scenes(args) -> int:
    from .scene import builtin_scenes, load_scene
    names = builtin_scenes()
    w = max(map(len, names))
    for k, v in names.items():      # every scene tagged by its dimension, the same way
        print(f"{k:<{w}}  {load_scene(k).dimension}D  {v}")
    return 0


def cmd_show(args) -> int:
    from .scene import load_scene
    sys.stdout.write(load_scene(args.scene).to_toml())
    return 0


def cmd_export_step(args) -> int:
    from .scene import load_scene
    from .result import check_output
    scene = load_scene(args.scene)
    _takes(scene, "export-step")
    out = check_output(args.out or default_output(scene.name, f"-step{args.step}.npz"), "step file")
    step = family(scene).export_step(scene, args.step, method=args.method)
    for path in step.save(out):
        print(f"wrote {path}")
    return 0


def cmd_check_step(args) -> int:
    from .stepfile import DEFAULT_TOL, check_step, load_solution, load_step
    from .stepfile.three import StepFile3D, check_step_3d, load_solution_3d
    step = load_step(args.step_file, arg="STEP.npz")       # either dimension's, by its format key
    tol = DEFAULT_TOL if args.tol is None else args.tol
    if isinstance(step, StepFile3D):
        rep = check_step_3d(step, load_solution_3d(args.solution, step.n, arg="SOLUTION.npz"), tol=tol)
    else:
        rep = check_step(step, load_solution(args.solution, step.n, arg="SOLUTION.npz"), tol=tol)
    print(rep)
    if rep.passed:
        return 0
    for line in rep.diagnosis():
        print(f"rollqp: check failed: {line}", file=sys.stderr)
    return 1


def cmd_crossval(args) -> int:
    from .crossval import report
    from .methods import SCENE_METHOD_NAMES as METHOD_NAMES
    methods = None
    if args.methods:
        methods = [m.strip() for m in args.methods.split(",") if m.strip()]
        bad = [m for m in methods if m not in METHOD_NAMES]
        if bad or not methods:
            from .errors import InputError
            raise InputError("--methods", f"unknown method(s) {', '.join(bad) or '(none given)'}; "
                                          f"choose from {', '.join(METHOD_NAMES)}")
    if args.scene.endswith(".npz"):
        from .stepfile import StepFile
        print(report(StepFile.load(args.scene, arg="SCENE"), methods=methods))
        return 0
    from .scene import load_scene
    scene = load_scene(args.scene)
    _takes(scene, "crossval")
    return family(scene).crossval(scene, args.step, methods)


def cmd_extrapolate(args) -> int:
    """``rollqp extrapolate SCENE [--grids N1,N2,N3]`` (:func:`rollqp.extrapolate.extrapolate`)."""
    from .errors import InputError
    from .scene import load_scene
    scene = load_scene(args.scene)
    _takes(scene, "extrapolate")
    grids = None
    if args.grids:
        try:
            grids = tuple(int(v) for v in args.grids.split(","))
        except ValueError:
            raise InputError("--grids", f"must be three integers N1,N2,N3, got {args.grids!r}") from None
        if any(g < 1 or g > 2000 for g in grids):
            raise InputError("--grids", f"each count must be in [1, 2000], got {args.grids!r}")
    from .extrapolate import extrapolate
    print(extrapolate(scene, grids))
    return 0


def benchmarks_folder():
    """The source repository's ``benchmarks/`` folder beside the package, or ``None`` (installed from a wheel)."""
    from pathlib import Path
    folder = Path(__file__).resolve().parent.parent / "benchmarks"
    return folder if (folder / "suite.py").is_file() else None


def cmd_bench(args) -> int:
    """``rollqp bench ARGS``: the benchmark suite of the source repository (``benchmarks/suite.py``)."""
    import runpy
    folder = benchmarks_folder()
    if folder is None:
        from .errors import InputError
        raise InputError("bench", "the benchmarks ship with the source repository (benchmarks/suite.py), which this "
                                  "installation does not have; clone it and run rollqp bench there")
    if str(folder) not in sys.path:
        sys.path.insert(0, str(folder))
    suite = runpy.run_path(str(folder / "suite.py"), run_name="rollqp_bench_suite")
    return suite["main"](args.bench_args)


# --------------------------------------------------------------------------- sweeps (docs/sweeps.md)
def _sweep_parsers(sub):
    """The ``sweep`` and ``creep-curve`` subcommands (extra ``sweep``: dask, xarray, zarr)."""
    w = sub.add_parser("sweep", help="a parameter study on dask: the product of --vary values, "
                       "results in one labelled zarr store (docs/sweeps.md)")
    w.add_argument("scene", help="the base scene: a TOML file or a built-in scene")
    w.add_argument("--vary", action="append", required=True, metavar="KEY=VALUES",
                   help="a dotted scene key and its values: a,b,c | start:stop:count | start:stop:count:log "
                        "(repeat for more keys; the points are the product)")
    w.add_argument("--out", help="the zarr store (default <scene name>-sweep.zarr); run again to complete it")
    _cluster_options(w)
    c = sub.add_parser("creep-curve", help="the steady creep curve Q/(mu P) against the creepage, on dask, "
                       "with Carter's law or the Bentall-Johnson limit (docs/sweeps.md)")
    c.add_argument("scene", help="the base scene: a TOML file or a built-in scene")
    c.add_argument("--ratios", default=None, help="2D: load ratios Q/(mu P): a,b,c or start:stop:count "
                   "(default 0.05:0.95:19)")
    c.add_argument("--friction", help="2D: friction coefficients mu (default: the scene's)")
    c.add_argument("--creepage", help="3D: the creepage swept: longitudinal | lateral | spin (default longitudinal)")
    c.add_argument("--values", help="3D: its values, a,b,c or start:stop:count (default 1e-4:2e-3:12; spin in "
                   "1/length)")
    c.add_argument("--plot", help="draw the creep-force figure to this file")
    c.add_argument("--out", help="the zarr store (default <scene name>-creep.zarr)")
    _cluster_options(c)


def _keep_count(text):
    """``--keep-every K``: a whole number >= 1 of a few digits."""
    t = str(text).strip()
    if not t.isdigit() or len(t) > 9 or int(t) < 1:
        shown = t if len(t) <= 20 else f"{t[:20]}… ({len(t)} characters)"
        raise argparse.ArgumentTypeError(f"must be a whole number >= 1 (keep every K-th state), got {shown!r}")
    return int(t)


def _workers_count(text):
    """``--workers N``: an integer of a few digits (its range is checked when the cluster starts)."""
    t = str(text).strip()
    if not t.isdigit() or len(t) > 6:
        shown = t if len(t) <= 20 else f"{t[:20]}… ({len(t)} characters)"
        raise argparse.ArgumentTypeError(f"must be a whole number of worker processes, got {shown!r}")
    return int(t)


def _cluster_options(p):
    p.add_argument("--scheduler", metavar="ADDRESS", help="an existing dask scheduler (tcp://host:8786, or "
                   "tls://host:8786 with a dask TLS configuration); default: a local cluster")
    p.add_argument("--workers", type=_workers_count, help="worker processes of the local cluster (default: one per core; 0: the points run in this "
                   "process, no cluster)")
    p.add_argument("--quiet", action="store_true", help="print nothing but errors")


def _sweep_signals(fn):
    """Run ``fn()`` with SIGTERM handled as Ctrl-C (the stored points stay)."""
    import signal
    previous = signal.signal(signal.SIGTERM, _on_sigterm)
    try:
        return fn()
    finally:
        signal.signal(signal.SIGTERM, previous)


def _sweep_exit(summary) -> int:
    if summary.interrupted:
        return EXIT_INTERRUPTED
    return EXIT_SOLVER if summary.failed else 0


def cmd_sweep(args) -> int:
    from .scene import load_scene
    scene = load_scene(args.scene)
    _takes(scene, "sweep")
    return family(scene).sweep(scene, args)


def _sweep_3d(scene, args) -> int:
    from .sweep.three import sweep_3d
    out = args.out or default_output(scene.name, "-sweep.zarr")
    _, summary = _sweep_signals(lambda: sweep_3d(scene, args.vary, out, scheduler=args.scheduler,
                                                 workers=args.workers, quiet=args.quiet))
    if not args.quiet:
        print(f"rollqp sweep of {scene.name} (3D): {out}")
        print(summary.table())
    return _sweep_exit(summary)


def _creep_3d(scene, args) -> int:
    from .errors import InputError
    from .sweep.three import creep_curve_3d
    if args.ratios is not None or args.friction is not None:
        raise InputError("--ratios" if args.ratios is not None else "--friction",
                         "a 3D creep curve prescribes the creepage: --creepage longitudinal|lateral|spin --values V")
    out = args.out or default_output(scene.name, "-creep.zarr")
    _check_plot(args.plot)
    curve = _sweep_signals(lambda: creep_curve_3d(scene, args.creepage or "longitudinal",
                                                  args.values or "1e-4:2e-3:12", out, scheduler=args.scheduler,
                                                  workers=args.workers, quiet=args.quiet))
    if curve.FN is None:       # interrupted: the points done are saved in the store
        print(curve.summary.table())
        return _sweep_exit(curve.summary)
    if args.plot:
        curve.plot(args.plot)
    if not args.quiet:
        print(curve.table())
        print(curve.summary.table())
        print(f"  store         {out}" + (f"\n  figure        {args.plot}" if args.plot else ""))
    return _sweep_exit(curve.summary)


def _sweep_2d(scene, args) -> int:
    from .sweep import sweep
    out = args.out or default_output(scene.name, "-sweep.zarr")
    summary = _sweep_signals(lambda: sweep(scene, args.vary, out, scheduler=args.scheduler, workers=args.workers,
                                           quiet=args.quiet))
    if not args.quiet:
        print(f"rollqp sweep of {scene.name}: {out}")
        print(summary.table())
    return _sweep_exit(summary)


def cmd_creep_curve(args) -> int:
    from .scene import load_scene
    scene = load_scene(args.scene)
    _takes(scene, "creep-curve")
    return family(scene).creep_curve(scene, args)


def _creep_2d(scene, args) -> int:
    from .errors import InputError
    from .sweep.creep import creep_curve
    if args.creepage is not None or args.values is not None:
        raise InputError("--creepage" if args.creepage is not None else "--values",
                         "a 2D creep curve prescribes the load ratios: --ratios (and --friction)")
    args.ratios = "0.05:0.95:19" if args.ratios is None else args.ratios
    out = args.out or default_output(scene.name, "-creep.zarr")
    _check_plot(args.plot)
    curve = _sweep_signals(lambda: creep_curve(scene, args.ratios, args.friction, out, scheduler=args.scheduler,
                                               workers=args.workers, quiet=args.quiet))
    if args.plot and not curve.summary.interrupted:
        curve.plot(args.plot)
    if not args.quiet:
        print(curve.table())
        print(curve.summary.table())
        print(f"  store         {out}" + (f"\n  figure        {args.plot}" if args.plot else ""))
    return _sweep_exit(curve.summary)


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    if argv[:1] == ["bench"]:  # the suite parses its own options (benchmarks/suite.py)
        args = argparse.Namespace(command="bench", bench_args=argv[1:])
    else:
        args = _parser().parse_args(argv)
    from .errors import InputError, RollqpError, SolverError
    from .threads import limited
    try:
        with limited():  # every BLAS pool at $ROLLQP_THREADS (default 1), scipy's included (rollqp.threads)
            return {"run": cmd_run, "scenes": cmd_scenes, "show": cmd_show, "export-step": cmd_export_step,
                    "check-step": cmd_check_step, "crossval": cmd_crossval, "bench": cmd_bench,
                    "extrapolate": cmd_extrapolate,
                    "sweep": cmd_sweep, "creep-curve": cmd_creep_curve,
                    "stresses": cmd_stresses, "wheelrail-table": cmd_wheelrail_table}[args.command](args)
    except SolverError as err:
        print(f"rollqp: solver error: {err}", file=sys.stderr)
        return EXIT_SOLVER
    except (InputError, RollqpError) as err:
        print(f"rollqp: error: {err}", file=sys.stderr)
        return EXIT_INPUT
    except OSError as err:
        print(f"rollqp: error: {err.strerror or err}: {err.filename or ''}".rstrip(": "), file=sys.stderr)
        return EXIT_INPUT
    except MemoryError as err:  # beyond what the checks before the run foresaw
        text = str(err).split("\n")[0][:200]
        print(f"rollqp: error: out of memory{(': ' + text) if text else ''}", file=sys.stderr)
        return EXIT_INPUT
    except KeyboardInterrupt:
        print("rollqp: interrupted", file=sys.stderr)
        return 130


# ----------------------------------------------------------------------------- wheel on rail
def _wheelrail_parser(sub):
    from .wheelrail.cli import add_parser
    add_parser(sub)


def cmd_wheelrail_table(args) -> int:
    from .wheelrail.cli import cmd_table
    return cmd_table(args)


# ----------------------------------------------------------------------------- stresses
def _stresses_parser(sub):
    t = sub.add_parser("stresses", help="subsurface stresses of one state of a result file (docs/stresses.md)")
    t.add_argument("result", metavar="RESULT.npz")
    t.add_argument("--step", type=int, required=True, help="the stored state K (0 = the starting state; "
                   "negative counts from the end)")
    t.add_argument("--plot", help="contour maps of von Mises and tau1 (3D: Tresca) with the surface tractions (PNG)")
    t.add_argument("--out", help="stress file (.npz): the points, every stress quantity, the maxima")
    t.add_argument("--body", default="A", choices=("A", "B"), help="body A (traction t) or B (-t)")
    t.add_argument("--grid", default=None, help="2D: NX,NZ points on ±WIDTH a_H and depths (0, DEPTH a_H] "
                   "(default 200,200)")
    t.add_argument("--width", type=float, default=None, help="2D: half-width of the grid in a_H (default 1.5)")
    t.add_argument("--depth", type=float, default=None, help="2D: depth of the grid in a_H (default 2)")
    t.add_argument("--plane", help="3D: the plane y=Y (points along x at the element centres) or x=X "
                   "(scene length units; default y=0)")
    t.add_argument("--line", help="3D: the vertical line x=X,y=Y instead of a plane")
    t.add_argument("--depths", help="3D: depths Z1,Z2,... (> 0, scene length units; default 40 down to 2a)")


def _stresses_3d(args, arrays) -> int:
    """``rollqp stresses`` on a 3D result: the section the user chose, its peaks, the stress file, the figure."""
    from .errors import InputError
    from .subsurface3d import (parse_depths, parse_line, parse_plane, plot_field3d, save_field3d, stresses3d,
                               summary_rows3d)
    for opt in ("grid", "width", "depth"):
        if getattr(args, opt) is not None:
            raise InputError(f"--{opt}", "is for 2D results; on a 3D result choose the points with --plane y=Y | "
                                         "--plane x=X | --line x=X,y=Y and --depths Z1,Z2,...")
    plane = parse_plane(args.plane) if args.plane is not None else None
    line = parse_line(args.line) if args.line is not None else None
    depths = parse_depths(args.depths) if args.depths is not None else None
    names = {"step": "--step", "result": "RESULT.npz", "depths": "--depths", "points": "--depths"}
    try:
        sf = stresses3d(arrays, args.step, plane, line, depths, body=args.body)
    except InputError as err:
        raise InputError(names.get(err.key, err.key), str(err).split(": ", 1)[-1]) from None
    p0 = float(arrays["p0"])
    nz, nh = sf.values["sxx"].shape
    print(f"  state         {sf.step} (q = {sf.q:.6g}), body {sf.body}, {sf.section.label}, "
          f"{nh} x {nz} points" if nh > 1 else f"  state         {sf.step} (q = {sf.q:.6g}), body {sf.body}, "
          f"{sf.section.label}, {nz} depths")
    for k, v in summary_rows3d(sf, p0):
        print(f"  {k:<20}  {v}")
    if args.out:
        print(f"  stress file   {save_field3d(sf, args.out)}")
    if args.plot:
        print(f"  figure        {plot_field3d(sf, arrays, args.plot, p0)}")
    return 0


def cmd_stresses(args) -> int:
    from .errors import InputError
    from .influence import get_model
    from .result import check_output, load_result
    from .subsurface import _source, default_grid, plot_field, save_field, stresses, summary_rows
    if args.out:
        check_output(args.out, "stress file", "--out")
    _check_plot(args.plot)
    loaded = load_result(args.result, "RESULT.npz")
    if "y" in loaded:  # a grid of elements: a 3D result
        return _stresses_3d(args, loaded)
    for opt in ("plane", "line", "depths"):
        if getattr(args, opt) is not None:
            raise InputError(f"--{opt}", "is for 3D results; on a 2D result choose the points with --grid NX,NZ, "
                                         "--width and --depth")
    grid = "200,200" if args.grid is None else args.grid
    width, depth = (1.5 if args.width is None else args.width), (2.0 if args.depth is None else args.depth)
    try:
        nx, nz = (int(v) for v in grid.split(","))
    except ValueError:
        raise InputError("--grid", f"must be NX,NZ (two integers), got {grid!r}") from None
    names = {"nx": "--grid", "nz": "--grid", "width": "--width", "depth": "--depth", "step": "--step",
             "result": "RESULT.npz"}
    try:
        arrays, scene = _source(loaded)
        sf = stresses(arrays, args.step, default_grid(scene, nx, nz, width, depth), body=args.body)
    except InputError as err:
        raise InputError(names.get(err.key, err.key), str(err).split(": ", 1)[-1]) from None
    a, p0 = float(arrays["a_H"]), float(arrays["p0"])
    print(f"  state         {sf.step} (q = {sf.q / a:.4f} a_H), body {sf.body}, grid {nx} x {nz}")
    if not get_model(scene.contact.model).halfspace_field:
        print(f"  note          half-space field below the model's tractions: error about a/(2R) p0 = "
              f"{a / (2 * scene.R):.2g} p0 (docs/stresses.md §4)")
    for k, v in summary_rows(sf, p0, a):
        print(f"  {k:<20}  {v}")
    if args.out:
        print(f"  stress file   {save_field(sf, args.out)}")
    if args.plot:
        print(f"  figure        {plot_field(sf, arrays, args.plot, p0, a)}")
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
