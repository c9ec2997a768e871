"""Friction laws on load paths: stops and reversals (``load.rolled``) with a
law that varies along the surface or with the slip velocity (rollqp.friction; docs/friction.md)."""
from __future__ import annotations

import numpy as np
import pytest

from rollqp.errors import InputError
from rollqp.friction.bound import step_coefficient
from friction_cases import patch_scene, veldep_scene
from rollqp.friction import parse_friction
from rollqp.march import run


def _same_path(scene, distance):
    """``load.rolled`` with one slope: q(τ) = τ over the whole run (the plain march's q = k·Δq)."""
    return scene.replace(**{"load.rolled": {"kind": "table", "q": [0.0, distance], "value": [0.0, distance]}})


@pytest.mark.parametrize("make", [
    lambda: patch_scene(elements=44, distance=3.0),
    lambda: veldep_scene(elements=46, memory=0.5, start="braked", distance=3.0, tangential=0.4),
], ids=["material patch", "falling friction with memory"])
def test_a_forward_load_path_is_the_plain_run(make):
    """A load path that only rolls forward gives the plain run: the laws see the same q, the same
    transport of the memory (the signed Δq = Δq) and the same directions (measured 1.8e-13 μp0 for
    the patch: the table's q_k − q_{k−1} against Δq, round-off)."""
    sc = make()
    mu = sc.contact.friction.reference
    a = run(sc).arrays()
    b = run(_same_path(sc, sc.discretization.distance)).arrays()
    # the plain march ends at K·Δq ≥ distance, the table at distance exactly (a shorter last step):
    # the states before the last one
    a, b = ({k: v[:-1] for k, v in r.items() if k in ("q", "pt", "friction_coefficient")} for r in (a, b))
    np.testing.assert_allclose(a["q"], b["q"], rtol=0, atol=1e-12 * sc.a_H)   # the table's q: round-off
    assert np.max(np.abs(a["pt"] - b["pt"])) / (mu * sc.p0) < 1e-11
    assert np.max(np.abs(a["friction_coefficient"] - b["friction_coefficient"])) < 1e-12


def test_reversal_brings_the_material_patch_back():
    """Roll a material patch into the contact, stop, roll back to q = 0: at every state of the way
    back the law's μ at the nodes is the one of the forward state at the same q (the patch is
    carried by the material both ways), and at q = 0 the patch is where it started."""
    sc = patch_scene(elements=44, distance=5.5, start=1.0, end=1.6)
    sc = sc.replace(**{"load.rolled": {"kind": "table", "q": [0, 2.5, 3.0, 5.5], "value": [0, 2.5, 2.5, 0]}})
    a = run(sc).arrays()
    q, mu = a["q"], a["friction_coefficient"]
    fwd = np.flatnonzero(a["direction"] == -1)
    back = np.flatnonzero(a["direction"] == +1)
    assert fwd.size and back.size
    for k in back:
        j = fwd[np.argmin(np.abs(q[fwd] - q[k]))]
        if abs(q[j] - q[k]) < 1e-9 * sc.a_H:
            assert np.array_equal(mu[j], mu[k]), (q[k], np.max(np.abs(mu[j] - mu[k])))
    law = sc.contact.friction
    x_hat = a["x"] / sc.a_H
    np.testing.assert_array_equal(mu[-1], law.coefficient(x_hat[None, :], 0.0, sc.load.direction))


@pytest.mark.parametrize("method", ["qp-osqp", pytest.param("qp-clarabel", marks=pytest.mark.slow)])
def test_methods_agree_on_a_load_path_with_a_patch(method):
    """A material patch through a stop and a reversal (constant elements): the QP backends (the
    friction fixed point is one QP a step for a patch) against Newton to their accuracy 1e-8 μp0."""
    sc = patch_scene(elements=44, distance=3.0, start=0.5, end=1.0)
    sc = sc.replace(**{"load.rolled": {"kind": "table", "q": [0, 1.0, 1.5, 3.0], "value": [0, 1.0, 1.0, -0.5]}})
    ref = run(sc, "newton").arrays()
    assert set(ref["direction"][1:]) == {-1, 0, 1}
    a = run(sc, method).arrays()
    mu = sc.contact.friction.reference
    assert np.max(np.abs(a["pt"] - ref["pt"])) / (mu * sc.p0) < 1e-8
    assert np.max(np.abs(a["pn"] - ref["pn"])) / sc.p0 < 1e-8


def test_memory_is_carried_back_by_a_negative_step():
    """The memory μ̄ moves with the material: by +Δq forward, by −Δq back (the node pattern shifted
    one spacing each way), and its weight L/(L + |Δq|) is the same both ways."""
    law = parse_friction({"law": "exponential", "static": 0.3, "kinetic": 0.2, "velocity": 1.0,
                     "rolling_speed": 1000.0, "memory": 0.5})
    x = np.linspace(-1.0, 1.0, 21)
    prev = 0.2 + 0.01 * np.arange(x.size)
    dx = x[1] - x[0]
    _, fwd = step_coefficient(law, x, 0.0, -1, dq_hat=dx, previous=prev)
    _, back = step_coefficient(law, x, 0.0, -1, dq_hat=-dx, previous=prev)
    assert fwd.weight == back.weight == pytest.approx(0.5 / (0.5 + dx))
    # direction −1: the material moves to −x rolling forward, so node i now holds what was at i + 1
    np.testing.assert_allclose(fwd.previous[:-1], prev[1:], rtol=0, atol=1e-15)
    np.testing.assert_allclose(back.previous[1:], prev[:-1], rtol=0, atol=1e-15)
    assert fwd.previous[-1] == back.previous[0] == pytest.approx(0.3)   # entering material: the static value


def test_a_patch_the_load_path_never_brings_into_the_strip_is_refused():
    """The sweep of a load path is the range of q it covers (a reversal does not extend it)."""
    sc = patch_scene(elements=44, distance=3.0, start=4.0, end=4.5)
    with pytest.raises(InputError, match=r"contact\.friction\.start.*outside the strip"):
        sc.replace(**{"load.rolled": {"kind": "table", "q": [0, 1.0, 3.0], "value": [0, 1.0, -1.0]}})
