"""``rollqp check-step STEP.npz SOLUTION.npz [--tol T]``: check a candidate solution of an exported step
(either dimension's, by the step file's format key); exit 1 when it fails, one line per failed condition."""
from __future__ import annotations

import sys

from ..stepfile import DEFAULT_TOL, StepFile3D, check_step, check_step_3d, load_solution, load_step
from ..stepfile.three import load_solution_3d


def add_arguments(c) -> None:
    c.add_argument("step_file", metavar="STEP.npz")
    c.add_argument("solution", metavar="SOLUTION.npz", help="keys p and/or t (scene units), optional delta, xi "
                   "(3D: p (n,) and t (2, n) on the grid, optional delta, xi, eta)")
    c.add_argument("--tol", type=float, default=None, help="pass/fail limit on each nondimensional residual "
                   "(default 1e-6: see docs/stepfiles.md)")


def main(args) -> int:
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
