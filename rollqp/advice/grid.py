"""What ``rollqp run`` says before a 3D run that will take long, and what it refuses: the conic route's
cost estimated from the scene and from this machine's speed (the 3D counterpart of :mod:`rollqp.advice`).

Newton's 3D steps take a fraction of a second on the built-in grids (docs/performance.md). A conic
method (``qp-clarabel``, ``qp-cvxpy``, ``socp-*``) poses each step as an SOCP whose Hessian is the
influence matrix of the contact area, dense: ``2m`` unknowns for ``m`` elements in contact.

**The cost model** (:func:`conic_step_seconds`): one conic step (the normal QP and the tangential SOCP,
Clarabel, with the active-set refinement) in units of a yardstick timed in the same process — a dense
Cholesky factorization of order 600 (:func:`yardstick`, a few milliseconds), so that the estimate follows
the machine and its load —

.. math:: t \\approx y\\,(\\alpha x^2 + \\beta x^3), \\qquad x = 2m/600,

with ``α`` (forming the dense Hessian, Clarabel's assembly of its KKT system, the refinement: the
``x²`` terms dominate up to a few thousand elements) fitted to conic steps on circles of 132 … 812 contact
elements, and ``β`` the interior point's factorizations (about 20 of order ``2m``; :data:`QUADRATIC`,
:data:`CUBIC`; benchmarks/three_speed.py ``--only conic-model`` measures the model against real steps).

Dissimilar bodies (``K ≠ 0``, eq. 3D.10) alternate the normal and the tangential step until both meet the
tolerance (:func:`rollqp.march.grid.coupled_step`): each step costs :func:`coupled_sweeps` sweeps of
:data:`SWEEP_COST` conic steps each (:func:`step_factor`). A rolling start by a method that cannot solve the
steady problem marches to it: similar bodies from FASTSIM's steady state in about :data:`START_STEPS`
steps, dissimilar ones from zero in :data:`MARCH_LENGTHS` contact lengths of ``dx`` steps. :func:`notes`
prints the estimate when it exceeds :data:`NOTE_SECONDS`;
:func:`refusal` refuses before any work a run whose estimate exceeds :data:`REFUSE_SECONDS`, or whose
dense Hessian would not fit :data:`~rollqp.influence.blocktoeplitz.DENSE_MAX`, naming what runs instead.
"""
from __future__ import annotations

import time

import numpy as np

from . import duration
from ..errors import InputError
from ..influence.blocktoeplitz import DENSE_MAX
from ..methods import capabilities, method_class

__all__ = ["notes", "refusal", "conic_step_seconds", "conic_run", "yardstick", "NOTE_SECONDS", "REFUSE_SECONDS",
           "QUADRATIC", "CUBIC", "MARCH_LENGTHS", "START_STEPS", "coupled_sweeps", "step_factor", "SWEEP_CONTRACTION",
           "SWEEP_COST"]

#: Order of the yardstick's dense Cholesky factorization (:func:`yardstick`).
YARDSTICK_ORDER = 600
#: The cost model's coefficients in yardsticks (module docstring): fitted to Clarabel steps on circles of
#: 132, 300, 524 and 812 contact elements (t/y = 125, 536, 1607, 3382 at x = 0.44, 1.0, 1.75, 2.71; the
#: quadratic term alone fits them within 25 %); the cubic one is about 20 factorizations of order 2m.
QUADRATIC, CUBIC = 500.0, 20.0
#: Estimated run time above which the note is printed (seconds).
NOTE_SECONDS = 60.0
#: Estimated run time above which ``rollqp run`` refuses to start (one hour), unless told ``--allow-long``.
REFUSE_SECONDS = 3600.0
#: Conic steps of the march to a steady state, per contact length ``2a/dx`` rolled: measured 4.6 with a
#: slip area (88 steps on the 24 × 24 circle, ξ = 1e-3, docs/performance.md); with everything sticking
#: two steps reach it (the estimate is then pessimistic).
MARCH_LENGTHS = 4.6
#: Conic steps of the march of similar bodies from FASTSIM's steady state (rollqp.march.grid.approximate_steady),
#: the start a march takes by default: measured 2 (ξ = 1e-5, all stick), 5 (ξ = 1e-3 and 4e-3) on the 24 × 24
#: circle and 6 on the 40 × 40 circle at ξ = 1e-3 (docs/performance.md); 8 leaves room.
START_STEPS = 8
#: The N–T alternation of dissimilar bodies (:func:`coupled_sweeps`): its contraction per sweep is about
#: ``SWEEP_CONTRACTION·|K|``, and it stops about :data:`SWEEP_MARGIN` below the tolerance. Measured with
#: socp-clarabel on cattaneo-3d at 12 × 12 (76 elements in contact, 21 steps, tolerance 1e-10; body B's E and
#: ν varied): 3.8, 4.6, 5.2, 6.0 sweeps a step at |K| = 0.017, 0.070, 0.125, 0.221, which
#: ``ln(tolerance·SWEEP_MARGIN)/ln(SWEEP_CONTRACTION·|K|)`` gives within 4 %.
SWEEP_CONTRACTION, SWEEP_MARGIN = 0.055, 1.0 / 30.0
#: Conic steps a sweep costs, in units of a similar-body step (whose pressure is solved once; a sweep solves
#: the normal and the tangential step): the same runs took 1.7–1.76 times the similar-body run's CPU time per
#: sweep.
SWEEP_COST = 1.7
#: Sweeps before the alternation gives up (:data:`rollqp.march.grid.MAX_SWEEPS`).
MAX_SWEEPS = 100

