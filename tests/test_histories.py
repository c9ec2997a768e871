"""Load histories (rollqp.histories): values, exact extremes, parsing and its errors."""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from rollqp.errors import InputError
from rollqp.histories import (HISTORY_KINDS, Constant, Harmonic, History, Ramp, Table,
                              parse_history)

finite = st.floats(min_value=-10.0, max_value=10.0, allow_nan=False, allow_infinity=False)


# --------------------------------------------------------------------------- values
def test_constant_values_and_shapes():
    h = Constant(0.75)
    assert h(2.0) == 0.75, "constant value at a scalar q"
    assert isinstance(h(2.0), float), "scalar q gives a float"
    v = h(np.linspace(0, 3, 7).reshape(7, 1))
    assert isinstance(v, np.ndarray) and v.shape == (7, 1), "array q keeps its shape"
    assert np.all(v == 0.75), "constant value on an array"
    assert h.extremes(5.0) == (0.75, 0.75), "constant extremes"
    assert h.to_dict() == {"kind": "constant", "value": 0.75}, "constant to_dict"


def test_ramp_values():
    h = Ramp(0.0, 0.75, 8.0 / 3.0)
    assert h(0.0) == 0.0, "ramp starts at start"
    assert h(4.0 / 3.0) == pytest.approx(0.375, abs=1e-15), "ramp is linear: half way"
    assert h(8.0 / 3.0) == pytest.approx(0.75, abs=1e-15), "ramp reaches end at over"
    assert h(100.0) == 0.75, "ramp is held after over"
    q = np.array([0.0, 1.0, 2.0, 3.0, 4.0])
    np.testing.assert_allclose(h(q), 0.75 * np.minimum(q / (8 / 3), 1.0), atol=1e-15,
                               err_msg="vectorized ramp")
    assert h.extremes(1.0) == (0.0, pytest.approx(0.28125)), "extremes before the ramp ends"
    assert h.extremes(10.0) == (0.0, 0.75), "extremes after the ramp ends"
    down = Ramp(1.0, -1.0, 2.0)
    assert down.extremes(1.0) == (pytest.approx(0.0), 1.0), "decreasing ramp extremes"
    assert down.to_dict() == {"kind": "ramp", "start": 1.0, "end": -1.0, "over": 2.0}, \
        "ramp to_dict"


def test_harmonic_values():
    h = Harmonic(1.0, 0.2, 4.0, phase=0.5)
    q = np.linspace(0.0, 9.0, 31)
    np.testing.assert_allclose(h(q), 1.0 + 0.2 * np.sin(2 * np.pi * q / 4.0 + 0.5),
                               rtol=0, atol=1e-15, err_msg="harmonic formula")
    assert h.to_dict() == {"kind": "harmonic", "mean": 1.0, "amplitude": 0.2,
                           "wavelength": 4.0, "phase": 0.5}, "harmonic to_dict with phase"


def test_harmonic_extremes_reach_peaks_only_when_inside():
    h = Harmonic(1.0, 0.2, 4.0)  # peak at q = 1, trough at q = 3
    lo, hi = h.extremes(0.5)
    assert lo == 1.0 and hi == pytest.approx(1.0 + 0.2 * math.sin(math.pi / 4)), \
        "before the first peak the extremes are the end values"
    assert h.extremes(2.0) == (1.0, 1.2), "peak reached, trough not"
    assert h.extremes(3.5) == (0.8, 1.2), "both reached, exact values"
    neg = Harmonic(1.0, -0.2, 4.0)
    assert neg.extremes(2.0) == (0.8, 1.0), "negative amplitude: the first extremum is a trough"
    assert Harmonic(2.0, 0.0, 1.0).extremes(7.0) == (2.0, 2.0), "zero amplitude"


def test_table_values():
    h = Table([0.0, 1.0, 3.0], [0.5, 1.5, -0.5])
    assert h(-1.0) == 0.5, "held before the first point"
    assert h(0.5) == 1.0, "linear between points"
    assert h(2.0) == 0.5, "linear between points"
    assert h(10.0) == -0.5, "held after the last point"
    assert h.extremes(0.5) == (0.5, 1.0), "extremes inside the first interval"
    assert h.extremes(2.0) == (0.5, 1.5), "breakpoint at q = 1 is the max"
    assert h.extremes(5.0) == (-0.5, 1.5), "all breakpoints"
    one = Table([2.0], [0.3])
    assert one(0.0) == 0.3 and one(5.0) == 0.3, "a single point is a constant"
    assert h.to_dict() == {"kind": "table", "q": [0.0, 1.0, 3.0], "value": [0.5, 1.5, -0.5]}, \
        "table to_dict gives lists"


