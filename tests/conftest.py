"""Shared fixtures: the QP backend table and small Hertz-scaled step problems.

Backends
--------
One table (:data:`BACKENDS`), in the manner of osqp-python's ``conftest.py``: each backend
carries its own tolerances and the reason for them, and tests read them from the table
instead of spelling ternaries. Tests parametrized over backends use the fixed ids
``clarabel``, ``osqp``, ``cvxpy`` (``pytest -k osqp``); tests over pairs use
``clarabel-osqp``, ``clarabel-cvxpy``, ``osqp-cvxpy``.

Problems
--------
The paper's steel rollers (§6.1.1: R_A = 150 mm, R_B = 300 mm, E = 210 GPa, ν = 0.3,
P = 1000 N/mm, μ = 0.1) on a strip of ±1.25 a_H, built with :class:`rollqp.Strip` and
:func:`rollqp.halfspace_influence`, with Hertz scales. Piecewise-constant elements on this
uniform grid give an exactly symmetric ``F·A`` (docs/formulation.md §7), so a QP solves the
collocation problem itself; quadratic elements (the paper's QCE) do not.
"""
from __future__ import annotations

import functools
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

import rollqp
from rollqp import closedforms as cf

# The reference cases the tests share with the benchmarks (benchmarks/refcases.py,
# benchmarks/friction_cases.py): fixtures, not part of the installed package.
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))


@pytest.fixture(scope="session", autouse=True)
def _one_blas_thread():
    """Pin BLAS to one thread, as the CLI and the benchmarks do: numpy's and scipy's wheels
    each bundle OpenBLAS, and the two pools fighting over 2 cores made one slow QP test
    3.4× slower (125 s against 37 s, measured)."""
    from threadpoolctl import threadpool_limits
    with threadpool_limits(1):
        yield

# ------------------------------------------------------------------------------- backends
#: Tolerance every test asks the backends for (QPMethod's default): rollqp then rejects any
#: step whose own residual is above ``residual_limit = 100 * TOLERANCE`` (QPMethod docstring).
TOLERANCE = 1e-10


@dataclass(frozen=True)
class Backend:
    """A QP backend and what it is held to at ``tolerance = 1e-10``.

    ``accuracy`` bounds the distance of its solution from the exact discrete one, in
    p0 (pressures), μ·p0 (tractions), u0 (approach) and p0/E* (creepage); two backends
    must then agree to the sum of their accuracies (triangle inequality).
    ``residual`` bounds rollqp's own nondimensional residual of its solutions.
    """

    name: str
    method: str
    accuracy: float
    residual: float
    why: str


BACKENDS = {
    "clarabel": Backend(
        "clarabel", "qp-clarabel", accuracy=5e-9, residual=1e-8,
        why="interior point stopped on the duality gap (1e-14): each slack·multiplier product "
            "is below it, leaving min(p, g) up to ~1e-11 at contact edges (measured 5e-12 on "
            "these problems, 2e-10 on random ones); 5e-9 keeps two pairs within 1e-8. The "
            "residual bound is QPMethod's residual_limit, 100·tolerance."),
    "osqp": Backend(
        "osqp", "qp-osqp", accuracy=5e-9, residual=1e-8,
        why="ADMM + polishing: a successful polish is an active-set linear solve, exact to "
            "round-off (measured 1e-14); a refused polish leaves an ADMM iterate at eps 1e-11 "
            "after the retries. Residual bound: QPMethod's residual_limit."),
    "cvxpy": Backend(
        "cvxpy", "qp-cvxpy", accuracy=5e-9, residual=1e-8,
        why="cvxpy's OSQP at eps 1e-7 with polishing, retried at 1e-9 and 1e-11 when the polish "
            "is refused (measured ≤ 3e-11 from the others). Residual bound: residual_limit."),
}

BACKEND_PARAMS = [pytest.param(b, id=k) for k, b in BACKENDS.items()]
PAIR_PARAMS = [pytest.param((BACKENDS[a], BACKENDS[b]), id=f"{a}-{b}")
               for a, b in (("clarabel", "osqp"), ("clarabel", "cvxpy"), ("osqp", "cvxpy"))]


@pytest.fixture(params=BACKEND_PARAMS)
def backend(request) -> Backend:
    """Each QP backend in turn, with its tolerances."""
    return request.param


@pytest.fixture(params=PAIR_PARAMS)
def pair(request) -> tuple[Backend, Backend]:
    """Each pair of distinct QP backends."""
    return request.param


def pair_tolerance(pair) -> float:
    """Agreement bound of two backends: the sum of their accuracies."""
    return pair[0].accuracy + pair[1].accuracy


# ------------------------------------------------------------------------------- problems
# The paper's §6.1.1 rollers (N, mm).
R_A, R_B, E, NU = 150.0, 300.0, 210000.0, 0.3
ESTAR = 1.0 / (2.0 * (1.0 - NU ** 2) / E)
R = 1.0 / (1.0 / R_A + 1.0 / R_B)
P = 1000.0
MU = 0.1
ZONE = 1.25          # L / a_H
RATIO = 0.75         # Q / (μP)


