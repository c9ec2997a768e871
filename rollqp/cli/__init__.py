"""The ``rollqp`` command (docs/scenes.md and docs/results.md: the command line, scene and result files).

    rollqp run SCENE [--out RESULT.npz] [--plot FIGURE.png] [--method METHOD] [--keep-every K] [--quiet]
    rollqp run --resume RESULT.npz
    rollqp scenes
    rollqp show SCENE
    rollqp export-step SCENE --step K [--out STEP.npz] [--method METHOD]
    rollqp check-step STEP.npz SOLUTION.npz [--tol T]
    rollqp crossval SCENE [--step K] [--methods M1,M2]
    rollqp extrapolate SCENE [--grids N1,N2,N3] [--target PCT] [--budget S] [--workers N]   (3D: creep forces)
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
One module per command (``rollqp/cli/run.py``, ``show.py``, …: its options in ``add_arguments(parser)``, the
command in ``main(args)``, the modules it needs imported at its top); :data:`COMMANDS` names each as data, and
:func:`main` imports only the chosen command's module (``rollqp show`` loads no solver, ``rollqp --help`` no
command). The commands dispatch on a scene's dimension through its :class:`~rollqp.cli.common.Family` record.
BLAS threads are pinned to ``$ROLLQP_THREADS`` (default one) before numpy and scipy load
(:mod:`rollqp.threads`): their wheels each bundle OpenBLAS, and two pools competing for 2 cores
made a 3D run 3× slower.
"""
from __future__ import annotations

import argparse
import importlib
import platform
import sys
from dataclasses import dataclass
from importlib import metadata

from ..errors import InputError, RollqpError, SolverError
from ..threads import limited
from ..version import __version__
from .common import (EXIT_INPUT, EXIT_INTERRUPTED, EXIT_SOLVER, EXIT_TERMINATED, EXIT_WRITE,  # noqa: F401 - the
                     default_output)                                                        # command's contract
from .families import FAMILIES, Family

__all__ = ["main", "COMMANDS", "Command", "version_text", "EXIT_INPUT", "EXIT_SOLVER", "EXIT_WRITE",
           "EXIT_INTERRUPTED", "EXIT_TERMINATED", "FAMILIES", "Family", "default_output"]


@dataclass(frozen=True)
class Command:
    """One subcommand: the module that holds it (``add_arguments(parser)`` and ``main(args) -> exit code``) and
    its line in ``rollqp --help``; the module is imported only when the command is chosen."""

    module: str
    help: str
    add_help: bool = True

    def load(self):
        return importlib.import_module(self.module)


#: The command table: name -> its module, in the order of ``rollqp --help``.
COMMANDS = {
    "run": Command("rollqp.cli.run", "run a scene and write its result file"),
    "scenes": Command("rollqp.cli.scenes", "list the built-in scenes"),
    "show": Command("rollqp.cli.show", "print a scene's TOML with defaults filled in"),
    "export-step": Command("rollqp.cli.export_step", "write one step's data and QP forms (docs/stepfiles.md)"),
    "check-step": Command("rollqp.cli.check_step", "check a candidate solution of an exported step"),
    "crossval": Command("rollqp.cli.crossval", "every available method on one step, side by side"),
    "extrapolate": Command("rollqp.cli.extrapolate", "3D: the steady state's creep forces on a few grids, "
                           "each averaged over grid positions, extrapolated with an error estimate (docs/performance.md)"),
    "stresses": Command("rollqp.cli.stresses", "subsurface stresses of one state of a result file (docs/stresses.md)"),
    "wheelrail-table": Command("rollqp.wheelrail.cli", "the Manchester benchmark A-2.2: its 21 positions of a "
                               "wheel-rail scene, left and right wheels, as one table (docs/validation-wheel-rail.md)"),
    "bench": Command("rollqp.cli.bench", "benchmarks: work–precision and scaling (docs/performance.md; "
                     "'rollqp bench --help' for the options)", add_help=False),
    "sweep": Command("rollqp.cli.sweep", "a parameter study on dask: the product of --vary values, results in one "
                     "labelled zarr store (docs/sweeps.md)"),
    "creep-curve": Command("rollqp.cli.creep_curve", "the steady creep curve Q/(mu P) against the creepage, on dask, "
                           "with Carter's law or the Bentall-Johnson limit (docs/sweeps.md)"),
}


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, no usage dump
        self.exit(EXIT_INPUT, f"rollqp: error: {message} (see 'rollqp --help')\n")


def version_text() -> str:
    """``rollqp X (Python …, numpy …, scipy …, clarabel …, osqp …)``: what a bug report needs."""
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


def parser(chosen: str | None = None) -> argparse.ArgumentParser:
    """The parser of ``rollqp``: every command with its help line, the options of ``chosen`` only (its module
    is imported to add them; the others' options are never parsed)."""
    p = _Parser(prog="rollqp", description="Transient rolling contact in 2D and 3D: convex QP/SOCP steps and "
                                           "generalized Newton.")
    p.add_argument("--version", action=_Version)
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)
    for name, command in COMMANDS.items():
        s = sub.add_parser(name, help=command.help, add_help=command.add_help)
        if name == chosen:
            command.load().add_arguments(s)
    return p


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    if argv[:1] == ["bench"]:  # the suite parses its own options (benchmarks/suite.py)
        args = argparse.Namespace(command="bench", bench_args=argv[1:])
    else:  # the command: the first word that is not an option (rollqp has no top-level option with a value)
        args = parser(next((a for a in argv if not a.startswith("-")), None)).parse_args(argv)
    try:
        with limited():  # every BLAS pool at $ROLLQP_THREADS (default 1), scipy's included (rollqp.threads)
            return COMMANDS[args.command].load().main(args)
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
        return EXIT_INTERRUPTED