def test_histories_are_frozen_and_normalized():
    t = Table([0, 1], [0, 1])
    assert t == Table((0.0, 1.0), (0.0, 1.0)), "lists and ints normalize to tuples of floats"
    assert hash(t) == hash(Table((0.0, 1.0), (0.0, 1.0))), "histories are hashable"
    assert isinstance(Constant(1).value, float), "ints become floats"
    with pytest.raises(dataclasses.FrozenInstanceError):
        t.q = (0.0,)  # type: ignore[misc]


def test_direct_construction_validates():
    with pytest.raises(InputError, match="wavelength"):
        Harmonic(1.0, 0.1, 0.0)
    with pytest.raises(InputError, match="over"):
        Ramp(0.0, 1.0, -1.0)
    with pytest.raises(InputError, match="increasing"):
        Table([0.0, 0.0], [1.0, 2.0])


# --------------------------------------------------------------------------- extremes
def _check_extremes(h: History, q_end: float, n: int, slack: float):
    lo, hi = h.extremes(q_end)
    q = np.linspace(0.0, q_end, n)
    v = h(q)
    scale = 1.0 + float(np.max(np.abs(v)))
    assert v.min() >= lo - 1e-12 * scale, f"{h}: sampled min {v.min()} below extremes {lo}"
    assert v.max() <= hi + 1e-12 * scale, f"{h}: sampled max {v.max()} above extremes {hi}"
    assert v.min() <= lo + slack + 1e-12 * scale, f"{h}: min {lo} not attained ({v.min()})"
    assert v.max() >= hi - slack - 1e-12 * scale, f"{h}: max {hi} not attained ({v.max()})"
    c = h(h.critical_points(q_end))
    assert c.min() == pytest.approx(lo, abs=1e-12 * scale), f"{h}: min at a critical point"
    assert c.max() == pytest.approx(hi, abs=1e-12 * scale), f"{h}: max at a critical point"


@settings(max_examples=200, deadline=None)
@given(mean=finite, amplitude=finite, wavelength=st.floats(0.05, 20.0),
       phase=st.floats(-7.0, 7.0), q_end=st.floats(0.0, 30.0))
def test_harmonic_extremes_match_dense_sampling(mean, amplitude, wavelength, phase, q_end):
    h = Harmonic(mean, amplitude, wavelength, phase)
    n = 20001
    dq = q_end / (n - 1)
    # a sample is within dq/2 of the extremum: sin drops by at most (π dq / λ)² / 2
    slack = abs(amplitude) * 0.5 * (math.pi * dq / wavelength) ** 2
    _check_extremes(h, q_end, n, slack)


@settings(max_examples=200, deadline=None)
@given(data=st.data(), q_end=st.floats(0.0, 10.0))
def test_table_extremes_match_sampling(data, q_end):
    qs = data.draw(st.lists(st.floats(-2.0, 12.0), min_size=1, max_size=8, unique=True))
    qs = sorted(qs)
    assume(all(b - a > 1e-6 for a, b in zip(qs, qs[1:])))
    vals = data.draw(st.lists(finite, min_size=len(qs), max_size=len(qs)))
    h = Table(qs, vals)
    lo, hi = h.extremes(q_end)
    grid = np.unique(np.concatenate((np.linspace(0.0, q_end, 2001),
                                     [x for x in qs if 0.0 <= x <= q_end])))
    v = h(grid)
    assert v.min() == pytest.approx(lo, abs=1e-12), "table min equals the sampled min"
    assert v.max() == pytest.approx(hi, abs=1e-12), "table max equals the sampled max"


@pytest.mark.parametrize("h", [Constant(0.3), Ramp(0.2, -0.4, 1.5),
                               Harmonic(0.0, 1.0, 0.7, 1.0), Table([0.5, 1.0], [1.0, 3.0])],
                         ids=["constant", "ramp", "harmonic", "table"])
