"""Friction laws varying over (x, y) on a 3D contact (docs/friction.md, "On the grid"): a table with rows
along ``y`` and a patch bounded in ``y``, checked against the exact integral of ``μ(x, y)`` times Hertz's
pressure under full sliding (with the slope of its error as the grid doubles), against the x-only table bit for
bit, on each element's own friction circle, and for bad input (one line naming the key)."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

import rollqp
from rollqp.errors import InputError
from rollqp.friction import parse_friction

# μ's kinks and jumps sit on element edges of every grid below (multiples of 0.1 a: the zone is 1.2 a, the
# elements 1/N a wide), so the midpoint rule sees each smooth piece whole
TABLE = {"law": "table", "x": [-0.9, 0.2, 0.8], "y": [-0.7, 0.3, 1.0],
         "values": [[0.2, 0.5, 0.3], [0.4, 0.1, 0.35], [0.25, 0.3, 0.6]]}
PATCH = {"law": "patch", "mu": 0.3, "inside": 0.1, "start": -0.4, "end": 2.0, "y_start": 0.0}


def _scene(law, per_semi_axis: int, xi: float = 0.05, distance: float = 0.5):
    """kalker-circular with ``per_semi_axis`` elements per Hertz semi-axis over the zone 1.2 a, steady rolling
    at the longitudinal creepage ``xi`` (0.05 and more: every element in contact slides)."""
    n = round(2.4 * per_semi_axis)
    return rollqp.load_scene("kalker-circular").replace(**{
        "discretization.elements": [n, n], "discretization.zone": [1.2, 1.2], "discretization.distance": distance,
        "load.creepage": {"longitudinal": xi, "lateral": 0.0, "spin": 0.0}, "contact.friction": law})


def _exact(law) -> float:
    """``∫∫ μ(x, y) p_H dA / F_N`` over the circular Hertz contact (``x, y`` in units of ``a``): scipy's
    quadrature of ``μ`` times the normalised Hertz pressure ``3/(2π) √(1 − x² − y²)``, split at μ's kinks."""
    L = parse_friction(law)
    xb = L.x if L.law == "table" else (L.start, L.end)
    yb = L.y if L.law == "table" else (L.y_start, L.y_end)
    xs = sorted({-1.0, 1.0, *(v for v in xb if v is not None and -1 < v < 1)})
    ys = sorted({-1.0, 1.0, *(v for v in yb if v is not None and -1 < v < 1)})

    def f(y, x):
        return L.coefficient(np.array([[x], [y]]), 0.0, -1)[0] * 1.5 / math.pi * math.sqrt(max(0.0, 1 - x * x - y * y))

    total = 0.0
    for x0, x1 in zip(xs, xs[1:]):
        for y0, y1 in zip(ys, ys[1:]):
            lo = lambda x, y0=y0: max(y0, -math.sqrt(max(0.0, 1 - x * x)))  # noqa: E731
            hi = lambda x, y1=y1, lo=lo: max(lo(x), min(y1, math.sqrt(max(0.0, 1 - x * x))))  # noqa: E731
            total += integrate.dblquad(f, x0, x1, lo, hi, epsabs=1e-13, epsrel=1e-12)[0]
    return total


def _mu(law, arrays):
    """μ at the result's element centres (the law read at ``(x, y)/a``), shaped like ``pn[-1]``."""
    x, y, a = arrays["x"], arrays["y"], float(arrays["a"])
    X, Y = np.meshgrid(x, y)
    return parse_friction(law).coefficient(np.array([X.ravel(), Y.ravel()]) / a, 0.0, -1).reshape(X.shape)


def test_a_table_with_equal_rows_is_the_x_table_bit_for_bit():
    x_only = {"law": "table", "x": [-0.9, 0.2, 0.8], "values": [0.2, 0.45, 0.3]}
    rows = {**x_only, "y": [-0.5, 0.1, 2.0], "values": [x_only["values"]] * 3}
    a = rollqp.run(_scene(x_only, 8, xi=2e-3, distance=1.0)).arrays()
    b = rollqp.run(_scene(rows, 8, xi=2e-3, distance=1.0)).arrays()
    assert (a["state"][-1] == 2).any() and (a["state"][-1] == 1).any()   # partial slip: μ shapes the tractions
    for k in ("pn", "px", "py", "Fx", "Fy", "Mz", "state"):
        assert np.array_equal(a[k], b[k]), k


