"""What the commands of ``rollqp`` share: the exit codes, the default output names, the ``--plot`` check, the
options of the commands on dask, and the :class:`Family` record of each dimension through which the commands
dispatch (so that none tests a scene's dimension itself)."""
from __future__ import annotations

import argparse
import importlib
import os
import re
import signal

from ..errors import InputError, MissingBackendError

EXIT_INPUT, EXIT_SOLVER = 2, 3
#: The journal or the result file could not be written (a full disk, a file size limit).
EXIT_WRITE = 4
#: Interrupted by Ctrl-C (SIGINT) or SIGTERM: the shell's 128 + signal number.
EXIT_INTERRUPTED, EXIT_TERMINATED = 130, 143


class Terminated(KeyboardInterrupt):
    """SIGTERM, handled as Ctrl-C: the completed states are written before rollqp exits."""


def on_sigterm(signum, frame):
    raise Terminated()


def default_output(name: str, suffix: str = ".npz") -> str:
    """``<name><suffix>`` in the current folder, the scene name reduced to a safe file name.

    A scene's name never steers the path: every character outside ``[A-Za-z0-9._-]`` becomes
    ``_`` and leading dots are dropped (``"../x"`` → ``"_x"``), so the default output stays in
    the working folder.
    """
    safe = re.sub(r"[^A-Za-z0-9._-]", "_", name).lstrip(".")[:100] or "result"
    return safe + suffix


def check_plot(path):
    """Check ``--plot`` before the run: a known image format and a writable folder."""
    if path is None:
        return
    try:  # matplotlib (extra "plot") itself: rollqp.plot's figures are imported only when one is drawn
        from matplotlib.backends.backend_agg import FigureCanvasAgg
    except ImportError as exc:  # pragma: no cover - depends on the installation
        raise MissingBackendError("--plot needs matplotlib: pip install 'rollqp[plot]'") from exc
    ext = os.path.splitext(path)[1].lstrip(".").lower()
    formats = FigureCanvasAgg.get_supported_filetypes()
    if ext not in formats:
        raise InputError("--plot", f"unknown figure format {ext or '(none)'!r}; use one of "
                                   f"{', '.join(sorted(formats))}")
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder) or not os.access(folder, os.W_OK):
        raise InputError("--plot", f"cannot write in folder {folder!r}")


# --------------------------------------------------------------------------- the commands on dask (docs/sweeps.md)
def workers_count(text):
    """``--workers N``: an integer of a few digits (its range is checked when the cluster starts)."""
    t = str(text).strip()
    if not t.isdigit() or len(t) > 6:
        shown = t if len(t) <= 20 else f"{t[:20]}… ({len(t)} characters)"
        raise argparse.ArgumentTypeError(f"must be a whole number of worker processes, got {shown!r}")
    return int(t)


def cluster_options(p):
    p.add_argument("--scheduler", metavar="ADDRESS", help="an existing dask scheduler (tcp://host:8786, or "
                   "tls://host:8786 with a dask TLS configuration); default: a local cluster")
    p.add_argument("--workers", type=workers_count, help="worker processes of the local cluster (default: one per core; 0: the points run in this "
                   "process, no cluster)")
    p.add_argument("--quiet", action="store_true", help="print nothing but errors")


def sweep_signals(fn):
    """Run ``fn()`` with SIGTERM handled as Ctrl-C (the stored points stay)."""
    previous = signal.signal(signal.SIGTERM, on_sigterm)
    try:
        return fn()
    finally:
        signal.signal(signal.SIGTERM, previous)


def sweep_exit(summary) -> int:
    if summary.interrupted:
        return EXIT_INTERRUPTED
    return EXIT_SOLVER if summary.failed else 0