@dataclass(frozen=True)
class HertzProblem:
    """A discretized two-cylinder contact and builders of its step problems.

    ``p_hertz`` is the closed-form Hertz pressure at the nodes and ``t_cattaneo`` Cattaneo's
    traction for Q = 0.75 μP: inputs for tangential steps that need no solver to set up.
    """

    strip: rollqp.Strip
    influence: rollqp.Influence
    scales: rollqp.Scales

    @property
    def f(self):
        return self.strip.weights

    @property
    def x(self):
        return self.strip.x

    @property
    def n(self):
        return self.strip.n

    @property
    def a(self):
        return self.scales.length

    @property
    def p0(self):
        return self.scales.stress

    @property
    def p_hertz(self):
        return cf.hertz_pressure(self.x, self.a, self.p0)

    @property
    def t_cattaneo(self):
        return cf.cattaneo_traction(self.x, self.a, self.p0, MU, RATIO)

    @property
    def dq(self):
        """The paper's rolling step, Δq = Le/2."""
        return 0.5 * self.strip.element_length

    def normal(self, **kw) -> rollqp.NormalStep:
        """The normal step; ``P`` unless ``delta`` (or another ``P``) is given."""
        if "delta" not in kw:
            kw.setdefault("P", P)
        return rollqp.NormalStep(A=self.influence.Ann, f=self.f, h=self.influence.h,
                                 scales=self.scales, **kw)

    def braked(self, **kw) -> rollqp.TangentialStep:
        """The static shift from unloaded bodies to Q = 0.75 μP on the Hertz pressure (Cattaneo)."""
        if "xi" not in kw:
            kw.setdefault("Q", RATIO * MU * P)
        return rollqp.TangentialStep(A=self.influence.Att, f=self.f, p=self.p_hertz, mu=MU,
                                     c=np.zeros(self.n), dq=self.a, scales=self.scales, **kw)

    def rolling(self, direction=-1, **kw) -> rollqp.TangentialStep:
        """One rolling step (material formulation, Δq = Le/2) from Cattaneo's state."""
        if "xi" not in kw:
            kw.setdefault("Q", RATIO * MU * P)
        w_prev = self.influence.Att @ self.t_cattaneo
        c = -(self.strip.history_operator("material", self.dq, direction) @ w_prev)
        return rollqp.TangentialStep(A=self.influence.Att, f=self.f, p=self.p_hertz, mu=MU, c=c,
                                     dq=self.dq, scales=self.scales, **kw)


@functools.lru_cache(maxsize=None)
def hertz_problem(element: str, elements: int) -> HertzProblem:
    """The §6.1.1 rollers on ``elements`` elements of kind ``element`` over ±1.25 a_H."""
    scales = rollqp.Scales.hertz(P, R, ESTAR)
    strip = rollqp.Strip(ZONE * scales.length, elements, element)
    infl = rollqp.halfspace_influence(strip, Estar=ESTAR, beta=0.0, R_A=R_A, R_B=R_B)
    return HertzProblem(strip=strip, influence=infl, scales=scales)


@pytest.fixture(scope="session")
def constant_problem() -> HertzProblem:
    """40 piecewise-constant elements: F·A exactly symmetric."""
    return hertz_problem("constant", 40)


@pytest.fixture(scope="session")
def quadratic_problem() -> HertzProblem:
    """40 quadratic elements (81 nodes), the paper's mesh: F·A asymmetric by ~0.1 %."""
    return hertz_problem("quadratic", 40)


# ------------------------------------------------------------------------------- scenes
@pytest.fixture(scope="session")
def builtin_scene():
    """A loader of built-in scenes with dotted-key changes (``scene.replace``)."""
    def load(name, **changes):
        scene = rollqp.load_scene(name)
        return scene.replace(**changes) if changes else scene
    return load


# ------------------------------------------------------------------------------- method wrappers
class Delegate:
    """A step method that delegates to ``inner`` (the :class:`rollqp.methods.base.Method` protocol);
    subclasses override :meth:`solve` to spy on or to break the inner method. Passed to
    :func:`rollqp.run` as the method object, it is composed and set up like any method."""

    def __init__(self, inner):
        self.inner = inner
        self.name, self.capabilities, self.tolerance = inner.name, inner.capabilities, inner.tolerance

    def setup(self, operators):
        self.inner.setup(operators)

    def solve(self, problem, warm=None):
        return self.inner.solve(problem, warm=warm)

    def carrier(self):
        """The inner method's (a composition: called only where the capabilities declare ``carries_state``)."""
        return self.inner.carrier()


def scene_method_of(scene, name=None):
    """The method ``name`` (default the scene's) built from ``scene``'s solver settings, not composed."""
    from rollqp.methods import method_class
    return method_class(name or scene.solver.method).from_settings(scene.solver)
