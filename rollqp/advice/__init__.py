"""The fast path chosen for the user, and what a run will cost before it starts (docs/matrix-free.md).

A scene names a method (``solver.method``) and, with ``solver.operator = "auto"`` (the default),
leaves the operators to rollqp. When the method needs the n × n influence matrices and the strip
is large enough that the dense path is slow or large — its estimated memory above
:data:`DENSE_MEMORY_LIMIT` or its estimated time above :data:`DENSE_SECONDS_LIMIT` — while a
registered matrix-free method does the same work (the same discrete steps to the same tolerance:
the influence model has FFT operators and the method solves every kind of step the scene poses),
:func:`fast_path` runs the scene with that method instead and says so (:attr:`Plan.note`, kept in
the result's ``meta["method_note"]`` and printed in the summary). ``solver.operator = "dense"``
keeps the named method whatever the size.

Estimates (:func:`dense_memory`, :func:`dense_seconds`) come from measurements, not from a model of
the code: the dense path's peak memory is about 11 doubles per n² (551 MiB at 2,561 nodes, 8.5 GB at
10,001, docs/matrix-free.md; estimate 553 MiB against 602 MiB measured at 2,561 nodes), and a state
of a Newton run costs about one dense Cholesky factorization of the strip's size
(:data:`NEWTON_STEP_CHOLESKY`), timed on this machine when asked (:func:`cholesky_seconds`). :func:`alternation_note` says, before a run, when a method
solves a coupled scene by the N–T alternation while another solves its coupled step directly.

Examples
--------
>>> import rollqp
>>> big = rollqp.load_scene("cattaneo-carter").replace(**{"discretization.elements": 2500})
>>> plan = fast_path(big)
>>> plan.scene.solver.method, plan.note is not None
('mf-newton', True)
>>> fast_path(rollqp.load_scene("cattaneo-carter")).note is None   # 81 nodes: the dense path is fast
True
"""
from __future__ import annotations

import functools
import time
from dataclasses import dataclass

import numpy as np
from ..influence import get_model
from ..methods import METHOD_NAMES
from ..methods import capabilities

__all__ = ["Plan", "fast_path", "duration", "dense_memory", "dense_seconds", "cholesky_seconds", "alternation_note",
           "DENSE_MEMORY_LIMIT", "DENSE_SECONDS_LIMIT"]

#: Peak bytes of the dense path per n² (doubles: 11; measured 551 MiB at 2,561 nodes, 8.5 GB at 10,001).
DENSE_BYTES_PER_N2 = 8 * 11
#: A state of the dense ``newton`` run against one dense Cholesky factorization of the strip's size, both
#: timed on the same machine: measured 1.5 at 1,281 nodes and 0.6 at 2,561 (CPU seconds of
#: ``cattaneo-carter`` runs of 12 and 22 states, the assembly included; docs/performance.md's step
#: target is at most 3). An order-of-magnitude estimate, which is all the choice needs.
NEWTON_STEP_CHOLESKY = 1.0
#: The dense path counts as large above this peak memory …
DENSE_MEMORY_LIMIT = 2.0 * 2 ** 30
#: … or as slow above this estimated time for the whole run (seconds).
DENSE_SECONDS_LIMIT = 60.0


@dataclass(frozen=True)
class Plan:
    """The scene to run and, if rollqp chose something for the user, what and why (one line)."""

    scene: object
    note: str | None = None


def dense_memory(scene) -> float:
    """Estimated peak bytes of the dense path: the influence matrices and their working copies, and the
    result's per-state arrays."""
    n, states = scene.n_nodes, scene.n_steps + 1
    return float(DENSE_BYTES_PER_N2 * n * n + 8.0 * 6 * states * n)


@functools.lru_cache(maxsize=1)
def cholesky_seconds(size: int = 400) -> float:
    """Seconds of one dense Cholesky factorization of ``size`` on this machine (best of three, ~ms)."""
    import scipy.linalg
    rng = np.random.default_rng(0)
    B = rng.standard_normal((size, size))
    M = B @ B.T + size * np.eye(size)
    best = np.inf
    for _ in range(3):
        t0 = time.perf_counter()
        scipy.linalg.cho_factor(M)
        best = min(best, time.perf_counter() - t0)
    return float(best)


def dense_seconds(scene) -> float:
    """Estimated seconds of the dense path's run: every state a Newton step of about
    :data:`NEWTON_STEP_CHOLESKY` Cholesky factorizations of the strip's size, scaled from this machine's."""
    n = scene.n_nodes
    return float((scene.n_steps + scene.load.start_steps + 1) * NEWTON_STEP_CHOLESKY * cholesky_seconds()
                 * (n / 400.0) ** 3)


