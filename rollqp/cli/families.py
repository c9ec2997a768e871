"""The :class:`Family` record of each kind of scene (its dimension, or its ``family``: a wheel on its rail), through
which the commands dispatch, so that none tests a scene's dimension itself; :func:`takes` refuses a command a
kind of scene does not take."""
from __future__ import annotations

import importlib

from ..errors import InputError


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
    goes back to the system (None: kept for the next allocation, :func:`rollqp.cli.run.keep_freed_memory`).

    Each part is named as data, ``"module:attribute"``, and imported when a command first uses it (so that a
    command loads only the parts of the scene's dimension it calls: ``rollqp run`` of a 3D scene neither the
    2D march's figures nor any step file), or given as the callable itself (:meth:`replace`). The command
    line's own parts of a dimension are in one module each (:mod:`rollqp.cli.two`, :mod:`rollqp.cli.three`,
    :mod:`rollqp.wheelrail.cli`; the sweeps of both in :mod:`rollqp.cli.sweeps`), which import nothing of this
    module: the names run one way only.
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
              advise="rollqp.cli.two:advise", spot="rollqp.cli.two:spot", check="rollqp.cli.two:check",
              stresses="rollqp.subsurface:stress_history", crossval="rollqp.cli.two:crossval",
              export_step="rollqp.stepfile:export_step", sweep="rollqp.cli.sweeps:sweep_2d",
              creep_curve="rollqp.cli.sweeps:creep_2d", memory_policy="rollqp.cli.two:give_back_freed_memory"),
    3: Family({"crossval", "export-step", "sweep", "creep-curve", "extrapolate"},
              run="rollqp.march.grid:run", summary="rollqp.report.grid:summary", plot="rollqp.plot.three:three_figure",
              advise="rollqp.cli.three:advise", spot="rollqp.cli.three:spot", check="rollqp.cli.three:check",
              crossval="rollqp.cli.three:crossval", refuse="rollqp.advice.grid:refusal",
              export_step="rollqp.stepfile.three:export_step_3d", sweep="rollqp.cli.sweeps:sweep_3d",
              creep_curve="rollqp.cli.sweeps:creep_3d", stresses="rollqp.subsurface3d:stress_history3d"),
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
