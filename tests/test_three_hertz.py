"""The Hertz ellipse, the body geometry and the grid (docs/theory3d.md §2–3)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from rollqp.errors import InputError
from rollqp.profiles.surface import Body, QuadraticProfile, curvatures
from rollqp.discretization.grid import ASPECT_RANGE, Grid
from rollqp.closedforms.hertz_ellipse import curvature_ratio, curvatures_for_ratio, hertz
from rollqp.materials import Materials


def test_circle_is_hertz_of_a_sphere():
    """A = B = 1/(2R): a³ = 3FR/(4E*), p0 = 3F/(2πa²), δ = a²/R (Johnson eq. 4.22–4.23)."""
    R, Estar, F = 30.0, 112e3, 1000.0
    e = hertz(1 / (2 * R), 1 / (2 * R), Estar, F)
    a = (3 * F * R / (4 * Estar)) ** (1 / 3)
    assert e.a == pytest.approx(a, rel=1e-14) and e.b == pytest.approx(a, rel=1e-14)
    assert e.p0 == pytest.approx(3 * F / (2 * math.pi * a * a), rel=1e-14)
    assert e.delta == pytest.approx(a * a / R, rel=1e-14)


def test_ellipse_matches_contact_hertz_output():
    """CONTACT's tractcurv (IPOTCN = −2, A1 = 0.8e-3, a/b = 0.5, FN = 106.7 kN, G = 82 GPa, ν = 0.28)
    prints B1 = 0.2814E-03, AA = 6.304, BB = 12.61: an independent code's Hertz solution, to its printed
    digits (its APPROACH is the grid solution's, checked in test_three_contact.py)."""
    m = Materials.from_shear(82000.0, 0.28, 82000.0, 0.28)
    B = curvatures_for_ratio(0.0008, 0.5)
    e = hertz(0.0008, B, m.Estar, 106700.0)
    assert B == pytest.approx(0.2814e-3, abs=0.00005e-3)
    assert e.a == pytest.approx(6.304, abs=0.0005) and e.b == pytest.approx(12.61, abs=0.005)
    assert e.a / e.b == pytest.approx(0.5, rel=1e-12)


@pytest.mark.parametrize("ratio", [0.2, 0.5, 1.0, 2.0, 5.0])
def test_semi_axis_ratio_round_trip(ratio):
    B = curvatures_for_ratio(0.01, ratio)
    e = hertz(0.01, B, 1e5, 50.0)
    assert e.a / e.b == pytest.approx(ratio, rel=1e-12)
    assert 2 / 3 * math.pi * e.a * e.b * e.p0 == pytest.approx(50.0, rel=1e-14)


def test_series_and_direct_quotients_join_continuously():
    """(K − E)/m and (E/g² − K)/m switch to their series at m = 1e-3: no step across it."""
    g_switch = math.sqrt(1 - 1e-3)
    below, above = curvature_ratio(g_switch * (1 + 1e-9)), curvature_ratio(g_switch * (1 - 1e-9))
    slope = (curvature_ratio(0.999) - curvature_ratio(0.9990001)) / (0.999 - 0.9990001)
    assert abs(below - above) < 1e-11 + abs(slope) * 3e-9


def test_hertz_pressure_is_zero_outside_and_p0_at_the_centre():
    e = hertz(0.02, 0.01, 1e5, 10.0)
    assert e.pressure(0.0, 0.0) == e.p0
    assert e.pressure(e.a * 1.0001, 0.0) == 0.0 and e.pressure(0.0, e.b * 1.0001) == 0.0


@pytest.mark.parametrize("args, key", [((0.0, 1.0, 1.0, 1.0), "A"), ((1.0, 1.0, -1.0, 1.0), "Estar"),
                                       ((1.0, 1.0, 1.0, float("inf")), "FN")])
def test_hertz_bad_input(args, key):
    with pytest.raises(InputError, match=f"^{key}:"):
        hertz(*args)


def test_curvatures_of_bodies():
    a, b = curvatures(Body(30.0, 60.0, "A"), Body(float("inf"), 120.0, "B"))
    assert (a, b) == (pytest.approx(1 / 60), pytest.approx(0.5 * (1 / 60 + 1 / 120)))
    assert QuadraticProfile(a, b)(np.array([1.0]), np.array([2.0]))[0] == pytest.approx(a + 4 * b)


@pytest.mark.parametrize("radius, key", [(0.0, "bodies.A.radius"), (-0.0, "bodies.A.radius"),
                                         (float("nan"), "bodies.A.radius"), ("x", "bodies.A.radius")])
def test_bad_radius_names_the_key(radius, key):
    with pytest.raises(InputError, match=key.replace(".", r"\.")):
        Body(radius, 1.0, "A")


def test_two_flat_generators_are_no_concentrated_contact():
    inf = float("inf")
    with pytest.raises(InputError, match="radius_y"):
        curvatures(Body(10.0, inf, "A"), Body(10.0, inf, "B"))


def test_grid_centres_are_contacts():
    """CONTACT's grid: element i's centre at XL + (i − ½)·DX (its cattaneo example prints −0.3500E-04
    for the centre row of XL = −1.26667, DX = 0.13333)."""
    g = Grid(19, 19, 0.13333, 0.13333, -1.26667, -1.26667)
    assert g.x[9] == pytest.approx(-0.35e-4, abs=1e-9)
    X, Y = g.centres()
    assert X.shape == (361,) and g.field(X).shape == (19, 19) and g.field(X)[3, 5] == g.x[5]


@pytest.mark.parametrize("kw, key", [(dict(nx=0), "nx"), (dict(dx=-1.0), "dx"), (dict(ny=2.5), "ny"),
                                     (dict(dx=1.0, dy=0.1), "elements"), (dict(nx=2000, ny=1000), "elements")])
def test_bad_grid_names_the_key(kw, key):
    base = dict(nx=10, ny=10, dx=0.1, dy=0.1, xl=-0.5, yl=-0.5)
    with pytest.raises(InputError, match=f"^{key}:"):
        Grid(**{**base, **kw})


def test_aspect_range_and_ellipse_cover():
    lo, hi = ASPECT_RANGE
    Grid(4, 4, lo, 1.0, 0.0, 0.0)
    Grid(4, 4, hi, 1.0, 0.0, 0.0)
    with pytest.raises(InputError, match="zone"):
        Grid.for_ellipse(1.0, 1.0, (10, 10), (1.0, 1.2))
    g = Grid.for_ellipse(1.0, 2.0, (20, 40), (1.2, 1.2))
    assert g.covers(1.0, 2.0) and not g.covers(1.1, 2.0)
