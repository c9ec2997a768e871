r"""Step files: one step of a scene, exported for any solver, and a checker for any solution.

:func:`export_step` marches a scene to step ``K`` and returns a :class:`StepFile`: the step's
data (influence matrices, weights, gap, friction, loads, history vector, scales), the state
before it, rollqp's solution, and the convex QP form of each half (docs/formulation.md §6) in the
arrays a generic QP solver takes. :meth:`StepFile.save` writes it as a ``.npz`` without
pickles, with solver-native files beside it (Clarabel's JSON, a cvxpy script); the keys are
documented in ``docs/stepfiles.md``. :func:`check_step` evaluates a candidate solution with
rollqp's own residuals (docs/formulation.md §5; paper eq. 51–60, 67), compares it with rollqp's
Newton and QP solutions, and says which condition fails at which nodes.

**Step numbering** follows the result file's ``q`` index (docs/results.md): step ``K >= 1`` is the
rolling step whose solution is state ``K`` (``q = K Δq``), solved from state ``K − 1``; step
``0`` is the starting state's last solve (the last static-shift increment of a braked start,
or the steady-rolling solve / last marching step of a rolling start).

**The step problem** is always stored in the coupled form of docs/formulation.md §4 (paper
eq. 63–64)::

    g = h − δ e + A_nn p + A_nt t,          s = ξ e + (c + A_tn p + A_tt t)/Δq,
    p >= 0, g >= 0, p·g = 0,                t = Proj_[−μp⁺, μp⁺](t − s),
    fᵀp = P (or δ given),                   fᵀt = Q (or ξ given).

``kind = "uncoupled"`` when ``A_nt = 0`` (similar materials, or the Goodman level): the normal
half does not see ``t``, and rollqp solves the normal half, then the tangential half at its
pressure. ``kind = "coupled"``: ``A_nt ≠ 0``, a quasi-variational inequality, not a QP.

The package: :mod:`.export` (a step of a scene), :mod:`.file` (the file), :mod:`.check` (checking and
solving a stored step), :mod:`.script` (the cvxpy script), :mod:`.three` (the step files of 3D scenes).
"""
from __future__ import annotations

from .check import (CONDITIONS, DEFAULT_TOL, SOLUTION_KEYS, CheckReport, Failure, check_step, load_solution,
                    solve_stored, validate_solution)
from ..npzfile import read_npz
from .export import export_step, from_record
from .file import FORMAT, MAX_NODES, STEP_TYPES, StepFile, clarabel_json
from .script import CVXPY_SCRIPT, cvxpy_script
from .three import FORMAT_3D, StepFile3D, check_step_3d, export_step_3d

__all__ = ["FORMAT", "DEFAULT_TOL", "CONDITIONS", "SOLUTION_KEYS", "MAX_NODES", "STEP_TYPES", "export_step", "from_record",
           "StepFile", "clarabel_json", "solve_stored", "Failure", "CheckReport", "load_solution", "validate_solution",
           "check_step", "cvxpy_script", "CVXPY_SCRIPT", "FORMAT_3D", "StepFile3D", "export_step_3d", "check_step_3d",
           "load_step"]


def load_step(path, arg: str = "STEP.npz"):
    """A step file of either dimension (:class:`StepFile` or :class:`StepFile3D`), chosen by its ``format`` key."""
    import numpy as np

    z = read_npz(path, arg)
    fmt = np.asarray(z.get("format", ""))
    if fmt.dtype.kind in "US" and fmt.shape == () and str(fmt) == FORMAT_3D:
        return StepFile3D.load(path, arg, z=z)
    return StepFile.load(path, arg)
