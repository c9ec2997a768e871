"""The run summary (rollqp.report.summary): units, small errors, steps with stops, resumed runs."""
from __future__ import annotations

import re

import numpy as np
import pytest

import rollqp
from rollqp.report import summary


def _row(text, label):
    return next(line for line in text.splitlines() if line.strip().startswith(label))


def test_summary_names_the_units_of_a_declared_scene():
    """a_H in mm and p0 in MPa beside the nondimensional values; the dissipation with its unit."""
    s = rollqp.load_scene("cattaneo-carter").replace(**{"discretization.distance": 0.25})
    text = summary(rollqp.run(s).arrays(), s, "newton", 1.0)
    assert re.search(r"a_H, p0 +1\.05046 mm, 606\.037 MPa", text), _row(text, "a_H")
    assert "N/mm per unit rolled distance" in _row(text, "dissipation")
    # without a declared unit system the numbers say what they are, never mm
    bare = s.replace(**{"units": None})
    text = summary(rollqp.run(bare).arrays(), bare, "newton", 1.0)
    assert "length units" in _row(text, "a_H") and "mm" not in _row(text, "a_H")


def test_small_errors_are_not_printed_as_zero(monkeypatch):
    """An rms error of 2e-5 (a fine mesh) prints as 2.05e-05, not 0.0000."""
    from rollqp import report
    s = rollqp.load_scene("cattaneo-carter").replace(**{"discretization.distance": 0.25})
    res = rollqp.run(s).arrays()
    monkeypatch.setattr(report, "closed_form_errors", lambda r, sc: [("hertz", 2.05e-5, "rms(pn - Hertz)/p0 at q = 0")])
    text = summary(res, s, "newton", 1.0)
    assert "2.05e-05" in _row(text, "error: hertz")


def test_steps_of_a_scene_with_a_stop():
    """stop-reverse: the stop's static steps are not counted as rolling steps."""
    s = rollqp.load_scene("stop-reverse").replace(**{
        "load.rolled": {"kind": "table", "q": [0, 0.5, 1.0, 1.5], "value": [0, 0.5, 0.5, 0]},
        "discretization.distance": 1.5})
    res = rollqp.run(s).arrays()
    at_rest = int(np.count_nonzero(res["direction"][1:] == 0))
    assert at_rest == 16  # 0.5 a_H of stop in steps of a_H/32
    row = _row(summary(res, s, "newton", 1.0), "steps")
    K = len(res["q"]) - 1
    assert f"{K} steps + starting state: {K - at_rest} rolling" in row and f"{at_rest} at rest" in row, row


def test_resumed_run_compares_wall_time_with_its_own_steps(tmp_path):
    """A resumed run's wall time covers only the steps computed after it resumed: the row says so and
    compares it with their stepping time, not with the whole file's."""
    from rollqp.result import load_result
    s = rollqp.load_scene("cattaneo-carter").replace(**{"discretization.distance": 1.0})
    part = rollqp.run(s.replace(**{"discretization.distance": 0.5})).save(tmp_path / "part.npz")
    run = rollqp.run(s, resume=load_result(part))
    res, first = run.arrays(), run.meta["resumed_from"]
    own = float(np.sum(res["step_time"][first + 1:]))
    row = _row(summary(res, s, "newton", own * 1.5), "wall time")
    assert f"steps {first + 1}..{len(res['q']) - 1} resumed here ({own:.3f} s stepping" in row, row
    assert float(row.split()[2]) >= own - 1e-3


@pytest.mark.parametrize("key, value", [("units", "furlongs"), ("units", 3), ("units", ["N-mm"]), ("units", {"a": 1})])
def test_bad_units_is_one_line(key, value):
    with pytest.raises(rollqp.InputError, match="units: must be one of 'N-mm'"):
        rollqp.load_scene("cattaneo-carter").replace(**{key: value})
