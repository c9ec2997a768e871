"""The worn depth of a 3D run (rollqp.wear.profile, the same function as in 2D; docs/stresses.md §10,
docs/validation3d.md §16): Archard's h = (k/H)∫p|s|dq along each material line (a row of elements), against
the closed form of a Hertz contact in full sliding with a convergence slope, the worn volume against the
frictional work, a reversal of load.rolled, and bad arguments in one line."""
from __future__ import annotations

import numpy as np
import pytest

import rollqp
from rollqp.energy import grid_balance
from rollqp.errors import InputError
from rollqp.wear import profile

KH = 1e-9      # Archard's k/H (1/MPa)
XI = 0.1       # full sliding: |ξ| is 17 times the largest elastic slip μ p0/G·(1 + ...) of this contact


def _sliding(n, **changes):
    """kalker-circular with ν = 0 (no lateral slip from the longitudinal traction), ξ = 0.1: every element of the
    contact slips with |s| = |ξ + ∂u/∂x|, rolled 3 a."""
    return rollqp.load_scene("kalker-circular").replace(**{
        "bodies.A.nu": 0.0, "bodies.B.nu": 0.0, "bodies.A.wear": KH, "load.creepage.longitudinal": XI,
        "discretization.elements": [n, n], "discretization.distance": 3.0, **changes})


def _plateau_error(n):
    """Largest difference over the rows between the worn depth of the material that crossed the whole contact
    and (k/H)|ξ|∫p_H dx = (k/H)|ξ|(π/2)p0 a(1 − y²/b²), over its peak."""
    s = _sliding(n)
    res = rollqp.run(s)
    sigma, h = profile(res)
    e, y = s.ellipse, res.arrays()["y"]
    exact = KH * XI * np.pi / 2 * e.p0 * e.a * np.clip(1 - (y / e.b) ** 2, 0, None)
    assert h.shape == (n, sigma.size)
    return float(np.abs(h.max(axis=1) - exact).max() / exact.max())


def test_the_worn_depth_of_full_sliding_converges_to_the_closed_form():
    """Measured 0.0250, 0.0122, 0.0067 (and 0.0032 on 80 × 80) of the peak on 10, 20, 40 elements across: first
    order (slopes 1.03, 0.87, 1.08), the grid's pressure against Hertz's near the edge of the ellipse (the
    elastic part of |s| integrates to zero along a row: p is even in x and ∂u/∂x odd). Bounds: each doubling
    at least 1.6 times smaller (slope 0.7), the 40 × 40 error below 0.008."""
    e = [_plateau_error(n) for n in (10, 20, 40)]
    assert e[0] / e[1] > 1.6 and e[1] / e[2] > 1.6 and e[2] < 0.008, e


@pytest.mark.parametrize("scene", ["sliding", "cattaneo-3d"])
def test_the_worn_volume_is_k_over_h_mu_times_the_frictional_work(scene):
    """∫∫h dσ dy = (k/H)/μ·Σ P_f Δq: where an element slips |t| = μp, so (k/H)p|s| = (k/H)/μ·(−t·s), and a
    sticking element neither wears nor dissipates. Full sliding: to 5e-14 (round-off); the braked start of
    cattaneo-3d rolling 2 a in partial slip: to the solver's tolerance on |t| = μp (measured 3e-10; bound 1e-8)."""
    s = _sliding(16) if scene == "sliding" else rollqp.load_scene("cattaneo-3d").replace(**{
        "discretization.elements": [16, 16], "discretization.distance": 2.0, "bodies.A.wear": KH})
    res = rollqp.run(s)
    a = res.arrays()
    sigma, h = profile(res, resolution=1)
    volume = float(h.sum()) * (sigma[1] - sigma[0]) * float(a["y"][1] - a["y"][0])
    work = grid_balance(a)["friction_work"][-1]
    assert work > 0 and volume == pytest.approx(KH / s.mu * work, rel=1e-8)


def test_a_reversal_wears_the_material_twice():
    """Rolled 3 a forward and 3 a back in full sliding (load.rolled): the material that crossed the contact both
    ways has twice the worn depth of the forward run's (to round-off: each pass sees the same steady state)."""
    forward = profile(rollqp.run(_sliding(12)))[1].max()
    back = profile(rollqp.run(_sliding(12, **{"discretization.distance": 6.0, "load.rolled": {
        "kind": "table", "q": [0.0, 3.0, 6.0], "value": [0.0, 3.0, 0.0]}})))[1].max()
    assert back == pytest.approx(2 * forward, rel=1e-12)


def test_the_coefficient_given_equals_the_scene_s():
    res = rollqp.run(_sliding(12))
    sigma, h = profile(res)
    s2, h2 = profile(res, coefficient=KH)
    assert np.array_equal(sigma, s2) and np.allclose(h2, h, rtol=1e-14, atol=0)


@pytest.mark.parametrize("kwargs, key", [
    (dict(body="C"), "body"), (dict(resolution=0), "resolution"), (dict(resolution=2.5), "resolution"),
    (dict(coefficient=-1.0), "coefficient"), (dict(coefficient=1.0), "coefficient"),
    (dict(body="B"), "coefficient")])
def test_bad_arguments_are_one_line_naming_them(kwargs, key):
    res = rollqp.run(_sliding(10, **{"discretization.distance": 0.5}))
    with pytest.raises(InputError, match=rf"^{key}: ") as err:
        profile(res, **kwargs)
    assert "\n" not in str(err.value)
