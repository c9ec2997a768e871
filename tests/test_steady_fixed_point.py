"""The rolling start is the fixed point of the march that follows it (docs/formulation.md §9).

A transient step's slip is ``ξ e + (w^k − M w^{k−1})/Δq`` with the history operator ``M`` of the
scene's formulation; the state that a step leaves unchanged has ``s = ξ e + (I − M) w/Δq``. The
direct steady solve poses exactly that (``Strip.steady_operator``): ``d·D_up`` for the
convective-local form, ``(I − R)/Δq`` for the material one. Held here:

* the operator: ``(I − M)/Δq`` of the history operator itself, dense and sparse (matrix-free) alike;
  equal to ``d·D_up`` off the leading node where ``R`` moves nodal values by whole node spacings,
  different where it interpolates (QCE with Δq = Le/4, the paper's §6.2.1);
* the march from the direct steady state does not move: over 1 a_H every state stays within
  the march's own tolerance of the start (``rollqp.march.strip.STEADY_TOL``, μp0 a step) on
  ``goodman-bentall`` with a rolling start (material, Δq = Le/4, QCE, 2β = 1, full coupling), on
  ``harmonic`` and on the material form with steps that are not a node spacing;
* the QP methods' marched start lands on the same state as the direct solve.
"""
from __future__ import annotations

import numpy as np
import pytest

import rollqp
from rollqp.errors import InputError
from rollqp.histories import Constant
from rollqp.march.strip import STEADY_TOL
from rollqp.matrixfree import sparse_history, sparse_steady
from rollqp.strip import Strip

#: Two exact solvers of the same equations stopped at a nondimensional residual of 1e-10 (the
#: scenes' solver.tolerance) differ by the residual times the condition of the active-set system
#: (a few), and an N–T alternation stopped at the tolerance by its contraction rate too: measured
#: ≤ 1.3e-13 μp0 for the QP starts (stopped at 1e-12), 4.9e-10 μp0 for nt-newton's alternation
#: (goodman-bentall; harmonic 6.5e-11); bound 1e-8 μp0, the agreement the rolling start promises.
AGREE = 1e-8
#: Every built-in 2D scene with full coupling (dissimilar bodies): each is checked with a rolling start
#: (the 3D scenes have no rolling start and no coupling level).
COUPLED = sorted(n for n in rollqp.builtin_scenes() if getattr(rollqp.load_scene(n), "coupling_level", None) == "full")


def rolling(name, **changes):
    return rollqp.load_scene(name).replace(**{"load.start": "rolling", **changes})


def drift(scene, method="newton", distance=1.0):
    """``(max |t_k − t_0|/(μp0), max |p_k − p_0|/p0, result)`` over a march of ``distance`` a_H from the start."""
    r = rollqp.run(scene.replace(**{"discretization.distance": distance}), method=method)
    pt, pn = np.asarray(r["pt"]), np.asarray(r["pn"])
    mu_p0 = scene.contact.friction * scene.p0
    return (float(np.abs(pt - pt[0]).max()) / mu_p0, float(np.abs(pn - pn[0]).max()) / scene.p0, r)


# =========================================================================== the operator
@pytest.mark.parametrize("element, ne", [("constant", 30), ("linear", 20), ("quadratic", 12)])
@pytest.mark.parametrize("step", [0.25, 0.5, 1.0, 1.7])
@pytest.mark.parametrize("direction", [-1, 1])
def test_material_steady_operator_is_the_history_operators_fixed_point(element, ne, step, direction):
    """``T = (I − R)/Δq`` with ``R`` the material history operator, dense and sparse to round-off."""
    strip = Strip(1.3, ne, element)
    dq = step * strip.element_length
    R = strip.history_operator("material", dq, direction)
    T = strip.steady_operator(direction, "material", dq)
    np.testing.assert_allclose(T, (np.eye(strip.n) - R) / dq, rtol=0, atol=1e-12 / dq)
    np.testing.assert_allclose(sparse_steady(strip, direction, "material", dq).toarray(), T, rtol=0,
                               atol=1e-12 / dq)
    np.testing.assert_allclose(sparse_history(strip, "material", dq, direction).toarray(), R, rtol=0, atol=1e-12)


