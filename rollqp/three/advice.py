"""What ``rollqp run`` says before a 3D run that will take long: the conic route's cost, estimated from
the scene alone (the 3D counterpart of :mod:`rollqp.advice`).

Newton's 3D steps take a fraction of a second on the built-in grids (docs/performance.md). A conic
method (``qp-clarabel``, ``qp-cvxpy``, ``socp-*``) poses each step as an SOCP with a dense Hessian
of the contact elements, whose factorization grows like their cube: :func:`conic_step_seconds`
estimates one step from a measured reference, and a rolling start multiplies it by the steps of the
march to the steady state (:func:`rollqp.three.march.steady`). A note is printed when the estimate is
above :data:`NOTE_SECONDS`, naming what runs faster.
"""
from __future__ import annotations

from ..advice import duration

__all__ = ["notes", "conic_step_seconds", "NOTE_SECONDS", "REFERENCE_CONTACT", "REFERENCE_SECONDS"]

#: One Clarabel step (QP + SOCP and the active-set refinement) on 812 contact elements (the 40 × 40
#: kalker-circular grid) took 5.3 s here (benchmarks/three_speed.py, load average 7 on 2 cores).
REFERENCE_CONTACT, REFERENCE_SECONDS = 812, 5.3
#: Estimated run time above which the note is printed (seconds).
NOTE_SECONDS = 60.0
#: Conic steps of the march to a steady state, per contact length 2a/dx rolled (measured: the
#: accelerated march of docs/validation3d.md §9 takes about one contact length).
MARCH_LENGTHS = 1.0


def conic_step_seconds(contact_elements: int) -> float:
    """The estimated wall time of one conic step on ``contact_elements`` (cube law from the reference)."""
    return REFERENCE_SECONDS * (max(contact_elements, 1) / REFERENCE_CONTACT) ** 3


def notes(scene) -> list[str]:
    """One line before a 3D run with a conic method whose estimated time exceeds :data:`NOTE_SECONDS`."""
    from ..methods import capabilities
    caps = capabilities(scene.solver.method, 3)
    if caps.matrix_free:
        return []
    n = scene.contact_elements()
    per = conic_step_seconds(n)
    steps = scene.n_steps
    if scene.load.start == "rolling" and "steady" not in caps.solves:
        steps += int(MARCH_LENGTHS * 2 * scene.ellipse.a / scene.grid.dx) + 1
    else:
        steps += scene.load.start_steps if scene.load.start == "braked" else 1
    total = per * steps
    if total <= NOTE_SECONDS:
        return []
    return [f"{scene.solver.method} on {n} contact elements: about {duration(per)} a step (an SOCP with a dense "
            f"Hessian, growing like the cube of the contact), {steps} steps: about {duration(total)} in all "
            "(estimate); solver.method = 'newton' solves the same steps in a fraction of that, and the run's "
            "cross-check solves a few of them by the conic route"]