_YARDSTICK = []


def yardstick() -> float:
    """Seconds of one dense Cholesky factorization of order :data:`YARDSTICK_ORDER` on this machine now
    (LAPACK's ``dpotrf`` in place, the best of eight after one to warm up; measured once per process, 25–200 ms)."""
    if not _YARDSTICK:
        from scipy.linalg import lapack
        rng = np.random.default_rng(0)
        a = rng.standard_normal((YARDSTICK_ORDER, YARDSTICK_ORDER))
        a = np.asfortranarray(a @ a.T + YARDSTICK_ORDER * np.eye(YARDSTICK_ORDER))
        work = np.empty_like(a, order="F")
        best = np.inf
        for k in range(9):  # in place (no allocation: the command line maps every array above 1 MiB afresh)
            np.copyto(work, a)
            t0 = time.perf_counter()
            lapack.dpotrf(work, lower=1, overwrite_a=1)
            if k:  # the first call pays for cold caches; then the best of eight (a loaded machine varies 3x)
                best = min(best, time.perf_counter() - t0)
        _YARDSTICK.append(best)
    return _YARDSTICK[0]


def conic_step_seconds(contact_elements: int, y: float | None = None) -> float:
    """The estimated wall time of one conic step on ``contact_elements`` (module docstring)."""
    x = 2.0 * max(int(contact_elements), 1) / YARDSTICK_ORDER
    return (yardstick() if y is None else y) * (QUADRATIC * x * x + CUBIC * x ** 3)


def coupled_sweeps(K: float, tolerance: float) -> float:
    """The N–T sweeps a step of bodies with Kalker's difference constant ``K`` takes to ``tolerance``
    (1 for similar bodies; :data:`SWEEP_CONTRACTION`).

    >>> coupled_sweeps(0.0, 1e-10), round(coupled_sweeps(-0.0698, 1e-10), 2)
    (1.0, 4.75)
    """
    if K == 0.0:
        return 1.0
    rate = min(SWEEP_CONTRACTION * abs(float(K)), 0.9)
    return float(min(max(np.log(float(tolerance) * SWEEP_MARGIN) / np.log(rate), 1.0), MAX_SWEEPS))


def step_factor(K: float, tolerance: float) -> float:
    """Conic steps of the cost model one step of bodies with ``K`` costs (1 for similar bodies)."""
    return 1.0 if K == 0.0 else SWEEP_COST * coupled_sweeps(K, tolerance)


def conic_run(scene) -> tuple:
    """``(steps, seconds a step, seconds in all)`` of ``scene`` run by a conic method (estimate; a step of
    dissimilar bodies counts its N–T sweeps, :func:`step_factor`)."""
    caps = capabilities(scene.solver.method, 3)
    n = scene.contact_elements()
    per = conic_step_seconds(n) * step_factor(scene.materials.K, scene.solver.tolerance)
    steps = scene.n_steps
    if scene.load.start == "rolling" and "steady" not in caps.solves:
        if scene.materials.K == 0.0:   # similar bodies: from FASTSIM's steady state (rollqp.march.grid.steady)
            steps += START_STEPS
        else:
            steps += int(MARCH_LENGTHS * 2 * scene.ellipse.a / scene.grid.dx) + 1
    else:
        steps += scene.load.start_steps if scene.load.start == "braked" else 1
    return steps, per, per * steps


