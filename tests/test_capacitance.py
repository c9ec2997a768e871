"""The 3D dense Newton direction through the contact block's inverse (eq. 3D.28a,
rollqp/methods/newton/capacitance.py) against the LU of the Newton matrix: the same steps to round-off."""
from __future__ import annotations

import numpy as np
import pytest

from rollqp.materials import Materials
from rollqp.methods.newton import capacitance
from rollqp.methods.newton.disc import NewtonMethod
from rollqp.operators.grid import Contact, Loads
from rollqp.march.grid import static_shift, steady, transient

FN, MU = 1000.0, 0.3
STEEL = Materials.from_young(210e3, 0.28, 210e3, 0.28)
#: Both paths stop at ‖Φ‖∞ ≤ 1e-10; the directions differ by round-off times the Newton matrix's
#: condition (measured: at most 2e-14 of μp0 on these cases), so the tractions agree far inside 1e-10.
AGREE = 1e-10


def _circle(per=6):
    zone = (per + 1) / per * (1 + 1e-9)
    return Contact.hertzian(STEEL, (1 / 60, 1 / 60), FN, MU, elements=(2 * per + 2, 2 * per + 2), zone=(zone, zone))


def _runs(c, loads):
    m = NewtonMethod(path="dense")
    p = m.solve(c.normal_step(FN))
    out = [steady(c, m, FN, loads, pressure=p)]
    out += list(transient(c, m, FN, loads, c.grid.dx, 6))
    out += static_shift(c, m, FN, Fx=0.4 * MU * FN, Fy=-0.2 * MU * FN, steps=2)
    return out


@pytest.mark.parametrize("loads", [Loads(xi=-1e-3, eta=0.0, phi=0.0), Loads(xi=-1e-3, eta=5e-4, phi=0.8e-3),
                                   Loads(xi=-6e-3, eta=3e-3, phi=0.0)], ids=["xi", "xi-eta-phi", "mostly-slip"])
def test_capacitance_path_is_the_lu_path(monkeypatch, loads):
    c = _circle()
    new = _runs(c, loads)
    monkeypatch.setattr(capacitance, "MAX_FRACTION", -1.0)     # every direction by the LU of J
    old = _runs(_circle(), loads)
    unit = MU * c.scales.stress
    for a, b in zip(new, old):
        assert np.max(np.abs(a.t - b.t)) / unit <= AGREE
        assert a.iterations == b.iterations


def test_singular_capacitance_returns_none():
    """``C = M + (I − M) (A⁻¹)_QQ``: the identity where ``M = 0`` (then ``J = I``); a singular ``C`` → ``None``."""
    nv = 3
    S = np.eye(2 * nv)
    zero = np.zeros(nv)
    out = capacitance.solve(capacitance.inverse(S), 1.0, np.arange(nv), zero, zero, zero, np.ones(2 * nv))
    assert out is not None and np.allclose(out, np.ones(2 * nv))   # M = 0: J = I
    minus = -np.ones(nv)                                               # S = 2I, M = −I: C = −I + 2I·I/2 = 0
    assert capacitance.solve(capacitance.inverse(2 * S), 1.0, np.arange(nv), minus, zero, minus,
                             np.ones(2 * nv)) is None


def test_a_resumed_march_is_the_uninterrupted_one_bit_for_bit():
    """The inverse a march's steps share is formed whole, so a march resumed on a fresh contact (nothing kept)
    repeats the uninterrupted one bit for bit; a steady state is the same whatever was solved before it."""
    loads = Loads(xi=-1e-3, eta=5e-4, phi=0.8e-3)
    c, m = _circle(10), NewtonMethod(path="dense")
    whole = list(transient(c, m, FN, loads, c.grid.dx, 8))
    c2 = _circle(10)
    resumed = list(transient(c2, NewtonMethod(path="dense"), FN, loads, c2.grid.dx, 8, start=whole[4], first=5))
    for a, b in zip(whole[5:], resumed[1:]):
        assert np.array_equal(a.t, b.t) and np.array_equal(a.p, b.p)
    p = m.solve(c.normal_step(FN))
    first = steady(c, m, FN, loads, pressure=p)
    steady(c, m, FN, Loads(xi=-4e-3, eta=0.0, phi=0.0), pressure=p)       # other elements slip in between
    again = steady(c, m, FN, loads, pressure=p)
    assert np.array_equal(first.t, again.t)
