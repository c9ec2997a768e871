"""Properties of the closed forms in rollqp.closedforms (docs/formulation.md §12).

The tests check physical properties (equilibrium, friction bound, stick conditions, symmetry,
limits), not the formulas retyped. Sign convention of docs/formulation.md §1: p ≥ 0; t acts on
body A in +x; ξ = (V_A − V_B)/|V|; d = sgn(V), material enters at x = −d·a.

Elasticity used for the stick checks (similar materials, half-space, plane strain): the
relative tangential displacement is w = A_tt t with kernel (2/(πE*))·(−ln|x − s|)
(docs/formulation.md §3), so

    ∂w/∂x(x) = −(2/(πE*))·PV∫ t(s)/(x − s) ds,

and the steady-rolling slip (docs/formulation.md §9, material derivative) is s = ξ + d·∂w/∂x.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad
from scipy.optimize import brentq

from rollqp import closedforms as cf
from rollqp.errors import InputError

# A steel-like geometry (units: N, mm). Only ratios matter; the values keep a/R small.
P, R, ESTAR, MU = 1000.0, 100.0, 1.1e5, 0.1
A = cf.hertz_half_width(P, R, ESTAR)
P0 = cf.hertz_peak_pressure(P, A)
RATIOS = [-0.99, -0.75, -0.3, -0.01, 0.01, 0.3, 0.75, 0.99]
DIRECTIONS = [-1, 1]
X = np.linspace(-1.2 * A, 1.2 * A, 4801)   # dense grid including points outside the contact


def _sgn(r: float) -> float:
    return math.copysign(1.0, r)


def _integral(fun, breaks):
    """∫ fun over [−a, a] split at the given interior breakpoints (kinks of the traction).

    Each piece is smooth inside with square-root endpoints, where QUADPACK reaches ~1e-12
    relative; the tolerances below allow 1e-10.
    """
    pts = sorted({-A, A, *[b for b in breaks if -A < b < A]})
    return sum(quad(fun, lo, hi, epsabs=0.0, epsrel=1e-13, limit=200)[0]
               for lo, hi in zip(pts[:-1], pts[1:]))


def _strain(traction, x, breaks):
    """∂w/∂x at x (not a breakpoint), from PV∫ t(s)/(x − s) ds on the pieces between breaks.

    quad's weight='cauchy' computes PV∫ f(s)/(s − x) ds on the piece containing x; the other
    pieces have a regular integrand.
    """
    pts = sorted({-A, A, *[b for b in breaks if -A < b < A]})
    pv = 0.0
    for lo, hi in zip(pts[:-1], pts[1:]):
        if lo < x < hi:
            pv -= quad(traction, lo, hi, weight="cauchy", wvar=x, epsabs=0.0, epsrel=1e-12,
                       limit=200)[0]
        else:
            pv += quad(lambda s: traction(s) / (x - s), lo, hi, epsabs=0.0, epsrel=1e-12,
                       limit=200)[0]
    return -2.0 / (math.pi * ESTAR) * pv


# ---------------------------------------------------------------------------------- Hertz
def test_hertz_pressure_carries_the_load():
    load = quad(lambda x: cf.hertz_pressure(x, A, P0), -A, A, epsabs=0.0, epsrel=1e-13)[0]
    # Smooth integrand with square-root endpoints: QUADPACK reaches ~1e-14; allow 1e-10.
    assert load == pytest.approx(P, rel=1e-10), f"∫p dx = {load!r} differs from P = {P!r}"


def test_hertz_peak_pressure_consistent_with_half_width():
    expected = A * ESTAR / (2.0 * R)
    # Two algebraically identical expressions: only rounding separates them.
    assert P0 == pytest.approx(expected, rel=1e-12), \
        f"p0 = 2P/(πa) = {P0!r} but aE*/(2R) = {expected!r}"


def test_hertz_pressure_nonnegative_and_zero_outside():
    p = cf.hertz_pressure(X, A, P0)
    assert p.shape == X.shape, f"vectorized output has shape {p.shape}, expected {X.shape}"
    assert np.all(p >= 0.0), "pressure must be compressive (p >= 0) everywhere"
    assert np.all(p[np.abs(X) > A] == 0.0), "pressure must vanish outside |x| <= a"
    assert cf.hertz_pressure(0.0, A, P0) == P0, "peak pressure must be at the centre"
    assert isinstance(cf.hertz_pressure(0.0, A, P0), float), "scalar x must give a float"


# ------------------------------------------------------------------------------- Cattaneo
@pytest.mark.parametrize("ratio", RATIOS)
def test_cattaneo_equilibrium(ratio):
    c = cf.cattaneo_stick_half_width(A, ratio)
    q = _integral(lambda x: cf.cattaneo_traction(x, A, P0, MU, ratio), [-c, c])
    # Piecewise smooth with square-root kinks at the breakpoints; 1e-10 relative to μP.
    assert q == pytest.approx(ratio * MU * P, abs=1e-10 * MU * P), \
        f"∫t dx = {q!r}, expected ratio·μP = {ratio * MU * P!r} (ratio {ratio})"


@pytest.mark.parametrize("ratio", RATIOS)
def test_cattaneo_friction_bound_and_slip_zone(ratio):
    t = cf.cattaneo_traction(X, A, P0, MU, ratio)
    mup = MU * cf.hertz_pressure(X, A, P0)
    c = cf.cattaneo_stick_half_width(A, ratio)
    tol = 1e-12 * MU * P0   # rounding of a difference of two O(μp0) terms
    assert np.all(np.abs(t) <= mup + tol), f"|t| > μp somewhere (ratio {ratio})"
    slip = (np.abs(X) >= c) & (np.abs(X) <= A)
    assert np.any(slip), "the grid must sample the slip zone"
    assert np.allclose(t[slip], _sgn(ratio) * mup[slip], rtol=0.0, atol=tol), \
        f"t must equal sgn(ratio)·μp in the slip zone c <= |x| <= a (ratio {ratio})"
    stick = np.abs(X) < 0.999 * c
    assert np.all(np.abs(t[stick]) < mup[stick]), \
        f"|t| must be strictly below μp inside the stick zone (ratio {ratio})"
    assert np.all(t * _sgn(ratio) >= -tol), f"t must have the sign of Q (ratio {ratio})"


@pytest.mark.parametrize("ratio", RATIOS)
def test_cattaneo_even(ratio):
    t = cf.cattaneo_traction(X, A, P0, MU, ratio)
    t_mirror = cf.cattaneo_traction(-X, A, P0, MU, ratio)
    # X is symmetric, so the same floating-point operations run on ±x.
    assert np.array_equal(t, t_mirror), f"Cattaneo traction must be even in x (ratio {ratio})"


@pytest.mark.parametrize("ratio", [-0.75, 0.3, 0.9])
def test_cattaneo_stick_zone_moves_rigidly(ratio):
    """In the stick zone w is a rigid shift: ∂w/∂x = 0."""
    c = cf.cattaneo_stick_half_width(A, ratio)
    traction = lambda s: cf.cattaneo_traction(s, A, P0, MU, ratio)  # noqa: E731
    scale = MU * A / R          # the natural strain scale (μa/R = 2μp0/E*)
    for frac in (-0.8, -0.3, 0.1, 0.6):
        e = _strain(traction, frac * c, [-c, c])
        # Cauchy principal values by QUADPACK: ~1e-10 relative to the strain scale.
        assert abs(e) <= 1e-8 * scale, \
            f"∂w/∂x = {e!r} at x = {frac}c must vanish in the Cattaneo stick zone (ratio {ratio})"


# --------------------------------------------------------------------------------- Carter
@pytest.mark.parametrize("direction", DIRECTIONS)
@pytest.mark.parametrize("ratio", RATIOS)
def test_carter_equilibrium(ratio, direction):
    lo, hi = cf.carter_stick_zone(A, ratio, direction)
    q = _integral(lambda x: cf.carter_traction(x, A, P0, MU, ratio, direction), [lo, hi])
    # As for Cattaneo: piecewise smooth with square-root kinks; 1e-10 relative to μP.
    assert q == pytest.approx(ratio * MU * P, abs=1e-10 * MU * P), \
        f"∫t dx = {q!r}, expected {ratio * MU * P!r} (ratio {ratio}, d {direction})"


@pytest.mark.parametrize("direction", DIRECTIONS)
@pytest.mark.parametrize("ratio", RATIOS)
def test_carter_friction_bound_and_slip_zone(ratio, direction):
    t = cf.carter_traction(X, A, P0, MU, ratio, direction)
    mup = MU * cf.hertz_pressure(X, A, P0)
    lo, hi = cf.carter_stick_zone(A, ratio, direction)
    tol = 1e-12 * MU * P0   # rounding of a difference of two O(μp0) terms
    assert np.all(np.abs(t) <= mup + tol), f"|t| > μp somewhere (ratio {ratio}, d {direction})"
    # The stick term is a square root vanishing at the zone ends: within δ of an end it is
    # O(√(δ/c)), so an ulp of rounding in the end itself would show up as ~1e-8; keep 1e-9·a away.
    outside = (X <= lo - 1e-9 * A) | (X >= hi + 1e-9 * A)
    assert np.allclose(t[outside], _sgn(ratio) * mup[outside], rtol=0.0, atol=tol), \
        f"t must equal sgn(ratio)·μp outside the stick zone (ratio {ratio}, d {direction})"
    half = 0.5 * (hi - lo)
    inner = np.abs(X - 0.5 * (lo + hi)) < 0.999 * half
    assert np.all(np.abs(t[inner]) < mup[inner]), \
        f"|t| must be strictly below μp inside the stick zone (ratio {ratio}, d {direction})"


@pytest.mark.parametrize("ratio", RATIOS)
def test_carter_stick_zone_at_leading_edge_and_mirrors(ratio):
    c = cf.cattaneo_stick_half_width(A, ratio)   # same half-width a√(1 − |ratio|)
    for d in DIRECTIONS:
        lo, hi = cf.carter_stick_zone(A, ratio, d)
        leading = lo if d == 1 else hi
        # Exact up to rounding of x_c ± c with x_c = −d(a − c).
        assert leading == pytest.approx(-d * A, rel=1e-14), \
            f"stick zone {lo, hi} must touch the leading edge x = {-d * A} (d {d})"
        assert hi - lo == pytest.approx(2 * c, rel=1e-12), \
            f"stick zone {lo, hi} must have width 2c = {2 * c} (d {d})"
    plus = cf.carter_traction(X, A, P0, MU, ratio, +1)
    minus_mirrored = cf.carter_traction(-X, A, P0, MU, ratio, -1)
    # Same operations up to the sign of x and x_c: rounding only.
    assert np.allclose(plus, minus_mirrored, rtol=0.0, atol=1e-13 * MU * P0), \
        f"carter(x, d=+1) must equal carter(−x, d=−1) (ratio {ratio})"


@pytest.mark.parametrize("direction", DIRECTIONS)
@pytest.mark.parametrize("ratio", [-0.75, -0.3, 0.1, 0.5, 0.9])
def test_carter_stick_zone_is_slip_free_at_carter_creepage(ratio, direction):
    """Uniform ∂w/∂x in the stick zone, s = ξ + d·∂w/∂x = 0 there, and −sgn(t) slip elsewhere."""
    lo, hi = cf.carter_stick_zone(A, ratio, direction)
    traction = lambda s: cf.carter_traction(s, A, P0, MU, ratio, direction)  # noqa: E731
    xi = cf.carter_creepage(A, R, MU, ratio)
    scale = MU * A / R          # natural strain/creepage scale
    for frac in (0.1, 0.35, 0.6, 0.85):
        x = lo + frac * (hi - lo)
        slip = xi + direction * _strain(traction, x, [lo, hi])
        # Cauchy principal values by QUADPACK: ~1e-10 of the scale; allow 1e-8.
        assert abs(slip) <= 1e-8 * scale, \
            f"slip {slip!r} ≠ 0 at x = {x} in the stick zone (ratio {ratio}, d {direction})"
    # In the slip zone (trailing side) friction opposes slip: t = −μp·sgn(s).
    trail_lo, trail_hi = (hi, A) if direction == 1 else (-A, lo)
    for frac in (0.2, 0.5, 0.8):
        x = trail_lo + frac * (trail_hi - trail_lo)
        slip = xi + direction * _strain(traction, x, [lo, hi])
        assert slip * _sgn(ratio) < -1e-6 * scale, \
            f"slip {slip!r} at x = {x} must oppose t (sign {_sgn(ratio)}) (ratio {ratio}, d {direction})"


def test_carter_creepage_opposes_load_and_ignores_direction():
    for r in RATIOS:
        xi = cf.carter_creepage(A, R, MU, r)
        assert xi * r < 0, f"ξ = {xi} and Q (ratio {r}) must have opposite signs"
        assert abs(xi) < MU * A / R, f"|ξ| = {abs(xi)} must stay below μa/R in partial slip"
    assert cf.carter_creepage(A, R, MU, 0.0) == 0.0, "no load, no creepage"
    arr = cf.carter_creepage(A, R, MU, np.array(RATIOS))
    assert arr.shape == (len(RATIOS),), "carter_creepage must vectorize over ratio"


@settings(max_examples=300, deadline=None)
@given(st.floats(min_value=-1.0, max_value=1.0, exclude_min=True, exclude_max=True))
def test_creep_force_law_inverts_carter_creepage(ratio):
    back = cf.creep_force_ratio(cf.carter_creepage(A, R, MU, ratio), A, R, MU)
    # 1 − √(1 − |r|) then 1 − (1 − u)²: absolute rounding ~1e-16; near r = 0 the creepage
    # underflows relative to 1 (|r| < 1e-16 maps to 0), so compare absolutely.
    assert back == pytest.approx(ratio, abs=1e-12), \
        f"creep_force_ratio(carter_creepage({ratio!r})) = {back!r}"


def test_creep_force_law_monotone_saturating_and_linear_slope():
    xi_sat = MU * A / R
    xi = np.linspace(-2.5 * xi_sat, 2.5 * xi_sat, 5001)
    f = cf.creep_force_ratio(xi, A, R, MU)
    assert np.all(np.diff(f) <= 0.0), "Q/(μP) must be non-increasing in ξ"
    inner = np.abs(xi) < xi_sat
    assert np.all(np.diff(f[inner]) < 0.0), "Q/(μP) must be strictly decreasing in partial slip"
    assert np.all(np.abs(f) <= 1.0), "|Q| must not exceed μP"
    beyond = np.abs(xi) >= xi_sat
    assert np.array_equal(f[beyond], -np.sign(xi[beyond])), \
        "beyond |ξ| = μa/R the law must saturate at full sliding, Q = −sgn(ξ)·μP"
    assert cf.creep_force_ratio(0.0, A, R, MU) == 0.0, "no creepage, no force"
    h = 1e-7 * xi_sat
    slope = (cf.creep_force_ratio(h, A, R, MU) - cf.creep_force_ratio(-h, A, R, MU)) / (2 * h)
    dq_dxi = MU * P * slope
    assert math.isfinite(dq_dxi) and dq_dxi < 0, f"dQ/dξ at 0 = {dq_dxi} must be finite and negative"
    # 2D linear creep coefficient dQ/dξ = −πaE*/2; the central difference of a law that is
    # quadratic in |ξ| errs by O(h/ξ_sat) = 1e-7 relative; allow 1e-6.
    assert dq_dxi == pytest.approx(-math.pi * A * ESTAR / 2, rel=1e-6), \
        f"dQ/dξ at 0 = {dq_dxi}, expected the 2D linear creep coefficient −πaE*/2"


def test_creep_force_law_zero_friction_is_full_sliding():
    f = cf.creep_force_ratio(np.array([-1e-9, 0.0, 1e-9]), A, R, 0.0)
    assert np.array_equal(f, [1.0, 0.0, -1.0]), f"μ = 0 must give full sliding, got {f}"


# ---------------------------------------------------------------------------------- limits
@pytest.mark.parametrize("direction", DIRECTIONS)
def test_small_ratio_gives_vanishing_traction(direction):
    assert np.all(cf.cattaneo_traction(X, A, P0, MU, 0.0) == 0.0), "Cattaneo at ratio 0 must be 0"
    assert np.all(cf.carter_traction(X, A, P0, MU, 0.0, direction) == 0.0), \
        "Carter at ratio 0 must be 0"
    previous = math.inf
    for r in (1e-2, 1e-4, 1e-6, -1e-8):
        peak = max(np.max(np.abs(cf.cattaneo_traction(X, A, P0, MU, r))),
                   np.max(np.abs(cf.carter_traction(X, A, P0, MU, r, direction))))
        # Bound (exact, not a tolerance), k = c/a: in both stick zones |t| grows towards the
        # stick/slip boundary, where it equals μp, and μp decreases beyond it (for |r| < 3/4).
        # Cattaneo: |t|/μp0 = (1 − k²)/(√(1 − X²) + √(k² − X²)) ≤ √(1 − k²) = √|r|.
        # Carter, E = distance from the leading edge / a: |t|/μp0 =
        # √E·2(1 − k)/(√(2 − E) + √(2k − E)) ≤ 2√(k(1 − k)) ≤ 2√|r|. Slack for rounding.
        assert peak <= 2.0 * MU * P0 * math.sqrt(abs(r)) + 1e-12 * MU * P0, \
            f"max|t| = {peak} at ratio {r} must be at most 2μp0√|ratio|"
        assert peak < previous, f"max|t| must decrease as ratio → 0 (ratio {r})"
        previous = peak


@pytest.mark.parametrize("direction", DIRECTIONS)
@pytest.mark.parametrize("sign", [-1.0, 1.0])
def test_ratio_near_one_gives_full_sliding_traction(sign, direction):
    mup = MU * cf.hertz_pressure(X, A, P0)
    for gap in (1e-2, 1e-6, 1e-12):
        r = sign * (1.0 - gap)
        # The stick term is bounded by μp0·c/a = μp0√gap; small slack for rounding.
        bound = MU * P0 * math.sqrt(gap) * (1 + 1e-9) + 1e-13 * MU * P0
        for t in (cf.cattaneo_traction(X, A, P0, MU, r),
                  cf.carter_traction(X, A, P0, MU, r, direction)):
            assert np.max(np.abs(t - sign * mup)) <= bound, \
                f"t must approach {sign:+}·μp as |ratio| → 1 (ratio {r}, d {direction})"


# ------------------------------------------------------------------------- Bentall–Johnson
def test_bentall_johnson_coefficient_and_magnitude():
    C = cf.BENTALL_JOHNSON_COEFFICIENT
    assert round(C, 3) == 0.457, f"coefficient {C} must round to the quoted 0.457"
    for kappa in (0.288, 1.0):
        xi = cf.bentall_johnson_creepage(kappa, A, R)
        assert xi == cf.bentall_johnson_creepage(-kappa, A, R) > 0, \
            "the function returns a magnitude, the same for ±κ"
        # Magnitude vs the quoted 0.457·κ·a/R: the quoted constant is rounded to 3 digits.
        assert xi == pytest.approx(0.457 * kappa * A / R, rel=1e-3), \
            f"|ξ| = {xi} must be 0.457·κ·a/R to the quoted precision"
    assert cf.bentall_johnson_creepage(0.0, A, R) == 0.0, "similar materials roll freely without creep"


@pytest.mark.parametrize("direction", DIRECTIONS)
@pytest.mark.parametrize("kappa", [0.288, -1.0])
def test_bentall_johnson_is_the_free_rolling_zero_friction_limit(kappa, direction):
    """As μ → 0, t → 0, so w comes from the pressure alone: with §3's A_tn,
    ∂w/∂x = −(κ/E*)·p and the steady slip is s = ξ − d·κ·p(x)/E*. Friction gives
    t = −μp·sgn(s); free rolling (Q = 0) must hold exactly at the returned |ξ|, with
    sgn(ξ) = d·sgn(κ)."""
    def s_of(xi, x):
        return xi - direction * kappa * cf.hertz_pressure(x, A, P0) / ESTAR

    def q_of(xi):
        # s is even in x and monotone in |x| (p is): locate its sign change on (0, a) by
        # bisection and integrate the piecewise-smooth traction piece by piece.
        breaks = [0.0]
        if s_of(xi, 0.0) * s_of(xi, A) < 0:
            b = brentq(lambda x: s_of(xi, x), 0.0, A, xtol=1e-15 * A, rtol=1e-15)
            breaks = [-b, b]
        t = lambda x: -MU * cf.hertz_pressure(x, A, P0) * np.sign(s_of(xi, x))  # noqa: E731
        return _integral(t, breaks)

    xi = direction * math.copysign(1.0, kappa) * cf.bentall_johnson_creepage(kappa, A, R)
    q = q_of(xi)
    # The root b is located to ~1e-15·a, where p jumps across it: Q error ~1e-14·μP, plus
    # quadrature ~1e-13; allow 1e-10·μP.
    assert abs(q) <= 1e-10 * MU * P, f"Q = {q} ≠ 0 at the Bentall–Johnson creepage {xi}"
    for factor in (0.95, 1.05):
        assert abs(q_of(factor * xi)) > 1e-3 * MU * P, \
            f"Q must be clearly nonzero at {factor}·ξ (the root is isolated)"
    assert abs(q_of(-xi)) > 0.5 * MU * P, \
        "the opposite sign of ξ must not be a free-rolling state (sign pinned: d·sgn(κ))"


# --------------------------------------------------------------------------- invalid input
@pytest.mark.parametrize("call, key", [
    (lambda: cf.cattaneo_traction(0.0, A, P0, MU, 1.0), "ratio"),
    (lambda: cf.cattaneo_traction(0.0, A, P0, MU, -1.5), "ratio"),
    (lambda: cf.cattaneo_traction(0.0, A, P0, MU, math.nan), "ratio"),
    (lambda: cf.cattaneo_traction(0.0, 0.0, P0, MU, 0.5), "a"),
    (lambda: cf.cattaneo_traction(0.0, A, P0, -0.1, 0.5), "mu"),
    (lambda: cf.cattaneo_stick_half_width(A, -1.0), "ratio"),
    (lambda: cf.cattaneo_stick_half_width(-A, 0.5), "a"),
    (lambda: cf.carter_traction(0.0, A, P0, MU, -1.0, 1), "ratio"),
    (lambda: cf.carter_traction(0.0, -A, P0, MU, 0.5, 1), "a"),
    (lambda: cf.carter_traction(0.0, A, P0, -MU, 0.5, 1), "mu"),
    (lambda: cf.carter_traction(0.0, A, P0, MU, 0.5, 0), "direction"),
    (lambda: cf.carter_traction(0.0, A, P0, MU, 0.5, 2), "direction"),
    (lambda: cf.carter_traction(0.0, A, P0, MU, 0.5, True), "direction"),
    (lambda: cf.carter_stick_zone(A, 0.5, -0.5), "direction"),
    (lambda: cf.carter_stick_zone(A, 1.0, 1), "ratio"),
    (lambda: cf.carter_creepage(A, R, MU, 1.0), "ratio"),
    (lambda: cf.carter_creepage(A, R, MU, [0.2, -1.2]), "ratio"),
    (lambda: cf.carter_creepage(0.0, R, MU, 0.5), "a"),
    (lambda: cf.carter_creepage(A, R, -MU, 0.5), "mu"),
    (lambda: cf.carter_creepage(A, 0.0, MU, 0.5), "R"),
    (lambda: cf.creep_force_ratio(1e-3, -A, R, MU), "a"),
    (lambda: cf.creep_force_ratio(1e-3, A, R, -MU), "mu"),
    (lambda: cf.creep_force_ratio(math.inf, A, R, MU), "xi"),
    (lambda: cf.hertz_half_width(P, -R, ESTAR), "R"),
    (lambda: cf.hertz_half_width(-P, R, ESTAR), "P"),
    (lambda: cf.hertz_half_width(P, R, 0.0), "Estar"),
    (lambda: cf.hertz_peak_pressure(P, 0.0), "a"),
    (lambda: cf.hertz_pressure(0.0, -1.0, P0), "a"),
    (lambda: cf.bentall_johnson_creepage(1.5, A, R), "kappa"),
    (lambda: cf.bentall_johnson_creepage(0.3, -A, R), "a"),
])
def test_invalid_input_names_the_argument(call, key):
    with pytest.raises(InputError) as info:
        call()
    assert info.value.key == key, f"InputError names {info.value.key!r}, expected {key!r}"
    assert str(info.value).startswith(f"{key}:"), f"message {info.value} must start with the key"


# ---------------------------------------------------------------------------- documentation
def test_every_function_is_documented_and_cited():
    functions = [n for n in cf.__all__ if callable(getattr(cf, n))]
    assert set(functions) == set(cf.SOURCES), \
        f"SOURCES keys {sorted(cf.SOURCES)} must match the public functions {sorted(functions)}"
    for name in functions:
        doc = getattr(cf, name).__doc__ or ""
        assert "Parameters" in doc and "Returns" in doc, f"{name} needs a numpydoc docstring"
        assert "SOURCES" in doc, f"{name}'s docstring must point to its citation"
        assert cf.SOURCES[name].strip(), f"{name} has an empty citation"


def test_carter_slip_vanishes_in_the_stick_zone_and_opposes_the_traction():
    """carter_slip: zero in Carter's stick zone, NaN outside the contact, of the sign opposite
    to the traction in the slip zone (t = −μp·sgn(s)), continuous at the stick edge, mirrored
    with the direction, and equal to ξ + d·∂w/∂x computed from the traction by quadrature."""
    a, R, mu = 1.3, 80.0, 0.25
    x = np.linspace(-1.2 * a, 1.2 * a, 2401)
    for ratio in (0.3, -0.75):
        for d in (1, -1):
            s = cf.carter_slip(x, a, R, mu, ratio, d)
            t = cf.carter_traction(x, a, 1.0, mu, ratio, d)
            lo, hi = cf.carter_stick_zone(a, ratio, d)
            inside = np.abs(x) < a
            assert np.all(np.isnan(s[~inside]))
            stick = (x > lo + 1e-12) & (x < hi - 1e-12)
            assert np.all(s[stick] == 0.0)
            slip = inside & ~((x >= lo) & (x <= hi))
            assert np.all(np.sign(s[slip]) == -np.sign(t[slip])), "slip must oppose the traction"
            assert np.allclose(cf.carter_slip(-x, a, R, mu, ratio, -d), s, equal_nan=True)
    # d·∂w/∂x by the Hilbert transform of the traction, evaluated numerically (midpoint rule on a
    # fine grid, the singular point excluded symmetrically: error O(h log h) ≈ 1e-3 relative)
    ratio, d = 0.6, 1
    E_star = 1.0
    p0 = a * E_star / (2 * R)
    h = a / 20000
    s_nodes = np.arange(-a + h / 2, a, h)
    t_nodes = cf.carter_traction(s_nodes, a, p0, mu, ratio, d)
    xi = cf.carter_creepage(a, R, mu, ratio)
    for xq in (0.55 * a, 0.8 * a, 0.95 * a):  # in the trailing slip zone for d = +1
        xq = s_nodes[np.argmin(np.abs(s_nodes - xq))] + h / 2  # between two nodes
        dwdx = -(2 / (np.pi * E_star)) * np.sum(t_nodes / (xq - s_nodes)) * h
        assert cf.carter_slip(xq, a, R, mu, ratio, d) == pytest.approx(xi + d * dwdx, abs=2e-3 * mu * a / R)
