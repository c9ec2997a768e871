"""The run of a scene over its discretization: one :func:`prepare`, :func:`march`, :func:`run` and :func:`resume`
for the strip (a 2D scene) and the grid (a 3D scene).

The dimension is a record that travels with the scene: :func:`family` hands a scene to the march of its
discretization (:data:`MARCHES`, by ``scene.dimension``), and every call here is that march's, with the same
arguments and guarantees (docs/results.md):

* :mod:`rollqp.march.strip` — the strip's transient (the starting state, the rolling steps, a load path;
  paper §4.1, §4.4);
* :mod:`rollqp.march.grid` — the grid's (static shift, steady state, transient, a load path; docs/theory3d.md
  §4, §6, §8);
* :mod:`rollqp.march.loop` — what both do the same way: the loop of the step records into the
  :class:`~rollqp.result.Result` streamed to its journal (:func:`drive`), the states a resumed run keeps, and
  the checks of an earlier part of a run before it is continued (the last state solved again, every earlier
  state consistent in itself).

Examples
--------
>>> from rollqp.march import family
>>> [family(s).__name__ for s in ("cattaneo-carter", "kalker-circular")]
['rollqp.march.strip', 'rollqp.march.grid']
"""
from __future__ import annotations

import importlib
import os

from ..errors import InputError
from ..result import resume_source
from ..scene import load_scene, scene_from_dict
from ..scene.core import SceneBase
from . import strip
from .loop import RESUME_TOL, drive
from .strip import State, StepRecord

__all__ = ["MARCHES", "family", "prepare", "march", "run", "resume", "drive", "RESUME_TOL", "State", "StepRecord"]

#: The march of each discretization, by the scene's dimension: a module of this package with ``prepare``,
#: ``march``, ``run``, ``check_resumed``, ``check_states`` and ``new_result`` of the same meaning (the grid's is
#: imported on first use, so that ``import rollqp`` stays light).
MARCHES = {2: "strip", 3: "grid"}


def _scene(scene) -> SceneBase:
    return scene if isinstance(scene, SceneBase) else load_scene(scene)


def family(scene):
    """The march of ``scene``'s discretization (:data:`MARCHES`): :mod:`rollqp.march.strip` or
    :mod:`rollqp.march.grid`."""
    scene = _scene(scene)
    if getattr(scene, "family", None) is not None:     # a wheel on its rail: one state per wheel (rollqp.run)
        raise InputError("scene", f"a {scene.family} scene is one state per wheel, not a march: use rollqp.run")
    try:
        return importlib.import_module(f"{__name__}.{MARCHES[scene.dimension]}")
    except KeyError:
        raise InputError("contact.dimension", f"no march for {scene.dimension!r}-dimensional scenes (one of "
                                              f"{', '.join(map(str, MARCHES))})") from None


def prepare(scene, method=None, **options):
    """``(scene, method, operators)``: the scene validated, its method made and set up on the operators of its
    discretization (:func:`rollqp.march.strip.prepare`, :func:`rollqp.march.grid.prepare`)."""
    scene = _scene(scene)
    return family(scene).prepare(scene, method, **options)


def march(scene, method=None, **options):
    """The run as a stream of step records, state 0 first (:func:`rollqp.march.strip.march`,
    :func:`rollqp.march.grid.march`)."""
    scene = _scene(scene)
    return family(scene).march(scene, method, **options)


def run(scene, method=None, progress=None, resume=None, observe=None, **options):
    """Run a scene and return its :class:`~rollqp.result.Result` (:func:`rollqp.march.strip.run`,
    :func:`rollqp.march.grid.run`): ``out`` the result file, every state journaled as it is completed;
    ``resume`` an earlier part of the run, its states checked first; ``keep_every``, ``start_progress`` and the
    strip's ``geometry`` as keywords."""
    scene = _scene(scene)
    return family(scene).run(scene, method, progress, resume, observe, **options)


def resume(path, method=None, **options):
    """Continue an interrupted, failed or killed run from its result file or journal ``path``: the scene stored
    in the file, run from after its last state (checked first: :func:`run` with ``resume``). ``out``: where the
    continued run is written (default: none, the result in memory)."""
    source = resume_source(os.fspath(path), "--resume")
    try:
        scene = scene_from_dict(source.meta["scene"], source=os.fspath(path))
    except (KeyError, TypeError) as exc:
        source.close()
        raise InputError("--resume", "the result file holds no scene (meta['scene'])") from exc
    try:
        return run(scene, method, resume=source, **options)
    finally:
        source.close()