def _conic(scene) -> bool:
    """Whether the scene's method needs the dense matrices (the conic backends; Newton works with FFT products)."""
    return not capabilities(scene.solver.method, 3).matrix_free


#: Newton's steady step on the FFT path, in yardsticks per ``n log n`` (``n`` the grid's elements): the
#: 300 × 300 partial-slip step (ξ = 1e-3, 12 iterations) took 33.5 s of CPU with a yardstick of 2.7 ms.
NEWTON_STEADY = 0.0119
#: Grids from which ``rollqp run`` says what Newton's steady step will take (elements).
NEWTON_NOTE_ELEMENTS = 40_000


def newton_steady_seconds(elements: int, y: float | None = None) -> float:
    """The estimated CPU time of Newton's steady step on a grid of ``elements`` (FFT path; module constants)."""
    n = max(int(elements), 2)
    return (yardstick() if y is None else y) * NEWTON_STEADY * n * np.log(n)


def _newton_note(scene) -> list[str]:
    n = scene.grid.nx * scene.grid.ny
    if n < NEWTON_NOTE_ELEMENTS or "steady" not in capabilities(scene.solver.method, 3).solves:
        return []
    t = newton_steady_seconds(n)
    return [f"{scene.grid.nx} × {scene.grid.ny} elements: a steady step of about {duration(t)} of CPU (estimate "
            f"from this machine's speed, the 300 × 300 step measured); progress lines follow"]


def notes(scene) -> list[str]:
    """One line before a 3D run with a conic method whose estimated time exceeds :data:`NOTE_SECONDS`, or
    before a large grid's steady step by Newton (its estimated CPU time)."""
    if not _conic(scene):
        return _newton_note(scene) if scene.load.start == "rolling" else []
    n = scene.contact_elements()
    steps, per, total = conic_run(scene)
    if total <= NOTE_SECONDS:
        return []
    march = " (the march to the steady state included)" if scene.load.start == "rolling" else ""
    return [f"{scene.solver.method} on about {n} contact elements: about {duration(per)} a step, {steps} steps"
            f"{march}: about {duration(total)} in all (estimate from this "
            "machine's speed now); --method newton solves the same steps in seconds"]


def refusal(scene, allow_long: bool = False) -> None:
    """Refuse, before any work, a conic run that cannot finish in reasonable time or memory (one
    :class:`~rollqp.errors.InputError` naming ``--method newton`` and a coarser grid); ``allow_long``
    lets a run above :data:`REFUSE_SECONDS` start (never one whose dense matrix does not fit)."""
    if getattr(method_class(scene.solver.method, 3), "steady_only", False) and (
            scene.n_steps > 0 or scene.load.start != "rolling"):
        raise InputError("solver.method", f"{scene.solver.method} solves the steady state of a rolling start only "
                                          f"(load.start = 'rolling', discretization.distance = 0; this scene has "
                                          f"{scene.n_steps} rolling steps and start {scene.load.start!r}); use "
                                          "--method newton for the rolling steps")
    if not _conic(scene):
        return
    n = scene.contact_elements()
    g = scene.grid
    entries = (2 * n) ** 2
    coarser = f"a coarser grid (discretization.elements, now {g.nx} × {g.ny})"
    if entries > DENSE_MAX:
        raise InputError("solver.method", f"{scene.solver.method} needs the influence matrix of the contact area "
                                          f"as a dense matrix: {entries:,} entries ({entries * 8 / 1e9:.1f} GB) "
                                          f"for about {n} contact elements, above the limit of {DENSE_MAX:,}; use "
                                          f"--method newton (FFT products, no matrix) or {coarser}")
    steps, per, total = conic_run(scene)
    if total > REFUSE_SECONDS and not allow_long:
        raise InputError("solver.method", f"{scene.solver.method} would take about {duration(total)} ({steps} "
                                          f"steps of about {duration(per)} on about {n} contact elements, "
                                          f"estimated from this machine's speed now); use --method newton "
                                          f"(seconds) or {coarser}, or --allow-long to run it anyway")
