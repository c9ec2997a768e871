"""rollqp: transient rolling contact of elastic bodies: cylinders in 2D, Kalker's problem in 3D.

Every step is posed two ways — as convex QPs solved by external solvers (Clarabel, OSQP,
cvxpy) and as a complementarity system for a generalized Newton method — so that each
holds the other to account (González & Abascal 2002; see ``docs/``).

Public API
----------
load_scene, builtin_scenes, Scene        scenes (docs/scenes.md)
march, run, StepRecord                   the transient (2D or 3D): step records, or a Result
SceneOperators                           what a scene's transient needs, built once
Result, load_result                      result files
Strip                                    strip discretization
halfspace_influence, Influence           influence matrices
NormalStep, TangentialStep, Scales       step problems built from arrays
StepSolution, Residuals, classify, compare
solve_step                               solve one step with any method
get_method, available_methods            the method registry
open_result                              a result file as an xarray Dataset (extra ``sweep``)
closedforms                              Hertz, Cattaneo, Carter, creep law, McEwen
stresses                                 subsurface stresses of a state (rollqp.subsurface)
"""
from . import threads as _threads

_threads.pin_environment()  # before numpy and scipy load: their BLAS pools start at $ROLLQP_THREADS (rollqp.threads)

import importlib  # noqa: E402

from .version import __version__  # noqa: E402,F401

from . import closedforms
from .errors import InputError, MissingBackendError, RollqpError, SolverError
from .influence import Influence, halfspace_influence
from .methods import STEP_METHOD, available_methods, get_method
from .problem import (NormalStep, Residuals, Scales, StepSolution, TangentialStep, classify,
                      compare)
from .result import Result, load_result
from .scene import Scene, builtin_scenes, load_scene
from .strip import Strip
from .operators import SceneOperators
from . import march as _march
from .march import StepRecord
from .scene.core import SceneBase as _SceneBase
from . import energy, wear  # noqa: E402,F401  (register their result fields)
from .subsurface import stresses  # noqa: E402  (rollqp.stresses(result, step, grid))


#: The run of a scene of a family of its own (a wheel on its rail: one state per wheel, no march), by module,
#: imported with the first such scene, as the march imports a discretization's (:data:`rollqp.march.MARCHES`).
_FAMILY_RUNS = {"wheel-rail": "rollqp.wheelrail.run"}


def _scene(scene):
    return scene if isinstance(scene, _SceneBase) else load_scene(scene)


def run(scene, method=None, progress=None, resume=None, observe=None, **options):
    """Run a scene and return its result: :func:`rollqp.march.run`, the march of the scene's discretization (the
    strip of a 2D scene, the grid of a 3D one, ``[contact] dimension = 3``), with the same arguments (``out``,
    ``keep_every``, and the strip's ``geometry``, as keywords); a wheel–rail scene (``[contact] kind =
    "wheel-rail"``) is solved by :func:`rollqp.wheelrail.run.run`.

    Examples
    --------
    >>> import rollqp
    >>> r = rollqp.run("kalker-circular")
    >>> r.arrays()["pn"].shape[1:], round(float(r.arrays()["FN"][-1]))
    ((40, 40), 1000)
    """
    scene = _scene(scene)
    with _threads.limited():  # every BLAS pool at $ROLLQP_THREADS (default 1) for the run (rollqp.threads)
        if getattr(scene, "family", None) == "wheel-rail":   # one state per wheel: no march (rollqp.wheelrail)
            if method is not None:
                if not isinstance(method, str):
                    raise InputError("method", "a wheel-rail scene takes a method name (e.g. 'newton'), "
                                               f"got {type(method).__name__}")
                scene = scene.replace(**{"solver.method": method})
            run_family = importlib.import_module(_FAMILY_RUNS[scene.family]).run
            return run_family(scene, progress=progress, resume=resume, observe=observe, **options)
        return _march.run(scene, method, progress, resume, observe, **options)


def march(scene, method=None, **options):
    """The run as a stream of step records: :func:`rollqp.march.march` (``prepared``, ``resume`` as keywords)."""
    return _march.march(_scene(scene), method, **options)


def solve_step(problem, method: str = STEP_METHOD, warm=None, **settings) -> StepSolution:
    """Solve one step problem (:class:`NormalStep` or :class:`TangentialStep`) with ``method``.

    ``settings`` go to the method (``tolerance``, ``residual_limit``, …). For many steps of
    the same matrices create the method once with :func:`get_method` and call its
    ``solve`` repeatedly: solver objects are then built once and only updated.
    """
    return get_method(method, **settings).solve(problem, warm=warm)


def open_result(path):
    """A result file (``.npz``) as a labelled :class:`xarray.Dataset` (:func:`rollqp.sweep.dataset.open_result`;
    needs xarray, extra ``sweep``)."""
    from .sweep.dataset import open_result as _open  # optional dependencies behind it: xarray (extra "sweep")
    return _open(path)


__all__ = ["open_result", "load_scene", "builtin_scenes", "Scene", "march", "run", "StepRecord", "SceneOperators", "Result", "load_result", "Strip",
           "halfspace_influence", "Influence", "NormalStep", "TangentialStep", "Scales", "StepSolution",
           "Residuals", "classify", "compare", "solve_step", "get_method", "available_methods",
           "closedforms", "stresses", "InputError", "SolverError", "RollqpError", "MissingBackendError"]