# --------------------------------------------------------------------------- one record per dimension
class Family:
    """What the command line does with the scenes of one dimension (``scene.dimension``): one record per
    dimension, so that the commands dispatch through it and never test the dimension themselves.

    ``run(scene, progress=, resume=, observe=)`` the run (a result with ``arrays()``, ``save()``);
    ``summary(arrays, scene, method, wall, stresses)``; ``plot(arrays, scene, path)``; ``advise(scene)``
    the notes before a run; ``spot(args, scene)`` → ``(kept, observe)`` of the cross-check and ``check(kept,
    scene, budget)`` its lines (``budget`` a time budget in seconds, None: none); ``stresses(result)`` the peak
    subsurface stresses (None: not for these scenes); ``commands``: the other subcommands that take its scenes;
    ``crossval(scene, step, methods)`` prints ``rollqp crossval``'s report and returns the exit code;
    ``export_step(scene, k, method)`` the step file of step ``k``; ``sweep(scene, args)`` and
    ``creep_curve(scene, args)`` run those commands and return the exit code; ``refuse(scene, allow_long)``
    raises an InputError, before any work, for a run that cannot finish in reasonable time or memory (3D conic
    runs: :func:`rollqp.advice.grid.refusal`; None: every run starts); ``memory_policy()`` how freed memory
    goes back to the system (:mod:`rollqp.cli.run`; None: kept for the next allocation).

    Each part is named as data, ``"module:attribute"``, and imported when a command first uses it (so that a
    command loads only the parts of the scene's dimension it calls: ``rollqp run`` of a 3D scene neither the
    2D march's figures nor any step file), or given as the callable itself (:meth:`replace`).
    """

    PARTS = ("run", "summary", "plot", "advise", "spot", "check", "stresses", "crossval", "export_step", "sweep",
             "creep_curve", "refuse", "memory_policy")

    def __init__(self, commands, **parts):
        unknown = sorted(set(parts) - set(self.PARTS))
        if unknown:
            raise TypeError(f"Family: unknown parts {unknown}; the parts are {', '.join(self.PARTS)}")
        self.commands = frozenset(commands)
        self._parts = parts

    def __getattr__(self, name):
        if name.startswith("_") or name not in Family.PARTS:
            raise AttributeError(name)
        part = self._parts.get(name)
        if isinstance(part, str):
            module, attr = part.split(":")
            return getattr(importlib.import_module(module), attr)
        return part

    def replace(self, **parts) -> Family:
        """The same record with some parts replaced (by a ``"module:attribute"`` name or a callable)."""
        return Family(self.commands, **{**self._parts, **parts})


#: The record of each dimension; a scene whose ``family`` names another record (a wheel on its rail) uses
#: that one.
FAMILIES = {
    2: Family({"export-step", "crossval", "sweep", "creep-curve"},
              run="rollqp.march:run", summary="rollqp.report:summary", plot="rollqp.plot:plot_result",
              advise="rollqp.cli.run:advise_2d", spot="rollqp.cli.crossval:spot_2d", check="rollqp.cli.crossval:check_2d",
              stresses="rollqp.subsurface:stress_history", crossval="rollqp.cli.crossval:crossval_2d",
              export_step="rollqp.stepfile:export_step", sweep="rollqp.cli.sweep:sweep_2d",
              creep_curve="rollqp.cli.creep_curve:creep_2d", memory_policy="rollqp.cli.run:give_back_freed_memory"),
    3: Family({"crossval", "export-step", "sweep", "creep-curve", "extrapolate"},
              run="rollqp.march.grid:run", summary="rollqp.report.grid:summary", plot="rollqp.plot.three:three_figure",
              advise="rollqp.cli.run:advise_3d", spot="rollqp.cli.crossval:spot_3d", check="rollqp.cli.crossval:check_3d",
              crossval="rollqp.cli.crossval:crossval_3d", refuse="rollqp.advice.grid:refusal",
              export_step="rollqp.stepfile.three:export_step_3d", sweep="rollqp.cli.sweep:sweep_3d",
              creep_curve="rollqp.cli.creep_curve:creep_3d", stresses="rollqp.subsurface3d:stress_history3d"),
    "wheel-rail": Family({"crossval"},
                         run="rollqp.wheelrail.run:run", summary="rollqp.wheelrail.run:summary",
                         plot="rollqp.wheelrail.run:figure", advise="rollqp.wheelrail.cli:advise",
                         spot="rollqp.wheelrail.cli:spot", check="rollqp.wheelrail.cli:check",
                         crossval="rollqp.wheelrail.cli:crossval_command"),
}


def family(scene) -> Family:
    """The :class:`Family` of ``scene``'s dimension (or of its ``family``)."""
    return FAMILIES[getattr(scene, "family", scene.dimension)]


def takes(scene, command: str) -> None:
    """Refuse a scene whose dimension's record does not list ``command``."""
    if command not in family(scene).commands:
        name = lambda d: f"{d}D" if isinstance(d, int) else d   # noqa: E731 - a dimension or a family's name
        dims = " and ".join(name(d) for d, f in FAMILIES.items() if command in f.commands)
        takes = ", ".join(["run", "show", "scenes", *sorted(family(scene).commands)])
        what = name(getattr(scene, "family", scene.dimension))
        raise InputError("SCENE", f"{scene.name!r} is a {what} scene; rollqp {command} works on {dims} "
                                  f"scenes (a {what} scene: rollqp {takes})")
