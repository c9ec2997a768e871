"""The ``rollqp`` command (SPEC.md, "Command line").

    rollqp run SCENE [--out RESULT.npz] [--plot FIGURE.png] [--method METHOD] [--quiet]
    rollqp scenes
    rollqp show SCENE

Errors are one line on stderr and a non-zero exit: 2 for invalid input, 3 for a solver
that did not converge (the completed steps are written to the result file first).
BLAS threads are pinned to one: numpy's and scipy's wheels each bundle OpenBLAS, and two
pools competing for 2 cores can make a dense solve 100× slower.
"""
from __future__ import annotations

import argparse
import os
import sys
import time

EXIT_INPUT, EXIT_SOLVER = 2, 3


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, no usage dump
        self.exit(EXIT_INPUT, f"rollqp: error: {message} (see 'rollqp --help')\n")


def _parser():
    from .methods import METHOD_NAMES
    p = _Parser(prog="rollqp", description="2D transient rolling contact: convex QP steps and generalized Newton.")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)
    r = sub.add_parser("run", help="run a scene and write its result file")
    r.add_argument("scene", help="a TOML scene file or the name of a built-in scene")
    r.add_argument("--out", help="result file (.npz); default: <scene name>.npz in the current folder")
    r.add_argument("--plot", help="draw tractions, slip and creepage to this PNG file")
    r.add_argument("--method", choices=METHOD_NAMES, help="overrides [solver].method")
    r.add_argument("--quiet", action="store_true", help="print nothing but errors")
    sub.add_parser("scenes", help="list the built-in scenes")
    s = sub.add_parser("show", help="print a scene's TOML with defaults filled in")
    s.add_argument("scene")
    return p


def _progress(quiet):
    """A progress callback: a tqdm bar that appears only after 2 s, on a terminal."""
    if quiet or not sys.stderr.isatty():
        return None, lambda: None
    try:
        from tqdm import tqdm
    except ImportError:  # pragma: no cover - tqdm is a dependency
        return None, lambda: None
    bar = {}

    def cb(k, K):
        if "b" not in bar:
            bar["b"] = tqdm(total=K, delay=2.0, unit="step", leave=False, file=sys.stderr)
        bar["b"].update(1)

    return cb, lambda: bar.get("b") and bar["b"].close()


def cmd_run(args) -> int:
    from . import driver
    from .plot import plot_result
    from .report import summary
    from .scene import load_scene
    scene = load_scene(args.scene)
    if args.method:
        scene = scene.replace(**{"solver.method": args.method})
    out = args.out or f"{scene.name}.npz"
    if not out.endswith(".npz"):
        from .errors import InputError
        raise InputError("--out", f"the result file must end in .npz, got {out!r}")
    cb, close = _progress(args.quiet)
    t0 = time.perf_counter()
    try:
        result = driver.run(scene, progress=cb)
    except Exception as err:
        partial = getattr(err, "partial", None)
        if partial is not None and len(partial):
            partial.meta["failed"] = str(err)
            partial.save(out)
            err.args = (f"{err} — the {len(partial)} completed states are in {out}",)
        raise
    finally:
        close()
    wall = time.perf_counter() - t0
    result.save(out)
    res = result.arrays()
    if args.plot:
        plot_result(res, scene, args.plot)
    if not args.quiet:
        print(summary(res, scene, scene.solver.method, wall))
        print(f"  result        {out}" + (f"\n  figure        {args.plot}" if args.plot else ""))
    return 0


def cmd_scenes(args) -> int:
    from .scene import builtin_scenes
    names = builtin_scenes()
    w = max(map(len, names))
    for k, v in names.items():
        print(f"{k:<{w}}  {v}")
    return 0


def cmd_show(args) -> int:
    from .scene import load_scene
    sys.stdout.write(load_scene(args.scene).to_toml())
    return 0


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    from .errors import InputError, RollqpError, SolverError
    try:
        from threadpoolctl import threadpool_limits
        limiter = threadpool_limits(limits=int(os.environ.get("ROLLQP_THREADS", "1")))
    except ImportError:  # pragma: no cover - threadpoolctl is a dependency
        limiter = None
    try:
        return {"run": cmd_run, "scenes": cmd_scenes, "show": cmd_show}[args.command](args)
    except SolverError as err:
        print(f"rollqp: solver error: {err}", file=sys.stderr)
        return EXIT_SOLVER
    except (InputError, RollqpError) as err:
        print(f"rollqp: error: {err}", file=sys.stderr)
        return EXIT_INPUT
    except OSError as err:
        print(f"rollqp: error: {err.strerror or err}: {err.filename or ''}".rstrip(": "), file=sys.stderr)
        return EXIT_INPUT
    except KeyboardInterrupt:
        print("rollqp: interrupted", file=sys.stderr)
        return 130
    finally:
        if limiter is not None:
            limiter.unregister() if hasattr(limiter, "unregister") else None


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