def test_critical_points_span_the_interval(h):
    c = h.critical_points(3.0)
    assert c[0] == 0.0 and c[-1] == 3.0, f"critical points start at 0 and end at q_end: {c}"
    assert np.all(np.diff(c) >= 0), "critical points are sorted"
    with pytest.raises(InputError, match="q_end"):
        h.extremes(-1.0)


# --------------------------------------------------------------------------- parsing
@pytest.mark.parametrize("h", [Constant(0.75), Ramp(0.0, 0.75, 8 / 3),
                               Harmonic(1.0, 0.2, 3.0, -0.3), Table([0.0, 2.0], [0.1, 0.2])],
                         ids=["constant", "ramp", "harmonic", "table"])
def test_parse_round_trip(h):
    d = h.to_dict()
    assert d["kind"] in HISTORY_KINDS, "to_dict names the kind"
    assert parse_history(d, "load.tangential") == h, "parse_history(to_dict()) gives it back"


def test_parse_defaults_and_shorthands():
    assert parse_history({"kind": "harmonic", "mean": 1, "amplitude": 0.1, "wavelength": 2},
                         "x").phase == 0.0, "harmonic phase defaults to 0"
    assert parse_history({"kind": "constant"}, "load.normal_history",
                         constant_default=1.0) == Constant(1.0), "constant default value"
    assert parse_history(0.5, "load.tangential") == Constant(0.5), "number shorthand"
    r = Ramp(0.0, 1.0, 1.0)
    assert parse_history(r, "load.tangential") is r, "a History is returned as is"


@pytest.mark.parametrize("obj, key, word", [
    ({"kind": "harmnic"}, "load.tangential.kind", "did you mean 'harmonic'"),
    ({"kind": "RAMP"}, "load.tangential.kind", "did you mean 'ramp'"),
    ({"value": 1.0}, "load.tangential.kind", "missing"),
    ({"kind": 3}, "load.tangential.kind", "must be one of"),
    ({"kind": "ramp", "start": 0, "end": 1, "ovr": 2}, "load.tangential.ovr",
     "did you mean 'over'"),
    ({"kind": "harmonic", "mean": 1, "amplitude": 0.1, "wavelenght": 2},
     "load.tangential.wavelenght", "did you mean 'wavelength'"),
    ({"kind": "ramp", "start": 0, "end": 1}, "load.tangential.over", "missing"),
    ({"kind": "constant"}, "load.tangential.value", "missing"),
    ({"kind": "harmonic", "mean": 1, "amplitude": 0.1, "wavelength": 0},
     "load.tangential.wavelength", "> 0"),
    ({"kind": "harmonic", "mean": 1, "amplitude": 0.1, "wavelength": -2},
     "load.tangential.wavelength", "> 0"),
    ({"kind": "ramp", "start": 0, "end": 1, "over": 0.0}, "load.tangential.over", "> 0"),
    ({"kind": "constant", "value": "0.5"}, "load.tangential.value", "finite number"),
    ({"kind": "constant", "value": True}, "load.tangential.value", "finite number"),
    ({"kind": "constant", "value": float("nan")}, "load.tangential.value", "finite"),
    ({"kind": "ramp", "start": float("inf"), "end": 1, "over": 1}, "load.tangential.start",
     "finite"),
    ({"kind": "table", "q": [], "value": []}, "load.tangential.q", "at least one"),
    ({"kind": "table", "q": [0, 1], "value": [1]}, "load.tangential.value", "as many"),
    ({"kind": "table", "q": [0, 2, 1], "value": [0, 1, 2]}, "load.tangential.q", "increasing"),
    ({"kind": "table", "q": [0, 1], "value": [0, "x"]}, "load.tangential.value[1]", "finite"),
    ({"kind": "table", "q": "0 1", "value": [0, 1]}, "load.tangential.q", "array"),
    ("1 + 1", "load.tangential", "inline table"),
    ([1, 2], "load.tangential", "inline table"),
], ids=lambda v: None if not isinstance(v, str) else v[:40])
def test_parse_errors_name_the_full_key(obj, key, word):
    with pytest.raises(InputError) as info:
        parse_history(obj, "load.tangential")
    msg = str(info.value)
    assert info.value.key == key, f"error key {info.value.key!r}, expected {key!r}: {msg}"
    assert msg.startswith(key), f"message names the key {key!r}: {msg}"
    assert word in msg, f"message mentions {word!r}: {msg}"