@pytest.mark.parametrize("law", [TABLE, PATCH], ids=["table", "patch"])
def test_full_sliding_force_converges_to_the_integral_of_mu_times_hertz(law):
    """Full sliding at ξ = 0.5: Fx = −Σ μ_i p_i dA → −∫∫ μ p_Hertz dA as the grid doubles (10, 20, 40 per a)."""
    exact = _exact(law)
    errors = []
    for n in (10, 20, 40):
        r = rollqp.run(_scene(law, n, xi=0.5)).arrays()
        FN, Fx, p = float(r["FN"][-1]), float(r["Fx"][-1]), r["pn"][-1]
        assert np.all(r["state"][-1][p > 0] == 2)   # full sliding: every element in contact slips
        # ... so Fx = −Σ μ_i p_i dA of the run's own pressure up to the lean of the slip directions from x (the
        # elastic slip under a varying μ, ∝ 1/ξ²): measured 3.1e-8 F_N at ξ = 0.5 (3.1e-6 at ξ = 0.05, the size
        # of the 40-element error, hence ξ = 0.5)
        dA = (r["x"][1] - r["x"][0]) * (r["y"][1] - r["y"][0])
        assert abs(Fx + np.sum(_mu(law, r) * p) * dA) <= 1e-7 * FN
        errors.append(abs(-Fx / FN - exact))
    slope = math.log2(errors[0] / errors[2]) / 2
    print(f"{law['law']}: |Fx/FN - exact| at 10, 20, 40 per a = {', '.join(f'{e:.3g}' for e in errors)}; "
          f"slope {slope:.2f}")   # docs/validation3d.md §18 (pytest -s)
    # measured |Fx/F_N − exact| at 10, 20, 40 elements per semi-axis: table 4.84e-5, 1.42e-5, 3.06e-6 (slope
    # 1.99), patch 3.22e-5, 8.84e-6, 2.99e-6 (slope 1.71). Expected between 1.5 and 2: the midpoint rule is
    # second order on each smooth piece of μ p (μ's kinks and jumps on element edges), Hertz's √ edge in the
    # elements the contact's rim cuts costs O(h^1.5)
    assert errors[1] < errors[0] and errors[2] < errors[1], errors
    assert slope >= 1.5, (errors, slope)


def test_slipping_tractions_lie_on_their_own_circles():
    law = {"law": "patch", "mu": 0.3, "inside": 0.12, "start": -5.0, "end": 5.0, "y_start": 0.0}
    r = rollqp.run(_scene(law, 10, xi=1.5e-3, distance=1.5)).arrays()
    p0 = float(r["p0"])
    mu, p, state = _mu(law, r), r["pn"][-1], r["state"][-1]
    t = np.hypot(r["px"][-1], r["py"][-1])
    slip = state == 2
    # slip on both halves (so the two radii are both tested) and stick somewhere
    assert (slip & (mu == 0.12)).any() and (slip & (mu == 0.3)).any() and (state == 1).any()
    # |t_i| <= μ_i p_i everywhere, = on the slipping elements: to 1e-8 p0 (the residual tolerance 1e-10 on the
    # nondimensional projection, with margin)
    assert np.all(t <= mu * np.maximum(p, 0) + 1e-8 * p0)
    assert np.max(np.abs(t[slip] - mu[slip] * p[slip])) <= 1e-8 * p0
    # a patch on y >= 0 only: Fy ≠ 0 is allowed, the circles are what is checked; the halves differ
    assert np.max(t[slip & (mu == 0.12)] / p[slip & (mu == 0.12)]) < 0.2


BAD = [
    ({**TABLE, "y": [0.0, 0.0, 1.0]}, "contact.friction.y:", "strictly increasing"),
    ({**TABLE, "y": [0.0, 1.0]}, "contact.friction.values:", "2 rows (one per y)"),
    ({**TABLE, "values": [[0.2, 0.5, 0.3], [0.4, 0.1], [0.25, 0.3, 0.6]]}, "contact.friction.values[1]:", "3 entries"),
    ({**TABLE, "values": [[0.2, 0.5, 0.3], [0.4, -0.1, 0.3], [0.25, 0.3, 0.6]]}, "contact.friction.values[1][1]:", ">= 0"),
    ({**TABLE, "values": [[0.2, 0.5, 0.3], [0.4, float("nan"), 0.3], [0.25, 0.3, 0.6]]},
     "contact.friction.values[1][1]:", "finite"),
    ({**TABLE, "y": [0.0, "a", 1.0]}, "contact.friction.y[1]:", ""),
    ({**PATCH, "y_start": 0.5, "y_end": 0.5}, "contact.friction.y_end:", "> y_start"),
    ({**PATCH, "y_start": float("inf")}, "contact.friction.y_start:", "finite"),
]


@pytest.mark.parametrize("law,key,range_", BAD)
def test_bad_y_keys_are_one_line_naming_the_key(law, key, range_):
    with pytest.raises(InputError) as err:
        _scene(law, 4)
    msg = str(err.value)
    assert "\n" not in msg and msg.startswith(key) and range_ in msg, msg


@pytest.mark.parametrize("law,key", [(TABLE, "contact.friction.y:"), (PATCH, "contact.friction.y_start:"),
                                     ({**PATCH, "y_start": None, "y_end": 0.5}, "contact.friction.y_end:")])
def test_a_2d_scene_refuses_the_y_keys_in_one_line(law, key):
    law = {k: v for k, v in law.items() if v is not None}
    with pytest.raises(InputError) as err:
        rollqp.load_scene("cattaneo-carter").replace(**{"contact.friction": law})
    msg = str(err.value)
    assert "\n" not in msg and msg.startswith(key) and "3D" in msg, msg