@pytest.mark.parametrize("element, ne, step, same", [
    ("constant", 30, 1.0, True),      # R shifts by one node: (I − R)/Δq = d·D_up
    ("constant", 30, 0.4, True),      # linear interpolation within one spacing: still d·D_up
    ("linear", 20, 0.5, True),
    ("quadratic", 12, 0.5, True),     # Δq = h = Le/2: R moves nodal values by one node
    ("quadratic", 12, 0.25, False),   # quadratic interpolation inside the element: another difference
])
def test_material_operator_against_the_upwind_difference(element, ne, step, same):
    """Off the leading node (out of contact, docs/formulation.md §1) the material ``T`` is ``d·D_up``
    exactly where ``R`` interpolates linearly over one step; with QCE and Δq = Le/4 it is not (the
    case where a steady solve with ``d·D_up`` would miss the march's fixed point)."""
    strip = Strip(1.3, ne, element)
    dq = step * strip.element_length
    for d in (-1, 1):
        T = strip.steady_operator(d, "material", dq)
        up = strip.steady_operator(d)
        rows = np.arange(strip.n) != strip.leading_index(d)
        gap = float(np.abs(T[rows] - up[rows]).max()) * strip.spacing
        assert (gap <= 1e-12) == same, f"d = {d}: max |T − d·D_up|·h = {gap:.2e}"
    np.testing.assert_array_equal(strip.steady_operator(-1, "convective-local", dq), strip.steady_operator(-1))


def test_the_built_in_coupled_scenes_are_the_two_of_the_paper():
    """The parametrization below runs over every built-in coupled scene; today §6.2.1 and §6.2.2."""
    assert {"goodman-bentall", "harmonic"} <= set(COUPLED)


def test_steady_operator_refuses_what_it_cannot_pose():
    strip = Strip(1.3, 10, "quadratic")
    with pytest.raises(InputError, match="formulation"):
        strip.steady_operator(-1, "static", 0.1)
    with pytest.raises(InputError, match="dq"):
        strip.steady_operator(-1, "material")
    with pytest.raises(InputError, match="dq"):
        sparse_steady(strip, -1, "material", 0.0)


# =========================================================================== the march stays
@pytest.mark.parametrize("name, changes", [
    ("goodman-bentall", {}),                                                        # material, Le/4, QCE, full
    ("harmonic", {"load.normal_history": Constant(1.0)}),                    # convective-local, coupled
    ("cattaneo-carter", {"discretization.step": 0.3}),                              # material, QCE, similar
    ("cattaneo-carter", {"discretization.element": "linear", "discretization.step": 1.6}),  # Δq > h
])
def test_the_march_from_the_direct_steady_state_stays_there(name, changes):
    """1 a_H at the start's constant loads from ``newton``'s direct steady state: every state within the
    march's tolerance of the start (the rounding of 1e-10 solves, measured ≤ 1e-12 μp0; with
    ``d·D_up`` in place of the material ``T`` goodman-bentall drifts by 0.20 μp0 over 1 a_H)."""
    scene = rolling(name, **changes)
    dt, dp, r = drift(scene)
    assert r.meta["rolling_start"] == "direct steady solve"
    assert dt < STEADY_TOL and dp < STEADY_TOL, f"the march moves the start by {dt:.1e} μp0, {dp:.1e} p0"


@pytest.mark.parametrize("name", COUPLED)
@pytest.mark.parametrize("method", ["qp-osqp", "qp-clarabel", "nt-newton"])
def test_every_route_to_the_rolling_start_lands_on_the_same_state(name, method):
    """The built-in coupled scenes with a rolling start: the QP starts (the active-set Newton method on
    the march map of N–T alternations of QPs, both backends) and nt-newton's direct solve against
    newton's direct solve, to :data:`AGREE`."""
    scene = rolling(name, **{"discretization.distance": 0.0})
    ref = rollqp.run(scene, method="newton")
    r = rollqp.run(scene, method=method)
    mu_p0 = scene.contact.friction * scene.p0
    dt = float(np.abs(np.asarray(r["pt"][0]) - ref["pt"][0]).max()) / mu_p0
    dp = float(np.abs(np.asarray(r["pn"][0]) - ref["pn"][0]).max()) / scene.p0
    dxi = abs(float(r["creepage"][0]) / float(ref["creepage"][0]) - 1)
    assert max(dt, dp, dxi) <= AGREE, f"Δt {dt:.1e} μp0, Δp {dp:.1e} p0, Δξ {dxi:.1e}"