def _needs(scene) -> set:
    """The kinds of step the scene poses that its method must solve itself (coupled steps excepted: the
    N–T alternation runs them on any method that solves both halves)."""
    need = {"normal", "tangential"}
    if scene.load.start == "rolling":
        need.add("steady")
    return need


def matrix_free_alternative(scene, same_method: bool = True) -> str | None:
    """A registered matrix-free method that does the scene's work, or None: the model has no FFT operators,
    or no matrix-free method solves what the scene poses. ``same_method``: it must also solve the same kinds
    of step as the scene's method (the coupled one possibly by the N–T alternation) — Newton for Newton, not
    Newton for the QP route, whose point is to be another route."""
    if not get_model(scene.contact.model).matrix_free:
        return None
    own = scene.method_capabilities.solves - {"coupled"}
    for name in METHOD_NAMES:
        caps = capabilities(name)
        if not (caps.matrix_free and _needs(scene) <= caps.solves and 2 in caps.dimensions):
            continue
        if not same_method or caps.solves - {"coupled"} == own:
            return name
    return None


def fast_path(scene) -> Plan:
    """The scene as it should run: matrix-free when the named method needs the matrices, the dense path is
    large or slow (:data:`DENSE_MEMORY_LIMIT`, :data:`DENSE_SECONDS_LIMIT`), ``solver.operator`` is
    ``"auto"`` and a matrix-free method does the same work (module docstring); else the scene as it is."""
    if (scene.solver.operator or "auto") != "auto" or scene.method_capabilities.matrix_free:
        return Plan(scene)
    memory = dense_memory(scene)
    if memory <= DENSE_MEMORY_LIMIT and scene.n_nodes < 1000:  # small: no need to time anything
        return Plan(scene)
    seconds = dense_seconds(scene)
    if memory <= DENSE_MEMORY_LIMIT and seconds <= DENSE_SECONDS_LIMIT:
        return Plan(scene)
    other = matrix_free_alternative(scene)
    if other is None:
        return Plan(scene)
    note = (f"{other}, matrix-free, chosen for {scene.solver.method!r}: the dense path would need about "
            f"{memory / 2 ** 30:.2g} GiB and {duration(seconds)} for {scene.n_nodes} nodes and {scene.n_steps} steps "
            f"(estimate); solver.operator = 'dense' keeps {scene.solver.method!r}")
    return Plan(scene.replace(**{"solver.method": other}), note)


def estimate_note(scene) -> str | None:
    """One line before a run that stays on a large or slow dense path (``solver.operator = "dense"``, a QP
    method, or a model without FFT operators): its estimated memory and time and what to change; else None."""
    if scene.method_capabilities.matrix_free or scene.n_nodes < 1000:
        return None
    memory, seconds = dense_memory(scene), dense_seconds(scene)
    if memory <= DENSE_MEMORY_LIMIT and seconds <= DENSE_SECONDS_LIMIT:
        return None
    same, other = matrix_free_alternative(scene), matrix_free_alternative(scene, same_method=False)
    if same is not None:
        how = f"solver.operator = 'auto' runs it with {same}, matrix-free"
    elif other is not None:
        how = (f"solver.method = '{other}' solves the same scene matrix-free; fewer discretization.elements or a "
               "longer discretization.step make this one cheaper")
    else:
        how = "fewer discretization.elements or a longer discretization.step make it cheaper"
    return (f"{scene.solver.method} on {scene.n_nodes} nodes, {scene.n_steps} steps: the dense path needs about "
            f"{memory / 2 ** 30:.2g} GiB and {duration(seconds)} here (estimate for Newton steps: a QP method's take "
            f"longer); {how}")


def alternation_note(scene) -> str | None:
    """Before a coupled run whose method solves it by the N–T alternation (two solves per outer iteration,
    ten or more outer iterations a step) while a registered method solves the coupled step directly: which."""
    caps = scene.method_capabilities
    if scene.coupling_level != "full" or "coupled" in caps.solves:
        return None
    direct = [m for m in METHOD_NAMES if "coupled" in capabilities(m).solves and not capabilities(m).matrix_free]
    if not direct:
        return None
    return (f"{scene.solver.method} solves this coupled scene by the N–T alternation, two solves per outer iteration "
            f"and about ten outer iterations a step; {direct[0]!r} solves the coupled step directly, typically "
            "10–100× faster (docs/examples.md, per-method tables). An estimate of this run follows its first step.")


def duration(seconds: float) -> str:
    """A time for a person: seconds below two minutes, minutes below two hours, else hours."""
    if seconds < 120:
        return f"{seconds:.0f} s"
    if seconds < 7200:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"
